//! Edges of a mesh with its vertices identified by position, so that texture seams
//! and the per-face split of flat lighting are not edges: for wireframes and
//! silhouettes.

use crate::mesh::Mesh;
use crate::render::wire::unique_edges;

/// Edges of a mesh with vertices identified by position.
pub(super) struct Topology {
    /// The triangles' corners as position ids.
    pub(super) indices: Vec<u32>,
    /// Unique edges over position ids.
    pub(super) edges: Vec<[u32; 2]>,
    /// The faces of each edge.
    pub(super) faces: Vec<[u32; 2]>,
}

impl Topology {
    pub(super) fn of(mesh: &Mesh) -> Self {
        let mut ids = std::collections::HashMap::new();
        let id: Vec<u32> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                *ids.entry(p.to_array().map(f32::to_bits))
                    .or_insert(i as u32)
            })
            .collect();
        let indices: Vec<u32> = mesh.indices.iter().map(|&i| id[i as usize]).collect();
        let edges = unique_edges(&indices);
        let faces = edge_faces(&indices, &edges);
        Self {
            indices,
            edges,
            faces,
        }
    }

    /// Each edge as two vertices of the mesh that is drawn (whose triangles are
    /// `drawn`, in the order of the mesh the topology is of): the corners of its first
    /// face. Loading splits faces apart for flat lighting but keeps them in order.
    pub(super) fn drawn_edges(&self, drawn: &[u32]) -> Vec<[u32; 2]> {
        let corner = |face: u32, v: u32| -> u32 {
            let f = face as usize * 3;
            let k = self.indices[f..f + 3]
                .iter()
                .position(|&c| c == v)
                .unwrap_or(0);
            drawn[f + k]
        };
        self.edges
            .iter()
            .zip(&self.faces)
            .map(|(&[a, b], f)| [corner(f[0], a), corner(f[0], b)])
            .collect()
    }
}

/// For each unique edge, the triangles that share it (the second is `u32::MAX` on a
/// boundary; edges shared by more than two keep the first two).
fn edge_faces(indices: &[u32], edges: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let mut faces = vec![[u32::MAX; 2]; edges.len()];
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = [a.min(b), a.max(b)];
            if let Ok(e) = edges.binary_search(&key) {
                let f = &mut faces[e];
                if f[0] == u32::MAX {
                    f[0] = t as u32;
                } else if f[1] == u32::MAX {
                    f[1] = t as u32;
                }
            }
        }
    }
    faces
}
