//! Per-substep work of soft–soft contacts: the XPBD vertex–triangle projection with
//! friction (and, for a particle grazing a side face, which face catches it:
//! `flush_beside`) and the end-of-frame statistics (the velocity pass is in
//! `velocity_pass`) (see
//! [`crate::SoftContacts`] for the equations).

use hecs::World;
use nalgebra::Vector3;
use tetpbd::Particles;

use crate::convert::finite3;
use crate::response::friction::{positional_friction, ContactStencil, Coulomb};
use crate::soft_soft::bvh::{closest_barycentric, plane_barycentric, triangle_normal};
use crate::soft_soft::carrying::Carrying;
use crate::soft_soft::gather::{Candidate, ContactFrame, Gather};
use crate::soft_soft::settings::{SoftContactSettings, SoftContactStats};

/// How far (in barycentric units) a particle's projection may lie outside a triangle and
/// still count as inside its prism: rounding only. A wider band lets a face catch particles
/// sliding past its edges (they snag and are shot off along the face normal).
const PRISM_TOLERANCE: f32 = 1e-3;

/// Largest `|cos|` of the angle between two triangles' normals for them to count as faces on
/// either side of a crease (a side face) in [`flush_beside`]: 45° to 135° apart. Coplanar
/// neighbours and the far side of a thin sheet are not side faces.
const CREASE_COS: f32 = 0.7;

/// Which per-particle array a load or store touches.
#[derive(Clone, Copy)]
pub(super) enum Field {
    Position,
    SubstepStart,
    Velocity,
}

impl ContactFrame {
    /// Copies `field` of every involved body's surface particles into the slots.
    pub(super) fn load(&mut self, world: &mut World, g: &Gather, field: Field) {
        for b in g.bodies.iter().filter(|b| b.involved) {
            let Ok(p) = world.query_one_mut::<&Particles>(b.entity) else {
                continue;
            };
            let src = match field {
                Field::Position => p.positions(),
                Field::SubstepStart => p.prev_positions(),
                Field::Velocity => p.velocities(),
            };
            let dst = match field {
                Field::Position => &mut self.x,
                Field::SubstepStart => &mut self.x_prev,
                Field::Velocity => &mut self.v,
            };
            for (k, &i) in g.cache(b).vertices.iter().enumerate() {
                if let Some(v) = src.get(i as usize) {
                    dst[b.offset + k] = *v;
                }
            }
        }
    }

    /// Writes the slots back (finite values only) into positions or velocities.
    pub(super) fn store(&self, world: &mut World, g: &Gather, field: Field) -> u64 {
        let mut rejected = 0;
        for b in g.bodies.iter().filter(|b| b.involved) {
            let Ok(p) = world.query_one_mut::<&mut Particles>(b.entity) else {
                continue;
            };
            let (src, dst) = match field {
                Field::Velocity => (&self.v, p.velocities_mut()),
                _ => (&self.x, p.positions_mut()),
            };
            for (k, &i) in g.cache(b).vertices.iter().enumerate() {
                let v = src[b.offset + k];
                match dst.get_mut(i as usize) {
                    Some(d) if finite3(&v) => *d = v,
                    Some(_) => rejected += 1,
                    None => {}
                }
            }
        }
        rejected
    }

    /// Substep start: record each candidate's distance to its triangle's plane and reset
    /// its multipliers.
    pub fn begin_substep(&mut self, world: &mut World, g: &Gather) {
        if self.candidates.is_empty() {
            return;
        }
        self.load(world, g, Field::SubstepStart);
        let x = &self.x_prev;
        for c in &mut self.candidates {
            let [a, b, t] = c.tri.map(|i| x[i as usize]);
            let p = x[c.p as usize];
            (c.d_prev, c.prism_prev) = match triangle_normal(&a, &b, &t) {
                Some(n) => {
                    let bw = plane_barycentric(&p, &a, &b, &t, &n);
                    let inside = bw.iter().all(|&v| v >= -PRISM_TOLERANCE);
                    ((p - a).dot(&n), inside)
                }
                None => (c.props.thickness, false),
            };
            c.lambda_n = 0.0;
            c.lambda_t = 0.0;
            c.held_before = c.active;
            c.active = false;
            c.clamped = false;
        }
    }

