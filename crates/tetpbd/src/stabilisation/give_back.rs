//! Giving a free body back the momentum the correction-energy limit held back, without
//! letting that give-back add the energy the limit just refused.
//!
//! Where the limit acts ([`crate::stabilisation::correction_energy`]) the velocity update sees
//! `s Δᵢ` of the families' corrections and the positions keep all of `Δᵢ`. The part held back,
//! `wᵢ = (1 − s) Δᵢ`, has no momentum about the substep starts (the spin removal took it
//! out), but it has some about the positions the substep ends at: moving a particle along
//! `wᵢ` while its velocity stays changes `Σ mᵢ xᵢ × vᵢ` by `Σ mᵢ wᵢ × vᵢ`. Its rigid fit about
//! the end positions, `bᵢ = w̄ + θ × (xᵢ − c)` ([`rigid_fit`]), goes back into the velocities,
//! so a free body is neither pushed nor turned by the limit.
//!
//! That give-back is kinetic energy the limit's sums did not see, and it need not be small: a
//! spinning body whose far particles the corrections pull inwards spins up when its angular
//! momentum is kept (a skater pulling in her arms), by `L²/2I` as `I` shrinks. Real muscles do
//! that work; a hard constraint closing a violation that was there before the substep has
//! none to do. A hard vertex–face body released with one vertex dragged 33 m out reached
//! about 200 J from rest (1 % of `M g L`) by this alone, and a body collapsed to a point kept
//! moving. So the give-back is measured, exactly, on the velocities the update will produce:
//! with `uᵢ` the velocity before this iteration, `kᵢ = s Δᵢ / h` the change the limit kept and
//! `gᵢ = bᵢ / h`, the iteration changes the velocities by `τ (kᵢ + gᵢ)` with the largest
//! `τ ∈ [0, 1]` such that
//!
//! ```text
//! ΔK(τ) = τ Σ mᵢ uᵢ·(kᵢ + gᵢ) + ½ τ² Σ mᵢ |kᵢ + gᵢ|²  ≤  E
//! ```
//!
//! (`E` the limit's budget, J). `τ = 1` wherever the give-back does not add energy beyond the
//! budget (it usually removes some: a body spinning slower after its corrections); below 1
//! only where energy would otherwise grow — there the principle that a body's constraints
//! never add energy they did not store wins over keeping all of the angular momentum the
//! held-back motion carried. The positions keep all of `Δᵢ` either way. This also absorbs
//! what the limit's sums (f32 blocks, a rotation removed in closed form) miss.
//!
//! Cost: in iterations where the limit acts, three passes over the body's particles (fit,
//! measure, apply), serial, in particle order (the same for any thread count).

use nalgebra::{Matrix3, Vector3};

use crate::kernels::slots::Slot;
use crate::stabilisation::rigid_fit::rigid_fit;

/// The arrays of one body the give-back reads and writes.
pub(crate) struct GiveBack<'a> {
    /// Positions at the end of the iteration, m.
    pub positions: &'a [Vector3<f32>],
    /// Rounding residuals, carrying the velocity the limit took out, m.
    pub residuals: &'a mut [Vector3<f32>],
    /// Substep starts, m.
    pub prev_positions: &'a [Vector3<f32>],
    /// The slots after [`crate::stabilisation::rigid_fit::FixUp::apply`]: the held-back
    /// displacement `(1 − s) Δᵢ` in the position lanes, the kept `s Δᵢ` in the residual lanes.
    pub slots: &'a [Slot],
    /// Lumped masses, kg.
    pub masses: &'a [f32],
}

