//! [`Coupling`]: one call that advances a rapier scene and the soft bodies of a hecs world
//! by one frame.

use std::time::{Duration, Instant};

use hecs::World;
use rapier3d::dynamics::{
    CCDSolver, ImpulseJointSet, IntegrationParameters, IslandManager, MultibodyJointSet,
    RigidBodySet, SoftBodySet,
};
use rapier3d::geometry::{BroadPhaseBvh, ColliderSet, NarrowPhase};
use rapier3d::math::Vector;
use rapier3d::pipeline::{EventHandler, PhysicsHooks, PhysicsPipeline, PhysicsWorld, QueryFilter};
use tetpbd::{Solver, SolverSettings, SubstepHook};

use crate::convert::{to_glam, to_na};
use crate::error::CouplingError;
use crate::frame::Frame;
use crate::hook::CouplingHook;
use crate::material::SoftCollider;
use crate::report::{ContactReport, CouplingStats};
use crate::support::{apply_reaction, support_reaction};

/// Settings of a [`Coupling`].
#[derive(Clone, Debug, PartialEq)]
pub struct CouplingSettings {
    /// Extra distance around soft bodies and colliders when candidates are gathered once per
    /// frame, m (≥ 0). Contacts closer than the margin plus each body's motion over the frame
    /// are evaluated in every substep.
    pub margin: f32,
    /// Collision properties of soft bodies without a [`SoftCollider`] component.
    pub default_collider: SoftCollider,
    /// Largest speed at which the overlap of a soft body created inside a collider (in its
    /// first frame in the coupling) is pushed out, m/s (> 0). Such an overlap is resolved
    /// over several substeps and frames instead of in one substep, so separation does not turn
    /// into an explosion. Every other contact, impacts included, is resolved fully. A rigid
    /// body created inside a soft one is not covered.
    pub max_depenetration_speed: f32,
    /// Mass ratio from which a dynamic rigid body resting on a soft body counts as heavy
    /// (≥ 0; `f32::INFINITY` turns the pass off). A soft body on an immovable support
    /// (fixed or kinematic collider, supported rigid body, pinned particles) that carries a
    /// dynamic body whose generalized mass at a contact is at least this many times the
    /// mass of the particle (or the mean of the triangle's particles) it touches gets the
    /// *stacking pass* after the ordinary projections of every iteration: its constraints
    /// once more from the ground up with the supported particles held, then the heavy body's
    /// contacts with the soft surface frozen (shock propagation, `stacking` module docs).
    /// Without it, one iteration per substep lets a 1000 kg box crush a 1 kg slab.
    pub stacking_mass_ratio: f32,
    /// Whether every soft body on an immovable support gets the ground-up sweep of the
    /// stacking pass under its own weight too, not only under a heavy rigid load (default
    /// `false`). One Gauss–Seidel iteration per substep leaves a resting body sagging by a
    /// volume error that falls only as `h²`; the sweep carries the support's reaction to the
    /// top within the substep and cuts that error by 4× or more (1 m cubes of 4³–12³ cells at 10
    /// substeps: 0.025–0.117 % → 0.000–0.030 %, `docs/performance.md`), at 1.7–2.0× the
    /// cost per frame (edges + volume, SIMD lanes).
    /// Only the sweep runs; the frozen-surface contact pass and
    /// velocity pass stay reserved for heavy loads. The sweep is one-way (the support acts
    /// as infinitely heavy), so leave it off for bodies that are not meant to rest.
    pub self_weight_stacking: bool,
}

impl Default for CouplingSettings {
    fn default() -> Self {
        CouplingSettings {
            margin: 0.02,
            default_collider: SoftCollider::default(),
            max_depenetration_speed: 2.0,
            stacking_mass_ratio: 10.0,
            self_weight_stacking: false,
        }
    }
}

impl CouplingSettings {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), CouplingError> {
        if !(self.margin.is_finite() && self.margin >= 0.0) {
            return Err(CouplingError::BadSetting {
                name: "margin (m)",
                value: self.margin,
            });
        }
        if !(self.max_depenetration_speed.is_finite() && self.max_depenetration_speed > 0.0) {
            return Err(CouplingError::BadSetting {
                name: "max depenetration speed (m/s)",
                value: self.max_depenetration_speed,
            });
        }
        if self.stacking_mass_ratio.is_nan() || self.stacking_mass_ratio < 0.0 {
            return Err(CouplingError::BadSetting {
                name: "stacking mass ratio",
                value: self.stacking_mass_ratio,
            });
        }
        Ok(())
    }
}

