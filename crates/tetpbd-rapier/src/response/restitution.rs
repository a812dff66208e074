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
//!    impact; a slower one (a resting contact, a tumbling body setting a corner down) has
//!    no compression phase and a bounce of 0, so it never springs off (step 3);
//! 2. compression ends at the first substep where the relative normal velocity `v_n` of the
//!    centre of mass is ≥ 0; the body then receives the uniform velocity change that makes
//!    `v_n = −e·v⁻` (with the opposite impulse on a dynamic rigid body, generalized inverse
//!    mass at `q`; a soft body with pinned particles is anchored and takes no share);
//! 3. while the contact lasts, `v_n` is capped at `−e·v⁻` (at 0 for a contact that is not
//!    an impact), so the body's elastic recoil does not add bounce: a corner squashed when
//!    a body was set down does not throw it back up as it recovers its shape; the episode
//!    ends with the last active contact (kept across frames). A
//!    soft body squeezed under a load after an impact therefore does not spring back while
//!    the load rests on it (it does once the load is lifted).
//!
//! `e` is the largest combined restitution among the pair's contacts.
//!
//! The cap stops the body's own recoil, not a pull: the loads applied to the body besides
//! its contacts — gravity, its user forces, a grab, an external acceleration
//! ([`tetpbd::applied_acceleration`]) — change `v_n` by `a_n h` in each substep, and the
//! episode raises its cap by their sum since it began, kept at or above 0:
//!
//! ```text
//! allowance ← max(0, allowance + n·a h),    cap = −e·v⁻ + allowance
//! allowance ← min(allowance, max(0, v_n − (−e·v⁻)))      (after the cap)
//! ```
//!
//! The second line keeps the allowance from running ahead of the separation the body
//! really has, so loads a contact balances (the weight of a soft body under another) do
//! not let recoil through.
//!
//! A body resting under its weight gains nothing (`n·g < 0`); a grab or force stronger than
//! the weight lifts it as it would lift a free body. The rigid body's own loads are not
//! counted (rapier moves it between frames).

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::geometry::ColliderHandle;
use tetpbd::Particles;

use crate::attachments::AttachRun;
use crate::contacts::corner::CornerContact;
use crate::contacts::particle::ParticleContact;
use crate::rigid::body::BodyProxy;
use crate::rigid::collider::ColliderProxy;

/// One impact episode of a pair in contact (a soft body and a collider, or two soft bodies).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Episode {
    key: (u64, u64),
    /// `v⁻`, m/s (< 0 when approaching).
    approach: f32,
    /// Whether the approach was an impact (faster than the threshold).
    impact: bool,
    /// The separation speed the applied loads have given since the episode began, m/s
    /// (module docs).
    allowance: f32,
    compressing: bool,
    seen: bool,
}

impl Episode {
    /// The change of the relative normal velocity `v_n` (m/s, > 0 separating) that steps 2
    /// and 3 of the module docs ask for in this substep, `e` the pair's restitution and
    /// `pull` (m/s) the change of `v_n` the applied loads gave in the substep; `None` when
    /// nothing is to change. A contact that is not an impact is capped at the allowance.
    pub fn change(&mut self, v_n: f32, e: f32, pull: f32) -> Option<f32> {
        if pull.is_finite() {
            self.allowance = (self.allowance + pull).max(0.0);
        }
        let bounce = if self.impact { -e * self.approach } else { 0.0 };
        let target = bounce + self.allowance;
        let dv = if self.compressing {
            if v_n < 0.0 {
                return None;
            }
            self.compressing = false;
            Some(target - v_n)
        } else {
            (v_n > target).then_some(target - v_n)
        };
        // The allowance never runs ahead of the separation the body has: loads that the
        // contact balances (a lower body's weight on its support) add nothing.
        let after = v_n + dv.unwrap_or(0.0) - bounce;
        self.allowance = self.allowance.min(after.max(0.0));
        dv
    }
}

/// The impact episodes of the pairs in contact, kept across substeps and frames (module
/// docs); one rule for soft bodies against colliders and against each other.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Episodes {
    list: Vec<Episode>,
}

