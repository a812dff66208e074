//! The two engines behind one small trait: tetpbd's [`Solver`] on a hecs world, and rapier's
//! built-in soft bodies in a [`PhysicsWorld`].

use std::time::Instant;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    PhysicsWorld, SoftBodyBuilder as RapierBuilder, SoftBodyCellModel, SoftBodyHandle,
    SoftBodyMaterial, SoftBodySolver,
};
use tetpbd::systems::{self, Measured};
use tetpbd::{
    hecs, ErrorStats, Family, Particles, SoftBody, SoftBodyBuilder, Solver, SolverSettings,
    StepStats,
};

use tetpbd_bench::{
    rapier_label, rapier_material, thread_cpu_ms, to_rapier, RAPIER_HARD_HZ, RAPIER_POISSON,
    RAPIER_YOUNG,
};

use crate::scenes::{Scene, DT, MATERIAL_POISSON, MATERIAL_YOUNG};

/// Soft compliance of the length constraints (edges, vertex–face), m/N.
pub const SOFT_LENGTH_COMPLIANCE: f32 = 1e-7;
/// Soft compliance of the volume constraints, m⁵/N.
pub const SOFT_VOLUME_COMPLIANCE: f32 = 1e-11;

/// The constraint sets of tetpbd that are swept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstraintSet {
    /// Edges and signed volumes.
    EdgesVolume,
    /// Vertex–face constraints alone.
    VertexFace,
    /// Vertex–face constraints and edges.
    VertexFaceEdges,
}

/// One model of either engine: what is simulated, independent of substeps and iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// tetpbd with a constraint set, compliance 0 (`soft == false`) or the soft compliances.
    Ours {
        /// Constraint families.
        set: ConstraintSet,
        /// Soft compliances instead of 0.
        soft: bool,
    },
    /// rapier's soft body with a cell model and solver.
    Rapier {
        /// Cell model.
        cell: SoftBodyCellModel,
        /// Solver.
        solver: SoftBodySolver,
        /// For the volume model: edges and cell volumes at [`RAPIER_HARD_HZ`] instead of the
        /// default 30 Hz softness.
        hard: bool,
    },
    /// tetpbd's Neo-Hookean material (the material scene's [`tetpbd::Material`]) and no
    /// constraint family.
    Material,
    /// rapier's elastic cell model with the material scene's E and ν.
    RapierMaterial {
        /// Cell model (corotational or Neo-Hookean).
        cell: SoftBodyCellModel,
        /// Solver.
        solver: SoftBodySolver,
    },
}

impl Model {
    /// The engine's name.
    pub fn engine(&self) -> &'static str {
        match self {
            Model::Ours { .. } | Model::Material => "tetpbd",
            Model::Rapier { .. } | Model::RapierMaterial { .. } => "rapier",
        }
    }

    /// A short label, unique among the swept models.
    pub fn label(&self) -> String {
        match *self {
            Model::Ours { set, soft } => {
                let s = match set {
                    ConstraintSet::EdgesVolume => "edges+volume",
                    ConstraintSet::VertexFace => "vertex-face",
                    ConstraintSet::VertexFaceEdges => "vertex-face+edges",
                };
                format!("tetpbd {s} {}", if soft { "soft" } else { "α=0" })
            }
            Model::Rapier { cell, solver, hard } => rapier_label(cell, solver, hard),
            Model::Material => format!("tetpbd Neo-Hookean E={MATERIAL_YOUNG:e}"),
            Model::RapierMaterial { cell, solver } => {
                format!("{} E={MATERIAL_YOUNG:e}", rapier_label(cell, solver, false))
            }
        }
    }

    /// `true` for tetpbd's models.
    pub fn is_ours(&self) -> bool {
        self.engine() == "tetpbd"
    }

    /// `true` for the models whose converged answer keeps every edge and volume at rest
    /// (tetpbd with α = 0 and a set holding edges or volumes; rapier's hard volume model).
    pub fn is_hard(&self) -> bool {
        match *self {
            Model::Ours { soft, .. } => !soft,
            Model::Rapier { cell, hard, .. } => hard && cell == SoftBodyCellModel::Volume,
            Model::Material | Model::RapierMaterial { .. } => false,
        }
    }

    /// How the model is set up, for the summary.
    pub fn setup(&self) -> String {
        match *self {
            Model::Ours { set, soft } => {
                let (l, v) = if soft {
                    (SOFT_LENGTH_COMPLIANCE, SOFT_VOLUME_COMPLIANCE)
                } else {
                    (0.0, 0.0)
                };
                match set {
                    ConstraintSet::EdgesVolume => format!("edges α={l:e} m/N, volume α={v:e} m⁵/N"),
                    ConstraintSet::VertexFace => format!("vertex-face α={l:e} m/N"),
                    ConstraintSet::VertexFaceEdges => {
                        format!("vertex-face α={l:e} m/N, edges α={l:e} m/N")
                    }
                }
            }
            Model::Rapier { cell, hard, .. } => match cell {
                SoftBodyCellModel::Volume if hard => format!(
                    "tet edges + per-cell volume, edge and volume softness {RAPIER_HARD_HZ:e} Hz, ζ=1"
                ),
                SoftBodyCellModel::Volume => {
                    "tet edges + per-cell volume, default softness 30 Hz, ζ=1".to_string()
                }
                _ => format!(
                    "no edges, E={RAPIER_YOUNG:e} Pa, ν={RAPIER_POISSON}, elastic damping ratio 1"
                ),
            },
            Model::Material => format!(
                "`Material::new({MATERIAL_YOUNG:e} Pa, {MATERIAL_POISSON})`: stable Neo-Hookean, no material damping, no other constraint"
            ),
            Model::RapierMaterial { .. } => format!(
                "no edges, E={MATERIAL_YOUNG:e} Pa, ν={MATERIAL_POISSON}, elastic damping ratio 1 (rapier's default)"
            ),
        }
    }
}

