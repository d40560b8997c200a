//! Interreflection by its statistics: shiny inside corners move points along their rays and
//! float ghosts, matte or convex scenes change nothing, a wider lobe blurs the mirrored stripes
//! away, and Zivid's reflection filter removes what the mirrored light decoded.

use ::sensor::noise::Interreflection;
use ::sensor::spec::{ReflectionMode, ReflectionRemoval};
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

/// Polished steel with a lobe of `lobe` radians.
fn steel(lobe: f32) -> Material {
    Material {
        lobe,
        ..materials::STAINLESS_STEEL
    }
}

/// Two walls 12 cm deep and 30 cm high of `material` meeting in a vertical edge 0.65 m in front
/// of the camera, `angle` degrees apart: an inside corner facing the camera, or a ridge (its
/// edge towards the camera) when `ridge`.
fn corner(angle: f32, material: Material, ridge: bool) -> World {
    World::new(&walls(angle, material, ridge, CORNER))
}

/// The distance of [`corner`]'s edge from the camera and its walls' depth, m.
const CORNER: [f32; 2] = [0.65, 0.12];

/// The walls of [`corner`], classes 1 and 2, their edge `z` metres from the camera and each
/// `depth` metres deep.
fn walls(angle: f32, material: Material, ridge: bool, [z, depth]: [f32; 2]) -> [Target; 2] {
    let half = (0.5 * angle).to_radians();
    let height = Vec3::Y * 0.15;
    let (edge, back) = if ridge {
        (Vec3::new(0.0, 0.0, z - depth * half.cos()), 1.0)
    } else {
        (Vec3::new(0.0, 0.0, z), -1.0)
    };
    let wall = |side: f32| {
        let along = 0.5 * depth * Vec3::new(side * half.sin(), 0.0, back * half.cos());
        let tris = shapes::rectangle(edge + along, along, height);
        Target::from_triangles(&tris, 1, if side < 0.0 { 1 } else { 2 }, material)
    };
    [wall(-1.0), wall(1.0)]
}

/// The SNR model, interreflection and Zivid's noise filter.
fn mirroring(enabled: bool) -> SensorSpec {
    let mut spec = structured(Noise {
        interreflection: Interreflection {
            enabled,
            diffuse_reach: 0.0,
        },
        ..snr_noise()
    });
    spec.processing.filters.noise = SensorSpec::preset("zivid-2plus-m60")
        .unwrap()
        .processing
        .filters
        .noise;
    spec
}

/// Of the pixels with a point in `off` (the scan without interreflection), those whose point
/// `on` moved by more than `by` metres or lost, and all of them.
fn moved(on: &Scan, off: &Scan, by: f32) -> (usize, usize) {
    let pairs = on
        .pixels
        .iter()
        .zip(&off.pixels)
        .filter(|(_, b)| b.is_valid());
    let moved = pairs
        .clone()
        .filter(|(a, b)| !a.is_valid() || a.point.distance(b.point) > by)
        .count();
    (moved, pairs.count())
}

/// The corner scanned with and without interreflection.
fn on_and_off(world: &World, spec: &SensorSpec, seed: u64) -> (Scan, Scan) {
    let mut off = spec.clone();
    off.noise.interreflection.enabled = false;
    let pose = Affine3A::IDENTITY;
    (
        scan(world, spec, &pose, seed),
        scan(world, &off, &pose, seed),
    )
}

#[test]
fn shiny_inside_corners_move_points_along_their_rays() {
    for angle in [60.0, 90.0] {
        let world = corner(angle, steel(0.05), false);
        let (on, off) = on_and_off(&world, &mirroring(true), 3);
        let (moved, total) = moved(&on, &off, 1e-3);
        assert!(total > 20_000, "{total}");
        assert!(moved > total / 10, "{angle}°: {moved} of {total} moved");
        // each on its own pixel's ray
        for p in on.pixels.iter().filter(|p| p.is_valid()) {
            let across = p.point.normalize().cross(p.clean.normalize()).length();
            assert!(across < 1e-5, "{angle}°: {across}");
        }
        // ghosts: points that float more than 2 cm off the walls
        let ghosts = on
            .pixels
            .iter()
            .filter(|p| p.is_valid() && p.point.distance(p.clean) > 0.02)
            .count();
        assert!(ghosts > 100, "{angle}°: {ghosts} ghosts");
        eprintln!("{angle}°: {moved} of {total} moved > 1 mm, {ghosts} > 2 cm");
    }
}

