//! Gathering: the per-frame state of the coupling ([`Frame`]): the soft bodies taking part,
//! proxies of the rigid bodies and colliders near them, and the constraint candidates
//! gathered once per frame from rapier's broad-phase BVH ([`candidates`]); the corner points
//! of rigid shapes ([`corner_points`]) and which of them meet which soft triangles
//! ([`corners`]).

mod candidates;
pub(crate) mod corner_points;
mod corners;

use std::collections::HashMap;

use hecs::Entity;
use nalgebra::{Isometry3, Matrix3, Vector3};
use rapier3d::dynamics::{
    ImpulseJointSet, JointAxesMask, MultibodyJointSet, RigidBodyHandle, RigidBodySet,
};
use rapier3d::geometry::{Aabb, ColliderHandle, ColliderSet, NarrowPhase};
use rapier3d::pipeline::QueryPipeline;

use crate::attachments::AttachRun;
use crate::contacts::corner::CornerContact;
use crate::contacts::particle::ParticleContact;
use crate::contacts::support::Support;
use crate::convert::{pose_to_glam, pose_to_na};
use crate::joints::{joints_of, JointRun};
use crate::mesh_side::MeshRules;
use crate::report::CouplingStats;
use crate::response::restitution::Episodes;
use crate::rigid::body::{BodyProxy, StartState};
use crate::rigid::collider::ColliderProxy;
use crate::soft_collider::SoftCollider;
use corner_points::Corners;

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
    /// How deep an impact its surface takes locally within a substep, m
    /// ([`tetpbd::ImpactReach`]).
    pub reach: f32,
    /// Its longitudinal wave speed, m/s ([`tetpbd::impact_speed::wave_speed`]; computed from
    /// rest data each frame for a body with contact candidates, `f32::INFINITY` otherwise):
    /// with `reach`, how fast it may approach something immovable (`contacts::approach`).
    pub wave_speed: f32,
    /// Its surface bounds grown by the soft–soft margin and how far it may move in the
    /// frame, m (`None` with soft–soft contacts off or its collider disabled).
    pub bounds: Option<(Vector3<f32>, Vector3<f32>)>,
    /// Whether those bounds meet another soft body's: it may touch a soft body this frame.
    pub near_soft: bool,
}

/// A particle–collider pair: `(entity bits, collider handle (index, generation), particle)`.
pub(crate) type PairKey = (u64, (u32, u32), u32);

/// Everything the coupling keeps for one frame (allocations reused across frames).
#[derive(Clone, Debug, Default)]
pub(crate) struct Frame {
    /// Particle–collider pairs in contact during the previous frame, sorted by
    /// `(entity bits, collider handle (index, generation), particle)`, with the overlap
    /// allowance they still had (m). A contact found in this frame whose pair is not here is
    /// new; one that is here continues with what was left of its overlap allowance (both
    /// are bounded by the depenetration speed: `contacts::particle` module docs).
    pub touching: Vec<(PairKey, f32)>,
    pub start_poses: Vec<((u32, u32), StartState)>,
    /// Soft bodies being pushed out of an overlap (`depenetration` module docs), kept
    /// across frames.
    pub depenetrating: Vec<crate::depenetration::Depenetrating>,
    /// Inside rules of the triangle meshes seen (`mesh_side` module docs).
    mesh_rules: MeshRules,
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
    /// Rigid contacts of anchored bodies (`contacts::support` module docs).
    pub supports: Vec<Support>,
    /// Joints of the dynamic bodies taking part (`joints` module docs).
    pub joints: Vec<JointRun>,
    /// Scratch: the joints gathered so far (each is met from both of its bodies).
    joint_keys: Vec<(bool, u32, u32)>,
    /// Force (N) and torque (N·m) added to bodies for rapier's next step (the load of the
    /// previous frame, `BodyProxy::load`), taken off again after that step.
    pub loads: Vec<(RigidBodyHandle, Vector3<f32>, Vector3<f32>)>,
    /// Scratch: generalized velocities of a multibody (`rigid::body::link` module docs).
    pub generalized: nalgebra::DVector<f32>,
    /// Ground-up sweeps of the stacking pass (`heavy_loads` module docs), one per soft body
    /// (by its index in `soft`), kept across frames.
    pub sweeps: Vec<tetpbd::GroundUpSweep>,
    /// Scratch of the stacking pass: which particles were pinned before it froze them.
    pub pinned: Vec<bool>,
    near: Vec<ColliderHandle>,
    /// Colliders of fast bodies with their swept AABB over the frame (`ccd` module docs).
    fast: Vec<(ColliderHandle, Aabb)>,
    vertex_contacts: Vec<(u32, usize)>,
    /// Scratch: a shape's corners (`gather_corners`).
    shape_corners: Corners,
    /// Scratch: the colliders of a body's active contacts
    /// (`response::restitution::restitution_pass`).
    pub active_colliders: Vec<usize>,
    /// Impact episodes in progress (kept across frames).
    pub episodes: Episodes,
    /// Passivity episodes in progress (kept across frames, `response::passivity`).
    pub passivity: crate::response::passivity::Passivity,
    /// Scratch of the waking pass (`sleeping` module docs).
    pub waking: crate::sleeping::Waking,
    /// Frame length, s (the solver's, `begin_frame`).
    pub dt: f32,
    /// Magnitude of the frame's gravity, m/s².
    pub gravity: f32,
    /// rapier's allowed linear error (its contacts' slop), m: the least *resting reach* of an
    /// anchored body (`contacts::support` module docs).
    pub rigid_slop: f32,
    pub stats: CouplingStats,
}

