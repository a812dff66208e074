//! [`DeformationDamping`]: damps a soft body's motion relative to its rigid motion (a hecs
//! component), the velocity damping of Müller et al. 2006 ("Position Based Dynamics", §3.5).
//!
//! After every substep's velocity update ([`crate::systems::update_velocities`]), before the
//! hook's [`crate::SubstepHook::end_substep`], with the body's [`RigidFit`] over its free
//! particles (centre of mass `c`, its velocity `v_c`, angular velocity `ω`):
//!
//! ```text
//! vᵢ ← vᵢ + k (v_c + ω × rᵢ − vᵢ),     rᵢ = xᵢ − c,   k = 1 − exp(−rate · h)
//! ```
//!
//! for every free particle. `v_c + ω × rᵢ` is the least-squares rigid motion of the
//! velocities, so the change `k (v_c + ω × rᵢ − vᵢ)` carries no linear and no angular
//! momentum (where `I` is invertible): only deformation is damped. Without it a stiff XPBD
//! body stores the energy of an impact in its constraints and springs back, so it bounces
//! even off a contact with restitution 0: give bodies that should behave like dead rubber
//! some damping.
//!
//! Cost: one rigid fit (one pass over the particles and a 3×3 eigen-decomposition) and one
//! pass to apply the change, per damped body and substep. A body without the component pays
//! nothing.

use hecs::World;

use crate::body::particles::Particles;
use crate::error::SettingsError;
#[cfg(doc)]
use crate::stabilisation::rigid_fit::RigidFit;

/// Deformation damping rate of one soft body, 1/s (a hecs component; module docs of
/// `stabilisation::deformation_damping` for the rule).
///
/// ```
/// use tetpbd::DeformationDamping;
/// let d = DeformationDamping::new(5.0)?;
/// assert_eq!(d.rate(), 5.0);
/// assert!(DeformationDamping::new(-1.0).is_err());
/// # Ok::<(), tetpbd::SettingsError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeformationDamping {
    rate: f32,
}

impl DeformationDamping {
    /// Damping rate, 1/s (finite, ≥ 0; 0 = none).
    pub fn new(rate: f32) -> Result<Self, SettingsError> {
        if rate.is_finite() && rate >= 0.0 {
            Ok(DeformationDamping { rate })
        } else {
            Err(SettingsError::BadDamping { value: rate })
        }
    }

    /// The rate, 1/s.
    pub fn rate(&self) -> f32 {
        self.rate
    }
}

/// Damps the deformation of every body with a [`DeformationDamping`] for a substep of length
/// `h` (s). [`crate::Solver`] runs it right after the velocity update.
pub fn damp_deformation(world: &mut World, h: f32) {
    let q = world.query_mut::<(&mut Particles, &DeformationDamping)>();
    for (p, d) in q.without::<&crate::Asleep>() {
        damp(p, d.rate, h);
    }
}

/// Applies the damping to one body.
fn damp(p: &mut Particles, rate: f32, h: f32) {
    let k = 1.0 - (-rate * h).exp();
    if k.is_nan() || k <= 0.0 {
        return;
    }
    let Some(fit) = p.rigid_fit() else {
        return;
    };
    let Particles {
        positions,
        velocities,
        inv_masses,
        ..
    } = p;
    for ((v, x), w) in velocities.iter_mut().zip(&*positions).zip(&*inv_masses) {
        if *w > 0.0 {
            *v += (fit.velocity_at(x) - *v) * k;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generators::{box_grid, CellSplit};
    use crate::{SoftBodyBuilder, Solver, SolverSettings};
    use nalgebra::Vector3;

    /// Sum of `vᵢ·xᵢ`: the expansion rate of a body centred on the origin.
    fn expansion(p: &Particles) -> f32 {
        (0..p.len())
            .map(|i| p.velocities()[i].dot(&p.positions()[i]))
            .sum()
    }

    #[test]
    fn damping_keeps_momentum_and_damps_deformation() {
        for (cells, rate, spin) in [(1, 100.0, 1.0), (2, 10.0, -3.0), (3, 1000.0, 0.2)] {
            let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Six).unwrap();
            let mut p = SoftBodyBuilder::new(mesh).build().unwrap().particles;
            for i in 0..p.len() {
                let x = p.positions()[i];
                // Translation + rotation about an axis + an expansion (deformation).
                let axis = Vector3::new(0.2, 1.0, -0.4) * spin;
                let v = Vector3::new(1.0, 0.0, 0.0) + axis.cross(&x) + x * 2.0;
                p.set_velocity(i, v).unwrap();
            }
            let (lin, ang) = (p.linear_momentum(), p.angular_momentum());
            let before = expansion(&p);
            damp(&mut p, rate, 0.01);
            assert!((p.linear_momentum() - lin).norm() < 1e-4 * lin.norm());
            assert!((p.angular_momentum() - ang).norm() < 1e-4 * ang.norm());
            let after = expansion(&p);
            let k = 1.0 - (-rate * 0.01f32).exp();
            assert!(
                (after - (1.0 - k) * before).abs() < 1e-3 * before,
                "{cells} cells, rate {rate}: expansion {before} -> {after}"
            );
        }
    }

    #[test]
    fn solver_damps_a_vibrating_body_and_leaves_a_spinning_one_spinning() {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [2, 2, 2], CellSplit::Six).unwrap();
        let settings = SolverSettings {
            gravity: Vector3::zeros(),
            ..Default::default()
        };
        let energy_after = |damping: Option<f32>, vibrate: bool| {
            let mut world = World::new();
            // Compliant enough to vibrate (a period of about 0.4 s) rather than stop at once.
            let body = SoftBodyBuilder::new(mesh.clone())
                .edges(1e-4)
                .volume(1e-4)
                .build()
                .unwrap()
                .spawn(&mut world);
            if let Some(rate) = damping {
                let d = DeformationDamping::new(rate).unwrap();
                world.insert_one(body, d).unwrap();
            }
            {
                let mut p = world.get::<&mut Particles>(body).unwrap();
                let c = p.center_of_mass();
                for i in 0..p.len() {
                    let r = p.positions()[i] - c;
                    let v = if vibrate {
                        r * 3.0
                    } else {
                        Vector3::y().cross(&r)
                    };
                    p.set_velocity(i, v).unwrap();
                }
            }
            let mut solver = Solver::new(settings.clone()).unwrap();
            let e0 = world.get::<&Particles>(body).unwrap().kinetic_energy();
            // The largest kinetic energy over the last 25 frames (more than a period).
            let mut e = 0.0f32;
            for frame in 0..60 {
                solver.step(&mut world).unwrap();
                if frame >= 35 {
                    e = e.max(world.get::<&Particles>(body).unwrap().kinetic_energy());
                }
            }
            e / e0
        };
        // A vibration loses its energy to the damping, far faster than without it.
        let (free, damped) = (energy_after(None, true), energy_after(Some(20.0), true));
        assert!(
            free > 0.1 && damped < 1e-3 * free,
            "vibration {free} -> {damped}"
        );
        // A rigid rotation is not deformation: the damping leaves its energy alone.
        let spin = energy_after(Some(20.0), false);
        assert!(
            spin > 0.95 && spin < 1.001,
            "rotation kept {spin} of its energy"
        );
    }
}
