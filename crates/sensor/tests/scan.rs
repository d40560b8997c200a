//! Scans of analytic scenes: exact geometry, projector shadows, incidence, noise statistics and
//! thread-count independence.

use ::sensor::noise::{self, Axial, Dropout, Incidence};
use ::sensor::*;
use glam::{Affine3A, Vec3};

/// A rectangle in the plane through `c` spanned by `a` and `b` (half extents), as a target.
fn quad(c: Vec3, a: Vec3, b: Vec3, class: u16, instance: u32) -> Target {
    Target {
        positions: vec![c - a - b, c + a - b, c + a + b, c - a + b],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        classes: Classes::Uniform(class),
        instance,
        material: Material::default(),
    }
}

fn sphere(c: Vec3, r: f32, n: usize) -> Target {
    let mut positions = Vec::new();
    for i in 0..=n {
        for j in 0..n {
            let (th, ph) = (
                std::f32::consts::PI * i as f32 / n as f32,
                std::f32::consts::TAU * j as f32 / n as f32,
            );
            positions.push(c + r * Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
        }
    }
    let id = |i: usize, j: usize| (i * n + j % n) as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Target {
        positions,
        triangles,
        classes: Classes::Uniform(3),
        instance: 7,
        material: Material::default(),
    }
}

fn small_camera(w: u32, h: u32, f: f64) -> Intrinsics {
    Intrinsics {
        width: w,
        height: h,
        fx: f,
        fy: f,
        cx: (w as f64 - 1.0) / 2.0,
        cy: (h as f64 - 1.0) / 2.0,
        distortion: Distortion::default(),
    }
}

fn ideal(intrinsics: Intrinsics) -> SensorSpec {
    SensorSpec {
        intrinsics,
        ..SensorSpec::preset("ideal").unwrap()
    }
}

fn facing_plane(z: f32) -> Target {
    quad(Vec3::new(0.0, 0.0, z), Vec3::X * 5.0, Vec3::Y * 5.0, 1, 1)
}

#[test]
fn plane_at_known_distance_is_exact_everywhere_even_with_distortion() {
    let mut k = small_camera(320, 240, 300.0);
    k.distortion = Distortion {
        k1: -0.12,
        k2: 0.05,
        k3: 0.0,
        p1: 0.001,
        p2: -0.0005,
    };
    k.validate().unwrap();
    let world = World::new(&[facing_plane(1.25)]);
    let s = scan(&world, &ideal(k), &Affine3A::IDENTITY, 1);
    assert_eq!(s.valid_count(), 320 * 240);
    for (i, p) in s.pixels.iter().enumerate() {
        assert!((p.point.z - 1.25).abs() < 2e-6, "{p:?}");
        assert_eq!(p.point, p.clean);
        assert_eq!((p.class, p.instance), (1, 1));
        assert!((p.normal - Vec3::NEG_Z).length() < 1e-6);
        let (u, v) = k.project(p.point).unwrap();
        assert!(
            (u - (i % 320) as f64).abs() < 1e-3 && (v - (i / 320) as f64).abs() < 1e-3,
            "pixel {i} projects to {u},{v}"
        );
    }
}

#[test]
fn camera_pose_moves_the_scene_into_the_camera_frame() {
    // a camera 2 m above a floor at z = 0, looking straight down
    let pose = look_at(
        Vec3::new(0.3, -0.2, 2.0),
        Vec3::new(0.3, -0.2, 0.0),
        Vec3::Z,
    )
    .unwrap();
    let floor = quad(Vec3::ZERO, Vec3::X * 5.0, Vec3::Y * 5.0, 2, 4);
    let s = scan(
        &World::new(&[floor]),
        &ideal(small_camera(64, 48, 60.0)),
        &pose,
        0,
    );
    assert_eq!(s.valid_count(), 64 * 48);
    assert!(s.pixels.iter().all(|p| (p.point.z - 2.0).abs() < 1e-5));
    // image x (right) is world +x for this pose; a pixel right of centre lies at larger world x
    let right = pose.transform_point3(s.pixels[24 * 64 + 60].point);
    assert!(right.x > 0.3 && right.z.abs() < 1e-5);
}

#[test]
fn sphere_points_lie_on_the_sphere() {
    let c = Vec3::new(0.05, -0.02, 2.0);
    let world = World::new(&[sphere(c, 0.5, 400)]);
    let k = small_camera(200, 200, 200.0);
    let s = scan(&world, &ideal(k), &Affine3A::IDENTITY, 0);
    let valid: Vec<&Pixel> = s.pixels.iter().filter(|p| p.is_valid()).collect();
    // the visible disc: radius f·r/sqrt(d² - r²) pixels
    let disc = std::f32::consts::PI * (200.0 * 0.5 / (4.0f32 - 0.25).sqrt()).powi(2);
    assert!(
        (valid.len() as f32 / disc - 1.0).abs() < 0.03,
        "{} vs {disc}",
        valid.len()
    );
    for p in valid {
        // tessellated: within the chord error of a 400-segment sphere
        let d = (p.point - c).length();
        assert!(d <= 0.5 + 1e-5 && d > 0.5 * (1.0 - 2e-4), "{d}");
        assert_eq!((p.class, p.instance), (3, 7));
    }
}

#[test]
fn clouds_hold_the_kept_pixels_in_pixel_order_with_their_labels() {
    // a sphere and a plane with two labels, on more pixels than one run of the cloud's passes
    let world = World::new(&[
        sphere(Vec3::new(0.05, -0.02, 2.0), 0.5, 100),
        quad(Vec3::new(0.0, 0.0, 3.0), Vec3::X * 5.0, Vec3::Y * 5.0, 2, 9),
    ]);
    let spec = SensorSpec {
        noise: Noise {
            axial: Axial {
                sigma: 0.002,
                ..Axial::default()
            },
            ..Noise::default()
        },
        ..ideal(small_camera(240, 180, 200.0))
    };
    let pose = Affine3A::from_translation(Vec3::new(0.1, 0.2, -0.3));
    let s = scan(&world, &spec, &pose, 4);
    let keep = |p: &Pixel| (p.is_valid() && p.point.x > 0.2).then_some(p.point * 2.0);
    let kept: Vec<&Pixel> = s.pixels.iter().filter(|p| keep(p).is_some()).collect();
    assert!(
        kept.len() > 5_000 && kept.len() < s.pixels.len() / 2,
        "{}",
        kept.len()
    );
    let cloud = s.points_where(keep);
    assert_eq!(cloud.len(), kept.len());
    for (k, p) in kept.iter().enumerate() {
        assert_eq!(cloud.xyz[k], p.point * 2.0);
        assert_eq!(cloud.normal[k], p.normal);
        assert_eq!(cloud.intensity[k], p.intensity);
        assert_eq!((cloud.class[k], cloud.instance[k]), (p.class, p.instance));
    }
    assert!(cloud.class.contains(&2) && cloud.class.contains(&3));
    // the whole cloud, in the world frame and millimetres
    let world = s.cloud(false, Frame::World, Units::Millimetres);
    let valid: Vec<&Pixel> = s.pixels.iter().filter(|p| p.is_valid()).collect();
    assert_eq!(world.len(), valid.len());
    for (k, p) in valid.iter().enumerate() {
        assert_eq!(world.xyz[k], pose.transform_point3(p.point) * 1000.0);
        assert_eq!(world.normal[k], pose.transform_vector3(p.normal));
    }
    assert!(s.points_where(|_| None).is_empty());
}

#[test]
fn projector_shadow_band_width_follows_from_the_baseline() {
    // occluder at z1 = 1 covering x > 0; background at z2 = 2; projector at x = b:
    // the background in x in [b - b·z2/z1, 0] is lit by no ray: a band b(z2 - z1)/z1 wide
    let (b, z1, z2) = (0.2f32, 1.0f32, 2.0f32);
    let occluder = quad(Vec3::new(2.0, 0.0, z1), Vec3::X * 2.0, Vec3::Y * 3.0, 2, 2);
    let background = quad(Vec3::new(0.0, 0.0, z2), Vec3::X * 6.0, Vec3::Y * 6.0, 1, 1);
    let world = World::new(&[occluder, background]);
    let k = small_camera(801, 101, 400.0);
    let projector = Projector {
        baseline: b,
        convergence: 1.5,
        hfov_deg: 120.0,
        vfov_deg: 120.0,
    };
    let sl = SensorSpec {
        intrinsics: k,
        model: Model::StructuredLight { projector },
        ..ideal(k)
    };
    let s = scan(&world, &sl, &Affine3A::IDENTITY, 0);
    let row = &s.pixels[50 * 801..51 * 801];
    let shadowed: Vec<usize> = (0..801)
        .filter(|&c| row[c].instance == 1 && !row[c].is_valid())
        .collect();
    let width = shadowed.len() as f32 * z2 / 400.0;
    let expect = b * (z2 - z1) / z1;
    assert!(
        (width - expect).abs() < 2.0 * z2 / 400.0,
        "band {width} m, expected {expect} m"
    );
    // the band sits just left of the occluder's edge
    let edge = (0..801).find(|&c| row[c].instance == 2).unwrap();
    assert_eq!(*shadowed.last().unwrap() + 1, edge);
    // the ideal sensor sees everything there
    let all = scan(&world, &ideal(k), &Affine3A::IDENTITY, 0);
    assert_eq!(all.valid_count(), 801 * 101);
    // a lens with (negligible) distortion is cast ray by ray, shadow rays included: the same
    // points, but where the projector's ray grazes the occluder's edge exactly (column 360,
    // x = b - b·z2/z1 at the background), as rounding decides
    let lens = Intrinsics {
        distortion: Distortion {
            k1: 1e-12,
            ..Distortion::default()
        },
        ..k
    };
    let cast = scan(
        &world,
        &SensorSpec {
            intrinsics: lens,
            ..sl
        },
        &Affine3A::IDENTITY,
        0,
    );
    let differ: Vec<usize> = (0..s.pixels.len())
        .filter(|&i| s.pixels[i].is_valid() != cast.pixels[i].is_valid())
        .collect();
    assert!(differ.iter().all(|i| i % 801 == 360), "{differ:?}");
}

#[test]
fn tilted_plane_gives_its_incidence_and_normal() {
    let theta = 30f32.to_radians();
    let n = Vec3::new(theta.sin(), 0.0, -theta.cos());
    let a = Vec3::Y.cross(n).normalize() * 3.0;
    let plane = quad(Vec3::new(0.0, 0.0, 1.0), a, Vec3::Y * 3.0, 1, 1);
    let s = scan(
        &World::new(&[plane]),
        &ideal(small_camera(101, 101, 100.0)),
        &Affine3A::IDENTITY,
        0,
    );
    let centre = s.pixels[50 * 101 + 50];
    assert!(
        (centre.incidence - theta).abs() < 1e-4,
        "{}",
        centre.incidence.to_degrees()
    );
    assert!(
        s.pixels
            .iter()
            .filter(|p| p.is_valid())
            .all(|p| (p.normal - n).length() < 1e-5)
    );
    // incidence varies with the ray: cos = n·(-dir)
    for p in s.pixels.iter().filter(|p| p.is_valid()) {
        let cos = n.dot(-p.point.normalize());
        assert!((p.incidence.cos() - cos).abs() < 1e-4);
    }
}

/// A 500×400 camera facing a plane at `z` (200k pixels) with the given noise.
fn noisy_plane(z: f32, noise: Noise, seed: u64) -> Scan {
    let k = small_camera(500, 400, 800.0);
    let tof = SensorSpec {
        intrinsics: k,
        model: Model::TimeOfFlight,
        noise,
        ..ideal(k)
    };
    scan(
        &World::new(&[facing_plane(z)]),
        &tof,
        &Affine3A::IDENTITY,
        seed,
    )
}

fn range_errors(s: &Scan) -> Vec<f64> {
    s.pixels
        .iter()
        .filter(|p| p.is_valid())
        .map(|p| (p.point.length() - p.clean.length()) as f64)
        .collect()
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (
        m,
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt(),
    )
}

#[test]
fn axial_noise_has_the_configured_sigma() {
    let noise = Noise {
        axial: Axial {
            sigma: 1e-3,
            ..Axial::default()
        },
        ..Noise::default()
    };
    let (m, sd) = mean_std(&range_errors(&noisy_plane(1.0, noise, 3)));
    assert!((sd / 1e-3 - 1.0).abs() < 0.05, "σ {sd}");
    assert!(m.abs() < 3.0 * 1e-3 / (200_000f64).sqrt() * 2.0, "mean {m}");
    // along the ray: the noisy point stays on its pixel's ray
    let s = noisy_plane(1.0, noise, 3);
    assert!(
        s.pixels
            .iter()
            .all(|p| p.point.normalize().dot(p.clean.normalize()) > 1.0 - 1e-6)
    );
}

#[test]
fn noise_proportional_to_distance_and_growing_at_grazing_angles() {
    let noise = Noise {
        axial: Axial {
            per_metre: 5e-4,
            ..Axial::default()
        },
        ..Noise::default()
    };
    for z in [1.0f32, 2.0] {
        let errors = range_errors(&noisy_plane(z, noise, 5));
        // ranges vary across the image; normalise each error by its own expected σ
        let s = noisy_plane(z, noise, 5);
        let ranges: Vec<f64> = s
            .pixels
            .iter()
            .filter(|p| p.is_valid())
            .map(|p| p.clean.length() as f64)
            .collect();
        let z_scores: Vec<f64> = errors
            .iter()
            .zip(&ranges)
            .map(|(e, r)| e / (5e-4 * r))
            .collect();
        let (_, sd) = mean_std(&z_scores);
        assert!((sd - 1.0).abs() < 0.05, "z = {z}: {sd}");
    }
    // the incidence term multiplies σ by 1 + gain·θ/(π/2 - θ)
    let inc = Incidence {
        gain: 0.5,
        max_factor: 10.0,
    };
    let theta = 60f32.to_radians();
    assert!(
        (inc.factor(theta) - (1.0 + 0.5 * theta / (std::f32::consts::FRAC_PI_2 - theta))).abs()
            < 1e-6
    );
    assert_eq!(Incidence::default().factor(1.0), 1.0);
}

#[test]
fn dropout_rate_matches() {
    let noise = Noise {
        dropout: Dropout {
            rate: 0.1,
            ..Dropout::default()
        },
        ..Noise::default()
    };
    let s = noisy_plane(1.0, noise, 9);
    let lost = 1.0 - s.valid_count() as f64 / 200_000.0;
    assert!((lost / 0.1 - 1.0).abs() < 0.05, "{lost}");
    // lost pixels keep their ground truth
    assert!(
        s.pixels
            .iter()
            .all(|p| !p.clean.x.is_nan() && p.instance == 1)
    );
    // low signal: a dark plane far away drops out, a bright near one does not
    let low = Noise {
        dropout: Dropout {
            rate: 0.0,
            signal_threshold: 0.3,
            softness: 0.01,
        },
        ..Noise::default()
    };
    assert!(noisy_plane(1.0, low, 1).valid_count() > 199_000); // signal 0.6 at the reference range
    assert!(noisy_plane(3.0, low, 1).valid_count() < 1_000); // 0.6 / 9
}

#[test]
fn quantisation_and_bias() {
    let q = Noise {
        quantization: 1e-3,
        ..Noise::default()
    };
    let s = noisy_plane(1.0, q, 0);
    for p in s.pixels.iter().filter(|p| p.is_valid()).take(5000) {
        let r = p.point.length() / 1e-3;
        assert!((r - r.round()).abs() < 1e-2, "{r}");
    }
    let biased = Noise {
        bias: noise::Bias {
            offset_sigma: 1e-3,
            scale_sigma: 0.0,
        },
        ..Noise::default()
    };
    let offsets: Vec<f64> = (0..200)
        .map(|seed| range_errors(&noisy_plane(1.0, biased, seed))[0])
        .collect();
    let (_, sd) = mean_std(&offsets);
    assert!((sd / 1e-3 - 1.0).abs() < 0.2, "per-scan offset σ {sd}");
    // one offset for the whole scan
    let e = range_errors(&noisy_plane(1.0, biased, 4));
    assert!(e.iter().all(|x| (x - e[0]).abs() < 1e-6));
}

#[test]
fn same_bytes_for_any_thread_count() {
    let noise = SensorSpec::preset("zivid-2plus-m130").unwrap().noise;
    let k = small_camera(300, 200, 300.0);
    let spec = SensorSpec {
        intrinsics: k,
        model: Model::StructuredLight {
            projector: Projector {
                baseline: 0.2,
                convergence: 1.3,
                hfov_deg: 90.0,
                vfov_deg: 90.0,
            },
        },
        noise,
        ..ideal(k)
    };
    let world = World::new(&[
        sphere(Vec3::new(0.0, 0.0, 1.2), 0.3, 200),
        facing_plane(1.6),
    ]);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| scan(&world, &spec, &Affine3A::IDENTITY, 42))
    };
    let bits = |s: &Scan| -> Vec<u32> {
        s.pixels
            .iter()
            .flat_map(|p| {
                [p.point.to_array(), p.clean.to_array(), p.normal.to_array()]
                    .concat()
                    .into_iter()
                    .map(f32::to_bits)
                    .chain([
                        p.class as u32,
                        p.instance,
                        p.intensity.to_bits(),
                        p.incidence.to_bits(),
                    ])
            })
            .collect()
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(bits(&one), bits(&two));
    assert_ne!(bits(&one), bits(&pool_free(&world, &spec, 43)));
}

