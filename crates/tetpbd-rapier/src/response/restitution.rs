//! Restitution of a whole soft body against a collider (Poisson's hypothesis on the
//! centre of mass).
//!
//! A soft body's impact lasts several substeps and involves many particles, so restitution
//! cannot be a per-particle velocity rule: setting a few contact particles to `−e·v` is
//! averaged away by the body's constraints, and the numerical springiness of a stiff XPBD
//! body makes it bounce off a contact with `e = 0`. Instead each (soft body, collider) pair
//! in contact runs an *impact episode*:
//!
//! 1. it begins at the first substep with an active contact (particle or rigid point on a
//!    surface triangle); `v⁻ = n·(v_cm − v_rigid(q))` is
//!    the approach speed of the body's centre of mass before that substep (`n`, `q` the mean
//!    normal and point of the active contacts). Only an approach faster than `2|g|h` is an
//!    impact (resting contacts never bounce);
//! 2. compression ends at the first substep where the relative normal velocity `v_n` of the
//!    centre of mass is ≥ 0; the body then receives the uniform velocity change that makes
//!    `v_n = −e·v⁻` (with the opposite impulse on a dynamic rigid body, generalized inverse
//!    mass at `q`; a soft body with pinned particles is anchored and takes no share);
//! 3. while the contact lasts, `v_n` is capped at `−e·v⁻`, so the body's elastic recoil does
//!    not add bounce; the episode ends with the last active contact (kept across frames). A
//!    soft body squeezed under a load after an impact therefore does not spring back while
//!    the load rests on it (it does once the load is lifted).
//!
//! `e` is the largest combined restitution among the pair's contacts.

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::geometry::ColliderHandle;
use tetpbd::Particles;

use crate::contacts::corner::CornerContact;
use crate::contacts::particle::ParticleContact;
use crate::rigid::body::BodyProxy;
use crate::rigid::collider::ColliderProxy;

/// One impact episode of a (soft body, collider) pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Episode {
    key: (u64, (u32, u32)),
    approach: f32,
    compressing: bool,
    seen: bool,
}

impl Episode {
    fn new(key: (u64, (u32, u32)), approach: f32, compressing: bool) -> Episode {
        Episode {
            key,
            approach,
            compressing,
            seen: false,
        }
    }
}

/// Centre-of-mass velocity and mass of the free particles of `p`.
pub(crate) fn com_velocity(p: &Particles) -> (Vector3<f32>, f32) {
    let mut m = 0.0;
    let mut mv = Vector3::zeros();
    for i in 0..p.len() {
        if p.inv_masses()[i] > 0.0 {
            m += p.masses()[i];
            mv += p.velocities()[i] * p.masses()[i];
        }
    }
    if m > 0.0 {
        (mv / m, m)
    } else {
        (Vector3::zeros(), 0.0)
    }
}

/// Runs the episodes of one soft body after a substep's velocity update. `contacts` are the
/// body's contacts (contiguous per collider), `v_cm_pre` its centre-of-mass velocity before
/// the substep. `active` is scratch space (its capacity is reused across calls).
#[allow(clippy::too_many_arguments)]
pub(crate) fn restitution_pass(
    episodes: &mut Vec<Episode>,
    active: &mut Vec<usize>,
    entity: Entity,
    contacts: &mut [ParticleContact],
    corners: &mut [CornerContact],
    p: &mut Particles,
    v_cm_pre: &Vector3<f32>,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    threshold: f32,
) {
    let (v_cm, mass) = com_velocity(p);
    if mass <= 0.0 {
        return;
    }
    // A body with pinned particles is anchored to the world: its centre of mass takes no
    // share of the restitution impulse.
    let anchored = p.inv_masses().contains(&0.0);
    active_colliders(active, contacts, corners);
    for &ci in active.iter() {
        let Some((n, q, count, e)) = contact_patch(ci, contacts, corners) else {
            continue;
        };
        let cp = &colliders[ci];
        let vb = cp
            .body
            .map_or(Vector3::zeros(), |b| bodies[b].velocity_at(&q));
        let key = (entity.to_bits().get(), collider_key(cp.handle));
        let k = match episodes.binary_search_by(|ep| ep.key.cmp(&key)) {
            Ok(k) => k,
            Err(k) => {
                let vb_pre = cp
                    .body
                    .map_or(Vector3::zeros(), |b| bodies[b].velocity_at_pre(&q));
                let approach = n.dot(&(v_cm_pre - vb_pre));
                let compressing = approach < -threshold;
                episodes.insert(k, Episode::new(key, approach, compressing));
                k
            }
        };
        let ep = &mut episodes[k];
        ep.seen = true;
        if ep.approach >= -threshold {
            continue;
        }
        let v_n = n.dot(&(v_cm - vb));
        let target = -e * ep.approach;
        let dv = if ep.compressing {
            if v_n < 0.0 {
                continue;
            }
            ep.compressing = false;
            target - v_n
        } else if v_n > target {
            target - v_n
        } else {
            continue;
        };
        let w_soft = if anchored { 0.0 } else { 1.0 / mass };
        let Some(j) = bounce(p, w_soft, bodies, cp.body, (&n, &q), dv) else {
            continue;
        };
        let share = n * (j / count as f32);
        for c in contacts
            .iter_mut()
            .filter(|c| c.collider == ci && c.active && c.solve)
        {
            c.impulse += share;
        }
        for k in corners.iter_mut().filter(|k| k.collider == ci && k.active) {
            k.impulse += share;
        }
    }
}

