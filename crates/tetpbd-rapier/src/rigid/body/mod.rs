//! Rigid bodies inside the soft substeps: one proxy per body a soft body touches.
//!
//! rapier has already advanced every body from its start pose `P₀` (velocity `v₀`) to its
//! end pose `P₁` (velocity `v₁`) when the soft substeps run. Inside substep `k`, at
//! `t = (k+1)·h`, a body stands at its *base* pose composed with an *offset* that the soft
//! contacts and attachments build up: a centre-of-mass translation `dx` and a rotation `dq`,
//! each moving on with its own velocity (`dv`, `dω`), as XPBD integrates a rigid body (Müller
//! et al. 2020). Fixed and kinematic bodies never get an offset (infinite mass).
//!
//! The base of a kinematic body is the linear interpolation `P₀ → P₁`. The base of a
//! dynamic body spreads rapier's velocity change `a·dt = v₁ − v₀` (gravity, rigid contacts,
//! joints) evenly over the substeps, integrated like the soft particles (symplectic Euler):
//! in the substep ending at `t` its velocity is `v₀ + a·t` and `c(t) = c₀ + v₀t + ½a·t(t + h)`;
//! the rotation is interpolated. A heavy body resting on a soft one is then pushed by its
//! weight a little every substep instead of hitting the soft body with a frame's worth of
//! gravity at once, and the soft impulse balances exactly `m·g·dt` per frame at rest. The end
//! position differs from rapier's `c₀ + v₁dt` by `½a·dt(dt − h)`; only bodies a soft body
//! actually touched are written back.
//!
//! rapier's end pose also holds what its contacts did by moving the body rather than by
//! changing its velocity: a fast body that hit the ground in rapier's step can end at the
//! ground with its velocity barely changed, and the path above would then run up to a
//! frame's travel into the ground, pushing whatever soft body lies there with it. So when
//! the path's end misses rapier's centre of mass `c₁` by more than the body's smooth
//! accelerations (gravity, user force) could explain over the frame, `|D| > a_s dt²` with
//! `D = c₁ − c(dt)`, the miss is taken as a velocity change at the frame's start:
//! `v₀ ← v₀ + D/dt` and `v₁ ← v₁ + D/dt`, so the path ends at `c₁` and its velocities stay
//! those of its positions. Motion under smooth forces is left as it is.
//!
//! A dynamic body in contact with other rigid colliders is *supported*: infinitely heavy
//! inside the substeps, its summed soft reaction handed to rapier as a force for its next
//! step. One that also carries an attachment is *anchored* (`contacts::support` module docs): it
//! takes part with its mass, except while its supports hold it against the soft load and
//! against impulses pressing it into supports it stands on.

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use rapier3d::dynamics::{RigidBody, RigidBodyHandle};

mod anchored;
mod impulses;
mod link;
mod pivoting;

use crate::convert::{inertia_to_na, pose_to_glam, to_glam, to_na};

/// A body's pose (m, rad) and linear velocity (m/s) before rapier's step.
pub(crate) type StartState = (Isometry3<f32>, Vector3<f32>);

/// Clearance (m) up to which an anchored body stands on its supports.
const TOUCH: f32 = 1e-6;

/// How a body takes part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BodyKind {
    Fixed,
    Kinematic,
    /// Dynamic, touched only by soft bodies, or *anchored* (supported and carrying an
    /// attachment, its rigid contacts kept as constraints: `contacts::support` module docs): takes
    /// part with its generalized inverse mass.
    Dynamic,
    /// Dynamic and in contact with other rigid colliders: infinitely heavy inside the soft
    /// substeps; the soft reaction is summed as an impulse and handed to rapier.
    Supported,
}

