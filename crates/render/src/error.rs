//! How rendering fails: bad input (the scene, the settings, the machine), or a fault of
//! the renderer or the array, which is not the user's doing.

use cwisim_scene::SceneError;
use cwisim_xproc::{ImageLimit, MachineError};

/// Why a render failed.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The scene file is malformed (its message is located).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The machine model or the numeric format is unusable.
    #[error(transparent)]
    Machine(#[from] MachineError),
    /// The image would be larger than the collector allows.
    #[error(transparent)]
    ImageLimit(#[from] ImageLimit),
    /// Settings that cannot be used with this scene or renderer.
    #[error("{0}")]
    Usage(String),
    /// No renderer of that name.
    #[error("unknown renderer `{name}`; known: {}", known.join(", "))]
    UnknownRenderer {
        /// The name asked for.
        name: String,
        /// The registered names.
        known: Vec<&'static str>,
    },
    /// The renderer failed while emitting (its frame plan returned an error): a fault of
    /// the renderer. An instruction the array refuses is an [`RenderError::Array`].
    #[error("the renderer `{renderer}` failed: {source}")]
    Renderer {
        /// The renderer.
        renderer: &'static str,
        /// What went wrong.
        source: std::io::Error,
    },
    /// The array refused an instruction (one the renderer emitted outside the array, say)
    /// or failed, or a tap beside it (a cost map) did.
    #[error("the array failed: {0}")]
    Array(std::io::Error),
}

impl RenderError {
    /// Whether the fault is cwisim's own (a renderer or the array misbehaving), not the
    /// input's.
    pub fn is_internal(&self) -> bool {
        matches!(self, RenderError::Renderer { .. } | RenderError::Array(_))
    }
}
