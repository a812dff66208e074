//! [`Coupling`]: one call that advances a rapier scene and the soft bodies of a hecs world
//! by one frame.

use std::time::{Duration, Instant};

use hecs::World;
use nalgebra::Vector3;
use rapier3d::dynamics::{MultibodyJointSet, RigidBodySet};
use rapier3d::pipeline::QueryFilter;
use tetpbd::{Solver, SolverSettings, SubstepHook};

use crate::contacts::support::{apply_reaction, support_reaction, Reaction};
use crate::context::RapierContext;
use crate::convert::{to_glam, to_na};
use crate::error::CouplingError;
use crate::gather::Frame;
use crate::report::{ContactReport, CouplingStats};
use crate::settings::CouplingSettings;
use crate::soft_soft::settings::SoftContactSettings;
use crate::soft_soft::SoftContacts;
use crate::substep::{CoupledHooks, CouplingHook};

/// Two-way coupling of `tetpbd` soft bodies with a rapier scene.
///
/// # One frame: [`Coupling::step`]
///
/// 1. Every non-fixed rigid body's pose `P₀` is recorded, then **rapier steps first**
///    (`PhysicsPipeline::step` with the borrowed state): rigid–rigid contacts, joints,
///    gravity on rigid bodies, kinematic targets. Bodies end at `P₁`.
/// 2. **The soft substeps run** ([`tetpbd::Solver::step_frame`] over rapier's `dt`, under
///    rapier's gravity: "Time step and gravity" below). Once per frame, surface particles and rigid corners near each collider are
///    gathered from rapier's broad-phase BVH. In every substep each rigid body stands at the
///    interpolation of `P₀ → P₁` plus the offset the soft body pushed it by; contacts and
///    attachments are XPBD constraints projected after the soft body's own constraints, with
///    dynamic bodies taking part through their generalized inverse mass.
/// 3. The dynamic bodies the soft bodies touched get the soft reaction written back: they
///    took part in the substeps with their generalized inverse mass and get their final pose
///    and velocity (`P₁` plus offset; the velocity of the last substep). A body that rapier's
///    narrow phase reports in contact with other rigid colliders is *anchored* (`contacts::support`
///    module docs): rapier's contacts of the body, as they stood after rapier's step, are
///    kept inside the substeps as unilateral constraints against immovable supports. While
///    it stands on them and the soft load of the previous substep lies in their friction cone
///    it is *held* (shock propagation): no soft impulse moves it, the supports take that
///    load. Otherwise it moves with its mass, except that an impulse pressing it into its
///    supports does not move it while it stands on them and moves it at most down to them
///    otherwise, so the soft body cannot push it into them and a body an attachment lifts is
///    pushed back down by what it lifts. A body's rapier joints (impulse and multibody) are
///    constraints inside the substeps too (`joints` module docs).
///
///    Why (measurements: `docs/decisions/coupled-rigid-supports.md`): handing the soft
///    reaction on a body that rests on others to rapier as a force for its next step, with
///    the body infinitely heavy inside the substeps, feeds back a frame late with the
///    soft/rigid mass ratio as gain (a 125 kg soft cube on a 1 kg box on the ground threw
///    the box at about 370 m/s by the second frame); leaving a jointed body free inside the
///    substeps let a box carrying a 2 kg soft beam drift 0.2–0.6 m off its anchor in 3 s,
///    growing linearly. With the body's contacts and joints as constraints in the substeps
///    both hold (box moved ≤ 1 mm at 1:1–1000:1, anchors within 1 mm over 10 s at 10×) and
///    scenes without a touched dynamic body run none of it. Stepping rapier at the substep
///    rate instead keeps the hand-over explicit, a substep late: it still threw the box at
///    148 m/s and let the anchor drift 36 mm (2 kg beam) to 505 mm (20 kg) in 3 s, at 1.9–4.2×
///    the frame time of a resting cube.
///
/// Who integrates what: rapier integrates rigid bodies under gravity, rigid contacts and joints;
/// the coupling integrates the soft bodies and the *reaction* of soft contacts and attachments on
/// rigid bodies, which rapier sees at its next step as an already-moved pose and changed
/// velocity. Rapier steps first so that the soft bodies see where the rigid bodies really are
/// this frame (kinematic platforms carry soft bodies without a frame of lag); the price is that a
/// soft push on a rigid body reaches the rigid bodies it does not touch one frame later.
///
/// Fast rigid bodies: rapier steps first, so a fast body may already stand beyond a thin
/// soft body when the soft substeps run. rapier still integrates it (to `P₁`); the coupling
/// gathers it from its swept motion `P₀ → P₁` rather than its end pose, and inside the
/// substeps its path is tested continuously against the soft surface (a particle's motion
/// relative to the collider cast as a ray; a rigid point that crossed a surface triangle's
/// plane caught where it crossed, in a pass before the particle contacts). A body the soft
/// contacts stop is written back where they stopped it (`ccd` module docs).
///
/// # Time step and gravity
///
/// A coupled scene has one clock and one gravity, rapier's: `IntegrationParameters::dt` and
/// the gravity of [`RapierContext`]. rapier steps first with them, so the soft bodies must
/// advance over the same interval under the same field; the coupling hands both to the
/// solver for the frame ([`tetpbd::Solver::step_frame`]) and never writes the solver's
/// settings. The solver's own [`SolverSettings::dt`] and [`SolverSettings::gravity`] are not
/// used: left at their defaults, or equal to rapier's, they are accepted; any other value
/// says the integrator expects it to act and is rejected before anything moves
/// ([`CouplingError::SolverDtDisagrees`], [`CouplingError::SolverGravityDisagrees`]). The
/// substep count, iterations and every other solver setting are the solver's; hooks read the
/// frame's `dt`, gravity and substep from their [`tetpbd::SubstepContext`].
///
/// # Constraints in the substeps
///
/// Each iteration, after the soft body's own families: rigid points of moving bodies that
/// crossed a soft surface triangle within the substep, particle–collider contacts
/// (`contacts::particle` module docs: XPBD inequality, positional Coulomb friction with static and
/// dynamic coefficients), the other rigid points against soft surface triangles (`contacts::corner`
/// module docs), then attachments ([`crate::Attachments`]), then, for a soft body on an
/// immovable support that carries a much heavier dynamic body, the *stacking pass*: its own
/// constraints once more from the ground up with the supported particles held, and the
/// heavy body's contacts with the surface frozen (`heavy_loads` module docs,
/// [`crate::StackingSettings::mass_ratio`]). After each substep's velocity update (where
/// the solver also damps the deformation of bodies with a [`tetpbd::DeformationDamping`]): the
/// separating velocity a stacking pass gave a heavy body is removed, the per-particle
/// separating velocity is removed, then restitution acts per (soft body,
/// collider) impact episode on the body's centre of mass (`response::restitution` module docs), a
/// rolling-resistance couple bounded by the substep's normal impulse opposes each body's
/// rotation relative to every collider it touches (`response::rolling` module docs,
/// [`crate::SoftCollider::rolling_resistance`]).
///
/// Why rolling resistance: sticking friction does no work on a rolling body and the
/// deformation damping leaves rigid rotation alone. On immovable colliders the passivity of
/// the contacts takes a rocking body's energy out (`response::passivity` module docs: a
/// rounded soft body rests on the ground at default settings,
/// `tests/rolling_blob_comes_to_rest.rs` at the workspace root); on a dynamic or moving
/// collider nothing else does, and a small coefficient (0.01) brings a rolling body to rest
/// within seconds. The default is 0, off (`response::rolling` module docs).
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
///   but keeps rocking (`tests/heavy_box_on_deep_soft_bodies.rs`). The
///   pass costs about one more sweep over the whole soft body per iteration (SIMD lanes;
///   `tetpbd-bench --bin stacking`).
/// * The soft load pressing an anchored body onto its supports does not reach rapier: it
///   neither tips the body over nor weighs on a dynamic support below it (only the body's
///   own motion into a support is handed to that support, as a force for rapier's next
///   step). Whether its supports hold it is decided from the load of the previous substep,
///   for the whole body (one friction cone, the load's moment ignored: `contacts::support`
///   module docs, Limits). A 100 kg soft cube attached with 1e-5 m/N to the top of a
///   0.125 kg box on the ground stays on it with the cube moved by up to 3 mm, rocking the
///   box up to 1 cm off its place in 10 s (`contacts::support` module docs).
/// * Rolling resistance is off by default and acts on the rigid fit of a whole body (its
///   centre of mass and mean angular velocity): a body with pinned particles is skipped,
///   a soft body lying over several colliders gets one couple per collider, and a dynamic
///   collider's share is estimated from its inverse inertia about the rotation axis only.
/// * Joints inside the substeps: their limits and motors, and a single locked angular axis,
///   are left to rapier's step; the joint reaction on a body that does not take part in the
///   substeps (a chain's far end) reaches it through rapier a frame later.
/// * Anchoring at extreme ratios (`tests/loads.rs`): soft cubes 100–1000× heavier than the
///   light boxes they rest on come to rest at 5–40 substeps (`contacts::support` module docs,
///   *resting reach*), except that a cube overhanging a box of half its side keeps rattling
///   at 0.08–2 m/s at 5 substeps and a tower of three such boxes under a 1000:1 cube topples
///   at 40 substeps (a held body does not tip). A rigid box 1000× lighter than the slab under it (1 g on 1 kg) is pushed 7 cm and turned
///   10°.
/// * Fast impacts ([`tetpbd::ImpactReach`]): of 448 shots (balls of 0.1 and 0.2 m, boxes of 0.08
///   and 0.2 m, 1 kg, at 50–300 m/s onto slabs of 1–4 cells, seven aim points), 12 still fail:
///   the 0.2 m box at 200–300 m/s (through the slab or throwing it) and hits within 0.1 m of
///   the slab's edge.
/// * Spinning impacts: a box spinning at 10–25 rad/s that hits a hard soft pad as wide as
///   itself at 20 substeps or more gains energy in the impact's frame (a 4 kg box at 15 m/s
///   and 23 rad/s on a 0.37 m pad: 567 → 840–1060 J, the pad's particles at up to 45 m/s;
///   `docs/decisions/support-overlaps-leave-at-the-depenetration-speed.md`).
#[derive(Clone, Debug)]
pub struct Coupling {
    solver: Solver,
    settings: CouplingSettings,
    frame: Frame,
    reports: Vec<ContactReport>,
    soft_contacts: SoftContacts,
    /// Scratch: the attached particles of the soft bodies (sorted `(body, particle)`), which
    /// untangling keeps in place.
    held: Vec<(hecs::Entity, u32)>,
}

