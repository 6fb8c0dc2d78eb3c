//! The `.cwt` text encoding: one instruction per line, `#` comments, made for reading,
//! diffing and snapshot tests.
//!
//! ```text
//! # comments run from '#' to the end of the line
//! cwisim-trace version=1 width=16 lines=4 channels=1
//! # a note: where the instructions below come from
//! Eval2 0 8 0.25 0.125
//! Refresh
//! ```
//!
//! The comment lines directly above an instruction (after the header line, with no blank
//! line between) are its **note** ([`crate::note`]): the reader hands it over
//! ([`TraceRead::note`]) and the writer writes the notes it is given
//! ([`TraceWrite::comment`]) that way, one `# line` per line. Trailing comments and
//! comment blocks followed by a blank line are remarks, read past.
//!
//! Operands follow [`Opcode::operands`]. An intensity is its channel values joined by
//! commas without spaces (`0.5,0.25,1.0` for RGB). Values are written in Rust's shortest
//! round-trip form, so text → value → text is exact. A value is read as
//! `[+-]digits[.digits][(e|E)[+-]digits]`: `0.`, `.5`, `1e` (a number cut short) are
//! refused, located at the missing digit.

use crate::error::{operand_error, ErrorKind, Location, TraceError};
use crate::header::{HeaderFault, TraceHeader, FORMAT_VERSION};
use crate::instruction::{Instruction, Intensity};
use crate::io::{LineReader, TraceRead, TraceWrite};
use crate::note::{Note, Scope};
use crate::opcode::{Opcode, OperandKind};
use std::fmt::Write as _;
use std::io::{self, BufRead, Write};

/// The first word of a text trace's header line.
pub const TEXT_MAGIC: &str = "cwisim-trace";

/// The header line, e.g. `cwisim-trace version=1 width=16 lines=4 channels=1`.
pub fn format_header(h: &TraceHeader) -> String {
    format!(
        "{TEXT_MAGIC} version={} width={} lines={} channels={}",
        h.version, h.width, h.lines, h.channels
    )
}

/// One value in its shortest exact form (`0.5`, `1.0`, `-0.0`, `1e-7`).
pub fn format_value(v: f64) -> String {
    format!("{v:?}")
}

/// One intensity: channel values joined by commas.
pub fn format_intensity(v: &Intensity) -> String {
    let mut s = String::new();
    for (k, x) in v.as_slice().iter().enumerate() {
        if k > 0 {
            s.push(',');
        }
        let _ = write!(s, "{x:?}");
    }
    s
}

/// One instruction as a line of text (without newline).
pub fn format_instruction(instr: &Instruction) -> String {
    let mut s = String::from(instr.op.name());
    for kind in instr.op.operands() {
        s.push(' ');
        match kind {
            OperandKind::X => {
                let _ = write!(s, "{}", instr.x);
            }
            OperandKind::Count | OperandKind::Period => {
                let _ = write!(s, "{}", instr.dx);
            }
            _ => s.push_str(&format_intensity(
                &instr.intensity(kind.value_slot().expect("value")),
            )),
        }
    }
    s
}

/// Writes a `.cwt` trace.
pub struct TextWriter<W: Write> {
    out: W,
}

impl<W: Write> TextWriter<W> {
    /// Starts a trace: writes the header line.
    pub fn new(mut out: W, header: &TraceHeader) -> io::Result<Self> {
        writeln!(out, "{}", format_header(header))?;
        Ok(TextWriter { out })
    }
}

impl<W: Write> TraceWrite for TextWriter<W> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        writeln!(self.out, "{}", format_instruction(instr))
    }

    fn comment(&mut self, text: &str) -> io::Result<()> {
        for line in crate::note::note_lines(text) {
            if line.is_empty() {
                writeln!(self.out, "#")?;
            } else {
                writeln!(self.out, "# {line}")?;
            }
        }
        Ok(())
    }

    fn wants_comments(&self) -> bool {
        true
    }

    fn finish(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

/// Reads a `.cwt` trace.
pub struct TextReader<R: BufRead> {
    lines: LineReader<R>,
    header: TraceHeader,
    location: Location,
    /// The comment lines read since the last instruction or blank line, joined by `\n`:
    /// the note of the next instruction if it follows directly.
    pending: String,
    /// Whether `pending` holds a comment block (it may be one empty line).
    has_pending: bool,
    /// The text of the last note attached.
    note: String,
    scope: Scope,
}

struct Token<'a> {
    text: &'a str,
    column: u64,
}

