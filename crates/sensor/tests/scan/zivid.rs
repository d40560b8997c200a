//! Zivid's error models by their statistics: the pattern's SNR and the precision it gives
//! (against distance too), the noise filter, noise correlated along the projector's stripes,
//! the camera's own calibration error, and the samplings each model offers.

use ::sensor::noise::{Axial, Correlated};
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

#[test]
fn zivid_precision_is_zivids_point_precision() {
    // a white surface facing the camera at the M60's focus distance: Zivid's datasheet gives
    // 0.08 mm point precision
    let m60 = SensorSpec::preset("zivid-2plus-m60").unwrap();
    let snr = &m60.noise.snr;
    let sigma = snr.sigma_z(snr.ratio(1.0, 1.0), 0.6, m60.focal_baseline());
    assert!((sigma / 8.0e-5 - 1.0).abs() < 0.01, "{sigma}");
    // 2×2 binning: four pixels' charge on a pixel twice as wide keeps the precision
    let by2 = m60.binned(2);
    let s2 = &by2.noise.snr;
    let sigma2 = s2.sigma_z(s2.ratio(1.0, 1.0), 0.6, by2.focal_baseline());
    assert!((sigma2 / sigma - 1.0).abs() < 0.02, "{sigma2} vs {sigma}");
}

/// The point precision (σ of the depth, m) a Zivid `preset` measures on a white plane facing it
/// at depth `z`, over the 100×100 pixels about the image's centre: its SNR model alone, with
/// the sampling it has by default.
fn precision_at(preset: &str, z: f32) -> f64 {
    let zivid = SensorSpec::preset(preset).unwrap();
    let spec = SensorSpec {
        noise: Noise {
            snr: zivid.noise.snr,
            ..Noise::default()
        },
        calibration: Default::default(),
        processing: Default::default(),
        ..zivid
    };
    let s = scan(&plane(z, 1.0), &spec, &Affine3A::IDENTITY, 4);
    let (w, h) = (s.width as usize, s.height as usize);
    let centre: Vec<f64> = (h / 2 - 50..h / 2 + 50)
        .flat_map(|r| &s.pixels[r * w + w / 2 - 50..r * w + w / 2 + 50])
        .filter(|p| p.is_valid())
        .map(|p| (p.point.z - p.clean.z) as f64)
        .collect();
    assert!(centre.len() > 9_000, "{preset} at {z} m: {}", centre.len());
    mean_std(&centre).1
}

#[test]
fn precision_grows_with_distance_as_triangulation_and_the_light_make_it() {
    // Zivid publishes the M60's precision at its focus distance (0.08 mm at 0.6 m) and that
    // noise grows with the working distance. Between, the model's: triangulation turns the
    // disparity's noise into depth as z², and at the preset's exposure the pattern's light
    // falls as 1/z² over a constant ambient, so that the SNR falls about as 1/z. (The plane
    // faces the camera, so the projector 0.11 m aside lights it a little obliquely, from a
    // little further.)
    let focus = precision_at("zivid-2plus-m60", 0.6);
    assert!((focus / 8.0e-5 - 1.0).abs() < 0.05, "{focus}");
    let mut table = vec![];
    for z in [0.3, 0.4, 0.8, 1.0, 1.1] {
        let sigma = precision_at("zivid-2plus-m60", z);
        let exponent = (sigma / focus).ln() / (z as f64 / 0.6).ln();
        table.push(format!("{z} m: {:.0} µm (z^{exponent:.2})", sigma * 1e6));
        assert!(
            (2.4..3.4).contains(&exponent),
            "{z} m: {sigma} (z^{exponent})"
        );
    }
    eprintln!("M60: 0.6 m: {:.0} µm; {}", focus * 1e6, table.join(", "));
}

