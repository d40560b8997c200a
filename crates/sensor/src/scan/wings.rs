//! Edge wings: the camera's blur mixes each pixel's neighbours' stripes into its own, and near
//! a depth jump or a shadow the pixel decodes a column between theirs (see
//! [`Wings`](crate::noise::Wings)).

use std::ops::Range;

use rayon::prelude::*;

use super::cast::Capture;
use super::decode::{Light, decode};
use super::{Pixel, Scan, Window, gaussian, reach};

/// How far depths may bend (second differences, relative to the depth) within the blur before
/// a pixel is decoded anew: below it, the stripes' phases vary as on a plane, whose blurred
/// stripes decode to the pixel's own column.
const JUMP: f32 = 2e-3;

/// How far the signal may step between neighbours before the pixels within the blur are decoded
/// anew: beyond it, the brighter side's stripes pull the darker side's phase (Zivid's contrast
/// distortion), where the stripes' phase runs across the step.
const STEP: f32 = 2.5;

/// Counts over a grid's windows in constant time: the summed-area table of a 0/1 mask.
struct Counts {
    width: usize,
    sums: Vec<u32>,
}

impl Counts {
    /// The table of `mask`, `width` wide: each row's running sums (in parallel), then each row
    /// added to the one below.
    fn new(mask: &[bool], width: usize) -> Counts {
        let w1 = width + 1;
        let mut sums = vec![0u32; w1 * (mask.len() / width + 1)];
        sums[w1..]
            .par_chunks_mut(w1)
            .zip(mask.par_chunks(width))
            .for_each(|(row, cells)| {
                for (c, &set) in cells.iter().enumerate() {
                    row[c + 1] = row[c] + u32::from(set);
                }
            });
        for r in 1..sums.len() / w1 {
            let (above, here) = sums[(r - 1) * w1..(r + 1) * w1].split_at_mut(w1);
            for (h, a) in here.iter_mut().zip(above.iter()) {
                *h += a;
            }
        }
        Counts { width, sums }
    }

    /// How many of the mask's cells in `rows` × `cols` are set.
    fn within(&self, rows: &Range<usize>, cols: &Range<usize>) -> u32 {
        let at = |r: usize, c: usize| self.sums[r * (self.width + 1) + c];
        at(rows.end, cols.end) + at(rows.start, cols.start)
            - at(rows.start, cols.end)
            - at(rows.end, cols.start)
    }
}