fn tokens(content: &str) -> Vec<Token<'_>> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in content.char_indices() {
        if c.is_ascii_whitespace() {
            if let Some(s) = start.take() {
                out.push(Token {
                    text: &content[s..i],
                    column: s as u64 + 1,
                });
            }
        } else if start.is_none() {
            start = Some(i);
        }
    }
    if let Some(s) = start {
        out.push(Token {
            text: &content[s..],
            column: s as u64 + 1,
        });
    }
    out
}

/// A line without an instruction, out of the reader's loop (which stays small enough to
/// be inlined into the batch read): a comment line's text (`comment`, after the `#`) is a
/// line of the note of the instruction directly below, if one is; a blank line (`None`)
/// makes the comments above it a remark.
#[inline(never)]
fn take_remark(pending: &mut String, has_pending: &mut bool, comment: Option<&str>) {
    match comment {
        Some(text) => {
            if *has_pending {
                pending.push('\n');
            }
            pending.push_str(text.strip_prefix(' ').unwrap_or(text));
            *has_pending = true;
        }
        None => {
            pending.clear();
            *has_pending = false;
        }
    }
}

#[inline]
fn strip_comment(line: &str) -> &str {
    match line.find('#') {
        Some(i) => &line[..i],
        None => line,
    }
}

impl<R: BufRead> TextReader<R> {
    /// The next instruction, with the comment lines directly above it as its note. Always
    /// inlined: into the batch read, the instruction is built in place rather than
    /// returned through memory.
    #[inline(always)]
    fn read_one(&mut self) -> Result<Option<Instruction>, TraceError> {
        loop {
            let Some((line_no, line)) = self.lines.next_line()? else {
                return Ok(None);
            };
            let content = strip_comment(line);
            let Some(instr) = parse_instruction(content, line_no, &self.header)? else {
                // a comment line (`#` after blanks only), or a blank one
                let comment = (content.len() < line.len()).then(|| &line[content.len() + 1..]);
                take_remark(&mut self.pending, &mut self.has_pending, comment);
                continue;
            };
            self.location = Location::Line {
                line: line_no,
                column: 1,
            };
            let attached = self.has_pending;
            if attached {
                std::mem::swap(&mut self.note, &mut self.pending);
                self.pending.clear();
                self.has_pending = false;
            }
            self.scope.step(instr.op, attached);
            return Ok(Some(instr));
        }
    }

    /// Opens a trace: reads up to and including the header line.
    pub fn new(input: R) -> Result<Self, TraceError> {
        let mut lines = LineReader::new(input);
        loop {
            let Some((line_no, line)) = lines.next_line()? else {
                return Err(TraceError::new(
                    ErrorKind::Truncated,
                    Location::Line { line: 1, column: 1 },
                    format!("the file ends before the header line `{TEXT_MAGIC} version={FORMAT_VERSION} width=W lines=H channels=C`"),
                ));
            };
            let toks = tokens(strip_comment(line));
            if toks.is_empty() {
                continue;
            }
            let header = parse_header(&toks, line_no)?;
            return Ok(TextReader {
                lines,
                header,
                location: Location::Line { line: 1, column: 1 },
                pending: String::new(),
                has_pending: false,
                note: String::new(),
                scope: Scope::default(),
            });
        }
    }
}