/// One frame's cost.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameCost {
    /// Wall time of the step, ms.
    pub ms: f64,
    /// CPU time of the calling thread during the step, ms.
    pub cpu_ms: f64,
    /// Constraint projections done (0 when the engine does not say).
    pub projections: u64,
}

/// A running simulation of one scene.
pub trait Sim {
    /// Advances one frame of [`DT`].
    fn step(&mut self) -> FrameCost;
    /// Current particle positions, in mesh vertex order.
    fn positions(&self) -> Vec<Vector3<f32>>;
    /// tetpbd's own per-family `|C|` after the last step, in [`Family::ALL`] order (None for
    /// rapier; a family the body does not have is None).
    fn family_errors(&self) -> Option<[Option<ErrorStats>; 3]>;
}

/// Times `f` in wall and thread CPU ms.
fn timed(f: impl FnOnce()) -> (f64, f64) {
    let (t, c) = (Instant::now(), thread_cpu_ms());
    f();
    (t.elapsed().as_secs_f64() * 1e3, thread_cpu_ms() - c)
}

/// Builds the simulation of `model` on `scene` with `substeps × iterations` (rapier: its
/// `num_solver_iterations` is the substep count; it has no separate iteration count).
pub fn build(model: Model, scene: &Scene, substeps: u32, iterations: u32) -> Box<dyn Sim> {
    match model {
        Model::Ours { set, soft } => Box::new(Ours::new(
            ours_body(set, soft, scene),
            scene,
            substeps,
            iterations,
        )),
        Model::Material => Box::new(Ours::new(material_body(scene), scene, substeps, iterations)),
        Model::Rapier { cell, solver, hard } => Box::new(Rapier::new(
            cell,
            solver,
            rapier_material(cell, hard),
            scene,
            substeps,
        )),
        Model::RapierMaterial { cell, solver } => {
            let material = SoftBodyMaterial {
                young_modulus: MATERIAL_YOUNG,
                poisson_ratio: MATERIAL_POISSON,
                ..rapier_material(cell, false)
            };
            Box::new(Rapier::new(cell, solver, material, scene, substeps))
        }
    }
}

struct Ours {
    world: hecs::World,
    solver: Solver,
    last: StepStats,
    measured: Measured,
}

/// tetpbd's body for `set` on `scene`, with the scene's start positions set: what both the
/// `f32` solver and the `f64` reference stepper ([`tetpbd_bench::Xpbd64`]) run.
pub fn ours_body(set: ConstraintSet, soft: bool, scene: &Scene) -> SoftBody {
    let (l, v) = if soft {
        (SOFT_LENGTH_COMPLIANCE, SOFT_VOLUME_COMPLIANCE)
    } else {
        (0.0, 0.0)
    };
    let b = SoftBodyBuilder::new(scene.mesh.clone())
        .density(scene.density)
        .pinned(scene.pinned.iter().copied());
    let b = match set {
        ConstraintSet::EdgesVolume => b.edges(l).volume(v),
        ConstraintSet::VertexFace => b.vertex_face(l),
        ConstraintSet::VertexFaceEdges => b.vertex_face(l).edges(l),
    };
    started(b, scene)
}

/// tetpbd's body of a material scene: the scene's [`tetpbd::Material`] alone (a scene without
/// one gets [`crate::scenes::scene_material`]), start positions set.
pub fn material_body(scene: &Scene) -> SoftBody {
    let material = scene.material.unwrap_or_else(crate::scenes::scene_material);
    let b = SoftBodyBuilder::new(scene.mesh.clone())
        .density(scene.density)
        .pinned(scene.pinned.iter().copied())
        .material(material);
    started(b, scene)
}

