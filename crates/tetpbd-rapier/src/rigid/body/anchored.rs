//! An anchored body against its supports (`contacts::support` module docs): when it
//! stands on them, whether a push presses it into them, and when they hold it.

use nalgebra::Vector3;

use super::{BodyKind, BodyProxy, TOUCH};

impl BodyProxy {
    /// Makes a supported body *anchored* (`contacts::support` module docs): it takes part with its
    /// generalized inverse mass, except while its supports hold it ([`Self::hold`]) and
    /// against impulses pressing it into supports it stands on; `normal` is their mean
    /// contact normal (towards the body), `friction` their smallest friction coefficient,
    /// `radius` the distance of the farthest support point from the centre of mass (m).
    /// It is written back every frame, which also keeps rapier from putting it to sleep:
    /// left at rapier's result in a frame where the soft body only pressed it into its
    /// supports, a light box holding a heavy soft body diverges within seconds.
    pub fn anchor(&mut self, normal: Vector3<f32>, friction: f32, radius: f32) {
        if self.kind == BodyKind::Supported {
            self.support_radius = radius;
            self.friction = friction;
            self.kind = BodyKind::Dynamic;
            self.touched = true;
            self.support_normal = normal.try_normalize(1e-6).unwrap_or_default();
        }
    }

    /// Makes a dynamic body *welded* (`joints` module docs): a joint holds it rigidly to a
    /// fixed or kinematic body, so inside the substeps it follows rapier's path as a
    /// supported body does, infinitely heavy, its soft reaction summed for rapier's next
    /// step, and it stops being anchored.
    pub fn weld(&mut self) {
        if self.is_dynamic() {
            self.kind = BodyKind::Supported;
            self.touched = true;
            self.support_normal = Vector3::zeros();
        }
    }

    /// Restricts a dynamic body that a joint holds to an immovable body without letting it
    /// turn to sliding along the joint's free translations, `project` the orthogonal
    /// projector onto them (world; `joints` module docs, "Welded, sliding and pivoting bodies"): soft
    /// impulses move it only along them and never turn it.
    pub fn slide(&mut self, project: &nalgebra::Matrix3<f32>) {
        if self.kind != BodyKind::Dynamic {
            return;
        }
        self.inv_mass = project * self.inv_mass * project;
        self.inv_inertia = nalgebra::Matrix3::zeros();
    }

    /// Records an anchored body's clearance `gap` (m) above its supports at its current pose.
    pub fn set_clearance(&mut self, gap: f32) {
        self.clearance = (gap, self.com());
    }

    /// Lowers the recorded clearance to `gap` (m) if it is smaller.
    pub fn lower_clearance(&mut self, gap: f32) {
        self.clearance.0 = self.clearance.0.min(gap);
    }

    /// The anchored body's clearance above its supports now, m: the last measured one plus
    /// the motion of its centre of mass along their mean normal since (its turn is left out).
    pub(super) fn clearance(&self) -> f32 {
        let (gap, com) = self.clearance;
        gap + self.support_normal.dot(&(self.com() - com))
    }

    /// `true` for an anchored body.
    pub(super) fn is_anchored(&self) -> bool {
        self.kind == BodyKind::Dynamic && self.support_normal != Vector3::zeros()
    }

    /// `true` for an anchored body its supports hold in this substep ([`Self::hold`]): no
    /// soft impulse moves it, so for the soft bodies on it it is as immovable as the ground.
    pub fn is_held(&self) -> bool {
        self.is_anchored() && self.held
    }

    /// Whether an impulse along `push` presses an anchored body into its supports (more
    /// than 60° against their mean normal).
    pub(super) fn presses(&self, push: &Vector3<f32>) -> bool {
        self.support_normal.dot(push) < -0.5 * push.norm()
    }

    /// Whether a soft impulse along `push` at the world point `q` moves the body: not on an
    /// anchored body that is held, nor when it presses an anchored body that stands on its
    /// supports — unless the body's point `q` comes at what pushes it ([`Self::rams`]).
    pub(super) fn moves(&self, push: &Vector3<f32>, q: &Vector3<f32>) -> bool {
        !self.is_anchored()
            || !(self.held
                || (self.presses(push) && self.clearance() <= TOUCH && !self.rams(push, q)))
    }

    /// Whether the body's material point at `q` comes at what pushes it back along `push`
    /// faster than a body at rest on its supports moves (its resting reach per substep,
    /// velocity taken at the substep's start). Such a body is not standing still: left
    /// immovable, it would push the soft side away at its own speed with infinite mass and
    /// give it energy no load explains (`contacts::support` module docs, *Only a body at
    /// rest is immovable*).
    fn rams(&self, push: &Vector3<f32>, q: &Vector3<f32>) -> bool {
        let Some(dir) = push.try_normalize(1e-12) else {
            return false;
        };
        -self.velocity_at_pre(q).dot(&dir) * self.h > self.reach
    }

    /// How far from its supports (m) an anchored body still rests on them when a substep
    /// starts (`contacts::support` module docs, *resting reach*): rapier's allowed linear
    /// error `slop` (m), or what its smooth acceleration (gravity, user force) moves it in one
    /// substep of `h`, `a_s h²`, whichever is larger, and at least 1 µm.
    fn resting_reach(&self, slop: f32) -> f32 {
        TOUCH.max(slop).max(self.smooth_accel * self.h * self.h)
    }

    /// Starts a substep of an anchored body, its clearance measured at its new pose: it is
    /// *held* when it rests on its supports — its clearance within its resting reach (`slop`
    /// rapier's allowed linear error, m), and no point as far from its centre of mass as its
    /// farthest support point ([`Self::anchor`]) moving by more than that reach in the
    /// substep — and the soft impulses of the previous substep, summed, lie in their friction
    /// cone (pressing it into them, their tangential part at most μ times their normal part).
    /// A held body keeps its offset from the previous substep (it moves along rapier's path
    /// only) and soft impulses do not move it.
    pub fn hold(&mut self, slop: f32) {
        self.reach = self.resting_reach(slop);
        let n = self.support_normal;
        let load = self.soft_load.1;
        let press = -n.dot(&load);
        let (v, w, _) = self.pre;
        let speed = v.norm() + w.norm() * self.support_radius;
        self.held = self.is_anchored()
            && self.clearance() <= self.reach
            && speed * self.h <= self.reach
            && press >= 0.0
            && (load + n * press).norm() <= self.friction * press;
        if self.held {
            self.dx = self.dx_sub;
            self.dq = self.dq_sub;
            self.dv = Vector3::zeros();
            self.dw = Vector3::zeros();
            let frac = self.frac;
            self.set_pose(frac);
            self.record_substep_start();
        }
    }
}
