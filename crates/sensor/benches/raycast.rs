//! Ray-caster throughput (single rays and packets of 4×4 rays) and a full Zivid 2+ frame, on the
//! world of `bench/raycast_peers.py`: a tessellated sphere resting on a plane, about 200k and 2M
//! triangles, seen from 1 m above by a 1944 x 1200 pinhole camera, on all threads. (`bench/raycast_peers.py` times Open3D on the
//! same rays.)

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Affine3A, Vec3};
use rayon::prelude::*;
use sensor::{
    Bvh, ColourCapture, Scan, SensorSpec, Target, World, look_at, materials, scan, scan_reusing,
};

/// A sphere of radius 0.25 m on a 1 m square plane, each an n×n grid: about `triangles`.
fn sphere_on_plane(triangles: usize) -> Vec<[Vec3; 3]> {
    sensor::shapes::sphere_on_plane(((triangles / 4) as f64).sqrt() as usize)
}

const W: usize = 1944;
const H: usize = 1200;

/// The camera's rays in the order a scan casts them: 4×4 pixel blocks row by row, each as four
/// 2×2 groups (top left, top right, bottom left, bottom right), each group's pixels likewise.
fn camera_rays() -> Vec<Vec3> {
    let f = 1500.0;
    (0..W * H)
        .map(|k| {
            let (block, group, lane) = (k / 16, k / 4 % 4, k % 4);
            let (u, v) = (
                4 * (block % (W / 4)) + 2 * (group % 2) + lane % 2,
                4 * (block / (W / 4)) + 2 * (group / 2) + lane / 2,
            );
            Vec3::new(
                (u as f32 - W as f32 / 2.0) / f,
                (v as f32 - H as f32 / 2.0) / f,
                -1.0,
            )
            .normalize()
        })
        .collect()
}

fn raycast(c: &mut Criterion) {
    let rays = camera_rays();
    let eye = Vec3::Z;
    let mut g = c.benchmark_group("raycast");
    g.sample_size(10);
    for size in [200_000, 2_000_000] {
        let tris = sphere_on_plane(size);
        let bvh = Bvh::build(&tris);
        let label = format!("{}k_triangles", tris.len() / 1000);
        g.throughput(Throughput::Elements(rays.len() as u64));
        g.bench_function(format!("primary_{label}"), |b| {
            b.iter(|| {
                rays.par_chunks(4096)
                    .map(|rs| {
                        rs.iter()
                            .filter(|d| bvh.cast(eye, **d, 10.0).is_some())
                            .count()
                    })
                    .sum::<usize>()
            })
        });
        g.bench_function(format!("primary_packets_{label}"), |b| {
            b.iter(|| {
                rays.par_chunks(4096)
                    .map(|rs| {
                        rs.chunks_exact(16)
                            .map(|d| {
                                let d =
                                    std::array::from_fn(|g| std::array::from_fn(|k| d[4 * g + k]));
                                let hits = bvh.cast_packet(&[[eye; 4]; 4], &d, &[[10.0; 4]; 4]);
                                hits.iter().flatten().filter(|h| h.is_some()).count()
                            })
                            .sum::<usize>()
                    })
                    .sum::<usize>()
            })
        });
        g.throughput(Throughput::Elements(tris.len() as u64));
        g.bench_function(format!("build_{label}"), |b| {
            b.iter(|| black_box(Bvh::build(&tris).len()))
        });
    }
    g.finish();
}

/// A full Zivid 2+ M130 frame (2448 x 2048 camera rays, a projector ray per hit, every noise
/// model of the preset, the organized scan in memory) of the 200k-triangle world from 1.3 m.
fn zivid_frame(c: &mut Criterion) {
    // a polished steel ball on a grey table: the ball's pixels mirror the table (the sphere
    // and the plane are each half the triangles)
    let tris = sphere_on_plane(200_000);
    let (ball, table) = tris.split_at(tris.len() / 2);
    let world = World::new(&[
        Target::from_triangles(ball, 1, 1, materials::STAINLESS_STEEL),
        Target::from_triangles(table, 2, 2, materials::MATTE_GREY),
    ]);
    let sensor = SensorSpec::preset("zivid-2plus-m130").unwrap();
    let pose: Affine3A = look_at(
        Vec3::new(0.1, -0.2, 1.28),
        Vec3::new(0.0, 0.0, 0.1),
        Vec3::Y,
    )
    .unwrap();
    let mut g = c.benchmark_group("scan");
    g.sample_size(10);
    g.throughput(Throughput::Elements(1));
    // each frame into fresh memory (dropped outside the timing, as criterion does with outputs
    // of `iter_batched`)
    g.bench_function("zivid_2plus_m130_frame_200k_triangles", |b| {
        b.iter_batched(
            || (),
            |()| scan(&world, &sensor, &pose, 1),
            BatchSize::PerIteration,
        )
    });
    // frame after frame into one buffer, as a camera loop or a dataset worker scans
    let mut earlier = Scan::default();
    g.bench_function("zivid_2plus_m130_frame_200k_triangles_reused_buffer", |b| {
        b.iter(|| {
            let frame = scan_reusing(
                &world,
                &sensor,
                &pose,
                1,
                None,
                std::mem::take(&mut earlier),
            );
            earlier = black_box(frame);
        })
    });
    // the same frame with one of the preset's error models off, and with none
    type Off = fn(&mut SensorSpec);
    let variants: [(&str, Off); 9] = [
        ("without_snr", |s| s.noise.snr = Default::default()),
        ("without_correlation", |s| {
            s.noise.correlated = Default::default()
        }),
        ("without_wings", |s| s.noise.wings = Default::default()),
        ("without_interreflection", |s| {
            s.noise.interreflection = Default::default()
        }),
        ("without_diffuse_interreflection", |s| {
            s.noise.interreflection.diffuse_reach = 0.0
        }),
        ("without_specular", |s| {
            s.noise.specular = Default::default()
        }),
        ("without_colour", |s| {
            s.colour.capture = ColourCapture::ThreeD
        }),
        ("without_calibration_error", |s| {
            s.calibration = Default::default()
        }),
        ("without_noise", |s| {
            s.noise = Default::default();
            s.calibration = Default::default();
        }),
    ];
    for (name, off) in variants {
        let mut spec = sensor.clone();
        off(&mut spec);
        g.bench_function(
            format!("zivid_2plus_m130_frame_200k_triangles_{name}"),
            |b| {
                b.iter_batched(
                    || (),
                    |()| scan(&world, &spec, &pose, 1),
                    BatchSize::PerIteration,
                )
            },
        );
    }
    g.finish();
}

criterion_group!(benches, raycast, zivid_frame);
criterion_main!(benches);
