//! Projector shadows cut in epipolar planes. With a pinhole camera and the projector on the
//! camera's x axis (where every [`crate::Projector`] sits), the shadow ray from the projector
//! to a point on a centre ray of pixel row r lies in the plane through the camera's x axis and
//! that row: the row's epipolar plane. Cut by it, the scene's triangles become segments, and the
//! ray is blocked iff it crosses one of them before its end: a test in two dimensions against
//! the few segments binned at the ray's angle from the projector, instead of a walk of the tree
//! per ray. The cut of an edge is computed from that edge alone, so neighbouring triangles'
//! segments end at the same point and no ray slips between them.

use std::ops::Range;

use glam::{Affine3A, DVec2, DVec3, Vec3};
use rayon::prelude::*;

use crate::camera::Intrinsics;

/// Nothing lies closer to the camera's plane than this, m: segments are clipped to it.
const NEAR: f64 = 1e-3;

/// Width of a bin of projector angle, in camera pixels.
const BIN_PX: f64 = 2.0;

/// The scene cut row by row for shadow rays from a projector at `baseline` m along camera +x.
pub(crate) struct Epipolar {
    /// Every triangle in the camera frame.
    tris: Vec<[Vec3; 3]>,
    baseline: f64,
    fy: f64,
    cy: f64,
    /// Bins per unit of projector angle (tan, as `Ray::alpha`).
    bins_per_unit: f64,
    /// Rows per band, and the band of the first row cut.
    band_rows: usize,
    first_band: usize,
    /// Band `i`'s triangles (those whose cut by one of its rows' planes may block a shadow
    /// ray) are `members[starts[i]..starts[i + 1]]`.
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
    /// Prepares to cut `tris` (world frame) seen from the camera-to-world `pose` in the rows
    /// `rows`, taken `band_rows` at a time from row 0, for shadow rays that end within
    /// `max_range` of the camera.
    pub(crate) fn new(
        tris: &[[Vec3; 3]],
        pose: &Affine3A,
        k: &Intrinsics,
        baseline: f32,
        rows: Range<usize>,
        band_rows: usize,
        max_range: f32,
    ) -> Epipolar {
        let to_camera = pose.inverse();
        let tris: Vec<[Vec3; 3]> = tris
            .par_iter()
            .map(|t| t.map(|v| to_camera.transform_point3(v)))
            .collect();
        let first_band = rows.start / band_rows;
        let bands = rows.end.div_ceil(band_rows).max(first_band) - first_band;
        // the bands whose row planes each triangle may cross
        let spans: Vec<Range<usize>> = tris
            .par_iter()
            .map(|t| {
                let z = t.map(|v| v.z as f64);
                if z.iter().all(|&z| z <= NEAR) || z.iter().all(|&z| z >= max_range as f64) {
                    return 0..0; // behind the camera, or beyond every shadow ray's end
                }
                let row_span = if z.iter().any(|&z| z <= NEAR) {
                    rows.clone() // across the camera's plane: any row
                } else {
                    let (lo, hi) = t.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |m, v| {
                        let row = k.fy * (v.y as f64 / v.z as f64) + k.cy;
                        (m.0.min(row), m.1.max(row))
                    });
                    let clamp = |r: f64| r.clamp(rows.start as f64, rows.end as f64) as usize;
                    clamp(lo.floor() - 1.0)..clamp(hi.ceil() + 2.0)
                };
                if row_span.is_empty() {
                    0..0
                } else {
                    row_span.start / band_rows - first_band
                        ..(row_span.end - 1) / band_rows + 1 - first_band
                }
            })
            .collect();
        let mut starts = vec![0u32; bands + 1];
        for span in &spans {
            for band in span.clone() {
                starts[band + 1] += 1;
            }
        }
        for i in 0..bands {
            starts[i + 1] += starts[i];
        }
        let mut next = starts.clone();
        let mut members = vec![0; starts[bands] as usize];
        for (slot, span) in spans.iter().enumerate() {
            for band in span.clone() {
                members[next[band] as usize] = slot as u32;
                next[band] += 1;
            }
        }
        Epipolar {
            tris,
            baseline: baseline as f64,
            fy: k.fy,
            cy: k.cy,
            bins_per_unit: k.fx / BIN_PX,
            band_rows,
            first_band,
            starts,
            members,
        }
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

