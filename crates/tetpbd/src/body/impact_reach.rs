//! Contacts deeper than a soft surface can take within a substep meet the whole soft body.
//!
//! A contact — a collider, a ground plane, a rigid body, written as a [`crate::SubstepHook`]
//! — is projected locally: the particle that went through is put back on the surface, the
//! correction shared with the other side by inverse masses. That holds for any contact a
//! substep can resolve and fails for fast impacts, where one substep carries particles a cell
//! or more into the other side:
//!
//! * a soft cube falling at 100–300 m/s onto the ground arrives a body size or more below it
//!   within a substep (at 1 substep of 1/60 s, 300 m/s is 5 m). Putting every particle back on
//!   the plane flattens the body and turns half its tetrahedra inside out; the next substeps
//!   cannot tell which side each one came from. Measured on the stability matrix's impact rows
//!   (0.5 m cube of 4³ cells, both grid splits, 1–80 substeps, every family): 64 of 192 cells
//!   ended crushed (up to 194 of 384 tetrahedra inverted, volume 100 % off) and 34 more were
//!   vertex–face-alone bodies left misshapen;
//! * its surface particles stopped at the collider while the particles behind them (one
//!   Gauss–Seidel projection away) kept going and passed through the body's own bottom;
//! * a rigid ball at 200 m/s pushed the triangle it hit 10 cm into a 20 cm slab in one
//!   substep: deeper than half a triangle behind the surface a rigid point is *inside* the soft
//!   body, where no contact sees it, and it crossed the slab (the rapier coupling's case).
//!
//! So a contact resolves at most the body's *local reach* ([`LOCAL_REACH`] of the mean rest
//! length of its surface edges) locally within a projection. The depth beyond it is taken by
//! the whole soft body moving as one: its free particles translated together (inverse mass
//! `1/M` of the free mass, [`Particles::rigid_inv_mass`]) against the other side's inverse
//! mass along the contact normal. The impact is perfectly inelastic at the level it happens
//! on, momentum kept exactly, and the body passes the momentum on through its own contacts.
//! A body with a pinned particle does not move (`1/M = 0`). Contacts within the reach,
//! resting and sliding ones included, are unchanged; what a fast impact loses is a dent deeper
//! than a quarter of a cell.
//!
//! With it the impact rows end intact (0 inverted, volume within 1 % of the body set down at
//! rest) in every cell of the edges + volume (hard), vertex–face and vertex–face + edges
//! columns, the vertex–face-alone bodies included (`cargo run --release -p tetpbd-stability
//! --bin stability -- --case "m/s, " --no-coupled --out /tmp/impacts.md`). The reach was
//! chosen there: an eighth of a cell leaves one more cell crushed, half a cell 12 more,
//! a whole cell 35 more. `tetpbd-rapier` applies the same rule to every particle and rigid-point
//! contact: 1 kg balls and boxes at 50–300 m/s onto soft slabs of 1–4 cells stay on the slab and
//! leave slower than they came, soft cubes at 50–300 m/s onto the ground, a plate or a box stop
//! on it (its `tests/projectiles.rs`).
//!
//! # Using it in a contact hook
//!
//! ```
//! use tetpbd::nalgebra::Vector3;
//! use tetpbd::{ImpactReach, Particles, Surface};
//!
//! /// Puts the particles below the immovable plane y = 0 back on it.
//! fn ground(p: &mut Particles, surface: &Surface) {
//!     let mut impact = ImpactReach::of(p, surface);
//!     for i in 0..p.len() {
//!         let depth = -p.positions()[i].y;
//!         impact.push_out(p, i, depth, &Vector3::y());
//!     }
//! }
//! ```
//!
//! Against something that moves, [`ImpactReach::take_excess`] returns the multiplier the
//! other side takes, as `tetpbd-rapier`'s contacts use it.
//!
//! The reach bounds how deep a particle goes, not how fast the body behind a stopped surface
//! keeps coming: a compliant body at short substeps runs through its own stopped surface
//! layer. Against something immovable, [`ImpactReach::limit_approach`] takes the whole
//! body's approach beyond what its constraints carry within a substep
//! ([`crate::impact_speed`]) before the particles are pushed out (the stability matrix's
//! ground does); [`ImpactReach::limit_relative_approach`] against something immovable
//! that itself moves, after the contacts are projected (`tetpbd-rapier` does, along the
//! mean normal of a body's contacts with fixed, kinematic and supported bodies).

use nalgebra::Vector3;

use crate::body::mesh::Surface;
use crate::body::particles::Particles;

/// Share of the mean rest length of a body's surface edges that a contact resolves locally
/// within a projection (dimensionless); the rest of a deeper contact meets the whole body.
/// A quarter of a cell keeps the inner particles of a fast soft body behind its stopped
/// surface (module docs).
pub const LOCAL_REACH: f32 = 0.25;

