//! What a coupled step reports: soft–rigid contacts and statistics.

use std::time::Duration;

use nalgebra::Vector3;
use rapier3d::geometry::ColliderHandle;

/// Which soft-body feature touched the collider.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoftFeature {
    /// A surface particle (vertex) of the soft body.
    Particle(u32),
    /// A boundary triangle (index into `Surface::triangles`) hit by a rigid corner.
    Triangle(u32),
}

/// One soft–rigid contact of the last step.
///
/// One report per soft feature and collider that were in contact during at least one
/// substep of the frame. Impulses are summed over the frame's substeps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactReport {
    /// The rigid collider.
    pub collider: ColliderHandle,
    /// The soft body's entity.
    pub entity: hecs::Entity,
    /// The soft feature in contact.
    pub feature: SoftFeature,
    /// Contact point on the collider's surface at the last substep the contact was active,
    /// world frame, m.
    pub point: Vector3<f32>,
    /// Unit contact normal pointing from the collider towards the soft body.
    pub normal: Vector3<f32>,
    /// Deepest penetration seen during the frame before it was resolved (predicted
    /// position against the collider surface plus contact thickness), m.
    pub depth: f32,
    /// Total impulse the collider applied to the soft body over the frame (normal,
    /// friction and restitution), N·s. The rigid body received the opposite.
    pub impulse: Vector3<f32>,
    /// `false` when the solver groups rejected the pair: the contact was seen, not solved.
    pub solved: bool,
}

/// Statistics of one coupled step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CouplingStats {
    /// The soft-body solver's own statistics of the frame.
    pub soft: tetpbd::StepStats,
    /// Wall time of rapier's step.
    pub rigid_time: Duration,
    /// Wall time of the whole coupled step.
    pub total_time: Duration,
    /// Particle–collider candidate pairs gathered from the broad phase.
    pub candidates: usize,
    /// Rigid-corner–soft-triangle candidate pairs.
    pub corner_candidates: usize,
    /// Contacts reported (see [`ContactReport`]).
    pub contacts: usize,
    /// Deepest penetration of a surface particle into a collider at the end of the step
    /// (signed distance below 0), m. Thickness not counted.
    pub max_penetration: f32,
    /// Largest violation of an attachment at the end of the step, m.
    pub max_attachment_error: f32,
    /// Attachments solved.
    pub attachments: usize,
    /// Attachments skipped because their rigid body no longer exists (counted per step).
    pub skipped_attachments: usize,
    /// Contact evaluations skipped because parry gave no usable normal (point exactly on the
    /// surface with no previous normal).
    pub degenerate_contacts: u64,
    /// Stacking passes run (one per stacked soft body and iteration; `heavy_loads` module
    /// docs, [`crate::StackingSettings::mass_ratio`]).
    pub stacking_passes: u64,
    /// Wall time of the stacking passes and their velocity passes (part of the soft step's
    /// hook time).
    pub stacking_time: Duration,
    /// Soft bodies (entities with `Particles`) stepped without a `Surface`: the solver moves
    /// them but they collide with nothing (`validate` module docs).
    pub bodies_without_surface: usize,
    /// Rigid bodies whose pose/velocity was written back.
    pub bodies_written: usize,
    /// Rigid bodies not written back because their result was not finite.
    pub non_finite_bodies: usize,
    /// What the soft–soft contacts did ([`crate::CouplingSettings::soft_contacts`]; all
    /// zero when they are off).
    pub soft_contacts: crate::SoftContactStats,
}