/// The user's rapier state, borrowed for one coupled step. Every field is the argument of
/// the same name of [`PhysicsPipeline::step`]; the integrator keeps owning all of it.
pub struct RapierContext<'a> {
    /// The integrator's physics pipeline.
    pub pipeline: &'a mut PhysicsPipeline,
    /// Gravity, m/s² (also used for the soft bodies).
    pub gravity: Vector,
    /// Integration parameters; their `dt` is the frame time of the soft bodies too.
    pub integration_parameters: &'a IntegrationParameters,
    /// Islands.
    pub islands: &'a mut IslandManager,
    /// Broad phase; its BVH finds the colliders near each soft body.
    pub broad_phase: &'a mut BroadPhaseBvh,
    /// Narrow phase (its query dispatcher runs the queries).
    pub narrow_phase: &'a mut NarrowPhase,
    /// Rigid bodies.
    pub bodies: &'a mut RigidBodySet,
    /// Colliders.
    pub colliders: &'a mut ColliderSet,
    /// Impulse joints.
    pub impulse_joints: &'a mut ImpulseJointSet,
    /// Multibody joints.
    pub multibody_joints: &'a mut MultibodyJointSet,
    /// rapier's own soft bodies (independent of `tetpbd`'s).
    pub soft_bodies: &'a mut SoftBodySet,
    /// CCD solver.
    pub ccd_solver: &'a mut CCDSolver,
    /// Physics hooks.
    pub hooks: &'a dyn PhysicsHooks,
    /// Event handler.
    pub events: &'a dyn EventHandler,
}

impl<'a> RapierContext<'a> {
    /// Borrows every part of a rapier [`PhysicsWorld`], with no hooks and no events.
    pub fn from_physics_world(w: &'a mut PhysicsWorld) -> Self {
        RapierContext {
            pipeline: &mut w.physics_pipeline,
            gravity: w.gravity,
            integration_parameters: &w.integration_parameters,
            islands: &mut w.islands,
            broad_phase: &mut w.broad_phase,
            narrow_phase: &mut w.narrow_phase,
            bodies: &mut w.bodies,
            colliders: &mut w.colliders,
            impulse_joints: &mut w.impulse_joints,
            multibody_joints: &mut w.multibody_joints,
            soft_bodies: &mut w.soft_bodies,
            ccd_solver: &mut w.ccd_solver,
            hooks: &(),
            events: &(),
        }
    }
}