/// Builds `b` and moves its particles to the scene's start positions.
fn started(b: SoftBodyBuilder, scene: &Scene) -> SoftBody {
    let mut body = b.build().expect("scene meshes are valid");
    for (i, x) in scene.start.iter().enumerate() {
        body.particles
            .set_position(i, *x)
            .expect("finite start positions");
    }
    body
}

/// tetpbd's solver settings for `scene` at `substeps × iterations`.
pub fn ours_settings(scene: &Scene, substeps: u32, iterations: u32) -> SolverSettings {
    SolverSettings {
        dt: DT,
        substeps,
        iterations,
        gravity: Vector3::new(0.0, scene.gravity, 0.0),
        damping: scene.damping,
        ..Default::default()
    }
}

impl Ours {
    fn new(body: SoftBody, scene: &Scene, substeps: u32, iterations: u32) -> Ours {
        let mut world = hecs::World::new();
        let e = body.spawn(&mut world);
        // The error is measured on the moving body: sleeping would freeze it.
        world
            .insert_one(e, tetpbd::Activation::never_sleeps())
            .expect("entity");
        let solver =
            Solver::new(ours_settings(scene, substeps, iterations)).expect("valid settings");
        Ours {
            world,
            solver,
            last: StepStats::default(),
            measured: Measured::default(),
        }
    }
}

impl Sim for Ours {
    fn step(&mut self) -> FrameCost {
        let (solver, world) = (&mut self.solver, &mut self.world);
        let mut stats = StepStats::default();
        let (ms, cpu_ms) = timed(|| stats = solver.step(world).expect("settings validated"));
        // The same evaluation `DiagnosticSettings::measure_error` runs, outside the timed step.
        self.measured = systems::measure(&mut self.world);
        self.last = stats;
        let s = &self.last;
        FrameCost {
            ms,
            cpu_ms,
            projections: s.edge.projections
                + s.vertex_face.projections
                + s.volume.projections
                + s.material.projections,
        }
    }

    fn positions(&self) -> Vec<Vector3<f32>> {
        let mut q = self.world.query::<&Particles>();
        q.iter()
            .next()
            .map(|p| p.positions().to_vec())
            .unwrap_or_default()
    }

    fn family_errors(&self) -> Option<[Option<ErrorStats>; 3]> {
        let m = &self.measured;
        Some(Family::ALL.map(|f| {
            let e = match f {
                Family::Edge => m.edge,
                Family::VertexFace => m.vertex_face,
                Family::Volume => m.volume,
            };
            (self.last.family(f).count > 0).then_some(e)
        }))
    }
}

struct Rapier {
    world: PhysicsWorld,
    handle: SoftBodyHandle,
}

impl Rapier {
    fn new(
        cell: SoftBodyCellModel,
        solver: SoftBodySolver,
        material: SoftBodyMaterial,
        scene: &Scene,
        substeps: u32,
    ) -> Rapier {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, scene.gravity, 0.0);
        world.integration_parameters.dt = DT;
        world.integration_parameters.num_solver_iterations = substeps as usize;
        let mut b = RapierBuilder::new(scene.mesh.vertices.iter().map(to_rapier).collect())
            .cells(scene.mesh.tets.clone())
            .masses(tetpbd_bench::lumped_masses(&scene.mesh, scene.density))
            .pinned_particles(scene.pinned.iter().copied())
            .cell_model(cell)
            .solver(solver)
            .material(material)
            .linear_damping(scene.damping)
            .no_surface_collider()
            .can_sleep(false);
        if cell == SoftBodyCellModel::Volume {
            b = b.edges(scene.edges.clone());
        }
        let handle = world.insert_soft_body(b);
        let body = &mut world.soft_bodies[handle];
        for (i, x) in scene.start.iter().enumerate() {
            body.set_particle_position(i, to_rapier(x));
        }
        Rapier { world, handle }
    }
}

impl Sim for Rapier {
    fn step(&mut self) -> FrameCost {
        let world = &mut self.world;
        let (ms, cpu_ms) = timed(|| world.step());
        FrameCost {
            ms,
            cpu_ms,
            projections: 0,
        }
    }

    fn positions(&self) -> Vec<Vector3<f32>> {
        self.world.soft_bodies[self.handle]
            .particle_positions()
            .map(|p| Vector3::new(p.x, p.y, p.z))
            .collect()
    }

    fn family_errors(&self) -> Option<[Option<ErrorStats>; 3]> {
        None
    }
}
