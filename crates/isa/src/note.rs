//! Notes: where an instruction came from, as the trace says it.
//!
//! A renderer that writes a `.cwt` trace puts a comment above each group of instructions
//! it emits for one piece of the picture (`# row 3 trapezium 4 (polygon 2): case 8: …`,
//! van Rij's DO_FILL case and its stretches). That comment is the group's **note**: the
//! provenance of its instructions, which the study tools (`cwisim dump`, `history`) show.
//!
//! The rule, the same in every encoding that carries notes: a note is *attached* to one
//! instruction and **covers** it and the instructions after it, up to the next
//! instruction with a note of its own or the next `Refresh`; a `Refresh` is covered only
//! by a note attached to itself, and no note covers an instruction after a `Refresh`
//! until a new one is attached. So a note never covers two scanlines.
//!
//! * `.cwt`: the comment lines directly above an instruction line (after the header line,
//!   no blank line between) are its note, one line of the note each, without the `#` and
//!   the one space after it. A trailing comment (`Eval1 0 4 0.5 # …`) and a comment block
//!   followed by a blank line are remarks, not notes.
//! * `.jsonl`: an optional `"note"` string on the record it is attached to.
//! * `.cwb`: none (the format has no place for them); a stream held in memory as `.cwb`
//!   keeps its notes beside it in a [`NoteTable`] ([`NoteTaker`], [`Annotated`]).
//!
//! A note never changes what is executed: the instructions read are the same with or
//! without them.
//!
//! A reader hands them over through [`crate::TraceRead::note`]; a writer takes them
//! through [`crate::TraceWrite::comment`] (called before the instruction the note is
//! attached to).

use crate::error::{Location, TraceError};
use crate::header::TraceHeader;
use crate::instruction::Instruction;
use crate::io::{TraceRead, TraceWrite};
use crate::opcode::Opcode;
use std::io;

/// The note of an instruction, as a reader hands it over.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Note<'a> {
    /// Which note of the trace, counted from 0 in the order they are attached: the
    /// instructions one note covers share it, and a writer writes the note once, before
    /// the first of them.
    pub serial: u64,
    /// The text: its lines joined by `\n`.
    pub text: &'a str,
}

/// A note's text as every encoding keeps it: its lines (split at `\n`, each without a
/// `\r` at its end, which the text form cannot keep) joined by `\n`. An empty text is
/// one empty line.
pub fn normalized(text: &str) -> String {
    if !text.contains('\r') {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len());
    for (k, line) in note_lines(text).enumerate() {
        if k > 0 {
            out.push('\n');
        }
        out.push_str(line);
    }
    out
}

/// The lines of a note's text, as [`normalized`] sees them.
pub(crate) fn note_lines(text: &str) -> impl Iterator<Item = &str> {
    text.split('\n')
        .map(|line| line.strip_suffix('\r').unwrap_or(line))
}

/// The coverage rule of the module documentation, step by step: which note covers each
/// instruction of a stream read or written in order.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Scope {
    /// Notes attached so far.
    attached: u64,
    /// A note covers the next instruction unless it is a `Refresh` or has its own.
    in_force: bool,
    /// The last instruction is covered (by note `attached - 1`).
    covered: bool,
}

impl Scope {
    /// The next instruction, `op`, with a note of its own (`attached`) or not: whether a
    /// note covers it.
    #[inline]
    pub(crate) fn step(&mut self, op: Opcode, attached: bool) -> bool {
        let refresh = op == Opcode::Refresh;
        if attached {
            self.attached += 1;
            self.covered = true;
            self.in_force = !refresh;
        } else {
            self.covered = self.in_force && !refresh;
            self.in_force &= !refresh;
        }
        self.covered
    }

    /// The serial of the note covering the last instruction, if one does.
    #[inline]
    pub(crate) fn serial(&self) -> Option<u64> {
        self.covered.then(|| self.attached - 1)
    }
}

/// One note and the run of consecutive instructions it covers.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Run {
    first: u64,
    end: u64,
    serial: u64,
    text: Box<str>,
}

/// The notes of a stream by instruction index (from 0, in the stream's order): each note
/// with the run of instructions it covers. One entry per note, whatever the number of
/// instructions it covers; looked up by binary search.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NoteTable {
    runs: Vec<Run>,
}

