//! The contact scenes in either engine: tetpbd bodies in a [`CoupledWorld`] (rigid ground
//! through the coupling, soft–soft contacts by the coupling too, on by default), or rapier's built-in
//! soft bodies in a [`PhysicsWorld`] with their default surface colliders.

use std::error::Error;
use std::time::Instant;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    ColliderBuilder, PhysicsWorld, RigidBodyBuilder, SoftBodyBuilder as RapierBuilder,
    SoftBodyCellModel, SoftBodyHandle, SoftBodySolver,
};
use tetpbd::{hecs, unique_edges, Activation, Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, DeformationDamping};

use crate::clock::thread_cpu_ms;
use crate::contact_scene::{ContactScene, GROUND_HALF_EXTENTS};
use crate::rapier_setup::{lumped_masses, rapier_label, rapier_material, to_rapier};
use crate::DT;

/// One engine set-up of the contact scenes, independent of substeps and iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactEngine {
    /// tetpbd: edges and volumes at compliance 0, with the coupling's deformation damping.
    Tetpbd {
        /// `DeformationDamping` rate, 1/s (0 = none).
        damping: f32,
        /// `StackingSettings::self_weight`.
        self_weight: bool,
    },
    /// rapier's soft body with a cell model and solver (material: [`crate::rapier_material`]).
    Rapier {
        /// Cell model.
        cell: SoftBodyCellModel,
        /// Solver.
        solver: SoftBodySolver,
        /// Hard edges and volumes (Volume model only).
        hard: bool,
    },
}

impl ContactEngine {
    /// The engine's name.
    pub fn engine(&self) -> &'static str {
        match self {
            ContactEngine::Tetpbd { .. } => "tetpbd",
            ContactEngine::Rapier { .. } => "rapier",
        }
    }

    /// A short label, unique among the engine set-ups.
    pub fn label(&self) -> String {
        match *self {
            ContactEngine::Tetpbd {
                damping,
                self_weight,
            } => {
                let sweep = if self_weight {
                    ", self-weight sweep"
                } else {
                    ""
                };
                if damping > 0.0 {
                    format!("tetpbd edges+volume α=0, damping {damping}/s{sweep}")
                } else {
                    format!("tetpbd edges+volume α=0, undamped{sweep}")
                }
            }
            ContactEngine::Rapier { cell, solver, hard } => rapier_label(cell, solver, hard),
        }
    }
}

/// A running contact scene.
pub trait ContactSim {
    /// Advances one frame of [`DT`]; returns its wall and thread CPU time, ms.
    fn step(&mut self) -> Result<(f64, f64), Box<dyn Error>>;
    /// Current particle positions of every body, in mesh vertex order, bodies in placement
    /// order.
    fn bodies(&self) -> Vec<Vec<Vector3<f32>>>;
}

/// Builds `engine` on `scene` with `substeps × iterations` (rapier: `num_solver_iterations`
/// is the substep count; it has no separate iteration count, so `iterations` must be 1).
pub fn build_contact(
    engine: ContactEngine,
    scene: &ContactScene,
    substeps: u32,
    iterations: u32,
) -> Result<Box<dyn ContactSim>, Box<dyn Error>> {
    Ok(match engine {
        ContactEngine::Tetpbd {
            damping,
            self_weight,
        } => Box::new(Ours::new(
            scene,
            damping,
            self_weight,
            substeps,
            iterations,
        )?),
        ContactEngine::Rapier { cell, solver, hard } => {
            if iterations != 1 {
                return Err(format!("rapier has no iteration count (got {iterations})").into());
            }
            Box::new(Rapier::new(scene, cell, solver, hard, substeps))
        }
    })
}

fn ground() -> (RigidBodyBuilder, ColliderBuilder) {
    let [x, y, z] = GROUND_HALF_EXTENTS;
    (
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -y, 0.0)),
        ColliderBuilder::cuboid(x, y, z),
    )
}

/// Wall and thread CPU ms of `f`.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let (t, c) = (Instant::now(), thread_cpu_ms());
    let r = f();
    (r, t.elapsed().as_secs_f64() * 1e3, thread_cpu_ms() - c)
}

struct Ours {
    scene: CoupledWorld,
    bodies: Vec<hecs::Entity>,
}

