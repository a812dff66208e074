//! [`Untangle`]: a body that came to rest tangled is pulled back to its rest shape.
//!
//! # Why tangled bodies stay tangled
//!
//! A body released from a scrambled, collapsed or mirrored start may come to rest in a fold:
//! a local minimum of its elastic energy where compliant constraints (or the Neo-Hookean
//! material) balance each other, with tetrahedra inverted or the volume percents off, and
//! energy stored that nothing outside holds. Hard constraints fight their way out (every
//! violation is removed at once); compliant ones only feel the local gradient, and a local
//! minimum has none. More substeps make it worse (stiffer per substep, calmer faster).
//!
//! # The rule
//!
//! A body is **tangled** when it is calm and yet
//!
//! * a tetrahedron is inverted, or
//! * it stores elastic energy no external load explains: `U > 2 M |g + a| u_max` with
//!   `u_max > 10⁻³ L` — `U` its elastic energy ([`ElasticFamilies`]), `M` its mass,
//!   `g + a` gravity plus its [`crate::ExternalAcceleration`], `u_max` the largest distance of
//!   a particle from its goal below, `L` its rest bounding-box diagonal. A uniform load
//!   stores at most the work it does, `½ Σ fᵢ·uᵢ ≤ M |g| u_max` (supports included, whose
//!   reactions sum to `−Mg`), so a body sagging under its weight is never tangled; without
//!   a load any stored energy is unexplained.
//!
//! **Calm**, over a check window of half the body's time until sleep: no particle moved
//! faster than the body's sleep threshold ([`crate::Activation::linear_threshold`])
//! relative to the centre-of-mass velocity (a tangled body is caught before it falls
//! asleep), or its kinetic energy relative to the centre of mass stayed below 10 % of its
//! elastic energy `U` over that window and the one before (a fold with a slow jiggle left).
//! A body vibrating freely about its rest shape trades all of `U` into kinetic energy every
//! period; it can be caught only at a turning point of a vibration whose period exceeds
//! about ten windows (5 s at the default time until sleep), and then the move only releases
//! elastic energy (it damps that vibration). The body is checked once per window, and every
//! frame while it is being moved.
//!
//! A tangled body is moved, at the end of a frame, towards its **goal**: its rest shape
//! under the best-fit rigid transform, `gᵢ = c + R (Xᵢ − X_c)` with `c`, `X_c` the current
//! and rest centres of mass and `R` the rotation of the polar decomposition of
//! `Σ mᵢ (xᵢ − c)(Xᵢ − X_c)ᵀ` (shape matching, Müller et al. 2005): the one shape whose only
//! energy minimum is the rest shape. The move is `xᵢ ← xᵢ + β (gᵢ − xᵢ)` on positions alone
//! (velocities kept), `β = min(1, β₀ 2ᵏ)` after `k` consecutive moves (`β₀ = 1/8`: paced,
//! then escalating until the fold is left, at most four frames from the first move to the
//! goal itself).
//!
//! **Energy.** The move is taken only where it releases elastic energy:
//! `U(x + β(g − x)) ≤ U(x)`; otherwise `β` doubles until it does, which it does at `β = 1`
//! (the goal stores none). The kinetic energy is unchanged (velocities kept), so the body's
//! mechanical energy never grows. Linear momentum is kept (the goal keeps the centre of
//! mass; velocities untouched). A body that moved restarts its sleep timer.
//!
//! **Scope.** Free bodies of an uncoupled world: not with a hook that moves particles (a
//! coupling's contacts are loads the core does not see: a heavy box on a soft slab stores
//! energy the slab's weight does not explain), not with a pinned particle, a
//! [`crate::Grab`], [`crate::UserForces`], [`crate::Plasticity`] (its rest shape flows) or
//! [`crate::Tearing`] (torn pieces have no common rest shape); not asleep.
//!
//! # Bodies a hook touches
//!
//! A coupled body lies on the ground, on rigid bodies, on other soft bodies: loads the core
//! does not see. [`crate::systems::untangle_touched_bodies`], run by the integrator after the
//! step, treats such bodies with two changes to the rule above:
//!
//! * only an **inverted tetrahedron** makes a calm body tangled (stored energy proves nothing
//!   when the loads are unknown: a soft slab under a heavy box stores what its own weight does
//!   not explain);
//! * the goal is **lifted** along `−(g + a)` until no particle of it is lower than the body's
//!   lowest particle now, since what holds the body up lies below that point (a goal that
//!   reaches into the ground would be pushed out again by the contacts). The lift's work
//!   against the load,
//!   `M |g + a| s` for a lift `s`, is charged to the move: `U(x') + β M |g + a| s ≤ U(x)`;
//!   where not even the goal pays for it the body stays as it is.
//!
//! Particles a hook holds at points the core does not see (a coupling's attachments) stay
//! where they are held: the goal is fitted to them (each weighted 10⁶ times its mass), and a
//! move that would carry one off by more than 10⁻³ of the body's size is not made. A
//! [`crate::Tearing`] body whose pieces stay one entity ([`crate::Pieces::KeepOne`]) is left
//! alone (no one rest shape); a torn body's pieces split into entities each have theirs.

