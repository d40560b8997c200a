//! Region scans: the pixel window, the columns each row casts, and the reach of neighbour
//! effects.

use ::sensor::noise::{self, Axial};
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

#[test]
fn region_scan_keeps_every_point_inside_the_region_and_skips_the_rest() {
    let spec = SensorSpec {
        noise: Noise {
            axial: Axial {
                sigma: 1e-3,
                ..Axial::default()
            },
            edges: noise::Edges {
                probability: 0.5,
                jump: 0.01,
            },
            lateral_px: 0.2,
            ..Noise::default()
        },
        ..ideal(small_camera(240, 180, 200.0))
    };
    let world = World::new(&[
        sphere(Vec3::new(0.05, 0.0, 1.0), 0.2, 120),
        facing_plane(1.5),
    ]);
    let crop = Region {
        min: Vec3::new(-0.1, -0.15, 0.7),
        max: Vec3::new(0.25, 0.1, 1.6),
    };
    // the region grows the crop by the sensor's reach at the crop's far corner, as datasets do
    let far = crop.max.length();
    let margin = spec.reach_px() * far / 200.0;
    assert!((spec.reach_px() - 4.2).abs() < 1e-6);
    let region = Region {
        min: crop.min - margin,
        max: crop.max + margin,
    };
    let inside = |p: &Pixel| {
        let q = p.point;
        q.cmpge(crop.min).all() && q.cmple(crop.max).all()
    };
    let full = scan(&world, &spec, &Affine3A::IDENTITY, 5);
    let part = scan_within(&world, &spec, &Affine3A::IDENTITY, 5, &region);
    let kept = |s: &Scan| -> Vec<Pixel> { s.pixels.iter().copied().filter(inside).collect() };
    assert!(kept(&full).len() > 2000, "{}", kept(&full).len());
    assert_eq!(kept(&full), kept(&part));
    let cast = part.pixels.iter().filter(|p| !p.clean.x.is_nan()).count();
    let all = full.pixels.iter().filter(|p| !p.clean.x.is_nan()).count();
    assert!(cast < all * 6 / 10, "{cast} of {all} pixels cast");
    // the window holds every pixel the scan filled, and what reads it alone misses nothing
    assert_eq!(full.window, Window::full(&spec.intrinsics));
    empty_outside_window(&part);
    let window = part.window.rows.len() * part.window.cols.len();
    assert!(window < part.pixels.len() * 6 / 10, "{window}");
    let valid = part.pixels.iter().filter(|p| p.is_valid()).count();
    assert_eq!(part.valid_count(), valid);
    assert_eq!(part.cloud(false, Frame::Camera, Units::Metres).len(), valid);
}

/// Asserts that every pixel of `scan` outside its window is empty.
fn empty_outside_window(scan: &Scan) {
    let (w, window) = (scan.width as usize, &scan.window);
    for (i, p) in scan.pixels.iter().enumerate() {
        let (c, r) = (i % w, i / w);
        if !(window.cols.contains(&c) && window.rows.contains(&r)) {
            let empty = !p.is_valid() && p.clean.x.is_nan() && p.class == 0 && p.instance == 0;
            assert!(empty, "pixel ({c}, {r}) outside the window {window:?}");
        }
    }
}

/// A region's pixel window holds every pixel whose centre ray crosses the box, from cameras all
/// around it, and is refused where a rectangle cannot bound those pixels.
#[test]
fn region_pixel_window_holds_every_crossing_pixel() {
    let k = small_camera(160, 120, 150.0);
    let region = Region {
        min: Vec3::new(-0.12, -0.05, -0.08),
        max: Vec3::new(0.1, 0.07, 0.04),
    };
    let mut windows = 0;
    for i in 0..24 {
        let a = i as f32 * 0.7;
        let eye = Vec3::new(a.cos() * 0.6, a.sin() * 0.5, 0.3 + 0.1 * (i % 3) as f32);
        let pose = look_at(eye, Vec3::new(0.02 * (i % 5) as f32, 0.0, 0.0), Vec3::Z).unwrap();
        let Some(window) = region.pixel_window(&k, &pose) else {
            continue;
        };
        windows += 1;
        let origin = Vec3::from(pose.translation);
        let mut crossing = 0;
        for r in 0..k.height as usize {
            for c in 0..k.width as usize {
                let dir = pose.transform_vector3(k.ray(c as f64, r as f64));
                if region.crossed_by(origin, dir) {
                    crossing += 1;
                    assert!(
                        window.cols.contains(&c) && window.rows.contains(&r),
                        "pose {i}: pixel ({c}, {r}) outside {window:?}"
                    );
                }
            }
        }
        assert!(crossing > 0, "pose {i} sees the region");
        assert!(
            window.cols.len() * window.rows.len() < 3 * crossing,
            "pose {i}: loose window"
        );
    }
    assert!(windows >= 20, "{windows} windows");
    // inside the box, or with a distorting lens, a rectangle bounds nothing
    assert_eq!(region.pixel_window(&k, &Affine3A::IDENTITY), None);
    let distorted = Intrinsics {
        distortion: Distortion {
            k1: -0.2,
            ..Distortion::default()
        },
        ..k
    };
    let pose = look_at(Vec3::new(0.0, 0.0, 0.6), Vec3::ZERO, Vec3::Y).unwrap();
    assert!(region.pixel_window(&k, &pose).is_some());
    assert_eq!(region.pixel_window(&distorted, &pose), None);
}

