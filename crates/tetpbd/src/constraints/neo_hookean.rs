//! The stable Neo-Hookean material as two XPBD constraints per tetrahedron (Macklin & Müller
//! 2021, "A Constraint-based Formulation of Stable Neo-Hookean Materials").

use nalgebra::{Matrix3, RealField, Vector3};

use super::Evaluated;

// ---------------------------------------------------------------------------------------
// Stable Neo-Hookean as constraints.
//
// With the rest edge matrix Dm = [X1 − X0, X2 − X0, X3 − X0] and the current one
// Ds = [x1 − x0, x2 − x0, x3 − x0], the deformation gradient is F = Ds Dm⁻¹ (dimensionless).
// The stable Neo-Hookean energy density (Smith et al. 2018 without the log term, in the form
// of Macklin & Müller 2021) is
//
//   Ψ(F) = μ/2 (tr(FᵀF) − 3) + λ'/2 (det F − γ)²,      γ = 1 + μ/λ',
//
// and with rest volume V₀ the body's energy V₀Ψ is the sum of two constraint energies
// C²/(2α) (plus a constant):
//
//   deviatoric   C_D = ‖F‖_F = √tr(FᵀF),   α_D = 1/(μ V₀)
//   hydrostatic  C_H = det F − γ,           α_H = 1/(λ' V₀)
//
// At rest (F = I) both constraints are violated (C_D = √3, C_H = −μ/λ'), but their forces
// cancel: ∂Ψ/∂F = μF + λ'(J − γ) cof F = μI − μI = 0. That is why the two are solved as one
// 2×2 system per tetrahedron (`neo_hookean_update`): the rest state is then a fixed
// point of a single Gauss–Seidel projection, which it is not for two separate projections.
//
// Small strain: the second variation at F = I is 2μ ε:ε + (λ' − μ)(tr ε)², linear elasticity
// with Lamé μ and λ = λ' − μ. So λ' = λ + μ, with μ, λ the Lamé parameters of E and ν.
//
// Gradients. With H = (∂C/∂F) Dm⁻ᵀ: ∇xᵢ C = column i−1 of H (i = 1, 2, 3), ∇x0 C = −Σ.
//   ∂C_D/∂F = F / ‖F‖_F          (undefined at F = 0: all four points coincide)
//   ∂C_H/∂F = cof F = [f1 × f2, f2 × f0, f0 × f1]  (fᵢ the columns of F; always defined,
//                                                   also for det F ≤ 0)
// So an inverted tetrahedron (det F < 0) has C_H < −γ and a gradient that points back to
// positive volume: it recovers like the seed's signed constraints.
// ---------------------------------------------------------------------------------------

/// The inverse rest edge matrix `Dm⁻¹` of a tetrahedron, `Dm = [p1 − p0, p2 − p0, p3 − p0]`
/// (columns, m; the inverse in 1/m). `None` when `Dm` is singular (a flat rest shape).
pub fn rest_shape_inverse<T: RealField + Copy>(
    p0: &Vector3<T>,
    p1: &Vector3<T>,
    p2: &Vector3<T>,
    p3: &Vector3<T>,
) -> Option<Matrix3<T>> {
    Matrix3::from_columns(&[p1 - p0, p2 - p0, p3 - p0]).try_inverse()
}

/// The deformation gradient `F = Ds Dm⁻¹` (dimensionless) of the tetrahedron `p` with inverse
/// rest edge matrix `dm_inv` ([`rest_shape_inverse`]).
#[inline]
pub fn deformation_gradient<T: RealField + Copy>(
    p: &[Vector3<T>; 4],
    dm_inv: &Matrix3<T>,
) -> Matrix3<T> {
    Matrix3::from_columns(&[p[1] - p[0], p[2] - p[0], p[3] - p[0]]) * dm_inv
}

/// The cofactor matrix `cof F = det(F) F⁻ᵀ`, as columns `[f1 × f2, f2 × f0, f0 × f1]`:
/// `∂ det F / ∂F`, defined for every `F`.
#[inline]
pub fn cofactor<T: RealField + Copy>(f: &Matrix3<T>) -> Matrix3<T> {
    let (f0, f1, f2) = (f.column(0), f.column(1), f.column(2));
    Matrix3::from_columns(&[f1.cross(&f2), f2.cross(&f0), f0.cross(&f1)])
}

/// The particle gradients of a constraint from `∂C/∂F`: `∇xᵢ C` = column `i − 1` of
/// `(∂C/∂F) Dm⁻ᵀ`, `∇x0 C = −(∇x1 C + ∇x2 C + ∇x3 C)`.
#[inline]
pub(super) fn particle_gradients<T: RealField + Copy>(
    dc_df: &Matrix3<T>,
    dm_inv: &Matrix3<T>,
) -> [Vector3<T>; 4] {
    let h = dc_df * dm_inv.transpose();
    let (g1, g2, g3) = (
        h.column(0).into_owned(),
        h.column(1).into_owned(),
        h.column(2).into_owned(),
    );
    [-(g1 + g2 + g3), g1, g2, g3]
}

