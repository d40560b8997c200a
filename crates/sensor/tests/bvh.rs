//! The BVH against brute force over random triangle soups, and against analytic shapes.

use glam::Vec3;
use proptest::prelude::*;
use sensor::Bvh;
use sensor::shapes::grid;

/// The nearest hit by testing every triangle in f64 (Möller–Trumbore with a 1e-12 tolerance).
fn brute(tris: &[[Vec3; 3]], o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, u32)> {
    brute_within(tris, o, d, t_max, 1e-12)
}

/// [`brute`] with a triangle's edges widened by `slack` in barycentric coordinates.
fn brute_within(
    tris: &[[Vec3; 3]],
    o: Vec3,
    d: Vec3,
    t_max: f32,
    slack: f64,
) -> Option<(f32, u32)> {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let mut best: Option<(f64, u32)> = None;
    for (i, tri) in tris.iter().enumerate() {
        let [a, b, c] = tri.map(|v| v.as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-18 {
            continue;
        }
        let s = o - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let t = e2.dot(q) / det;
        let inside = u >= -slack && v >= -slack && u + v <= 1.0 + slack;
        if inside && t > 0.0 && t < t_max as f64 && best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, i as u32));
        }
    }
    best.map(|(t, i)| (t as f32, i))
}

/// How far inside triangle `tri` the line through `o` along `d` passes, in barycentric
/// coordinates (f64): the smallest of u, v and 1 - u - v; negative outside.
fn inside_by(tri: &[Vec3; 3], o: Vec3, d: Vec3) -> f64 {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    let s = o - a;
    let u = s.dot(p) / det;
    let v = d.dot(s.cross(e1)) / det;
    u.min(v).min(1.0 - u - v)
}

/// Whether the ray grazes an edge of the triangle it hits (by `hit`, its index) within the
/// rounding of f32: there the BVH's f32 test and the f64 brute force may disagree.
fn grazes(tris: &[[Vec3; 3]], o: Vec3, d: Vec3, hit: Option<u32>) -> bool {
    hit.is_some_and(|i| inside_by(&tris[i as usize], o, d).abs() < 1e-5)
}

fn v3() -> impl Strategy<Value = Vec3> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn closest_hit_and_occlusion_match_brute_force(
        centres in prop::collection::vec(v3(), 1..400),
        offsets in prop::collection::vec((v3(), v3()), 400),
        rays in prop::collection::vec((v3(), v3()), 64),
    ) {
        let tris: Vec<[Vec3; 3]> = centres
            .iter()
            .zip(&offsets)
            .map(|(c, (p, q))| [*c, *c + 0.2 * *p, *c + 0.2 * *q])
            .collect();
        let bvh = Bvh::build(&tris);
        prop_assert_eq!(bvh.len(), tris.len());
        for (o, d) in &rays {
            let o = *o * 2.0;
            let Some(d) = d.try_normalize() else { continue };
            let got = bvh.cast(o, d, 10.0);
            let want = brute(&tris, o, d, 10.0);
            match (got, want) {
                (None, None) => {}
                // a nearer hit the BVH misses only where the ray grazes its edge
                (Some(h), Some((t, i))) if h.t > t + 1e-4 && grazes(&tris, o, d, Some(i)) => {}
                (Some(h), Some((t, i))) => {
                    prop_assert!((h.t - t).abs() < 1e-4, "t {} vs {} ({})", h.t, t, inside_by(&tris[i as usize], o, d));
                    if h.triangle != i {
                        // a different triangle only at a tie
                        let other = brute(&[tris[h.triangle as usize]], o, d, 10.0).map(|x| x.0);
                        prop_assert!(other.is_some_and(|x| (x - t).abs() < 1e-4));
                    }
                    let p = tris[h.triangle as usize];
                    let hit = p[0] + h.u * (p[1] - p[0]) + h.v * (p[2] - p[0]);
                    prop_assert!((hit - (o + h.t * d)).length() < 1e-4);
                }
                // grazing edge hits may differ between the two tests by rounding
                (g, w) => prop_assert!(
                    grazes(&tris, o, d, g.map(|h| h.triangle)) || grazes(&tris, o, d, w.map(|x| x.1)),
                    "bvh {:?} vs brute {:?}", g, w
                ),
            }
            prop_assert!(
                bvh.occluded(o, d, 10.0) == want.is_some() || grazes(&tris, o, d, want.map(|x| x.1))
                    || grazes(&tris, o, d, bvh.cast(o, d, 10.0).map(|h| h.triangle))
            );
            // nothing short of the nearest hit by more than f32's rounding of distances (1e-4,
            // as above: a relative margin fails for a hit micrometres from the origin), but
            // where the ray grazes an edge
            if let Some((t, _)) = want.filter(|&(t, _)| t > 1e-4) {
                let before = t - 1e-4;
                prop_assert!(
                    !bvh.occluded(o, d, before) || brute_within(&tris, o, d, before, 1e-5).is_some()
                );
            }
        }
    }
}

