//! The edge distance constraint.

use nalgebra::{RealField, Vector3};

use super::Evaluated;

// ---------------------------------------------------------------------------------------
// Edge distance.
//
// C = |p0 − p1| − d. With n = (p0 − p1)/|p0 − p1|: ∇p0 C = n, ∇p1 C = −n, |∇|² = 1 each.
// A zero-length edge has no direction; the caller may pass the rest direction as fallback.
// ---------------------------------------------------------------------------------------

/// Edge distance constraint `C = |p0 − p1| − d`.
///
/// * `C` in metres, compliance in m/N.
/// * `∇p0 C = (p0 − p1) / |p0 − p1|`, `∇p1 C = −∇p0 C`.
///
/// When `|p0 − p1|` is below `1e-6 · d` (coincident points) the direction is undefined. The
/// `fallback` unit vector is then used as `∇p0 C` (the solver passes the rest-pose direction,
/// so a collapsed edge re-expands the way it was built); with `fallback = None` the function
/// returns `None`.
#[inline]
pub fn edge<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    rest_length: T,
    fallback: Option<&Vector3<T>>,
) -> Option<Evaluated<T, 2>> {
    let d = p0 - p1;
    let len = d.norm();
    let tiny = rest_length * nalgebra::convert::<f64, T>(1e-6);
    let n = if len > tiny && len > T::zero() {
        d / len
    } else {
        *fallback?
    };
    Some(Evaluated {
        c: len - rest_length,
        grad: [n, -n],
    })
}