#[test]
fn snr_follows_the_light_and_sets_the_precision() {
    let spec = structured(snr_noise());
    let snr = spec.noise.snr;
    let fb = spec.focal_baseline();
    let mut precision = Vec::new();
    for (z, reflectivity) in [(0.6, 1.0), (0.6, 0.12), (1.0, 0.6)] {
        let s = scan(&plane(z, reflectivity), &spec, &Affine3A::IDENTITY, 1);
        let valid: Vec<&Pixel> = s.pixels.iter().filter(|p| p.is_valid()).collect();
        assert!(valid.len() > 150_000, "{}", valid.len());
        // each point's SNR is the model's for its light; dark and far surfaces have less
        for p in &valid {
            assert_eq!(p.snr, snr.ratio(p.intensity, reflectivity));
        }
        let mean_snr = valid.iter().map(|p| p.snr as f64).sum::<f64>() / valid.len() as f64;
        // the depth errors have the σ the SNR gives, pixel by pixel
        let scores = z_scores(&s, |p| snr.sigma_z(p.snr, p.clean.z, fb) as f64);
        let (mean, sd) = mean_std(&scores);
        assert!(
            (sd - 1.0).abs() < 0.02,
            "z {z}, ρ {reflectivity}: σ ratio {sd}"
        );
        assert!(mean.abs() < 0.01, "{mean}");
        let (_, sd_z) = mean_std(&z_scores(&s, |_| 1.0));
        precision.push((mean_snr, sd_z));
    }
    let [(white, white_sd), (dark, dark_sd), (far, far_sd)] = precision[..] else {
        unreachable!()
    };
    assert!(
        white > 50.0 && dark < white / 2.0 && far < white,
        "{precision:?}"
    );
    assert!(
        dark_sd > 2.0 * white_sd && far_sd > 2.0 * white_sd,
        "{precision:?}"
    );
}

#[test]
fn the_noise_filter_removes_the_points_below_its_snr_and_nothing_else() {
    let mut spec = structured(snr_noise());
    // a dark plane whose SNR crosses 7 across the image (the light falls off from its centre)
    let world = plane(0.6, 0.032);
    let open = scan(&world, &spec, &Affine3A::IDENTITY, 3);
    spec.processing.filters.noise.removal = Removal {
        enabled: true,
        threshold: 7.0,
    };
    let filtered = scan(&world, &spec, &Affine3A::IDENTITY, 3);
    let (mut kept, mut removed) = (0, 0);
    for (a, b) in open.pixels.iter().zip(&filtered.pixels) {
        if !a.is_valid() {
            assert!(!b.is_valid());
        } else if a.snr < 7.0 {
            assert!(!b.is_valid(), "SNR {} kept", a.snr);
            removed += 1;
        } else {
            assert_eq!(a, b, "a point of SNR {} changed", a.snr);
            kept += 1;
        }
    }
    assert!(
        kept > 10_000 && removed > 10_000,
        "{kept} kept, {removed} removed"
    );
}

#[test]
fn the_snr_model_needs_a_projector() {
    let tof = tof_camera(snr_noise());
    let err = tof.validate().unwrap_err().to_string();
    assert!(err.contains("noise.snr.electrons"), "{err}");
}

/// The correlation of the depth errors of pixels `lag` apart along `axis` (0: a row, 1: a
/// column).
fn correlation(s: &Scan, axis: usize, lag: usize) -> f64 {
    let w = s.width as usize;
    let error = |i: usize| {
        let p = &s.pixels[i];
        p.is_valid()
            .then(|| (p.point.length() - p.clean.length()) as f64)
    };
    let step = if axis == 0 { lag } else { lag * w };
    let pairs: Vec<(f64, f64)> = (0..s.pixels.len() - step)
        .filter(|i| axis == 1 || i % w + lag < w)
        .filter_map(|i| Some((error(i)?, error(i + step)?)))
        .collect();
    let (ma, sa) = mean_std(&pairs.iter().map(|p| p.0).collect::<Vec<_>>());
    let (mb, sb) = mean_std(&pairs.iter().map(|p| p.1).collect::<Vec<_>>());
    let cov = pairs.iter().map(|(a, b)| (a - ma) * (b - mb)).sum::<f64>() / pairs.len() as f64;
    cov / (sa * sb)
}

#[test]
fn correlated_noise_runs_along_the_stripes_for_its_length() {
    let noise = Noise {
        axial: Axial {
            sigma: 1e-3,
            ..Axial::default()
        },
        correlated: Correlated {
            share: 0.8,
            length_px: 4.0,
        },
        ..Noise::default()
    };
    let s = noisy_plane(1.0, noise, 5);
    // the σ stays what the axial model gives
    let (_, sd) = mean_std(&range_errors(&s));
    assert!((sd / 1e-3 - 1.0).abs() < 0.03, "σ {sd}");
    // along a column: strongly correlated next door, not at all two lengths away
    let near = correlation(&s, 1, 1);
    assert!(near > 0.6 && near < 0.8, "lag 1 along a column: {near}");
    let far = correlation(&s, 1, 8);
    assert!(far.abs() < 0.02, "lag 8 along a column: {far}");
    // across columns (along the baseline): white
    let across = correlation(&s, 0, 1);
    assert!(across.abs() < 0.02, "lag 1 along a row: {across}");
    // off: white along columns too
    let white = noisy_plane(
        1.0,
        Noise {
            correlated: Correlated::default(),
            ..noise
        },
        5,
    );
    assert!(correlation(&white, 1, 1).abs() < 0.02);
}

