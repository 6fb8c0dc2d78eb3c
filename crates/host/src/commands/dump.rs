//! `cwisim dump`: a trace in the text form, every instruction annotated with its number,
//! its scanline and the cycles the bus started issuing it and handed it to the array,
//! and headed by its note (where it came from: the renderer's `# row 3 trapezium 4
//! (polygon 2): case 8: …`) as the trace has it.
//!
//! The output is itself a valid `.cwt` trace (annotations are trailing comments, and the
//! scanline markers are set apart by a blank line, so that only the notes are notes), so
//! `cwisim dump t.cwb > t.cwt` disassembles, and the dump of a `.cwt` reads back with its
//! notes.

use super::MachineArgs;
use crate::error::CliError;
use crate::progress::Progress;
use crate::range::{parse_range, Range};
use clap::Args;
use cwisim_isa::text::format_header;
use cwisim_isa::{Instruction, NoteTable};
use cwisim_study::inspect::dump_line;
use cwisim_study::provenance::{comment_lines, NoteRecorder};
use cwisim_study::until::UntilLine;
use cwisim_xproc::{replay_probed_from, NullSink, Probe, StepFrom};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::io::Write;
use std::path::PathBuf;

/// The arguments of `cwisim dump`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct DumpArgs {
    /// The trace (.cwt, .jsonl, .cwb), or a scene (a .json file or an embedded name:
    /// `cwisim scenes`) drawn with the drawing options below, as `render` draws it.
    #[arg(value_name = "TRACE|SCENE")]
    pub trace: PathBuf,
    /// Only these scanlines: N, A..B (B not included), A..=B or A.. (to the end).
    #[arg(long, value_name = "RANGE", value_parser = parse_range)]
    pub lines: Option<Range>,
    /// Only the scanlines of these frames, in the same syntax (frames of the trace header's
    /// lines per frame).
    #[arg(long, value_name = "RANGE", value_parser = parse_range, conflicts_with = "lines")]
    pub frames: Option<Range>,
    /// The machine model (for the cycles).
    #[command(flatten)]
    pub machine: MachineArgs,
    /// How to draw a scene (refused with a trace).
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: crate::draw::DrawArgs,
}

/// Prints each instruction when its token enters the array (the bus hands instructions
/// over in order, so a queue pairs issue and entry), headed by its note when a new one
/// covers it.
struct Printer<'o> {
    out: &'o mut dyn Write,
    lines: Range,
    pending: VecDeque<(u64, u64, u64, Instruction)>, // (index, line, begin, instruction)
    current_line: Option<u64>,
    /// The notes of the instructions read, by index (an instruction is read before its
    /// token enters the array).
    notes: &'o RefCell<NoteTable>,
    /// The serial of the note of the last instruction printed.
    last_note: Option<u64>,
    error: Option<std::io::Error>,
}

impl Printer<'_> {
    fn print(
        &mut self,
        index: u64,
        line: u64,
        issue: u64,
        enter: u64,
        instr: &Instruction,
    ) -> std::io::Result<()> {
        if self.current_line != Some(line) {
            // set apart from a note below: read back, it is a remark
            writeln!(self.out, "# --- scanline {line}\n")?;
            self.current_line = Some(line);
            // no note covers two scanlines: those before are done with
            self.notes.borrow_mut().forget_before(index);
        }
        let cell = self.notes;
        let notes = cell.borrow();
        let note = notes.get(index);
        if let Some(n) = note.filter(|n| self.last_note != Some(n.serial)) {
            for l in comment_lines(n.text) {
                writeln!(self.out, "{l}")?;
            }
        }
        self.last_note = note.map(|n| n.serial);
        writeln!(self.out, "{}", dump_line(index, line, issue, enter, instr))
    }
}

impl Probe for Printer<'_> {
    fn issue(&mut self, cycle: u64, index: u64, line: u64, instr: &Instruction) {
        self.pending.push_back((index, line, cycle, instr.clone()));
    }

    fn enter(&mut self, cycle: u64, index: u64) {
        let Some((i, line, begin, instr)) = self.pending.pop_front() else {
            return;
        };
        debug_assert_eq!(i, index, "tokens enter in issue order");
        if self.error.is_some() || !self.lines.contains(line) {
            return;
        }
        if let Err(e) = self.print(index, line, begin, cycle, &instr) {
            self.error = Some(e);
        }
    }
}

/// Runs `cwisim dump`.
pub fn run(args: &DumpArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    crate::input::drawing_applies(&args.draw, &[Some(&args.trace)])?;
    let machine = args.machine.load()?;
    let (mut file, size) = crate::input::open_noted(&args.trace, &args.draw)?;
    let header = *file.header();
    let lines =
        Range::selection(args.lines, args.frames, u64::from(header.lines)).unwrap_or(Range::ALL);
    writeln!(stdout, "{}", format_header(&header)).map_err(CliError::Stdout)?;
    writeln!(
        stdout,
        "# cycles of the bus: `issue` = it starts issuing, `enter` = the token enters processor 0"
    )
    .map_err(CliError::Stdout)?;
    let notes = RefCell::new(NoteTable::new());
    let mut printer = Printer {
        out: stdout,
        lines,
        pending: VecDeque::new(),
        current_line: None,
        notes: &notes,
        last_note: None,
        error: None,
    };
    // the notes of the scanlines shown, by index, as the replay reads them
    let mut recorder = NoteRecorder::new(&mut *file, &notes, lines.first);
    // the scanlines before the first asked for run on the fast engine; only those shown
    // are stepped
    let mut reader = UntilLine::new(&mut recorder, lines.last);
    let mut bar = Progress::new(size, progress);
    replay_probed_from::<f64>(
        &mut reader,
        &machine,
        StepFrom::Scanline(lines.first),
        &mut printer,
        &mut NullSink,
        &mut |bytes| bar.update(bytes),
    )?;
    drop(bar);
    let output = reader.lines_read();
    if let Some(e) = printer.error {
        return Err(CliError::Stdout(e));
    }
    // the rest of the file, checked though not shown: no success on a damaged trace
    file.check_to_end()?;
    if lines.first > 0 && lines.first >= output {
        return Err(CliError::Usage(format!(
            "--lines {lines}: {} outputs only {output} scanline(s){}",
            args.trace.display(),
            if output == 0 {
                String::new()
            } else {
                format!(" (0..={})", output - 1)
            }
        )));
    }
    Ok(())
}
