//! One pass of each rotating LiDAR preset over a stand-in for a factory hall: a 40 m × 30 m
//! floor and its walls, 48 boxes of 1–2 m (stations, shelving) and 48 spheres of 40k triangles
//! each on them (about 2M triangles), the head 1.8 m up in the middle, on all threads.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use sensor::shapes::{rectangle, sphere};
use sensor::{LIDAR_PRESETS, Lidar, Target, World, head_pose, scan_lidar};

/// The hall's triangles.
fn hall() -> Vec<[Vec3; 3]> {
    let (x, y, z) = (Vec3::X, Vec3::Y, Vec3::Z);
    let mut tris = rectangle(Vec3::ZERO, x * 20.0, y * 15.0);
    for (centre, a) in [(x * 20.0, y), (-x * 20.0, y), (y * 15.0, x), (-y * 15.0, x)] {
        let half = if a == y { 15.0 } else { 20.0 };
        tris.extend(rectangle(centre + z * 3.0, a * half, z * 3.0));
    }
    for k in 0..48 {
        let (i, j) = ((k % 8) as f32, (k / 8) as f32);
        let centre = Vec3::new(-17.5 + 5.0 * i, -12.5 + 5.0 * j, 0.0);
        // half extents 0.5–0.9 × 0.4–0.6 × 0.5–0.8 m, standing on the floor
        let half = Vec3::new(
            0.5 + 0.1 * (k % 5) as f32,
            0.4 + 0.1 * (k % 3) as f32,
            0.5 + 0.1 * (k % 4) as f32,
        );
        let middle = centre + z * half.z;
        for (axis, u, v) in [(x, y, z), (y, z, x), (z, x, y)] {
            let (u, v, out) = (u * u.dot(half), v * v.dot(half), axis * axis.dot(half));
            tris.extend(rectangle(middle + out, u, v));
            tris.extend(rectangle(middle - out, v, u));
        }
        tris.extend(sphere(middle + z * (half.z + 0.3), 0.3, 141));
    }
    tris
}

fn passes(c: &mut Criterion) {
    let world = World::new(&[Target::from_triangles(&hall(), 1, 1, Default::default())]);
    let pose = head_pose(Vec3::new(0.1, 0.2, 1.8), Vec3::new(1.0, 0.2, 1.8), Vec3::Z).unwrap();
    let mut g = c.benchmark_group("lidar");
    g.sample_size(10);
    for name in LIDAR_PRESETS {
        let lidar = Lidar::preset(name).unwrap();
        g.throughput(Throughput::Elements(lidar.rays() as u64));
        g.bench_function(name, |b| {
            b.iter(|| scan_lidar(&world, &lidar, &pose, &Default::default(), 0))
        });
    }
    g.finish();
}

criterion_group!(benches, passes);
criterion_main!(benches);