use hecs::World;
use nalgebra::{Matrix3, Vector3};

use crate::body::activation::{Activation, Asleep};
use crate::body::elastic_energy::ElasticFamilies;
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::{ExternalAcceleration, Particles};

/// The first move's fraction of the way to the goal.
const FIRST_STEP: f32 = 0.125;
/// The largest kinetic energy, as a fraction of the stored elastic energy, over the last two
/// check windows of a calm body that moves faster than the sleep threshold.
const KINETIC_FRACTION: f64 = 0.1;
/// The smallest distance from the goal, as a fraction of the rest bounding-box diagonal, at
/// which stored energy counts as a tangle.
const DISTANCE_FLOOR: f32 = 1e-3;
/// How much more than its mass a held particle weighs in the fit of a held body's goal.
const HELD_WEIGHT: f64 = 1e6;
/// How far a move may carry a held particle, as a fraction of the rest bounding-box diagonal.
const HELD_TOLERANCE: f32 = 1e-3;

/// A body's tangle recovery (a hecs component, spawned with every body by
/// [`crate::SoftBody::spawn`]; a body without it is never untangled). Rule in the module
/// docs.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Untangle {
    /// `true`: the body is never untangled.
    pub disabled: bool,
    window: f32,
    slow: bool,
    kinetic_peak: f64,
    kinetic_before: f64,
    moves: u32,
    /// Scratch: the goal and a trial move (filled only when the body is tangled: its first
    /// move allocates them, once).
    #[cfg_attr(feature = "serde", serde(skip))]
    goals: Vec<Vector3<f32>>,
    #[cfg_attr(feature = "serde", serde(skip))]
    trial: Vec<Vector3<f32>>,
}

impl Default for Untangle {
    fn default() -> Self {
        Untangle {
            disabled: false,
            window: 0.0,
            slow: true,
            kinetic_peak: 0.0,
            kinetic_before: 0.0,
            moves: 0,
            goals: Vec::new(),
            trial: Vec::new(),
        }
    }
}

impl PartialEq for Untangle {
    fn eq(&self, o: &Untangle) -> bool {
        // Every field but the scratch, which is neither state nor serialized.
        self.disabled == o.disabled
            && self.window == o.window
            && self.slow == o.slow
            && self.kinetic_peak == o.kinetic_peak
            && self.kinetic_before == o.kinetic_before
            && self.moves == o.moves
    }
}

/// How calm a body was over the window since its last check.
#[derive(Clone, Copy)]
struct Calm {
    /// No particle faster than the sleep threshold relative to the centre of mass.
    slow: bool,
    /// The largest kinetic energy relative to the centre of mass over this window and the
    /// one before, J.
    kinetic_peak: f64,
}

impl Calm {
    /// Calm: slow, or moving with at most [`KINETIC_FRACTION`] of the stored energy `u` (J).
    fn holds(&self, u: f64) -> bool {
        self.slow || self.kinetic_peak < KINETIC_FRACTION * u
    }
}

impl Untangle {
    /// Consecutive frames the body has been moved towards its goal (0: not tangled).
    pub fn moves(&self) -> u32 {
        self.moves
    }

