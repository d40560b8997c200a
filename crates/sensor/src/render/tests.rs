use std::f32::consts::PI;

use glam::Vec3;

use super::*;
use crate::world::{Material, Target};
use crate::{look_at, shapes};

fn lambert(albedo: f32) -> Material {
    Material {
        colour: [albedo; 3],
        metallic: 0.0,
        ior_level: 0.0,
        ..Material::default()
    }
}

fn plane(material: Material) -> World {
    let tris = shapes::rectangle(Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 2.0);
    World::new(&[Target::from_triangles(&tris, 1, 1, material)])
}

fn above(height: f32) -> Affine3A {
    look_at(Vec3::new(0.0, 0.0, height), Vec3::ZERO, Vec3::Y).unwrap()
}

/// Mean radiance of the pixels whose centre ray meets the plane z = 0 within `radius` of the
/// origin, for a camera looking straight down from `height`.
fn centre_mean(image: &Image, camera: &Intrinsics, height: f32, radius: f32) -> Vec3 {
    let (mut sum, mut n) = (Vec3::ZERO, 0);
    for row in 0..image.height {
        for col in 0..image.width {
            let r = camera.ray(col as f64, row as f64);
            let on_plane = r * (height / r.z);
            if on_plane.truncate().length() < radius {
                sum += Vec3::from(image.pixels[(row * image.width + col) as usize]);
                n += 1;
            }
        }
    }
    sum / n as f32
}

#[test]
fn a_white_sphere_vanishes_in_a_white_furnace() {
    // a convex white object under uniform radiance 1 reflects radiance 1 everywhere: a
    // Lambertian one, a white metal and a white dielectric with its specular layer alike
    let environment = [1.0; 3];
    let camera = Intrinsics::from_fov(48, 48, 30.0, 30.0);
    let pose = look_at(Vec3::new(0.0, -2.0, 0.0), Vec3::ZERO, Vec3::Z).unwrap();
    for (name, material, tolerance) in [
        ("lambert", lambert(1.0), 0.01),
        (
            "rough metal",
            Material {
                colour: [1.0; 3],
                metallic: 1.0,
                roughness: 0.6,
                ..Material::default()
            },
            0.04,
        ),
        (
            "dielectric",
            Material {
                colour: [1.0; 3],
                ..Material::default()
            },
            0.04,
        ),
    ] {
        let sphere = shapes::sphere(Vec3::ZERO, 0.4, 48);
        let world = World::new(&[Target::from_triangles(&sphere, 1, 1, material)]);
        let lighting = Lighting {
            lights: vec![],
            environment,
        };
        let settings = Settings {
            samples: 256,
            ..Settings::default()
        };
        let image = render(&world, &camera, &pose, &lighting, &settings).unwrap();
        let mean = image.pixels.iter().map(|p| p[0]).sum::<f32>() / image.pixels.len() as f32;
        let worst = image
            .pixels
            .iter()
            .map(|p| (p[0] - 1.0).abs())
            .fold(0.0, f32::max);
        assert!(
            (mean - 1.0).abs() < tolerance,
            "{name}: mean {mean}, worst pixel off by {worst}"
        );
    }
}

