//! Body-level restitution of soft–soft contacts: bodies in contact stop separating as
//! wholes at the end of every substep (restitution 0 at the level of the bodies' centres of
//! mass).
//!
//! The per-particle velocity pass removes the separating velocity a contact's projection
//! gives its particles, but a stiff XPBD body also stores the impact in its constraints and
//! springs back while still touching: a soft cube dropped on another soft body leaves it at
//! about 60 % of its impact speed, and a pile of them scatters. So after each substep, for
//! every body pair with contacts projected in it:
//!
//! ```text
//! n     = normalize( Σ contact normals, oriented from b to a )
//! v_rel = (v_cm,a − v_cm,b) · n
//! if v_rel > 0:  a's velocities −= n v_rel W_a/(W_a+W_b),  b's += n v_rel W_b/(W_a+W_b)
//! ```
//!
//! (`W`: 1/body mass, 0 for a body with a pinned particle). Momentum is conserved, every
//! particle of a body gets the same change (no deformation is added), and only the normal
//! part of the relative motion is touched: sliding and rolling are left to friction.
//! Turned off by [`crate::SoftContactSettings::inelastic`].

use hecs::World;
use nalgebra::Vector3;
use tetpbd::Particles;

use crate::soft_soft::gather::{ContactFrame, Gather};

/// Applies the body-level restitution pass after a substep; `sums` is scratch.
pub(crate) fn body_restitution(
    world: &mut World,
    g: &Gather,
    frame: &ContactFrame,
    sums: &mut Vec<Vector3<f32>>,
) {
    sums.clear();
    sums.resize(g.pairs.len(), Vector3::zeros());
    let mut any = false;
    for c in frame.candidates.iter().filter(|c| c.active) {
        let bp = g.body_of_slot(c.p as usize);
        let bt = g.body_of_slot(c.tri[0] as usize);
        if bp == bt {
            continue;
        }
        let key = (bp.min(bt), bp.max(bt));
        let Ok(k) = g.pairs.binary_search(&key) else {
            continue;
        };
        // The triangle's normal points from its body to the particle's.
        let n = if bp == key.0 { c.n } else { -c.n };
        sums[k] += n;
        any = true;
    }
    if !any {
        return;
    }
    for (k, &(a, b)) in g.pairs.iter().enumerate() {
        let len = sums[k].norm();
        if len.is_nan() || len <= 1e-9 {
            continue;
        }
        let n = sums[k] / len;
        let (wa, wb) = (g.bodies[a].inv_mass, g.bodies[b].inv_mass);
        let wsum = wa + wb;
        if wsum.is_nan() || wsum <= 0.0 {
            continue;
        }
        let rel = (com_velocity(world, g, a) - com_velocity(world, g, b)).dot(&n);
        if rel.is_nan() || rel <= 0.0 {
            continue;
        }
        add_velocity(world, g, a, n * (-rel * wa / wsum));
        add_velocity(world, g, b, n * (rel * wb / wsum));
    }
}

fn com_velocity(world: &mut World, g: &Gather, k: usize) -> Vector3<f32> {
    match world.query_one_mut::<&Particles>(g.bodies[k].entity) {
        Ok(p) if p.total_mass() > 0.0 => p.linear_momentum() / p.total_mass(),
        _ => Vector3::zeros(),
    }
}

fn add_velocity(world: &mut World, g: &Gather, k: usize, dv: Vector3<f32>) {
    if dv == Vector3::zeros() || !dv.iter().all(|c| c.is_finite()) {
        return;
    }
    if let Ok(p) = world.query_one_mut::<&mut Particles>(g.bodies[k].entity) {
        for i in 0..p.len() {
            if p.inv_masses()[i] > 0.0 {
                p.velocities_mut()[i] += dv;
            }
        }
    }
}
