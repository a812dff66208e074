//! The degeneracy-aware form of the vertex–face constraint the solver runs: the height where
//! the face is healthy, the signed volume over a bounded area where it is thin.

use nalgebra::{RealField, Vector3};

use super::Evaluated;

// ---------------------------------------------------------------------------------------
// Degeneracy-aware vertex–face constraint.
//
// f = a·m = 6V (m³), s = |m| (m², twice the face's area), Q = (|b|² + |c|²)/2 (m²),
// K = κQ (m², κ dimensionless). The height is f/s; here s is replaced by
//   D = s                      if s ≥ K   (healthy face: D = s, C̃ = the height)
//   D = (s² + K²)/(2K)         if s < K   (thin face: D ≥ K/2, C¹ at s = K)
//   C̃ = f/D − d
// Gradients:  ∇C̃ = ∇f/D − (f/D²) ∇D, with
//   ∇a f = m,  ∇b f = c × a,  ∇c f = a × b,
//   ∇a D = 0,  ∇b D = E (c × m) + β b,  ∇c D = E (m × b) + β c,
//   E = 1/s, β = 0 (healthy);  E = 1/K, β = (κ/2)(1 − s²/K²) (thin).
// ∇p1 = ∇a, ∇p2 = ∇b, ∇p3 = ∇c, ∇p0 = −(∇p1 + ∇p2 + ∇p3).
// ---------------------------------------------------------------------------------------

/// Face-thinness threshold κ of [`vertex_face_bounded`] used by the solver: a face counts as
/// thin when `|b × c| < κ (|b|² + |c|²) / 2` (the ratio is `sin θ` for two equal sides at an
/// angle θ). Dimensionless.
///
/// 0.05 leaves every face of a regular tetrahedron (ratio 0.87) and of the box generators' cells
/// (≥ 0.57) on the exact-height branch at rest; the long thin faces of slivers (⅓ m × 1 mm:
/// about 0.006) are on the thin branch from the start.
pub const VERTEX_FACE_KAPPA: f32 = 0.05;

