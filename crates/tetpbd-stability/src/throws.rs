//! A seeded family of throws at immovable ground: bodies of any size, resolution, grid
//! split and shape (box grids and balls), at any speed and substep count, hard or compliant,
//! run on the suite's own ground ([`crate::Ground`], [`Throw::run_core`]) or coupled to a
//! fixed rapier ground ([`Throw::run_coupled`]).
//!
//! Every throw must end intact — no inverted tetrahedron, and, after the settling of
//! [`crate::settle`], the volume of the same body released at rest from the same height
//! within 1 % — and never leave faster than it came. The impact rows of the matrix throw
//! one 0.5 m cube of 4³ cells; this family is what tells a rule that holds for that cube
//! from one that holds for bodies in general.

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{ball, box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings, TetMesh, Tetrahedra};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftCollider};

use crate::config::{Config, ConstraintSet};
use crate::draws::Draws;
use crate::run::{run_scene, Scene};
use crate::settle::{SETTLE_DAMPING, SETTLE_FRAMES};

/// The body thrown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A cube of this edge (m) and cells per side.
    Cube(f32, u32, CellSplit),
    /// A ball of this radius (m) from a grid of this many cells per side
    /// ([`tetpbd::generators::ball`]).
    Ball(f32, u32, CellSplit),
}

impl Shape {
    /// Its mesh, its lowest vertex [`Throw::GAP`] above the plane y = 0.
    pub fn mesh(&self) -> TetMesh {
        let mesh = match *self {
            Shape::Cube(size, cells, split) => box_grid(Vector3::repeat(size), [cells; 3], split),
            Shape::Ball(radius, cells, split) => ball(radius, cells, split),
        };
        let mut mesh = mesh.unwrap_or_default();
        let low = mesh
            .vertices
            .iter()
            .map(|v| v.y)
            .fold(f32::INFINITY, f32::min);
        for v in &mut mesh.vertices {
            v.y += Throw::GAP - low;
        }
        mesh
    }
}

/// One throw: a body straight down at immovable ground (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Throw {
    /// The body.
    pub shape: Shape,
    /// Its families and whether they are compliant.
    pub config: Config,
    /// Multiplies [`Config`]'s soft edge and vertex–face compliance (1 = the matrix's own).
    pub length_scale: f32,
    /// Multiplies [`Config`]'s soft volume compliance.
    pub volume_scale: f32,
    /// Speed of the throw, m/s.
    pub speed: f32,
    /// Substeps per 1/60 s frame.
    pub substeps: u32,
}

/// What one throw measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Landing {
    /// Inverted tetrahedra at the end of the run or after the settling, whichever is more.
    pub inverted: usize,
    /// |settled volume / that of the same body released at rest − 1|.
    pub volume_off: f32,
    /// Fastest upward speed of the centre of mass, m/s.
    pub rose: f32,
    /// Whether every position and velocity stayed finite with no non-finite reset.
    pub finite: bool,
}

impl Landing {
    /// Intact, finite, and never rose as fast as it came at `speed` (m/s).
    pub fn holds(&self, speed: f32) -> bool {
        self.finite && self.inverted == 0 && self.volume_off < 0.01 && self.rose < speed
    }
}

impl Throw {
    /// Gap between the body's lowest vertex and the ground at the start, m.
    pub const GAP: f32 = 0.05;
    /// Frames of the throw proper (1/60 s).
    pub const FRAMES: usize = 120;

    /// Throws number `index` of the family seeded `seed`: sizes 0.1–2 m, 2–8 cells per side,
    /// both splits, cubes and balls, 50–300 m/s, 1–80 substeps, edges + volume or
    /// vertex–face + edges, hard or compliant. A compliant body is drawn as a material: a
    /// modulus `M` of 0.1–10 MPa for every family, its compliances those of its cells
    /// (edges and vertex–face `1/(M L)` m/N with `L` the cell's edge, volume `V/M` m⁵/N with
    /// `V` its tetrahedra's mean volume), so a fine mesh is as stiff as a coarse one. (A
    /// fixed compliance at any cell size is not one material: the matrix's 1e-9 m⁵/N on
    /// 2 cm cells is a bulk modulus of 20 Pa, a body that folds under a 2 m/s landing.)
    pub fn sample(seed: u64, index: u64) -> Throw {
        let mut r = Draws::stream(seed, index);
        let size = 0.1 * 20f32.powf(r.unit());
        let cells = 2 + r.below(7) as u32;
        let split = if r.below(2) == 0 {
            CellSplit::Five
        } else {
            CellSplit::Six
        };
        let shape = if r.below(3) == 0 {
            Shape::Ball(size / 2.0, cells.max(3), split)
        } else {
            Shape::Cube(size, cells, split)
        };
        let set = if r.below(2) == 0 {
            ConstraintSet::EdgesVolume
        } else {
            ConstraintSet::VertexFaceEdges
        };
        let soft = r.below(3) != 0;
        let modulus = 1e5 * 100f32.powf(r.unit());
        let cell = size / cells as f32;
        let tets = if split == CellSplit::Five { 5.0 } else { 6.0 };
        Throw {
            shape,
            config: Config { set, soft },
            length_scale: 1.0 / (modulus * cell) / Config::SOFT_LENGTH,
            volume_scale: cell.powi(3) / tets / modulus / Config::SOFT_VOLUME,
            speed: 50.0 + 250.0 * r.unit(),
            substeps: [1, 2, 5, 10, 20, 30, 40, 60, 80][r.below(9) as usize],
        }
    }