#[test]
fn one_denoised_path_keeps_the_white_furnace_and_removes_its_noise() {
    // the rough metal and the dielectric scatter each path differently (a Lambertian white
    // returns exactly 1 along every path): one path per pixel is noisy, the denoised frame
    // keeps the furnace's 1 with a fraction of that noise
    let camera = Intrinsics::from_fov(96, 96, 30.0, 30.0);
    let pose = look_at(Vec3::new(0.0, -2.0, 0.0), Vec3::ZERO, Vec3::Z).unwrap();
    let lighting = Lighting {
        lights: vec![],
        environment: [1.0; 3],
    };
    for (name, metallic, roughness) in [("rough metal", 1.0, 0.6), ("dielectric", 0.0, 0.5)] {
        let material = Material {
            colour: [1.0; 3],
            metallic,
            roughness,
            ..Material::default()
        };
        let sphere = shapes::sphere(Vec3::ZERO, 0.4, 48);
        let world = World::new(&[Target::from_triangles(&sphere, 1, 1, material)]);
        let frame = |denoise| {
            let settings = Settings {
                samples: 1,
                denoise,
                ..Settings::default()
            };
            render(&world, &camera, &pose, &lighting, &settings).unwrap()
        };
        let (raw, denoised) = (frame(false), frame(true));
        // the sphere's pixels, away from its rim
        let on_sphere: Vec<usize> = (0..camera.width * camera.height)
            .map(|i| i as usize)
            .filter(|&i| {
                let (col, row) = (i % 96, i / 96);
                let r = camera.ray(col as f64, row as f64);
                let d = pose.transform_vector3(r);
                let o = pose.transform_point3(Vec3::ZERO);
                // distance of the ray from the centre below 0.35 (the radius is 0.4)
                (o - d * o.dot(d)).length() < 0.35
            })
            .collect();
        let stats = |image: &Image| {
            let v: Vec<f32> = on_sphere.iter().map(|&i| image.pixels[i][1]).collect();
            let mean = v.iter().sum::<f32>() / v.len() as f32;
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / v.len() as f32;
            (mean, var.sqrt())
        };
        let ((raw_mean, raw_std), (mean, std)) = (stats(&raw), stats(&denoised));
        assert!(
            (mean - 1.0).abs() < 0.04,
            "{name}: mean {mean} (raw {raw_mean})"
        );
        assert!(
            std < raw_std / 3.0,
            "{name}: deviation {std} against {raw_std} raw"
        );
    }
}

#[test]
fn light_blocks_keep_the_mean_and_each_pixels_colour() {
    // a plane, grey on the left and four times brighter on the right, under a point light and
    // the surroundings: the light traced at one pixel in nine, denoised and spread, gives each
    // side the mean every pixel's paths give, and keeps the sides four times apart to their
    // seam (the light divided by one albedo, multiplied by another)
    let half = |x0: f32, albedo: f32| {
        // half extents: each half 2 m wide, meeting at x = 0
        let tris = shapes::rectangle(Vec3::new(x0, 0.0, 0.0), Vec3::X, Vec3::Y * 2.0);
        Target::from_triangles(&tris, 1, 1, lambert(albedo))
    };
    let world = World::new(&[half(-1.0, 0.2), half(1.0, 0.8)]);
    let lighting = Lighting {
        lights: vec![Light::Point {
            position: [0.0, 0.0, 1.0],
            power: 20.0,
            colour: [1.0; 3],
        }],
        environment: [0.5; 3],
    };
    let camera = Intrinsics::from_fov(48, 48, 40.0, 40.0);
    let frame = |light_block| {
        let settings = Settings {
            samples: 64,
            denoise: true,
            light_block,
            ..Settings::default()
        };
        render(&world, &camera, &above(2.0), &lighting, &settings).unwrap()
    };
    // the mean of columns `cols` over the middle rows
    let mean = |image: &Image, cols: std::ops::Range<u32>| {
        let rows = 16..32;
        let sum: f32 = rows
            .clone()
            .flat_map(|r| cols.clone().map(move |c| (r * image.width + c) as usize))
            .map(|i| image.pixels[i][0])
            .sum();
        sum / (rows.len() * cols.len()) as f32
    };
    let (all, blocks) = (frame(1), frame(3));
    for cols in [8..23, 25..40] {
        let (a, b) = (mean(&all, cols.clone()), mean(&blocks, cols.clone()));
        assert!((b / a - 1.0).abs() < 0.02, "{cols:?}: {b} against {a}");
    }
    // the columns either side of the seam (column 23.5)
    let (left, right) = (mean(&blocks, 22..23), mean(&blocks, 25..26));
    assert!((right / left / 4.0 - 1.0).abs() < 0.05, "{right} / {left}");
    for invalid in [
        Settings {
            light_block: 0,
            denoise: true,
            ..Settings::default()
        },
        Settings {
            light_block: 9,
            denoise: true,
            ..Settings::default()
        },
        Settings {
            light_block: 2,
            ..Settings::default()
        },
    ] {
        assert!(render(&world, &camera, &above(2.0), &lighting, &invalid).is_err());
    }
}

