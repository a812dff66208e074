//! Fragments of a split whose families leave their shape free (vertex–face or volume
//! constraints alone fix four or one of a tetrahedron's six shape degrees of freedom) get the
//! edges that fix it and start in their rest shape, moving rigidly with the momentum they
//! had: no inverted or stretched single tetrahedron flies off, and the split gains no
//! kinetic energy. A body whose families fix its pieces' shapes keeps them as they were.

use hecs::World;
use nalgebra::Vector3;
use tetpbd::{cut, Blade, EdgeConstraints, Particles, SoftBodyBuilder, TetMesh, Untangle};

/// Two tetrahedra sharing the face (1, 2, 3) at x = 0, one on each side.
fn pair_mesh() -> TetMesh {
    TetMesh {
        vertices: vec![
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(1.0, 0.2, 0.2),
        ],
        tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
    }
}

/// [`pair_mesh`]'s two tetrahedra, stretched along x by `stretch` and moving
/// apart at `speed` m/s, cut along that face.
fn cut_pair(
    families: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
    stretch: f32,
    speed: f32,
) -> (World, f64) {
    let mesh = pair_mesh();
    let mut world = World::new();
    let body = families(SoftBodyBuilder::new(mesh)).build().unwrap();
    let e = body.spawn(&mut world);
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        for i in 0..p.len() {
            let x = p.positions()[i];
            let moved = Vector3::new(x.x * (1.0 + stretch), x.y, x.z);
            p.set_position(i, moved).unwrap();
            let v = Vector3::new(speed * x.x.signum(), 0.1 * x.y, 0.0);
            p.set_velocity(i, v).unwrap();
        }
    }
    let before = kinetic(&world);
    let blade = Blade::Plane {
        point: Vector3::new(0.05, 0.0, 0.0),
        normal: Vector3::new(1.0, 0.0, 0.0),
    };
    let event = cut(&mut world, e, &blade).unwrap().expect("a cut");
    assert_eq!(event.pieces.len(), 2);
    (world, before)
}

fn kinetic(world: &World) -> f64 {
    let mut q = world.query::<&Particles>();
    q.iter().map(|p| f64::from(p.kinetic_energy())).sum()
}

/// The largest relative difference of an edge's length from its rest length, over every body.
fn worst_edge_strain(world: &World) -> f32 {
    let mut q = world.query::<(&Particles, &EdgeConstraints)>();
    q.iter()
        .flat_map(|(p, e)| {
            let x = p.positions();
            e.edges()
                .iter()
                .zip(e.rest_lengths())
                .map(|(&[a, b], &l)| ((x[a as usize] - x[b as usize]).norm() / l - 1.0).abs())
                .collect::<Vec<_>>()
        })
        .fold(0.0, f32::max)
}

#[test]
fn a_fragment_of_vertex_face_constraints_alone_gets_edges_and_starts_undeformed() {
    for stretch in [0.0, 0.3, 1.0] {
        for speed in [0.0, 1.0, 20.0] {
            for alpha in [0.0, 1e-6] {
                let (world, before) = cut_pair(|b| b.vertex_face(alpha), stretch, speed);
                let at = format!("stretch {stretch}, {speed} m/s, α = {alpha}");
                let with_edges = world.query::<&EdgeConstraints>().iter().count();
                assert_eq!(with_edges, 2, "{at}: each single tetrahedron has edges");
                let strain = worst_edge_strain(&world);
                assert!(strain < 1e-5, "{at}: an edge strained {strain}");
                let after = kinetic(&world);
                assert!(
                    after <= before * (1.0 + 1e-5) + 1e-9,
                    "{at}: kinetic energy {before} J before the split, {after} J after"
                );
            }
        }
    }
}

#[test]
fn a_fragment_whose_edges_fix_its_shape_keeps_its_deformation() {
    let (world, _) = cut_pair(|b| b.edges(0.0).vertex_face(0.0), 0.3, 1.0);
    let strain = worst_edge_strain(&world);
    assert!(
        strain > 0.1,
        "the stretch was kept: worst edge strain {strain}"
    );
}

/// The pieces of a cut body are untangled as the body was: every piece of a body whose
/// untangling is off has it off, every piece of a body without the component has none, and
/// the pieces of an ordinary body have it on.
#[test]
fn pieces_are_untangled_as_the_body_they_came_from() {
    for setting in [None, Some(false), Some(true)] {
        let families = |b: SoftBodyBuilder| b.edges(0.0).volume(0.0);
        let mut world = World::new();
        let mesh = pair_mesh();
        let e = families(SoftBodyBuilder::new(mesh))
            .build()
            .unwrap()
            .spawn(&mut world);
        match setting {
            None => {
                world.remove_one::<Untangle>(e).unwrap();
            }
            Some(disabled) => {
                world.get::<&mut Untangle>(e).unwrap().disabled = disabled;
            }
        }
        let blade = Blade::Plane {
            point: Vector3::new(0.05, 0.0, 0.0),
            normal: Vector3::new(1.0, 0.0, 0.0),
        };
        let event = cut(&mut world, e, &blade).unwrap().expect("a cut");
        assert_eq!(event.pieces.len(), 2);
        let bodies = world.query::<&Particles>().iter().count();
        let untangled: Vec<bool> = world
            .query::<&Untangle>()
            .iter()
            .map(|u| u.disabled)
            .collect();
        match setting {
            None => assert!(untangled.is_empty(), "{untangled:?}"),
            Some(disabled) => assert_eq!(untangled, vec![disabled; bodies], "{setting:?}"),
        }
    }
}
