//! Surface import and tetrahedralization: typed errors on bad input, and the tetrahedra
//! contain the surface they were made from.
#![cfg(feature = "mesher")]

use nalgebra::Vector3;
use tetpbd::SoftBodyBuilder;
use tetpbd_io::{shapes, Skin, SurfaceError, SurfaceMesh, TetrahedralizeBuilder};

const TET_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

fn tet_surface() -> SurfaceMesh {
    SurfaceMesh::from_obj_str(TET_OBJ).unwrap()
}

#[test]
fn array_errors_name_the_culprit() {
    let v = tet_surface().vertices;
    let e = SurfaceMesh::new(vec![], vec![]).unwrap_err();
    assert!(
        matches!(
            e,
            SurfaceError::Empty {
                vertices: 0,
                triangles: 0
            }
        ),
        "{e}"
    );
    let e = SurfaceMesh::new(v.clone(), vec![]).unwrap_err();
    assert!(
        matches!(
            e,
            SurfaceError::Empty {
                vertices: 4,
                triangles: 0
            }
        ),
        "{e}"
    );

    let e = SurfaceMesh::new(v.clone(), vec![[0, 1, 2], [0, 1, 7]]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "triangle 1: vertex 7 does not exist (4 vertices)"
    );
    assert!(matches!(
        e,
        SurfaceError::IndexOutOfRange {
            triangle: 1,
            index: 7,
            vertex_count: 4
        }
    ));

    let mut bad = v.clone();
    bad[2].y = f32::NAN;
    let e = SurfaceMesh::new(bad, vec![[0, 1, 2]]).unwrap_err();
    assert!(
        matches!(e, SurfaceError::NonFinite { vertex: 2, .. }),
        "{e}"
    );

    let e = SurfaceMesh::new(v, vec![[0, 1, 1]]).unwrap_err();
    assert!(
        matches!(e, SurfaceError::DegenerateTriangle { triangle: 0 }),
        "{e}"
    );
}

#[test]
fn topology_errors() {
    let v = tet_surface().vertices;
    let open = SurfaceMesh::new(v.clone(), vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]]).unwrap();
    let e = open.closed().unwrap_err();
    assert!(matches!(e, SurfaceError::OpenEdge { .. }), "{e}");
    // Also through the tetrahedralizer.
    let e = TetrahedralizeBuilder::new(0.2).build(&open).unwrap_err();
    assert!(matches!(e, SurfaceError::OpenEdge { .. }), "{e}");

    // One face flipped.
    let flipped =
        SurfaceMesh::new(v.clone(), vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 3, 2]]).unwrap();
    let e = flipped.closed().unwrap_err();
    assert!(
        matches!(e, SurfaceError::InconsistentOrientation { .. }),
        "{e}"
    );

    // Two tetrahedra glued along a fin: edge 0-1 has three triangles... and a fourth.
    let mut v5 = v.clone();
    v5.push(Vector3::new(0.0, -1.0, 0.0));
    let tris = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 1, 4]];
    let e = SurfaceMesh::new(v5, tris).unwrap().closed().unwrap_err();
    assert!(
        matches!(
            e,
            SurfaceError::NonManifoldEdge {
                a: 0,
                b: 1,
                triangles: 3
            }
        ),
        "{e}"
    );

    // A closed surface with no volume (two copies of one triangle, back to back).
    let flat = SurfaceMesh::new(v, vec![[0, 1, 2], [0, 2, 1]]).unwrap();
    let e = flat.closed().unwrap_err();
    assert!(matches!(e, SurfaceError::ZeroVolume), "{e}");
}

#[test]
fn duplicated_vertices_are_welded_and_inward_winding_flipped() {
    // Each face with its own three vertices (as OBJ exporters write seams), wound inward.
    let s = tet_surface();
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for t in &s.triangles {
        let base = vertices.len() as u32;
        vertices.extend(t.iter().map(|&i| s.vertices[i as usize]));
        triangles.push([base, base + 2, base + 1]);
    }
    let split = SurfaceMesh::new(vertices, triangles).unwrap();
    assert!(split.enclosed_volume() < 0.0);
    let closed = split.closed().unwrap();
    assert_eq!(closed.vertices.len(), 4);
    assert!((closed.enclosed_volume() - 1.0 / 6.0).abs() < 1e-6);
}

