//! Which surface samples can be seen from outside the motor: one sample alone ([`exposed`]),
//! or many, nearby samples together sharing what blocked their rays ([`exposed_each`]), with
//! the same answers.

use glam::Vec3;
use rayon::prelude::*;
use sensor::World;
use std::sync::LazyLock;

/// How many directions [`exposed`] tries.
const DIRECTION_COUNT: usize = 64;

/// Directions spread evenly over the sphere (a Fibonacci lattice).
static DIRECTIONS: LazyLock<Vec<Vec3>> = LazyLock::new(|| {
    const N: usize = DIRECTION_COUNT;
    (0..N)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f32 / N as f32;
            let r = (1.0 - z * z).sqrt();
            let (sin, cos) = (i as f32 * 2.399_963).sin_cos();
            Vec3::new(r * cos, r * sin, z)
        })
        .collect()
});

/// A direction `d` faces out of a surface with normal `normal` (by more than about 3°).
fn faces_out(d: Vec3, normal: Vec3) -> bool {
    d.dot(normal) > 0.05
}

/// Where the rays of a sample's bundle along `d` start: the centre ray just off the surface
/// point `p`, and four rays 0.5 mm beside it, from the surface's tangent plane.
fn bundle(p: Vec3, normal: Vec3, d: Vec3) -> (Vec3, [Vec3; 4]) {
    let from = p + 1e-5 * normal;
    let (a, b) = d.any_orthonormal_pair();
    let sides = [a, -a, b, -b].map(|o| {
        let side = from + 5e-4 * o;
        let back = (side - from).dot(normal) / d.dot(normal);
        side - back * d
    });
    (from, sides)
}

/// Whether the surface point `p` with outward `normal` can be seen from outside the motor
/// (`motor`): along one of 64 directions spread over the sphere, of those facing out of its
/// surface, a bundle of rays 1 mm across leaves the motor (the centre ray and four 0.5 mm
/// beside it, so that the gaps between parts and crevices under a millimetre do not count).
/// The magnets inside the pole pot are hidden; of the armature and the gears, what the shaft's
/// hole and the gear container's openings show is not.
pub fn exposed(motor: &World, p: Vec3, normal: Vec3) -> bool {
    let leaves = |o: Vec3, d: Vec3| !motor.occluded(o, d, f32::INFINITY);
    DIRECTIONS
        .iter()
        .filter(|&&d| faces_out(d, normal))
        .any(|&d| {
            let (from, sides) = bundle(p, normal, d);
            leaves(from, d) && sides.iter().all(|&o| leaves(o, d))
        })
}

/// Samples tested together.
const LANES: usize = 16;

/// [`exposed`] for each of the samples at `points` with outward `normals`, the same answers
/// found sooner: samples near each other and facing alike go sixteen together, trying the
/// same directions in the same order (the most outward for them first), and a ray first tries
/// the triangle that blocked the last ray along its direction, which on a hidden sample's
/// neighbours blocks theirs too, sparing their walks through the tree.
pub fn exposed_each(motor: &World, points: &[Vec3], normals: &[Vec3]) -> Vec<bool> {
    let (lo, hi) = points
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let scale = 1023.0 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_by_cached_key(|&i| {
        let (p, n) = (points[i as usize], normals[i as usize]);
        let octant = u64::from(n.x < 0.0) | u64::from(n.y < 0.0) << 1 | u64::from(n.z < 0.0) << 2;
        let cell = ((p - lo) * scale).as_uvec3();
        octant << 30 | morton(cell.x) | morton(cell.y) << 1 | morton(cell.z) << 2
    });
    let found: Vec<Vec<bool>> = order
        .par_chunks(LANES)
        .map(|chunk| {
            let samples: Vec<(Vec3, Vec3)> = chunk
                .iter()
                .map(|&i| (points[i as usize], normals[i as usize]))
                .collect();
            exposed_together(motor, &samples)
        })
        .collect();
    let mut shown = vec![false; points.len()];
    for (chunk, found) in order.chunks(LANES).zip(found) {
        for (&i, found) in chunk.iter().zip(found) {
            shown[i as usize] = found;
        }
    }
    shown
}

/// `x`'s low ten bits spread to every third bit.
fn morton(x: u32) -> u64 {
    let mut x = u64::from(x.min(1023));
    x = (x | x << 16) & 0x0300_00ff;
    x = (x | x << 8) & 0x0300_f00f;
    x = (x | x << 4) & 0x030c_30c3;
    (x | x << 2) & 0x0924_9249
}

/// [`exposed`] for a few samples (position, outward normal) near each other.
fn exposed_together(motor: &World, samples: &[(Vec3, Vec3)]) -> Vec<bool> {
    let bvh = motor.bvh();
    let mean: Vec3 = samples.iter().map(|&(_, n)| n).sum();
    let mut directions: Vec<(f32, Vec3)> = DIRECTIONS.iter().map(|&d| (d.dot(mean), d)).collect();
    directions.sort_unstable_by(|a, b| b.0.total_cmp(&a.0));
    let mut shown = vec![false; samples.len()];
    for (_, d) in directions {
        // the triangle that blocked the last ray along `d`
        let mut last: Option<u32> = None;
        let mut leaves = |o: Vec3| {
            if last.is_some_and(|slot| bvh.blocks(slot, o, d, f32::INFINITY)) {
                return false;
            }
            let blocker = bvh.occluder(o, d, f32::INFINITY);
            last = blocker.or(last);
            blocker.is_none()
        };
        for (shown, &(p, normal)) in shown.iter_mut().zip(samples) {
            if *shown || !faces_out(d, normal) {
                continue;
            }
            let (from, sides) = bundle(p, normal, d);
            *shown = leaves(from) && sides.iter().all(|&o| leaves(o));
        }
        if shown.iter().all(|&s| s) {
            break;
        }
    }
    shown
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{Kind, Object};
    use crate::coverage::{Surface, motor_world};
    use glam::Affine3A;

    #[test]
    fn packets_of_samples_find_what_single_rays_find() {
        for seed in [1, 2, 3] {
            let params = motorgen::ParamSpace::addon().sample(seed).unwrap();
            let objects: Vec<Object> = motorgen::build(&params, motorgen::Detail::Normal)
                .parts
                .iter()
                .map(|p| Object::part(p, &Affine3A::IDENTITY, Kind::Assembled { motor: 0 }))
                .collect();
            let all = Surface::sample_all(&objects, 1e5, seed);
            let motor = motor_world(&objects);
            let one: Vec<bool> = all
                .points
                .iter()
                .zip(&all.normals)
                .map(|(&p, &n)| exposed(&motor, p, n))
                .collect();
            let shown = one.iter().filter(|&&s| s).count();
            assert!(
                shown > all.len() / 4 && shown < all.len(),
                "{shown} of {}",
                all.len()
            );
            let each = exposed_each(&motor, &all.points, &all.normals);
            let differ = each.iter().zip(&one).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{differ} of {} samples differ", all.len());
        }
    }
}
