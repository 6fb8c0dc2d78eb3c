//! What the study commands read: a trace file, or a scene drawn through a renderer with
//! the drawing options of the command line (`DrawArgs`, the same flags and defaults as
//! `render`). A scene's stream is emitted into memory and read back as a `.cwb` trace, so
//! every command replays it exactly as it would replay `cwisim emit`'s file; for the
//! tools that show where each instruction came from ([`open_noted`]), with the renderer's
//! notes kept beside it (`.cwb` carries none).

use crate::draw::DrawArgs;
use crate::error::CliError;
use cwisim_isa::binary::{BinaryReader, BinaryWriter};
use cwisim_isa::note::{Annotated, NoteTaker};
use cwisim_isa::{Encoding, FileReader, TraceRead};
use std::io::{BufReader, Cursor};
use std::path::Path;

/// What an input argument names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    /// A trace file: `.cwt`, `.jsonl` or `.cwb`.
    Trace,
    /// A scene: a `.json` file or an embedded scene's name.
    Scene,
}

impl InputKind {
    /// By the extension: a trace encoding's is a trace; `.json`, or none (an embedded
    /// scene's name), a scene; any other is refused, naming the ones it can read.
    pub fn of(path: &Path) -> Result<InputKind, CliError> {
        match path.extension().and_then(|e| e.to_str()) {
            None => Ok(InputKind::Scene),
            Some(e) if e.eq_ignore_ascii_case("json") => Ok(InputKind::Scene),
            Some(_) if Encoding::from_path(path).is_ok() => Ok(InputKind::Trace),
            Some(e) => Err(CliError::Usage(format!(
                "{}: unknown input extension `.{e}`; expected a trace (.cwt, .jsonl, .cwb) or a scene (.json, or an embedded scene's name)",
                path.display()
            ))),
        }
    }

    /// "trace" or "scene".
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Trace => "trace",
            InputKind::Scene => "scene",
        }
    }
}

/// Refuses drawing flags given on the command line when none of `inputs` is a scene:
/// they would change nothing. `None` is the embedded demo trace (`run` without TRACE);
/// a `.npy` file (`diff`) is an output image.
pub fn drawing_applies(draw: &DrawArgs, inputs: &[Option<&Path>]) -> Result<(), CliError> {
    let Some(first) = draw.given.first() else {
        return Ok(());
    };
    let mut replayed = None;
    for input in inputs {
        let what = match input {
            None => "without one, the embedded demo trace is replayed as it is".to_string(),
            Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy")) => {
                format!("{} is an output image, compared as it is", p.display())
            }
            Some(p) => match InputKind::of(p)? {
                InputKind::Scene => return Ok(()),
                InputKind::Trace => format!("{} is a trace, replayed as it is", p.display()),
            },
        };
        replayed.get_or_insert(what);
    }
    let what = replayed.unwrap_or_default();
    Err(CliError::Usage(match draw.given.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!(
            "{} and {last} apply when the input is a scene; {what}",
            rest.join(", ")
        ),
        _ => format!("{first} applies when the input is a scene; {what}"),
    }))
}

/// A reader on the input's instructions: the trace file, or the scene's stream as
/// `draw` renders it.
pub fn open(input: &Path, draw: &DrawArgs) -> Result<Box<dyn TraceRead>, CliError> {
    open_sized(input, draw, false).map(|(reader, _)| reader)
}

/// [`open`], and the size in bytes of what the reader reads (for progress).
/// `allow_incomplete` (`--keep-partial`): a trace file that ends short of whole frames is
/// read to its end without an error, and the reader's `incomplete()` says where it ended.
pub fn open_sized(
    input: &Path,
    draw: &DrawArgs,
    allow_incomplete: bool,
) -> Result<(Box<dyn TraceRead>, u64), CliError> {
    open_input(input, draw, allow_incomplete, false)
}

/// [`open_sized`] for the tools that show where each instruction came from (`dump`,
/// `history`): the reader hands over the notes of the instructions
/// ([`TraceRead::note`]), a trace file's own, or a scene's as its renderer writes them
/// into a `.cwt` trace (`# row 3 trapezium 4 (polygon 2): case 8: …`). The instructions
/// are the same as [`open_sized`]'s.
pub fn open_noted(input: &Path, draw: &DrawArgs) -> Result<(Box<dyn TraceRead>, u64), CliError> {
    open_input(input, draw, false, true)
}

fn open_input(
    input: &Path,
    draw: &DrawArgs,
    allow_incomplete: bool,
    notes: bool,
) -> Result<(Box<dyn TraceRead>, u64), CliError> {
    match InputKind::of(input)? {
        InputKind::Trace => {
            let mut reader = FileReader::open(input)?;
            if allow_incomplete {
                reader.allow_incomplete();
            }
            let size = reader.size();
            Ok((Box::new(reader), size))
        }
        InputKind::Scene => {
            let drawn = draw.draw(Some(input))?;
            emitted(&*drawn.renderer, notes)
        }
    }
}

/// A renderer's stream emitted into memory and read back as a trace, and its size in
/// bytes; with `notes`, where each instruction came from too (the renderer composes its
/// notes only for a writer that keeps them).
pub fn emitted(
    renderer: &dyn cwisim_render::Renderer,
    notes: bool,
) -> Result<(Box<dyn TraceRead>, u64), CliError> {
    let header = renderer.header();
    let in_memory = |e| CliError::Internal(format!("encoding a stream in memory: {e}"));
    let mut bytes = Vec::new();
    let writer = BinaryWriter::new(&mut bytes, &header).map_err(in_memory)?;
    let table = if notes {
        let mut taker = NoteTaker::new(writer);
        cwisim_render::emit(renderer, &mut taker)?;
        Some(taker.into_parts().1)
    } else {
        let mut writer = writer;
        cwisim_render::emit(renderer, &mut writer)?;
        None
    };
    let size = bytes.len() as u64;
    let reader = BinaryReader::new(BufReader::new(Cursor::new(bytes)))?;
    Ok(match table {
        Some(table) => (Box::new(Annotated::new(reader, table)), size),
        None => (Box::new(reader), size),
    })
}