    /// The cut of the plane of `row` for `rays` (rays of that row), binned by angle in
    /// `scratch`.
    pub(crate) fn cut<'s>(
        &self,
        row: usize,
        rays: impl Iterator<Item = Ray>,
        scratch: &'s mut CutScratch,
    ) -> Cut<'s> {
        let (mut lo, mut hi, mut z_end) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for ray in rays {
            (lo, hi, z_end) = (lo.min(ray.alpha), hi.max(ray.alpha), z_end.max(ray.z_end));
        }
        let CutScratch {
            segments,
            starts,
            entries,
        } = scratch;
        segments.clear();
        let band = row / self.band_rows - self.first_band;
        let t = (row as f64 - self.cy) / self.fy;
        if lo <= hi {
            for &slot in &self.members[self.starts[band] as usize..self.starts[band + 1] as usize] {
                if let Some(s) = Segment::cut(&self.tris[slot as usize], t, self.baseline)
                    && s.z_min < z_end
                    && s.alpha[0] <= hi
                    && s.alpha[1] >= lo
                {
                    segments.push(s);
                }
            }
        }
        // bins of angle over the rays' range, each listing the segments that overlap it
        let span = (hi - lo).max(0.0);
        let per_unit = self.bins_per_unit.min((MAX_BINS - 2) as f64 / span);
        let bins = nearest(span * per_unit) + 1;
        let bin = |alpha: f64| nearest((alpha - lo) * per_unit);
        starts.clear();
        starts.resize(bins + 1, 0);
        for s in segments.iter() {
            for b in bin(s.alpha[0].max(lo))..=bin(s.alpha[1].min(hi)) {
                starts[b + 1] += 1;
            }
        }
        for b in 0..bins {
            starts[b + 1] += starts[b];
        }
        entries.resize(starts[bins] as usize, 0);
        for (i, s) in segments.iter().enumerate() {
            for b in bin(s.alpha[0].max(lo))..=bin(s.alpha[1].min(hi)) {
                entries[starts[b] as usize] = i as u32;
                starts[b] += 1;
            }
        }
        // each bin's end is now the next one's start
        starts.rotate_right(1);
        starts[0] = 0;
        Cut {
            segments,
            starts,
            entries,
            lo,
            per_unit,
        }
    }
}

/// Bins of one row at most (a guard against rays at extreme angles).
const MAX_BINS: usize = 1 << 16;

/// Reusable storage of a [`Cut`].
#[derive(Default)]
pub(crate) struct CutScratch {
    segments: Vec<Segment>,
    starts: Vec<u32>,
    entries: Vec<u32>,
}

/// The segments of one row's plane, binned by angle from the projector.
pub(crate) struct Cut<'s> {
    segments: &'s [Segment],
    starts: &'s [u32],
    entries: &'s [u32],
    lo: f64,
    per_unit: f64,
}

impl Cut<'_> {
    /// Whether a segment blocks `ray` (one of the rays the cut was made for).
    #[inline]
    pub(crate) fn blocks(&self, ray: Ray) -> bool {
        let b = nearest((ray.alpha - self.lo) * self.per_unit);
        let listed = &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize];
        listed
            .iter()
            .any(|&i| self.segments[i as usize].blocks(ray))
    }
}

/// A triangle's cut by an epipolar plane, in the plane's coordinates (x, z).
#[derive(Clone, Copy, Debug)]
struct Segment {
    /// Smallest and largest angle from the projector of its points (tan, as `Ray::alpha`).
    alpha: [f64; 2],
    /// Its nearest depth.
    z_min: f64,
    /// The line through it, as `a·(x - baseline) + b·z = c`.
    line: [f64; 3],
}

