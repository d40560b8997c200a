//! Zivid's error models by their statistics: the pattern's SNR and the precision it gives, the
//! noise filter, noise correlated along the projector's stripes, the camera's own calibration
//! error.

use ::sensor::noise::{Axial, Correlated};
use ::sensor::spec::{ClusterRemoval, Correction, Gaussian, HoleRepair};
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

/// A plane facing the camera at depth `z`, of `reflectivity`.
fn plane(z: f32, reflectivity: f32) -> World {
    let mut p = facing_plane(z);
    p.material.reflectivity = reflectivity;
    World::new(&[p])
}

/// Depth errors (camera z) of the valid pixels, each divided by `sigma(pixel)`.
fn z_scores(s: &Scan, sigma: impl Fn(&Pixel) -> f64) -> Vec<f64> {
    s.pixels
        .iter()
        .filter(|p| p.is_valid())
        .map(|p| (p.point.z - p.clean.z) as f64 / sigma(p))
        .collect()
}

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

/// A plane at `far` with a plane at `near` over its upper half (y < 0): a horizontal edge,
/// across the baseline, with no projector shadow.
fn step(near: f32, far: f32) -> World {
    let upper = quad(
        Vec3::new(0.0, -2.5, near),
        Vec3::X * 5.0,
        Vec3::Y * 2.5,
        2,
        2,
    );
    World::new(&[upper, facing_plane(far)])
}

/// The pixels whose point lies more than 5σ off their own surface (σ from their SNR).
fn off_surface<'a>(s: &'a Scan, spec: &SensorSpec) -> Vec<(usize, &'a Pixel)> {
    let (snr, fb) = (spec.noise.snr, spec.focal_baseline());
    s.pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            p.is_valid() && (p.point.z - p.clean.z).abs() > 5.0 * snr.sigma_z(p.snr, p.clean.z, fb)
        })
        .collect()
}

#[test]
fn wings_span_a_few_pixels_from_the_blur_and_lie_on_their_rays() {
    let (near, far) = (0.6, 0.61);
    let world = step(near, far);
    let with = |psf: f32| {
        let mut noise = snr_noise();
        noise.wings.psf_px = psf;
        let mut spec = structured(noise);
        spec.processing.filters.noise.removal = Removal {
            enabled: true,
            threshold: 7.0,
        };
        spec
    };
    let mut widths = Vec::new();
    for psf in [0.0, 1.0, 2.0] {
        let spec = with(psf);
        let s = scan(&world, &spec, &Affine3A::IDENTITY, 1);
        let wings = off_surface(&s, &spec);
        widths.push(wings.len() as f64 / s.width as f64);
        let reach = (3.0 * psf).ceil() as usize;
        let sigma = spec.noise.snr.sigma_z(40.0, far, spec.focal_baseline());
        let mut between = 0;
        for &(i, p) in &wings {
            // beside the edge (rows 199 and 200 meet at y = 0), on the pixel's own ray
            let row = i / s.width as usize;
            assert!(
                row + reach >= 199 && row <= 200 + reach,
                "a wing at row {row}"
            );
            assert!(p.point.normalize().dot(p.clean.normalize()) > 1.0 - 1e-6);
            between += usize::from(p.point.z > near - 3.0 * sigma && p.point.z < far + 3.0 * sigma);
        }
        if !wings.is_empty() {
            let share = between as f64 / wings.len() as f64;
            assert!(
                share > 0.9,
                "psf {psf}: {share} of the wing points between the surfaces"
            );
        }
    }
    // off: no point leaves its surface; a blur of σ 1 px: about 2 pixels a column (one each
    // side of the edge), more at σ 2 px (3 to 4: whole pixels whose displacement passes 5σ)
    let [off, one, two] = widths[..] else {
        unreachable!()
    };
    assert!(off == 0.0, "{off}");
    assert!(one > 1.5 && one < 3.5, "σ 1 px: {one} pixels a column");
    assert!(
        two / one > 1.4 && two / one < 2.5,
        "σ 2 px: {two} pixels a column"
    );
    // a smooth surface is not touched
    let plane = plane(0.6, 0.6);
    let a = scan(&plane, &with(0.0), &Affine3A::IDENTITY, 4);
    let b = scan(&plane, &with(1.5), &Affine3A::IDENTITY, 4);
    let interior = |s: &Scan| -> Vec<Pixel> {
        (5..395)
            .flat_map(|r| s.pixels[r * 500 + 5..r * 500 + 495].to_vec())
            .collect()
    };
    assert!(
        interior(&a) == interior(&b),
        "the blur moved points of a smooth plane"
    );
}

