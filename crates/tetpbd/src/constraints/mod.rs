//! Constraint math: pure functions, no ECS, no rapier.
//!
//! Every function here is generic over the scalar (`f32` in the solver, `f64` in the
//! finite-difference tests) and returns `None` instead of a non-finite value when the
//! configuration is degenerate. The systems count those `None`s in [`crate::StepStats`].
//!
//! # XPBD
//!
//! For a constraint `C(x₀ … xₙ)` with compliance `α` (inverse stiffness), one Gauss–Seidel
//! projection inside a substep of length `h` is (Macklin et al. 2016, "XPBD"):
//!
//! ```text
//! α̃  = α / h²
//! Δλ = (−C − α̃ λ) / (Σᵢ wᵢ |∇ᵢC|² + α̃)
//! Δxᵢ = wᵢ ∇ᵢC Δλ,        λ ← λ + Δλ
//! ```
//!
//! where `wᵢ` is the inverse mass of particle `i` and `λ` the constraint's accumulated
//! Lagrange multiplier, reset to zero at the start of every substep. With `α = 0` this is
//! the hard PBD projection of Müller et al. 2006, which removes `C` to first order in one
//! step. The potential energy behind a compliant constraint is `U = C² / (2α)`, so `α` has the
//! units of `C² / J`: m/N for the two length constraints and the grab, m⁵/N for the volume constraint, 1/J for
//! the Neo-Hookean material's dimensionless constraints.
//!
//! # Where each constraint lives
//!
//! * [`edge()`] — edge distance (`edge.rs`);
//! * [`vertex_face()`] — the seed's vertex–face constraint (`vertex_face.rs`), and
//!   [`vertex_face_bounded()`], the degeneracy-aware form the solver runs
//!   (`vertex_face_bounded.rs`);
//! * [`volume()`] — signed volume, and [`volume_recovering`], the form with the recovery
//!   direction of a tetrahedron collapsed onto a line that the solver runs (`volume.rs`);
//! * [`neo_hookean_deviatoric`] and [`neo_hookean_hydrostatic`] — the stable Neo-Hookean
//!   material's two constraints per tetrahedron, solved together by
//!   [`neo_hookean_update`] (`neo_hookean.rs`), and
//!   [`neo_hookean_hydrostatic_recovering`], the hydrostatic one with the recovery direction
//!   of a collapsed tetrahedron that the solver runs (`neo_hookean_recovery.rs`);
//! * [`grab()`] — a material point held to a target with a bounded force (`grab.rs`);
//! * [`xpbd_delta_lambda`], [`bounded_step`] and [`apply()`] — the XPBD update (`xpbd.rs`).

use nalgebra::{RealField, Vector3};

mod edge;
mod grab;
mod neo_hookean;
mod neo_hookean_recovery;
mod vertex_face;
mod vertex_face_bounded;
mod volume;
mod xpbd;

pub use edge::edge;
pub use grab::{grab, grab_delta_lambda};
pub use neo_hookean::{
    cofactor, deformation_gradient, neo_hookean_deviatoric, neo_hookean_energy_density,
    neo_hookean_hydrostatic, neo_hookean_rest_offset, neo_hookean_stress, neo_hookean_update,
    rest_shape_inverse, NeoHookeanUpdate,
};
pub use neo_hookean_recovery::{
    neo_hookean_collapse_threshold, neo_hookean_hydrostatic_recovering, recovery_weight,
};
pub use vertex_face::{
    signed_height, vertex_face, vertex_face_step_bound, VERTEX_FACE_MAX_STEP, VERTEX_FACE_ORDER,
    VERTEX_FACE_SLIVER,
};
pub use vertex_face_bounded::{bounded_height, vertex_face_bounded, VERTEX_FACE_KAPPA};
pub use volume::{signed_volume, volume, volume_recovering, VOLUME_GATE};
pub use xpbd::{apply, bounded_step, xpbd_delta_lambda};

/// A constraint value with its gradients with respect to each of its `N` particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluated<T: RealField + Copy, const N: usize> {
    /// The constraint value `C`.
    pub c: T,
    /// `∇ᵢC` for each particle, in the order the particles were passed.
    pub grad: [Vector3<T>; N],
}