/// One rigid body during the soft substeps of a frame.
#[derive(Clone, Debug)]
pub(crate) struct BodyProxy {
    pub handle: RigidBodyHandle,
    pub kind: BodyKind,
    com_local: Vector3<f32>,
    com_start: Vector3<f32>,
    com_end: Vector3<f32>,
    rot_start: UnitQuaternion<f32>,
    rot_end: UnitQuaternion<f32>,
    v_start: Vector3<f32>,
    w_base: Vector3<f32>,
    v_end: Vector3<f32>,
    w_end: Vector3<f32>,
    dt: f32,
    h: f32,
    inv_mass: Matrix3<f32>,
    inv_inertia: Matrix3<f32>,
    dx: Vector3<f32>,
    dq: UnitQuaternion<f32>,
    dv: Vector3<f32>,
    dw: Vector3<f32>,
    dx_sub: Vector3<f32>,
    dq_sub: UnitQuaternion<f32>,
    frac: f32,
    /// Pose at the end of the current substep (after corrections so far).
    pub pose: Isometry3<f32>,
    /// Pose at the end of the previous substep.
    pub prev: Isometry3<f32>,
    /// Whether a soft correction moved the body this frame.
    pub touched: bool,
    /// How far the body moves along its path in the current substep: the shift of its
    /// origin (m) and its turn (rad), from `prev` to `pose` before soft corrections.
    pub substep_motion: (f32, f32),
    sub_impulse: Vector3<f32>,
    sub_angular: Vector3<f32>,
    impulse: Vector3<f32>,
    angular: Vector3<f32>,
    /// Mean contact normal of an anchored body's rigid supports (unit, towards the body;
    /// zero for any other body): the soft load they hold and impulses pressing the body
    /// into them are left to them (`contacts::support` module docs).
    support_normal: Vector3<f32>,
    /// An anchored body's clearance above its supports (m, the smallest support constraint value,
    /// `contacts::support` module docs) when it was last measured, and its centre of mass then.
    clearance: (f32, Vector3<f32>),
    /// The soft positional impulses on an anchored body (kg·m), moving it or not, summed
    /// over the current and over the previous substep.
    soft_load: (Vector3<f32>, Vector3<f32>),
    /// The smallest friction coefficient of an anchored body's supports.
    friction: f32,
    /// Whether an anchored body is held on its supports in this substep ([`Self::hold`]).
    held: bool,
    /// An anchored body's resting reach in this substep, m ([`Self::hold`]).
    reach: f32,
    /// How far an anchored body's farthest support point lies from its centre of mass, m.
    support_radius: f32,
    /// Linear and angular velocity at the start of the current substep (before any soft
    /// correction), and the centre of mass they refer to.
    pre: (Vector3<f32>, Vector3<f32>, Vector3<f32>),
    /// Magnitude of the body's smooth acceleration over the frame (gravity times its
    /// scale, its user force over its mass), m/s².
    smooth_accel: f32,
    /// Whether the base path has been made to end at rapier's centre of mass (module docs;
    /// done in the frame's first substep, whose length the path depends on).
    ends_at_rapier: bool,
    /// The pivot of a pivoting body (`pivoting` module docs).
    pivot: Option<pivoting::Pivot>,
}

impl BodyKind {
    /// How `body` takes part; `supported`: rapier reports it in contact with other rigid
    /// colliders.
    fn of(body: &RigidBody, supported: bool) -> BodyKind {
        if body.is_dynamic() && supported {
            BodyKind::Supported
        } else if body.is_dynamic() {
            BodyKind::Dynamic
        } else if body.is_kinematic() {
            BodyKind::Kinematic
        } else {
            BodyKind::Fixed
        }
    }
}

/// Effective inverse mass (world, 1/kg) and world inverse inertia (1/(kg·m²)) of a dynamic
/// body; zero for the others.
fn inverse_mass(body: &RigidBody) -> (Matrix3<f32>, Matrix3<f32>) {
    if body.is_dynamic() {
        let mp = body.mass_properties();
        (
            Matrix3::from_diagonal(&to_na(mp.effective_inv_mass)),
            inertia_to_na(&mp.effective_world_inv_inertia),
        )
    } else {
        (Matrix3::zeros(), Matrix3::zeros())
    }
}

