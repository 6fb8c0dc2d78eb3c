//! Choosing an encoding by file extension, and opening readers and writers on files.

use crate::binary::{BinaryReader, BinaryWriter};
use crate::error::{ErrorKind, Location, TraceError};
use crate::header::TraceHeader;
use crate::io::{TraceRead, TraceWrite};
use crate::jsonl::{JsonlReader, JsonlWriter};
use crate::opcode::Opcode;
use crate::text::{TextReader, TextWriter};
use std::fs::File;
use std::io::{self, BufReader, BufWriter, Read, Write};
use std::path::Path;

/// The three trace encodings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// `.cwt`: text.
    Text,
    /// `.jsonl`: JSON Lines.
    JsonLines,
    /// `.cwb`: binary.
    Binary,
}

impl Encoding {
    /// Every encoding with its extension.
    pub const ALL: [(Encoding, &'static str); 3] = [
        (Encoding::Text, "cwt"),
        (Encoding::JsonLines, "jsonl"),
        (Encoding::Binary, "cwb"),
    ];

    /// The encoding named by a path's extension.
    pub fn from_path(path: &Path) -> Result<Encoding, TraceError> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        Encoding::ALL
            .iter()
            .find(|(_, e)| *e == ext)
            .map(|(enc, _)| *enc)
            .ok_or_else(|| {
                TraceError::new(
                    ErrorKind::Encoding,
                    Location::File,
                    format!("unknown trace extension `.{ext}`; expected .cwt (text), .jsonl (JSON Lines) or .cwb (binary)"),
                )
                .in_file(path)
            })
    }

    /// A reader of this encoding over any byte stream.
    pub fn reader<'a, R: Read + 'a>(self, input: R) -> Result<Box<dyn TraceRead + 'a>, TraceError> {
        Ok(match self {
            Encoding::Text => Box::new(TextReader::new(BufReader::new(input))?),
            Encoding::JsonLines => Box::new(JsonlReader::new(BufReader::new(input))?),
            Encoding::Binary => Box::new(BinaryReader::new(BufReader::new(input))?),
        })
    }

    /// A writer of this encoding over any byte sink.
    pub fn writer<'a, W: Write + 'a>(
        self,
        out: W,
        header: &TraceHeader,
    ) -> io::Result<Box<dyn TraceWrite + 'a>> {
        Ok(match self {
            Encoding::Text => Box::new(TextWriter::new(out, header)?),
            Encoding::JsonLines => Box::new(JsonlWriter::new(out, header)?),
            Encoding::Binary => Box::new(BinaryWriter::new(out, header)?),
        })
    }
}

/// A reader on a trace file, by its extension. Errors name the file.
///
/// It also checks that the file holds the whole trace: a trace is a positive whole
/// number of frames of the header's `lines` scanlines, so its `Refresh` count is a
/// positive multiple of `lines`. A file that ends otherwise — every record whole, but cut
/// at a line's end, or left by a writer that stopped early — is refused when the end is
/// reached: the call that reaches it returns an [`ErrorKind::Incomplete`] error at
/// [`Location::End`] (`t.cwt: the trace ends after 65 scanlines, inside frame 0 (65 of
/// its 400 lines): it is incomplete (cut short?)`), unless [`Self::allow_incomplete`]
/// was called. The error is returned once; later reads return the end again (`None`,
/// `0`), and [`Self::completeness`] and [`Self::check_to_end`] still report it.
/// A caller that stops reading early calls [`Self::check_to_end`] before it claims
/// success.
pub struct FileReader {
    inner: Box<dyn TraceRead>,
    path: std::path::PathBuf,
    size: u64,
    refreshes: u64,
    allow_incomplete: bool,
    completeness: Completeness,
}

/// Whether a [`FileReader`] has found its trace whole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Completeness {
    /// The end has not been reached yet.
    Reading,
    /// The trace ended after a positive whole number of frames.
    Complete,
    /// The trace ended short of a whole frame (refused unless allowed).
    Incomplete(Incomplete),
}

/// Where a trace that is not a whole number of frames ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Incomplete {
    /// The scanlines the trace holds (its `Refresh` count, over the whole trace); the
    /// last one reached is `scanlines - 1`, counted from 0 as `--lines` counts them.
    pub scanlines: u64,
    /// The scanlines per frame the header announces (its `lines`).
    pub lines_per_frame: u32,
}

impl Incomplete {
    /// The frame the trace ends inside, counted from 0.
    pub fn frame(&self) -> u64 {
        self.scanlines / u64::from(self.lines_per_frame.max(1))
    }

