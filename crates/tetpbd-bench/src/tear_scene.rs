//! The tearing scene, the same in both engines: a soft slab (1 × 0.1 × 0.4 m, 10 × 1 × 4
//! cells, 1000 kg/m³) lying on the ground, its two end faces attached to two kinematic boxes
//! that move apart at a given speed until each has travelled [`PULL_DISTANCE`], then stop.
//! The slab tears past a strain of [`TEAR_STRAIN`], smoothed over [`TEAR_SMOOTHING`].
//!
//! In `tetpbd` the slab is a body of a [`CoupledWorld`] with stiff edges and volumes and its
//! ends held by [`Attachments`] of compliance 0; in rapier 0.36 it is rapier's own soft body
//! (its `Constraints` solver, `Volume` cell model at [`crate::RAPIER_HARD_HZ`], the same lumped
//! masses, as in every comparison of this crate) in the same rapier scene, its end particles
//! attached with `SoftBody::attach_particle`, `tear_strain` and `tear_smoothing` set to the
//! same figures, its solver iterations equal to `tetpbd`'s substeps. rapier's strain is an
//! edge's or a cell's, `tetpbd`'s the distance across a face: the thresholds are the same
//! number, not the same physical criterion.

use std::sync::Mutex;
use std::time::Instant;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    ColliderBuilder, ColliderSet, CollisionEvent, ContactPair, EventHandler, RigidBodyBuilder,
    RigidBodyHandle, RigidBodySet, SoftBodyBuilder as RapierBuilder, SoftBodyCellModel,
    SoftBodyHandle, SoftBodySet, SoftBodySolver, SoftBodyTearEvent,
};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{unique_edges, Particles, SoftBodyBuilder, SolverSettings, TearingSettings};
use tetpbd::{TetMesh, Tetrahedra};
use tetpbd_rapier::{Attachments, CoupledWorld, CouplingSettings, SoftCollider};

use crate::rapier_setup::{lumped_masses, rapier_material, to_rapier};

/// Strain at which the slab tears, both engines (dimensionless).
pub const TEAR_STRAIN: f32 = 0.3;
/// Time constant of the strain's smoothing, both engines, s.
pub const TEAR_SMOOTHING: f32 = 0.05;
/// How far each box travels before it stops, m.
pub const PULL_DISTANCE: f32 = 0.6;
/// Soft substeps per frame (rapier: solver iterations).
pub const TEAR_SUBSTEPS: u32 = 10;
/// Half extents of the fixed ground cuboid, m; its top face is at y = 0.
pub const TEAR_GROUND_HALF_EXTENTS: [f32; 3] = [10.0, 0.5, 10.0];

/// Half the slab's length, m.
const HALF: f32 = 0.5;
/// Density of the slab, kg/m³.
const DENSITY: f32 = 1000.0;

/// Which engine simulates the slab.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TearEngine {
    /// `tetpbd` through the coupling.
    Tetpbd,
    /// rapier 0.36's own soft body.
    Rapier,
}

/// One tear or cut, in either engine's terms.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TearSummary {
    /// The body that tore (the engine's entity or handle, printed).
    pub body: String,
    /// The bodies split off it (printed).
    pub new_pieces: Vec<String>,
    /// Faces torn (`tetpbd`), or edges and cells torn (rapier).
    pub torn: usize,
    /// Particles copied or inserted.
    pub particles_copied: usize,
}

impl TearSummary {
    /// A `tetpbd` event.
    pub fn of_tetpbd(e: &tetpbd::TearEvent) -> TearSummary {
        TearSummary {
            body: format!("{:?}", e.body),
            new_pieces: e.new_entities().map(|n| format!("{n:?}")).collect(),
            torn: e.faces_torn,
            particles_copied: e.particles_added(),
        }
    }

    /// A rapier event.
    pub fn of_rapier(e: &SoftBodyTearEvent) -> TearSummary {
        TearSummary {
            body: rapier_name(e.soft_body),
            new_pieces: e
                .bodies()
                .filter(|&b| b != e.soft_body)
                .map(rapier_name)
                .collect(),
            torn: e.torn_edges.len() + e.torn_cells.len(),
            particles_copied: e.split_particles.len() + e.inserted_particles.len(),
        }
    }
}