/// How deep a contact the surface of `p` takes locally within a substep, m: [`LOCAL_REACH`]
/// times the mean rest length of its surface edges (each triangle's three edges; shared edges
/// counted twice, which leaves the mean unchanged on a closed surface). `f32::INFINITY` for a
/// body without surface triangles or with a triangle indexing past its particles.
pub fn local_reach(p: &Particles, surface: &Surface) -> f32 {
    let rest = p.rest_positions();
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for t in surface.triangles() {
        let Some([a, b, c]) = corners(rest, t) else {
            return f32::INFINITY;
        };
        sum += f64::from((b - a).norm() + (c - b).norm() + (a - c).norm());
        n += 3;
    }
    if n == 0 {
        return f32::INFINITY;
    }
    let reach = LOCAL_REACH * (sum / n as f64) as f32;
    if reach.is_finite() && reach > 0.0 {
        reach
    } else {
        f32::INFINITY
    }
}

fn corners(rest: &[Vector3<f32>], t: &[u32; 3]) -> Option<[Vector3<f32>; 3]> {
    let get = |i: u32| rest.get(i as usize).copied();
    Some([get(t[0])?, get(t[1])?, get(t[2])?])
}

/// The whole-body part of one soft body's contacts in one projection sweep: its local reach
/// and, once needed, its inverse free mass (module docs).
#[derive(Clone, Copy, Debug)]
pub struct ImpactReach {
    reach: f32,
    inv_mass: Option<f32>,
}

impl ImpactReach {
    /// A sweep over a body whose surface takes `reach` (m) locally ([`local_reach`];
    /// `f32::INFINITY`: never the whole body).
    pub fn new(reach: f32) -> Self {
        ImpactReach {
            reach,
            inv_mass: None,
        }
    }

    /// A sweep over the body `p` with surface `surface`: [`Self::new`] of [`local_reach`].
    pub fn of(p: &Particles, surface: &Surface) -> Self {
        Self::new(local_reach(p, surface))
    }

    /// The depth a contact resolves locally, m.
    pub fn reach(&self) -> f32 {
        self.reach
    }

    /// For a violated contact `c_val < 0` (m) whose other side has the generalized inverse
    /// mass `w_other` (1/kg) along it (0 for something immovable): moves the whole soft body
    /// along the unit direction `soft_dir` by its share of the depth beyond the reach and
    /// returns the multiplier `Δλ` (kg·m; the other side gets `−soft_dir·Δλ`) and the depth so
    /// resolved (m); `None` when the contact is within reach or nothing can move.
    pub fn take_excess(
        &mut self,
        p: &mut Particles,
        c_val: f32,
        w_other: f32,
        soft_dir: &Vector3<f32>,
    ) -> Option<(f32, f32)> {
        let excess = -c_val - self.reach;
        if excess.is_nan() || excess <= 0.0 {
            return None;
        }
        let w_soft = *self.inv_mass.get_or_insert_with(|| p.rigid_inv_mass());
        let dl = excess / (w_soft + w_other);
        if !(dl.is_finite() && dl > 0.0) {
            return None;
        }
        translate_free(p, &(soft_dir * (w_soft * dl)));
        Some((dl, excess))
    }

    /// Resolves particle `i` lying `depth` (m) inside something immovable, to be pushed out
    /// along the unit direction `dir`: the depth beyond the reach moves the whole body
    /// ([`Self::take_excess`]), the rest moves the particle alone. Nothing for `depth ≤ 0`, a
    /// pinned particle or an index out of range; the whole-body part only where the body can
    /// move.
    pub fn push_out(&mut self, p: &mut Particles, i: usize, depth: f32, dir: &Vector3<f32>) {
        if depth.is_nan() || depth <= 0.0 || p.inv_masses().get(i).is_none_or(|&w| w <= 0.0) {
            return;
        }
        let taken = self
            .take_excess(p, -depth, 0.0, dir)
            .map_or(0.0, |(_, excess)| excess);
        p.positions_mut()[i] += dir * (depth - taken);
    }

    /// For a body in contact with something immovable that pushes its particles out along
    /// the unit direction `dir`: if the centre of mass of its free particles moved against
    /// `dir` by more than `limit` (m) since the substep began (its previous positions), the
    /// whole body is moved back along `dir` by the excess, which takes the excess off its
    /// approach speed ([`crate::impact_speed`]: `limit` from
    /// [`crate::impact_speed::approach_limit`]). Returns the distance moved, m; 0 when the
    /// body approaches slower, cannot move, or `limit` is not a finite non-negative length.
    pub fn limit_approach(&mut self, p: &mut Particles, dir: &Vector3<f32>, limit: f32) -> f32 {
        self.limit_relative_approach(p, dir, 0.0, limit)
    }