fn pool_free(world: &World, spec: &SensorSpec, seed: u64) -> Scan {
    scan(world, spec, &Affine3A::IDENTITY, seed)
}

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

#[test]
fn kinect_depth_comes_in_disparity_steps_and_the_window_removes_strays() {
    let mut spec = SensorSpec::preset("kinect-v1").unwrap();
    let Model::Kinect {
        projector,
        ref mut disparity_sigma_px,
        ..
    } = spec.model
    else {
        unreachable!()
    };
    *disparity_sigma_px = 0.0;
    let s = scan(
        &World::new(&[facing_plane(1.5)]),
        &spec,
        &Affine3A::IDENTITY,
        0,
    );
    assert!(s.valid_count() > 200_000);
    let fb = spec.intrinsics.fx as f32 * projector.baseline;
    for p in s.pixels.iter().filter(|p| p.is_valid()).step_by(97) {
        let steps = fb / p.point.z * 8.0;
        assert!(
            (steps - steps.round()).abs() < 2e-3,
            "disparity {} px is not a multiple of 1/8",
            steps / 8.0
        );
        assert!(
            (p.point.z - 1.5).abs() < 1.5 * 1.5 / fb / 8.0,
            "{}",
            p.point.z
        );
    }
    // a small object nearer than the inlier distance of nothing around it is filtered out
    let speck = quad(
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::X * 0.004,
        Vec3::Y * 0.004,
        5,
        9,
    );
    let s = scan(
        &World::new(&[speck, facing_plane(1.5)]),
        &spec,
        &Affine3A::IDENTITY,
        0,
    );
    assert!(!s.pixels.iter().any(|p| p.is_valid() && p.instance == 9));
}

