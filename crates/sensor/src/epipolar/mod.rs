//! Scanning in epipolar planes. With a pinhole camera, every centre ray of pixel row r lies in
//! the plane through the camera's x axis and that row; so does the shadow ray from a projector
//! on that axis (where every [`crate::Projector`] sits) to any point on those rays. Cut by the
//! row's plane, the world's triangles become segments, and both questions become questions in
//! two dimensions: which segment each pixel's ray meets first (a one-dimensional depth buffer
//! over the row's columns, as a rasteriser's), and whether a shadow ray crosses a segment before
//! its end (a test against the few segments binned at its angle from the projector). No tree is
//! walked per ray. The cut of an edge is computed from that edge alone, so neighbouring
//! triangles' segments end at the same point and no ray slips between them.

use std::hint::select_unpredictable;
use std::ops::Range;

use glam::{Affine3A, DVec2, DVec3, Vec3};
use rayon::prelude::*;

use crate::camera::Intrinsics;

/// Nothing is seen, nor shadows, closer to the camera's plane than this, m: segments are
/// clipped to it (their angles grow without bound towards the plane).
pub(crate) const NEAR: f64 = 1e-6;

/// Width of a bin of projector angle, in camera pixels.
const BIN_PX: f64 = 2.0;

/// Bins of one row at most (a guard against rays at extreme angles).
const MAX_BINS: usize = 1 << 16;

/// A world prepared to be cut row by row: the triangles in the camera frame, listed under the
/// rows whose planes they may cross.
pub(crate) struct Epipolar {
    /// Every triangle (by BVH slot) in the camera frame.
    tris: Vec<[Vec3; 3]>,
    /// The projector's distance along camera +x, m (0 without one).
    baseline: f64,
    fx: f64,
    cx: f64,
    /// x / z of each image column's pixel rays.
    xs: Vec<f64>,
    fy: f64,
    cy: f64,
    /// Surfaces deeper than this (camera z, m) are not met.
    max_depth: f64,
    /// The first row prepared for.
    first_row: usize,
    /// The triangles of row `first_row + i` (those whose cut by its plane may be seen or block
    /// a shadow ray) are `members[starts[i]..starts[i + 1]]`, in slot order.
    starts: Vec<u32>,
    members: Vec<u32>,
}

/// A shadow ray, in the epipolar plane of its row: its angle from the projector, as the tangent
/// `(x - baseline) / z`, and the depth `z` where it ends.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ray {
    alpha: f64,
    z_end: f64,
}