impl NoteTable {
    /// An empty table.
    pub fn new() -> NoteTable {
        NoteTable::default()
    }

    /// Records that `note` covers instruction `index`. Indices are recorded in increasing
    /// order; an index that follows the last one recorded under the same serial extends
    /// that note's run, any other starts a new run.
    ///
    /// # Panics
    /// If `index` is not after the last index recorded.
    pub fn record(&mut self, index: u64, note: Note<'_>) {
        if let Some(last) = self.runs.last_mut() {
            assert!(
                index >= last.end,
                "notes are recorded in the stream's order"
            );
            if last.serial == note.serial && last.end == index {
                last.end += 1;
                return;
            }
        }
        self.runs.push(Run {
            first: index,
            end: index + 1,
            serial: note.serial,
            text: note.text.into(),
        });
    }

    /// The note covering instruction `index`, if any.
    pub fn get(&self, index: u64) -> Option<Note<'_>> {
        let k = self.runs.partition_point(|r| r.end <= index);
        self.runs.get(k).filter(|r| r.first <= index).map(|r| Note {
            serial: r.serial,
            text: &r.text,
        })
    }

    /// Every note with the instructions it covers (`first..end`), in the stream's order.
    pub fn runs(&self) -> impl Iterator<Item = (std::ops::Range<u64>, Note<'_>)> + '_ {
        self.runs.iter().map(|r| {
            (
                r.first..r.end,
                Note {
                    serial: r.serial,
                    text: &r.text,
                },
            )
        })
    }

    /// The number of runs held.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether no note is held.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Drops the runs that end before instruction `index` (a reader that has shown them,
    /// keeping its memory to what it may still ask for).
    pub fn forget_before(&mut self, index: u64) {
        let k = self.runs.partition_point(|r| r.end <= index);
        self.runs.drain(..k);
    }
}

/// A writer that passes every instruction on to `inner` and keeps the notes it is given
/// ([`TraceWrite::comment`]) in a [`NoteTable`], by instruction index: for an encoding
/// that carries no notes (a `.cwb` stream held in memory), read back with [`Annotated`].
/// It asks for notes ([`TraceWrite::wants_comments`]); `inner` is not given them.
pub struct NoteTaker<W> {
    inner: W,
    table: NoteTable,
    scope: Scope,
    pending: Option<String>,
    index: u64,
}

impl<W: TraceWrite> NoteTaker<W> {
    /// Takes the notes of what is written to `inner`.
    pub fn new(inner: W) -> NoteTaker<W> {
        NoteTaker {
            inner,
            table: NoteTable::new(),
            scope: Scope::default(),
            pending: None,
            index: 0,
        }
    }

    /// The writer and the notes taken.
    pub fn into_parts(self) -> (W, NoteTable) {
        (self.inner, self.table)
    }
}

impl<W: TraceWrite> TraceWrite for NoteTaker<W> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        self.inner.write(instr)?;
        let attached = self.pending.take();
        if self.scope.step(instr.op, attached.is_some()) {
            let serial = self.scope.serial().expect("covered");
            match &attached {
                Some(text) => self.table.record(self.index, Note { serial, text }),
                // covered without a note of its own: the instruction before was covered
                // by the same note, and its run goes on
                None => self.table.runs.last_mut().expect("the note in force").end += 1,
            }
        }
        self.index += 1;
        Ok(())
    }

    fn comment(&mut self, text: &str) -> io::Result<()> {
        append_note(&mut self.pending, text);
        Ok(())
    }

    fn wants_comments(&self) -> bool {
        true
    }

    fn finish(&mut self) -> io::Result<()> {
        self.inner.finish()
    }
}

/// Adds `text` (normalized) to the note waiting for the next instruction, a line after
/// what it holds.
pub(crate) fn append_note(pending: &mut Option<String>, text: &str) {
    let text = normalized(text);
    match pending {
        Some(p) => {
            p.push('\n');
            p.push_str(&text);
        }
        None => *pending = Some(text),
    }
}

/// A reader that hands over `inner`'s instructions with the notes of a [`NoteTable`]
/// (by instruction index, from 0): a stream kept in an encoding without notes, with the
/// notes a [`NoteTaker`] took when it was written.
pub struct Annotated<R> {
    inner: R,
    table: NoteTable,
    /// Instructions returned so far.
    index: u64,
}