/// Deviatoric Neo-Hookean constraint `C_D = ‖F‖_F = √tr(FᵀF)`, `F = Ds Dm⁻¹`.
///
/// * `C_D` dimensionless; compliance `α_D = 1/(μ V₀)` in 1/J (1/(Pa·m³)), so that
///   `C_D²/(2α_D) = V₀ μ/2 tr(FᵀF)`.
/// * `∂C_D/∂F = F/‖F‖_F`; `∇xᵢ C_D` = column `i − 1` of `(F/‖F‖_F) Dm⁻ᵀ` (1/m),
///   `∇x0 C_D = −Σᵢ ∇xᵢ C_D`.
///
/// `None` when `‖F‖_F` vanishes (all four points coincide), where the direction is undefined.
#[inline]
pub fn neo_hookean_deviatoric<T: RealField + Copy>(
    p: &[Vector3<T>; 4],
    dm_inv: &Matrix3<T>,
) -> Option<Evaluated<T, 4>> {
    let f = deformation_gradient(p, dm_inv);
    let c = f.norm();
    let tiny = T::default_epsilon() * T::default_epsilon();
    if c.partial_cmp(&tiny) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    Some(Evaluated {
        c,
        grad: particle_gradients(&(f / c), dm_inv),
    })
}

/// Hydrostatic Neo-Hookean constraint `C_H = det F − γ` with `γ = 1 + μ/λ'`
/// ([`neo_hookean_rest_offset`]).
///
/// * `C_H` dimensionless; compliance `α_H = 1/(λ' V₀)` in 1/J, `λ' = λ + μ` (Pa).
/// * `∂C_H/∂F = cof F = [f1 × f2, f2 × f0, f0 × f1]`; `∇xᵢ C_H` = column `i − 1` of
///   `cof(F) Dm⁻ᵀ` (1/m), `∇x0 C_H = −Σᵢ ∇xᵢ C_H`.
///
/// Always finite for finite input, inverted (`det F < 0`) or flat tetrahedra included; the
/// gradients vanish only when `F` has rank ≤ 1 (all four points on a line).
#[inline]
pub fn neo_hookean_hydrostatic<T: RealField + Copy>(
    p: &[Vector3<T>; 4],
    dm_inv: &Matrix3<T>,
    gamma: T,
) -> Evaluated<T, 4> {
    let f = deformation_gradient(p, dm_inv);
    Evaluated {
        c: f.determinant() - gamma,
        grad: particle_gradients(&cofactor(&f), dm_inv),
    }
}

/// The rest offset `γ = 1 + μ/λ'` of [`neo_hookean_hydrostatic`], with `μ` and `λ' = λ + μ`
/// in Pa: the volume ratio at which the hydrostatic term balances the deviatoric one's pull
/// at rest.
#[inline]
pub fn neo_hookean_rest_offset<T: RealField + Copy>(mu: T, lambda_prime: T) -> T {
    T::one() + mu / lambda_prime
}

/// One coupled XPBD update of the two Neo-Hookean constraints of a tetrahedron: the
/// multiplier steps, the particle moves and the constraint values after them (to first order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeoHookeanUpdate<T: RealField + Copy> {
    /// `[Δλ_D, Δλ_H]`.
    pub delta_lambda: [T; 2],
    /// The move of each particle, `wᵢ (∇ᵢC_D Δλ_D + ∇ᵢC_H Δλ_H)`, m.
    pub moves: [Vector3<T>; 4],
    /// `[C_D, C_H]` after the moves, to first order: `C + G Δλ`.
    pub c_after: [T; 2],
}

