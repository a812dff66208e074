//! A soft body taking part in a frame of soft–soft contacts.

use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::{applied_acceleration, ExternalAcceleration, Grab, Particles, UserForces};

use crate::soft_collider::SoftCollider;

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
    /// The body's collision properties (its component, or the default).
    pub collider: SoftCollider,
    /// Inverse of the body's mass, 1/kg; 0 when a particle is pinned (the body is not
    /// shifted by deep-overlap separation).
    pub inv_mass: f32,
    /// `true` when some candidate refers to the body's slots.
    pub involved: bool,
}

impl FrameBody {
    /// Velocity of the body's free particles' centre of mass, m/s
    /// ([`tetpbd::Particles::free_velocity`]; zero when it cannot be read).
    pub fn com_velocity(&self, world: &mut World) -> Vector3<f32> {
        match world.query_one_mut::<&Particles>(self.entity) {
            Ok(p) => p.free_velocity().map_or(Vector3::zeros(), |v| v.0),
            Err(_) => Vector3::zeros(),
        }
    }

    /// The change of the body's centre-of-mass velocity (m/s) that gravity `g` (m/s²) and
    /// the loads applied to it ([`tetpbd::applied_acceleration`]) give over a substep of `h`
    /// (s); zero for a body held by a pinned particle or that cannot be read.
    pub fn pull(&self, world: &mut World, g: &Vector3<f32>, h: f32) -> Vector3<f32> {
        if self.inv_mass <= 0.0 {
            return Vector3::zeros();
        }
        type Loads<'a> = (
            &'a Particles,
            Option<&'a UserForces>,
            Option<&'a Grab>,
            Option<&'a ExternalAcceleration>,
        );
        match world.query_one_mut::<Loads<'_>>(self.entity) {
            Ok((p, f, grab, a)) => (g + applied_acceleration(p, f, grab, a)) * h,
            Err(_) => Vector3::zeros(),
        }
    }
}

/// The normal velocity of body `a`'s centre of mass relative to body `b`'s along the unit
/// normal `n` (m/s, > 0 separating).
pub(crate) fn relative_normal_velocity(
    world: &mut World,
    a: &FrameBody,
    b: &FrameBody,
    n: &Vector3<f32>,
) -> f32 {
    (a.com_velocity(world) - b.com_velocity(world)).dot(n)
}

/// Changes the relative normal velocity of `a` against `b` along the unit normal `n` by `dv`
/// (m/s) with opposite impulses on the two bodies, shared by the inverse masses `W` given
/// (1/kg; the bodies' own, or 0 for a body held still): `a`'s free particles all get
/// `n dv W_a/(W_a+W_b)`, `b`'s `−n dv W_b/(W_a+W_b)` (momentum kept when the `W` are the
/// bodies', no deformation added). Nothing when neither can move.
pub(crate) fn exchange(
    world: &mut World,
    (a, b): (&FrameBody, &FrameBody),
    (wa, wb): (f32, f32),
    n: &Vector3<f32>,
    dv: f32,
) {
    let wsum = wa + wb;
    if wsum.is_nan() || wsum <= 0.0 {
        return;
    }
    add_velocity(world, a.entity, n * (dv * wa / wsum));
    add_velocity(world, b.entity, n * (-dv * wb / wsum));
}

/// Adds `dv` (m/s) to the velocity of every free particle of a body.
fn add_velocity(world: &mut World, e: Entity, dv: Vector3<f32>) {
    if let Ok(p) = world.query_one_mut::<&mut Particles>(e) {
        p.add_free_velocity(&dv);
    }
}