#[test]
fn shiny_surfaces_saturate_near_the_mirror_direction() {
    let mut plane = facing_plane(1.0);
    plane.material = Material {
        reflectivity: 0.6,
        specular: 1.0,
        lobe: 5f32.to_radians(),
    };
    let noise = Noise {
        specular: noise::Specular { probability: 0.5 },
        ..Noise::default()
    };
    let k = small_camera(500, 400, 800.0);
    let tof = SensorSpec {
        intrinsics: k,
        model: Model::TimeOfFlight,
        noise,
        ..ideal(k)
    };
    let s = scan(&World::new(&[plane]), &tof, &Affine3A::IDENTITY, 2);
    // with the light at the camera, the highlight is where the ray meets the plane within 5°
    let (mut inside, mut lost_inside, mut lost_outside) = (0, 0, 0);
    for p in &s.pixels {
        let angle = p.clean.normalize().dot(Vec3::Z).acos();
        if angle < 4.5f32.to_radians() {
            inside += 1;
            lost_inside += !p.is_valid() as usize;
        } else if angle > 5.5f32.to_radians() {
            lost_outside += !p.is_valid() as usize;
        }
    }
    let rate = lost_inside as f64 / inside as f64;
    assert!((rate - 0.5).abs() < 0.03, "{rate} over {inside}");
    assert_eq!(lost_outside, 0);
}

