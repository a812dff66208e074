//! Which kernels run the projections, and what a sweep counts.

use crate::kernels::scalar;

/// Which kernels the projections run on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Kernel {
    /// One constraint at a time: the reference.
    Scalar,
    /// Four independent constraints of a colour class at once (`wide::f32x4`), the rest
    /// and the overflow class on the scalar kernel. Agrees with [`Kernel::Scalar`] to
    /// rounding.
    #[default]
    Simd,
}

/// Projections done and skipped by one call of a family system.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProjectionCount {
    /// Projections applied.
    pub applied: u64,
    /// Degenerate configurations skipped or handled by a fallback direction.
    pub degenerate: u64,
}

impl ProjectionCount {
    #[inline(always)]
    pub(crate) fn add(&mut self, o: scalar::Outcome) {
        match o {
            scalar::Outcome::Applied => self.applied += 1,
            scalar::Outcome::Degenerate => self.degenerate += 1,
            scalar::Outcome::Skipped => {}
        }
    }
}

impl std::ops::AddAssign for ProjectionCount {
    fn add_assign(&mut self, o: ProjectionCount) {
        self.applied += o.applied;
        self.degenerate += o.degenerate;
    }
}
