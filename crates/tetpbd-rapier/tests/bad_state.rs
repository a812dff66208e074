//! Bad state of a soft body's components and out-of-range settings get a typed error
//! naming what is wrong, never a panic.

mod robust_common;

use nalgebra::Vector3;
use robust_common::{ground, scene, soft_box};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{SoftBodyBuilder, SolverSettings, Surface};
use tetpbd_rapier::{
    CoupledWorld, CouplingError, CouplingSettings, SoftCollider, SoftColliderBuilder,
};

#[test]
fn a_surface_naming_missing_particles_is_a_typed_error_not_a_panic() {
    for (cells, other) in [(1u32, 2u32), (2, 3), (3, 5)] {
        let mut s = scene();
        ground(&mut s);
        let at = Vector3::new(0.0, 0.3, 0.0);
        let e = soft_box(
            &mut s,
            Vector3::repeat(0.4),
            [cells; 3],
            at,
            Vector3::zeros(),
            1000.0,
        );
        s.step().expect("a valid body steps");
        let bigger = box_grid(Vector3::repeat(0.4), [other; 3], CellSplit::Six).expect("mesh");
        let surface = SoftBodyBuilder::new(bigger).build().expect("body").surface;
        let largest = *surface.vertices().last().expect("vertices");
        s.soft.insert_one(e, surface).expect("entity");
        let len = (cells as usize + 1).pow(3);
        match s.step() {
            Err(CouplingError::SurfaceOutOfRange {
                entity,
                index,
                len: l,
            }) => {
                assert_eq!((entity, index, l), (e, largest, len));
            }
            r => panic!("{cells}³ cells with a {other}³ surface: {r:?}"),
        }
        // Nothing moved, and the body steps again once its own surface is back.
        let own = box_grid(Vector3::repeat(0.4), [cells; 3], CellSplit::Six).expect("mesh");
        let own = SoftBodyBuilder::new(own).build().expect("body").surface;
        s.soft.insert_one(e, own).expect("entity");
        s.step().expect("steps again");
    }
}

#[test]
fn an_empty_surface_is_fine() {
    let mut s = scene();
    let at = Vector3::new(0.0, 0.3, 0.0);
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.4),
        [2; 3],
        at,
        Vector3::zeros(),
        1000.0,
    );
    s.soft.insert_one(e, Surface::default()).expect("entity");
    s.step().expect("an empty surface names no particle");
}

#[test]
fn thickness_margin_and_depenetration_speed_have_upper_bounds() {
    let t = SoftCollider::MAX_THICKNESS;
    assert!(SoftColliderBuilder::new().thickness(t).build().is_ok());
    for bad in [t * 1.01, 1.0, 1e30, f32::INFINITY] {
        let r = SoftColliderBuilder::new().thickness(bad).build();
        assert!(matches!(r, Err(CouplingError::BadCoefficient { value, .. }) if value == bad));
    }
    let ok = CouplingSettings {
        margin: CouplingSettings::MAX_MARGIN,
        max_depenetration_speed: CouplingSettings::MAX_DEPENETRATION_SPEED,
        ..CouplingSettings::default()
    };
    assert!(ok.validate().is_ok());
    for margin in [CouplingSettings::MAX_MARGIN * 1.01, 1e30] {
        let bad = CouplingSettings {
            margin,
            ..CouplingSettings::default()
        };
        assert!(
            matches!(bad.validate(), Err(CouplingError::BadSetting { value, .. }) if value == margin)
        );
    }
    let speed = CouplingSettings::MAX_DEPENETRATION_SPEED * 1.01;
    let bad = CouplingSettings {
        max_depenetration_speed: speed,
        ..CouplingSettings::default()
    };
    let r = CoupledWorld::new(SolverSettings::default(), bad);
    assert!(matches!(r, Err(CouplingError::BadSetting { .. })));
}