#[test]
fn the_calibration_error_is_the_cameras_own_and_the_same_every_capture() {
    let calibration = Calibration {
        seed: 11,
        scale: 5e-4,
        warp: 4e-5,
    };
    let spec = SensorSpec {
        calibration,
        ..structured(Noise::default())
    };
    let world = plane(0.6, 0.6);
    let one = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    let two = scan(&world, &spec, &Affine3A::IDENTITY, 2);
    let points = |s: &Scan| -> Vec<[u32; 3]> {
        s.pixels
            .iter()
            .map(|p| p.point.to_array().map(f32::to_bits))
            .collect()
    };
    assert!(
        points(&one) == points(&two),
        "the error changed between captures"
    );
    let error = spec.calibration_error().unwrap();
    assert!(structured(Noise::default()).calibration_error().is_none());
    for p in one.pixels.iter().filter(|p| p.is_valid()) {
        // on its ray, the depth scaled by the camera's factor for that direction
        let dir = p.clean.normalize();
        assert!(p.point.normalize().dot(dir) > 1.0 - 1e-6);
        let factor = error.factor(dir);
        assert!((p.point.z / p.clean.z - factor).abs() < 2e-6);
    }
    let other = SensorSpec {
        calibration: Calibration {
            seed: 12,
            ..calibration
        },
        ..spec.clone()
    };
    assert!(points(&scan(&world, &other, &Affine3A::IDENTITY, 1)) != points(&one));
    // over many cameras, the scale error at the image centre has the configured σ, and the
    // warp moves the corners against the centre by about the warp's σ
    let cameras: Vec<CalibrationError> = (0..4000)
        .map(|seed| {
            SensorSpec {
                calibration: Calibration {
                    seed,
                    ..calibration
                },
                ..spec.clone()
            }
            .calibration_error()
            .unwrap()
        })
        .collect();
    let centre: Vec<f64> = cameras
        .iter()
        .map(|c| (c.factor(Vec3::Z) - 1.0) as f64)
        .collect();
    let (m, sd) = mean_std(&centre);
    let expected = (5e-4f64.powi(2) + (2.0 / 3.0 * 4e-5f64).powi(2)).sqrt();
    assert!(m.abs() < 3.0 * expected / 4000f64.sqrt(), "{m}");
    assert!((sd / expected - 1.0).abs() < 0.05, "{sd} vs {expected}");
    let corner = Vec3::new(250.0 / 800.0, 200.0 / 800.0, 1.0);
    let bend: Vec<f64> = cameras
        .iter()
        .map(|c| (c.factor(corner) - c.factor(Vec3::Z)) as f64)
        .collect();
    let (_, bend_sd) = mean_std(&bend);
    assert!(bend_sd > 2e-5 && bend_sd < 2e-4, "{bend_sd}");
}

