//! Constraint math: pure functions, no ECS, no rapier.
//!
//! Every function here is generic over the scalar (`f32` in the solver, `f64` in the
//! finite-difference tests) and returns `None` instead of a non-finite value when the
//! configuration is degenerate. The systems count those `None`s in [`crate::StepStats`].
//!
//! # XPBD
//!
//! For a constraint `C(x₀ … xₙ)` with compliance `α` (inverse stiffness), one Gauss–Seidel
//! projection inside a substep of length `h` is (Macklin et al. 2016, "XPBD"):
//!
//! ```text
//! α̃  = α / h²
//! Δλ = (−C − α̃ λ) / (Σᵢ wᵢ |∇ᵢC|² + α̃)
//! Δxᵢ = wᵢ ∇ᵢC Δλ,        λ ← λ + Δλ
//! ```
//!
//! where `wᵢ` is the inverse mass of particle `i` and `λ` the constraint's accumulated
//! Lagrange multiplier, reset to zero at the start of every substep. With `α = 0` this is
//! the hard PBD projection of Müller et al. 2006, which removes `C` to first order in one
//! step. The potential energy behind a compliant constraint is `U = C² / (2α)`, so `α` has the
//! units of `C² / J`: m/N for the two length constraints, m⁵/N for the volume constraint.

use nalgebra::{RealField, Vector3};

/// One XPBD multiplier update.
///
/// `c` is the constraint value, `lambda` its accumulated multiplier, `alpha_tilde = α/h²`,
/// `w_grad_sq` the sum `Σ wᵢ |∇ᵢC|²`. Returns `Δλ`, or `None` when the denominator is not
/// positive (all particles pinned and `α = 0`, or a vanishing gradient).
#[inline]
pub fn xpbd_delta_lambda<T: RealField + Copy>(
    c: T,
    lambda: T,
    alpha_tilde: T,
    w_grad_sq: T,
) -> Option<T> {
    let denom = w_grad_sq + alpha_tilde;
    if denom > T::default_epsilon() * T::default_epsilon() {
        Some((-c - alpha_tilde * lambda) / denom)
    } else {
        None
    }
}

/// Largest particle move of one vertex–face projection, as a fraction of the tetrahedron's
/// rest size `max_k |d_k|` (the largest of its four rest values, m; see
/// [`vertex_face_step_bound`]). Dimensionless.
///
/// 2: a projection moves no particle further than twice the tetrahedron's largest rest
/// height (its largest rest value, smaller than that height on faces thin at rest).
/// Corrections of a healthy scene are far below it and unchanged; it acts where a
/// near-singular gradient would take a step of many body sizes (the hard sliver plate of the
/// stability matrix). 1 bounded the plate tighter but, together with the safety net's
/// momentum restoration, left a scrambled vertex–face-only body tangled for good
/// (`tests/recovery.rs`); measured in `docs/stability.md` against 0.5, 1 and 4.
pub const VERTEX_FACE_MAX_STEP: f32 = 2.0;

/// The move bound of one tetrahedron's vertex–face projections, m:
/// [`VERTEX_FACE_MAX_STEP`] `· max_k |d_k|` over its four rest values `d_k` (m).
#[inline(always)]
pub fn vertex_face_step_bound(rest_values: &[f32; 4]) -> f32 {
    let size = rest_values.iter().fold(0.0f32, |m, d| m.max(d.abs()));
    VERTEX_FACE_MAX_STEP * size
}

/// A multiplier step `Δλ` scaled down so that no particle moves further than `max_step`.
///
/// `reach_sq ≥ maxᵢ (wᵢ |∇ᵢC|)²` (the squared move per unit `Δλ`, or an upper bound of it:
/// the kernels pass `maxᵢ wᵢ · Σᵢ wᵢ |∇ᵢC|²`, which the XPBD denominator already holds),
/// `max_step` in metres. The projection moves particle `i` by `wᵢ ∇ᵢC Δλ`, so no move exceeds
/// `|Δλ| √reach_sq`; where that exceeds `max_step` the step becomes
/// `sign(Δλ) · max_step / √reach_sq` (every move scaled by the same factor: the correction
/// keeps its direction and, as the gradients sum to zero, conserves momentum). Smaller steps
/// are returned unchanged, bit for bit. Units: `Δλ` in those of the multiplier (kg·m for a
/// length constraint), `reach_sq` in `1/kg² · |∇C|²`.
#[inline(always)]
pub fn bounded_step<T: RealField + Copy>(dl: T, reach_sq: T, max_step: T) -> T {
    if dl * dl * reach_sq > max_step * max_step {
        let s = max_step / reach_sq.sqrt();
        if dl < T::zero() {
            -s
        } else {
            s
        }
    } else {
        dl
    }
}

/// A constraint value with its gradients with respect to each of its `N` particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluated<T: RealField + Copy, const N: usize> {
    /// The constraint value `C`.
    pub c: T,
    /// `∇ᵢC` for each particle, in the order the particles were passed.
    pub grad: [Vector3<T>; N],
}

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
///   collapses to a segment. The seed's [`vertex_face`] is the limit `κ = 0`.
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
/// is collinear (`s ≤ 1e-7 (|b|² + |c|²)`, as in [`vertex_face`]).
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
/// collinear, which [`xpbd_delta_lambda`] reports as `None`.
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

/// Applies one XPBD projection of an evaluated constraint to the particles `idx`.
///
/// `w` are the particles' inverse masses, `lambda` the constraint's multiplier (updated in
/// place). Returns `false` (and moves nothing) when [`xpbd_delta_lambda`] returns `None`.
/// Generic like the rest of this module: the solver runs it in `f32`, the f64 reference
/// stepper of the benchmarks in `f64`.
#[inline]
pub fn apply<T: RealField + Copy, const N: usize>(
    positions: &mut [Vector3<T>],
    idx: [usize; N],
    w: [T; N],
    e: &Evaluated<T, N>,
    lambda: &mut T,
    alpha_tilde: T,
) -> bool {
    let w_grad_sq = w
        .iter()
        .zip(&e.grad)
        .fold(T::zero(), |s, (w, g)| s + *w * g.norm_squared());
    match xpbd_delta_lambda(e.c, *lambda, alpha_tilde, w_grad_sq) {
        Some(dl) => {
            *lambda += dl;
            for k in 0..N {
                positions[idx[k]] += e.grad[k] * (w[k] * dl);
            }
            true
        }
        None => false,
    }
}
