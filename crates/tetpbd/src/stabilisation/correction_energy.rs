//! Keeping the families' corrections from adding kinetic energy
//! ([`crate::SafetySettings::limit_correction_energy`]).
//!
//! A substep turns every position correction into velocity, `vᵢ = (xᵢ − x̄ᵢ)/h`. For a
//! violation the substep's own motion created, that is the constraint's reaction and it only
//! removes kinetic energy: a hard constraint projects the predicted motion back onto the
//! constraint surface, an inelastic projection. A violation that was there *before* the
//! substep (a tangled, inverted or collapsed start, a body crushed flat by a deep impact
//! that the contacts undid in one substep) is different: a hard constraint closes it in one
//! substep, and `C/h` becomes velocity from nothing. On a body whose constraints cannot all
//! be met at once the next substep finds new violation, and the energy never stops coming:
//! a mirrored 1 m cube of hard edges and vertex–faces reached 1.8·10⁷ J from rest, and more
//! substeps (smaller `h`) made it worse.
//!
//! The rule: in one iteration, the families may add to a body's kinetic energy at most the
//! elastic energy their compliant constraints release. Hard constraints (α = 0) store no
//! energy, so a body of hard families never gains kinetic energy from its own constraints;
//! what they correct beyond that stays a position correction (the body recovers its shape)
//! and does not become velocity, as if the part of the correction that removes old
//! violation were projected at the start of the substep with the substep start moved along
//! (pre-stabilisation).
//!
//! With `Δᵢ` the families' corrections in the iteration (after the spin removal, so free of
//! linear and angular momentum) and `vᵢ` the predicted velocities, the kinetic energy they add
//! is
//!
//! ```text
//! ΔK(s) = s A + s² Q,   A = Σ mᵢ vᵢ·Δᵢ / h,   Q = Σ mᵢ|Δᵢ|² / (2h²)
//! ```
//!
//! when a fraction `s` of the corrections becomes velocity. If `ΔK(1)` exceeds the budget
//! `E`, the largest `s ∈ [0, 1]` with `ΔK(s) = E` is kept: the positions keep all of `Δ`,
//! the velocity update sees `sΔ/h` (the rest is taken out of the rounding residual the
//! update adds back, [`crate::systems::add_compensated`]). One scale for the whole field keeps its
//! zero linear momentum, and its zero angular momentum about the substep starts; about the
//! positions the velocity update ends at, the part held back `(1 − s)Δ` carries a little
//! angular momentum, whose rigid fit is given back to a free body
//! ([`crate::stabilisation::give_back`], more passes only in iterations where the limit
//! acts), so the limit never pushes or turns a free body. That pass also measures the
//! velocity change it leaves, exactly, and scales it to the budget where the give-back
//! would add energy (the limit wins over the momentum there). It also runs, with `s = 1`,
//! where the sums cannot tell the gain from the budget: they are f32 blocks, and a
//! correction undoing most of the motion makes the gain a small difference of large terms
//! ([`SUMS_UNCERTAINTY`] of them). A body with pinned particles
//! (no spin removal) exchanges momentum with its pins anyway. The sums are
//! the spin removal's ([`crate::stabilisation::angular_momentum`]), taken in the same pass; the limit costs a few
//! multiply–adds per particle there and one more pass only in iterations where it acts.
//!
//! **Work against the applied accelerations.** The positions keep all of `Δᵢ`, so they also
//! move the body in its potential `U = −Σ mᵢ a·xᵢ` (`a` the body's gravity plus
//! [`crate::ExternalAcceleration`] plus the mean acceleration its [`crate::UserForces`] give
//! the free particles, uniform over the body): by
//!
//! ```text
//! G = −Σ mᵢ a·Δᵢ = −a·Σ mᵢ Δᵢ      (J)
//! ```
//!
//! whatever `s` is. On a free body `Σ mᵢΔᵢ = 0` and `G = 0`; a body with pins exchanges
//! momentum with them, and its corrections can lift it: a hard vertex–face cube hanging from
//! its top face (a family that keeps finding violation) gained 0.3–0.9 J of `G` a substep
//! with `ΔK ≤ 0` held, and its mechanical energy rose by the sum, 1e-3 × `M g L` in two
//! seconds, as kinetic energy (the prediction turns the lifted height back into speed). So
//! the limit bounds the whole mechanical gain `ΔK(s) + G`, not `ΔK(s)` alone.
//!
//! That alone would act on every resting substep: a body hanging at rest has `u = 0`, the
//! prediction moves its free particles by `h²a` and the corrections take them back,
//! `Δᵢ = −h²a`, so `A = −h²|a|² M_f`, `Q = ½h²|a|² M_f`, `G = h²|a|² M_f` and
//! `ΔK + G = ½h²|a|² M_f > 0` (`M_f` the free particles' mass). That is the energy the
//! prediction took out: with `vᵢ = k(uᵢ + h a)` (`k = max(0, 1 − damping·h)`), the prediction
//! changes `K + U` by
//!
//! ```text
//! ΔE_pred = ½Σ mᵢ(|vᵢ|² − |uᵢ|²) − h Σ mᵢ a·vᵢ
//!         = −½(1 − k²) Σ mᵢ|uᵢ|²  −  [½k² h²|a|² M_f + (1 − k) h a·Σ mᵢ vᵢ]
//! ```
//!
//! (sums over the free particles). The first term is the damping of the motion the body
//! had: dissipation, not the constraints' to spend (a tangled body under damping would
//! otherwise never calm down). The bracket is what the step along `a` took out of the
//! discrete energy, the part the constraints' reaction to that step gives back; it is the
//! credit `P`, taken from the predicted velocities (at rest it is exactly the `½h²|a|²M_f`
//! above, with damping `(k − ½k²)h²|a|²M_f`). Over the substep the body's mechanical energy
//! changes by `ΔE_pred + ΔK(s) + G`, so with
//!
//! ```text
//! ΔK(s) + G − P ≤ E     (E the budget below)
//! ```
//!
//! the body ends no substep with more mechanical energy than it started with plus `E`.
//! The credit goes with the part of the prediction's step the corrections undo: an
//! iteration is granted `f P` with `f = G/(k h²|a|²M_f)` clamped to `[0, 1]` (at rest
//! `Δᵢ = −kh²a`, `f = 1`; a uniform partial undo by `f` gains `f²P ≤ fP`). A free body's
//! corrections undo none of it (`Σ mᵢΔᵢ = 0`) and get no credit; iterations that undo the
//! step once between them are credited `P` once.
//!
//! A hook's moves change the potential too: a contact pressing a resting body onto a pinned
//! slab pushes the slab's free particles down by `δ` a substep and the slab's families lift
//! them back, `G = m a·δ`, while the hook's measure ([`crate::stabilisation::hook_work`])
//! counts only the kinetic `m|δ|²/2h²`. The part of `G` that undoes the hook's move along
//! `a` since the last pass, `min(G, a·Σ mᵢΔcᵢ)` where both are positive, is not charged:
//! the body ends where it was, and the descent the hook caused is given back, not created.
//! The limit keeps the largest `s` with
//! `ΔK(s) ≤ E − G + P`; where even the `s ∈ [0, 1]` that takes the most kinetic energy out
//! (`−A/2Q`) leaves too much, the give-back pass scales the iteration's velocities down
//! until the kinetic energy pays for the lift ([`crate::stabilisation::give_back`]). The
//! limit acts only on a gain above a tolerance of the sums' uncertainty of `G` and
//! [`REST_TOLERANCE`] of `P`: a body hanging at rest has `ΔK + G − P = 0` up to its
//! discrete rest state's convergence and is left alone (and falls asleep).
//!
//! The budget: a compliant constraint `C` with compliance `α` (`α̃ = α/h²`) and multiplier
//! step `Δλ` releases, to first order,
//!
//! ```text
//! (C² − (C + W Δλ)²) / (2α) = Δλ² W (2α̃ + W) / (2α),   W = Σ wᵢ|∇ᵢC|²,
//! ```
//!
//! (with `C = −(α̃ + W)Δλ` from the XPBD update) of which, from rest, `Δλ² W / (2h²)` — at
//! most half — becomes its own kinetic energy. The kernels do not keep `W`; the budget takes
//! it as `W̄ = w_max G` with `w_max` the body's largest inverse mass and `G` a bound of
//! `Σ|∇ᵢC|²` at the rest shape (2 for an edge and for a vertex–face height, `L⁴/12` for the
//! volume of a tetrahedron of edge `L`), summed over the multipliers the substep holds.
//! Over-estimating `W` only makes the budget larger: compliant rebound is never cut, and the
//! limit acts on what the hard constraints and the stiff end of the compliant ones would
//! add. A compliant body's stored elastic energy is real energy and is released; a hard body
//! has none.

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::stabilisation::rigid_fit::Moments;
use nalgebra::Vector3;