/// A rapier soft body's handle as `{index}v{generation}`, as hecs prints an entity.
fn rapier_name(h: SoftBodyHandle) -> String {
    let (i, g) = h.into_raw_parts();
    format!("{i}v{g}")
}

/// rapier's tear events of a step, gathered.
#[derive(Default)]
struct Collector(Mutex<Vec<TearSummary>>);

impl EventHandler for Collector {
    fn handle_collision_event(
        &self,
        _: &RigidBodySet,
        _: &ColliderSet,
        _: CollisionEvent,
        _: Option<&ContactPair>,
    ) {
    }

    fn handle_contact_force_event(
        &self,
        _: f32,
        _: &RigidBodySet,
        _: &ColliderSet,
        _: &ContactPair,
        _: f32,
    ) {
    }

    fn handle_soft_body_tear_event(&self, _: &SoftBodySet, event: &SoftBodyTearEvent) {
        if let Ok(mut v) = self.0.lock() {
            v.push(TearSummary::of_rapier(event));
        }
    }
}

/// One piece of the slab as it is now.
#[derive(Clone, Debug)]
pub struct Fragment {
    /// Particle positions, m.
    pub positions: Vec<Vector3<f32>>,
    /// Particle velocities, m/s.
    pub velocities: Vec<Vector3<f32>>,
    /// Particle masses, kg.
    pub masses: Vec<f32>,
    /// Tetrahedra whose rest shape is inverted (signed rest volume ≤ 0).
    pub inverted_rest: usize,
    /// Tetrahedra whose signed volume now has the opposite sign of their rest volume's.
    pub inverted: usize,
}

impl Fragment {
    /// Every position and velocity finite.
    pub fn finite(&self) -> bool {
        let ok = |v: &Vector3<f32>| v.iter().all(|c| c.is_finite());
        self.positions.iter().all(ok) && self.velocities.iter().all(ok)
    }

    /// Speed of the centre of mass, m/s (0 for a massless piece).
    pub fn speed(&self) -> f32 {
        let m: f32 = self.masses.iter().sum();
        if m <= 0.0 {
            return 0.0;
        }
        let p: Vector3<f32> = self
            .velocities
            .iter()
            .zip(&self.masses)
            .map(|(v, &m)| v * m)
            .sum();
        (p / m).norm()
    }

    /// Lowest particle over the ground (|x|, |z| inside its top face), m; `+∞` if none is.
    pub fn lowest_over_ground(&self) -> f32 {
        let [gx, _, gz] = TEAR_GROUND_HALF_EXTENTS;
        self.positions
            .iter()
            .filter(|x| x.x.abs() < gx && x.z.abs() < gz)
            .map(|x| x.y)
            .fold(f32::INFINITY, f32::min)
    }
}

/// The slab pulled apart by two boxes, in either engine (module docs).
pub struct SlabPull {
    /// The engine simulating the slab.
    pub engine: TearEngine,
    /// The scene: rapier's world, and `tetpbd`'s soft world (empty with rapier's soft body).
    pub world: CoupledWorld,
    /// The two boxes, at −x and +x.
    pub holders: [RigidBodyHandle; 2],
    speed: f32,
    frame: usize,
    events: Collector,
}

/// The slab's rest mesh, centred at the origin.
fn slab_mesh() -> Result<TetMesh, String> {
    box_grid(
        Vector3::new(2.0 * HALF, 0.1, 0.4),
        [10, 1, 4],
        CellSplit::Six,
    )
    .map_err(|e| e.to_string())
}

/// Where the slab lies: its bottom 1 cm above the ground.
const AT: Vector3<f32> = Vector3::new(0.0, 0.06, 0.0);

