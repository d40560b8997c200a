//! The mesh kernel: closed solids built straight from 2D profiles (sweep, revolve, extrude,
//! stack), watertight by construction, and booleans of such solids where no profile will do.

pub mod csg;
mod extrude;
mod mesh;
mod prisms;
mod stack;
mod sweep;
mod topology;
mod wedge;

pub use extrude::{Extrusion, cuboid, extrude};
pub use mesh::{Aabb, Mesh};
pub use prisms::{PlateId, Prisms, Shape};
pub use stack::{Stretch, stack};
pub use sweep::{Pocket, Section, sweep, sweep_loop};
pub use topology::{MeshReport, inspect, shell_ids};
pub use wedge::{Plane, Slope, Wedge, difference};

use glam::Vec2;
use serde::{Deserialize, Serialize};

/// Tessellation fineness: the largest allowed gap (sagitta) between a true circle and its polygon.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Detail {
    /// 0.3 mm chord error: quick previews, huge datasets.
    Coarse,
    /// 0.1 mm chord error, near the pixel pitch of a Zivid 2+ at 0.6 m.
    #[default]
    Normal,
    /// 0.02 mm chord error.
    Fine,
}

impl Detail {
    /// Allowed chord error in metres.
    pub fn tolerance(self) -> f32 {
        match self {
            Detail::Coarse => 3e-4,
            Detail::Normal => 1e-4,
            Detail::Fine => 2e-5,
        }
    }

    /// Vertices of a full circle of `radius` metres: a multiple of 4 in 8..=256.
    pub fn segments(self, radius: f32) -> usize {
        let ratio = (1.0 - self.tolerance() / radius.max(1e-6)).clamp(-1.0, 1.0);
        let n = (std::f32::consts::PI / ratio.acos()).ceil() as usize;
        n.clamp(8, 256).next_multiple_of(4)
    }
}

/// `n` points of a circle of radius `r` about `c`, counter-clockwise from angle `start`.
pub fn circle(c: Vec2, r: f32, n: usize, start: f32) -> Vec<Vec2> {
    (0..n)
        .map(|i| {
            let a = start + std::f32::consts::TAU * i as f32 / n as f32;
            c + r * Vec2::from_angle(a)
        })
        .collect()
}

/// Twice the signed area of a closed polygon: positive when counter-clockwise.
pub fn signed_area2(poly: &[Vec2]) -> f32 {
    let n = poly.len();
    (0..n).map(|i| poly[i].perp_dot(poly[(i + 1) % n])).sum()
}

/// Triangulates the planar loops `outer` and `holes` (vertex indices into `mesh`, projected to
/// xy) and adds the triangles wound counter-clockwise seen from +z when `up`, clockwise
/// otherwise. Every loop edge is used by exactly one cap triangle.
fn cap(mesh: &mut Mesh, outer: &[u32], holes: &[&[u32]], up: bool) {
    let tris = cap_triangles(mesh, outer, holes);
    mesh.triangles.extend(
        tris.into_iter()
            .map(|t| if up { t } else { [t[0], t[2], t[1]] }),
    );
}

/// The triangles of a cap over `outer` and `holes`, counter-clockwise seen from +z.
fn cap_triangles(mesh: &Mesh, outer: &[u32], holes: &[&[u32]]) -> Vec<[u32; 3]> {
    let loops = std::iter::once(outer).chain(holes.iter().copied());
    let order: Vec<u32> = loops.clone().flatten().copied().collect();
    let mut hole_starts = Vec::with_capacity(holes.len());
    let mut start = outer.len() as u32;
    for h in holes {
        hole_starts.push(start);
        start += h.len() as u32;
    }
    let xy: Vec<[f64; 2]> = order
        .iter()
        .map(|&i| {
            let p = mesh.positions[i as usize];
            [p.x as f64, p.y as f64]
        })
        .collect();
    let mut local: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut_slice(&xy, &hole_starts, &mut local);
    // Delaunay flips remove the slivers ear clipping leaves between (near) collinear vertices.
    earcut::refine(&mut local, &xy);
    local
        .chunks_exact(3)
        .map(|t| {
            let mut tri = [
                order[t[0] as usize],
                order[t[1] as usize],
                order[t[2] as usize],
            ];
            let [a, b, c] = tri.map(|i| mesh.positions[i as usize].truncate());
            if (b - a).perp_dot(c - a) < 0.0 {
                tri.swap(1, 2);
            }
            tri
        })
        .collect()
}
