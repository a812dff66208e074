//! What a rigid proxy gives way by: its generalized inverse masses, and the position,
//! support, angular and velocity impulses the soft contacts and attachments apply to it
//! (module docs of [`super`]).

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::{BodyKind, BodyProxy};

impl BodyProxy {
    /// Generalized inverse mass `nᵀM⁻¹n + (r×n)ᵀ I⁻¹ (r×n)` for a unit direction `n` at the
    /// world point `q`, 1/kg; 0 for fixed and kinematic bodies.
    pub fn inv_mass_at(&self, q: &Vector3<f32>, n: &Vector3<f32>) -> f32 {
        if self.kind != BodyKind::Dynamic {
            return 0.0;
        }
        if let Some(w) = self.pivot_inv_mass_at(q, n) {
            return w;
        }
        let rn = (q - self.com()).cross(n);
        n.dot(&(self.inv_mass * n)) + rn.dot(&(self.inv_inertia * rn))
    }

    /// Generalized inverse mass `aᵀ I⁻¹ a` of a rotation about the unit axis `a` (world),
    /// 1/(kg·m²); 0 for fixed and kinematic bodies.
    pub fn inv_inertia_along(&self, a: &Vector3<f32>) -> f32 {
        if self.kind != BodyKind::Dynamic {
            return 0.0;
        }
        match self.pivot_turn_angular(a) {
            Some(turn) => a.dot(&turn),
            None => a.dot(&(self.inv_inertia * a)),
        }
    }

    /// Turns the body by the angular positional impulse `l` (kg·m²·rad: axis × Δλ) of a
    /// joint (`joints` module docs); fixed and kinematic bodies do not move.
    pub fn apply_angular_impulse(&mut self, l: &Vector3<f32>) {
        if self.kind != BodyKind::Dynamic {
            return;
        }
        let dtheta = self
            .pivot_turn_angular(l)
            .unwrap_or_else(|| self.inv_inertia * l);
        self.turn_offset(&dtheta);
    }

    /// Turns the offset rotation by `dtheta` (rad, world) and moves the pose to it.
    fn turn_offset(&mut self, dtheta: &Vector3<f32>) {
        let dq = Quaternion::from_parts(0.0, *dtheta) * self.dq.into_inner() * 0.5;
        self.dq = UnitQuaternion::new_normalize(self.dq.into_inner() + dq);
        self.touched = true;
        let frac = self.frac;
        self.set_pose(frac);
    }

    /// Applies a soft positional impulse `p` (kg·m: direction × Δλ) at the world point `q`.
    /// An anchored body ignores it when it does not move the body ([`Self::moves`]), and
    /// one pressing it into its supports moves it at most down to them.
    pub fn apply_position_impulse(&mut self, p: &Vector3<f32>, q: &Vector3<f32>) {
        if self.is_anchored() {
            self.soft_load.0 += p;
            if !self.moves(p, q) {
                return;
            }
            let sink = -self.support_normal.dot(&(self.inv_mass * p));
            let room = self.clearance();
            if self.presses(p) && sink > room {
                self.apply_support_impulse(&(p * (room / sink)), q);
                return;
            }
        }
        self.apply_support_impulse(p, q);
    }

    /// Applies a positional impulse `p` (kg·m) of an anchored body's support (or a soft one
    /// that moves the body) at the world point `q`.
    pub fn apply_support_impulse(&mut self, p: &Vector3<f32>, q: &Vector3<f32>) {
        if self.kind == BodyKind::Supported {
            self.sub_impulse += p;
            self.sub_angular += (q - self.com()).cross(p);
            self.touched = true;
            return;
        }
        if self.kind != BodyKind::Dynamic {
            return;
        }
        if let Some(turn) = self.pivot_turn(p, q) {
            self.turn_offset(&turn);
            return;
        }
        let dtheta = self.inv_inertia * (q - self.com()).cross(p);
        self.dx += self.inv_mass * p;
        self.turn_offset(&dtheta);
    }

    /// Applies a velocity impulse `j` (N·s) at the world point `q` (an anchored body ignores
    /// one that does not move it, [`Self::moves`]).
    pub fn apply_velocity_impulse(&mut self, j: &Vector3<f32>, q: &Vector3<f32>) {
        if !self.moves(j, q) {
            return;
        }
        if self.kind == BodyKind::Supported {
            self.impulse += j;
            self.angular += (q - self.com()).cross(j);
            self.touched = true;
            return;
        }
        if self.kind != BodyKind::Dynamic || self.pivot_velocity_impulse(j, q) {
            return;
        }
        self.dv += self.inv_mass * j;
        self.dw += self.inv_inertia * (q - self.com()).cross(j);
        self.touched = true;
    }
}
