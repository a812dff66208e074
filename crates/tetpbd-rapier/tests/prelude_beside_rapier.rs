//! tetpbd's prelude lives beside `rapier3d::prelude::*`: every name it exports is usable
//! with both globs in scope (a clash would make the name ambiguous and this file would not
//! compile), and a body placed with rapier's types starts where the nalgebra pose puts it.

use rapier3d::prelude::*;
use tetpbd_rapier::prelude::*;

#[test]
fn every_prelude_name_resolves_next_to_rapiers_prelude() -> Result<(), Box<dyn std::error::Error>> {
    let mut scene = CoupledWorld::new(SolverSettings::default(), CouplingSettings::default())?;
    scene.physics.insert(
        RigidBodyBuilder::fixed(),
        ColliderBuilder::cuboid(2.0, 0.1, 2.0),
    );
    let mesh: TetMesh = generators::box_grid(
        nalgebra::Vector3::repeat(0.2),
        [2, 2, 2],
        generators::CellSplit::Six,
    )?;
    let body: TetBody = TetBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .placement(Placement {
            translation: nalgebra::Vector3::new(0.0, 0.4, 0.0),
            ..Placement::default()
        })
        .build()?;
    let e = body.spawn(&mut scene.soft);
    let collider: SoftCollider = SoftColliderBuilder::new().friction(0.5).build()?;
    scene.soft.insert(e, (collider, Attachments::default()))?;
    let stats: Result<CouplingStats, CouplingError> = scene.step();
    stats?;
    let _: Vec<ContactReport> = scene.coupling.contacts().to_vec();
    let _: fn(&Particles) -> usize = Particles::len;
    let _: fn(&Tetrahedra) -> usize = Tetrahedra::len;
    let _: fn(&Surface) -> &[[u32; 3]] = Surface::triangles;
    let _: Option<(StepStats, ExternalAcceleration, Solver)> = None;
    let _: Option<(UserForces, Grab, MaterialPoint)> = None;
    let _: Option<(BuildError, SettingsError, StateError, StepError)> = None;
    let (soft, rigid) = scene.queries();
    let ray = Ray::new(Vector::new(0.0, 2.0, 0.0), Vector::new(0.0, -1.0, 0.0));
    let filter: SoftQueryFilter = SoftQueryFilter::new();
    let hit: Option<SceneRayHit> = soft.cast_ray_scene(&rigid, &ray, Real::MAX, true, filter)?;
    assert!(matches!(hit, Some(SceneRayHit::Soft(SoftRayHit { entity, .. })) if entity == e));
    let _: &SoftQueries = soft;
    let _: Option<(
        QueryError,
        ScenePointProjection,
        SoftLocation,
        SoftPointProjection,
        SoftVolumePoint,
    )> = None;
    let _: Option<(
        AttachTarget,
        Attachment,
        SoftFeature,
        RapierContext<'_>,
        Coupling,
    )> = None;
    Ok(())
}

#[test]
fn rapier_pose_places_a_body_as_the_nalgebra_pose_does() -> Result<(), Box<dyn std::error::Error>> {
    let mesh = || {
        generators::box_grid(
            nalgebra::Vector3::repeat(0.3),
            [2, 2, 2],
            generators::CellSplit::Five,
        )
    };
    for k in 0..8 {
        let angle = 0.4 * k as f32;
        let translation = Vector::new(k as f32, -2.0, 0.5 * k as f32);
        let pose = Pose::from_parts(
            translation,
            Rotation::from_axis_angle(Vector::new(0.6, 0.0, 0.8), angle),
        );
        let linvel = Vector::new(1.0, 0.0, -k as f32);
        let angvel = Vector::new(0.0, angle, 1.0);
        let by_rapier = TetBodyBuilder::new(mesh()?)
            .edges(0.0)
            .rapier_pose(pose)
            .rapier_velocity(linvel, angvel)
            .build()?;
        let iso = nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::new(translation.x, translation.y, translation.z),
            nalgebra::UnitQuaternion::from_axis_angle(
                &nalgebra::Unit::new_normalize(nalgebra::Vector3::new(0.6, 0.0, 0.8)),
                angle,
            ),
        );
        let by_nalgebra = TetBodyBuilder::new(mesh()?)
            .edges(0.0)
            .pose(iso)
            .velocity(nalgebra::Vector3::new(linvel.x, linvel.y, linvel.z))
            .angular_velocity(nalgebra::Vector3::new(angvel.x, angvel.y, angvel.z))
            .build()?;
        let (a, b) = (&by_rapier.particles, &by_nalgebra.particles);
        for (x, y) in a.positions().iter().zip(b.positions()) {
            assert!((x - y).norm() < 1e-5, "pose {k}: {x:?} vs {y:?}");
        }
        for (x, y) in a.velocities().iter().zip(b.velocities()) {
            assert!((x - y).norm() < 1e-5, "velocity {k}");
        }
    }
    Ok(())
}
