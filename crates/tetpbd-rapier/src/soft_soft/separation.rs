//! Deep-overlap separation: bodies that start a frame inside each other are walked apart
//! rigidly, at most `S h` per substep, instead of being pushed apart particle by particle.
//!
//! Pushing only the surface particles that lie inside the other body deforms both bodies
//! (their interiors stay where they are), and the elasticity turns that deformation into
//! speed: a half-overlap of two stiff cubes then flies apart at several m/s however small the
//! per-contact correction. So a surface particle found strictly inside another body at the
//! frame start (a *deep* particle) is not projected. Instead, once per frame and body pair
//! with deep particles:
//!
//! ```text
//! for D in [centre of a − centre of b (normalized), ±x, ±y, ±z]:
//!     need(D) = δ + max( exit distance along +D out of b of a's deep particles,
//!                        exit distance along −D out of a of b's deep particles )
//! D* = the direction of least need        (exit distance: ray cast on the surface BVH)
//! ```
//!
//! and in every substep of the frame, while some of `need(D*)` remains:
//!
//! ```text
//! shift = min(remaining, S h)            (a clamp is counted when remaining > S h)
//! a moves by +D* shift W_a/(W_a+W_b), b by −D* shift W_b/(W_a+W_b)   (W: 1/body mass, 0 if pinned)
//! ```
//!
//! The shift moves every particle of a body by the same vector after the prediction of a
//! substep, and the velocity it would create is removed after the velocity update, so it adds
//! neither velocity nor deformation: two bodies separate at a relative speed of at most `S`
//! (the documented bound), and no energy is injected. The shift is undone by nothing; the
//! frame's regular contacts keep the separated surfaces apart.

use hecs::World;
use nalgebra::Vector3;
use tetpbd::Particles;

use crate::soft_soft::body::{exchange, relative_normal_velocity, FrameBody};
use crate::soft_soft::bvh::BodyCache;
use crate::soft_soft::settings::{SoftContactSettings, SoftContactStats};

/// A body pair with deep particles, and its separation budget for the frame.
#[derive(Clone, Debug)]
pub(crate) struct PairShift {
    pub a: usize,
    pub b: usize,
    /// Direction in which `a` moves away from `b` (unit), fixed for the frame.
    pub dir: Vector3<f32>,
    /// Relative displacement still to apply in this frame, m.
    pub remaining: f32,
}

/// One side of a pair: a body's cache, the surface-local positions of its particles at the
/// frame start and the positions of its deep particles (inside the other body).
pub(crate) struct Side<'a> {
    pub cache: &'a BodyCache,
    pub xs: &'a [Vector3<f32>],
    pub deep: &'a [Vector3<f32>],
    pub centre: Vector3<f32>,
}

/// Deep-overlap state of a frame.
#[derive(Clone, Debug, Default)]
pub(crate) struct Separation {
    pub pairs: Vec<PairShift>,
    /// Rigid shift applied to each frame body in the current substep, m.
    pub shift: Vec<Vector3<f32>>,
}

impl Separation {
    pub fn clear(&mut self) {
        self.pairs.clear();
        self.shift.clear();
    }

    /// Adds the pair `(a, b)` when either side has deep particles: picks the direction of
    /// least separation (see the module docs).
    pub fn add_pair(&mut self, a: usize, b: usize, sa: &Side<'_>, sb: &Side<'_>, thickness: f32) {
        if sa.deep.is_empty() && sb.deep.is_empty() {
            return;
        }
        let centre = sa.centre - sb.centre;
        let len = centre.norm();
        let axes = [
            Vector3::x(),
            -Vector3::x(),
            Vector3::y(),
            -Vector3::y(),
            Vector3::z(),
            -Vector3::z(),
        ];
        let towards = (len.is_finite() && len > 1e-6).then(|| centre / len);
        let mut best: Option<(f32, Vector3<f32>)> = None;
        for d in towards.into_iter().chain(axes) {
            let Some(need) = need_along(sa, sb, &d) else {
                continue;
            };
            if best.is_none_or(|(b, _)| need < b) {
                best = Some((need, d));
            }
        }
        if let Some((need, dir)) = best {
            self.pairs.push(PairShift {
                a,
                b,
                dir,
                remaining: need + thickness,
            });
        }
    }

    /// After the prediction of a substep: shifts the bodies of every pair apart by at most
    /// `S h` (see the module docs).
    pub fn apply(
        &mut self,
        world: &mut World,
        bodies: &[FrameBody],
        s: &SoftContactSettings,
        h: f32,
        stats: &mut SoftContactStats,
    ) {
        self.shift.clear();
        self.shift.resize(bodies.len(), Vector3::zeros());
        if self.pairs.is_empty() {
            return;
        }
        let step = s.max_separation_speed * h;
        for pair in &mut self.pairs {
            let (wa, wb) = (bodies[pair.a].inv_mass, bodies[pair.b].inv_mass);
            let wsum = wa + wb;
            if wsum.is_nan() || wsum <= 0.0 || pair.remaining <= 0.0 {
                continue;
            }
            if pair.remaining > step {
                stats.clamps += 1;
            }
            let shift = pair.remaining.min(step);
            pair.remaining -= shift;
            self.shift[pair.a] += pair.dir * (shift * wa / wsum);
            self.shift[pair.b] -= pair.dir * (shift * wb / wsum);
        }
        for (b, d) in bodies.iter().zip(&self.shift) {
            if *d == Vector3::zeros() {
                continue;
            }
            if let Ok(p) = world.query_one_mut::<&mut Particles>(b.entity) {
                for x in p.positions_mut() {
                    *x += d;
                }
            }
        }
    }

    /// After the velocity update: removes the velocity the substep's shift created, then
    /// the approaching relative velocity along `D` of every deep pair (an inelastic
    /// body-level impulse, so gravity cannot push a body back in while it is walked out).
    pub fn remove_velocity(&self, world: &mut World, bodies: &[FrameBody], h: f32) {
        self.remove_shift_velocity(world, bodies, h);
        for pair in &self.pairs {
            let (a, b) = (&bodies[pair.a], &bodies[pair.b]);
            if a.inv_mass + b.inv_mass <= 0.0 {
                continue;
            }
            let rel = relative_normal_velocity(world, a, b, &pair.dir);
            if rel.is_nan() || rel >= 0.0 {
                continue;
            }
            exchange(world, (a, b), (a.inv_mass, b.inv_mass), &pair.dir, -rel);
        }
    }

    fn remove_shift_velocity(&self, world: &mut World, bodies: &[FrameBody], h: f32) {
        for (b, d) in bodies.iter().zip(&self.shift) {
            if *d == Vector3::zeros() {
                continue;
            }
            let dv = d / h;
            if let Ok(p) = world.query_one_mut::<&mut Particles>(b.entity) {
                for v in p.velocities_mut() {
                    *v -= dv;
                }
            }
        }
    }
}

/// Relative displacement along `d` that takes every deep particle out (m), or `None` when a
/// ray finds no exit.
fn need_along(sa: &Side<'_>, sb: &Side<'_>, d: &Vector3<f32>) -> Option<f32> {
    let mut need = 0.0f32;
    for x in sa.deep {
        need = need.max(sb.cache.exit_distance(x, d, sb.xs)?);
    }
    let back = -d;
    for x in sb.deep {
        need = need.max(sa.cache.exit_distance(x, &back, sa.xs)?);
    }
    need.is_finite().then_some(need)
}
