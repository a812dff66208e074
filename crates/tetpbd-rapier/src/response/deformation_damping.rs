//! [`DeformationDamping`]: damps a soft body's motion relative to its rigid motion (a hecs
//! component), the velocity damping of Müller et al. 2006 ("Position Based Dynamics", §3.5).
//!
//! After every substep, with `x_cm`, `v_cm` the body's centre of mass and its velocity,
//! `rᵢ = xᵢ − x_cm`, `L = Σ rᵢ × mᵢvᵢ`, `I = Σ mᵢ [rᵢ]ₓ[rᵢ]ₓᵀ` and `ω = I⁻¹L`:
//!
//! ```text
//! vᵢ ← vᵢ + k (v_cm + ω × rᵢ − vᵢ),     k = 1 − exp(−rate · h)
//! ```
//!
//! Linear and angular momentum are preserved; only deformation is damped. Without it a
//! stiff XPBD body stores the energy of an impact in its constraints and springs back, so
//! it bounces even off a contact with restitution 0: give bodies that should behave like
//! dead rubber some damping.

use nalgebra::{Matrix3, Vector3};
use tetpbd::Particles;

use crate::error::{check_coefficient, CouplingError};

/// Deformation damping rate of one soft body, 1/s (a hecs component).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeformationDamping {
    rate: f32,
}

impl DeformationDamping {
    /// Damping rate, 1/s (finite, ≥ 0; 0 = none).
    pub fn new(rate: f32) -> Result<Self, CouplingError> {
        Ok(DeformationDamping {
            rate: check_coefficient("deformation damping rate (1/s)", rate)?,
        })
    }

    /// The rate, 1/s.
    pub fn rate(&self) -> f32 {
        self.rate
    }
}

/// The rigid motion that best fits a soft body's free particles (pinned ones excluded):
/// centre of mass `x_cm` (m), its velocity `v_cm` (m/s), the inertia tensor about it
/// `I = Σ mᵢ [rᵢ]ₓ[rᵢ]ₓᵀ` (kg·m²) and the angular velocity `ω = I⁻¹ Σ rᵢ × mᵢvᵢ` (rad/s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RigidFit {
    pub x_cm: Vector3<f32>,
    pub v_cm: Vector3<f32>,
    pub inertia: Matrix3<f32>,
    pub omega: Vector3<f32>,
}

impl RigidFit {
    /// The fit of `p`; `None` without free mass or when the result is not finite.
    pub fn of(p: &Particles) -> Option<RigidFit> {
        let mut m = 0.0f32;
        let mut x_cm = Vector3::zeros();
        let mut v_cm = Vector3::zeros();
        for i in 0..p.len() {
            if p.inv_masses()[i] > 0.0 {
                let mi = p.masses()[i];
                m += mi;
                x_cm += p.positions()[i] * mi;
                v_cm += p.velocities()[i] * mi;
            }
        }
        if m <= 0.0 {
            return None;
        }
        x_cm /= m;
        v_cm /= m;
        let mut l = Vector3::zeros();
        let mut inertia = Matrix3::zeros();
        for i in 0..p.len() {
            if p.inv_masses()[i] > 0.0 {
                let mi = p.masses()[i];
                let r = p.positions()[i] - x_cm;
                l += r.cross(&(p.velocities()[i] * mi));
                let rx = r.cross_matrix();
                inertia += rx * rx.transpose() * mi;
            }
        }
        let omega = inertia
            .try_inverse()
            .map_or(Vector3::zeros(), |inv| inv * l);
        omega.iter().all(|c| c.is_finite()).then_some(RigidFit {
            x_cm,
            v_cm,
            inertia,
            omega,
        })
    }
}

/// Applies the damping to `p` for a substep of length `h`.
pub(crate) fn damp(p: &mut Particles, rate: f32, h: f32) {
    let k = 1.0 - (-rate * h).exp();
    if k <= 0.0 {
        return;
    }
    let Some(fit) = RigidFit::of(p) else {
        return;
    };
    for i in 0..p.len() {
        if p.inv_masses()[i] > 0.0 {
            let r = p.positions()[i] - fit.x_cm;
            let target = fit.v_cm + fit.omega.cross(&r);
            let v = &mut p.velocities_mut()[i];
            *v += (target - *v) * k;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tetpbd::generators::{box_grid, CellSplit};
    use tetpbd::SoftBodyBuilder;

    #[test]
    fn keeps_momentum_and_damps_deformation() {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [1, 1, 1], CellSplit::Six).unwrap();
        let mut p = SoftBodyBuilder::new(mesh).build().unwrap().particles;
        for i in 0..p.len() {
            let x = p.positions()[i];
            // Translation + rotation about z + an expansion (deformation).
            let v = Vector3::new(1.0, 0.0, 0.0) + Vector3::z().cross(&x) + x * 2.0;
            p.set_velocity(i, v).unwrap();
        }
        let (lin, ang) = (p.linear_momentum(), p.angular_momentum());
        let deformation = |p: &Particles| {
            (0..p.len())
                .map(|i| p.velocities()[i].dot(&p.positions()[i]))
                .sum::<f32>()
        };
        let before = deformation(&p);
        damp(&mut p, 100.0, 0.01);
        assert!((p.linear_momentum() - lin).norm() < 1e-4 * lin.norm());
        assert!((p.angular_momentum() - ang).norm() < 1e-4 * ang.norm());
        let after = deformation(&p);
        assert!(after < 0.5 * before, "deformation {before} -> {after}");
        assert!(DeformationDamping::new(-1.0).is_err());
    }
}