    /// The scanlines of [`Self::frame`] the trace holds (fewer than a frame's).
    pub fn lines_of_frame(&self) -> u64 {
        self.scanlines % u64::from(self.lines_per_frame.max(1))
    }

    /// The refusal: this, at [`Location::End`], of kind [`ErrorKind::Incomplete`].
    pub fn error(&self) -> TraceError {
        TraceError::new(
            ErrorKind::Incomplete,
            Location::End,
            format!("{self}: it is incomplete (cut short?)"),
        )
    }
}

/// Where the trace ends, in one line: `the trace ends after 65 scanlines, inside frame 0
/// (65 of its 400 lines)`, or `the trace ends before its first scanline (no Refresh; the
/// header announces 400 lines per frame)`.
impl std::fmt::Display for Incomplete {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let lines = self.lines_per_frame;
        if self.scanlines == 0 {
            return write!(
                f,
                "the trace ends before its first scanline (no Refresh; the header announces {lines} line{} per frame)",
                if lines == 1 { "" } else { "s" }
            );
        }
        write!(
            f,
            "the trace ends after {} scanline{}, inside frame {} ({} of its {lines} lines)",
            self.scanlines,
            if self.scanlines == 1 { "" } else { "s" },
            self.frame(),
            self.lines_of_frame()
        )
    }
}

impl FileReader {
    /// Opens `path` and reads its header.
    pub fn open(path: &Path) -> Result<FileReader, TraceError> {
        let enc = Encoding::from_path(path)?;
        let file = File::open(path).map_err(|e| {
            TraceError::new(ErrorKind::Io, Location::File, format!("cannot open: {e}"))
                .in_file(path)
        })?;
        let size = file.metadata().map(|m| m.len()).unwrap_or(0);
        let inner = enc.reader(file).map_err(|e| e.in_file(path))?;
        Ok(FileReader {
            inner,
            path: path.to_path_buf(),
            size,
            refreshes: 0,
            allow_incomplete: false,
            completeness: Completeness::Reading,
        })
    }

    /// The file's size in bytes (for progress bars).
    pub fn size(&self) -> u64 {
        self.size
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Accepts a trace that ends short of a whole frame (`--keep-partial`): reaching its
    /// end is then no error, and [`Self::completeness`] says where it ended, for a warning.
    pub fn allow_incomplete(&mut self) {
        self.allow_incomplete = true;
    }

    /// The `Refresh` instructions read so far: the scanlines of the trace up to here.
    pub fn refreshes_read(&self) -> u64 {
        self.refreshes
    }

    /// Whether the trace was found whole: [`Completeness::Reading`] until its end is
    /// reached.
    pub fn completeness(&self) -> Completeness {
        self.completeness
    }

    /// The refusal of an incomplete trace, saying where the file ends (its byte count).
    fn refusal(&self, incomplete: &Incomplete) -> TraceError {
        let mut e = incomplete.error().in_file(&self.path);
        e.message.push_str(&format!(
            "; the file ends at byte {}",
            self.inner.bytes_read()
        ));
        e
    }

    /// The inner reader has reached the end: judges the trace the first time.
    fn reached_end(&mut self) -> Result<(), TraceError> {
        if self.completeness != Completeness::Reading {
            return Ok(());
        }
        let lines = self.inner.header().lines;
        if self.refreshes > 0 && self.refreshes.is_multiple_of(u64::from(lines)) {
            self.completeness = Completeness::Complete;
            return Ok(());
        }
        let incomplete = Incomplete {
            scanlines: self.refreshes,
            lines_per_frame: lines,
        };
        self.completeness = Completeness::Incomplete(incomplete);
        if self.allow_incomplete {
            Ok(())
        } else {
            Err(self.refusal(&incomplete))
        }
    }
}

impl TraceRead for FileReader {
    /// Reads the rest of the trace to its end without keeping it, checking every
    /// instruction and the trace's completeness: for a caller that stopped reading early
    /// (one scanline dumped, one processor's history), so that it never claims success
    /// on a damaged or truncated file. `Ok` at the end of a whole trace, or of an
    /// incomplete one after [`Self::allow_incomplete`] (then see [`Self::completeness`]);
    /// after the end it reports the same again.
    fn check_to_end(&mut self) -> Result<(), TraceError> {
        const CHUNK: usize = 4096;
        let mut scratch = Vec::with_capacity(CHUNK);
        while self.read_batch(&mut scratch, CHUNK)? > 0 {
            scratch.clear();
        }
        match self.completeness {
            Completeness::Incomplete(i) if !self.allow_incomplete => Err(self.refusal(&i)),
            _ => Ok(()),
        }
    }

