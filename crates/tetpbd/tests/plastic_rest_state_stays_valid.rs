//! A plastic body's rest state stays valid and exact: no inverted, flat or NaN rest shape under
//! any crushing, rest volumes kept by volume-preserving flow, a held shape becoming the rest
//! shape of every family, a reset giving the built state back; bad settings are typed errors,
//! a component made for another body is skipped, and a flowing body survives a snapshot.

mod common;

use common::plastic::{arc, check_rest_state, mould, solver, spawn_bar, Bar, Families};
use common::Rng;
use hecs::World;
use nalgebra::{Matrix3, Vector3};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    BuildError, EdgeConstraints, Particles, Plasticity, PlasticityError, PlasticitySettings,
    SoftBodyBuilder, Tetrahedra, VertexFaceConstraints,
};

/// Held in random stretches, shears and squashes, frame after frame: volume-preserving flow
/// keeps every rest volume within the documented tolerance, full flow within the bounds of
/// the maximum plastic strain, and no rest shape is ever inverted, flat or NaN.
#[test]
fn rest_state_stays_valid_and_volume_preserving_flow_keeps_rest_volumes() {
    let mut rng = Rng::new(5);
    for case in 0..8 {
        let volume_preserving = case % 2 == 0;
        let s = PlasticitySettings {
            volume_preserving,
            max_plastic_strain: [0.3, 0.5, 0.9, 0.99][case / 2],
            flow_rate: f32::INFINITY,
            ..Default::default()
        };
        let bar = Bar {
            length: 1.0,
            cells: 6,
            substeps: 5,
            families: [Families::EdgesVolume, Families::EdgesVertexFace][(case / 2) % 2],
        };
        let mut world = World::new();
        let e = spawn_bar(&mut world, bar, Some(s));
        let mut solver = solver(bar.substeps, 5.0);
        let mut worst = 0.0f32;
        for _ in 0..40 {
            let a = Matrix3::from_fn(|_, _| rng.range(-0.6, 0.6) as f32) + Matrix3::identity();
            if a.determinant() < 0.2 {
                continue;
            }
            {
                let mut p = world.get::<&mut Particles>(e).unwrap();
                for i in 0..p.len() {
                    let moved = a * p.rest_positions()[i];
                    p.set_position(i, moved).unwrap();
                }
            }
            solver.step(&mut world).unwrap();
            worst = worst.max(check_rest_state(&world, e, &s));
        }
        if !volume_preserving {
            assert!(
                worst > 0.01,
                "case {case}: full flow never changed a rest volume"
            );
        }
        println!(
            "rest volume change: volume-preserving {volume_preserving}, max plastic strain {}: largest |V/V0 - 1| = {worst:e}",
            s.max_plastic_strain
        );
        let p = world.get::<&Plasticity>(e).unwrap();
        let most = p.max_plastic_strain();
        assert!(most > 0.1, "case {case}: no flow ({most})");
    }
}

/// Bad settings are typed errors naming the value, from the builder and from the component.
#[test]
fn bad_plasticity_settings_are_typed_errors() {
    let ok = PlasticitySettings::default();
    let cases = [
        (
            PlasticitySettings {
                yield_strain: -0.1,
                ..ok
            },
            PlasticityError::BadYieldStrain { value: -0.1 },
        ),
        (
            PlasticitySettings {
                yield_strain: f32::INFINITY,
                ..ok
            },
            PlasticityError::BadYieldStrain {
                value: f32::INFINITY,
            },
        ),
        (
            PlasticitySettings {
                flow_rate: -1.0,
                ..ok
            },
            PlasticityError::BadFlowRate { value: -1.0 },
        ),
        (
            PlasticitySettings {
                max_plastic_strain: 1.0,
                ..ok
            },
            PlasticityError::BadMaxPlasticStrain { value: 1.0 },
        ),
        (
            PlasticitySettings {
                max_plastic_strain: -0.5,
                ..ok
            },
            PlasticityError::BadMaxPlasticStrain { value: -0.5 },
        ),
    ];
    let mesh = || box_grid(Vector3::repeat(1.0), [2, 2, 2], CellSplit::Five).unwrap();
    for (s, expected) in cases {
        let built = SoftBodyBuilder::new(mesh())
            .edges(0.0)
            .plasticity(s)
            .build();
        assert_eq!(built.unwrap_err(), BuildError::Plasticity(expected));
        assert!(expected.to_string().contains(&format!(
            "{}",
            match expected {
                PlasticityError::BadYieldStrain { value }
                | PlasticityError::BadFlowRate { value }
                | PlasticityError::BadMaxPlasticStrain { value } => value,
            }
        )));
    }
    // NaN in each setting (NaN never equals itself: match the variant).
    for k in 0..3 {
        let mut s = ok;
        *[
            &mut s.yield_strain,
            &mut s.flow_rate,
            &mut s.max_plastic_strain,
        ][k] = f32::NAN;
        let err = s.validate().unwrap_err();
        let variant_ok = match (k, err) {
            (0, PlasticityError::BadYieldStrain { value }) => value.is_nan(),
            (1, PlasticityError::BadFlowRate { value }) => value.is_nan(),
            (2, PlasticityError::BadMaxPlasticStrain { value }) => value.is_nan(),
            _ => false,
        };
        assert!(variant_ok, "setting {k}: {err:?}");
        assert!(err.to_string().contains("NaN"));
    }
    // The component keeps its settings when given bad ones.
    let body = SoftBodyBuilder::new(mesh()).plasticity(ok).build().unwrap();
    let mut p = body.plasticity.unwrap();
    let bad = PlasticitySettings {
        flow_rate: f32::NAN,
        ..ok
    };
    assert!(p.set_settings(bad).is_err());
    assert_eq!(*p.settings(), ok);
    // An infinite flow rate is allowed: everything past the yield flows at once.
    let instant = PlasticitySettings {
        flow_rate: f32::INFINITY,
        ..ok
    };
    assert_eq!(instant.validate(), Ok(()));
}

