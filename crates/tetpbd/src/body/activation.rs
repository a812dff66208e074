//! Sleeping: [`Activation`], a body's sleep settings and state, and [`Asleep`], the marker
//! the solver's systems skip.
//!
//! A body whose fastest particle stays slower than [`Activation::linear_threshold`] (m/s)
//! for [`Activation::time_until_sleep`] (s) is ready to sleep. Bodies that touch each other
//! (a [`crate::SubstepHook`] reports who touches whom, [`crate::Touching`]) form an island,
//! which falls asleep when all of its bodies are ready and none is held awake: their
//! velocities are set to zero and the [`Asleep`] marker is added. The solver's systems skip a
//! body with the marker entirely (no prediction, no projection, no velocity update: its
//! archetype is not even visited). A woken body continues from the positions it slept at
//! with zero velocity, as if it had come to rest there.
//!
//! A body wakes ([`crate::wake`]) when the user writes its particles (positions, velocities,
//! pinning, impulses: [`crate::Particles`] remembers a write until the end of the next
//! step), when [`crate::wake`] is called, or when a hook wakes it (a coupling crate: a moving
//! body comes near). A change of another component (an [`crate::ExternalAcceleration`]
//! inserted, a compliance changed) does not wake it: call [`crate::wake`] after one.
//!
//! The rule is rapier's (`RigidBodyActivation`, and rapier's soft bodies, which read the
//! fastest particle too) with its time until sleep (0.5 s) and its soft bodies' effective
//! particle-speed threshold halved (0.05 m/s).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// Sleep settings and state of one soft body (a hecs component, spawned with every body by
/// [`crate::SoftBody::spawn`]; a body without it never sleeps).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Activation {
    /// Whether the body may fall asleep at all.
    pub can_sleep: bool,
    /// Speed below which the body's fastest particle must stay, m/s (pinned particles moved
    /// by a velocity count too).
    pub linear_threshold: f32,
    /// How long the fastest particle must stay below [`Activation::linear_threshold`]
    /// before the body may sleep, s.
    pub time_until_sleep: f32,
    time_below: f32,
    sleeping: bool,
}

impl Default for Activation {
    fn default() -> Self {
        Activation {
            can_sleep: true,
            linear_threshold: Activation::DEFAULT_LINEAR_THRESHOLD,
            time_until_sleep: Activation::DEFAULT_TIME_UNTIL_SLEEP,
            time_below: 0.0,
            sleeping: false,
        }
    }
}

impl Activation {
    /// Default [`Activation::linear_threshold`], m/s.
    pub const DEFAULT_LINEAR_THRESHOLD: f32 = 0.05;
    /// Default [`Activation::time_until_sleep`], s.
    pub const DEFAULT_TIME_UNTIL_SLEEP: f32 = 0.5;

    /// Settings that never let the body sleep.
    pub fn never_sleeps() -> Self {
        Activation {
            can_sleep: false,
            ..Activation::default()
        }
    }

    /// Whether the body is asleep.
    pub fn sleeping(&self) -> bool {
        self.sleeping
    }

    /// How long the body's fastest particle has been below the threshold, s (reset by
    /// motion above it, a user write and waking).
    pub fn time_below(&self) -> f32 {
        self.time_below
    }

    /// Whether the body is ready to sleep: allowed to, and slow for long enough.
    pub(crate) fn ready(&self) -> bool {
        self.can_sleep && self.time_below >= self.time_until_sleep
    }

    /// Advances the timer by `dt` (s) given the fastest particle's speed (m/s).
    pub(crate) fn observe(&mut self, max_speed: f32, dt: f32) {
        if self.can_sleep && max_speed < self.linear_threshold {
            self.time_below += dt;
        } else {
            self.time_below = 0.0;
        }
    }

    /// Restarts the timer (a write, a wake).
    pub(crate) fn restart(&mut self) {
        self.time_below = 0.0;
    }

    pub(crate) fn set_sleeping(&mut self, sleeping: bool) {
        self.sleeping = sleeping;
        if !sleeping {
            self.time_below = 0.0;
        }
    }
}

/// Marks a sleeping body (a hecs component without data). The solver adds it when the body
/// falls asleep and removes it when the body wakes; the solver's systems, and those of a
/// coupling crate, skip bodies that have it (`query_mut::<Q>().without::<&Asleep>()`). Do
/// not add or remove it yourself: [`crate::wake`] wakes a body.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Asleep;
