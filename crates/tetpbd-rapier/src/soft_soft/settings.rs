//! Settings and statistics of soft–soft contacts, and the self-collision marker.

use crate::error::CouplingError;
#[cfg(doc)]
use crate::SoftContacts;

/// Opt-in marker component: this soft body also collides with itself (surface particles
/// against its own surface triangles, excluding those of their tetrahedron neighbours).
/// A body without it pays nothing for self collision.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SelfCollision;

/// Settings of [`SoftContacts`]. Build with [`SoftContacts::new`] or
/// [`SoftContacts::set_settings`], which validate them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftContactSettings {
    /// Contact thickness `δ`: the distance kept between a particle and another surface, m
    /// (> 0). Sheets must be thicker than this.
    pub thickness: f32,
    /// Extra candidate distance on top of the motion bound, m (≥ 0).
    pub margin: f32,
    /// Acceleration assumed in the motion bound `|v| dt + ½ a dt²`, m/s² (≥ 0); should be at
    /// least gravity.
    pub max_acceleration: f32,
    /// `S`: the largest relative normal speed at which a contact separates two surfaces,
    /// m/s (> 0). Bounds how fast deep overlaps are resolved (see the module docs).
    pub max_separation_speed: f32,
    /// `S_skin`: the largest speed at which a particle that starts a substep inside the
    /// contact skin `[0, δ)` of a surface (e.g. bodies created touching) is pushed to the
    /// full thickness, m/s (> 0). Small, so touching bodies do not pop apart.
    pub skin_speed: f32,
    /// Body-level restitution 0: after every substep, bodies in contact stop separating as
    /// wholes along their contact normal (see `soft_restitution`). Without it stiff bodies
    /// spring back off each other at a large part of their impact speed.
    pub inelastic: bool,
    /// Static friction coefficient between soft bodies (≥ 0, dimensionless).
    pub static_friction: f32,
    /// Dynamic friction coefficient between soft bodies (≥ 0, dimensionless).
    pub dynamic_friction: f32,
    /// Contact compliance, m/N (≥ 0; 0 = hard contact).
    pub compliance: f32,
}

impl Default for SoftContactSettings {
    fn default() -> Self {
        SoftContactSettings {
            thickness: 0.005,
            margin: 0.01,
            max_acceleration: 20.0,
            max_separation_speed: 2.0,
            skin_speed: 0.1,
            inelastic: true,
            static_friction: 0.5,
            dynamic_friction: 0.4,
            compliance: 0.0,
        }
    }
}

impl SoftContactSettings {
    /// Checks every field; the first bad one is returned.
    pub fn validate(&self) -> Result<(), CouplingError> {
        let fields = [
            ("thickness (m)", self.thickness, false),
            ("margin (m)", self.margin, true),
            ("max_acceleration (m/s²)", self.max_acceleration, true),
            (
                "max_separation_speed (m/s)",
                self.max_separation_speed,
                false,
            ),
            ("static_friction", self.static_friction, true),
            ("dynamic_friction", self.dynamic_friction, true),
            ("compliance (m/N)", self.compliance, true),
        ];
        for (name, value, zero_ok) in fields {
            let ok = value.is_finite() && (value > 0.0 || (zero_ok && value == 0.0));
            if !ok {
                return Err(CouplingError::BadSetting { name, value });
            }
        }
        Ok(())
    }
}

/// What [`SoftContacts`] did in the last frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SoftContactStats {
    /// Soft bodies taking part (with particles, surface and tetrahedra).
    pub bodies: usize,
    /// Body pairs whose motion-grown AABBs overlap (the broad phase's output).
    pub body_pairs: usize,
    /// Bodies colliding with themselves.
    pub self_bodies: usize,
    /// Particle–triangle candidates gathered for the frame.
    pub candidates: usize,
    /// Candidates whose constraint was violated and projected at least once.
    pub contacts: usize,
    /// Surface particles that started the frame inside another body (deep-overlap
    /// contacts).
    pub deep: usize,
    /// Largest depth of a contact particle below its triangle at the end of the frame, m.
    pub max_penetration: f32,
    /// Substep-contacts whose separation was limited to `max_separation_speed`.
    pub clamps: u64,
    /// Projections skipped because a triangle was degenerate or a result not finite.
    pub degenerate: u64,
    /// Bodies skipped because their mesh refers to missing particles or a position is not
    /// finite.
    pub skipped_bodies: usize,
}
