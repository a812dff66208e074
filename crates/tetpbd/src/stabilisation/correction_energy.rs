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
/// `θ` (zero when not removed), the substep `h` (s) and the budget (J, asked only when the
/// corrections add energy at all; its arguments are the body's largest inverse mass, 1/kg,
/// the work term `A` and the gain `ΔK(1)`, J: it may stop summing once it has reached the
/// gain). Returns `s` and, where the sums cannot tell the gain from the budget, the budget
/// the exact check ([`crate::stabilisation::give_back`]) holds the iteration to.
pub(crate) fn velocity_scale(
    sums: &Moments<f64>,
    origin: f32,
    c: Vector3<f64>,
    theta: Vector3<f64>,
    h: f32,
    budget: impl FnOnce(f32, f64, f64) -> f64,
) -> Limit {
    let h = f64::from(h);
    // The corrections after the spin removal, Δ' = Δ − θ × r with r = x̄ − o − c:
    // Σ m v·Δ' = Σ m v·Δ − θ·Σ m r × v and Σ m|Δ'|² = Σ m|Δ|² − θ·Σ m r × Δ (θ = I⁺ Σ m r × Δ).
    let r_cross_v = sums.momentum_moment - c.cross(&sums.momentum);
    let r_cross_d = sums.torque - c.cross(&sums.push);
    let (spin_work, spin_square) = (theta.dot(&r_cross_v), theta.dot(&r_cross_d));
    let work = sums.work - spin_work;
    let square = (sums.square - spin_square).max(0.0);
    let (a, q) = (work / h, square / (2.0 * h * h));
    let gain = a + q;
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
    // No gain, or a NaN one, or one within rounding: nothing to limit.
    let floor = rounding_floor(sums, origin, h);
    if (gain + unsure).partial_cmp(&floor) != Some(std::cmp::Ordering::Greater) {
        return none;
    }
    let e = budget(sums.inv_mass as f32, a, gain + unsure).max(0.0);
    if gain + unsure <= e.max(floor) || !e.is_finite() {
        return none;
    }
    if gain <= e {
        return Limit {
            scale: 1.0,
            check: Some(e),
        };
    }
    // The larger root of q s² + a s − e = 0: ΔK(s) ≤ e on [0, s], and ΔK(1) > e.
    let s = if q > 0.0 {
        (-a + (a * a + 4.0 * q * e).sqrt()) / (2.0 * q)
    } else {
        e / a
    };
    Limit {
        scale: if s.is_finite() {
            s.clamp(0.0, 1.0) as f32
        } else {
            1.0
        },
        check: Some(e),
    }
}

/// Relative uncertainty of the gain the store pass's sums give (dimensionless): f32 sums over
/// blocks of 256 particles, a few times `256 ε`.
const SUMS_UNCERTAINTY: f64 = 1e-4;

/// What [`velocity_scale`] decided for one body and iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Limit {
    /// The fraction `s ∈ [0, 1]` of the corrections that becomes velocity.
    pub scale: f32,
    /// The budget (J) the iteration's velocity change is then checked against, exactly,
    /// after the give-back; `None`: the sums show it within the budget.
    pub check: Option<f64>,
}

/// The kinetic energy (J) of corrections at the rounding of the positions: a particle at
/// distance `L` from the world origin is stored to about `ε L` (`ε` = f32's epsilon), and
/// corrections of a few `ε L` are rounding, not violation; scaling them changes nothing
/// physical but would make the limit act on every substep of a moving body. With `L` the
/// body's distance plus its radius of gyration, the floor is `M (4 ε L)² / (2h²)`.
fn rounding_floor(sums: &Moments<f64>, origin: f32, h: f64) -> f64 {
    if sums.mass.is_nan() || sums.mass <= 0.0 {
        return 0.0;
    }
    let spread = (sums.second[0] + sums.second[1] + sums.second[2]) / sums.mass;
    let l = f64::from(origin) + spread.max(0.0).sqrt();
    let d = 4.0 * f64::from(f32::EPSILON) * l;
    let floor = sums.mass * d * d / (2.0 * h * h);
    if floor.is_finite() {
        floor
    } else {
        0.0
    }
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
/// corrections when `spin` is set and limiting the kinetic energy they add when `limit`
/// is set. Returns the number of bodies the limit acted on.
pub(crate) fn store_bodies(world: &mut hecs::World, h: f32, spin: bool, limit: bool) -> u64 {
    let mut limited = 0;
    for (p, e, t, vf, vol, m, a) in world
        .query_mut::<(
            &mut crate::Particles,
            Option<&EdgeConstraints>,
            Option<&Tetrahedra>,
            Option<&VertexFaceConstraints>,
            Option<&VolumeConstraints>,
            Option<&crate::NeoHookeanMaterial>,
            Option<&mut crate::body::activation::Activation>,
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
        if crate::stabilisation::angular_momentum::store_measured(p, h, spin, budget) {
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
