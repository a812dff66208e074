//! The momentum restoration of the correction-speed safety net
//! ([`crate::SolverSettings::max_correction_speed`]).
//!
//! The per-particle clamp of [`crate::systems::update_velocities`] removes a velocity
//! `δvᵢ = v_clampedᵢ − v_unclampedᵢ` from each clamped particle, and with it linear momentum
//! `ΔP = Σ mᵢδvᵢ` and angular momentum `ΔL = Σ mᵢ(xᵢ − c) × δvᵢ` about the centre of mass
//! `c`. [`restore`] gives both back as a rigid velocity change of the whole body,
//!
//! ```text
//! vᵢ += u + ω × (xᵢ − c),   u = −ΔP / M,   ω = I⁻¹(−ΔL),
//! ```
//!
//! with `M` the body's mass and `I = Σ mᵢ(|rᵢ|²E − rᵢrᵢᵀ)`, `rᵢ = xᵢ − c`, its inertia tensor
//! about `c`. Because `Σ mᵢrᵢ = 0`, the change carries exactly `−ΔP` and `−ΔL`: the net then
//! limits only the body's deformational velocity, never its motion as a whole. A singular
//! `I` (every particle on one line or at one point) is inverted on its range only (a
//! pseudo-inverse), so the angular part about a degenerate axis is dropped rather than made
//! infinite.
//!
//! What this does not remove: the projections conserve angular momentum only to second
//! order in the correction (each gradient is taken before its finite correction), so a
//! snap-back violent enough to be clamped (corrections of up to the body's size per substep)
//! can spin the body up through the projections themselves, with or without the net (a
//! mirrored 1 m cube: 8e3 kg·m²/s after one frame without the net). Giving back what the
//! clamp removed keeps that spin, where the per-particle clamp used to cut part of it.
//!
//! The sums run over the particles in index order, in f64, on one thread: the result does
//! not depend on the thread count.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// Eigenvalues of the inertia tensor below this fraction of the largest are treated as zero
/// (the pseudo-inverse's cut-off). A rod of aspect ratio 1000 has a ratio of about 1e-5.
const SINGULAR: f64 = 1e-9;

/// Iteration cap of the inertia tensor's eigen-decomposition (a 3 × 3 converges in a few);
/// if it does not converge the angular part is skipped.
const EIGEN_ITERATIONS: usize = 100;

/// The arrays of one body [`restore`] reads and writes.
pub(crate) struct RestoreRun<'a> {
    /// Positions at the end of the substep, m.
    pub positions: &'a [Vector3<f32>],
    /// Positions at the start of the substep, m.
    pub prev_positions: &'a [Vector3<f32>],
    /// Rounding residuals of the substep's position updates, m.
    pub residuals: &'a [Vector3<f32>],
    /// Velocities after the clamp, m/s; the rigid change is added here.
    pub velocities: &'a mut [Vector3<f32>],
    /// Lumped masses, kg (every particle free).
    pub masses: &'a [f32],
}

/// Gives back the linear and angular momentum the clamp removed from one body whose
/// velocities were just set by [`crate::systems::VelocityRun::update`] with step `h` (s).
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
    let (mut total, mut first) = (0.0f64, Vector3::<f64>::zeros());
    for i in 0..n {
        let m = f64::from(masses[i]);
        total += m;
        first += positions[i].cast::<f64>() * m;
    }
    if !(total.is_finite() && total > 0.0) {
        return;
    }
    let c = first / total;
    let (mut dp, mut dl, mut inertia) = (Vector3::zeros(), Vector3::zeros(), Matrix3::zeros());
    for i in 0..n {
        let m = f64::from(masses[i]);
        let r = positions[i].cast::<f64>() - c;
        inertia += (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * m;
        let reset = velocities[i] == Vector3::zeros() && positions[i] == prev_positions[i];
        // The update's own expression (see `VelocityRun::update`), bit for bit.
        let unclamped = ((positions[i] - prev_positions[i]) + residuals[i]) / h;
        if reset || !unclamped.iter().all(|x| x.is_finite()) {
            continue;
        }
        let dv = (velocities[i] - unclamped).cast::<f64>();
        dp += dv * m;
        dl += r.cross(&dv) * m;
    }
    let u = -dp / total;
    let w = pseudo_inverse_apply(inertia, -dl);
    if !(u.iter().chain(w.iter()).all(|x| x.is_finite())) {
        return;
    }
    for i in 0..n {
        let r = positions[i].cast::<f64>() - c;
        let v = (velocities[i].cast::<f64>() + u + w.cross(&r)).cast::<f32>();
        if v.iter().all(|x| x.is_finite()) {
            velocities[i] = v;
        }
    }
}

/// `I⁺ b` for a symmetric positive semi-definite `I`: `b`'s components along eigenvectors
/// of eigenvalues below [`SINGULAR`] × the largest are dropped. Zero when `I` is zero or
/// its decomposition does not converge.
fn pseudo_inverse_apply(inertia: Matrix3<f64>, b: Vector3<f64>) -> Vector3<f64> {
    let Some(eig) = SymmetricEigen::try_new(inertia, f64::EPSILON, EIGEN_ITERATIONS) else {
        return Vector3::zeros();
    };
    let largest = eig.eigenvalues.iter().fold(0.0f64, |a, &l| a.max(l));
    if !(largest.is_finite() && largest > 0.0) {
        return Vector3::zeros();
    }
    let mut out = Vector3::zeros();
    for k in 0..3 {
        let l = eig.eigenvalues[k];
        if l > SINGULAR * largest {
            let q = eig.eigenvectors.column(k);
            out += q * (q.dot(&b) / l);
        }
    }
    out
}