impl Epipolar {
    /// Prepares to cut `tris` (world frame, by BVH slot) seen by the pinhole camera `k` from
    /// the camera-to-world `pose`, in the rows `rows`, for surfaces no deeper than `max_depth`
    /// (camera z) and a projector at `baseline`.
    pub(crate) fn new(
        tris: &[[Vec3; 3]],
        pose: &Affine3A,
        k: &Intrinsics,
        baseline: f32,
        rows: Range<usize>,
        max_depth: f32,
    ) -> Epipolar {
        let to_camera = pose.inverse();
        let tris: Vec<[Vec3; 3]> = tris
            .par_iter()
            .map(|t| t.map(|v| to_camera.transform_point3(v)))
            .collect();
        // the rows whose planes each triangle may cross, as indices from the first
        let spans: Vec<Range<usize>> = tris
            .par_iter()
            .map(|t| {
                let z = t.map(|v| v.z as f64);
                if z.iter().all(|&z| z <= NEAR) || z.iter().all(|&z| z >= max_depth as f64) {
                    return 0..0; // behind the camera, or beyond every ray's reach
                }
                if z.iter().any(|&z| z <= NEAR) {
                    return 0..rows.len(); // across the camera's plane: any row
                }
                let (lo, hi) = t.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |m, v| {
                    let row = k.fy * (v.y as f64 / v.z as f64) + k.cy;
                    (m.0.min(row), m.1.max(row))
                });
                // the rows from its first to its last, a millionth of a row to spare for
                // rounding (casts truncate)
                let clamp = |r: f64| (r - rows.start as f64).clamp(0.0, rows.len() as f64) as usize;
                clamp(lo - 1e-6)..clamp(hi + (1.0 + 1e-6))
            })
            .collect();
        let (mut starts, mut members) = (Vec::new(), Vec::new());
        bucket(rows.len(), spans.iter().cloned(), &mut starts, &mut members);
        Epipolar {
            tris,
            baseline: baseline as f64,
            fx: k.fx,
            cx: k.cx,
            xs: (0..k.width).map(|c| (c as f64 - k.cx) / k.fx).collect(),
            fy: k.fy,
            cy: k.cy,
            max_depth: max_depth as f64,
            first_row: rows.start,
            starts,
            members,
        }
    }

    /// Cuts the plane of `row` (in the rows prepared for): its segments, in slot order, into
    /// `row_cut`.
    pub(crate) fn cut(&self, row: usize, row_cut: &mut RowCut) {
        let i = row - self.first_row;
        let t = (row as f64 - self.cy) / self.fy;
        row_cut.segments.clear();
        row_cut.t = t;
        let members = &self.members[self.starts[i] as usize..self.starts[i + 1] as usize];
        for &slot in members {
            if let Some(s) = Segment::cut(&self.tris[slot as usize], t, slot) {
                row_cut.segments.push(s);
            }
        }
    }

    /// The first surface on the centre ray of each pixel of the cut row over `cols`: its slot
    /// and distance along the unit ray, into `hits` (one per column).
    pub(crate) fn first_hits(
        &self,
        row_cut: &mut RowCut,
        cols: &Range<usize>,
        hits: &mut Vec<Option<(u32, f32)>>,
    ) {
        let RowCut {
            segments,
            t: y,
            depth,
            ..
        } = row_cut;
        // inverse depths: nearer is larger; nothing beyond the reach counts
        depth.clear();
        depth.resize(cols.len(), ((1.0 / self.max_depth).to_bits(), u32::MAX));
        let column = |x: f64| x * self.fx + self.cx;
        let (first, end) = (cols.start as f64, cols.end as f64);
        for (i, s) in segments.iter().enumerate() {
            let [x0, x1] = s.camera;
            // the columns from the segment's first to its last, a millionth of a column to
            // spare for rounding (casts round towards zero: no floor call on baseline x86-64);
            // each column is tested exactly below
            let from = (column(x0) - 1e-6).clamp(first, end) as usize;
            let to = (column(x1) + (1.0 + 1e-6)).clamp(first, end) as usize;
            let [a, b, c] = s.line;
            if c == 0.0 {
                continue; // edge-on: in a plane through the camera
            }
            let (a, b) = (a / c, b / c);
            let depth = &mut depth[from - cols.start..to - cols.start];
            for (&x, best) in self.xs[from..to].iter().zip(depth) {
                let w = a * x + b;
                // segments come in slot order: of equals, the lower slot stays (chosen without
                // a branch: which segment is nearer is as good as random)
                let nearer = (w > f64::from_bits(best.0)) & (x >= x0) & (x <= x1);
                best.0 = select_unpredictable(nearer, w.to_bits(), best.0);
                best.1 = select_unpredictable(nearer, i as u32, best.1);
            }
        }
        let y = *y; // the row's pixel rays' y / z
        hits.clear();
        hits.extend(
            self.xs[cols.clone()]
                .iter()
                .zip(depth.iter())
                .map(|(&x, &(w, i))| {
                    let t = (1.0 + x * x + y * y).sqrt() / f64::from_bits(w);
                    (i != u32::MAX).then(|| (segments[i as usize].slot, t as f32))
                }),
        );
    }

    /// The unit centre ray (camera frame) of column `col` of the cut row: as
    /// [`Intrinsics::ray`] gives it for a camera without distortion.
    #[inline]
    pub(crate) fn centre_ray(&self, row_cut: &RowCut, col: usize) -> Vec3 {
        Vec3::new(self.xs[col] as f32, row_cut.t as f32, 1.0).normalize()
    }

    /// The shadow ray from the projector towards camera-frame `point` (on a centre ray of a
    /// pixel), ending `gap` m short of it.
    pub(crate) fn ray(&self, point: Vec3, distance: f32, gap: f32) -> Ray {
        let p = point.as_dvec3();
        Ray {
            alpha: (p.x - self.baseline) / p.z,
            z_end: p.z * ((distance - gap) / distance) as f64,
        }
    }

    /// The cut row's segments that may block `rays` (shadow rays of that row), binned by their
    /// angle from the projector.
    pub(crate) fn shadows<'s>(
        &self,
        row_cut: &'s mut RowCut,
        rays: impl Iterator<Item = Ray>,
    ) -> Shadows<'s> {
        let (mut lo, mut hi, mut z_end) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for ray in rays {
            (lo, hi, z_end) = (lo.min(ray.alpha), hi.max(ray.alpha), z_end.max(ray.z_end));
        }
        let RowCut {
            segments,
            blockers,
            starts,
            entries,
            ..
        } = row_cut;
        blockers.clear();
        for s in segments.iter() {
            let blocker = Blocker::of(s, self.baseline);
            if s.z_min < z_end && blocker.alpha[0] <= hi && blocker.alpha[1] >= lo {
                blockers.push(blocker);
            }
        }
        // bins of angle over the rays' range, each listing the segments that overlap it
        let span = (hi - lo).max(0.0);
        let per_unit = (self.fx / BIN_PX).min((MAX_BINS - 2) as f64 / span);
        let bins = nearest(span * per_unit) + 1;
        let bin = |alpha: f64| nearest((alpha - lo) * per_unit);
        let spans = blockers
            .iter()
            .map(|s| bin(s.alpha[0].max(lo))..bin(s.alpha[1].min(hi)) + 1);
        bucket(bins, spans, starts, entries);
        Shadows {
            blockers,
            starts,
            entries,
            lo,
            per_unit,
        }
    }
}