#[test]
fn mixed_pixels_fly_between_the_two_depths_at_edges_only() {
    let near = quad(Vec3::new(0.5, 0.0, 1.0), Vec3::X * 0.5, Vec3::Y * 2.0, 2, 2);
    let world = World::new(&[near, facing_plane(1.5)]);
    let noise = Noise {
        edges: noise::Edges {
            probability: 1.0,
            jump: 0.05,
        },
        ..Noise::default()
    };
    let k = small_camera(200, 50, 200.0);
    let spec = SensorSpec {
        intrinsics: k,
        model: Model::TimeOfFlight,
        noise,
        ..ideal(k)
    };
    let s = scan(&world, &spec, &Affine3A::IDENTITY, 0);
    let mut flying = 0;
    for (i, p) in s.pixels.iter().enumerate() {
        let (r, r0) = (p.point.length(), p.clean.length());
        if (r - r0).abs() > 1e-5 {
            flying += 1;
            // between the two surfaces, on its own ray, next to the edge column
            assert!(
                p.point.z > 1.0 - 1e-4 && p.point.z < 1.5 + 1e-4,
                "{:?}",
                p.point
            );
            assert!(p.point.normalize().dot(p.clean.normalize()) > 1.0 - 1e-6);
            let col = i % 200;
            assert!((98..=101).contains(&col), "flying pixel at column {col}");
        }
    }
    assert!(flying >= 2 * 50 - 4, "{flying}");
}