impl Episodes {
    /// The episode of pair `key`, begun now with the approach speed `approach()` (m/s,
    /// normal velocity before the substep, < 0 approaching) if it is new (an impact when
    /// faster than `threshold`, m/s), marked as seen in this substep.
    pub fn episode(
        &mut self,
        key: (u64, u64),
        approach: impl FnOnce() -> f32,
        threshold: f32,
    ) -> &mut Episode {
        let k = match self.list.binary_search_by(|ep| ep.key.cmp(&key)) {
            Ok(k) => k,
            Err(k) => {
                let approach = approach();
                let impact = approach < -threshold;
                let ep = Episode {
                    key,
                    approach,
                    impact,
                    allowance: 0.0,
                    compressing: impact,
                    seen: false,
                };
                self.list.insert(k, ep);
                k
            }
        };
        let ep = &mut self.list[k];
        ep.seen = true;
        ep
    }

    /// Ends the substep: drops the episodes of pairs with no active contact in it.
    pub fn end_substep(&mut self) {
        self.list.retain(|ep| ep.seen);
        for ep in self.list.iter_mut() {
            ep.seen = false;
        }
    }
}

/// Runs the episodes of one soft body after a substep's velocity update. `contacts` are the
/// body's contacts (contiguous per collider), `v_cm_pre` its centre-of-mass velocity before
/// the substep, `pull` the change of its velocity the applied loads and gravity gave in the
/// substep (m/s, module docs), `attached` its attachment runs. `active` is scratch space
/// (its capacity is reused across calls). Returns the kinetic energy the bounces gave the
/// body (J, the rises only: `response::passivity` counts it as work done on purpose).
#[allow(clippy::too_many_arguments)]
pub(crate) fn restitution_pass(
    episodes: &mut Episodes,
    active: &mut Vec<usize>,
    entity: Entity,
    contacts: &mut [ParticleContact],
    corners: &mut [CornerContact],
    p: &mut Particles,
    v_cm_pre: &Vector3<f32>,
    pull: &Vector3<f32>,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    attached: &[AttachRun],
    threshold: f32,
) -> f32 {
    let Some((v_cm, mass)) = p.free_velocity() else {
        return 0.0;
    };
    let (mut given, mut v_now) = (0.0f32, v_cm);
    // A body with pinned particles is anchored to the world: its centre of mass takes no
    // share of the restitution impulse.
    let anchored = p.inv_masses().contains(&0.0);
    active_colliders(active, contacts, corners);
    for &ci in active.iter() {
        let Some((n, q, count, e)) = contact_patch(ci, contacts, corners) else {
            continue;
        };
        let cp = &colliders[ci];
        // A body attached to the collider's rigid body moves with it through the attachment,
        // which owns their relative motion: no episode between them.
        if cp.body.is_some() && attached.iter().any(|a| a.body == cp.body) {
            continue;
        }
        let vb = cp
            .body
            .map_or(Vector3::zeros(), |b| bodies[b].velocity_at(&q));
        let key = (entity.to_bits().get(), collider_key(cp.handle));
        let approach = || {
            let vb_pre = cp
                .body
                .map_or(Vector3::zeros(), |b| bodies[b].velocity_at_pre(&q));
            n.dot(&(v_cm_pre - vb_pre))
        };
        let ep = episodes.episode(key, approach, threshold);
        let pull = if anchored { 0.0 } else { n.dot(pull) };
        let Some(dv) = ep.change(n.dot(&(v_cm - vb)), e, pull) else {
            continue;
        };
        let w_soft = if anchored { 0.0 } else { 1.0 / mass };
        let Some(j) = bounce(p, w_soft, bodies, cp.body, (&n, &q), dv) else {
            continue;
        };
        let dv_soft = n * (j * w_soft);
        given += (mass * (v_now.dot(&dv_soft) + 0.5 * dv_soft.norm_squared())).max(0.0);
        v_now += dv_soft;
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
    given
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
    p.add_free_velocity(&(n * (j * w_soft)));
    if let Some(b) = body {
        bodies[b].apply_velocity_impulse(&(-n * j), q);
    }
    Some(j)
}

/// The active contacts of a soft body with collider `ci`, as one patch: unit mean normal,
/// mean point (world, m), number of contacts and the largest restitution coefficient.
/// `None` without contacts or without a usable normal.
pub(crate) fn contact_patch(
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

/// A collider handle as one episode key half (index and generation).
fn collider_key(h: ColliderHandle) -> u64 {
    let (index, generation) = h.into_raw_parts();
    (u64::from(index) << 32) | u64::from(generation)
}
