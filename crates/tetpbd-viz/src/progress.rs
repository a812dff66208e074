//! [`Progress`]: a progress bar on a terminal, plain periodic lines elsewhere (CI, pipes).

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// How often the plain-line mode reports at most.
const LINE_INTERVAL: Duration = Duration::from_secs(10);

/// Progress of a long run of `total` steps, on standard error.
///
/// When standard error is a terminal it is an [indicatif] bar; otherwise a line
/// `label: done/total (p %), t s` every 10 % and at most every 10 s, and one at
/// [`Progress::finish`] — so logs of non-interactive runs stay short.
///
/// ```
/// let mut progress = tetpbd_viz::Progress::new("frames", 120);
/// for _ in 0..120 {
///     progress.inc(1);
/// }
/// progress.finish();
/// ```
#[derive(Debug)]
pub struct Progress {
    label: String,
    total: u64,
    done: u64,
    started: Instant,
    mode: Mode,
}

#[derive(Debug)]
enum Mode {
    Bar(ProgressBar),
    Lines {
        last_line: Instant,
        last_decile: u64,
    },
    Finished,
}

impl Progress {
    /// Starts reporting a run of `total` steps named `label`: a bar when standard error is a
    /// terminal, plain lines otherwise.
    pub fn new(label: impl Into<String>, total: u64) -> Progress {
        Progress::with_terminal(label, total, std::io::stderr().is_terminal())
    }

    /// As [`Progress::new`], with the choice of bar (`terminal`) or plain lines made by the
    /// caller.
    pub fn with_terminal(label: impl Into<String>, total: u64, terminal: bool) -> Progress {
        let label = label.into();
        let now = Instant::now();
        let mode = if terminal {
            let bar = ProgressBar::new(total);
            let style = ProgressStyle::with_template(
                "{prefix} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta})",
            )
            .map(|s| s.progress_chars("=> "))
            .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            bar.set_prefix(label.clone());
            Mode::Bar(bar)
        } else {
            Mode::Lines {
                last_line: now,
                last_decile: 0,
            }
        };
        Progress {
            label,
            total,
            done: 0,
            started: now,
            mode,
        }
    }

    /// Steps done so far.
    pub fn done(&self) -> u64 {
        self.done
    }

    /// The line printed in plain mode for the current count.
    pub fn line(&self) -> String {
        let percent = if self.total > 0 {
            100.0 * self.done as f64 / self.total as f64
        } else {
            100.0
        };
        format!(
            "{}: {}/{} ({percent:.0} %), {:.1} s",
            self.label,
            self.done,
            self.total,
            self.started.elapsed().as_secs_f64()
        )
    }

    /// Records `n` more steps done.
    pub fn inc(&mut self, n: u64) {
        self.done = self.done.saturating_add(n);
        let decile = self
            .done
            .saturating_mul(10)
            .checked_div(self.total)
            .map_or(0, |d| d.min(10));
        let unfinished = self.done < self.total;
        let due = match &mut self.mode {
            Mode::Bar(bar) => {
                bar.inc(n);
                false
            }
            Mode::Lines {
                last_line,
                last_decile,
            } => {
                // The line at 100 % is left to `finish`, which adds the total time.
                let due =
                    unfinished && (decile > *last_decile || last_line.elapsed() >= LINE_INTERVAL);
                if due {
                    *last_decile = decile;
                    *last_line = Instant::now();
                }
                due
            }
            Mode::Finished => false,
        };
        if due {
            eprintln!("{}", self.line());
        }
    }

    /// Runs `f` (which prints to standard output, say) with the bar hidden, so its lines do
    /// not tear the bar; in plain mode just runs `f`.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.mode {
            Mode::Bar(bar) => bar.suspend(f),
            _ => f(),
        }
    }

    /// Ends the report: clears the bar, or prints a last line with the total time.
    pub fn finish(&mut self) {
        let line = self.line();
        match std::mem::replace(&mut self.mode, Mode::Finished) {
            Mode::Bar(bar) => bar.finish_and_clear(),
            Mode::Lines { .. } => eprintln!("{line}, done"),
            Mode::Finished => {}
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Mode::Bar(bar) = &self.mode {
            bar.finish_and_clear();
        }
    }
}
