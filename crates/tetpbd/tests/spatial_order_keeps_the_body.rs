//! Particle renumbering in rows (`SoftBodyBuilder::spatial_order`): the mapping to the
//! input mesh is exact, pins given by input vertex index hold the right physical points, and
//! the body behaves like the one built in input order.

use nalgebra::Vector3;
use tetpbd::constraints::signed_volume;
use tetpbd::generators::{box_grid, shuffled, CellSplit};
use tetpbd::{BuildError, Particles, SoftBodyBuilder, Solver, SolverSettings, Surface, TetMesh};

fn shuffled_cube(cells: u32) -> TetMesh {
    let grid = box_grid(Vector3::repeat(1.0), [cells; 3], CellSplit::Six).unwrap();
    shuffled(&grid, 7).0
}

/// Input vertices of the top face of a 1 m cube centred at the origin.
fn top_face(mesh: &TetMesh) -> Vec<u32> {
    (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > 0.4999)
        .collect()
}

#[test]
fn shuffling_keeps_the_geometry() {
    let grid = box_grid(Vector3::repeat(1.0), [2, 3, 2], CellSplit::Five).unwrap();
    let (mesh, order) = shuffled(&grid, 3);
    assert_ne!(order, (0..order.len() as u32).collect::<Vec<_>>());
    for (k, &i) in order.iter().enumerate() {
        assert_eq!(mesh.vertices[k], grid.vertices[i as usize]);
    }
    let mut a: Vec<[u32; 4]> = mesh
        .tets
        .iter()
        .map(|t| t.map(|k| order[k as usize]))
        .collect();
    let mut b = grid.tets.clone();
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b);
}

#[test]
fn a_shuffled_grid_gets_the_grid_numbering_back() {
    let grid = box_grid(Vector3::repeat(1.0), [5, 4, 3], CellSplit::Six).unwrap();
    let kept = SoftBodyBuilder::new(grid.clone())
        .spatial_order(true)
        .build()
        .unwrap();
    let identity: Vec<u32> = (0..grid.vertices.len() as u32).collect();
    assert_eq!(kept.particles.source(), identity.as_slice());
    let (mesh, order) = shuffled(&grid, 9);
    let body = SoftBodyBuilder::new(mesh)
        .spatial_order(true)
        .build()
        .unwrap();
    // Particle k is shuffled vertex source[k], which is grid vertex order[source[k]] = k.
    let back: Vec<u32> = body
        .particles
        .source()
        .iter()
        .map(|&v| order[v as usize])
        .collect();
    assert_eq!(back, identity);
}

#[test]
fn particles_map_to_input_vertices_and_back() {
    let mesh = shuffled_cube(4);
    let body = SoftBodyBuilder::new(mesh.clone())
        .spatial_order(true)
        .edges(0.0)
        .build()
        .unwrap();
    let p = &body.particles;
    let source = p.source();
    assert_ne!(source, (0..p.len() as u32).collect::<Vec<_>>().as_slice());
    let mut sorted = source.to_vec();
    sorted.sort_unstable();
    assert_eq!(sorted, (0..mesh.vertices.len() as u32).collect::<Vec<_>>());
    for (k, &v) in source.iter().enumerate() {
        assert_eq!(p.particle_of(v), Some(k as u32));
        assert_eq!(p.rest_positions()[k], mesh.vertices[v as usize]);
        assert_eq!(p.positions()[k], mesh.vertices[v as usize]);
    }
    assert_eq!(p.particle_of(mesh.vertices.len() as u32), None);
    // Tetrahedra: same corners in the same order (so the same signed volume), mapped back
    // through both sources.
    let t = &body.tetrahedra;
    let mut seen = vec![false; mesh.tets.len()];
    for (k, tet) in t.indices().iter().enumerate() {
        let input = t.source()[k] as usize;
        assert_eq!(tet.map(|i| source[i as usize]), mesh.tets[input]);
        let [a, b, c, d] = mesh.tets[input].map(|i| mesh.vertices[i as usize]);
        assert_eq!(t.rest_volumes()[k], signed_volume(&a, &b, &c, &d));
        seen[input] = true;
    }
    assert!(seen.iter().all(|s| *s));
    // The surface is the input's surface, renumbered.
    let input_surface = Surface::from_tetrahedra(&mesh.tets, &mesh.vertices);
    let mut mapped: Vec<[u32; 3]> = body
        .surface
        .triangles()
        .iter()
        .map(|tri| tri.map(|i| source[i as usize]))
        .collect();
    let mut expected = input_surface.triangles().to_vec();
    for tris in [&mut mapped, &mut expected] {
        for tri in tris.iter_mut() {
            // Same winding, canonical rotation.
            let m = (0..3).min_by_key(|&k| tri[k]).unwrap();
            tri.rotate_left(m);
        }
        tris.sort_unstable();
    }
    assert_eq!(mapped, expected);
    // Edges: the input's unique edges, renumbered.
    let mut edges: Vec<[u32; 2]> = body
        .edges
        .unwrap()
        .edges()
        .iter()
        .map(|e| {
            let [a, b] = e.map(|i| source[i as usize]);
            [a.min(b), a.max(b)]
        })
        .collect();
    edges.sort_unstable();
    assert_eq!(edges, tetpbd::unique_edges(&mesh.tets));
}