impl BodyProxy {
    /// A proxy of `body`, whose pose before rapier's step was `start` (m, rad).
    /// `gravity` is the magnitude of the scene's gravity, m/s².
    pub fn new(
        handle: RigidBodyHandle,
        body: &RigidBody,
        (start, v_start): (Isometry3<f32>, Vector3<f32>),
        (dt, gravity): (f32, f32),
        supported: bool,
    ) -> Self {
        let kind = BodyKind::of(body, supported);
        let end = crate::convert::pose_to_na(body.position());
        let start = if kind == BodyKind::Fixed { end } else { start };
        let com_local = to_na(body.local_center_of_mass());
        let com_start = start * nalgebra::Point3::from(com_local);
        let com_end = end * nalgebra::Point3::from(com_local);
        let v_end = to_na(body.linvel());
        let (v_start, v_end_base, w_base) = match kind {
            BodyKind::Fixed => (Vector3::zeros(), Vector3::zeros(), Vector3::zeros()),
            BodyKind::Kinematic => {
                let v = (com_end.coords - com_start.coords) / dt;
                (
                    v,
                    v,
                    (end.rotation * start.rotation.inverse()).scaled_axis() / dt,
                )
            }
            BodyKind::Dynamic | BodyKind::Supported => (
                v_start,
                v_end,
                (end.rotation * start.rotation.inverse()).scaled_axis() / dt,
            ),
        };
        let (inv_mass, inv_inertia) = inverse_mass(body);
        let mass = body.mass();
        let force = if mass > 0.0 {
            body.user_force().length() / mass
        } else {
            0.0
        };
        let smooth_accel = gravity * body.gravity_scale().abs() + force;
        BodyProxy {
            handle,
            kind,
            com_local,
            com_start: com_start.coords,
            com_end: com_end.coords,
            rot_start: start.rotation,
            rot_end: end.rotation,
            v_start,
            w_base,
            v_end: v_end_base,
            dt,
            h: dt,
            w_end: to_na(body.angvel()),
            inv_mass,
            inv_inertia,
            dx: Vector3::zeros(),
            dq: UnitQuaternion::identity(),
            dv: Vector3::zeros(),
            dw: Vector3::zeros(),
            dx_sub: Vector3::zeros(),
            dq_sub: UnitQuaternion::identity(),
            frac: 0.0,
            pose: start,
            prev: start,
            touched: false,
            substep_motion: (0.0, 0.0),
            sub_impulse: Vector3::zeros(),
            sub_angular: Vector3::zeros(),
            impulse: Vector3::zeros(),
            angular: Vector3::zeros(),
            support_normal: Vector3::zeros(),
            clearance: (0.0, Vector3::zeros()),
            soft_load: (Vector3::zeros(), Vector3::zeros()),
            friction: 0.0,
            held: false,
            reach: TOUCH,
            support_radius: 0.0,
            pre: (Vector3::zeros(), Vector3::zeros(), Vector3::zeros()),
            smooth_accel,
            ends_at_rapier: false,
            pivot: None,
        }
    }

    /// [`Self::inv_mass_at`] for a constraint that pushes the body along `push`: 0 when the
    /// push does not move it.
    pub fn inv_mass_pushed(&self, q: &Vector3<f32>, push: &Vector3<f32>) -> f32 {
        if !self.moves(push, q) {
            return 0.0;
        }
        self.inv_mass_at(q, &push.try_normalize(1e-12).unwrap_or_default())
    }

    /// `true` for a dynamic body (finite mass in rapier).
    pub fn is_dynamic(&self) -> bool {
        matches!(self.kind, BodyKind::Dynamic | BodyKind::Supported)
    }

    /// Moves to the end of the next substep; `frac` is its end time as a fraction of the frame.
    pub fn begin_substep(&mut self, frac: f32, h: f32) {
        self.h = h;
        if !self.ends_at_rapier {
            self.ends_at_rapier = true;
            self.end_at_rapier();
        }
        self.prev = self.pose;
        self.soft_load = (Vector3::zeros(), self.soft_load.0);
        self.held = false;
        if self.kind == BodyKind::Dynamic {
            self.dx_sub = self.dx;
            self.dq_sub = self.dq;
            self.dx += self.dv * h;
            self.dq = UnitQuaternion::from_scaled_axis(self.dw * h) * self.dq;
        }
        self.set_pose(frac);
        self.record_substep_start();
    }

