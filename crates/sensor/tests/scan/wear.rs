//! Wear as the depth sensor and the colour image see it: rust is dark and matte, dust light and
//! matte, grease dark.

use ::sensor::wear::{Grain, Mask, Rust, Seats, Wear};
use ::sensor::*;
use glam::{Affine3A, Vec3};

/// A Zivid 2+ M60 scan of a stainless-steel sphere 0.55 m away, the sphere rusted over
/// `share` of its surface (none for 0).
fn pole_pot(share: f32, seed: u64) -> Scan {
    dirty_pole_pot(share, 0.0, 0.0, seed)
}

/// [`pole_pot`] with shares of dust and grease.
fn dirty_pole_pot(share: f32, dust: f32, grease: f32, seed: u64) -> Scan {
    let mut sphere = Target::from_triangles(
        &shapes::sphere(Vec3::new(0.0, 0.0, 0.55), 0.05, 64),
        2,
        2,
        materials::STAINLESS_STEEL,
    );
    // centimetres about the sphere's centre, as a motor part's
    let texture = Affine3A::from_scale(Vec3::splat(100.0))
        * Affine3A::from_translation(Vec3::new(0.0, 0.0, -0.55));
    sphere.wear = (share + dust + grease > 0.0).then(|| Wear {
        dust,
        grease,
        ..Wear::new(texture, Mask::Coverage { share }, Rust::new(1).unwrap())
    });
    let spec = SensorSpec::preset("zivid-2plus-m60").unwrap().binned(4);
    scan(&World::new(&[sphere]), &spec, &Affine3A::IDENTITY, seed)
}

/// (share of the sphere's pixels saturated, mean SNR of its points, mean wear of its pixels, mean
/// green of its colour).
fn statistics(s: &Scan) -> (f64, f64, f64, f64) {
    let saturation = SensorSpec::preset("zivid-2plus-m60")
        .unwrap()
        .noise
        .specular
        .saturation;
    let on: Vec<&Pixel> = s.pixels.iter().filter(|p| p.instance == 2).collect();
    let n = on.len() as f64;
    let lost = on
        .iter()
        .filter(|p| !p.is_valid() && p.intensity > saturation)
        .count() as f64
        / n;
    let valid: Vec<&&Pixel> = on.iter().filter(|p| p.is_valid()).collect();
    let snr = valid.iter().map(|p| f64::from(p.snr)).sum::<f64>() / valid.len() as f64;
    let wear = on.iter().map(|p| f64::from(p.wear) / 255.0).sum::<f64>() / n;
    let green = on.iter().map(|p| f64::from(p.rgb[1])).sum::<f64>() / n;
    (lost, snr, wear, green)
}

#[test]
fn rust_lowers_the_snr_and_the_saturated_share_of_stainless_steel() {
    let (clean_lost, clean_snr, clean_wear, _) = statistics(&pole_pot(0.0, 3));
    let (rust_lost, rust_snr, rust_wear, _) = statistics(&pole_pot(1.0, 3));
    assert_eq!(clean_wear, 0.0);
    assert!(rust_wear > 0.99, "wear {rust_wear}");
    // the clean sphere's highlight saturates and leaves a hole; rust has none
    assert!(clean_lost > 0.002, "clean: {clean_lost} lost");
    assert!(
        rust_lost < clean_lost / 4.0,
        "lost {rust_lost} vs {clean_lost}"
    );
    assert!(rust_snr < 0.8 * clean_snr, "SNR {rust_snr} vs {clean_snr}");
}

#[test]
fn the_wear_channel_is_the_share_of_rust_and_follows_the_coverage() {
    let mut last = 0.0;
    for share in [0.2, 0.5, 0.8] {
        let (_, _, wear, _) = statistics(&pole_pot(share, 1));
        // a hemisphere of a few noise periods: the share seen is near the share drawn
        assert!((wear - f64::from(share)).abs() < 0.2, "{share}: {wear}");
        assert!(wear > last, "{share}: {wear} after {last}");
        last = wear;
    }
    let s = pole_pot(0.5, 1);
    let cloud = s.cloud(false, Frame::Camera, Units::Metres);
    assert!(cloud.wear.contains(&0.0) && cloud.wear.contains(&1.0));
    assert_eq!(
        s.pixels
            .iter()
            .filter(|p| p.instance == 0)
            .map(|p| u32::from(p.wear))
            .sum::<u32>(),
        0
    );
}

