//! Colliders near a soft body, as the substeps see them: pose relative to their body's
//! proxy, inside rule and material.

use nalgebra::Isometry3;
use rapier3d::dynamics::CoefficientCombineRule;
use rapier3d::geometry::ColliderHandle;

use crate::rigid::body::BodyProxy;
use crate::rigid::shape_query::InsideRule;

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
