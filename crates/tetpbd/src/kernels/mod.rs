//! The projection kernels and the memory they run on.
//!
//! * [`working_copy`] — the particles copied into 32-byte slots for the sweep ([`slots`]);
//! * [`compensated`] — the compensated position update;
//! * [`particle_runs`] — prediction and velocity update over a run of particles;
//! * [`scalar`] — one projection of one constraint, the reference kernel;
//! * [`lanes`] — SIMD kernels: four or eight constraints of one colour class at once, over
//!   the lane types of [`lane_types`] (edges and volumes, and the lane toolkit);
//!   [`vertex_face_lanes`] the vertex–face family's;
//! * [`neo_hookean`] — the material's scalar kernel, its class runs and its serial sweep;
//!   [`neo_hookean_lanes`] its SIMD kernel;
//! * [`class_runs`] — a colour class run through the kernels, and the instruction-set choice;
//! * [`count`] — the kernel choice ([`Kernel`](count::Kernel)) and the projection counts.

pub(crate) mod class_runs;
pub(crate) mod compensated;
pub(crate) mod count;
pub(crate) mod lane_types;
pub(crate) mod lanes;
pub(crate) mod neo_hookean;
pub(crate) mod neo_hookean_lanes;
pub(crate) mod particle_runs;
pub(crate) mod scalar;
pub(crate) mod slots;
pub(crate) mod vertex_face_lanes;
pub(crate) mod working_copy;
