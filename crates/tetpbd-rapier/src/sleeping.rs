//! Sleeping in a coupled scene: what wakes a sleeping soft body, and what keeps one awake.
//!
//! The rule of a body falling asleep is the solver's ([`tetpbd::Activation`]); the coupling
//! adds what only it sees:
//!
//! * **Waking** (before the frame's candidates are gathered, so a woken body gets its
//!   contacts in the same frame): a sleeping soft body wakes when an awake rigid body that
//!   can move (dynamic and not sleeping in rapier, or kinematic with a velocity) has a
//!   collider within the contact margin plus the body's thickness of it, or swept across it
//!   in rapier's step (fast bodies); when it is attached to such a body, or to a point target
//!   that moved; and, with soft–soft contacts on, when an awake soft body comes within the
//!   soft margin plus both thicknesses plus how far it can travel in the frame. Waking is
//!   repeated until nothing more wakes, so a woken body wakes the sleeping bodies it touches
//!   in the same frame: an island wakes as one.
//! * **Islands** ([`tetpbd::SubstepHook::touching`]): two soft bodies near the same dynamic
//!   rigid body (a candidate contact of both) sleep and wake together; a soft body near an
//!   awake dynamic rigid body, or one that moves kinematically, stays awake. With soft–soft
//!   contacts on, two soft bodies whose bounds overlap within the soft margin are one island.
//! * **rapier's bodies keep rapier's rule**: the reaction written back to an awake rigid
//!   body does not restart its sleep timer (rapier decides from the body's own motion), and a
//!   sleeping rigid body is written, and woken, only when the reaction would move it faster
//!   than its own sleep threshold. A box resting on a soft pile falls asleep in rapier, then
//!   the pile falls asleep; sleeping soft bodies gather no contacts, so nothing touches the
//!   box until something wakes it.
//!
//! Thresholds of rapier's bodies are read in metres (`length_unit` 1).

use hecs::{Entity, World};
use nalgebra::Vector3;
use rapier3d::dynamics::{RigidBody, RigidBodySet};
use rapier3d::geometry::{Aabb, ColliderHandle};
use rapier3d::parry::bounding_volume::BoundingVolume;
use tetpbd::{Asleep, Particles, Surface, Touching};

use crate::attachments::{AttachTarget, Attachments};
use crate::convert::to_glam;
use crate::gather::{Frame, GatherInput};
use crate::soft_collider::SoftCollider;

/// Whether a velocity change `v` (m/s), `w` (rad/s) moves a rigid body faster than its
/// sleep thresholds (so that it should wake).
pub(crate) fn moves_rigid(body: &RigidBody, v: &Vector3<f32>, w: &Vector3<f32>) -> bool {
    let a = body.activation();
    v.norm() >= a.normalized_linear_threshold || w.norm() >= a.angular_threshold
}

/// Whether a rigid body can wake a soft body: awake and able to move.
pub(crate) fn awake_moving(rb: &RigidBody) -> bool {
    if rb.is_fixed() || rb.is_sleeping() {
        return false;
    }
    rb.is_dynamic() || rb.linvel().length() > 0.0 || rb.angvel().length() > 0.0
}

/// One soft body's bounds for the waking pass.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    entity: Entity,
    aabb: Aabb,
    /// How far beyond its bounds the body reaches within the frame, m (awake bodies).
    reach: f32,
    asleep: bool,
}

/// Scratch of the waking pass (kept across frames so that a step allocates nothing).
#[derive(Clone, Debug, Default)]
pub(crate) struct Waking {
    bounds: Vec<Bounds>,
    woken: Vec<Entity>,
    /// Scratch of [`touching`]: `(rigid body proxy, soft entity)`.
    links: Vec<(usize, Entity)>,
}

impl Waking {
    /// Wakes the sleeping soft bodies something awake comes near (module docs), until
    /// nothing more wakes. `fast` are the swept bounds of fast colliders, `soft_margin` the
    /// soft–soft contact margin (`None`: soft–soft contacts off). Returns the number woken.
    pub(crate) fn run(
        &mut self,
        world: &mut World,
        input: &GatherInput<'_, '_>,
        fast: &[(ColliderHandle, Aabb)],
        soft_margin: Option<f32>,
        dt: f32,
    ) -> usize {
        let near = |aabb: &Aabb, att: Option<&Attachments>| near_rigid(aabb, input, fast, att);
        self.run_with(world, input.default_collider, soft_margin, dt, near)
    }

    /// The soft–soft part of [`Waking::run`] alone, for [`crate::SoftContacts`] run as the
    /// solver's hook without a coupling.
    pub(crate) fn run_soft(
        &mut self,
        world: &mut World,
        default: &SoftCollider,
        margin: f32,
        dt: f32,
    ) -> usize {
        self.run_with(world, default, Some(margin), dt, |_, _| false)
    }

