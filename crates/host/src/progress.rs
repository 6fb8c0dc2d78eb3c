//! The progress bars of `cwisim run` (bytes of the trace read so far) and `cwisim render`
//! (scanlines done), on standard error.
//!
//! It stays hidden for the first second (short runs never flash a bar) and whenever
//! standard error is not a terminal (pipes, files, tests), so it never pollutes captured
//! output.

use indicatif::{HumanDuration, ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How long a run goes before its bar appears.
pub const SHOW_AFTER: Duration = Duration::from_secs(1);

/// A progress bar over the bytes of one trace file, or the scanlines of one render.
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
    /// The first progress reported, and when: the estimate of the time left counts only
    /// the work done since (so the set-up before it does not make the rate look slow).
    first: Arc<Mutex<Option<(Instant, u64)>>>,
    /// Whether the bar may ever appear (standard error is a terminal).
    enabled: bool,
    shown: bool,
}

impl Progress {
    /// A bar over `total_bytes` (0 if unknown), drawn only if `enabled` and standard error
    /// is a terminal, and not before [`SHOW_AFTER`].
    pub fn new(total_bytes: u64, enabled: bool) -> Self {
        Self::with_template(
            total_bytes,
            enabled,
            "{spinner} replaying [{wide_bar}] {bytes}/{total_bytes} ({eta} left)",
        )
    }

    /// A bar over the `total` scanlines of a render (`cwisim render`), with the same rules.
    pub fn scanlines(total: u64, enabled: bool) -> Self {
        Self::with_template(
            total,
            enabled,
            "{spinner} rendering [{wide_bar}] {pos}/{len} scanlines ({eta} left)",
        )
    }

    /// A bar over `total` steps of a command's work (settings measured, stages done),
    /// `what` saying what it is doing; the same rules.
    pub fn steps(total: u64, enabled: bool, what: &str) -> Self {
        Self::with_template(
            total,
            enabled,
            &format!("{{spinner}} {what} [{{wide_bar}}] {{pos}}/{{len}} {{msg}} ({{eta}} left)"),
        )
    }

    /// Runs `f` with the bar hidden, so that what it prints stands above the bar.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
    }

    /// Says what the current step is (`vanrij, gouraud, f64`).
    pub fn message(&self, msg: String) {
        self.bar.set_message(msg);
    }

    fn with_template(total: u64, enabled: bool, template: &str) -> Self {
        let len = (total > 0).then_some(total);
        let bar = ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden());
        let first: Arc<Mutex<Option<(Instant, u64)>>> = Arc::new(Mutex::new(None));
        let seen = Arc::clone(&first);
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> ").with_key(
                "eta",
                move |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let first = seen.lock().ok().and_then(|f| *f);
                    let left = first.and_then(|(at, at_first)| {
                        let done = state.pos().saturating_sub(at_first);
                        let left = state.len()?.saturating_sub(state.pos());
                        time_left(done, left, at.elapsed())
                    });
                    let _ = match left {
                        Some(d) => write!(w, "{:#}", HumanDuration(d)),
                        None => write!(w, "?"),
                    };
                },
            ));
        }
        Progress {
            bar,
            start: Instant::now(),
            first,
            enabled: enabled && std::io::stderr().is_terminal(),
            shown: false,
        }
    }

    /// `done` bytes (or scanlines) so far.
    pub fn update(&mut self, done: u64) {
        if done > 0 {
            if let Ok(mut first) = self.first.lock() {
                first.get_or_insert((Instant::now(), done));
            }
        }
        self.bar.set_position(done);
        if self.enabled && !self.shown && self.start.elapsed() >= SHOW_AFTER {
            self.shown = true;
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    /// Whether the bar has appeared.
    pub fn is_shown(&self) -> bool {
        self.shown
    }
}

/// A spinner for a stage whose work has no count the command can see (loading and
/// preparing a scene, exact visibility, building an inspect page): it appears after
/// [`SHOW_AFTER`] on a terminal, turning on its own, says what is being done, and is gone
/// when dropped.
pub struct Stage {
    bar: ProgressBar,
}

impl Stage {
    /// A spinner saying `what`, if `enabled` and standard error is a terminal.
    pub fn new(enabled: bool, what: &str) -> Stage {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
            bar.set_style(style);
        }
        bar.set_message(what.to_string());
        if enabled && std::io::stderr().is_terminal() {
            let shown = bar.clone();
            std::thread::spawn(move || {
                std::thread::sleep(SHOW_AFTER);
                if !shown.is_finished() {
                    shown.set_draw_target(ProgressDrawTarget::stderr());
                    shown.enable_steady_tick(Duration::from_millis(120));
                }
            });
        }
        Stage { bar }
    }

    /// Says what is being done now.
    pub fn message(&self, what: &str) {
        self.bar.set_message(what.to_string());
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// The time the `left` steps still take at the mean rate of the `done` steps that took
/// `elapsed`: from the work done, not from the last steps' rate (which one slow first band
/// or a burst of quick ones makes wrong by orders of magnitude). `None` before any step.
pub fn time_left(done: u64, left: u64, elapsed: Duration) -> Option<Duration> {
    (done > 0).then(|| elapsed.mul_f64(left as f64 / done as f64))
}

impl Drop for Progress {
    /// Erases the bar (also when the run failed), so that messages start on a clean line.
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disabled_bar_never_appears() {
        let mut p = Progress::new(100, false);
        p.update(50);
        p.update(100);
        assert!(!p.is_shown());
    }

    #[test]
    fn time_left_is_the_mean_rate_of_the_work_done() {
        assert_eq!(time_left(0, 100, Duration::from_secs(5)), None);
        assert_eq!(
            time_left(10, 90, Duration::from_secs(1)),
            Some(Duration::from_secs(9))
        );
        assert_eq!(
            time_left(100, 0, Duration::from_secs(3)),
            Some(Duration::ZERO)
        );
        // however slow the set-up before the first step (not counted), and however the
        // steps bunch up, the estimate is the mean
        assert_eq!(
            time_left(1000, 2000, Duration::from_millis(500)),
            Some(Duration::from_secs(1))
        );
    }

    #[test]
    fn a_short_run_never_shows_its_bar() {
        let mut p = Progress::new(0, true);
        p.update(10);
        assert!(!p.is_shown());
    }
}