/// The fraction `s ∈ [0, 1]` of the families' corrections that may become velocity (see the
/// module docs), from the store pass's sums (taken about a point at distance `origin`, m,
/// from the world origin), the spin removal's centre `c` and rotation
/// `θ` (zero when not removed), the substep `h` (s), the acceleration the prediction applied
/// and the budget (J, asked only when the corrections add energy at all; its arguments are
/// the body's largest inverse mass, 1/kg, the work term `A` and the gain `ΔK(1) + G − P`, J:
/// it may stop summing once it has reached the gain). Returns `s` and the kinetic-energy
/// budget `E − G + P` (J, negative where the kinetic energy must pay for a lift) the exact
/// check ([`crate::stabilisation::give_back`]) holds the iteration to.
pub(crate) fn velocity_scale(
    sums: &Moments<f64>,
    origin: f32,
    [c, theta]: [Vector3<f64>; 2],
    (h, applied): (f32, Applied),
    budget: impl FnOnce(f32, f64, f64) -> f64,
) -> Limit {
    let h = f64::from(h);
    // The work against the applied acceleration and the prediction's credit (module docs), J.
    let (lift, credit) = applied.lift_and_credit(sums, h);
    // The corrections after the spin removal, Δ' = Δ − θ × r with r = x̄ − o − c:
    // Σ m v·Δ' = Σ m v·Δ − θ·Σ m r × v and Σ m|Δ'|² = Σ m|Δ|² − θ·Σ m r × Δ (θ = I⁺ Σ m r × Δ).
    let r_cross_v = sums.momentum_moment - c.cross(&sums.momentum);
    let r_cross_d = sums.torque - c.cross(&sums.push);
    let (spin_work, spin_square) = (theta.dot(&r_cross_v), theta.dot(&r_cross_d));
    let work = sums.work - spin_work;
    let square = (sums.square - spin_square).max(0.0);
    let (a, q) = (work / h, square / (2.0 * h * h));
    let gain = a + q + lift - credit;
    let none = Limit {
        scale: 1.0,
        check: None,
    };
    // The sums are f32 blocks and the rotation is removed in closed form: where the gain is
    // a small difference of large terms (a correction undoing most of the motion), its sign
    // is not known to better than this, J.
    let terms =
        (sums.work.abs() + spin_work.abs()) / h + (sums.square + spin_square.abs()) / (2.0 * h * h);
    let unsure = SUMS_UNCERTAINTY * terms;
    // The tolerance on the lift: its sums' uncertainty and a small part of the credit, J.
    // Within it the limit does not act (a body hanging at rest stays untouched and sleeps).
    let tolerance = SUMS_UNCERTAINTY * lift.abs() + REST_TOLERANCE * credit;
    // No gain, or a NaN one, or one within rounding: nothing to limit.
    let floor = rounding_floor(sums, origin, h) + tolerance;
    if (gain + unsure).partial_cmp(&floor) != Some(std::cmp::Ordering::Greater) {
        return none;
    }
    let e = budget(sums.inv_mass as f32, a, gain + unsure).max(0.0);
    if gain + unsure <= (e + tolerance).max(floor) || !e.is_finite() {
        return none;
    }
    // What the kinetic energy may gain: the budget less the lift the positions keep, J
    // (negative where the corrections lift the body more than the budget and the credit).
    let e = e - lift + credit;
    if a + q <= e {
        return Limit {
            scale: 1.0,
            check: Some(e),
        };
    }
    Limit {
        scale: largest_scale(a, q, e),
        check: Some(e),
    }
}