#[test]
fn a_lambertian_plane_under_a_point_light_is_albedo_over_pi_times_irradiance() {
    // L = ρ/π · I cos θ / r², I = P / 4π; straight below a light 1 m up, cos θ = 1, r = 1
    let (albedo, power, height) = (0.5, 40.0, 1.0);
    let world = plane(lambert(albedo));
    let lighting = Lighting {
        lights: vec![Light::Point {
            position: [0.0, 0.0, height],
            power,
            colour: [1.0; 3],
        }],
        environment: [0.0; 3],
    };
    let camera = Intrinsics::from_fov(64, 64, 60.0, 60.0);
    let pose = above(2.0);
    let settings = Settings {
        samples: 4,
        bounces: 0,
        seed: 1,
        ..Settings::default()
    };
    let image = render(&world, &camera, &pose, &lighting, &settings).unwrap();
    for (col, row) in [(32, 32), (5, 40), (60, 3)] {
        // the analytic radiance at the point the pixel's centre ray meets (its four samples
        // spread over a footprint across which the radiance varies far less than the tolerance)
        let r = pose.transform_vector3(camera.ray(col as f64, row as f64));
        let p = Vec3::from(pose.translation) + r * (2.0 / -r.z);
        let d = Vec3::new(0.0, 0.0, height) - p;
        let expected = albedo / PI * power / (4.0 * PI) * (d.z / d.length()) / d.length_squared();
        let got = image.pixels[(row * 64 + col) as usize][0];
        assert!(
            (got / expected - 1.0).abs() < 0.02,
            "pixel ({col}, {row}): {got} against {expected}"
        );
    }
}

#[test]
fn a_rectangle_light_gives_the_irradiance_of_its_form_factor() {
    // a 0.2 m square of radiance L 0.5 m above a plane: the irradiance at the point below, by
    // integrating over the square
    let (albedo, power, height, half) = (0.8, 10.0, 0.5f32, 0.1f32);
    let world = plane(lambert(albedo));
    let lighting = Lighting {
        lights: vec![Light::Rect {
            centre: [0.0, 0.0, height],
            half_u: [0.0, half, 0.0],
            half_v: [half, 0.0, 0.0],
            power,
            colour: [1.0; 3],
        }],
        environment: [0.0; 3],
    };
    let camera = Intrinsics::from_fov(32, 32, 10.0, 10.0);
    let pose = above(1.0);
    let settings = Settings {
        samples: 256,
        bounces: 0,
        seed: 2,
        ..Settings::default()
    };
    let image = render(&world, &camera, &pose, &lighting, &settings).unwrap();
    let got = centre_mean(&image, &camera, 1.0, 0.02).x;
    // E = L ∫ cos θ_x cos θ_l / r² dA over the square, by a fine midpoint rule
    let radiance = power / (PI * 4.0 * half * half);
    let n = 400;
    let cell = 2.0 * half / n as f32;
    let mut irradiance = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (
                -half + (i as f32 + 0.5) * cell,
                -half + (j as f32 + 0.5) * cell,
            );
            let r2 = x * x + y * y + height * height;
            irradiance += f64::from(height * height / (r2 * r2) * cell * cell);
        }
    }
    let expected = albedo / PI * radiance * irradiance as f32;
    assert!(
        (got / expected - 1.0).abs() < 0.02,
        "{got} against {expected}"
    );
}

