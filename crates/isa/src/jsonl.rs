//! The `.jsonl` encoding: JSON Lines, one object per line.
//!
//! ```text
//! {"format":"cwisim-trace","version":1,"width":16,"lines":4,"channels":1}
//! {"op":"Eval2","x":0,"dx":8,"I":[0.25],"dI":[0.125]}
//! {"op":"Refresh"}
//! ```
//!
//! Keys are the operand names of [`Opcode::operands`]; intensities are always arrays,
//! one number per channel. Floats round-trip exactly (serde_json's `float_roundtrip`).
//!
//! A record may carry a `"note"` string (written last): the note attached to its
//! instruction ([`crate::note`]: where it came from; it covers the instructions after it
//! up to the next note or `Refresh`). Lines of a note are joined by `\n`. A record
//! without one is written exactly as before notes existed; readers older than notes
//! refuse a record with one (`unknown field "note"`).

use crate::error::{operand_error, ErrorKind, Location, TraceError};
use crate::header::TraceHeader;
use crate::instruction::{Instruction, Intensity};
use crate::io::{LineReader, TraceRead, TraceWrite};
use crate::note::{append_note, Note, Scope};
use crate::opcode::{Opcode, OperandKind};
use crate::text::{header_from_u64, TEXT_MAGIC};
use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize, Serializer};
use std::io::{self, BufRead, Write};

impl Serialize for Instruction {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Noted(self, None).serialize(s)
    }
}

/// An instruction's record, with its note when it has one.
struct Noted<'a>(&'a Instruction, Option<&'a str>);

impl Serialize for Noted<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let Noted(instr, note) = self;
        let kinds = instr.op.operands();
        let mut m = s.serialize_map(Some(kinds.len() + 1 + usize::from(note.is_some())))?;
        m.serialize_entry("op", instr.op.name())?;
        for kind in kinds {
            match kind {
                OperandKind::X => m.serialize_entry("x", &instr.x)?,
                OperandKind::Count | OperandKind::Period => m.serialize_entry("dx", &instr.dx)?,
                _ => {
                    m.serialize_entry(kind.name(), instr.value(kind.value_slot().expect("value")))?
                }
            }
        }
        if let Some(note) = note {
            m.serialize_entry("note", note)?;
        }
        m.end()
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct HeaderRecord {
    format: String,
    version: u64,
    width: u64,
    lines: u64,
    channels: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Record<'a> {
    /// Borrowed from the line unless it holds escapes: no allocation per record.
    #[serde(borrow)]
    op: std::borrow::Cow<'a, str>,
    x: Option<u64>,
    dx: Option<u64>,
    #[serde(rename = "I")]
    i: Option<Vec<f64>>,
    #[serde(rename = "dI")]
    di: Option<Vec<f64>>,
    #[serde(rename = "ddI")]
    ddi: Option<Vec<f64>>,
    note: Option<String>,
}

/// Writes a `.jsonl` trace.
pub struct JsonlWriter<W: Write> {
    out: W,
    /// The note of the next instruction.
    pending: Option<String>,
}

impl<W: Write> JsonlWriter<W> {
    /// Starts a trace: writes the header object.
    pub fn new(mut out: W, header: &TraceHeader) -> io::Result<Self> {
        let rec = HeaderRecord {
            format: TEXT_MAGIC.into(),
            version: header.version.into(),
            width: header.width.into(),
            lines: header.lines.into(),
            channels: header.channels.into(),
        };
        serde_json::to_writer(&mut out, &rec)?;
        out.write_all(b"\n")?;
        Ok(JsonlWriter { out, pending: None })
    }
}

