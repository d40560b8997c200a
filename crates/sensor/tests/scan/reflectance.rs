//! How materials return the light: the specular lobe's energy, and the signal and SNR that a
//! material's reflectivity and sheen give together.

use ::sensor::materials::{BLACK_PA66, GREY_PLASTIC, WHITE_PLASTIC};
use ::sensor::noise::{Lobe, Specular};
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

/// The share of the light a lobe returns over the hemisphere, lit from `incidence` radians off
/// the normal: the highlight's signal (1 = a white diffuse surface, albedo 1) averaged over the
/// outgoing directions, weighted by their cosine.
fn lobe_albedo(lobe: &Lobe, incidence: f64) -> f64 {
    let highlight = Specular { saturation: 1.0 };
    let light = Vec3::new(incidence.sin() as f32, 0.0, incidence.cos() as f32);
    let (n_theta, n_phi) = (2000, 720);
    let mut sum = 0.0;
    for i in 0..n_theta {
        let theta = (i as f64 + 0.5) / n_theta as f64 * std::f64::consts::FRAC_PI_2;
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) / n_phi as f64 * std::f64::consts::TAU;
            let out = Vec3::new(
                (theta.sin() * phi.cos()) as f32,
                (theta.sin() * phi.sin()) as f32,
                theta.cos() as f32,
            );
            let half = (light + out).normalize();
            let signal = highlight.highlight(lobe, half.z, 1.0) as f64;
            sum += signal * theta.cos() * theta.sin();
        }
    }
    let cell = std::f64::consts::FRAC_PI_2 / n_theta as f64 * std::f64::consts::TAU / n_phi as f64;
    sum * cell / std::f64::consts::PI
}

#[test]
fn a_lobe_returns_the_specular_share_its_material_states_and_never_more() {
    let library = MATERIALS
        .iter()
        .map(|&(_, m)| m)
        .filter(|m| m.specular > 0.0);
    let lobes = [0.02f32, 0.1, 0.3, 0.8, 2.0, std::f32::consts::PI].map(|lobe| Material {
        specular: 0.5,
        lobe,
        ..Material::default()
    });
    for m in library.chain(lobes) {
        let lobe = Lobe::of(&m);
        let straight = lobe_albedo(&lobe, 0.0);
        let specular = f64::from(m.specular);
        assert!(
            (straight / specular - 1.0).abs() < 0.01,
            "{m:?}: {straight}"
        );
        for degrees in [20.0f64, 45.0, 70.0, 85.0] {
            let oblique = lobe_albedo(&lobe, degrees.to_radians());
            assert!(oblique <= specular * 1.01, "{m:?} at {degrees}°: {oblique}");
        }
    }
}

/// The Zivid 2+ M60: its optics about the axis, on `side`×`side` pixels.
fn m60_about_the_axis(side: u32) -> SensorSpec {
    let m60 = SensorSpec::preset("zivid-2plus-m60").unwrap();
    let centre = (f64::from(side) - 1.0) / 2.0;
    let k = Intrinsics {
        width: side,
        height: side,
        cx: centre,
        cy: centre,
        distortion: Distortion::default(),
        ..m60.intrinsics
    };
    SensorSpec {
        intrinsics: k,
        ..m60
    }
}

/// The median SNR of the Zivid 2+ M60's pixels on a plane of `material` 0.6 m away, tilted by
/// `tilt` radians about the camera's x axis.
fn median_snr(material: Material, tilt: f32) -> f32 {
    let spec = m60_about_the_axis(160);
    let mut plane = quad(
        Vec3::new(0.0, 0.0, 0.6),
        Vec3::X * 0.2,
        Vec3::new(0.0, tilt.cos(), tilt.sin()) * 0.2,
        1,
        1,
    );
    plane.material = material;
    let s = scan(&World::new(&[plane]), &spec, &Affine3A::IDENTITY, 1);
    let mut snr: Vec<f32> = s
        .pixels
        .iter()
        .filter(|p| p.is_valid())
        .map(|p| p.snr)
        .collect();
    assert!(snr.len() > 10_000, "{} points", snr.len());
    snr.sort_by(f32::total_cmp);
    snr[snr.len() / 2]
}

