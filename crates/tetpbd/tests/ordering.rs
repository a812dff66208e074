//! Solver order: colour classes share no particle, and the reordering is recoverable.

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::ordering::greedy_colours;
use tetpbd::SoftBodyBuilder;

#[test]
fn items_of_one_colour_share_no_particle() {
    let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [4, 4, 4], CellSplit::Six).unwrap();
    let n = mesh.vertices.len();
    let colours = greedy_colours(&mesh.tets, n);
    let max = *colours.iter().max().unwrap();
    assert!(max < 63, "the grid needs {} colours", max + 1);
    for c in 0..=max {
        let mut seen = vec![false; n];
        for (t, tet) in mesh
            .tets
            .iter()
            .enumerate()
            .filter(|(t, _)| colours[*t] == c)
        {
            for &i in tet {
                assert!(
                    !seen[i as usize],
                    "colour {c}: tetrahedron {t} reuses particle {i}"
                );
                seen[i as usize] = true;
            }
        }
    }
}

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