fn parse_header(toks: &[Token<'_>], line: u64) -> Result<TraceHeader, TraceError> {
    let at = |column| Location::Line { line, column };
    if toks[0].text != TEXT_MAGIC {
        return Err(TraceError::new(
            ErrorKind::Header,
            at(toks[0].column),
            format!(
                "expected the header `{TEXT_MAGIC} version={FORMAT_VERSION} width=W lines=H channels=C` first, found `{}`",
                toks[0].text
            ),
        ));
    }
    let mut fields: [Option<u64>; 4] = [None; 4];
    let mut columns: [u64; 4] = [1; 4];
    const KEYS: [&str; 4] = ["version", "width", "lines", "channels"];
    for t in &toks[1..] {
        let Some((key, value)) = t.text.split_once('=') else {
            return Err(TraceError::new(
                ErrorKind::Header,
                at(t.column),
                format!("expected `key=value` in the header, found `{}`", t.text),
            ));
        };
        let Some(k) = KEYS.iter().position(|k| *k == key) else {
            return Err(TraceError::new(
                ErrorKind::Header,
                at(t.column),
                format!(
                    "unknown header key `{key}`; expected one of version, width, lines, channels"
                ),
            ));
        };
        if fields[k].is_some() {
            return Err(TraceError::new(
                ErrorKind::Header,
                at(t.column),
                format!("header key `{key}` given twice"),
            ));
        }
        let v: u64 = value.parse().map_err(|_| {
            TraceError::new(
                ErrorKind::Header,
                at(t.column + key.len() as u64 + 1),
                format!("expected an unsigned integer for `{key}`, found `{value}`"),
            )
        })?;
        fields[k] = Some(v);
        columns[k] = t.column;
    }
    for (k, f) in fields.iter().enumerate() {
        if f.is_none() {
            return Err(TraceError::new(
                ErrorKind::Header,
                at(1),
                format!("the header lacks `{}=`", KEYS[k]),
            ));
        }
    }
    let [version, width, lines, channels] = fields.map(|f| f.expect("checked"));
    header_from_u64(version, width, lines, channels).map_err(|f| {
        let k = KEYS.iter().position(|k| *k == f.field).unwrap_or(0);
        TraceError::new(ErrorKind::Header, at(columns[k]), f.message)
    })
}

/// Builds and checks a header from wide integers, so that absurd sizes get a message
/// rather than a wrap-around.
pub(crate) fn header_from_u64(
    version: u64,
    width: u64,
    lines: u64,
    channels: u64,
) -> Result<TraceHeader, HeaderFault> {
    let narrow = |field: &'static str, v: u64, max: u64| {
        if v > max {
            Err(HeaderFault {
                field,
                message: format!(
                    "{field} {v} is absurd (it does not even fit in {} bits)",
                    64 - max.leading_zeros()
                ),
            })
        } else {
            Ok(v)
        }
    };
    let h = TraceHeader {
        version: narrow("version", version, u64::from(u16::MAX))? as u16,
        width: narrow("width", width, u64::from(u32::MAX))? as u32,
        lines: narrow("lines", lines, u64::from(u32::MAX))? as u32,
        channels: narrow("channels", channels, u64::from(u8::MAX))? as u8,
    };
    h.check()?;
    Ok(h)
}

/// Parses one instruction line (comment already stripped) against a header.
pub fn parse_instruction(
    content: &str,
    line: u64,
    header: &TraceHeader,
) -> Result<Option<Instruction>, TraceError> {
    let toks = tokens(content);
    if toks.is_empty() {
        return Ok(None);
    }
    let at = |column| Location::Line { line, column };
    let name = toks[0].text;
    let Some(op) = Opcode::from_name(name) else {
        let hint = Opcode::suggest(name)
            .map(|op| format!("; did you mean `{}`?", op.name()))
            .unwrap_or_default();
        return Err(TraceError::new(
            ErrorKind::UnknownOpcode,
            at(toks[0].column),
            format!("unknown opcode `{name}`{hint}"),
        ));
    };
    let kinds = op.operands();
    let given = toks.len() - 1;
    if given != kinds.len() {
        let column = toks
            .get(kinds.len() + 1)
            .map_or(content.len() as u64 + 1, |t| t.column);
        return Err(TraceError::new(
            ErrorKind::Syntax,
            at(column),
            format!(
                "`{}` takes {} operand(s), found {given}",
                op.signature(),
                kinds.len()
            ),
        ));
    }
    let (mut x, mut dx) = (0, 0);
    let mut values = [Intensity::NONE; 3];
    let channels = header.channel_count();
    for (kind, tok) in kinds.iter().zip(&toks[1..]) {
        match kind {
            OperandKind::X | OperandKind::Count | OperandKind::Period => {
                let v = parse_u32(tok.text, kind.name())
                    .map_err(|m| TraceError::new(ErrorKind::Syntax, at(tok.column), m))?;
                if *kind == OperandKind::X {
                    x = v;
                } else {
                    dx = v;
                }
            }
            _ => {
                let parts: Vec<&str> = tok.text.split(',').collect();
                if parts.len() != channels {
                    return Err(TraceError::new(
                        ErrorKind::Channels,
                        at(tok.column),
                        format!(
                            "{} has {} channel value(s) `{}`, the trace has {channels} (join channels with commas, no spaces)",
                            kind.name(),
                            parts.len(),
                            tok.text
                        ),
                    ));
                }
                let mut vals = [0.0; crate::header::MAX_CHANNELS];
                let mut col = tok.column;
                for (k, p) in parts.iter().enumerate() {
                    vals[k] = parse_f64(p, kind.name()).map_err(|(kind, offset, m)| {
                        TraceError::new(kind, at(col + offset as u64), m)
                    })?;
                    col += p.len() as u64 + 1;
                }
                values[kind.value_slot().expect("value")] = Intensity::new(&vals[..channels]);
            }
        }
    }
    let instr = Instruction::from_parts(op, x, dx, values);
    instr
        .check(header)
        .map_err(|e| operand_error(e, at(toks[1].column), op))?;
    Ok(Some(instr))
}