/// What candidate gathering needs besides the frame.
pub(crate) struct GatherInput<'q, 'a> {
    pub qp: &'q QueryPipeline<'a>,
    pub narrow_phase: &'q NarrowPhase,
    pub impulse_joints: &'q ImpulseJointSet,
    pub multibody_joints: &'q MultibodyJointSet,
    pub default_collider: &'q SoftCollider,
    pub margin: f32,
    /// The soft–soft contact margin, m (`None`: soft–soft contacts off).
    pub soft_margin: Option<f32>,
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
        self.bodies.push(BodyProxy::new(
            handle,
            rb,
            start,
            (self.dt, self.gravity),
            supported,
        ));
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
            rule: self.mesh_rules.rule(handle, co.shape()),
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
    }

    /// Makes every dynamic body taking part that a joint locks in all six degrees of freedom
    /// to a fixed or kinematic body *welded* (immovable inside the substeps, its soft
    /// reaction handed to rapier), one whose joint to such a body locks its rotation and
    /// some of its translation *sliding* along the free axes, and one whose joint to such a
    /// body locks its translation and leaves it one or three rotations (revolute, spherical)
    /// *pivoting* about the joint's anchor (`joints` module docs, "Welded, sliding and
    /// pivoting bodies").
    /// The joint a pivoting body pivots on holds by construction and is not projected
    /// ([`Self::gather_joints`]).
    pub(crate) fn weld_jointed_bodies(&mut self, input: &GatherInput<'_, '_>) {
        self.joint_keys.clear();
        for b in 0..self.bodies.len() {
            if !self.bodies[b].is_dynamic() {
                continue;
            }
            let Some((restriction, key)) = restriction(self.bodies[b].handle, input) else {
                continue;
            };
            match restriction {
                Restriction::Weld => self.bodies[b].weld(),
                Restriction::Slide(free) => self.bodies[b].slide(&free),
                Restriction::Pivot(anchor, axis, (other, at)) => {
                    let q = input.qp.bodies;
                    let Some(o) = self.body_proxy(other, q, input.narrow_phase) else {
                        continue;
                    };
                    let (start, end) = self.bodies[o].frame_poses();
                    let path = (start * at, end * at);
                    self.bodies[b].pivot(anchor, axis, (path.0.coords, path.1.coords));
                }
            }
            if self.bodies[b].is_pivoting() {
                self.joint_keys.push(key);
            }
        }
    }

    /// The joints of the dynamic bodies taking part (`joints` module docs), but for those
    /// already in `joint_keys` ([`Self::weld_jointed_bodies`]); the other body of a joint gets
    /// a proxy if it has none.
    pub(crate) fn gather_joints(&mut self, input: &GatherInput<'_, '_>) {
        self.joints.clear();
        let n = self.bodies.len();
        for b in 0..n {
            if !self.bodies[b].is_dynamic() {
                continue;
            }
            let handle = self.bodies[b].handle;
            let joints = joints_of(handle, input.impulse_joints, input.multibody_joints);
            for (h1, h2, key, joint) in joints {
                if self.joint_keys.contains(&key) {
                    continue;
                }
                let (Some(p1), Some(p2)) = (
                    self.body_proxy(h1, input.qp.bodies, input.narrow_phase),
                    self.body_proxy(h2, input.qp.bodies, input.narrow_phase),
                ) else {
                    continue;
                };
                if let Some(run) = JointRun::new(joint, p1, p2) {
                    self.joint_keys.push(key);
                    self.joints.push(run);
                }
            }
        }
    }
}