/// Two-way coupling of `tetpbd` soft bodies with a rapier scene.
///
/// # One frame: [`Coupling::step`]
///
/// 1. Every non-fixed rigid body's pose `P₀` is recorded, then **rapier steps first**
///    (`PhysicsPipeline::step` with the borrowed state): rigid–rigid contacts, joints,
///    gravity on rigid bodies, kinematic targets. Bodies end at `P₁`.
/// 2. **The soft substeps run** ([`tetpbd::Solver::step_with`], `dt` and gravity taken from
///    rapier). Once per frame, surface particles and rigid corners near each collider are
///    gathered from rapier's broad-phase BVH. In every substep each rigid body stands at the
///    interpolation of `P₀ → P₁` plus the offset the soft body pushed it by; contacts and
///    attachments are XPBD constraints projected after the soft body's own constraints, with
///    dynamic bodies taking part through their generalized inverse mass.
/// 3. The dynamic bodies the soft bodies touched get the soft reaction written back. A body
///    touching only soft bodies took part in the substeps with its generalized inverse mass
///    and gets its final pose and velocity (`P₁` plus offset; the velocity of the last
///    substep). A body that rapier's narrow phase reports in contact with other rigid
///    colliders is *supported*: inside the substeps it is infinitely heavy (it stays on its
///    `P₀ → P₁` path), and the summed soft impulse and its moment become a force and torque
///    added to the body for rapier's next step (and taken off again after it), which rapier's
///    solver applies in its substeps together with the rigid contacts, as it does gravity.
///    (A velocity change of the same impulse is an impact: a 100 kg soft body resting on a
///    0.125 kg box handed the box about 100 m/s per frame, which rapier's contacts did not
///    cancel cleanly.) Moving such a body by the offset would push it into its rigid
///    neighbours, which rapier only pushes out again over several frames (a soft body on a
///    stack of boxes would squash the stack).
///    A supported body that a soft body is attached to is *anchored* instead (`support`
///    module docs): an attachment is bilateral, and handing its reaction over a frame late
///    feeds back with the soft/rigid mass ratio as gain (a soft body attached to a light box
///    on the ground threw the box away within two frames, issue 3). An anchored body takes
///    part in the substeps with its generalized inverse mass like a body touched only by
///    soft bodies, and is written back the same way; rapier's contacts of the body, as they
///    stood after rapier's step, are kept inside the substeps as unilateral constraints
///    against immovable supports. While it stands on them and the soft load of the previous
///    substep lies in their friction cone it is *held* (shock propagation): no soft impulse
///    moves it, the supports take that load. Otherwise it moves with its mass, except that
///    an impulse pressing it into its supports does not move it while it stands on them and
///    moves it at most down to them otherwise, so the soft body cannot push it into them
///    and a body an attachment lifts is pushed back down by what it lifts.
///
/// Who integrates what: rapier integrates rigid bodies under gravity, rigid contacts and
/// joints; the coupling integrates the soft bodies and the *reaction* of soft contacts and
/// attachments on rigid bodies, which rapier sees at its next step as an already-moved pose
/// and changed velocity (bodies touched only by soft bodies, anchored bodies) or as a force
/// and torque acting over that step (supported bodies). Rapier steps first so that the soft bodies see where the rigid
/// bodies really are this frame (kinematic platforms carry soft bodies without a frame of
/// lag); the price is that a soft push on a rigid body reaches rigid–rigid contacts one
/// frame later.
///
/// Fast rigid bodies: rapier steps first, so a fast body may already stand beyond a thin
/// soft body when the soft substeps run. rapier still integrates it (to `P₁`); the coupling
/// gathers it from its swept motion `P₀ → P₁` rather than its end pose, and inside the
/// substeps its path is tested continuously against the soft surface (a particle's motion
/// relative to the collider cast as a ray; a rigid point that crossed a surface triangle's
/// plane caught where it crossed, in a pass before the particle contacts). A body the soft
/// contacts stop is written back where they stopped it (`sweep` module docs).
///
/// # Constraints in the substeps
///
/// Each iteration, after the soft body's own families: rigid points of moving bodies that
/// crossed a soft surface triangle within the substep, particle–collider contacts
/// (`contact` module docs: XPBD inequality, positional Coulomb friction with static and
/// dynamic coefficients), the other rigid points against soft surface triangles (`corner`
/// module docs), then attachments ([`crate::Attachments`]), then, for a soft body on an
/// immovable support that carries a much heavier dynamic body, the *stacking pass*: its own
/// constraints once more from the ground up with the supported particles held, and the
/// heavy body's contacts with the surface frozen (`stacking` module docs,
/// [`CouplingSettings::stacking_mass_ratio`]). After each substep's velocity update: the
/// separating velocity a stacking pass gave a heavy body is removed, the per-particle
/// separating velocity is removed, then restitution acts per (soft body,
/// collider) impact episode on the body's centre of mass (`restitution` module docs), a
/// rolling-resistance couple bounded by the substep's normal impulse opposes each body's
/// rotation relative to every collider it touches (`rolling` module docs,
/// [`crate::SoftCollider::rolling_resistance`]), and [`crate::DeformationDamping`] damps
/// deformation of bodies that carry it.
///
/// Why rolling resistance: sticking friction does no work on a rolling body and the
/// deformation damping leaves rigid rotation alone, so without it a rounded soft body rocks
/// on its belly for tens of seconds. Measured on the `asset_drop` blob (0.07 m cells, 10
/// substeps, deformation damping 5/s): with the coefficient 0, max |v| still swings up to
/// 0.065 m/s between 10 and 20 s, kinetic plus potential energy staying within ±0.04 J of
/// 20 J; once the rocking is stopped by hand (velocities halved every frame for 5 s) the
/// released body stays at rest (≤ 0.002 m/s), so the contacts do not pump energy into it,
/// they only fail to take it out. A stiffer body (40 substeps, or 4 iterations) still
/// reaches 0.01–0.02 m/s after 10 s. With a coefficient of 0.01 (what the example sets;
/// the default is 0, off: `rolling` module docs) max |v| is below 0.01 m/s from 4.4 s on
/// and below 0.0003 m/s after 5 s.
///
/// # Known limits
///
/// * Gauss–Seidel with one iteration per substep carries large mass ratios poorly. A heavy
///   rigid body on a soft body resting on an immovable support is carried by the stacking
///   pass (a 1000 kg box on a 1 kg slab at 10 substeps × 1 iteration,
///   `tests/collision_mass_ratio.rs`); one on a soft body that rests on nothing immovable
///   (on another dynamic body, or in free flight) is not. The heavy body rests on the soft
///   surface as on a frozen one (step 3 of the pass), so a very compliant soft body is
///   squashed less under it than a converged solve would squash it. On a slender soft
///   column (a 1000 kg box on a 1 kg column 0.6 m wide and 16 cells tall) the box is held
///   but rocks at up to 0.5 m/s after 3 s (`tests/issue_6_stacking_deep_bodies.rs`). The
///   pass costs about one more sweep over the whole soft body per iteration (SIMD lanes;
///   `tetpbd-bench --bin stacking`).
/// * A heavy soft body on a stack of supported rigid bodies keeps a small rocking motion
///   (a few cm/s), the one-frame lag between the soft load and rapier's answer.
/// * The soft load pressing an anchored body onto its supports does not reach rapier: it
///   neither tips the body over nor weighs on a dynamic support below it (only the body's
///   own motion into a support is handed to that support, as an impulse). Whether its
///   supports hold it is decided from the load of the previous substep, for the whole body
///   (one friction cone, the load's moment ignored: `support` module docs, Limits). A
///   100 kg soft cube attached with 1e-5 m/N to the top of a 0.125 kg box on the ground
///   stays on it with the cube moved by up to 3 mm, rocking the box up to 1 cm off its
///   place in 10 s (`support` module docs).
/// * The force and torque of a supported body's load stay in rapier's user force and torque
///   of the body until the coupling takes them off after rapier's next step; calling
///   `RigidBody::reset_forces`/`reset_torques` on it between two coupled steps leaves their
///   opposite behind.
/// * Rolling resistance is off by default and acts on the rigid fit of a whole body (its
///   centre of mass and mean angular velocity): a body with pinned particles is skipped,
///   a soft body lying over several colliders gets one couple per collider, and a dynamic
///   collider's share is estimated from its inverse inertia about the rotation axis only.
/// * Joints are only enforced by rapier: inside the substeps a jointed dynamic body moves
///   freely under soft reactions, and rapier pulls it back at the next step.
#[derive(Clone, Debug)]
pub struct Coupling {
    solver: Solver,
    settings: CouplingSettings,
    frame: Frame,
    reports: Vec<ContactReport>,
}