    /// The same settings from a fresh state (a piece of a torn body: the body's windows and
    /// moves describe a shape that no longer exists).
    pub(crate) fn restarted(&self) -> Untangle {
        Untangle {
            disabled: self.disabled,
            ..Untangle::default()
        }
    }
}

/// Moves every tangled body towards its goal (module docs) at the end of a frame of length
/// `dt` (s) under `gravity` (m/s²). Returns the bodies moved.
pub(crate) fn untangle_bodies(world: &mut World, dt: f32, gravity: Vector3<f32>) -> usize {
    let mut moved = 0;
    let query = world
        .query_mut::<(
            &mut Particles,
            &Tetrahedra,
            &mut Untangle,
            Option<&mut Activation>,
            Option<&ExternalAcceleration>,
            Families,
        )>()
        .without::<&Asleep>()
        .without::<&crate::Grab>()
        .without::<&crate::UserForces>()
        .without::<&crate::Plasticity>()
        .without::<&crate::Tearing>();
    for (p, t, u, act, accel, families) in query {
        let body = Body {
            p,
            t,
            u,
            act,
            accel,
            families,
        };
        moved += usize::from(body.untangle(dt, gravity, Reach::Free));
    }
    moved
}

/// Moves every tangled body a hook's contacts may touch towards its goal, lifted so that no
/// particle ends lower (along `gravity`) than the body's lowest one now (module docs, "Bodies
/// a hook touches"), at the end of a frame of length `dt` (s) under `gravity` (m/s²). `held`
/// (sorted) lists the `(body, particle)` pairs a hook holds at points the core does not see
/// (a coupling's attachments): the goal is fitted to them, and a move that would carry one of
/// them off its place is not made. Returns the bodies moved.
pub(crate) fn untangle_touched_bodies(
    world: &mut World,
    dt: f32,
    gravity: Vector3<f32>,
    held: &[(hecs::Entity, u32)],
) -> usize {
    let mut moved = 0;
    let query = world
        .query_mut::<(
            hecs::Entity,
            (&mut Particles, &Tetrahedra, &mut Untangle),
            Option<&mut Activation>,
            Option<&ExternalAcceleration>,
            Families,
            Option<&crate::Tearing>,
        )>()
        .without::<&Asleep>()
        .without::<&crate::Grab>()
        .without::<&crate::UserForces>()
        .without::<&crate::Plasticity>();
    for (e, (p, t, u), act, accel, families, tearing) in query {
        // One entity holding several pieces has no one rest shape to fit.
        let one_piece = tearing.is_none_or(|t| t.settings().pieces == crate::Pieces::Split);
        if !one_piece {
            continue;
        }
        let from = held.partition_point(|&(b, _)| b < e);
        let to = held.partition_point(|&(b, _)| b <= e);
        let body = Body {
            p,
            t,
            u,
            act,
            accel,
            families,
        };
        moved += usize::from(body.untangle(dt, gravity, Reach::Touched(&held[from..to])));
    }
    moved
}

/// The families a body's elastic energy comes from.
type Families<'a> = (
    Option<&'a EdgeConstraints>,
    Option<&'a VolumeConstraints>,
    Option<&'a VertexFaceConstraints>,
    Option<&'a NeoHookeanMaterial>,
);

/// Which bodies a pass moves: free ones (no hook moves particles), or ones a hook's
/// contacts may touch, whose loads the core does not see.
#[derive(Clone, Copy, Debug)]
enum Reach<'a> {
    Free,
    /// With the `(body, particle)` pairs the hook holds.
    Touched(&'a [(hecs::Entity, u32)]),
}

/// One body's part in a pass.
struct Body<'a> {
    p: &'a mut Particles,
    t: &'a Tetrahedra,
    u: &'a mut Untangle,
    act: Option<&'a mut Activation>,
    accel: Option<&'a ExternalAcceleration>,
    families: Families<'a>,
}

