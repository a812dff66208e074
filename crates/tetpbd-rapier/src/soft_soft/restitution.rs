//! Body-level restitution of soft–soft contacts: bodies in contact separate as wholes at no
//! more than `e` times the speed at which they met, `e` the combined restitution of their
//! [`crate::SoftCollider`]s (0 by default).
//!
//! The per-particle velocity pass removes the separating velocity a contact's projection
//! gives its particles, but a stiff XPBD body also stores the impact in its constraints and
//! springs back while still touching: a soft cube dropped on another soft body leaves it at
//! about 60 % of its impact speed, and a pile of them scatters. So after each substep, for
//! every body pair with contacts projected in it, with
//!
//! ```text
//! n   = normalize( Σ contact normals, oriented from b to a )
//! v_n = (v_cm,a − v_cm,b) · n          (> 0 separating)
//! ```
//!
//! (`v_cm` the velocity of a body's free particles' centre of mass,
//! [`tetpbd::Particles::free_velocity`]), the pair runs the same impact episode as a soft
//! body against a collider (`response::restitution`, Poisson's hypothesis on the centres of
//! mass): an approach faster than `2 a_max h` before the episode's first substep
//! ([`crate::SoftContactSettings::max_acceleration`] standing in for gravity, which a bare
//! solver's hook does not know) is an impact, bounced back at `e` times its approach speed
//! once compression ends and capped there while the contact lasts. Any other contact, and
//! every contact when `e = 0`, does not separate as a whole: `v_n` is capped at 0. Both caps
//! are raised by what gravity and the loads applied to the two bodies (user forces, grabs,
//! external accelerations) have added to `v_n` since the contact began, as for a collider
//! (`response::restitution`): a pull lifts a body off another, its recoil does not. The change
//! is an opposite pair of impulses on the two bodies shared by `W` (1/body mass, 0 for a
//! body with a pinned particle): momentum is conserved, every particle of a body gets the
//! same change (no deformation is added), and only the normal part of the relative motion is
//! touched (sliding and rolling are left to friction). With `e = 0` no approach speed is
//! needed and none is measured.
//!
//! Limit: the separation never exceeds `e v⁻`, but a fast impact between stiff bodies
//! (several m/s) ends below it, part of the bounce lost to the per-particle velocity pass and
//! the bodies' constraints (`tests/soft_soft_restitution.rs`).

use hecs::World;
use nalgebra::Vector3;

use crate::response::restitution::Episodes;
use crate::soft_soft::body::{exchange, relative_normal_velocity};
use crate::soft_soft::gather::{ContactFrame, Gather};

/// State of the body-level restitution kept across substeps and frames.
#[derive(Clone, Debug, Default)]
pub(crate) struct BodyRestitution {
    /// Per pair of the frame: sum of the contact normals of the substep.
    sums: Vec<Vector3<f32>>,
    /// Per pair of the frame: the body a held contact of the substep holds still (one of
    /// the pair's frame bodies; `carrying` module docs).
    held: Vec<Option<usize>>,
    /// Per frame body: centre-of-mass velocity at the substep start (only when some pair
    /// has a restitution above 0).
    v_pre: Vec<Vector3<f32>>,
    /// Per frame body: the velocity change gravity and the applied loads gave it in the
    /// substep, m/s (only when some pair is in contact).
    pulls: Vec<Vector3<f32>>,
    episodes: Episodes,
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
            .extend(g.bodies.iter().map(|b| b.com_velocity(world)));
    }

    /// Applies the body-level restitution after a substep of `h` (s) under `gravity`
    /// (m/s²); `a_max` (m/s²) sets the impact threshold (module docs).
    pub fn apply(
        &mut self,
        world: &mut World,
        g: &Gather,
        frame: &ContactFrame,
        (a_max, gravity): (f32, &Vector3<f32>),
        h: f32,
    ) {
        self.sums.clear();
        self.sums.resize(g.pairs.len(), Vector3::zeros());
        self.held.clear();
        self.held.resize(g.pairs.len(), None);
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
            match c.held {
                1 => self.held[k] = Some(bp),
                2 => self.held[k] = Some(bt),
                _ => {}
            }
            any = true;
        }
        if any {
            self.pulls.clear();
            self.pulls
                .extend(g.bodies.iter().map(|b| b.pull(world, gravity, h)));
            let threshold = 2.0 * a_max * h;
            for k in 0..g.pairs.len() {
                self.pair(world, g, k, threshold);
            }
        }
        self.episodes.end_substep();
    }

    /// The restitution of pair `k` of the frame.
    fn pair(&mut self, world: &mut World, g: &Gather, k: usize, threshold: f32) {
        let (a, b) = g.pairs[k];
        let len = self.sums[k].norm();
        if len.is_nan() || len <= 1e-9 {
            return;
        }
        let n = self.sums[k] / len;
        let (ba, bb) = (&g.bodies[a], &g.bodies[b]);
        if ba.inv_mass + bb.inv_mass <= 0.0 {
            return;
        }
        let v_n = relative_normal_velocity(world, ba, bb, &n);
        let e = g.pair_props[k].restitution;
        let key = (ba.entity.to_bits().get(), bb.entity.to_bits().get());
        let v_pre = (self.v_pre.get(a), self.v_pre.get(b));
        let approach = || match v_pre {
            (Some(va), Some(vb)) if e > 0.0 => (va - vb).dot(&n),
            _ => 0.0,
        };
        let pull = (self.pulls[a] - self.pulls[b]).dot(&n);
        let dv = self
            .episodes
            .episode(key, approach, threshold)
            .change(v_n, e, pull);
        if let Some(dv) = dv.filter(|dv| !dv.is_nan()) {
            // A body resting on a support that holds a much heavier one still takes no
            // share (`carrying` module docs).
            let weights = match self.held[k] {
                Some(h) if h == a => (0.0, bb.inv_mass),
                Some(h) if h == b => (ba.inv_mass, 0.0),
                _ => (ba.inv_mass, bb.inv_mass),
            };
            exchange(world, (ba, bb), weights, &n, dv);
        }
    }
}