/// Degeneracy-aware vertex–face constraint: the signed height of `p1` above the plane through
/// `p0, p2, p3` where the face is healthy, the signed volume over a bounded area where it is
/// thin.
///
/// With `a = p1 − p0`, `b = p2 − p0`, `c = p3 − p0`, `m = b × c`, `f = a·m = 6V` (m³),
/// `s = |m|` (m², twice the face's area), `Q = (|b|² + |c|²)/2` (m², the face's size) and
/// `K = κQ`:
///
/// ```text
/// D = s                   if s ≥ K       (C̃ + d = f/s = (p1 − p0)·n, the seed's height)
/// D = (s² + K²) / (2K)    if s < K       (D ≥ K/2 > 0)
/// C̃ = f / D − d
/// ```
///
/// * `C̃` in metres (m³ / m²), compliance in m/N, `d` the rest value of `f/D` (signed; equal
///   to the rest height where the face is healthy at rest), `kappa` dimensionless.
/// * `D` and its gradient are continuous at `s = K` (C¹), so the switch is smooth.
/// * Gradients, dimensionless: `∇C̃ = ∇f/D − (f/D²) ∇D` with `∇a f = m`, `∇b f = c × a`,
///   `∇c f = a × b`, `∇a D = 0`, `∇b D = E (c × m) + β b`, `∇c D = E (m × b) + β c`, where
///   `E = 1/s`, `β = 0` on the healthy branch and `E = 1/K`, `β = (κ/2)(1 − s²/K²)` on the
///   thin one. `∇p1 = ∇a`, `∇p2 = ∇b`, `∇p3 = ∇c`, `∇p0 = −(∇p1 + ∇p2 + ∇p3)`.
/// * `D` does not depend on `p1`, so `C̃` is linear (monotone) in the vertex's position, as the
///   height is. `C̃` is homogeneous of degree 1 in the positions, its gradients of degree 0,
///   and `D ≥ max(s, K/2)`: on the thin branch the gradients are bounded by about
///   `(1 + 4|a|/√Q)/κ` at any scale, instead of growing as `|a||c| / |b × c|` when the face
///   collapses to a segment. The seed's [`vertex_face`](crate::constraints::vertex_face()) is the limit `κ = 0`.
///
/// Where the thin branch's gradients are weaker than the seed's apex gradient alone
/// (`Σᵢ |∇ᵢC̃|² < 1`; the seed's sum is always ≥ 1) the seed's height is used instead
/// (`D = s`): that happens for a tetrahedron nearly collapsed onto a line, where `C̃ ≈ −d`
/// while every thin-branch gradient vanishes and a hard projection would step about
/// `d / |∇C̃|`, without bound, whereas the seed's step is bounded by `|C|`. `C̃` jumps there
/// (from `f/D − d` to `f/s − d`); a projection evaluates it afresh, so only the step size
/// changes.
///
/// Returns `None` when the face has collapsed to a point (`Q ≤ 1e-12 d²`, or `d = 0` and
/// `Q = 0`), when the input is not finite, or when the seed's height is needed and the face
/// is collinear (`s ≤ 1e-7 (|b|² + |c|²)`, as in [`vertex_face`](crate::constraints::vertex_face())).
#[inline(always)]
pub fn vertex_face_bounded<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    p2: &Vector3<T>,
    p3: &Vector3<T>,
    rest_value: T,
    kappa: T,
) -> Option<Evaluated<T, 4>> {
    let a = p1 - p0;
    let b = p2 - p0;
    let c = p3 - p0;
    let m = b.cross(&c);
    let s = m.norm();
    let half = nalgebra::convert::<f64, T>(0.5);
    let q = (b.norm_squared() + c.norm_squared()) * half;
    let floor = rest_value * rest_value * nalgebra::convert::<f64, T>(1e-12);
    // NaN-safe: a NaN size is "not above the floor" and reported as degenerate.
    if q.partial_cmp(&floor) != Some(std::cmp::Ordering::Greater) || !s.is_finite() {
        return None;
    }
    let k = kappa * q;
    let f = a.dot(&m);
    let grads = |inv_d: T, e: T, beta: T| {
        let r = f * inv_d * inv_d;
        let g1 = m * inv_d;
        let (mut u_b, mut u_c) = (c.cross(&m) * e, m.cross(&b) * e);
        if beta != T::zero() {
            u_b += b * beta;
            u_c += c * beta;
        }
        let g2 = c.cross(&a) * inv_d - u_b * r;
        let g3 = a.cross(&b) * inv_d - u_c * r;
        let g0 = -(g1 + g2 + g3);
        Evaluated {
            c: f * inv_d - rest_value,
            grad: [g0, g1, g2, g3],
        }
    };
    if s < k {
        let r = s / k;
        let e = grads(
            T::one() / ((s * r + k) * half),
            T::one() / k,
            kappa * half * (T::one() - r * r),
        );
        let strength: T = e
            .grad
            .iter()
            .map(|g| g.norm_squared())
            .fold(T::zero(), |x, y| x + y);
        // At least the seed's apex gradient (|n|² = 1): otherwise nearly collapsed onto a
        // line, and the seed's height (below) takes the bounded step.
        if strength >= T::one() {
            return Some(e);
        }
    }
    // Healthy (or weak thin) face: the seed's height, defined unless the face is collinear.
    let threshold = q * nalgebra::convert::<f64, T>(2e-7);
    if s.partial_cmp(&threshold) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let inv_s = T::one() / s;
    Some(grads(inv_s, inv_s, T::zero()))
}

/// The value `f/D` of [`vertex_face_bounded`] (its `C̃ + d`): the signed height of `p1` above
/// the plane of `p0, p2, p3` where that face is healthy. `None` for a face collapsed to a
/// point (its three points within about `1e-6 · scale` of each other, `scale` in metres: pass
/// the rest value when evaluating a deformed pose, 0 for the rest pose itself).
#[inline]
pub fn bounded_height<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    p2: &Vector3<T>,
    p3: &Vector3<T>,
    kappa: T,
    scale: T,
) -> Option<T> {
    vertex_face_bounded(p0, p1, p2, p3, scale, kappa).map(|e| e.c + scale)
}
