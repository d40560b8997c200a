//! Boolean union and difference of closed shells, for the parts the add-on builds from boxes
//! and cylinders in several directions, which no sweep makes in one piece. Manifold (its Rust
//! port, `manifold-rust`) computes them exactly on such input and returns manifold meshes.
//! They cost milliseconds, so the part builders use them only for parts that are the same in
//! every motor up to a translation, and build those once.

use glam::Vec3;
use manifold_rust::manifold::Manifold;
use manifold_rust::types::{Error, MeshGL, OpType};

use super::mesh::Mesh;

fn to_manifold(m: &Mesh) -> Manifold {
    let mesh = MeshGL {
        num_prop: 3,
        vert_properties: m.positions.iter().flat_map(|p| p.to_array()).collect(),
        tri_verts: m.triangles.iter().flatten().copied().collect(),
        ..MeshGL::default()
    };
    let solid = Manifold::from_mesh_gl(&mesh);
    assert_eq!(
        solid.status(),
        Error::NoError,
        "a CSG operand is not a closed shell"
    );
    solid
}

fn from_manifold(solid: &Manifold) -> Mesh {
    let mesh = solid.get_mesh_gl(-1);
    let stride = mesh.num_prop as usize;
    Mesh {
        positions: mesh
            .vert_properties
            .chunks_exact(stride)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect(),
        triangles: mesh
            .tri_verts
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    }
}

/// The union of closed shells (each a mesh of its own), as closed shells none of which touch.
pub fn union(shells: &[Mesh]) -> Mesh {
    let solids: Vec<Manifold> = shells.iter().map(to_manifold).collect();
    from_manifold(&Manifold::batch_boolean(&solids, OpType::Add))
}

/// `base` less every one of `cutters` (closed shells each).
pub fn difference(base: &Mesh, cutters: &[Mesh]) -> Mesh {
    let cut: Vec<Manifold> = cutters.iter().map(to_manifold).collect();
    let cut = Manifold::batch_boolean(&cut, OpType::Add);
    from_manifold(&to_manifold(base).difference(&cut))
}
