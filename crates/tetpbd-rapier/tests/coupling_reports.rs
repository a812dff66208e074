//! Contact reports and bad input of the coupled step.

mod coupling_common;

use coupling_common::{ground, particles, scene, soft_box};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use tetpbd::SolverSettings;
use tetpbd_rapier::{
    CoupledWorld, CouplingError, CouplingSettings, SoftCollider, SoftColliderBuilder, SoftFeature,
};

/// A soft cube at rest on the ground: its contacts name the ground and the cube, sit on the
/// ground's surface with upward normals, and their impulses carry the cube's weight.
#[test]
fn resting_contacts_carry_the_weight() {
    let mut s = scene(10);
    let (_, g) = ground(&mut s);
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [2, 2, 2],
        Vector3::new(0.0, 0.1025, 0.0),
        SoftCollider::default(),
    );
    for _ in 0..120 {
        s.step().expect("step");
    }
    let stats = s.step().expect("step");
    let reports = s.coupling.contacts();
    let dt = s.physics.integration_parameters.dt;
    let weight = particles(&s, e).total_mass() * 9.81;
    let total: Vector3<f32> = reports.iter().map(|c| c.impulse).sum();
    println!(
        "{} contacts, total impulse {total:?} N·s, weight × dt {:.5} N·s",
        reports.len(),
        weight * dt
    );
    assert_eq!(stats.contacts, reports.len());
    assert_eq!(reports.len(), 9, "the bottom face has 9 particles");
    for c in reports {
        assert_eq!(c.collider, g);
        assert_eq!(c.entity, e);
        assert!(matches!(c.feature, SoftFeature::Particle(_)));
        assert!(c.solved);
        assert!(
            (c.normal - Vector3::y()).norm() < 1e-3,
            "normal {:?}",
            c.normal
        );
        assert!(c.point.y.abs() < 1e-4, "point {:?}", c.point);
        assert!(c.depth >= 0.0 && c.depth < 0.01);
    }
    assert!((total.y - weight * dt).abs() < 0.02 * weight * dt);
    assert!(total.x.abs() + total.z.abs() < 0.01 * weight * dt);
}

#[test]
fn bad_settings_are_rejected_before_anything_moves() {
    let bad_margin = CouplingSettings {
        margin: -1.0,
        ..CouplingSettings::default()
    };
    assert!(matches!(
        CoupledWorld::new(SolverSettings::default(), bad_margin),
        Err(CouplingError::BadSetting { .. })
    ));
    for ratio in [f32::NAN, -1.0] {
        let bad_ratio = CouplingSettings {
            stacking: Some(tetpbd_rapier::StackingSettings {
                mass_ratio: ratio,
                ..Default::default()
            }),
            ..CouplingSettings::default()
        };
        assert!(matches!(
            CoupledWorld::new(SolverSettings::default(), bad_ratio),
            Err(CouplingError::BadSetting {
                name: "stacking mass ratio",
                ..
            })
        ));
    }
    // Infinity turns the heavy-load pass off: a valid setting, as is no stacking at all.
    let never = CouplingSettings {
        stacking: Some(tetpbd_rapier::StackingSettings {
            mass_ratio: f32::INFINITY,
            ..Default::default()
        }),
        ..CouplingSettings::default()
    };
    assert!(CoupledWorld::new(SolverSettings::default(), never).is_ok());
    let off = CouplingSettings {
        stacking: None,
        ..CouplingSettings::default()
    };
    assert!(CoupledWorld::new(SolverSettings::default(), off).is_ok());
    let no_substeps = SolverSettings {
        substeps: 0,
        ..SolverSettings::default()
    };
    assert!(matches!(
        CoupledWorld::new(no_substeps, CouplingSettings::default()),
        Err(CouplingError::Solver(_))
    ));
    assert!(matches!(
        SoftColliderBuilder::new().friction(-0.1).build(),
        Err(CouplingError::BadCoefficient { .. })
    ));
    assert!(matches!(
        SoftColliderBuilder::new().restitution(1.5).build(),
        Err(CouplingError::BadCoefficient { .. })
    ));
    assert!(matches!(
        SoftColliderBuilder::new().thickness(f32::NAN).build(),
        Err(CouplingError::BadCoefficient { .. })
    ));

    let mut s = scene(10);
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [1, 1, 1],
        Vector3::new(0.0, 1.0, 0.0),
        SoftCollider::default(),
    );
    let before = particles(&s, e);
    s.physics.integration_parameters.dt = 0.0;
    assert_eq!(
        s.step().map(|_| ()),
        Err(CouplingError::BadRapierDt { value: 0.0 })
    );
    s.physics.integration_parameters.dt = 1.0 / 60.0;
    s.physics.gravity = Vector::new(0.0, f32::INFINITY, 0.0);
    assert_eq!(s.step().map(|_| ()), Err(CouplingError::NonFiniteGravity));
    s.physics.gravity = Vector::new(0.0, -9.81, 0.0);
    s.coupling.settings_mut().margin = f32::NAN;
    assert!(matches!(
        s.step().map(|_| ()),
        Err(CouplingError::BadSetting { .. })
    ));
    assert_eq!(
        particles(&s, e),
        before,
        "a rejected step moved the soft body"
    );
    s.coupling.settings_mut().margin = 0.02;
    s.step().expect("step");
    assert!(particles(&s, e).center_of_mass().y < 1.0);
}

