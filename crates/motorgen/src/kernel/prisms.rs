//! Unions of plates along z (2.5D solids), meshed as closed shells that share nothing.
//!
//! A plate is a planar region (the union of some polygons less the union of others) over an
//! interval of z, less cuts that take shapes away over other intervals. The union of the plates
//! is meshed without any 3D boolean: every outline goes into one planar arrangement,
//! snap-rounded onto an integer grid (each crossing rounded to its grid point, each edge routed
//! through every grid point whose pixel it passes, so that no two edges cross); each face of
//! the arrangement gets the intervals of z that the plates fill over it (winding numbers carried
//! across its edges); the mesh is each face's caps at its intervals' ends and, on each edge,
//! walls where the intervals on its two sides differ. Walls meeting at a vertex are split at
//! every height any of them ends at, so that no vertex lies inside another triangle's edge.

use std::borrow::Cow;

use glam::{I64Vec2, IVec2, Vec2, Vec3};

use super::mesh::Mesh;

/// How far a solid reaches into another that it would only touch along an edge (grid steps).
const TOUCH: i32 = 4;

/// Edges shorter than this (grid steps) split the walls at their two ends at the same heights.
const SHORT: i64 = 512;

/// A polygon given to [`Prisms::shape`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape(u32);

/// A plate given to [`Prisms::plate`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlateId(u32);

/// Plates along z and the cuts from them; [`Prisms::mesh`] meshes their union.
#[derive(Clone, Debug)]
pub struct Prisms {
    /// Grid step, in the input's units.
    step: f32,
    /// Simple polygons on the grid, counter-clockwise.
    shapes: Vec<Vec<IVec2>>,
    plates: Vec<Plate>,
    /// Shapes taken from every plate over a range of z (grid units).
    cuts: Vec<(u32, i32, i32)>,
}

#[derive(Clone, Debug)]
struct Plate {
    add: Vec<u32>,
    /// Shapes taken away over a range of z (grid units).
    sub: Vec<(u32, i32, i32)>,
    z: [i32; 2],
}

impl Prisms {
    /// An empty union whose coordinates are rounded to multiples of `step`.
    pub fn new(step: f32) -> Prisms {
        Prisms {
            step,
            shapes: Vec::new(),
            plates: Vec::new(),
            cuts: Vec::new(),
        }
    }

    fn grid(&self, x: f32) -> i32 {
        (x / self.step).round() as i32
    }

    /// A simple polygon (either winding) to build plates and cuts of.
    pub fn shape(&mut self, polygon: &[Vec2]) -> Shape {
        let mut p: Vec<IVec2> = Vec::with_capacity(polygon.len());
        for q in polygon {
            let q = IVec2::new(self.grid(q.x), self.grid(q.y));
            if p.last() != Some(&q) {
                p.push(q);
            }
        }
        while p.len() > 1 && p.first() == p.last() {
            p.pop();
        }
        if area2(&p) < 0 {
            p.reverse();
        }
        self.shapes.push(p);
        Shape(self.shapes.len() as u32 - 1)
    }

    /// A plate: the union of `add` less the union of `sub`, from `z0` to `z1`.
    pub fn plate(&mut self, add: &[Shape], sub: &[Shape], z0: f32, z1: f32) -> PlateId {
        let z = [self.grid(z0.min(z1)), self.grid(z0.max(z1))];
        self.plates.push(Plate {
            add: add.iter().map(|s| s.0).collect(),
            sub: sub.iter().map(|s| (s.0, z[0], z[1])).collect(),
            z,
        });
        PlateId(self.plates.len() as u32 - 1)
    }

    /// Takes `shape` from plate `plate` from `z0` to `z1`.
    pub fn cut_plate(&mut self, plate: PlateId, shape: Shape, z0: f32, z1: f32) {
        let z = (self.grid(z0.min(z1)), self.grid(z0.max(z1)));
        self.plates[plate.0 as usize].sub.push((shape.0, z.0, z.1));
    }

    /// Takes `shape` from every plate from `z0` to `z1`.
    pub fn cut(&mut self, shape: Shape, z0: f32, z1: f32) {
        let z = (self.grid(z0.min(z1)), self.grid(z0.max(z1)));
        self.cuts.push((shape.0, z.0, z.1));
    }

    /// The union of the plates: closed, outward shells that share no vertex, edge or face.
    ///
    /// Where solids touch along a vertical line only (corners meeting within a grid step), a
    /// bridge a few grid steps wide joins them there (see `Arrangement::bridges`), so that
    /// every edge has two triangles.
    pub fn mesh(&self) -> Mesh {
        let mut shapes = Cow::Borrowed(&self.shapes);
        let mut bridges: Vec<(u32, i32, i32)> = Vec::new();
        loop {
            let arrangement = Arrangement::new(&shapes);
            let mut spans = arrangement.spans(|inside| self.spans(inside));
            arrangement.absorb_slivers(&mut spans);
            arrangement.overlap_touches(&mut spans);
            // the bridges last (a bridge is thin: no sliver to be absorbed)
            if !bridges.is_empty() {
                let over = arrangement.spans(|inside| {
                    bridges
                        .iter()
                        .filter(|b| inside(b.0))
                        .map(|b| [b.1, b.2])
                        .collect()
                });
                for (s, o) in spans.iter_mut().zip(over) {
                    if !o.is_empty() {
                        s.extend(o);
                        *s = merged(std::mem::take(s));
                    }
                }
            }
            let more = arrangement.bridges(&spans);
            if more.is_empty() || bridges.len() > 64 {
                return arrangement.mesh(&spans, self.step);
            }
            for (triangle, z0, z1) in more {
                shapes.to_mut().push(triangle);
                bridges.push((shapes.len() as u32 - 1, z0, z1));
            }
        }
    }

    /// The intervals of z (grid units, sorted, apart) the plates fill over a face inside the
    /// shapes for which `inside` holds.
    fn spans(&self, inside: impl Fn(u32) -> bool) -> Vec<[i32; 2]> {
        let mut out: Vec<[i32; 2]> = Vec::new();
        for p in &self.plates {
            if !p.add.iter().any(|&s| inside(s)) {
                continue;
            }
            let mut pieces = vec![p.z];
            for &(s, z0, z1) in p.sub.iter().chain(&self.cuts) {
                if inside(s) {
                    pieces = pieces
                        .into_iter()
                        .flat_map(|[a, b]| [[a, b.min(z0)], [a.max(z1), b]])
                        .filter(|[a, b]| a < b)
                        .collect();
                }
            }
            out.extend(pieces);
        }
        merged(out)
    }
}

/// The intervals sorted, those that meet or overlap made one.
fn merged(mut intervals: Vec<[i32; 2]>) -> Vec<[i32; 2]> {
    intervals.sort_unstable();
    let mut out: Vec<[i32; 2]> = Vec::with_capacity(intervals.len());
    for [a, b] in intervals {
        match out.last_mut() {
            Some(last) if a <= last[1] => last[1] = last[1].max(b),
            _ => out.push([a, b]),
        }
    }
    out
}

/// The root of `v`'s set in the union-find forest `root` (halving the path on the way).
fn find(root: &mut [u32], mut v: u32) -> u32 {
    while root[v as usize] != v {
        root[v as usize] = root[root[v as usize] as usize];
        v = root[v as usize];
    }
    v
}

/// Joins the sets of `a` and `b` in the union-find forest `root` (the smaller root leads).
fn join(root: &mut [u32], a: u32, b: u32) {
    let (a, b) = (find(root, a), find(root, b));
    root[a.max(b) as usize] = a.min(b);
}

/// Sorts `v[from..]` and drops repeats from it.
fn sort_dedup(v: &mut Vec<i32>, from: usize) {
    v[from..].sort_unstable();
    let mut kept = from;
    for i in from..v.len() {
        if i == from || v[i] != v[kept - 1] {
            v[kept] = v[i];
            kept += 1;
        }
    }
    v.truncate(kept);
}

