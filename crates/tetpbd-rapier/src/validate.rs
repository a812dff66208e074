//! Checks of the soft bodies' components before a coupled step moves anything.
//!
//! The coupling reads a soft body's [`Surface`] as indices into its [`Particles`]; a surface
//! that names a particle the body does not have (a `Surface` taken from another body, or one
//! left over after `Particles` was replaced) is bad state and rejected with
//! [`CouplingError::SurfaceOutOfRange`] before rapier steps. A soft body without a `Surface`
//! is stepped by the solver but does not collide ("a body gets only what it asks for"); the
//! coupling counts it in [`crate::CouplingStats::bodies_without_surface`], so a body that
//! lost its surface does not fall through the ground unnoticed.

use hecs::{Entity, World};
use tetpbd::{Particles, Surface};

use crate::error::CouplingError;

/// Checks that every soft body's surface indexes only its own particles; returns the
/// number of soft bodies (entities with `Particles`) without a `Surface`.
pub(crate) fn check_soft_bodies(world: &mut World) -> Result<usize, CouplingError> {
    for (entity, p, surface) in world.query_mut::<(Entity, &Particles, &Surface)>() {
        let len = p.len();
        let largest = surface
            .triangles()
            .iter()
            .flatten()
            .chain(surface.vertices().last())
            .copied()
            .max();
        if let Some(index) = largest.filter(|&i| i as usize >= len) {
            return Err(CouplingError::SurfaceOutOfRange { entity, index, len });
        }
    }
    Ok(world
        .query_mut::<&Particles>()
        .without::<&Surface>()
        .into_iter()
        .count())
}