#[test]
fn wings_reach_into_the_projectors_shadow() {
    // a near plane over the right half (x > 0): the projector (at +x) casts its shadow on the
    // far plane beside the edge, about 12 pixels wide
    let right = quad(
        Vec3::new(2.5, 0.0, 0.55),
        Vec3::X * 2.5,
        Vec3::Y * 5.0,
        2,
        2,
    );
    let world = World::new(&[right, facing_plane(0.6)]);
    let mut noise = snr_noise();
    let filtered = |noise: Noise| SensorSpec {
        processing: SensorSpec::preset("zivid-2plus-m60").unwrap().processing,
        ..structured(noise)
    };
    let plain = scan(&world, &filtered(noise), &Affine3A::IDENTITY, 2);
    noise.wings.psf_px = 1.0;
    let blurred = scan(&world, &filtered(noise), &Affine3A::IDENTITY, 2);
    let mut into_shadow = 0;
    for (a, b) in plain.pixels.iter().zip(&blurred.pixels) {
        // a pixel of the far plane in the shadow: no light of its own, a point from its
        // neighbours' light, on its own ray
        if !a.is_valid() && a.class == 1 && b.is_valid() {
            assert_eq!(a.intensity, 0.0);
            assert!(b.point.normalize().dot(a.clean.normalize()) > 1.0 - 1e-6);
            // the colour of the light it decodes, not the black of a pixel never measured
            assert_ne!(b.rgb, [0; 3]);
            into_shadow += 1;
        }
    }
    let shadow = plain
        .pixels
        .iter()
        .filter(|p| !p.is_valid() && p.class == 1)
        .count();
    assert!(shadow > 400 * 5, "{shadow} shadowed pixels");
    // the noise filter keeps those the light reaches strongly: a pixel or two on either side
    // of a shadow 12 pixels wide (400 rows)
    let per_row = into_shadow as f64 / 400.0;
    assert!(per_row > 1.0 && per_row < 6.0, "{into_shadow} of {shadow}");
}

/// A plane at 0.6 m, dark (reflectivity 0.05) on one side of a line through the centre and
/// white (0.9) on the other, the line across `across`: no depth edge, only a step of brightness.
fn halves(across: Vec3) -> World {
    let along = Vec3::Z.cross(across);
    let half = |sign: f32, reflectivity: f32| {
        let mut q = quad(
            Vec3::new(0.0, 0.0, 0.6) + across * 2.5 * sign,
            across * 2.5,
            along * 5.0,
            1,
            1,
        );
        q.material.reflectivity = reflectivity;
        q
    };
    World::new(&[half(-1.0, 0.05), half(1.0, 0.9)])
}

#[test]
fn contrast_distortion_pulls_dark_pixels_beside_bright_ones_across_the_baseline_only() {
    let mut noise = snr_noise();
    noise.wings.psf_px = 1.0;
    let spec = structured(noise);
    let mut displaced = Vec::new();
    for across in [Vec3::X, Vec3::Y] {
        let s = scan(&halves(across), &spec, &Affine3A::IDENTITY, 3);
        // the largest mean depth error of a line of pixels parallel to the step
        let lines: Vec<f64> = if across == Vec3::X {
            (0..500)
                .map(|c| (0..400).map(|r| &s.pixels[r * 500 + c]).collect::<Vec<_>>())
                .map(|l| line_error(&l))
                .collect()
        } else {
            (0..400)
                .map(|r| s.pixels[r * 500..(r + 1) * 500].iter().collect::<Vec<_>>())
                .map(|l| line_error(&l))
                .collect()
        };
        displaced.push(lines.iter().fold(0.0f64, |m, e| m.max(e.abs())));
    }
    // a step across the baseline (along x) pulls the dark side's phase by a good part of a
    // millimetre; one along it (the stripes' phase constant across it) leaves the depth
    let sigma = spec.noise.snr.sigma_z(10.0, 0.6, spec.focal_baseline()) as f64;
    let [across, along] = displaced[..] else {
        unreachable!()
    };
    assert!(across > 3.0 * sigma, "across the baseline: {across} m");
    assert!(
        along < across / 10.0,
        "along the baseline: {along} m vs {across} m"
    );
}