    /// The suite's scene of this throw on [`crate::Ground`].
    pub fn scene(&self) -> Scene {
        let mut s = Scene::new(self.shape.mesh());
        s.velocity = Vector3::new(0.0, -self.speed, 0.0);
        s.ground = true;
        s.settings.substeps = self.substeps;
        s.frames = Self::FRAMES;
        s.compliance_scale = self.length_scale;
        s.volume_compliance_scale = self.volume_scale / self.length_scale;
        s
    }

    /// Runs it on the suite's ground ([`run_scene`]: the settled volume is compared with
    /// the same body set down at rest).
    pub fn run_core(&self) -> Landing {
        let o = run_scene(&self.scene(), &self.config);
        Landing {
            inverted: o.final_inverted,
            volume_off: o.final_volume_error,
            rose: o.rebound.map_or(f32::INFINITY, |(_, rose)| rose),
            finite: o.finite && o.non_finite_resets == 0,
        }
    }

    /// Runs it coupled to a fixed rapier cuboid ground, default settings: the body thrown,
    /// then the same body released at rest, both settled; their volumes compared.
    pub fn run_coupled(&self) -> Result<Landing, String> {
        let thrown = self.coupled(self.speed)?;
        let rest = self.coupled(0.0)?;
        Ok(Landing {
            volume_off: (thrown.1 / rest.1 - 1.0).abs(),
            ..thrown.0
        })
    }

    /// One coupled run at `speed`: the landing (its volume unset) and the settled volume
    /// ratio.
    fn coupled(&self, speed: f32) -> Result<(Landing, f32), String> {
        let solver = SolverSettings {
            substeps: self.substeps,
            ..SolverSettings::default()
        };
        let mut s =
            CoupledWorld::new(solver, CouplingSettings::default()).map_err(|e| e.to_string())?;
        s.physics.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
            ColliderBuilder::cuboid(10.0, 0.5, 10.0),
        );
        let b = SoftBodyBuilder::new(self.shape.mesh())
            .density(1000.0)
            .velocity(Vector3::new(0.0, -speed, 0.0));
        let body = self
            .config
            .apply_scaled(b, self.length_scale, self.volume_scale)
            .build()
            .map_err(|e| e.to_string())?;
        let e = body.spawn(&mut s.soft);
        s.soft
            .insert_one(e, SoftCollider::default())
            .map_err(|e| e.to_string())?;
        let mut out = Landing {
            inverted: 0,
            volume_off: 0.0,
            rose: f32::NEG_INFINITY,
            finite: true,
        };
        let look = |s: &CoupledWorld| -> Result<(usize, f32, f32, bool), String> {
            let p = s.soft.get::<&Particles>(e).map_err(|e| e.to_string())?;
            let t = s.soft.get::<&Tetrahedra>(e).map_err(|e| e.to_string())?;
            let finite = p
                .positions()
                .iter()
                .chain(p.velocities())
                .all(|x| x.iter().all(|c| c.is_finite()));
            Ok((
                t.count_inverted(p.positions()),
                t.volume_ratio(p.positions()),
                p.linear_momentum().y / p.total_mass(),
                finite,
            ))
        };
        for _ in 0..Self::FRAMES {
            let stats = s.step().map_err(|e| e.to_string())?;
            let (_, _, up, finite) = look(&s)?;
            out.finite &= finite && stats.soft.non_finite_resets == 0;
            out.rose = out.rose.max(up);
        }
        out.inverted = look(&s)?.0;
        s.coupling.solver_mut().settings.damping = SETTLE_DAMPING;
        for _ in 0..SETTLE_FRAMES {
            s.step().map_err(|e| e.to_string())?;
        }
        let (inverted, volume, _, finite) = look(&s)?;
        out.inverted = out.inverted.max(inverted);
        out.finite &= finite;
        Ok((out, volume))
    }

    /// A one-line description.
    pub fn label(&self) -> String {
        let shape = match self.shape {
            Shape::Cube(size, cells, split) => format!("{size:.2} m cube of {cells}³ {split:?}"),
            Shape::Ball(r, cells, split) => format!("ball r {r:.2} m of {cells}³ {split:?}"),
        };
        let scale = if self.config.soft {
            format!(
                " (α ×{:.2} edges, ×{:.2} volume)",
                self.length_scale, self.volume_scale
            )
        } else {
            String::new()
        };
        format!(
            "{shape}, {}{scale}, {:.0} m/s, {} substeps",
            self.config.label(),
            self.speed,
            self.substeps
        )
    }
}
