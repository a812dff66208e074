//! The signed volume constraint.

use nalgebra::{Matrix3, RealField, Vector3};

use super::neo_hookean_recovery::{neo_hookean_hydrostatic_recovering, TAU_CAP};
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

// ---------------------------------------------------------------------------------------
// A volume constraint with no direction.
//
// With Ds = [p1 − p0, p2 − p0, p3 − p0] = F Dm (Dm the rest edges, F the deformation
// gradient), V = det Ds / 6 = V₀ det F and ∂V/∂Ds = V₀ cof F Dm⁻ᵀ: the gradient vanishes
// with cof F, for every F of rank ≤ 1 (the four points on a line or at a point). A line is
// then invariant: edges along it keep their particles on it, the volume constraints have
// no direction, and a body collapsed onto a line stays there (a point collapse whose
// zero-length edges re-expand along their rest directions one after another strings the
// body out along the first one). The way out is the Neo-Hookean material's
// (`neo_hookean_recovery.rs`): where ‖cof F‖_F < √3 τ the constraint is projected along
// V₀ (cof F + b I) Dm⁻ᵀ, b = 1 − ‖cof F‖_F / (√3 τ), the rest gradient blended in
// continuously; τ is that module's cap (only tetrahedra crushed below about a tenth of
// their rest size are touched). V − V₀ = V₀ (det F − 1) is the hydrostatic constraint with
// γ = 1 scaled by V₀: one implementation of the direction for both.
// ---------------------------------------------------------------------------------------

/// Below this, `(Σᵢ |∇ᵢC|²)³ < VOLUME_GATE · V₀⁴` (dimensionless), a volume constraint's
/// gradient is weak enough that the kernels evaluate [`volume_recovering`]: about 100 times
/// the value at the recovery region's edge on a regular tetrahedron (`Σ|∇C|² ≈ 1.16 V₀^{4/3}`
/// at rest, `τ²` of that at the edge), so the region is always inside the gate.
pub const VOLUME_GATE: f64 = 1e-6;

/// The signed volume constraint `C = V − V₀` (m³, as [`volume`]) with the recovery direction
/// of a tetrahedron collapsed onto a line or a point: particle directions (m²) the columns
/// of `V₀ G Dm⁻ᵀ`, `∇p0 = −Σ`, `G = cof F + b I`, `b = max(0, 1 − ‖cof F‖_F / (√3 τ))`,
/// `τ = 0.01`, `F = Ds Dm⁻¹` with `dm_inv` the inverse of the rest edge matrix (1/m).
///
/// Equal to [`volume`] (value and gradients) wherever `‖cof F‖_F ≥ √3 τ`; inside, the rest
/// gradient blended in continuously (a search direction, not a gradient; theory in the
/// module source). Always finite for finite input.
#[inline]
pub fn volume_recovering<T: RealField + Copy>(
    p: &[Vector3<T>; 4],
    dm_inv: &Matrix3<T>,
    rest_volume: T,
) -> Evaluated<T, 4> {
    let tau = nalgebra::convert::<f64, T>(TAU_CAP);
    let e = neo_hookean_hydrostatic_recovering(p, dm_inv, T::one(), tau);
    Evaluated {
        c: signed_volume(&p[0], &p[1], &p[2], &p[3]) - rest_volume,
        grad: e.grad.map(|g| g * rest_volume),
    }
}