#[test]
fn contrast_distortion_filters_take_back_the_pull_and_remove_what_is_left() {
    // exact ranges: a point's depth error is its pull alone
    let mut noise = snr_noise();
    noise.wings.psf_px = 1.0;
    noise.snr.disparity_px = 0.0;
    let with = |strength: Option<f32>, removal: Option<f32>| {
        let mut spec = structured(noise);
        let filters = &mut spec.processing.filters.experimental.contrast_distortion;
        if let Some(strength) = strength {
            filters.correction = Correction {
                enabled: true,
                strength,
            };
        }
        if let Some(threshold) = removal {
            filters.removal = Removal {
                enabled: true,
                threshold,
            };
        }
        spec
    };
    let world = halves(Vec3::X);
    let errors = |spec: &SensorSpec| -> Vec<f32> {
        let s = scan(&world, spec, &Affine3A::IDENTITY, 3);
        s.pixels
            .iter()
            .map(|p| {
                if p.is_valid() {
                    p.point.z - p.clean.z
                } else {
                    f32::NAN
                }
            })
            .collect()
    };
    let raw = errors(&with(None, None));
    let pulled: Vec<usize> = (0..raw.len()).filter(|&i| raw[i].abs() > 1e-4).collect();
    assert!(pulled.len() > 400 * 2, "{} pulled", pulled.len());
    // half the pull taken back: each pulled point's error halves (the depth is nearly linear
    // in the column over a pull this small); all of it: every point on its surface
    let half = errors(&with(Some(0.5), None));
    for &i in &pulled {
        let ratio = half[i] / raw[i];
        assert!((0.45..0.55).contains(&ratio), "pixel {i}: {ratio}");
    }
    let full = errors(&with(Some(1.0), None));
    assert!(full.iter().all(|e| e.is_nan() || e.abs() < 1e-5));
    // the removal takes the points pulled by more than (1 - threshold) × the blur's σ (1 px) of
    // disparity, more the higher the threshold, as Zivid's, and leaves the others as they were
    // (1 px of disparity: z² / (f·b) = 4.5 mm at 0.6 m; the projector's toe-in changes the
    // scale by under 3 %)
    let pull_px = |i: usize| f64::from(raw[i].abs()) * 800.0 * 0.1 / (0.6 * 0.6);
    let mut last = 0;
    // (the lines beside the step are pulled 1.09, 1.03, 0.47, 0.18 and 0.11 px)
    for threshold in [0.1f32, 0.6, 0.85, 0.95] {
        let removed = errors(&with(None, Some(threshold)));
        let limit = f64::from(1.0 - threshold);
        let mut gone = 0;
        for i in 0..raw.len() {
            if raw[i].is_nan() {
                continue;
            }
            if removed[i].is_nan() {
                assert!(
                    pull_px(i) > 0.97 * limit,
                    "{threshold}: {} px removed",
                    pull_px(i)
                );
                gone += 1;
            } else {
                assert_eq!(removed[i].to_bits(), raw[i].to_bits());
                assert!(
                    pull_px(i) < 1.03 * limit,
                    "{threshold}: {} px kept",
                    pull_px(i)
                );
            }
        }
        assert!(
            gone > last,
            "{threshold}: {gone} removed, {last} at the lower threshold"
        );
        last = gone;
    }
    // wings at a depth edge are no contrast distortion: the filters leave them
    let edge = step(0.6, 0.61);
    let at_edge = |spec: &SensorSpec| bits(&scan(&edge, spec, &Affine3A::IDENTITY, 3));
    assert_eq!(
        at_edge(&with(Some(1.0), Some(1.0))),
        at_edge(&with(None, None))
    );
}

/// The mean depth error of the points of a line of pixels.
fn line_error(line: &[&Pixel]) -> f64 {
    let errors: Vec<f64> = line
        .iter()
        .filter(|p| p.is_valid())
        .map(|p| f64::from(p.point.z - p.clean.z))
        .collect();
    errors.iter().sum::<f64>() / errors.len().max(1) as f64
}