/// tetpbd's side of `sc`: the coupled world (ground, frame [`DT`], `substeps` ×
/// `iterations`, `self_weight` as `StackingSettings::self_weight`) and one soft body
/// per placement, edges and volumes at compliance 0, with `DeformationDamping` at `damping`
/// 1/s when it is above 0. Soft–soft contacts are the coupling's
/// (`CouplingSettings::soft_contacts`, on by default).
pub fn tetpbd_contact_world(
    sc: &ContactScene,
    damping: f32,
    self_weight: bool,
    substeps: u32,
    iterations: u32,
) -> Result<(CoupledWorld, Vec<hecs::Entity>), Box<dyn Error>> {
    let solver = SolverSettings {
        dt: DT,
        substeps,
        iterations,
        ..SolverSettings::default()
    };
    let coupling = CouplingSettings {
        stacking: Some(tetpbd_rapier::StackingSettings {
            self_weight,
            ..Default::default()
        }),
        ..CouplingSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, coupling)?;
    let (body, collider) = ground();
    scene.physics.insert(body, collider);
    let mut bodies = Vec::new();
    for at in &sc.placements {
        let e = SoftBodyBuilder::new(sc.cube.clone())
            .density(sc.density)
            .edges(0.0)
            .volume(0.0)
            .translation(*at)
            .build()?
            .spawn(&mut scene.soft);
        // Benchmarks time the solver on awake bodies: sleeping would end the work being measured.
        scene.soft.insert_one(e, Activation::never_sleeps())?;
        if damping > 0.0 {
            scene
                .soft
                .insert_one(e, DeformationDamping::new(damping)?)?;
        }
        bodies.push(e);
    }
    Ok((scene, bodies))
}

impl Ours {
    fn new(
        sc: &ContactScene,
        damping: f32,
        self_weight: bool,
        substeps: u32,
        iterations: u32,
    ) -> Result<Ours, Box<dyn Error>> {
        let (scene, bodies) = tetpbd_contact_world(sc, damping, self_weight, substeps, iterations)?;
        Ok(Ours { scene, bodies })
    }
}

impl ContactSim for Ours {
    fn step(&mut self) -> Result<(f64, f64), Box<dyn Error>> {
        let scene = &mut self.scene;
        let (r, ms, cpu) = timed(|| scene.step());
        r?;
        Ok((ms, cpu))
    }

    fn bodies(&self) -> Vec<Vec<Vector3<f32>>> {
        self.bodies
            .iter()
            .map(|&e| {
                self.scene
                    .soft
                    .get::<&Particles>(e)
                    .map(|p| p.positions().to_vec())
                    .unwrap_or_default()
            })
            .collect()
    }
}

struct Rapier {
    world: PhysicsWorld,
    bodies: Vec<SoftBodyHandle>,
}

impl Rapier {
    fn new(
        sc: &ContactScene,
        cell: SoftBodyCellModel,
        solver: SoftBodySolver,
        hard: bool,
        substeps: u32,
    ) -> Rapier {
        let mut world = PhysicsWorld::new();
        world.integration_parameters.dt = DT;
        world.integration_parameters.num_solver_iterations = substeps as usize;
        let (body, collider) = ground();
        world.insert(body, collider);
        let masses = lumped_masses(&sc.cube, sc.density);
        let edges = unique_edges(&sc.cube.tets);
        let bodies = (0..sc.placements.len())
            .map(|b| {
                let mut builder = RapierBuilder::new(sc.start(b).iter().map(to_rapier).collect())
                    .cells(sc.cube.tets.clone())
                    .masses(masses.clone())
                    .cell_model(cell)
                    .solver(solver)
                    .material(rapier_material(cell, hard))
                    .can_sleep(false);
                if cell == SoftBodyCellModel::Volume {
                    builder = builder.edges(edges.clone());
                }
                world.insert_soft_body(builder)
            })
            .collect();
        Rapier { world, bodies }
    }
}

impl ContactSim for Rapier {
    fn step(&mut self) -> Result<(f64, f64), Box<dyn Error>> {
        let world = &mut self.world;
        let ((), ms, cpu) = timed(|| world.step());
        Ok((ms, cpu))
    }

    fn bodies(&self) -> Vec<Vec<Vector3<f32>>> {
        self.bodies
            .iter()
            .map(|&h| {
                self.world.soft_bodies[h]
                    .particle_positions()
                    .map(|p| Vector3::new(p.x, p.y, p.z))
                    .collect()
            })
            .collect()
    }
}
