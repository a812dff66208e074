//! [`SoftContacts`]: soft–soft and self collision of `tetpbd` bodies, as a
//! [`tetpbd::SubstepHook`].
//!
//! # The constraint
//!
//! A surface particle `p` of one body against a surface triangle `(a, b, c)` of another body
//! (or of the same body, for bodies with the [`SelfCollision`] component), with the
//! triangle's outward unit normal `n` and thickness `δ` (the seed's vertex–face constraint
//! with a thickness; `δ`, the friction coefficients and the restitution come from the two
//! bodies' [`crate::SoftCollider`]s, combined as its docs say):
//!
//! ```text
//! C  = (p − q)·n − δ ≥ 0,   q = β_a a + β_b b + β_c c   (β: barycentric point of p on the triangle)
//! ∇p C = n,   ∇a C = −β_a n,   ∇b C = −β_b n,   ∇c C = −β_c n   (n held fixed)
//! Δλ = (−C − α̃λ) / (w_p + β_a² w_a + β_b² w_b + β_c² w_c + α̃),   λ ≥ 0
//! ```
//!
//! so the correction is spread barycentrically over the triangle's three particles and both
//! bodies move according to their inverse masses. Only violated constraints are projected
//! (an inequality), every iteration of every substep. Friction is positional (Müller et al.
//! 2020): the relative tangential displacement of `p` against `q` over the substep is removed
//! while the tangential multiplier stays under `μ_s λ`, otherwise only up to `μ_d λ`. After
//! each substep the separating normal velocity a contact's projection created is removed, a
//! contact that let go in the substep keeps its particle at the relative normal velocity it
//! had while held (the correction it held back is not released as speed; `velocity_pass`),
//! and the separating velocity of the two bodies' centres of mass is capped at `e` times
//! their approach speed (`restitution` module; `e` = 0 by default), so impacts do not turn
//! into bounces.
//!
//! # Candidates (once per frame)
//!
//! Bodies are paired by a sweep over their AABBs (never all pairs). Each body keeps a parry
//! BVH over its surface triangles, refitted every frame. Each particle has a *motion bound*
//! `m = |v| dt + ½ a_max dt²` (`a_max` = [`SoftContactSettings::max_acceleration`]). Bodies
//! whose [`crate::SoftCollider`] is disabled, and pairs whose collision groups do not accept
//! each other, are left out. A particle–triangle pair is a candidate when the particle's box grown by `m + margin + δ`
//! meets the triangle's box grown by its vertices' bounds. A candidate is kept only when the
//! particle starts the frame on the outer side of the triangle's plane (`d₀ ≥ −δ`). It is
//! active when the particle is less than the frame's relative motion behind the plane and
//! either was over the triangle (inside its prism) at the substep start and still is, or its
//! path over the substep crossed the plane inside the triangle. That is what catches a fast
//! particle: one that crosses a thin sheet within a substep is still within `m` of the face
//! it came from and is pushed back to it, while a particle resting under the sheet is never
//! pulled through it, and one sliding past a face's edge beside it does not snag on it.
//!
//! A candidate that is not yet active in the substep is also left alone while its particle
//! is behind the triangle's plane but less deep behind another triangle of the same body
//! across a crease (normals 45° to 135° apart: a side face), whose prism it is in, and at
//! most `δ` behind that one: the particle is grazing the side face (two cubes falling past
//! each other face to face, edges flush), not entering through the face it passes. Without
//! this, a landed cube's few millimetres of bulge put its top-edge particles inside the
//! falling neighbour's bottom face, which stopped the neighbour on the edge and kicked it
//! sideways. The side face takes the particle over from the next substep on, once
//! the particle was inside its prism at the substep start.
//!
//! # Deep overlap and the speed bound
//!
//! Every contact's target height is reached at a bounded rate: with `d_prev` the
//! particle's signed distance to the triangle's plane at the substep start,
//!
//! ```text
//! target = max( min(0, d_prev + S h), min(δ, d_prev + S_skin h) )
//! ```
//!
//! `S` = [`SoftContactSettings::max_separation_speed`], `S_skin` =
//! [`SoftContactSettings::skin_speed`]. A particle arriving from outside (`d_prev ≥ δ`) goes
//! straight back to `δ` (that is what stops a fast particle); one found below the surface
//! comes out at no more than `S`; one inside the skin `[0, δ)` (bodies created touching)
//! creeps out at `S_skin`, so touching bodies do not pop apart.
//!
//! A surface particle that starts the frame strictly inside a tetrahedron of another body
//! is *deep*: it is not projected (pushing only the surface particles of the overlap region
//! deforms both bodies, and their elasticity turns that into an explosion). Instead the two
//! bodies are walked apart **rigidly** along the direction of least separation, by at most
//! `S h` per substep, with no velocity added and the approaching relative velocity along that
//! direction removed (see `soft_separation`).
//!
//! **Bound:** bodies created inside each other separate at a relative speed of at most `S`
//! (m/s; default 2), i.e. by `S·dt` per frame, and the separation itself adds no particle
//! velocity. Each substep in which a pair's separation, or a contact below the surface, was
//! limited by `S` counts as one clamp in [`SoftContactStats::clamps`].
//!
//! # Limits
//!
//! Vertex–triangle only: two edges crossing without a vertex passing a face are not
//! detected. A sheet must be thicker than `δ`. Self collision excludes the triangles of the
//! particle's tetrahedron neighbours, and has no deep-overlap recovery (a body already
//! folded through itself stays so). Deep-overlap separation is rigid: a body pair with a
//! pinned body on each side is not separated.

