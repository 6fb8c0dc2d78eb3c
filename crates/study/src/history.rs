//! One pixel's history: every instruction that reached processor `x` on scanline `y`,
//! with the registers before and after it acted (`cwisim history`), computed by the
//! cycle-stepped engine through a [`Probe`]. Only scanline `y` is stepped: the fast
//! engine runs the scanlines before it and hands its state over
//! ([`cwisim_xproc::replay_probed_numeric`]).
//!
//! Each visit's instruction keeps its provenance: the note the trace attaches to it
//! (`row 3 trapezium 4 (polygon 2): case 8: …`, [`crate::provenance`]), in the
//! [`History`]'s table by the visit's [`Visit::index`].

use crate::error::StudyError;
use crate::provenance::{comment_lines, NoteRecorder};
use crate::until::UntilLine;
use cwisim_isa::note::{Note, NoteTable};
use cwisim_isa::{Instruction, Opcode, TraceRead};
use cwisim_xproc::{
    replay_probed_numeric, Machine, NullSink, Numeric, Probe, ProcessorState, StepFrom,
};
use std::cell::RefCell;
use std::fmt::Write as _;

/// Replays `trace` up to scanline `y` and returns every visit of a token to processor
/// `x` on it. `Ok(Err(n))`: the trace outputs only `n` scanlines.
pub fn pixel_history(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    x: usize,
    y: u64,
) -> Result<Result<Vec<Visit>, u64>, StudyError> {
    let history = pixel_history_with_progress(trace, machine, &Numeric::F64, x, y, &mut |_| {})?;
    Ok(history.map(|h| h.visits))
}

/// A pixel's history: the visits, and where their instructions came from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct History {
    /// Every visit of a token to the processor on the scanline, in order.
    pub visits: Vec<Visit>,
    /// The notes of the scanline's instructions, by their index in the trace
    /// ([`Visit::index`]): see [`Self::provenance`].
    pub notes: NoteTable,
}

impl History {
    /// Where the instruction of a visit came from: the note the trace attaches to it
    /// (a renderer's `row 3 trapezium 4 (polygon 2): case 8: …`), if it has one. Visits
    /// of the instructions one note covers share its [`Note::serial`].
    pub fn provenance(&self, visit: &Visit) -> Option<Note<'_>> {
        self.notes.get(visit.index)
    }
}

/// [`pixel_history`] with registers of the format `numeric` (the values the history shows
/// are the registers' own, as `f64`), calling `progress` with the bytes of `trace` read so
/// far every few thousand instructions (and at the end): for a progress bar. The history
/// keeps the notes of the scanline's instructions ([`History::provenance`]).
pub fn pixel_history_with_progress(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    numeric: &Numeric,
    x: usize,
    y: u64,
    progress: &mut dyn FnMut(u64),
) -> Result<Result<History, u64>, StudyError> {
    let mut watch = Watch {
        x,
        y,
        visits: Vec::new(),
    };
    let notes = RefCell::new(NoteTable::new());
    let mut recorder = NoteRecorder::new(trace, &notes, y);
    let mut reader = UntilLine::new(&mut recorder, Some(y));
    replay_probed_numeric(
        &mut reader,
        machine,
        numeric,
        StepFrom::Scanline(y),
        &mut watch,
        &mut NullSink,
        progress,
    )?;
    let lines = reader.lines_read();
    if lines <= y {
        return Ok(Err(lines));
    }
    Ok(Ok(History {
        visits: watch.visits,
        notes: notes.into_inner(),
    }))
}

/// One visit of a token to the watched processor.
#[derive(Clone, Debug, PartialEq)]
pub struct Visit {
    /// The cycle the token arrived.
    pub cycle: u64,
    /// The instruction's index in the trace, from 0.
    pub index: u64,
    /// The instruction.
    pub instr: Instruction,
    /// Whether it addressed this processor (else its token only passed through).
    pub addressed: bool,
    /// The processor's registers and flags before it acted.
    pub before: ProcessorState,
    /// And after.
    pub after: ProcessorState,
}

impl Visit {
    /// Whether the processor changed.
    pub fn changed(&self) -> bool {
        self.before != self.after
    }

    /// What the visit amounted to, when not a plain action: `"passes through"`,
    /// `"suppressed: locked by Eval0"`, `"suppressed: masked by Dis"`.
    pub fn note(&self) -> Option<&'static str> {
        visit_note(self.instr.op, self.addressed, &self.before, &self.after)
    }
}

