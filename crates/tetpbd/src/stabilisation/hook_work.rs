//! The kinetic energy a hook's position corrections hand the families: external work in the
//! budget of the correction-energy limit ([`crate::stabilisation::correction_energy`]).
//!
//! A hook (a coupling's contacts, attachments, a user's constraint) corrects particles'
//! positions between the families' passes. A contact that stops the bottom layer of a body
//! resting on the ground leaves the layer above compressed; the families' next pass turns
//! that violation into the upward velocity that carries the body's weight. That violation
//! was not there "before" in the limit's sense: the hook put it there, and converting it to
//! motion is how a contact's push spreads through a body. Without counting it, the limit
//! held the support back, and bodies resting on contacts jittered and dragged.
//!
//! The measure: a hook moving particle `i` by `Δcᵢ` in a substep of length `h` is an impulse
//! `Jᵢ = mᵢ Δcᵢ / h` on it; the kinetic energy an impulse can put into the particles' motion
//! relative to one another is at most `|Jᵢ|² / (2mᵢ)`, so
//!
//! ```text
//! E_hook = Σ mᵢ |Δcᵢ|² / (2h²)     (J)
//! ```
//!
//! summed over the hook's calls between two passes of the families (its `project` after an
//! iteration, its `begin_substep` before the next one) is added to the limit's budget of the
//! next pass and spent there: a hook that stops pushing gives nothing to the passes after.
//! A hook that changes velocities instead (`end_substep`: velocity-level friction and
//! restitution on the particles a contact touches) hands the next prediction the same kind
//! of relative motion; its impulses `mᵢΔvᵢ` count `Σ mᵢ|Δvᵢ|²/2` the same way.
//! On a body alone (the empty hook, [`crate::SubstepHook::moves_particles`] `false`) nothing
//! is measured and nothing is added.

use nalgebra::Vector3;

use crate::Particles;

/// Per body: the positions before the running hook call (scratch) and the kinetic energy the
/// hook's corrections have handed the families' next pass (J).
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct HookWork {
    /// Positions before the hook call being measured (m); scratch, neither compared nor
    /// serialized.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) start: Vec<Vector3<f32>>,
    /// `Σ mᵢ|Δcᵢ|²/(2h²)` of the hook calls since the families' last pass (J).
    pub(crate) energy: f64,
    /// `Σ mᵢΔcᵢ` of the same calls (kg m; `Δcᵢ = hΔvᵢ` for a velocity change): how far the
    /// hook moved the body's mass, for the work against the applied acceleration
    /// ([`crate::stabilisation::correction_energy`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub(crate) push: Vector3<f64>,
}

impl PartialEq for HookWork {
    fn eq(&self, o: &HookWork) -> bool {
        self.energy.to_bits() == o.energy.to_bits()
            && self.push.map(f64::to_bits) == o.push.map(f64::to_bits)
    }
}

/// What a hook call changes: positions (`begin_substep`, `project`: an impulse `mᵢΔcᵢ/h`)
/// or velocities (`end_substep`: an impulse `mᵢΔvᵢ`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Changed {
    /// Positions, m.
    Positions,
    /// Velocities, m/s.
    Velocities,
}

fn field(p: &mut Particles, changed: Changed) -> (&[Vector3<f32>], &[f32], &mut HookWork) {
    let Particles {
        positions,
        velocities,
        masses,
        hook,
        ..
    } = p;
    match changed {
        Changed::Positions => (positions, masses, hook),
        Changed::Velocities => (velocities, masses, hook),
    }
}

/// Records every body's positions or velocities before a hook call.
pub(crate) fn before_hook(world: &mut hecs::World, changed: Changed) {
    for p in world
        .query_mut::<&mut Particles>()
        .without::<&crate::Asleep>()
    {
        let (now, _, hook) = field(p, changed);
        hook.start.clear();
        hook.start.extend_from_slice(now);
    }
}

/// Adds the energy of the impulses of the hook call since [`before_hook`] to every body's
/// hook work: `Σ mᵢ|Δcᵢ|²/(2h²)` for positions, `Σ mᵢ|Δvᵢ|²/2` for velocities; and the
/// mass moved, `Σ mᵢΔcᵢ` (`Σ mᵢ hΔvᵢ`).
pub(crate) fn after_hook(world: &mut hecs::World, h: f32, changed: Changed) {
    let (factor, length) = match changed {
        Changed::Positions => (0.5 / (f64::from(h) * f64::from(h)), 1.0),
        Changed::Velocities => (0.5, f64::from(h)),
    };
    for p in world
        .query_mut::<&mut Particles>()
        .without::<&crate::Asleep>()
    {
        let (now, masses, hook) = field(p, changed);
        if hook.start.len() != now.len() {
            continue;
        }
        let (mut sum, mut moved) = (0.0f64, Vector3::<f64>::zeros());
        for ((x, s), m) in now.iter().zip(&hook.start).zip(masses) {
            let d = x - s;
            sum += f64::from(*m) * f64::from(d.norm_squared());
            moved += d.cast::<f64>() * f64::from(*m);
        }
        // A non-finite state is the non-finite check's business, not the budget's.
        if sum.is_finite() && moved.iter().all(|c| c.is_finite()) {
            hook.energy += sum * factor;
            hook.push += moved * length;
        }
    }
}
