//! Positional Coulomb friction (Müller et al. 2020), one rule for every contact kind.
//!
//! A contact joins two sides, each a *stencil*: a particle, a soft triangle's point with
//! barycentric weights `β`, or a rigid body's material point. After the normal projection of
//! the contact (multiplier `λ_n`, unit normal `n`), the relative displacement of the first
//! side against the second over the substep, `Δp`, has a tangential part
//!
//! ```text
//! Δp_t = Δp − (n·Δp) n,   t = Δp_t / |Δp_t|
//! w    = Σ_k w_k β_k² + w_rigid(r, t)     (both sides; w_rigid = 0 without a body), 1/kg
//! Δλ_t = |Δp_t| / w                                    (removes all of Δp_t)
//! ```
//!
//! which is removed completely while the accumulated tangential multiplier stays under the
//! static cone, `λ_t + Δλ_t ≤ μ_s λ_n` (sticking); otherwise only up to the dynamic cone,
//! `Δλ_t ≤ μ_d λ_n − λ_t` (sliding). The first side moves by `−t Δλ_t` and the second by
//! `+t Δλ_t`, each share weighted by its inverse masses (and `β`).
//!
//! Contacts against rigid colliders ([`crate::contacts::particle`],
//! [`crate::contacts::corner`]) and between soft bodies ([`crate::soft_soft`]) implement
//! [`ContactStencil`] and call [`positional_friction`].

use nalgebra::Vector3;

/// The two sides of a contact, as friction sees them.
pub(crate) trait ContactStencil {
    /// Displacement over the substep of the first side relative to the second at the
    /// contact point, m.
    fn relative_motion(&self) -> Vector3<f32>;
    /// Sum of both sides' generalised inverse masses along the unit direction `t`, 1/kg.
    fn inv_mass(&self, t: &Vector3<f32>) -> f32;
    /// Moves the first side by `−t·dl` and the second by `+t·dl` (`dl`: kg·m), each
    /// weighted by its inverse masses.
    fn apply(&mut self, t: &Vector3<f32>, dl: f32);
}

/// The friction state of one contact within a substep.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Coulomb {
    /// Normal multiplier accumulated in the substep, kg·m.
    pub lambda_n: f32,
    /// Static and dynamic friction coefficients.
    pub mu_s: f32,
    pub mu_d: f32,
}

/// Applies positional Coulomb friction to one contact just projected along its unit normal
/// `n` (module docs); `lambda_t` (kg·m) is the contact's tangential multiplier accumulated in
/// the substep and grows by what is applied. Returns the direction `t` the first side was
/// pushed against (it moved by `−t·dl`) and `dl`, or `None` when nothing was applied (no
/// tangential motion, no mobile mass, or the cone is used up).
pub(crate) fn positional_friction(
    stencil: &mut impl ContactStencil,
    n: &Vector3<f32>,
    coulomb: Coulomb,
    lambda_t: &mut f32,
) -> Option<(Vector3<f32>, f32)> {
    let dp = stencil.relative_motion();
    let dpt = dp - n * n.dot(&dp);
    let len = dpt.norm();
    if len.is_nan() || len <= 1e-9 || !len.is_finite() {
        return None;
    }
    let t = dpt / len;
    let w = stencil.inv_mass(&t);
    if w.is_nan() || w <= 0.0 {
        return None;
    }
    let full = len / w;
    let applied = if *lambda_t + full <= coulomb.mu_s * coulomb.lambda_n {
        full
    } else {
        full.min((coulomb.mu_d * coulomb.lambda_n - *lambda_t).max(0.0))
    };
    if applied.is_nan() || applied <= 0.0 || !applied.is_finite() {
        return None;
    }
    stencil.apply(&t, applied);
    *lambda_t += applied;
    Some((t, applied))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One particle (inverse mass `w`) sliding by `motion` over a fixed plane.
    struct OnPlane {
        x: Vector3<f32>,
        motion: Vector3<f32>,
        w: f32,
    }

    impl ContactStencil for OnPlane {
        fn relative_motion(&self) -> Vector3<f32> {
            self.motion
        }
        fn inv_mass(&self, _t: &Vector3<f32>) -> f32 {
            self.w
        }
        fn apply(&mut self, t: &Vector3<f32>, dl: f32) {
            self.x -= t * (self.w * dl);
        }
    }

    fn slide(motion: Vector3<f32>, lambda_n: f32, mu: f32) -> (Vector3<f32>, f32) {
        let mut s = OnPlane {
            x: Vector3::zeros(),
            motion,
            w: 2.0,
        };
        let mut lambda_t = 0.0;
        let c = Coulomb {
            lambda_n,
            mu_s: mu,
            mu_d: mu,
        };
        positional_friction(&mut s, &Vector3::y(), c, &mut lambda_t);
        (s.x, lambda_t)
    }

    #[test]
    fn sticking_removes_the_tangential_motion_and_sliding_is_capped_by_the_cone() {
        let n = Vector3::y();
        for &(dx, dy, lambda_n, mu) in &[
            (1e-3, 5e-4, 1.0, 0.5),
            (0.2, -0.1, 1e-3, 0.3),
            (-0.05, 0.0, 0.02, 1.0),
            (0.0, 0.3, 1.0, 0.5),
        ] {
            let motion = Vector3::new(dx, dy, 0.5 * dx);
            let (x, lambda_t) = slide(motion, lambda_n, mu);
            let tangential = motion - n * n.dot(&motion);
            // Never pushed along the normal, never against the motion's opposite, never past
            // the cone.
            assert!(x.dot(&n).abs() < 1e-9);
            assert!(lambda_t <= mu * lambda_n + 1e-6);
            let removed = -x;
            assert!(removed.dot(&tangential) >= 0.0);
            assert!(removed.norm() <= tangential.norm() + 1e-6);
            let full = tangential.norm() / 2.0;
            if full <= mu * lambda_n {
                assert!(
                    (removed - tangential).norm() < 1e-5,
                    "sticking: all removed"
                );
            } else {
                assert!(
                    (lambda_t - mu * lambda_n).abs() < 1e-6,
                    "sliding: at the cone"
                );
            }
        }
    }

    #[test]
    fn no_mobile_mass_or_no_motion_applies_nothing() {
        let c = Coulomb {
            lambda_n: 1.0,
            mu_s: 1.0,
            mu_d: 1.0,
        };
        for (motion, w) in [
            (Vector3::x(), 0.0),
            (Vector3::zeros(), 1.0),
            (Vector3::x(), f32::NAN),
        ] {
            let mut s = OnPlane {
                x: Vector3::zeros(),
                motion,
                w,
            };
            let mut lambda_t = 0.0;
            assert!(positional_friction(&mut s, &Vector3::y(), c, &mut lambda_t).is_none());
            assert_eq!(lambda_t, 0.0);
            assert_eq!(s.x, Vector3::zeros());
        }
    }
}
