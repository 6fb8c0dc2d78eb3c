//! The progress bars of `cwisim run` (bytes of the trace read so far) and `cwisim render`
//! (scanlines done), on standard error.
//!
//! It stays hidden for the first second (short runs never flash a bar) and whenever
//! standard error is not a terminal (pipes, files, tests), so it never pollutes captured
//! output.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// How long a run goes before its bar appears.
pub const SHOW_AFTER: Duration = Duration::from_secs(1);

/// A progress bar over the bytes of one trace file, or the scanlines of one render.
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
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

    fn with_template(total: u64, enabled: bool, template: &str) -> Self {
        let len = (total > 0).then_some(total);
        let bar = ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Progress {
            bar,
            start: Instant::now(),
            enabled: enabled && std::io::stderr().is_terminal(),
            shown: false,
        }
    }

    /// `done` bytes (or scanlines) so far.
    pub fn update(&mut self, done: u64) {
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
    fn a_short_run_never_shows_its_bar() {
        let mut p = Progress::new(0, true);
        p.update(10);
        assert!(!p.is_shown());
    }
}
