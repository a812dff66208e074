//! Rolling resistance: a couple between a soft body and each collider it touches that
//! opposes their relative rotation (rolling and spinning), bounded by the normal impulse.
//!
//! Why: a soft body is stiff enough to roll like a rigid one, and rolling with sticking
//! friction does no work, so nothing in the contacts takes the energy of a rocking or
//! rolling body; [`tetpbd::DeformationDamping`] only damps deformation, not the rigid
//! rotation. On immovable colliders the passivity of the contacts takes that energy out
//! (`response::passivity`: a blob dropped on its rounded belly on the ground rests within
//! 7 s without rolling resistance, `tests/rolling_blob_comes_to_rest.rs`); on a dynamic or
//! moving collider, where passivity does not act, nothing else does. Real bodies stop
//! because the contact patch deforms with hysteresis, which moves the normal force ahead of
//! the contact point: a resisting couple of at most `c_rr · N · R` (`c_rr` the rolling
//! resistance coefficient, `N` the normal force, `R` the lever from the centre of mass to the
//! contact). This module applies that couple.
//!
//! After each substep's velocity pass, per soft body and collider with active contacts:
//!
//! ```text
//! J_n   = Σ λ_n / h                      normal impulse of the substep's contacts, N·s
//! q     = mean contact point,  R = |q − x_cm|
//! ω_rel = ω_body − ω_collider            ω_body from the body's rigid fit (`Particles::rigid_fit`)
//! β     = min(1, c_rr · J_n · R / |I ω_rel|)
//! vᵢ   += (−β ω_rel) × (xᵢ − x_cm)        for every free particle
//! ```
//!
//! The body's linear momentum is unchanged and its kinetic energy can only drop
//! (`ΔE = −β(1 − β/2) ω_relᵀ I ω_rel` against a fixed collider); a dynamic collider body gets
//! the opposite angular impulse as a couple (two opposite forces, no net linear impulse),
//! and the stopping impulse `I ω_rel` is first scaled by `w_s / (w_s + w_b)`, the soft and
//! rigid inverse inertias `ûᵀI⁻¹û` about its axis, so a light rigid body is not spun past
//! the relative rest.
//! Bodies with pinned particles are anchored and skipped.
//!
//! Cost: one rigid fit per soft body in contact per substep (two passes over its
//! particles, like the deformation damping) and one pass to apply the change: on the
//! `asset_drop` blob at rest (468 particles, 10 substeps) about 2.0–2.1 ms per frame against
//! 1.5–1.9 ms with the coefficient 0 (release, a loaded 2-core machine). In accuracy:
//! a rolling body slows at `c_rr · N · R / I` rad/s², and a body can rest tilted as long as
//! its centre of mass is within `c_rr · R` of the support point (0.01 · 0.17 m ≈ 2 mm for the
//! example's blob with `c_rr` = 0.01).
//!
//! Off by default (`c_rr` = 0): as a default of 0.01 it tipped two marginal existing cases
//! — the stability suite's 1000 kg rigid box on a 1 kg slab (20 substeps of 5 iterations,
//! vertex–face + edges) exploded, and a small cube dropped on a round cuboid still moved at
//! 0.02 m/s after 3 s (`collision_ground`). The box case exploded even at 0.001 with the
//! normal impulse capped at the slab's own weight, a couple of at most 4·10⁻⁷ N·m·s per
//! substep, and held at 10⁻⁶, so it looks sensitive to any perturbation rather than driven
//! by the resistance, but that was not settled.

use nalgebra::Vector3;
use tetpbd::{Particles, RigidFit};

use crate::contacts::corner::CornerContact;
use crate::contacts::particle::ParticleContact;
use crate::response::restitution::active_colliders;
use crate::rigid::body::BodyProxy;
use crate::rigid::collider::ColliderProxy;

/// Applies the rolling resistance of one soft body for a substep of length `h`. `active` is
/// scratch space (its capacity is reused); `fit` the body's rigid fit when the substep
/// already took it (`response::passivity`), else it is taken here.
#[allow(clippy::too_many_arguments)]
pub(crate) fn rolling_pass(
    active: &mut Vec<usize>,
    contacts: &[ParticleContact],
    corners: &[CornerContact],
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    coefficient: f32,
    h: f32,
    fit: Option<RigidFit>,
) {
    if coefficient <= 0.0 || p.inv_masses().contains(&0.0) {
        return;
    }
    active_colliders(active, contacts, corners);
    if active.is_empty() {
        return;
    }
    let Some(mut fit) = fit.or_else(|| p.rigid_fit()) else {
        return;
    };
    for &ci in active.iter() {
        let Some((lambda, q)) = normal_load(ci, contacts, corners) else {
            continue;
        };
        let cp = &colliders[ci];
        let w_collider = cp
            .body
            .map_or(Vector3::zeros(), |b| angular_velocity(&bodies[b]));
        let w_rel = fit.angular_velocity - w_collider;
        let stop = stopping_impulse(&fit, &w_rel, cp.body.map(|b| &bodies[b]));
        let need = stop.norm();
        let cap = coefficient * (lambda / h) * (q - fit.centre).norm();
        if need.is_nan() || need <= 0.0 || !cap.is_finite() {
            continue;
        }
        let beta = (cap / need).min(1.0);
        let dw = -(fit.inverse_inertia * stop) * beta;
        if !dw.iter().all(|c| c.is_finite()) {
            continue;
        }
        for i in 0..p.len() {
            if p.inv_masses()[i] > 0.0 {
                let r = p.positions()[i] - fit.centre;
                p.velocities_mut()[i] += dw.cross(&r);
            }
        }
        fit.angular_velocity += dw;
        if let Some(b) = cp.body {
            apply_couple(&mut bodies[b], &(stop * beta), &q);
        }
    }
}

