//! Every bad input returns its typed error, naming what is wrong.

mod common;

use common::unit_tet;
use nalgebra::Vector3;
use tetpbd::generators::{ball, box_grid, CellSplit};
use tetpbd::{
    BuildError, ExternalAcceleration, Particles, SettingsError, SoftBodyBuilder, Solver,
    SolverSettings, StateError, TetMesh,
};

fn err(b: SoftBodyBuilder) -> BuildError {
    b.build().expect_err("must be rejected")
}

#[test]
fn builder_rejects_bad_meshes() {
    assert_eq!(
        err(SoftBodyBuilder::new(TetMesh::default())),
        BuildError::NoVertices
    );
    let mut m = unit_tet();
    m.vertices[2].y = f32::NAN;
    assert_eq!(
        err(SoftBodyBuilder::new(m)),
        BuildError::NonFiniteVertex { vertex: 2 }
    );
    let mut m = unit_tet();
    m.vertices[3].z = f32::INFINITY;
    assert_eq!(
        err(SoftBodyBuilder::new(m)),
        BuildError::NonFiniteVertex { vertex: 3 }
    );
    let mut m = unit_tet();
    m.tets.push([0, 1, 2, 7]);
    assert_eq!(
        err(SoftBodyBuilder::new(m)),
        BuildError::IndexOutOfRange {
            tet: 1,
            index: 7,
            vertex_count: 4
        }
    );
    let mut m = unit_tet();
    m.tets[0] = [0, 1, 1, 3];
    assert_eq!(
        err(SoftBodyBuilder::new(m)),
        BuildError::RepeatedVertex { tet: 0, index: 1 }
    );
    let mut m = unit_tet();
    m.vertices[3] = Vector3::new(0.5, 0.5, 0.0); // coplanar
    assert!(matches!(
        err(SoftBodyBuilder::new(m)),
        BuildError::DegenerateTetrahedron { tet: 0, .. }
    ));
    let mut m = unit_tet();
    m.vertices.push(Vector3::new(5.0, 5.0, 5.0));
    assert_eq!(
        err(SoftBodyBuilder::new(m)),
        BuildError::UnreferencedVertex { vertex: 4 }
    );
    // A non-finite translation is a bad pose; one that overflows the coordinates names the
    // vertex.
    assert_eq!(
        err(SoftBodyBuilder::new(unit_tet()).translation(Vector3::new(0.0, f32::NAN, 0.0))),
        BuildError::NonFinitePose
    );
    let mut m = unit_tet();
    m.vertices[1].x = f32::MAX;
    assert_eq!(
        err(SoftBodyBuilder::new(m).scale(2.0)),
        BuildError::NonFiniteVertex { vertex: 1 }
    );
}

#[test]
fn builder_rejects_bad_parameters() {
    for d in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let e = err(SoftBodyBuilder::new(unit_tet()).density(d));
        assert!(matches!(e, BuildError::BadDensity { .. }), "{d}: {e:?}");
    }
    for a in [-1e-9, f32::NAN, f32::INFINITY] {
        assert!(matches!(
            err(SoftBodyBuilder::new(unit_tet()).edges(a)),
            BuildError::BadCompliance { family: "edge", .. }
        ));
        assert!(matches!(
            err(SoftBodyBuilder::new(unit_tet()).vertex_face(a)),
            BuildError::BadCompliance {
                family: "vertex-face",
                ..
            }
        ));
        assert!(matches!(
            err(SoftBodyBuilder::new(unit_tet()).volume(a)),
            BuildError::BadCompliance {
                family: "volume",
                ..
            }
        ));
    }
    assert_eq!(
        err(SoftBodyBuilder::new(unit_tet()).pinned([9])),
        BuildError::PinnedOutOfRange {
            index: 9,
            vertex_count: 4
        }
    );
    assert_eq!(
        err(SoftBodyBuilder::new(unit_tet()).velocity(Vector3::new(f32::NAN, 0.0, 0.0))),
        BuildError::NonFiniteVelocity
    );
    assert!(matches!(
        err(SoftBodyBuilder::new(unit_tet()).volume_epsilon(-1.0)),
        BuildError::BadEpsilon { .. }
    ));
    assert!(box_grid(Vector3::new(1.0, 0.0, 1.0), [1, 1, 1], CellSplit::Six).is_err());
    assert!(box_grid(Vector3::new(1.0, 1.0, 1.0), [1, 0, 1], CellSplit::Six).is_err());
    assert!(ball(f32::NAN, 2, CellSplit::Six).is_err());
    // Messages name the value.
    let msg = err(SoftBodyBuilder::new(unit_tet()).density(-3.0)).to_string();
    assert!(msg.contains("-3"), "{msg}");
}

