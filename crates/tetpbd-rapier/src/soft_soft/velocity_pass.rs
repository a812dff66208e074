//! The velocity pass of soft–soft contacts after each substep: the separating normal velocity
//! of every contact projected in the substep is removed (restitution 0), and a contact that
//! let go in the substep keeps its particle at the relative normal velocity it had while held
//! (see [`crate::SoftContacts`] for the contact).

use hecs::World;
use nalgebra::Vector3;

use crate::soft_soft::gather::{ContactFrame, Gather};
use crate::soft_soft::project::Field;
#[cfg(doc)]
use crate::soft_soft::settings::SoftContactSettings;

impl ContactFrame {
    /// After the velocity update: removes the separating normal velocity of every contact
    /// projected in the substep (restitution 0), and holds every contact that let go in the
    /// substep at the relative normal velocity it had while held.
    ///
    /// A contact that holds a particle against its own stiff body (a light corner caught on
    /// a face while the body's bulk moves on) pushes it back out every substep, and the
    /// families' next pass pulls it back in: the correction the contact holds back grows
    /// with the mass ratio between the corner and its neighbours, and the families may turn
    /// it into speed (a hook's corrections are external work in their budget,
    /// `tetpbd::stabilisation::hook_work`). When the contact lets go (the particle slides
    /// past the triangle's edge), that correction comes out in one pass as a normal speed
    /// `Δc/h` into the face, far beyond anything the bodies brought in. A released
    /// particle's relative normal velocity `v_n = (v_p − v_q)·n` (last normal `n` and
    /// barycentrics of the contact) is therefore kept at
    ///
    /// ```text
    /// v_n ≥ min(v_held, (v̄ − v_q)·n) − S     (m/s)
    /// ```
    ///
    /// with `v_held` (≤ 0) what the contact left after its last velocity pass, `v̄` the mean
    /// velocity of the particle's body (its surface particles, by mass) and `S` =
    /// [`SoftContactSettings::max_separation_speed`], the bound on every speed a contact's
    /// correction turns into: a released particle approaches the face no faster than its
    /// body does. The snap is the body's own (its families'), so what is removed from the
    /// particle is given back to its body's surface particles as one uniform velocity: the
    /// body's momentum is kept and the other body is not pushed (no bounce). The particle
    /// loses more kinetic energy than the body gains, so the pass never adds energy, and a
    /// particle that leaves the face with its body (an impact, a cube sliding off an edge) is
    /// left alone.
    pub fn velocity_pass(&mut self, world: &mut World, g: &Gather, release_speed: f32) {
        if !self.candidates.iter().any(|c| c.active || c.held_before) {
            return;
        }
        self.load(world, g, Field::Velocity);
        self.separating();
        if self.candidates.iter().any(|c| c.held_before && !c.active) {
            self.released(g, release_speed);
        }
        self.store(world, g, Field::Velocity);
    }

    /// Removes the separating normal velocity of the contacts projected in the substep.
    fn separating(&mut self) {
        let ContactFrame { v, candidates, .. } = self;
        for c in candidates.iter_mut().filter(|c| c.active) {
            let (p, n, bary, w) = (c.p as usize, c.n, c.bary, c.weights);
            let tri = c.tri.map(|i| i as usize);
            let vq: Vector3<f32> = (0..3).map(|k| v[tri[k]] * bary[k]).sum();
            // A held side moves the other one no faster than the support it rests on
            // (at rest): its own separating normal velocity is not handed on.
            let (vp_n, vq_n) = match c.held {
                1 => (n.dot(&v[p]).max(0.0), n.dot(&vq)),
                2 => (n.dot(&v[p]), n.dot(&vq).min(0.0)),
                _ => (n.dot(&v[p]), n.dot(&vq)),
            };
            let vn = vp_n - vq_n;
            c.vn_held = vn.min(0.0);
            let wsum = w[0] + (0..3).map(|k| bary[k] * bary[k] * w[k + 1]).sum::<f32>();
            if !(vn > 0.0 && wsum > 0.0) {
                continue;
            }
            let j = -vn / wsum;
            v[p] += n * (w[0] * j);
            for k in 0..3 {
                v[tri[k]] -= n * (w[k + 1] * bary[k] * j);
            }
        }
    }

    /// Holds the contacts released in the substep (see [`ContactFrame::velocity_pass`]).
    fn released(&mut self, g: &Gather, release_speed: f32) {
        let ContactFrame {
            v,
            w,
            candidates,
            body_motion,
            ..
        } = self;
        body_motion.clear();
        body_motion.extend(g.bodies.iter().map(|b| {
            let range = b.offset..b.offset + b.len;
            v[range.clone()]
                .iter()
                .zip(&w[range])
                .filter(|(_, wi)| **wi > 0.0)
                .fold((Vector3::zeros(), 0.0), |(m, s), (vi, wi)| {
                    (m + vi / *wi, s + 1.0 / *wi)
                })
        }));
        for c in candidates.iter().filter(|c| c.held_before && !c.active) {
            let (p, n, bary) = (c.p as usize, c.n, c.bary);
            let b = g.body_of_slot(p);
            let (Some(&(momentum, mass)), Some(body)) = (body_motion.get(b), g.bodies.get(b))
            else {
                continue;
            };
            if !(w[p] > 0.0 && mass > 0.0) {
                continue;
            }
            let vq: Vector3<f32> = c
                .tri
                .iter()
                .zip(bary)
                .map(|(&i, b)| v[i as usize] * b)
                .sum();
            let vn = n.dot(&(v[p] - vq));
            let floor = c.vn_held.min(n.dot(&(momentum / mass - vq))) - release_speed;
            if vn.partial_cmp(&floor) != Some(std::cmp::Ordering::Less) {
                continue;
            }
            let dv = floor - vn;
            v[p] += n * dv;
            let back = n * (dv / (w[p] * mass));
            for vi in v[body.offset..body.offset + body.len].iter_mut() {
                *vi -= back;
            }
        }
    }
}