pub(crate) mod body;
pub(crate) mod bvh;
pub(crate) mod carrying;
pub(crate) mod gather;
pub(crate) mod project;
pub(crate) mod restitution;
pub(crate) mod separation;
pub(crate) mod settings;
pub(crate) mod velocity_pass;

use hecs::World;
use tetpbd::{FrameContext, SubstepContext, SubstepHook};

use crate::error::CouplingError;
use crate::soft_collider::SoftCollider;
use crate::soft_soft::carrying::Carrying;
use crate::soft_soft::gather::{ContactFrame, Gather};
use crate::soft_soft::restitution::BodyRestitution;
use crate::soft_soft::separation::Separation;
#[cfg(doc)]
use settings::SelfCollision;
use settings::{SoftContactSettings, SoftContactStats};

/// Soft–soft and self collision of the `tetpbd` bodies of a world, run inside the soft
/// solver's substeps (see the module docs of `soft_soft` for the constraint, the
/// candidates and the deep-overlap bound). Each body collides with its
/// [`SoftCollider`] component, or [`SoftContacts::default_collider`] without one.
///
/// A [`crate::Coupling`] runs one itself ([`crate::CouplingSettings::soft_contacts`]); this
/// type is the same contacts as a hook of its own, for soft bodies on a bare
/// [`tetpbd::Solver`]:
///
/// ```
/// use tetpbd::{generators, Solver, SolverSettings, SoftBodyBuilder};
/// use tetpbd_rapier::{SoftContactSettings, SoftContacts};
///
/// let mut world = hecs::World::new();
/// let mesh = generators::box_grid(nalgebra::Vector3::repeat(0.5), [2, 2, 2], generators::CellSplit::Six)?;
/// for y in [0.0, 0.51] {
///     SoftBodyBuilder::new(mesh.clone())
///         .edges(0.0)
///         .volume(0.0)
///         .translation(nalgebra::Vector3::new(0.0, y, 0.0))
///         .build()?
///         .spawn(&mut world);
/// }
/// let mut solver = Solver::new(SolverSettings::default())?;
/// let mut contacts = SoftContacts::new(SoftContactSettings::default())?;
/// solver.step_with(&mut world, &mut contacts)?;
/// assert_eq!(contacts.stats().body_pairs, 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone)]
pub struct SoftContacts {
    settings: SoftContactSettings,
    default_collider: SoftCollider,
    gather: Gather,
    frame: ContactFrame,
    separation: Separation,
    restitution: BodyRestitution,
    stats: SoftContactStats,
    /// Scratch of the waking pass (`sleeping` module docs).
    waking: crate::sleeping::Waking,
    /// Which bodies rest on a support, for carried contacts (`carrying` module docs).
    carrying: Carrying,
}

