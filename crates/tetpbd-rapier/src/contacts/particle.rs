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
//! `n` instead of the closest point, which may lie on the far side (`ccd` module docs).
//!
//! Overlap is not resolved at once: a contact whose particle, at its first evaluation in a
//! frame, already stood deeper than one substep's push at the substep start, against the
//! collider where the collider stood then (a body created inside a collider, a surface given
//! back to a body that sank, a teleport), tolerates an allowance: that starting depth (skin
//! included) less `max_depenetration_speed · h`, which shrinks by that much every substep
//! (and carries over to the next frames), so the overlap is pushed out at a bounded speed
//! instead of turning into an explosion. Impacts (outside at the substep start) and
//! colliders moving into a particle get no allowance. The body does not keep the speed of
//! that push (`depenetration` module docs).
//!
//! The velocity pass then removes the separating normal velocity the projection gave each
//! contact particle; restitution is applied to the whole body by [`crate::response::restitution`],
//! rolling resistance by [`crate::response::rolling`] (sticking friction alone lets a rounded body
//! roll and rock without loss).

use nalgebra::{Point3, Vector3};
use rapier3d::geometry::ColliderSet;
use tetpbd::Particles;

use crate::ccd::swept_entry;
use crate::response::friction::{positional_friction, ContactStencil, Coulomb};
use crate::rigid::body::{BodyKind, BodyProxy};
use crate::rigid::collider::ColliderProxy;
use crate::rigid::shape_query::{surface_point, InsideRule};
use tetpbd::ImpactReach;

/// A surface particle near a collider: an XPBD inequality contact re-evaluated every
/// iteration of every substep.
#[derive(Clone, Debug)]
pub(crate) struct ParticleContact {
    pub particle: u32,
    pub collider: usize,
    pub mu_d: f32,
    pub mu_s: f32,
    pub restitution: f32,
    pub thickness: f32,
    pub solve: bool,
    pub lambda_n: f32,
    pub lambda_t: f32,
    pub active: bool,
    pub ever_active: bool,
    pub has_normal: bool,
    pub normal: Vector3<f32>,
    pub point: Vector3<f32>,
    pub depth: f32,
    /// Penetration tolerated in this substep (pre-existing overlap beyond one substep's
    /// allowed push-out), m; see `CouplingSettings::max_depenetration_speed`.
    pub allowance: f32,
    /// Whether `allowance` was decided for the frame (at the contact's first evaluation; a
    /// pair already touching in the previous frame starts from what was left of its
    /// allowance).
    pub allowance_fresh: bool,
    pub sub_impulse: Vector3<f32>,
    pub impulse: Vector3<f32>,
    /// For a thin mesh (`mesh_side` module docs): the side the particle belongs on in the
    /// current substep (unit, world; from where it stood at the substep start), once decided.
    pub side: Option<Vector3<f32>>,
}

/// One sweep over a soft body's particle contacts. Returns the number of degenerate
/// evaluations (no usable normal).
pub(crate) fn project_contacts(
    contacts: &mut [ParticleContact],
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    set: &ColliderSet,
    max_push: f32,
    impact: &mut ImpactReach,
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
        let moving = cp.body.is_some_and(|b| bodies[b].kind != BodyKind::Fixed);
        if cp.rule == InsideRule::ThinMesh && c.side.is_none() {
            let before = if moving { cp.prev_pose(bodies) } else { pose };
            c.side = thin_side(shape, &before, &p.prev_positions()[i], fallback);
        }
        let closest = surface_point(shape, cp.rule, &pose, &x, fallback, c.side);
        // Relative motion that entered the shape within the substep (`ccd` module docs).
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
            // First evaluation of the contact in the frame. If it is deeper than one substep
            // may push out and was already this deep at the substep start, against the
            // collider where it stood then (an overlap, not an impact nor a collider moving
            // into it), resolve only `max_push` of that pre-existing overlap per substep: the
            // allowance decays by `max_push` each substep (`finish_substep`).
            c.allowance_fresh = true;
            if depth > max_push {
                let x0 = p.prev_positions()[i];
                let before = if moving { cp.prev_pose(bodies) } else { pose };
                if let Some(s0) = surface_point(shape, cp.rule, &before, &x0, Some(n), c.side) {
                    let overlap = c.thickness - s0.distance - max_push;
                    c.allowance = c.allowance.max(overlap);
                }
            }
        }
        let mut c_val = -depth + c.allowance;
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
        // An impact deeper than the surface can take locally within the substep meets the
        // whole soft body ([`tetpbd::ImpactReach`]).
        let w_b = cp.body.map_or(0.0, |b| bodies[b].inv_mass_pushed(&q, &-n));
        if let Some((dl, excess)) = impact.take_excess(p, c_val, w_b, &n) {
            if let Some(b) = cp.body {
                bodies[b].apply_position_impulse(&(-n * dl), &q);
            }
            c.lambda_n += dl;
            c.sub_impulse += n * dl;
            c_val += excess;
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

/// A particle against a collider's material point `q`, for friction.
struct ParticleOnCollider<'s> {
    p: &'s mut Particles,
    i: usize,
    bodies: &'s mut [BodyProxy],
    body: Option<usize>,
    q: Vector3<f32>,
}

