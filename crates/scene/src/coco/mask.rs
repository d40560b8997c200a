//! A binary mask as COCO writes it: its tight box, its run-length encoding (pycocotools'
//! compressed string) and one polygon whose even-odd fill, as pycocotools rasterises it, is the
//! mask pixel for pixel.

/// A binary mask over an image, row-major: pixel (x, y) is `inside[y * width + x]`.
pub struct Mask<'a> {
    /// Pixels across.
    pub width: usize,
    /// Pixels down.
    pub height: usize,
    /// Whether each pixel is in the mask.
    pub inside: &'a [bool],
}

impl Mask<'_> {
    fn at(&self, x: i64, y: i64) -> bool {
        (0..self.width as i64).contains(&x)
            && (0..self.height as i64).contains(&y)
            && self.inside[y as usize * self.width + x as usize]
    }

    /// The pixels in the mask.
    pub fn area(&self) -> usize {
        self.inside.iter().filter(|&&b| b).count()
    }

    /// The tight box `[x, y, width, height]` in pixels (a pixel spans one unit from its
    /// corner), or `None` for an empty mask.
    pub fn bbox(&self) -> Option<[usize; 4]> {
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
        for (k, _) in self.inside.iter().enumerate().filter(|(_, b)| **b) {
            let (x, y) = (k % self.width, k / self.width);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
        (x0 != usize::MAX).then(|| [x0, y0, x1 - x0 + 1, y1 - y0 + 1])
    }

    /// COCO's run lengths of this mask placed at (`x0`, `y0`) in a `width`×`height` image:
    /// column by column (column-major), alternating runs outside and inside the mask, the
    /// first outside (0 when the image's first pixel is inside).
    pub fn runs_in(&self, x0: usize, y0: usize, width: usize, height: usize) -> Vec<u32> {
        let mut runs = Runs::default();
        runs.add(false, x0 * height);
        for x in 0..self.width {
            runs.add(false, y0);
            for y in 0..self.height {
                runs.add(self.inside[y * self.width + x], 1);
            }
            runs.add(false, height - y0 - self.height);
        }
        runs.add(false, (width - x0 - self.width) * height);
        runs.counts.push(runs.length);
        runs.counts
    }

    /// One closed polygon, `[x0, y0, x1, y1, …]` in pixel corners, whose even-odd fill is the
    /// mask: every loop of the mask's outline (outer edges and holes' edges alike) joined to
    /// the first by a bridge walked there and back, so that the bridges fill nothing. `None`
    /// for an empty mask.
    pub fn polygon(&self) -> Option<Vec<f64>> {
        let loops = self.outline();
        let first = loops.first()?;
        let start = first[0];
        let mut path: Vec<(i64, i64)> = first.clone();
        path.push(start);
        for l in &loops[1..] {
            path.extend(l);
            path.push(l[0]);
            path.push(start);
        }
        // the path returns to its start, which the polygon closes by itself
        path.pop();
        Some(
            path.iter()
                .flat_map(|&(x, y)| [x as f64, y as f64])
                .collect(),
        )
    }

    /// The loops of the mask's outline: each edge between a pixel inside and one outside
    /// exactly once, walked with the inside on the left (so holes turn the other way), only
    /// the corners where the outline turns kept.
    fn outline(&self) -> Vec<Vec<(i64, i64)>> {
        // each directed edge from its start corner; a corner starts at most two
        let corners = (self.width + 1) * (self.height + 1);
        let index = |(x, y): (i64, i64)| y as usize * (self.width + 1) + x as usize;
        let mut out: Vec<[Option<(i64, i64)>; 2]> = vec![[None; 2]; corners];
        let mut add = |from: (i64, i64), to: (i64, i64)| {
            let slot = &mut out[index(from)];
            if slot[0].is_none() {
                slot[0] = Some(to);
            } else {
                slot[1] = Some(to);
            }
        };
        for y in 0..self.height as i64 {
            for x in 0..self.width as i64 {
                if !self.at(x, y) {
                    continue;
                }
                // the pixel spans (x, y)..(x + 1, y + 1); image y points down, so inside on
                // the left is clockwise on the page
                if !self.at(x, y - 1) {
                    add((x + 1, y), (x, y));
                }
                if !self.at(x - 1, y) {
                    add((x, y), (x, y + 1));
                }
                if !self.at(x, y + 1) {
                    add((x, y + 1), (x + 1, y + 1));
                }
                if !self.at(x + 1, y) {
                    add((x + 1, y + 1), (x + 1, y));
                }
            }
        }
        let mut loops = Vec::new();
        for start in 0..corners {
            while let Some(first) = take(&mut out[start]) {
                let origin = (
                    (start % (self.width + 1)) as i64,
                    (start / (self.width + 1)) as i64,
                );
                let mut corners = vec![origin];
                let mut at = first;
                while at != origin {
                    let next =
                        take(&mut out[index(at)]).expect("an outline's edges close into loops");
                    corners.push(at);
                    at = next;
                }
                loops.push(turns(&corners));
            }
        }
        loops
    }
}

/// Run lengths being counted: the runs closed, and the open one's value and length.
#[derive(Default)]
struct Runs {
    counts: Vec<u32>,
    value: bool,
    length: u32,
}

impl Runs {
    /// `n` more pixels of `value`.
    fn add(&mut self, value: bool, n: usize) {
        if n == 0 {
            return;
        }
        if value != self.value {
            self.counts.push(self.length);
            (self.value, self.length) = (value, 0);
        }
        self.length += n as u32;
    }
}

/// Takes one of a corner's edges, if it has any left. Any will do: every corner of an outline
/// starts as many edges as end there, so a walk can only end where it began.
fn take(slot: &mut [Option<(i64, i64)>; 2]) -> Option<(i64, i64)> {
    slot[0].take().or_else(|| slot[1].take())
}

/// The corners of a closed loop where it turns.
fn turns(corners: &[(i64, i64)]) -> Vec<(i64, i64)> {
    let n = corners.len();
    (0..n)
        .filter(|&i| {
            let (p, c, q) = (corners[(i + n - 1) % n], corners[i], corners[(i + 1) % n]);
            (c.0 - p.0, c.1 - p.1) != (q.0 - c.0, q.1 - c.1)
        })
        .map(|i| corners[i])
        .collect()
}

/// Run lengths as pycocotools compresses them (`rleToString`): each run less the run two
/// before it (from the third on), in little-endian groups of five bits, a sixth bit set while
/// more follow, each group offset by 48 into printable ASCII.
pub fn compressed(runs: &[u32]) -> String {
    let mut s = String::new();
    for (i, &run) in runs.iter().enumerate() {
        let mut x = i64::from(run) - if i > 2 { i64::from(runs[i - 2]) } else { 0 };
        loop {
            let mut c = x & 0x1f;
            x >>= 5;
            let more = if c & 0x10 != 0 { x != -1 } else { x != 0 };
            if more {
                c |= 0x20;
            }
            s.push(char::from(b'0' + c as u8));
            if !more {
                break;
            }
        }
    }
    s
}
