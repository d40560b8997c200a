//! Unions of plates along z: closed shells that share nothing, the union's volume, and, on random
//! plates, the solid along vertical lines against the plates' own definition.

use glam::{Vec2, Vec3};
mod common;

use common::{assert_solid, close};
use motorgen::kernel::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Grid step of the tests' unions.
const STEP: f32 = 1e-4;

fn square(x0: f32, y0: f32, x1: f32, y1: f32) -> Vec<Vec2> {
    vec![
        Vec2::new(x0, y0),
        Vec2::new(x1, y0),
        Vec2::new(x1, y1),
        Vec2::new(x0, y1),
    ]
}

#[test]
fn overlapping_boxes_are_one_shell_of_their_union() {
    let mut p = Prisms::new(STEP);
    let a = p.shape(&square(0.0, 0.0, 2.0, 2.0));
    let b = p.shape(&square(1.0, 1.0, 3.0, 3.0));
    p.plate(&[a], &[], 0.0, 1.0);
    p.plate(&[b], &[], 0.5, 2.0);
    let m = p.mesh();
    assert_solid(&m, 1);
    assert!(close(m.signed_volume(), 4.0 + 6.0 - 0.5, 1e-6));
}

#[test]
fn a_floor_and_its_wall_overlapping_are_one_cup() {
    let n = 64;
    let mut p = Prisms::new(STEP);
    let outer = p.shape(&circle(Vec2::ZERO, 2.0, n, 0.0));
    let inner = p.shape(&circle(Vec2::ZERO, 1.8, n, 0.0));
    p.plate(&[outer], &[], 0.0, 0.2);
    p.plate(&[outer], &[inner], 0.19, 1.0);
    let m = p.mesh();
    assert_solid(&m, 1);
    let ngon = |r: f64| 0.5 * n as f64 * (std::f64::consts::TAU / n as f64).sin() * r * r;
    let expect = ngon(2.0) * 1.0 - ngon(1.8) * 0.8;
    // the corners rounded to the grid: within a grid step over the radius
    let v = m.signed_volume();
    assert!(close(v, expect, 1e-4), "{v} vs {expect}");
}

#[test]
fn plates_apart_and_islands_in_holes_are_shells_apart() {
    let mut p = Prisms::new(STEP);
    let ring = p.shape(&circle(Vec2::ZERO, 2.0, 48, 0.0));
    let hole = p.shape(&circle(Vec2::ZERO, 1.0, 48, 0.0));
    let island = p.shape(&square(-0.5, -0.5, 0.5, 0.5));
    let far = p.shape(&square(5.0, 5.0, 6.0, 6.0));
    p.plate(&[ring], &[hole], 0.0, 1.0);
    p.plate(&[island], &[], 0.0, 1.0);
    p.plate(&[far], &[], 0.0, 1.0);
    assert_solid(&p.mesh(), 3);
}

#[test]
fn cuts_take_their_range_from_every_plate() {
    // a bar with a slot cut through its middle third, from z 0.5 up: a U
    let mut p = Prisms::new(STEP);
    let bar = p.shape(&square(0.0, 0.0, 3.0, 1.0));
    let slot = p.shape(&square(1.0, -1.0, 2.0, 2.0));
    p.plate(&[bar], &[], 0.0, 2.0);
    p.cut(slot, 0.5, 3.0);
    let m = p.mesh();
    assert_solid(&m, 1);
    assert!(close(m.signed_volume(), 6.0 - 1.5, 1e-6));
    // a cut of one plate leaves the others whole
    let mut p = Prisms::new(STEP);
    let bar = p.shape(&square(0.0, 0.0, 3.0, 1.0));
    let slot = p.shape(&square(1.0, -1.0, 2.0, 2.0));
    let cut = p.plate(&[bar], &[], 0.0, 2.0);
    p.plate(&[bar], &[], 2.0, 3.0);
    p.cut_plate(cut, slot, 0.5, 3.0);
    let m = p.mesh();
    assert_solid(&m, 1);
    assert!(close(m.signed_volume(), 9.0 - 1.5, 1e-6));
}

#[test]
fn shapes_sharing_edges_and_corners_meet_in_one_shell() {
    // side by side along a shared edge, at other heights; a stack of the same square
    let mut p = Prisms::new(STEP);
    let a = p.shape(&square(0.0, 0.0, 1.0, 1.0));
    let b = p.shape(&square(1.0, 0.0, 2.0, 1.0));
    let c = p.shape(&square(0.0, 0.0, 1.0, 1.0));
    p.plate(&[a], &[], 0.0, 1.0);
    p.plate(&[b], &[], 0.5, 1.5);
    p.plate(&[c], &[], 1.0, 2.0);
    let m = p.mesh();
    assert_solid(&m, 1);
    assert!(close(m.signed_volume(), 3.0, 1e-6));
}

/// The z-intervals over `q` of plates given as (added polygons, taken polygons, z0, z1), by
/// the plates' definition: no arrangement, no grid.
/// A plate as the tests give it: polygons added, polygons taken away, z0, z1.
type Plate = (Vec<Vec<Vec2>>, Vec<Vec<Vec2>>, f32, f32);

fn intervals_at(plates: &[Plate], q: Vec2) -> Vec<[f32; 2]> {
    let inside = |poly: &Vec<Vec2>| {
        let mut wind = false;
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                wind = !wind;
            }
        }
        wind
    };
    let mut all: Vec<[f32; 2]> = plates
        .iter()
        .filter(|(add, sub, _, _)| add.iter().any(inside) && !sub.iter().any(inside))
        .map(|&(_, _, z0, z1)| [z0, z1])
        .collect();
    all.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut merged: Vec<[f32; 2]> = Vec::new();
    for [a, b] in all {
        match merged.last_mut() {
            Some(last) if a <= last[1] => last[1] = last[1].max(b),
            _ => merged.push([a, b]),
        }
    }
    merged
}