/// Changes the relative normal velocity at the patch (unit normal `n` towards the soft
/// body, point `q`) by `dv` (m/s): the soft body's free particles (inverse mass `w_soft`,
/// 1/kg) all get the same velocity change, the rigid body the opposite impulse at `q`.
/// Returns the impulse (N·s), `None` when it is not finite.
fn bounce(
    p: &mut Particles,
    w_soft: f32,
    bodies: &mut [BodyProxy],
    body: Option<usize>,
    (n, q): (&Vector3<f32>, &Vector3<f32>),
    dv: f32,
) -> Option<f32> {
    let w_b = body.map_or(0.0, |b| bodies[b].inv_mass_at(q, n));
    let j = dv / (w_soft + w_b);
    if !j.is_finite() {
        return None;
    }
    let dv_soft = n * (j * w_soft);
    for i in 0..p.len() {
        if p.inv_masses()[i] > 0.0 {
            p.velocities_mut()[i] += dv_soft;
        }
    }
    if let Some(b) = body {
        bodies[b].apply_velocity_impulse(&(-n * j), q);
    }
    Some(j)
}

/// The active contacts of a soft body with collider `ci`, as one patch: unit mean normal,
/// mean point (world, m), number of contacts and the largest restitution coefficient.
/// `None` without contacts or without a usable normal.
fn contact_patch(
    ci: usize,
    contacts: &[ParticleContact],
    corners: &[CornerContact],
) -> Option<(Vector3<f32>, Vector3<f32>, usize, f32)> {
    let mut n = Vector3::zeros();
    let mut q = Vector3::zeros();
    let mut count = 0usize;
    let mut e = 0.0f32;
    for c in contacts
        .iter()
        .filter(|c| c.collider == ci && c.active && c.solve)
    {
        n += c.normal;
        q += c.point;
        count += 1;
        e = e.max(c.restitution);
    }
    for k in corners.iter().filter(|k| k.collider == ci && k.active) {
        n += k.normal;
        q += k.point;
        count += 1;
        e = e.max(k.restitution);
    }
    let len = n.norm();
    if count == 0 || len.is_nan() || len <= 1e-6 {
        return None;
    }
    Some((n / len, q / count as f32, count, e))
}

/// Fills `active` with the sorted, distinct collider indices of the solved particle
/// contacts and the rigid-point contacts active in the current substep.
pub(crate) fn active_colliders(
    active: &mut Vec<usize>,
    contacts: &[ParticleContact],
    corners: &[CornerContact],
) {
    active.clear();
    active.extend(
        contacts
            .iter()
            .filter(|c| c.active && c.solve)
            .map(|c| c.collider)
            .chain(corners.iter().filter(|k| k.active).map(|k| k.collider)),
    );
    active.sort_unstable();
    active.dedup();
}

/// Drops the episodes of pairs with no active contact this substep; clears the marks.
pub(crate) fn end_episodes(episodes: &mut Vec<Episode>) {
    episodes.retain(|ep| ep.seen);
    for ep in episodes.iter_mut() {
        ep.seen = false;
    }
}

fn collider_key(h: ColliderHandle) -> (u32, u32) {
    h.into_raw_parts()
}