#[test]
fn black_plastic_returns_a_weaker_signal_than_grey_and_grey_than_white() {
    for degrees in [0.0f32, 20.0, 45.0, 70.0] {
        let tilt = degrees.to_radians();
        let [black, grey, white] =
            [BLACK_PA66, GREY_PLASTIC, WHITE_PLASTIC].map(|m| median_snr(m, tilt));
        assert!(
            black < grey && grey < white,
            "at {degrees}°: black {black}, grey {grey}, white {white}"
        );
    }
}

/// A Zivid 2+ M60 (its optics on 400×400 pixels, the contrast-distortion correction off and
/// the removal at `removal`, if given) facing a stainless-steel sphere 3 cm across 0.6 m away:
/// the mean depth error, mm, of its points 1 to 5 px from the highlight's saturated core on
/// each side of it (left, right, above, below), and the 90th percentile of the absolute error of
/// those points and of those 8 to 20 px from it (beyond the blur's reach, as steep).
fn highlight_neighbours(removal: Option<f32>) -> ([f64; 4], f64, f64) {
    let mut spec = m60_about_the_axis(400);
    let filters = &mut spec.processing.filters.experimental.contrast_distortion;
    filters.correction.enabled = false;
    if let Some(threshold) = removal {
        filters.removal.enabled = true;
        filters.removal.threshold = threshold;
    }
    let mut ball = sphere(Vec3::new(0.0, 0.0, 0.6), 0.03, 128);
    ball.material = materials::STAINLESS_STEEL;
    let s = scan(&World::new(&[ball]), &spec, &Affine3A::IDENTITY, 1);
    let w = 400;
    let at = |i: usize| ((i / w) as f64, (i % w) as f64);
    let saturation = spec.noise.specular.saturation;
    let core: Vec<(f64, f64)> = (0..s.pixels.len())
        .filter(|&i| !s.pixels[i].is_valid() && s.pixels[i].intensity > saturation)
        .map(at)
        .collect();
    assert!(core.len() > 100, "{} saturated", core.len());
    let centre = core.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let centre = (centre.0 / core.len() as f64, centre.1 / core.len() as f64);
    let (mut sides, mut near, mut far) = ([(0.0, 0.0); 4], Vec::new(), Vec::new());
    for (i, p) in s.pixels.iter().enumerate().filter(|(_, p)| p.is_valid()) {
        let (r, c) = at(i);
        let d = core
            .iter()
            .map(|q| (q.0 - r).hypot(q.1 - c))
            .fold(f64::MAX, f64::min);
        let error = f64::from(p.point.z - p.clean.z) * 1000.0;
        if (8.0..20.0).contains(&d) {
            far.push(error.abs());
        } else if (0.5..5.5).contains(&d) {
            near.push(error.abs());
            let (dr, dc) = (r - centre.0, c - centre.1);
            let side = match (dc.abs() > dr.abs(), dc < 0.0, dr < 0.0) {
                (true, true, _) => 0,
                (true, false, _) => 1,
                (false, _, true) => 2,
                (false, _, false) => 3,
            };
            sides[side].0 += error;
            sides[side].1 += 1.0;
        }
    }
    let p90 = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() * 9 / 10]
    };
    (sides.map(|(sum, n)| sum / n), p90(&mut near), p90(&mut far))
}

#[test]
fn a_highlight_bleeds_into_its_neighbours_along_the_baseline() {
    // the lens blurs the highlight's far brighter stripes into the pixels beside its core:
    // they decode a phase pulled towards it across the baseline (x), not along it (y), and
    // its light's noise with it
    let ([left, right, above, below], near, far) = highlight_neighbours(None);
    assert!(left - right > 0.3, "left {left} mm, right {right} mm");
    assert!(
        (above - below).abs() < 0.1,
        "above {above} mm, below {below} mm"
    );
    assert!(
        near > 1.4 * far,
        "90th percentile: near {near} mm, far {far} mm"
    );
    // Zivid's contrast-distortion removal takes the pulled points, more at a higher threshold
    let pull = left - right;
    let mut last = pull;
    for threshold in [0.5, 0.9] {
        let ([left, right, ..], ..) = highlight_neighbours(Some(threshold));
        assert!(
            left - right <= last,
            "{threshold}: {} mm after {last} mm",
            left - right
        );
        last = left - right;
    }
    assert!(last < pull / 3.0, "{last} mm left of {pull} mm");
}
