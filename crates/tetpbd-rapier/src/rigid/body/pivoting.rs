//! A *pivoting* body (`joints` module docs, "Welded, sliding and pivoting bodies"): a dynamic
//! body on a spherical or revolute joint to a fixed or kinematic body. Inside the substeps it
//! moves only by rotation about the joint's anchor `a` (for a revolute joint only about the
//! hinge axis `e`), so the anchor never leaves rapier's path.
//!
//! With `I_a = I_c + m(|r|²𝟙 − r rᵀ)` its inertia about the anchor (`r = a − c`, parallel-axis
//! theorem), a positional impulse `J` (kg·m) at the point `p` turns it by
//!
//! ```text
//! Δθ = I_p⁻¹ ((p − a) × J),   I_p⁻¹ = I_a⁻¹ (ball joint),   I_p⁻¹ = e eᵀ / (eᵀ I_a e) (hinge)
//! ```
//!
//! and its centre of mass follows the rotation of the anchor offset: with `u = a − c` on the
//! body's base path and `δq` its offset rotation, `c = a − δq·u`, where `a` is the anchor
//! on the immovable body (moved linearly from its start to its end pose over the frame).
//! rapier's end pose holds the joint to its own precision, so the body's anchor stays on
//! it; following the base path's anchor instead, it missed it by the path's `½a·dt(dt − h)`
//! (`body` module docs) every frame, and a swinging box crept off its anchor by 0.4 mm a
//! second. Its generalized inverse
//! mass at `p` along the unit `n` is `w = ((p − a) × n)ᵀ I_p⁻¹ ((p − a) × n)` (1/kg).
//!
//! # Friction on a pivoting body
//!
//! Positional friction removes a contact's slip `Δp_t` against the body's material point
//! right after the contact's normal projection (`response::friction`). A later contact of the
//! same iteration turns the body by `Δθ = I_p⁻¹((p' − a) × J')`, which moves the point `q` of
//! the contact already solved by `Δθ × (q − a)`, partly along the surface; the next substep
//! measures slip from where the particle and the body then stand, so that residual is never
//! taken back. It has a direction: the contacts undo what rapier's step did to the body
//! (which swings a light box back towards the vertical, unaware of its load), so the residual
//! drags the load downhill, the body leans under it, and a load whose rig's centre of mass
//! is little below the anchor creeps off (a 10× soft cube on a hinged 2 kg box: 0.025 mm a
//! frame, off after 7 s, with the energy never growing). So after every contact, attachment
//! and joint of the iteration, the contacts with pivoting bodies get their friction again,
//! against where the iteration left the body, a few Gauss–Seidel sweeps with the static cone
//! shared with the first (`contacts::particle::friction_on_pivoting`;
//! `docs/decisions/pivoting-friction.md`).

use nalgebra::{Matrix3, Vector3};

use super::{BodyKind, BodyProxy};

/// The pivot of a pivoting body.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pivot {
    /// The joint's anchor in the body's frame, m.
    anchor: Vector3<f32>,
    /// Inverse of the inertia about the anchor, restricted to the hinge axis for a revolute
    /// joint (world, 1/(kg·m²); module docs).
    inv_inertia: Matrix3<f32>,
    /// The anchor on the immovable body at the frame's start and end (world, m).
    path: (Vector3<f32>, Vector3<f32>),
}

impl BodyProxy {
    /// Makes a dynamic body *pivoting* about the joint anchor `anchor` (m, the body's frame):
    /// about any axis for `axis` `None` (a ball joint), about the unit `axis` (world) only
    /// for a hinge (module docs). Nothing changes when its inertia about the anchor is
    /// singular or not finite.
    pub fn pivot(
        &mut self,
        anchor: Vector3<f32>,
        axis: Option<Vector3<f32>>,
        (start, end): (Vector3<f32>, Vector3<f32>),
    ) {
        if self.kind != BodyKind::Dynamic || self.inv_mass == Matrix3::zeros() {
            return;
        }
        let Some(i_com) = self.inv_inertia.try_inverse() else {
            return;
        };
        let mass = 1.0 / self.inv_mass.diagonal().max();
        let r = self.pose * nalgebra::Point3::from(anchor) - nalgebra::Point3::from(self.com());
        let i_a = i_com + (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * mass;
        let inv = match axis {
            Some(e) => {
                let k = e.dot(&(i_a * e));
                (e * e.transpose()) / k
            }
            None => match i_a.try_inverse() {
                Some(inv) => inv,
                None => return,
            },
        };
        if inv.iter().all(|x| x.is_finite()) {
            self.pivot = Some(Pivot {
                anchor,
                inv_inertia: inv,
                path: (start, end),
            });
            let frac = self.frac;
            self.set_pose(frac);
        }
    }

    /// `true` for a pivoting body.
    pub fn is_pivoting(&self) -> bool {
        self.pivot.is_some() && self.kind == BodyKind::Dynamic
    }

    /// The anchor (world, m) and inverse inertia about it of a pivoting body.
    fn pivot_now(&self) -> Option<(Vector3<f32>, &Matrix3<f32>)> {
        let p = self.pivot.as_ref()?;
        let a = self.pose * nalgebra::Point3::from(p.anchor);
        Some((a.coords, &p.inv_inertia))
    }

    /// A pivoting body's generalized inverse mass at `q` along the unit `n` (module docs), or
    /// `None` for any other body.
    pub(super) fn pivot_inv_mass_at(&self, q: &Vector3<f32>, n: &Vector3<f32>) -> Option<f32> {
        let (a, inv) = self.pivot_now()?;
        let rn = (q - a).cross(n);
        Some(rn.dot(&(inv * rn)))
    }

    /// The turn (rad, world) of a pivoting body under the positional impulse `p` (kg·m) at
    /// `q`, or `None` for any other body.
    pub(super) fn pivot_turn(&self, p: &Vector3<f32>, q: &Vector3<f32>) -> Option<Vector3<f32>> {
        let (a, inv) = self.pivot_now()?;
        Some(inv * (q - a).cross(p))
    }

    /// The turn (rad, world) of a pivoting body under the angular positional impulse `l`
    /// (kg·m²·rad), or `None` for any other body.
    pub(super) fn pivot_turn_angular(&self, l: &Vector3<f32>) -> Option<Vector3<f32>> {
        let p = self.pivot.as_ref()?;
        Some(p.inv_inertia * l)
    }

    /// The centre of mass of a pivoting body (m) at the fraction `frac` of the frame for its
    /// base rotation `rot` (module docs: its anchor on the immovable body's anchor, moved
    /// linearly over the frame), or `None` for any other body.
    pub(super) fn pivot_com(
        &self,
        frac: f32,
        rot: &nalgebra::UnitQuaternion<f32>,
    ) -> Option<Vector3<f32>> {
        let p = self.pivot.as_ref()?;
        let a = p.path.0.lerp(&p.path.1, frac);
        Some(a - self.dq * (rot * (p.anchor - self.com_local)))
    }

    /// Applies a velocity impulse `j` (N·s) at `q` to a pivoting body: its angular offset
    /// velocity changes by `I_p⁻¹((q − a) × j)` and its linear one follows the anchor offset.
    /// Returns `false` (and does nothing) for any other body.
    pub(super) fn pivot_velocity_impulse(&mut self, j: &Vector3<f32>, q: &Vector3<f32>) -> bool {
        let Some((a, inv)) = self.pivot_now() else {
            return false;
        };
        let dw = inv * (q - a).cross(j);
        self.dw += dw;
        self.dv += dw.cross(&(self.com() - a));
        self.touched = true;
        true
    }
}
