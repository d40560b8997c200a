use glam::{Affine3A, Vec3};

use super::*;
use crate::world::{Classes, Material, Target, World};

/// A square of side `2·half` in the plane through `centre` spanned by `u` and `v`.
fn square(centre: Vec3, u: Vec3, v: Vec3, half: f32, reflectivity: f32, class: u16) -> Target {
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    Target {
        positions: corners
            .iter()
            .map(|&(a, b)| centre + (u * a + v * b) * half)
            .collect(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        classes: Classes::Uniform(class),
        instance: u32::from(class),
        material: Material {
            reflectivity,
            ..Material::default()
        },
        wear: None,
    }
}

/// A floor 400 m across.
fn floor() -> World {
    World::new(&[square(Vec3::ZERO, Vec3::X, Vec3::Y, 200.0, 0.6, 1)])
}

/// The preset without noise, bias or reflectivity limit.
fn ideal(name: &str) -> Lidar {
    let mut lidar = Lidar::preset(name).unwrap();
    lidar.noise.sigma = 0.0;
    lidar.reflectivity.distance = f32::INFINITY;
    lidar.lasers.iter_mut().for_each(|l| l.bias = 0.0);
    lidar
}

/// A head standing still.
fn still() -> Motion {
    Motion::default()
}

/// A head `h` metres above the origin, yaw 0 along +x.
fn above(h: f32) -> Affine3A {
    head_pose(Vec3::new(0.0, 0.0, h), Vec3::new(1.0, 0.0, h), Vec3::Z).unwrap()
}

#[test]
fn every_preset_is_valid_and_blensor_sized() {
    for name in LIDAR_PRESETS {
        let lidar = Lidar::preset(name).unwrap();
        lidar.validate().unwrap();
        assert_eq!(lidar.name, name);
    }
    let hdl = Lidar::preset("velodyne-hdl64e-s2").unwrap();
    // Blensor's int(360 / 0.1728) columns of 64 lasers: about 133k rays a revolution
    assert_eq!((hdl.columns(), hdl.rays()), (2083, 133_312));
    assert_eq!(Lidar::preset("velodyne-vlp16").unwrap().rays(), 16 * 1800);
    assert_eq!(Lidar::preset("generic-lidar").unwrap().rays(), 1080);
    assert!(Lidar::preset("velodyne-hdl-64").is_err());
}

#[test]
fn on_a_flat_floor_each_ring_lies_at_h_over_tan_elevation() {
    let (world, h) = (floor(), 1.8);
    for name in ["velodyne-vlp16", "velodyne-hdl64e-s2", "velodyne-hdl32e"] {
        let lidar = ideal(name);
        let scan = scan_lidar(&world, &lidar, &above(h), &still(), 7);
        for r in &scan.returns {
            let laser = &lidar.lasers[r.laser as usize];
            let e = laser.elevation.to_radians();
            assert!(e < 0.0, "{name}: laser {} looks up yet returned", r.laser);
            let radius = r.point.truncate().length();
            // from the laser's origin, `offset` above the head's centre
            let expected = (h + laser.offset) / (-e).tan();
            assert!(
                (radius - expected).abs() <= 1e-4 * expected,
                "{name}: ring {} at {radius} m, expected {expected} m",
                r.laser
            );
            assert!(
                (r.point.z + h).abs() < 1e-4,
                "{name}: the floor is {h} m below"
            );
        }
        // every downward laser in range of the floor returns in every column, the others never
        let down = lidar
            .lasers
            .iter()
            .filter(|l| {
                let e = -l.elevation.to_radians();
                e > 0.0 && h / e.tan() < 199.0 && h / e.sin() < lidar.max_range
            })
            .count();
        assert_eq!(scan.returns.len(), down * lidar.columns(), "{name}");
        // the VLP-16's lasers start from its manual's vertical corrections: −15° 11.2 mm up
        let offsets: Vec<f32> = lidar.lasers.iter().map(|l| l.offset).collect();
        if name == "velodyne-vlp16" {
            assert_eq!((offsets[0], offsets[15]), (0.0112, -0.0112));
        } else {
            assert!(offsets.iter().all(|&o| o == 0.0), "{name}");
        }
        assert_eq!(scan.rays, lidar.rays());
    }
}

#[test]
fn the_rings_hold_their_radius_within_the_noise() {
    let lidar = Lidar::preset("velodyne-vlp16").unwrap();
    let scan = scan_lidar(&floor(), &lidar, &above(1.0), &still(), 3);
    let sigma = lidar.noise.sigma;
    for laser in 0..lidar.lasers.len() {
        let e = lidar.lasers[laser].elevation.to_radians();
        let ring: Vec<f32> = scan
            .returns
            .iter()
            .filter(|r| r.laser as usize == laser)
            .map(|r| r.measured - r.distance)
            .collect();
        if e >= 0.0 {
            assert!(ring.is_empty());
            continue;
        }
        // measured − true distance: mean 0 (the VLP-16 has no bias), deviation sigma
        let n = ring.len() as f32;
        let mean = ring.iter().sum::<f32>() / n;
        let sd = (ring.iter().map(|d| (d - mean).powi(2)).sum::<f32>() / (n - 1.0)).sqrt();
        assert!(
            mean.abs() < 4.0 * sigma / n.sqrt(),
            "laser {laser}: mean {mean}"
        );
        assert!((sd / sigma - 1.0).abs() < 0.1, "laser {laser}: sd {sd}");
    }
}

#[test]
fn the_per_laser_bias_reproduces_blensors_table() {
    let mut lidar = Lidar::preset("velodyne-hdl64e-s2").unwrap();
    lidar.noise.sigma = 0.0;
    let blensor = BLENSOR_VELODYNE_BIAS;
    // Blensor's digits, at the ends and the largest
    assert_eq!(blensor[0], 0.023188431056485468);
    assert_eq!(blensor[37], 0.17981608947109032);
    assert_eq!(blensor[63], 0.06568249229806342);
    for (laser, &b) in lidar.lasers.iter().zip(&blensor) {
        assert_eq!(laser.bias, b as f32);
    }
    let scan = scan_lidar(&floor(), &lidar, &above(2.0), &still(), 0);
    assert!(scan.returns.len() > 100_000);
    for r in &scan.returns {
        let bias = blensor[r.laser as usize];
        let off = f64::from(r.measured) - f64::from(r.distance);
        assert!(
            (off - bias).abs() < 1e-5,
            "laser {}: {off} against {bias}",
            r.laser
        );
    }
}

#[test]
fn the_reflectivity_limit_drops_dark_far_surfaces_only() {
    // a wall across the generic LiDAR's forward beam at 20 m and at 80 m, dark or bright; the
    // VLP-16's limit (Blensor's Velodyne: 0.1 at 50 m, +0.01 a metre) asks 0.4 at 80 m
    let mut lidar = Lidar::preset("velodyne-vlp16").unwrap();
    lidar.noise.sigma = 0.0;
    lidar.lasers = vec![Laser {
        elevation: 0.0,
        bias: 0.0,
        delay: 0.0,
        offset: 0.0,
    }];
    for (distance, reflectivity, kept) in [
        (20.0, 0.05, true),
        (80.0, 0.05, false),
        (80.0, 0.8, true),
        (80.0, 0.39, false),
        (80.0, 0.41, true),
    ] {
        let wall = square(
            Vec3::new(distance, 0.0, 0.0),
            Vec3::Y,
            Vec3::Z,
            5.0,
            reflectivity,
            2,
        );
        let scan = scan_lidar(&World::new(&[wall]), &lidar, &above(0.0), &still(), 0);
        assert_eq!(
            !scan.returns.is_empty(),
            kept,
            "reflectivity {reflectivity} at {distance} m"
        );
    }
}

#[test]
fn the_distance_table_is_interpolated_and_held_at_its_ends() {
    let noise = RangeNoise {
        mu: 9.0,
        sigma: 9.0,
        table: vec![[2.0, 0.01, 0.02], [4.0, 0.03, 0.06], [10.0, 0.0, 0.03]],
    };
    let close = |a: (f32, f32), b: (f32, f32)| (a.0 - b.0).abs() < 1e-7 && (a.1 - b.1).abs() < 1e-7;
    assert!(close(noise.at(1.0), (0.01, 0.02)));
    assert!(close(noise.at(2.0), (0.01, 0.02)));
    assert!(close(noise.at(3.0), (0.02, 0.04)));
    assert!(close(noise.at(7.0), (0.015, 0.045)));
    assert!(close(noise.at(50.0), (0.0, 0.03)));
    let plain = RangeNoise {
        table: Vec::new(),
        ..noise
    };
    assert_eq!(plain.at(3.0), (9.0, 9.0));
}

#[test]
fn a_scan_is_the_same_whatever_the_threads() {
    let world = World::new(&[
        square(Vec3::ZERO, Vec3::X, Vec3::Y, 50.0, 0.6, 1),
        square(Vec3::new(6.0, 1.0, 1.0), Vec3::Y, Vec3::Z, 1.0, 0.3, 2),
    ]);
    let lidar = Lidar::preset("velodyne-hdl32e").unwrap();
    let pose = above(1.5);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| scan_lidar(&world, &lidar, &pose, &still(), 11))
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert!(one.returns.iter().any(|r| r.class == 2));
    assert_ne!(
        one,
        scan_lidar(&world, &lidar, &pose, &still(), 12),
        "the seed draws the noise"
    );
}