/// One row's plane cut, with storage reused from row to row.
#[derive(Default)]
pub(crate) struct RowCut {
    /// The cut plane, y = t·z: its rows' pixel rays' y / z.
    t: f64,
    segments: Vec<Segment>,
    /// Per column: the nearest inverse depth so far (its bits, which a branch-free choice keeps
    /// in integer registers) and its segment.
    depth: Vec<(u64, u32)>,
    blockers: Vec<Blocker>,
    starts: Vec<u32>,
    entries: Vec<u32>,
}

/// The segments of one row's plane that may block its shadow rays, binned by angle from the
/// projector.
pub(crate) struct Shadows<'s> {
    blockers: &'s [Blocker],
    starts: &'s [u32],
    entries: &'s [u32],
    lo: f64,
    per_unit: f64,
}

impl Shadows<'_> {
    /// Whether a segment blocks `ray` (one of the rays the bins were made for).
    #[inline]
    pub(crate) fn block(&self, ray: Ray) -> bool {
        let b = nearest((ray.alpha - self.lo) * self.per_unit);
        let listed = &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize];
        listed
            .iter()
            .any(|&i| self.blockers[i as usize].blocks(ray))
    }
}

/// A triangle's cut by an epipolar plane, in the plane's coordinates (x, z), camera frame.
#[derive(Clone, Copy, Debug)]
struct Segment {
    /// The triangle's slot.
    slot: u32,
    /// Smallest and largest x / z of its points: the pixel rays that meet it.
    camera: [f64; 2],
    /// Its ends.
    ends: [DVec2; 2],
    /// Its nearest depth.
    z_min: f64,
    /// The line through it, as `a·x + b·z = c`.
    line: [f64; 3],
}

impl Segment {
    /// The cut of triangle `tri` (camera frame) by the plane y = `t`·z, clipped to z ≥
    /// [`NEAR`]; `None` where the plane misses it, touches it in a point, or holds it.
    fn cut(tri: &[Vec3; 3], t: f64, slot: u32) -> Option<Segment> {
        let v = tri.map(|v| v.as_dvec3());
        let side = v.map(|v| v.y - t * v.z);
        let above = (side[0] > 0.0) & (side[1] > 0.0) & (side[2] > 0.0);
        let below = (side[0] < 0.0) & (side[1] < 0.0) & (side[2] < 0.0);
        if above | below {
            return None; // the usual case: all on one side
        }
        let mut points = [DVec2::ZERO; 3];
        let mut n = 0;
        for i in 0..3 {
            if side[i] == 0.0 {
                points[n] = DVec2::new(v[i].x, v[i].z);
                n += 1;
            }
        }
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            // opposite signs (a non-zero side is far above the square root of the smallest
            // float64, as it comes from float32 corners: the product cannot underflow)
            if side[i] * side[j] < 0.0 {
                // from the edge's lesser corner, so that both triangles on it get the same point
                let (p, q, sp, sq) = if lesser(tri[i], tri[j]) {
                    (v[i], v[j], side[i], side[j])
                } else {
                    (v[j], v[i], side[j], side[i])
                };
                let x: DVec3 = p + (q - p) * (sp / (sp - sq));
                points[n] = DVec2::new(x.x, x.z);
                n += 1;
            }
        }
        if n != 2 {
            return None;
        }
        let [mut a, mut b] = [points[0], points[1]];
        if a.y < NEAR && b.y < NEAR {
            return None;
        }
        let clip = |p: DVec2, q: DVec2| p + (q - p) * ((NEAR - p.y) / (q.y - p.y));
        if a.y < NEAR {
            a = clip(a, b);
        } else if b.y < NEAR {
            b = clip(b, a);
        }
        let (xa, xb) = (a.x / a.y, b.x / b.y);
        let e = b - a;
        Some(Segment {
            slot,
            camera: [xa.min(xb), xa.max(xb)],
            ends: [a, b],
            z_min: a.y.min(b.y),
            line: [e.y, -e.x, e.y * a.x - e.x * a.y],
        })
    }
}