#[test]
fn single_triangle_and_empty() {
    let bvh = Bvh::build(&[[
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    ]]);
    let h = bvh.cast(Vec3::ZERO, Vec3::Z, 100.0).unwrap();
    assert!((h.t - 2.0).abs() < 1e-6 && h.triangle == 0);
    assert!(bvh.cast(Vec3::ZERO, -Vec3::Z, 100.0).is_none());
    assert!(Bvh::build(&[]).cast(Vec3::ZERO, Vec3::Z, 1.0).is_none());
}

#[test]
fn a_large_grid_gets_a_shallow_tree_and_exact_hits() {
    // a 300 x 300 quad grid (180k triangles) at z = 1.5:
    // every ray down the z axis hits it at 1.5
    let n = 300;
    let tris = grid(n, |a, b| {
        Vec3::new(a as f32 / n as f32 - 0.5, b as f32 / n as f32 - 0.5, 1.5)
    });
    let bvh = Bvh::build(&tris);
    for k in 0..1000 {
        let x = (k % 37) as f32 / 37.0 - 0.49;
        let y = (k / 37) as f32 / 28.0 - 0.49;
        let h = bvh.cast(Vec3::new(x, y, 0.0), Vec3::Z, 10.0).unwrap();
        assert!((h.t - 1.5).abs() < 1e-6);
        // a good tree: a few dozen nodes and a handful of triangles per ray, not thousands
        let (nodes, leaves) = bvh.cost(Vec3::new(x, y, 0.0), Vec3::Z, 10.0);
        assert!(nodes < 80 && leaves < 8, "{nodes} nodes, {leaves} leaves");
    }
}

#[test]
fn coincident_and_degenerate_triangles_build_a_shallow_tree() {
    // 60,000 copies of one triangle: every centroid equal, which no SAH plane splits
    let one = [
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    ];
    let copies = vec![one; 60_000];
    let bvh = Bvh::build(&copies);
    assert_eq!(bvh.len(), 60_000);
    assert!(bvh.depth() <= 12, "{} levels", bvh.depth());
    let h = bvh.cast(Vec3::ZERO, Vec3::Z, 100.0).unwrap();
    assert!((h.t - 2.0).abs() < 1e-6);
    // a fan of zero-area slivers whose centroids crowd towards one end at every scale (as a
    // polygon fan-triangulated over repeated indices), where a split peels one off at a time
    let sliver = |k: usize| {
        let x = 0.5f32.powi((k % 120) as i32) + k as f32 * 1e-9;
        [
            Vec3::new(x, 0.0, 1.0),
            Vec3::new(2.0 * x, 0.0, 1.0),
            Vec3::new(3.0 * x, 0.0, 1.0),
        ]
    };
    let mut mesh: Vec<[Vec3; 3]> = (0..40_000).map(sliver).collect();
    mesh.push(one);
    let bvh = Bvh::build(&mesh);
    assert!(bvh.depth() <= 40, "{} levels", bvh.depth());
    let h = bvh.cast(Vec3::ZERO, Vec3::Z, 100.0).unwrap();
    assert_eq!(h.triangle, 40_000);
}

#[test]
fn a_tree_is_the_same_whatever_the_threads() {
    // 60,000 scattered triangles, a grid of 20,000 (ties between equal boxes) and 10,000
    // copies of one triangle (no SAH split): ranges large enough to be split on two threads
    let mut state = 17u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut tris: Vec<[Vec3; 3]> = (0..60_000)
        .map(|_| {
            let c = Vec3::new(next(), next(), next()) * 10.0;
            [0; 3].map(|_| c + Vec3::new(next(), next(), next()) * 0.1)
        })
        .collect();
    tris.extend(grid(100, |a, b| Vec3::new(a as f32, b as f32, 3.0)));
    tris.extend(vec![tris[0]; 10_000]);
    let built = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Bvh::build(&tris))
    };
    let one = built(1);
    assert_eq!(one.len(), tris.len());
    assert!(one == built(2) && one == built(3));
}