#[test]
fn the_renumbered_order_is_more_local() {
    // Mean index distance between the particles of a tetrahedron: small after renumbering.
    let mesh = shuffled_cube(8);
    let spread = |p: &Particles, tets: &[[u32; 4]]| {
        let _ = p;
        tets.iter()
            .map(|t| (t.iter().max().unwrap() - t.iter().min().unwrap()) as f64)
            .sum::<f64>()
            / tets.len() as f64
    };
    let off = SoftBodyBuilder::new(mesh.clone())
        .spatial_order(false)
        .build()
        .unwrap();
    let on = SoftBodyBuilder::new(mesh)
        .spatial_order(true)
        .build()
        .unwrap();
    let s_off = spread(&off.particles, off.tetrahedra.indices());
    let s_on = spread(&on.particles, on.tetrahedra.indices());
    assert!(
        s_on * 4.0 < s_off,
        "index spread {s_on} (on) vs {s_off} (off)"
    );
}

#[test]
fn pins_given_by_input_vertex_hold_those_points() {
    let mesh = shuffled_cube(3);
    let top = top_face(&mesh);
    let body = SoftBodyBuilder::new(mesh.clone())
        .spatial_order(true)
        .edges(1e-5)
        .volume(1e-6)
        .pinned(top.iter().copied())
        .build()
        .unwrap();
    let mut world = hecs::World::new();
    let e = body.spawn(&mut world);
    let mut solver = Solver::new(SolverSettings::default()).unwrap();
    for _ in 0..30 {
        solver.step(&mut world).unwrap();
    }
    let p = world.get::<&Particles>(e).unwrap();
    let pinned = (0..p.len()).filter(|&k| p.is_pinned(k)).count();
    assert_eq!(pinned, top.len());
    for &v in &top {
        let k = p.particle_of(v).unwrap() as usize;
        assert!(p.is_pinned(k), "vertex {v} (particle {k}) is not pinned");
        assert_eq!(p.positions()[k], mesh.vertices[v as usize]);
    }
    // The rest of the cube hangs: the bottom face sank.
    let bottom = (0..mesh.vertices.len() as u32)
        .find(|&v| mesh.vertices[v as usize].y < -0.4999)
        .unwrap();
    let k = p.particle_of(bottom).unwrap() as usize;
    assert!(p.positions()[k].y < mesh.vertices[bottom as usize].y - 1e-2);
}

#[test]
fn renumbered_and_input_order_bodies_agree() {
    let mesh = shuffled_cube(3);
    let top = top_face(&mesh);
    let mut world = hecs::World::new();
    let bodies = [false, true].map(|on| {
        SoftBodyBuilder::new(mesh.clone())
            .spatial_order(on)
            .edges(1e-5)
            .volume(1e-6)
            .pinned(top.iter().copied())
            .build()
            .unwrap()
            .spawn(&mut world)
    });
    let mut solver = Solver::new(SolverSettings::default()).unwrap();
    for _ in 0..60 {
        solver.step(&mut world).unwrap();
    }
    let off = world.get::<&Particles>(bodies[0]).unwrap();
    let on = world.get::<&Particles>(bodies[1]).unwrap();
    assert_eq!(
        off.source(),
        (0..off.len() as u32).collect::<Vec<_>>().as_slice()
    );
    // Gauss–Seidel visits the constraints in another order, so the states differ by the
    // solver's convergence error, not more.
    let mut worst = 0.0f32;
    for v in 0..mesh.vertices.len() as u32 {
        let a = off.positions()[v as usize];
        let b = on.positions()[on.particle_of(v).unwrap() as usize];
        worst = worst.max((a - b).norm());
    }
    let sag = mesh
        .vertices
        .iter()
        .map(|x| x.y)
        .fold(f32::INFINITY, f32::min)
        - off.aabb().0.y;
    println!("sag {sag} m, largest difference {worst} m");
    assert!(sag > 5e-3, "the cube hangs (sag {sag} m)");
    assert!(
        worst < 0.2 * sag,
        "largest difference {worst} m, sag {sag} m"
    );
}

#[test]
fn errors_name_input_indices() {
    let mesh = shuffled_cube(2);
    let n = mesh.vertices.len() as u32;
    let err = SoftBodyBuilder::new(mesh.clone())
        .spatial_order(true)
        .pinned([n + 3])
        .build()
        .unwrap_err();
    assert_eq!(
        err,
        BuildError::PinnedOutOfRange {
            index: n + 3,
            vertex_count: n as usize
        }
    );
    let mut bad = mesh;
    bad.tets[5][2] = n;
    let err = SoftBodyBuilder::new(bad)
        .spatial_order(true)
        .build()
        .unwrap_err();
    assert_eq!(
        err,
        BuildError::IndexOutOfRange {
            tet: 5,
            index: n,
            vertex_count: n as usize
        }
    );
}
