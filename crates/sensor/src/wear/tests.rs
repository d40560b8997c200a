use glam::Vec3;

use super::pattern::{Ramp, fbm_colour, luminance, voronoi_colour};
use super::{Armature, ArmatureSurface, Mask};

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

/// An armature about the axis (0.3, -0.2): a core of radius 1.2 from z 1 to 3, a commutator
/// from z 4 to 5, eight bars.
const ARMATURE: Armature = Armature {
    axis: [0.3, -0.2],
    shaft_radius: 0.15,
    core_radius: 1.2,
    core: [1.0, 3.0],
    commutator: [4.0, 5.0],
    bars: 8,
    worn: 0.0,
    seed: 0,
};

/// The point at radius `r`, turned `turn` about the armature's axis, at height `z`.
fn around(r: f32, turn: f32, z: f32) -> Vec3 {
    Vec3::new(0.3 + r * turn.cos(), -0.2 + r * turn.sin(), z)
}

/// How many runs of `dark` values a sequence has.
fn runs(values: impl Iterator<Item = bool>) -> usize {
    let mut last = false;
    values
        .filter(|&dark| {
            let start = dark && !last;
            last = dark;
            start
        })
        .count()
}

#[test]
fn an_armatures_surfaces_lie_where_its_layout_puts_them() {
    use ArmatureSurface::*;
    for (r, z, want) in [
        (0.15, 0.5, Shaft),
        (0.15, 2.0, Shaft),
        (0.15, 3.5, Shaft),
        (1.0, 2.0, Laminations),
        (0.6, 1.0, Laminations),
        (1.2, 2.9, Laminations),
        (1.25, 2.0, Windings),
        (1.285, 1.5, Windings),
        (0.4, 4.5, Commutator),
        (0.3, 4.0, Commutator),
    ] {
        for turn in [0.0, 1.0, 4.0] {
            assert_eq!(ARMATURE.surface(around(r, turn, z)), want, "r {r}, z {z}");
        }
    }
}

#[test]
fn laminations_wires_and_bars_repeat_at_their_pitch() {
    let copper = crate::materials::COPPER;
    let brightness = |q: Vec3| luminance(Vec3::from(ARMATURE.material(&copper, q).colour));
    // 1.5 cm of the core along its axis: a dark seam at each of 30 sheets' faces
    let steel = luminance(Vec3::from(crate::materials::ELECTRICAL_STEEL.colour));
    let along: Vec<f32> = (0..15_000)
        .map(|k| brightness(around(1.2, 0.7, 1.2 + k as f32 * 1e-4)))
        .collect();
    let seams = runs(along.iter().map(|&b| b < 0.7 * steel));
    assert!((30..=31).contains(&seams), "{seams}");
    // and between the seams each sheet within 8 % of the steel's colour
    assert!(
        along
            .iter()
            .all(|&b| b < 0.7 * steel || (b / steel - 1.0).abs() <= 0.081),
        "{along:?}"
    );
    // a 1 cm arc of the windings: a groove between each of 33 wires
    let arc = 1.0 / 1.285;
    let across: Vec<f32> = (0..10_000)
        .map(|k| brightness(around(1.285, 0.2 + arc * k as f32 * 1e-4, 2.0)))
        .collect();
    let copper_y = luminance(Vec3::from(copper.colour));
    let grooves = runs(across.iter().map(|&b| b < 0.6 * copper_y));
    assert!((33..=34).contains(&grooves), "{grooves}");
    // a turn of the commutator: its eight bars, the mica between them dark
    let turn: Vec<f32> = (0..7200)
        .map(|k| {
            brightness(around(
                0.4,
                0.4 + k as f32 * std::f32::consts::TAU / 7200.0,
                4.5,
            ))
        })
        .collect();
    let gaps = runs(turn.iter().map(|&b| b < 0.1));
    assert_eq!(gaps, 8);
    let mica = turn.iter().filter(|&&b| b < 0.1).count() as f32 / turn.len() as f32;
    assert!((mica - super::GAP).abs() < 0.01, "{mica}");
}

#[test]
fn worn_bars_are_the_drawn_share_and_dark() {
    let copper = crate::materials::COPPER;
    let bars = |worn: f32, seed: u32| {
        let a = Armature {
            worn,
            seed,
            bars: 200,
            ..ARMATURE
        };
        // each bar's middle, halfway along the commutator
        (0..200)
            .map(|k| {
                let turn = (k as f32 + 0.55) / 200.0 * std::f32::consts::TAU;
                luminance(Vec3::from(
                    a.material(&copper, around(0.4, turn, 4.5)).colour,
                ))
            })
            .collect::<Vec<f32>>()
    };
    let clean = bars(0.0, 0);
    let darkest_clean = clean.iter().copied().fold(f32::INFINITY, f32::min);
    for (worn, seed) in [(0.3, 0), (0.3, 9), (0.7, 1)] {
        let seen = bars(worn, seed);
        let dark = seen.iter().filter(|&&l| l < darkest_clean / 3.0).count();
        assert!(
            (dark as f32 / 200.0 - worn).abs() < 0.08,
            "{worn} {seed}: {dark} of 200 dark"
        );
    }
    // another seed wears other bars
    assert_ne!(bars(0.3, 0), bars(0.3, 9));
    assert!(bars(1.0, 0).iter().all(|&l| l < darkest_clean / 3.0));
}