    /// [`Self::limit_approach`] against something immovable by the body that itself moved
    /// `toward` (m) against `dir`, towards the body, since the substep began (a kinematic
    /// collider): the approach is the body's step along `−dir` plus `toward`. The whole body
    /// may then be moved along `dir` farther than it came (it is carried along). 0 when
    /// `toward` is not finite.
    pub fn limit_relative_approach(
        &mut self,
        p: &mut Particles,
        dir: &Vector3<f32>,
        toward: f32,
        limit: f32,
    ) -> f32 {
        if !(limit.is_finite() && limit >= 0.0 && toward.is_finite()) {
            return 0.0;
        }
        let (mut step, mut mass) = (Vector3::zeros(), 0.0f32);
        for i in 0..p.len() {
            if p.inv_masses()[i] > 0.0 {
                let m = p.masses()[i];
                step += (p.positions()[i] - p.prev_positions()[i]) * m;
                mass += m;
            }
        }
        if mass <= 0.0 {
            return 0.0;
        }
        let excess = -step.dot(dir) / mass + toward - limit;
        if !(excess.is_finite() && excess > 0.0) {
            return 0.0;
        }
        translate_free(p, &(dir * excess));
        excess
    }
}

/// Moves every free particle by `dx`, m.
fn translate_free(p: &mut Particles, dx: &Vector3<f32>) {
    if *dx == Vector3::zeros() || !dx.iter().all(|c| c.is_finite()) {
        return;
    }
    for i in 0..p.len() {
        if p.inv_masses()[i] > 0.0 {
            p.positions_mut()[i] += dx;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generators::{box_grid, CellSplit};
    use crate::SoftBodyBuilder;

    fn cube(size: f32) -> (Particles, Surface) {
        let mesh = box_grid(Vector3::repeat(size), [4; 3], CellSplit::Five).unwrap();
        let body = SoftBodyBuilder::new(mesh).edges(0.0).build().unwrap();
        let mut world = hecs::World::new();
        let e = body.spawn(&mut world);
        let (p, s) = world
            .remove::<(Particles, Surface)>(e)
            .expect("spawned bodies have particles and a surface");
        (p, s)
    }

    #[test]
    fn reach_is_a_quarter_of_the_mean_surface_edge_at_every_size() {
        for size in [0.01f32, 0.5, 40.0] {
            let (p, s) = cube(size);
            let reach = local_reach(&p, &s);
            let cell = size / 4.0;
            // Surface edges of a Five-split grid: cell edges and face diagonals.
            assert!(
                reach > LOCAL_REACH * cell && reach < LOCAL_REACH * cell * 2f32.sqrt(),
                "size {size}: reach {reach}"
            );
        }
    }

    #[test]
    fn excess_beyond_the_reach_moves_the_whole_body_and_keeps_momentum_with_the_other_side() {
        let (mut p, s) = cube(0.5);
        let mut impact = ImpactReach::of(&p, &s);
        let before: Vec<_> = p.positions().to_vec();
        let depth = impact.reach() + 0.1;
        let w_other = 0.02;
        let (dl, taken) = impact
            .take_excess(&mut p, -depth, w_other, &Vector3::y())
            .expect("deeper than the reach");
        assert!((taken - 0.1).abs() < 1e-6);
        let m = p.total_mass();
        let shift = p.positions()[0].y - before[0].y;
        // The body moved by its share, the other side by its own: together the excess.
        assert!((shift + w_other * dl - 0.1).abs() < 1e-5, "shift {shift}");
        // Equal and opposite position impulses: M·shift = Δλ.
        assert!(
            (m * shift - dl).abs() < 1e-3 * dl,
            "M shift {} vs {dl}",
            m * shift
        );
        for (a, b) in p.positions().iter().zip(&before) {
            assert!(((a - b) - Vector3::y() * shift).norm() < 1e-6);
        }
        assert!(impact
            .take_excess(&mut p, -0.5 * impact.reach(), 0.0, &Vector3::y())
            .is_none());
    }

    #[test]
    fn a_deep_particle_is_pushed_out_and_the_body_keeps_its_shape_beyond_the_reach() {
        let (mut p, s) = cube(0.5);
        let mut impact = ImpactReach::of(&p, &s);
        let reach = impact.reach();
        let before: Vec<_> = p.positions().to_vec();
        // Particle 0 is 1 m below where it may be: it ends there, the others 1 m − reach up.
        impact.push_out(&mut p, 0, 1.0, &Vector3::y());
        assert!((p.positions()[0].y - (before[0].y + 1.0)).abs() < 1e-5);
        for (i, (x, x0)) in p.positions().iter().zip(&before).enumerate().skip(1) {
            let dy = x.y - x0.y;
            assert!((dy - (1.0 - reach)).abs() < 1e-5, "particle {i}: {dy}");
        }
        // Within the reach only the particle moves.
        let before: Vec<_> = p.positions().to_vec();
        impact.push_out(&mut p, 3, 0.5 * reach, &Vector3::y());
        for (i, (x, x0)) in p.positions().iter().zip(&before).enumerate() {
            let expected = if i == 3 { 0.5 * reach } else { 0.0 };
            assert!((x.y - x0.y - expected).abs() < 1e-6);
        }
    }

    #[test]
    fn a_body_approaching_faster_than_the_limit_is_moved_back_by_the_excess_only() {
        for (step, limit) in [(0.5f32, 0.01f32), (0.06, 0.03), (0.02, 0.03), (0.01, 0.0)] {
            let (mut p, s) = cube(0.5);
            let mut impact = ImpactReach::of(&p, &s);
            // The body moved `step` down this substep, one particle twice as far.
            for i in 0..p.len() {
                p.positions_mut()[i].y -= if i == 7 { 2.0 * step } else { step };
            }
            let before: Vec<_> = p.positions().to_vec();
            let m = p.total_mass();
            let approach = |p: &Particles| {
                let d: f32 = (0..p.len())
                    .map(|i| (p.prev_positions()[i].y - p.positions()[i].y) * p.masses()[i])
                    .sum();
                d / m
            };
            let came = approach(&p);
            let moved = impact.limit_approach(&mut p, &Vector3::y(), limit);
            let expected = (came - limit).max(0.0);
            assert!(
                (moved - expected).abs() < 1e-5,
                "step {step}: moved {moved}"
            );
            // Rigidly: every particle by the same distance, the shape untouched.
            for (x, b) in p.positions().iter().zip(&before) {
                assert!(((x - b) - Vector3::y() * moved).norm() < 1e-5);
            }
            assert!(approach(&p) <= limit + 1e-5 || moved == 0.0);
        }
    }

    #[test]
    fn something_immovable_coming_at_the_body_counts_in_its_approach() {
        for (step, toward, limit) in [
            (0.0f32, 0.05f32, 0.01f32),
            (0.02, 0.03, 0.01),
            (0.0, 0.005, 0.01),
        ] {
            let (mut p, s) = cube(0.5);
            let mut impact = ImpactReach::of(&p, &s);
            for i in 0..p.len() {
                p.positions_mut()[i].y -= step;
            }
            let moved = impact.limit_relative_approach(&mut p, &Vector3::y(), toward, limit);
            let expected = (step + toward - limit).max(0.0);
            assert!(
                (moved - expected).abs() < 1e-5,
                "{step} {toward}: moved {moved}"
            );
        }
        let (mut p, s) = cube(0.5);
        let mut impact = ImpactReach::of(&p, &s);
        assert_eq!(
            impact.limit_relative_approach(&mut p, &Vector3::y(), f32::NAN, 0.0),
            0.0
        );
    }

    #[test]
    fn the_approach_limit_moves_no_pinned_body_and_takes_no_bad_limit() {
        let (mut p, s) = cube(0.5);
        for i in 0..p.len() {
            p.positions_mut()[i].y -= 0.5;
        }
        let mut impact = ImpactReach::of(&p, &s);
        for limit in [f32::NAN, f32::INFINITY, -1.0] {
            assert_eq!(impact.limit_approach(&mut p, &Vector3::y(), limit), 0.0);
        }
        for i in 0..p.len() {
            p.set_pinned(i, true).unwrap();
        }
        let before: Vec<_> = p.positions().to_vec();
        assert_eq!(impact.limit_approach(&mut p, &Vector3::y(), 0.0), 0.0);
        assert_eq!(p.positions(), &before[..]);
    }

    #[test]
    fn a_pinned_body_is_not_moved_by_an_immovable_contact() {
        let (mut p, s) = cube(0.5);
        p.set_pinned(0, true).unwrap();
        let mut impact = ImpactReach::of(&p, &s);
        let before: Vec<_> = p.positions().to_vec();
        assert!(impact
            .take_excess(&mut p, -1.0, 0.0, &Vector3::y())
            .is_none());
        assert_eq!(p.positions(), &before[..]);
    }

    #[test]
    fn a_surface_indexing_past_the_particles_never_moves_the_whole_body() {
        let (p, _) = cube(0.5);
        let bad = Surface {
            triangles: vec![[0, 1, 100_000]],
            vertices: vec![0, 1, 100_000],
        };
        assert_eq!(local_reach(&p, &bad), f32::INFINITY);
    }
}