#[test]
fn matte_or_convex_scenes_see_no_interreflection() {
    let matte = corner(90.0, materials::MATTE_GREY, false);
    let ridge = corner(90.0, steel(0.05), true);
    for world in [matte, ridge] {
        let (on, off) = on_and_off(&world, &mirroring(true), 5);
        assert!(on.valid_count() > 20_000);
        assert_eq!(bits(&on), bits(&off));
    }
}

#[test]
fn the_mirrored_light_pulls_by_its_strength_and_sharpness() {
    let moved = |specular: f32, lobe: f32| {
        let material = Material {
            specular,
            ..steel(lobe)
        };
        let (on, off) = on_and_off(&corner(90.0, material, false), &mirroring(true), 7);
        moved(&on, &off, 1e-3).0
    };
    let (faint, strong, blurred) = (moved(0.05, 0.03), moved(0.6, 0.03), moved(0.6, 0.3));
    eprintln!("faint {faint} strong {strong} blurred {blurred}");
    assert!(faint * 3 < strong, "specular 0.05: {faint}, 0.6: {strong}");
    assert!(blurred < strong, "lobe 0.3: {blurred}, 0.03: {strong}");
}

/// Zivid's reflection filter in `mode`, or off.
fn filtered(mut spec: SensorSpec, mode: Option<ReflectionMode>) -> SensorSpec {
    spec.processing.filters.reflection.removal = ReflectionRemoval {
        enabled: mode.is_some(),
        mode: mode.unwrap_or_default(),
    };
    spec
}

/// Of the points of `scan` whose surface lies `from` to `to` metres from the edge of a corner
/// `z` metres away, those within 5 mm of it (the surface) and those further (ghosts).
fn surface_and_ghosts(scan: &Scan, z: f32, [from, to]: [f32; 2]) -> [usize; 2] {
    let mut counts = [0; 2];
    for p in scan.pixels.iter().filter(|p| p.is_valid()) {
        if (from..to).contains(&p.clean.x.hypot(p.clean.z - z)) {
            counts[usize::from(p.point.distance(p.clean) > 0.005)] += 1;
        }
    }
    counts
}

#[test]
fn the_reflection_filter_removes_the_ghost_plane_and_keeps_the_surface() {
    // a stainless groove at the Zivid 2+ M60's focus: walls 20 cm deep meeting at 90°, 0.6 m
    // from the camera, with interreflection
    let (z, everywhere, plane) = (0.6, [0.0, 1.0], [0.05, 0.1]);
    let world = World::new(&walls(90.0, materials::STAINLESS_STEEL, false, [z, 0.2]));
    let mut m60 = SensorSpec::preset("zivid-2plus-m60").unwrap();
    m60.noise.interreflection.enabled = true;
    let pose = Affine3A::IDENTITY;
    let raw = scan(&world, &filtered(m60.clone(), None), &pose, 3);
    let [surface, ghosts] = surface_and_ghosts(&raw, z, everywhere);
    // unfiltered, ghosts float over the groove: over half the points 5-10 cm from the edge
    let [near, floating] = surface_and_ghosts(&raw, z, plane);
    eprintln!(
        "unfiltered: {surface} on the surface, {ghosts} ghosts; 5-10 cm from the edge {near} and {floating}"
    );
    assert!(ghosts > surface / 5 && floating > near / 2);
    let mut left = vec![];
    for mode in [ReflectionMode::Global, ReflectionMode::Local] {
        let kept = scan(&world, &filtered(m60.clone(), Some(mode)), &pose, 3);
        let [s, g] = surface_and_ghosts(&kept, z, everywhere);
        let [near, floating] = surface_and_ghosts(&kept, z, plane);
        eprintln!(
            "{mode:?}: {s} on the surface, {g} ghosts; 5-10 cm from the edge {near} and {floating}"
        );
        // it only removes points (the noise filter's suppression then averages a few
        // neighbours less)
        for (r, k) in raw.pixels.iter().zip(&kept.pixels) {
            assert!(
                !k.is_valid() || r.point.distance(k.point) < 1e-3,
                "{mode:?}"
            );
        }
        // no ghost plane over the groove: under a twentieth of the points 5-10 cm from the edge
        assert!(
            floating * 20 < near,
            "{mode:?}: {floating} ghosts, {near} on the surface"
        );
        left.push([s, g]);
    }
    let [
        [global_surface, global_ghosts],
        [local_surface, local_ghosts],
    ] = left[..]
    else {
        unreachable!()
    };
    // the global mode keeps nine tenths of the surface and leaves a smaller ghost plane
    assert!(
        global_surface * 10 > surface * 9,
        "{global_surface} of {surface}"
    );
    assert!(global_ghosts * 2 < ghosts, "{global_ghosts} of {ghosts}");
    // the local mode leaves no ghost, and more of the surface goes with them
    assert!(local_ghosts * 100 < ghosts, "{local_ghosts} of {ghosts}");
    assert!(local_surface < global_surface && local_surface * 2 > surface);
    // where each pixel's light is its own surface's, neither removes anything
    for mode in [ReflectionMode::Global, ReflectionMode::Local] {
        let plane = World::new(&[facing_plane(0.6)]);
        let matte = corner(90.0, materials::MATTE_GREY, false);
        for world in [plane, matte] {
            let spec = mirroring(true);
            let unfiltered = scan(&world, &spec, &pose, 9);
            let kept = scan(&world, &filtered(spec, Some(mode)), &pose, 9);
            assert_eq!(bits(&kept), bits(&unfiltered), "{mode:?}");
        }
    }
}