#[test]
fn cell_size_errors() {
    let s = tet_surface();
    for value in [0.0, -0.1, f32::NAN, f32::INFINITY] {
        let e = TetrahedralizeBuilder::new(value).build(&s).unwrap_err();
        assert!(
            matches!(e, SurfaceError::BadCellSize { .. }),
            "{value}: {e}"
        );
    }
    let e = TetrahedralizeBuilder::new(1e-6).build(&s).unwrap_err();
    assert!(
        matches!(
            e,
            SurfaceError::TooManyLatticePoints {
                limit: 2_000_000,
                ..
            }
        ),
        "{e}"
    );
    let e = TetrahedralizeBuilder::new(0.1)
        .max_lattice_points(100)
        .build(&s)
        .unwrap_err();
    assert!(
        matches!(e, SurfaceError::TooManyLatticePoints { limit: 100, .. }),
        "{e}"
    );
}

#[test]
fn obj_errors() {
    let e = SurfaceMesh::from_obj_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap_err();
    assert!(
        matches!(
            e,
            SurfaceError::Obj(_) | SurfaceError::IndexOutOfRange { .. }
        ),
        "{e}"
    );
    let e = SurfaceMesh::from_obj_str("v 0 zero 0\n").unwrap_err();
    assert!(matches!(e, SurfaceError::Obj(_)), "{e}");
    let e = SurfaceMesh::from_obj_str("# nothing\n").unwrap_err();
    assert!(matches!(e, SurfaceError::Empty { .. }), "{e}");
    let e = SurfaceMesh::read_obj("/nonexistent/dir/mesh.obj").unwrap_err();
    assert!(matches!(e, SurfaceError::Io { .. }), "{e}");
    assert!(e.to_string().contains("/nonexistent/dir/mesh.obj"));
}

#[test]
fn torus_tetrahedra_contain_the_surface_and_build() {
    let torus = shapes::torus(0.3, 0.12, 32, 16);
    for (smoothing, cell) in [(0, 0.08), (3, 0.06)] {
        let mesh = TetrahedralizeBuilder::new(cell)
            .smoothing(smoothing)
            .build(&torus)
            .unwrap();
        let body = SoftBodyBuilder::new(mesh.clone())
            .edges(0.0)
            .volume(0.0)
            .build()
            .unwrap();
        let tet_volume: f32 = body.tetrahedra.rest_volumes().iter().sum();
        let surface_volume = torus.enclosed_volume();
        assert!(
            tet_volume > surface_volume,
            "{tet_volume} vs {surface_volume}"
        );
        // Not grossly bigger: within the cover's margin of about a cell around the tube.
        assert!(
            tet_volume < 4.0 * surface_volume,
            "{tet_volume} vs {surface_volume}"
        );
        // Every surface vertex is inside some tetrahedron (the hole stays open: a point on
        // the axis is outside).
        let mut points = torus.vertices.clone();
        points.push(Vector3::zeros());
        let skin = Skin::embed(&mesh.vertices, &mesh.tets, &points).unwrap();
        let inside = skin.bindings()[..torus.vertices.len()]
            .iter()
            .all(|b| b.distance == 0.0);
        assert!(inside, "max distance {}", skin.max_outside_distance());
        assert!(skin.bindings()[torus.vertices.len()].distance > 0.1);
    }
}

#[test]
fn finer_cells_give_more_tetrahedra_and_a_tighter_cover() {
    let blob = shapes::bunny_blob(2);
    let coarse = TetrahedralizeBuilder::new(0.1).build(&blob).unwrap();
    let fine = TetrahedralizeBuilder::new(0.05).build(&blob).unwrap();
    let vol = |m: &tetpbd::TetMesh| -> f32 {
        let b = SoftBodyBuilder::new(m.clone()).build().unwrap();
        b.tetrahedra.rest_volumes().iter().sum()
    };
    assert!(fine.tets.len() > 4 * coarse.tets.len());
    assert!(vol(&fine) < vol(&coarse));
    assert!(vol(&fine) > blob.enclosed_volume());
}

#[test]
fn obj_normals_texcoords_quads_and_objects() {
    // A unit cube as quads with normals and texture coordinates, split over two objects,
    // with negative (relative) indices in the second: the same surface as plain triangles.
    let text = "mtllib cube.mtl\no a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n\
v 1 1 1\nv -0 1 1 0.5 0.5 0.5\nvt 0 0\nvn 0 0 -1\nusemtl red\ns off\n\
f 1/1/1 4/1/1 3/1/1 2/1/1\nf 5//1 6//1 7//1 8//1\nf 1 2 6 5\no b\n\
f -7 -6 -2 -3\nf -6 -5 -1 -2\nf -8 -4 -1 -5\nl 1 2\n";
    let s = SurfaceMesh::from_obj_str(text).unwrap();
    assert_eq!(s.triangles.len(), 12);
    let closed = s.closed().unwrap();
    assert_eq!(closed.vertices.len(), 8);
    assert!((closed.enclosed_volume() - 1.0).abs() < 1e-6);
}