/// How a joint to an immovable body restricts a dynamic body inside the substeps (`joints`
/// module docs, "Welded, sliding and pivoting bodies").
enum Restriction {
    /// Locked in all six degrees of freedom.
    Weld,
    /// Rotation locked, translation free along the projector's range (world).
    Slide(Matrix3<f32>),
    /// Translation locked at the anchor (m, the body's frame); rotation free about the unit
    /// axis (world) of a hinge, or about any axis (`None`); the immovable body and the
    /// anchor in its frame (m).
    Pivot(
        Vector3<f32>,
        Option<Vector3<f32>>,
        (RigidBodyHandle, nalgebra::Point3<f32>),
    ),
}

/// The restriction of the dynamic body `handle` by its first enabled joint to a fixed or
/// kinematic body that locks all its translations or all its rotations, and that joint's
/// key; a weld wins over the others.
fn restriction(
    handle: RigidBodyHandle,
    input: &GatherInput<'_, '_>,
) -> Option<(Restriction, (bool, u32, u32))> {
    let lin = [
        JointAxesMask::LIN_X,
        JointAxesMask::LIN_Y,
        JointAxesMask::LIN_Z,
    ];
    let ang = [
        JointAxesMask::ANG_X,
        JointAxesMask::ANG_Y,
        JointAxesMask::ANG_Z,
    ];
    let mut found = None;
    for (h1, h2, key, joint) in joints_of(handle, input.impulse_joints, input.multibody_joints) {
        let other = if h1 == handle { h2 } else { h1 };
        let immovable = input.qp.bodies.get(other).is_some_and(|o| !o.is_dynamic());
        let m = joint.locked_axes;
        if !joint.is_enabled() || !immovable {
            continue;
        }
        if m.contains(JointAxesMask::LOCKED_FIXED_AXES) {
            return Some((Restriction::Weld, key));
        }
        // Two such joints: the body can only move as both allow; keep the first and let
        // the second's projection hold the rest.
        if found.is_some() {
            continue;
        }
        let Some(b1) = input.qp.bodies.get(h1) else {
            continue;
        };
        let frame1 = pose_to_na(b1.position()) * pose_to_na(&joint.local_frame1);
        if m.contains(JointAxesMask::ANG_AXES) {
            // The projector onto the joint's free translations (first frame's axes).
            let free = (0..3)
                .filter(|&k| !m.contains(lin[k]))
                .fold(Matrix3::zeros(), |p, k| {
                    let a = frame1.rotation * Vector3::ith(k, 1.0);
                    p + a * a.transpose()
                });
            found = Some((Restriction::Slide(free), key));
        } else if m.contains(JointAxesMask::LIN_AXES) {
            let (local, far) = if h2 == handle {
                (&joint.local_frame2, &joint.local_frame1)
            } else {
                (&joint.local_frame1, &joint.local_frame2)
            };
            let anchor = crate::convert::to_na(local.translation);
            let far = nalgebra::Point3::from(crate::convert::to_na(far.translation));
            let free: usize = (0..3).filter(|&k| !m.contains(ang[k])).count();
            let axis = match free {
                3 => None,
                1 => {
                    let k = (0..3).find(|&k| !m.contains(ang[k])).unwrap_or(0);
                    Some(frame1.rotation * Vector3::ith(k, 1.0))
                }
                _ => continue,
            };
            found = Some((Restriction::Pivot(anchor, axis, (other, far)), key));
        }
    }
    found
}