/// Whether the point `q2` (doubled coordinates) lies inside the polygon `poly` (crossing count).
fn inside_doubled(poly: &[IVec2], q2: IVec2) -> bool {
    let q = q2.as_i64vec2();
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (
            (2 * poly[i]).as_i64vec2(),
            (2 * poly[(i + 1) % poly.len()]).as_i64vec2(),
        );
        if (a.y > q.y) != (b.y > q.y) {
            // x of the edge at q.y, against q.x: (b.x - a.x)(q.y - a.y) / (b.y - a.y) + a.x > q.x
            let lhs = (b.x - a.x) as i128 * (q.y - a.y) as i128;
            let rhs = (q.x - a.x) as i128 * (b.y - a.y) as i128;
            if (b.y > a.y && lhs > rhs) || (b.y < a.y && lhs < rhs) {
                inside = !inside;
            }
        }
    }
    inside
}

/// Twice the signed area of a polygon on the grid.
fn area2(p: &[IVec2]) -> i64 {
    (0..p.len())
        .map(|i| cross(p[i].as_i64vec2(), p[(i + 1) % p.len()].as_i64vec2()))
        .sum()
}

fn cross(a: I64Vec2, b: I64Vec2) -> i64 {
    a.x * b.y - a.y * b.x
}

/// Sign of the turn a → b → c.
fn orient(a: IVec2, b: IVec2, c: IVec2) -> i64 {
    cross((b - a).as_i64vec2(), (c - a).as_i64vec2()).signum()
}

/// `n / d` rounded to the nearest integer (halves up), `d` ≠ 0.
fn div_round(n: i128, d: i128) -> i128 {
    let (n, d) = if d < 0 { (-n, -d) } else { (n, d) };
    (2 * n + d).div_euclid(2 * d)
}

/// The grid point nearest the crossing of segments `a0 a1` and `b0 b1` when they cross at a
/// point inside both (not at an end of either).
fn crossing(a0: IVec2, a1: IVec2, b0: IVec2, b1: IVec2) -> Option<IVec2> {
    let (o1, o2) = (orient(a0, a1, b0), orient(a0, a1, b1));
    let (o3, o4) = (orient(b0, b1, a0), orient(b0, b1, a1));
    if o1 * o2 >= 0 || o3 * o4 >= 0 {
        return None;
    }
    let (da, db) = ((a1 - a0).as_i64vec2(), (b1 - b0).as_i64vec2());
    let den = cross(da, db) as i128;
    let num = cross((b0 - a0).as_i64vec2(), db) as i128;
    let x = a0.x as i128 + div_round(da.x as i128 * num, den);
    let y = a0.y as i128 + div_round(da.y as i128 * num, den);
    Some(IVec2::new(x as i32, y as i32))
}

/// Whether the segment `a b` meets the half-open pixel [h - ½, h + ½)² of grid point `h`.
fn meets_pixel(a: IVec2, b: IVec2, h: IVec2) -> bool {
    // doubled coordinates: the pixel's sides lie on odd numbers
    let (a, d) = ((2 * a).as_i64vec2(), (2 * (b - a)).as_i64vec2());
    let (lo, hi) = ((2 * h - 1).as_i64vec2(), (2 * h + 1).as_i64vec2());
    // the parameter interval [t0, t1] of the segment inside the closed pixel, as fractions
    // (numerator, positive denominator), by Liang and Barsky
    let mut t0 = (0i64, 1i64);
    let mut t1 = (1i64, 1i64);
    let less = |p: (i64, i64), q: (i64, i64)| {
        (p.0 as i128) * (q.1 as i128) < (q.0 as i128) * (p.1 as i128)
    };
    for (a, d, lo, hi) in [(a.x, d.x, lo.x, hi.x), (a.y, d.y, lo.y, hi.y)] {
        if d == 0 {
            if a < lo || a >= hi {
                // outside, or on the open side
                return false;
            }
            continue;
        }
        let (mut enter, mut leave) = ((lo - a, d), (hi - a, d));
        if d < 0 {
            enter = (-(hi - a), -d);
            leave = (-(lo - a), -d);
        }
        if less(t0, enter) {
            t0 = enter;
        }
        if less(leave, t1) {
            t1 = leave;
        }
    }
    if less(t1, t0) {
        return false;
    }
    if less(t0, t1) {
        return true;
    }
    // a single point: it must lie off the open sides
    let at = |a: i64, d: i64| (a as i128) * (t0.1 as i128) + (d as i128) * (t0.0 as i128);
    at(a.x, d.x) < (hi.x as i128) * (t0.1 as i128) && at(a.y, d.y) < (hi.y as i128) * (t0.1 as i128)
}

/// Sorts direction vectors counter-clockwise by angle from +x.
fn angle_order(a: IVec2, b: IVec2) -> std::cmp::Ordering {
    let half = |v: IVec2| v.y < 0 || (v.y == 0 && v.x < 0);
    half(a)
        .cmp(&half(b))
        .then_with(|| 0.cmp(&cross(a.as_i64vec2(), b.as_i64vec2())))
}

/// A uniform grid of square cells over a set of points, to find what lies near a segment.
struct Cells {
    origin: IVec2,
    /// Cell width, in grid steps: a power of two, 2^`shift`.
    size: i32,
    shift: i32,
    /// Cells across and up.
    n: IVec2,
}

