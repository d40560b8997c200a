//! Stacked solids: an outer boundary and a hole that each run along z through stretches of
//! (possibly turning) outlines, with flat steps where one outline gives way to the next. A gear
//! with its pinion or hub on one axis is such a solid.

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
/// hole, each listed from the bottom up, each stretch beginning where the one before ends; both
/// boundaries span the same z range. Where an outline changes, the one must lie strictly
/// inside the other, and every hole strictly inside the outer outline at the same height.
pub fn stack(outer: &[Stretch], hole: &[Stretch]) -> Mesh {
    let mut mesh = Mesh::default();
    let outer_rings = walls(&mut mesh, outer, false);
    let hole_rings = walls(&mut mesh, hole, true);
    let bottom_hole: Vec<&[u32]> = hole_rings
        .first()
        .map(|r| r.0.as_slice())
        .into_iter()
        .collect();
    let top_hole: Vec<&[u32]> = hole_rings
        .last()
        .map(|r| r.1.as_slice())
        .into_iter()
        .collect();
    cap(&mut mesh, &outer_rings[0].0, &bottom_hole, false);
    let top = &outer_rings[outer_rings.len() - 1].1;
    cap(&mut mesh, top, &top_hole, true);
    mesh.orient_outward()
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
        let (below, above) = (&rings[k - 1].1, &rings[k].0);
        let area = |s: &Stretch| signed_area2(&s.outline).abs();
        let below_bigger = area(&stretches[k - 1]) > area(&stretches[k]);
        // a step faces up where the solid widens below it, down where it widens above; a hole
        // turns that round
        let up = below_bigger != is_hole;
        if below_bigger {
            cap(mesh, below, &[above], up);
        } else {
            cap(mesh, above, &[below], up);
        }
    }
    rings
}