impl<R: TraceRead> Annotated<R> {
    /// `inner` with the notes of `table`.
    pub fn new(inner: R, table: NoteTable) -> Annotated<R> {
        Annotated {
            inner,
            table,
            index: 0,
        }
    }
}

impl<R: TraceRead> TraceRead for Annotated<R> {
    fn header(&self) -> &TraceHeader {
        self.inner.header()
    }

    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        let next = self.inner.next_instruction()?;
        self.index += u64::from(next.is_some());
        Ok(next)
    }

    fn location(&self) -> Location {
        self.inner.location()
    }

    fn bytes_read(&self) -> u64 {
        self.inner.bytes_read()
    }

    fn read_batch(&mut self, out: &mut Vec<Instruction>, max: usize) -> Result<usize, TraceError> {
        let n = self.inner.read_batch(out, max)?;
        self.index += n as u64;
        Ok(n)
    }

    fn check_to_end(&mut self) -> Result<(), TraceError> {
        self.inner.check_to_end()
    }

    fn incomplete(&self) -> Option<crate::Incomplete> {
        self.inner.incomplete()
    }

    fn note(&self) -> Option<Note<'_>> {
        self.index.checked_sub(1).and_then(|i| self.table.get(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::binary::{BinaryReader, BinaryWriter};
    use crate::Intensity;

    fn eval(x: u32) -> Instruction {
        Instruction::eval1(x, 1, Intensity::grey(0.5))
    }

    /// Which note (by text) covers each instruction of a stream written with `notes`
    /// before some of them.
    fn covered(stream: &[(Option<&str>, Instruction)]) -> Vec<Option<String>> {
        let header = TraceHeader::new(8, 4, 1).unwrap();
        let mut bytes = Vec::new();
        let mut taker = NoteTaker::new(BinaryWriter::new(&mut bytes, &header).unwrap());
        for (note, i) in stream {
            if let Some(n) = note {
                taker.comment(n).unwrap();
            }
            taker.write(i).unwrap();
        }
        taker.finish().unwrap();
        let (w, table) = taker.into_parts();
        drop(w);
        let mut r = Annotated::new(BinaryReader::new(&bytes[..]).unwrap(), table);
        let mut out = Vec::new();
        while r.next_instruction().unwrap().is_some() {
            out.push(r.note().map(|n| n.text.to_string()));
        }
        out
    }

    #[test]
    fn a_note_covers_up_to_the_next_note_or_refresh() {
        let r = Instruction::refresh;
        let got = covered(&[
            (None, eval(0)),
            (Some("a"), eval(1)),
            (None, eval(2)),
            (Some("b\nsecond line"), eval(3)),
            (None, r()),
            (None, eval(4)),
            (Some("c"), r()),
            (None, eval(5)),
        ]);
        let s = |t: &str| Some(t.to_string());
        assert_eq!(
            got,
            [
                None,
                s("a"),
                s("a"),
                s("b\nsecond line"),
                None,
                None,
                s("c"),
                None
            ]
        );
    }

    #[test]
    fn the_table_finds_runs_and_forgets() {
        let mut t = NoteTable::new();
        for (i, serial) in [(2, 0), (3, 0), (4, 1), (7, 1), (8, 2)] {
            t.record(
                i,
                Note {
                    serial,
                    text: ["x", "y", "z"][serial as usize],
                },
            );
        }
        let texts: Vec<_> = (0..10).map(|i| t.get(i).map(|n| n.text)).collect();
        assert_eq!(
            texts,
            [
                None,
                None,
                Some("x"),
                Some("x"),
                Some("y"),
                None,
                None,
                Some("y"),
                Some("z"),
                None
            ]
        );
        // one note over two runs keeps its serial
        assert_eq!(t.get(4).unwrap().serial, t.get(7).unwrap().serial);
        assert_eq!(t.len(), 4);
        t.forget_before(5);
        assert_eq!(t.len(), 2);
        assert_eq!(t.get(3), None);
        assert_eq!(t.get(8).unwrap().text, "z");
    }

    #[test]
    fn texts_are_kept_as_lines() {
        assert_eq!(normalized(""), "");
        assert_eq!(normalized("a\r\nb\n"), "a\nb\n");
        assert_eq!(normalized("a\rb\r"), "a\rb");
        assert_eq!(note_lines("a\n").collect::<Vec<_>>(), ["a", ""]);
    }
}
