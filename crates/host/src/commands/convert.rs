//! `cwisim convert`: re-encode a trace, streaming, one instruction at a time.

use crate::error::CliError;
use crate::files::{write_atomic, Io};
use clap::Args;
use cwisim_isa::{Encoding, FileReader, TraceRead};
use std::io::Write;
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
    /// Print nothing on standard output (errors and warnings still go to standard error).
    #[arg(short, long)]
    pub quiet: bool,
}

/// What [`convert`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Converted {
    /// Instructions copied.
    pub instructions: u64,
    /// Notes of the input its output's encoding has no record for (`.cwb`), not written.
    pub notes_dropped: u64,
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

/// Runs `cwisim convert`: says what it wrote on `stdout` (unless `--quiet`), and on
/// `stderr` what of the input it could not write.
pub fn run(
    args: &ConvertArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<Converted, CliError> {
    let output = args.output()?;
    let done = convert(&args.input, output)?;
    if done.notes_dropped > 0 {
        // a lost warning is no reason to fail the run
        let _ = writeln!(
            stderr,
            "warning: {} note(s) of {} not written: .cwb has no record for them (.cwt and .jsonl keep them)",
            done.notes_dropped,
            args.input.display()
        );
    }
    if !args.quiet {
        let detail = format!("{} instruction(s)", done.instructions);
        if let Some(line) = crate::files::wrote_line(&[output], Some(&detail)) {
            writeln!(stdout, "{line}").map_err(CliError::Stdout)?;
        }
    }
    Ok(done)
}

/// Copies every instruction of the trace `input` into a new trace `output`, each in the
/// encoding its extension names. Every instruction is checked on the way; `output` is
/// written all-or-nothing, so a malformed input leaves no partial file. The notes of the
/// instructions (where each came from: the comment lines directly above an instruction
/// of a `.cwt`, `"note"` in a `.jsonl`; `cwisim_isa::note`) are kept when `output`'s
/// encoding carries them (`.cwt`, `.jsonl`; `.cwb` carries none: they are counted in
/// [`Converted::notes_dropped`]); other comments are not.
pub fn convert(input: &Path, output: &Path) -> Result<Converted, CliError> {
    Encoding::from_path(input)?;
    let out_encoding = crate::files::trace_output_encoding(output)?;
    Io::new()
        .input("trace being read (IN)", Some(input))
        .output("OUT", Some(output))
        .check()?;
    let mut reader = FileReader::open(input)?;
    let header = *reader.header();
    let mut count = 0;
    let mut dropped = 0;
    write_atomic(output, |out| {
        let io_err = |e| CliError::write(output, e);
        let mut writer = out_encoding.writer(out, &header).map_err(io_err)?;
        let notes = writer.wants_comments();
        let mut last_note = None;
        while let Some(instr) = reader.next_instruction()? {
            // each note once, before the first instruction it covers (or counted, when
            // the output has no record for it)
            let note = reader.note();
            if let Some(n) = note.filter(|n| last_note != Some(n.serial)) {
                if notes {
                    writer.comment(n.text).map_err(io_err)?;
                } else {
                    dropped += 1;
                }
            }
            last_note = note.map(|n| n.serial);
            writer.write(&instr).map_err(io_err)?;
            count += 1;
        }
        writer.finish().map_err(io_err)
    })?;
    Ok(Converted {
        instructions: count,
        notes_dropped: dropped,
    })
}
