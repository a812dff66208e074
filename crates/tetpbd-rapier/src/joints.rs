//! rapier's joints inside the soft substeps.
//!
//! rapier solves a body's joints in its own step; inside the soft substeps the body used to
//! move freely under the soft reactions, and the joint only pulled it back at rapier's next
//! step. An attachment is bilateral, so a box hanging on a joint with a soft beam attached
//! was dragged off its anchor by the beam in every frame: 0.22 m after 3 s on a spherical
//! joint (fixed joint: 0.62 m), growing about linearly. So every impulse joint and
//! multibody joint of a dynamic body taking part in the substeps is also a constraint
//! there, projected after the contacts, attachments and supports of every iteration.
//!
//! With the joint frames `F₁ = P₁·f₁`, `F₂ = P₂·f₂` (the bodies' poses and rapier's local
//! frames), as position-based joints (Müller et al. 2020):
//!
//! ```text
//! linear:  d = Σ_locked ((o₂ − o₁)·eᵢ) eᵢ,  eᵢ the axes of F₁;  C = |d|,  n = d / |d|
//!          Δλ = −C / (w₁(n) + w₂(n)),  body 2 gets n·Δλ at o₂, body 1 −n·Δλ at o₁
//! angular: 3 axes locked: θ = axis-angle of R(F₁)·R(F₂)⁻¹;
//!          2 locked (a hinge about frame axis x): θ = (R(F₂)x) × (R(F₁)x);
//!          C = |θ|, a = θ/|θ|,  Δλ = −C / (aᵀI₁⁻¹a + aᵀI₂⁻¹a),  body 2 turns by −I₂⁻¹a·Δλ
//! ```
//!
//! `w(n)` is a body's generalized inverse mass at the anchor (0 for fixed and kinematic
//! bodies, which the constraint does not move). Limits, motors and a single locked angular
//! axis are left to rapier (its step still enforces them); a joint between two bodies
//! neither of which takes part in the substeps is not looked at.
//!
//! # Welded, sliding and pivoting bodies
//!
//! A dynamic body that a joint locks in all six degrees of freedom to a fixed or kinematic
//! body is *welded*: inside the substeps it follows rapier's path and is infinitely heavy, as
//! a supported body is before it is anchored, and the soft reaction it took is handed to
//! rapier as a force for its next step, where rapier's joint solver holds it. Projected as a
//! free proxy instead, a light welded box under a heavy soft body is pushed out of its joint
//! by the first contacts of each substep and pulled back by the joint after them, so the
//! contacts further on see a tilted surface; the soft body gains a little sideways velocity
//! every substep and creeps off. A 20 kg soft cube on a 2 kg box on a fixed joint slid off
//! within 2.5 s, its speed growing exponentially; welded, it stays put. The same holds for a
//! body whose joint to a fixed or kinematic body locks its rotation but leaves it translations
//! (a prismatic joint): inside the substeps it *slides*, moved by soft impulses only along the
//! free axes of the joint's first frame and never turned (its inverse mass projected onto
//! them, its inverse inertia zero). On a prismatic joint the cube crept 4.6 cm along a locked
//! axis in 2 s at 10:1 and 1.2 cm in 9 s at 3:1; sliding, it stays put.
//!
//! A body whose joint to a fixed or kinematic body locks its translation and leaves it one
//! rotation (revolute) or three (spherical) *pivots*: inside the substeps it only turns about
//! the joint's anchor (about the hinge axis only), with its inertia about the anchor, and its
//! anchor rides on the immovable body's (`rigid::body::pivoting` module docs); that joint is
//! not projected. Projected as a free proxy, a light hinged or ball-jointed box under a heavy
//! soft cube crept like the welded one: at 10:1 the cube slid off the hinged box and the box
//! left its joint by about 1 m. Pivoting, its anchor stays within 0.09 mm over 10 s in every
//! run of the sweep (mass ratios 1, 3, 10; 5, 10, 20 substeps; both constraint sets; impulse
//! and multibody joints), and the cube moves 2–5.3 mm on a hinged box at 10:1 and on a
//! ball-jointed one at 3:1 (10 substeps). Letting the body's anchor follow its own base path
//! instead of the immovable body's missed the anchor by the path's `½a·dt(dt − h)` every frame:
//! a ball-jointed box with a 0.2 kg beam crept 0.35 mm a second.
//!
//! A dynamic multibody link that takes part with its mass hands its change over the frame to
//! its multibody through its Jacobian (`rigid::body::link` module docs): rapier rebuilds a
//! link's pose and velocity from the multibody's coordinates, so writing them to the link's
//! rigid body, as before, lost the soft reaction (a soft beam did not swing a multibody
//! link; now it swings it within 0.2 rad of an impulse-jointed box over a 1.6 rad swing).
//!
//! Friction against a pivoting body is swept again after the iteration's other contacts
//! (`rigid::body::pivoting` module docs, "Friction on a pivoting body"): without it a soft
//! cube kept awake on a hinged or ball-jointed box crept downhill and tilted the box until it
//! slid off.
//!
//! Known limits. A soft cube 10 times heavier than a ball-jointed box at 5 substeps with
//! edges and volume tilts the box and slides off (the anchor holds). A soft body 100 or more
//! times heavier than a box on a *multibody* slider, or on one at 5 substeps, keeps jiggling
//! at 0.02–0.5 m/s (it stays on the box).

use nalgebra::{Isometry3, Vector3};
use rapier3d::dynamics::{
    GenericJoint, ImpulseJointSet, JointAxesMask, MultibodyJointSet, RigidBodyHandle,
};

