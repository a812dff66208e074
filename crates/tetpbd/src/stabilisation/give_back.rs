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
//! moving. So the give-back is measured, exactly, on the velocities the update will produce.
//! With `uᵢ` the velocity before this iteration, the iteration's change splits into its rigid
//! part `Rᵢ` (the rigid fit of the kept `s Δᵢ`, plus `bᵢ`, over `h`: it carries all of the
//! change's momentum) and the rest `Nᵢ`, and becomes `τ_R Rᵢ + τ_N Nᵢ` with
//!
//! ```text
//! ΔK = τ_R Σ mᵢ uᵢ·Rᵢ + ½τ_R² Σ mᵢ|Rᵢ|² + τ_N Σ mᵢ uᵢ·Nᵢ + ½τ_N² Σ mᵢ|Nᵢ|² + τ_R τ_N Σ mᵢ Rᵢ·Nᵢ  ≤  E
//! ```
//!
//! (`E` the limit's budget, J): `τ_R = 1` and the largest `τ_N ≤ 1` where the rigid part alone
//! fits in the budget (the momentum is kept whole; the rigid part usually removes energy: a
//! body spinning slower after its corrections), otherwise `τ_N = 0` and the largest `τ_R`:
//! there the principle that a body's constraints never add energy they did not store wins
//! over keeping all of the angular momentum the held-back motion carried. The positions keep
//! all of `Δᵢ` either way. This also absorbs what the limit's sums (f32 blocks, a rotation
//! removed in closed form) miss.
//!
//! On a body with pins the budget can be negative: its corrections lifted it against the
//! applied acceleration by more than the budget and the prediction's credit allow
//! ([`crate::stabilisation::correction_energy`], work against the applied accelerations), and
//! the kinetic energy has to pay for the lift. Where the `τ`s cannot take that much out (at
//! best `τ = −w/s` of the change alone), the free particles' velocities after the change are
//! scaled by one `σ ∈ [0, 1]` with `σ² K' = K + E` (`K`, `K'` the kinetic energies before and
//! after the iteration's change): of all velocity fields with that kinetic energy the
//! nearest one, in the mass-weighted norm, to the velocities the update would produce. A
//! free body never gets there (its corrections carry no momentum, so they lift nothing).
//!
//! Cost: in iterations where the limit acts, four passes over the body's particles (two
//! fits, measure, apply), serial, in particle order (the same for any thread count).

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
    /// Inverse masses, 1/kg (0: pinned).
    pub inv_masses: &'a [f32],
}

/// Gives back the rigid fit of the held-back displacements (only with `free`: a body with
/// pins exchanges momentum with them), then holds the iteration's velocity change to
/// `budget` (J) of added kinetic energy, negative where the kinetic energy must pay for a lift
/// (module docs): its non-rigid part is scaled first, the rigid part only where that alone
/// would exceed the budget, the whole velocity where both cannot meet it; `h` the substep
/// (s). Returns the smallest of the scales.
pub(crate) fn give_back_within_budget(run: GiveBack<'_>, h: f32, budget: f64, free: bool) -> f32 {
    let GiveBack {
        positions,
        residuals,
        prev_positions,
        slots,
        masses,
        inv_masses,
    } = run;
    let held = |s: &Slot| lanes(s.xw);
    let kept = |s: &Slot| lanes(s.r);
    let back = if free {
        rigid_fit_of(positions, slots, masses, held)
    } else {
        None
    };
    // A body with pins has no momentum of its own to keep: its whole change is scaled alike.
    let kept_rigid = if free {
        rigid_fit_of(positions, slots, masses, kept)
    } else {
        None
    };
    // Per particle: the rigid part `R` of the change (the kept part's rigid fit plus the
    // give-back) and the rest `N`, both as displacements (m).
    let parts = |i: usize| {
        let k = kept(&slots[i]);
        let rk = at(kept_rigid, &positions[i]);
        (rk + at(back, &positions[i]), k - rk)
    };
    let hf = f64::from(h);
    let (mut wr, mut sr, mut wn, mut sn, mut x) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    // Twice the free particles' kinetic energy before the change, J.
    let mut before_k = 0.0f64;
    for i in 0..positions.len() {
        let (r, n) = parts(i);
        let (r, n) = (r.cast::<f64>() / hf, n.cast::<f64>() / hf);
        let now = ((positions[i] - prev_positions[i]) + residuals[i]).cast::<f64>() / hf;
        let before = now - kept(&slots[i]).cast::<f64>() / hf;
        let m = f64::from(masses[i]);
        wr += m * before.dot(&r);
        sr += m * r.norm_squared();
        wn += m * before.dot(&n);
        sn += m * n.norm_squared();
        x += m * r.dot(&n);
        if inv_masses[i] > 0.0 {
            before_k += m * before.norm_squared();
        }
    }
    // ΔK = τR wr + ½τR² sr + τN (wn + τR x) + ½τN² sn.
    let budget = if budget.is_nan() { 0.0 } else { budget };
    let rigid = wr + 0.5 * sr;
    let (tau_r, tau_n) = if rigid <= budget.max(0.0) {
        (1.0, largest_within(wn + x, sn, budget - rigid))
    } else {
        (largest_within(wr, sr, budget.max(0.0)), 0.0)
    };
    for i in 0..positions.len() {
        let (r, n) = parts(i);
        residuals[i] += at(back, &positions[i]);
        residuals[i] -= r * (1.0 - tau_r) + n * (1.0 - tau_n);
    }
    let (tr, tn) = (f64::from(tau_r), f64::from(tau_n));
    let added = tr * wr + 0.5 * tr * tr * sr + tn * (wn + tr * x) + 0.5 * tn * tn * sn;
    let sigma = if added > budget {
        let run = Lift {
            positions,
            residuals,
            prev_positions,
            inv_masses,
            masses,
        };
        pay_for_lift(run, hf, [0.5 * before_k, budget])
    } else {
        1.0
    };
    tau_r.min(tau_n).min(sigma)
}