#[test]
fn the_outlier_filter_removes_lone_points_and_nothing_else() {
    // a plane at 0.6 m and, 10 cm before it, a speck only pixel (250, 200)'s ray meets
    let ray = Vec3::new(0.5 / 800.0, 0.5 / 800.0, 1.0);
    let speck = quad(ray * 0.5, Vec3::X * 1.2e-4, Vec3::Y * 1.2e-4, 2, 2);
    let world = World::new(&[speck, facing_plane(0.6)]);
    let mut spec = tof_camera(Noise::default());
    let open = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    assert_eq!(open.pixels.iter().filter(|p| p.class == 2).count(), 1);
    spec.processing.filters.outlier.removal = Removal {
        enabled: true,
        threshold: 5.0,
    };
    let filtered = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    for (a, b) in open.pixels.iter().zip(&filtered.pixels) {
        if a.class == 2 {
            assert!(a.is_valid() && !b.is_valid(), "the speck stayed");
            assert_eq!(a.instance, b.instance);
        } else {
            assert_eq!(a, b, "a point of the plane changed");
        }
    }
}

/// The SNR model with exact ranges (the pattern's noise off) and Zivid's noise filter at 7.
fn exact_and_noise_filtered() -> SensorSpec {
    let mut noise = snr_noise();
    noise.snr.disparity_px = 0.0;
    let mut spec = structured(noise);
    spec.processing.filters.noise.removal = Removal {
        enabled: true,
        threshold: 7.0,
    };
    spec
}

/// The points of class `class`.
fn points_of(s: &Scan, class: u16) -> usize {
    s.pixels
        .iter()
        .filter(|p| p.class == class && p.is_valid())
        .count()
}

#[test]
fn noise_repair_fills_lone_removed_pixels_and_nothing_else() {
    // a white plane at 0.6 m with dark stripes (reflectivity 0.005: SNR under 2) across the
    // rows: one a pixel wide (column 250), one ten (columns 300 to 309)
    let pitch = 0.6 / 800.0;
    let x = |col: f32| (col - 249.5) * pitch;
    let stripe = |x0: f32, x1: f32, reflectivity: f32, class: u16| {
        let mut t = quad(
            Vec3::new(0.5 * (x0 + x1), 0.0, 0.6),
            Vec3::X * 0.5 * (x1 - x0),
            Vec3::Y * 0.3,
            class,
            u32::from(class),
        );
        t.material.reflectivity = reflectivity;
        t
    };
    let edges = [-0.3, x(249.5), x(250.5), x(299.5), x(309.5), 0.3];
    let world = World::new(&[
        stripe(edges[0], edges[1], 1.0, 1),
        stripe(edges[1], edges[2], 0.005, 2),
        stripe(edges[2], edges[3], 1.0, 1),
        stripe(edges[3], edges[4], 0.005, 3),
        stripe(edges[4], edges[5], 1.0, 1),
    ]);
    // exact ranges, to see where the repaired points land
    let mut spec = exact_and_noise_filtered();
    let removed = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    assert_eq!((points_of(&removed, 2), points_of(&removed, 3)), (0, 0));
    spec.processing.filters.noise.repair.enabled = true;
    let repaired = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    // the one-pixel stripe comes back but in the first and last row (5 neighbours), on the
    // plane, with its own pixel's colour; the wide one stays empty
    assert_eq!((points_of(&repaired, 2), points_of(&repaired, 3)), (398, 0));
    for (i, (a, b)) in removed.pixels.iter().zip(&repaired.pixels).enumerate() {
        if a.class == 2 && b.is_valid() {
            assert!((b.point.z - 0.6).abs() < 1e-5, "{}", b.point.z);
            assert_eq!(b.rgb, a.rgb, "pixel {i}");
        } else {
            assert_eq!(bits_of(a), bits_of(b), "another pixel changed");
        }
    }
}

