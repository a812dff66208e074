//! The momentum restoration of the correction-speed safety net
//! ([`crate::SolverSettings::max_correction_speed`]).
//!
//! The per-particle clamp of [`crate::systems::update_velocities`] removes a velocity
//! `δvᵢ = v_clampedᵢ − v_unclampedᵢ` from each clamped particle, and with it the linear
//! momentum `ΔP = Σ mᵢδvᵢ`: an asymmetric snap-back clamped particle by particle used to
//! throw the whole body (2150 kg·m/s, 2.15 m/s of drift, three frames after a tangled
//! release). [`restore`] gives it back as a uniform velocity change of the whole body,
//!
//! ```text
//! vᵢ += −ΔP / M,
//! ```
//!
//! `M` the body's mass: the net never changes the body's linear momentum.
//!
//! The angular momentum the clamp removes is not given back, by measurement. The
//! projections conserve angular momentum only to second order in the correction (each
//! gradient is taken before its finite correction), so a snap-back violent enough to be
//! clamped spins the body up through the projections themselves, with or without the net
//! (a mirrored 1 m cube: 8e3 kg·m²/s after one frame without it). What the clamp removes
//! about the centre of mass is mostly that spurious spin: giving it back as a rigid rotation
//! (the inertia tensor's pseudo-inverse) took the stability matrix with the net from 95 to
//! 90 of 108 cells and left two recovery tests' bodies tangled; restoring the angular
//! momentum to its value before the substep instead (93 of 108) kept a collapsed body from
//! re-expanding. With the linear part alone: 94 of 108 (the cells that changed are chaotic
//! releases, crates/tetpbd-stability/src/bin/findings.md).
//!
//! The sums run over the particles in index order, in f64, on one thread: the result does
//! not depend on the thread count.

use nalgebra::Vector3;

/// The arrays of one body [`restore`] reads and writes.
pub(crate) struct RestoreRun<'a> {
    /// Positions at the end of the substep, m.
    pub positions: &'a [Vector3<f32>],
    /// Positions at the start of the substep, m.
    pub prev_positions: &'a [Vector3<f32>],
    /// Rounding residuals of the substep's position updates, m.
    pub residuals: &'a [Vector3<f32>],
    /// Velocities after the clamp, m/s; the uniform change is added here.
    pub velocities: &'a mut [Vector3<f32>],
    /// Lumped masses, kg (every particle free).
    pub masses: &'a [f32],
}

/// Gives back the linear momentum the clamp removed from one body whose velocities were
/// just set by [`crate::systems::VelocityRun::update`] with step `h` (s).
///
/// The unclamped velocity of each particle is recomputed with the same expression the
/// update used, so a particle the clamp left alone contributes exactly zero. A particle the
/// update reset for a non-finite position (back at its substep start with zero velocity)
/// contributes nothing either. Nothing is written unless the result is finite.
pub(crate) fn restore(run: RestoreRun<'_>, h: f32) {
    let RestoreRun {
        positions,
        prev_positions,
        residuals,
        velocities,
        masses,
    } = run;
    let n = positions
        .len()
        .min(prev_positions.len())
        .min(residuals.len())
        .min(velocities.len())
        .min(masses.len());
    let (mut total, mut dp) = (0.0f64, Vector3::<f64>::zeros());
    for i in 0..n {
        let m = f64::from(masses[i]);
        total += m;
        let reset = velocities[i] == Vector3::zeros() && positions[i] == prev_positions[i];
        // The update's own expression (see `VelocityRun::update`), bit for bit.
        let unclamped = ((positions[i] - prev_positions[i]) + residuals[i]) / h;
        if reset || !unclamped.iter().all(|x| x.is_finite()) {
            continue;
        }
        dp += (velocities[i] - unclamped).cast::<f64>() * m;
    }
    if !(total.is_finite() && total > 0.0) {
        return;
    }
    let u = -dp / total;
    if !u.iter().all(|x| x.is_finite()) {
        return;
    }
    for v in velocities[..n].iter_mut() {
        let w = (v.cast::<f64>() + u).cast::<f32>();
        if w.iter().all(|x| x.is_finite()) {
            *v = w;
        }
    }
}