#[test]
fn firing_times_follow_the_turn_and_the_firing_order() {
    let lidar = Lidar::preset("velodyne-vlp16").unwrap();
    // 0.2° steps at 10 Hz: a column every 55.6 µs, lasers 2.304 µs apart
    assert!((lidar.time(1, 0) - 0.1 / 1800.0).abs() < 1e-9);
    assert!((lidar.time(0, 15) - 15.0 * 2.304e-6).abs() < 1e-9);
    let last = lidar.time(lidar.columns() - 1, 0);
    assert!((last - 0.1 * 1799.0 / 1800.0).abs() < 1e-6);
    // yaw 90° points along the head's y (left)
    let d = lidar.direction(450, 0);
    assert!(d.x.abs() < 1e-6 && d.y > 0.9 && (d.z - (-15f32).to_radians().sin()).abs() < 1e-6);
    // the head turns on while a column fires: laser 15, 34.6 µs late, 0.124° further
    let yaw = |d: Vec3| d.y.atan2(d.x).to_degrees();
    let late = yaw(lidar.direction(450, 15)) - yaw(lidar.direction(450, 0));
    assert!((late - 3600.0 * 15.0 * 2.304e-6).abs() < 1e-3, "{late}");
    let scan = scan_lidar(&floor(), &lidar, &above(1.0), &still(), 0);
    for r in scan.returns.iter().filter(|r| r.laser == 14) {
        let at = r.point.y.atan2(r.point.x).to_degrees().rem_euclid(360.0);
        let off = (at - r.yaw + 180.0).rem_euclid(360.0) - 180.0;
        assert!(off.abs() < 1e-3, "{at} against {}", r.yaw);
    }
}

