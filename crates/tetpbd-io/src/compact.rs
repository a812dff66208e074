//! Dropping vertices no tetrahedron uses (e.g. the surface-only or geometry nodes of a Gmsh
//! file), which the soft-body builder would reject.

use tetpbd::TetMesh;

/// `mesh` without the vertices no tetrahedron refers to, and for each kept vertex its index
/// in `mesh`. Kept vertices stay in their original order; tetrahedra are renumbered.
///
/// Tetrahedron indices that are out of range are kept as they are, so the builder still
/// reports them.
pub fn drop_unreferenced_vertices(mesh: &TetMesh) -> (TetMesh, Vec<u32>) {
    let mut used = vec![false; mesh.vertices.len()];
    for &i in mesh.tets.iter().flatten() {
        if let Some(u) = used.get_mut(i as usize) {
            *u = true;
        }
    }
    let mut new_index = vec![u32::MAX; mesh.vertices.len()];
    let mut kept = Vec::new();
    let mut vertices = Vec::new();
    for (old, (&u, v)) in used.iter().zip(&mesh.vertices).enumerate() {
        if u {
            new_index[old] = kept.len() as u32;
            kept.push(old as u32);
            vertices.push(*v);
        }
    }
    let tets = mesh
        .tets
        .iter()
        .map(|t| t.map(|i| new_index.get(i as usize).copied().unwrap_or(i)))
        .collect();
    (TetMesh { vertices, tets }, kept)
}