/// A closed cube of side 2 about the origin, each face an n x n grid of quad pairs.
fn grid_cube(n: usize) -> Vec<[Vec3; 3]> {
    let mut tris = Vec::new();
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let p = |i: usize, j: usize| {
                let (a, b) = (
                    2.0 * i as f32 / n as f32 - 1.0,
                    2.0 * j as f32 / n as f32 - 1.0,
                );
                let mut v = [0.0; 3];
                v[axis] = side;
                v[(axis + 1) % 3] = a;
                v[(axis + 2) % 3] = b;
                Vec3::from(v)
            };
            tris.extend(grid(n, p));
        }
    }
    tris
}

#[test]
fn watertight_through_vertices_and_edges() {
    let tris = grid_cube(24);
    let bvh = Bvh::build(&tris);
    let mut targets: Vec<Vec3> = Vec::new();
    for t in &tris {
        targets.extend(t.iter().copied());
        targets.extend([
            (t[0] + t[1]) * 0.5,
            (t[1] + t[2]) * 0.5,
            (t[2] + t[0]) * 0.5,
        ]);
    }
    for origin in [Vec3::ZERO, Vec3::new(0.1, -0.23, 0.31)] {
        for target in &targets {
            let d = (*target - origin).normalize();
            let h = bvh
                .cast(origin, d, 10.0)
                .expect("a ray from inside a closed mesh always hits");
            assert!((h.t - (*target - origin).length()).abs() < 1e-5);
        }
        // the same through packets of sixteen neighbouring targets (groups of four share axes)
        for sixteen in targets.chunks_exact(16) {
            let dirs: [[Vec3; 4]; 4] = std::array::from_fn(|g| {
                std::array::from_fn(|k| (sixteen[4 * g + k] - origin).normalize())
            });
            let hits = bvh.cast_packet(&[[origin; 4]; 4], &dirs, &[[10.0; 4]; 4]);
            for (k, h) in hits.iter().flatten().enumerate() {
                let h = h.expect("a ray from inside a closed mesh always hits");
                assert!((h.t - (sixteen[k] - origin).length()).abs() < 1e-5);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// No ray from inside a closed mesh gets out, with no allowance for rounding: a cube of
    /// n × n quads a face, bent by a random smooth map (each corner moved as a function of its
    /// position, so triangles that share an edge still share it to the bit), and rays from
    /// random points inside at its corners, at the f32-rounded midpoints of its edges (which
    /// fall either side of the edge) and at random points of its triangles; alone and as
    /// packets. A ray at a point well inside a triangle, and not grazing it, meets the mesh no
    /// further than there.
    #[test]
    fn no_ray_leaves_a_closed_mesh(
        n in 1usize..10,
        bend in (0.0f32..0.35, v3(), -3.0f32..3.0),
        origins in prop::collection::vec(v3(), 3),
        weights in prop::collection::vec((0.0f32..1.0, 0.0f32..1.0), 16),
    ) {
        let (amplitude, wave, phase) = bend;
        let bent = |v: Vec3| v * (1.0 + amplitude * (4.0 * wave.dot(v) + phase).sin());
        let tris: Vec<[Vec3; 3]> = grid_cube(n).into_iter().map(|t| t.map(bent)).collect();
        let bvh = Bvh::build(&tris);
        // (target, the normal of the triangle it lies well inside, if it does)
        let mut targets: Vec<(Vec3, Option<Vec3>)> = Vec::new();
        for (i, t) in tris.iter().enumerate() {
            let (a, b) = weights[i % weights.len()];
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let inside = a > 0.01 && b > 0.01 && a + b < 0.99;
            let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            targets.extend([t[0], (t[0] + t[1]) * 0.5, (t[1] + t[2]) * 0.5, (t[2] + t[0]) * 0.5].map(|p| (p, None)));
            targets.push((t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]), inside.then_some(normal)));
        }
        targets.truncate(targets.len() / 16 * 16);
        // the bent cube keeps the ball of radius 0.65 about its centre inside
        for origin in origins.iter().map(|o| *o * 0.35) {
            let dir = |(t, _): &(Vec3, Option<Vec3>)| (*t - origin).normalize();
            for target in &targets {
                let d = dir(target);
                let h = bvh.cast(origin, d, 10.0);
                prop_assert!(h.is_some(), "a ray from {} towards {:?} got out", origin, target);
                // (a grazing ray meets the plane far from the target rounded off it)
                if target.1.is_some_and(|normal| normal.dot(d).abs() > 0.05) {
                    prop_assert!(h.unwrap().t <= (target.0 - origin).length() * (1.0 + 1e-5));
                }
                prop_assert!(bvh.occluded(origin, d, 10.0));
            }
            for sixteen in targets.chunks_exact(16) {
                let dirs: [[Vec3; 4]; 4] =
                    std::array::from_fn(|g| std::array::from_fn(|k| dir(&sixteen[4 * g + k])));
                let hits = bvh.cast_packet(&[[origin; 4]; 4], &dirs, &[[10.0; 4]; 4]);
                prop_assert!(hits.iter().flatten().all(Option::is_some));
                let blocked = bvh.occluded_packet(&[[origin; 4]; 4], &dirs, &[[10.0; 4]; 4]);
                prop_assert!(blocked.iter().flatten().all(|&b| b));
            }
        }
    }
}

/// Rays with exactly zero direction components (an image's centre row and column) meet boxes
/// that are flat or touch the ray's coordinate exactly: 0·∞ in a slab test must not lose hits.
#[test]
fn axis_parallel_rays_through_a_sphere_pole_match_brute_force() {
    let n = 64;
    let p = |i: usize, j: usize| {
        let (th, ph) = (
            std::f32::consts::PI * i as f32 / n as f32,
            std::f32::consts::TAU * j as f32 / n as f32,
        );
        Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * 0.25 + Vec3::Z * 0.25
    };
    let tris = grid(n, p);
    let bvh = Bvh::build(&tris);
    for k in -40..=40 {
        let s = k as f32 * 0.005;
        for (o, d) in [
            (Vec3::new(0.0, s, 1.0), Vec3::NEG_Z),
            (Vec3::new(s, 0.0, 1.0), Vec3::NEG_Z),
            (
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.0, s, -1.0).normalize(),
            ),
            (
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(s, 0.0, -1.0).normalize(),
            ),
        ] {
            let want = brute(&tris, o, d, 10.0).map(|h| h.0);
            let got = bvh.cast(o, d, 10.0).map(|h| h.t);
            assert_eq!(got.is_some(), want.is_some(), "{o} {d}");
            if let (Some(g), Some(w)) = (got, want) {
                assert!((g - w).abs() < 1e-5, "{o} {d}: {g} vs {w}");
            }
        }
    }
}

