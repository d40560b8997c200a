use glam::Vec3;

use super::Mask;
use super::pattern::{Ramp, fbm_colour, luminance, voronoi_colour};

/// A 16-bit RGB pass of `fidelity/appearance/reference/pattern-<name>.png`: its size and its
/// pixels as raw values 0..1.
fn pass(name: &str) -> (usize, Vec<Vec3>) {
    let path = format!(
        "{}/../../fidelity/appearance/reference/pattern-{name}.png",
        env!("CARGO_MANIFEST_DIR")
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.bit_depth, png::BitDepth::Sixteen);
    let channels = info.color_type.samples();
    let values: Vec<f32> = buf[..info.buffer_size()]
        .chunks(2)
        .map(|b| f32::from(u16::from_be_bytes([b[0], b[1]])) / 65535.0)
        .collect();
    let pixels = values
        .chunks(channels)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    (info.width as usize, pixels)
}

/// The share of `name`'s pixels where `ours` (at the pixel centre's world point) is within
/// 1/1000 of Cycles'.
fn agreement(name: &str, ours: impl Fn(Vec3) -> Vec3) -> f64 {
    let (n, pixels) = pass(name);
    // scenes.json's "pattern": a 6-unit square from (-3.1, 2.7)
    let step = 6.0 / n as f32;
    let close = pixels
        .iter()
        .enumerate()
        .filter(|(k, want)| {
            let (i, j) = ((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
            let p = Vec3::new(-3.1 + i * step, 2.7 - j * step, 0.0);
            (ours(p) - **want).abs().max_element() < 1e-3
        })
        .count();
    close as f64 / pixels.len() as f64
}

const THRESHOLD: f32 = 0.144_404_34; // the pattern scene's percent / num (40 / 277)

#[test]
fn the_noise_is_blenders() {
    let share = agreement("noise", |p| fbm_colour(0.5 * p, 2.0, 0.833));
    assert_eq!(share, 1.0);
}

#[test]
fn the_voronoi_cells_are_blenders() {
    // a pixel whose centre lies within a sample's jitter of a cell's edge may differ
    let share = agreement("cells", |p| voronoi_colour(2.0 * p));
    assert!(share > 0.99, "{share}");
}

#[test]
fn the_addon_mask_and_its_stages_are_blenders() {
    let ramped = |p: Vec3| {
        let c =
            Ramp([(THRESHOLD, 0.0), (0.909, 1.0)]).at(luminance(fbm_colour(0.5 * p, 16.0, 0.833)));
        Vec3::splat(c)
    };
    let share = agreement("voronoi", |p| voronoi_colour(2.0 * ramped(p)));
    assert!(share > 0.99, "{share}");
    let mask = Mask::Addon {
        threshold: THRESHOLD,
    };
    let share = agreement("mask", |p| Vec3::splat(mask.share(p)));
    assert!(share > 0.99, "{share}");
}

/// The deviations the rust's and the grain's noises are scaled by are the noises' own.
#[test]
fn the_noises_deviations_are_measured() {
    for (detail, roughness, sigma) in [
        (3.0f32, 0.6f32, super::RUST_NOISE_SIGMA),
        (2.0, 0.5, super::grain::NOISE_SIGMA),
    ] {
        let v: Vec<f64> = (0..100_000u32)
            .map(|k| {
                let (i, j, l) = (k % 47, (k / 47) % 47, k / 2209);
                let p = Vec3::new(i as f32 * 0.731, j as f32 * 0.517, l as f32 * 0.613);
                f64::from(super::pattern::fbm(p, detail, roughness))
            })
            .collect();
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let s = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt();
        assert!((m - 0.5).abs() < 0.005, "{m}");
        assert!(
            (s / f64::from(sigma) - 1.0).abs() < 0.03,
            "{detail}: {s} vs {sigma}"
        );
    }
}