impl Coupling {
    /// A coupling with validated settings. The solver's `dt` and `gravity` are replaced by
    /// rapier's at every step.
    pub fn new(solver: SolverSettings, settings: CouplingSettings) -> Result<Self, CouplingError> {
        settings.validate()?;
        Ok(Coupling {
            solver: Solver::new(solver)?,
            settings,
            frame: Frame::default(),
            reports: Vec::new(),
        })
    }

    /// The soft-body solver.
    pub fn solver(&self) -> &Solver {
        &self.solver
    }

    /// The soft-body solver, for changing its settings (validated at the next step).
    pub fn solver_mut(&mut self) -> &mut Solver {
        &mut self.solver
    }

    /// Sets (or clears) the rayon pool running the soft solver's parallel passes (feature
    /// `parallel`; [`Solver::set_thread_pool`]): pass the `Arc` given to rapier's
    /// `PhysicsPipeline::set_thread_pool` to run both on the same threads. Without a pool the
    /// passes run in the caller's rayon context; [`tetpbd::ParallelSettings`] makes them serial.
    #[cfg(feature = "parallel")]
    pub fn set_thread_pool(&mut self, pool: Option<std::sync::Arc<tetpbd::rayon::ThreadPool>>) {
        self.solver.set_thread_pool(pool);
    }

    /// The coupling settings.
    pub fn settings(&self) -> &CouplingSettings {
        &self.settings
    }

    /// The coupling settings, for changing them (validated at the next step).
    pub fn settings_mut(&mut self) -> &mut CouplingSettings {
        &mut self.settings
    }

    /// The soft–rigid contacts of the last step.
    pub fn contacts(&self) -> &[ContactReport] {
        &self.reports
    }

    /// Advances rapier and every soft body of `world` by one frame (see the type docs for
    /// the order). Settings are validated before anything moves.
    pub fn step(
        &mut self,
        world: &mut World,
        ctx: RapierContext<'_>,
    ) -> Result<CouplingStats, CouplingError> {
        self.step_with(world, ctx, &mut ())
    }

