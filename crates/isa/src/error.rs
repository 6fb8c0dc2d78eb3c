//! Located, typed errors for every trace encoding.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a trace file something went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// 1-based line and column (text and JSON Lines).
    Line {
        /// 1-based line number.
        line: u64,
        /// 1-based column (in bytes).
        column: u64,
    },
    /// Byte offset from the start of the file (binary).
    Byte(u64),
    /// The file as a whole (opening it, choosing its encoding).
    File,
    /// The end of the file, after its last instruction (a trace that ends short of the
    /// frames its header announces).
    End,
}

impl Location {
    /// Whether an error's display names this location: [`Location::File`] and
    /// [`Location::End`] are said by the message itself.
    fn is_shown(self) -> bool {
        !matches!(self, Location::File | Location::End)
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line { line, column } => write!(f, "{line}:{column}"),
            Location::Byte(b) => write!(f, "byte {b}"),
            Location::File => Ok(()),
            Location::End => f.write_str("end of file"),
        }
    }
}

/// What kind of fault a trace has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// Reading the file failed.
    Io,
    /// The file ends before the trace does (cut short inside a record, or before the
    /// binary end marker).
    Truncated,
    /// Every record is whole, but the trace ends short of the frames its header announces:
    /// its `Refresh` count is not a positive multiple of the header's `lines` (a file cut
    /// at a line's end, or a writer that stopped early).
    Incomplete,
    /// The bytes are not a trace of this format (bad magic, bad checksum, trailing data…).
    Corrupt,
    /// Malformed text or JSON.
    Syntax,
    /// An opcode name or code that does not exist.
    UnknownOpcode,
    /// A header outside the limits, or of an unsupported version.
    Header,
    /// An operand outside the array, or a zero period.
    Range,
    /// An intensity with the wrong number of channels.
    Channels,
    /// NaN or an infinity.
    NonFinite,
    /// A line or file larger than the reader accepts.
    Limit,
    /// The file name's extension names no trace encoding.
    Encoding,
}

/// A trace that cannot be read: where, what kind of fault, and what was expected.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TraceError {
    /// The file, when known.
    pub path: Option<PathBuf>,
    /// Where in the file.
    pub location: Location,
    /// The kind of fault.
    pub kind: ErrorKind,
    /// One line saying what was expected and what was found.
    pub message: String,
}

impl TraceError {
    /// An error at `location`.
    pub fn new(kind: ErrorKind, location: Location, message: impl Into<String>) -> Self {
        TraceError {
            path: None,
            location,
            kind,
            message: message.into(),
        }
    }

    /// The same error, naming the file.
    pub fn in_file(mut self, path: &Path) -> Self {
        self.path = Some(path.to_path_buf());
        self
    }

    pub(crate) fn io(location: Location, err: &std::io::Error) -> Self {
        TraceError::new(ErrorKind::Io, location, format!("read failed: {err}"))
    }
}

/// `text` with every control character (a line break, a carriage return, an escape)
/// written as its Rust escape (`\n`, `\r`, `\u{1b}`): a message that echoes what it
/// read from the input stays one printable line, whatever the input held.
pub fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// One printable line (see [`printable`]): the file, the location, the message.
impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(p) = &self.path {
            write!(f, "{}", printable(&p.display().to_string()))?;
            if self.location.is_shown() {
                match self.location {
                    Location::Byte(_) => write!(f, ": {}", self.location)?,
                    _ => write!(f, ":{}", self.location)?,
                }
            }
            write!(f, ": ")?;
        } else if self.location.is_shown() {
            write!(f, "{}: ", self.location)?;
        }
        f.write_str(&printable(&self.message))
    }
}

impl std::error::Error for TraceError {}

impl From<crate::instruction::OperandError> for ErrorKind {
    fn from(e: crate::instruction::OperandError) -> Self {
        match e {
            crate::instruction::OperandError::Range(_) => ErrorKind::Range,
            crate::instruction::OperandError::Channels(_) => ErrorKind::Channels,
            crate::instruction::OperandError::NonFinite(_) => ErrorKind::NonFinite,
        }
    }
}

pub(crate) fn operand_error(
    e: crate::instruction::OperandError,
    location: Location,
    op: crate::Opcode,
) -> TraceError {
    let message = format!("{op}: {}", e.message());
    TraceError::new(e.into(), location, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_place() {
        let e = TraceError::new(
            ErrorKind::Syntax,
            Location::Line { line: 3, column: 7 },
            "expected x",
        )
        .in_file(Path::new("t.cwt"));
        assert_eq!(e.to_string(), "t.cwt:3:7: expected x");
        let e = TraceError::new(ErrorKind::Truncated, Location::Byte(42), "cut")
            .in_file(Path::new("t.cwb"));
        assert_eq!(e.to_string(), "t.cwb: byte 42: cut");
        let e = TraceError::new(ErrorKind::Encoding, Location::File, "unknown")
            .in_file(Path::new("t.txt"));
        assert_eq!(e.to_string(), "t.txt: unknown");
        let e = TraceError::new(ErrorKind::Incomplete, Location::End, "the trace ends")
            .in_file(Path::new("t.cwt"));
        assert_eq!(e.to_string(), "t.cwt: the trace ends");
        assert_eq!(Location::End.to_string(), "end of file");
    }
}

#[cfg(test)]
mod printable_tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_the_rest_kept() {
        assert_eq!(printable("plain ünïcode"), "plain ünïcode");
        assert_eq!(printable("a\nb\r\u{1b}c\t"), "a\\nb\\r\\u{1b}c\\t");
        let e = TraceError::new(
            ErrorKind::Syntax,
            Location::Line { line: 2, column: 3 },
            "header \"format\" is \"cwisim-\race\"",
        );
        assert_eq!(e.to_string(), "2:3: header \"format\" is \"cwisim-\\race\"");
    }
}
