//! The signed volume constraint.

use nalgebra::{RealField, Vector3};

use super::Evaluated;

// ---------------------------------------------------------------------------------------
// Signed volume.
//
// C = (1/6) a·(b × c) − V with a, b, c as above.
//   ∇p1 C = (1/6) b × c,  ∇p2 C = (1/6) c × a,  ∇p3 C = (1/6) a × b,  ∇p0 C = −Σ.
// (The seed writes ∇p2 = −(1/6) a × c, the same vector.) The gradients vanish only when all
// four points are collinear/coincident; the XPBD denominator then vanishes and the caller
// skips the projection.
// ---------------------------------------------------------------------------------------

/// Signed volume of the tetrahedron `(p0, p1, p2, p3)`: `(1/6)(p1 − p0)·((p2 − p0) × (p3 − p0))`,
/// in m³. Positive when `p1` lies on the side of the face `(p0, p2, p3)` its normal points to.
#[inline]
pub fn signed_volume<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    p2: &Vector3<T>,
    p3: &Vector3<T>,
) -> T {
    (p1 - p0).dot(&(p2 - p0).cross(&(p3 - p0))) * nalgebra::convert::<f64, T>(1.0 / 6.0)
}

/// Signed volume constraint `C = (1/6)(p1 − p0)·((p2 − p0) × (p3 − p0)) − V`.
///
/// * `C` in m³, compliance in m⁵/N (`U = C²/2α`; a bulk modulus `K` in Pa corresponds to
///   `α = V/K`).
/// * With `a = p1 − p0`, `b = p2 − p0`, `c = p3 − p0`: `∇p1 C = (1/6) b × c`,
///   `∇p2 C = (1/6) c × a`, `∇p3 C = (1/6) a × b`, `∇p0 C = −(∇p1 C + ∇p2 C + ∇p3 C)`.
///
/// Always finite for finite input; the gradients are all zero when the four points are
/// collinear, which [`xpbd_delta_lambda`](crate::constraints::xpbd_delta_lambda) reports as `None`.
#[inline]
pub fn volume<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    p2: &Vector3<T>,
    p3: &Vector3<T>,
    rest_volume: T,
) -> Evaluated<T, 4> {
    let sixth = nalgebra::convert::<f64, T>(1.0 / 6.0);
    let a = p1 - p0;
    let b = p2 - p0;
    let c = p3 - p0;
    let g1 = b.cross(&c) * sixth;
    let g2 = c.cross(&a) * sixth;
    let g3 = a.cross(&b) * sixth;
    let g0 = -(g1 + g2 + g3);
    Evaluated {
        c: a.dot(&b.cross(&c)) * sixth - rest_volume,
        grad: [g0, g1, g2, g3],
    }
}
