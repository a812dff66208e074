//! A soft body taking part in a frame of soft–soft contacts.

use hecs::Entity;
use nalgebra::Vector3;

/// A soft body taking part in the frame; its surface particles occupy the slots
/// `offset..offset + len` of the [`ContactFrame`](super::gather::ContactFrame) arrays.
#[derive(Clone, Debug)]
pub(crate) struct FrameBody {
    pub entity: Entity,
    pub cache: usize,
    pub offset: usize,
    pub len: usize,
    /// Surface AABB at the frame start grown by each particle's motion bound, m.
    pub lo: Vector3<f32>,
    pub hi: Vector3<f32>,
    pub self_collide: bool,
    /// Inverse of the body's mass, 1/kg; 0 when a particle is pinned (the body is not
    /// shifted by deep-overlap separation).
    pub inv_mass: f32,
    /// `true` when some candidate refers to the body's slots.
    pub involved: bool,
}
