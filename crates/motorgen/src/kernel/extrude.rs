//! Straight extrusions of planar polygons with holes.

use glam::{Vec2, Vec3};

use super::{cap_triangles, mesh::Mesh, sweep::ccw};

/// A polygon with holes, extruded along z from `z0` to `z1`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Extrusion {
    /// Outer boundary.
    pub outer: Vec<Vec2>,
    /// Through-holes, each strictly inside `outer` and apart from each other.
    pub holes: Vec<Vec<Vec2>>,
    /// Bottom.
    pub z0: f32,
    /// Top.
    pub z1: f32,
}

/// Builds an extrusion as one closed shell facing outwards.
pub fn extrude(e: &Extrusion) -> Mesh {
    let mut mesh = Mesh::default();
    let mut layer = |poly: &[Vec2], z: f32| -> Vec<u32> {
        poly.iter().map(|&p| mesh.vertex(p.extend(z))).collect()
    };
    let loops: Vec<Vec<Vec2>> = std::iter::once(ccw(&e.outer))
        .chain(e.holes.iter().map(|h| ccw(h)))
        .collect();
    let bottoms: Vec<Vec<u32>> = loops.iter().map(|l| layer(l, e.z0)).collect();
    let tops: Vec<Vec<u32>> = loops.iter().map(|l| layer(l, e.z1)).collect();
    for (k, (b, t)) in bottoms.iter().zip(&tops).enumerate() {
        let n = b.len();
        for j in 0..n {
            let j1 = (j + 1) % n;
            if k == 0 {
                mesh.quad(b[j], b[j1], t[j1], t[j]);
            } else {
                mesh.quad(b[j1], b[j], t[j], t[j1]);
            }
        }
    }
    // one triangulation for both caps: the top's vertices follow the bottom's, one layer on
    let layer = mesh.positions.len() as u32 / 2;
    let bottom = cap_triangles(&mesh, &bottoms[0], &inner_loops(&bottoms));
    for t in bottom {
        mesh.triangles.push([t[0], t[2], t[1]]);
        mesh.triangles.push(t.map(|v| v + layer));
    }
    if e.z1 < e.z0 {
        mesh.flip();
    }
    mesh
}

fn inner_loops(rings: &[Vec<u32>]) -> Vec<&[u32]> {
    rings[1..].iter().map(Vec::as_slice).collect()
}

/// An axis-aligned box between two corners.
pub fn cuboid(min: Vec3, max: Vec3) -> Mesh {
    let outer = vec![
        Vec2::new(min.x, min.y),
        Vec2::new(max.x, min.y),
        Vec2::new(max.x, max.y),
        Vec2::new(min.x, max.y),
    ];
    extrude(&Extrusion {
        outer,
        z0: min.z,
        z1: max.z,
        ..Extrusion::default()
    })
}
