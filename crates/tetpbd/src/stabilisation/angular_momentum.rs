//! Removing the spin Gauss–Seidel creates
//! ([`crate::SafetySettings::conserve_angular_momentum`]).
//!
//! A body's internal constraints exert no net force and no net torque. Each projection's
//! correction `Δᵢ = wᵢ∇ᵢC Δλ` is free of both *about the positions it was computed at*
//! (the gradients of a rotation-invariant `C` sum to zero, and `Σ pᵢ × ∇ᵢC = 0`), so linear
//! momentum is conserved exactly. Angular momentum is not, for two second-order reasons:
//!
//! * the velocity is `vᵢ = (xᵢ − x̄ᵢ)/h` with `x̄ᵢ` the substep start. Moving the particles
//!   by `Δᵢ` changes `L = Σ mᵢ xᵢ × vᵢ` by
//!
//!   ```text
//!   h ΔL = Σ mᵢ [(xᵢ + Δᵢ) × (xᵢ + Δᵢ − x̄ᵢ) − xᵢ × (xᵢ − x̄ᵢ)] = Σ mᵢ x̄ᵢ × Δᵢ,
//!   ```
//!
//!   which vanishes for a torque-free correction only where the body has not moved since
//!   the substep start (`xᵢ = x̄ᵢ`);
//! * Gauss–Seidel applies the corrections one after another, each computed at positions the
//!   previous ones moved, so even from rest the sum carries a commutator term `Σ mᵢ Δ₂ × Δ₁`.
//!
//! In a body whose constraints cannot all be met (a tangled, self-intersecting equilibrium)
//! the corrections are centimetres every
//! substep and the error is a steady torque: undamped and without this pass, a tangled 1 m
//! cube released at rest reaches 22 kJ of rotation in 10 s.
//!
//! This pass removes the rigid-rotation part of the families' corrections, once per
//! iteration. With `rᵢ = x̄ᵢ − c` (`c` the centre of mass at the substep start), the
//! mass-weighted least-squares rotation of the correction field,
//!
//! ```text
//! θ = argmin Σ mᵢ |Δᵢ − θ × rᵢ|²,   I θ = Σ mᵢ rᵢ × Δᵢ = h ΔL,
//! I = Σ mᵢ (|rᵢ|² 𝟙 − rᵢ rᵢᵀ)  (the inertia tensor at the substep start),
//! ```
//!
//! is subtracted, `Δᵢ ← Δᵢ − θ × rᵢ`: afterwards `Σ mᵢ rᵢ × Δᵢ = 0`, so the families leave
//! `L` unchanged, and `Σ mᵢ θ × rᵢ = θ × Σ mᵢ rᵢ = 0` leaves the linear momentum as it was.
//! It is an orthogonal projection in the mass-weighted norm, so it never lengthens the
//! correction field: `Σ mᵢ|θ × rᵢ|² ≤ Σ mᵢ|Δᵢ|²`. `I` is inverted through its eigenvalues,
//! those below `10⁻⁹` of the largest taken as zero (a body collapsed onto a line or a
//! point has no rotation about that axis to remove, and `h ΔL` has no component there).
//! A rotation is `C`-invariant to first order, so the constraint errors change by
//! `O(|θ|²)`.
//!
//! Only the families' own corrections are measured (between the working copy's load and
//! store, [`crate::kernels::working_copy`]): a [`crate::SubstepHook`]'s contacts and attachments apply real
//! torques and are left alone. A body with a pinned particle is skipped: its pins exert
//! torque. Sums in f32 over blocks of 256 particles and in f64 across blocks, in block
//! order on one thread: the result does not depend on the thread count (with the
//! `parallel` feature the blocks of a large body are summed concurrently, then folded in
//! order). Cost: the copy back from the working copy, which this pass takes over, measures
//! the corrections on the way, plus one more pass to apply `θ`.

use nalgebra::Vector3;

use crate::body::particles::Particles;
use crate::stabilisation::give_back::{give_back_within_budget, GiveBack};
use crate::stabilisation::rigid_fit::{FixUp, Moments, StoreRun, BLOCK};