impl SlabPull {
    /// The scene with the boxes moving apart at `speed` m/s each. `families` adds the
    /// constraint families of `tetpbd`'s slab (ignored for rapier's);
    /// [`SlabPull::stiff`] is the scene's own choice.
    pub fn new(
        engine: TearEngine,
        speed: f32,
        families: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
    ) -> Result<SlabPull, String> {
        if !(speed.is_finite() && speed >= 0.0) {
            return Err(format!("speed {speed} m/s: not finite and ≥ 0"));
        }
        let solver = SolverSettings {
            substeps: TEAR_SUBSTEPS,
            ..SolverSettings::default()
        };
        let mut world =
            CoupledWorld::new(solver, CouplingSettings::default()).map_err(|e| e.to_string())?;
        world.physics.integration_parameters.num_solver_iterations = TEAR_SUBSTEPS as usize;
        let [gx, gy, gz] = TEAR_GROUND_HALF_EXTENTS;
        world.physics.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, -gy, 0.0)),
            ColliderBuilder::cuboid(gx, gy, gz),
        );
        let mut holders = [RigidBodyHandle::invalid(); 2];
        for (k, side) in [-1.0f32, 1.0].into_iter().enumerate() {
            let (h, _) = world.physics.insert(
                RigidBodyBuilder::kinematic_velocity_based()
                    .translation(Vector::new(side * (HALF + 0.05), 0.3, 0.0))
                    .linvel(Vector::new(side * speed, 0.0, 0.0)),
                ColliderBuilder::cuboid(0.05, 0.05, 0.05),
            );
            holders[k] = h;
        }
        let mesh = slab_mesh()?;
        match engine {
            TearEngine::Tetpbd => spawn_tetpbd(&mut world, mesh, holders, families)?,
            TearEngine::Rapier => spawn_rapier(&mut world, mesh, holders),
        }
        Ok(SlabPull {
            engine,
            world,
            holders,
            speed,
            frame: 0,
            events: Collector::default(),
        })
    }

    /// The scene's own families: edges at 10⁻⁶ m/N, volumes at 10⁻⁸ m⁵/N.
    pub fn stiff(b: SoftBodyBuilder) -> SoftBodyBuilder {
        b.edges(1e-6).volume(1e-8)
    }

    /// Frames until both boxes have stopped.
    pub fn pull_frames(&self) -> usize {
        if self.speed > 0.0 {
            (PULL_DISTANCE / self.speed / crate::DT).ceil() as usize
        } else {
            0
        }
    }

    /// Steps one frame (stopping the boxes once they have travelled [`PULL_DISTANCE`]) and
    /// returns the tears of the frame.
    pub fn step(&mut self) -> Result<Vec<TearSummary>, String> {
        if self.frame == self.pull_frames() {
            for h in self.holders {
                self.world.physics.bodies[h].set_linvel(Vector::ZERO, true);
            }
        }
        self.frame += 1;
        match self.engine {
            TearEngine::Tetpbd => {
                self.world.step().map_err(|e| e.to_string())?;
                let events = self.world.coupling.tear_events();
                Ok(events.iter().map(TearSummary::of_tetpbd).collect())
            }
            TearEngine::Rapier => {
                self.world.physics.step_with_events(&(), &self.events);
                let mut v = self.events.0.lock().map_err(|e| e.to_string())?;
                Ok(std::mem::take(&mut *v))
            }
        }
    }

    /// Steps one frame and times it: the tears and the wall time, ms.
    pub fn step_timed(&mut self) -> Result<(Vec<TearSummary>, f64), String> {
        let t = Instant::now();
        let tears = self.step()?;
        Ok((tears, t.elapsed().as_secs_f64() * 1e3))
    }

    /// The slab's pieces as they are now, in the engine's order.
    pub fn fragments(&self) -> Vec<Fragment> {
        match self.engine {
            TearEngine::Tetpbd => tetpbd_fragments(&self.world),
            TearEngine::Rapier => rapier_fragments(&self.world),
        }
    }
}