    fn run_with(
        &mut self,
        world: &mut World,
        default: &SoftCollider,
        soft_margin: Option<f32>,
        dt: f32,
        mut near_rigid: impl FnMut(&Aabb, Option<&Attachments>) -> bool,
    ) -> usize {
        self.bounds.clear();
        self.woken.clear();
        let mut any_asleep = false;
        for (entity, p, _, sc, att, asleep) in world.query_mut::<(
            Entity,
            &Particles,
            &Surface,
            Option<&SoftCollider>,
            Option<&Attachments>,
            Option<&Asleep>,
        )>() {
            let sc = sc.copied().unwrap_or(*default);
            let (lo, hi) = p.aabb();
            let aabb = Aabb::new(to_glam(&lo), to_glam(&hi)).loosened(sc.thickness.max(0.0));
            let asleep = asleep.is_some();
            any_asleep |= asleep;
            let reach = if asleep { 0.0 } else { p.max_speed() * dt };
            if asleep && sc.enabled && near_rigid(&aabb, att) {
                self.woken.push(entity);
            }
            if sc.enabled {
                self.bounds.push(Bounds {
                    entity,
                    aabb,
                    reach,
                    asleep,
                });
            }
        }
        if !any_asleep {
            return 0;
        }
        self.bounds.sort_unstable_by_key(|b| b.entity.to_bits());
        for b in &mut self.bounds {
            if self.woken.contains(&b.entity) {
                b.asleep = false;
            }
        }
        if let Some(margin) = soft_margin {
            self.wake_soft_neighbours(margin);
        }
        for &e in &self.woken {
            tetpbd::wake(world, e);
        }
        self.woken.len()
    }

    /// Wakes every sleeping body within `margin` (plus the awake body's reach) of an awake
    /// one, repeatedly, so that a woken body wakes its own neighbours.
    fn wake_soft_neighbours(&mut self, margin: f32) {
        loop {
            let mut changed = false;
            for i in 0..self.bounds.len() {
                if !self.bounds[i].asleep {
                    continue;
                }
                let a = self.bounds[i].aabb;
                let near = self
                    .bounds
                    .iter()
                    .any(|b| !b.asleep && b.aabb.loosened(margin + b.reach).intersects(&a));
                if near {
                    self.bounds[i].asleep = false;
                    self.woken.push(self.bounds[i].entity);
                    changed = true;
                }
            }
            if !changed {
                return;
            }
        }
    }
}

/// Whether an awake, movable rigid body is near a sleeping soft body's bounds `aabb`, or
/// moves one of its attachments (module docs).
fn near_rigid(
    aabb: &Aabb,
    input: &GatherInput<'_, '_>,
    fast: &[(ColliderHandle, Aabb)],
    att: Option<&Attachments>,
) -> bool {
    let qp = input.qp;
    let region = aabb.loosened(input.margin);
    let near = qp.intersect_aabb_conservative(region).any(|(_, co)| {
        co.is_enabled()
            && !co.is_sensor()
            && co
                .parent()
                .and_then(|h| qp.bodies.get(h))
                .is_some_and(awake_moving)
    });
    if near || fast.iter().any(|(_, swept)| swept.intersects(&region)) {
        return true;
    }
    att.is_some_and(|att| {
        att.items.iter().any(|a| match a.target {
            AttachTarget::Body { handle, .. } => qp.bodies.get(handle).is_some_and(awake_moving),
            AttachTarget::Point { position, previous } => position != previous,
        })
    })
}

/// The islands the rigid bodies make (module docs): soft bodies with candidate contacts or
/// attachments to the same dynamic body are paired; those near an awake dynamic body, or a
/// kinematic one that moves, are kept awake.
pub(crate) fn touching(frame: &mut Frame, bodies: &RigidBodySet, out: &mut Touching) {
    let mut links = std::mem::take(&mut frame.waking.links);
    links.clear();
    for s in &frame.soft {
        let contacts = frame.contacts[s.contacts.clone()]
            .iter()
            .map(|c| c.collider);
        let corners = frame.corners[s.corners.clone()].iter().map(|c| c.collider);
        let via_colliders = contacts
            .chain(corners)
            .filter_map(|c| frame.colliders[c].body);
        let via_attachments = frame.attachments[s.attachments.clone()]
            .iter()
            .filter_map(|a| a.body);
        for b in via_colliders.chain(via_attachments) {
            links.push((b, s.entity));
        }
    }
    links.sort_unstable_by_key(|&(b, e)| (b, e.to_bits()));
    links.dedup();
    let mut first = 0;
    for k in 0..links.len() {
        let (b, e) = links[k];
        if links[first].0 != b {
            first = k;
        }
        let Some(rb) = bodies.get(frame.bodies[b].handle) else {
            continue;
        };
        if rb.is_fixed() {
            continue;
        }
        if awake_moving(rb) {
            out.keep_awake.push(e);
        }
        if rb.is_dynamic() && k > first {
            out.pairs.push((links[first].1, e));
        }
    }
    frame.waking.links = links;
}