fn parse_u32(text: &str, name: &str) -> Result<u32, String> {
    if !text.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!(
            "expected an unsigned integer for `{name}`, found `{text}`"
        ));
    }
    text.parse::<u32>()
        .map_err(|_| format!("`{name}` = {text} does not fit in 32 bits"))
}

/// Where `text` first departs from the number grammar
/// `[+-]? digits ('.' digits)? ([eE] [+-]? digits)?` (digits: one or more ASCII digits),
/// as its byte offset and what was expected there; `None` when it is a number. So `0.`,
/// `.5`, `1e` and `1e-` (a number cut short, or half written) are refused, and every form
/// [`format_value`] writes (`1.0`, `-0.0`, `1e-7`, `1e16`) is read.
fn number_fault(text: &str) -> Option<(usize, &'static str)> {
    let b = text.as_bytes();
    let digits = |i: &mut usize| {
        let start = *i;
        while b.get(*i).is_some_and(u8::is_ascii_digit) {
            *i += 1;
        }
        *i > start
    };
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    if !digits(&mut i) {
        let what = if b.get(i) == Some(&b'.') {
            "a digit before the decimal point"
        } else {
            "a digit"
        };
        return Some((i, what));
    }
    if b.get(i) == Some(&b'.') {
        i += 1;
        if !digits(&mut i) {
            return Some((i, "a digit after the decimal point"));
        }
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        i += 1;
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        if !digits(&mut i) {
            return Some((i, "a digit in the exponent"));
        }
    }
    (i < b.len()).then_some((i, "the end of the number"))
}

/// One channel value: a finite number of the grammar of [`number_fault`]. A refusal
/// gives the kind, the byte offset in `text` where it was found, and the message.
fn parse_f64(text: &str, name: &str) -> Result<f64, (ErrorKind, usize, String)> {
    let looks_numeric = !text.is_empty()
        && text
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E'));
    if !looks_numeric {
        let kind = if text
            .to_ascii_lowercase()
            .trim_start_matches(['-', '+'])
            .starts_with("inf")
            || text.eq_ignore_ascii_case("nan")
        {
            ErrorKind::NonFinite
        } else {
            ErrorKind::Syntax
        };
        return Err((
            kind,
            0,
            format!("expected a finite number for `{name}`, found `{text}`"),
        ));
    }
    if let Some((at, expected)) = number_fault(text) {
        let found = match text[at..].chars().next() {
            Some(c) => format!("found `{c}`"),
            None => "found its end".to_string(),
        };
        return Err((
            ErrorKind::Syntax,
            at,
            format!("expected {expected} in the number `{text}` for `{name}`, {found}"),
        ));
    }
    let v: f64 = text.parse().map_err(|_| {
        (
            ErrorKind::Syntax,
            0,
            format!("expected a finite number for `{name}`, found `{text}`"),
        )
    })?;
    if !v.is_finite() {
        return Err((
            ErrorKind::NonFinite,
            0,
            format!("`{name}` = {text} overflows f64"),
        ));
    }
    Ok(v)
}