    fn incomplete(&self) -> Option<Incomplete> {
        match self.completeness {
            Completeness::Incomplete(i) => Some(i),
            _ => None,
        }
    }

    fn header(&self) -> &TraceHeader {
        self.inner.header()
    }
    fn next_instruction(&mut self) -> Result<Option<crate::Instruction>, TraceError> {
        if self.completeness != Completeness::Reading {
            return Ok(None);
        }
        match self.inner.next_instruction() {
            Ok(Some(i)) => {
                self.refreshes += u64::from(i.op == Opcode::Refresh);
                Ok(Some(i))
            }
            Ok(None) => self.reached_end().map(|()| None),
            Err(e) => Err(e.in_file(&self.path)),
        }
    }
    fn location(&self) -> Location {
        self.inner.location()
    }
    fn bytes_read(&self) -> u64 {
        self.inner.bytes_read()
    }
    fn note(&self) -> Option<crate::Note<'_>> {
        self.inner.note()
    }
    fn read_batch(
        &mut self,
        out: &mut Vec<crate::Instruction>,
        max: usize,
    ) -> Result<usize, TraceError> {
        if self.completeness != Completeness::Reading {
            return Ok(0);
        }
        let start = out.len();
        let read = self.inner.read_batch(out, max);
        // branch-free over the batch: a compare and an add per instruction
        self.refreshes += out[start..]
            .iter()
            .map(|i| u64::from(i.op == Opcode::Refresh))
            .sum::<u64>();
        match read {
            Ok(0) => self.reached_end().map(|()| 0),
            Ok(n) => Ok(n),
            Err(e) => Err(e.in_file(&self.path)),
        }
    }
}