#[test]
fn a_moving_heads_skew_is_its_speed_times_the_firing_time() {
    // one level laser turning once at 10 Hz in 1° steps, the head driving at 2 m/s towards a
    // wall 10 m ahead and turning 90°/s: the wall's distance at yaw α, fired at t, is
    // (10 − 2t) / cos(α + 90°/s·t) in the head's frame, and the world sees the wall flat
    let lidar = Lidar {
        lasers: vec![Laser {
            elevation: 0.0,
            bias: 0.0,
            delay: 0.0,
            offset: 0.0,
        }],
        start: 0.0,
        end: 360.0,
        resolution: 1.0,
        rotation: 10.0,
        ..ideal("velodyne-vlp16")
    };
    let wall = square(Vec3::new(10.0, 0.0, 0.0), Vec3::Y, Vec3::Z, 50.0, 0.6, 2);
    let world = World::new(&[wall]);
    let motion = Motion {
        velocity: Vec3::new(2.0, 0.0, 0.0),
        turn: 90.0,
    };
    let scan = scan_lidar(&world, &lidar, &above(0.0), &motion, 0);
    assert!(scan.returns.len() > 100, "{}", scan.returns.len());
    for r in &scan.returns {
        let heading = (r.yaw + motion.turn * r.time).to_radians();
        let expected = (10.0 - 2.0 * r.time) / heading.cos();
        assert!(
            (r.distance - expected).abs() < 1e-4 * expected,
            "yaw {} at {} s: {} m, expected {expected} m",
            r.yaw,
            r.time,
            r.distance
        );
        let world = scan
            .to_frame(r, LidarFrame::World, 1.0)
            .transform_point3(r.point);
        assert!((world.x - 10.0).abs() < 1e-4, "the wall at x = {}", world.x);
    }
    // the column at yaw 0 fires first, the one at 359° (its heading 8° on) 0.1 s · 359/360
    // later: the skew between them is the 0.2 m the head drove meanwhile
    let first = scan.returns.iter().find(|r| r.yaw == 0.0).unwrap();
    let last = scan.returns.iter().find(|r| r.yaw == 359.0).unwrap();
    let drove = 2.0 * (last.time - first.time);
    assert!((drove - 0.2 * 359.0 / 360.0).abs() < 1e-5);
    let ahead = |r: &LidarReturn| r.distance * (r.yaw + motion.turn * r.time).to_radians().cos();
    assert!((ahead(first) - ahead(last) - drove).abs() < 1e-4);
    // standing still, the wall is where it is in every column
    let still = scan_lidar(&world, &lidar, &above(0.0), &still(), 0);
    let flat = |r: &LidarReturn| (r.distance * r.yaw.to_radians().cos() - 10.0).abs() < 1e-4;
    assert!(still.returns.iter().all(flat));
}