#[test]
fn hole_repair_fills_holes_as_wide_as_it_is_told_on_their_surface() {
    // a white plane through (0, 0, 0.6) turned 20° about y, and on it (10 µm before it) a dark
    // square (reflectivity 0.005: the noise filter removes it) about 10 pixels wide
    let turn = 20f32.to_radians();
    let (u, v) = (Vec3::new(turn.cos(), 0.0, turn.sin()), Vec3::Y);
    let normal = u.cross(v);
    let centre = Vec3::new(0.0375, -0.0375, 0.6 + 0.0375 * turn.tan());
    let mut dark = quad(centre - 1e-5 * normal, u * 3.8e-3, v * 3.8e-3, 2, 2);
    dark.material.reflectivity = 0.005;
    let plane = quad(Vec3::new(0.0, 0.0, 0.6), u * 5.0, v * 5.0, 1, 1);
    let world = World::new(&[dark, plane]);
    let spec = exact_and_noise_filtered();
    let open = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    let hole: Vec<usize> = (0..open.pixels.len())
        .filter(|&i| open.pixels[i].class == 2)
        .collect();
    assert!((80..140).contains(&hole.len()), "{} pixels", hole.len());
    assert!(hole.iter().all(|&i| !open.pixels[i].is_valid()));
    let repaired = |hole_size: f32, strictness: u32| {
        let mut spec = spec.clone();
        spec.processing.filters.hole.repair = HoleRepair {
            enabled: true,
            hole_size,
            strictness,
        };
        scan(&world, &spec, &Affine3A::IDENTITY, 1)
    };
    // 0.2 reaches 16 pixels (12 mm at 0.6 m), across it: every pixel filled, on the plane,
    // with its own surface's labels; nothing else changes
    let wide = repaired(0.2, 4);
    for (i, (a, b)) in open.pixels.iter().zip(&wide.pixels).enumerate() {
        if hole.contains(&i) {
            // on the plane: inverse depth is linear across a plane's image
            assert!(b.is_valid(), "pixel {i} not filled");
            assert!(
                (b.point.z - b.clean.z).abs() < 5e-5,
                "{} vs {}",
                b.point.z,
                b.clean.z
            );
            assert_eq!((b.class, b.instance), (2, 2));
        } else {
            assert_eq!(bits_of(a), bits_of(b), "pixel {i} changed");
        }
    }
    // 0.01 (under a pixel) reaches no hole pixel's far side
    assert_eq!(bits(&repaired(0.01, 1)), bits(&open));
}

#[test]
fn the_cluster_filter_removes_small_blobs_and_nothing_else() {
    // a plane at 0.6 m and, floating before it, squares of 1 cm (100 mm², class 2) and 4 cm
    // (1600 mm², class 3) seen face on
    let small = quad(
        Vec3::new(-0.05, 0.0, 0.55),
        Vec3::X * 5e-3,
        Vec3::Y * 5e-3,
        2,
        2,
    );
    let large = quad(
        Vec3::new(0.05, 0.0, 0.5),
        Vec3::X * 0.02,
        Vec3::Y * 0.02,
        3,
        3,
    );
    let world = World::new(&[small, large, facing_plane(0.6)]);
    let mut spec = tof_camera(Noise::default());
    let open = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    // a pixel is (z / 800)² of the surface: about 210 of the small square's
    assert!(
        (190..230).contains(&points_of(&open, 2)),
        "{}",
        points_of(&open, 2)
    );
    for (min_area, small_kept) in [(150.0, false), (50.0, true)] {
        spec.processing.filters.cluster.removal = ClusterRemoval {
            enabled: true,
            max_neighbor_distance: 10.0,
            min_area,
        };
        let filtered = scan(&world, &spec, &Affine3A::IDENTITY, 1);
        for (a, b) in open.pixels.iter().zip(&filtered.pixels) {
            if a.class == 2 && !small_kept {
                assert!(!b.is_valid(), "the small square stayed at {min_area} mm²");
                assert_eq!(a.instance, b.instance);
            } else {
                assert_eq!(bits_of(a), bits_of(b), "a point changed at {min_area} mm²");
            }
        }
    }
    // joined to the plane within the distance, the square is part of a large cluster
    spec.processing
        .filters
        .cluster
        .removal
        .max_neighbor_distance = 100.0;
    spec.processing.filters.cluster.removal.min_area = 150.0;
    let joined = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    assert_eq!(points_of(&joined, 2), points_of(&open, 2));
}