#[test]
fn a_frame_has_the_same_bytes_on_any_number_of_threads() {
    let sphere = shapes::sphere_on_plane(16);
    let world = World::new(&[Target::from_triangles(
        &sphere,
        1,
        1,
        crate::materials::COPPER,
    )]);
    let lighting = Lighting {
        lights: vec![Light::Rect {
            centre: [0.3, -0.3, 1.0],
            half_u: [0.2, 0.0, 0.0],
            half_v: [0.0, 0.2, 0.0],
            power: 50.0,
            colour: [1.0, 0.9, 0.8],
        }],
        environment: [0.05; 3],
    };
    let camera = Intrinsics::from_fov(40, 30, 50.0, 40.0);
    let pose = look_at(Vec3::new(0.0, -1.2, 0.8), Vec3::ZERO, Vec3::Z).unwrap();
    let settings = Settings {
        samples: 8,
        ..Settings::default()
    };
    let frame = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&world, &camera, &pose, &lighting, &settings).unwrap())
    };
    let one = frame(1);
    assert_eq!(one, frame(3));
    let other_seed = render(
        &world,
        &camera,
        &pose,
        &lighting,
        &Settings {
            seed: 9,
            ..settings
        },
    )
    .unwrap();
    assert_ne!(one, other_seed);
}

#[test]
fn bad_settings_and_lights_are_refused_in_words() {
    let world = plane(lambert(0.5));
    let camera = Intrinsics::from_fov(4, 4, 10.0, 10.0);
    let lighting = Lighting::default();
    let refused = |settings: Settings, lighting: &Lighting| {
        render(&world, &camera, &above(1.0), lighting, &settings)
            .unwrap_err()
            .to_string()
    };
    let zero = Settings {
        samples: 0,
        ..Settings::default()
    };
    assert!(refused(zero, &lighting).contains("render.samples"));
    let dark = Lighting {
        lights: vec![Light::Point {
            position: [0.0; 3],
            power: -1.0,
            colour: [1.0; 3],
        }],
        environment: [0.0; 3],
    };
    assert!(refused(Settings::default(), &dark).contains("watts"));
    let flat = Lighting {
        lights: vec![Light::Rect {
            centre: [0.0; 3],
            half_u: [1.0, 0.0, 0.0],
            half_v: [2.0, 0.0, 0.0],
            power: 1.0,
            colour: [1.0; 3],
        }],
        environment: [0.0; 3],
    };
    assert!(refused(Settings::default(), &flat).contains("rectangle"));
}

/// A plane at z = 0 lit by a uniform environment of radiance 1: white where x > 0, black
/// where x < 0 (white Lambertian reflects exactly 1 with one bounce: cosine sampling's weight
/// is its albedo).
fn step_edge() -> (World, Lighting) {
    let white = shapes::rectangle(Vec3::new(1.0, 0.0, 0.0), Vec3::X, Vec3::Y * 2.0);
    let black = shapes::rectangle(Vec3::new(-1.0, 0.0, 0.0), Vec3::X, Vec3::Y * 2.0);
    let world = World::new(&[
        Target::from_triangles(&white, 1, 1, lambert(1.0)),
        Target::from_triangles(&black, 2, 2, lambert(0.0)),
    ]);
    let lighting = Lighting {
        lights: vec![],
        environment: [1.0; 3],
    };
    (world, lighting)
}

/// The profile across the step edge along the middle row: (world x where the pixel's centre
/// ray meets the plane, radiance), for a camera looking down from `height`.
fn edge_profile(settings: &Settings, camera: &Intrinsics, height: f32) -> Vec<(f32, f32)> {
    let (world, lighting) = step_edge();
    let pose = above(height);
    let image = render(&world, camera, &pose, &lighting, settings).unwrap();
    let row = camera.height / 2;
    (0..camera.width)
        .map(|col| {
            let r = pose.transform_vector3(camera.ray(f64::from(col), f64::from(row)));
            let x = pose.translation.x + r.x * (height / -r.z);
            (x, image.pixels[(row * camera.width + col) as usize][0])
        })
        .collect()
}