#[test]
fn region_scan_keeps_every_point_inside_the_region_and_skips_the_rest() {
    let spec = SensorSpec {
        noise: Noise {
            axial: Axial {
                sigma: 1e-3,
                ..Axial::default()
            },
            edges: noise::Edges {
                probability: 0.5,
                jump: 0.01,
            },
            lateral_px: 0.2,
            ..Noise::default()
        },
        ..ideal(small_camera(240, 180, 200.0))
    };
    let world = World::new(&[
        sphere(Vec3::new(0.05, 0.0, 1.0), 0.2, 120),
        facing_plane(1.5),
    ]);
    let crop = Region {
        min: Vec3::new(-0.1, -0.15, 0.7),
        max: Vec3::new(0.25, 0.1, 1.6),
    };
    // the region grows the crop by the sensor's reach at the crop's far corner, as datasets do
    let far = crop.max.length();
    let margin = spec.reach_px() * far / 200.0;
    assert!((spec.reach_px() - 4.2).abs() < 1e-6);
    let region = Region {
        min: crop.min - margin,
        max: crop.max + margin,
    };
    let inside = |p: &Pixel| {
        let q = p.point;
        q.cmpge(crop.min).all() && q.cmple(crop.max).all()
    };
    let full = scan(&world, &spec, &Affine3A::IDENTITY, 5);
    let part = scan_within(&world, &spec, &Affine3A::IDENTITY, 5, &region);
    let kept = |s: &Scan| -> Vec<Pixel> { s.pixels.iter().copied().filter(inside).collect() };
    assert!(kept(&full).len() > 2000, "{}", kept(&full).len());
    assert_eq!(kept(&full), kept(&part));
    let cast = part.pixels.iter().filter(|p| !p.clean.x.is_nan()).count();
    let all = full.pixels.iter().filter(|p| !p.clean.x.is_nan()).count();
    assert!(cast < all * 6 / 10, "{cast} of {all} pixels cast");
}