    /// One Gauss–Seidel sweep over the candidates.
    pub fn project(
        &mut self,
        world: &mut World,
        (g, carrying): (&Gather, &mut Carrying),
        s: &SoftContactSettings,
        h: f32,
        stats: &mut SoftContactStats,
    ) {
        if self.candidates.is_empty() {
            return;
        }
        self.load(world, g, Field::Position);
        carrying.on_support.clear();
        carrying.on_support.extend(g.bodies.iter().map(|b| {
            carrying
                .supported
                .binary_search(&b.entity.to_bits().get())
                .is_ok()
        }));
        let carrying = &*carrying;
        let carries = carrying.any();
        let steps = (
            s.compliance / (h * h),
            s.max_separation_speed * h,
            s.skin_speed * h,
        );
        let ContactFrame {
            x,
            x_prev,
            w,
            candidates,
            ..
        } = self;
        for i in 0..candidates.len() {
            if candidates[i].recovery {
                continue;
            }
            let bodies = if carries {
                let c = &candidates[i];
                Some((
                    g.body_of_slot(c.p as usize),
                    g.body_of_slot(c.tri[0] as usize),
                ))
            } else {
                None
            };
            let weights = |c: &Candidate, n: &Vector3<f32>| {
                let own = [
                    w[c.p as usize],
                    w[c.tri[0] as usize],
                    w[c.tri[1] as usize],
                    w[c.tri[2] as usize],
                ];
                match bodies {
                    Some((bp, bt)) => {
                        let carried = carrying.weights(bp, bt, own, n);
                        (carried, carried != own)
                    }
                    None => (own, false),
                }
            };
            match project_one(candidates, i, x, x_prev, weights, steps) {
                Outcome::Degenerate => stats.degenerate += 1,
                Outcome::Clamped => stats.clamps += 1,
                Outcome::Done => {}
            }
        }
        stats.degenerate += self.store(world, g, Field::Position);
    }

    /// End of frame: contact count and the largest penetration at the final positions.
    pub fn finish(&mut self, world: &mut World, g: &Gather, stats: &mut SoftContactStats) {
        stats.contacts = self.candidates.iter().filter(|c| c.ever).count();
        if self.candidates.is_empty() {
            return;
        }
        self.load(world, g, Field::Position);
        let mut pen = 0.0f32;
        for c in &self.candidates {
            let p = self.x[c.p as usize];
            let [a, b, t] = c.tri.map(|i| self.x[i as usize]);
            let Some(n) = triangle_normal(&a, &b, &t) else {
                continue;
            };
            let d = (p - a).dot(&n);
            let counted = if c.recovery {
                true
            } else {
                let bw = plane_barycentric(&p, &a, &b, &t, &n);
                d > -c.depth_limit && bw.iter().all(|&v| v >= -PRISM_TOLERANCE)
            };
            if counted && d.is_finite() {
                pen = pen.max(-d);
            }
        }
        stats.max_penetration = pen.max(0.0);
    }
}

enum Outcome {
    Done,
    Clamped,
    Degenerate,
}

