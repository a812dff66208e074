//! The XPBD update shared by every constraint: the multiplier step, its bound, and one
//! projection applied to the particles.

use nalgebra::{RealField, Vector3};

use super::Evaluated;

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
