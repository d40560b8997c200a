//! The cut against the caster: every pixel's first hit and shadow compared with rays cast
//! through the BVH, on triangle soups, a sphere's pole and a sphere on a plane.

use proptest::prelude::*;

use super::*;
use crate::scan::gap;
use crate::shapes::sphere_on_plane;
use crate::{Material, Projector, Target, World, look_at};

/// For every pixel whose centre ray meets a surface: whether the projector's ray to that
/// point is blocked, by the cut and by the caster's shadow ray. Returns the pixels tested,
/// those the caster finds in shadow, and those where the two disagree.
fn compare_shadows(
    tris: &[[Vec3; 3]],
    k: &Intrinsics,
    pose: &Affine3A,
    baseline: f32,
) -> (usize, usize, Vec<String>) {
    let world = World::new(&[Target::from_triangles(tris, 1, 1, Material::default())]);
    let projector = Projector {
        baseline,
        convergence: 1.0,
        hfov_deg: 90.0,
        vfov_deg: 90.0,
    };
    let (w, h) = (k.width as usize, k.height as usize);
    let epipolar = world.epipolar(k, pose, baseline, 0..h, 50.0);
    let origin = Vec3::from(pose.translation);
    let light = pose.transform_point3(projector.centre());
    let mut row_cut = RowCut::default();
    let (mut tested, mut shadowed, mut differ) = (0, 0, Vec::new());
    for r in 0..h {
        let mut rays = Vec::new();
        for c in 0..w {
            let centre = k.ray(c as f64, r as f64);
            if let Some(hit) = world.cast(origin, pose.transform_vector3(centre), 50.0) {
                let point = centre * hit.t;
                let distance = (point - projector.centre()).length();
                rays.push((c, point, distance, hit.normal));
            }
        }
        let ends: Vec<Ray> = rays
            .iter()
            .map(|&(_, p, d, _)| epipolar.ray(p, d, gap(d)))
            .collect();
        epipolar.cut(r, &mut row_cut);
        let cut = epipolar.shadows(&mut row_cut, ends.iter().copied());
        for (&(c, point, distance, normal), &ray) in rays.iter().zip(&ends) {
            let dir = pose.transform_vector3((point - projector.centre()) / distance);
            let caster = world.occluded(light, dir, distance - gap(distance));
            let occluded = |d: Vec3| world.occluded(light, d, distance - gap(distance));
            // a ray along its own surface (within 0.6°) crosses it anywhere near its end
            let along = normal.dot(dir).abs() < 1e-2;
            if cut.block(ray) != caster && !along && !grazing(dir, pose, occluded) {
                differ.push(format!("pixel ({c}, {r}): caster says {caster}"));
            }
            tested += 1;
            shadowed += usize::from(caster);
        }
    }
    (tested, shadowed, differ)
}

/// Every pixel's first hit through the cut against the caster's: (pixels hit, pixels that
/// differ by more than a tie within rounding or a ray grazing a silhouette).
fn compare_hits(tris: &[[Vec3; 3]], k: &Intrinsics, pose: &Affine3A) -> (usize, Vec<String>) {
    let world = World::new(&[Target::from_triangles(tris, 1, 1, Material::default())]);
    let (w, h) = (k.width as usize, k.height as usize);
    let epipolar = world.epipolar(k, pose, 0.0, 0..h, 50.0);
    let origin = Vec3::from(pose.translation);
    let (mut row_cut, mut got) = (RowCut::default(), Vec::new());
    let (mut hits, mut differ) = (0, Vec::new());
    for r in 0..h {
        epipolar.cut(r, &mut row_cut);
        epipolar.first_hits(&mut row_cut, &(0..w), &mut got);
        for (c, got) in got.iter().enumerate() {
            let dir = pose.transform_vector3(k.ray(c as f64, r as f64));
            let want = world.cast(origin, dir, 50.0);
            let got = got.map(|(slot, t)| world.describe_slot(slot, t, origin, dir));
            hits += usize::from(want.is_some());
            let same = match (want, got) {
                (None, None) => true,
                // the same triangle (at grazing incidence the caster's distance strays from
                // the cut's float64 one), or another at the same depth (an edge)
                (Some(a), Some(b)) => {
                    let gap = (a.t - b.t).abs() / a.t;
                    gap <= 1e-5 || (a.triangle == b.triangle && gap <= 1e-3)
                }
                _ => false,
            };
            if !same
                && !grazing(dir, pose, |d| {
                    world.cast(origin, d, 50.0).map(|h| h.triangle)
                })
            {
                differ.push(format!("pixel ({c}, {r}): caster {want:?}, cut {got:?}"));
            }
        }
    }
    (hits, differ)
}

