//! Solid-mesh invariants: closed, 2-manifold, consistently and outwardly oriented shells.

use std::collections::HashMap;

use super::mesh::Mesh;

/// What [`inspect`] found in a mesh. A valid solid has no boundary, non-manifold, misoriented,
/// degenerate or non-finite elements, and every shell encloses positive volume.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshReport {
    /// Connected components (by shared vertices).
    pub shells: usize,
    /// Edges used by a single triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges whose two triangles traverse them in the same direction.
    pub misoriented_edges: usize,
    /// Triangles with repeated vertices or (near) zero area.
    pub degenerate_triangles: usize,
    /// Vertices with NaN or infinite coordinates.
    pub non_finite_vertices: usize,
    /// Smallest signed volume of any shell, in cubic metres.
    pub min_shell_volume: f64,
}

impl MeshReport {
    /// True when the mesh is a set of closed, oriented, non-degenerate shells of positive volume.
    pub fn is_valid_solid(&self) -> bool {
        self.boundary_edges == 0
            && self.non_manifold_edges == 0
            && self.misoriented_edges == 0
            && self.degenerate_triangles == 0
            && self.non_finite_vertices == 0
            && self.shells > 0
            && self.min_shell_volume > 0.0
    }
}

/// Triangles whose height over their longest edge is below this (metres) count as degenerate:
/// 10 nm, about the resolution of f32 coordinates half a metre from the origin.
const MIN_TRIANGLE_HEIGHT: f64 = 1e-8;

/// Checks the solid-mesh invariants of `mesh`.
pub fn inspect(mesh: &Mesh) -> MeshReport {
    let mut report = MeshReport {
        non_finite_vertices: mesh.positions.iter().filter(|p| !p.is_finite()).count(),
        ..MeshReport::default()
    };

    // Directed edge -> number of triangles traversing it that way.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.triangles.len() * 3);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let height = (b - a).cross(c - a).length() / longest;
        if t[0] == t[1]
            || t[1] == t[2]
            || t[0] == t[2]
            || height.is_nan()
            || height < MIN_TRIANGLE_HEIGHT
        {
            report.degenerate_triangles += 1;
        }
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &forward) in &directed {
        let backward = directed.get(&(b, a)).copied().unwrap_or(0);
        // Visit each undirected edge once: from its smaller end, or from the only direction used.
        if a > b && backward > 0 {
            continue;
        }
        match (forward, backward) {
            (1, 1) => {}
            (f, r) if f + r == 1 => report.boundary_edges += 1,
            (f, r) if f + r > 2 => report.non_manifold_edges += 1,
            _ => report.misoriented_edges += 1,
        }
    }

    let shells = shell_ids(mesh);
    report.shells = shells.iter().copied().max().map_or(0, |m| m + 1);
    let mut volumes = vec![0.0f64; report.shells];
    for (t, &s) in mesh.triangles.iter().zip(&shells) {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
        volumes[s] += a.dot(b.cross(c)) / 6.0;
    }
    report.min_shell_volume = volumes.into_iter().fold(f64::INFINITY, f64::min);
    if report.shells == 0 {
        report.min_shell_volume = 0.0;
    }
    report
}

/// The shell (connected component) index of each triangle, numbered from 0 in order of first use.
pub fn shell_ids(mesh: &Mesh) -> Vec<usize> {
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for t in &mesh.triangles {
        let r0 = find(&mut parent, t[0]);
        for &v in &t[1..] {
            let r = find(&mut parent, v);
            parent[r as usize] = r0;
        }
    }
    let mut numbering: HashMap<u32, usize> = HashMap::new();
    mesh.triangles
        .iter()
        .map(|t| {
            let root = find(&mut parent, t[0]);
            let next = numbering.len();
            *numbering.entry(root).or_insert(next)
        })
        .collect()
}