/// Copies a body's working copy back ([`crate::kernels::working_copy::store`]), removes the rigid-rotation
/// part of the corrections the families made on it since it was loaded (the copy in the
/// slots, `Particles` still holding the positions before the families) when `spin` is set
/// and the body has no pinned particle, and keeps what is left from adding kinetic energy
/// beyond `budget` ([`crate::stabilisation::correction_energy`]; `budget` is called only when the corrections would add
/// energy at all). Returns `true` when the energy limit scaled the corrections' velocity.
/// One pass stores and measures; a second, only when there is a rotation to remove or an
/// energy limit to apply, corrects.
pub(crate) fn store_measured(
    p: &mut Particles,
    (h, applied): (f32, crate::stabilisation::correction_energy::Applied),
    spin: bool,
    budget: impl FnOnce(f32, f64, f64) -> f64,
) -> bool {
    let n = p.positions.len();
    if n == 0 || p.work.0.len() != n {
        crate::kernels::working_copy::store(p);
        return false;
    }
    let spin = spin && !p.inv_masses.contains(&0.0);
    // Raw moments about the first particle's start `o` (small numbers, little
    // cancellation), summed in f32 over blocks of `BLOCK` particles and in f64 across blocks,
    // in block order (the same sums for any thread count).
    let (o, v0) = (p.prev_positions[0], p.velocities[0]);
    let mut sums = Moments::<f64>::default();
    let Particles {
        positions,
        prev_positions,
        velocities,
        residuals,
        masses,
        work,
        ..
    } = p;
    let run = StoreRun {
        slots: &mut work.0,
        positions,
        residuals,
        prev_positions,
        velocities,
        masses,
    };
    #[cfg(feature = "parallel")]
    let parallel = crate::parallel::sweeps::particles_worth_it(n);
    #[cfg(not(feature = "parallel"))]
    let parallel = false;
    if parallel {
        #[cfg(feature = "parallel")]
        BLOCKS.with_borrow_mut(|blocks| {
            blocks.clear();
            blocks.resize(n.div_ceil(BLOCK), Moments::default());
            crate::parallel::sweeps::store_measuring(run, [o, v0], blocks, spin);
            for block in blocks.iter() {
                sums.fold(block);
            }
        });
    } else {
        let StoreRun {
            slots,
            positions,
            residuals,
            prev_positions,
            velocities,
            masses,
        } = run;
        for start in (0..n).step_by(BLOCK) {
            let r = start..(start + BLOCK).min(n);
            let block = StoreRun {
                slots: &mut slots[r.clone()],
                positions: &mut positions[r.clone()],
                residuals: &mut residuals[r.clone()],
                prev_positions: &prev_positions[r.clone()],
                velocities: &velocities[r.clone()],
                masses: &masses[r],
            };
            let block = if spin {
                block.store_measuring::<true>([o, v0])
            } else {
                block.store_measuring::<false>([o, v0])
            };
            sums.fold(&block);
        }
    }
    let (c, theta) = if spin {
        sums.fit().unwrap_or((Vector3::zeros(), Vector3::zeros()))
    } else {
        (Vector3::zeros(), Vector3::zeros())
    };
    // The work was summed with velocities relative to `v0`: Σ m v·Δ = Σ m (v − v0)·Δ + v0·Σ m Δ
    // (the last term vanishes on a free body, not on a pinned one).
    sums.work += v0.cast::<f64>().dot(&sums.push);
    sums.free_momentum += v0.cast::<f64>() * sums.free_mass;
    let limit = crate::stabilisation::correction_energy::velocity_scale(
        &sums,
        o.norm(),
        [c, theta],
        (h, applied),
        budget,
    );
    let scale = limit.scale;
    if theta == Vector3::zeros() && limit.check.is_none() {
        return false;
    }
    // Δᵢ −= θ × rᵢ = rᵢ × θ, with rᵢ = x̄ᵢ − o − c; then the velocity of (1 − s) Δᵢ taken out.
    let (theta, c) = (theta.cast::<f32>(), c.cast::<f32>());
    let Particles {
        positions,
        prev_positions,
        residuals,
        masses,
        inv_masses,
        work,
        ..
    } = p;
    let fix = FixUp {
        positions,
        residuals,
        prev_positions,
        before: &mut work.0,
    };
    #[cfg(feature = "parallel")]
    if parallel {
        crate::parallel::sweeps::fix_up(fix, [o, c], theta, limit);
    } else {
        fix.apply([o, c], theta, limit);
    }
    #[cfg(not(feature = "parallel"))]
    fix.apply([o, c], theta, limit);
    // The scale keeps the momentum of the corrections about the substep start, not about
    // where the velocity update ends: give that back on a free body, and hold the whole
    // change to the budget.
    let Some(allowed) = limit.check else {
        return false;
    };
    let run = GiveBack {
        positions,
        residuals,
        prev_positions,
        slots: &work.0,
        masses,
        inv_masses,
    };
    let tau = give_back_within_budget(run, h, allowed, spin);
    scale < 1.0 || tau < 1.0
}

#[cfg(feature = "parallel")]
thread_local! {
    /// Per-block sums of the parallel path (grown once per body size, then reused).
    static BLOCKS: std::cell::RefCell<Vec<Moments<f32>>> = const { std::cell::RefCell::new(Vec::new()) };
}
