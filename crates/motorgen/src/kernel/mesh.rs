//! Indexed triangle meshes and their affine transforms.

use glam::{Affine3A, DVec3, Vec3};
use serde::Serialize;

/// An indexed triangle mesh in metres; triangles wind counter-clockwise seen from outside.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box, the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// The smallest box holding both.
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Edge lengths.
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Centre point.
    pub fn centre(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Appends another mesh's vertices and triangles.
    pub fn append(&mut self, other: &Mesh) {
        let offset = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]),
        );
    }

    /// Applies an affine transform; a mirroring transform also reverses the winding so that
    /// normals keep pointing outwards.
    pub fn transform(&mut self, t: &Affine3A) {
        for p in &mut self.positions {
            *p = t.transform_point3(*p);
        }
        if t.matrix3.determinant() < 0.0 {
            self.flip();
        }
    }

    /// The mesh under an affine transform (see [`Mesh::transform`]).
    pub fn transformed(mut self, t: &Affine3A) -> Mesh {
        self.transform(t);
        self
    }

    /// Reverses the winding of every triangle.
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    /// Bounding box of the vertices ([`Aabb::EMPTY`] for an empty mesh).
    pub fn bounds(&self) -> Aabb {
        self.positions.iter().fold(Aabb::EMPTY, |b, &p| Aabb {
            min: b.min.min(p),
            max: b.max.max(p),
        })
    }

    /// Signed enclosed volume (divergence theorem, accumulated in f64); positive for a closed
    /// mesh whose triangles face outwards.
    // kept out of line: inlined into its callers' iterator chains it ran several times slower
    #[inline(never)]
    pub fn signed_volume(&self) -> f64 {
        let positions: Vec<DVec3> = self.positions.iter().map(|p| p.as_dvec3()).collect();
        let mut sum = 0.0f64;
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            sum += a.dot(b.cross(c));
        }
        sum / 6.0
    }

    /// Flips a single closed shell so that it encloses positive volume.
    pub(crate) fn orient_outward(mut self) -> Mesh {
        if self.signed_volume() < 0.0 {
            self.flip();
        }
        self
    }

    /// Adds a vertex and returns its index.
    pub(crate) fn vertex(&mut self, p: Vec3) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }

    /// Adds the quad a-b-c-d as two triangles.
    pub(crate) fn quad(&mut self, a: u32, b: u32, c: u32, d: u32) {
        self.triangles.push([a, b, c]);
        self.triangles.push([a, c, d]);
    }
}