/// Items in cells: those of cell `c` are `items[start[c]..start[c + 1]]`.
struct Bins {
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Cells {
    /// Cells over the bounding box of `points`, about as many as points, at most 64 × 64.
    fn new(points: &[IVec2]) -> Cells {
        let (lo, hi) = points
            .iter()
            .fold((IVec2::MAX, IVec2::MIN), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let extent = (hi - lo).max(IVec2::ONE).as_i64vec2();
        let per_side = ((points.len() as f64).sqrt().ceil() as i64).clamp(1, 64);
        let size = ((extent.x.max(extent.y) + per_side - 1) / per_side).max(16) as u32;
        let shift = size.next_power_of_two().trailing_zeros() as i32;
        let size = 1 << shift;
        // a cell's margin of one grid step round the box, for what lies on its edges
        let origin = lo - 1;
        let n = ((hi + 1 - origin) >> shift) + 1;
        Cells {
            origin,
            size,
            shift,
            n,
        }
    }

    /// The cell holding `p` (clamped into the grid).
    fn cell(&self, p: IVec2) -> IVec2 {
        ((p - self.origin) >> self.shift).clamp(IVec2::ZERO, self.n - 1)
    }

    fn index(&self, p: IVec2) -> usize {
        let c = self.cell(p);
        (c.y * self.n.x + c.x) as usize
    }

    /// Calls `f` with each cell that the segment `a b`, widened by `margin` grid steps, may
    /// meet.
    fn along(&self, a: IVec2, b: IVec2, margin: i32, mut f: impl FnMut(usize)) {
        let (lo, hi) = (self.cell(a.min(b) - margin), self.cell(a.max(b) + margin));
        if lo.x == hi.x {
            for cy in lo.y..=hi.y {
                f((cy * self.n.x + lo.x) as usize);
            }
            return;
        }
        let d = (b - a).as_i64vec2();
        for cx in lo.x..=hi.x {
            // the segment's y-range within this column of cells (and the margin round it)
            let (x0, x1) = (
                (self.origin.x + cx * self.size - margin).max(a.x.min(b.x)),
                (self.origin.x + (cx + 1) * self.size + margin).min(a.x.max(b.x)),
            );
            let (mut y0, mut y1) = (a.y.min(b.y), a.y.max(b.y));
            if d.x != 0 && x0 <= x1 {
                let y_at = |x: i32| a.y as i64 + (x - a.x) as i64 * d.y / d.x;
                let (ya, yb) = (y_at(x0), y_at(x1));
                y0 = (ya.min(yb) - 1) as i32;
                y1 = (ya.max(yb) + 1) as i32;
            }
            let (c0, c1) = (
                self.cell(IVec2::new(0, y0 - margin)).y.max(lo.y),
                self.cell(IVec2::new(0, y1 + margin)).y.min(hi.y),
            );
            for cy in c0..=c1 {
                f((cy * self.n.x + cx) as usize);
            }
        }
    }

    /// The segments `s` binned by the cells they may meet.
    fn bin(&self, s: impl Iterator<Item = (IVec2, IVec2)> + Clone) -> Bins {
        let mut start = vec![0u32; (self.n.x * self.n.y) as usize + 1];
        for (a, b) in s.clone() {
            self.along(a, b, 1, |c| start[c + 1] += 1);
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; *start.last().expect("one cell") as usize];
        for (k, (a, b)) in s.enumerate() {
            self.along(a, b, 1, |c| {
                items[fill[c] as usize] = k as u32;
                fill[c] += 1;
            });
        }
        Bins { start, items }
    }

    /// The points binned by the cell that holds each.
    fn bin_points(&self, points: &[IVec2]) -> Bins {
        let mut start = vec![0u32; (self.n.x * self.n.y) as usize + 1];
        for &p in points {
            start[self.index(p) + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; points.len()];
        for (k, &p) in points.iter().enumerate() {
            let c = self.index(p);
            items[fill[c] as usize] = k as u32;
            fill[c] += 1;
        }
        Bins { start, items }
    }
}

/// An outline segment: its ends and its shape.
type Segment = (IVec2, IVec2, u32);

/// An edge piece of a routed segment: its ends (points, the smaller first), its shape and +1
/// when the shape runs from the first to the second, -1 the other way.
type Piece = (u32, u32, u32, i32);

/// The hot grid points, sorted: the `corners` and the rounded crossings of the segments.
fn hot_points(segments: &[Segment], mut points: Vec<IVec2>, cells: &Cells) -> Vec<IVec2> {
    let bins = cells.bin(segments.iter().map(|s| (s.0, s.1)));
    let boxes: Vec<[IVec2; 2]> = segments
        .iter()
        .map(|s| [s.0.min(s.1), s.0.max(s.1)])
        .collect();
    // a cell's segments by the left of their boxes: each one meets only those after it that
    // start left of its right end
    let mut bin: Vec<u32> = Vec::new();
    for c in 0..bins.start.len() - 1 {
        bin.clear();
        bin.extend_from_slice(&bins.items[bins.start[c] as usize..bins.start[c + 1] as usize]);
        bin.sort_unstable_by_key(|&i| boxes[i as usize][0].x);
        for (k, &i) in bin.iter().enumerate() {
            let (a0, a1, _) = segments[i as usize];
            let [alo, ahi] = boxes[i as usize];
            for &j in &bin[k + 1..] {
                let [blo, bhi] = boxes[j as usize];
                if blo.x > ahi.x {
                    break;
                }
                if blo.y > ahi.y || alo.y > bhi.y {
                    continue;
                }
                let (b0, b1, _) = segments[j as usize];
                // each crossing once: in its own cell
                if let Some(p) = crossing(a0, a1, b0, b1)
                    && cells.index(p) == c
                {
                    points.push(p);
                }
            }
        }
    }
    points.sort_unstable_by_key(|p| (p.x, p.y));
    points.dedup();
    points
}

/// Each segment routed through the hot points whose pixels it meets, as pieces.
fn route(segments: &[Segment], points: &[IVec2], cells: &Cells) -> Vec<Piece> {
    let bins = cells.bin_points(points);
    // the hot points among `near` other than `ends` whose pixels the segment a b meets, in
    // order along it
    let through = |a: IVec2, b: IVec2, ends: [u32; 2], near: &[u32], out: &mut Vec<(i64, u32)>| {
        out.clear();
        let d = (b - a).as_i64vec2();
        // a pixel the segment meets has its centre within half a pixel's width across
        let reach = d.x.abs() + d.y.abs();
        for &k in near {
            let h = points[k as usize];
            let off = (h - a).as_i64vec2();
            if !ends.contains(&k) && 2 * cross(d, off).abs() <= reach && meets_pixel(a, b, h) {
                out.push((off.dot(d), k));
            }
        }
        out.sort_unstable();
        out.dedup_by_key(|r| r.1);
    };
    let id = |p: IVec2| {
        points
            .binary_search_by_key(&(p.x, p.y), |q| (q.x, q.y))
            .expect("a hot point") as u32
    };
    let mut pieces: Vec<Piece> = Vec::new();
    let mut found: Vec<(i64, u32)> = Vec::new();
    let mut near: Vec<u32> = Vec::new();
    // the route so far, from its end back: each stretch is routed anew through the points its
    // own pixels meet, until none does (iterated snap rounding: no point lies within half a
    // grid step of an edge it does not end)
    let mut todo: Vec<u32> = Vec::new();
    for &(a, b, s) in segments {
        let (ia, ib) = (id(a), id(b));
        if ia == ib {
            continue;
        }
        // the hot points a few grid steps from the segment: all that its stretches may meet
        near.clear();
        let d = (b - a).as_i64vec2();
        let (lo, hi) = (a.min(b) - 4, a.max(b) + 4);
        cells.along(a, b, 4, |c| {
            near.extend(
                bins.items[bins.start[c] as usize..bins.start[c + 1] as usize]
                    .iter()
                    .filter(|&&k| {
                        let h = points[k as usize];
                        h.cmpge(lo).all()
                            && h.cmple(hi).all()
                            && (cross(d, (h - a).as_i64vec2()) as i128).pow(2)
                                <= 16 * d.length_squared() as i128
                    }),
            );
        });
        // first the hot points the segment itself meets, then each stretch between them anew
        through(a, b, [ia, ib], &near, &mut found);
        todo.clear();
        todo.push(ib);
        todo.extend(found.iter().rev().map(|f| f.1));
        let mut from = ia;
        while let Some(&to) = todo.last() {
            let (p, q) = (points[from as usize], points[to as usize]);
            through(p, q, [from, to], &near, &mut found);
            if found.is_empty() {
                todo.pop();
                if from < to {
                    pieces.push((from, to, s, 1));
                } else {
                    pieces.push((to, from, s, -1));
                }
                from = to;
            } else {
                todo.extend(found.iter().rev().map(|f| f.1));
            }
        }
    }
    pieces
}

/// Edges: their ends (points, the smaller first), and each one's winding steps per shape, as a
/// range of `steps`.
struct Edges {
    ends: Vec<[u32; 2]>,
    step_range: Vec<(u32, u32)>,
    steps: Vec<(u32, i32)>,
}

/// The edges of the pieces: their ends, and their winding steps per shape summed (as a range
/// of the steps list); edges whose steps all cancel divide nothing and go.
fn merge(mut pieces: Vec<Piece>) -> Edges {
    pieces.sort_unstable();
    let mut ends = Vec::new();
    let mut step_range = Vec::new();
    let mut steps: Vec<(u32, i32)> = Vec::new();
    let mut k = 0;
    while k < pieces.len() {
        let (p, q) = (pieces[k].0, pieces[k].1);
        let start = steps.len();
        while k < pieces.len() && (pieces[k].0, pieces[k].1) == (p, q) {
            let (s, d) = (pieces[k].2, pieces[k].3);
            match steps[start..].last_mut() {
                Some(last) if last.0 == s => last.1 += d,
                _ => steps.push((s, d)),
            }
            k += 1;
        }
        let mut kept = start;
        for i in start..steps.len() {
            if steps[i].1 != 0 {
                steps[kept] = steps[i];
                kept += 1;
            }
        }
        steps.truncate(kept);
        if kept > start {
            ends.push([p, q]);
            step_range.push((start as u32, kept as u32));
        }
    }
    Edges {
        ends,
        step_range,
        steps,
    }
}

/// The snap-rounded arrangement of the shapes' outlines: half-edges `2e` (from `ends[e][0]` to
/// `ends[e][1]`) and `2e + 1` (back), faces (0 the unbounded one) and each edge's winding
/// steps.
struct Arrangement {
    points: Vec<IVec2>,
    ends: Vec<[u32; 2]>,
    /// Per edge, its range in `steps`.
    step_range: Vec<(u32, u32)>,
    /// (shape, winding step): crossing edge e from its right to its left side adds the step to
    /// the shape's winding number.
    steps: Vec<(u32, i32)>,
    next: Vec<u32>,
    /// The face on each half-edge's left.
    face: Vec<u32>,
    /// Per face, one half-edge of each boundary cycle (the outer one first, none for face 0).
    cycles: Vec<Vec<u32>>,
    /// The half-edges out of each point, counter-clockwise (from +x when more than two):
    /// `star[star_start[v]..star_start[v + 1]]`.
    star: Vec<u32>,
    star_start: Vec<u32>,
    shapes: usize,
}

impl Arrangement {
    fn new(shapes: &[Vec<IVec2>]) -> Arrangement {
        // the outline segments, each with its shape
        let mut segments: Vec<Segment> = Vec::new();
        for (s, poly) in shapes.iter().enumerate() {
            for i in 0..poly.len() {
                segments.push((poly[i], poly[(i + 1) % poly.len()], s as u32));
            }
        }
        let corners: Vec<IVec2> = segments.iter().map(|s| s.0).collect();
        let cells = Cells::new(&corners);
        let points = hot_points(&segments, corners, &cells);
        let pieces = route(&segments, &points, &cells);
        let Edges {
            ends,
            step_range,
            steps,
        } = merge(pieces);
        let mut a = Arrangement {
            points,
            ends,
            step_range,
            steps,
            next: Vec::new(),
            face: Vec::new(),
            cycles: Vec::new(),
            star: Vec::new(),
            star_start: Vec::new(),
            shapes: shapes.len(),
        };
        a.link();
        a
    }

    fn origin(&self, h: u32) -> u32 {
        self.ends[(h / 2) as usize][(h % 2) as usize]
    }

    fn target(&self, h: u32) -> u32 {
        self.origin(h ^ 1)
    }

    fn direction(&self, h: u32) -> IVec2 {
        self.points[self.target(h) as usize] - self.points[self.origin(h) as usize]
    }

    /// Links the half-edges into face cycles and finds the faces, holes included.
    fn link(&mut self) {
        let n = self.points.len();
        let halves = 2 * self.ends.len();
        let direction: Vec<IVec2> = (0..halves as u32).map(|h| self.direction(h)).collect();
        // outgoing half-edges of each point, counter-clockwise
        let mut start = vec![0u32; n + 1];
        for h in 0..halves as u32 {
            start[self.origin(h) as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut out = vec![0u32; halves];
        for h in 0..halves as u32 {
            let o = self.origin(h) as usize;
            out[fill[o] as usize] = h;
            fill[o] += 1;
        }
        let mut position = vec![0u32; halves];
        for v in 0..n {
            let range = start[v] as usize..start[v + 1] as usize;
            if range.len() > 2 {
                out[range.clone()].sort_unstable_by(|&a, &b| {
                    angle_order(direction[a as usize], direction[b as usize])
                });
            }
            for i in range {
                position[out[i] as usize] = i as u32;
            }
        }
        // the next half-edge: out of the target, the one before the twin counter-clockwise
        self.next = (0..halves as u32)
            .map(|h| {
                let v = self.target(h) as usize;
                let (first, last) = (start[v], start[v + 1]);
                let at = position[(h ^ 1) as usize];
                out[(if at == first { last } else { at } - 1) as usize]
            })
            .collect();
        // cycles, with their signed areas
        const NONE: u32 = u32::MAX;
        let mut cycle_of = vec![NONE; halves];
        let mut cycles: Vec<(u32, i64)> = Vec::new();
        for h in 0..halves as u32 {
            if cycle_of[h as usize] != NONE {
                continue;
            }
            let c = cycles.len() as u32;
            let mut area = 0i64;
            let mut g = h;
            loop {
                cycle_of[g as usize] = c;
                let p = self.points[self.origin(g) as usize].as_i64vec2();
                area += cross(p, direction[g as usize].as_i64vec2());
                g = self.next[g as usize];
                if g == h {
                    break;
                }
            }
            cycles.push((h, area));
        }
        // connected components of the points, by edge
        let mut component: Vec<u32> = (0..n as u32).collect();
        for &[p, q] in &self.ends {
            join(&mut component, p, q);
        }
        for v in 0..n as u32 {
            component[v as usize] = find(&mut component, v);
        }
        // faces: 0 outside everything, then one per counter-clockwise cycle; a component's
        // clockwise cycle (its outside) bounds the face that holds the component: the face
        // left of the first edge met going left from it, or the face that holds that edge's
        // component when the edge is on its outside
        let mut face_of_cycle = vec![NONE; cycles.len()];
        let mut faces: Vec<Vec<u32>> = vec![Vec::new()];
        for (c, &(h, area)) in cycles.iter().enumerate() {
            if area > 0 {
                face_of_cycle[c] = faces.len() as u32;
                faces.push(vec![h]);
            }
        }
        let held_by: Vec<Option<u32>> = cycles
            .iter()
            .map(|&(h, area)| {
                if area > 0 {
                    return None;
                }
                self.left_of(h, &component, &out, &start)
                    .map(|g| cycle_of[g as usize])
            })
            .collect();
        for c in 0..cycles.len() {
            if cycles[c].1 > 0 {
                continue;
            }
            // follow outsides to the left until a face or nothing
            let mut d = c;
            let f = loop {
                if face_of_cycle[d] != NONE {
                    break face_of_cycle[d];
                }
                match held_by[d] {
                    Some(e) => d = e as usize,
                    None => break 0,
                }
            };
            face_of_cycle[c] = f;
            faces[f as usize].push(cycles[c].0);
        }
        self.face = cycle_of
            .iter()
            .map(|&c| face_of_cycle[c as usize])
            .collect();
        self.cycles = faces;
        self.star = out;
        self.star_start = start;
    }

    /// Faces narrower than a grid step (slivers between near-coincident outlines, whose caps
    /// would be needles) take the spans of the face beside their longest edge.
    fn absorb_slivers(&self, spans: &mut [Vec<[i32; 2]>]) {
        for f in 1..self.cycles.len() {
            let (mut area2, mut perimeter, mut longest) = (0i64, 0f64, (0f64, 0u32));
            for &first in &self.cycles[f] {
                let mut h = first;
                loop {
                    let (p, d) = (
                        self.points[self.origin(h) as usize].as_i64vec2(),
                        self.direction(h).as_i64vec2(),
                    );
                    area2 += cross(p, d);
                    let length = d.as_dvec2().length();
                    perimeter += length;
                    if length > longest.0 {
                        longest = (length, h);
                    }
                    h = self.next[h as usize];
                    if h == first {
                        break;
                    }
                }
            }
            // twice the area under the perimeter: narrower than a grid step on average
            if (area2 as f64) < perimeter {
                let beside = self.face[(longest.1 ^ 1) as usize] as usize;
                spans[f] = spans[beside].clone();
            }
        }
    }

    /// Where two faces side by side hold solids that meet only along their shared edge (one
    /// ends at a height where the other begins), the smaller face's solid reaches `TOUCH` grid
    /// steps into the other's, so that the edge is not shared by four triangles.
    fn overlap_touches(&self, spans: &mut [Vec<[i32; 2]>]) {
        let mut area: Vec<Option<i64>> = vec![None; spans.len()];
        let mut area_of = |f: usize| {
            *area[f].get_or_insert_with(|| {
                self.cycles[f]
                    .iter()
                    .map(|&first| {
                        let mut sum = 0i64;
                        let mut h = first;
                        loop {
                            sum += cross(
                                self.points[self.origin(h) as usize].as_i64vec2(),
                                self.direction(h).as_i64vec2(),
                            );
                            h = self.next[h as usize];
                            if h == first {
                                break sum;
                            }
                        }
                    })
                    .sum()
            })
        };
        for e in 0..self.ends.len() {
            let (l, r) = (self.face[2 * e] as usize, self.face[2 * e + 1] as usize);
            if l == 0 || r == 0 {
                continue;
            }
            for (a, b) in [(l, r), (r, l)] {
                // a's solid ends where b's begins
                let Some(h) = spans[a]
                    .iter()
                    .map(|s| s[1])
                    .find(|&h| spans[b].iter().any(|s| s[0] == h))
                else {
                    continue;
                };
                let (grow, up) = if area_of(a) <= area_of(b) {
                    (a, true)
                } else {
                    (b, false)
                };
                for s in &mut spans[grow] {
                    if up && s[1] == h {
                        s[1] += TOUCH;
                    } else if !up && s[0] == h {
                        s[0] -= TOUCH;
                    }
                }
                // grown spans that now meet are one
                spans[grow] = merged(std::mem::take(&mut spans[grow]));
            }
        }
    }

    /// Where the solid pinches (round a point, over a range of z, solid and empty faces
    /// alternate more than once: two solids meeting in a vertical line), the bridges that
    /// join them: for each such point and range, the narrowest empty wedge between solid faces
    /// filled near the point over the range both solids fill.
    fn bridges(&self, spans: &[Vec<[i32; 2]>]) -> Vec<(Vec<IVec2>, i32, i32)> {
        let mut out = Vec::new();
        let mut heights: Vec<i32> = Vec::new();
        let mut solid: Vec<bool> = Vec::new();
        for v in 0..self.points.len() {
            let star = &self.star[self.star_start[v] as usize..self.star_start[v + 1] as usize];
            if star.len() < 4 {
                continue;
            }
            heights.clear();
            for &h in star {
                heights.extend(spans[self.face[h as usize] as usize].iter().flatten());
            }
            heights.sort_unstable();
            heights.dedup();
            for w in heights.windows(2) {
                let span_over = |h: u32| {
                    spans[self.face[h as usize] as usize]
                        .iter()
                        .find(|&&[a, b]| a <= w[0] && b >= w[1])
                        .copied()
                };
                // solid[i]: the wedge from star[i] to star[i + 1], counter-clockwise
                solid.clear();
                solid.extend(star.iter().map(|&h| span_over(h).is_some()));
                let n = star.len();
                let changes = (0..n).filter(|&i| solid[i] != solid[(i + 1) % n]).count();
                if changes <= 2 {
                    continue;
                }
                // the narrowest empty wedge between solid ones
                let wedge = |i: usize| {
                    let (a, b) = (self.direction(star[i]), self.direction(star[(i + 1) % n]));
                    let (a, b) = (a.as_dvec2().normalize(), b.as_dvec2().normalize());
                    a.angle_to(b).rem_euclid(std::f64::consts::TAU)
                };
                let Some(i) = (0..n)
                    .filter(|&i| !solid[i] && solid[(i + n - 1) % n] && solid[(i + 1) % n])
                    .min_by(|&i, &j| wedge(i).total_cmp(&wedge(j)))
                else {
                    continue;
                };
                let (h0, h1) = (star[i], star[(i + 1) % n]);
                let (before, after) = (
                    span_over(star[(i + n - 1) % n]).expect("solid"),
                    span_over(h1).expect("solid"),
                );
                // the wedge filled from the point as far as it is narrow (four grid steps
                // across), along its sides: to their far ends where they end sooner, which
                // leaves no sliver beside them
                let at = self.points[v];
                let reach = 4.0 / (0.5 * wedge(i)).sin().max(1e-6);
                let polygon: Vec<IVec2> = std::iter::once(at)
                    .chain([h0, h1].map(|h| {
                        let end = self.points[self.target(h) as usize];
                        let side = (end - at).as_dvec2();
                        if side.length() <= reach {
                            end
                        } else {
                            at + (side.normalize() * reach).round().as_ivec2()
                        }
                    }))
                    .collect();
                out.push((polygon, before[0].max(after[0]), before[1].min(after[1])));
            }
        }
        out
    }

    /// The half-edge whose left side holds the outside cycle through `h` (of the component
    /// `component[origin(h)]`): the first edge of another component met going left (−x) from
    /// the cycle's lowest leftmost point, or `None` when nothing is there. `out` and `start`
    /// are the points' half-edges, counter-clockwise.
    fn left_of(&self, h: u32, component: &[u32], out: &[u32], start: &[u32]) -> Option<u32> {
        let own = component[self.origin(h) as usize];
        // the lowest leftmost point of the cycle
        let mut v = self.origin(h);
        let mut g = self.next[h as usize];
        while g != h {
            let o = self.origin(g);
            let (p, q) = (self.points[o as usize], self.points[v as usize]);
            if (p.x, p.y) < (q.x, q.y) {
                v = o;
            }
            g = self.next[g as usize];
        }
        let at = self.points[v as usize];
        // the nearest crossing left of `at` on the line y = at.y, as x (a fraction with a
        // positive denominator) and what is met there: an edge's inside or a point
        enum Met {
            Edge(u32),
            Point(u32),
        }
        let mut best: Option<((i128, i128), Met)> = None;
        let mut consider = |x: (i128, i128), met: Met| {
            if best
                .as_ref()
                .is_none_or(|((bn, bd), _)| x.0 * bd > bn * x.1)
            {
                best = Some((x, met));
            }
        };
        for (e, &[p, q]) in self.ends.iter().enumerate() {
            if component[p as usize] == own {
                continue;
            }
            let (a, b) = (self.points[p as usize], self.points[q as usize]);
            for (w, c) in [(p, a), (q, b)] {
                if c.y == at.y && c.x < at.x {
                    consider((c.x as i128, 1), Met::Point(w));
                }
            }
            // an edge across the line (not through a point on it)
            if (a.y - at.y).signum() * (b.y - at.y).signum() >= 0 {
                continue;
            }
            // x of the crossing: a.x + (at.y - a.y)(b.x - a.x)/(b.y - a.y)
            let den = (b.y - a.y) as i128;
            let num = a.x as i128 * den + (at.y - a.y) as i128 * (b.x - a.x) as i128;
            let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
            if num < at.x as i128 * den {
                // the half-edge going down has the +x side on its left
                let down = if b.y < a.y {
                    2 * e as u32
                } else {
                    2 * e as u32 + 1
                };
                consider((num, den), Met::Edge(down));
            }
        }
        match best? {
            (_, Met::Edge(g)) => Some(g),
            // the half-edge out of w last counter-clockwise (angles from +x): its left side
            // holds the direction +x
            (_, Met::Point(w)) => {
                let star = &out[start[w as usize] as usize..start[w as usize + 1] as usize];
                star.iter()
                    .copied()
                    .max_by(|&a, &b| angle_order(self.direction(a), self.direction(b)))
            }
        }
    }

    /// Each face's intervals of z: `spans(inside)` with `inside(shape)` whether the face lies
    /// inside the shape. Face 0 is empty.
    fn spans(&self, spans: impl Fn(&dyn Fn(u32) -> bool) -> Vec<[i32; 2]>) -> Vec<Vec<[i32; 2]>> {
        let faces = self.cycles.len();
        let s = self.shapes;
        let mut winding = vec![0i32; faces * s];
        let mut seen = vec![false; faces];
        let mut queue = vec![0u32];
        seen[0] = true;
        while let Some(f) = queue.pop() {
            for &first in &self.cycles[f as usize] {
                let mut h = first;
                loop {
                    let g = self.face[(h ^ 1) as usize];
                    if !seen[g as usize] {
                        seen[g as usize] = true;
                        let (from, to) = (f as usize * s, g as usize * s);
                        winding.copy_within(from..from + s, to);
                        // crossing h from its left to its right takes away the steps along h
                        let (lo, hi) = self.step_range[(h / 2) as usize];
                        let sign = if h % 2 == 0 { 1 } else { -1 };
                        for &(shape, step) in &self.steps[lo as usize..hi as usize] {
                            winding[to + shape as usize] -= sign * step;
                        }
                        queue.push(g);
                    }
                    h = self.next[h as usize];
                    if h == first {
                        break;
                    }
                }
            }
        }
        (0..faces)
            .map(|f| {
                if f == 0 {
                    return Vec::new();
                }
                let w = &winding[f * s..(f + 1) * s];
                spans(&|shape| w[shape as usize] > 0)
            })
            .collect()
    }

    /// The closed mesh of the faces' `spans`, coordinates scaled by `step`.
    fn mesh(&self, spans: &[Vec<[i32; 2]>], step: f32) -> Mesh {
        let points = &self.points;
        // heights at each point: every end of a span of a face round it or round a point
        // joined to it by edges shorter than `SHORT` (so that the walls on short edges split
        // their two sides alike, and none is a needle), sorted, one list per point
        // (`heights[start[v]..start[v + 1]]`); each (point, height) becomes a vertex when first
        // used
        let mut cluster: Vec<u32> = (0..points.len() as u32).collect();
        let mut short = false;
        for (e, &[p, q]) in self.ends.iter().enumerate() {
            if self.direction(2 * e as u32).as_i64vec2().length_squared() < SHORT * SHORT {
                join(&mut cluster, p, q);
                short = true;
            }
        }
        // each point's own heights, then each cluster's (the same list for all its points)
        let mut start = Vec::with_capacity(points.len() + 1);
        let mut heights: Vec<i32> = Vec::new();
        start.push(0u32);
        for v in 0..points.len() {
            let from = heights.len();
            for &h in &self.star[self.star_start[v] as usize..self.star_start[v + 1] as usize] {
                heights.extend(spans[self.face[h as usize] as usize].iter().flatten());
            }
            sort_dedup(&mut heights, from);
            start.push(heights.len() as u32);
        }
        if short {
            let mut shared: Vec<i32> = Vec::new();
            let mut shared_start = vec![0u32; points.len() + 1];
            let mut members: Vec<(u32, u32)> = (0..points.len() as u32)
                .map(|v| (find(&mut cluster, v), v))
                .collect();
            members.sort_unstable();
            let mut out_start = vec![0u32; points.len() + 1];
            for group in members.chunk_by(|a, b| a.0 == b.0) {
                let from = shared.len();
                for &(_, v) in group {
                    shared.extend_from_slice(
                        &heights[start[v as usize] as usize..start[v as usize + 1] as usize],
                    );
                }
                sort_dedup(&mut shared, from);
                for &(_, v) in group {
                    out_start[v as usize] = from as u32;
                    shared_start[v as usize] = shared.len() as u32;
                }
            }
            // one list per point again, in point order
            heights.clear();
            for v in 0..points.len() {
                heights.extend_from_slice(&shared[out_start[v] as usize..shared_start[v] as usize]);
                start[v + 1] = heights.len() as u32;
            }
        }
        let slot = |v: u32, z: i32| {
            let (from, to) = (start[v as usize] as usize, start[v as usize + 1] as usize);
            from + heights[from..to].partition_point(|&h| h < z)
        };
        let mut index = vec![u32::MAX; heights.len()];
        let mut m = Mesh::default();
        let mut vertex = |m: &mut Mesh, v: u32, k: usize| -> u32 {
            if index[k] == u32::MAX {
                let p = points[v as usize];
                m.positions
                    .push(Vec3::new(p.x as f32, p.y as f32, heights[k] as f32) * step);
                index[k] = m.positions.len() as u32 - 1;
            }
            index[k]
        };
        // caps: faces of the same spans that share an edge are one region, capped as one
        // polygon whose boundary is the half-edges between different spans
        let differs: Vec<bool> = (0..self.ends.len())
            .map(|e| spans[self.face[2 * e] as usize] != spans[self.face[2 * e + 1] as usize])
            .collect();
        let differ = |h: u32| differs[(h / 2) as usize];
        let mut region: Vec<u32> = (0..spans.len() as u32).collect();
        for e in 0..self.ends.len() as u32 {
            if !differ(2 * e) {
                join(
                    &mut region,
                    self.face[2 * e as usize],
                    self.face[2 * e as usize + 1],
                );
            }
        }
        // the regions' boundary cycles: (region, first half-edge, twice the signed area)
        let mut seen = vec![false; 2 * self.ends.len()];
        let mut cycles: Vec<(u32, u32, i64)> = Vec::new();
        for h in 0..2 * self.ends.len() as u32 {
            let f = self.face[h as usize];
            if seen[h as usize] || !differ(h) || spans[f as usize].is_empty() {
                continue;
            }
            let mut area = 0i64;
            let mut g = h;
            loop {
                seen[g as usize] = true;
                area += cross(
                    points[self.origin(g) as usize].as_i64vec2(),
                    points[self.target(g) as usize].as_i64vec2(),
                );
                g = self.next[g as usize];
                while !differ(g) {
                    g = self.next[(g ^ 1) as usize];
                }
                if g == h {
                    break;
                }
            }
            cycles.push((find(&mut region, f), h, area));
        }
        // by region, the outer cycle (counter-clockwise) first
        cycles.sort_unstable_by_key(|&(r, _, area)| (r, std::cmp::Reverse(area)));
        let mut earcut = earcut::int::EarcutI32::new();
        let mut refiner = earcut::Refiner::new();
        let mut face = FaceBuffers::default();
        let mut corner_vertex: Vec<u32> = Vec::new();
        // a region's boundary cycle from its first half-edge, as corners
        let corners_of = |first: u32| {
            let mut out = Vec::new();
            let mut h = first;
            loop {
                out.push(points[self.origin(h) as usize]);
                h = self.next[h as usize];
                while !differ(h) {
                    h = self.next[(h ^ 1) as usize];
                }
                if h == first {
                    break out;
                }
            }
        };
        let mut polygons: Vec<Vec<u32>> = Vec::new();
        for group in cycles.chunk_by(|a, b| a.0 == b.0) {
            let outers = group.iter().take_while(|c| c.2 > 0).count();
            if outers <= 1 {
                polygons.push(group.iter().map(|c| c.1).collect());
                continue;
            }
            // a region that touches itself at a point: a polygon per outer cycle, each hole in
            // the smallest that holds it
            let first = polygons.len();
            polygons.extend(group[..outers].iter().map(|c| vec![c.1]));
            let outer_corners: Vec<Vec<IVec2>> =
                group[..outers].iter().map(|c| corners_of(c.1)).collect();
            for hole in &group[outers..] {
                let c = corners_of(hole.1);
                // the middle of its first edge, doubled
                let q = c[0] + c[1 % c.len()];
                let holder = (0..outers)
                    .rev()
                    .find(|&k| inside_doubled(&outer_corners[k], q))
                    .unwrap_or(0);
                polygons[first + holder].push(hole.1);
            }
        }
        for polygon in &polygons {
            let f = self.face[polygon[0] as usize] as usize;
            face.clear();
            for (k, &first) in polygon.iter().enumerate() {
                if k > 0 {
                    face.holes.push(face.ids.len() as u32);
                }
                let start = face.ids.len() as u32;
                let mut h = first;
                loop {
                    let v = self.origin(h);
                    face.ids.push(v);
                    face.next.push(face.ids.len() as u32);
                    let p = points[v as usize];
                    face.xy.push([p.x, p.y]);
                    h = self.next[h as usize];
                    while !differ(h) {
                        h = self.next[(h ^ 1) as usize];
                    }
                    if h == first {
                        break;
                    }
                }
                *face.next.last_mut().expect("a cycle has corners") = start;
            }
            face.triangulate(&mut earcut, &mut refiner);
            for &[z0, z1] in &spans[f] {
                for (z, up) in [(z0, false), (z1, true)] {
                    corner_vertex.clear();
                    for &v in &face.ids {
                        corner_vertex.push(vertex(&mut m, v, slot(v, z)));
                    }
                    m.triangles.extend(face.triangles.iter().map(|t| {
                        let [a, b, c] = t.map(|k| corner_vertex[k as usize]);
                        if up { [a, b, c] } else { [a, c, b] }
                    }));
                }
            }
        }
        // walls
        let mut ranges = Vec::new();
        for (e, &[p, q]) in self.ends.iter().enumerate() {
            let (left, right) = (
                &spans[self.face[2 * e] as usize],
                &spans[self.face[2 * e + 1] as usize],
            );
            for (from, to, solid, empty) in [(p, q, left, right), (q, p, right, left)] {
                difference(solid, empty, &mut ranges);
                for &[z0, z1] in &ranges {
                    let side = |v: u32| (v, slot(v, z0), slot(v, z1));
                    wall(&mut m, &mut vertex, &heights, side(from), side(to));
                }
            }
        }
        m
    }
}

/// One face's cap in the making, its buffers kept from face to face.
#[derive(Default)]
struct FaceBuffers {
    /// Each boundary corner's point, position and successor on the boundary (local indices).
    ids: Vec<u32>,
    xy: Vec<[i32; 2]>,
    xy_f: Vec<[f64; 2]>,
    next: Vec<u32>,
    /// Where each hole's corners begin.
    holes: Vec<u32>,
    /// Ear clipping's triangles (local indices, flat).
    local: Vec<u32>,
    /// The cap's triangles (local indices, counter-clockwise).
    triangles: Vec<[u32; 3]>,
    /// The corners ear clipping sees (where the boundary turns), their positions and where
    /// each hole's begin among them.
    kept: Vec<u32>,
    kept_xy: Vec<[i32; 2]>,
    kept_holes: Vec<u32>,
    /// Ear clipping's triangles (counter-clockwise, with area); those round each corner
    /// (`round_items[round[k]..round[k + 1]]`); a run of corners to put back.
    ear_triangles: Vec<[u32; 3]>,
    round: Vec<u32>,
    round_items: Vec<u32>,
    run: Vec<u32>,
    /// The triangles' sides by point.
    point_sides: Vec<(u32, u32)>,
    /// Which corners a triangle has; corners to put back: (triangle, the side's first corner,
    /// place along the side, corner).
    used: Vec<bool>,
    inserts: Vec<(u32, u32, u32, u32)>,
    poly: Vec<u32>,
}

impl FaceBuffers {
    fn clear(&mut self) {
        self.ids.clear();
        self.xy.clear();
        self.next.clear();
        self.holes.clear();
        self.local.clear();
        self.triangles.clear();
    }

    /// Triangulates the face: ear clipping of the corners where its boundary turns, the others
    /// put back, and needles flipped away.
    fn triangulate(&mut self, earcut: &mut earcut::int::EarcutI32, refiner: &mut earcut::Refiner) {
        let p = |k: u32| IVec2::from(self.xy[k as usize]);
        // the corners where the boundary turns: ear clipping sees only these, and the others
        // go back on the sides they lie on
        self.kept.clear();
        self.kept_xy.clear();
        self.kept_holes.clear();
        let mut cycle_start = 0usize;
        for c in 0..=self.holes.len() {
            let end = self.holes.get(c).map_or(self.ids.len(), |&h| h as usize);
            if c > 0 {
                self.kept_holes.push(self.kept.len() as u32);
            }
            let n = end - cycle_start;
            for k in cycle_start..end {
                let prev = cycle_start + (k - cycle_start + n - 1) % n;
                let next = self.next[k] as usize;
                if orient(p(prev as u32), p(k as u32), p(next as u32)) != 0 {
                    self.kept.push(k as u32);
                    self.kept_xy.push(self.xy[k]);
                }
            }
            cycle_start = end;
        }
        earcut.earcut_slice(&self.kept_xy, &self.kept_holes, &mut self.local);
        for k in &mut self.local {
            *k = self.kept[*k as usize];
        }
        self.conform();
        self.flip_needles(refiner);
    }

    /// Flips away needles (triangles lower than a twentieth of a grid step over their longest
    /// side, where corners lie a hair off each other's lines): where there is one, Lawson's
    /// flips make the triangulation Delaunay, the roundest there is with these corners and
    /// this boundary.
    fn flip_needles(&mut self, refiner: &mut earcut::Refiner) {
        let p = |k: u32| IVec2::from(self.xy[k as usize]).as_i64vec2();
        let needle = |t: &[u32; 3]| {
            let [a, b, c] = t.map(p);
            let area2 = cross(b - a, c - a) as f64;
            let longest = (b - a)
                .length_squared()
                .max((c - b).length_squared())
                .max((a - c).length_squared());
            400.0 * area2 * area2 < longest as f64
        };
        if !self.triangles.iter().any(needle) {
            return;
        }
        self.local.clear();
        self.local.extend(self.triangles.iter().flatten());
        self.xy_f.clear();
        self.xy_f
            .extend(self.xy.iter().map(|p| [f64::from(p[0]), f64::from(p[1])]));
        refiner.refine(&mut self.local, &self.xy_f);
        self.triangles.clear();
        self.triangles
            .extend(self.local.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
    }

    /// The cap's triangles from ear clipping's, counter-clockwise, with the corners it did not
    /// see put back: a triangle whose side passes over them takes them as its own and is cut
    /// again.
    fn conform(&mut self) {
        let xy = &self.xy;
        let p = |k: u32| IVec2::from(xy[k as usize]);
        let ids = &self.ids;
        let ccw = |t: &[u32]| {
            if orient(p(t[0]), p(t[1]), p(t[2])) < 0 {
                [t[0], t[2], t[1]]
            } else {
                [t[0], t[1], t[2]]
            }
        };
        let flat = |t: &[u32]| orient(p(t[0]), p(t[1]), p(t[2])) == 0;
        let mut tris = std::mem::take(&mut self.ear_triangles);
        tris.clear();
        tris.extend(self.local.chunks_exact(3).filter(|t| !flat(t)).map(ccw));
        // the corners not in any triangle, each put back on the side from the corner before
        // it that is in one to the next that is (found by the triangles round that corner)
        self.used.clear();
        self.used.resize(ids.len(), false);
        for t in &tris {
            for &k in t {
                self.used[k as usize] = true;
            }
        }
        self.inserts.clear();
        let (mut runs, mut found) = (0, 0);
        if self.used.iter().any(|&u| !u) {
            self.round.clear();
            self.round.resize(ids.len() + 1, 0);
            for t in &tris {
                for &k in t {
                    self.round[k as usize + 1] += 1;
                }
            }
            for i in 0..ids.len() {
                self.round[i + 1] += self.round[i];
            }
            self.round_items.clear();
            self.round_items.resize(3 * tris.len(), 0);
            let mut fill = self.round.clone();
            for (i, t) in tris.iter().enumerate() {
                for &k in t {
                    self.round_items[fill[k as usize] as usize] = i as u32;
                    fill[k as usize] += 1;
                }
            }
            let mut run = std::mem::take(&mut self.run);
            for k in 0..ids.len() {
                if self.used[k] || !self.used[self.next[k] as usize] {
                    continue;
                }
                // k ends a run of unused corners: find where it starts
                run.clear();
                run.push(k as u32);
                let mut before = self.previous(k as u32);
                while !self.used[before as usize] && run.len() < ids.len() {
                    run.push(before);
                    before = self.previous(before);
                }
                run.reverse();
                runs += 1;
                let after = self.next[k];
                let round = &self.round_items[self.round[before as usize] as usize
                    ..self.round[before as usize + 1] as usize];
                let side = round.iter().copied().find(|&i| {
                    let t = tris[i as usize];
                    (0..3).any(|j| t[j] == before && t[(j + 1) % 3] == after)
                });
                if let Some(tri) = side {
                    found += 1;
                    self.inserts.extend(
                        run.iter()
                            .enumerate()
                            .map(|(j, &c)| (tri, before, j as u32, c)),
                    );
                }
            }
            self.run = run;
        }
        self.inserts.sort_unstable();
        let mut poly = std::mem::take(&mut self.poly);
        for (i, t) in tris.iter().enumerate() {
            let from = self.inserts.partition_point(|x| x.0 < i as u32);
            let to = self.inserts.partition_point(|x| x.0 <= i as u32);
            if from == to {
                self.triangles.push(*t);
                continue;
            }
            let on_side = |k: usize| self.inserts[from..to].iter().filter(move |x| x.1 == t[k]);
            let sides_with = (0..3).filter(|&k| on_side(k).next().is_some()).count();
            if sides_with == 1 {
                // all on one side: a fan from the corner across
                let k = (0..3)
                    .find(|&k| on_side(k).next().is_some())
                    .expect("a side");
                let (x, y, z) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let mut last = x;
                for c in on_side(k).map(|x| x.3).chain([y]) {
                    self.triangles.push([z, last, c]);
                    last = c;
                }
                continue;
            }
            poly.clear();
            for (k, &corner) in t.iter().enumerate() {
                poly.push(corner);
                poly.extend(on_side(k).map(|x| x.3));
            }
            clip_ears(&mut poly, &p, &mut self.triangles);
        }
        self.poly = poly;
        self.ear_triangles = tris;
        // (where ear clipping bridged a hole along a line through corners, its sides may pass
        // over them)
        if found < runs || (!self.holes.is_empty() && !self.conforms()) {
            self.repair();
        }
    }

    /// The corner before `k` on its cycle.
    fn previous(&self, k: u32) -> u32 {
        // the cycle's corners run from its start to the one whose next is the start
        let start = self
            .holes
            .iter()
            .rev()
            .find(|&&h| h <= k)
            .copied()
            .unwrap_or(0);
        if k == start {
            let end = self
                .holes
                .iter()
                .find(|&&h| h > k)
                .copied()
                .unwrap_or(self.ids.len() as u32);
            end - 1
        } else {
            k - 1
        }
    }

    /// Whether every boundary side is a side of a triangle (by point) and no triangle is flat.
    fn conforms(&mut self) -> bool {
        let p = |k: u32| IVec2::from(self.xy[k as usize]);
        let ids = &self.ids;
        self.point_sides.clear();
        for t in &self.triangles {
            if orient(p(t[0]), p(t[1]), p(t[2])) <= 0 {
                return false;
            }
            let t = t.map(|k| ids[k as usize]);
            self.point_sides
                .extend([(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]);
        }
        self.point_sides.sort_unstable();
        (0..ids.len()).all(|k| {
            let side = (ids[k], ids[self.next[k] as usize]);
            self.point_sides.binary_search(&side).is_ok()
        })
    }

    /// Triangulates anew where ear clipping's triangles do not conform (where it bridged a
    /// hole along a line through corners, its sides may pass over them): flat triangles go,
    /// and each triangle takes every corner its sides pass over and is cut again.
    fn repair(&mut self) {
        let xy = &self.xy;
        let p = |k: u32| IVec2::from(xy[k as usize]);
        let ids = &self.ids;
        let tris: Vec<[u32; 3]> = self
            .local
            .chunks_exact(3)
            .filter(|t| orient(p(t[0]), p(t[1]), p(t[2])) != 0)
            .map(|t| {
                if orient(p(t[0]), p(t[1]), p(t[2])) < 0 {
                    [t[0], t[2], t[1]]
                } else {
                    [t[0], t[1], t[2]]
                }
            })
            .collect();
        self.triangles.clear();
        let mut corners: Vec<u32> = (0..ids.len() as u32).collect();
        corners.sort_unstable_by_key(|&k| ids[k as usize]);
        corners.dedup_by_key(|k| ids[*k as usize]);
        let mut on: Vec<(i64, u32)> = Vec::new();
        for t in tris {
            let poly = &mut self.poly;
            poly.clear();
            for i in 0..3 {
                let (x, y) = (t[i], t[(i + 1) % 3]);
                poly.push(x);
                // corners on the side, in order along it
                let d = (p(y) - p(x)).as_i64vec2();
                on.clear();
                on.extend(corners.iter().filter_map(|&k| {
                    let off = (p(k) - p(x)).as_i64vec2();
                    let along = off.dot(d);
                    (cross(d, off) == 0 && along > 0 && along < d.length_squared())
                        .then_some((along, k))
                }));
                on.sort_unstable();
                poly.extend(on.iter().map(|&(_, k)| k));
            }
            clip_ears(poly, &p, &mut self.triangles);
        }
    }
}

/// Triangulates a small polygon that is a triangle with corners put back on or beside its
/// sides, counter-clockwise, by clipping ears (strictly convex corners whose triangle holds no
/// other corner), the roundest first, so that a corner a hair off a side makes no needle.
fn clip_ears(poly: &mut Vec<u32>, p: &impl Fn(u32) -> IVec2, out: &mut Vec<[u32; 3]>) {
    while poly.len() > 3 {
        let n = poly.len();
        let corners = |i: usize| (poly[(i + n - 1) % n], poly[i], poly[(i + 1) % n]);
        // the square of the triangle's height over its longest side, as a fraction
        let roundness = |(a, b, c): (u32, u32, u32)| {
            let (a, b, c) = (p(a).as_i64vec2(), p(b).as_i64vec2(), p(c).as_i64vec2());
            let area2 = cross(b - a, c - a) as f64;
            let longest = (b - a)
                .length_squared()
                .max((c - b).length_squared())
                .max((a - c).length_squared()) as f64;
            area2 * area2 / longest
        };
        let ear = (0..n)
            .filter(|&i| {
                let (a, b, c) = corners(i);
                orient(p(a), p(b), p(c)) > 0
                    && poly.iter().all(|&k| {
                        k == a
                            || k == b
                            || k == c
                            || orient(p(a), p(b), p(k)) < 0
                            || orient(p(b), p(c), p(k)) < 0
                            || orient(p(c), p(a), p(k)) < 0
                    })
            })
            .max_by(|&i, &j| roundness(corners(i)).total_cmp(&roundness(corners(j))));
        let Some(i) = ear else {
            break;
        };
        let (a, b, c) = corners(i);
        out.push([a, b, c]);
        poly.remove(i);
    }
    if poly.len() == 3 {
        out.push([poly[0], poly[1], poly[2]]);
    }
}

/// The parts of the sorted, disjoint intervals `a` outside those of `b`, into `out`.
fn difference(a: &[[i32; 2]], b: &[[i32; 2]], out: &mut Vec<[i32; 2]>) {
    out.clear();
    for &[mut lo, hi] in a {
        for &[b0, b1] in b {
            if b1 <= lo || b0 >= hi {
                continue;
            }
            if b0 > lo {
                out.push([lo, b0]);
            }
            lo = lo.max(b1);
            if lo >= hi {
                break;
            }
        }
        if lo < hi {
            out.push([lo, hi]);
        }
    }
}

/// A wall on the edge from `p` to `q`, facing right of it: each end given as its point and
/// the range of its heights (slots of `heights`) from the wall's bottom to its top, the sides
/// split at every height between.
fn wall(
    m: &mut Mesh,
    vertex: &mut impl FnMut(&mut Mesh, u32, usize) -> u32,
    heights: &[i32],
    (p, p0, p1): (u32, usize, usize),
    (q, q0, q1): (u32, usize, usize),
) {
    debug_assert!(heights[p0] == heights[q0] && heights[p1] == heights[q1]);
    let (mut i, mut j) = (p0, q0);
    while i < p1 || j < q1 {
        let a = vertex(m, p, i);
        let b = vertex(m, q, j);
        let c = if i == p1 || (j < q1 && heights[j + 1] <= heights[i + 1]) {
            j += 1;
            vertex(m, q, j)
        } else {
            i += 1;
            vertex(m, p, i)
        };
        m.triangles.push([a, b, c]);
    }
}