/// The mean over a pixel's width `pixel` (its box filter) of `f` about `x`.
fn boxed(f: impl Fn(f32) -> f32, x: f32, pixel: f32) -> f32 {
    (0..64)
        .map(|k| f(x + pixel * ((k as f32 + 0.5) / 64.0 - 0.5)))
        .sum::<f32>()
        / 64.0
}

#[test]
fn a_thin_lens_blurs_an_edge_out_of_focus_by_its_circle_of_confusion() {
    // an edge 0.5 m away, the lens focused at 0.25 m: each pixel sees a disc of the plane of
    // radius R |1 - d/s| about its pinhole point, so the edge's profile is the share of that
    // disc beyond the edge
    let (height, focus, aperture) = (0.5f32, 0.25f32, 0.02f32);
    let camera = Intrinsics::from_fov(64, 4, 30.0, 2.0);
    let settings = Settings {
        samples: 1024,
        bounces: 1,
        seed: 3,
        aperture,
        focus,
        ..Settings::default()
    };
    let radius = aperture * (1.0 - height / focus).abs();
    let disc = |x: f32| {
        let t = (x / radius).clamp(-1.0, 1.0);
        0.5 + (t * (1.0 - t * t).sqrt() + t.asin()) / PI
    };
    let pixel = height / camera.fx as f32;
    let profile = edge_profile(&settings, &camera, height);
    let mut blurred = 0;
    for &(x, got) in &profile {
        let expected = boxed(disc, x, pixel);
        assert!(
            (got - expected).abs() < 0.04,
            "x {x:.4} m: {got:.3} against {expected:.3}"
        );
        blurred += usize::from(got > 0.05 && got < 0.95);
    }
    // the blur spans the disc's diameter, 2 R |1 - d/s| / pixel, about 15 pixels
    let width = 2.0 * radius / pixel;
    assert!(
        (blurred as f32 - width).abs() <= 3.0,
        "{blurred} px vs {width}"
    );
    // in focus, the edge is as sharp as a pinhole's
    let sharp = edge_profile(
        &Settings {
            focus: height,
            ..settings
        },
        &camera,
        height,
    );
    assert!(sharp.iter().filter(|p| p.1 > 0.05 && p.1 < 0.95).count() <= 2);
}

#[test]
fn motion_over_the_exposure_smears_an_edge_into_a_ramp() {
    // the camera moving 8 mm across an edge 0.5 m away: each pixel averages the plane over an
    // 8 mm stretch, a linear ramp
    let (height, travel) = (0.5f32, 0.008f32);
    let camera = Intrinsics::from_fov(64, 4, 30.0, 2.0);
    let settings = Settings {
        samples: 512,
        bounces: 1,
        seed: 4,
        motion: [travel, 0.0, 0.0],
        ..Settings::default()
    };
    let ramp = |x: f32| (x / travel + 0.5).clamp(0.0, 1.0);
    let pixel = height / camera.fx as f32;
    for (x, got) in edge_profile(&settings, &camera, height) {
        // the camera's x runs along the world's -x or +x: the ramp is symmetric about the edge
        let expected = boxed(ramp, x, pixel);
        assert!(
            (got - expected).abs() < 0.05,
            "x {x:.4} m: {got:.3} against {expected:.3}"
        );
    }
}

#[test]
fn lens_and_motion_out_of_range_are_refused() {
    let (world, lighting) = step_edge();
    let camera = Intrinsics::from_fov(8, 8, 30.0, 30.0);
    for (settings, key) in [
        (
            Settings {
                aperture: -0.1,
                ..Settings::default()
            },
            "render.aperture",
        ),
        (
            Settings {
                motion: [0.0, f32::NAN, 0.0],
                ..Settings::default()
            },
            "render.motion",
        ),
    ] {
        let e = render(&world, &camera, &above(1.0), &lighting, &settings).unwrap_err();
        assert!(e.to_string().contains(key), "{e}");
    }
}
