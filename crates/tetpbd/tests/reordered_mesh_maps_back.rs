//! The solver's reordering of the tetrahedra and edges is recoverable: every stored item maps
//! back to the input mesh.

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::SoftBodyBuilder;

#[test]
fn stored_tetrahedra_map_back_to_the_input() {
    let mesh = box_grid(Vector3::new(1.0, 2.0, 1.0), [3, 4, 2], CellSplit::Five).unwrap();
    let body = SoftBodyBuilder::new(mesh.clone())
        .edges(0.0)
        .build()
        .unwrap();
    let t = &body.tetrahedra;
    let mut seen = vec![false; mesh.tets.len()];
    for (k, &s) in t.source().iter().enumerate() {
        assert_eq!(t.indices()[k], mesh.tets[s as usize]);
        seen[s as usize] = true;
    }
    assert!(seen.iter().all(|s| *s));
    // Every unique edge is still there, once.
    let mut edges = body.edges.unwrap().edges().to_vec();
    edges.sort_unstable();
    assert_eq!(edges, tetpbd::unique_edges(&mesh.tets));
}