/// [`Visit::note`] of a visit of an `op` instruction's token, from its parts.
pub fn visit_note(
    op: Opcode,
    addressed: bool,
    before: &ProcessorState,
    after: &ProcessorState,
) -> Option<&'static str> {
    if !addressed {
        Some("passes through")
    } else if before == after
        && before.locked
        && matches!(
            op,
            Opcode::Eval0 | Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3
        )
    {
        Some("suppressed: locked by Eval0")
    } else if before.masked && !after.masked && before.acc == after.acc {
        Some("suppressed: masked by Dis")
    } else {
        None
    }
}

/// The lines `cwisim history` prints for one visit: the instruction with the cycle its
/// token arrived (and [`Visit::note`]), then the registers before and after.
pub fn visit_lines(v: &Visit) -> [String; 3] {
    let how = v.note().map_or_else(String::new, |n| format!("  ({n})"));
    [
        format!(
            "cycle {:>8}  #{:<6} {}{how}",
            v.cycle,
            v.index,
            cwisim_isa::text::format_instruction(&v.instr)
        ),
        format!("    before  {}", state(&v.before)),
        format!("    after   {}", state(&v.after)),
    ]
}

/// Whether `cwisim history` lists a visit (with `all`, every one; else those that
/// address the processor or change it).
pub fn shown(v: &Visit, all: bool) -> bool {
    all || v.addressed || v.changed()
}

/// The line after the visits: the value the scanline's `Refresh` shifted out (its
/// accumulator just before).
pub fn shifted_out_line(acc: &[f64]) -> String {
    format!("shifted out: {}", values(acc))
}

/// The last line when visits were left out.
pub fn hidden_line(hidden: usize) -> String {
    format!("# {hidden} more instruction(s) passed through without acting (--all lists them)")
}

/// Everything `cwisim history` prints after its heading: each shown visit's lines, headed
/// by the note of its instruction as the trace writes it (`# row 3 trapezium 4 (polygon
/// 2): case 8: …`, once above the visits of the instructions one note covers), the value
/// shifted out, and how many visits were left out. The `inspect` page holds the same
/// lines for every pixel of its window.
pub fn history_lines(history: &History, all: bool) -> Vec<String> {
    let visits = &history.visits;
    let mut out = Vec::new();
    let mut shown_count = 0;
    let mut last_note = None;
    for v in visits.iter().filter(|v| shown(v, all)) {
        shown_count += 1;
        let note = history.provenance(v);
        if let Some(n) = note.filter(|n| last_note != Some(n.serial)) {
            out.extend(comment_lines(n.text));
        }
        last_note = note.map(|n| n.serial);
        out.extend(visit_lines(v));
    }
    if let Some(r) = visits.iter().rev().find(|v| v.instr.op == Opcode::Refresh) {
        out.push(shifted_out_line(&r.before.acc));
    }
    let hidden = visits.len() - shown_count;
    if hidden > 0 {
        out.push(hidden_line(hidden));
    }
    out
}

struct Watch {
    x: usize,
    y: u64,
    visits: Vec<Visit>,
}

impl Probe for Watch {
    fn watches(&self, p: usize) -> bool {
        p == self.x
    }

    fn visit(
        &mut self,
        cycle: u64,
        _p: usize,
        index: u64,
        line: u64,
        instr: &Instruction,
        addressed: bool,
        before: &ProcessorState,
        after: &ProcessorState,
    ) {
        if line == self.y {
            self.visits.push(Visit {
                cycle,
                index,
                instr: instr.clone(),
                addressed,
                before: before.clone(),
                after: after.clone(),
            });
        }
    }
}

/// Values as the text trace writes them, comma-separated.
pub fn values(v: &[f64]) -> String {
    let mut out = String::new();
    write_values(&mut out, v);
    out
}

/// [`values`], appended to `out`.
pub fn write_values(out: &mut String, v: &[f64]) {
    for (k, x) in v.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        // as cwisim_isa::text::format_value writes it
        let _ = write!(out, "{x:?}");
    }
}

/// The registers and flags, one line: `acc=… I=… dI=… ddI=… [locked masked neg]`;
/// a preload register shows `-` when it holds no unconsumed value.
pub fn state(s: &ProcessorState) -> String {
    let mut out = String::new();
    write_state(&mut out, s);
    out
}