/// Two triangles meeting on the line y = 0, so that their boxes end exactly at y = 0, and rays
/// in the plane y = 0: a slab test computing 0·∞ skips both boxes and the ray leaks through.
#[test]
fn rays_in_the_plane_where_boxes_end_still_hit() {
    let tris = [
        [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ],
        [
            Vec3::new(5.0, 5.0, -1.0),
            Vec3::new(6.0, 5.0, -1.0),
            Vec3::new(5.0, 6.0, -1.0),
        ],
    ];
    let bvh = Bvh::build(&tris);
    // every ray lands on the shared edge, between x = -0.8 and 0.9
    for k in -6..=6 {
        let x = k as f32 * 0.1;
        for d in [
            Vec3::NEG_Z,
            Vec3::new(0.3, 0.0, -1.0).normalize(),
            Vec3::new(-0.2, 0.0, -1.0).normalize(),
        ] {
            let o = Vec3::new(x, 0.0, 1.0);
            let h = bvh
                .cast(o, d, 10.0)
                .unwrap_or_else(|| panic!("ray from {o} along {d} leaked"));
            assert!((h.t - 1.0 / -d.z).abs() < 1e-5);
            assert!(bvh.occluded(o, d, 10.0));
        }
    }
}

/// The case that leaked in a slab test computing 0·∞: a sphere tessellated in f64 and stored
/// in f32 (so one meridian lies at y = 0 exactly and its neighbour's closing edge at y = -2e-16),
/// seen by the centre row of a camera, whose rays have a direction y of exactly 0.
#[test]
fn centre_row_rays_on_an_f64_tessellated_sphere_match_brute_force() {
    let tris = sensor::shapes::sphere(Vec3::Z * 0.25, 0.25, 40);
    let bvh = Bvh::build(&tris);
    for u in 0..400 {
        let d = Vec3::new((u as f32 - 200.0) / 300.0, 0.0, -1.0).normalize();
        let o = Vec3::new(0.0, 0.0, 1.0);
        let want = brute(&tris, o, d, 10.0).map(|h| h.0);
        let got = bvh.cast(o, d, 10.0).map(|h| h.t);
        assert_eq!(
            got.is_some(),
            want.is_some(),
            "column {u}: {got:?} vs {want:?}"
        );
        if let (Some(g), Some(w)) = (got, want) {
            assert!((g - w).abs() < 1e-5, "column {u}: {g} vs {w}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 100, ..ProptestConfig::default() })]

    /// Rays traced together as a packet (four groups of four) give each lane exactly what one
    /// ray alone gets (closest hit and occlusion): near-parallel groups from one origin (camera
    /// blocks) or from nearby ones (a surface's mirror rays), spread-out ones, idle lanes, and
    /// shared edges of a closed grid.
    #[test]
    fn packets_match_single_rays_bit_for_bit(
        centres in prop::collection::vec(v3(), 1..300),
        offsets in prop::collection::vec((v3(), v3()), 300),
        origin in v3(),
        groups in prop::collection::vec((v3(), v3(), v3(), v3(), 0.0f32..1.0, 0u8..16), 24),
        moved in prop::collection::vec(v3(), 96),
        apart in prop_oneof![Just(0.0f32), 0.0f32..0.05, 0.0f32..1.0],
    ) {
        let mut tris: Vec<[Vec3; 3]> = centres
            .iter()
            .zip(&offsets)
            .map(|(c, (p, q))| [*c, *c + 0.2 * *p, *c + 0.2 * *q])
            .collect();
        tris.extend(grid_cube(6).into_iter().map(|t| t.map(|v| v * 1.5)));
        let bvh = Bvh::build(&tris);
        let group = |(d, a, b, c, spread, idle): &(Vec3, Vec3, Vec3, Vec3, f32, u8)| {
            let d = d.try_normalize().unwrap_or(Vec3::Z);
            let dirs = [d, d + *spread * *a, d + *spread * *b, d + *spread * *c]
                .map(|x| x.try_normalize().unwrap_or(d));
            let t_max: [f32; 4] =
                std::array::from_fn(|k| if idle & (1 << k) != 0 { 0.0 } else { 10.0 });
            (dirs, t_max)
        };
        for (packet, moved) in groups.chunks_exact(4).zip(moved.chunks_exact(16)) {
            let dirs: [[Vec3; 4]; 4] = std::array::from_fn(|g| group(&packet[g]).0);
            let t_max: [[f32; 4]; 4] = std::array::from_fn(|g| group(&packet[g]).1);
            // each lane's origin: the packet's, moved up to `apart` (0: one origin)
            let o: [[Vec3; 4]; 4] = std::array::from_fn(|g| {
                std::array::from_fn(|k| origin * 0.5 + apart * moved[4 * g + k])
            });
            let hits = bvh.cast_packet(&o, &dirs, &t_max);
            // occlusion just short of and just past each lane's closest hit
            for scale in [0.5, 0.999, 1.001] {
                let reach: [[f32; 4]; 4] = std::array::from_fn(|g| {
                    std::array::from_fn(|k| hits[g][k].map_or(t_max[g][k], |h| h.t * scale))
                });
                let blocked = bvh.occluded_packet(&o, &dirs, &reach);
                for (g, k) in (0..4).flat_map(|g| (0..4).map(move |k| (g, k))) {
                    let one = reach[g][k] > 0.0 && bvh.occluded(o[g][k], dirs[g][k], reach[g][k]);
                    prop_assert_eq!(blocked[g][k], one, "occlusion, lane {}.{}, scale {}", g, k, scale);
                    // the occluder named blocks the ray by the walk's own test
                    let occluder = (reach[g][k] > 0.0)
                        .then(|| bvh.occluder(o[g][k], dirs[g][k], reach[g][k]))
                        .flatten();
                    prop_assert_eq!(occluder.is_some(), one);
                    if let Some(slot) = occluder {
                        prop_assert!(bvh.blocks(slot, o[g][k], dirs[g][k], reach[g][k]));
                    }
                }
            }
            for (g, k) in (0..4).flat_map(|g| (0..4).map(move |k| (g, k))) {
                let one = if t_max[g][k] > 0.0 {
                    bvh.cast(o[g][k], dirs[g][k], t_max[g][k])
                } else {
                    None
                };
                prop_assert_eq!(hits[g][k], one, "lane {}.{}", g, k);
            }
        }
    }
}
