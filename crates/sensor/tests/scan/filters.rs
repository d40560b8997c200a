//! Zivid's point-cloud filters by what they remove and keep: outliers, noise repair and
//! suppression, hole repair, clusters and Gaussian smoothing.

use ::sensor::noise::Axial;
use ::sensor::spec::{ClusterRemoval, Gaussian, HoleRepair};
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

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
