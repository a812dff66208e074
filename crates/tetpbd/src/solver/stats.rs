//! Step statistics: what each [`crate::Solver::step`] returns.

use std::time::Duration;

use crate::body::families::Family;

/// Max and RMS of `|C|` over a family's constraints (in the family's units: m or m³).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorStats {
    /// Largest `|C|`.
    pub max: f32,
    /// Root mean square of `C`.
    pub rms: f32,
}

/// Accumulates `C` values into [`ErrorStats`] (sums in f64).
#[derive(Clone, Copy, Debug, Default)]
pub struct ErrorAccumulator {
    max: f32,
    sum_sq: f64,
    n: u64,
}

impl ErrorAccumulator {
    /// Adds one constraint value.
    #[inline]
    pub fn add(&mut self, c: f32) {
        self.max = self.max.max(c.abs());
        self.sum_sq += f64::from(c) * f64::from(c);
        self.n += 1;
    }

    /// The max and RMS of what was added (zeros when nothing was).
    pub fn finish(&self) -> ErrorStats {
        ErrorStats {
            max: self.max,
            rms: if self.n > 0 {
                (self.sum_sq / self.n as f64).sqrt() as f32
            } else {
                0.0
            },
        }
    }
}

/// Statistics of one constraint family over one step, summed over all bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FamilyStats {
    /// Number of scalar constraints in the family (over all bodies).
    pub count: usize,
    /// Projections carried out (count × substeps × iterations, less skips).
    pub projections: u64,
    /// Projections skipped (or given the documented fallback direction) because the
    /// configuration was degenerate.
    pub degenerate: u64,
    /// `|C|` at the end of the step (when [`crate::DiagnosticSettings::measure_error`] is on).
    pub after: Option<ErrorStats>,
    /// `|C|` at the start of the step, before prediction (when
    /// [`crate::DiagnosticSettings::measure_before`] is on).
    pub before: Option<ErrorStats>,
    /// Wall time spent in the family's system.
    pub time: Duration,
}

/// What one frame of the solver did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Number of soft bodies in the world, asleep or not.
    pub bodies: usize,
    /// Bodies asleep during the step: the systems skipped them (their particles and
    /// constraints are in no other count of these statistics).
    pub bodies_asleep: usize,
    /// Bodies woken at the start of the step (by a write of their particles) or by a hook.
    pub bodies_woken: usize,
    /// Bodies that fell asleep at the end of the step.
    pub bodies_fell_asleep: usize,
    /// Bodies asleep at the end of the step.
    pub bodies_asleep_after: usize,
    /// Bodies found tangled at the end of the step and moved towards their rest shape
    /// ([`crate::Untangle`]).
    pub bodies_untangled: usize,
    /// Number of particles over the awake bodies.
    pub particles: usize,
    /// Substeps run.
    pub substeps: u32,
    /// Iterations per substep.
    pub iterations: u32,
    /// Edge family.
    pub edge: FamilyStats,
    /// Vertex–face family.
    pub vertex_face: FamilyStats,
    /// Volume family.
    pub volume: FamilyStats,
    /// The Neo-Hookean material ([`crate::NeoHookeanMaterial`]; `count` is its tetrahedra,
    /// two constraints each; no error measure).
    pub material: FamilyStats,
    /// Tetrahedra inverted at the end of the step (when measuring error).
    pub inverted: Option<usize>,
    /// Particles whose state became non-finite during the step and were reset to their
    /// substep start with zero velocity (a safety net; 0 in every healthy run).
    pub non_finite_resets: u64,
    /// Particles found not finite at the start of a substep (written by the caller or a
    /// hook) and restored to their last finite state; the step then returns
    /// [`crate::StepError::NonFiniteState`].
    pub non_finite_restored: u64,
    /// Particle velocity updates clamped by
    /// [`crate::SafetySettings::max_correction_speed`] (summed over substeps; the momentum
    /// restoration that follows a body's clamps is not counted separately).
    pub velocity_clamps: u64,
    /// Body iterations in which the families' corrections would have added more kinetic
    /// energy than their compliant constraints released, and were limited
    /// ([`crate::SafetySettings::limit_correction_energy`]).
    pub energy_limited: u64,
    /// Time in prediction (gravity, damping, integration).
    pub predict_time: Duration,
    /// Time in the velocity update.
    pub velocity_time: Duration,
    /// Time removing the rigid rotation of the families' corrections
    /// ([`crate::SafetySettings::conserve_angular_momentum`]) and limiting their energy
    /// ([`crate::SafetySettings::limit_correction_energy`]), including the copy back from
    /// the working copy that it takes over (then not in [`StepStats::copy_time`]).
    pub spin_time: Duration,
    /// Time copying the particles into the projections' working copy and back, once per
    /// iteration (the families' times exclude it; the copy back is in
    /// [`StepStats::spin_time`] when the spin removal is on).
    pub copy_time: Duration,
    /// Time in user hooks (e.g. collision constraints).
    pub hook_time: Duration,
    /// Time measuring error after the step.
    pub measure_time: Duration,
    /// Faces torn by the tearing pass ([`crate::Tearing`]) after the substeps; the events are
    /// in [`crate::Solver::tear_events`].
    pub faces_torn: usize,
    /// Time of the tearing pass (the strain check, and the splits of a frame that tears).
    pub tearing_time: Duration,
    /// Wall time of the whole step.
    pub total_time: Duration,
}

impl StepStats {
    /// The statistics of one family.
    pub fn family(&self, f: Family) -> &FamilyStats {
        match f {
            Family::Edge => &self.edge,
            Family::VertexFace => &self.vertex_face,
            Family::Volume => &self.volume,
        }
    }

    /// Mutable statistics of one family.
    pub fn family_mut(&mut self, f: Family) -> &mut FamilyStats {
        match f {
            Family::Edge => &mut self.edge,
            Family::VertexFace => &mut self.vertex_face,
            Family::Volume => &mut self.volume,
        }
    }

    /// Degenerate skips over all families.
    pub fn degenerate(&self) -> u64 {
        self.edge.degenerate
            + self.vertex_face.degenerate
            + self.volume.degenerate
            + self.material.degenerate
    }
}