/// Scales the free particles' velocities (as the update will produce them from positions and
/// residuals, over the substep `h`, s) by `σ ∈ [0, 1]` with `σ² K' = max(0, K + budget)`,
/// `K'` their kinetic energy now and `[K, budget]` the kinetic energy before the iteration's
/// change and the (negative) budget, J. Returns `σ`.
fn pay_for_lift(run: Lift<'_>, h: f64, [before, budget]: [f64; 2]) -> f32 {
    let Lift {
        positions,
        residuals,
        prev_positions,
        inv_masses,
        masses,
    } = run;
    let moved = |i: usize, r: &[Vector3<f32>]| (positions[i] - prev_positions[i]) + r[i];
    let mut now = 0.0f64;
    for i in 0..positions.len() {
        if inv_masses[i] > 0.0 {
            let v = moved(i, residuals).cast::<f64>() / h;
            now += 0.5 * f64::from(masses[i]) * v.norm_squared();
        }
    }
    let target = (before + budget).max(0.0);
    if !(now > target && now.is_finite()) {
        return 1.0;
    }
    let sigma = (target / now).sqrt().clamp(0.0, 1.0) as f32;
    for i in 0..positions.len() {
        if inv_masses[i] > 0.0 {
            let d = moved(i, residuals);
            residuals[i] -= d * (1.0 - sigma);
        }
    }
    sigma
}

/// The arrays [`pay_for_lift`] reads and writes.
struct Lift<'a> {
    positions: &'a [Vector3<f32>],
    residuals: &'a mut [Vector3<f32>],
    prev_positions: &'a [Vector3<f32>],
    inv_masses: &'a [f32],
    masses: &'a [f32],
}

/// The first three lanes of a slot's vector.
fn lanes(v: wide::f32x4) -> Vector3<f32> {
    let [a, b, c, _] = v.to_array();
    Vector3::new(a, b, c)
}

/// A rigid displacement field `w̄ + θ × (x − o − c)` (m) at `x`; zero where there is none or
/// it is not finite.
fn at(fit: Option<RigidField>, x: &Vector3<f32>) -> Vector3<f32> {
    let Some((o, mean, c, theta)) = fit else {
        return Vector3::zeros();
    };
    let b = (mean + theta.cross(&((x - o).cast::<f64>() - c))).cast::<f32>();
    if b.iter().all(|v| v.is_finite()) {
        b
    } else {
        Vector3::zeros()
    }
}

/// The largest `τ ∈ [0, 1]` with `τ work + ½ τ² square ≤ budget` (J); where none qualifies
/// (a negative budget below the least the change can add), the `τ` that adds the least,
/// `−work/square`. 1 when the sums are not finite (nothing measured to act on).
fn largest_within(work: f64, square: f64, budget: f64) -> f32 {
    if !(work.is_finite() && square.is_finite() && budget.is_finite()) {
        return 1.0;
    }
    if work + 0.5 * square <= budget {
        return 1.0;
    }
    // ½ square τ² + work τ − budget = 0, larger root; with square = 0, work > budget here.
    let disc = work * work + 2.0 * square * budget;
    let tau = if square > 0.0 && disc >= 0.0 {
        (-work + disc.sqrt()) / square
    } else if square > 0.0 {
        -work / square
    } else {
        budget / work
    };
    if tau.is_finite() {
        tau.clamp(0.0, 1.0) as f32
    } else {
        0.0
    }
}

/// A rigid field: the origin `o` its sums were taken about (the first particle), the mean
/// `w̄`, the centre `c − o` and the rotation `θ`.
type RigidField = (Vector3<f32>, Vector3<f64>, Vector3<f64>, Vector3<f64>);

/// The rigid fit `w̄ + θ × (x − c)` of the displacements `field` reads from the slots, about
/// the current positions. Sums in f64 in particle order.
fn rigid_fit_of(
    positions: &[Vector3<f32>],
    slots: &[Slot],
    masses: &[f32],
    field: impl Fn(&Slot) -> Vector3<f32>,
) -> Option<RigidField> {
    let &o = positions.first()?;
    let (mut mass, mut first, mut second) = (0.0f64, Vector3::zeros(), Matrix3::zeros());
    let (mut moment, mut total) = (Vector3::<f64>::zeros(), Vector3::<f64>::zeros());
    for ((x, s), m) in positions.iter().zip(slots).zip(masses) {
        let (m, x) = (f64::from(*m), (x - o).cast::<f64>());
        let w = field(s).cast::<f64>() * m;
        mass += m;
        first += x * m;
        second += x * x.transpose() * m;
        moment += x.cross(&w);
        total += w;
    }
    let (c, theta) = rigid_fit(mass, first, second, moment, total)?;
    Some((o, total / mass, c, theta))
}
