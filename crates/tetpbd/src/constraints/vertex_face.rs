//! The vertex–face ("plane") constraint of the seed: a vertex held at its rest height above
//! the plane of the opposite face, and the move bound of its projections.

use nalgebra::{RealField, Vector3};

use super::Evaluated;

// ---------------------------------------------------------------------------------------
// Vertex–face ("plane") constraint, as derived in the seed.
//
// Translate so that p0 = 0: a = p1 − p0, b = p2 − p0, c = p3 − p0, m = b × c, n = m/|m|.
//   C      = a·n − d
//   ∇p1 C  = n
//   ∇p2 C  = ( c × a + (n × c)(n·a) ) / |m|
//   ∇p3 C  = −( b × a + (n × b)(n·a) ) / |m|
//   ∇p0 C  = −(∇p1 + ∇p2 + ∇p3)           (translation invariance)
// |m| → 0 (the face collapses to a segment or a point) leaves n undefined: return None.
// ---------------------------------------------------------------------------------------

/// Vertex–face constraint: `p1` held at signed height `d` above the plane through
/// `p0, p2, p3`.
///
/// ```text
/// C = (p1 − p0) · n − d,     n = ((p2 − p0) × (p3 − p0)) / |(p2 − p0) × (p3 − p0)|
/// ```
///
/// * `C` in metres, compliance in m/N; `d` is signed (from the rest pose), so an inverted
///   tetrahedron has `C ≈ −2d` and is pushed back through the plane.
/// * With `a = p1 − p0`, `b = p2 − p0`, `c = p3 − p0`, `m = b × c`:
///   `∇p1 C = n`, `∇p2 C = (c × a + (n × c)(n·a)) / |m|`,
///   `∇p3 C = −(b × a + (n × b)(n·a)) / |m|`, `∇p0 C = −(∇p1 C + ∇p2 C + ∇p3 C)`.
///
/// Returns `None` when the face is degenerate: `|m| ≤ 1e-7 · (|b|² + |c|²)` (collinear or
/// coincident face points; the plane's normal is undefined).
#[inline]
pub fn vertex_face<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    p2: &Vector3<T>,
    p3: &Vector3<T>,
    rest_height: T,
) -> Option<Evaluated<T, 4>> {
    let a = p1 - p0;
    let b = p2 - p0;
    let c = p3 - p0;
    let m = b.cross(&c);
    let m_len = m.norm();
    let scale = b.norm_squared() + c.norm_squared();
    let threshold = scale * nalgebra::convert::<f64, T>(1e-7);
    // NaN-safe: a NaN length is "not above the threshold" and reported as degenerate.
    if m_len.partial_cmp(&threshold) != Some(std::cmp::Ordering::Greater) || m_len <= T::zero() {
        return None;
    }
    let inv = T::one() / m_len;
    let n = m * inv;
    let na = n.dot(&a);
    let g1 = n;
    let g2 = (c.cross(&a) + n.cross(&c) * na) * inv;
    let g3 = -(b.cross(&a) + n.cross(&b) * na) * inv;
    let g0 = -(g1 + g2 + g3);
    Some(Evaluated {
        c: na - rest_height,
        grad: [g0, g1, g2, g3],
    })
}

/// The four vertex–face constraints of tetrahedron `(v0, v1, v2, v3)`.
///
/// Entry `k` lists the corners passed to [`vertex_face`] as `(p0, p1, p2, p3)` so that
/// corner `k` plays `p1`, the vertex held above the plane of the other three. Each is an
/// even permutation of `(0, 1, 2, 3)`, so all four rest heights carry the sign of the
/// tetrahedron's signed volume.
pub const VERTEX_FACE_ORDER: [[usize; 4]; 4] =
    [[1, 0, 3, 2], [0, 1, 2, 3], [0, 2, 3, 1], [0, 3, 1, 2]];

/// Signed height of `p1` above the plane through `p0, p2, p3` (the `C + d` of
/// [`vertex_face`]), or `None` for a degenerate face.
#[inline]
pub fn signed_height<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    p2: &Vector3<T>,
    p3: &Vector3<T>,
) -> Option<T> {
    vertex_face(p0, p1, p2, p3, T::zero()).map(|e| e.c)
}

/// Largest particle move of one vertex–face projection, as a multiple of the tetrahedron's
/// rest size (see [`vertex_face_step_bound`]). Dimensionless.
///
/// 2: a projection moves no particle further than twice the tetrahedron's largest rest value
/// (its largest rest height, or less on a face thin at rest) — on a sliver, twice its
/// smallest. Corrections of a healthy scene are far below it and unchanged; it acts where a
/// near-singular gradient would take a step of many body sizes. A projection linearises its
/// constraint, and a sliver's faces turn by a right angle when a vertex moves by about its
/// thickness: a longer step lands where the linearisation says nothing. Bounded by its
/// largest height, the compliant vertex–face plate of the stability matrix (1 mm thick)
/// stored 1e5 J of vertex–face energy from nothing in 15 frames and turned it into motion
/// (80 × `M g L`).
pub const VERTEX_FACE_MAX_STEP: f32 = 2.0;

/// A tetrahedron whose smallest rest value is below this fraction of its largest is a sliver
/// for [`vertex_face_step_bound`] (the solver's sliver threshold on altitudes,
/// `stabilisation::sliver_orientation`, is the same 0.1). Dimensionless.
pub const VERTEX_FACE_SLIVER: f32 = 0.1;

/// The move bound of one tetrahedron's vertex–face projections, m: [`VERTEX_FACE_MAX_STEP`]
/// `· max_k |d_k|` over its four rest values `d_k` (m), or `· min_k |d_k|` on a sliver
/// (`min_k |d_k| < VERTEX_FACE_SLIVER · max_k |d_k|`, compared in squares).
#[inline(always)]
pub fn vertex_face_step_bound(rest_values: &[f32; 4]) -> f32 {
    let largest = rest_values.iter().fold(0.0f32, |m, d| m.max(d.abs()));
    let smallest = rest_values
        .iter()
        .fold(f32::INFINITY, |m, d| m.min(d.abs()));
    // In squares, as the SIMD kernel compares them (the same rounding at the threshold).
    let sliver =
        largest * largest * (VERTEX_FACE_SLIVER * VERTEX_FACE_SLIVER) > smallest * smallest;
    let size = if sliver { smallest } else { largest };
    VERTEX_FACE_MAX_STEP * size
}