/// Heights at which the vertical line through `q` crosses the mesh's triangles.
fn crossings(m: &Mesh, q: Vec2) -> Vec<f32> {
    let mut zs = Vec::new();
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let (a2, b2, c2) = (a.truncate(), b.truncate(), c.truncate());
        let area = (b2 - a2).perp_dot(c2 - a2);
        if area.abs() < 1e-12 {
            continue;
        }
        let (u, v) = (
            (c2 - b2).perp_dot(q - b2) / area,
            (a2 - c2).perp_dot(q - c2) / area,
        );
        let w = 1.0 - u - v;
        if u >= 0.0 && v >= 0.0 && w >= 0.0 {
            zs.push(u * a.z + v * b.z + w * c.z);
        }
    }
    zs.sort_by(f32::total_cmp);
    zs
}

#[test]
fn random_plates_are_solid_and_fill_what_their_definition_fills() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for case in 0..300 {
        let mut p = Prisms::new(STEP);
        let mut plates = Vec::new();
        let polygon = |rng: &mut ChaCha8Rng| -> Vec<Vec2> {
            let c = Vec2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            match rng.random_range(0..3) {
                0 => circle(
                    c,
                    rng.random_range(0.2..1.5),
                    4 * rng.random_range(3..16),
                    rng.random(),
                ),
                1 => {
                    let s = Vec2::new(rng.random_range(0.2..1.5), rng.random_range(0.2..1.5));
                    square(c.x - s.x, c.y - s.y, c.x + s.x, c.y + s.y)
                }
                _ => {
                    // a strip at any angle
                    let d =
                        Vec2::from_angle(rng.random_range(0.0..6.3)) * rng.random_range(0.5..2.0);
                    let side = d.normalize().perp() * rng.random_range(0.05..0.3);
                    vec![c - d - side, c + d - side, c + d + side, c - d + side]
                }
            }
        };
        for _ in 0..rng.random_range(2..9) {
            let add = vec![polygon(&mut rng)];
            let sub = if rng.random_bool(0.3) {
                vec![polygon(&mut rng)]
            } else {
                vec![]
            };
            // heights on a coarse lattice, so that plates often meet exactly
            let z0 = rng.random_range(0..8) as f32 * 0.25;
            let z1 = z0 + rng.random_range(1..6) as f32 * 0.25;
            let add_ids: Vec<Shape> = add.iter().map(|s| p.shape(s)).collect();
            let sub_ids: Vec<Shape> = sub.iter().map(|s| p.shape(s)).collect();
            p.plate(&add_ids, &sub_ids, z0, z1);
            plates.push((add, sub, z0, z1));
        }
        let m = p.mesh();
        let rep = inspect(&m);
        if !rep.is_valid_solid() {
            let mut count = std::collections::HashMap::new();
            for t in &m.triangles {
                for k in 0..3 {
                    *count
                        .entry((t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
                        .or_insert(0) += 1;
                }
            }
            for ((a, b), n) in count {
                if n != 2 {
                    eprintln!(
                        "edge {} {} x{n}",
                        m.positions[a as usize], m.positions[b as usize]
                    );
                }
            }
            for (add, sub, z0, z1) in &plates {
                eprintln!("plate {add:?} - {sub:?} {z0} {z1}");
            }
        }
        assert!(rep.is_valid_solid(), "case {case}: {rep:?}");
        // along vertical lines away from every outline, the mesh bounds what the plates fill
        let outlines: Vec<(Vec2, Vec2)> = plates
            .iter()
            .flat_map(|(a, s, _, _)| a.iter().chain(s))
            .flat_map(|poly| (0..poly.len()).map(move |i| (poly[i], poly[(i + 1) % poly.len()])))
            .collect();
        let mut checked = 0;
        while checked < 200 {
            let q = Vec2::new(rng.random_range(-3.5..3.5), rng.random_range(-3.5..3.5));
            let near = outlines.iter().any(|&(a, b)| {
                let t = ((q - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                q.distance(a + t * (b - a)) < 1e-3
            });
            if near {
                continue;
            }
            checked += 1;
            let want: Vec<f32> = intervals_at(&plates, q).into_iter().flatten().collect();
            let got = crossings(&m, q);
            // a line through a vertex or edge of the caps' triangles meets several: one each
            let mut got_unique: Vec<f32> = Vec::new();
            for z in got {
                if got_unique.last().is_none_or(|l| (z - l).abs() > 1e-4) {
                    got_unique.push(z);
                }
            }
            assert_eq!(
                want.len(),
                got_unique.len(),
                "case {case} at {q}: {want:?} vs {got_unique:?}"
            );
            for (w, g) in want.iter().zip(&got_unique) {
                assert!(
                    (w - g).abs() < 1e-4,
                    "case {case} at {q}: {want:?} vs {got_unique:?}"
                );
            }
        }
    }
}

#[test]
fn mirrored_input_gives_a_mirrored_solid() {
    let mut p = Prisms::new(STEP);
    let a = p.shape(&circle(Vec2::new(0.3, 0.1), 1.0, 40, 0.0));
    let b = p.shape(&square(0.0, -0.2, 2.0, 0.2));
    p.plate(&[a], &[], 0.0, 0.5);
    p.plate(&[b], &[], 0.2, 1.0);
    let m = p.mesh();
    let mirrored = m
        .clone()
        .transformed(&glam::Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
    assert_solid(&mirrored, 1);
    assert!(close(mirrored.signed_volume(), m.signed_volume(), 1e-9));
}
