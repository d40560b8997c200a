//! Sensor specifications: presets against Zivid's calibration, the working range on camera z,
//! refused intrinsics, binning.

use ::sensor::*;

use glam::{Affine3A, Vec3};

use crate::kit::*;

#[test]
fn presets_are_valid_and_unknown_ones_are_refused() {
    for name in PRESETS {
        let s = SensorSpec::preset(name).unwrap();
        s.validate().unwrap();
        assert_eq!(s.name, name);
    }
    let e = SensorSpec::preset("zivid-3").unwrap_err().to_string();
    assert!(
        e.contains("zivid-3") && e.contains("zivid-2plus-m130"),
        "{e}"
    );
    let tof = SensorSpec::preset("blensor-tof").unwrap().intrinsics;
    let (h, v) = tof.fov_deg();
    assert!((h - 43.6).abs() < 1e-6 && (v - 34.6).abs() < 1e-6);
}

#[test]
fn colour_camera_presets_have_their_published_optics() {
    let d435 = SensorSpec::preset("realsense-d435-rgb").unwrap();
    let k = &d435.intrinsics;
    assert_eq!((k.width, k.height), (1920, 1080));
    let (h, v) = k.fov_deg();
    assert!(
        (h - 69.4).abs() < 1e-6 && (v - 42.5).abs() < 1e-6,
        "{h} {v}"
    );
    // its 1.88 mm lens over 1.4 µm pixels, within the field's ±3° tolerance
    assert!((k.fx * 1.4e-3 / 1.88 - 1.0).abs() < 0.05, "{}", k.fx);
    // f/2 of 1.94 mm: an aperture of 0.49 mm radius
    let r = d435.colour.aperture_radius(k);
    assert!(
        (r - k.fx as f32 * 1.4e-6 / 4.0).abs() < 1e-9 && r > 4.5e-4,
        "{r}"
    );
    assert!(!d435.colour.flash && matches!(d435.model, Model::Ideal));

    let c = SensorSpec::preset("industrial-5mp").unwrap();
    let k = &c.intrinsics;
    assert_eq!((k.width, k.height), (2448, 2048));
    // 12 mm over 3.45 µm pixels; f/4: 1.5 mm
    assert!((k.fx - 12.0 / 3.45e-3).abs() < 1e-6);
    assert!((c.colour.aperture_radius(k) - 1.5e-3).abs() < 1e-7);
    // barrel distortion: a corner's ray lands 1 to 2 % nearer the centre than a pinhole's
    let ray = k.ray(0.0, 0.0);
    let pinhole = ((k.cx / k.fx).powi(2) + (k.cy / k.fy).powi(2)).sqrt();
    let undistorted = f64::from(ray.x.hypot(ray.y) / ray.z);
    let shrink = pinhole / undistorted - 1.0;
    assert!((-0.02..-0.01).contains(&shrink), "{shrink}");
    // binned 2×2: pixels twice as wide, the same lens
    let binned = c.binned(2);
    assert!((binned.colour.aperture_radius(&binned.intrinsics) - 1.5e-3).abs() < 1e-7);
}

#[test]
fn a_resized_image_keeps_the_cameras_rays_and_gathers_its_pixels_light() {
    let camera = SensorSpec::preset("industrial-5mp").unwrap();
    let resized = camera.resized(1280, 1024).unwrap();
    let (k, r) = (&camera.intrinsics, &resized.intrinsics);
    assert_eq!((r.width, r.height), (1280, 1024));
    // the width fits (2448 -> 1280); of the 1071 rows, 23.5 are cut off at the top and bottom
    let scale = 1280.0 / 2448.0;
    let cut = (2048.0 * scale - 1024.0) / 2.0;
    for (u, v) in [
        (-0.5, -0.5),
        (0.0, 0.0),
        (639.5, 511.5),
        (1279.5, 1023.5),
        (100.0, 900.0),
    ] {
        let (ou, ov) = ((u + 0.5) / scale - 0.5, (v + 0.5 + cut) / scale - 0.5);
        let (a, b) = (r.ray(u, v), k.ray(ou, ov));
        assert!((a - b).length() < 1e-6, "({u}, {v}): {a} vs {b}");
    }
    // each new pixel the light of 1/scale² old ones: the colour noise falls by that side
    let expected = camera.colour.noise * scale as f32;
    assert!((resized.colour.noise - expected).abs() < 1e-7);
    assert!((resized.colour.pixel_um - 3.45 / scale as f32).abs() < 1e-5);
    assert!(camera.resized(0, 10).is_err() && camera.resized(6000, 10).is_err());
}

#[test]
fn impossible_intrinsics_are_refused() {
    let good = small_camera(100, 100, 100.0);
    for (bad, key) in [
        (Intrinsics { fx: 0.0, ..good }, "fx"),
        (
            Intrinsics {
                fy: f64::NAN,
                ..good
            },
            "fy",
        ),
        (Intrinsics { width: 0, ..good }, "width"),
        (Intrinsics { cx: 500.0, ..good }, "cx"),
        (
            Intrinsics {
                distortion: Distortion {
                    k1: -50.0,
                    ..Distortion::default()
                },
                ..good
            },
            "distortion",
        ),
    ] {
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.contains(key), "{e}");
    }
}