#[test]
fn shiny_surfaces_in_the_projectors_shadow_mirror_lit_ones() {
    // the corner, and a post 30 cm before the camera between it and the projector (at +x),
    // whose shadow falls on the right wall
    let with_post = |material: Material| {
        let mut post = quad(
            Vec3::new(0.07, 0.0, 0.3),
            Vec3::X * 0.01,
            Vec3::Y * 0.03,
            3,
            3,
        );
        post.material = materials::MATTE_GREY;
        let [left, right] = walls(90.0, material, false, CORNER);
        World::new(&[left, right, post])
    };
    let pose = Affine3A::IDENTITY;
    // the shadow: the matte corner's wall pixels without a point
    let matte = scan(
        &with_post(materials::MATTE_GREY),
        &mirroring(true),
        &pose,
        11,
    );
    let shadow: Vec<bool> = matte
        .pixels
        .iter()
        .map(|p| p.class != 3 && !p.clean.x.is_nan() && !p.is_valid())
        .collect();
    let shadowed = shadow.iter().filter(|&&s| s).count();
    assert!(shadowed > 2_000, "{shadowed}");
    // mirror-polished steel (a lobe of 0.05 rad blurs the finest stripes away over the bounce,
    // and the noise filter takes what is left): with interreflection, shadowed pixels decode
    // the lit wall they mirror
    let world = with_post(steel(0.01));
    let (on, off) = on_and_off(&world, &mirroring(true), 11);
    let lit_in_shadow = |s: &Scan| {
        s.pixels
            .iter()
            .zip(&shadow)
            .filter(|(p, s)| **s && p.is_valid())
            .count()
    };
    let (with, without) = (lit_in_shadow(&on), lit_in_shadow(&off));
    eprintln!("{with} of {shadowed} shadowed pixels have a point ({without} without the model)");
    assert_eq!(without, 0);
    assert!(with > shadowed / 10, "{with} of {shadowed}");
    // ghosts: on their own rays, off their wall
    let mut floating = 0;
    for (p, _) in on
        .pixels
        .iter()
        .zip(&shadow)
        .filter(|(p, s)| **s && p.is_valid())
    {
        assert!(p.point.normalize().cross(p.clean.normalize()).length() < 1e-5);
        floating += usize::from(p.point.distance(p.clean) > 0.01);
    }
    eprintln!("{floating} float over 1 cm");
    assert!(floating > with / 2, "{floating} of {with}");
}

/// The SNR model, Zivid's noise filter and the diffuse bounce within `reach` metres.
fn diffusing(reach: f32) -> SensorSpec {
    let mut spec = mirroring(false);
    spec.noise.interreflection.diffuse_reach = reach;
    spec
}

/// Matte walls of reflectivity `reflectivity`.
fn matte(reflectivity: f32) -> Material {
    Material {
        reflectivity,
        ..materials::MATTE_GREY
    }
}

