//! Non-finite state found at the start of a substep, and how it is restored.
//!
//! The state the solver reads at the start of a substep is whatever the caller (or a hook)
//! left in [`crate::Particles`]: a NaN or an infinity written through
//! [`crate::Particles::positions_mut`] or [`crate::Particles::velocities_mut`] would spread
//! through the constraints to the whole body within one substep. Prediction
//! ([`crate::systems::predict`]) therefore checks every particle it reads, at the cost of one
//! sum and one comparison per particle, before it overwrites the substep start: a particle
//! whose position is not finite goes back to its substep start (its last finite position, a
//! substep before it was overwritten; its rest position if that too is not finite), one whose
//! velocity is not finite gets zero velocity. Each restoration is counted, and the step
//! reports the first one as [`crate::StepError::NonFiniteState`] after finishing the frame.

use nalgebra::Vector3;

/// The particles [`crate::systems::predict`] found non-finite and restored.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Restored {
    /// Particles restored (over all bodies).
    pub count: u64,
    /// The first one: body, particle index, `"position"` or `"velocity"`, the value found.
    pub first: Option<(hecs::Entity, usize, &'static str, [f32; 3])>,
}

/// [`Restored`] within one body (indices relative to the run's first particle).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct RestoredRun {
    pub count: u64,
    pub first: Option<(usize, &'static str, [f32; 3])>,
}

impl RestoredRun {
    /// The same restorations with particle indices moved by `offset`.
    #[cfg_attr(not(feature = "parallel"), allow(dead_code))]
    pub fn offset(mut self, offset: usize) -> RestoredRun {
        if let Some(f) = &mut self.first {
            f.0 += offset;
        }
        self
    }
}

impl std::ops::AddAssign for RestoredRun {
    /// Sums the counts and keeps the lowest particle index, whatever the order of the runs.
    fn add_assign(&mut self, o: RestoredRun) {
        self.count += o.count;
        self.first = match (self.first, o.first) {
            (Some(a), Some(b)) => Some(if b.0 < a.0 { b } else { a }),
            (a, b) => a.or(b),
        };
    }
}

/// `true` when a position and a velocity are finite: one sum and one comparison (a sum of
/// finite coordinates above `f32::MAX` is checked coordinate by coordinate).
#[inline(always)]
pub(crate) fn is_finite(x: &Vector3<f32>, v: &Vector3<f32>) -> bool {
    (x.x + x.y + x.z + v.x + v.y + v.z).is_finite()
        || (x.iter().all(|c| c.is_finite()) && v.iter().all(|c| c.is_finite()))
}

/// Restores particle `i` (see the module docs) and records it; `prev` and `rest` are its
/// substep start and rest position.
#[cold]
#[inline(never)]
pub(crate) fn restore(
    out: &mut RestoredRun,
    i: usize,
    x: &mut Vector3<f32>,
    v: &mut Vector3<f32>,
    prev: Vector3<f32>,
    rest: Vector3<f32>,
) {
    let finite = |p: &Vector3<f32>| p.iter().all(|c| c.is_finite());
    let found = if finite(x) {
        ("velocity", [v.x, v.y, v.z])
    } else {
        ("position", [x.x, x.y, x.z])
    };
    if !finite(x) {
        *x = if finite(&prev) { prev } else { rest };
    }
    if !finite(v) {
        *v = Vector3::zeros();
    }
    *out += RestoredRun {
        count: 1,
        first: Some((i, found.0, found.1)),
    };
}