/// The coupled XPBD update of the two Neo-Hookean constraints `d` (deviatoric) and `y`
/// (hydrostatic) of a tetrahedron, with damping in the XPBD form (Macklin et al. 2016,
/// eq. 26).
///
/// Solves the 2×2 system
///
/// ```text
/// ((1 + β/h) G + diag(α̃)) Δλ = −C − α̃ λ − (β/h) (∇C · (x − x̄)),
/// ```
///
/// `w` the particles' inverse masses (1/kg), `lambda = [λ_D, λ_H]`,
/// `alpha_tilde = [α_D/h², α_H/h²]` (1/(J·s²)), `G_ab = Σᵢ wᵢ ∇ᵢC_a · ∇ᵢC_b`,
/// `damping = β/h` with `β` the damping time (s; a damping force `β k Ċ` for a constraint of
/// stiffness `k = 1/α`, the same time for both terms) and `rate = [∇C_D·(x − x̄),
/// ∇C_H·(x − x̄)]`, the constraints' change since the substep start `x̄`.
///
/// Near rest the two gradients are nearly parallel (`∇C_H = √3 ∇C_D` at `F = I`), so `G` is
/// nearly singular and `det((1 + β/h)G + diag(α̃))` would be the difference of two nearly
/// equal products. The solve therefore splits `∇C_H = r ∇C_D + ∇⊥C_H` with
/// `r = G_DH / G_DD`, in which basis every term of the determinant is positive
/// (`G_HH − r G_DH = Σ wᵢ |∇ᵢ⊥C_H|²` is computed as a sum of squares), and moves the particles
/// by `wᵢ (∇ᵢC_D u + ∇ᵢ⊥C_H Δλ_H)` with `u = Δλ_D + r Δλ_H`: at rest, where the two
/// constraints' pulls cancel, nothing large is cancelled in f32.
///
/// `None` when the system is singular (all particles pinned, or the gradients vanishing with
/// zero compliance) or its result not finite.
#[inline]
pub fn neo_hookean_update<T: RealField + Copy>(
    d: &Evaluated<T, 4>,
    y: &Evaluated<T, 4>,
    w: [T; 4],
    lambda: [T; 2],
    alpha_tilde: [T; 2],
    damping: T,
    rate: [T; 2],
) -> Option<NeoHookeanUpdate<T>> {
    let zero = T::zero();
    let g_dd = (0..4).fold(zero, |s, i| s + w[i] * d.grad[i].norm_squared());
    let g_dh = (0..4).fold(zero, |s, i| s + w[i] * d.grad[i].dot(&y.grad[i]));
    let r = if g_dd > zero { g_dh / g_dd } else { zero };
    let perp: [Vector3<T>; 4] = std::array::from_fn(|i| y.grad[i] - d.grad[i] * r);
    let g_perp = (0..4).fold(zero, |s, i| s + w[i] * perp[i].norm_squared());
    let k = T::one() + damping;
    let [ad, ah] = alpha_tilde;
    let b0 = -d.c - ad * lambda[0] - damping * rate[0];
    let b1 = -y.c - ah * lambda[1] - damping * rate[1];
    // In the variables (u, Δλ_H), Δλ_D = u − r Δλ_H:
    //   (k G_DD + α̃_D) u − α̃_D r Δλ_H = b0
    //   k r G_DD u + (k G⊥ + α̃_H) Δλ_H = b1
    let p = k * g_dd + ad;
    let q = k * g_perp + ah;
    let det = p * q + ad * r * r * k * g_dd;
    if det.partial_cmp(&zero) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let u = (b0 * q + ad * r * b1) / det;
    let dl_h = (p * b1 - k * r * g_dd * b0) / det;
    let dl_d = u - r * dl_h;
    let moves: [Vector3<T>; 4] = std::array::from_fn(|i| (d.grad[i] * u + perp[i] * dl_h) * w[i]);
    let finite = u.is_finite() && dl_h.is_finite() && dl_d.is_finite();
    finite.then_some(NeoHookeanUpdate {
        delta_lambda: [dl_d, dl_h],
        moves,
        c_after: [d.c + g_dd * u, y.c + r * g_dd * u + g_perp * dl_h],
    })
}

/// The stable Neo-Hookean energy density `Ψ(F) = μ/2 (tr(FᵀF) − 3) + λ'/2 (det F − γ)² −
/// λ'/2 (1 − γ)²` (Pa = J/m³), shifted so that `Ψ(I) = 0`; `μ`, `λ'` in Pa. The energy of
/// the two constraints, `C_D²/(2α_D) + C_H²/(2α_H)`, is `V₀ Ψ` plus a constant.
#[inline]
pub fn neo_hookean_energy_density<T: RealField + Copy>(
    f: &Matrix3<T>,
    mu: T,
    lambda_prime: T,
) -> T {
    let half = nalgebra::convert::<f64, T>(0.5);
    let three = nalgebra::convert::<f64, T>(3.0);
    let gamma = neo_hookean_rest_offset(mu, lambda_prime);
    let j = f.determinant() - gamma;
    let j0 = T::one() - gamma;
    half * mu * (f.norm_squared() - three) + half * lambda_prime * (j * j - j0 * j0)
}

/// The first Piola–Kirchhoff stress `P = ∂Ψ/∂F = μF + λ'(det F − γ) cof F` (Pa) of
/// [`neo_hookean_energy_density`]; `μ`, `λ'` in Pa. The force a tetrahedron's material puts
/// on its corner `i = 1, 2, 3` is column `i − 1` of `−V₀ P Dm⁻ᵀ`.
#[inline]
pub fn neo_hookean_stress<T: RealField + Copy>(
    f: &Matrix3<T>,
    mu: T,
    lambda_prime: T,
) -> Matrix3<T> {
    let gamma = neo_hookean_rest_offset(mu, lambda_prime);
    f * mu + cofactor(f) * (lambda_prime * (f.determinant() - gamma))
}
