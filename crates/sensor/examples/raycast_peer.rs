//! Times the ray caster on a mesh and rays stored as .npy (the workload of
//! `bench/raycast_peers.py`): `raycast_peer VERTICES.npy TRIANGLES.npy RAYS.npy THREADS REPEATS
//! OUT.npy packets|single`. Prints build time, the best and median rates and the tree's bytes
//! per triangle; writes the hits (t, triangle, normal) of the last run for comparison with the
//! peer. Mode `cost` prints instead the nodes visited and triangles tested per ray (every 97th
//! ray, alone) and the tree's depth.

use std::io::Write;

use glam::Vec3;
use rayon::prelude::*;
use sensor::{Classes, Material, Target, World};

fn read<T: npyz::Deserialize>(path: &str) -> (Vec<u64>, Vec<T>) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    (npy.shape().to_vec(), npy.into_vec().unwrap())
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (threads, repeats): (usize, usize) = (a[4].parse().unwrap(), a[5].parse().unwrap());
    let packets = a.get(7).is_some_and(|m| m == "packets");
    let (_, v) = read::<f32>(&a[1]);
    let (_, t) = read::<u32>(&a[2]);
    let (_, r) = read::<f32>(&a[3]);
    let target = Target {
        positions: v.chunks_exact(3).map(Vec3::from_slice).collect(),
        triangles: t.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        classes: Classes::Uniform(1),
        instance: 1,
        material: Material::default(),
        wear: None,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let start = std::time::Instant::now();
    let world = pool.install(|| World::new(std::slice::from_ref(&target)));
    let build = start.elapsed().as_secs_f64();
    let rays: Vec<(Vec3, Vec3)> = r
        .chunks_exact(6)
        .map(|c| {
            (
                Vec3::from_slice(&c[..3]),
                // the script's unit directions as they are, the bits every peer casts
                Vec3::from_slice(&c[3..]),
            )
        })
        .collect();
    if a.get(7).is_some_and(|m| m == "cost") {
        let (mut nodes, mut tris) = (0u64, 0u64);
        for (o, d) in rays.iter().step_by(97) {
            let (n, t) = world.bvh().cost(*o, *d, f32::INFINITY);
            nodes += u64::from(n);
            tris += u64::from(t);
        }
        let rays = rays.len().div_ceil(97) as f64;
        println!(
            "{{\"nodes_per_ray\": {:.2}, \"triangles_per_ray\": {:.2}, \"depth\": {}}}",
            nodes as f64 / rays,
            tris as f64 / rays,
            world.bvh().depth()
        );
        return;
    }
    let mut out = vec![[f32::INFINITY, -1.0, 0.0, 0.0, 0.0]; rays.len()];
    let mut times = Vec::new();
    for _ in 0..repeats {
        let start = std::time::Instant::now();
        pool.install(|| {
            out.par_chunks_mut(4096)
                .zip(rays.par_chunks(4096))
                .for_each(|(o, rs)| {
                    if packets {
                        // 16 consecutive rays (a 4×4 block of 2×2 groups in the script's
                        // order) as one packet, as a scan casts them
                        for (slots, rs) in o.chunks_mut(16).zip(rs.chunks(16)) {
                            let ray = |k: usize| rs.get(k).map(|r| r.1);
                            let origins: [[Vec3; 4]; 4] = std::array::from_fn(|g| {
                                std::array::from_fn(|l| rs.get(4 * g + l).map_or(rs[0].0, |r| r.0))
                            });
                            let dirs: [[Vec3; 4]; 4] = std::array::from_fn(|g| {
                                std::array::from_fn(|l| ray(4 * g + l).unwrap_or(Vec3::Z))
                            });
                            let t_max: [[f32; 4]; 4] = std::array::from_fn(|g| {
                                std::array::from_fn(|l| {
                                    ray(4 * g + l).map_or(0.0, |_| f32::INFINITY)
                                })
                            });
                            let hits = world.cast_packet(&origins, &dirs, &t_max);
                            let rays = origins.iter().flatten().zip(dirs.iter().flatten());
                            for ((slot, h), (&o, &d)) in
                                slots.iter_mut().zip(hits.iter().flatten()).zip(rays)
                            {
                                *slot = match h.map(|h| world.surface(&h, o, d)) {
                                    Some(h) => {
                                        [h.t, h.triangle as f32, h.normal.x, h.normal.y, h.normal.z]
                                    }
                                    None => [f32::INFINITY, -1.0, 0.0, 0.0, 0.0],
                                };
                            }
                        }
                        return;
                    }
                    for (slot, (origin, dir)) in o.iter_mut().zip(rs) {
                        *slot = match world.cast(*origin, *dir, f32::INFINITY) {
                            Some(h) => [h.t, h.triangle as f32, h.normal.x, h.normal.y, h.normal.z],
                            None => [f32::INFINITY, -1.0, 0.0, 0.0, 0.0],
                        };
                    }
                })
        });
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let rate = |s: f64| rays.len() as f64 / s / 1e6;
    println!(
        "{{\"build_s\": {build:.4}, \"best_mrays\": {:.3}, \"median_mrays\": {:.3}, \"bvh_bytes_per_triangle\": {:.1}}}",
        rate(times[0]),
        rate(times[times.len() / 2]),
        world.bvh().bytes() as f64 / world.triangle_count().max(1) as f64
    );
    let mut f = std::io::BufWriter::new(std::fs::File::create(&a[6]).unwrap());
    let header = format!(
        "{{'descr': '<f4', 'fortran_order': False, 'shape': ({}, 5), }}",
        out.len()
    );
    let pad = (10 + header.len() + 1).next_multiple_of(64) - 10 - header.len() - 1;
    f.write_all(b"\x93NUMPY\x01\x00").unwrap();
    f.write_all(&((header.len() + pad + 1) as u16).to_le_bytes())
        .unwrap();
    f.write_all(format!("{header}{}\n", " ".repeat(pad)).as_bytes())
        .unwrap();
    for row in &out {
        for x in row {
            f.write_all(&x.to_le_bytes()).unwrap();
        }
    }
}