impl SoftContacts {
    /// Soft contacts with validated settings.
    pub fn new(settings: SoftContactSettings) -> Result<Self, CouplingError> {
        settings.validate()?;
        Ok(SoftContacts {
            settings,
            default_collider: SoftCollider::default(),
            gather: Gather::default(),
            frame: ContactFrame::default(),
            separation: Separation::default(),
            waking: crate::sleeping::Waking::default(),
            restitution: BodyRestitution::default(),
            stats: SoftContactStats::default(),
            carrying: Carrying::default(),
        })
    }

    /// The settings.
    pub fn settings(&self) -> &SoftContactSettings {
        &self.settings
    }

    /// Replaces the settings after validating them (from the next frame on).
    pub fn set_settings(&mut self, settings: SoftContactSettings) -> Result<(), CouplingError> {
        settings.validate()?;
        self.settings = settings;
        Ok(())
    }

    /// Statistics of the last frame.
    pub fn stats(&self) -> &SoftContactStats {
        &self.stats
    }

    /// Sets the mass ratio from which a soft body resting on an immovable support holds a
    /// heavier one above it still (`f32::INFINITY`: never; `carrying` module docs).
    pub(crate) fn set_carrying_ratio(&mut self, ratio: f32) {
        self.carrying.ratio = ratio;
    }

    /// The soft bodies touching an immovable support in the current substep (entity bits,
    /// any order), before [`SubstepHook::project`].
    pub(crate) fn set_supported(&mut self, supported: impl Iterator<Item = u64>) {
        let list = &mut self.carrying.supported;
        list.clear();
        list.extend(supported);
        list.sort_unstable();
        list.dedup();
    }

    /// The collision properties of bodies without a [`SoftCollider`] component
    /// ([`SoftCollider::default`] unless set).
    pub fn default_collider(&self) -> &SoftCollider {
        &self.default_collider
    }

    /// Sets the collision properties of bodies without a [`SoftCollider`] component (from
    /// the next frame on).
    pub fn set_default_collider(&mut self, collider: SoftCollider) {
        self.default_collider = collider;
    }
}

impl std::fmt::Debug for SoftContacts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SoftContacts")
            .field("settings", &self.settings)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl SubstepHook for SoftContacts {
    fn begin_frame(&mut self, world: &mut World, frame: FrameContext) {
        self.stats = SoftContactStats::default();
        let margin = self.settings.margin;
        self.waking
            .run_soft(world, &self.default_collider, margin, frame.dt());
        self.gather.run(
            world,
            frame.dt(),
            (&self.settings, &self.default_collider),
            &mut self.frame,
            &mut self.separation,
            &mut self.stats,
        );
    }

    fn begin_substep(&mut self, world: &mut World, substep: SubstepContext) {
        self.frame.begin_substep(world, &self.gather);
        self.restitution.begin_substep(world, &self.gather);
        self.separation.apply(
            world,
            &self.gather.bodies,
            &self.settings,
            substep.h(),
            &mut self.stats,
        );
    }

    fn project(&mut self, world: &mut World, substep: SubstepContext) {
        let h = substep.h();
        let up = -substep.gravity();
        self.carrying.up = up
            .try_normalize(1e-6)
            .unwrap_or_else(nalgebra::Vector3::zeros);
        self.frame.project(
            world,
            (&self.gather, &mut self.carrying),
            &self.settings,
            h,
            &mut self.stats,
        );
    }

    fn end_substep(&mut self, world: &mut World, substep: SubstepContext) {
        self.separation
            .remove_velocity(world, &self.gather.bodies, substep.h());
        self.frame
            .velocity_pass(world, &self.gather, self.settings.max_separation_speed);
        let a_max = self.settings.max_acceleration;
        self.restitution.apply(
            world,
            &self.gather,
            &self.frame,
            (a_max, &substep.gravity()),
            substep.h(),
        );
    }

    fn end_frame(&mut self, world: &mut World, _frame: FrameContext) {
        self.frame.finish(world, &self.gather, &mut self.stats);
    }

    /// Bodies whose bounds overlap within the margin are one island (`sleeping` module
    /// docs).
    fn touching(&mut self, _world: &mut World, touching: &mut tetpbd::Touching) {
        let bodies = &self.gather.bodies;
        touching.pairs.extend(
            self.gather
                .pairs
                .iter()
                .map(|&(a, b)| (bodies[a].entity, bodies[b].entity)),
        );
    }
}
