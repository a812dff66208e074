//! Building soft bodies and the components they are made of.
//!
//! [`SoftBodyBuilder`](builder::SoftBodyBuilder) turns a [`TetMesh`](builder::TetMesh)
//! (vertices and tetrahedra, from a file or a [`generators`] function) into the components of
//! one body: [`Particles`](particles::Particles) (one flat array per quantity),
//! [`Tetrahedra`](mesh::Tetrahedra), [`Surface`](mesh::Surface) and one optional component per
//! constraint family ([`families`]): a body pays only for the families it has, and for
//! [`Plasticity`](plasticity::Plasticity) and [`Tearing`](tearing::Tearing) only if it has
//! them.

pub(crate) mod activation;
pub(crate) mod builder;
pub(crate) mod cutting;
pub(crate) mod elastic_energy;
pub(crate) mod face_forces;
pub(crate) mod families;
pub(crate) mod forces;
pub mod generators;
pub(crate) mod grab;
pub(crate) mod impact_reach;
pub mod impact_speed;
pub(crate) mod impulses;
pub(crate) mod lumped_mass;
pub(crate) mod material;
pub(crate) mod material_point;
pub(crate) mod mesh;
pub(crate) mod neo_hookean;
pub(crate) mod particles;
pub(crate) mod pieces;
pub(crate) mod placement;
pub(crate) mod plastic_rest;
pub(crate) mod plasticity;
pub(crate) mod rebuild;
pub(crate) mod rest_families;
pub(crate) mod split;
pub(crate) mod tear_relaxation;
pub(crate) mod tearing;
