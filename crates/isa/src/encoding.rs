//! Choosing an encoding by file extension, and opening readers and writers on files.

use crate::binary::{BinaryReader, BinaryWriter};
use crate::error::{ErrorKind, Location, TraceError};
use crate::header::TraceHeader;
use crate::io::{TraceRead, TraceWrite};
use crate::jsonl::{JsonlReader, JsonlWriter};
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
pub struct FileReader {
    inner: Box<dyn TraceRead>,
    path: std::path::PathBuf,
    size: u64,
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
}

impl TraceRead for FileReader {
    fn header(&self) -> &TraceHeader {
        self.inner.header()
    }
    fn next_instruction(&mut self) -> Result<Option<crate::Instruction>, TraceError> {
        self.inner
            .next_instruction()
            .map_err(|e| e.in_file(&self.path))
    }
    fn location(&self) -> Location {
        self.inner.location()
    }
    fn bytes_read(&self) -> u64 {
        self.inner.bytes_read()
    }
    fn read_batch(
        &mut self,
        out: &mut Vec<crate::Instruction>,
        max: usize,
    ) -> Result<usize, TraceError> {
        self.inner
            .read_batch(out, max)
            .map_err(|e| e.in_file(&self.path))
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
