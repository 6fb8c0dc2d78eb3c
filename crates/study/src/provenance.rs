//! Where an instruction came from, kept through the study tools: the notes a trace
//! attaches to its instructions (`# row 3 trapezium 4 (polygon 2): case 8: …` above a
//! renderer's instructions in a `.cwt`; see [`cwisim_isa::note`] for the rule and the
//! encodings that carry them).
//!
//! The study tools replay a trace through a [`Probe`](cwisim_xproc::Probe), which names
//! each instruction by its index in the trace. A [`NoteRecorder`] between the trace and
//! the replay records the notes of the instructions it passes on into a [`NoteTable`] by
//! that index, so that a probe can look up the note of any instruction it is told of
//! (`cwisim dump` as it prints, `cwisim history` for each visit).

use cwisim_isa::note::{Note, NoteTable};
use cwisim_isa::{Instruction, Location, Opcode, TraceError, TraceHeader, TraceRead};
use std::cell::RefCell;

/// Passes `inner`'s instructions on, and records into `notes` the note of each one of
/// scanline `from_line` or later (scanlines counted by `Refresh`, from 0), by its index
/// in the trace (from 0: the index a probe is given, when the recorder reads the trace
/// from its start).
///
/// `notes` is shared: the probe of the replay that reads through the recorder looks
/// notes up in it while the replay runs (an instruction is read before it is issued).
pub struct NoteRecorder<'a> {
    inner: &'a mut dyn TraceRead,
    notes: &'a RefCell<NoteTable>,
    from_line: u64,
    index: u64,
    line: u64,
}

impl<'a> NoteRecorder<'a> {
    /// Records the notes of `inner`'s scanlines `from_line` and later into `notes`.
    pub fn new(
        inner: &'a mut dyn TraceRead,
        notes: &'a RefCell<NoteTable>,
        from_line: u64,
    ) -> NoteRecorder<'a> {
        NoteRecorder {
            inner,
            notes,
            from_line,
            index: 0,
            line: 0,
        }
    }
}

impl TraceRead for NoteRecorder<'_> {
    fn header(&self) -> &TraceHeader {
        self.inner.header()
    }

    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        let next = self.inner.next_instruction()?;
        if let Some(instr) = &next {
            if self.line >= self.from_line {
                if let Some(note) = self.inner.note() {
                    self.notes.borrow_mut().record(self.index, note);
                }
            }
            self.index += 1;
            self.line += u64::from(instr.op == Opcode::Refresh);
        }
        Ok(next)
    }

    fn location(&self) -> Location {
        self.inner.location()
    }

    fn bytes_read(&self) -> u64 {
        self.inner.bytes_read()
    }

    fn check_to_end(&mut self) -> Result<(), TraceError> {
        self.inner.check_to_end()
    }

    fn incomplete(&self) -> Option<cwisim_isa::Incomplete> {
        self.inner.incomplete()
    }

    fn note(&self) -> Option<Note<'_>> {
        self.inner.note()
    }
}

/// A note as the text trace writes it: each of its lines as a comment, `# line`.
pub fn comment_lines(text: &str) -> impl Iterator<Item = String> + '_ {
    text.split('\n').map(|l| format!("# {l}"))
}

/// What a renderer's note of one trapezium row says (van Rij's DO_FILL, and the renderers
/// that fill their pieces with it): `row R trapezium T (polygon P): case C: …`, or
/// `… (polygon P): point-sampled …`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FillNote {
    /// The pixel row.
    pub row: u64,
    /// The trapezium, as the renderer numbers them.
    pub trapezium: u64,
    /// The polygon the trapezium was cut from (for a patch renderer, the piece of a
    /// patch).
    pub polygon: u64,
    /// The DO_FILL case (1–12); `None` for a point-sampled row.
    pub case: Option<u8>,
}

/// The fields of a renderer's note of one trapezium row, when `text` is one (its first
/// line); `None` for any other note.
pub fn fill_note(text: &str) -> Option<FillNote> {
    let line = text.split('\n').next()?;
    let rest = line.strip_prefix("row ")?;
    let (row, rest) = rest.split_once(" trapezium ")?;
    let (trapezium, rest) = rest.split_once(" (polygon ")?;
    let (polygon, rest) = rest.split_once("): ")?;
    let case = match rest.strip_prefix("case ") {
        Some(c) => Some(c.split(':').next()?.parse().ok()?),
        None if rest.starts_with("point-sampled") => None,
        None => return None,
    };
    Some(FillNote {
        row: row.parse().ok()?,
        trapezium: trapezium.parse().ok()?,
        polygon: polygon.parse().ok()?,
        case,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::text::TextReader;

    const TRACE: &str = "cwisim-trace version=1 width=8 lines=2 channels=1
# row 0 trapezium 1 (polygon 0): case 5: pixel 2 sequence 3..=4
Eval1 2 1 0.5
Eval3 3 2 0.25 0.125 0.0
Refresh
# row 1 trapezium 2 (polygon 1): point-sampled span 0..=3
Eval2 0 4 0.5 0.0
Refresh
";

    #[test]
    fn the_recorder_keeps_the_notes_of_the_scanlines_asked_for_by_index() {
        for (from, expected) in [
            (
                0,
                vec![
                    (
                        0..2,
                        "row 0 trapezium 1 (polygon 0): case 5: pixel 2 sequence 3..=4",
                    ),
                    (
                        3..4,
                        "row 1 trapezium 2 (polygon 1): point-sampled span 0..=3",
                    ),
                ],
            ),
            (
                1,
                vec![(
                    3..4,
                    "row 1 trapezium 2 (polygon 1): point-sampled span 0..=3",
                )],
            ),
            (2, vec![]),
        ] {
            let mut file = TextReader::new(TRACE.as_bytes()).unwrap();
            let notes = RefCell::new(NoteTable::new());
            let mut r = NoteRecorder::new(&mut file, &notes, from);
            let all = cwisim_isa::io::read_all(&mut r).unwrap();
            assert_eq!(all.len(), 5);
            let notes = notes.into_inner();
            let got: Vec<_> = notes.runs().map(|(range, n)| (range, n.text)).collect();
            assert_eq!(got, expected);
        }
    }

    #[test]
    fn a_renderers_note_names_its_polygon_and_case() {
        assert_eq!(
            fill_note("row 54 trapezium 867 (polygon 417): case 3: pixel 216 pixel 217"),
            Some(FillNote {
                row: 54,
                trapezium: 867,
                polygon: 417,
                case: Some(3)
            })
        );
        assert_eq!(
            fill_note("row 1 trapezium 2 (polygon 1): point-sampled span 0..=3"),
            Some(FillNote {
                row: 1,
                trapezium: 2,
                polygon: 1,
                case: None
            })
        );
        assert_eq!(fill_note("first pixel of the left edge"), None);
        assert_eq!(fill_note("row x trapezium 2 (polygon 1): case 4:"), None);
    }

    #[test]
    fn comment_lines_are_one_per_line() {
        assert_eq!(
            comment_lines("a\n\nb").collect::<Vec<_>>(),
            ["# a", "# ", "# b"]
        );
    }
}