#[test]
fn binning_keeps_the_field_of_view() {
    let k = SensorSpec::preset("zivid-2plus-m130").unwrap().intrinsics;
    for f in [2, 4] {
        let b = k.binned(f);
        assert_eq!((b.width, b.height), (k.width / f, k.height / f));
        let (h0, v0) = k.fov_deg();
        let (h1, v1) = b.fov_deg();
        assert!((h0 - h1).abs() < 1e-9 && (v0 - v1).abs() < 1e-9);
        // the same direction through the binned pixel centre as through the block's centre
        let d0 = k.ray((f as f64 - 1.0) / 2.0, (f as f64 - 1.0) / 2.0);
        assert!((b.ray(0.0, 0.0) - d0).length() < 1e-6);
    }
}

/// Zivid's numbers for each preset, from its own simulation (`zivid/zivid-isaac-sim`) as the
/// sensor facts (§7) tabulate them, written out here apart from the presets: the field at the
/// focus distance (mm), the focus distance (mm), the camera-to-projector distance along x (mm)
/// and the projector's turn towards the camera's axis (rad).
const ZIVID: [(&str, [f64; 2], f64, f64, f64); 8] = [
    ("zivid-2plus-m60", [592.0, 495.0], 600.0, 111.2, 0.085),
    ("zivid-2plus-mr60", [592.0, 495.0], 600.0, 111.2, 0.085),
    ("zivid-2plus-m130", [790.0, 661.0], 1300.0, 111.9, 0.069),
    ("zivid-2plus-mr130", [790.0, 661.0], 1300.0, 111.9, 0.069),
    ("zivid-2plus-l110", [1086.0, 909.0], 1100.0, 111.6, 0.087),
    ("zivid-2plus-lr110", [1086.0, 909.0], 1100.0, 111.6, 0.087),
    ("zivid-2-m70", [762.0, 471.0], 700.0, 111.2, 0.113),
    // L100: fx 1784 over 1944×1200 at 1000 mm
    ("zivid-2-l100", [1089.7, 672.6], 1000.0, 111.3, 0.112),
];

#[test]
fn zivid_presets_see_the_field_zivid_calibrated() {
    for (name, field, focus, baseline, toe) in ZIVID {
        let s = SensorSpec::preset(name).unwrap();
        let k = s.intrinsics;
        // the field at the focus distance, from the image's two edges
        let at = |u: f64, v: f64| k.ray(u, v) * (focus / k.ray(u, v).z as f64) as f32;
        let width = (at(k.width as f64 - 0.5, k.cy) - at(-0.5, k.cy)).x as f64;
        let height = (at(k.cx, k.height as f64 - 0.5) - at(k.cx, -0.5)).y as f64;
        assert!(
            (width / field[0] - 1.0).abs() < 0.01,
            "{name}: {width} mm wide"
        );
        assert!(
            (height / field[1] - 1.0).abs() < 0.01,
            "{name}: {height} mm high"
        );
        // the projector where Zivid puts it, turned as Zivid turns it
        let p = s.projector().unwrap();
        assert!((p.baseline as f64 * 1e3 - baseline).abs() < 1e-3, "{name}");
        let turn = (p.baseline / p.convergence).atan() as f64;
        assert!((turn - toe).abs() < 1e-6, "{name}: turned {turn} rad");
        // the working range holds the focus distance
        let focus_m = (focus * 1e-3) as f32;
        assert!(s.min_range < focus_m && focus_m < s.max_range, "{name}");
    }
}

/// The working range bounds depth (camera z), not the length of a pixel's ray: a plane at
/// either limit is measured in every pixel, corners too, and its noise is not cut off there.
#[test]
fn the_working_range_is_on_camera_z() {
    let k = small_camera(120, 100, 100.0); // a wide field: corner rays 1.5 times the centre's
    let noise = Noise {
        axial: noise::Axial {
            sigma: 2e-3,
            ..noise::Axial::default()
        },
        ..Noise::default()
    };
    let camera = SensorSpec {
        model: Model::TimeOfFlight,
        noise,
        min_range: 0.5,
        max_range: 1.0,
        ..ideal(k)
    };
    let pixels = (k.width * k.height) as usize;
    for (z, seen) in [(0.5, pixels), (1.0, pixels), (0.499, 0), (1.001, 0)] {
        let s = scan(
            &World::new(&[facing_plane(z)]),
            &camera,
            &Affine3A::IDENTITY,
            1,
        );
        assert_eq!(s.valid_count(), seen, "plane at {z} m");
        if seen > 0 {
            // noise on both sides of the limit, as much beyond it as within
            let depth: Vec<f64> = s
                .pixels
                .iter()
                .filter(|p| p.is_valid())
                .map(|p| (p.point.z - z) as f64)
                .collect();
            let beyond = depth.iter().filter(|d| (**d > 0.0) == (z > 0.75)).count();
            let share = beyond as f64 / depth.len() as f64;
            assert!(
                (share - 0.5).abs() < 0.05,
                "plane at {z} m: {share} beyond the limit"
            );
        }
    }
    // what the camera reports of a scene out of range: its depth, not a ray's length
    let corner_only = World::new(&[quad(
        Vec3::new(0.55, 0.45, 1.2),
        Vec3::X * 0.05,
        Vec3::Y * 0.05,
        1,
        1,
    )]);
    let d = nearest_surface(&corner_only, &camera, &Affine3A::IDENTITY).unwrap();
    assert!((d - 1.2).abs() < 1e-4, "{d}");
}
