//! A pull lifts a soft body that rests on something: a grab or an upward user force
//! stronger than the body's weight lifts it off a rigid floor or off another soft body,
//! whether it landed there with an impact or was placed at rest. The contacts' restitution
//! caps stop the body's own elastic recoil from bouncing it, not the user's pull.

use nalgebra::Vector3;
use rapier3d::prelude::*;
use tetpbd_rapier::prelude::*;

/// How the body is pulled.
#[derive(Clone, Copy, Debug)]
enum Pull {
    /// A grab at the body's top whose target rises 1 m over 0.5 s.
    Grab,
    /// An upward user force of `k` times the body's weight, spread over its particles.
    Force(f32),
}

/// A soft cube of `size` (m) dropped from `drop` (m) above what is under it, left to
/// settle for 1.5 s, then pulled for 1 s. Returns how high its centre of mass rose (m).
fn lift(size: f32, drop: f32, substeps: u32, on_soft: bool, pull: Pull) -> f32 {
    let solver = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, CouplingSettings::default()).unwrap();
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(3.0, 0.5, 3.0),
    );
    let cube = |y: f32| {
        let mesh = generators::box_grid(
            Vector3::repeat(size),
            [3, 3, 3],
            generators::CellSplit::Five,
        )
        .unwrap();
        TetBodyBuilder::new(mesh)
            .density(500.0)
            .edges(1e-6)
            .volume(0.0)
            .translation(Vector3::new(0.0, y, 0.0))
            .build()
            .unwrap()
    };
    let mut base = 0.5 * size;
    if on_soft {
        cube(base).spawn(&mut scene.soft);
        base += size;
    }
    let body = cube(base + drop);
    let weight = body.particles.total_mass() * 9.81;
    let e = body.spawn(&mut scene.soft);
    for _ in 0..90 {
        scene.step().unwrap();
    }
    let start = scene.soft.get::<&Particles>(e).unwrap().center_of_mass();
    let top = start + Vector3::y() * (0.5 * size);
    match pull {
        Pull::Grab => {
            let g = {
                let p = scene.soft.get::<&Particles>(e).unwrap();
                let t = scene.soft.get::<&Tetrahedra>(e).unwrap();
                Grab::at(&p, &t, top, 0.001 / weight, 10.0 * weight).unwrap()
            };
            scene.soft.insert_one(e, g).unwrap();
        }
        Pull::Force(k) => {
            let f = {
                let p = scene.soft.get::<&Particles>(e).unwrap();
                let mut f = UserForces::new(&p);
                f.add_force(&p, Vector3::y() * (k * weight)).unwrap();
                f
            };
            scene.soft.insert_one(e, f).unwrap();
        }
    }
    for frame in 1..=60 {
        if let Pull::Grab = pull {
            let target = top + Vector3::y() * (frame.min(30) as f32 / 30.0);
            let mut g = scene.soft.get::<&mut Grab>(e).unwrap();
            g.set_target(target).unwrap();
        }
        scene.step().unwrap();
    }
    let end = scene.soft.get::<&Particles>(e).unwrap().center_of_mass();
    end.y - start.y
}

#[test]
fn a_pull_stronger_than_the_weight_lifts_a_resting_body() {
    // An upward force of k·mg gives (k − 1) g: over 1 s the body rises (k − 1) g / 2.
    for (case, &(size, drop, substeps, on_soft)) in [
        (0.3, 0.0, 10, false),
        (0.3, 0.2, 10, false),
        (0.5, 0.5, 5, false),
        (0.4, 0.3, 20, false),
        (0.3, 0.0, 10, true),
        (0.3, 0.2, 10, true),
        (0.5, 0.3, 5, true),
    ]
    .iter()
    .enumerate()
    {
        let k = 1.1 + 0.05 * case as f32;
        let free_rise = (k - 1.0) * 9.81 / 2.0;
        let rise = lift(size, drop, substeps, on_soft, Pull::Force(k));
        assert!(
            rise > 0.8 * free_rise && rise < 1.1 * free_rise,
            "size {size}, drop {drop}, {substeps} substeps, on soft {on_soft}, force {k} mg: \
             rose {rise:.3} m, free rise {free_rise:.3} m"
        );
        let rise = lift(size, drop, substeps, on_soft, Pull::Grab);
        assert!(
            rise > 0.9,
            "size {size}, drop {drop}, {substeps} substeps, on soft {on_soft}, grab: rose {rise:.3} m of 1 m"
        );
    }
}
