//! Vectors between `tetpbd`'s nalgebra and parry's glam, component by component.

use nalgebra::Vector3;
use parry3d::math::Vector;

/// nalgebra vector → glam vector.
#[inline]
pub(crate) fn to_glam(v: &Vector3<f32>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// glam vector → nalgebra vector.
#[inline]
pub(crate) fn to_na(v: Vector) -> Vector3<f32> {
    Vector3::new(v.x, v.y, v.z)
}
