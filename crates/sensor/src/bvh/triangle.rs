//! The watertight ray-triangle test (Woop, Benthin and Wald 2013) for one ray and for four
//! rays at once, with the closest hit widened like the boxes so that ties resolve the same in
//! any traversal order.

use glam::{Vec3, Vec4};

use super::Tri;
use super::traverse::{Span, inverse, live_lanes};

/// γ(3) = 3ε / (1 - 3ε): the relative error bound of three f32 operations.
const GAMMA3: f32 = 3.0 * f32::EPSILON / (1.0 - 3.0 * f32::EPSILON);

/// The factor that makes a box test's far distance (and the current closest hit it is compared
/// with) conservative: 1 + 2γ(3) (Ize, "Robust BVH ray traversal", 2013). Scaling the closest
/// hit too means every box holding a triangle hit at exactly that distance is entered, so ties
/// resolve the same way (lowest input index) in any traversal order.
pub(super) const WIDEN: Vec4 = Vec4::splat(1.0 + 2.0 * GAMMA3);

/// A ray prepared for the watertight test: its dominant axis becomes z, and a shear maps the
/// direction onto +z.
pub(super) struct ShearedRay {
    origin: Vec3,
    axes: [usize; 3],
    shear: Vec3,
}

impl ShearedRay {
    #[inline(always)]
    pub(super) fn new(origin: Vec3, dir: Vec3) -> ShearedRay {
        let axes = ShearedRay::axes(dir);
        let [kx, ky, kz] = axes;
        let d = dir.to_array();
        let shear = Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        ShearedRay {
            origin,
            axes,
            shear,
        }
    }

    /// The permutation that makes the dominant axis of `dir` z (keeping the winding).
    #[inline(always)]
    fn axes(dir: Vec3) -> [usize; 3] {
        let kz = dir.abs().max_position();
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if dir.to_array()[kz] < 0.0 {
            [ky, kx, kz]
        } else {
            [kx, ky, kz]
        }
    }

    /// (t, u, v) when the ray hits the triangle with 0 < t < `t_max`; u and v are the
    /// barycentric weights of the second and third vertex.
    #[inline(always)]
    pub(super) fn intersect(&self, tri: &Tri, t_max: f32) -> Option<(f32, f32, f32)> {
        let [kx, ky, kz] = self.axes;
        let s = self.shear;
        // arrays, not Vec3: glam's Vec3 indexing is a branchy match
        let [a, b, c] = tri.map(|v| (v - self.origin).to_array());
        let (ax, ay) = (a[kx] - s.x * a[kz], a[ky] - s.y * a[kz]);
        let (bx, by) = (b[kx] - s.x * b[kz], b[ky] - s.y * b[kz]);
        let (cx, cy) = (c[kx] - s.x * c[kz], c[ky] - s.y * c[kz]);
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // on an edge to f32 precision: decide in f64, as the paper does
            let d =
                |p: f32, q: f32, r: f32, t: f32| (p as f64 * q as f64 - r as f64 * t as f64) as f32;
            u = d(cx, by, cy, bx);
            v = d(ax, cy, ay, cx);
            w = d(bx, ay, by, ax);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * s.z * a[kz] + v * s.z * b[kz] + w * s.z * c[kz];
        let inv = 1.0 / det;
        let t = t_scaled * inv;
        (t > 0.0 && t < t_max).then_some((t, v * inv, w * inv))
    }
}

/// Four rays prepared for the watertight test: together in SIMD lanes where the live rays share
/// their sheared axes (nearly always), else one by one.
pub(super) struct Rays4 {
    /// Origin and direction components per axis (x, y, z), a ray per lane.
    origins: [Vec4; 3],
    dirs: [Vec4; 3],
    /// The range of the live rays' origins and of their inverse directions.
    pub(super) from: Span,
    pub(super) inv: Span,
    /// The sheared frame of the live rays, if they share its axes.
    shared: Option<Shear4>,
}

/// The sheared frame four rays share: the axes (see [`ShearedRay`]) and each ray's shear.
struct Shear4 {
    axes: [usize; 3],
    sx: Vec4,
    sy: Vec4,
    sz: Vec4,
}

impl Rays4 {
    /// The groups of a packet; lanes with `t_max <= 0` are idle and never tested.
    pub(super) fn packet<const G: usize>(
        origins: &[[Vec3; 4]; G],
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
    ) -> [Rays4; G] {
        std::array::from_fn(|g| Rays4::new(&origins[g], &dirs[g], live_lanes(t_max[g])))
    }

