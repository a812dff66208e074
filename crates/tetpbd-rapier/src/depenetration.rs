//! Pushing a soft body out of an overlap without launching it.
//!
//! A contact that starts deeper than one substep's push is resolved at most at
//! `max_depenetration_speed` (`contacts::particle` module docs). The push moves the contact particles,
//! the body's constraints carry it to the rest of the body over the following substeps, and
//! XPBD turns every such displacement into velocity: a cube spawned 2 cm inside the ground
//! left it at 2.4 m/s with a bound of 2 m/s and hopped 31 cm. Separation is a correction of
//! position, not an impact, so it must not leave the body with speed of its own.
//!
//! While any of a soft body's contacts still has an overlap allowance, and for [`SETTLE`]
//! seconds after the last one did (the time the body's elastic response to the push takes
//! to die out), the body's particle velocities along the mean normal `n` of those contacts are capped after
//! every substep at `max(0, n·v⁻)`, `v⁻` the body's centre-of-mass velocity after the
//! substep's prediction. Motion towards the collider, sideways, and a separating motion the
//! body already had are left alone; only speed the overlap gave it is removed (against the
//! collider, which takes no reaction, as for any resolved overlap).

use hecs::Entity;
use nalgebra::Vector3;
use tetpbd::Particles;

use crate::contacts::particle::ParticleContact;

/// How long a body's velocity stays capped after its last overlap allowance ran out, s.
/// Measured on cubes of 0.3–1 m spawned 0.5–20 cm inside the ground at 10 substeps: with
/// the cap for one frame only (1/60 s) the compressed body still sprang up at up to 2.3 m/s
/// and hopped 11 cm; with 1/6 s its centre of mass never rose faster than 2 mm/s
/// (`tests/depenetration.rs`).
pub(crate) const SETTLE: f32 = 0.2;

/// [`SETTLE`] in substeps of `h` seconds.
pub(crate) fn settle_substeps(h: f32) -> u32 {
    (SETTLE / h).ceil().min(u32::MAX as f32) as u32
}

/// A soft body being pushed out of an overlap: entity bits, the mean contact normal of its
/// depenetrating contacts (unit), and how many more substeps its velocity is capped for.
pub(crate) type Depenetrating = (u64, Vector3<f32>, u32);

/// After a substep's velocity update, before the contacts are reset: records whether
/// `entity` is being pushed out of an overlap (one of `contacts` has an allowance left) and
/// caps its particle velocities while it is (or was within the last `window` substeps).
/// `list` is kept across frames, sorted by entity bits.
pub(crate) fn cap_depenetration(
    list: &mut Vec<Depenetrating>,
    entity: Entity,
    contacts: &[ParticleContact],
    p: &mut Particles,
    v_cm_pre: &Vector3<f32>,
    window: u32,
) {
    let key = entity.to_bits().get();
    let normal: Vector3<f32> = contacts
        .iter()
        .filter(|c| c.has_normal && c.solve && c.allowance > 0.0)
        .map(|c| c.normal)
        .sum();
    let at = list.binary_search_by_key(&key, |d| d.0);
    let normal = match (normal.try_normalize(1e-6), at) {
        (Some(n), Ok(k)) => {
            list[k] = (key, n, window);
            n
        }
        (Some(n), Err(k)) => {
            list.insert(k, (key, n, window));
            n
        }
        (None, Ok(k)) if list[k].2 > 0 => {
            list[k].2 -= 1;
            list[k].1
        }
        (None, Ok(k)) => {
            list.remove(k);
            return;
        }
        (None, Err(_)) => return,
    };
    let cap = normal.dot(v_cm_pre).max(0.0);
    for i in 0..p.len() {
        let vn = normal.dot(&p.velocities()[i]);
        if p.inv_masses()[i] > 0.0 && vn > cap {
            p.velocities_mut()[i] -= normal * (vn - cap);
        }
    }
}
