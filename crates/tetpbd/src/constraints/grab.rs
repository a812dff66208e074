//! The grab constraint: a material point held to a target point, with a bounded force.

use nalgebra::{RealField, Vector3};

use super::Evaluated;

// ---------------------------------------------------------------------------------------
// Grab (material point to target).
//
// p = Σ bₖ xₖ (the material point, bₖ its barycentric coordinates, fixed), t the target.
// C = |p − t|. With n = (p − t)/|p − t|: ∇xₖ C = bₖ n, Σ wₖ|∇ₖC|² = Σ wₖ bₖ².
// A point on its target has no direction: C = 0 there and nothing is to be done.
//
// Force bound: with α̃ = α/h², the force the constraint exerts over a substep is
// ∇C λ / h² (magnitude |λ|/h², towards the target as λ ≤ 0), so |force| ≤ F_max is |λ| ≤ F_max h². C ≥ 0, so λ ≤ 0:
// λ is kept in [−F_max h², 0] and the step is Δλ = clamp(λ + Δλ) − λ.
// ---------------------------------------------------------------------------------------

/// Grab constraint `C = |Σ bₖ xₖ − t|` between the material point with barycentric
/// coordinates `b` in the tetrahedron `x` and the target `t`.
///
/// * `C` in metres, compliance in m/N (the spring `1/α` in N/m holding the point to the
///   target), maximum force in N ([`grab_delta_lambda`]).
/// * `∇xₖ C = bₖ (p − t) / |p − t|` with `p = Σ bₖ xₖ`.
///
/// Returns `None` when the point is on its target (`|p − t|` zero or not finite): there is
/// no direction and nothing to correct.
#[inline]
pub fn grab<T: RealField + Copy>(
    x: [&Vector3<T>; 4],
    b: [T; 4],
    target: &Vector3<T>,
) -> Option<Evaluated<T, 4>> {
    let p = x
        .iter()
        .zip(&b)
        .fold(Vector3::zeros(), |acc, (x, b)| acc + *x * *b);
    let d = p - target;
    let len = d.norm();
    if !(len > T::zero() && len.is_finite()) {
        return None;
    }
    let n = d / len;
    Some(Evaluated {
        c: len,
        grad: b.map(|b| n * b),
    })
}

/// The grab's multiplier step: the XPBD step ([`super::xpbd_delta_lambda`]) with the
/// accumulated multiplier kept in `[−max_force · h², 0]`, so the force the grab exerts
/// over the substep never exceeds `max_force` (N; `f32::INFINITY` for no bound). `h` is the
/// substep length, s. Returns `None` as [`super::xpbd_delta_lambda`] does.
#[inline]
pub fn grab_delta_lambda<T: RealField + Copy>(
    c: T,
    lambda: T,
    alpha_tilde: T,
    w_grad_sq: T,
    max_force: T,
    h: T,
) -> Option<T> {
    let dl = super::xpbd_delta_lambda(c, lambda, alpha_tilde, w_grad_sq)?;
    let floor = -(max_force * h * h);
    Some((lambda + dl).max(floor).min(T::zero()) - lambda)
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::grab;

    /// Seeded values in [-1, 1).
    fn next(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    #[test]
    fn grab_gradient_matches_central_differences() {
        let mut seed = 7u64;
        for _ in 0..200 {
            let mut x = [Vector3::<f64>::zeros(); 4];
            for c in &mut x {
                *c = Vector3::new(next(&mut seed), next(&mut seed), next(&mut seed));
            }
            let raw = [0; 4].map(|_| next(&mut seed).abs() + 0.05);
            let s: f64 = raw.iter().sum();
            let b = raw.map(|r| r / s);
            let t = Vector3::new(next(&mut seed), next(&mut seed), next(&mut seed)) * 2.0;
            let Some(e) = grab([&x[0], &x[1], &x[2], &x[3]], b, &t) else {
                continue;
            };
            let eps = 1e-6;
            for k in 0..4 {
                for a in 0..3 {
                    let (mut xp, mut xm) = (x, x);
                    xp[k][a] += eps;
                    xm[k][a] -= eps;
                    let cp = grab([&xp[0], &xp[1], &xp[2], &xp[3]], b, &t).unwrap().c;
                    let cm = grab([&xm[0], &xm[1], &xm[2], &xm[3]], b, &t).unwrap().c;
                    let fd = (cp - cm) / (2.0 * eps);
                    assert!(
                        (fd - e.grad[k][a]).abs() < 1e-6,
                        "corner {k} axis {a}: fd {fd}, analytic {}",
                        e.grad[k][a]
                    );
                }
            }
        }
    }

    #[test]
    fn a_point_on_its_target_has_nothing_to_correct() {
        let x = [
            Vector3::<f64>::zeros(),
            Vector3::x(),
            Vector3::y(),
            Vector3::z(),
        ];
        let b = [0.25; 4];
        let p = (x[1] + x[2] + x[3]) * 0.25;
        assert!(grab([&x[0], &x[1], &x[2], &x[3]], b, &p).is_none());
    }

    #[test]
    fn grab_multiplier_stays_within_the_force_bound() {
        let mut seed = 3u64;
        for _ in 0..500 {
            let h = 1e-3 + next(&mut seed).abs() * 1e-2;
            let f_max = next(&mut seed).abs() * 100.0;
            let mut lambda = 0.0;
            for _ in 0..5 {
                let c = next(&mut seed).abs() * 2.0;
                let dl =
                    super::grab_delta_lambda(c, lambda, 1e-4 / (h * h), 0.5, f_max, h).unwrap();
                lambda += dl;
                assert!(lambda <= 0.0 && lambda >= -f_max * h * h * (1.0 + 1e-12));
            }
        }
    }
}