/// `tetpbd`'s slab: stiff families (or `families`), tearing, a soft collider, its end faces
/// attached to the boxes with compliance 0.
fn spawn_tetpbd(
    world: &mut CoupledWorld,
    mesh: TetMesh,
    holders: [RigidBodyHandle; 2],
    families: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
) -> Result<(), String> {
    let b = SoftBodyBuilder::new(mesh).density(DENSITY);
    let body = families(b)
        .tearing(TearingSettings {
            strain: Some(TEAR_STRAIN),
            smoothing_time: TEAR_SMOOTHING,
            ..Default::default()
        })
        .translation(AT)
        .build()
        .map_err(|e| e.to_string())?;
    let mut att = Attachments::new();
    for (h, side) in holders.into_iter().zip([-1.0f32, 1.0]) {
        for i in 0..body.particles.len() {
            if (body.particles.positions()[i].x - side * HALF).abs() < 1e-4 {
                att.attach_to_body(&body.particles, i as u32, &world.physics.bodies, h, 0.0)
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    let e = body.spawn(&mut world.soft);
    world
        .soft
        .insert(e, (att, SoftCollider::default()))
        .map_err(|e| e.to_string())
}

/// rapier's slab (module docs), its end particles attached to the boxes.
fn spawn_rapier(world: &mut CoupledWorld, mesh: TetMesh, holders: [RigidBodyHandle; 2]) {
    let cell = SoftBodyCellModel::Volume;
    let mut material = rapier_material(cell, true);
    material.tear_strain = Some(TEAR_STRAIN);
    material.tear_smoothing = TEAR_SMOOTHING;
    let b = RapierBuilder::new(mesh.vertices.iter().map(|v| to_rapier(&(v + AT))).collect())
        .cells(mesh.tets.clone())
        .edges(unique_edges(&mesh.tets))
        .masses(lumped_masses(&mesh, DENSITY))
        .cell_model(cell)
        .solver(SoftBodySolver::Constraints)
        .material(material)
        .can_sleep(false);
    let h = world.physics.insert_soft_body(b);
    let physics = &mut world.physics;
    let body = &mut physics.soft_bodies[h];
    for (k, side) in [-1.0f32, 1.0].into_iter().enumerate() {
        for (i, v) in mesh.vertices.iter().enumerate() {
            if (v.x - side * HALF).abs() < 1e-4 {
                body.attach_particle(i, holders[k], &physics.bodies);
            }
        }
    }
}

fn signed(p: &[Vector3<f32>], t: &[u32; 4]) -> f32 {
    let [a, b, c, d] = t.map(|i| p[i as usize]);
    tetpbd::constraint::signed_volume(&a, &b, &c, &d)
}

fn tetpbd_fragments(world: &CoupledWorld) -> Vec<Fragment> {
    let mut q = world.soft.query::<(&Particles, &Tetrahedra)>();
    q.iter()
        .map(|(p, t)| {
            let rest: Vec<f32> = t
                .indices()
                .iter()
                .map(|t| signed(p.rest_positions(), t))
                .collect();
            Fragment {
                positions: p.positions().to_vec(),
                velocities: p.velocities().to_vec(),
                masses: p.masses().to_vec(),
                inverted_rest: rest.iter().filter(|&&v| v <= 0.0).count(),
                inverted: t
                    .indices()
                    .iter()
                    .zip(&rest)
                    .filter(|(t, &r)| (signed(p.positions(), t) > 0.0) != (r > 0.0))
                    .count(),
            }
        })
        .collect()
}

fn rapier_fragments(world: &CoupledWorld) -> Vec<Fragment> {
    let na = |v: Vector| Vector3::new(v.x, v.y, v.z);
    world
        .physics
        .soft_bodies()
        .map(|(_, b)| {
            let rest: Vec<_> = b
                .particles()
                .iter()
                .map(|p| na(p.rest_position()))
                .collect();
            let positions: Vec<_> = b.particle_positions().map(na).collect();
            let rest_signs: Vec<f32> = b
                .cells()
                .iter()
                .map(|c| signed(&rest, &c.vertices))
                .collect();
            Fragment {
                inverted_rest: rest_signs.iter().filter(|&&v| v <= 0.0).count(),
                inverted: b
                    .cells()
                    .iter()
                    .zip(&rest_signs)
                    .filter(|(c, &r)| (signed(&positions, &c.vertices) > 0.0) != (r > 0.0))
                    .count(),
                positions,
                velocities: b.particle_velocities().map(na).collect(),
                masses: b.particles().iter().map(|p| p.mass()).collect(),
            }
        })
        .collect()
}
