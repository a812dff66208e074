//! Particle–collider contacts: XPBD inequality constraints with Coulomb friction, and the
//! velocity pass for restitution.
//!
//! Per iteration, for surface particle `p` and the closest point `q` on the collider (normal
//! `n` from the collider to the particle, thickness `δ`):
//!
//! ```text
//! C   = (p − q)·n − δ ≥ 0                      (only violated contacts are projected)
//! w   = w_p + w_rigid,   w_rigid = nᵀM⁻¹n + (r×n)ᵀ I⁻¹ (r×n)   (0 for fixed/kinematic)
//! Δλ  = −C / w,   p += w_p n Δλ,   rigid body gets −n Δλ at q
//! ```
//!
//! Friction (positional, Müller et al. 2020): the relative tangential displacement `Δp_t` of
//! the particle against the body's material point over the substep is removed completely
//! while the accumulated tangential multiplier stays under `μ_s λ_n` (sticking), otherwise
//! only up to `μ_d λ_n` (sliding).
//!
//! A particle whose motion relative to the collider entered the shape during the substep
//! (a fast body, or a thin shape) takes the entry point and entry face's normal as `q` and
//! `n` instead of the closest point, which may lie on the far side (`sweep` module docs).
//!
//! Overlap a soft body is created with (its first frame in the coupling, a particle already
//! inside a collider) is not resolved at once: the contact tolerates an allowance, the
//! starting penetration into the collider itself (the thickness skin is resolved as usual)
//! less `max_depenetration_speed · h`, which shrinks by that much every
//! substep (and carries over to the next frames), so the overlap is pushed out at a bounded
//! speed instead of turning into an explosion. Every other contact, impacts included, has no
//! allowance.
//!
//! The velocity pass then removes the separating normal velocity the projection gave each
//! contact particle; restitution is applied to the whole body by [`crate::restitution`],
//! rolling resistance by [`crate::rolling`] (sticking friction alone lets a rounded body
//! roll and rock without loss).

use nalgebra::{Point3, Vector3};
use rapier3d::geometry::ColliderSet;
use tetpbd::Particles;

use crate::bodies::{BodyKind, BodyProxy};
use crate::frame::{ColliderProxy, ParticleContact};
use crate::shape_query::surface_point;
use crate::sweep::swept_entry;

/// One sweep over a soft body's particle contacts. Returns the number of degenerate
/// evaluations (no usable normal).
pub(crate) fn project_contacts(
    contacts: &mut [ParticleContact],
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    set: &ColliderSet,
    max_push: f32,
) -> u64 {
    let mut degenerate = 0;
    for c in contacts {
        let cp = &colliders[c.collider];
        let Some(shape) = set.get(cp.handle).map(|co| co.shape()) else {
            continue;
        };
        let i = c.particle as usize;
        let x = p.positions()[i];
        let pose = cp.pose(bodies);
        let fallback = c.has_normal.then_some(c.normal);
        let closest = surface_point(shape, cp.rule, &pose, &x, fallback);
        // Relative motion that entered the shape within the substep (`sweep` module docs).
        let moving = cp.body.is_some_and(|b| bodies[b].kind != BodyKind::Fixed);
        let swept = swept_entry(
            shape,
            &pose,
            &if moving { cp.prev_pose(bodies) } else { pose },
            &x,
            &p.prev_positions()[i],
            closest.as_ref(),
        );
        let Some(sp) = swept.or(closest) else {
            degenerate += 1;
            continue;
        };
        let (q, n) = (sp.point, sp.normal);
        let depth = c.thickness - sp.distance;
        if !c.allowance_fresh {
            // First evaluation of this contact in the frame. If it is deeper than one substep
            // may push out and was already this deep at the substep start (an overlap, not an
            // impact), resolve only `max_push` of that pre-existing overlap per substep: the
            // allowance decays by `max_push` each substep (`finish_substep`).
            c.allowance_fresh = true;
            if depth > max_push {
                let x0 = p.prev_positions()[i];
                if let Some(s0) = surface_point(shape, cp.rule, &pose, &x0, Some(n)) {
                    c.allowance = (-s0.distance - max_push).max(0.0);
                }
            }
        }
        let c_val = -depth + c.allowance;
        if depth <= 0.0 {
            continue;
        }
        c.active = true;
        c.ever_active = true;
        c.has_normal = true;
        c.normal = n;
        c.point = q;
        c.depth = c.depth.max(depth);
        if !c.solve || c_val >= 0.0 {
            continue;
        }
        let w_p = p.inv_masses()[i];
        let w_b = cp.body.map_or(0.0, |b| bodies[b].inv_mass_pushed(&q, &-n));
        let wsum = w_p + w_b;
        if wsum.is_nan() || wsum <= 0.0 {
            continue;
        }
        let dl = -c_val / wsum;
        p.positions_mut()[i] += n * (w_p * dl);
        if let Some(b) = cp.body {
            bodies[b].apply_position_impulse(&(-n * dl), &q);
        }
        c.lambda_n += dl;
        c.sub_impulse += n * dl;
        friction(c, p, bodies, cp, &q, &n);
    }
    degenerate
}

