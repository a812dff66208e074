//! The scene of the `asset_drop` example, shared by `tests/asset_drop.rs` and
//! `tests/rolling_blob_comes_to_rest.rs`: a committed OBJ asset tetrahedralized with
//! `tetpbd-io` and dropped on a fixed ground cuboid (top at y = 0) at 60 Hz, 10 substeps,
//! density 300 kg/m³, stiff edges and volume, deformation damping 5/s.
#![allow(dead_code)]

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::{SoftBodyBuilder, SolverSettings};
use tetpbd_io::{Skin, SurfaceMesh, TetrahedralizeBuilder};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, DeformationDamping, SoftCollider};

/// A dropped asset, ready to step.
pub struct AssetDrop {
    /// The scene.
    pub scene: CoupledWorld,
    /// The soft body.
    pub body: Entity,
    /// The asset's surface mesh (at its original place).
    pub render: SurfaceMesh,
    /// The render vertices where the body starts, m.
    pub points: Vec<Vector3<f32>>,
    /// The render vertices embedded in the body's tetrahedra.
    pub skin: Skin,
    /// Number of tetrahedra.
    pub tets: usize,
}

/// `examples/assets/{name}` tetrahedralized at `cell` (m) with `smoothing` passes, its lowest
/// point `height` (m) above the ground, colliding with `collider`.
pub fn asset_drop(
    name: &str,
    cell: f32,
    smoothing: u32,
    height: f32,
    collider: SoftCollider,
) -> AssetDrop {
    let path = format!("{}/examples/assets/{name}", env!("CARGO_MANIFEST_DIR"));
    let render = SurfaceMesh::read_obj(path).expect("asset");
    let mesh = TetrahedralizeBuilder::new(cell)
        .smoothing(smoothing)
        .build(&render)
        .expect("tetrahedra");
    let solver = SolverSettings {
        substeps: 10,
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, CouplingSettings::default()).expect("scene");
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    );
    let lowest = render.vertices.iter().map(|v| v.y).fold(f32::MAX, f32::min);
    let lift = Vector3::new(0.0, height - lowest, 0.0);
    let body = SoftBodyBuilder::new(mesh)
        .density(300.0)
        .edges(1e-6)
        .volume(0.0)
        .translation(lift)
        .build()
        .expect("body");
    let points: Vec<_> = render.vertices.iter().map(|v| v + lift).collect();
    let skin = Skin::embed(
        body.particles.positions(),
        body.tetrahedra.indices(),
        &points,
    )
    .expect("skin");
    let tets = body.tetrahedra.len();
    let e = body.spawn(&mut scene.soft);
    scene.soft.insert_one(e, collider).expect("entity");
    scene
        .soft
        .insert_one(e, DeformationDamping::new(5.0).expect("damping"))
        .expect("entity");
    AssetDrop {
        scene,
        body: e,
        render,
        points,
        skin,
        tets,
    }
}