/// A plane facing the camera at `z` with, flush on it, a dark square `side` m wide at the
/// image's centre (class 2: the noise filter removes it), scanned with hole repair at
/// `hole_size`: the share of the square's pixels filled.
fn filled_share(z: f32, side: f32, hole_size: f32) -> f64 {
    let mut dark = quad(
        Vec3::new(0.0, 0.0, z - 1e-5),
        Vec3::X * side / 2.0,
        Vec3::Y * side / 2.0,
        2,
        2,
    );
    dark.material.reflectivity = 0.005;
    let world = World::new(&[dark, facing_plane(z)]);
    let mut spec = exact_and_noise_filtered();
    spec.processing.filters.hole.repair = HoleRepair {
        enabled: true,
        hole_size,
        strictness: 2,
    };
    let s = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    let hole: Vec<&Pixel> = s.pixels.iter().filter(|p| p.class == 2).collect();
    assert!(hole.len() > 50, "{} pixels", hole.len());
    hole.iter().filter(|p| p.is_valid()).count() as f64 / hole.len() as f64
}

#[test]
fn hole_repair_fills_holes_up_to_its_size_times_a_tenth_of_their_distance() {
    // Zivid's hole size is relative and scales with the distance: at 0.2 the widest hole is
    // 12 mm at 0.6 m and 24 mm at 1.2 m
    for z in [0.6f32, 1.2] {
        let widest = 0.2 * HoleRepair::SCALE * z;
        assert_eq!(filled_share(z, 0.8 * widest, 0.2), 1.0, "at {z} m");
        let wide = filled_share(z, 2.0 * widest, 0.2);
        assert!(
            wide < 0.8,
            "at {z} m: {wide} of a hole twice the widest filled"
        );
    }
    // a projector's shadow 55 mm wide at 0.6 m stays open
    assert_eq!(filled_share(0.6, 0.055, 0.2), 0.0);
}

/// Whether the cluster filter (normalised distance 10, 150 mm²) keeps a 1 cm square floating
/// `gap` m before a plane facing the camera at `z`.
fn floating_square_kept(z: f32, gap: f32) -> bool {
    let square = quad(
        Vec3::new(0.0, 0.0, z - gap),
        Vec3::X * 5e-3,
        Vec3::Y * 5e-3,
        2,
        2,
    );
    let world = World::new(&[square, facing_plane(z)]);
    let mut spec = tof_camera(Noise::default());
    spec.processing.filters.cluster.removal = ClusterRemoval {
        enabled: true,
        max_neighbor_distance: 10.0,
        min_area: 150.0,
    };
    let s = scan(&world, &spec, &Affine3A::IDENTITY, 1);
    points_of(&s, 2) > 0
}

#[test]
fn the_cluster_filters_neighbour_distance_scales_with_depth() {
    // 10 spacings of neighbouring points: 7.5 mm at 0.6 m (f 800 px), 15 mm at 1.2 m; a
    // square joined to the plane behind it belongs to a large cluster and stays
    assert!(floating_square_kept(0.6, 0.005));
    assert!(floating_square_kept(1.2, 0.005));
    assert!(!floating_square_kept(0.6, 0.011));
    assert!(floating_square_kept(1.2, 0.011));
    assert!(!floating_square_kept(1.2, 0.02));
}

#[test]
fn gaussian_smoothing_lowers_the_noise_as_its_weights_do_and_keeps_a_plane() {
    let sigma = 1.5f32;
    let smoothing = |spec: &mut SensorSpec| {
        spec.processing.filters.smoothing.gaussian = Gaussian {
            enabled: true,
            sigma,
        }
    };
    // white noise of 1 mm along the rays of a facing plane: the weights' own ratio
    let noise = Noise {
        axial: Axial {
            sigma: 1e-3,
            ..Axial::default()
        },
        ..Noise::default()
    };
    let mut spec = tof_camera(noise);
    smoothing(&mut spec);
    let s = scan(
        &World::new(&[facing_plane(1.0)]),
        &spec,
        &Affine3A::IDENTITY,
        7,
    );
    let interior = |s: &Scan| -> Vec<Pixel> {
        (8..392)
            .flat_map(|r| s.pixels[r * 500 + 8..r * 500 + 492].to_vec())
            .collect()
    };
    let errors: Vec<f64> = interior(&s)
        .iter()
        .map(|p| f64::from(p.point.z - p.clean.z))
        .collect();
    let (_, sd) = mean_std(&errors);
    let radius = (2.5 * sigma).ceil() as i32;
    let taps: Vec<f64> = (-radius..=radius)
        .map(|k| (-0.5 * (k as f64 / f64::from(sigma)).powi(2)).exp())
        .collect();
    let (sum, squares): (f64, f64) = (taps.iter().sum(), taps.iter().map(|t| t * t).sum());
    let expected = 1e-3 * squares / (sum * sum); // sqrt(Σw²)/Σw in 2D, of separable weights
    assert!((sd / expected - 1.0).abs() < 0.05, "σ {sd} vs {expected}");
    // a tilted plane without noise keeps its points (inverse depth is linear in the image),
    // and every pixel its labels and whether it has a point
    let tilted = quad(
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 0.6) * 3.0,
        Vec3::Y * 3.0,
        1,
        1,
    );
    let world = World::new(&[tilted]);
    let mut exact = tof_camera(Noise::default());
    let plain = scan(&world, &exact, &Affine3A::IDENTITY, 1);
    smoothing(&mut exact);
    let smoothed = scan(&world, &exact, &Affine3A::IDENTITY, 1);
    for (a, b) in interior(&plain).iter().zip(&interior(&smoothed)) {
        assert!(
            (a.point - b.point).length() < 1e-6 * a.point.length(),
            "{a:?} {b:?}"
        );
    }
    for (a, b) in plain.pixels.iter().zip(&smoothed.pixels) {
        assert_eq!(
            (a.is_valid(), a.class, a.instance),
            (b.is_valid(), b.class, b.instance)
        );
        assert!(!a.is_valid() || b.point.normalize().dot(a.point.normalize()) > 1.0 - 1e-6);
    }
}