impl<R: BufRead> TraceRead for TextReader<R> {
    fn header(&self) -> &TraceHeader {
        &self.header
    }

    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        self.read_one()
    }

    /// The default's loop, over `read_one` inlined.
    fn read_batch(&mut self, out: &mut Vec<Instruction>, max: usize) -> Result<usize, TraceError> {
        let mut n = 0;
        while n < max.max(1) {
            match self.read_one()? {
                Some(i) => out.push(i),
                None => break,
            }
            n += 1;
        }
        Ok(n)
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

    fn read(src: &str) -> Result<(TraceHeader, Vec<Instruction>), TraceError> {
        let mut r = TextReader::new(src.as_bytes())?;
        let v = read_all(&mut r)?;
        Ok((*r.header(), v))
    }

    #[test]
    fn reads_comments_blank_lines_and_rgb() {
        let (h, v) = read(
            "# a trace\n\ncwisim-trace version=1 width=8 lines=2 channels=3 # trailing\nEval2 0 4 1.0,0.5,0.0 -0.25,0,1e-3\n  Refresh  \n",
        )
        .unwrap();
        assert_eq!(h.width, 8);
        assert_eq!(v.len(), 2);
        assert_eq!(v[0].di().as_slice(), &[-0.25, 0.0, 1e-3]);
        assert_eq!(
            format_instruction(&v[0]),
            "Eval2 0 4 1.0,0.5,0.0 -0.25,0.0,0.001"
        );
    }

    /// Each instruction's note (its text and serial), as the reader hands them over.
    fn notes(src: &str) -> Vec<(String, Option<(u64, String)>)> {
        let mut r = TextReader::new(src.as_bytes()).unwrap();
        let mut out = Vec::new();
        while let Some(i) = r.next_instruction().unwrap() {
            let note = r.note().map(|n| (n.serial, n.text.to_string()));
            out.push((format_instruction(&i), note));
        }
        out
    }

    #[test]
    fn comment_lines_directly_above_an_instruction_are_its_note() {
        let got = notes(
            "# about the file, not a note\ncwisim-trace version=1 width=8 lines=2 channels=1\n\
             # row 0 trapezium 1 (polygon 0): case 8\n\
             #second line\n\
             Eval1 0 4 0.5 # a trailing remark\n\
             Eval1 4 4 0.25\n\
             Refresh\n\
             Eval1 0 1 1.0\n\
             # a remark set apart by a blank line\n\
             \n\
             Eval1 1 1 1.0\n\
             \t# indented\n\
             #\n\
             Refresh\n\
             Eval1 2 1 1.0 # not a note\n",
        );
        let n = |serial, t: &str| Some((serial, t.to_string()));
        let row = "row 0 trapezium 1 (polygon 0): case 8\nsecond line";
        assert_eq!(
            got,
            [
                ("Eval1 0 4 0.5".to_string(), n(0, row)),
                ("Eval1 4 4 0.25".to_string(), n(0, row)),
                ("Refresh".to_string(), None),
                ("Eval1 0 1 1.0".to_string(), None),
                ("Eval1 1 1 1.0".to_string(), None),
                ("Refresh".to_string(), n(1, "indented\n")),
                ("Eval1 2 1 1.0".to_string(), None),
            ]
        );
    }

    #[test]
    fn notes_written_read_back() {
        let header = TraceHeader::new(8, 2, 1).unwrap();
        let mut bytes = Vec::new();
        let mut w = TextWriter::new(&mut bytes, &header).unwrap();
        w.comment("a\n\nb").unwrap();
        w.comment("c\r\n").unwrap();
        w.write(&Instruction::eval1(0, 1, Intensity::grey(0.5)))
            .unwrap();
        w.write(&Instruction::eval1(1, 1, Intensity::grey(0.5)))
            .unwrap();
        w.comment("").unwrap(); // one empty line
        w.write(&Instruction::refresh()).unwrap();
        w.finish().unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert_eq!(
            text,
            "cwisim-trace version=1 width=8 lines=2 channels=1\n# a\n#\n# b\n# c\n#\nEval1 0 1 0.5\nEval1 1 1 0.5\n#\nRefresh\n"
        );
        let got = notes(&text);
        assert_eq!(got[0].1, Some((0, "a\n\nb\nc\n".to_string())));
        assert_eq!(got[1].1, got[0].1);
        assert_eq!(got[2].1, Some((1, String::new())));
    }

    #[test]
    fn errors_are_located() {
        let e =
            read("cwisim-trace version=1 width=8 lines=2 channels=1\nEval2 0 4 1.0\n").unwrap_err();
        assert_eq!(e.kind, ErrorKind::Syntax);
        assert_eq!(
            e.location,
            Location::Line {
                line: 2,
                column: 14
            }
        );
        let e = read("cwisim-trace version=1 width=8 lines=2 channels=1\nEval1 -1 4 1.0\n")
            .unwrap_err();
        assert_eq!(e.location, Location::Line { line: 2, column: 7 });
        assert!(e.message.contains("unsigned integer"), "{}", e.message);
        let e =
            read("cwisim-trace version=1 width=8 lines=2 channels=1\nEval1 0 4 NaN\n").unwrap_err();
        assert_eq!(e.kind, ErrorKind::NonFinite);
        let e =
            read("cwisim-trace version=1 width=8 lines=2 channels=1\neval1 0 4 1\n").unwrap_err();
        assert!(e.message.contains("did you mean `Eval1`"), "{}", e.message);
        let e = read("cwisim-trace version=1 width=99999999999 lines=2 channels=1\n").unwrap_err();
        assert_eq!(e.kind, ErrorKind::Header);
        let e = read("").unwrap_err();
        assert_eq!(e.kind, ErrorKind::Truncated);
    }

    /// The first value of `Eval1 0 4 <value>`, or the error; the value starts at column 11.
    fn value(v: &str) -> Result<f64, TraceError> {
        let src = format!("cwisim-trace version=1 width=8 lines=2 channels=1\nEval1 0 4 {v}\n");
        read(&src).map(|(_, i)| i[0].i().as_slice()[0])
    }

    #[test]
    fn numbers_cut_short_are_refused_where_the_digit_is_missing() {
        for (v, column, expected) in [
            ("0.", 13, "expected a digit after the decimal point in the number `0.` for `I`, found its end"),
            ("-3.e5", 14, "expected a digit after the decimal point in the number `-3.e5` for `I`, found `e`"),
            (".5", 11, "expected a digit before the decimal point in the number `.5` for `I`, found `.`"),
            ("-.5", 12, "expected a digit before the decimal point in the number `-.5` for `I`, found `.`"),
            ("1e", 13, "expected a digit in the exponent in the number `1e` for `I`, found its end"),
            ("1e-", 14, "expected a digit in the exponent in the number `1e-` for `I`, found its end"),
            ("1.5E+", 16, "expected a digit in the exponent in the number `1.5E+` for `I`, found its end"),
            ("-", 12, "expected a digit in the number `-` for `I`, found its end"),
            ("+-1", 12, "expected a digit in the number `+-1` for `I`, found `-`"),
            ("1.0.0", 14, "expected the end of the number in the number `1.0.0` for `I`, found `.`"),
            ("1-2", 12, "expected the end of the number in the number `1-2` for `I`, found `-`"),
        ] {
            let e = value(v).unwrap_err();
            assert_eq!(e.kind, ErrorKind::Syntax, "{v}: {e}");
            assert_eq!(e.location, Location::Line { line: 2, column }, "{v}: {e}");
            assert_eq!(e.message, expected);
        }
        // in a channel after the first: located in that channel
        let src = "cwisim-trace version=1 width=8 lines=2 channels=3\nEval1 0 4 1.0,0.,2.0\n";
        let e = read(src).unwrap_err();
        assert_eq!(
            e.location,
            Location::Line {
                line: 2,
                column: 17
            },
            "{e}"
        );
    }

    #[test]
    fn every_form_the_writer_writes_and_the_documented_ones_are_read() {
        for (v, want) in [
            ("1.0", 1.0),
            ("-0.0", -0.0),
            ("1e-7", 1e-7),
            ("1e16", 1e16),
            ("1E5", 1e5),
            ("1e+5", 1e5),
            ("+0.5", 0.5),
            ("0", 0.0),
            ("007", 7.0),
            ("5e-324", 5e-324),
            ("1.7976931348623157e308", f64::MAX),
        ] {
            let got = value(v).unwrap_or_else(|e| panic!("{v}: {e}"));
            assert_eq!(got.to_bits(), want.to_bits(), "{v}");
        }
        for v in [
            0.1,
            -0.0,
            1e-7,
            1e300,
            5e-324,
            f64::MIN_POSITIVE,
            0.176,
            -12345.678,
        ] {
            assert_eq!(value(&format_value(v)).unwrap().to_bits(), v.to_bits());
        }
        // as before: the non-finite are refused as such
        for v in ["inf", "-inf", "NaN", "infinity", "1e999"] {
            assert_eq!(value(v).unwrap_err().kind, ErrorKind::NonFinite, "{v}");
        }
    }
}