/// The largest `s ∈ [0, 1]` with `q s² + a s ≤ e` (J; `ΔK(1) = a + q > e`); where no `s`
/// qualifies (`e` below the least `ΔK`), the `s` that adds the least, `−a/2q`.
fn largest_scale(a: f64, q: f64, e: f64) -> f32 {
    let disc = a * a + 4.0 * q * e;
    let s = if q > 0.0 && disc >= 0.0 {
        // The larger root of q s² + a s − e = 0: ΔK(s) ≤ e between the roots.
        (-a + disc.sqrt()) / (2.0 * q)
    } else if q > 0.0 {
        -a / (2.0 * q)
    } else {
        e / a
    };
    if s.is_finite() {
        s.clamp(0.0, 1.0) as f32
    } else {
        1.0
    }
}

/// The acceleration the prediction applied to a body's free particles and how much of their
/// velocity it kept, for the work term and the credit of the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Applied {
    /// Gravity plus the body's [`crate::ExternalAcceleration`] and the mean acceleration of
    /// its [`crate::UserForces`] ([`crate::applied_acceleration`]), m/s².
    pub acceleration: Vector3<f64>,
    /// The damping factor `k = max(0, 1 − damping·h)` (dimensionless).
    pub keep: f64,
    /// The mass the hook moved since the families' last pass, `Σ mᵢΔcᵢ` (kg m,
    /// [`crate::stabilisation::hook_work`]).
    pub hook_push: Vector3<f64>,
}