#[test]
fn either_orientation_is_accepted() {
    let mut m = unit_tet();
    m.tets[0] = [0, 2, 1, 3]; // negative orientation
    let b = SoftBodyBuilder::new(m)
        .vertex_face(0.0)
        .volume(0.0)
        .build()
        .unwrap();
    assert!(b.tetrahedra.rest_volumes()[0] < 0.0);
    assert!(b.vertex_face.unwrap().rest_heights()[0]
        .iter()
        .all(|h| *h < 0.0));
}

#[test]
fn solver_rejects_bad_settings() {
    let bad = |f: &dyn Fn(&mut SolverSettings)| {
        let mut s = SolverSettings::default();
        f(&mut s);
        Solver::new(s).expect_err("must be rejected")
    };
    assert!(matches!(bad(&|s| s.dt = f32::NAN), SettingsError::BadDt { value } if value.is_nan()));
    assert!(matches!(bad(&|s| s.dt = -0.1), SettingsError::BadDt { .. }));
    assert!(matches!(bad(&|s| s.dt = 0.0), SettingsError::BadDt { .. }));
    assert_eq!(
        bad(&|s| s.substeps = 0),
        SettingsError::ZeroCount { what: "substeps" }
    );
    assert_eq!(
        bad(&|s| s.iterations = 0),
        SettingsError::ZeroCount { what: "iterations" }
    );
    assert_eq!(
        bad(&|s| s.gravity.y = f32::INFINITY),
        SettingsError::NonFiniteGravity
    );
    assert!(matches!(
        bad(&|s| s.damping = -1.0),
        SettingsError::BadDamping { .. }
    ));
    assert!(matches!(
        bad(&|s| s.safety.max_correction_speed = Some(0.0)),
        SettingsError::BadCorrectionSpeed { .. }
    ));
    assert_eq!(
        bad(&|s| s.order = [
            tetpbd::Family::Edge,
            tetpbd::Family::Edge,
            tetpbd::Family::Volume
        ]),
        SettingsError::BadOrder
    );
    // Settings changed after construction are checked by every step, before any state moves.
    let mut world = hecs::World::new();
    let e = SoftBodyBuilder::new(unit_tet())
        .edges(0.0)
        .build()
        .unwrap()
        .spawn(&mut world);
    let mut solver = Solver::default();
    solver.settings.dt = f32::NAN;
    assert!(solver.step(&mut world).is_err());
    let p = world.get::<&Particles>(e).unwrap();
    assert!(p
        .positions()
        .iter()
        .all(|x| x.iter().all(|c| c.is_finite())));
}

#[test]
fn state_writes_reject_bad_values() {
    let mut p = SoftBodyBuilder::new(unit_tet()).build().unwrap().particles;
    assert_eq!(
        p.set_position(4, Vector3::zeros()),
        Err(StateError::ParticleOutOfRange { index: 4, len: 4 })
    );
    assert_eq!(
        p.set_position(1, Vector3::new(f32::NAN, 0.0, 0.0)),
        Err(StateError::NonFinite {
            what: "position",
            index: 1
        })
    );
    assert_eq!(
        p.set_velocity(2, Vector3::new(0.0, f32::NEG_INFINITY, 0.0)),
        Err(StateError::NonFinite {
            what: "velocity",
            index: 2
        })
    );
    assert!(p.set_pinned(10, true).is_err());
    assert!(ExternalAcceleration::new(Vector3::new(0.0, f32::NAN, 0.0)).is_err());
    let mut e = SoftBodyBuilder::new(unit_tet())
        .edges(0.0)
        .build()
        .unwrap()
        .edges
        .unwrap();
    assert!(e.set_compliance(f32::NAN).is_err());
    assert_eq!(
        e.set_compliance(-1.0),
        Err(StateError::BadCompliance { value: -1.0 })
    );
    assert_eq!(e.compliance(), 0.0);
}
