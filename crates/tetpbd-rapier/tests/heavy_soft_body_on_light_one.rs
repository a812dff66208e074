//! A heavy soft body landing on a much lighter soft body that rests on the ground neither
//! throws the light one out from under it nor gains energy (`soft_soft::carrying` module
//! docs): a seeded sweep over sizes, densities, speeds and substep counts at default
//! settings.

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings};

/// Kinetic + gravitational energy (J) and the fastest particle (m/s).
fn energy(s: &CoupledWorld) -> (f64, f32) {
    let (mut e, mut fastest) = (0.0f64, 0.0f32);
    for p in s.soft.query::<&Particles>().iter() {
        e += f64::from(p.kinetic_energy());
        for (x, m) in p.positions().iter().zip(p.masses()) {
            e += f64::from(m * 9.81 * x.y);
        }
        fastest = fastest.max(p.max_speed());
    }
    (e, fastest)
}

/// Drops a heavy hard cube (`heavy` m, density `rho`) at `speed` onto a light slab of
/// compliant shape and hard volume resting on the ground; returns the largest energy rise
/// over the start (J), the start's energy scale (J) and the fastest particle after the
/// first frame (m/s).
fn drop(heavy: f32, rho: f32, speed: f32, substeps: u32) -> (f64, f64, f32) {
    let solver = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    let mut s = CoupledWorld::new(solver, CouplingSettings::default()).expect("settings");
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(50.0, 0.5, 50.0),
    );
    let slab = generators::box_grid(Vector3::new(1.1, 0.4, 1.1), [3, 3, 3], CellSplit::Five)
        .expect("mesh");
    SoftBodyBuilder::new(slab)
        .density(48.0)
        .vertex_face(1e-6)
        .volume(0.0)
        .translation(Vector3::new(0.0, 0.2, 0.0))
        .build()
        .expect("slab")
        .spawn(&mut s.soft);
    let cube =
        generators::box_grid(Vector3::repeat(heavy), [3, 3, 3], CellSplit::Six).expect("mesh");
    SoftBodyBuilder::new(cube)
        .density(rho)
        .edges(0.0)
        .vertex_face(0.0)
        .translation(Vector3::new(0.05, 0.45 + 0.5 * heavy, 0.0))
        .velocity(Vector3::new(0.0, -speed, 0.0))
        .build()
        .expect("cube")
        .spawn(&mut s.soft);
    let (e0, _) = energy(&s);
    let scale = e0.abs() + 1.0;
    let (mut gain, mut fastest) = (0.0f64, 0.0f32);
    for f in 0..60 {
        s.step().expect("step");
        let (e, v) = energy(&s);
        gain = gain.max(e - e0);
        if f > 0 {
            fastest = fastest.max(v);
        }
    }
    (gain, scale, fastest)
}

#[test]
fn a_heavy_soft_body_on_a_light_one_never_throws_it() {
    for (heavy, rho, speed, substeps) in [(0.9, 1700.0, 8.0, 40), (0.7, 2500.0, 6.0, 10)] {
        let (gain, scale, fastest) = drop(heavy, rho, speed, substeps);
        let limit = 1.5 * (speed * speed + 2.0 * 9.81 * 1.5).sqrt() + 5.0;
        assert!(
            gain < 1e-2 * scale && fastest < limit,
            "{heavy} m at {rho} kg/m³, {speed} m/s, {substeps} substeps: gain {gain:.1} of \
             {scale:.1} J, fastest particle {fastest:.1} m/s (limit {limit:.1})"
        );
    }
}
