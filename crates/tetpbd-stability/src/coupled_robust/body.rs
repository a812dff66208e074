//! A soft body of the robustness scenes in either engine: `tetpbd` through the coupling, or
//! rapier 0.36's own soft body (hard edges and volumes, its `Constraints` solver, the
//! material and lumped masses of `tetpbd-bench`'s comparisons) in the same rapier scene.

use nalgebra::Vector3;
use rapier3d::prelude::{
    SoftBodyBuilder as RapierBuilder, SoftBodyCellModel, SoftBodyHandle, SoftBodySolver,
};
use tetpbd::{unique_edges, Activation, Particles, SoftBodyBuilder, SolverSettings, TetMesh};
use tetpbd_bench::{lumped_masses, rapier_material, to_rapier};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftCollider};

use crate::config::Config;

/// Soft substeps per frame in both engines (rapier: `num_solver_iterations`).
pub(crate) const SUBSTEPS: u32 = 10;

/// Which engine simulates the soft bodies of a scene.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Engine<'a> {
    /// `tetpbd` under a configuration of the suite, default coupling settings.
    Tetpbd(&'a Config),
    /// rapier's own soft bodies.
    Rapier,
}

/// A soft body in either engine, with its rest mesh.
pub(crate) struct Soft {
    kind: SoftKind,
    tets: Vec<[u32; 4]>,
    rest_signs: Vec<bool>,
}

enum SoftKind {
    Tetpbd(hecs::Entity),
    Rapier(SoftBodyHandle),
}

/// An empty scene at 60 Hz with [`SUBSTEPS`] substeps (default solver and coupling settings
/// otherwise); for rapier's soft bodies its solver iterations are set to the same count.
pub(crate) fn world(engine: Engine) -> Result<CoupledWorld, String> {
    let solver = SolverSettings {
        substeps: SUBSTEPS,
        ..SolverSettings::default()
    };
    let mut s =
        CoupledWorld::new(solver, CouplingSettings::default()).map_err(|e| e.to_string())?;
    if let Engine::Rapier = engine {
        s.physics.integration_parameters.num_solver_iterations = SUBSTEPS as usize;
    }
    Ok(s)
}

fn signed(p: &[Vector3<f32>], t: &[u32; 4]) -> f32 {
    let [a, b, c, d] = t.map(|i| p[i as usize]);
    tetpbd::constraint::signed_volume(&a, &b, &c, &d)
}

impl Soft {
    /// Spawns `mesh` (rest pose, m) moved by `at`, at `density` kg/m³ and `velocity` m/s.
    /// `tetpbd`: the configuration's families and the default [`SoftCollider`], never
    /// sleeping; rapier: hard edges and volumes, never sleeping.
    pub(crate) fn spawn(
        s: &mut CoupledWorld,
        engine: Engine,
        mesh: TetMesh,
        at: Vector3<f32>,
        velocity: Vector3<f32>,
        density: f32,
    ) -> Result<Soft, String> {
        let tets = mesh.tets.clone();
        let rest_signs = tets
            .iter()
            .map(|t| signed(&mesh.vertices, t) > 0.0)
            .collect();
        let kind = match engine {
            Engine::Tetpbd(config) => {
                let b = SoftBodyBuilder::new(mesh)
                    .density(density)
                    .translation(at)
                    .velocity(velocity);
                let body = config.apply(b, 1.0).build().map_err(|e| e.to_string())?;
                let e = body.spawn(&mut s.soft);
                // Watched awake, as rapier's bodies here: the suite measures the dynamics.
                s.soft
                    .insert(e, (SoftCollider::default(), Activation::never_sleeps()))
                    .map_err(|e| e.to_string())?;
                SoftKind::Tetpbd(e)
            }
            Engine::Rapier => {
                let cell = SoftBodyCellModel::Volume;
                let positions = mesh.vertices.iter().map(|v| to_rapier(&(v + at))).collect();
                let b = RapierBuilder::new(positions)
                    .cells(mesh.tets.clone())
                    .edges(unique_edges(&mesh.tets))
                    .masses(lumped_masses(&mesh, density))
                    .cell_model(cell)
                    .solver(SoftBodySolver::Constraints)
                    .material(rapier_material(cell, true))
                    .can_sleep(false);
                let h = s.physics.insert_soft_body(b);
                let body = &mut s.physics.soft_bodies[h];
                for i in 0..body.num_particles() {
                    body.set_particle_velocity(i, to_rapier(&velocity));
                }
                SoftKind::Rapier(h)
            }
        };
        Ok(Soft {
            kind,
            tets,
            rest_signs,
        })
    }

    /// The `tetpbd` entity, if the body is one.
    pub(crate) fn entity(&self) -> Option<hecs::Entity> {
        match self.kind {
            SoftKind::Tetpbd(e) => Some(e),
            SoftKind::Rapier(_) => None,
        }
    }

    /// The rapier handle, if the body is rapier's.
    pub(crate) fn rapier(&self) -> Option<SoftBodyHandle> {
        match self.kind {
            SoftKind::Tetpbd(_) => None,
            SoftKind::Rapier(h) => Some(h),
        }
    }

    /// Particle positions (m) and velocities (m/s), in mesh order.
    pub(crate) fn state(&self, s: &CoupledWorld) -> (Vec<Vector3<f32>>, Vec<Vector3<f32>>) {
        match self.kind {
            SoftKind::Tetpbd(e) => s.soft.get::<&Particles>(e).map_or_else(
                |_| (Vec::new(), Vec::new()),
                |p| (p.positions().to_vec(), p.velocities().to_vec()),
            ),
            SoftKind::Rapier(h) => s.physics.soft_bodies.get(h).map_or_else(
                || (Vec::new(), Vec::new()),
                |b| {
                    let na = |v: rapier3d::math::Vector| Vector3::new(v.x, v.y, v.z);
                    (
                        b.particle_positions().map(na).collect(),
                        b.particle_velocities().map(na).collect(),
                    )
                },
            ),
        }
    }

    /// Tetrahedra whose signed volume has the opposite sign of their rest volume's.
    pub(crate) fn inverted(&self, s: &CoupledWorld) -> usize {
        let (p, _) = self.state(s);
        if p.is_empty() {
            return 0;
        }
        self.tets
            .iter()
            .zip(&self.rest_signs)
            .filter(|(t, &up)| (signed(&p, t) > 0.0) != up)
            .count()
    }
}

/// What one frame of a soft body showed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Look {
    /// Lowest particle, m.
    pub lowest: f32,
    /// Fastest particle, m/s.
    pub fastest: f32,
    /// Centre of the particles (unweighted), m.
    pub centre: Vector3<f32>,
    /// Every position and velocity finite.
    pub finite: bool,
}

impl Soft {
    /// This frame's [`Look`].
    pub(crate) fn look(&self, s: &CoupledWorld) -> Look {
        let (p, v) = self.state(s);
        let n = p.len().max(1) as f32;
        Look {
            lowest: p.iter().map(|x| x.y).fold(f32::INFINITY, f32::min),
            fastest: v.iter().map(|x| x.norm()).fold(0.0, f32::max),
            centre: p.iter().sum::<Vector3<f32>>() / n,
            finite: p.iter().chain(&v).all(|x| x.iter().all(|c| c.is_finite())),
        }
    }
}