impl Applied {
    /// The lift `G = −a·Σ mᵢΔᵢ` less the part of it that undoes the hook's move along `a`
    /// (`min(G, a·Σ mᵢΔcᵢ)` where both are positive), and the credit `f P`, with
    /// `P = ½k²h²|a|²M_f + (1 − k) h a·Σ mᵢvᵢ` (free particles, predicted velocities; at
    /// least 0) and `f` the part of the prediction's step along `a` the rest of the lift
    /// undoes, `G' / (k h²|a|²M_f)` clamped to `[0, 1]` (module docs), J, in a substep of `h` s.
    fn lift_and_credit(&self, sums: &Moments<f64>, h: f64) -> (f64, f64) {
        let (a, k) = (self.acceleration, self.keep);
        let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
        let lift = finite(-a.dot(&sums.push));
        let lowered = finite(a.dot(&self.hook_push)).max(0.0);
        let lift = lift - lift.clamp(0.0, lowered);
        let credit = 0.5 * k * k * h * h * a.norm_squared() * sums.free_mass
            + (1.0 - k) * h * a.dot(&sums.free_momentum);
        let step = k * h * h * a.norm_squared() * sums.free_mass;
        let undone = if step > 0.0 {
            (lift / step).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (lift, (finite(undone) * finite(credit)).max(0.0))
    }
}

/// Relative uncertainty of the gain the store pass's sums give (dimensionless): f32 sums over
/// blocks of 256 particles, a few times `256 ε`.
const SUMS_UNCERTAINTY: f64 = 1e-4;

/// The part of the credit `P` a body may gain in a substep without the limit acting
/// (dimensionless): a body converging to its discrete rest state under gravity gains about
/// 1e-3 `P` a substep; this bounds the gain let through to `10⁻² × ½h²|a|²M_f` a substep,
/// `0.005 |a|² M_f h` per second of simulated time.
const REST_TOLERANCE: f64 = 1e-2;

/// What [`velocity_scale`] decided for one body and iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Limit {
    /// The fraction `s ∈ [0, 1]` of the corrections that becomes velocity.
    pub scale: f32,
    /// The kinetic-energy budget (J, negative where the kinetic energy must pay for a lift)
    /// the iteration's velocity change is then checked against, exactly,
    /// after the give-back; `None`: the sums show it within the budget.
    pub check: Option<f64>,
}

