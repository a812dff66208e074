//! The per-frame state of the coupling: soft bodies, rigid proxies and constraint
//! candidates gathered once per frame from rapier's broad-phase BVH.

use std::collections::HashMap;

use hecs::{Entity, World};
use nalgebra::{Isometry3, Vector3};
use rapier3d::dynamics::{CoefficientCombineRule, RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{Aabb, ColliderHandle, ColliderSet, NarrowPhase};
use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::pipeline::QueryPipeline;
use tetpbd::{Particles, Surface};

use crate::attachment::{AttachTarget, Attachments};
use crate::bodies::{BodyKind, BodyProxy};
use crate::convert::{pose_to_glam, pose_to_na, to_glam};
use crate::corner::{gather_corners, CornerContact};
use crate::corner_points::Corners;
use crate::material::SoftCollider;
use crate::report::CouplingStats;
use crate::shape_query::InsideRule;
use crate::support::{gather_supports, Support};

/// A body's pose (m, rad) and linear velocity (m/s) before rapier's step.
pub(crate) type StartState = (Isometry3<f32>, Vector3<f32>);

/// A soft body taking part in the frame.
#[derive(Clone, Debug)]
pub(crate) struct SoftEntry {
    pub entity: Entity,
    /// Centre-of-mass velocity after the prediction of the current substep, m/s.
    pub v_cm_pre: Vector3<f32>,
    pub contacts: std::ops::Range<usize>,
    pub corners: std::ops::Range<usize>,
    pub attachments: std::ops::Range<usize>,
    /// Whether the stacking pass ran on the body in the current substep.
    pub stacked: bool,
}

/// A collider near a soft body.
#[derive(Clone, Debug)]
pub(crate) struct ColliderProxy {
    pub handle: ColliderHandle,
    pub body: Option<usize>,
    pub local: Isometry3<f32>,
    pub rule: InsideRule,
    pub friction: f32,
    pub friction_rule: CoefficientCombineRule,
    pub restitution: f32,
    pub restitution_rule: CoefficientCombineRule,
}

impl ColliderProxy {
    /// World pose at the current substep.
    pub fn pose(&self, bodies: &[BodyProxy]) -> Isometry3<f32> {
        match self.body {
            Some(b) => bodies[b].pose * self.local,
            None => self.local,
        }
    }

    /// World pose at the end of the previous substep.
    pub fn prev_pose(&self, bodies: &[BodyProxy]) -> Isometry3<f32> {
        match self.body {
            Some(b) => bodies[b].prev * self.local,
            None => self.local,
        }
    }
}

/// A surface particle near a collider: an XPBD inequality contact re-evaluated every
/// iteration of every substep.
#[derive(Clone, Debug)]
pub(crate) struct ParticleContact {
    pub particle: u32,
    pub collider: usize,
    pub mu_d: f32,
    pub mu_s: f32,
    pub restitution: f32,
    pub thickness: f32,
    pub solve: bool,
    pub lambda_n: f32,
    pub lambda_t: f32,
    pub active: bool,
    pub ever_active: bool,
    pub has_normal: bool,
    pub normal: Vector3<f32>,
    pub point: Vector3<f32>,
    pub depth: f32,
    /// Penetration tolerated in this substep (pre-existing overlap beyond one substep's
    /// allowed push-out), m; see `CouplingSettings::max_depenetration_speed`.
    pub allowance: f32,
    /// Whether `allowance` was decided: at the contact's first evaluation in the frame, or
    /// at gathering for a pair already touching in the previous frame (no allowance).
    pub allowance_fresh: bool,
    pub sub_impulse: Vector3<f32>,
    pub impulse: Vector3<f32>,
}

/// A particle–collider pair: `(entity bits, collider handle (index, generation), particle)`.
pub(crate) type PairKey = (u64, (u32, u32), u32);

/// An attachment in the frame.
#[derive(Clone, Debug)]
pub(crate) struct AttachRun {
    pub particle: u32,
    pub body: Option<usize>,
    pub local: Vector3<f32>,
    pub start: Vector3<f32>,
    pub end: Vector3<f32>,
    pub compliance: f32,
    pub lambda: f32,
}

/// Everything the coupling keeps for one frame (allocations reused across frames).
#[derive(Clone, Debug, Default)]
pub(crate) struct Frame {
    /// Particle–collider pairs in contact during the previous frame, sorted by
    /// `(entity bits, collider handle (index, generation), particle)`, with the overlap
    /// allowance they still had (m). A contact found in this frame whose pair is not here is
    /// new: an overlap it starts with is pushed out at the bounded depenetration speed (see
    /// `contact::project_contacts`); one that is here continues with its allowance.
    pub touching: Vec<(PairKey, f32)>,
    /// Soft bodies (entity bits) stepped in the previous frame, sorted. Only a body not in
    /// this list (created this frame) gets an overlap allowance: an overlap it was created
    /// with is pushed out at the bounded speed; any other penetration is resolved fully.
    pub seen: Vec<u64>,
    pub start_poses: Vec<((u32, u32), StartState)>,
    pub soft: Vec<SoftEntry>,
    pub bodies: Vec<BodyProxy>,
    /// Proxy index of a rigid body handle (lookups only; cleared, capacity kept).
    body_index: HashMap<(u32, u32), usize>,
    pub colliders: Vec<ColliderProxy>,
    /// Proxy index of a collider handle (lookups only; cleared, capacity kept).
    collider_index: HashMap<(u32, u32), usize>,
    pub contacts: Vec<ParticleContact>,
    pub corners: Vec<CornerContact>,
    pub attachments: Vec<AttachRun>,
    /// Rigid contacts of anchored bodies (`support` module docs).
    pub supports: Vec<Support>,
    /// Force (N) and torque (N·m) added to bodies for rapier's next step (the load of the
    /// previous frame, `BodyProxy::load`), taken off again after that step.
    pub loads: Vec<(RigidBodyHandle, Vector3<f32>, Vector3<f32>)>,
    /// Levels of the stacking pass (`stacking` module docs), one per soft body (by its
    /// index in `soft`), kept across frames.
    pub layers: Vec<(Option<Entity>, tetpbd::StackingLayers)>,
    /// Scratch of the stacking pass: which particles were pinned before it froze them.
    pub pinned: Vec<bool>,
    near: Vec<ColliderHandle>,
    /// Colliders of fast bodies with their swept AABB over the frame (`sweep` module docs).
    fast: Vec<(ColliderHandle, Aabb)>,
    vertex_contacts: Vec<(u32, usize)>,
    /// Scratch: a shape's corners (`corner::gather_corners`).
    shape_corners: Corners,
    /// Scratch: the colliders of a body's active contacts (`restitution::restitution_pass`).
    pub active_colliders: Vec<usize>,
    /// Impact episodes in progress (kept across frames).
    pub episodes: Vec<crate::restitution::Episode>,
    pub substep: u32,
    pub substeps: u32,
    pub dt: f32,
    pub gravity: f32,
    pub stats: CouplingStats,
}

/// What candidate gathering needs besides the frame.
pub(crate) struct GatherInput<'q, 'a> {
    pub qp: &'q QueryPipeline<'a>,
    pub narrow_phase: &'q NarrowPhase,
    pub default_collider: &'q SoftCollider,
    pub margin: f32,
}

impl Frame {
    /// Records every non-fixed body's pose before rapier's step.
    pub fn capture_start(&mut self, bodies: &RigidBodySet) {
        self.start_poses.clear();
        for (h, b) in bodies.iter() {
            if !b.is_fixed() {
                self.start_poses.push((
                    h.into_raw_parts(),
                    (pose_to_na(b.position()), crate::convert::to_na(b.linvel())),
                ));
            }
        }
    }

    fn start_pose(&self, handle: RigidBodyHandle) -> Option<StartState> {
        let key = handle.into_raw_parts();
        self.start_poses
            .binary_search_by(|(k, _)| k.cmp(&key))
            .ok()
            .map(|i| self.start_poses[i].1)
    }

    /// The proxy of `handle`, created on first use; `None` when the body does not exist.
    pub fn body_proxy(
        &mut self,
        handle: RigidBodyHandle,
        bodies: &RigidBodySet,
        narrow_phase: &NarrowPhase,
    ) -> Option<usize> {
        let key = handle.into_raw_parts();
        if let Some(&i) = self.body_index.get(&key) {
            return Some(i);
        }
        let rb = bodies.get(handle)?;
        let start = self.start_pose(handle).unwrap_or_else(|| {
            (
                pose_to_na(rb.position()),
                crate::convert::to_na(rb.linvel()),
            )
        });
        let supported = rb.is_dynamic()
            && rb.colliders().iter().any(|&c| {
                narrow_phase
                    .contact_pairs_with(c)
                    .any(|pair| pair.has_any_active_contact())
            });
        self.bodies
            .push(BodyProxy::new(handle, rb, start, self.dt, supported));
        self.body_index.insert(key, self.bodies.len() - 1);
        Some(self.bodies.len() - 1)
    }

    fn collider_proxy(
        &mut self,
        handle: ColliderHandle,
        bodies: &RigidBodySet,
        colliders: &ColliderSet,
        narrow_phase: &NarrowPhase,
    ) -> Option<usize> {
        let key = handle.into_raw_parts();
        if let Some(&i) = self.collider_index.get(&key) {
            return Some(i);
        }
        let co = colliders.get(handle)?;
        let (body, local) = match co.parent() {
            Some(parent) => {
                let b = self.body_proxy(parent, bodies, narrow_phase)?;
                let local = co
                    .position_wrt_parent()
                    .map(pose_to_na)
                    .unwrap_or_else(Isometry3::identity);
                (Some(b), local)
            }
            None => (None, pose_to_na(co.position())),
        };
        self.colliders.push(ColliderProxy {
            handle,
            body,
            local,
            rule: InsideRule::of(co.shape()),
            friction: co.friction(),
            friction_rule: co.friction_combine_rule(),
            restitution: co.restitution(),
            restitution_rule: co.restitution_combine_rule(),
        });
        self.collider_index.insert(key, self.colliders.len() - 1);
        Some(self.colliders.len() - 1)
    }

    /// Swept world AABB of a collider proxy over the frame.
    fn swept_aabb(&self, c: usize, colliders: &ColliderSet) -> Option<Aabb> {
        let cp = &self.colliders[c];
        let shape = colliders.get(cp.handle)?.shape();
        let (start, end) = match cp.body {
            Some(b) => {
                let (s, e) = self.bodies[b].frame_poses();
                (s * cp.local, e * cp.local)
            }
            None => (cp.local, cp.local),
        };
        Some(shape.compute_swept_aabb(&pose_to_glam(&start), &pose_to_glam(&end)))
    }

    /// Clears the previous frame and gathers this frame's candidates.
    pub fn gather(&mut self, world: &mut World, input: &GatherInput<'_, '_>) {
        self.soft.clear();
        self.bodies.clear();
        self.body_index.clear();
        self.colliders.clear();
        self.collider_index.clear();
        self.contacts.clear();
        self.corners.clear();
        self.attachments.clear();
        self.supports.clear();
        self.substep = 0;
        let qp = input.qp;
        crate::sweep::fast_colliders(
            &mut self.fast,
            &self.start_poses,
            qp.bodies,
            qp.colliders,
            input.margin,
        );
        let dt = self.dt;
        let fall = 0.5 * self.gravity * dt * dt;
        for (entity, p, surface, sc, att) in world.query_mut::<(
            Entity,
            &Particles,
            &Surface,
            Option<&SoftCollider>,
            Option<&Attachments>,
        )>() {
            let sc = sc.copied().unwrap_or(*input.default_collider);
            let newcomer = self.seen.binary_search(&entity.to_bits().get()).is_err();
            let c0 = self.contacts.len();
            let k0 = self.corners.len();
            let a0 = self.attachments.len();
            if sc.enabled && !surface.vertices().is_empty() {
                let reach = input.margin + sc.thickness + p.max_speed() * dt + fall;
                let (lo, hi) = surface_bounds(p, surface);
                let aabb = Aabb::new(to_glam(&lo), to_glam(&hi)).loosened(reach);
                let mut near = std::mem::take(&mut self.near);
                near.clear();
                let keep = |co: &rapier3d::geometry::Collider| {
                    co.is_enabled()
                        && !co.is_sensor()
                        && sc.collision_groups.test(co.collision_groups())
                };
                near.extend(
                    qp.intersect_aabb_conservative(aabb)
                        .filter(|(_, co)| keep(co))
                        .map(|(h, _)| h),
                );
                // Fast bodies that crossed the soft body during rapier's step.
                for (h, swept) in &self.fast {
                    if swept.intersects(&aabb)
                        && !near.contains(h)
                        && qp.colliders.get(*h).is_some_and(keep)
                    {
                        near.push(*h);
                    }
                }
                for &handle in &near {
                    let Some(ci) =
                        self.collider_proxy(handle, qp.bodies, qp.colliders, input.narrow_phase)
                    else {
                        continue;
                    };
                    let Some(caabb) = self.swept_aabb(ci, qp.colliders) else {
                        continue;
                    };
                    // Loosened by the body's fastest motion too, not only by each
                    // particle's own path below: a slow particle of a body being struck
                    // (another body landing on it) is sped up within the frame and would
                    // sink through the collider until the next gathering (issue 6, the
                    // pile's launch, crates/tetpbd-bench/tests/issue_6_pile_launch.rs).
                    let caabb = caabb.loosened(reach);
                    let Some(co) = qp.colliders.get(handle) else {
                        continue;
                    };
                    let solve = sc.solver_groups.test(co.solver_groups());
                    let cp = &self.colliders[ci];
                    // Does not move over the frame (`corner::gather_corners`).
                    let still = cp
                        .body
                        .is_none_or(|b| self.bodies[b].kind == BodyKind::Fixed);
                    let (mu_d, mu_s) = sc.combined_friction(cp.friction, cp.friction_rule);
                    let e = sc.combined_restitution(cp.restitution, cp.restitution_rule);
                    let first = self.contacts.len();
                    for &i in surface.vertices() {
                        let x = p.positions()[i as usize];
                        let y = x + p.velocities()[i as usize] * dt;
                        let pa = Aabb::new(to_glam(&x.inf(&y)), to_glam(&x.sup(&y)));
                        if !pa.intersects(&caabb) {
                            continue;
                        }
                        let key = (entity.to_bits().get(), handle.into_raw_parts(), i);
                        let previous = self.touching.binary_search_by_key(&key, |t| t.0).ok();
                        // Allowance decided now unless the body is new (see `seen`).
                        let decided = previous.is_some() || !newcomer;
                        self.contacts.push(ParticleContact {
                            particle: i,
                            collider: ci,
                            mu_d,
                            mu_s,
                            restitution: e,
                            thickness: sc.thickness,
                            solve,
                            lambda_n: 0.0,
                            lambda_t: 0.0,
                            active: false,
                            ever_active: false,
                            has_normal: false,
                            normal: Vector3::zeros(),
                            point: Vector3::zeros(),
                            depth: 0.0,
                            // Touching in the previous frame: an ongoing contact, which keeps
                            // what is left of its overlap allowance (usually nothing).
                            allowance: previous.map_or(0.0, |k| self.touching[k].1),
                            allowance_fresh: decided,
                            sub_impulse: Vector3::zeros(),
                            impulse: Vector3::zeros(),
                        });
                    }
                    if sc.triangles && solve {
                        let mut vertex_contacts = std::mem::take(&mut self.vertex_contacts);
                        vertex_contacts.clear();
                        vertex_contacts.extend(
                            (first..self.contacts.len())
                                .map(|k| (self.contacts[k].particle, k - c0)),
                        );
                        gather_corners(
                            &mut self.corners,
                            co.shape(),
                            ci,
                            &caabb,
                            &pose_to_na(co.position()),
                            still,
                            p,
                            surface,
                            dt,
                            sc.thickness,
                            (mu_d, mu_s, e),
                            &vertex_contacts,
                            &mut self.shape_corners,
                        );
                        self.vertex_contacts = vertex_contacts;
                    }
                }
                self.near = near;
            }
            if let Some(att) = att {
                for a in &att.items {
                    if a.particle as usize >= p.len() {
                        self.stats.skipped_attachments += 1;
                        continue;
                    }
                    let run = match a.target {
                        AttachTarget::Body {
                            handle,
                            local_point,
                        } => match self.body_proxy(handle, qp.bodies, input.narrow_phase) {
                            Some(b) => AttachRun {
                                particle: a.particle,
                                body: Some(b),
                                local: local_point,
                                start: Vector3::zeros(),
                                end: Vector3::zeros(),
                                compliance: a.compliance,
                                lambda: 0.0,
                            },
                            None => {
                                self.stats.skipped_attachments += 1;
                                continue;
                            }
                        },
                        AttachTarget::Point { position, previous } => AttachRun {
                            particle: a.particle,
                            body: None,
                            local: Vector3::zeros(),
                            start: previous,
                            end: position,
                            compliance: a.compliance,
                            lambda: 0.0,
                        },
                    };
                    self.attachments.push(run);
                }
            }
            self.soft.push(SoftEntry {
                entity,
                v_cm_pre: Vector3::zeros(),
                contacts: c0..self.contacts.len(),
                corners: k0..self.corners.len(),
                attachments: a0..self.attachments.len(),
                stacked: false,
            });
        }
        // A supported body holding a soft body by an attachment is anchored: it takes part
        // with its own mass, its rigid contacts kept as constraints (`support` module docs).
        for k in 0..self.attachments.len() {
            let Some(b) = self.attachments[k].body else {
                continue;
            };
            if self.bodies[b].kind == BodyKind::Supported {
                let first = self.supports.len();
                gather_supports(
                    &mut self.supports,
                    b,
                    &self.bodies[b],
                    qp.bodies,
                    qp.colliders,
                    input.narrow_phase,
                );
                let normal = self.supports[first..].iter().map(|s| s.normal).sum();
                let friction = self.supports[first..]
                    .iter()
                    .map(|s| s.friction)
                    .fold(f32::INFINITY, f32::min);
                self.bodies[b].anchor(normal, friction);
            }
        }
        self.stats.candidates = self.contacts.len();
        self.stats.corner_candidates = self.corners.len();
        self.stats.attachments = self.attachments.len();
    }
}

/// Bounds of a body's surface particles, m.
fn surface_bounds(p: &Particles, surface: &Surface) -> (Vector3<f32>, Vector3<f32>) {
    let mut lo = Vector3::repeat(f32::INFINITY);
    let mut hi = Vector3::repeat(f32::NEG_INFINITY);
    for &i in surface.vertices() {
        let x = p.positions()[i as usize];
        lo = lo.inf(&x);
        hi = hi.sup(&x);
    }
    (lo, hi)
}

impl Frame {
    /// Remembers which soft bodies were stepped and which particle–collider pairs touched in
    /// this frame, with their remaining overlap allowance (for the next frame). Reuses the
    /// allocations.
    pub fn remember_touching(&mut self) {
        self.touching.clear();
        for s in &self.soft {
            for c in &self.contacts[s.contacts.clone()] {
                if c.ever_active {
                    let handle = self.colliders[c.collider].handle.into_raw_parts();
                    let key = (s.entity.to_bits().get(), handle, c.particle);
                    self.touching.push((key, c.allowance));
                }
            }
        }
        self.touching.sort_unstable_by_key(|t| t.0);
        self.seen.clear();
        self.seen
            .extend(self.soft.iter().map(|s| s.entity.to_bits().get()));
        self.seen.sort_unstable();
    }
}