    /// [`Coupling::step`] with another [`SubstepHook`] run inside the same substeps, after
    /// the coupling's constraints at every point (e.g. [`crate::SoftContacts`] for soft–soft
    /// contacts).
    pub fn step_with(
        &mut self,
        world: &mut World,
        mut ctx: RapierContext<'_>,
        extra: &mut dyn SubstepHook,
    ) -> Result<CouplingStats, CouplingError> {
        let start = Instant::now();
        self.settings.validate()?;
        let dt = ctx.integration_parameters.dt;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(CouplingError::BadRapierDt { value: dt });
        }
        let gravity = to_na(ctx.gravity);
        if !gravity.iter().all(|g| g.is_finite()) {
            return Err(CouplingError::NonFiniteGravity);
        }
        self.solver.settings.dt = dt;
        self.solver.settings.gravity = gravity;
        self.solver.settings.validate()?;

        self.frame.capture_start(ctx.bodies);
        let rigid_time = step_rapier(&mut ctx);
        // The soft load of the previous frame has acted over that step: take it off again.
        for (handle, force, torque) in self.frame.loads.drain(..) {
            if let Some(rb) = ctx.bodies.get_mut(handle) {
                rb.add_force(to_glam(&-force), false);
                rb.add_torque(to_glam(&-torque), false);
            }
        }

        self.frame.dt = dt;
        self.frame.substeps = self.solver.settings.substeps;
        self.frame.gravity = gravity.norm();
        self.frame.stats = CouplingStats::default();
        let soft = {
            let qp = ctx.broad_phase.as_query_pipeline(
                ctx.narrow_phase.query_dispatcher(),
                ctx.bodies,
                ctx.colliders,
                QueryFilter::default(),
            );
            let hook = CouplingHook {
                frame: &mut self.frame,
                qp,
                narrow_phase: &*ctx.narrow_phase,
                default_collider: self.settings.default_collider,
                margin: self.settings.margin,
                max_depenetration_speed: self.settings.max_depenetration_speed,
                stacking_mass_ratio: self.settings.stacking_mass_ratio,
                self_weight_stacking: self.settings.self_weight_stacking,
                order: self.solver.settings.order,
                kernel: self.solver.settings.kernel,
                reports: &mut self.reports,
            };
            self.solver.step_with(world, &mut (hook, extra))?
        };
        let mut stats = std::mem::take(&mut self.frame.stats);
        // Only the bodies that get a reaction are borrowed mutably: `get_mut` marks a body
        // as modified for rapier's next step.
        for b in self
            .frame
            .bodies
            .iter()
            .filter(|b| b.is_dynamic() && b.touched)
        {
            if let Some(rb) = ctx.bodies.get_mut(b.handle) {
                if b.write_back(rb) {
                    stats.bodies_written += 1;
                    if let Some((force, torque)) = b.load() {
                        self.frame.loads.push((b.handle, force, torque));
                    }
                } else {
                    stats.non_finite_bodies += 1;
                }
            }
        }
        // The reaction of the anchored bodies' pushes on their dynamic supports.
        for (handle, j, l) in self.frame.supports.iter().filter_map(support_reaction) {
            if let Some(rb) = ctx.bodies.get_mut(handle) {
                if !apply_reaction(rb, &j, &l) {
                    stats.non_finite_bodies += 1;
                }
            }
        }
        stats.soft = soft;
        stats.rigid_time = rigid_time;
        stats.total_time = start.elapsed();
        Ok(stats)
    }
}

/// rapier's step with the borrowed state; returns how long it took.
///
/// Never inlined, and it does work after rapier returns (the timing), so it is never a tail
/// call either: it stays a frame of its own in backtraces and profiles, with everything
/// below it rapier's (`PhysicsPipeline::step` itself is a thin wrapper that optimised builds
/// inline or turn into a jump, so its own name can be missing from a release backtrace).
/// `tests/no_alloc_coupled.rs` excuses rapier's allocations by this frame: keep it to the
/// call of rapier's step.
#[inline(never)]
fn step_rapier(ctx: &mut RapierContext<'_>) -> Duration {
    let t = Instant::now();
    ctx.pipeline.step(
        ctx.gravity,
        ctx.integration_parameters,
        ctx.islands,
        ctx.broad_phase,
        ctx.narrow_phase,
        ctx.bodies,
        ctx.colliders,
        ctx.impulse_joints,
        ctx.multibody_joints,
        ctx.soft_bodies,
        ctx.ccd_solver,
        ctx.hooks,
        ctx.events,
    );
    t.elapsed()
}
