//! Dropping unreferenced vertices renumbers tetrahedra and makes a Gmsh file buildable.

use tetpbd::nalgebra::Vector3;
use tetpbd::{BuildError, SoftBodyBuilder, TetMesh};
use tetpbd_io::{drop_unreferenced_vertices, read_msh_str};

#[test]
fn unused_gmsh_node_is_dropped_and_the_body_builds() {
    // Node 99 belongs only to a point element (type 15), not to the tetrahedron.
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 5 1 99\n3 1 0 5\n\
                99\n1\n2\n3\n4\n5 5 5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n\
                $Elements\n2 2 1 2\n0 1 15 1\n1 99\n3 1 4 1\n2 1 2 3 4\n$EndElements\n";
    let mesh = read_msh_str(text).unwrap();
    assert_eq!(mesh.tets, vec![[1, 2, 3, 4]]);
    let err = SoftBodyBuilder::new(mesh.clone())
        .density(1000.0)
        .build()
        .unwrap_err();
    assert_eq!(err, BuildError::UnreferencedVertex { vertex: 0 });
    let (compact, kept) = drop_unreferenced_vertices(&mesh);
    assert_eq!(kept, vec![1, 2, 3, 4]);
    assert_eq!(compact.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(compact.vertices[3], Vector3::new(0.0, 0.0, 1.0));
    assert!(SoftBodyBuilder::new(compact)
        .density(1000.0)
        .build()
        .is_ok());
}

#[test]
fn out_of_range_indices_survive_for_the_builder_to_report() {
    let mesh = TetMesh {
        vertices: vec![Vector3::zeros(); 3],
        tets: vec![[0, 1, 2, 7]],
    };
    let (compact, kept) = drop_unreferenced_vertices(&mesh);
    assert_eq!(kept, vec![0, 1, 2]);
    assert_eq!(compact.tets, vec![[0, 1, 2, 7]]);
}