/// The kinetic energy (J) of corrections at the rounding of the positions: a particle at
/// distance `L` from the world origin is stored to about `ε L` (`ε` = f32's epsilon), and
/// corrections of a few `ε L` are rounding, not violation; scaling them changes nothing
/// physical but would make the limit act on every substep of a moving body. With `L` the
/// body's distance plus its radius of gyration, the floor is `M (4 ε L)² / (2h²)`.
fn rounding_floor(sums: &Moments<f64>, origin: f32, h: f64) -> f64 {
    let Some(d) = rounding_length(sums, origin) else {
        return 0.0;
    };
    let floor = sums.mass * d * d / (2.0 * h * h);
    if floor.is_finite() {
        floor
    } else {
        0.0
    }
}

/// The rounding of a body's positions, `4 ε L` (m), with `L` its distance from the world
/// origin plus its radius of gyration; `None` without mass.
fn rounding_length(sums: &Moments<f64>, origin: f32) -> Option<f64> {
    if sums.mass.is_nan() || sums.mass <= 0.0 {
        return None;
    }
    let spread = (sums.second[0] + sums.second[1] + sums.second[2]) / sums.mass;
    let l = f64::from(origin) + spread.max(0.0).sqrt();
    Some(4.0 * f64::from(f32::EPSILON) * l)
}

/// The elastic energy the compliant families of one body may have released in the current
/// substep (J): `(1 + W̄/α̃)|A|` for the energy the prediction moved in or out of them, plus
/// `Σ λ² W̄ (2α̃ + W̄)/(2α)` per compliant family, with `W̄ = w_max G` (module docs); the
/// multiplier sums are skipped once the first term covers `gain`. Zero for hard families.
pub(crate) fn elastic_release(
    [h, w_max]: [f32; 2],
    [work, gain]: [f64; 2],
    edges: Option<&EdgeConstraints>,
    tets: Option<&Tetrahedra>,
    vertex_face: Option<&VertexFaceConstraints>,
    volume: Option<&VolumeConstraints>,
) -> f64 {
    let (h2, w) = (f64::from(h) * f64::from(h), f64::from(w_max));
    let compliant = |alpha: f32| (alpha > 0.0).then_some(f64::from(alpha));
    let edges = edges.and_then(|f| Some((f, compliant(f.compliance)?)));
    let vertex_face = vertex_face.and_then(|f| Some((f, compliant(f.compliance)?)));
    let volume = volume.and_then(|f| Some((f, compliant(f.compliance)?, tets?)));
    // Σ|∇V|² of a regular tetrahedron of the body's mean rest volume V: edge L = (6√2 V)^⅓,
    // Σ|∇V|² = L⁴/12.
    let volume_g = |t: &Tetrahedra| {
        let n = t.rest_volumes.len().max(1) as f64;
        let mean = t
            .rest_volumes
            .iter()
            .map(|v| f64::from(v.abs()))
            .sum::<f64>()
            / n;
        (6.0 * std::f64::consts::SQRT_2 * mean).cbrt().powi(4) / 12.0
    };
    let moved = |wbar: f64, alpha: f64| (1.0 + wbar * h2 / alpha) * work.abs();
    let wbar_ev = [
        edges.map(|(_, alpha)| (2.0 * w, alpha)),
        vertex_face.map(|(_, alpha)| (2.0 * w, alpha)),
    ];
    let mut bound = wbar_ev
        .iter()
        .flatten()
        .map(|&(b, a)| moved(b, a))
        .fold(0.0, f64::max);
    if bound >= gain {
        return bound;
    }
    // The volume family's W̄ takes a pass over the rest volumes: only when needed.
    let volume = volume.map(|(f, alpha, t)| (f, alpha, volume_g(t) * w));
    if let Some((_, alpha, wbar)) = volume {
        bound = bound.max(moved(wbar, alpha));
        if bound >= gain {
            return bound;
        }
    }
    let wbars = [
        wbar_ev[0],
        wbar_ev[1],
        volume.map(|(_, alpha, wbar)| (wbar, alpha)),
    ];
    let release = |(wbar, alpha): (f64, f64), sum_sq: f64| {
        sum_sq * wbar * (2.0 * alpha / h2 + wbar) / (2.0 * alpha)
    };
    let squares =
        |l: &mut dyn Iterator<Item = f32>| -> f64 { l.map(|x| f64::from(x) * f64::from(x)).sum() };
    let mut e = bound;
    if let (Some((f, _)), Some(wa)) = (edges, wbars[0]) {
        e += release(wa, squares(&mut f.lambdas.iter().copied()));
    }
    if let (Some((f, _)), Some(wa)) = (vertex_face, wbars[1]) {
        e += release(wa, squares(&mut f.lambdas.iter().flatten().copied()));
    }
    if let (Some((f, _, _)), Some(wa)) = (volume, wbars[2]) {
        e += release(wa, squares(&mut f.lambdas.iter().copied()));
    }
    e
}

