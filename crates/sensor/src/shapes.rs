//! Analytic shapes as triangle soups (the form of [`Target::from_triangles`]), for tests,
//! benchmarks and examples: surfaces whose ray hits are known in closed form.
//!
//! [`Target::from_triangles`]: crate::Target::from_triangles

use glam::{DVec3, Vec3};

/// Two triangles per cell of the `n`×`n` parametric grid `p(i, j)`, `i` and `j` in `0..=n`,
/// wound as `(i, j) → (i + 1, j) → (i + 1, j + 1)`.
pub fn grid(n: usize, p: impl Fn(usize, usize) -> Vec3) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::with_capacity(2 * n * n);
    for i in 0..n {
        for j in 0..n {
            tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    tris
}

/// A sphere about `centre`, `n` rings of `n` cells from the +z pole, tessellated in f64 and
/// stored in f32 (so the meridian at angle 0 lies in the plane y = centre.y exactly): `2n²`
/// triangles.
pub fn sphere(centre: Vec3, radius: f32, n: usize) -> Vec<[Vec3; 3]> {
    let (c, r) = (centre.as_dvec3(), f64::from(radius));
    grid(n, |i, j| {
        let (th, ph) = (
            std::f64::consts::PI * i as f64 / n as f64,
            std::f64::consts::TAU * j as f64 / n as f64,
        );
        (c + r * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())).as_vec3()
    })
}

/// A 1 m square in the plane z = 0 about the origin and a sphere of radius 0.25 m resting on it,
/// each an `n`×`n` grid: `4n²` triangles.
pub fn sphere_on_plane(n: usize) -> Vec<[Vec3; 3]> {
    let mut tris = sphere(Vec3::Z * 0.25, 0.25, n);
    tris.extend(grid(n, |i, j| {
        Vec3::new(i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5, 0.0)
    }));
    tris
}

/// The rectangle through `centre` with half extents `a` and `b`, facing `a × b`.
pub fn rectangle(centre: Vec3, a: Vec3, b: Vec3) -> Vec<[Vec3; 3]> {
    let corners = [
        centre - a - b,
        centre + a - b,
        centre + a + b,
        centre - a + b,
    ];
    vec![
        [corners[0], corners[1], corners[2]],
        [corners[0], corners[2], corners[3]],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_vertex_lies_on_its_surface() {
        let c = Vec3::new(0.1, -0.2, 0.3);
        for v in sphere(c, 0.5, 16).iter().flatten() {
            assert!(((*v - c).length() - 0.5).abs() < 1e-6);
        }
        let both = sphere_on_plane(8);
        assert_eq!(both.len(), 4 * 8 * 8);
        let (ball, plane) = both.split_at(2 * 8 * 8);
        assert!(
            plane
                .iter()
                .flatten()
                .all(|v| v.z == 0.0 && v.x.abs() <= 0.5)
        );
        let lowest = ball
            .iter()
            .flatten()
            .map(|v| v.z)
            .fold(f32::INFINITY, f32::min);
        assert!(
            lowest.abs() < 1e-7,
            "the sphere touches the plane: {lowest}"
        );
        let r = rectangle(Vec3::Z, Vec3::X, Vec3::Y);
        let n = (r[0][1] - r[0][0]).cross(r[0][2] - r[0][0]);
        assert!(n.normalize().abs_diff_eq(Vec3::Z, 1e-6));
    }
}
