//! Sensor specifications: presets, refused intrinsics, binning.

use ::sensor::*;

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