/// Whether `verdict` changes for some ray within a microradian of `dir`: a ray grazing a
/// silhouette or a surface, where rounding may decide either way.
fn grazing<T: PartialEq>(dir: Vec3, pose: &Affine3A, verdict: impl Fn(Vec3) -> T) -> bool {
    let here = verdict(dir);
    let (x, y) = (
        Vec3::from(pose.x_axis) * 1e-6,
        Vec3::from(pose.y_axis) * 1e-6,
    );
    [x, -x, y, -y]
        .iter()
        .any(|&d| verdict((dir + d).normalize()) != here)
}

/// How many pixels differ, and the first few.
fn summary(differ: &[String]) -> String {
    format!(
        "{} differ: {:?}",
        differ.len(),
        &differ[..3.min(differ.len())]
    )
}

/// A camera over the sphere's pole, seeing it and the plane around it.
fn over_the_pole() -> (Intrinsics, Affine3A) {
    let k = Intrinsics::from_fov(320, 256, 40.0, 32.0);
    let eye = Vec3::new(0.1, -0.2, 1.28);
    (k, look_at(eye, Vec3::new(0.0, 0.0, 0.1), Vec3::Y).unwrap())
}

#[test]
fn a_sphere_seen_over_its_pole_gives_the_casters_hits() {
    // the pole is a fan of slivers meeting at one point, seen head on
    let (k, pose) = over_the_pole();
    let (hits, differ) = compare_hits(&sphere_on_plane(70), &k, &pose);
    assert!(hits > 50_000, "{hits} pixels hit");
    assert!(differ.is_empty(), "{}", summary(&differ));
}

#[test]
fn a_sphere_on_a_plane_casts_the_casters_shadows() {
    let (k, pose) = over_the_pole();
    for baseline in [0.2, -0.35] {
        let (tested, shadowed, differ) = compare_shadows(&sphere_on_plane(70), &k, &pose, baseline);
        assert!(tested > 70_000, "{tested} pixels");
        assert!(shadowed > 2_000, "{shadowed} in shadow");
        assert!(differ.is_empty(), "{}", summary(&differ));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Triangle soups around the camera (some behind it or across its plane, some
    /// intersecting) give the caster's hits at every pixel.
    #[test]
    fn triangle_soups_give_the_casters_hits(
        corners in prop::collection::vec(-1.0f32..1.0, 9..=360),
        eye in (-1.5f32..1.5, -1.5f32..1.5, 0.3f32..2.5),
        fov in 20.0f64..90.0,
    ) {
        let tris: Vec<[Vec3; 3]> = corners
            .chunks_exact(9)
            .map(|c| [0, 3, 6].map(|i| Vec3::from_slice(&c[i..i + 3])))
            .collect();
        let k = Intrinsics::from_fov(48, 36, fov, fov * 0.75);
        let pose = look_at(Vec3::new(eye.0, eye.1, eye.2), Vec3::ZERO, Vec3::Y).unwrap();
        let (_, differ) = compare_hits(&tris, &k, &pose);
        prop_assert!(differ.is_empty(), "{}", summary(&differ));
    }

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
        let (_, _, differ) = compare_shadows(&tris, &k, &pose, baseline);
        prop_assert!(differ.is_empty(), "{}", summary(&differ));
    }
}
