//! Conversions between rapier's glam types and the nalgebra types of `tetpbd`.
//!
//! rapier 0.36 speaks glam (through `glamx`); the soft-body core speaks nalgebra. Every
//! value crosses the boundary through these functions, so the rest of the crate works in
//! nalgebra only.

use nalgebra::{Isometry3, Matrix3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rapier3d::math::{AngularInertia, Pose, Rotation, Vector};

/// glam vector → nalgebra vector.
#[inline]
pub(crate) fn to_na(v: Vector) -> Vector3<f32> {
    Vector3::new(v.x, v.y, v.z)
}

/// nalgebra vector → glam vector.
#[inline]
pub(crate) fn to_glam(v: &Vector3<f32>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// glam rotation → nalgebra unit quaternion.
#[inline]
pub(crate) fn rot_to_na(r: Rotation) -> UnitQuaternion<f32> {
    UnitQuaternion::new_normalize(Quaternion::new(r.w, r.x, r.y, r.z))
}

/// nalgebra unit quaternion → glam rotation.
#[inline]
pub(crate) fn rot_to_glam(r: &UnitQuaternion<f32>) -> Rotation {
    let q = r.quaternion();
    Rotation::from_xyzw(q.i, q.j, q.k, q.w)
}

/// glam pose → nalgebra isometry.
#[inline]
pub(crate) fn pose_to_na(p: &Pose) -> Isometry3<f32> {
    Isometry3::from_parts(
        Translation3::from(to_na(p.translation)),
        rot_to_na(p.rotation),
    )
}

/// nalgebra isometry → glam pose.
#[inline]
pub(crate) fn pose_to_glam(p: &Isometry3<f32>) -> Pose {
    Pose::from_parts(to_glam(&p.translation.vector), rot_to_glam(&p.rotation))
}

/// rapier's symmetric world inverse inertia → nalgebra matrix.
#[inline]
pub(crate) fn inertia_to_na(i: &AngularInertia) -> Matrix3<f32> {
    Matrix3::new(
        i.m11, i.m12, i.m13, //
        i.m12, i.m22, i.m23, //
        i.m13, i.m23, i.m33,
    )
}

/// `true` when every component is finite.
#[inline]
pub(crate) fn finite3(v: &Vector3<f32>) -> bool {
    v.iter().all(|c| c.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_round_trip() {
        let iso = Isometry3::new(Vector3::new(1.0, -2.0, 3.0), Vector3::new(0.3, 0.2, -0.1));
        let back = pose_to_na(&pose_to_glam(&iso));
        assert!((back.translation.vector - iso.translation.vector).norm() < 1e-6);
        assert!(back.rotation.angle_to(&iso.rotation) < 1e-5);
        let p = Vector3::new(0.5, 0.1, -0.7);
        let a = iso * nalgebra::Point3::from(p);
        let b = to_na(pose_to_glam(&iso).transform_point(to_glam(&p)));
        assert!((a.coords - b).norm() < 1e-5);
    }
}
