//! The per-particle passes of a substep over a run of particles — prediction and velocity
//! update — shared by the serial systems and the parallel passes.

use crate::solver::non_finite::{self, RestoredRun};
use nalgebra::Vector3;

use crate::kernels::compensated::add_compensated;

/// The particle arrays [`predict`](crate::systems::predict) writes, for a run of particles.
pub(crate) struct PredictRun<'a> {
    pub positions: &'a mut [Vector3<f32>],
    pub prev_positions: &'a mut [Vector3<f32>],
    pub velocities: &'a mut [Vector3<f32>],
    pub inv_masses: &'a [f32],
    pub residuals: &'a mut [Vector3<f32>],
    pub rest_positions: &'a [Vector3<f32>],
}

impl PredictRun<'_> {
    /// [`predict`](crate::systems::predict) on these particles, with acceleration `a` and
    /// damping factor `keep`; a non-finite particle is restored first
    /// ([`crate::solver::non_finite`]).
    pub fn predict(self, a: Vector3<f32>, h: f32, keep: f32) -> RestoredRun {
        let PredictRun {
            positions,
            prev_positions,
            velocities,
            inv_masses,
            residuals,
            rest_positions,
        } = self;
        let mut restored = RestoredRun::default();
        for i in 0..positions.len() {
            if !non_finite::is_finite(&positions[i], &velocities[i]) {
                let (x, v) = (&mut positions[i], &mut velocities[i]);
                let (prev, rest) = (prev_positions[i], rest_positions[i]);
                non_finite::restore(&mut restored, i, x, v, prev, rest);
            }
            prev_positions[i] = positions[i];
            residuals[i] = Vector3::zeros();
            if inv_masses[i] > 0.0 {
                velocities[i] = (velocities[i] + a * h) * keep;
            }
            add_compensated(&mut positions[i], &mut residuals[i], velocities[i] * h);
        }
        restored
    }
}

/// What [`update_velocities`](crate::systems::update_velocities) did besides the plain update.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VelocityUpdate {
    /// Particles whose position became non-finite, reset to their substep start.
    pub non_finite_resets: u64,
    /// Particles whose correction speed was clamped.
    pub clamped: u64,
}

impl std::ops::AddAssign for VelocityUpdate {
    fn add_assign(&mut self, o: VelocityUpdate) {
        self.non_finite_resets += o.non_finite_resets;
        self.clamped += o.clamped;
    }
}

/// The particle arrays [`update_velocities`](crate::systems::update_velocities) uses, for a run of particles.
pub(crate) struct VelocityRun<'a> {
    pub positions: &'a mut [Vector3<f32>],
    pub prev_positions: &'a [Vector3<f32>],
    pub velocities: &'a mut [Vector3<f32>],
    pub residuals: &'a [Vector3<f32>],
}

impl VelocityRun<'_> {
    /// [`update_velocities`](crate::systems::update_velocities) on these particles.
    pub fn update(self, h: f32, max_correction_speed: Option<f32>) -> VelocityUpdate {
        let VelocityRun {
            positions,
            prev_positions,
            velocities,
            residuals,
        } = self;
        let mut out = VelocityUpdate::default();
        for i in 0..positions.len() {
            // Divide, not multiply by 1/h: h · (1/h) ≠ 1 in f32, a bias every substep.
            // `momentum_restoration::restore` recomputes this expression; keep the two the same.
            let mut v = ((positions[i] - prev_positions[i]) + residuals[i]) / h;
            if let Some(limit) = max_correction_speed {
                let dv = v - velocities[i];
                let n2 = dv.norm_squared();
                if n2 > limit * limit {
                    v = velocities[i] + dv * (limit / n2.sqrt());
                    out.clamped += 1;
                }
            }
            if v.iter().all(|c| c.is_finite()) {
                velocities[i] = v;
            } else {
                positions[i] = prev_positions[i];
                velocities[i] = Vector3::zeros();
                out.non_finite_resets += 1;
            }
        }
        out
    }
}
