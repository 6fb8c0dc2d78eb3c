//! Every way a `cwisim` command can fail, and the exit code each gives.

use cwisim_isa::TraceError;
use cwisim_render::RenderError;
use cwisim_scene::budget::BudgetError;
use cwisim_scene::SceneError;
use cwisim_study::StudyError;
use cwisim_xproc::{ImageLimit, MachineError, ReplayError};
use std::path::PathBuf;

/// Exit code of `cwisim diff` when the two sides differ — and of nothing else, so that a
/// snapshot check can tell "different" from every failure.
pub const EXIT_DIFFERENT: u8 = 1;
/// Exit code for bad input or usage: a malformed trace, scene or machine file, bad
/// arguments, or a size over a budget.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit code when the input was fine but an output could not be written (a file, or
/// standard output: a full disk, a read-only directory, `/dev/full`).
pub const EXIT_WRITE_FAILED: u8 = 3;
/// Exit code when cwisim itself failed: an internal fault, a bug, never the input's doing.
pub const EXIT_INTERNAL: u8 = 4;
/// Exit code of a command interrupted by SIGINT, SIGTERM or SIGHUP (128 + SIGINT, as
/// shells report it); its partial outputs are removed and no old file is replaced.
pub const EXIT_INTERRUPTED: u8 = 130;

/// Why a command failed. Every message is one line and names the file involved.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The trace cannot be read (its message is located: `file:line:col` or `file: byte N`).
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// The machine description (file or `--set`) is unusable.
    #[error(transparent)]
    Machine(#[from] MachineError),
    /// The scene file is malformed (its message is located).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The output image would be larger than the collector allows (the memory budget).
    #[error("{0} (CWISIM_MAX_MEMORY=SIZE raises the memory budget)")]
    ImageLimit(#[from] ImageLimit),
    /// The work would need more memory, output or threads than the budget
    /// (`CWISIM_MAX_MEMORY`, `CWISIM_MAX_OUTPUT`), or a budget variable is not a size.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// Arguments that contradict each other or the trace (same input and output, a
    /// 4-channel PNG, …).
    #[error("{0}")]
    Usage(String),
    /// An output file could not be written.
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// The output file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// Standard output could not be written (a closed pipe, a full disk).
    #[error("cannot write to standard output: {0}")]
    Stdout(std::io::Error),
    /// cwisim itself failed — a renderer emitted an instruction the array refuses, or the
    /// array failed: a bug, not bad input.
    #[error(
        "internal error (a bug in cwisim; please report it with the command that gave it): {0}"
    )]
    Internal(String),
}

impl From<StudyError> for CliError {
    fn from(e: StudyError) -> Self {
        match e {
            StudyError::Render(e) => e.into(),
            StudyError::Trace(e) => CliError::Trace(e),
            StudyError::Machine(e) => CliError::Machine(e),
            StudyError::ImageLimit(e) => CliError::ImageLimit(e),
            // (the command line never asks to cancel: its Ctrl-C ends the process)
            e @ (StudyError::Array(_) | StudyError::Cancelled) => CliError::Internal(e.to_string()),
            e @ (StudyError::Usage(_) | StudyError::Plot(_)) => CliError::Usage(e.to_string()),
        }
    }
}

impl From<RenderError> for CliError {
    fn from(e: RenderError) -> Self {
        match e {
            RenderError::Scene(e) => CliError::Scene(e),
            RenderError::Machine(e) => CliError::Machine(e),
            RenderError::ImageLimit(e) => CliError::ImageLimit(e),
            // (the command line never asks to cancel: its Ctrl-C ends the process)
            e @ (RenderError::Renderer { .. }
            | RenderError::Array(_)
            | RenderError::Cancelled { .. }) => CliError::Internal(e.to_string()),
            e @ (RenderError::Usage(_)
            | RenderError::UnknownRenderer { .. }
            | RenderError::Overflow { .. }) => CliError::Usage(e.to_string()),
        }
    }
}

impl From<ReplayError> for CliError {
    fn from(e: ReplayError) -> Self {
        match e {
            ReplayError::Trace(e) => CliError::Trace(e),
            ReplayError::Machine(e) => CliError::Machine(e),
        }
    }
}

impl CliError {
    /// The process exit code: [`EXIT_BAD_INPUT`] (2) for bad input or usage,
    /// [`EXIT_WRITE_FAILED`] (3) when writing an output failed, [`EXIT_INTERNAL`] (4) when
    /// cwisim itself failed.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Trace(_)
            | CliError::Machine(_)
            | CliError::Scene(_)
            | CliError::ImageLimit(_)
            | CliError::Budget(_)
            | CliError::Usage(_) => EXIT_BAD_INPUT,
            CliError::Write { .. } | CliError::Stdout(_) => EXIT_WRITE_FAILED,
            CliError::Internal(_) => EXIT_INTERNAL,
        }
    }

    /// A write error on `path`.
    pub fn write(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        CliError::Write {
            path: path.into(),
            source,
        }
    }

    /// The message as exactly one line (any line break of an inner message becomes a
    /// space), for `error: <message>`.
    pub fn one_line(&self) -> String {
        let text = self.to_string();
        let mut out = String::with_capacity(text.len());
        for (i, part) in text
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .enumerate()
        {
            if i > 0 {
                out.push(' ');
            }
            out.push_str(part);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::{ErrorKind, Location};
    use std::path::Path;

    #[test]
    fn messages_are_one_line_and_codes_follow_the_cause() {
        let e: CliError = TraceError::new(
            ErrorKind::Syntax,
            Location::Line { line: 3, column: 7 },
            "expected x",
        )
        .in_file(Path::new("t.cwt"))
        .into();
        assert_eq!(e.one_line(), "t.cwt:3:7: expected x");
        assert_eq!(e.exit_code(), 2);
        let e = CliError::Usage("first\nsecond\n".into());
        assert_eq!(e.one_line(), "first second");
        let e = CliError::write("out.png", std::io::Error::other("disk full"));
        assert_eq!(e.one_line(), "out.png: cannot write: disk full");
        assert_eq!(e.exit_code(), EXIT_WRITE_FAILED);
        let e = CliError::Stdout(std::io::Error::other("disk full"));
        assert_eq!(e.exit_code(), EXIT_WRITE_FAILED);
        let e: CliError = RenderError::Array(std::io::Error::other("refused")).into();
        assert_eq!(e.exit_code(), EXIT_INTERNAL);
        assert!(
            e.one_line().starts_with("internal error"),
            "{}",
            e.one_line()
        );
        let e: CliError = cwisim_render::find("nope").unwrap_err().into();
        assert_eq!(e.exit_code(), 2);
        assert!(e
            .one_line()
            .starts_with("unknown renderer `nope`; known: vanrij"));
    }
}
