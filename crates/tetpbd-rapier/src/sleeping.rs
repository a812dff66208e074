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
//!   rigid body (a candidate contact of both) sleep and wake together; a soft body near a
//!   dynamic rigid body that ends the frame faster than its sleep threshold, or a kinematic
//!   one that moves, stays awake. With soft–soft contacts on, two soft bodies whose bounds
//!   overlap within the soft margin are one island.
//! * **rapier's bodies sleep with their island**: a dynamic rigid body whose soft bodies all
//!   fell asleep in a frame (it was slow, or they would not have) is written back and put to
//!   sleep with them (`RigidBody::sleep`), as rapier puts an island to sleep; it wakes by
//!   rapier's rules (a contact, a joint, a user call) and then wakes them. A sleeping support
//!   of an anchored body gets its reaction, and wakes, only when it would move it faster than
//!   its sleep threshold. Sleeping soft bodies gather no contacts, so nothing touches a
//!   sleeping box on a sleeping pile until something wakes one of them.
//!
//! * **Losing what holds it**: a sleeping body whose surface is removed or whose collider is
//!   disabled wakes (it no longer collides, so it falls); one still being pushed out of an
//!   overlap never sleeps.
//! * **Supports going away**: a sleeping soft body remembers the rigid bodies it fell asleep
//!   touching, with their poses, and wakes when one of them moves, wakes or is removed (a
//!   box lifted off it, a ground teleported).
//!
//! Thresholds of rapier's bodies are read in metres (`length_unit` 1).

use hecs::{Entity, World};
use nalgebra::Vector3;
use rapier3d::dynamics::{RigidBody, RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{Aabb, ColliderHandle};
use rapier3d::math::Pose;
use rapier3d::parry::bounding_volume::BoundingVolume;
use tetpbd::{Asleep, Particles, Surface, Touching};

use crate::attachments::{AttachTarget, Attachments};
use crate::convert::to_glam;
use crate::gather::{Frame, GatherInput};
use crate::rigid::body::BodyProxy;
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
    /// The rigid bodies each sleeping soft body fell asleep touching, with their pose then:
    /// the body wakes when one of them moves, wakes or goes away.
    rest: Vec<(Entity, RigidBodyHandle, Pose)>,
    /// Scratch of [`Waking::run`]: soft bodies whose resting rigid bodies changed.
    changed: Vec<Entity>,
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
        let bodies = input.qp.bodies;
        self.rest.retain(|(e, _, _)| tetpbd::is_sleeping(world, *e));
        let mut support_changed = std::mem::take(&mut self.changed);
        support_changed.clear();
        support_changed.extend(self.rest.iter().filter_map(|&(e, h, pose)| {
            let same = bodies
                .get(h)
                .is_some_and(|rb| *rb.position() == pose && !awake_moving(rb));
            (!same).then_some(e)
        }));
        let near = |e: Entity, aabb: &Aabb, att: Option<&Attachments>| {
            support_changed.contains(&e) || near_rigid(aabb, input, fast, att)
        };
        let n = self.run_with(world, input.default_collider, soft_margin, dt, near);
        self.changed = support_changed;
        n
    }

    /// Records the rigid bodies the soft bodies that fell asleep this frame touch (from
    /// [`touching`]'s links), with their poses.
    pub(crate) fn remember_rest(
        &mut self,
        frame_bodies: &[BodyProxy],
        bodies: &RigidBodySet,
        world: &World,
    ) {
        for &(b, e) in &self.links {
            let h = frame_bodies[b].handle;
            if tetpbd::is_sleeping(world, e) && !self.rest.iter().any(|r| r.0 == e && r.1 == h) {
                if let Some(rb) = bodies.get(h) {
                    self.rest.push((e, h, *rb.position()));
                }
            }
        }
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
        self.run_with(world, default, Some(margin), dt, |_, _, _| false)
    }

    fn run_with(
        &mut self,
        world: &mut World,
        default: &SoftCollider,
        soft_margin: Option<f32>,
        dt: f32,
        mut near_rigid: impl FnMut(Entity, &Aabb, Option<&Attachments>) -> bool,
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
            if asleep && sc.enabled && near_rigid(entity, &aabb, att) {
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
        self.bounds.sort_unstable_by_key(|b| b.entity.to_bits());
        // A sleeping body that can no longer collide (its surface removed, its collider
        // disabled) lost what held it: it wakes.
        for (entity, sc) in world
            .query_mut::<(Entity, Option<&SoftCollider>)>()
            .with::<(&Asleep, &Particles)>()
        {
            let enabled = sc.copied().unwrap_or(*default).enabled;
            let key = entity.to_bits();
            let found = self
                .bounds
                .binary_search_by_key(&key, |b| b.entity.to_bits())
                .is_ok();
            if !enabled || !found {
                self.woken.push(entity);
                any_asleep = true;
            }
        }
        if !any_asleep {
            return 0;
        }
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
    // A body still being pushed out of an overlap (`depenetration` module docs) is not at
    // rest, however slowly the push moves it.
    out.keep_awake.extend(
        frame
            .depenetrating
            .iter()
            .filter_map(|d| Entity::from_bits(d.0)),
    );
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
        let (v, w) = frame.bodies[b].final_velocity();
        let moving = if rb.is_dynamic() {
            moves_rigid(rb, &v, &w)
        } else {
            awake_moving(rb)
        };
        if moving {
            out.keep_awake.push(e);
        }
        if rb.is_dynamic() && k > first {
            out.pairs.push((links[first].1, e));
        }
    }
    frame.waking.links = links;
}

/// Whether every soft body touching rigid body proxy `body` (as [`touching`] found them this
/// frame) is asleep: the body falls asleep with them.
pub(crate) fn soft_asleep(waking: &Waking, body: usize, world: &World) -> bool {
    let from = waking.links.partition_point(|&(b, _)| b < body);
    let mut linked = waking.links[from..]
        .iter()
        .take_while(|&&(b, _)| b == body)
        .peekable();
    linked.peek().is_some() && linked.all(|&(_, e)| tetpbd::is_sleeping(world, e))
}