impl Body<'_> {
    /// Watches the body over its window and moves it if it is tangled; returns whether it
    /// moved.
    fn untangle(self, dt: f32, gravity: Vector3<f32>, reach: Reach<'_>) -> bool {
        let Body {
            p,
            t,
            u,
            act,
            accel,
            families: (edges, volume, vertex_face, material),
        } = self;
        if u.disabled || p.inv_masses.iter().any(|&w| w <= 0.0) {
            return false;
        }
        let (threshold, calm_after) = act.as_ref().map_or(
            (
                Activation::DEFAULT_LINEAR_THRESHOLD,
                Activation::DEFAULT_TIME_UNTIL_SLEEP,
            ),
            |a| (a.linear_threshold, a.time_until_sleep),
        );
        let (speed, kinetic) = internal_motion(p);
        u.window += dt;
        u.slow &= speed < threshold;
        u.kinetic_peak = u.kinetic_peak.max(kinetic);
        if u.moves == 0 && u.window < 0.5 * calm_after {
            return false;
        }
        let calm = Calm {
            slow: u.slow,
            kinetic_peak: u.kinetic_peak.max(u.kinetic_before),
        };
        u.kinetic_before = u.kinetic_peak;
        (u.window, u.slow, u.kinetic_peak) = (0.0, true, 0.0);
        let families = ElasticFamilies {
            edges,
            volume,
            vertex_face,
            material,
        };
        let load = gravity + accel.map_or(Vector3::zeros(), |a| a.0);
        if !move_if_tangled(p, t, u, &families, load, calm, reach) {
            u.moves = 0;
            return false;
        }
        if let Some(a) = act {
            a.restart();
        }
        true
    }
}

/// The largest particle speed (m/s) and the kinetic energy (J) relative to the
/// centre-of-mass velocity.
fn internal_motion(p: &Particles) -> (f32, f64) {
    let m: f32 = p.masses.iter().sum();
    if m <= 0.0 {
        return (0.0, 0.0);
    }
    let vc = p
        .velocities
        .iter()
        .zip(&p.masses)
        .fold(Vector3::zeros(), |s, (v, &mi)| s + v * mi)
        / m;
    let (mut fastest, mut kinetic) = (0.0f32, 0.0f64);
    for (v, &mi) in p.velocities.iter().zip(&p.masses) {
        let s = (v - vc).norm_squared();
        fastest = fastest.max(s);
        kinetic += 0.5 * f64::from(mi) * f64::from(s);
    }
    (fastest.sqrt(), kinetic)
}

