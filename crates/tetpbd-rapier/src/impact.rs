//! Impacts deeper than a soft surface can take within a substep meet the whole soft body.
//!
//! A contact is projected locally: the correction is split between the rigid body and the
//! few particles of the soft surface it touches, by their masses. That holds for any
//! contact a substep can resolve, and fails for fast impacts, where one substep carries the
//! rigid point (or the particle) a cell or more into the other side:
//!
//! * a 1 kg ball at 200 m/s crossing a triangle of ~0.5 kg particles pushed it 10 cm into a
//!   20 cm slab in one substep, was slowed only to 150 m/s and slipped past the surface.
//!   Deeper than half a triangle's edge behind the surface a rigid point is *inside* the
//!   soft body, where no contact sees it any more (contacts live on the surface; the
//!   structural cause): the ball crossed the slab within the frame, was pushed up out of the
//!   ground by rapier and left at up to 400 m/s, the slab's crushed cells springing back. A
//!   tumbling 8 cm box hit at a corner was slowed, then sank between the particles at
//!   8 m/s, pushing one triangle after the other less than the reach below it;
//! * a soft cube of 0.1 m cells at 150 m/s onto the ground: its surface particles stopped at
//!   the collider, the particles behind them (one Gauss–Seidel projection away) kept going
//!   and passed through the body's own bottom.
//!
//! So every particle contact and rigid-point contact resolves at most the body's *local
//! reach* ([`LOCAL_REACH`] of the mean surface edge) locally within a projection; the depth
//! beyond it (after the overlap allowance of a body created inside a collider,
//! `contacts::particle` module docs) is taken by the whole soft body moving as one: its free particles
//! translated together (inverse mass `1/M` of the free mass) against the rigid body's
//! generalized inverse mass. The impact is then perfectly inelastic at the level it happens
//! on, momentum kept exactly, and the soft body passes the momentum on through its own
//! contacts (the ground under a slab). A soft body with a pinned particle does not move
//! (`1/M = 0`). Contacts within the reach, resting and sliding ones included, are
//! unchanged; what fast impacts lose is a dent deeper than the reach.
//!
//! Measured (`tests/projectiles.rs`): 1 kg balls (r 0.05 and 0.1 m) and boxes (0.08 m) at
//! 50–300 m/s onto slabs of 1–4 cells on the ground stay on the slab and leave slower than
//! they came; soft cubes at 50–300 m/s onto the ground or a fixed plate stop on it.

use nalgebra::Vector3;
use tetpbd::{Particles, Surface};

/// Share of the mean rest length of the surface edges that a contact resolves locally within
/// a projection; the rest of a deeper impact meets the whole body. A quarter of a cell keeps
/// the inner particles of a fast soft body behind its stopped surface.
const LOCAL_REACH: f32 = 0.25;

/// How deep an impact the surface of `p` takes locally within a substep, m: [`LOCAL_REACH`]
/// times the mean rest length of its surface edges (each triangle's three edges; shared edges
/// counted twice, which leaves the mean unchanged on a closed surface).
pub(crate) fn local_reach(p: &Particles, surface: &Surface) -> f32 {
    let rest = p.rest_positions();
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for t in surface.triangles() {
        let [a, b, c] = t.map(|i| rest[i as usize]);
        sum += f64::from((b - a).norm() + (c - b).norm() + (a - c).norm());
        n += 3;
    }
    if n == 0 {
        return f32::INFINITY;
    }
    LOCAL_REACH * (sum / n as f64) as f32
}

/// The whole-body part of a soft body's contacts in one projection sweep: its local reach
/// and, once needed, its inverse free mass.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Impact {
    reach: f32,
    inv_mass: Option<f32>,
}

impl Impact {
    /// A sweep over a body whose surface takes `reach` (m) locally ([`local_reach`];
    /// `f32::INFINITY`: never the whole body).
    pub fn new(reach: f32) -> Self {
        Impact {
            reach,
            inv_mass: None,
        }
    }

    /// For a violated contact `c_val < 0` (m) whose rigid side has the generalized inverse
    /// mass `w_body` (1/kg) along it: moves the whole soft body along the unit direction
    /// `soft_dir` by its share of the depth beyond the reach and returns the multiplier
    /// `Δλ` (kg·m, the rigid side gets `−soft_dir·Δλ`) and the depth so resolved (m);
    /// `None` when the contact is within reach or nothing can move.
    pub fn take_excess(
        &mut self,
        p: &mut Particles,
        c_val: f32,
        w_body: f32,
        soft_dir: &Vector3<f32>,
    ) -> Option<(f32, f32)> {
        let excess = -c_val - self.reach;
        if excess.is_nan() || excess <= 0.0 {
            return None;
        }
        let w_soft = *self.inv_mass.get_or_insert_with(|| inv_free_mass(p));
        let dl = excess / (w_soft + w_body);
        if !(dl.is_finite() && dl > 0.0) {
            return None;
        }
        translate_free(p, &(soft_dir * (w_soft * dl)));
        Some((dl, excess))
    }
}

/// Inverse of the free particles' total mass, 1/kg; 0 when a particle is pinned (the body
/// is held in place) or there is no free mass.
fn inv_free_mass(p: &Particles) -> f32 {
    let mut mass = 0.0f32;
    for (&w, &m) in p.inv_masses().iter().zip(p.masses()) {
        if w <= 0.0 {
            return 0.0;
        }
        mass += m;
    }
    if mass > 0.0 {
        1.0 / mass
    } else {
        0.0
    }
}

/// Moves every free particle by `dx`, m.
fn translate_free(p: &mut Particles, dx: &Vector3<f32>) {
    if *dx == Vector3::zeros() {
        return;
    }
    for i in 0..p.len() {
        if p.inv_masses()[i] > 0.0 {
            p.positions_mut()[i] += dx;
        }
    }
}
