//! Settings of the coupling between soft bodies and rapier colliders.

use crate::error::CouplingError;
use crate::soft_collider::SoftCollider;
use crate::soft_soft::settings::SoftContactSettings;
#[cfg(doc)]
use crate::Coupling;

/// Settings of a [`Coupling`].
#[derive(Clone, Debug, PartialEq)]
pub struct CouplingSettings {
    /// Extra distance around soft bodies and colliders when candidates are gathered once per
    /// frame, m (0 to [`CouplingSettings::MAX_MARGIN`]). Contacts closer than the margin plus
    /// each body's motion over the frame are evaluated in every substep.
    pub margin: f32,
    /// Collision properties of soft bodies without a [`SoftCollider`] component.
    pub default_collider: SoftCollider,
    /// Largest speed at which an overlap of a soft body with a collider is pushed out, m/s
    /// (> 0, at most [`CouplingSettings::MAX_DEPENETRATION_SPEED`]): a contact that starts
    /// deeper than one substep's push at that speed (a body created inside a collider, a
    /// surface given back to a body that sank, a teleport), in any frame. Such an overlap is
    /// resolved over several substeps and frames instead of in one substep, and the body
    /// does not keep the speed of the push (`depenetration` module docs), so separation does
    /// not turn into an explosion or a hop. Impacts and ongoing contacts are resolved fully.
    /// The same speed bounds how fast a dynamic body a soft body touches leaves an overlap
    /// with its rigid supports that it started the frame with (`contacts::support` module
    /// docs). A rigid body created inside a soft one is not covered.
    pub max_depenetration_speed: f32,
    /// The stacking pass for bodies under heavy loads (shock propagation, `heavy_loads`
    /// module docs) and soft–soft carrying, with the mass ratio that turns them on; `None`
    /// turns both off. On by default: without it, one iteration per substep lets a 1000 kg
    /// box crush a 1 kg slab.
    pub stacking: Option<StackingSettings>,
    /// Contacts between soft bodies and of a body with itself (`soft_soft` module docs of
    /// [`crate::SoftContacts`]), run by [`Coupling::step`] in the same substeps after the
    /// soft–rigid contacts; `None` turns them off. Thickness, friction and restitution come
    /// from each body's [`SoftCollider`] (combine rule in its docs); these settings hold the
    /// candidate search and the overlap-recovery speeds.
    ///
    /// On by default: bodies that touch must not pass through each other. A scene that has
    /// no use for them pays almost nothing: with fewer than two enabled soft bodies and no
    /// [`crate::SelfCollision`] nothing runs; otherwise, when no two bodies come near each
    /// other, one copy of the surface particles and a sweep over the bodies' boxes per frame.
    /// Turn them off for scenes whose soft bodies are known never to meet.
    pub soft_contacts: Option<SoftContactSettings>,
}

/// The stacking pass of a [`CouplingSettings`] (its `stacking` group): the ground-up sweep that
/// carries a heavy load's weight down a soft body to its support within a substep. Theory in
/// the `heavy_loads` module docs; decisions in `docs/decisions/ground-up-sweep.md` and
/// `self-weight-sweep-opt-in.md`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StackingSettings {
    /// Mass ratio from which a dynamic rigid body resting on a soft body counts as heavy (≥ 0,
    /// default 10; `f32::INFINITY` keeps only the [`StackingSettings::self_weight`] sweep). A
    /// soft body on an immovable support (fixed or kinematic collider, supported rigid body,
    /// pinned particles) that carries a dynamic body whose generalized mass at a contact is at
    /// least this many times the mass of the particle (or the mean of the triangle's particles)
    /// it touches gets the *stacking pass* after the ordinary projections of every iteration:
    /// its constraints once more from the ground up with the supported particles held, then the
    /// heavy body's contacts with the soft surface frozen (shock propagation, `heavy_loads`
    /// module docs). Without it, one iteration per substep lets a 1000 kg box crush a 1 kg slab.
    ///
    /// The same ratio decides soft–soft *carrying*: a soft body touching an immovable support
    /// holds still under a soft body at least this many times heavier per particle that rests on
    /// it (`soft_soft::carrying` module docs); without it a 1.5 t soft cube landing on a 24 kg
    /// soft slab threw the slab out from under it at 240 m/s.
    pub mass_ratio: f32,
    /// Whether every soft body on an immovable support gets the ground-up sweep of the stacking
    /// pass under its own weight too, not only under a heavy rigid load (default `false`). One
    /// Gauss–Seidel iteration per substep leaves a resting body sagging by a volume error that
    /// falls only as `h²`; the sweep carries the support's reaction to the top within the
    /// substep and cuts that error several times, at up to about twice the cost per frame
    /// (figures in `docs/performance.md`). Only the sweep runs; the frozen-surface contact pass
    /// and velocity pass stay reserved for heavy loads. The sweep is one-way (the support acts
    /// as infinitely heavy), so leave it off for bodies that are not meant to rest.
    pub self_weight: bool,
}

impl Default for StackingSettings {
    fn default() -> Self {
        StackingSettings {
            mass_ratio: 10.0,
            self_weight: false,
        }
    }
}

impl Default for CouplingSettings {
    fn default() -> Self {
        CouplingSettings {
            margin: 0.02,
            default_collider: SoftCollider::default(),
            max_depenetration_speed: 2.0,
            stacking: Some(StackingSettings::default()),
            soft_contacts: Some(SoftContactSettings::default()),
        }
    }
}

impl CouplingSettings {
    /// Largest [`CouplingSettings::margin`] accepted, m. The margin only widens the candidate
    /// search; beyond a metre it gathers colliders no contact can reach within a frame.
    pub const MAX_MARGIN: f32 = 1.0;

    /// Largest [`CouplingSettings::max_depenetration_speed`] accepted, m/s.
    pub const MAX_DEPENETRATION_SPEED: f32 = 100.0;

    /// The mass ratio of the stacking pass and soft–soft carrying in force:
    /// [`StackingSettings::mass_ratio`], or infinite (never) when `stacking` is `None`.
    pub fn stacking_mass_ratio(&self) -> f32 {
        self.stacking.map_or(f32::INFINITY, |s| s.mass_ratio)
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<(), CouplingError> {
        if !(self.margin.is_finite() && (0.0..=Self::MAX_MARGIN).contains(&self.margin)) {
            return Err(CouplingError::BadSetting {
                name: "margin (m, 0 to CouplingSettings::MAX_MARGIN)",
                value: self.margin,
            });
        }
        if !(self.max_depenetration_speed > 0.0
            && self.max_depenetration_speed <= Self::MAX_DEPENETRATION_SPEED)
        {
            return Err(CouplingError::BadSetting {
                name: "max depenetration speed (m/s, > 0, at most MAX_DEPENETRATION_SPEED)",
                value: self.max_depenetration_speed,
            });
        }
        if let Some(s) = &self.stacking {
            if s.mass_ratio.is_nan() || s.mass_ratio < 0.0 {
                return Err(CouplingError::BadSetting {
                    name: "stacking mass ratio",
                    value: s.mass_ratio,
                });
            }
        }
        if let Some(s) = &self.soft_contacts {
            s.validate()?;
        }
        Ok(())
    }
}