/// A `Plasticity` made for another body is skipped, not a panic; a body without one is
/// untouched by the flow system.
#[test]
fn plasticity_of_another_body_is_ignored() {
    let mut world = World::new();
    let small =
        SoftBodyBuilder::new(box_grid(Vector3::repeat(1.0), [1, 1, 1], CellSplit::Five).unwrap())
            .edges(0.0)
            .plasticity(PlasticitySettings::default())
            .build()
            .unwrap();
    let bar = Bar {
        length: 1.0,
        cells: 4,
        substeps: 5,
        families: Families::EdgesVolume,
    };
    let e = spawn_bar(&mut world, bar, None);
    world.insert_one(e, small.plasticity.unwrap()).unwrap();
    let before = world
        .get::<&EdgeConstraints>(e)
        .unwrap()
        .rest_lengths()
        .to_vec();
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        for i in 0..p.len() {
            let x = p.positions()[i];
            p.set_position(i, Vector3::new(2.0 * x.x, x.y, x.z))
                .unwrap();
        }
    }
    let flowed = tetpbd::systems::flow_plastically(&mut world, 1.0 / 60.0);
    assert_eq!(flowed, 0);
    assert_eq!(
        world.get::<&EdgeConstraints>(e).unwrap().rest_lengths(),
        &before[..]
    );
}

/// With the `serde` feature, a flowing plastic body saved mid-flow (every component through
/// JSON) and restored into a fresh world continues bit-identically, rest state included.
#[cfg(feature = "serde")]
#[test]
fn flowing_body_restored_from_a_snapshot_continues_bit_identically() {
    use tetpbd::{Activation, Surface};
    type Saved = (
        Particles,
        Tetrahedra,
        Surface,
        EdgeConstraints,
        VertexFaceConstraints,
        Activation,
        Plasticity,
    );
    let mut world = World::new();
    let bar = Bar {
        length: 1.0,
        cells: 4,
        substeps: 5,
        families: Families::EdgesVertexFace,
    };
    let e = spawn_bar(&mut world, bar, Some(PlasticitySettings::default()));
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        for i in 0..p.len() {
            let x = p.positions()[i];
            p.set_position(i, Vector3::new(1.4 * x.x, x.y + 0.3 * x.x, x.z))
                .unwrap();
        }
    }
    let mut solver = solver(bar.substeps, 0.0);
    for _ in 0..3 {
        solver.step(&mut world).unwrap();
    }
    let saved: Saved = {
        let (p, t, s, ed, vf, a, pl) = world
            .query_one_mut::<(
                &Particles,
                &Tetrahedra,
                &Surface,
                &EdgeConstraints,
                &VertexFaceConstraints,
                &Activation,
                &Plasticity,
            )>(e)
            .unwrap();
        (
            p.clone(),
            t.clone(),
            s.clone(),
            ed.clone(),
            vf.clone(),
            *a,
            pl.clone(),
        )
    };
    let json = serde_json::to_string(&saved).unwrap();
    let mut fresh = World::new();
    let e2 = fresh.spawn(serde_json::from_str::<Saved>(&json).unwrap());
    let mut solver2 = tetpbd::Solver::new(solver.settings.clone()).unwrap();
    for _ in 0..20 {
        solver.step(&mut world).unwrap();
        solver2.step(&mut fresh).unwrap();
    }
    assert_ne!(
        *world.get::<&Plasticity>(e).unwrap(),
        saved.6,
        "the body flowed after the snapshot"
    );
    assert_eq!(
        *world.get::<&Plasticity>(e).unwrap(),
        *fresh.get::<&Plasticity>(e2).unwrap()
    );
    assert_eq!(
        world.get::<&EdgeConstraints>(e).unwrap().rest_lengths(),
        fresh.get::<&EdgeConstraints>(e2).unwrap().rest_lengths()
    );
    let (a, b) = (
        world.get::<&Particles>(e).unwrap(),
        fresh.get::<&Particles>(e2).unwrap(),
    );
    for (x, y) in a.positions().iter().zip(b.positions()) {
        assert_eq!(x.map(f32::to_bits), y.map(f32::to_bits));
    }
}