    /// Records how far the body moves in the current substep and its velocity at the start.
    fn record_substep_start(&mut self) {
        self.substep_motion = if self.kind == BodyKind::Fixed {
            (0.0, 0.0)
        } else {
            (
                (self.pose.translation.vector - self.prev.translation.vector).norm(),
                self.pose.rotation.angle_to(&self.prev.rotation),
            )
        };
        if self.kind != BodyKind::Fixed {
            self.pre = (
                self.v_start.lerp(&self.v_end, self.frac) + self.dv,
                self.w_base + self.dw,
                self.com(),
            );
        }
    }

    /// Velocity of the material point at `q` at the start of the current substep, before
    /// any soft correction of the substep, m/s.
    pub fn velocity_at_pre(&self, q: &Vector3<f32>) -> Vector3<f32> {
        let (v, w, com) = self.pre;
        v + w.cross(&(q - com))
    }

    fn set_pose(&mut self, frac: f32) {
        if self.kind == BodyKind::Fixed {
            self.pose = Isometry3::from_parts(
                Translation3::from(self.com_end - self.rot_end * self.com_local),
                self.rot_end,
            );
            return;
        }
        self.frac = frac;
        let (base_com, base_rot) = self.base_at(frac);
        if let Some(com) = self.pivot_com(frac, &base_rot) {
            self.dx = com - base_com;
        }
        let com = base_com + self.dx;
        let rot = self.dq * base_rot;
        self.pose = Isometry3::from_parts(Translation3::from(com - rot * self.com_local), rot);
    }

    /// The centre of mass on the base path at time `t` of the frame, s (module docs).
    fn base_com(&self, t: f32) -> Vector3<f32> {
        self.com_start
            + self.v_start * t
            + (self.v_end - self.v_start) * (0.5 * t * (t + self.h) / self.dt)
    }

    /// Takes a miss of rapier's end centre of mass that the smooth accelerations do not
    /// explain as a velocity change at the frame's start (module docs).
    fn end_at_rapier(&mut self) {
        if !matches!(self.kind, BodyKind::Dynamic | BodyKind::Supported) {
            return;
        }
        let miss = self.com_end - self.base_com(self.dt);
        let explained = self.smooth_accel * self.dt * self.dt;
        let len = miss.norm();
        if len.is_finite() && len > explained {
            let dv = miss / self.dt;
            self.v_start += dv;
            self.v_end += dv;
        }
    }

    /// Poses before and after rapier's step (no soft offsets).
    pub fn frame_poses(&self) -> (Isometry3<f32>, Isometry3<f32>) {
        let at = |com: Vector3<f32>, rot: UnitQuaternion<f32>| {
            Isometry3::from_parts(Translation3::from(com - rot * self.com_local), rot)
        };
        (
            at(self.com_start, self.rot_start),
            at(self.com_end, self.rot_end),
        )
    }

    /// Centre of mass (m) and rotation on the base path at `frac` of the frame.
    fn base_at(&self, frac: f32) -> (Vector3<f32>, UnitQuaternion<f32>) {
        (
            self.base_com(frac * self.dt),
            self.rot_start.nlerp(&self.rot_end, frac),
        )
    }

    /// The pose on the base path (no soft offsets) at the end of the current substep.
    pub fn base_pose(&self) -> Isometry3<f32> {
        if self.kind == BodyKind::Fixed {
            return self.frame_poses().1;
        }
        let (com, rot) = self.base_at(self.frac);
        Isometry3::from_parts(Translation3::from(com - rot * self.com_local), rot)
    }

    /// Distance (m) of the body-frame point `local` from the centre of mass.
    pub fn distance_from_com(&self, local: &Vector3<f32>) -> f32 {
        (local - self.com_local).norm()
    }

