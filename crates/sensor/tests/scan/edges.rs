//! Zivid's errors at edges by their statistics: wings from the lens's blur of the stripes, and
//! the contrast distortion beside bright steps with Zivid's filters for it.

use ::sensor::spec::Correction;
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

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