#[test]
fn a_mirror_returns_nothing_itself_and_what_its_reflection_meets_at_the_whole_path() {
    // a level beam meets a mirror 5 m ahead turned 45°, which sends it to a wall 8 m to the
    // left: the return is the wall's, 13 m along the beam as it left the head (Blensor's)
    let mut lidar = ideal("velodyne-vlp16");
    lidar.lasers.truncate(1);
    (lidar.lasers[0].elevation, lidar.lasers[0].offset) = (0.0, 0.0);
    (lidar.start, lidar.end, lidar.resolution) = (-2.0, 2.5, 0.5);
    let diagonal = Vec3::new(1.0, 1.0, 0.0).normalize();
    let mut mirror = square(Vec3::new(5.0, 0.0, 0.0), diagonal, Vec3::Z, 1.0, 0.04, 2);
    mirror.material = crate::materials::MIRROR;
    let wall = square(Vec3::new(5.0, 8.0, 0.0), Vec3::X, Vec3::Z, 5.0, 0.6, 3);
    let scan = scan_lidar(
        &World::new(&[mirror, wall]),
        &lidar,
        &above(0.0),
        &still(),
        0,
    );
    assert_eq!(scan.returns.len(), 9);
    assert!(
        scan.returns
            .iter()
            .all(|r| r.class == 3 && r.distance > 12.0)
    );
    let ahead = scan.returns.iter().find(|r| r.yaw == 0.0).unwrap();
    assert!((ahead.distance - 13.0).abs() < 1e-3, "{}", ahead.distance);
    assert!((ahead.point - Vec3::new(ahead.distance, 0.0, 0.0)).length() < 1e-5);
    // a matte plate in the mirror's place returns itself at 5 m
    let mut plate = square(Vec3::new(5.0, 0.0, 0.0), diagonal, Vec3::Z, 1.0, 0.6, 2);
    plate.material.specular = 0.5;
    let wall = square(Vec3::new(5.0, 8.0, 0.0), Vec3::X, Vec3::Z, 5.0, 0.6, 3);
    let scan = scan_lidar(
        &World::new(&[plate, wall]),
        &lidar,
        &above(0.0),
        &still(),
        0,
    );
    assert!(
        scan.returns
            .iter()
            .all(|r| r.class == 2 && r.distance < 6.0)
    );
}

/// One level laser fired once, straight ahead, thin.
fn one_beam() -> Lidar {
    let mut lidar = ideal("velodyne-vlp16");
    lidar.lasers.truncate(1);
    lidar.lasers[0].elevation = 0.0;
    (lidar.start, lidar.end, lidar.resolution) = (0.0, 1.0, 1.0);
    lidar
}

