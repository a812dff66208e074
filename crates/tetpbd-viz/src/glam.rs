//! rapier's glam poses and vectors → the nalgebra types the meshes use.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use tetpbd_rapier::rapier3d::math::{Pose, Vector};

/// glam vector → nalgebra vector.
#[inline]
pub(crate) fn to_na(v: Vector) -> Vector3<f32> {
    Vector3::new(v.x, v.y, v.z)
}

/// glam pose → nalgebra isometry.
#[inline]
pub(crate) fn pose_to_na(p: &Pose) -> Isometry3<f32> {
    let r = p.rotation;
    Isometry3::from_parts(
        Translation3::from(to_na(p.translation)),
        UnitQuaternion::new_normalize(Quaternion::new(r.w, r.x, r.y, r.z)),
    )
}
