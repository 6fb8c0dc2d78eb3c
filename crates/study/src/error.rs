//! How a study fails: bad input or settings (nothing to draw, too large an image, a
//! renderer's refusal), or a drawing that could not be made.

use cwisim_isa::TraceError;
use cwisim_render::RenderError;
use cwisim_xproc::{ImageLimit, MachineError, ReplayError};

/// Why a study could not be made.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// Rendering the scene failed (its own error says whether the input or cwisim is at
    /// fault).
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The trace cannot be read (its message is located).
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// The machine model or the numeric format is unusable.
    #[error(transparent)]
    Machine(#[from] MachineError),
    /// The image would be larger than the collector allows.
    #[error(transparent)]
    ImageLimit(#[from] ImageLimit),
    /// The input cannot be studied so (nothing to draw, a map too large, a search that
    /// found nothing).
    #[error("{0}")]
    Usage(String),
    /// The array refused a stream it had already run: a fault of cwisim's own.
    #[error("the array failed: {0}")]
    Array(std::io::Error),
    /// A plot could not be drawn (the message says so).
    #[error("{0}")]
    Plot(String),
    /// The caller asked the work to stop (a Python caller's Ctrl-C), and it stopped.
    #[error("interrupted")]
    Cancelled,
}

impl From<ReplayError> for StudyError {
    fn from(e: ReplayError) -> Self {
        match e {
            ReplayError::Trace(e) => StudyError::Trace(e),
            ReplayError::Machine(e) => StudyError::Machine(e),
        }
    }
}

impl StudyError {
    /// Whether the fault is cwisim's own, not the input's.
    pub fn is_internal(&self) -> bool {
        match self {
            StudyError::Render(e) => e.is_internal(),
            StudyError::Array(_) => true,
            _ => false,
        }
    }
}