impl<W: Write> TraceWrite for JsonlWriter<W> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        let note = self.pending.take();
        serde_json::to_writer(&mut self.out, &Noted(instr, note.as_deref()))?;
        self.out.write_all(b"\n")
    }

    fn comment(&mut self, text: &str) -> io::Result<()> {
        append_note(&mut self.pending, text);
        Ok(())
    }

    fn wants_comments(&self) -> bool {
        true
    }

    fn finish(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// Reads a `.jsonl` trace.
pub struct JsonlReader<R: BufRead> {
    lines: LineReader<R>,
    header: TraceHeader,
    location: Location,
    /// The text of the last note attached.
    note: String,
    scope: Scope,
}

fn json_error(e: &serde_json::Error, line: u64) -> TraceError {
    let kind = if e.is_eof() {
        ErrorKind::Truncated
    } else {
        ErrorKind::Syntax
    };
    // serde_json's message ends with " at line L column C"; we give our own location.
    let msg = e.to_string();
    let msg = msg
        .rsplit_once(" at line ")
        .map_or(msg.as_str(), |(m, _)| m);
    TraceError::new(
        kind,
        Location::Line {
            line,
            column: e.column().max(1) as u64,
        },
        format!("invalid JSON record: {msg}"),
    )
}

impl<R: BufRead> JsonlReader<R> {
    /// Opens a trace: reads the header object on the first line.
    pub fn new(input: R) -> Result<Self, TraceError> {
        let mut lines = LineReader::new(input);
        let at1 = Location::Line { line: 1, column: 1 };
        let Some((_, first)) = lines.next_line()? else {
            return Err(TraceError::new(
                ErrorKind::Truncated,
                at1,
                "the file is empty; expected the header object {\"format\":\"cwisim-trace\",\"version\":1,…}",
            ));
        };
        let rec: HeaderRecord = serde_json::from_str(first).map_err(|e| {
            let mut err = json_error(&e, 1);
            err.kind = ErrorKind::Header;
            err.message = format!("expected the header object {{\"format\":\"cwisim-trace\",\"version\",\"width\",\"lines\",\"channels\"}}: {}", err.message);
            err
        })?;
        if rec.format != TEXT_MAGIC {
            return Err(TraceError::new(
                ErrorKind::Header,
                at1,
                format!(
                    "header \"format\" is \"{}\", expected \"{TEXT_MAGIC}\"",
                    rec.format
                ),
            ));
        }
        let header =
            header_from_u64(rec.version, rec.width, rec.lines, rec.channels).map_err(|f| {
                TraceError::new(
                    ErrorKind::Header,
                    at1,
                    format!("header \"{}\": {}", f.field, f.message),
                )
            })?;
        Ok(JsonlReader {
            lines,
            header,
            location: at1,
            note: String::new(),
            scope: Scope::default(),
        })
    }
}

/// One record's instruction; its note, if it has one, into `note`.
fn parse_record(
    line: &str,
    line_no: u64,
    header: &TraceHeader,
    note: &mut String,
) -> Result<(Instruction, bool), TraceError> {
    let at = Location::Line {
        line: line_no,
        column: 1,
    };
    let rec: Record = serde_json::from_str(line).map_err(|e| json_error(&e, line_no))?;
    let Some(op) = Opcode::from_name(&rec.op) else {
        let hint = Opcode::suggest(&rec.op)
            .map(|op| format!("; did you mean \"{}\"?", op.name()))
            .unwrap_or_default();
        return Err(TraceError::new(
            ErrorKind::UnknownOpcode,
            at,
            format!("unknown opcode \"{}\"{hint}", rec.op),
        ));
    };
    let kinds = op.operands();
    let present = [
        ("x", rec.x.is_some()),
        ("dx", rec.dx.is_some()),
        ("I", rec.i.is_some()),
        ("dI", rec.di.is_some()),
        ("ddI", rec.ddi.is_some()),
    ];
    for (name, is_present) in present {
        let wanted = kinds.iter().any(|k| k.name() == name);
        if wanted && !is_present {
            return Err(TraceError::new(
                ErrorKind::Syntax,
                at,
                format!("`{}` lacks operand \"{name}\"", op.signature()),
            ));
        }
        if !wanted && is_present {
            return Err(TraceError::new(
                ErrorKind::Syntax,
                at,
                format!("`{}` has no operand \"{name}\"", op.signature()),
            ));
        }
    }
    let narrow = |name: &str, v: Option<u64>| -> Result<u32, TraceError> {
        let v = v.unwrap_or(0);
        u32::try_from(v).map_err(|_| {
            TraceError::new(
                ErrorKind::Range,
                at,
                format!("\"{name}\" = {v} does not fit in 32 bits"),
            )
        })
    };
    let channels = header.channel_count();
    let vector = |name: &str, v: Option<Vec<f64>>| -> Result<Intensity, TraceError> {
        match v {
            None => Ok(Intensity::NONE),
            Some(v) if v.len() != channels => Err(TraceError::new(
                ErrorKind::Channels,
                at,
                format!(
                    "\"{name}\" has {} channel value(s), the trace has {channels}",
                    v.len()
                ),
            )),
            Some(v) => Ok(Intensity::new(&v)),
        }
    };
    let instr = Instruction::from_parts(
        op,
        narrow("x", rec.x)?,
        narrow("dx", rec.dx)?,
        [
            vector("I", rec.i)?,
            vector("dI", rec.di)?,
            vector("ddI", rec.ddi)?,
        ],
    );
    instr.check(header).map_err(|e| operand_error(e, at, op))?;
    let attached = rec.note.is_some();
    if let Some(text) = rec.note {
        *note = text;
    }
    Ok((instr, attached))
}

impl<R: BufRead> TraceRead for JsonlReader<R> {
    fn header(&self) -> &TraceHeader {
        &self.header
    }

    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        let Some((line_no, line)) = self.lines.next_line()? else {
            return Ok(None);
        };
        if line.trim().is_empty() {
            return Err(TraceError::new(
                ErrorKind::Syntax,
                Location::Line {
                    line: line_no,
                    column: 1,
                },
                "empty line; JSON Lines holds one JSON object on every line",
            ));
        }
        let (instr, attached) = parse_record(line, line_no, &self.header, &mut self.note)?;
        self.location = Location::Line {
            line: line_no,
            column: 1,
        };
        self.scope.step(instr.op, attached);
        Ok(Some(instr))
    }

    fn note(&self) -> Option<Note<'_>> {
        self.scope.serial().map(|serial| Note {
            serial,
            text: &self.note,
        })
    }

    fn location(&self) -> Location {
        self.location
    }

    fn bytes_read(&self) -> u64 {
        self.lines.bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::read_all;

    const HEAD: &str =
        "{\"format\":\"cwisim-trace\",\"version\":1,\"width\":8,\"lines\":2,\"channels\":1}\n";

    fn read(body: &str) -> Result<Vec<Instruction>, TraceError> {
        let src = format!("{HEAD}{body}");
        let mut r = JsonlReader::new(src.as_bytes())?;
        read_all(&mut r)
    }

    #[test]
    fn writes_the_documented_form() {
        let mut buf = Vec::new();
        let h = TraceHeader::new(8, 2, 1).unwrap();
        let mut w = JsonlWriter::new(&mut buf, &h).unwrap();
        w.write(&Instruction::eval2(
            0,
            4,
            Intensity::grey(0.25),
            Intensity::grey(-0.0),
        ))
        .unwrap();
        w.write(&Instruction::refresh()).unwrap();
        let s = String::from_utf8(buf).unwrap();
        assert_eq!(
            s,
            format!("{HEAD}{{\"op\":\"Eval2\",\"x\":0,\"dx\":4,\"I\":[0.25],\"dI\":[-0.0]}}\n{{\"op\":\"Refresh\"}}\n")
        );
        assert_eq!(
            read(&s[HEAD.len()..]).unwrap()[0].di().as_slice()[0].to_bits(),
            (-0.0f64).to_bits()
        );
    }

    #[test]
    fn a_note_is_written_last_and_read_back() {
        let mut buf = Vec::new();
        let h = TraceHeader::new(8, 2, 1).unwrap();
        let mut w = JsonlWriter::new(&mut buf, &h).unwrap();
        w.comment("row 0 trapezium 1 (polygon 0): case 8").unwrap();
        w.comment("\"quoted\"").unwrap();
        w.write(&Instruction::eval1(0, 4, Intensity::grey(0.5)))
            .unwrap();
        w.write(&Instruction::eval1(4, 4, Intensity::grey(0.5)))
            .unwrap();
        w.write(&Instruction::refresh()).unwrap();
        let s = String::from_utf8(buf).unwrap();
        let body = &s[HEAD.len()..];
        assert_eq!(
            body,
            "{\"op\":\"Eval1\",\"x\":0,\"dx\":4,\"I\":[0.5],\"note\":\"row 0 trapezium 1 (polygon 0): case 8\\n\\\"quoted\\\"\"}\n\
             {\"op\":\"Eval1\",\"x\":4,\"dx\":4,\"I\":[0.5]}\n{\"op\":\"Refresh\"}\n"
        );
        let mut r = JsonlReader::new(s.as_bytes()).unwrap();
        let mut got = Vec::new();
        while r.next_instruction().unwrap().is_some() {
            got.push(r.note().map(|n| (n.serial, n.text.to_string())));
        }
        let note = Some((
            0,
            "row 0 trapezium 1 (polygon 0): case 8\n\"quoted\"".to_string(),
        ));
        assert_eq!(got, [note.clone(), note, None]);
        // a note must be a string
        assert_eq!(
            read("{\"op\":\"Refresh\",\"note\":3}\n").unwrap_err().kind,
            ErrorKind::Syntax
        );
    }

    #[test]
    fn rejects_missing_extra_and_unknown() {
        assert_eq!(
            read("{\"op\":\"Eval1\",\"x\":0,\"I\":[1]}\n")
                .unwrap_err()
                .kind,
            ErrorKind::Syntax
        );
        assert_eq!(
            read("{\"op\":\"Refresh\",\"x\":0}\n").unwrap_err().kind,
            ErrorKind::Syntax
        );
        assert_eq!(
            read("{\"op\":\"Refresh\",\"y\":0}\n").unwrap_err().kind,
            ErrorKind::Syntax
        );
        assert_eq!(
            read("{\"op\":\"Blit\"}\n").unwrap_err().kind,
            ErrorKind::UnknownOpcode
        );
        assert_eq!(
            read("{\"op\":\"Eval1\",\"x\":0,\"dx\":1,\"I\":[1,2]}\n")
                .unwrap_err()
                .kind,
            ErrorKind::Channels
        );
        assert_eq!(
            read("{\"op\":\"Eval1\",\"x\":0,\"dx\":9,\"I\":[1]}\n")
                .unwrap_err()
                .kind,
            ErrorKind::Range
        );
        let e = read("{\"op\":\"Eval1\",\"x\":0,\"dx\":1,\"I\":[1e999]}\n").unwrap_err();
        assert_eq!(
            e.location,
            Location::Line {
                line: 2,
                column: 37
            }
        );
        let e = read("{\"op\":\"Eval1\",\"x\":0,\"dx\":1,\n").unwrap_err();
        assert_eq!(e.kind, ErrorKind::Truncated);
    }

    /// A file cut anywhere inside a record (mid-number included: `0.176` cut to `0.`) is
    /// refused; a cut only reads back whole records when it falls at a record's end.
    #[test]
    fn a_file_cut_inside_a_record_is_refused() {
        let body = "{\"op\":\"Eval2\",\"x\":0,\"dx\":4,\"I\":[0.176],\"dI\":[-1e-7]}\n{\"op\":\"Refresh\"}\n";
        let whole = format!("{HEAD}{body}");
        for cut in HEAD.len()..whole.len() {
            let part = &whole[..cut];
            let got = JsonlReader::new(part.as_bytes()).and_then(|mut r| read_all(&mut r));
            let at_a_record_end = part.ends_with('}') || part.ends_with('\n');
            match got {
                Ok(v) => {
                    assert!(at_a_record_end, "cut {cut} `{part}` accepted");
                    assert_eq!(v.len(), part.matches('}').count() - 1);
                }
                Err(e) => {
                    assert!(!at_a_record_end, "cut {cut}: {e}");
                    assert_eq!(e.kind, ErrorKind::Truncated, "cut {cut}: {e}");
                    assert!(
                        matches!(e.location, Location::Line { line: 2 | 3, .. }),
                        "{e}"
                    );
                }
            }
        }
    }
}
