//! The camera's colour image: shading, the flash's shadows and highlights, the image pixel for
//! pixel with the points, Zivid's 3D-only pink and the R line's grey.

use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

fn linear(v: u8) -> f64 {
    let x = f64::from(v) / 255.0;
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

fn lambert(colour: [f32; 3]) -> Material {
    Material {
        colour,
        ior_level: 0.0,
        ..Material::default()
    }
}

/// A Lambertian surface lit by the camera's own light (a sensor without a projector) records
/// albedo × (light × exposure + ambient × the ambient light's colour): decoded from sRGB, the
/// residual has zero mean and the camera's deviation on every channel.
#[test]
fn a_lambertian_surface_records_its_albedo_under_the_light_with_the_cameras_noise() {
    let albedo = [0.5, 0.25, 0.1];
    let mut plane = facing_plane(1.0);
    plane.material = lambert(albedo);
    let tof = tof_camera(Noise::default());
    let s = scan(&World::new(&[plane]), &tof, &Affine3A::IDENTITY, 9);
    let c = tof.colour;
    let ambient = c.ambient_colour();
    for (k, albedo) in albedo.into_iter().enumerate() {
        let residual: Vec<f64> = s
            .pixels
            .iter()
            .filter(|p| p.is_valid())
            .map(|p| {
                let light = f64::from(p.intensity / plane_reflectivity());
                let expected = f64::from(albedo)
                    * (light * f64::from(c.exposure) + f64::from(c.ambient * ambient[k]));
                linear(p.rgb[k]) - expected
            })
            .collect();
        let (m, sd) = mean_std(&residual);
        assert!(m.abs() < 2e-3, "channel {k}: mean {m}");
        assert!(
            (sd / f64::from(c.noise) - 1.0).abs() < 0.15,
            "channel {k}: deviation {sd}"
        );
    }
}

fn plane_reflectivity() -> f32 {
    Material::default().reflectivity
}

/// A plane 0.6 m in front of the camera, red for x < 0 and blue for x > 0.
fn red_and_blue() -> World {
    let half = |x: f32, colour, instance| Target {
        material: lambert(colour),
        ..quad(
            Vec3::new(x, 0.0, 0.6),
            Vec3::X * 0.5,
            Vec3::Y * 1.0,
            1,
            instance,
        )
    };
    World::new(&[
        half(-0.5, [0.6, 0.05, 0.05], 1),
        half(0.5, [0.05, 0.05, 0.6], 2),
    ])
}

fn m60(name: &str) -> SensorSpec {
    SensorSpec::preset(name).unwrap().binned(4)
}

fn rgb_png(s: &Scan) -> Vec<u8> {
    let mut bytes = Vec::new();
    formats::write_rgb_png(&mut bytes, s).unwrap();
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut data = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut data).unwrap();
    assert_eq!((info.width, info.height), (s.width, s.height));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    data
}

#[test]
fn a_zivid_colour_image_is_pixel_for_pixel_with_its_points() {
    let s = scan(
        &red_and_blue(),
        &m60("zivid-2plus-m60"),
        &Affine3A::IDENTITY,
        3,
    );
    let image = rgb_png(&s);
    let (mut red, mut blue) = (0, 0);
    for (k, p) in s.pixels.iter().enumerate() {
        let at = &image[3 * k..3 * k + 3];
        assert_eq!(at, p.rgb, "pixel {k}");
        // a point in the flash has the colour of the half its pixel's centre ray meets (points
        // beyond the flash's field, made of the blurred light of their neighbours, have the
        // ambient light's)
        if p.clean.x.abs() < 1e-3 || !p.is_valid() || p.intensity < 0.1 {
            continue;
        }
        if p.clean.x < 0.0 {
            assert!(at[0] > 2 * at[2], "pixel {k} on red: {at:?}");
            red += 1;
        } else {
            assert!(at[2] > 2 * at[0], "pixel {k} on blue: {at:?}");
            blue += 1;
        }
    }
    assert!(
        red > 10_000 && blue > 10_000,
        "points {red} red, {blue} blue"
    );
}

#[test]
fn a_3d_only_capture_is_pink_and_the_r_line_records_grey() {
    let world = red_and_blue();
    let mut three_d = m60("zivid-2plus-m60");
    three_d.colour.capture = ColourCapture::ThreeD;
    let pink = scan(&world, &three_d, &Affine3A::IDENTITY, 3);
    assert!(pink.valid_count() > 20_000);
    assert!(pink.pixels.iter().all(|p| p.rgb == [200, 50, 200]));
    let grey = scan(&world, &m60("zivid-2plus-mr60"), &Affine3A::IDENTITY, 3);
    assert!(grey.valid_count() > 20_000);
    assert!(
        grey.pixels
            .iter()
            .all(|p| p.rgb[0] == p.rgb[1] && p.rgb[1] == p.rgb[2])
    );
    // not black: the red and the blue half in their own greys
    let mean = |x: f32| {
        let v: Vec<f64> = grey
            .pixels
            .iter()
            .filter(|p| (p.clean.x - x).abs() < 0.05)
            .map(|p| f64::from(p.rgb[0]))
            .collect();
        mean_std(&v).0
    };
    let (on_red, on_blue) = (mean(-0.1), mean(0.1));
    assert!(
        on_red > 40.0 && on_blue > 20.0 && on_red > on_blue,
        "{on_red} {on_blue}"
    );
}