impl ContactStencil for ParticleOnCollider<'_> {
    fn relative_motion(&self) -> Vector3<f32> {
        let x = self.p.positions()[self.i];
        let x_prev = self.p.prev_positions()[self.i];
        let body_motion = match self.body {
            Some(b) => {
                let body = &self.bodies[b];
                let local = body.pose.inverse_transform_point(&Point3::from(self.q));
                (body.pose * local).coords - (body.prev * local).coords
            }
            None => Vector3::zeros(),
        };
        (x - x_prev) - body_motion
    }

    fn inv_mass(&self, t: &Vector3<f32>) -> f32 {
        let w_p = self.p.inv_masses()[self.i];
        let w_b = self
            .body
            .map_or(0.0, |b| self.bodies[b].inv_mass_at(&self.q, t));
        w_p + w_b
    }

    fn apply(&mut self, t: &Vector3<f32>, dl: f32) {
        let w_p = self.p.inv_masses()[self.i];
        self.p.positions_mut()[self.i] -= t * (w_p * dl);
        if let Some(b) = self.body {
            self.bodies[b].apply_position_impulse(&(t * dl), &self.q);
        }
    }
}

/// Coulomb friction of a particle contact just projected ([`crate::response::friction`]).
fn friction(
    c: &mut ParticleContact,
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    cp: &ColliderProxy,
    q: &Vector3<f32>,
    n: &Vector3<f32>,
) {
    let mut stencil = ParticleOnCollider {
        p,
        i: c.particle as usize,
        bodies,
        body: cp.body,
        q: *q,
    };
    let coulomb = Coulomb {
        lambda_n: c.lambda_n,
        mu_s: c.mu_s,
        mu_d: c.mu_d,
    };
    if let Some((t, dl)) = positional_friction(&mut stencil, n, coulomb, &mut c.lambda_t) {
        c.sub_impulse -= t * dl;
    }
}

/// Sweeps of [`friction_on_pivoting`] per iteration (`rigid::body::pivoting` module docs,
/// "Friction on a pivoting body": one sweep let a 10× cube creep off a ball-jointed box in
/// 7 s, two left the rig spinning up about the vertical, four hold it).
const PIVOTING_FRICTION_SWEEPS: usize = 4;

/// Friction of one soft body's active contacts with pivoting bodies once more, against
/// where every contact of the iteration left the bodies (`rigid::body::pivoting` module
/// docs, "Friction on a pivoting body"); the static cone is shared with the contact's first
/// friction in the substep (`lambda_t` goes on accumulating).
pub(crate) fn friction_on_pivoting(
    contacts: &mut [ParticleContact],
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
) {
    for _ in 0..PIVOTING_FRICTION_SWEEPS {
        for c in contacts.iter_mut() {
            let cp = &colliders[c.collider];
            let pivoting = cp.body.is_some_and(|b| bodies[b].is_pivoting());
            if !(pivoting && c.active && c.solve && c.lambda_n > 0.0) {
                continue;
            }
            let (q, n) = (c.point, c.normal);
            friction(c, p, bodies, cp, &q, &n);
        }
    }
}

/// Velocity pass after a substep, per particle: the relative normal velocity of every
/// contact active in the substep is set to zero (Müller et al. 2020 with `e = 0`), which
/// removes the separating velocity the position projection created. Restitution itself
/// acts on the whole body (see [`crate::response::restitution`]).
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

/// The side of a thin mesh at `pose` that the point `x0` stands on (unit, world, from the
/// mesh towards it: `mesh_side` module docs); `fallback` when `x0` lies on the mesh.
fn thin_side(
    shape: &dyn rapier3d::parry::shape::Shape,
    pose: &nalgebra::Isometry3<f32>,
    x0: &Vector3<f32>,
    fallback: Option<Vector3<f32>>,
) -> Option<Vector3<f32>> {
    let mesh = shape.as_trimesh()?;
    let local = pose.inverse_transform_point(&Point3::from(*x0));
    let proj = rapier3d::parry::query::PointQuery::project_local_point(
        mesh,
        crate::convert::to_glam(&local.coords),
        false,
    );
    let d = local.coords - crate::convert::to_na(proj.point);
    match d.try_normalize(1e-6) {
        Some(n) => Some(pose.rotation * n),
        None => fallback,
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
        c.side = None;
        c.allowance = (c.allowance - max_push).max(0.0);
    }
}
