//! The momentum restoration of the correction-speed safety net
//! ([`crate::SafetySettings::max_correction_speed`]).
//!
//! The per-particle clamp of [`crate::solver::systems::update_velocities`] removes a velocity
//! `δvᵢ = v_clampedᵢ − v_unclampedᵢ` from each clamped particle, and with it the linear
//! momentum `ΔP = Σ mᵢδvᵢ` and the angular momentum `ΔL = Σ mᵢ rᵢ × δvᵢ` about the centre of
//! mass `c` (`rᵢ = xᵢ − c`): clamped particle by particle, an asymmetric snap-back would
//! throw the whole body and set it turning. [`restore`] gives both back as a rigid velocity
//! field,
//!
//! ```text
//! vᵢ += −ΔP / M + ω × rᵢ,   I ω = −ΔL,
//! ```
//!
//! `M` the body's mass, `I = Σ mᵢ(|rᵢ|²𝟙 − rᵢrᵢᵀ)` its inertia tensor at the end of the
//! substep (inverted through its eigenvalues, those below 10⁻⁹ of the largest taken as zero,
//! by the same [`rigid_fit`](crate::stabilisation::rigid_fit::rigid_fit) the
//! angular-momentum conservation uses): the net never changes a free body's linear or
//! angular momentum.
//!
//! Limit: giving the angular part back assumes the projections create no spin of their own
//! ([`crate::SafetySettings::conserve_angular_momentum`], on by default). With that switched
//! off, a snap-back violent enough to be clamped spins the body up through the projections
//! themselves, what the clamp removes is mostly that spurious spin, and giving it back makes
//! recovery from tangled states worse.
//!
//! The sums run over the particles in index order, in f64, on one thread: the result does
//! not depend on the thread count.

use nalgebra::{Matrix3, Vector3};

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

/// Gives back the linear and angular momentum the clamp removed from one body whose
/// velocities were just set by [`crate::kernels::particle_runs::VelocityRun::update`] with step `h` (s).
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
    let (mut total, mut dp, mut dl) = (0.0f64, Vector3::<f64>::zeros(), Vector3::zeros());
    let (mut first, mut second) = (Vector3::<f64>::zeros(), Matrix3::<f64>::zeros());
    for i in 0..n {
        let m = f64::from(masses[i]);
        let x = positions[i].cast::<f64>();
        total += m;
        first += x * m;
        second += x * x.transpose() * m;
        let reset = velocities[i] == Vector3::zeros() && positions[i] == prev_positions[i];
        // The update's own expression (see `VelocityRun::update`), bit for bit.
        let unclamped = ((positions[i] - prev_positions[i]) + residuals[i]) / h;
        if reset || !unclamped.iter().all(|x| x.is_finite()) {
            continue;
        }
        let dv = (velocities[i] - unclamped).cast::<f64>() * m;
        dp += dv;
        dl += x.cross(&dv);
    }
    if !(total.is_finite() && total > 0.0) {
        return;
    }
    let u = -dp / total;
    let (c, omega) = crate::stabilisation::rigid_fit::rigid_fit(total, first, second, -dl, -dp)
        .unwrap_or((first / total, Vector3::zeros()));
    if !u.iter().all(|x| x.is_finite()) {
        return;
    }
    for (v, x) in velocities[..n].iter_mut().zip(positions) {
        let rot = omega.cross(&(x.cast::<f64>() - c));
        let w = (v.cast::<f64>() + u + rot).cast::<f32>();
        if w.iter().all(|x| x.is_finite()) {
            *v = w;
        }
    }
}