#[test]
fn lateral_jitter_moves_points_on_the_surface_by_the_configured_pixels() {
    let noise = Noise {
        lateral_px: 0.5,
        ..Noise::default()
    };
    // 200k pixels of a plane 1 m away at f = 800 px: one pixel is 1.25 mm
    let s = noisy_plane(1.0, noise, 3);
    let (dx, dy): (Vec<f64>, Vec<f64>) = s
        .pixels
        .iter()
        .filter(|p| p.is_valid())
        .map(|p| {
            assert!(
                (p.point.z - 1.0).abs() < 1e-5,
                "left the plane: {}",
                p.point
            );
            (
                (p.point.x - p.clean.x) as f64,
                (p.point.y - p.clean.y) as f64,
            )
        })
        .unzip();
    assert_eq!(dx.len(), 200_000);
    for d in [dx, dy] {
        let (m, sd) = mean_std(&d);
        assert!(m.abs() < 1e-5, "mean {m}");
        assert!((sd / (0.5 / 800.0) - 1.0).abs() < 0.05, "σ {sd}");
    }
}

/// The per-pixel normal draws: zero mean, unit σ, Gaussian tails, and independent streams.
#[test]
fn pixel_normals_are_standard_and_streams_independent() {
    use ::sensor::noise::{PixelRng, stream};
    let n = 400_000;
    let draws: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let rng = PixelRng::new(7, i);
            (
                rng.normal(stream::AXIAL) as f64,
                rng.normal(stream::LATERAL) as f64,
            )
        })
        .collect();
    let a: Vec<f64> = draws.iter().map(|d| d.0).collect();
    let (m, sd) = mean_std(&a);
    assert!(m.abs() < 4.0 / (n as f64).sqrt(), "mean {m}");
    assert!((sd - 1.0).abs() < 0.01, "σ {sd}");
    let beyond = |k: f64| a.iter().filter(|z| z.abs() > k).count() as f64 / n as f64;
    assert!(
        (beyond(2.0) / 0.0455 - 1.0).abs() < 0.05,
        "P(|z| > 2) {}",
        beyond(2.0)
    );
    assert!(
        (beyond(3.0) / 0.0027 - 1.0).abs() < 0.15,
        "P(|z| > 3) {}",
        beyond(3.0)
    );
    let corr = draws.iter().map(|(x, y)| x * y).sum::<f64>() / n as f64;
    assert!(corr.abs() < 4.0 / (n as f64).sqrt(), "correlation {corr}");
}