/// Stores every swept body's working copy back, removing the spin of the families'
/// corrections when `spin` is set and limiting the mechanical energy they add when `limit`
/// is set, in a substep of `h` (s) under `gravity` (m/s²) and `damping` (1/s). Returns the number of bodies the limit acted on.
pub(crate) fn store_bodies(
    world: &mut hecs::World,
    (h, gravity, damping): (f32, Vector3<f32>, f32),
    spin: bool,
    limit: bool,
) -> u64 {
    let mut limited = 0;
    let keep = f64::from((1.0 - damping * h).max(0.0));
    for (p, e, t, vf, vol, m, a, (extra, forces)) in world
        .query_mut::<(
            &mut crate::Particles,
            Option<&EdgeConstraints>,
            Option<&Tetrahedra>,
            Option<&VertexFaceConstraints>,
            Option<&VolumeConstraints>,
            Option<&crate::NeoHookeanMaterial>,
            Option<&mut crate::body::activation::Activation>,
            (
                Option<&crate::ExternalAcceleration>,
                Option<&crate::UserForces>,
            ),
        )>()
        .without::<&crate::Asleep>()
    {
        if !(e.is_some() || (t.is_some() && (vf.is_some() || vol.is_some() || m.is_some()))) {
            continue;
        }
        if !limit && !spin {
            crate::kernels::working_copy::store(p);
            continue;
        }
        // What a hook's corrections handed this pass is external work, spent here.
        let hook = std::mem::take(&mut p.hook.energy);
        let hook_push = std::mem::take(&mut p.hook.push);
        let budget = |w_max: f32, work: f64, gain: f64| {
            if !limit {
                f64::INFINITY
            } else if hook >= gain {
                hook
            } else {
                let material = m.map_or(0.0, crate::solver::material_systems::energy_budget);
                hook + material + elastic_release([h, w_max], [work, gain - hook], e, t, vf, vol)
            }
        };
        // The loads besides gravity, as the mean acceleration of the free particles: exact
        // for loads proportional to mass, and one pass over the particles only for a body
        // with user forces.
        let loads = match forces {
            Some(f) => crate::applied_acceleration(p, Some(f), None, extra),
            None => extra.map_or(Vector3::zeros(), |x| x.0),
        };
        let applied = Applied {
            acceleration: (gravity + loads).cast::<f64>(),
            keep,
            hook_push,
        };
        if crate::stabilisation::angular_momentum::store_measured(p, (h, applied), spin, budget) {
            limited += 1;
            // Corrections held back from the velocities still moved the positions: the
            // body is not at rest, whatever its particles' speeds say.
            if let Some(a) = a {
                a.restart();
            }
        }
    }
    limited
}