/// With no yield and an instant flow, one frame makes a held (compatible) shape the rest
/// shape of every family: all constraints are satisfied there.
#[test]
fn instant_flow_without_yield_makes_the_held_shape_the_rest_shape() {
    for families in [Families::EdgesVolume, Families::EdgesVertexFace] {
        let bar = Bar {
            length: 2.0,
            cells: 8,
            substeps: 5,
            families,
        };
        let s = PlasticitySettings {
            yield_strain: 0.0,
            flow_rate: f32::INFINITY,
            max_plastic_strain: 0.9,
            volume_preserving: false,
        };
        let mut world = World::new();
        let e = spawn_bar(&mut world, bar, Some(s));
        {
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for i in 0..p.len() {
                let x = arc(p.rest_positions()[i], bar.length, 1.0);
                p.set_position(i, x).unwrap();
            }
        }
        let flowed = tetpbd::systems::flow_plastically(&mut world, 1.0 / 60.0);
        assert!(flowed > 0);
        let m = tetpbd::systems::measure(&mut world);
        // Rounding of the f32 rest values: 1e-6 of the lengths (m) and volumes (m³) involved.
        assert!(
            m.edge.max < 1e-6 && m.vertex_face.max < 1e-6,
            "{families:?}: {m:?}"
        );
        assert!(m.volume.max < 1e-9, "{families:?}: {m:?}");
        // The rest edge matrices a further family would read are the held shape's, up to a
        // rotation: equal metrics `DᵀD`.
        let p = world.get::<&Particles>(e).unwrap();
        let t = world.get::<&Tetrahedra>(e).unwrap();
        let plastic = world.get::<&Plasticity>(e).unwrap();
        for (k, tet) in t.indices().iter().enumerate() {
            let dm = plastic.rest_edge_matrix(k, &p, &t).unwrap();
            let x = tet.map(|i| p.positions()[i as usize].cast::<f64>());
            let ds = Matrix3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]]);
            let gap = (dm.transpose() * dm - ds.transpose() * ds).norm();
            assert!(gap < 1e-5 * (ds.transpose() * ds).norm(), "tet {k}: {gap}");
        }
        assert!(plastic.rest_edge_matrix(t.len(), &p, &t).is_none());
        assert!(plastic.plastic_strain(t.len()).is_none());
    }
}

/// After a flow, `Plasticity::reset` gives every family its built rest values back, bit for
/// bit.
#[test]
fn reset_gives_back_the_built_rest_state() {
    for families in [Families::EdgesVolume, Families::EdgesVertexFace] {
        let bar = Bar {
            length: 1.0,
            cells: 4,
            substeps: 5,
            families,
        };
        let mut world = World::new();
        let e = spawn_bar(&mut world, bar, Some(PlasticitySettings::default()));
        let built_edges = world
            .get::<&EdgeConstraints>(e)
            .unwrap()
            .rest_lengths()
            .to_vec();
        let built_volumes = world.get::<&Tetrahedra>(e).unwrap().rest_volumes().to_vec();
        let built_heights = world
            .get::<&VertexFaceConstraints>(e)
            .ok()
            .map(|v| v.rest_heights().to_vec());
        let rest: Vec<Vector3<f32>> = world
            .get::<&Particles>(e)
            .unwrap()
            .rest_positions()
            .to_vec();
        let held: Vec<Vector3<f32>> = rest.iter().map(|x| arc(*x, bar.length, 2.0)).collect();
        mould(&mut world, e, &held, true);
        let mut solver = solver(bar.substeps, 0.0);
        for _ in 0..10 {
            solver.step(&mut world).unwrap();
        }
        assert_ne!(
            world.get::<&EdgeConstraints>(e).unwrap().rest_lengths(),
            &built_edges[..]
        );
        let (p, t, plastic, vf, edges) = world
            .query_one_mut::<(
                &Particles,
                &mut Tetrahedra,
                &mut Plasticity,
                Option<&mut VertexFaceConstraints>,
                Option<&mut EdgeConstraints>,
            )>(e)
            .unwrap();
        assert!(plastic.reset(p, t, vf, edges, None));
        assert_eq!(
            world.get::<&EdgeConstraints>(e).unwrap().rest_lengths(),
            &built_edges[..]
        );
        assert_eq!(
            world.get::<&Tetrahedra>(e).unwrap().rest_volumes(),
            &built_volumes[..]
        );
        let heights = world
            .get::<&VertexFaceConstraints>(e)
            .ok()
            .map(|v| v.rest_heights().to_vec());
        assert_eq!(heights, built_heights);
    }
}
