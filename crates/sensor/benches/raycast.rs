//! Primary-ray throughput of the BVH on tessellated spheres of about 200k and 2M triangles, seen
//! by a 1944 x 1200 pinhole camera (the Zivid 2 resolution), on all threads.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use rayon::prelude::*;
use sensor::Bvh;

/// A UV sphere of radius 0.3 m at 1 m with about `2·n²` triangles.
fn sphere(n: usize) -> Vec<[Vec3; 3]> {
    let p = |i: usize, j: usize| {
        let (th, ph) = (
            std::f32::consts::PI * i as f32 / n as f32,
            std::f32::consts::TAU * j as f32 / n as f32,
        );
        Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * 0.3 + Vec3::Z
    };
    let mut t = Vec::with_capacity(2 * n * n);
    for i in 0..n {
        for j in 0..n {
            t.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            t.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    t
}

const W: usize = 1944;
const H: usize = 1200;

fn camera_rays() -> Vec<Vec3> {
    let f = 1800.0;
    (0..W * H)
        .map(|k| {
            Vec3::new(
                ((k % W) as f32 - W as f32 / 2.0) / f,
                ((k / W) as f32 - H as f32 / 2.0) / f,
                1.0,
            )
            .normalize()
        })
        .collect()
}

fn raycast(c: &mut Criterion) {
    let rays = camera_rays();
    let mut g = c.benchmark_group("raycast");
    g.sample_size(10);
    g.throughput(Throughput::Elements(rays.len() as u64));
    for n in [316, 1000] {
        let tris = sphere(n);
        let bvh = Bvh::build(&tris);
        let label = format!("{}k_triangles", tris.len() / 1000);
        g.bench_function(format!("primary_{label}"), |b| {
            b.iter(|| {
                let hits: usize = rays
                    .par_chunks(W)
                    .map(|row| {
                        row.iter()
                            .filter(|d| bvh.cast(Vec3::ZERO, **d, 10.0).is_some())
                            .count()
                    })
                    .sum();
                black_box(hits)
            })
        });
        g.bench_function(format!("build_{label}"), |b| {
            b.iter(|| black_box(Bvh::build(&tris).len()))
        });
    }
    g.finish();
}

criterion_group!(benches, raycast);
criterion_main!(benches);