impl Coupling {
    /// A coupling with validated settings. The solver's `dt` and `gravity` are not used: the
    /// frame's are rapier's ("Time step and gravity" in the type docs).
    pub fn new(solver: SolverSettings, settings: CouplingSettings) -> Result<Self, CouplingError> {
        settings.validate()?;
        Ok(Coupling {
            solver: Solver::new(solver)?,
            settings,
            frame: Frame::default(),
            reports: Vec::new(),
            soft_contacts: SoftContacts::new(SoftContactSettings::default())?,
            held: Vec::new(),
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

    /// What the last step's tearing did ([`tetpbd::Solver::tear_events`]); the coupling's
    /// components already follow the pieces ([`crate::follow_pieces`]).
    pub fn tear_events(&self) -> &[tetpbd::TearEvent] {
        self.solver.tear_events()
    }

    /// The soft–rigid contacts of the last step; a sleeping soft body's are those it fell
    /// asleep on.
    pub fn contacts(&self) -> &[ContactReport] {
        &self.reports
    }

    /// Advances rapier and every soft body of `world` by one frame (see the type docs for
    /// the order). Settings, rapier's `dt` and gravity, their agreement with the solver's
    /// ("Time step and gravity" in the type docs) and the soft bodies' surfaces are checked
    /// before anything moves ([`CouplingError::SurfaceOutOfRange`]); a soft body without a
    /// `Surface` is counted in [`CouplingStats::bodies_without_surface`].
    pub fn step(
        &mut self,
        world: &mut World,
        ctx: RapierContext<'_>,
    ) -> Result<CouplingStats, CouplingError> {
        self.step_with(world, ctx, &mut ())
    }

    /// [`Coupling::step`] with another [`SubstepHook`] of the integrator's run inside the
    /// same substeps, after the coupling's work (soft–rigid, then soft–soft contacts) at
    /// every point.
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
        check_solver_frame(&self.solver.settings, dt, gravity)?;
        self.solver.settings.validate_frame(dt, gravity)?;
        let without_surface = crate::validate::check_soft_bodies(world)?;

        self.frame.capture_start(ctx.bodies);
        self.frame.rigid_slop = ctx.integration_parameters.allowed_linear_error();
        let rigid_time = step_rapier(&mut ctx);
        // The soft load of the previous frame has acted over that step: take it off again.
        for (handle, force, torque) in self.frame.loads.drain(..) {
            if let Some(rb) = ctx.bodies.get_mut(handle) {
                rb.add_force(to_glam(&-force), false);
                rb.add_torque(to_glam(&-torque), false);
            }
        }

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
                impulse_joints: &*ctx.impulse_joints,
                multibody_joints: &*ctx.multibody_joints,
                default_collider: self.settings.default_collider,
                margin: self.settings.margin,
                soft_margin: self.settings.soft_contacts.map(|s| s.margin),
                max_depenetration_speed: self.settings.max_depenetration_speed,
                stacking_mass_ratio: self.settings.stacking_mass_ratio(),
                self_weight_stacking: self.settings.stacking.is_some_and(|s| s.self_weight),
                reports: &mut self.reports,
            };
            let soft = match self.settings.soft_contacts {
                Some(s) => {
                    self.soft_contacts.set_settings(s)?;
                    let default = self.settings.default_collider;
                    self.soft_contacts.set_default_collider(default);
                    let ratio = self.settings.stacking_mass_ratio();
                    self.soft_contacts.set_carrying_ratio(ratio);
                    Some(&mut self.soft_contacts)
                }
                None => None,
            };
            let mut hooks = CoupledHooks {
                rigid: hook,
                soft,
                extra,
            };
            let out = self.solver.step_frame(world, dt, gravity, &mut hooks);
            // The coupling's components follow the pieces of the step's tears (also when
            // the step reports a restored particle: the frame ran to its end).
            for event in self.solver.tear_events() {
                crate::pieces::follow_pieces(world, event);
            }
            let mut out = out?;
            // The step leaves bodies touched by a hook's contacts tangled; here they are
            // untangled with the ground below them in mind (`tetpbd::Untangle`), their
            // attached particles kept in place.
            self.held.clear();
            for (e, a) in world.query_mut::<(hecs::Entity, &crate::Attachments)>() {
                self.held
                    .extend(a.items().iter().map(|item| (e, item.particle)));
            }
            self.held.sort_unstable();
            out.bodies_untangled +=
                tetpbd::systems::untangle_touched_bodies(world, dt, gravity, &self.held);
            out
        };
        let mut stats = std::mem::take(&mut self.frame.stats);
        self.write_back(world, (ctx.bodies, ctx.multibody_joints), &mut stats);
        let (waking, proxies) = (&mut self.frame.waking, &self.frame.bodies);
        waking.remember_rest(proxies, ctx.bodies, world);
        stats.soft = soft;
        stats.bodies_without_surface = without_surface;
        if self.settings.soft_contacts.is_some() {
            stats.soft_contacts = *self.soft_contacts.stats();
        }
        stats.rigid_time = rigid_time;
        stats.total_time = start.elapsed();
        Ok(stats)
    }