/// The flash's shadow beside a box on a plane is lit by the ambient light alone, and a metal
/// sphere mirrors the flash into a saturated highlight.
#[test]
fn the_flash_casts_shadows_and_shiny_metal_saturates() {
    let spec = structured(Noise::default());
    let block = Target::from_triangles(
        &shapes::sphere(Vec3::new(0.0, 0.0, 0.55), 0.04, 48),
        2,
        2,
        materials::STAINLESS_STEEL,
    );
    let mut plane = facing_plane(0.6);
    plane.material = lambert([0.5; 3]);
    let s = scan(&World::new(&[plane, block]), &spec, &Affine3A::IDENTITY, 5);
    let on_plane = |lit: bool| -> Vec<f64> {
        s.pixels
            .iter()
            .filter(|p| p.instance == 1 && (p.intensity > 0.0) == lit)
            .map(|p| linear(p.rgb[1]))
            .collect()
    };
    let (lit, shadow) = (on_plane(true), on_plane(false));
    assert!(shadow.len() > 200, "{} shadowed pixels", shadow.len());
    let (lit, shadow) = (mean_std(&lit).0, mean_std(&shadow).0);
    // in the shadow only the ambient light: 0.15 × the ambient's green × 0.5
    let ambient = f64::from(spec.colour.ambient * spec.colour.ambient_colour().y) * 0.5;
    assert!(
        (shadow / ambient - 1.0).abs() < 0.05,
        "shadow {shadow}, ambient {ambient}"
    );
    assert!(lit > 4.0 * shadow, "lit {lit}, shadow {shadow}");
    let saturated = s
        .pixels
        .iter()
        .filter(|p| p.instance == 2 && p.rgb == [255; 3])
        .count();
    assert!(saturated > 3, "{saturated} saturated pixels on the sphere");
}

/// Blensor's time-of-flight scanner records each material's own colour, unlit and exact.
#[test]
fn the_blensor_tof_records_the_materials_colour_unlit() {
    let mut plane = facing_plane(1.0);
    plane.material = lambert([0.8, 0.1, 0.05]);
    let tof = SensorSpec::preset("blensor-tof").unwrap();
    let s = scan(&World::new(&[plane]), &tof, &Affine3A::IDENTITY, 2);
    let want = [0.8f32, 0.1, 0.05].map(render::srgb8);
    assert!(
        s.pixels
            .iter()
            .filter(|p| p.is_valid())
            .all(|p| p.rgb == want)
    );
}

/// The Kinect's RGB camera sits 2.5 cm beside its infrared camera: the plane behind a sphere
/// shows it a shadow of its own, where the registered image is black, and the infrared
/// projector does not light it (a plane's colour is even, the room's light alone).
#[test]
fn the_kinects_rgb_camera_beside_the_infrared_one_cannot_see_behind_a_sphere() {
    let mut plane = facing_plane(1.6);
    plane.material = lambert([0.5; 3]);
    let mut ball = sphere(Vec3::new(0.0, 0.0, 1.2), 0.1, 48);
    ball.material = lambert([0.5; 3]);
    let kinect = SensorSpec::preset("kinect-v1").unwrap();
    let s = scan(&World::new(&[plane, ball]), &kinect, &Affine3A::IDENTITY, 4);
    let on_plane: Vec<&Pixel> = s
        .pixels
        .iter()
        .filter(|p| p.instance == 1 && !p.clean.x.is_nan())
        .collect();
    let black = on_plane.iter().filter(|p| p.rgb == [0; 3]).count();
    // the hidden sliver lies on the sphere's -x side (the RGB camera is at +x)
    let hidden_x: Vec<f32> = on_plane
        .iter()
        .filter(|p| p.rgb == [0; 3])
        .map(|p| p.clean.x)
        .collect();
    assert!(black > 100, "{black} black pixels");
    assert!(hidden_x.iter().all(|&x| x < 0.0), "hidden at x > 0");
    let greens: Vec<f64> = on_plane
        .iter()
        .filter(|p| p.rgb != [0; 3])
        .map(|p| linear(p.rgb[1]))
        .collect();
    let (mean, sd) = mean_std(&greens);
    // 0.5 albedo × 0.5 ambient × the 4000 K light's green, the noise alone spreading it
    let expected = 0.25 * f64::from(kinect.colour.ambient_colour().y);
    assert!((mean / expected - 1.0).abs() < 0.05, "{mean} vs {expected}");
    assert!(sd < 2.0 * f64::from(kinect.colour.noise), "{sd}");
}
