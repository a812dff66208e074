//! Placing a soft body with rapier's types.

use rapier3d::math::{Pose, Vector};
use tetpbd::SoftBodyBuilder;

use crate::convert::{pose_to_na, to_na};

/// Builder methods taking rapier's glam types, for code that speaks rapier.
pub trait RapierPlacement: Sized {
    /// Rotation and translation of the mesh, as a rapier pose (see
    /// [`SoftBodyBuilder::pose`]).
    fn rapier_pose(self, pose: Pose) -> Self;
    /// Initial linear (m/s) and angular (rad/s, about the placed body's centre of mass)
    /// velocity, as rapier vectors (see [`SoftBodyBuilder::velocity`] and
    /// [`SoftBodyBuilder::angular_velocity`]).
    fn rapier_velocity(self, linvel: Vector, angvel: Vector) -> Self;
}

impl RapierPlacement for SoftBodyBuilder {
    fn rapier_pose(self, pose: Pose) -> Self {
        self.pose(pose_to_na(&pose))
    }

    fn rapier_velocity(self, linvel: Vector, angvel: Vector) -> Self {
        self.velocity(to_na(linvel)).angular_velocity(to_na(angvel))
    }
}