use crate::convert::pose_to_na;

/// Sweeps over the joints per iteration.
const SWEEPS: usize = 2;

/// One joint during the soft substeps.
#[derive(Clone, Debug)]
pub(crate) struct JointRun {
    /// Proxies of the two bodies.
    pub bodies: [usize; 2],
    /// The joint's frames in each body's frame.
    frames: [Isometry3<f32>; 2],
    /// Locked linear axes (x, y, z of frame 1).
    linear: [bool; 3],
    /// Locked angular axes (x, y, z).
    angular: [bool; 3],
}

impl JointRun {
    /// The run of `joint` between proxies `b1` and `b2`; `None` for a disabled joint or one
    /// that locks nothing.
    pub fn new(joint: &GenericJoint, b1: usize, b2: usize) -> Option<Self> {
        if !joint.is_enabled() {
            return None;
        }
        let m = joint.locked_axes;
        let linear = [
            JointAxesMask::LIN_X,
            JointAxesMask::LIN_Y,
            JointAxesMask::LIN_Z,
        ]
        .map(|a| m.contains(a));
        let angular = [
            JointAxesMask::ANG_X,
            JointAxesMask::ANG_Y,
            JointAxesMask::ANG_Z,
        ]
        .map(|a| m.contains(a));
        (linear.iter().chain(&angular).any(|&l| l)).then(|| JointRun {
            bodies: [b1, b2],
            frames: [
                pose_to_na(&joint.local_frame1),
                pose_to_na(&joint.local_frame2),
            ],
            linear,
            angular,
        })
    }
}

/// The joints of rigid body `handle` as `(body 1, body 2, key, joint)`: impulse joints and
/// multibody joints (a link and its parent); `key` tells the same joint apart when it is
/// met from both bodies.
pub(crate) fn joints_of<'a>(
    handle: RigidBodyHandle,
    impulse: &'a ImpulseJointSet,
    multibody: &'a MultibodyJointSet,
) -> impl Iterator<
    Item = (
        RigidBodyHandle,
        RigidBodyHandle,
        (bool, u32, u32),
        &'a GenericJoint,
    ),
> + 'a {
    let imp = impulse.attached_joints(handle).map(|(b1, b2, h, j)| {
        let (i, g) = h.into_raw_parts();
        (b1, b2, (false, i, g), &j.data)
    });
    let mb = multibody
        .attached_joints(handle)
        .filter_map(move |(b1, b2, h)| {
            let (mb, link) = multibody.get(h)?;
            let joint = &mb.link(link)?.joint.data;
            let (i, g) = b2.into_raw_parts();
            Some((b1, b2, (true, i, g), joint))
        });
    imp.chain(mb)
}

/// One sweep over the joints: each projected once (module docs).
pub(crate) fn project_joints(joints: &[JointRun], bodies: &mut [crate::rigid::body::BodyProxy]) {
    for _ in 0..SWEEPS {
        for j in joints {
            let [a, b] = j.bodies;
            if a == b {
                continue;
            }
            project_angular(j, bodies);
            project_linear(j, bodies);
        }
    }
}

fn frames(j: &JointRun, bodies: &[crate::rigid::body::BodyProxy]) -> [Isometry3<f32>; 2] {
    let [a, b] = j.bodies;
    [bodies[a].pose * j.frames[0], bodies[b].pose * j.frames[1]]
}

fn project_linear(j: &JointRun, bodies: &mut [crate::rigid::body::BodyProxy]) {
    if !j.linear.iter().any(|&l| l) {
        return;
    }
    let [f1, f2] = frames(j, bodies);
    let (o1, o2) = (f1.translation.vector, f2.translation.vector);
    let delta = o2 - o1;
    let mut d = Vector3::zeros();
    for (k, &locked) in j.linear.iter().enumerate() {
        if locked {
            let e = f1.rotation * Vector3::ith(k, 1.0);
            d += e * delta.dot(&e);
        }
    }
    let c = d.norm();
    if c.is_nan() || c <= 1e-9 {
        return;
    }
    let n = d / c;
    let [a, b] = j.bodies;
    let w = bodies[a].inv_mass_at(&o1, &n) + bodies[b].inv_mass_at(&o2, &n);
    if w.is_nan() || w <= 0.0 {
        return;
    }
    let dl = -c / w;
    bodies[b].apply_support_impulse(&(n * dl), &o2);
    bodies[a].apply_support_impulse(&(-n * dl), &o1);
}

fn project_angular(j: &JointRun, bodies: &mut [crate::rigid::body::BodyProxy]) {
    let locked = j.angular.iter().filter(|&&l| l).count();
    let [f1, f2] = frames(j, bodies);
    let theta = match locked {
        3 => (f1.rotation * f2.rotation.inverse()).scaled_axis(),
        2 => {
            let free = j.angular.iter().position(|&l| !l).unwrap_or(0);
            let axis = Vector3::ith(free, 1.0);
            (f2.rotation * axis).cross(&(f1.rotation * axis))
        }
        _ => return,
    };
    let c = theta.norm();
    if c.is_nan() || c <= 1e-9 {
        return;
    }
    let axis = theta / c;
    let [a, b] = j.bodies;
    let w = bodies[a].inv_inertia_along(&axis) + bodies[b].inv_inertia_along(&axis);
    if w.is_nan() || w <= 0.0 {
        return;
    }
    let dl = -c / w;
    bodies[b].apply_angular_impulse(&(-axis * dl));
    bodies[a].apply_angular_impulse(&(axis * dl));
}