#[test]
fn a_footprint_spreads_the_beam_within_its_divergence() {
    let beam = Beam {
        divergence: 0.004,
        samples: 32,
        ..Beam::default()
    };
    let dir = Vec3::new(0.3, -0.5, 0.8).normalize();
    let rays: Vec<(Vec3, f32)> = beam.footprint(dir).collect();
    assert_eq!(rays.len(), 32);
    assert!((rays.iter().map(|r| r.1).sum::<f32>() - 1.0).abs() < 1e-6);
    let angles: Vec<f32> = rays.iter().map(|r| r.0.angle_between(dir)).collect();
    assert!(angles.iter().all(|&a| a <= 0.002 + 1e-6), "{angles:?}");
    // the profile falls outwards: the centre's rays weigh more than the rim's
    assert!(rays[0].1 > rays[31].1 * 2.0);
    // a thin beam is its centre alone
    let thin: Vec<(Vec3, f32)> = Beam::default().footprint(dir).collect();
    assert_eq!(thin, [(dir, 1.0)]);
}

#[test]
fn a_beam_across_an_edge_returns_both_surfaces_or_their_mix() {
    // a plate 5 m ahead covers the footprint's right half (y < 0), a wall 10 m ahead the rest
    let plate = square(Vec3::new(5.0, -1.0, 0.0), Vec3::Y, Vec3::Z, 1.0, 0.6, 2);
    let wall = square(Vec3::new(10.0, 0.0, 0.0), Vec3::Y, Vec3::Z, 5.0, 0.6, 3);
    let world = World::new(&[plate, wall]);
    let scan = |echoes: Echoes, separation: f32| {
        let mut lidar = one_beam();
        lidar.beam = Beam {
            divergence: 0.02,
            samples: 64,
            separation,
            echoes,
            intensity_reference: 0.0,
        };
        scan_lidar(&world, &lidar, &above(0.0), &still(), 0).returns
    };
    let dual = scan(Echoes::Dual, 0.75);
    let got: Vec<(u8, u8, u16)> = dual.iter().map(|r| (r.echo, r.echoes, r.class)).collect();
    assert_eq!(got, [(1, 2, 2), (2, 2, 3)]);
    assert!((dual[0].distance - 5.0).abs() < 0.01 && (dual[1].distance - 10.0).abs() < 0.01);
    // each echo fills about half the footprint: half the reflectivity
    assert!(
        dual.iter().all(|r| (r.reflectivity - 0.3).abs() < 0.06),
        "{dual:?}"
    );
    let strongest = scan(Echoes::Strongest, 0.75);
    assert_eq!(strongest.len(), 1);
    assert_eq!((strongest[0].class, strongest[0].echoes), (2, 1));
    let last = scan(Echoes::Last, 0.75);
    assert_eq!(last[0].class, 3);
    // closer than the separation, the two merge at their power-weighted mean: a mixed return
    let mixed = scan(Echoes::Dual, 6.0);
    assert_eq!(mixed.len(), 1);
    assert!(
        (mixed[0].distance - 7.5).abs() < 0.6,
        "{}",
        mixed[0].distance
    );
    assert!((mixed[0].reflectivity - 0.6).abs() < 1e-4);
}

#[test]
fn intensity_falls_with_incidence_and_range_from_its_reference() {
    // a wall 8 m ahead turned 60° from the beam: 0.6 · cos 60° · (4 / 8)² = 0.075
    let normal = Vec3::new(0.5, 3f32.sqrt() / 2.0, 0.0);
    let wall = square(
        Vec3::new(8.0, 0.0, 0.0),
        normal.cross(Vec3::Z),
        Vec3::Z,
        3.0,
        0.6,
        2,
    );
    let world = World::new(&[wall]);
    let mut lidar = one_beam();
    let blensor = scan_lidar(&world, &lidar, &above(0.0), &still(), 0).returns;
    assert_eq!(blensor[0].intensity, 0.6);
    lidar.beam.intensity_reference = 4.0;
    let physical = scan_lidar(&world, &lidar, &above(0.0), &still(), 0).returns;
    assert!(
        (physical[0].intensity - 0.075).abs() < 1e-5,
        "{}",
        physical[0].intensity
    );
}