/// Gives back the rigid fit of the held-back displacements (only with `free`: a body with
/// pins exchanges momentum with them), the whole iteration's velocity change then scaled so
/// it adds at most `budget` (J) of kinetic energy (module docs); `h` the substep (s).
/// Returns the scale `τ` applied.
pub(crate) fn give_back_within_budget(run: GiveBack<'_>, h: f32, budget: f64, free: bool) -> f32 {
    let GiveBack {
        positions,
        residuals,
        prev_positions,
        slots,
        masses,
    } = run;
    let back = if free {
        held_back_fit(positions, slots, masses)
    } else {
        None
    };
    let lanes = |v: wide::f32x4| {
        let [a, b, c, _] = v.to_array();
        Vector3::new(a, b, c)
    };
    // The displacement the give-back adds at particle i (m).
    let back_at = |x: &Vector3<f32>| match back {
        Some((o, mean, c, theta)) => {
            let b = mean + theta.cross(&((x - o).cast::<f64>() - c));
            let b = b.cast::<f32>();
            if b.iter().all(|v| v.is_finite()) {
                b
            } else {
                Vector3::zeros()
            }
        }
        None => Vector3::zeros(),
    };
    // ΔK(τ) = τ·work + ½τ²·square, from the velocities the update would produce now.
    let (mut work, mut square) = (0.0f64, 0.0f64);
    for i in 0..positions.len() {
        let kept = lanes(slots[i].r);
        let change = (kept + back_at(&positions[i])).cast::<f64>() / f64::from(h);
        let now = ((positions[i] - prev_positions[i]) + residuals[i]).cast::<f64>() / f64::from(h);
        let before = now - kept.cast::<f64>() / f64::from(h);
        let m = f64::from(masses[i]);
        work += m * before.dot(&change);
        square += m * change.norm_squared();
    }
    let tau = largest_within(work, square, budget.max(0.0));
    for i in 0..positions.len() {
        let b = back_at(&positions[i]);
        residuals[i] += b;
        if tau < 1.0 {
            residuals[i] -= (lanes(slots[i].r) + b) * (1.0 - tau);
        }
    }
    tau
}

/// The largest `τ ∈ [0, 1]` with `τ work + ½ τ² square ≤ budget` (`budget ≥ 0`, so `τ = 0`
/// always qualifies). 1 when the sums are not finite (nothing measured to act on).
fn largest_within(work: f64, square: f64, budget: f64) -> f32 {
    if !(work.is_finite() && square.is_finite() && budget.is_finite()) {
        return 1.0;
    }
    if work + 0.5 * square <= budget {
        return 1.0;
    }
    // ½ square τ² + work τ − budget = 0, larger root; square > 0 here (else work > budget
    // and τ = budget / work).
    let tau = if square > 0.0 {
        (-work + (work * work + 2.0 * square * budget).sqrt()) / square
    } else {
        budget / work
    };
    if tau.is_finite() {
        tau.clamp(0.0, 1.0) as f32
    } else {
        0.0
    }
}

/// The rigid fit `w̄ + θ × (x − c)` of the held-back displacements (the slots' position
/// lanes) about the current positions, with the origin `o` its sums were taken about
/// (the first particle): `(o, w̄, c − o, θ)`. Sums in f64 in particle order.
#[allow(clippy::type_complexity)]
fn held_back_fit(
    positions: &[Vector3<f32>],
    slots: &[Slot],
    masses: &[f32],
) -> Option<(Vector3<f32>, Vector3<f64>, Vector3<f64>, Vector3<f64>)> {
    let &o = positions.first()?;
    let (mut mass, mut first, mut second) = (0.0f64, Vector3::zeros(), Matrix3::zeros());
    let (mut moment, mut total) = (Vector3::<f64>::zeros(), Vector3::<f64>::zeros());
    for ((x, s), m) in positions.iter().zip(slots).zip(masses) {
        let [a, b, c, _] = s.xw.to_array();
        let (m, x) = (f64::from(*m), (x - o).cast::<f64>());
        let w = Vector3::new(a, b, c).cast::<f64>() * m;
        mass += m;
        first += x * m;
        second += x * x.transpose() * m;
        moment += x.cross(&w);
        total += w;
    }
    let (c, theta) = rigid_fit(mass, first, second, moment, total)?;
    Some((o, total / mass, c, theta))
}
