//! Body-level restitution of soft–soft contacts: bodies in contact separate as wholes at no
//! more than `e` times the speed at which they met (Poisson's hypothesis on the two centres
//! of mass), `e` the combined restitution of their [`crate::SoftCollider`]s (0 by default).
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
//! v⁻    = −(v_cm,a − v_cm,b)⁻ · n      the approach speed before the substep in which the
//!                                      pair's contact episode began (kept while it lasts)
//! if v_rel > e v⁻:  a's velocities −= n (v_rel − e v⁻) W_a/(W_a+W_b),  b's += n (…) W_b/(W_a+W_b)
//! ```
//!
//! (`W`: 1/body mass, 0 for a body with a pinned particle; `v_cm` the velocity of a body's
//! free particles' centre of mass, [`tetpbd::Particles::free_velocity`]). Momentum is
//! conserved, every particle of a body gets the same change (no deformation is added), and
//! only the normal part of the relative motion is touched: sliding and rolling are left to
//! friction. An episode ends with the first substep in which the pair has no contact. With
//! `e = 0` no approach speed is needed and none is measured.

use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::Particles;

use crate::soft_soft::gather::{ContactFrame, Gather};

/// The contact episode of a pair of soft bodies (entity bits, lower first).
#[derive(Clone, Copy, Debug)]
struct Episode {
    key: (u64, u64),
    /// Approach speed `v⁻` (m/s, ≥ 0) when the episode began.
    approach: f32,
    seen: bool,
}

/// State of the body-level restitution kept across substeps and frames.
#[derive(Clone, Debug, Default)]
pub(crate) struct BodyRestitution {
    /// Per pair of the frame: sum of the contact normals of the substep.
    sums: Vec<Vector3<f32>>,
    /// Per frame body: centre-of-mass velocity at the substep start (only when some pair
    /// has a restitution above 0).
    v_pre: Vec<Vector3<f32>>,
    episodes: Vec<Episode>,
}

impl BodyRestitution {
    /// Substep start: records the bodies' centre-of-mass velocities when a pair of the frame
    /// may bounce.
    pub fn begin_substep(&mut self, world: &mut World, g: &Gather) {
        self.v_pre.clear();
        if g.pair_props.iter().all(|p| p.restitution <= 0.0) {
            return;
        }
        self.v_pre
            .extend(g.bodies.iter().map(|b| com_velocity(world, b.entity)));
    }

    /// Applies the body-level restitution after a substep.
    pub fn apply(&mut self, world: &mut World, g: &Gather, frame: &ContactFrame) {
        for ep in &mut self.episodes {
            ep.seen = false;
        }
        self.sums.clear();
        self.sums.resize(g.pairs.len(), Vector3::zeros());
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
            self.sums[k] += n;
            any = true;
        }
        if any {
            for k in 0..g.pairs.len() {
                self.pair(world, g, k);
            }
        }
        self.episodes.retain(|ep| ep.seen);
    }

    /// The restitution of pair `k` of the frame.
    fn pair(&mut self, world: &mut World, g: &Gather, k: usize) {
        let (a, b) = g.pairs[k];
        let len = self.sums[k].norm();
        if len.is_nan() || len <= 1e-9 {
            return;
        }
        let n = self.sums[k] / len;
        let (wa, wb) = (g.bodies[a].inv_mass, g.bodies[b].inv_mass);
        let wsum = wa + wb;
        if wsum.is_nan() || wsum <= 0.0 {
            return;
        }
        let e = g.pair_props[k].restitution;
        let approach = if e > 0.0 {
            let (ea, eb) = (g.bodies[a].entity, g.bodies[b].entity);
            let v_pre = (self.v_pre.get(a), self.v_pre.get(b));
            let before = match v_pre {
                (Some(va), Some(vb)) => (vb - va).dot(&n).max(0.0),
                _ => 0.0,
            };
            self.episode(ea, eb, before)
        } else {
            0.0
        };
        let va = com_velocity(world, g.bodies[a].entity);
        let vb = com_velocity(world, g.bodies[b].entity);
        let excess = (va - vb).dot(&n) - e * approach;
        if excess.is_nan() || excess <= 0.0 {
            return;
        }
        add_velocity(world, g.bodies[a].entity, n * (-excess * wa / wsum));
        add_velocity(world, g.bodies[b].entity, n * (excess * wb / wsum));
    }

    /// The approach speed of the pair's episode, begun now with `before` if it is new.
    fn episode(&mut self, a: Entity, b: Entity, before: f32) -> f32 {
        let (ka, kb) = (a.to_bits().get(), b.to_bits().get());
        let key = (ka.min(kb), ka.max(kb));
        let k = match self.episodes.binary_search_by(|ep| ep.key.cmp(&key)) {
            Ok(k) => k,
            Err(k) => {
                let ep = Episode {
                    key,
                    approach: before,
                    seen: false,
                };
                self.episodes.insert(k, ep);
                k
            }
        };
        self.episodes[k].seen = true;
        self.episodes[k].approach
    }
}

fn com_velocity(world: &mut World, e: Entity) -> Vector3<f32> {
    match world.query_one_mut::<&Particles>(e) {
        Ok(p) => p.free_velocity().map_or(Vector3::zeros(), |v| v.0),
        Err(_) => Vector3::zeros(),
    }
}

fn add_velocity(world: &mut World, e: Entity, dv: Vector3<f32>) {
    if dv == Vector3::zeros() || !dv.iter().all(|c| c.is_finite()) {
        return;
    }
    if let Ok(p) = world.query_one_mut::<&mut Particles>(e) {
        for i in 0..p.len() {
            if p.inv_masses()[i] > 0.0 {
                p.velocities_mut()[i] += dv;
            }
        }
    }
}