    /// The rays in `lanes` (a bit mask).
    #[inline(always)]
    fn new(origins: &[Vec3; 4], dirs: &[Vec3; 4], lanes: u32) -> Rays4 {
        let by_axis = |[a, b, c, e]: &[Vec3; 4]| {
            [
                Vec4::new(a.x, b.x, c.x, e.x),
                Vec4::new(a.y, b.y, c.y, e.y),
                Vec4::new(a.z, b.z, c.z, e.z),
            ]
        };
        let (o, d) = (by_axis(origins), by_axis(dirs));
        let [dx, dy, dz] = d;
        // the dominant axis per lane, as `Vec3::max_position` picks it (first on ties)
        let (ax, ay, az) = (dx.abs(), dy.abs(), dz.abs());
        let is_z = az.cmpgt(ax.max(ay)).bitmask() & lanes;
        let is_y = ay.cmpgt(ax).bitmask() & !is_z & lanes;
        let uniform = |m: u32| m == 0 || m == lanes;
        let kz = if is_z != 0 { 2 } else { usize::from(is_y != 0) };
        let negative = d[kz].cmplt(Vec4::ZERO).bitmask() & lanes;
        let shared = (uniform(is_z) && uniform(is_y) && uniform(negative)).then(|| {
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            let axes = if negative != 0 {
                [ky, kx, kz]
            } else {
                [kx, ky, kz]
            };
            let [x, y, z] = [d[axes[0]], d[axes[1]], d[axes[2]]];
            Shear4 {
                axes,
                sx: x / z,
                sy: y / z,
                sz: Vec4::ONE / z,
            }
        });
        Rays4 {
            origins: o,
            dirs: d,
            from: Span::of(&o, lanes),
            inv: Span::of(&d.map(inverse), lanes),
            shared,
        }
    }

    /// Lane `lane` as a single ray.
    fn ray(&self, lane: usize) -> ShearedRay {
        let at = |v: [Vec4; 3]| Vec3::from(v.map(|c| c.to_array()[lane]));
        ShearedRay::new(at(self.origins), at(self.dirs))
    }

    /// Calls `hit(lane, (t, u, v))` for each lane in `mask` whose ray hits `tri` with
    /// 0 < t < `limit[lane]`: all four lanes at once where the rays share their axes, else (and
    /// on edges, in f64) one by one.
    #[inline(always)]
    pub(super) fn hits(
        &self,
        tri: &Tri,
        mask: u32,
        limit: [f32; 4],
        mut hit: impl FnMut(usize, (f32, f32, f32)),
    ) {
        let (found, t, u, v, mut todo) = match &self.shared {
            Some(shear) => shear.intersect(&self.origins, tri, mask, Vec4::from(limit)),
            None => (0, [0.0; 4], [0.0; 4], [0.0; 4], mask),
        };
        todo |= found;
        while todo != 0 {
            let lane = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            if found & (1 << lane) != 0 {
                hit(lane, (t[lane], u[lane], v[lane]));
            } else if let Some(h) = self.ray(lane).intersect(tri, limit[lane]) {
                hit(lane, h);
            }
        }
    }
}

impl Shear4 {
    /// The watertight test of one triangle against the four rays from `origins` (per axis, a
    /// ray per lane), with the same operations as [`ShearedRay::intersect`] so that each lane
    /// gets the same bits. For the
    /// lanes in `mask`: (lanes hit with 0 < t < `limit`, t, u, v, lanes on an edge to f32
    /// precision, which the scalar test settles in f64).
    #[inline(always)]
    fn intersect(
        &self,
        origins: &[Vec4; 3],
        tri: &Tri,
        mask: u32,
        limit: Vec4,
    ) -> (u32, [f32; 4], [f32; 4], [f32; 4], u32) {
        let [kx, ky, kz] = self.axes;
        let [a, b, c] = tri.map(|v| {
            let v = v.to_array();
            [kx, ky, kz].map(|k| Vec4::splat(v[k]) - origins[k])
        });
        let sheared = |[x, y, z]: [Vec4; 3]| (x - self.sx * z, y - self.sy * z);
        let ((ax, ay), (bx, by), (cx, cy)) = (sheared(a), sheared(b), sheared(c));
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = (u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero)).bitmask() & mask;
        let negative = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let positive = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let inside = !(negative & positive).bitmask() & !on_edge & mask;
        if inside == 0 {
            return (0, [0.0; 4], [0.0; 4], [0.0; 4], on_edge); // most tests miss
        }
        let det = u + v + w;
        let t_scaled = u * self.sz * a[2] + v * self.sz * b[2] + w * self.sz * c[2];
        let inv = Vec4::ONE / det;
        let t = t_scaled * inv;
        let valid = det.cmpne(zero) & t.cmpgt(zero) & t.cmplt(limit);
        let found = valid.bitmask() & inside;
        (
            found,
            t.to_array(),
            (v * inv).to_array(),
            (w * inv).to_array(),
            on_edge,
        )
    }
}