/// A region's pixel window holds every pixel whose centre ray crosses the box, from cameras all
/// around it, and is refused where a rectangle cannot bound those pixels.
#[test]
fn region_pixel_window_holds_every_crossing_pixel() {
    let k = small_camera(160, 120, 150.0);
    let region = Region {
        min: Vec3::new(-0.12, -0.05, -0.08),
        max: Vec3::new(0.1, 0.07, 0.04),
    };
    let mut windows = 0;
    for i in 0..24 {
        let a = i as f32 * 0.7;
        let eye = Vec3::new(a.cos() * 0.6, a.sin() * 0.5, 0.3 + 0.1 * (i % 3) as f32);
        let pose = look_at(eye, Vec3::new(0.02 * (i % 5) as f32, 0.0, 0.0), Vec3::Z).unwrap();
        let Some([c0, c1, r0, r1]) = region.pixel_window(&k, &pose) else {
            continue;
        };
        windows += 1;
        let origin = Vec3::from(pose.translation);
        let mut crossing = 0;
        for r in 0..k.height as usize {
            for c in 0..k.width as usize {
                let dir = pose.transform_vector3(k.ray(c as f64, r as f64));
                if region.crossed_by(origin, dir) {
                    crossing += 1;
                    assert!(
                        (c0..c1).contains(&c) && (r0..r1).contains(&r),
                        "pose {i}: pixel ({c}, {r}) outside {c0}..{c1} x {r0}..{r1}"
                    );
                }
            }
        }
        assert!(crossing > 0, "pose {i} sees the region");
        assert!(
            (c1 - c0) * (r1 - r0) < 3 * crossing,
            "pose {i}: loose window"
        );
    }
    assert!(windows >= 20, "{windows} windows");
    // inside the box, or with a distorting lens, a rectangle bounds nothing
    assert_eq!(region.pixel_window(&k, &Affine3A::IDENTITY), None);
    let distorted = Intrinsics {
        distortion: Distortion {
            k1: -0.2,
            ..Distortion::default()
        },
        ..k
    };
    let pose = look_at(Vec3::new(0.0, 0.0, 0.6), Vec3::ZERO, Vec3::Y).unwrap();
    assert!(region.pixel_window(&k, &pose).is_some());
    assert_eq!(region.pixel_window(&distorted, &pose), None);
}