fn friction(
    c: &mut ParticleContact,
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    cp: &ColliderProxy,
    q: &Vector3<f32>,
    n: &Vector3<f32>,
) {
    let i = c.particle as usize;
    let x = p.positions()[i];
    let x_prev = p.prev_positions()[i];
    let body_motion = match cp.body {
        Some(b) => {
            let body = &bodies[b];
            let local = body.pose.inverse_transform_point(&Point3::from(*q));
            (body.pose * local).coords - (body.prev * local).coords
        }
        None => Vector3::zeros(),
    };
    let dp = (x - x_prev) - body_motion;
    let dpt = dp - n * n.dot(&dp);
    let len = dpt.norm();
    if len.is_nan() || len <= 1e-9 {
        return;
    }
    let t = dpt / len;
    let w_p = p.inv_masses()[i];
    let w_b = cp.body.map_or(0.0, |b| bodies[b].inv_mass_at(q, &t));
    if (w_p + w_b).is_nan() || w_p + w_b <= 0.0 {
        return;
    }
    let full = len / (w_p + w_b);
    let applied = if c.lambda_t + full <= c.mu_s * c.lambda_n {
        full
    } else {
        full.min((c.mu_d * c.lambda_n - c.lambda_t).max(0.0))
    };
    if applied <= 0.0 {
        return;
    }
    p.positions_mut()[i] -= t * (w_p * applied);
    if let Some(b) = cp.body {
        bodies[b].apply_position_impulse(&(t * applied), q);
    }
    c.lambda_t += applied;
    c.sub_impulse -= t * applied;
}

/// Velocity pass after a substep, per particle: the relative normal velocity of every
/// contact active in the substep is set to zero (Müller et al. 2020 with `e = 0`), which
/// removes the separating velocity the position projection created. Restitution itself
/// acts on the whole body (see [`crate::restitution`]).
pub(crate) fn velocity_pass(
    contacts: &mut [ParticleContact],
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
) {
    for c in contacts.iter_mut().filter(|c| c.active && c.solve) {
        let cp = &colliders[c.collider];
        let i = c.particle as usize;
        let (q, n) = (c.point, c.normal);
        let vb = cp
            .body
            .map_or(Vector3::zeros(), |b| bodies[b].velocity_at(&q));
        let vn = n.dot(&(p.velocities()[i] - vb));
        let w_p = p.inv_masses()[i];
        let w_b = cp.body.map_or(0.0, |b| bodies[b].inv_mass_at(&q, &n));
        if vn > 0.0 && w_p + w_b > 0.0 {
            let j = -vn / (w_p + w_b);
            p.velocities_mut()[i] += n * (w_p * j);
            if let Some(b) = cp.body {
                bodies[b].apply_velocity_impulse(&(-n * j), &q);
            }
            c.impulse += n * j;
        }
    }
}

/// Resets the per-substep state of the contacts; the substep's impulses join the frame's.
pub(crate) fn finish_substep(contacts: &mut [ParticleContact], h: f32, max_push: f32) {
    for c in contacts {
        c.impulse += c.sub_impulse / h;
        c.sub_impulse = Vector3::zeros();
        c.lambda_n = 0.0;
        c.lambda_t = 0.0;
        c.active = false;
        c.allowance = (c.allowance - max_push).max(0.0);
    }
}
