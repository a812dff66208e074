//! Where a new body is placed and how it starts moving.
//!
//! A body is built from a mesh in its own frame. Its rest shape is the mesh scaled by
//! [`Placement::scale`]; its particles start at `R (s v) + t` for each mesh vertex `v`, moving at
//! `v₀ + ω × (x − c)` with `c` the body's centre of mass. Rest data (edge lengths, heights,
//! volumes, [`Particles::rest_positions`](crate::Particles::rest_positions)) is the scaled mesh,
//! free of rotation and translation.

use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::error::BuildError;

/// Pose, uniform scale and initial motion of a body being built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Rotation applied to the scaled mesh, about the mesh's origin.
    pub rotation: UnitQuaternion<f32>,
    /// Translation applied after the rotation, m.
    pub translation: Vector3<f32>,
    /// Uniform scale of the mesh, dimensionless, > 0. It scales the rest shape too.
    pub scale: f32,
    /// Initial velocity of every free particle, m/s.
    pub linear_velocity: Vector3<f32>,
    /// Initial angular velocity about the placed body's centre of mass, rad/s.
    pub angular_velocity: Vector3<f32>,
}

impl Default for Placement {
    fn default() -> Self {
        Placement {
            rotation: UnitQuaternion::identity(),
            translation: Vector3::zeros(),
            scale: 1.0,
            linear_velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        }
    }
}

impl Placement {
    /// The pose as an isometry.
    pub fn pose(&self) -> Isometry3<f32> {
        Isometry3::from_parts(self.translation.into(), self.rotation)
    }

    /// Rejects a non-finite pose or motion and a scale that is not finite and positive.
    pub(crate) fn check(&self) -> Result<(), BuildError> {
        let finite = |v: &[f32]| v.iter().all(|c| c.is_finite());
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(BuildError::BadScale { value: self.scale });
        }
        if !finite(self.rotation.coords.as_slice()) || !finite(self.translation.as_slice()) {
            return Err(BuildError::NonFinitePose);
        }
        if !finite(self.linear_velocity.as_slice()) || !finite(self.angular_velocity.as_slice()) {
            return Err(BuildError::NonFiniteVelocity);
        }
        Ok(())
    }

    /// Where the rest-shape point `rest` (already scaled) starts, m.
    pub(crate) fn place(&self, rest: &Vector3<f32>) -> Vector3<f32> {
        self.rotation * rest + self.translation
    }

    /// Initial velocities: `v₀ + ω × (xᵢ − c)` for free particles (`wᵢ > 0`), zero for pinned
    /// ones; `c` is the centre of mass of every particle, summed in f64.
    pub(crate) fn velocities(
        &self,
        positions: &[Vector3<f32>],
        masses: &[f32],
        inv_masses: &[f32],
    ) -> Vec<Vector3<f32>> {
        let (mut m, mut first) = (0.0f64, Vector3::<f64>::zeros());
        for (x, mi) in positions.iter().zip(masses) {
            m += f64::from(*mi);
            first += x.cast::<f64>() * f64::from(*mi);
        }
        let c = if m > 0.0 {
            (first / m).cast::<f32>()
        } else {
            Vector3::zeros()
        };
        let (v, w) = (self.linear_velocity, self.angular_velocity);
        positions
            .iter()
            .zip(inv_masses)
            .map(|(x, wi)| {
                if *wi > 0.0 {
                    v + w.cross(&(x - c))
                } else {
                    Vector3::zeros()
                }
            })
            .collect()
    }
}