/// Creates `path` and a writer of the encoding its extension names.
pub fn create_trace(path: &Path, header: &TraceHeader) -> Result<Box<dyn TraceWrite>, TraceError> {
    let enc = Encoding::from_path(path)?;
    let file = File::create(path).map_err(|e| {
        TraceError::new(ErrorKind::Io, Location::File, format!("cannot create: {e}")).in_file(path)
    })?;
    enc.writer(BufWriter::new(file), header).map_err(|e| {
        TraceError::new(ErrorKind::Io, Location::File, format!("cannot write: {e}")).in_file(path)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::read_all;
    use crate::{Instruction, Intensity};
    use std::path::PathBuf;

    /// `scanlines` scanlines of a header of `lines` per frame, each an `Eval1` and a
    /// `Refresh`, then an `Eval1` the trace never outputs.
    fn trace(lines: u32, scanlines: u32) -> (TraceHeader, Vec<Instruction>) {
        let header = TraceHeader::new(8, lines, 1).unwrap();
        let mut v = Vec::new();
        for k in 0..scanlines {
            v.push(Instruction::eval1(
                0,
                8,
                Intensity::grey(f64::from(k) * 0.176),
            ));
            v.push(Instruction::refresh());
        }
        v.push(Instruction::eval1(1, 2, Intensity::grey(0.5)));
        (header, v)
    }

    /// Scratch files, removed when dropped.
    struct Scratch(Vec<PathBuf>);

    impl Drop for Scratch {
        fn drop(&mut self) {
            for p in &self.0 {
                std::fs::remove_file(p).ok();
            }
        }
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join("cwisim-isa-encoding");
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(format!("{}-{name}", std::process::id()))
    }

    /// Writes the trace to a fresh file of each encoding.
    fn files(name: &str, (header, instrs): &(TraceHeader, Vec<Instruction>)) -> Scratch {
        Scratch(
            Encoding::ALL
                .iter()
                .map(|(_, ext)| {
                    let path = scratch(&format!("{name}.{ext}"));
                    let mut w = create_trace(&path, header).unwrap();
                    for i in instrs {
                        w.write(i).unwrap();
                    }
                    w.finish().unwrap();
                    path
                })
                .collect(),
        )
    }

    fn by_instruction(r: &mut FileReader) -> Result<Vec<Instruction>, TraceError> {
        let mut v = Vec::new();
        while let Some(i) = r.next_instruction()? {
            v.push(i);
        }
        Ok(v)
    }

    #[test]
    fn a_trace_short_of_whole_frames_is_refused_at_its_end() {
        for (scanlines, said) in [
            (0, "the trace ends before its first scanline (no Refresh; the header announces 4 lines per frame)"),
            (1, "the trace ends after 1 scanline, inside frame 0 (1 of its 4 lines)"),
            (3, "the trace ends after 3 scanlines, inside frame 0 (3 of its 4 lines)"),
            (6, "the trace ends after 6 scanlines, inside frame 1 (2 of its 4 lines)"),
        ] {
            for path in &files(&format!("short-{scanlines}"), &trace(4, scanlines)).0 {
                let size = std::fs::metadata(path).unwrap().len();
                let want = format!(
                    "{}: {said}: it is incomplete (cut short?); the file ends at byte {size}",
                    path.display()
                );
                for batched in [true, false] {
                    let mut r = FileReader::open(path).unwrap();
                    let e = if batched {
                        read_all(&mut r).unwrap_err()
                    } else {
                        by_instruction(&mut r).unwrap_err()
                    };
                    assert_eq!(e.to_string(), want);
                    assert_eq!((e.kind, e.location), (ErrorKind::Incomplete, Location::End));
                    assert_eq!(e.path.as_deref(), Some(path.as_path()));
                    assert_eq!(r.refreshes_read(), u64::from(scanlines));
                    let reached = Incomplete {
                        scanlines: u64::from(scanlines),
                        lines_per_frame: 4,
                    };
                    assert_eq!(r.completeness(), Completeness::Incomplete(reached));
                    // once: then the end again, and the check says it again
                    assert_eq!(r.next_instruction().unwrap(), None);
                    assert_eq!(r.read_batch(&mut Vec::new(), 8).unwrap(), 0);
                    assert_eq!(r.check_to_end().unwrap_err(), e);
                }
            }
        }
    }

    #[test]
    fn whole_frames_pass() {
        for scanlines in [4, 8] {
            for path in &files(&format!("whole-{scanlines}"), &trace(4, scanlines)).0 {
                let mut r = FileReader::open(path).unwrap();
                assert_eq!(r.completeness(), Completeness::Reading);
                let v = read_all(&mut r).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(v, trace(4, scanlines).1);
                assert_eq!(r.refreshes_read(), u64::from(scanlines));
                assert_eq!(r.completeness(), Completeness::Complete);
                assert_eq!(r.read_batch(&mut Vec::new(), 8).unwrap(), 0);
                r.check_to_end().unwrap();
                let mut r = FileReader::open(path).unwrap();
                assert_eq!(by_instruction(&mut r).unwrap().len(), v.len());
            }
        }
    }

    #[test]
    fn allowed_an_incomplete_trace_reads_to_its_end_and_says_where() {
        for path in &files("allowed", &trace(4, 6)).0 {
            let mut r = FileReader::open(path).unwrap();
            r.allow_incomplete();
            assert_eq!(read_all(&mut r).unwrap(), trace(4, 6).1);
            let Completeness::Incomplete(reached) = r.completeness() else {
                panic!("{:?}", r.completeness());
            };
            assert_eq!((reached.scanlines, reached.lines_per_frame), (6, 4));
            assert_eq!((reached.frame(), reached.lines_of_frame()), (1, 2));
            assert_eq!(
                reached.to_string(),
                "the trace ends after 6 scanlines, inside frame 1 (2 of its 4 lines)"
            );
            r.check_to_end().unwrap();
        }
    }

    #[test]
    fn check_to_end_reads_and_judges_the_rest() {
        for (scanlines, whole) in [(8, true), (7, false), (5, false)] {
            for path in &files(&format!("rest-{scanlines}"), &trace(4, scanlines)).0 {
                let mut r = FileReader::open(path).unwrap();
                let mut head = Vec::new();
                r.read_batch(&mut head, 3).unwrap();
                assert_eq!(r.completeness(), Completeness::Reading);
                let checked = r.check_to_end();
                assert_eq!(checked.is_ok(), whole, "{}: {checked:?}", path.display());
                assert_eq!(r.refreshes_read(), u64::from(scanlines));
                if let Err(e) = checked {
                    assert_eq!(e.kind, ErrorKind::Incomplete);
                }
            }
        }
        // every instruction is checked, not only counted
        let bad = Scratch(vec![scratch("rest-bad.cwt")]);
        let path = &bad.0[0];
        std::fs::write(
            path,
            "cwisim-trace version=1 width=8 lines=2 channels=1\nRefresh\nRefresh\nEval1 0 4 0.\n",
        )
        .unwrap();
        let mut r = FileReader::open(path).unwrap();
        r.next_instruction().unwrap();
        let e = r.check_to_end().unwrap_err();
        assert_eq!(
            (e.kind, e.location),
            (
                ErrorKind::Syntax,
                Location::Line {
                    line: 4,
                    column: 13
                }
            )
        );
    }
}
