//! Rigid supports of an *anchored* body inside the soft substeps.
//!
//! A dynamic body that rapier reports in contact with other rigid colliders is normally
//! *supported*: infinitely heavy inside the substeps, its summed soft reaction handed to
//! rapier as a force for its next step (`rigid::body` module docs). That is an explicit coupling
//! with a frame of lag, stable for contacts, which mostly press a body onto its supports. An
//! attachment is two-way and bilateral: rapier moves the body by the reaction, the body drags
//! the attached soft body along, whose reaction moves the body further. The gain of that loop
//! is the mass ratio soft/rigid, so a light body holding a heavy soft body would diverge
//! within a few frames.
//!
//! A supported body that carries an attachment is therefore *anchored*: it takes part in the
//! substeps with its generalized inverse mass like a body touched only by soft bodies
//! (implicit, two-way, the same projections), and rapier's contacts of the body, as they
//! stood after rapier's step, are kept inside the substeps as unilateral XPBD constraints
//! against an immovable other side: `C = n·(x − y) − min(0, C₁) ≥ 0` for the body's material
//! point `x` of each contact point, `y` the other collider's point and `n` the contact normal
//! towards the body; `C₁` is the value at the body's pose on rapier's path (below), so an
//! overlap rapier left is neither pushed out nor deepened here. The body is then written
//! back like any body that took part (pose and velocity), without being pushed into its
//! supports.
//!
//! *Overlaps at the frame's start.* The body's path `P₀ → P₁` starts where the previous frame
//! left it, which may overlap a support by more than rapier's end pose does (a fast-spinning
//! box written back with a corner in the ground; rapier lifts it over its step). Pushing that
//! overlap out in one substep of `h` seconds moves the body by it and, since its velocity is
//! its motion over the substep, throws it at `overlap / h` — at 80 substeps a 3 cm overlap
//! threw a 4.6 kg cube at 81 m/s. So, as the particle contacts do (`contacts::particle` module
//! docs), an overlap found at a support's first substep, at the body's pose at that
//! substep's start, is tolerated less the depenetration push `max_push`
//! ([`crate::CouplingSettings::max_depenetration_speed`] times `h`): the constraint becomes
//! `C + s ≥ 0` with the allowance `s = max(0, −C₀ − max_push)`, which shrinks by `max_push`
//! every substep. The body leaves the overlap along rapier's path and at most at the
//! depenetration speed beyond it; an approach within the substep is still stopped in full.
//!
//! Gauss–Seidel alone would let a heavy soft body sink into a light anchored body: each soft
//! projection moves mostly the body, the support moves it back, and the soft penetration
//! stays. So, as in shock propagation, an anchored body is *held* by its supports in a
//! substep when it rests on them (its clearance, the smallest support constraint value, at
//! most its *resting reach*, below) and the soft positional impulses on it in the previous
//! substep, summed, lie
//! in their friction cone: pressing it into them (along their mean normal), their
//! tangential part at most μ times their normal part (μ the smallest coefficient of its
//! supports). A held body keeps its offset of the previous substep (it follows rapier's
//! path only) and no soft impulse moves it: the soft side takes the whole correction. Its
//! supports would take that load (a fixed ground cancels it), so it is not handed to rapier
//! either: a soft load handed to a light body a frame late is what made it unstable. The
//! cost: such a load neither tips the body nor weighs on a dynamic support below it.
//!
//! *Only a body at rest is immovable.* Held, or standing under a pressing impulse, a body
//! is as heavy as the ground for the soft side. That is right for a box lying still and
//! wrong for one that moves: squeezed out from under a heavy soft body or carried along
//! rapier's path, a light box left immovable pushed the soft body away at its own speed with
//! infinite mass (random scenes: a 47.5 kg body thrown at a 0.47 kg box on the ground at
//! 58.6 m/s left faster than it came, +38 kJ; a 1138 kg body tumbling over a 4.6 kg box
//! gained 16 kJ). So a body is held only while no point near it (within the farthest of its
//! support points from its centre of mass) moves by more than its resting reach in the
//! substep, and a pressing impulse leaves a standing body in place only while the body's
//! point there does not come at the soft side faster than that.
//!
//! *Resting reach.* A body resting on its supports does not sit exactly on them at a
//! substep's start: rapier's path, the offset kept from the previous substep and the support
//! projections leave it micrometres above or below, and rapier's own solver lets a stack
//! move by up to its allowed linear error (its contact slop, 1 mm at its defaults). So a body
//! rests on its supports while its clearance is within the larger of that slop and what its
//! smooth acceleration `a_s` (gravity, user force) moves it in one substep, `a_s h²` (27 µm
//! under `g` at 60 Hz and 10 substeps). With a fixed 1 µm instead, a 1 kg box under a 1000 kg
//! soft cube started every other substep 1.2 µm above the ground, was not held there, and took
//! the cube's impulses with its own 1 kg: it was held and free by turns, the cube rattled at
//! 0.16–0.5 m/s and the box walked and turned by up to 13 cm and 8° in 3 s; on a stack of
//! light boxes at 20–40 substeps the top box was thrown (measurements and the alternatives:
//! `docs/decisions/resting-reach.md`). A body lifted off its supports is not held however
//! close it is: the load must press it into them.
//!
//! A body that is not held moves with its generalized inverse mass under every soft impulse, except
//! that one pressing it into its supports (more than 60° against their mean normal) does not move
//! it while it stands on them, and moves it at most down to them otherwise (its clearance, measured
//! at every iteration and followed by its centre of mass). The soft load is then shared as Newton's
//! third law has it: a body that an attachment lifts off its supports is pushed back down by the
//! soft body it lifts, rather than staying immovable against it while the attachment moves it up.
//! (Never moving the body under a pressing impulse, whatever its pose, would let a light box
//! holding a heavy soft cube by a compliant attachment do work on the cube each time the spring
//! lifts it.) The friction cone decides from the load alone, whether the soft side moved: a soft
//! body pulling an anchored box sideways harder than its supports' friction can hold moves it, and
//! one pulling it up off them lifts it.
//!
//! The reaction of a dynamic support to the body's own motion into it is summed over the
//! frame and handed to it as a force (and torque) for rapier's next step, as a supported
//! body's soft load is (`rigid::body` module docs): rapier's solver applies it together with
//! the support's own contacts. Handed as a velocity change, the same impulse was an impact
//! on a light support: a 1 kg box under a 50 kg box carrying a 154 kg soft cube was given
//! 4–10 m/s into the ground in single frames. A fixed or kinematic support takes none.
//!
//! *Overlaps along rapier's path.* The floor `min(0, C)` of each constraint is taken at the
//! body's pose on rapier's path at the substep (`BodyProxy::base_pose`), not only at its end:
//! an overlap that rapier's step removes gradually (two dynamic boxes placed 4 cm into each
//! other) is removed at rapier's pace. With the end value as the floor, the constraints
//! pushed the body out ahead of its path, each substep again while it was held, and the
//! summed reaction threw a 10 kg support under a 50 kg box at 24 m/s (64 m/s at 40
//! substeps).
//!
//! The supports carry static friction (rapier's combined coefficient): the tangential motion
//! of a contact point over a substep is undone up to μ times the substep's normal impulse.
//!
//! Limits: the contact points are those of rapier's manifolds, computed at the start of its
//! step and read as points of each collider's own frame; for a part of a compound shape that
//! reading is not checked (the part's pose in the compound is not applied). Only rapier's
//! active contacts count: a support the body only comes to touch inside the substeps is
//! not there. The clearance leaves out the body's turn since it was measured, and the
//! decision to hold a body lags its load by a substep (in a frame's first substep, whose
//! previous load is not kept, a body standing on its supports is held). The friction cone
//! is that of the whole body, not of each contact, and ignores the body's weight; the
//! moment of the load is not looked at (a held body does not tip).
//!
//! Guarded by `tests/attachment_to_body_with_contacts.rs`: a soft cube attached to the top
//! of a light box on the ground stays on it, bounded in speed and energy, with a rigid pin
//! and with a compliant attachment.