/// Projects candidate `i` (see the module docs of `soft_contact`).
fn project_one(
    candidates: &mut [Candidate],
    i: usize,
    x: &mut [Vector3<f32>],
    x_prev: &[Vector3<f32>],
    weights: impl Fn(&Candidate, &Vector3<f32>) -> ([f32; 4], bool),
    (alpha_tilde, step, skin_step): (f32, f32, f32),
) -> Outcome {
    let c = &candidates[i];
    let p = c.p as usize;
    let tri = c.tri.map(|i| i as usize);
    let [a, b, t] = tri.map(|i| x[i]);
    let xp = x[p];
    let Some(n) = triangle_normal(&a, &b, &t) else {
        return Outcome::Degenerate;
    };
    let d = (xp - a).dot(&n);
    if d < -c.depth_limit {
        return Outcome::Done;
    }
    let bw = plane_barycentric(&xp, &a, &b, &t, &n);
    let inside_now = bw.iter().all(|&v| v >= -PRISM_TOLERANCE);
    // A particle touches the triangle if it was over it at the substep start and still is,
    // or if its path over the substep crossed the triangle's plane inside the triangle (a
    // fast particle entering at a convex edge). One sliding past the triangle's edge beside
    // it does neither and is left to the neighbouring faces, and so is one behind the plane
    // that is grazing a side face of the same body.
    let touching = c.active || (c.prism_prev && inside_now) || crossed_inside(c, d, x, x_prev);
    if !touching
        || (!c.active && d < 0.0 && flush_beside(candidates, i, &n, d, x, c.props.thickness))
    {
        return Outcome::Done;
    }
    let c = &mut candidates[i];
    let bary = if inside_now {
        let bw = bw.map(|v| v.max(0.0));
        let sum: f32 = bw.iter().sum();
        if sum.is_nan() || sum <= 0.0 {
            return Outcome::Degenerate;
        }
        bw.map(|v| v / sum)
    } else {
        closest_barycentric(&xp, &a, &b, &t)
    };
    let q = a * bary[0] + b * bary[1] + t * bary[2];
    let dist = (xp - q).dot(&n);
    let target = contact_target(c.d_prev, c.props.thickness, step, skin_step);
    let mut cval = dist - target;
    if cval.is_nan() || cval >= 0.0 {
        return Outcome::Done;
    }
    let (w, carried) = weights(c, &n);
    if carried {
        // The carrying side is held still, but it is not immovable: the part of the violation
        // its own motion made in this substep (a squeezed light body springing back) is
        // handed to the carried side at no more than the separation speed (`carrying`
        // module docs).
        let light_in = if w[0] == 0.0 {
            -(x[p] - x_prev[p]).dot(&n)
        } else {
            (0..3)
                .map(|k| bary[k] * (x[tri[k]] - x_prev[tri[k]]).dot(&n))
                .sum::<f32>()
        };
        if light_in > 0.0 {
            cval = cval.max(-((-cval - light_in).max(0.0) + step));
        }
    }
    let wp = w[0];
    let wsum = wp + (0..3).map(|k| bary[k] * bary[k] * w[k + 1]).sum::<f32>();
    let denom = wsum + alpha_tilde;
    if !(wsum > 0.0 && denom.is_finite()) {
        return Outcome::Done;
    }
    let mut dl = (-cval - alpha_tilde * c.lambda_n) / denom;
    if c.lambda_n + dl < 0.0 {
        dl = -c.lambda_n;
    }
    if !dl.is_finite() {
        return Outcome::Degenerate;
    }
    x[p] += n * (wp * dl);
    for k in 0..3 {
        x[tri[k]] -= n * (w[k + 1] * bary[k] * dl);
    }
    c.lambda_n += dl;
    c.active = true;
    c.ever = true;
    c.n = n;
    c.bary = bary;
    c.wsum = wsum;
    c.weights = w;
    c.held = match (w[0] == 0.0, w[1..] == [0.0; 3]) {
        (true, false) => 1,
        (false, true) => 2,
        _ => 0,
    };
    friction(c, x, x_prev);
    let clamped = target < 0.0 && !c.clamped;
    if clamped {
        c.clamped = true;
        Outcome::Clamped
    } else {
        Outcome::Done
    }
}

/// `true` when candidate `i`'s particle, `d` (m, < 0) behind its triangle (unit normal `n`),
/// is less deep behind a side face of the same body: another candidate of its group whose
/// normal `m` makes a crease with `n` (`|m·n| <` [`CREASE_COS`]), whose prism it is in and
/// whose plane it is at most `thickness` behind. It is then grazing that side face, not
/// entering through this one (see the module docs of `soft_contact`).
fn flush_beside(
    candidates: &[Candidate],
    i: usize,
    n: &Vector3<f32>,
    d: f32,
    x: &[Vector3<f32>],
    thickness: f32,
) -> bool {
    let c = &candidates[i];
    let xp = x[c.p as usize];
    let [g0, g1] = c.group.map(|k| k as usize);
    candidates.get(g0..g1).is_some_and(|group| {
        group.iter().enumerate().any(|(k, o)| {
            if g0 + k == i {
                return false;
            }
            let [a, b, t] = o.tri.map(|j| x[j as usize]);
            let Some(m) = triangle_normal(&a, &b, &t) else {
                return false;
            };
            let crease = m.dot(n).abs() < CREASE_COS;
            let dm = (xp - a).dot(&m);
            crease
                && dm >= -thickness
                && dm > d
                && plane_barycentric(&xp, &a, &b, &t, &m)
                    .iter()
                    .all(|&v| v >= -PRISM_TOLERANCE)
        })
    })
}