#[test]
fn noise_suppression_smooths_weak_signal_and_keeps_steps_and_strong_signal() {
    use ::sensor::spec::Suppression;
    let spec = structured(snr_noise());
    let mut suppressed = spec.clone();
    suppressed.processing.filters.noise.suppression.enabled = true;
    let pose = Affine3A::IDENTITY;
    // a dark plane (SNR under the filter's level everywhere): its noise falls 3× or more, each
    // point on its ray
    let dark = plane(0.6, 0.05);
    let (raw, smooth) = (
        scan(&dark, &spec, &pose, 4),
        scan(&dark, &suppressed, &pose, 4),
    );
    assert!(raw.valid_count() > 150_000);
    assert_eq!(raw.valid_count(), smooth.valid_count());
    for (a, b) in raw.pixels.iter().zip(&smooth.pixels) {
        if a.is_valid() {
            assert!(a.snr < Suppression::BELOW, "SNR {}", a.snr);
            assert!(a.point.normalize().cross(b.point.normalize()).length() < 1e-6);
        }
    }
    let (mean, before) = mean_std(&z_scores(&raw, |_| 1.0));
    let (_, after) = mean_std(&z_scores(&smooth, |_| 1.0));
    eprintln!("dark plane: σ {before:e} → {after:e}, mean {mean:e}");
    assert!(after * 3.0 < before, "σ {before} → {after}");
    // a well lit plane: untouched
    let white = plane(0.6, 1.0);
    let (raw, smooth) = (
        scan(&white, &spec, &pose, 4),
        scan(&white, &suppressed, &pose, 4),
    );
    assert!(
        raw.pixels
            .iter()
            .all(|p| !p.is_valid() || p.snr >= Suppression::BELOW)
    );
    assert_eq!(bits(&raw), bits(&smooth));
    // a dark step of 2 cm (about 12σ): the rows beside it keep to their own surface (a mean
    // over the step would pull them millimetres towards the other)
    let (mut upper, mut lower) = (
        quad(
            Vec3::new(0.0, -2.5, 0.6),
            Vec3::X * 5.0,
            Vec3::Y * 2.5,
            2,
            2,
        ),
        facing_plane(0.62),
    );
    upper.material.reflectivity = 0.05;
    lower.material.reflectivity = 0.05;
    let step = World::new(&[upper, lower]);
    let smooth = scan(&step, &suppressed, &pose, 4);
    let w = smooth.width as usize;
    let edge = smooth.pixels.iter().position(|p| p.class != 2).unwrap() / w;
    for row in edge - 3..edge + 3 {
        let errors: Vec<f64> = smooth.pixels[row * w..(row + 1) * w]
            .iter()
            .filter(|p| p.is_valid())
            .map(|p| (p.point.z - p.clean.z) as f64)
            .collect();
        let (mean, _) = mean_std(&errors);
        assert!(errors.len() > 400 && mean.abs() < 2e-4, "row {row}: {mean}");
    }
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
