//! OBJ and VTU writers produce output with the expected counts, values and flags.

use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::nalgebra::Vector3;
use tetpbd::{SoftBody, SoftBodyBuilder, TetMesh};
use tetpbd_io::{
    surface_obj, tetrahedra_vtu, triangles_obj, write_surface_obj, write_tetrahedra_vtu, WriteError,
};

fn body(mesh: TetMesh) -> SoftBody {
    SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .build()
        .unwrap()
}

fn grid_body() -> SoftBody {
    body(box_grid(Vector3::new(2.0, 2.0, 2.0), [2, 2, 2], CellSplit::Six).unwrap())
}

/// The numbers inside the `<DataArray … Name="name" …>` element of `vtu`.
fn data_array(vtu: &str, name: &str) -> Vec<f64> {
    let start = vtu.find(&format!("Name=\"{name}\"")).unwrap();
    let body = &vtu[start..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</DataArray>").unwrap();
    body[open..close]
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn obj_of_a_grid_surface_has_its_vertices_and_triangles() {
    let b = grid_body();
    let obj = surface_obj(&b.surface, b.particles.positions()).unwrap();
    let v: Vec<Vector3<f32>> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f32> = l.split(' ').map(|t| t.parse().unwrap()).collect();
            Vector3::new(c[0], c[1], c[2])
        })
        .collect();
    let f: Vec<[usize; 3]> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| {
            let c: Vec<usize> = l.split(' ').map(|t| t.parse().unwrap()).collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    // A 2×2×2 grid: 27 vertices, 26 on the boundary; 6 sides × 4 squares × 2 triangles.
    assert_eq!(v.len(), 26);
    assert_eq!(f.len(), 48);
    // Faces point at the same positions as the surface triangles, in order and winding.
    for (face, tri) in f.iter().zip(b.surface.triangles()) {
        for k in 0..3 {
            assert_eq!(v[face[k] - 1], b.particles.positions()[tri[k] as usize]);
        }
    }
    let path = std::env::temp_dir().join(format!("tetpbd-io-{}.obj", std::process::id()));
    write_surface_obj(&path, &b.surface, b.particles.positions()).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), obj);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn unwritable_paths_are_io_errors() {
    let b = grid_body();
    let missing = std::env::temp_dir().join("tetpbd-io-no-such-dir/x/frame.vtu");
    let err = write_tetrahedra_vtu(&missing, &b.particles, &b.tetrahedra).unwrap_err();
    assert!(matches!(err, WriteError::Io(_)), "{err}");
    let err = write_surface_obj(
        missing.with_extension("obj"),
        &b.surface,
        b.particles.positions(),
    )
    .unwrap_err();
    assert!(err.to_string().starts_with("write failed: "), "{err}");
}

#[test]
fn obj_rejects_indices_past_the_positions() {
    let positions = [Vector3::zeros(); 3];
    let err = triangles_obj(&positions, &[[0, 1, 3]]).unwrap_err();
    assert!(
        matches!(err, WriteError::IndexOutOfRange { index: 3, len: 3 }),
        "{err}"
    );
}

#[test]
fn vtu_of_a_grid_at_rest() {
    let b = grid_body();
    let vtu = tetrahedra_vtu(&b.particles, &b.tetrahedra).unwrap();
    assert!(vtu.contains("<Piece NumberOfPoints=\"27\" NumberOfCells=\"48\">"));
    assert_eq!(data_array(&vtu, "connectivity").len(), 4 * 48);
    assert_eq!(data_array(&vtu, "offsets").last(), Some(&(4.0 * 48.0)));
    assert!(data_array(&vtu, "types").iter().all(|&t| t == 10.0));
    let ratio = data_array(&vtu, "volume_ratio");
    assert_eq!(ratio.len(), 48);
    assert!(ratio.iter().all(|&r| (r - 1.0).abs() < 1e-6), "{ratio:?}");
    assert_eq!(data_array(&vtu, "inverted"), vec![0.0; 48]);
    let path = std::env::temp_dir().join(format!("tetpbd-io-{}.vtu", std::process::id()));
    write_tetrahedra_vtu(&path, &b.particles, &b.tetrahedra).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), vtu);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn vtu_flags_a_mirrored_tetrahedron_and_halved_volume() {
    let unit = vec![
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(0.0, 0.0, 1.0),
    ];
    let mut b = body(TetMesh {
        vertices: unit,
        tets: vec![[0, 1, 2, 3]],
    });
    b.particles
        .set_position(3, Vector3::new(0.0, 0.0, -1.0))
        .unwrap();
    let vtu = tetrahedra_vtu(&b.particles, &b.tetrahedra).unwrap();
    assert!(vtu.contains("NumberOfPoints=\"4\" NumberOfCells=\"1\""));
    assert_eq!(data_array(&vtu, "inverted"), vec![1.0]);
    assert_eq!(data_array(&vtu, "volume_ratio"), vec![-1.0]);
    b.particles
        .set_position(3, Vector3::new(0.0, 0.0, 0.5))
        .unwrap();
    let vtu = tetrahedra_vtu(&b.particles, &b.tetrahedra).unwrap();
    assert_eq!(data_array(&vtu, "inverted"), vec![0.0]);
    assert_eq!(data_array(&vtu, "volume_ratio"), vec![0.5]);
}