/// Decodes anew every pixel of `window` (the pixels cast) whose blur reaches light and a dark
/// pixel, a bend of the depths or a step of the signal.
pub(super) fn wings(scan: &mut Scan, window: &Window, setup: &Capture) {
    let sensor = setup.sensor;
    let Some(stripes) = &setup.stripes else {
        return;
    };
    let noise = &sensor.noise;
    let (psf, radius) = (noise.wings.psf_px, noise.wings.radius());
    let (stride, c0, w, h) = (
        scan.width as usize,
        window.cols.start,
        window.cols.len(),
        window.rows.len(),
    );
    // the window's pixel (row, column) in the scan
    let index = |r: usize, c: usize| (window.rows.start + r) * stride + c0 + c;
    let pixels = &scan.pixels;
    let reach = |at: usize, len: usize| reach(at, radius, len);
    // the depth of each pixel whose surface the pattern lights (NaN for the dark: a shadow, or
    // no surface), whether it has a point, and its signal
    let mut depth = vec![f32::NAN; h * w];
    let mut valid = vec![false; h * w];
    let mut signal = vec![0.0; h * w];
    depth
        .par_chunks_mut(w)
        .zip(valid.par_chunks_mut(w))
        .zip(signal.par_chunks_mut(w))
        .enumerate()
        .for_each(|(r, ((depth, valid), signal))| {
            let row = &pixels[index(r, 0)..index(r, 0) + w];
            for (c, p) in row.iter().enumerate() {
                if p.intensity > 0.0 {
                    (depth[c], valid[c], signal[c]) = (p.clean.z, p.is_valid(), p.intensity);
                }
            }
        });
    let lit = Counts::new(&grid(h, w, |r, c| !depth[r * w + c].is_nan()), w);
    // where the depths bend (second differences), and where the signal steps, along a row or
    // a column
    let bend = |r: usize, c: usize| {
        let (i, z) = (r * w + c, depth[r * w + c]);
        let bends = |a: f32, b: f32| (a + b - 2.0 * z).abs() > JUMP * z;
        (c > 0 && c + 1 < w && bends(depth[i - 1], depth[i + 1]))
            || (r > 0 && r + 1 < h && bends(depth[i - w], depth[i + w]))
    };
    // a saturated pixel is a highlight's core: its light, far brighter than its neighbours',
    // bleeds into them however smoothly its lobe falls off
    let step = |r: usize, c: usize| {
        let i = r * w + c;
        let steps = |j: usize| {
            let (a, b) = (signal[i], signal[j]);
            a > 0.0 && b > 0.0 && a.max(b) > STEP * a.min(b)
        };
        noise.specular.saturates(signal[i])
            || (c > 0 && c + 1 < w && steps(i + 1))
            || (r > 0 && r + 1 < h && steps(i + w))
    };
    let bends = Counts::new(&grid(h, w, |r, c| bend(r, c) || step(r, c)), w);
    // with Zivid's contrast-distortion filters, the pixels pulled by steps of brightness alone
    // are told apart: no dark pixel and no bend of the depths within reach
    let contrast = sensor.processing.filters.experimental.contrast_distortion;
    let depth_bends = contrast.is_on().then(|| Counts::new(&grid(h, w, bend), w));
    let pulled = |r: usize, c: usize| {
        let (rs, cs) = (reach(r, h), reach(c, w));
        depth_bends.as_ref().is_some_and(|bends| {
            lit.within(&rs, &cs) == (rs.len() * cs.len()) as u32 && bends.within(&rs, &cs) == 0
        })
    };
    // the pixels the blur changes, of those with a point and the dark (a lit pixel the sensor
    // lost keeps its loss): light within reach, and a dark pixel within reach (the image's edge
    // is not an edge of the scene: the lens images what lies beyond it) or a bend (on a plane,
    // the blurred stripes decode to the pixel's own column)
    let changed = grid(h, w, |r, c| {
        if !(valid[r * w + c] || depth[r * w + c].is_nan()) {
            return false;
        }
        let (rs, cs) = (reach(r, h), reach(c, w));
        let lit = lit.within(&rs, &cs);
        lit > 0 && (lit < (rs.len() * cs.len()) as u32 || bends.within(&rs, &cs) > 0)
    });
    // the pixels whose light a changed pixel receives are those within reach of one
    let sinks = Counts::new(&changed, w);
    // the blur's weights along a row or a column, normalised over the whole window
    let taps = gaussian(psf, radius);
    let total: f32 = taps.iter().sum();
    let taps: Vec<f32> = taps.iter().map(|t| t / total).collect();
    // the changed pixels decoded, a band of rows at a time, read from the scan as it was
    // (with the light of the pixels within reach); then written
    const BAND: usize = 32;
    let decoded: Vec<Vec<(usize, Pixel)>> = (0..h.div_ceil(BAND))
        .into_par_iter()
        .map(|band| {
            let band_rows = band * BAND..((band + 1) * BAND).min(h);
            let in_band = &changed[band_rows.start * w..band_rows.end * w];
            let count = in_band.iter().filter(|&&c| c).count();
            if count == 0 {
                return Vec::new();
            }
            let first = band_rows.start.saturating_sub(radius);
            // (collected from a product of ranges, whose length an iterator does not know:
            // grown in one step)
            let rows = first..(band_rows.end + radius).min(h);
            let mut lights = Vec::with_capacity(rows.len() * w);
            lights.extend(
                rows.flat_map(|r| (0..w).map(move |c| (r, c)))
                    .map(|(r, c)| {
                        let p = &pixels[index(r, c)];
                        if p.intensity > 0.0 && sinks.within(&reach(r, h), &reach(c, w)) > 0 {
                            let column = stripes.frustum.column(p.clean);
                            Light::new(p.intensity, p.snr, column, [1.0; 3], stripes, &noise.snr)
                        } else {
                            Light::default()
                        }
                    }),
            );
            let mut out = Vec::with_capacity(count);
            for r in band_rows {
                for c in (0..w).filter(|&c| changed[r * w + c]) {
                    let mut sum = Light::default();
                    for rr in reach(r, h) {
                        let wr = taps[rr + radius - r];
                        let line = &lights[(rr - first) * w..(rr - first + 1) * w];
                        for (cc, l) in reach(c, w).zip(&line[reach(c, w)]) {
                            sum.add(l, wr * taps[cc + radius - c]);
                        }
                    }
                    // the neighbour whose light dominates, for a pixel without a point of its
                    // own (its labels where it sees no surface, its colour)
                    let strongest = if !pixels[index(r, c)].is_valid() {
                        let weighted = |&(rr, cc): &(usize, usize)| {
                            taps[rr + radius - r]
                                * taps[cc + radius - c]
                                * lights[(rr - first) * w + cc].amplitude
                        };
                        reach(r, h)
                            .flat_map(|rr| reach(c, w).map(move |cc| (rr, cc)))
                            .max_by(|a, b| weighted(a).total_cmp(&weighted(b)))
                            .unwrap_or((r, c))
                    } else {
                        (r, c)
                    };
                    let (i, at) = (index(r, c), [c0 + c, window.rows.start + r]);
                    let other = &pixels[index(strongest.0, strongest.1)];
                    let px = &pixels[i];
                    let decoded = decode(setup, stripes, &sum, at, px, other, pulled(r, c));
                    out.push((i, decoded));
                }
            }
            out
        })
        .collect();
    // written band by band, in parallel: a band's pixels lie in its own rows
    let first = window.rows.start * stride;
    scan.pixels[first..]
        .par_chunks_mut(BAND * stride)
        .zip(decoded)
        .enumerate()
        .for_each(|(band, (rows, out))| {
            let base = first + band * BAND * stride;
            for (i, px) in out {
                rows[i - base] = px;
            }
        });
}

/// `f` of every cell (row, column) of an `h`×`w` grid, row by row.
fn grid(h: usize, w: usize, f: impl Fn(usize, usize) -> bool + Sync) -> Vec<bool> {
    let mut out = vec![false; h * w];
    out.par_chunks_mut(w).enumerate().for_each(|(r, line)| {
        for (c, v) in line.iter_mut().enumerate() {
            *v = f(r, c);
        }
    });
    out
}