#[test]
fn region_scans_cast_every_crossing_pixel_and_little_else() {
    // a floor under the region, seen from all around: each row casts the columns towards the
    // region's cut by the row's plane, which is no polygon the pixel window is
    let spec = ideal(small_camera(160, 120, 150.0));
    let floor = quad(
        Vec3::new(0.0, 0.0, -0.2),
        Vec3::X * 8.0,
        Vec3::Y * 8.0,
        1,
        1,
    );
    let world = World::new(&[floor]);
    let region = Region {
        min: Vec3::new(-0.12, -0.05, -0.08),
        max: Vec3::new(0.1, 0.07, 0.04),
    };
    for i in 0..12 {
        let a = i as f32 * 0.9;
        let eye = Vec3::new(a.cos() * 0.6, a.sin() * 0.5, 0.3 + 0.1 * (i % 3) as f32);
        let pose = look_at(eye, Vec3::new(0.02 * (i % 5) as f32, 0.0, 0.0), Vec3::Z).unwrap();
        let full = scan(&world, &spec, &pose, 1);
        let part = scan_within(&world, &spec, &pose, 1, &region);
        let (mut crossing, mut cast) = (0, 0);
        for (p, (whole, within)) in full.pixels.iter().zip(&part.pixels).enumerate() {
            let (c, r) = (p % 160, p / 160);
            let dir = pose.transform_vector3(spec.intrinsics.ray(c as f64, r as f64));
            let cast_here = !within.clean.x.is_nan();
            cast += cast_here as usize;
            if region.crossed_by(Vec3::from(pose.translation), dir) && whole.is_valid() {
                crossing += 1;
                assert!(
                    cast_here,
                    "pose {i}: pixel ({c}, {r}) crosses but was not cast"
                );
                assert_eq!(within, whole);
            }
        }
        assert!(crossing > 500, "pose {i}: {crossing}");
        empty_outside_window(&part);
        // a column to spare either side of each row's cut, and a third on the right
        assert!(
            cast <= crossing + 3 * 120,
            "pose {i}: {cast} cast, {crossing} crossing"
        );
    }
}

/// [`SensorSpec::reach_px`] bounds how far a measured point lands from its own pixel (lateral
/// jitter), so that datasets grow their scan regions enough.
#[test]
fn reach_bounds_how_far_points_land_from_their_pixel() {
    let noise = Noise {
        lateral_px: 0.5,
        ..Noise::default()
    };
    let spec = SensorSpec {
        noise,
        ..ideal(small_camera(500, 400, 800.0))
    };
    assert_eq!(spec.reach_px(), 9.0);
    let s = noisy_plane(1.0, noise, 11);
    let k = small_camera(500, 400, 800.0);
    let farthest = s
        .pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_valid())
        .map(|(i, p)| {
            let (u, v) = k.project(p.point).unwrap();
            let (c, r) = ((i % 500) as f64, (i / 500) as f64);
            ((u - c).powi(2) + (v - r).powi(2)).sqrt()
        })
        .fold(0.0, f64::max);
    // 200k pixels jittered with σ = 0.5 px: some move over 3σ, none anywhere near the reach
    assert!(farthest > 1.5, "{farthest}");
    assert!(farthest < spec.reach_px() as f64 - 1.0, "{farthest}");
}