    /// Hands the soft reaction to the rapier bodies the soft bodies touched (module docs of
    /// [`Coupling`], step 3), and the anchored bodies' reaction to their dynamic supports.
    /// A multibody link gets it through its multibody (`rigid::body::link` module docs).
    fn write_back(
        &mut self,
        world: &World,
        (bodies, multibodies): (&mut RigidBodySet, &mut MultibodyJointSet),
        stats: &mut CouplingStats,
    ) {
        // Only the bodies that get a reaction are borrowed mutably: `get_mut` marks a body
        // as modified for rapier's next step.
        for (i, b) in self.frame.bodies.iter().enumerate() {
            if !(b.is_dynamic() && b.touched) {
                continue;
            }
            let asleep = crate::sleeping::soft_asleep(&self.frame.waking, i, world);
            let scratch = &mut self.frame.generalized;
            if let Some(written) = b.write_back_link(bodies, multibodies, scratch) {
                if !written {
                    stats.non_finite_bodies += 1;
                } else if let Some(rb) = bodies.get_mut(b.handle) {
                    stats.bodies_written += 1;
                    if asleep {
                        rb.sleep();
                    } else {
                        rb.wake_up(true);
                    }
                }
                continue;
            }
            if let Some(rb) = bodies.get_mut(b.handle) {
                if b.write_back(rb, asleep) {
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
            if let Some(rb) = bodies.get_mut(handle) {
                match apply_reaction(rb, &j, &l, self.frame.dt) {
                    Reaction::Added(force, torque) => {
                        self.frame.loads.push((handle, force, torque));
                    }
                    Reaction::Asleep => {}
                    Reaction::NonFinite => stats.non_finite_bodies += 1,
                }
            }
        }
    }
}

/// Checks that the solver's own `dt` and `gravity`, which a coupled step does not use (it
/// steps the soft bodies over rapier's `dt` under rapier's gravity), were not set to other
/// values than rapier's: each must be at its default ([`SolverSettings::default`]) or equal
/// rapier's (exactly).
fn check_solver_frame(
    solver: &SolverSettings,
    dt: f32,
    gravity: Vector3<f32>,
) -> Result<(), CouplingError> {
    let defaults = SolverSettings::default();
    if solver.dt != dt && solver.dt != defaults.dt {
        return Err(CouplingError::SolverDtDisagrees {
            solver: solver.dt,
            rapier: dt,
        });
    }
    if solver.gravity != gravity && solver.gravity != defaults.gravity {
        return Err(CouplingError::SolverGravityDisagrees {
            solver: solver.gravity,
            rapier: gravity,
        });
    }
    Ok(())
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
