//! Keeping a team's helper off the core of the thread it helps (feature `parallel`, Linux),
//! only when the integrator asks for it ([`crate::ParallelSettings::move_helpers_off_step_core`],
//! off by default: a library does not move its host's threads unasked).
//!
//! Why: the helper of [`crate::parallel::team`] is a rayon thread woken by the step's thread, and the
//! kernel often wakes it on the waker's core. Two threads spinning on one core share it, and
//! an idle core takes one of them over only after some milliseconds: frames where most
//! chunks run with both threads on one core are about 1.5 times as slow. A helper that finds itself on the step thread's
//! core narrows its own CPU mask to the other cores it may use, which migrates it at once, and
//! restores the mask it had when it leaves the team ([`Moved`]'s drop).
//!
//! Elsewhere (not Linux, or a mask that allows no other core) nothing is moved.

/// The core this thread runs on now, if the platform tells.
pub(crate) fn current_cpu() -> Option<usize> {
    imp::current_cpu()
}

/// A thread's mask narrowed by [`Moved::off`]; restored on drop.
#[derive(Default)]
pub(crate) struct Moved {
    original: Option<imp::Mask>,
}

impl Moved {
    /// Moves this thread off `cpu` (to the other cores its mask allowed when first moved).
    /// `false` if it could not (no other core allowed, or the platform has no masks).
    pub fn off(&mut self, cpu: usize) -> bool {
        if self.original.is_none() {
            self.original = imp::mask();
        }
        let Some(original) = &self.original else {
            return false;
        };
        imp::set_without(original, cpu)
    }
}

impl Drop for Moved {
    fn drop(&mut self) {
        if let Some(original) = &self.original {
            imp::restore(original);
        }
    }
}

#[cfg(target_os = "linux")]
mod imp {
    /// A thread's CPU mask.
    pub type Mask = libc::cpu_set_t;

    pub fn current_cpu() -> Option<usize> {
        // SAFETY: no arguments; returns -1 on failure.
        let cpu = unsafe { libc::sched_getcpu() };
        usize::try_from(cpu).ok()
    }

    pub fn mask() -> Option<Mask> {
        // SAFETY: an all-zero `cpu_set_t` is a valid (empty) set.
        let mut set: Mask = unsafe { std::mem::zeroed() };
        // SAFETY: pid 0 is this thread; `set` is a valid, writable `cpu_set_t` of that size.
        let ok = unsafe { libc::sched_getaffinity(0, std::mem::size_of::<Mask>(), &mut set) };
        (ok == 0).then_some(set)
    }

    pub fn set_without(original: &Mask, cpu: usize) -> bool {
        let mut set = *original;
        if cpu >= libc::CPU_SETSIZE as usize {
            return false;
        }
        // SAFETY: `cpu` is below CPU_SETSIZE (checked).
        unsafe { libc::CPU_CLR(cpu, &mut set) };
        // SAFETY: reads a valid `cpu_set_t`.
        if unsafe { libc::CPU_COUNT(&set) } == 0 {
            return false;
        }
        // SAFETY: pid 0 is this thread; `set` is a valid `cpu_set_t` of that size.
        unsafe { libc::sched_setaffinity(0, std::mem::size_of::<Mask>(), &set) == 0 }
    }

    pub fn restore(original: &Mask) {
        // SAFETY: as in `set_without`; a failure leaves the narrowed mask, which still allows
        // the thread to run.
        unsafe { libc::sched_setaffinity(0, std::mem::size_of::<Mask>(), original) };
    }
}

#[cfg(not(target_os = "linux"))]
mod imp {
    /// No masks here.
    pub type Mask = ();

    pub fn current_cpu() -> Option<usize> {
        None
    }

    pub fn mask() -> Option<Mask> {
        None
    }

    pub fn set_without(_: &Mask, _: usize) -> bool {
        false
    }

    pub fn restore(_: &Mask) {}
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// Moving off the current core lands elsewhere (when another core is allowed), and the
    /// mask comes back whole on drop.
    #[test]
    fn moves_off_and_restores() {
        let before = imp::mask().expect("mask");
        let Some(cpu) = current_cpu() else { return };
        let mut moved = Moved::default();
        // SAFETY: reads a valid `cpu_set_t`.
        let others = unsafe { libc::CPU_COUNT(&before) } > 1;
        assert_eq!(moved.off(cpu), others);
        if others {
            assert_ne!(current_cpu(), Some(cpu));
        }
        drop(moved);
        let after = imp::mask().expect("mask");
        // SAFETY: reads valid `cpu_set_t`s.
        assert!(unsafe { libc::CPU_EQUAL(&before, &after) });
    }
}
