//! A plastic slab pressed by a kinematic block keeps a dent once the block is gone; an elastic
//! slab pressed the same way springs back flat.

use nalgebra::Vector3;
use rapier3d::prelude::*;
use tetpbd_rapier::prelude::*;

/// A 1 m × 0.2 m × 1 m slab on a fixed floor, pressed 5 cm deep at its centre by a 0.2 m block
/// that then leaves; returns how far the centre of the slab's top lies below its corners
/// (m) 1 s after the block left.
fn dent(plastic: bool, substeps: u32) -> f32 {
    let solver = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, CouplingSettings::default()).unwrap();
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(3.0, 0.5, 3.0),
    );
    let mesh = generators::box_grid(
        Vector3::new(1.0, 0.2, 1.0),
        [8, 2, 8],
        generators::CellSplit::Six,
    )
    .unwrap();
    let b = TetBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(1e-6)
        .vertex_face(1e-6)
        .translation(Vector3::new(0.0, 0.1, 0.0));
    let b = if plastic {
        b.plasticity(PlasticitySettings::default())
    } else {
        b
    };
    let e = b.build().unwrap().spawn(&mut scene.soft);
    let (block, _) = scene.physics.insert(
        RigidBodyBuilder::kinematic_velocity_based().translation(Vector::new(0.0, 0.31, 0.0)),
        ColliderBuilder::cuboid(0.1, 0.1, 0.1),
    );
    // Settle, press 6 cm down over 0.3 s (0.05 m into the slab), hold 0.25 s, leave upward.
    let phases = [(30, 0.0), (18, -0.2), (15, 0.0), (60, 1.0), (60, 0.0)];
    for (frames, vy) in phases {
        scene.physics.bodies[block].set_linvel(Vector::new(0.0, vy, 0.0), true);
        for _ in 0..frames {
            scene.step().unwrap();
        }
    }
    let p = scene.soft.get::<&Particles>(e).unwrap();
    let mean_y = |pick: &dyn Fn(Vector3<f32>) -> bool| {
        let ys: Vec<f32> = (0..p.len())
            .filter(|&i| p.rest_positions()[i].y > 0.099 && pick(p.rest_positions()[i]))
            .map(|i| p.positions()[i].y)
            .collect();
        ys.iter().sum::<f32>() / ys.len() as f32
    };
    let centre = mean_y(&|x| x.x.abs() < 0.07 && x.z.abs() < 0.07);
    let corners = mean_y(&|x| x.x.abs() > 0.49 && x.z.abs() > 0.49);
    corners - centre
}

#[test]
fn plastic_slab_keeps_a_dent_and_an_elastic_one_springs_back() {
    for substeps in [5, 10, 20] {
        let plastic = dent(true, substeps);
        let elastic = dent(false, substeps);
        println!("{substeps} substeps: dent {plastic:.4} m plastic, {elastic:.4} m elastic");
        assert!(
            plastic > 0.01,
            "{substeps} substeps: the plastic dent is {plastic} m"
        );
        assert!(
            elastic.abs() < 0.003,
            "{substeps} substeps: the elastic dent is {elastic} m"
        );
    }
}