/// `true` when the particle, moving from its substep start towards the triangle's plane
/// (`d_prev` → `d`), crossed the plane inside the triangle (both linearly interpolated).
fn crossed_inside(c: &Candidate, d: f32, x: &[Vector3<f32>], x_prev: &[Vector3<f32>]) -> bool {
    if c.d_prev.is_nan() || c.d_prev <= d || c.d_prev < 0.0 {
        return false;
    }
    let s = (c.d_prev / (c.d_prev - d)).clamp(0.0, 1.0);
    let lerp = |i: u32| x_prev[i as usize] + (x[i as usize] - x_prev[i as usize]) * s;
    let [a, b, t] = c.tri.map(lerp);
    let p = lerp(c.p);
    match triangle_normal(&a, &b, &t) {
        Some(n) => plane_barycentric(&p, &a, &b, &t, &n)
            .iter()
            .all(|&v| v >= -PRISM_TOLERANCE),
        None => false,
    }
}

/// The height a contact pushes its particle to in this substep: the thickness `δ`, reached
/// from the substep-start distance `d_prev` at no more than `S h` while below the surface
/// and no more than `S_skin h` inside the skin `[0, δ)`.
#[inline]
fn contact_target(d_prev: f32, thickness: f32, step: f32, skin_step: f32) -> f32 {
    let out_of_depth = (d_prev + step).min(0.0);
    let through_skin = (d_prev + skin_step).min(thickness);
    out_of_depth.max(through_skin)
}

/// A particle (first side) against its triangle's point at barycentrics `bary` (second
/// side), for friction; `wsum` is the contact's `w_p + Σ β² w` from its projection.
struct ParticleOnTriangle<'s> {
    x: &'s mut [Vector3<f32>],
    x_prev: &'s [Vector3<f32>],
    /// Inverse masses `[w_p, w_a, w_b, w_c]`, 1/kg.
    w: [f32; 4],
    p: usize,
    tri: [usize; 3],
    bary: [f32; 3],
    wsum: f32,
}

impl ContactStencil for ParticleOnTriangle<'_> {
    fn relative_motion(&self) -> Vector3<f32> {
        let (x, x_prev, tri, bary) = (&*self.x, self.x_prev, self.tri, self.bary);
        let dq: Vector3<f32> = (0..3).map(|k| (x[tri[k]] - x_prev[tri[k]]) * bary[k]).sum();
        (x[self.p] - x_prev[self.p]) - dq
    }

    fn inv_mass(&self, _t: &Vector3<f32>) -> f32 {
        self.wsum
    }

    fn apply(&mut self, t: &Vector3<f32>, dl: f32) {
        let (w, tri) = (self.w, self.tri);
        self.x[self.p] -= t * (w[0] * dl);
        for k in 0..3 {
            self.x[tri[k]] += t * (w[k + 1] * self.bary[k] * dl);
        }
    }
}

/// Coulomb friction of one contact just projected ([`crate::response::friction`]).
fn friction(c: &mut Candidate, x: &mut [Vector3<f32>], x_prev: &[Vector3<f32>]) {
    let mut stencil = ParticleOnTriangle {
        x,
        x_prev,
        w: c.weights,
        p: c.p as usize,
        tri: c.tri.map(|i| i as usize),
        bary: c.bary,
        wsum: c.wsum,
    };
    let coulomb = Coulomb {
        lambda_n: c.lambda_n,
        mu_s: c.props.mu_s,
        mu_d: c.props.mu_d,
    };
    positional_friction(&mut stencil, &c.n, coulomb, &mut c.lambda_t);
}

#[cfg(test)]
mod tests {
    use super::contact_target;

    #[test]
    fn target_rates() {
        let (d, s, k) = (0.005, 0.002, 0.0001);
        // Resting or arriving from outside: straight to the thickness.
        assert_eq!(contact_target(0.005, d, s, k), 0.005);
        assert_eq!(contact_target(0.3, d, s, k), 0.005);
        // Deep: out at S h per substep.
        assert!((contact_target(-0.1, d, s, k) - (-0.098)).abs() < 1e-7);
        // Just below the surface: to the surface, not further than the skin rate.
        assert!((contact_target(-0.001, d, s, k) - 0.0).abs() < 1e-7);
        // In the skin: creeps at S_skin h.
        assert!((contact_target(0.002, d, s, k) - 0.0021).abs() < 1e-7);
    }
}