#[test]
fn the_same_seed_gives_the_same_rust() {
    let (a, b) = (pole_pot(0.5, 9), pole_pot(0.5, 9));
    assert!(
        a.pixels
            .iter()
            .zip(&b.pixels)
            .all(|(p, q)| p.wear == q.wear && p.rgb == q.rgb)
    );
}

#[test]
fn dust_hides_the_highlights_and_grease_darkens_without_counting_as_rust() {
    let (clean_lost, _, _, clean_green) = statistics(&pole_pot(0.0, 4));
    let (dust_lost, _, dust_wear, dust_green) = statistics(&dirty_pole_pot(0.0, 1.0, 0.0, 4));
    let (_, _, grease_wear, grease_green) = statistics(&dirty_pole_pot(0.0, 0.0, 1.0, 4));
    assert!(
        dust_lost < clean_lost / 4.0,
        "lost {dust_lost} vs {clean_lost}"
    );
    assert!(
        grease_green < 0.7 * clean_green,
        "green {grease_green} vs {clean_green}"
    );
    assert!(
        dust_green > grease_green,
        "dust {dust_green}, grease {grease_green}"
    );
    assert_eq!((dust_wear, grease_wear), (0.0, 0.0));
}

/// A stainless-steel square of 20 cm facing the camera 0.6 m away, instance 2.
fn steel_plane() -> Target {
    Target::from_triangles(
        &shapes::rectangle(Vec3::new(0.0, 0.0, 0.6), Vec3::X * 0.1, Vec3::Y * 0.1),
        2,
        2,
        materials::STAINLESS_STEEL,
    )
}

/// Rust kept to a seat rusts only within the seat's radius of its centre.
#[test]
fn a_seat_keeps_the_rust_to_its_disc() {
    let mut plane = steel_plane();
    // centimetres about the plane's centre; one seat of 2 cm at (3 cm, 0)
    let texture = Affine3A::from_scale(Vec3::splat(100.0))
        * Affine3A::from_translation(Vec3::new(0.0, 0.0, -0.6));
    plane.wear = Some(Wear {
        seats: Some(Seats::new(&[Vec3::new(3.0, 0.0, 0.0)], 2.0)),
        ..Wear::new(
            texture,
            Mask::Coverage { share: 1.0 },
            Rust::new(3).unwrap(),
        )
    });
    let spec = SensorSpec::preset("zivid-2plus-m60").unwrap().binned(4);
    let s = scan(&World::new(&[plane]), &spec, &Affine3A::IDENTITY, 1);
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for p in s.pixels.iter().filter(|p| p.instance == 2) {
        let d = (p.clean * 100.0 - Vec3::new(3.0, 0.0, 60.0)).length();
        if d < 1.3 {
            inside.push(p.wear);
        } else if d > 2.05 {
            outside.push(p.wear);
        }
    }
    assert!(inside.len() > 50 && inside.iter().all(|&w| w == 255));
    assert!(outside.len() > 1000 && outside.iter().all(|&w| w == 0));
}

/// Drawn steel's streaks run along the texture's z: neighbouring pixels across them differ,
/// along them hardly.
#[test]
fn drawn_steel_is_streaked_along_its_axis() {
    let mut plane = steel_plane();
    // centimetres, the streaks' axis (texture z) along the camera's y
    let texture = Affine3A::from_scale(Vec3::splat(100.0))
        * Affine3A::from_rotation_x(std::f32::consts::FRAC_PI_2);
    plane.wear = Some(Wear {
        grain: Grain::Drawn,
        ..Wear::new(
            texture,
            Mask::Coverage { share: 0.0 },
            Rust::new(1).unwrap(),
        )
    });
    let mut spec = SensorSpec::preset("zivid-2plus-m60").unwrap().binned(4);
    spec.colour.noise = 0.0;
    let s = scan(&World::new(&[plane]), &spec, &Affine3A::IDENTITY, 1);
    let w = s.width as usize;
    let green = |k: usize| f64::from(s.pixels[k].rgb[1]);
    let (mut across, mut along, mut n) = (0.0, 0.0, 0);
    for k in 0..s.pixels.len() - w - 1 {
        let near = [k, k + 1, k + w].iter().all(|&i| {
            let p = &s.pixels[i];
            p.instance == 2 && p.clean.x.abs() < 0.02 && p.clean.y.abs() < 0.02
        });
        if near {
            across += (green(k + 1) - green(k)).abs();
            along += (green(k + w) - green(k)).abs();
            n += 1;
        }
    }
    assert!(n > 1000, "{n} pixels");
    assert!(across > 3.0 * along, "across {across}, along {along}");
}
