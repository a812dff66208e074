//! Removing the spin Gauss–Seidel creates
//! ([`crate::SolverSettings::conserve_angular_momentum`]).
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

use hecs::World;
use nalgebra::Vector3;

use crate::body::particles::Particles;
use crate::stabilisation::rigid_fit::{rotate_back, Moments, StoreRun, BLOCK};

/// Copies every swept body's working copy back ([`crate::kernels::working_copy::store`]) and removes the
/// rigid-rotation part of the corrections the families made on it since it was loaded (the
/// copy in the slots, `Particles` still holding the positions before the families).
pub(crate) fn store_bodies_without_spin(world: &mut World) {
    crate::kernels::working_copy::for_each_swept(world, store_without_spin);
}

/// [`store_bodies_without_spin`] for one body. A free body is stored and measured in one
/// pass, then corrected in a second; a body with a pinned particle is only stored.
fn store_without_spin(p: &mut Particles) {
    let n = p.positions.len();
    if n == 0 || p.work.0.len() != n || p.inv_masses.contains(&0.0) {
        crate::kernels::working_copy::store(p);
        return;
    }
    // Raw moments about the first particle's start `o` (small numbers, little
    // cancellation), summed in f32 over blocks of `BLOCK` particles and in f64 across blocks,
    // in block order (the same sums for any thread count).
    let o = p.prev_positions[0];
    let mut sums = Moments::<f64>::default();
    let Particles {
        positions,
        prev_positions,
        residuals,
        masses,
        work,
        ..
    } = p;
    let run = StoreRun {
        slots: &work.0,
        positions,
        residuals,
        prev_positions,
        masses,
    };
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::particles_worth_it(n) {
        BLOCKS.with_borrow_mut(|blocks| {
            blocks.clear();
            blocks.resize(n.div_ceil(BLOCK), Moments::default());
            crate::parallel::sweeps::store_measuring(run, o, blocks);
            for block in blocks.iter() {
                sums.fold(block);
            }
        });
        return finish(sums, positions, residuals, prev_positions, o);
    }
    let StoreRun {
        slots,
        positions,
        residuals,
        prev_positions,
        masses,
    } = run;
    for start in (0..n).step_by(BLOCK) {
        let r = start..(start + BLOCK).min(n);
        let block = StoreRun {
            slots: &slots[r.clone()],
            positions: &mut positions[r.clone()],
            residuals: &mut residuals[r.clone()],
            prev_positions: &prev_positions[r.clone()],
            masses: &masses[r],
        }
        .store_measuring(o);
        sums.fold(&block);
    }
    finish(sums, positions, residuals, prev_positions, o);
}

/// Solves for `θ` from the sums and applies `Δᵢ −= θ × rᵢ` to the stored positions.
fn finish(
    sums: Moments<f64>,
    positions: &mut [Vector3<f32>],
    residuals: &mut [Vector3<f32>],
    prev_positions: &[Vector3<f32>],
    o: Vector3<f32>,
) {
    let Some((c, theta)) = sums.fit() else {
        return;
    };
    if theta == Vector3::zeros() {
        return;
    }
    // Δᵢ −= θ × rᵢ = rᵢ × θ, with rᵢ = x̄ᵢ − o − c.
    let (theta, c) = (theta.cast::<f32>(), c.cast::<f32>());
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::particles_worth_it(positions.len()) {
        crate::parallel::sweeps::rotate_back(positions, residuals, prev_positions, [o, c], theta);
        return;
    }
    rotate_back(positions, residuals, prev_positions, [o, c], theta);
}

#[cfg(feature = "parallel")]
thread_local! {
    /// Per-block sums of the parallel path (grown once per body size, then reused).
    static BLOCKS: std::cell::RefCell<Vec<Moments<f32>>> = const { std::cell::RefCell::new(Vec::new()) };
}
