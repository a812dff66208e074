//! A soft body coming at something immovable faster than its constraints carry a push is
//! stopped as a whole, down to what they carry (`tetpbd::impact_speed`).
//!
//! The contacts resolve at most the body's local reach per projection; the depth beyond it
//! meets the whole body ([`tetpbd::ImpactReach`]). That bounds how deep a particle goes, not
//! how fast the body behind its stopped surface keeps coming: with compliant constraints
//! and short substeps the push crosses the body at its wave speed `c`, slower than one cell
//! a substep, and the body runs through its own stopped surface layer. So after the contact
//! projection of an iteration, a body touching immovable colliders (fixed, kinematic,
//! supported or held bodies, static colliders: [`crate::heavy_loads::immovable`]) approaches
//! them by at most `LOCAL_REACH × min(c h, L)` per substep
//! ([`tetpbd::impact_speed::approach_limit`]); the excess of its centre-of-mass approach is
//! taken by the whole body ([`tetpbd::ImpactReach::limit_relative_approach`]), perfectly
//! inelastic.
//!
//! *Several contacts.* The approach is measured along the mean of the active immovable
//! contacts' normals weighted by their normal multipliers in the substep: the direction of
//! their net reaction on the body (on a ground, its normal; on a box edge or in a corner,
//! between the faces, leaning to the one pressed harder). The approach is relative: a
//! kinematic collider's motion at each contact point over the substep, weighted the same
//! way, is subtracted from the body's (fixed ones do not move). Where the normals disagree
//! (the net reaction less than half the sum of the multipliers: a body squeezed between
//! opposite walls), the body as a whole is not approaching one surface and nothing is done;
//! the contacts resolve it. The momentum taken off the body goes to the contacts in
//! proportion to their multipliers: into their reported impulses and, for a supported body,
//! into the load handed to rapier. Not into their friction budgets: a surface particle whose
//! Coulomb bound came from the whole body's stop would stop the surface layer sideways
//! alone, a shear the body's constraints carry no faster than the push.
//!
//! Limits: the tangential stop of the surface layer (friction under a body sliding at
//! hundreds of m/s, a wall met sideways) is not limited, so a compliant body thrown
//! obliquely at many substeps can still be crushed; limiting each distinct face's normal
//! separately instead of the mean did worse (`docs/decisions/impact-approach-speed.md`).

use nalgebra::{Point3, Vector3};
use tetpbd::{ImpactReach, Particles};

use crate::contacts::corner::CornerContact;
use crate::contacts::particle::ParticleContact;
use crate::heavy_loads::immovable;
use crate::rigid::body::BodyProxy;
use crate::rigid::collider::ColliderProxy;

/// Cosine-like agreement below which the active immovable normals are taken to disagree:
/// `|Σ λᵢ nᵢ| < ½ Σ λᵢ` (a mean spread of more than 60°).
const AGREEMENT: f32 = 0.5;

/// The active immovable contacts of one soft body in an iteration, summed.
#[derive(Default)]
struct Net {
    /// Σ λᵢ (kg·m).
    weight: f32,
    /// Σ λᵢ nᵢ (kg·m).
    normal: Vector3<f32>,
    /// Σ λᵢ (motion of the collider at the contact point over the substep) (kg·m²).
    motion: Vector3<f32>,
}

impl Net {
    fn add(&mut self, lambda: f32, n: &Vector3<f32>, motion: Vector3<f32>) {
        if lambda.is_finite() && lambda > 0.0 {
            self.weight += lambda;
            self.normal += n * lambda;
            self.motion += motion * lambda;
        }
    }
}

/// How far the material point of collider `cp` at the world point `q` moved over the
/// substep so far, m (zero for a static collider or a fixed body).
fn motion_at(cp: &ColliderProxy, bodies: &[BodyProxy], q: &Vector3<f32>) -> Vector3<f32> {
    cp.body.map_or(Vector3::zeros(), |b| {
        let body = &bodies[b];
        let local = body.pose.inverse_transform_point(&Point3::from(*q));
        (body.pose * local).coords - (body.prev * local).coords
    })
}

/// Applies the approach limit (module docs) to soft body `p` after its contact projection
/// in an iteration: `limit` (m) from [`tetpbd::impact_speed::approach_limit`]. Returns the
/// distance the whole body was moved back, m (0 when it was not).
pub(crate) fn limit_approach(
    contacts: &mut [ParticleContact],
    corners: &mut [CornerContact],
    p: &mut Particles,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    impact: &mut ImpactReach,
    limit: f32,
) -> f32 {
    let counts = |active: bool, collider: usize, bodies: &[BodyProxy]| {
        active && immovable(&colliders[collider], bodies)
    };
    let mut net = Net::default();
    for c in contacts.iter().filter(|c| c.solve) {
        if counts(c.active, c.collider, bodies) {
            let motion = motion_at(&colliders[c.collider], bodies, &c.point);
            net.add(c.lambda_n, &c.normal, motion);
        }
    }
    for k in corners.iter() {
        if counts(k.active, k.collider, bodies) {
            let motion = motion_at(&colliders[k.collider], bodies, &k.point);
            net.add(k.lambda_n, &k.normal, motion);
        }
    }
    let len = net.normal.norm();
    if !(net.weight > 0.0 && len >= AGREEMENT * net.weight) {
        return 0.0;
    }
    let n = net.normal / len;
    let toward = net.motion.dot(&n) / net.weight;
    let moved = impact.limit_relative_approach(p, &n, toward, limit);
    if moved > 0.0 {
        share_impulse(
            contacts, corners, p, bodies, colliders, &n, moved, net.weight,
        );
    }
    moved
}

/// Hands the momentum of moving the body `moved` (m) along `n` to the active immovable
/// contacts in proportion to their multipliers (their sum `weight`).
#[allow(clippy::too_many_arguments)]
fn share_impulse(
    contacts: &mut [ParticleContact],
    corners: &mut [CornerContact],
    p: &Particles,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    n: &Vector3<f32>,
    moved: f32,
    weight: f32,
) {
    let free: f32 = (0..p.len())
        .filter(|&i| p.inv_masses()[i] > 0.0)
        .map(|i| p.masses()[i])
        .sum();
    let dl = free * moved;
    if !(dl.is_finite() && dl > 0.0) {
        return;
    }
    let share = |lambda: f32| dl * lambda / weight;
    for c in contacts
        .iter_mut()
        .filter(|c| c.solve && c.active && c.lambda_n > 0.0)
    {
        let cp = &colliders[c.collider];
        if immovable(cp, bodies) {
            let j = share(c.lambda_n);
            give(bodies, cp, &c.point, &(-n * j));
            c.sub_impulse += n * j;
        }
    }
    for k in corners.iter_mut().filter(|k| k.active && k.lambda_n > 0.0) {
        let cp = &colliders[k.collider];
        if immovable(cp, bodies) {
            let j = share(k.lambda_n);
            give(bodies, cp, &k.point, &(-n * j));
            k.sub_impulse += n * j;
        }
    }
}

/// The positional impulse `j` (kg·m) on collider `cp`'s body at `q`, if it has one (a
/// supported or held body sums it into its load; a fixed or kinematic one takes none).
fn give(bodies: &mut [BodyProxy], cp: &ColliderProxy, q: &Vector3<f32>, j: &Vector3<f32>) {
    if let Some(b) = cp.body {
        bodies[b].apply_position_impulse(j, q);
    }
}
