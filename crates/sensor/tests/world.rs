//! `sensor::World`: what a hit carries is its own triangle's, whichever slot of the tree holds
//! the triangle, for single rays and packets alike.

use glam::Vec3;
use sensor::shapes::sphere;
use sensor::{Classes, Material, Target, World};

/// A small deterministic generator (xorshift64*), uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Three spheres side by side, each its own target and instance, every triangle of the second
/// and third its own class (the first one class).
fn targets() -> Vec<Target> {
    (0..3)
        .map(|k| {
            let tris = sphere(Vec3::new(k as f32 * 0.3, 0.0, 0.0), 0.12, 24);
            let mut target = Target::from_triangles(&tris, 7, 10 + k, Material::default());
            if k > 0 {
                let classes = (0..tris.len()).map(|i| (i * 7 + k as usize) as u16 % 500);
                target.classes = Classes::PerTriangle(classes.collect());
            }
            target
        })
        .collect()
}

/// The (target, triangle within it) of a world triangle, numbered target by target.
fn owner(targets: &[Target], mut triangle: usize) -> (usize, usize) {
    for (k, t) in targets.iter().enumerate() {
        if triangle < t.triangles.len() {
            return (k, triangle);
        }
        triangle -= t.triangles.len();
    }
    panic!("triangle {triangle} past the world's");
}

#[test]
fn a_hit_carries_its_own_triangles_class_instance_and_normal() {
    let targets = targets();
    let world = World::new(&targets);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut hits, mut rays) = (0, 0);
    for _ in 0..200 {
        // a packet of 16 rays from one point above towards the spheres
        let origin = Vec3::new(rng.next() * 0.6, -1.0, rng.next() - 0.5);
        let dirs: [[Vec3; 4]; 4] = std::array::from_fn(|_| {
            std::array::from_fn(|_| {
                let to = Vec3::new(rng.next() * 0.84 - 0.12, 0.0, rng.next() * 0.3 - 0.15);
                (to - origin).normalize()
            })
        });
        let packet = world.cast_packet(&[[origin; 4]; 4], &dirs, &[[f32::INFINITY; 4]; 4]);
        for (g, lane) in (0..16).map(|i| (i / 4, i % 4)) {
            let dir = dirs[g][lane];
            let single = world.cast(origin, dir, f32::INFINITY);
            let from_packet = packet[g][lane].map(|h| world.surface(&h, origin, dir));
            assert_eq!(single, from_packet, "packet lane and single ray differ");
            rays += 1;
            let Some(hit) = single else { continue };
            hits += 1;
            let (k, i) = owner(&targets, hit.triangle as usize);
            let t = &targets[k];
            let [a, b, c] = t.triangles[i].map(|v| t.positions[v as usize]);
            let class = match &t.classes {
                Classes::Uniform(c) => *c,
                Classes::PerTriangle(v) => v[i],
            };
            assert_eq!((hit.class, hit.instance), (class, t.instance));
            let normal = (b - a).cross(c - a).normalize();
            assert_eq!(
                hit.normal,
                if normal.dot(dir) > 0.0 {
                    -normal
                } else {
                    normal
                }
            );
            // the hit point lies on that triangle's plane
            let p = origin + hit.t * dir;
            assert!((p - a).dot(normal).abs() < 1e-5, "hit off its triangle");
        }
    }
    assert!(hits > rays / 2, "{hits} of {rays} rays hit");
}
