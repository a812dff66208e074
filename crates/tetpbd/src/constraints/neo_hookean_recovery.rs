//! The Neo-Hookean material's way out of a collapsed tetrahedron: the hydrostatic
//! constraint with a recovery direction where its gradient vanishes.

use nalgebra::{Matrix3, RealField, Vector3};

use super::neo_hookean::{cofactor, deformation_gradient, particle_gradients};
use super::Evaluated;

// ---------------------------------------------------------------------------------------
// Why a collapsed tetrahedron does not come back by itself.
//
// Every smooth isotropic energy is stationary at F = 0 (its stress P(0) must equal
// Q P(0) Rᵀ for all rotations Q, R), and the stable Neo-Hookean energy of Macklin & Müller
// has a local *minimum* there: along F = sI,
//
//   Ψ(sI) = 3μ/2 s² + λ'/2 (s³ − γ)² + const = const + 3μ/2 s² − λ'γ s³ + O(s⁶),
//
// the quadratic deviatoric term pulls towards the point and the hydrostatic term, cubic in
// s, pushes out only beyond the barrier s* = μ/(λ'γ) = μ/(λ' + μ) (0.02 for rubber at
// ν = 0.49, 0.09 for soft tissue at ν = 0.45). In constraint terms: ∂C_H/∂F = cof F vanishes
// quadratically (and for every F of rank ≤ 1: all four points on a line), so the
// hydrostatic constraint, violated by the whole −γ, has no direction to correct along, and
// the deviatoric one, met at F = 0, holds the point. A body collapsed to a point stays one,
// with its hydrostatic energy V₀(λ' − μ)/2 stored.
//
// The recovery direction. Where the cofactor is weak, ‖cof F‖_F < √3 τ, the hydrostatic
// constraint is projected along
//
//   G(F) = cof F + b I,        b = 1 − ‖cof F‖_F / (√3 τ)   (0 ≤ b ≤ 1),
//
// instead of cof F: the constraint's gradient at rest (cof I = I), the one direction that
// an isotropic F = 0 cannot give, taken from the rest shape as the edge constraint takes
// a zero-length edge's rest direction. G is continuous (b = 0 at the threshold, G = I at
// F = 0), the value C_H = det F − γ is unchanged, and the particle directions sum to zero
// (linear momentum kept; at a point all particles coincide, so no torque either).
//
// The threshold. Along F = sI with s² < τ, |G| ≥ √3 τ, so the hydrostatic push
// λ'γ√3 τ beats the deviatoric pull μ√3 s ≤ μ√3 √τ when √τ > s*; beyond, cof F itself
// pushes harder than the pull (s > √τ > s*). τ = 4 s*² (twice the barrier) leaves a factor
// 2 of margin: 1.6e-3 for rubber (only compressions below 4 % of the rest size are
// touched). It is capped at 0.01 (a tenth of the rest size): inside the region the
// direction is not the energy's, and on a large one (foam, ν = 0.3, would get 0.33) it
// climbed the deviatoric energy of stretched needle-like tetrahedra — a mirrored foam cube
// gained 8 % of its energy. Under the cap (soft tissue: 0.01 for 0.033; foam and softer
// ν) the push beats the pull only below the cap's size, and a tetrahedron between there and
// the barrier is left to the material's own forces and its neighbours.
//
// Energy. G is a search direction, not the gradient of an energy: a projection along it
// may climb the small barrier (V₀ μ s*²/2 at most) on its way out. The kernels take the
// energy a projection released exactly from the positions (never from the direction), so
// the correction-energy limit hands no more kinetic energy to the body than the material
// really released.
// ---------------------------------------------------------------------------------------

/// The largest collapse threshold: the recovery direction acts only on tetrahedra crushed
/// below about a tenth of their rest size (`‖cof F‖_F < √3 · 0.01`).
pub const TAU_CAP: f64 = 0.01;

/// The collapse threshold `τ = min(4 (μ/(λ' + μ))², 0.01)` of
/// [`neo_hookean_hydrostatic_recovering`] (dimensionless), `μ`, `λ'` in Pa: twice the
/// barrier `s* = μ/(λ' + μ)` below which an isotropically collapsed tetrahedron is drawn
/// to the point, squared.
#[inline]
pub fn neo_hookean_collapse_threshold<T: RealField + Copy>(mu: T, lambda_prime: T) -> T {
    let s = mu / (lambda_prime + mu);
    let four = nalgebra::convert::<f64, T>(4.0);
    let cap = nalgebra::convert::<f64, T>(TAU_CAP);
    (four * s * s).min(cap)
}

/// The hydrostatic Neo-Hookean constraint `C_H = det F − γ` (as
/// [`super::neo_hookean_hydrostatic`]) with the recovery direction of a collapsed
/// tetrahedron: its particle directions are the columns of `G(F) Dm⁻ᵀ` (1/m,
/// `∇x0 = −Σ`), `G = cof F + b I`, `b = max(0, 1 − ‖cof F‖_F / (√3 τ))`, `τ` the collapse
/// threshold ([`neo_hookean_collapse_threshold`], dimensionless).
///
/// Where `‖cof F‖_F ≥ √3 τ` (every state but a tetrahedron crushed towards a point or a
/// line) this is exactly [`super::neo_hookean_hydrostatic`]: value and gradients. Inside,
/// `G` is not a gradient but a direction that increases `det F` for a finite step from a
/// collapsed tetrahedron, continuous in `F` and equal to the rest gradient `I` at `F = 0`
/// (theory in the module source). Always finite for finite input.
#[inline]
pub fn neo_hookean_hydrostatic_recovering<T: RealField + Copy>(
    p: &[Vector3<T>; 4],
    dm_inv: &Matrix3<T>,
    gamma: T,
    tau: T,
) -> Evaluated<T, 4> {
    let f = deformation_gradient(p, dm_inv);
    let cof = cofactor(&f);
    let g = cof + Matrix3::identity() * recovery_weight(&cof, tau);
    Evaluated {
        c: f.determinant() - gamma,
        grad: particle_gradients(&g, dm_inv),
    }
}

/// `b = max(0, 1 − ‖cof F‖_F / (√3 τ))` of [`neo_hookean_hydrostatic_recovering`]; 0 when
/// `τ ≤ 0`.
#[inline]
pub fn recovery_weight<T: RealField + Copy>(cof: &Matrix3<T>, tau: T) -> T {
    let zero = T::zero();
    if tau.partial_cmp(&zero) != Some(std::cmp::Ordering::Greater) {
        return zero;
    }
    let three = nalgebra::convert::<f64, T>(3.0);
    let b = T::one() - cof.norm() / (three.sqrt() * tau);
    b.max(zero)
}
