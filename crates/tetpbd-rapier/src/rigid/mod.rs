//! Rigid bodies and colliders as the soft substeps see them: one proxy per rapier body a
//! soft body touches (its pose and mass inside the substeps, the impulses it receives),
//! collider proxies, and closest-point queries on rigid shapes.

pub(crate) mod body;
pub(crate) mod collider;
pub(crate) mod shape_query;