impl Segment {
    /// The cut of triangle `tri` (camera frame) by the plane y = `t`·z, clipped to z ≥
    /// [`NEAR`]; `None` where the plane misses it, touches it in a point, or holds it.
    fn cut(tri: &[Vec3; 3], t: f64, baseline: f64) -> Option<Segment> {
        let v = tri.map(|v| v.as_dvec3());
        let side = v.map(|v| v.y - t * v.z);
        if side.iter().all(|&s| s > 0.0) || side.iter().all(|&s| s < 0.0) {
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
            if (side[i] < 0.0 && side[j] > 0.0) || (side[i] > 0.0 && side[j] < 0.0) {
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
        let (a, b) = (a - DVec2::new(baseline, 0.0), b - DVec2::new(baseline, 0.0));
        let (alpha_a, alpha_b) = (a.x / a.y, b.x / b.y);
        let e = b - a;
        Some(Segment {
            alpha: [alpha_a.min(alpha_b), alpha_a.max(alpha_b)],
            z_min: a.y.min(b.y),
            line: [e.y, -e.x, e.y * a.x - e.x * a.y],
        })
    }

    /// Whether it crosses `ray` at a depth in (0, the ray's end).
    #[inline(always)]
    fn blocks(&self, ray: Ray) -> bool {
        if self.z_min >= ray.z_end || ray.alpha < self.alpha[0] || ray.alpha > self.alpha[1] {
            return false;
        }
        // the ray's points are (alpha·z, z): on the line where z·(a·alpha + b) = c
        let [a, b, c] = self.line;
        let z = c / (a * ray.alpha + b);
        z > 0.0 && z < ray.z_end
    }
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
mod tests {
    use glam::DVec3;
    use proptest::prelude::*;

    use super::*;
    use crate::scan::gap;
    use crate::{Material, Projector, Scene, Target, look_at};

    /// For every pixel whose centre ray meets a surface: whether the projector's ray to that
    /// point is blocked, by the cut and by the caster's shadow ray. Returns the pixels tested,
    /// those the caster finds in shadow, and those where the two disagree.
    fn compare(
        tris: &[[Vec3; 3]],
        k: &Intrinsics,
        pose: &Affine3A,
        baseline: f32,
    ) -> (usize, usize, Vec<String>) {
        let scene = Scene::new(&[Target::from_triangles(tris, 1, 1, Material::default())]);
        let projector = Projector {
            baseline,
            convergence: 1.0,
            hfov_deg: 90.0,
            vfov_deg: 90.0,
        };
        let (w, h) = (k.width as usize, k.height as usize);
        let epipolar = scene.epipolar(k, pose, &projector, 0..h, 4, 50.0);
        let origin = Vec3::from(pose.translation);
        let light = pose.transform_point3(projector.centre());
        let mut scratch = CutScratch::default();
        let (mut tested, mut shadowed, mut differ) = (0, 0, Vec::new());
        for r in 0..h {
            let mut rays = Vec::new();
            for c in 0..w {
                let centre = k.ray(c as f64, r as f64);
                if let Some(hit) = scene.cast(origin, pose.transform_vector3(centre), 50.0) {
                    let point = centre * hit.t;
                    let distance = (point - projector.centre()).length();
                    rays.push((c, point, distance));
                }
            }
            let ends: Vec<Ray> = rays
                .iter()
                .map(|&(_, p, d)| epipolar.ray(p, d, gap(d)))
                .collect();
            let cut = epipolar.cut(r, ends.iter().copied(), &mut scratch);
            for (&(c, point, distance), &ray) in rays.iter().zip(&ends) {
                let dir = pose.transform_vector3((point - projector.centre()) / distance);
                let caster = scene.occluded(light, dir, distance - gap(distance));
                if cut.blocks(ray) != caster {
                    // the rays within a microradian: a ray grazing a surface (its crossing
                    // moved far along the ray by rounding) may go either way
                    let (x, y) = (pose.x_axis * 1e-6, pose.y_axis * 1e-6);
                    let near = [x, -x, y, -y].map(|d| {
                        let dir = (dir + Vec3::from(d)).normalize();
                        scene.occluded(light, dir, distance - gap(distance))
                    });
                    if !near.contains(&!caster) {
                        differ.push(format!("pixel ({c}, {r}): caster says {caster}"));
                    }
                }
                tested += 1;
                shadowed += usize::from(caster);
            }
        }
        (tested, shadowed, differ)
    }

    fn sphere_on_plane(n: usize) -> Vec<[Vec3; 3]> {
        let sphere = |i: usize, j: usize| {
            let (th, ph) = (
                std::f64::consts::PI * i as f64 / n as f64,
                std::f64::consts::TAU * j as f64 / n as f64,
            );
            (DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos() + 1.0) * 0.25).as_vec3()
        };
        let plane = |i: usize, j: usize| {
            Vec3::new(i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5, 0.0)
        };
        let mut tris = Vec::new();
        for p in [&sphere as &dyn Fn(usize, usize) -> Vec3, &plane] {
            for i in 0..n {
                for j in 0..n {
                    tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                    tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
                }
            }
        }
        tris
    }

    #[test]
    fn a_sphere_on_a_plane_casts_the_casters_shadows() {
        let k = Intrinsics::from_fov(320, 256, 40.0, 32.0);
        let eye = Vec3::new(0.1, -0.2, 1.28);
        let pose = look_at(eye, Vec3::new(0.0, 0.0, 0.1), Vec3::Y).unwrap();
        for baseline in [0.2, -0.35] {
            let (tested, shadowed, differ) = compare(&sphere_on_plane(70), &k, &pose, baseline);
            assert!(tested > 70_000, "{tested} pixels");
            assert!(shadowed > 2_000, "{shadowed} in shadow");
            assert!(
                differ.is_empty(),
                "{} differ: {:?}",
                differ.len(),
                &differ[..3.min(differ.len())]
            );
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Triangle soups around the camera (some behind it or across its plane, some
        /// intersecting) shadow as the caster's rays do, but for rays through a corner or an
        /// edge within rounding.
        #[test]
        fn triangle_soups_cast_the_casters_shadows(
            corners in prop::collection::vec(-1.0f32..1.0, 9..=360),
            eye in (-1.5f32..1.5, -1.5f32..1.5, 0.3f32..2.5),
            baseline in -0.5f32..0.5,
        ) {
            let tris: Vec<[Vec3; 3]> = corners
                .chunks_exact(9)
                .map(|c| [0, 3, 6].map(|i| Vec3::from_slice(&c[i..i + 3])))
                .collect();
            let k = Intrinsics::from_fov(48, 36, 60.0, 45.0);
            let pose = look_at(Vec3::new(eye.0, eye.1, eye.2), Vec3::ZERO, Vec3::Y).unwrap();
            let (_, _, differ) = compare(&tris, &k, &pose, baseline);
            prop_assert!(differ.is_empty(), "{} differ: {:?}", differ.len(), &differ[..3.min(differ.len())]);
        }
    }
}