#[test]
fn subsampling_keeps_one_colours_pixels_of_each_block_under_its_light() {
    let m60 = SensorSpec::preset("zivid-2plus-m60").unwrap();
    let mr60 = SensorSpec::preset("zivid-2plus-mr60").unwrap();
    let k = &m60.intrinsics;
    // Zivid's pixel mapping: blue the 2×2 block's first pixel, red its last, a bin its centre;
    // a 4×4 block's blue pixels (0 and 2) about 1, its red ones about 2
    for (spec, sampling, offset) in [
        (&m60, Sampling::BlueSubsample2x2, 0.0),
        (&m60, Sampling::RedSubsample2x2, 1.0),
        (&mr60, Sampling::By2x2, 0.5),
        (&m60, Sampling::BlueSubsample4x4, 1.0),
        (&m60, Sampling::RedSubsample4x4, 2.0),
        (&mr60, Sampling::By4x4, 1.5),
    ] {
        let s = spec.sampled(sampling).unwrap();
        let f = f64::from(sampling.factor());
        assert_eq!(
            (s.intrinsics.width, s.intrinsics.height),
            (2448 / sampling.factor(), 2048 / sampling.factor())
        );
        for (u, v) in [(0.0, 0.0), (300.0, 200.0), (611.0, 511.0)] {
            let (a, b) = (
                s.intrinsics.ray(u, v),
                k.ray(f * u + offset, f * v + offset),
            );
            assert!(a.angle_between(b) < 1e-6, "{sampling}: {a} vs {b}");
        }
    }
    // a 2×2 subsample has one pixel's light and a third of the ambient: between every pixel and
    // the 2×2 bin; a 4×4 subsample four pixels' light; the points err by the σ their SNR gives
    let world = plane(0.6, 0.5);
    let mean_snr = |spec: &SensorSpec| {
        let s = scan(&world, spec, &Affine3A::IDENTITY, 3);
        let valid: Vec<&Pixel> = s.pixels.iter().filter(|p| p.is_valid()).collect();
        valid.iter().map(|p| p.snr as f64).sum::<f64>() / valid.len() as f64
    };
    let all = mean_snr(&m60);
    let blue_spec = m60.sampled(Sampling::BlueSubsample2x2).unwrap();
    let s = scan(&world, &blue_spec, &Affine3A::IDENTITY, 3);
    let snr = blue_spec.noise.snr;
    let valid: Vec<&Pixel> = s.pixels.iter().filter(|p| p.is_valid()).collect();
    let blue = valid.iter().map(|p| p.snr as f64).sum::<f64>() / valid.len() as f64;
    let by2 = mean_snr(&mr60.sampled(Sampling::By2x2).unwrap());
    let blue4 = mean_snr(&m60.sampled(Sampling::BlueSubsample4x4).unwrap());
    assert!(
        all < blue && blue < by2 && blue < blue4,
        "all {all}, blue {blue}, by2x2 {by2}, blue 4×4 {blue4}"
    );
    let full = m60.noise.snr;
    assert_eq!(
        (snr.electrons, snr.ambient),
        (full.electrons, full.ambient / 3.0)
    );
    let snr4 = m60.sampled(Sampling::BlueSubsample4x4).unwrap().noise.snr;
    assert_eq!(
        (snr4.electrons, snr4.ambient),
        (4.0 * full.electrons, full.ambient / 3.0)
    );
    let fb = blue_spec.focal_baseline();
    let (_, sd) = mean_std(&z_scores(&s, |p| snr.sigma_z(p.snr, p.clean.z, fb) as f64));
    assert!((sd - 1.0).abs() < 0.02, "{sd}");
}

#[test]
fn each_zivid_offers_the_samplings_zivid_lists_for_it() {
    use Sampling::*;
    let plus = vec![
        All,
        BlueSubsample2x2,
        RedSubsample2x2,
        BlueSubsample4x4,
        RedSubsample4x4,
    ];
    for (preset, offered) in [
        ("zivid-one-plus-m", vec![All]),
        ("zivid-2-m70", plus[..3].to_vec()),
        ("zivid-2-l100", plus[..3].to_vec()),
        ("zivid-2plus-m60", plus.clone()),
        ("zivid-2plus-m130", plus.clone()),
        ("zivid-2plus-l110", plus.clone()),
        ("zivid-2plus-mr60", vec![All, By2x2, By4x4]),
        ("zivid-2plus-mr130", vec![All, By2x2, By4x4]),
        ("zivid-2plus-lr110", vec![All, By2x2, By4x4]),
    ] {
        let spec = SensorSpec::preset(preset).unwrap();
        assert_eq!(spec.samplings, offered, "{preset}");
        let names: Vec<String> = offered.iter().map(Sampling::to_string).collect();
        for sampling in Sampling::ALL {
            match spec.sampled(sampling) {
                Ok(_) => assert!(offered.contains(&sampling), "{preset} took {sampling}"),
                Err(e) => {
                    assert!(!offered.contains(&sampling), "{preset}: {e}");
                    assert_eq!(
                        e.to_string(),
                        format!(
                            "sampling = \"{sampling}\" is not allowed: expected one of {} on {preset}",
                            names.join(", ")
                        )
                    );
                }
            }
        }
    }
    // cameras of no maker's list: binning anywhere, subsampling on a Bayer imager under a
    // projector only
    let d435 = SensorSpec::preset("realsense-d435-rgb").unwrap();
    assert!(d435.samplings.is_empty() && d435.sampled(By4x4).is_ok());
    assert!(d435.sampled(BlueSubsample2x2).is_err());
}
