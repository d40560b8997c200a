//! Sweeps of a (u, z) profile through a family of cross-sections: revolve for circles, and the
//! pole pot's "cylinder with two flats" for the pot, the collar and the connector insert.

use glam::{Vec2, Vec3};

use super::{cap, mesh::Mesh};

/// A family of closed, convex cross-sections in the xy plane, indexed by the profile's `u`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Section {
    /// Circles of radius `u` about the z axis (a revolve); `u = 0` collapses to a pole.
    Circle {
        /// Vertices per ring.
        segments: usize,
    },
    /// A circle of radius `radius + u` cut by two flats at |x| = `half_width + u`: the pole-pot
    /// outline offset outwards by `u`.
    FlatCircle {
        /// Radius of the nominal (u = 0) circle.
        radius: f32,
        /// Half the distance between the flats of the nominal outline.
        half_width: f32,
        /// Vertices on each of the two circular arcs.
        arc_segments: usize,
    },
}

/// A blind pocket sunk from the top cap of a sweep: the outline (inside the top ring) and depth.
#[derive(Clone, Debug, PartialEq)]
pub struct Pocket {
    /// Closed outline in the xy plane.
    pub outline: Vec<Vec2>,
    /// Depth below the top cap, in metres.
    pub depth: f32,
}

impl Section {
    /// Whether the ring at `u` collapses to a point on the axis.
    fn collapses(&self, u: f32) -> bool {
        matches!(self, Section::Circle { .. }) && u <= 0.0
    }

    /// The ring at `u`, counter-clockwise seen from +z.
    pub fn ring(&self, u: f32) -> Vec<Vec2> {
        match *self {
            Section::Circle { segments } => super::circle(Vec2::ZERO, u, segments, 0.0),
            Section::FlatCircle {
                radius,
                half_width,
                arc_segments,
            } => {
                let r = radius + u;
                let alpha = ((half_width + u) / r).clamp(-1.0, 1.0).acos();
                let arc = |from: f32| {
                    (0..=arc_segments).map(move |i| {
                        let a = from
                            + (std::f32::consts::PI - 2.0 * alpha) * i as f32 / arc_segments as f32;
                        r * Vec2::from_angle(a)
                    })
                };
                arc(alpha)
                    .chain(arc(std::f32::consts::PI + alpha))
                    .collect()
            }
        }
    }
}

/// Sweeps an open profile of (u, z) points through `section`. Both ends are closed: a circle end
/// at u = 0 becomes a pole, any other end a flat cap. `pockets` are sunk into the last cap, which
/// must then be the top of the solid. Returns one closed shell facing outwards.
pub fn sweep(section: &Section, profile: &[Vec2], pockets: &[Pocket]) -> Mesh {
    let mut mesh = Mesh::default();
    let rings: Vec<Vec<u32>> = profile
        .iter()
        .map(|p| add_ring(&mut mesh, section, *p))
        .collect();
    for pair in rings.windows(2) {
        band(&mut mesh, &pair[0], &pair[1]);
    }
    if rings[0].len() > 1 {
        cap(&mut mesh, &rings[0], &[], false);
    }
    let last = rings.last().expect("a profile has points");
    if last.len() > 1 {
        let top = profile.last().expect("a profile has points").y;
        let pocket_rings: Vec<Vec<u32>> = pockets
            .iter()
            .map(|p| {
                ccw(&p.outline)
                    .into_iter()
                    .map(|q| mesh.vertex(q.extend(top)))
                    .collect()
            })
            .collect();
        let holes: Vec<&[u32]> = pocket_rings.iter().map(Vec::as_slice).collect();
        cap(&mut mesh, last, &holes, true);
        for (ring, pocket) in pocket_rings.iter().zip(pockets) {
            let floor: Vec<u32> = ring
                .iter()
                .map(|&i| {
                    let p = mesh.positions[i as usize];
                    mesh.vertex(p - Vec3::Z * pocket.depth)
                })
                .collect();
            band(&mut mesh, ring, &floor);
            cap(&mut mesh, &floor, &[], true);
        }
    } else {
        assert!(pockets.is_empty(), "pockets need a flat top cap");
    }
    mesh.orient_outward()
}

/// Sweeps a closed profile loop of (u, z) points (a tube or ring); no point may lie on a
/// collapsing axis. Returns one closed shell facing outwards.
pub fn sweep_loop(section: &Section, profile: &[Vec2]) -> Mesh {
    let mut mesh = Mesh::default();
    let rings: Vec<Vec<u32>> = profile
        .iter()
        .map(|p| add_ring(&mut mesh, section, *p))
        .collect();
    for k in 0..rings.len() {
        band(&mut mesh, &rings[k], &rings[(k + 1) % rings.len()]);
    }
    mesh.orient_outward()
}

fn add_ring(mesh: &mut Mesh, section: &Section, p: Vec2) -> Vec<u32> {
    if section.collapses(p.x) {
        vec![mesh.vertex(Vec3::new(0.0, 0.0, p.y))]
    } else {
        section
            .ring(p.x)
            .into_iter()
            .map(|q| mesh.vertex(q.extend(p.y)))
            .collect()
    }
}

/// Joins two rings of equal length, or a ring and a pole.
fn band(mesh: &mut Mesh, a: &[u32], b: &[u32]) {
    let n = a.len().max(b.len());
    for j in 0..n {
        let k = (j + 1) % n;
        match (a.len(), b.len()) {
            (1, 1) => return,
            (1, _) => mesh.triangles.push([a[0], b[k], b[j]]),
            (_, 1) => mesh.triangles.push([a[j], a[k], b[0]]),
            _ => mesh.quad(a[j], a[k], b[k], b[j]),
        }
    }
}

/// The polygon wound counter-clockwise.
pub(crate) fn ccw(poly: &[Vec2]) -> Vec<Vec2> {
    let mut p = poly.to_vec();
    if super::signed_area2(&p) < 0.0 {
        p.reverse();
    }
    p
}