/// Mass-weighted mean velocity of a soft body, m/s.
fn mean_velocity(s: &CoupledWorld, e: hecs::Entity) -> Vector3<f32> {
    let p = particles(s, e);
    let m: Vector3<f32> = p
        .velocities()
        .iter()
        .zip(p.masses())
        .map(|(v, &m)| v * m)
        .sum();
    m / p.total_mass()
}

/// A coupled scene runs on rapier's clock and gravity: a free soft body falls with rapier's
/// gravity over rapier's `dt` (several of each) while the solver's `dt` and `gravity` stay
/// at their defaults and are never written; a solver `dt` or `gravity` set to anything else
/// is rejected, naming both values, before anything moves; set equal to rapier's it is
/// accepted.
#[test]
fn rapier_owns_the_time_step_and_gravity() {
    let defaults = SolverSettings::default();
    for (g, dt) in [
        (Vector::new(0.0, -9.81, 0.0), 1.0 / 60.0),
        (Vector::new(0.0, -3.0, 0.0), 1.0 / 120.0),
        (Vector::ZERO, 1.0 / 30.0),
        (Vector::new(1.0, 2.0, -0.5), 1.0 / 90.0),
    ] {
        let mut s = scene(10);
        let e = soft_box(
            &mut s,
            Vector3::repeat(0.2),
            [1, 1, 1],
            Vector3::new(0.0, 5.0, 0.0),
            SoftCollider::default(),
        );
        s.physics.gravity = g;
        s.physics.integration_parameters.dt = dt;
        let frames = 6;
        for _ in 0..frames {
            s.step().expect("step");
        }
        let expected = Vector3::new(g.x, g.y, g.z) * (frames as f32 * dt);
        let v = mean_velocity(&s, e);
        assert!(
            (v - expected).norm() <= 1e-4 * (1.0 + expected.norm()),
            "gravity {g:?}, dt {dt}: {v:?} against {expected:?}"
        );
        let settings = &s.coupling.solver().settings;
        assert_eq!(
            (settings.dt, settings.gravity),
            (defaults.dt, defaults.gravity)
        );
    }

    let mut s = scene(10);
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [1, 1, 1],
        Vector3::new(0.0, 5.0, 0.0),
        SoftCollider::default(),
    );
    let before = particles(&s, e);
    s.coupling.solver_mut().settings.gravity = Vector3::zeros();
    assert_eq!(
        s.step().map(|_| ()),
        Err(CouplingError::SolverGravityDisagrees {
            solver: Vector3::zeros(),
            rapier: Vector3::new(0.0, -9.81, 0.0),
        })
    );
    s.coupling.solver_mut().settings.gravity = defaults.gravity;
    s.coupling.solver_mut().settings.dt = 0.01;
    assert_eq!(
        s.step().map(|_| ()),
        Err(CouplingError::SolverDtDisagrees {
            solver: 0.01,
            rapier: 1.0 / 60.0,
        })
    );
    assert_eq!(
        particles(&s, e),
        before,
        "a rejected step moved the soft body"
    );

    // Set equal to rapier's, both are accepted.
    s.physics.integration_parameters.dt = 0.01;
    s.physics.gravity = Vector::ZERO;
    s.coupling.solver_mut().settings.gravity = Vector3::zeros();
    s.step().expect("step");
    assert!(mean_velocity(&s, e).norm() < 1e-6);
}