/// [`state`], appended to `out`.
pub fn write_state(out: &mut String, s: &ProcessorState) {
    out.push_str("acc=");
    write_values(out, &s.acc);
    for (k, name) in [" I=", " dI=", " ddI="].into_iter().enumerate() {
        out.push_str(name);
        if s.has[k] {
            write_values(out, &s.reg[k]);
        } else {
            out.push('-');
        }
    }
    out.push_str(" flags=");
    let flags = [
        (s.locked, "locked"),
        (s.masked, "masked"),
        (s.negative_enabled, "neg"),
    ];
    let mut any = false;
    for (_, name) in flags.iter().filter(|f| f.0) {
        if any {
            out.push(',');
        }
        out.push_str(name);
        any = true;
    }
    if !any {
        out.push('-');
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::window_tests::{machines, reader, trace};
    use cwisim_xproc::replay_probed;

    /// Each visit's instruction keeps the note the trace attaches to it; the lines show it
    /// once above the visits it covers; notes change nothing else.
    #[test]
    fn every_visit_keeps_its_note() {
        let noted = "cwisim-trace version=1 width=8 lines=2 channels=1
# row 0 trapezium 1 (polygon 0): case 8
Eval1 0 8 0.5
Refresh
# row 1 trapezium 1 (polygon 0): case 5
# a second line
Eval1 0 4 0.25
Eval1 2 4 0.25
Refresh
";
        let plain: String = noted
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| format!("{l}\n"))
            .collect();
        let machine = Machine::default();
        let read = |text: &str| {
            let mut r = cwisim_isa::text::TextReader::new(text.as_bytes()).unwrap();
            pixel_history_with_progress(&mut r, &machine, &Numeric::F64, 3, 1, &mut |_| {})
                .unwrap()
                .unwrap()
        };
        let h = read(noted);
        let notes: Vec<_> = h
            .visits
            .iter()
            .map(|v| h.provenance(v).map(|n| (n.serial, n.text)))
            .collect();
        let row1 = Some((1, "row 1 trapezium 1 (polygon 0): case 5\na second line"));
        assert_eq!(notes, [row1, row1, None]);
        // only the scanline's notes are kept
        assert_eq!(h.notes.len(), 1);
        let lines = history_lines(&h, false);
        assert_eq!(lines[0], "# row 1 trapezium 1 (polygon 0): case 5");
        assert_eq!(lines[1], "# a second line");
        assert!(lines[2].contains("#2      Eval1 0 4 0.25"), "{lines:?}");
        assert!(lines[5].contains("#3      Eval1 2 4 0.25"), "{lines:?}");
        assert!(lines.iter().filter(|l| l.starts_with("# ")).count() == 2);
        // without the notes: the same visits, the same lines but for the notes
        let bare = read(&plain);
        assert_eq!(bare.visits, h.visits);
        assert!(bare.notes.is_empty());
        assert_eq!(history_lines(&bare, false), lines[2..]);
    }

    /// The values are written as the text trace writes them.
    #[test]
    fn values_are_the_text_traces() {
        let v = [0.1, -0.0, 1e300, -2.5e-310, f64::NAN, f64::INFINITY, 3.0];
        let want: Vec<String> = v
            .iter()
            .map(|x| cwisim_isa::text::format_value(*x))
            .collect();
        assert_eq!(values(&v), want.join(","));
        assert_eq!(values(&[]), "");
    }

    /// Every pixel's history, with the scanlines before it on the fast engine, is the
    /// history a stepped run from the start of the trace gives.
    #[test]
    fn every_history_is_that_of_a_stepped_run_from_the_start() {
        let text = trace();
        for machine in machines() {
            for y in 0..13 {
                for x in 0..16 {
                    let windowed = pixel_history(&mut reader(&text), &machine, x, y).unwrap();
                    let mut watch = Watch {
                        x,
                        y,
                        visits: Vec::new(),
                    };
                    replay_probed::<f64>(&mut reader(&text), &machine, &mut watch, &mut NullSink)
                        .unwrap();
                    if y < 12 {
                        assert!(!watch.visits.is_empty());
                        assert_eq!(windowed, Ok(watch.visits), "({x}, {y})");
                    } else {
                        assert_eq!(windowed, Err(12));
                    }
                }
            }
        }
    }
}
