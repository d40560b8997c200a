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

/// The result in f32. Manifold keeps some vertices apart by less than f32 resolves: edges
/// shorter than a millionth of the part's size collapse, and the triangles on them are dropped.
fn from_manifold(solid: &Manifold) -> Mesh {
    let mesh = solid.get_mesh_gl(-1);
    let stride = mesh.num_prop as usize;
    let positions: Vec<Vec3> = mesh
        .vert_properties
        .chunks_exact(stride)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    let triangles: Vec<[u32; 3]> = mesh
        .tri_verts
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let bounds = Mesh {
        positions: positions.clone(),
        triangles: vec![],
    }
    .bounds();
    let tolerance = 1e-6 * bounds.size().length();
    // union-find: each vertex points towards the one it collapses into
    let mut into: Vec<u32> = (0..positions.len() as u32).collect();
    fn root(into: &mut [u32], mut v: u32) -> u32 {
        while into[v as usize] != v {
            into[v as usize] = into[into[v as usize] as usize];
            v = into[v as usize];
        }
        v
    }
    for t in &triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if positions[a as usize].distance(positions[b as usize]) < tolerance {
                let (ra, rb) = (root(&mut into, a), root(&mut into, b));
                into[ra.max(rb) as usize] = ra.min(rb);
            }
        }
    }
    // keep the vertices still in use, in their order
    let mut kept = Mesh::default();
    let mut new_index = vec![u32::MAX; positions.len()];
    for t in &triangles {
        let t = t.map(|v| root(&mut into, v));
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        let t = t.map(|v| {
            if new_index[v as usize] == u32::MAX {
                new_index[v as usize] = kept.vertex(positions[v as usize]);
            }
            new_index[v as usize]
        });
        kept.triangles.push(t);
    }
    kept
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