/// A segment as seen from the projector.
#[derive(Clone, Copy, Debug)]
struct Blocker {
    /// Smallest and largest angle from the projector of its points (tan, as `Ray::alpha`).
    alpha: [f64; 2],
    /// Its nearest depth.
    z_min: f64,
    /// The line through it, as `a·(x - baseline) + b·z = c`.
    line: [f64; 3],
}

impl Blocker {
    fn of(s: &Segment, baseline: f64) -> Blocker {
        let alpha = s.ends.map(|p| (p.x - baseline) / p.y);
        let [a, b, c] = s.line;
        Blocker {
            alpha: [alpha[0].min(alpha[1]), alpha[0].max(alpha[1])],
            z_min: s.z_min,
            line: [a, b, c - a * baseline],
        }
    }

    /// Whether it crosses `ray` at a depth in (0, the ray's end). Every test is made, without
    /// a branch: which of them fails is as good as random.
    #[inline(always)]
    fn blocks(&self, ray: Ray) -> bool {
        let within =
            (self.z_min < ray.z_end) & (ray.alpha >= self.alpha[0]) & (ray.alpha <= self.alpha[1]);
        // the ray's points are (alpha·z, z): on the line where z·(a·alpha + b) = c
        let [a, b, c] = self.line;
        let z = c / (a * ray.alpha + b);
        within & (z > 0.0) & (z < ray.z_end)
    }
}

/// Lists items by bucket, each item in the range of buckets `spans` gives it: bucket `b`'s
/// items are `entries[starts[b]..starts[b + 1]]`, in item order (a counting sort).
fn bucket(
    buckets: usize,
    spans: impl Iterator<Item = Range<usize>> + Clone,
    starts: &mut Vec<u32>,
    entries: &mut Vec<u32>,
) {
    starts.clear();
    starts.resize(buckets + 1, 0);
    // the counts as a difference array (each span adds one where it begins and takes it off
    // where it ends: no loop whose length varies), summed into each bucket's start
    for span in spans.clone() {
        debug_assert!(span.start <= span.end, "a span runs backwards: {span:?}");
        starts[span.start] = starts[span.start].wrapping_add(1);
        starts[span.end] = starts[span.end].wrapping_sub(1);
    }
    let (mut covering, mut total) = (0u32, 0u32);
    for start in starts.iter_mut() {
        covering = covering.wrapping_add(*start);
        *start = total;
        total = total.wrapping_add(covering);
    }
    entries.resize(starts[buckets] as usize, 0);
    for (i, span) in spans.enumerate() {
        for b in span {
            entries[starts[b] as usize] = i as u32;
            starts[b] += 1;
        }
    }
    // each bucket's end is now the next one's start
    starts.rotate_right(1);
    starts[0] = 0;
}

/// `x` (in [0, 2³¹)) rounded to the nearest integer by the float's own rounding: adding 2⁵²
/// leaves it in the low bits of the sum. Two instructions where a cast checks for overflow;
/// like a cast, it never decreases as `x` grows, which is what binning needs.
#[inline(always)]
fn nearest(x: f64) -> usize {
    const SHIFT: f64 = (1u64 << 52) as f64;
    ((x + SHIFT).to_bits() as u32) as usize
}

/// A fixed order of points (by x, then y, then z).
fn lesser(p: Vec3, q: Vec3) -> bool {
    p.to_array()
        .iter()
        .zip(q.to_array())
        .map(|(a, b)| a.total_cmp(&b))
        .find(|o| o.is_ne())
        .is_some_and(|o| o.is_lt())
}

#[cfg(test)]
mod tests;