#[test]
fn region_scans_cast_every_crossing_pixel_and_little_else() {
    // a floor under the region, seen from all around: each row casts the columns towards the
    // region's cut by the row's plane, which is no polygon the pixel window is
    let spec = ideal(small_camera(160, 120, 150.0));
    let floor = quad(
        Vec3::new(0.0, 0.0, -0.2),
        Vec3::X * 8.0,
        Vec3::Y * 8.0,
        1,
        1,
    );
    let world = World::new(&[floor]);
    let region = Region {
        min: Vec3::new(-0.12, -0.05, -0.08),
        max: Vec3::new(0.1, 0.07, 0.04),
    };
    for i in 0..12 {
        let a = i as f32 * 0.9;
        let eye = Vec3::new(a.cos() * 0.6, a.sin() * 0.5, 0.3 + 0.1 * (i % 3) as f32);
        let pose = look_at(eye, Vec3::new(0.02 * (i % 5) as f32, 0.0, 0.0), Vec3::Z).unwrap();
        let full = scan(&world, &spec, &pose, 1);
        let part = scan_within(&world, &spec, &pose, 1, &region);
        let (mut crossing, mut cast) = (0, 0);
        for (p, (whole, within)) in full.pixels.iter().zip(&part.pixels).enumerate() {
            let (c, r) = (p % 160, p / 160);
            let dir = pose.transform_vector3(spec.intrinsics.ray(c as f64, r as f64));
            let cast_here = !within.clean.x.is_nan();
            cast += cast_here as usize;
            if region.crossed_by(Vec3::from(pose.translation), dir) && whole.is_valid() {
                crossing += 1;
                assert!(
                    cast_here,
                    "pose {i}: pixel ({c}, {r}) crosses but was not cast"
                );
                assert_eq!(within, whole);
            }
        }
        assert!(crossing > 500, "pose {i}: {crossing}");
        // a column to spare either side of each row's cut, and a third on the right
        assert!(
            cast <= crossing + 3 * 120,
            "pose {i}: {cast} cast, {crossing} crossing"
        );
    }
}

/// [`SensorSpec::reach_px`] bounds how far a measured point lands from its own pixel (lateral
/// jitter), so that datasets grow their scan regions enough.
#[test]
fn reach_bounds_how_far_points_land_from_their_pixel() {
    let noise = Noise {
        lateral_px: 0.5,
        ..Noise::default()
    };
    let spec = SensorSpec {
        noise,
        ..ideal(small_camera(500, 400, 800.0))
    };
    assert_eq!(spec.reach_px(), 9.0);
    let s = noisy_plane(1.0, noise, 11);
    let k = small_camera(500, 400, 800.0);
    let farthest = s
        .pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_valid())
        .map(|(i, p)| {
            let (u, v) = k.project(p.point).unwrap();
            let (c, r) = ((i % 500) as f64, (i / 500) as f64);
            ((u - c).powi(2) + (v - r).powi(2)).sqrt()
        })
        .fold(0.0, f64::max);
    // 200k pixels jittered with σ = 0.5 px: some move over 3σ, none anywhere near the reach
    assert!(farthest > 1.5, "{farthest}");
    assert!(farthest < spec.reach_px() as f64 - 1.0, "{farthest}");
}

/// A scan into an earlier scan's buffer, whatever it holds, equals a fresh scan.
#[test]
fn scans_reusing_a_buffer_equal_fresh_ones() {
    let spec = |camera| SensorSpec {
        noise: Noise {
            axial: Axial {
                sigma: 1e-3,
                ..Axial::default()
            },
            ..Noise::default()
        },
        ..ideal(camera)
    };
    let world = World::new(&[sphere(Vec3::new(0.0, 0.0, 1.0), 0.2, 40), facing_plane(1.5)]);
    let region = Region {
        min: Vec3::new(-0.1, -0.1, 0.7),
        max: Vec3::new(0.1, 0.1, 1.6),
    };
    let dirty = vec![
        Pixel {
            point: Vec3::ONE,
            class: 9,
            ..Pixel::EMPTY
        };
        20_000
    ];
    // (a 400×300 buffer, 6 MB, spans huge pages: it is advised to use them as it grows)
    let cameras = [small_camera(120, 90, 100.0), small_camera(400, 300, 330.0)];
    for (camera, region) in cameras
        .iter()
        .flat_map(|&k| [(k, None), (k, Some(&region))])
    {
        let spec = spec(camera);
        let fresh = scan_reusing(&world, &spec, &Affine3A::IDENTITY, 3, region, Vec::new());
        let reused = scan_reusing(&world, &spec, &Affine3A::IDENTITY, 3, region, dirty.clone());
        // (compared as text: the empty pixels' NaNs are unequal to themselves)
        let text = |s: &Scan| format!("{s:?}");
        assert!(fresh.valid_count() > 200, "{}", fresh.valid_count());
        assert_eq!(text(&fresh), text(&reused));
        let plain = match region {
            Some(r) => scan_within(&world, &spec, &Affine3A::IDENTITY, 3, r),
            None => scan(&world, &spec, &Affine3A::IDENTITY, 3),
        };
        assert_eq!(text(&fresh), text(&plain));
    }
}
