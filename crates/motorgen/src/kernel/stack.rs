//! Stacked solids: an outer boundary and a hole that each run along z through stretches of
//! (possibly turning) outlines, with flat steps where one outline gives way to the next; the
//! hole may stop inside the solid and start again. A gear with its pinion or hub on one axis is
//! such a solid, and so is the pole pot on its shaft boss.

use glam::Vec2;

use super::{cap, mesh::Mesh, signed_area2, sweep::ccw};

/// A stretch of a boundary: `outline` held from `z0` to `z1`, turned about the z axis by
/// `turn[0]` radians at `z0` and `turn[1]` at `z1` (a helical gear's teeth inclination).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stretch {
    /// Closed outline in the xy plane.
    pub outline: Vec<Vec2>,
    /// Bottom.
    pub z0: f32,
    /// Top.
    pub z1: f32,
    /// Rotation at the bottom and at the top, radians.
    pub turn: [f32; 2],
}

/// Builds one closed shell facing outwards from the stretches of its outer boundary and of its
/// hole, each listed from the bottom up. The outer stretches each begin where the one before
/// ends; a hole stretch begins where the one before ends or higher up (the solid is full
/// between), and the hole lies within the outer boundary's z range. Where an outline changes,
/// the one must lie strictly inside the other, and every hole strictly inside the outer
/// outline at the same height.
pub fn stack(outer: &[Stretch], hole: &[Stretch]) -> Mesh {
    let mut mesh = Mesh::default();
    let outer_rings = walls(&mut mesh, outer, false);
    let hole_rings = walls(&mut mesh, hole, true);
    let (bottom, top) = (outer[0].z0, outer[outer.len() - 1].z1);
    let bottom_hole: Vec<&[u32]> = match (hole.first(), hole_rings.first()) {
        (Some(s), Some(r)) if s.z0 == bottom => vec![r.0.as_slice()],
        _ => vec![],
    };
    let top_hole: Vec<&[u32]> = match (hole.last(), hole_rings.last()) {
        (Some(s), Some(r)) if s.z1 == top => vec![r.1.as_slice()],
        _ => vec![],
    };
    end_cap(&mut mesh, &outer_rings[0].0, &bottom_hole, false);
    let top_ring = &outer_rings[outer_rings.len() - 1].1;
    end_cap(&mut mesh, top_ring, &top_hole, true);
    // the floor and the ceiling of each stretch of hole that ends inside the solid
    for (k, s) in hole.iter().enumerate() {
        let (floor, ceiling) = (&hole_rings[k].0, &hole_rings[k].1);
        let from_below = k > 0 && hole[k - 1].z1 == s.z0;
        if !from_below && s.z0 != bottom {
            cap(&mut mesh, floor, &[], true);
        }
        let on_above = hole.get(k + 1).is_some_and(|next| next.z0 == s.z1);
        if !on_above && s.z1 != top {
            cap(&mut mesh, ceiling, &[], false);
        }
    }
    // outward by construction: walls round counter-clockwise outlines, caps wound to face out
    mesh
}

/// A cap over `outer` less `hole` (none or one).
fn end_cap(mesh: &mut Mesh, outer: &[u32], hole: &[&[u32]], up: bool) {
    match hole {
        [inner] => ring_cap(mesh, outer, inner, up),
        _ => cap(mesh, outer, hole, up),
    }
}

/// The cap between two counter-clockwise loops round the z axis, each seen from the axis as
/// one turn (star-shaped), zipped by angle: the outlines of a stack always are.
fn ring_cap(mesh: &mut Mesh, outer: &[u32], inner: &[u32], up: bool) {
    let angle = |v: u32| {
        let p = mesh.positions[v as usize];
        p.y.atan2(p.x)
    };
    // each loop's angles from the outer loop's first corner on, increasing
    let unwrap = |lp: &[u32], start: usize, from: f32| -> Vec<f32> {
        let mut last = from - std::f32::consts::PI;
        (0..=lp.len())
            .map(|k| {
                let mut a = angle(lp[(start + k) % lp.len()]);
                while a < last {
                    a += std::f32::consts::TAU;
                }
                last = a;
                a
            })
            .collect()
    };
    let a0 = angle(outer[0]);
    let j0 = (0..inner.len())
        .min_by(|&x, &y| {
            let d = |j: usize| {
                let d = (angle(inner[j]) - a0).rem_euclid(std::f32::consts::TAU);
                d.min(std::f32::consts::TAU - d)
            };
            d(x).total_cmp(&d(y))
        })
        .expect("a loop has corners");
    let ao = unwrap(outer, 0, a0);
    let ai = unwrap(inner, j0, a0);
    let (n, m) = (outer.len(), inner.len());
    let o = |i: usize| outer[i % n];
    let h = |j: usize| inner[(j0 + j) % m];
    // a triangle's height over its longest edge, in the plane
    let height = |t: [u32; 3]| {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize].truncate());
        let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
        (b - a).perp_dot(c - a).abs() / longest
    };
    let (mut i, mut j) = (0, 0);
    while i < n || j < m {
        let along_outer = [o(i), o(i + 1), h(j)];
        let along_inner = [o(i), h(j + 1), h(j)];
        // by angle, unless that triangle is a sliver (a tooth's flank in line with a hole's
        // corner) and the other is not
        let mut outer_first = j == m || (i < n && ao[i + 1] <= ai[j + 1]);
        if i < n && j < m {
            // ten times what the kernel calls degenerate, in centimetres
            let sliver = |t: [u32; 3]| height(t) < 1e-5;
            if sliver(if outer_first {
                along_outer
            } else {
                along_inner
            }) {
                outer_first = !outer_first;
            }
        }
        let tri = if outer_first {
            i += 1;
            along_outer
        } else {
            j += 1;
            along_inner
        };
        mesh.triangles
            .push(if up { tri } else { [tri[0], tri[2], tri[1]] });
    }
}

/// The side walls of one boundary and the steps between its stretches; returns each stretch's
/// bottom and top rings.
fn walls(mesh: &mut Mesh, stretches: &[Stretch], is_hole: bool) -> Vec<(Vec<u32>, Vec<u32>)> {
    let rings: Vec<(Vec<u32>, Vec<u32>)> = stretches
        .iter()
        .map(|s| {
            let outline = ccw(&s.outline);
            let mut ring = |z: f32, turn: f32| -> Vec<u32> {
                let r = Vec2::from_angle(turn);
                outline
                    .iter()
                    .map(|&p| mesh.vertex(r.rotate(p).extend(z)))
                    .collect()
            };
            (ring(s.z0, s.turn[0]), ring(s.z1, s.turn[1]))
        })
        .collect();
    for (b, t) in &rings {
        let n = b.len();
        for j in 0..n {
            let j1 = (j + 1) % n;
            if is_hole {
                mesh.quad(b[j1], b[j], t[j], t[j1]);
            } else {
                mesh.quad(b[j], b[j1], t[j1], t[j]);
            }
        }
    }
    for k in 1..stretches.len() {
        if stretches[k - 1].z1 != stretches[k].z0 {
            continue;
        }
        let (below, above) = (&rings[k - 1].1, &rings[k].0);
        let area = |s: &Stretch| signed_area2(&s.outline).abs();
        let below_bigger = area(&stretches[k - 1]) > area(&stretches[k]);
        // a step faces up where the solid widens below it, down where it widens above; a hole
        // turns that round
        let up = below_bigger != is_hole;
        if below_bigger {
            ring_cap(mesh, below, above, up);
        } else {
            ring_cap(mesh, above, below, up);
        }
    }
    rings
}
