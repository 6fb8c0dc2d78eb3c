//! How rendering fails: bad input (the scene, the settings, the machine, or scene values
//! that overflow a renderer's arithmetic), or a fault of the renderer or the array, which
//! is not the user's doing.

use cwisim_isa::Instruction;
use cwisim_scene::SceneError;
use cwisim_xproc::{ImageLimit, MachineError};
use std::io;

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
    /// The caller asked the render to stop ([`crate::Taps::cancel`]: a Python caller's
    /// Ctrl-C), and it stopped after a scanline.
    #[error("interrupted: the render was cancelled after {lines} scanline(s)")]
    Cancelled {
        /// Scanlines the array had output.
        lines: u64,
    },
    /// A value the renderer made for the array is not finite: the scene's values, each
    /// within its limit, still overflow `f64` in the renderer's arithmetic. Bad input, like
    /// a scene over a limit (the CLI's exit 2), found where the value was made (per-pixel
    /// shading) or, at the latest, where the array checks every operand — before the array
    /// runs it. Located by the renderer, the frame (renderers of several frames), the
    /// pixel row and the pixel or instruction.
    #[error(
        "{renderer}: {}{source}: a value computed from the scene overflows f64 (its intensities or lighting terms are too large for this renderer's arithmetic; docs/LIMITS.md, \"Intensities\")",
        place(*.frame, .source.row)
    )]
    Overflow {
        /// The renderer.
        renderer: &'static str,
        /// The frame, for a renderer that draws several (`None`: it draws one).
        frame: Option<u32>,
        /// What was made, and where: the row (`source.row`), the pixel or instruction.
        source: NonFinite,
    },
}

/// A value made for the array that is not finite, as found where it was made: the stage
/// and what (a pixel's shade; an instruction's operand). It travels in an [`io::Error`]
/// (what emitters return, [`NonFinite::into_io`]) to the pipeline, which reports it as
/// [`RenderError::Overflow`], naming the renderer and the row.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{stage}: {detail}")]
pub struct NonFinite {
    /// The pixel row it was made for, when known where it was found (else the pipeline
    /// gives it, from the scanlines it has had: [`NonFinite::at_row`]).
    pub row: Option<u32>,
    /// What made it: `"per-pixel shading"`, `"emitted instruction"`.
    pub stage: &'static str,
    /// Where in the row and what: `"pixel 4, channel 0: the shade is inf"`.
    pub detail: String,
}

impl NonFinite {
    /// The value of an instruction's operand that is not finite, if one is: its slot
    /// named (`I`, `dI`, `ddI`) with the instruction.
    pub fn in_instruction(instr: &Instruction) -> Option<NonFinite> {
        const SLOTS: [&str; 3] = [
            "the intensity I",
            "the first forward difference dI",
            "the second forward difference ddI",
        ];
        let values = instr.values();
        let (slot, bad) = values.iter().enumerate().find_map(|(s, v)| {
            v.as_slice()
                .iter()
                .find(|f| !f.is_finite())
                .map(|bad| (s, *bad))
        })?;
        Some(NonFinite {
            row: None,
            stage: "emitted instruction",
            detail: format!("`{instr}`: {} is {bad}", SLOTS[slot]),
        })
    }

    /// As an [`io::Error`] (kind `InvalidData`), for an emitter to return.
    pub fn into_io(self) -> io::Error {
        io::Error::new(io::ErrorKind::InvalidData, self)
    }

    /// The `NonFinite` an [`io::Error`] carries, if any.
    pub fn carried_by(e: &io::Error) -> Option<&NonFinite> {
        e.get_ref()?.downcast_ref()
    }

    /// `e` located at the row `row`, for a renderer that makes its rows' values in a loop
    /// of its own: its [`NonFinite`] (if it carries one without a row) given the row; any
    /// other error not yet located (a fault of the renderer's, an internal error) said
    /// to be the row's (`row R: …`), so that its message names the scanline.
    pub fn at_row(e: io::Error, row: u32) -> io::Error {
        if scene_error_in(&e).is_some() {
            // located in the scene already
            return e;
        }
        match NonFinite::carried_by(&e) {
            Some(nf) if nf.row.is_none() => NonFinite {
                row: Some(row),
                ..nf.clone()
            }
            .into_io(),
            Some(_) => e,
            None if e.get_ref().is_some_and(|s| s.is::<AtRow>()) => e,
            None => io::Error::new(e.kind(), AtRow { row, source: e }),
        }
    }
}

/// A scene's error found while a renderer emits (a texture that fails to decode when a
/// shading call first needs it), as an [`io::Error`] for an emitter to return; the
/// pipeline reports it as the scene error it is ([`RenderError::Scene`]).
pub fn scene_io(e: SceneError) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, e)
}

/// The [`SceneError`] an [`io::Error`] carries ([`scene_io`]), if any.
pub fn scene_error_in(e: &io::Error) -> Option<&SceneError> {
    e.get_ref()?.downcast_ref()
}

/// A renderer's error located at the pixel row it was making.
#[derive(Debug, thiserror::Error)]
#[error("row {row}: {source}")]
pub struct AtRow {
    /// The pixel row.
    pub row: u32,
    /// What went wrong there.
    pub source: io::Error,
}

/// `frame F, row R: `, as much of it as is known.
fn place(frame: Option<u32>, row: Option<u32>) -> String {
    match (frame, row) {
        (Some(f), Some(r)) => format!("frame {f}, row {r}: "),
        (Some(f), None) => format!("frame {f}: "),
        (None, Some(r)) => format!("row {r}: "),
        (None, None) => String::new(),
    }
}

impl RenderError {
    /// What an error of `renderer`'s own making is: a value that is not finite
    /// ([`RenderError::Overflow`], bad input) if `source` carries a [`NonFinite`];
    /// otherwise the renderer's fault ([`RenderError::Renderer`]). For renderers that
    /// make a frame's values before it is emitted (their `frame`), and the pipeline.
    pub fn of_renderer(renderer: &'static str, source: io::Error) -> RenderError {
        if let Some(e) = scene_error_in(&source) {
            return RenderError::Scene(e.clone());
        }
        match NonFinite::carried_by(&source) {
            Some(nf) => RenderError::Overflow {
                renderer,
                frame: None,
                source: nf.clone(),
            },
            None => RenderError::Renderer { renderer, source },
        }
    }

    /// Whether the fault is cwisim's own (a renderer or the array misbehaving), not the
    /// input's.
    pub fn is_internal(&self) -> bool {
        matches!(self, RenderError::Renderer { .. } | RenderError::Array(_))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_row_names_the_row_of_any_error_once() {
        let e = NonFinite::at_row(io::Error::other("target -1e-15 is negative"), 7);
        assert_eq!(e.to_string(), "row 7: target -1e-15 is negative");
        // located once: an outer loop does not say it again
        let e = NonFinite::at_row(e, 9);
        assert_eq!(e.to_string(), "row 7: target -1e-15 is negative");
        // a value that is not finite gets the row in its own record
        let nf = NonFinite {
            row: None,
            stage: "per-pixel shading",
            detail: "pixel 3, channel 0: the shade is inf".into(),
        };
        let e = NonFinite::at_row(nf.into_io(), 5);
        assert_eq!(NonFinite::carried_by(&e).and_then(|nf| nf.row), Some(5));
    }
}
