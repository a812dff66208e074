//! Waiting without holding a core: spin, yield now and then, sleep after a while.

use std::time::{Duration, Instant};

/// How long a wait spins (yielding the core every 256 rounds) before it sleeps between
/// checks: on a loaded machine the thread waited for may not be running, and a spinning
/// waiter would hold the core it needs.
const SLEEP_AFTER: Duration = Duration::from_micros(200);

/// One waiting loop's state: spin, yield now and then, sleep after [`SLEEP_AFTER`].
#[derive(Default)]
pub(crate) struct Backoff {
    spins: u32,
    start: Option<Instant>,
}

impl Backoff {
    /// One round of waiting.
    pub fn wait(&mut self) {
        self.spins = self.spins.wrapping_add(1);
        if !self.spins.is_multiple_of(256) {
            std::hint::spin_loop();
            return;
        }
        let start = *self.start.get_or_insert_with(Instant::now);
        if start.elapsed() > SLEEP_AFTER {
            std::thread::sleep(Duration::from_micros(20));
        } else {
            std::thread::yield_now();
        }
    }
}
