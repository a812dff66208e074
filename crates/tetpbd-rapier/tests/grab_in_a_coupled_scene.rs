//! A grab works through the coupling: the soft solver the coupling runs projects it, so a
//! soft body grabbed in the air over a rigid floor follows a moving target.

use nalgebra::Vector3;
use rapier3d::prelude::*;
use tetpbd_rapier::prelude::*;

#[test]
fn body_grabbed_in_the_air_follows_the_target_in_a_coupled_scene() {
    for (case, substeps) in [5u32, 10, 20].into_iter().enumerate() {
        let solver = SolverSettings {
            substeps,
            ..SolverSettings::default()
        };
        let mut scene = CoupledWorld::new(solver, CouplingSettings::default()).unwrap();
        scene.physics.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
            ColliderBuilder::cuboid(3.0, 0.5, 3.0),
        );
        let size = 0.2 + 0.1 * case as f32;
        let mesh =
            generators::box_grid(Vector3::repeat(size), [3, 3, 3], generators::CellSplit::Six)
                .unwrap();
        let body = TetBodyBuilder::new(mesh)
            .density(500.0)
            .edges(1e-6)
            .volume(0.0)
            .translation(Vector3::new(0.0, 0.6, 0.0))
            .build()
            .unwrap();
        let weight = body.particles.total_mass() * 9.81;
        let top = Vector3::new(0.0, 0.6 + 0.5 * size, 0.0);
        let grab = Grab::at(
            &body.particles,
            &body.tetrahedra,
            top,
            0.01 / weight,
            5.0 * weight,
        )
        .unwrap();
        let e = body.spawn(&mut scene.soft);
        scene.soft.insert_one(e, grab).unwrap();
        let frames = 60;
        for frame in 1..=frames {
            let s = frame as f32 / frames as f32;
            let target = top + Vector3::new(0.3 * s, 0.3 * s, 0.0);
            scene
                .soft
                .get::<&mut Grab>(e)
                .unwrap()
                .set_target(target)
                .unwrap();
            scene.step().unwrap();
        }
        // Let it settle on the last target.
        for _ in 0..60 {
            scene.step().unwrap();
        }
        let p = scene.soft.get::<&Particles>(e).unwrap();
        let t = scene.soft.get::<&Tetrahedra>(e).unwrap();
        let g = scene.soft.get::<&Grab>(e).unwrap();
        let err = g.error(&p, &t).unwrap();
        assert!(
            err < 0.03,
            "{substeps} substeps: the grabbed point is {err} m off its target"
        );
        assert!(
            scene.coupling.contacts().is_empty(),
            "{substeps} substeps: the body hangs clear of the floor"
        );
    }
}
