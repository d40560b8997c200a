//! Exact geometry: distances, poses, normals and incidence, projector shadows, clouds, and
//! the same bytes for any thread count or reused buffer.

use ::sensor::noise::Axial;
use ::sensor::*;
use glam::{Affine3A, Vec3};

use crate::kit::*;

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
        assert_eq!((cloud.snr[k], cloud.rgb[k]), (p.snr, p.rgb));
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
    let (one, two) = (run(1), run(2));
    assert_eq!(bits(&one), bits(&two));
    assert_ne!(bits(&one), bits(&pool_free(&world, &spec, 43)));
}

/// A scan into an earlier scan's buffer equals a fresh scan, whatever the earlier scan was:
/// of another camera, of the whole image, or of another region.
#[test]
fn scans_reusing_a_buffer_equal_fresh_ones() {
    let noisy = |camera| SensorSpec {
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
    // another region, up and to the side: its window overlaps the first's in part
    let aside = Region {
        min: Vec3::new(0.0, -0.3, 0.7),
        max: Vec3::new(0.3, 0.0, 1.6),
    };
    // (a 400×300 buffer, 6 MB, spans huge pages: it is advised to use them as it grows)
    let cameras = [small_camera(120, 90, 100.0), small_camera(400, 300, 330.0)];
    let pose = Affine3A::IDENTITY;
    for (camera, region) in cameras
        .iter()
        .flat_map(|&k| [(k, None), (k, Some(&region))])
    {
        let spec = noisy(camera);
        let fresh = scan_reusing(&world, &spec, &pose, 3, region, Scan::default());
        // (compared as text: the empty pixels' NaNs are unequal to themselves)
        let text = |s: &Scan| format!("{s:?}");
        assert!(fresh.valid_count() > 200, "{}", fresh.valid_count());
        let plain = match region {
            Some(r) => scan_within(&world, &spec, &pose, 3, r),
            None => scan(&world, &spec, &pose, 3),
        };
        assert_eq!(text(&fresh), text(&plain));
        let earlier = cameras.iter().flat_map(|&k| {
            let other = noisy(k);
            [
                scan(&world, &other, &pose, 5),
                scan_within(&world, &other, &pose, 5, &aside),
            ]
        });
        for earlier in earlier {
            let reused = scan_reusing(&world, &spec, &pose, 3, region, earlier);
            assert_eq!(text(&fresh), text(&reused));
        }
    }
}

#[test]
fn undistortion_inverts_the_lens_over_the_whole_image() {
    let lenses = [
        Distortion {
            k1: -0.10,
            k2: 0.15,
            p1: 1e-4,
            p2: -1e-4,
            k3: 0.0,
        },
        Distortion {
            k1: -0.30,
            k2: 0.10,
            p1: 2e-3,
            p2: -1e-3,
            k3: -0.02,
        },
        Distortion {
            k1: 0.20,
            k2: 0.05,
            p1: -1e-3,
            p2: 1e-3,
            k3: 0.01,
        },
    ];
    for d in lenses {
        let mut worst = 0.0f64;
        for i in 0..=40 {
            for j in 0..=40 {
                // a 5 MP imager's field behind a 12 mm lens: |x| ≤ 0.35, |y| ≤ 0.3
                let (xd, yd) = (
                    -0.35 + 0.7 * f64::from(i) / 40.0,
                    -0.3 + 0.6 * f64::from(j) / 40.0,
                );
                let (x, y) = d.undistort(xd, yd);
                let (rx, ry) = d.distort(x, y);
                worst = worst.max((rx - xd).abs().max((ry - yd).abs()));
            }
        }
        assert!(worst < 1e-12, "{d}: {worst}");
    }
}