    /// Current world centre of mass, m.
    pub fn com(&self) -> Vector3<f32> {
        self.pose.translation.vector + self.pose.rotation * self.com_local
    }

    /// Ends a substep: the offset velocities follow from the offset motion.
    pub fn end_substep(&mut self, h: f32) {
        if self.kind == BodyKind::Supported {
            self.impulse += self.sub_impulse / h;
            self.angular += self.sub_angular / h;
            self.sub_impulse = Vector3::zeros();
            self.sub_angular = Vector3::zeros();
        }
        if self.kind != BodyKind::Dynamic {
            return;
        }
        self.h = h;
        self.dv = (self.dx - self.dx_sub) / h;
        self.dw = (self.dq * self.dq_sub.inverse()).scaled_axis() / h;
    }

    /// Velocity of the body's material point at the world point `q`, m/s.
    pub fn velocity_at(&self, q: &Vector3<f32>) -> Vector3<f32> {
        match self.kind {
            BodyKind::Fixed => Vector3::zeros(),
            _ => {
                let w = self.w_base + self.dw;
                let v_base = self.v_start.lerp(&self.v_end, self.frac);
                v_base + self.dv + w.cross(&(q - self.com()))
            }
        }
    }

    /// Velocity (m/s) and angular velocity (rad/s) the body ends the frame with.
    pub fn final_velocity(&self) -> (Vector3<f32>, Vector3<f32>) {
        (self.v_end + self.dv, self.w_end + self.dw)
    }

    /// Force (N) and torque about the centre of mass (N·m) that carry the summed soft
    /// impulse on a supported body through rapier's next step (the impulse of this frame
    /// spread over `dt`); `None` for any other body or when there is none.
    pub fn load(&self) -> Option<(Vector3<f32>, Vector3<f32>)> {
        (self.kind == BodyKind::Supported
            && self.touched
            && (self.impulse != Vector3::zeros() || self.angular != Vector3::zeros()))
        .then(|| (self.impulse / self.dt, self.angular / self.dt))
    }

    /// Writes the result back to rapier: for a body that took part with its mass its final
    /// pose and velocity (`v₁` plus the offset's); the [`Self::load`] of a supported body
    /// as a force and torque added for rapier's next step (the caller takes
    /// them off again after that step). A force, not a velocity change: rapier's solver
    /// applies it in its substeps together with the rigid contacts, as it does gravity, where
    /// a velocity change of the same impulse is an impact (a 100 kg soft body resting on a
    /// 0.125 kg box hands it about 100 m/s per frame, which rapier's contacts do not cancel
    /// cleanly). Returns `false` (and writes nothing) when the result is not finite.
    pub fn write_back(&self, body: &mut RigidBody, soft_asleep: bool) -> bool {
        if !self.touched {
            return true;
        }
        let finite = |x: &Vector3<f32>| x.iter().all(|c| c.is_finite());
        let load = self.load();
        if load.is_some_and(|(f, t)| !(finite(&f) && finite(&t))) {
            return false;
        }
        // Sleeping (`sleeping` module docs): a body whose soft bodies all fell asleep with
        // it is written and put to sleep with them; otherwise it is written and kept awake.
        match self.kind {
            BodyKind::Dynamic => {
                let (v, w, p) = (self.v_end + self.dv, self.w_end + self.dw, self.pose);
                if !(finite(&v)
                    && finite(&w)
                    && finite(&p.translation.vector)
                    && p.rotation.coords.iter().all(|c| c.is_finite()))
                {
                    return false;
                }
                body.set_position(pose_to_glam(&p), true);
                body.set_linvel(to_glam(&v), true);
                body.set_angvel(to_glam(&w), true);
            }
            BodyKind::Supported => {}
            BodyKind::Fixed | BodyKind::Kinematic => return true,
        }
        if let Some((force, torque)) = load {
            body.add_force(to_glam(&force), true);
            body.add_torque(to_glam(&torque), true);
        }
        if soft_asleep {
            body.sleep();
        }
        true
    }
}
