//! The soft reaction on a multibody link, written back through the multibody.
//!
//! rapier moves a multibody's links from its generalized coordinates `q` and velocities `q̇`:
//! a pose or velocity written to a link's rigid body is overwritten by the next step. So a
//! link that took part in the substeps with its mass hands its change over the frame to the
//! multibody: with `J` the link's body Jacobian (its centre-of-mass velocity and angular
//! velocity per unit `q̇`), `M_l` its mass and world inertia and `M` the multibody's mass
//! matrix, a change `ξ` of the link's spatial velocity (its offset velocity `(δv, δω)`)
//! is the generalized impulse `Jᵀ M_l ξ`, and
//!
//! ```text
//! Δq̇ = M⁻¹ Jᵀ M_l (δv, δω),    Δq = M⁻¹ Jᵀ M_l (δc, δθ)
//! ```
//!
//! with `(δc, δθ)` the offset of its centre of mass and rotation from rapier's end pose. For
//! a link on a fixed base `M = Jᵀ M_l J` and a change the joint allows comes out exactly
//! (`J Δq̇ = ξ`); on a longer chain the impulse is shared with the other links as rapier
//! would share a force. The displaced coordinates are carried to every link's pose by
//! forward kinematics. No allocation once the scratch vector has the multibody's size.

use nalgebra::{DVector, Matrix3, Vector3, Vector6};
use rapier3d::dynamics::{MultibodyJointSet, RigidBodySet};

use super::{BodyKind, BodyProxy};
use crate::convert::{inertia_to_na, to_na};

impl BodyProxy {
    /// Writes a dynamic multibody link's change over the frame to its multibody (module
    /// docs), `scratch` a reused vector. `None` when the body is not a multibody link, or
    /// its multibody has kinematic degrees of freedom; `Some(false)` (nothing written) when
    /// the result is not finite.
    pub fn write_back_link(
        &self,
        bodies: &mut RigidBodySet,
        multibodies: &mut MultibodyJointSet,
        scratch: &mut DVector<f32>,
    ) -> Option<bool> {
        if self.kind != BodyKind::Dynamic {
            return None;
        }
        let link = *multibodies.rigid_body_link(self.handle)?;
        let rb = bodies.get(self.handle)?;
        let mp = rb.mass_properties();
        let mass = Matrix3::from_diagonal(&to_na(mp.effective_mass()));
        let inertia = inertia_to_na(&mp.effective_angular_inertia());
        let mb = multibodies.get_multibody_mut(link.multibody)?;
        let n = mb.ndofs();
        if n == 0 {
            return Some(true);
        }
        if mb.links().any(|l| l.joint().kinematic) {
            return None;
        }
        if scratch.len() != n {
            *scratch = DVector::zeros(n);
        }
        let jacobian_id = mb.link(link.id)?.link_id();
        let turn = (self.pose.rotation * self.rot_end.inverse()).scaled_axis();
        let shift = self.com() - self.com_end;
        let velocity = (self.dv, self.dw);
        // The displacement first, then the velocity change, each through `M⁻¹ Jᵀ M_l`.
        let momentum = |(lin, ang): (Vector3<f32>, Vector3<f32>)| {
            let (p, l) = (mass * lin, inertia * ang);
            Vector6::new(p.x, p.y, p.z, l.x, l.y, l.z)
        };
        let generalized = |mb: &rapier3d::dynamics::Multibody, out: &mut DVector<f32>, f| {
            mb.body_jacobian(jacobian_id).tr_mul_to(&momentum(f), out);
            mb.inv_augmented_mass().solve_mut(out) && out.iter().all(|x| x.is_finite())
        };
        if !generalized(mb, scratch, (shift, turn)) {
            return Some(false);
        }
        mb.apply_displacements(scratch.as_slice());
        if !generalized(mb, scratch, velocity) {
            return Some(false);
        }
        mb.generalized_velocity_mut().axpy(1.0, scratch, 1.0);
        mb.forward_kinematics(bodies, false);
        mb.update_rigid_bodies(bodies, true);
        Some(true)
    }
}