/// The white (`reflectivity` 0.8) or black (0.12) matte inside corner of `angle` degrees,
/// scanned with the diffuse bounce and without it.
fn diffuse_corner(reflectivity: f32, angle: f32, ridge: bool) -> (Scan, Scan) {
    let world = corner(angle, matte(reflectivity), ridge);
    let pose = Affine3A::IDENTITY;
    (
        scan(&world, &diffusing(0.05), &pose, 3),
        scan(&world, &diffusing(0.0), &pose, 3),
    )
}

/// How far the points of `on` moved from those of `off` along their rays (m, positive away
/// from the camera), of the pixels with a point in both whose surface lies `from` to `to`
/// metres from the corner's edge (the line x = 0, z = 0.65), sorted.
fn moved_near_edge(on: &Scan, off: &Scan, from: f32, to: f32) -> Vec<f32> {
    let mut d: Vec<f32> = on
        .pixels
        .iter()
        .zip(&off.pixels)
        .filter(|(a, b)| a.is_valid() && b.is_valid())
        .filter(|(_, b)| (from..to).contains(&b.clean.x.hypot(b.clean.z - 0.65)))
        .map(|(a, b)| a.point.length() - b.point.length())
        .collect();
    d.sort_by(f32::total_cmp);
    d
}

/// The share of `d` over `by` in size.
fn share_over(d: &[f32], by: f32) -> f32 {
    d.iter().filter(|x| x.abs() > by).count() as f32 / d.len() as f32
}

#[test]
fn bright_inside_corners_bend_their_points_near_the_edge() {
    let (on, off) = diffuse_corner(0.8, 90.0, false);
    let bands = [(0.0, 0.002), (0.005, 0.01), (0.01, 0.02), (0.06, 1.0)];
    let [edge, near, nearby, far] = bands.map(|(from, to)| moved_near_edge(&on, &off, from, to));
    for (band, d) in bands.iter().zip([&edge, &near, &nearby, &far]) {
        let n = d.len();
        eprintln!(
            "{band:?} m from the edge: {n} points, 10th / 50th / 90th percentile {:.3} / {:.3} / {:.3} mm, {:.0} % over 0.1 mm, {:.0} % over 1 mm",
            1e3 * d[n / 10],
            1e3 * d[n / 2],
            1e3 * d[9 * n / 10],
            100.0 * share_over(d, 1e-4),
            100.0 * share_over(d, 1e-3)
        );
        assert!(n > 1000, "{band:?}: {n}");
    }
    // within a centimetre of the edge most points move by over 0.1 mm (the SNR model's
    // precision here), from 1 to 2 cm a few, none by 1 mm; beyond the reach (5 cm, and a
    // cell) none at all
    assert!(share_over(&edge, 1e-4) > 0.5);
    assert!(share_over(&near, 1e-4) > 0.5);
    assert!(share_over(&nearby, 1e-4) < 0.25);
    assert_eq!(share_over(&nearby, 1e-3), 0.0);
    assert_eq!(share_over(&far, 0.0), 0.0);
    // each on its own pixel's ray, and no point lost
    for p in on.pixels.iter().filter(|p| p.is_valid()) {
        assert!(p.point.normalize().cross(p.clean.normalize()).length() < 1e-5);
    }
    assert_eq!(on.valid_count(), off.valid_count());
}

#[test]
fn the_diffuse_light_follows_the_walls_reflectivity() {
    let near_edge = |reflectivity: f32| {
        let (on, off) = diffuse_corner(reflectivity, 90.0, false);
        let d = moved_near_edge(&on, &off, 0.0, 0.005);
        d.iter().map(|x| x.abs()).sum::<f32>() / d.len() as f32
    };
    let (white, black) = (near_edge(0.8), near_edge(0.12));
    eprintln!("mean displacement within 5 mm of the edge: white {white:e} m, black {black:e} m");
    assert!(white > 4.0 * black, "white {white}, black {black}");
}

#[test]
fn matte_ridges_see_no_diffuse_light() {
    for angle in [60.0, 90.0, 120.0] {
        let (on, off) = diffuse_corner(0.8, angle, true);
        assert!(on.valid_count() > 20_000);
        assert_eq!(bits(&on), bits(&off), "{angle}°");
    }
}