/// `ûᵀ I⁻¹ û` for the unit direction `û` of `axis`, 1/(kg·m²); 0 for a zero axis.
/// Summed normal multiplier (kg·m) and mean point (world, m) of a soft body's active
/// contacts with collider `ci`; `None` without a load.
fn normal_load(
    ci: usize,
    contacts: &[ParticleContact],
    corners: &[CornerContact],
) -> Option<(f32, Vector3<f32>)> {
    let mut lambda = 0.0f32;
    let mut q = Vector3::zeros();
    let mut count = 0usize;
    for c in contacts
        .iter()
        .filter(|c| c.collider == ci && c.active && c.solve)
    {
        lambda += c.lambda_n;
        q += c.point;
        count += 1;
    }
    for k in corners.iter().filter(|k| k.collider == ci && k.active) {
        lambda += k.lambda_n;
        q += k.point;
        count += 1;
    }
    if count == 0 || lambda.is_nan() || lambda <= 0.0 {
        return None;
    }
    Some((lambda, q / count as f32))
}

/// The angular impulse (kg·m²/s) that stops the soft body's rotation `w_rel` relative to
/// the collider. A dynamic body turns back under the reaction: the impulse is then smaller
/// by the ratio of the two bodies' inverse inertias about its axis (`I_s⁻¹` of the soft
/// body, `I_b⁻¹` of the rigid one).
fn stopping_impulse(
    fit: &RigidFit,
    w_rel: &Vector3<f32>,
    body: Option<&BodyProxy>,
) -> Vector3<f32> {
    let mut stop = fit.inertia * w_rel;
    if let Some(body) = body {
        let rigid = inv_inertia_about(body, &stop);
        if rigid > 0.0 {
            let soft = inv_inertia_along(&fit.inverse_inertia, &stop);
            if soft > 0.0 {
                stop *= soft / (soft + rigid);
            }
        }
    }
    stop
}

fn inv_inertia_along(inv: &nalgebra::Matrix3<f32>, axis: &Vector3<f32>) -> f32 {
    let u = axis.try_normalize(0.0).unwrap_or_else(Vector3::zeros);
    u.dot(&(inv * u))
}

/// `ûᵀ I⁻¹ û` of a rigid proxy about the direction of `axis`, 1/(kg·m²), from its
/// generalized inverse masses: for a unit `a ⟂ û` and `n = û × a`, `a × n = û`, so the
/// inverse mass for `n` at `com + a` exceeds the one at `com` by `ûᵀ I⁻¹ û`. 0 for fixed,
/// kinematic and supported bodies (infinitely heavy inside the substeps).
fn inv_inertia_about(body: &BodyProxy, axis: &Vector3<f32>) -> f32 {
    let Some((a, n)) = couple(axis) else {
        return 0.0;
    };
    let n = n.try_normalize(0.0).unwrap_or_else(Vector3::zeros);
    let c = body.com();
    (body.inv_mass_at(&(c + a), &n) - body.inv_mass_at(&c, &n)).max(0.0)
}

/// Angular velocity of a rigid proxy, rad/s, from the velocities of its material points:
/// with `uₖ = v(c + eₖ) − v(c) = ω × eₖ`, `Σₖ eₖ × uₖ = 2ω`.
fn angular_velocity(body: &BodyProxy) -> Vector3<f32> {
    let c = body.com();
    let vc = body.velocity_at(&c);
    let mut sum = Vector3::zeros();
    for k in 0..3 {
        let e = Vector3::ith(k, 1.0);
        sum += e.cross(&(body.velocity_at(&(c + e)) - vc));
    }
    sum * 0.5
}

/// Gives `body` the angular impulse `tau` (N·m·s) as a couple (see [`couple`]) at `q`.
fn apply_couple(body: &mut BodyProxy, tau: &Vector3<f32>, q: &Vector3<f32>) {
    if let Some((a, f)) = couple(tau) {
        body.apply_velocity_impulse(&f, &(q + a));
        body.apply_velocity_impulse(&(-f), q);
    }
}

/// A couple with moment `tau`: the force `f` applied at an offset `a` (unit, perpendicular
/// to `tau`) from a point, and `−f` at the point, since `a × (τ × a) = τ`. `None` for a zero
/// or non-finite `tau`.
fn couple(tau: &Vector3<f32>) -> Option<(Vector3<f32>, Vector3<f32>)> {
    let len = tau.norm();
    if len.is_nan() || len <= 0.0 || !len.is_finite() {
        return None;
    }
    let axis = tau / len;
    let a = axis.cross(&Vector3::x());
    let a = if a.norm_squared() > 0.25 {
        a.normalize()
    } else {
        axis.cross(&Vector3::y()).normalize()
    };
    Some((a, tau.cross(&a)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn couple_has_the_moment_and_no_net_force() {
        for tau in [
            Vector3::new(0.3, -1.0, 2.0),
            Vector3::x() * 5.0,
            Vector3::y() * 1e-3,
        ] {
            let (a, f) = couple(&tau).unwrap();
            assert!((a.norm() - 1.0).abs() < 1e-5);
            assert!((a.cross(&f) - tau).norm() < 1e-5 * tau.norm());
        }
        assert!(couple(&Vector3::zeros()).is_none());
        assert!(couple(&Vector3::new(f32::NAN, 0.0, 0.0)).is_none());
    }
}
