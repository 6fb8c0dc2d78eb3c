//! The reader and writer traits every encoding implements, and the bounded line reader
//! the two text-based encodings share.

use crate::error::{ErrorKind, Location, TraceError};
use crate::header::TraceHeader;
use crate::instruction::Instruction;
use std::io::{self, BufRead};

/// The longest line the text and JSON Lines readers accept.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// A stream of instructions from a trace, in any encoding.
pub trait TraceRead {
    /// The trace's header (read when the reader was opened).
    fn header(&self) -> &TraceHeader;
    /// The next instruction, `None` at the end of the trace.
    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError>;
    /// Where the last instruction returned starts.
    fn location(&self) -> Location;
    /// Bytes consumed so far (for progress reports).
    fn bytes_read(&self) -> u64;
    /// Appends up to `max` (at least 1) of the next instructions to `out`; how many, 0
    /// at the end of the trace. The same instructions and faults as as many
    /// [`Self::next_instruction`]s (which is the default), in fewer calls: a reader may
    /// decode a run of them in one loop.
    fn read_batch(&mut self, out: &mut Vec<Instruction>, max: usize) -> Result<usize, TraceError> {
        let mut n = 0;
        while n < max.max(1) {
            match self.next_instruction()? {
                Some(i) => out.push(i),
                None => break,
            }
            n += 1;
        }
        Ok(n)
    }

    /// Reads the rest of the trace to its end without keeping it, checking every
    /// instruction (and, for a file, its completeness: `FileReader`): for a caller that
    /// stopped reading early (one scanline dumped, one processor's history), so that it
    /// never claims success on a damaged or truncated file. The default drains the reader.
    fn check_to_end(&mut self) -> Result<(), TraceError> {
        let mut scratch = Vec::with_capacity(4096);
        while self.read_batch(&mut scratch, 4096)? > 0 {
            scratch.clear();
        }
        Ok(())
    }

    /// Where the trace ended short of whole frames, once its end was reached by a reader
    /// that was allowed to accept that (`FileReader::allow_incomplete`, for
    /// `--keep-partial`); `None` for a whole trace, before the end, or for a reader that
    /// does not count frames (the default: a stream made in memory is whole by
    /// construction).
    fn incomplete(&self) -> Option<crate::Incomplete> {
        None
    }

    /// The note of the last instruction returned (by [`Self::next_instruction`]; after
    /// [`Self::read_batch`], of the batch's last): where it came from, as the trace says
    /// (see [`crate::note`] for which instructions a note covers). `None` when no note
    /// covers it, or for a reader of an encoding without notes (the default).
    fn note(&self) -> Option<crate::Note<'_>> {
        None
    }
}

/// Reads every remaining instruction.
pub fn read_all(reader: &mut dyn TraceRead) -> Result<Vec<Instruction>, TraceError> {
    let mut out = Vec::new();
    while reader.read_batch(&mut out, 4096)? > 0 {}
    Ok(out)
}

/// A destination for instructions: a trace file in some encoding, or anything that takes
/// a stream (the X-processor array, a counter, a renderer's test harness).
pub trait TraceWrite {
    /// Appends one instruction.
    fn write(&mut self, instr: &Instruction) -> io::Result<()>;
    /// The note of the next instruction written (where it came from; it covers that
    /// instruction and the ones after it up to the next note or `Refresh`: see
    /// [`crate::note`]). Several before one instruction make one note of several lines.
    /// Encodings without notes drop it (the default).
    fn comment(&mut self, _text: &str) -> io::Result<()> {
        Ok(())
    }
    /// Whether [`comment`](Self::comment) keeps anything: writers of notes may skip
    /// composing them when it does not (the default).
    fn wants_comments(&self) -> bool {
        false
    }
    /// Writes what ends the trace (footer, flush). Call once, last.
    fn finish(&mut self) -> io::Result<()>;
}

/// Collects the stream in memory, one [`Instruction`] per write (comments dropped).
impl TraceWrite for Vec<Instruction> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        self.push(instr.clone());
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Reads `\n`-terminated UTF-8 lines with a length limit, counting lines and bytes.
pub(crate) struct LineReader<R> {
    inner: R,
    line_no: u64,
    bytes: u64,
    raw: Vec<u8>,
}

impl<R: BufRead> LineReader<R> {
    pub(crate) fn new(inner: R) -> Self {
        LineReader {
            inner,
            line_no: 0,
            bytes: 0,
            raw: Vec::new(),
        }
    }

    pub(crate) fn bytes(&self) -> u64 {
        self.bytes
    }

    /// The next line without its terminator, or `None` at the end of the file.
    pub(crate) fn next_line(&mut self) -> Result<Option<(u64, &str)>, TraceError> {
        self.raw.clear();
        let start_line = self.line_no + 1;
        loop {
            let buf = match self.inner.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    return Err(TraceError::io(
                        Location::Line {
                            line: start_line,
                            column: 1,
                        },
                        &e,
                    ))
                }
            };
            if buf.is_empty() {
                break;
            }
            let (take, done) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (buf.len(), false),
            };
            self.raw.extend_from_slice(&buf[..take]);
            self.inner.consume(take);
            self.bytes += take as u64;
            if self.raw.len() > MAX_LINE_BYTES + 2 {
                return Err(TraceError::new(
                    ErrorKind::Limit,
                    Location::Line {
                        line: start_line,
                        column: 1,
                    },
                    format!("line is longer than the {MAX_LINE_BYTES}-byte limit"),
                ));
            }
            if done {
                break;
            }
        }
        if self.raw.is_empty() {
            return Ok(None);
        }
        self.line_no = start_line;
        if self.raw.last() == Some(&b'\n') {
            self.raw.pop();
            if self.raw.last() == Some(&b'\r') {
                self.raw.pop();
            }
        }
        match std::str::from_utf8(&self.raw) {
            Ok(s) => Ok(Some((start_line, s))),
            Err(e) => Err(TraceError::new(
                ErrorKind::Syntax,
                Location::Line {
                    line: start_line,
                    column: e.valid_up_to() as u64 + 1,
                },
                "invalid UTF-8; a text trace is UTF-8 text",
            )),
        }
    }
}