/// Checks whether the calm body `p` is tangled and, if so, moves it towards its goal
/// (module docs); `load` is `g + a` (m/s²). Returns whether it moved.
fn move_if_tangled(
    p: &mut Particles,
    t: &Tetrahedra,
    u: &mut Untangle,
    families: &ElasticFamilies<'_>,
    load: Vector3<f32>,
    calm: Calm,
    reach: Reach<'_>,
) -> bool {
    // Only inverted tetrahedra tell a touched body tangled: none, no fit. (A free body's
    // are counted below, only when its stored energy does not already say so.)
    let (held, free) = match reach {
        Reach::Free => (&[][..], true),
        Reach::Touched(_) if t.count_inverted(&p.positions) == 0 => return false,
        Reach::Touched(h) => (h, false),
    };
    let Some((c, xc, r)) = best_fit(p, held) else {
        return false;
    };
    let goal = |x: &Vector3<f32>| (c + r * (x.cast::<f64>() - xc)).cast::<f32>();
    let u_max = p
        .rest_positions
        .iter()
        .zip(&p.positions)
        .map(|(r, x)| (goal(r) - x).norm())
        .fold(0.0f32, f32::max);
    let (lo, hi) = p.rest_positions.iter().fold(
        (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN)),
        |(lo, hi), x| (lo.inf(x), hi.sup(x)),
    );
    let size = (hi - lo).norm();
    let mass: f64 = p.masses.iter().map(|&m| f64::from(m)).sum();
    let energy = families.energy(t, &p.positions);
    // A hook's loads are not known here: only inverted tetrahedra say a touched body is
    // tangled.
    let unexplained = free
        && u_max > DISTANCE_FLOOR * size
        && energy > 2.0 * mass * f64::from(load.norm()) * f64::from(u_max);
    let inverted = || !free || t.count_inverted(&p.positions) > 0;
    if !calm.holds(energy) || (!unexplained && !inverted()) {
        return false;
    }
    // Only a tangled body fills the scratch: ordinary frames allocate nothing.
    u.goals.clear();
    u.goals.extend(p.rest_positions.iter().map(goal));
    // A touched body's goal is lifted against the load until no particle of it is lower than
    // the body's lowest now: what holds the body up is below that point. The lift's work
    // against the load is paid from the elastic energy the move releases.
    let mut lift_work = 0.0f64;
    if !free && load.norm() > 0.0 {
        let down = load.normalize();
        let lowest = |xs: &[Vector3<f32>]| xs.iter().map(|x| x.dot(&down)).fold(f32::MIN, f32::max);
        let sink = lowest(&u.goals) - lowest(&p.positions);
        if sink > 0.0 {
            for g in &mut u.goals {
                *g -= down * sink;
            }
            lift_work = mass * f64::from(load.norm()) * f64::from(sink);
        }
    }
    let mut beta = (FIRST_STEP * 2f32.powi(u.moves.min(8) as i32)).min(1.0);
    loop {
        u.trial.clear();
        u.trial.extend(
            p.positions
                .iter()
                .zip(&u.goals)
                .map(|(x, g)| x + (g - x) * beta),
        );
        // The goal itself stores no elastic energy: a free body always reaches it.
        if beta >= 1.0 && free {
            break;
        }
        let cost = families.energy(t, &u.trial) + f64::from(beta) * lift_work;
        if cost <= energy {
            break;
        }
        if beta >= 1.0 {
            // Not even the goal releases what the lift costs: stay.
            return false;
        }
        beta = (2.0 * beta).min(1.0);
    }
    let to = if beta >= 1.0 { &u.goals } else { &u.trial };
    // A held particle stays where the hook holds it.
    let off = held
        .iter()
        .filter_map(|&(_, i)| Some((to.get(i as usize)? - p.positions[i as usize]).norm()))
        .fold(0.0f32, f32::max);
    if off > HELD_TOLERANCE * size {
        return false;
    }
    p.positions.copy_from_slice(to);
    u.moves += 1;
    true
}

/// The best-fit rigid transform of the rest shape onto the current positions: current and
/// rest centres of mass and the rotation (polar decomposition by SVD, reflection removed).
/// With `held` particles (`(body, particle)` pairs of this body) the fit is theirs, each
/// weighted [`HELD_WEIGHT`] times its mass: a goal that keeps them where they are held.
fn best_fit(
    p: &Particles,
    held: &[(hecs::Entity, u32)],
) -> Option<(Vector3<f64>, Vector3<f64>, Matrix3<f64>)> {
    let w = |i: usize| {
        let m = f64::from(p.masses[i]);
        // `held` is one body's pairs, sorted: by particle.
        if held.binary_search_by_key(&(i as u32), |&(_, k)| k).is_ok() {
            HELD_WEIGHT * m
        } else {
            m
        }
    };
    let mass: f64 = (0..p.len()).map(w).sum();
    if mass <= 0.0 {
        return None;
    }
    let (mut c, mut xc) = (Vector3::zeros(), Vector3::zeros());
    for (i, (x, r)) in p.positions.iter().zip(&p.rest_positions).enumerate() {
        c += x.cast::<f64>() * w(i);
        xc += r.cast::<f64>() * w(i);
    }
    c /= mass;
    xc /= mass;
    let mut a = Matrix3::zeros();
    for (i, (x, r)) in p.positions.iter().zip(&p.rest_positions).enumerate() {
        a += (x.cast::<f64>() - c) * (r.cast::<f64>() - xc).transpose() * w(i);
    }
    let svd = a.svd(true, true);
    let (mut uu, vt) = (svd.u?, svd.v_t?);
    if (uu * vt).determinant() < 0.0 {
        let k = svd.singular_values.imin();
        uu.column_mut(k).neg_mut();
    }
    let r = uu * vt;
    r.iter().all(|v| v.is_finite()).then_some((c, xc, r))
}
