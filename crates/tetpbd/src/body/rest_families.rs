//! The constraint families of a built mesh at its rest shape: edges with their rest
//! lengths, vertex–face rest heights, and the mesh's unique edges.

use crate::body::builder::TetMesh;
use crate::body::families::{EdgeConstraints, VertexFaceConstraints};
use crate::constraints::{bounded_height, VERTEX_FACE_KAPPA, VERTEX_FACE_ORDER};
use crate::ordering::partition::part_order;

/// The edge family of a built mesh (particles and tetrahedra in solver order), its edges in
/// the solver's order for the body's parts.
pub(crate) fn edge_constraints(
    mesh: &TetMesh,
    part_of: &[u32],
    parts: usize,
    alpha: f32,
) -> EdgeConstraints {
    let sorted = unique_edges(&mesh.tets);
    let (edge_order, classes) = part_order(&sorted, part_of, parts, mesh.vertices.len());
    let list: Vec<[u32; 2]> = edge_order.iter().map(|&k| sorted[k]).collect();
    let rest_lengths = list
        .iter()
        .map(|[a, b]| (mesh.vertices[*a as usize] - mesh.vertices[*b as usize]).norm())
        .collect();
    EdgeConstraints {
        lambdas: vec![0.0; list.len()],
        edges: list,
        rest_lengths,
        compliance: alpha,
        classes,
    }
}

/// The vertex–face family of a built mesh: the rest values of each tetrahedron's four
/// constraints.
pub(crate) fn vertex_face_constraints(mesh: &TetMesh, alpha: f32) -> VertexFaceConstraints {
    VertexFaceConstraints {
        rest_heights: mesh
            .tets
            .iter()
            .map(|tet| {
                VERTEX_FACE_ORDER.map(|o| {
                    let [a, b, c, d] = o.map(|k| mesh.vertices[tet[k] as usize]);
                    // The volume check guarantees a non-degenerate tetrahedron.
                    bounded_height(&a, &b, &c, &d, VERTEX_FACE_KAPPA, 0.0).unwrap_or(0.0)
                })
            })
            .collect(),
        lambdas: vec![[0.0; 4]; mesh.tets.len()],
        compliance: alpha,
    }
}

/// The unique edges of `tets`, each `[low, high]`, sorted.
pub fn unique_edges(tets: &[[u32; 4]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = Vec::with_capacity(tets.len() * 6);
    for t in tets {
        for a in 0..4 {
            for b in a + 1..4 {
                edges.push([t[a].min(t[b]), t[a].max(t[b])]);
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    edges
}
