//! `cwisim convert`: re-encode a trace, streaming, one instruction at a time.

use crate::error::CliError;
use crate::files::{write_atomic, Io};
use clap::Args;
use cwisim_isa::{Encoding, FileReader, TraceRead};
use std::path::{Path, PathBuf};

/// The arguments of `cwisim convert`.
#[derive(Args, Clone, Debug, PartialEq, Eq)]
pub struct ConvertArgs {
    /// The trace to read: .cwt, .jsonl or .cwb.
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// The trace to write: .cwt, .jsonl or .cwb (replaced if it exists). Given as
    /// `-o OUT` like every command's output, or second, as `cwisim convert IN OUT`.
    #[arg(
        short = 'o',
        long = "output",
        value_name = "OUT",
        required_unless_present = "out",
        conflicts_with = "out"
    )]
    pub output: Option<PathBuf>,
    /// The trace to write, as the second argument (the same as `-o OUT`).
    #[arg(value_name = "OUT", hide = true)]
    pub out: Option<PathBuf>,
}

impl ConvertArgs {
    /// The trace to write, however it was given.
    pub fn output(&self) -> Result<&Path, CliError> {
        self.output
            .as_deref()
            .or(self.out.as_deref())
            .ok_or_else(|| CliError::Usage("convert needs the trace to write: -o OUT".into()))
    }
}

/// Runs `cwisim convert`. Returns the number of instructions copied.
pub fn run(args: &ConvertArgs) -> Result<u64, CliError> {
    convert(&args.input, args.output()?)
}

/// Copies every instruction of the trace `input` into a new trace `output`, each in the
/// encoding its extension names. Every instruction is checked on the way; `output` is
/// written all-or-nothing, so a malformed input leaves no partial file. The notes of the
/// instructions (where each came from: the comment lines directly above an instruction
/// of a `.cwt`, `"note"` in a `.jsonl`; `cwisim_isa::note`) are kept when `output`'s
/// encoding carries them (`.cwt`, `.jsonl`; `.cwb` carries none); other comments are
/// not.
pub fn convert(input: &Path, output: &Path) -> Result<u64, CliError> {
    Encoding::from_path(input)?;
    let out_encoding = crate::files::trace_output_encoding(output)?;
    Io::new()
        .input("trace being read (IN)", Some(input))
        .output("OUT", Some(output))
        .check()?;
    let mut reader = FileReader::open(input)?;
    let header = *reader.header();
    let mut count = 0;
    write_atomic(output, |out| {
        let io_err = |e| CliError::write(output, e);
        let mut writer = out_encoding.writer(out, &header).map_err(io_err)?;
        let notes = writer.wants_comments();
        let mut last_note = None;
        while let Some(instr) = reader.next_instruction()? {
            if notes {
                // each note once, before the first instruction it covers
                let note = reader.note();
                if let Some(n) = note.filter(|n| last_note != Some(n.serial)) {
                    writer.comment(n.text).map_err(io_err)?;
                }
                last_note = note.map(|n| n.serial);
            }
            writer.write(&instr).map_err(io_err)?;
            count += 1;
        }
        writer.finish().map_err(io_err)
    })?;
    Ok(count)
}