use nalgebra::{Point3, Vector3};
use rapier3d::dynamics::{RigidBody, RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{ColliderSet, NarrowPhase};

use crate::convert::{pose_to_na, to_glam, to_na};
use crate::rigid::body::BodyProxy;

/// One contact point of an anchored body with a rigid support.
#[derive(Clone, Debug)]
pub(crate) struct Support {
    /// The anchored body's proxy.
    pub body: usize,
    /// The contact point on the body, in the body's frame, m.
    local: Vector3<f32>,
    /// The contact point on the support (world, at rapier's end pose), m.
    point: Vector3<f32>,
    /// Unit contact normal from the support towards the body (world).
    pub normal: Vector3<f32>,
    /// Lowest value the constraint may take, m (≤ 0).
    floor: f32,
    /// Friction coefficient of the contact (rapier's combined one).
    pub friction: f32,
    /// Overlap (m) the constraint tolerates: the one found at its first substep, less one
    /// substep's push, shrinking by that push every substep (module docs).
    allowance: f32,
    /// Whether `allowance` was decided for the frame.
    allowance_fresh: bool,
    /// The support's body when it is dynamic, and its world centre of mass, m.
    other: Option<(RigidBodyHandle, Vector3<f32>)>,
    /// Positional impulse on the anchored body in the current substep, kg·m.
    sub: Vector3<f32>,
    /// Impulse on the anchored body over the frame, N·s.
    impulse: Vector3<f32>,
}

/// Appends the contact points of proxy `b` (an anchored body) with other rigid colliders.
pub(crate) fn gather_supports(
    out: &mut Vec<Support>,
    b: usize,
    proxy: &BodyProxy,
    bodies: &RigidBodySet,
    colliders: &ColliderSet,
    narrow_phase: &NarrowPhase,
) {
    let Some(rb) = bodies.get(proxy.handle) else {
        return;
    };
    let end = proxy.frame_poses().1;
    for &ch in rb.colliders() {
        let Some(co) = colliders.get(ch) else {
            continue;
        };
        let in_body = co.position_wrt_parent().map(pose_to_na).unwrap_or_default();
        for pair in narrow_phase.contact_pairs_with(ch) {
            if !pair.has_any_active_contact() {
                continue;
            }
            let first = pair.collider1 == ch;
            let other_handle = if first {
                pair.collider2
            } else {
                pair.collider1
            };
            let Some(other) = colliders.get(other_handle) else {
                continue;
            };
            let other_pose = pose_to_na(other.position());
            let other_body = other
                .parent()
                .and_then(|h| bodies.get(h).map(|o| (h, o)))
                .filter(|(_, o)| o.is_dynamic())
                .map(|(h, o)| (h, to_na(o.center_of_mass())));
            for m in pair.manifolds() {
                if m.data.solver_contacts.is_empty() {
                    continue;
                }
                let n1 = to_na(m.data.normal);
                let normal = if first { -n1 } else { n1 };
                for pt in &m.points {
                    let (ours, theirs) = if first {
                        (pt.local_p1, pt.local_p2)
                    } else {
                        (pt.local_p2, pt.local_p1)
                    };
                    let local = in_body * Point3::from(to_na(ours));
                    let point = other_pose * Point3::from(to_na(theirs));
                    let c_end = normal.dot(&((end * local) - point));
                    out.push(Support {
                        body: b,
                        local: local.coords,
                        point: point.coords,
                        normal,
                        floor: c_end.min(0.0),
                        friction: m.data.friction,
                        allowance: 0.0,
                        allowance_fresh: false,
                        other: other_body,
                        sub: Vector3::zeros(),
                        impulse: Vector3::zeros(),
                    });
                }
            }
        }
    }
}

impl Support {
    /// The contact point on the body, in the body's frame, m.
    pub fn local(&self) -> &Vector3<f32> {
        &self.local
    }

    /// The constraint value (m) at the body's pose `pose`: `n·(x − y) − min(0, C₁)` plus
    /// the allowance (module docs); negative where the point is too deep.
    fn value(&self, pose: &nalgebra::Isometry3<f32>) -> f32 {
        self.separation(pose) - self.floor + self.allowance
    }

    /// The separation `n·(x − y)` (m) of the contact point at the body's pose `pose`.
    fn separation(&self, pose: &nalgebra::Isometry3<f32>) -> f32 {
        let x = (pose * Point3::from(self.local)).coords;
        self.normal.dot(&(x - self.point))
    }
}

/// Measures each anchored body's clearance above its supports at its current pose: the
/// smallest support constraint value (m; ≤ 0 where it stands on them).
pub(crate) fn measure_clearance(supports: &[Support], bodies: &mut [BodyProxy]) {
    for s in supports {
        bodies[s.body].set_clearance(f32::INFINITY);
    }
    for s in supports {
        let body = &mut bodies[s.body];
        let c = s.value(&body.pose);
        if !c.is_nan() {
            body.lower_clearance(c);
        }
    }
}

/// Starts a substep of the anchored bodies: decides the allowance of supports new in the
/// frame from the body's pose at the substep's start (module docs; `max_push`, m), measures
/// their clearance and decides which are held on their supports ([`BodyProxy::hold`];
/// `slop`: rapier's allowed linear error, m).
pub(crate) fn hold_supported(
    supports: &mut [Support],
    bodies: &mut [BodyProxy],
    slop: f32,
    max_push: f32,
) {
    let mut base = (usize::MAX, nalgebra::Isometry3::identity());
    for s in supports.iter_mut() {
        if base.0 != s.body {
            base = (s.body, bodies[s.body].base_pose());
        }
        let floor = s.separation(&base.1).min(0.0);
        if floor.is_finite() {
            s.floor = floor;
        }
    }
    for s in supports.iter_mut().filter(|s| !s.allowance_fresh) {
        s.allowance_fresh = true;
        let c0 = s.value(&bodies[s.body].prev);
        if c0.is_finite() {
            s.allowance = (-c0 - max_push).max(0.0);
        }
    }
    measure_clearance(supports, bodies);
    let mut last = usize::MAX;
    for s in supports {
        if s.body != last {
            bodies[s.body].hold(slop);
            last = s.body;
        }
    }
}

/// One sweep over the supports: keeps each anchored body's contact points out of its
/// supports (the support immovable), with static Coulomb friction on the point's motion
/// over the substep (as the particle contacts, `contacts::particle` module docs).
pub(crate) fn project_supports(supports: &mut [Support], bodies: &mut [BodyProxy]) {
    for s in supports {
        let body = &mut bodies[s.body];
        let x = (body.pose * Point3::from(s.local)).coords;
        let c = s.value(&body.pose);
        if c.is_nan() || c >= 0.0 {
            continue;
        }
        let w = body.inv_mass_at(&x, &s.normal);
        if w.is_nan() || w <= 0.0 {
            continue;
        }
        let p = s.normal * (-c / w);
        body.apply_support_impulse(&p, &x);
        s.sub += p;
        // Friction: undo the tangential motion of the point over the substep, up to
        // μ times the normal impulse of the substep.
        let x = (body.pose * Point3::from(s.local)).coords;
        let moved = x - (body.prev * Point3::from(s.local)).coords;
        let slide = moved - s.normal * s.normal.dot(&moved);
        let len = slide.norm();
        if len.is_nan() || len <= 1e-9 {
            continue;
        }
        let t = slide / len;
        let w = body.inv_mass_at(&x, &t);
        if w.is_nan() || w <= 0.0 {
            continue;
        }
        let normal = s.normal.dot(&s.sub);
        let tangential = (s.sub - s.normal * normal).norm();
        let room = (s.friction * normal - tangential).max(0.0);
        let dl = (len / w).min(room);
        if dl > 0.0 {
            let p = -t * dl;
            body.apply_support_impulse(&p, &x);
            s.sub += p;
        }
    }
}

/// Ends a substep of `h` seconds: the substep's positional impulses become impulses and
/// the allowances shrink by the depenetration push `max_push` (m).
pub(crate) fn end_substep_supports(supports: &mut [Support], h: f32, max_push: f32) {
    for s in supports {
        s.impulse += s.sub / h;
        s.sub = Vector3::zeros();
        s.allowance = (s.allowance - max_push).max(0.0);
    }
}

/// The dynamic support of `s` and the impulse (N·s) and angular impulse about its centre of
/// mass (N·m·s) it takes over the frame (the reaction of the anchored body's push).
pub(crate) fn support_reaction(
    s: &Support,
) -> Option<(RigidBodyHandle, Vector3<f32>, Vector3<f32>)> {
    let (h, com) = s.other?;
    let j = -s.impulse;
    (j != Vector3::zeros()).then(|| (h, j, (s.point - com).cross(&j)))
}

/// What [`apply_reaction`] did with a support's reaction.
pub(crate) enum Reaction {
    /// Added as this force (N) and torque (N·m) for rapier's next step.
    Added(Vector3<f32>, Vector3<f32>),
    /// Left out: too small to wake the sleeping support.
    Asleep,
    /// Left out: not finite.
    NonFinite,
}

/// Hands a support's reaction (impulse `j`, N·s, and angular impulse `l`, N·m·s, over a
/// frame of `dt` seconds) to its rapier body as a force and torque for rapier's next step,
/// which the caller takes off again after that step, as it does a supported body's load
/// ([`crate::rigid::body::BodyProxy::write_back`]): rapier's solver applies it together with
/// the support's own contacts.
pub(crate) fn apply_reaction(
    body: &mut RigidBody,
    j: &Vector3<f32>,
    l: &Vector3<f32>,
    dt: f32,
) -> Reaction {
    let (force, torque) = (j / dt, l / dt);
    if !(force.iter().chain(torque.iter()).all(|c| c.is_finite())) {
        return Reaction::NonFinite;
    }
    // A sleeping support is woken only by a reaction that moves it faster than its sleep
    // threshold; an awake one keeps rapier's sleep timer (`sleeping` module docs).
    let wake = body.is_sleeping();
    if wake {
        let m = body.mass();
        let dv = if m > 0.0 { j / m } else { Vector3::zeros() };
        if !crate::sleeping::moves_rigid(body, &dv, &Vector3::zeros()) {
            return Reaction::Asleep;
        }
    }
    body.add_force(to_glam(&force), wake);
    body.add_torque(to_glam(&torque), wake);
    Reaction::Added(force, torque)
}
