//! Noise models by their statistics: axial, incidence, dropout, quantization and bias, Kinect
//! disparity, specular saturation, mixed pixels, lateral jitter and the random streams.

use ::sensor::noise::{self, Axial, Dropout, Incidence};
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

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
fn quantization_and_bias() {
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
fn highlights_saturate_a_blob_that_follows_the_lobe_and_the_exposure() {
    // with the light at the camera, a facing plane's highlight is centred on the axis: a ray θ
    // off the axis sees the half vector θ off the normal, under light cos³θ (incidence and
    // range), and saturates where 0.6·cos³θ + peak·cos³θ·e^(−(1 − cos θ)/lobe²) exceeds the
    // saturation, the peak such that the lobe lit straight on returns the specular share (1)
    // over the hemisphere: 1 / (2·∫₀¹ e^(−(1 − cos(acos(u)/2))/lobe²)·u du)
    let share = |lobe: f64| {
        let n = 100_000;
        let sum: f64 = (0..n)
            .map(|i| {
                let u = (i as f64 + 0.5) / n as f64;
                (-(1.0 - (u.acos() / 2.0).cos()) / (lobe * lobe)).exp() * u
            })
            .sum();
        2.0 * sum / n as f64
    };
    let signal = |theta: f64, lobe: f64, share: f64| {
        let light = theta.cos().powi(3);
        0.6 * light + light / share * (-(1.0 - theta.cos()) / (lobe * lobe)).exp()
    };
    let mut blobs = Vec::new();
    for (lobe_deg, saturation) in [(3.0f32, 4.0f32), (6.0, 4.0), (6.0, 8.0)] {
        let mut plane = facing_plane(1.0);
        plane.material = Material {
            specular: 1.0,
            lobe: lobe_deg.to_radians(),
            ..Material::default()
        };
        let noise = Noise {
            specular: noise::Specular { saturation },
            ..Noise::default()
        };
        let s = scan(
            &World::new(&[plane]),
            &tof_camera(noise),
            &Affine3A::IDENTITY,
            2,
        );
        // the blob's edge: the angle where the signal falls to the saturation
        let lobe = f64::from(lobe_deg.to_radians());
        let share = share(lobe);
        let edge = (0..500_000)
            .map(|k| k as f64 * 1e-6)
            .find(|&t| signal(t, lobe, share) <= f64::from(saturation))
            .unwrap();
        let pixel = 1.0 / 800.0; // the camera's angle a pixel near the axis
        let mut saturated = 0;
        for p in &s.pixels {
            let theta = f64::from(p.clean.normalize().dot(Vec3::Z)).acos();
            if theta < edge - pixel / 4.0 {
                assert!(!p.is_valid(), "a point inside the blob at {theta}");
                assert!(p.intensity > saturation, "{}", p.intensity);
                saturated += 1;
            } else if theta > edge + pixel / 4.0 {
                assert!(p.is_valid(), "no point outside the blob at {theta}");
            }
        }
        // the blob is the disc of that angle, in pixels of the camera
        let radius = edge.tan() * 800.0;
        let expected = std::f64::consts::PI * radius * radius;
        let ratio = saturated as f64 / expected;
        assert!(
            (ratio - 1.0).abs() < 0.05,
            "lobe {lobe_deg}°: {saturated} vs {expected}"
        );
        blobs.push(saturated);
    }
    // a wider lobe saturates more; a shorter exposure (a higher saturation) less
    assert!(blobs[1] > blobs[0] && blobs[2] < blobs[1], "{blobs:?}");
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
