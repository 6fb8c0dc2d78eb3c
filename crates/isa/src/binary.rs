//! The `.cwb` binary encoding: compact, checksummed, for traces of millions of
//! instructions.
//!
//! | part | bytes | content |
//! | --- | --- | --- |
//! | magic | 8 | `CWBTRACE` |
//! | version | 2 | u16 little-endian |
//! | channels | 1 | u8 |
//! | reserved | 1 | 0 |
//! | width | 4 | u32 LE |
//! | lines | 4 | u32 LE |
//! | records | … | opcode byte ([`Opcode::code`]), then the operands in [`Opcode::operands`] order: `x` and `dx` as LEB128 varints (canonical, ≤ 5 bytes), each intensity as `channels` × f64 LE |
//! | end marker | 1 | `0xFF` |
//! | count | 8 | u64 LE: the number of records |
//! | checksum | 4 | u32 LE: CRC-32 (IEEE) of all record bytes |
//!
//! A file that stops before its end marker is *truncated*; one whose bytes contradict the
//! format (bad magic, unknown opcode, bad varint, checksum or count mismatch, bytes after
//! the end marker) is *corrupt*.
//!
//! A `.cwb` carries no notes ([`crate::note`]): the format has no place for them, and its
//! writer drops what it is given. A stream kept in memory as `.cwb` keeps its notes
//! beside it ([`crate::note::NoteTaker`], [`crate::note::Annotated`]).

use crate::error::{operand_error, ErrorKind, Location, TraceError};
use crate::header::{TraceHeader, MAX_CHANNELS};
use crate::instruction::{Instruction, Intensity};
use crate::io::{TraceRead, TraceWrite};
use crate::opcode::{Opcode, OperandKind};
use crate::text::header_from_u64;
use std::io::{self, BufRead, Read, Write};

/// The first eight bytes of every `.cwb` file.
pub const MAGIC: &[u8; 8] = b"CWBTRACE";
/// The byte that starts the end marker.
pub const END_MARKER: u8 = 0xFF;
const END_WHAT: &str = "the end marker";
/// Size of the fixed header.
pub const HEADER_BYTES: u64 = 20;

/// Writes a `.cwb` trace.
pub struct BinaryWriter<W: Write> {
    out: W,
    crc: crc32fast::Hasher,
    count: u64,
    record: Vec<u8>,
}

impl<W: Write> BinaryWriter<W> {
    /// Starts a trace: writes the fixed header.
    pub fn new(mut out: W, h: &TraceHeader) -> io::Result<Self> {
        out.write_all(MAGIC)?;
        out.write_all(&h.version.to_le_bytes())?;
        out.write_all(&[h.channels, 0])?;
        out.write_all(&h.width.to_le_bytes())?;
        out.write_all(&h.lines.to_le_bytes())?;
        Ok(BinaryWriter {
            out,
            crc: crc32fast::Hasher::new(),
            count: 0,
            record: Vec::with_capacity(64),
        })
    }
}

fn put_varint(buf: &mut Vec<u8>, mut v: u32) {
    loop {
        let byte = (v & 0x7F) as u8;
        v >>= 7;
        if v == 0 {
            buf.push(byte);
            return;
        }
        buf.push(byte | 0x80);
    }
}

impl<W: Write> TraceWrite for BinaryWriter<W> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        self.record.clear();
        self.record.push(instr.op.code());
        for kind in instr.op.operands() {
            match kind {
                OperandKind::X => put_varint(&mut self.record, instr.x),
                OperandKind::Count | OperandKind::Period => put_varint(&mut self.record, instr.dx),
                _ => {
                    for v in instr.value(kind.value_slot().expect("value")) {
                        self.record.extend_from_slice(&v.to_le_bytes());
                    }
                }
            }
        }
        self.crc.update(&self.record);
        self.count += 1;
        self.out.write_all(&self.record)
    }

    fn finish(&mut self) -> io::Result<()> {
        let crc = std::mem::take(&mut self.crc).finalize();
        self.out.write_all(&[END_MARKER])?;
        self.out.write_all(&self.count.to_le_bytes())?;
        self.out.write_all(&crc.to_le_bytes())?;
        self.out.flush()
    }
}

/// Reads a `.cwb` trace.
///
/// A record that lies whole in the input's buffer is decoded from it in place
/// ([`Self::decode_buffered`]); anything else — a record across the buffer's end, the end
/// marker, a fault of any kind — takes the byte-by-byte path, which locates every fault.
pub struct BinaryReader<R: BufRead> {
    input: R,
    header: TraceHeader,
    offset: u64,
    record_start: u64,
    count: u64,
    crc: crc32fast::Hasher,
    done: bool,
    /// Bytes of the input's buffer decoded in place, not yet checksummed or consumed.
    pending: usize,
}

impl<R: BufRead> BinaryReader<R> {
    /// Opens a trace: reads and checks the fixed header.
    pub fn new(mut input: R) -> Result<Self, TraceError> {
        let mut head = [0u8; HEADER_BYTES as usize];
        let got =
            read_full(&mut input, &mut head).map_err(|e| TraceError::io(Location::Byte(0), &e))?;
        let magic_seen = &head[..got.min(8)];
        if magic_seen != &MAGIC[..magic_seen.len()] {
            return Err(TraceError::new(
                ErrorKind::Corrupt,
                Location::Byte(0),
                format!(
                    "bad magic \"{}\"; a .cwb trace starts with \"CWBTRACE\"",
                    magic_seen.escape_ascii()
                ),
            ));
        }
        if got < head.len() {
            return Err(TraceError::new(
                ErrorKind::Truncated,
                Location::Byte(got as u64),
                format!("the file ends inside the {HEADER_BYTES}-byte header"),
            ));
        }
        let version = u16::from_le_bytes([head[8], head[9]]);
        let channels = head[10];
        if head[11] != 0 {
            return Err(TraceError::new(
                ErrorKind::Corrupt,
                Location::Byte(11),
                format!("reserved header byte is {:#04x}, expected 0", head[11]),
            ));
        }
        let width = u32::from_le_bytes(head[12..16].try_into().expect("4 bytes"));
        let lines = u32::from_le_bytes(head[16..20].try_into().expect("4 bytes"));
        let header = header_from_u64(version.into(), width.into(), lines.into(), channels.into())
            .map_err(|f| {
            let offset = match f.field {
                "version" => 8,
                "channels" => 10,
                "width" => 12,
                _ => 16,
            };
            TraceError::new(ErrorKind::Header, Location::Byte(offset), f.message)
        })?;
        Ok(BinaryReader {
            input,
            header,
            offset: HEADER_BYTES,
            record_start: HEADER_BYTES,
            count: 0,
            crc: crc32fast::Hasher::new(),
            done: false,
            pending: 0,
        })
    }

    fn truncated(&self, what: &str) -> TraceError {
        TraceError::new(
            ErrorKind::Truncated,
            Location::Byte(self.offset),
            format!(
                "the file ends inside {what} (record {} starting at byte {})",
                self.count + 1,
                self.record_start
            ),
        )
    }

    /// Reads exactly `buf.len()` bytes (into the checksum when `checked`).
    fn take(&mut self, buf: &mut [u8], what: &str, checked: bool) -> Result<(), TraceError> {
        let got = read_full(&mut self.input, buf)
            .map_err(|e| TraceError::io(Location::Byte(self.offset), &e))?;
        if checked {
            self.crc.update(&buf[..got]);
        }
        self.offset += got as u64;
        if got < buf.len() {
            return Err(self.truncated(what));
        }
        Ok(())
    }

    fn varint(&mut self, name: &str) -> Result<u32, TraceError> {
        let start = self.offset;
        let mut v: u64 = 0;
        for i in 0..5 {
            let mut b = [0u8];
            self.take(&mut b, &format!("the varint `{name}`"), true)?;
            v |= u64::from(b[0] & 0x7F) << (7 * i);
            if b[0] & 0x80 == 0 {
                if i > 0 && b[0] == 0 {
                    return Err(TraceError::new(
                        ErrorKind::Corrupt,
                        Location::Byte(start),
                        format!("non-canonical varint for `{name}` (a trailing zero byte)"),
                    ));
                }
                return u32::try_from(v).map_err(|_| {
                    TraceError::new(
                        ErrorKind::Corrupt,
                        Location::Byte(start),
                        format!("varint `{name}` = {v} does not fit in 32 bits"),
                    )
                });
            }
        }
        Err(TraceError::new(
            ErrorKind::Corrupt,
            Location::Byte(start),
            format!("varint `{name}` is longer than 5 bytes"),
        ))
    }

    fn footer(&mut self) -> Result<(), TraceError> {
        let mut tail = [0u8; 12];
        self.take(&mut tail, END_WHAT, false)?;
        let count = u64::from_le_bytes(tail[..8].try_into().expect("8 bytes"));
        let crc = u32::from_le_bytes(tail[8..].try_into().expect("4 bytes"));
        if count != self.count {
            return Err(TraceError::new(
                ErrorKind::Corrupt,
                Location::Byte(self.record_start + 1),
                format!(
                    "the end marker counts {count} instructions, the file holds {}",
                    self.count
                ),
            ));
        }
        let actual = std::mem::take(&mut self.crc).finalize();
        if crc != actual {
            return Err(TraceError::new(
                ErrorKind::Corrupt,
                Location::Byte(self.record_start + 9),
                format!("checksum mismatch: the end marker says {crc:#010x}, the records give {actual:#010x}"),
            ));
        }
        let mut extra = [0u8; 1];
        let got = read_full(&mut self.input, &mut extra)
            .map_err(|e| TraceError::io(Location::Byte(self.offset), &e))?;
        if got != 0 {
            return Err(TraceError::new(
                ErrorKind::Corrupt,
                Location::Byte(self.offset),
                "trailing bytes after the end marker",
            ));
        }
        Ok(())
    }
}

fn read_full<R: Read>(r: &mut R, buf: &mut [u8]) -> io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// A canonical varint of at most 5 bytes, fitting in 32 bits, at the start of `b`: the
/// value and its length; `None` for anything else (a short slice included).
#[inline]
fn varint_at(b: &[u8]) -> Option<(u32, usize)> {
    let mut v: u64 = 0;
    for (i, &byte) in b.iter().take(5).enumerate() {
        v |= u64::from(byte & 0x7F) << (7 * i);
        if byte & 0x80 == 0 {
            if i > 0 && byte == 0 {
                return None;
            }
            return Some((u32::try_from(v).ok()?, i + 1));
        }
    }
    None
}

impl<R: BufRead> BinaryReader<R> {
    /// The next record decoded straight from the input's buffer, if it lies there whole
    /// and is sound (a known opcode, canonical varints, operands that pass
    /// [`Instruction::check`]); `None` leaves it for the byte-by-byte path, which then
    /// finds the same record (or the end marker, or the fault and where it is).
    ///
    /// Records decoded here stay in the buffer (`self.pending` bytes of it) until the
    /// buffer is used up or the byte-by-byte path needs the input: then they go into
    /// the checksum in one piece and are consumed ([`Self::settle`]).
    ///
    /// Always inlined: out of line, the record came back through memory, written as
    /// 8-byte fields and copied on with 16-byte loads, which store forwarding cannot
    /// serve (a stall per instruction, half of `read_batch`'s time).
    #[inline(always)]
    fn decode_buffered(&mut self) -> Option<Instruction> {
        if let Some(i) = self.decode_at_pending() {
            return Some(i);
        }
        if self.pending == 0 {
            return None;
        }
        // the buffer is used up (or the next record lies across its end): refill
        self.settle();
        self.decode_at_pending()
    }

    /// Checksums and consumes the records decoded in place.
    fn settle(&mut self) {
        if self.pending > 0 {
            if let Ok(buf) = self.input.fill_buf() {
                self.crc.update(&buf[..self.pending]);
            }
            self.input.consume(self.pending);
            self.pending = 0;
        }
    }

    #[inline(always)]
    fn decode_at_pending(&mut self) -> Option<Instruction> {
        if self.header.channel_count() == 1 {
            self.decode_record::<true>()
        } else {
            self.decode_record::<false>()
        }
    }

    /// [`Self::decode_at_pending`] for a grey trace (`GREY`) or any other.
    #[inline(always)]
    fn decode_record<const GREY: bool>(&mut self) -> Option<Instruction> {
        let width = self.header.width;
        let channels = if GREY { 1 } else { self.header.channel_count() };
        let buf = self.input.fill_buf().ok()?.get(self.pending..)?;
        let op = Opcode::from_code(*buf.first()?)?;
        let mut at = 1;
        let (mut x, mut dx) = (0u32, 0u32);
        let (mut grey, mut present) = ([0.0; 3], 0u8);
        let mut wide = if GREY {
            None
        } else {
            Some([Intensity::NONE; 3])
        };
        for kind in op.operands() {
            match kind {
                OperandKind::X => {
                    let (v, n) = varint_at(&buf[at..])?;
                    if v >= width {
                        return None;
                    }
                    (x, at) = (v, at + n);
                }
                OperandKind::Count | OperandKind::Period => {
                    let (v, n) = varint_at(&buf[at..])?;
                    let bad = if *kind == OperandKind::Count {
                        u64::from(x) + u64::from(v) > u64::from(width)
                    } else {
                        v == 0
                    };
                    if bad {
                        return None;
                    }
                    (dx, at) = (v, at + n);
                }
                _ => {
                    let slot = kind.value_slot().expect("value");
                    let raw = buf.get(at..at + 8 * channels)?;
                    let mut vals = [0.0; MAX_CHANNELS];
                    for (v, b) in vals.iter_mut().zip(raw.chunks_exact(8)) {
                        *v = f64::from_le_bytes(b.try_into().expect("8 bytes"));
                        if !v.is_finite() {
                            return None;
                        }
                    }
                    match &mut wide {
                        None => {
                            grey[slot] = vals[0];
                            present |= 1 << slot;
                        }
                        Some(w) => w[slot] = Intensity::new(&vals[..channels]),
                    }
                    at += 8 * channels;
                }
            }
        }
        // the operands in range and finite, the channel count the header's: what
        // `Instruction::check` asks
        let instr = match wide {
            None => Instruction::grey(op, x, dx, present, grey),
            Some(w) => Instruction::from_parts(op, x, dx, w),
        };
        debug_assert!(instr.check(&self.header).is_ok());
        self.pending += at;
        self.record_start = self.offset;
        self.offset += at as u64;
        self.count += 1;
        Some(instr)
    }
}

impl<R: BufRead> TraceRead for BinaryReader<R> {
    fn header(&self) -> &TraceHeader {
        &self.header
    }

    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        if self.done {
            return Ok(None);
        }
        if let Some(instr) = self.decode_buffered() {
            return Ok(Some(instr));
        }
        self.settle();
        self.record_start = self.offset;
        let mut code = [0u8];
        let got = read_full(&mut self.input, &mut code)
            .map_err(|e| TraceError::io(Location::Byte(self.offset), &e))?;
        if got == 0 {
            return Err(TraceError::new(
                ErrorKind::Truncated,
                Location::Byte(self.offset),
                format!("the file ends after {} instruction(s) without the end marker; was it cut short?", self.count),
            ));
        }
        self.offset += 1;
        if code[0] == END_MARKER {
            self.footer()?;
            self.done = true;
            return Ok(None);
        }
        self.crc.update(&code);
        let Some(op) = Opcode::from_code(code[0]) else {
            return Err(TraceError::new(
                ErrorKind::UnknownOpcode,
                Location::Byte(self.record_start),
                format!(
                    "unknown opcode byte {:#04x}; expected 0x01..=0x{:02X} or the end marker 0xFF",
                    code[0],
                    Opcode::COUNT
                ),
            ));
        };
        let (mut x, mut dx) = (0, 0);
        let mut values = [Intensity::NONE; 3];
        let channels = self.header.channel_count();
        for kind in op.operands() {
            match kind {
                OperandKind::X => x = self.varint("x")?,
                OperandKind::Count | OperandKind::Period => dx = self.varint("dx")?,
                _ => {
                    let mut raw = [0u8; 8 * MAX_CHANNELS];
                    let what = format!("the operand `{}` of {op}", kind.name());
                    self.take(&mut raw[..8 * channels], &what, true)?;
                    let mut vals = [0.0; MAX_CHANNELS];
                    for (k, v) in vals.iter_mut().take(channels).enumerate() {
                        *v = f64::from_le_bytes(raw[8 * k..8 * k + 8].try_into().expect("8 bytes"));
                    }
                    values[kind.value_slot().expect("value")] = Intensity::new(&vals[..channels]);
                }
            }
        }
        let instr = Instruction::from_parts(op, x, dx, values);
        instr
            .check(&self.header)
            .map_err(|e| operand_error(e, Location::Byte(self.record_start), op))?;
        self.count += 1;
        Ok(Some(instr))
    }

    fn location(&self) -> Location {
        Location::Byte(self.record_start)
    }

    fn bytes_read(&self) -> u64 {
        self.offset
    }

    fn read_batch(&mut self, out: &mut Vec<Instruction>, max: usize) -> Result<usize, TraceError> {
        let mut n = 0;
        while n < max.max(1) {
            if let Some(i) = self.decode_buffered() {
                out.push(i);
            } else if let Some(i) = self.next_instruction()? {
                out.push(i);
            } else {
                break;
            }
            n += 1;
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::read_all;

    fn encode(instrs: &[Instruction]) -> Vec<u8> {
        let h = TraceHeader::new(256, 4, 1).unwrap();
        let mut buf = Vec::new();
        let mut w = BinaryWriter::new(&mut buf, &h).unwrap();
        for i in instrs {
            w.write(i).unwrap();
        }
        w.finish().unwrap();
        buf
    }

    fn decode(bytes: &[u8]) -> Result<Vec<Instruction>, TraceError> {
        let mut r = BinaryReader::new(bytes)?;
        read_all(&mut r)
    }

    #[test]
    fn round_trips_and_is_compact() {
        let v = vec![
            Instruction::eval2(3, 200, Intensity::grey(0.5), Intensity::grey(-1e-9)),
            Instruction::refresh(),
        ];
        let bytes = encode(&v);
        // header 20 + (1 + 1 + 2 + 16) + 1 + footer 13
        assert_eq!(bytes.len(), 20 + 20 + 1 + 13);
        assert_eq!(decode(&bytes).unwrap(), v);
    }

    /// The in-buffer path and the byte-by-byte one give the same instructions and the
    /// same faults at the same offsets, whatever the buffer's size (a record across its
    /// end takes the byte-by-byte path).
    #[test]
    fn any_buffer_size_reads_the_same() {
        let bytes = encode(&[
            Instruction::eval3(
                200,
                50,
                Intensity::grey(1.0),
                Intensity::grey(-0.5),
                Intensity::grey(0.25),
            ),
            Instruction::set_pi(3, 7, Intensity::grey(2.0)),
            Instruction::dis(0, 256),
            Instruction::refresh(),
        ]);
        let outcome = |r: Result<Vec<Instruction>, TraceError>| {
            r.map_err(|e| (e.kind, e.location, e.to_string()))
        };
        let mut variants = vec![bytes.clone()];
        for at in 0..bytes.len() {
            for bit in [0x01, 0x80] {
                let mut b = bytes.clone();
                b[at] ^= bit;
                variants.push(b);
            }
            variants.push(bytes[..at].to_vec());
        }
        for v in &variants {
            let whole = outcome(decode(v));
            for cap in [1, 2, 5, 13] {
                let r = BinaryReader::new(io::BufReader::with_capacity(cap, &v[..]))
                    .and_then(|mut r| read_all(&mut r));
                assert_eq!(outcome(r), whole, "buffer {cap}");
            }
        }
    }

    #[test]
    fn tells_truncated_from_corrupt() {
        let bytes = encode(&[
            Instruction::eval1(0, 4, Intensity::grey(1.0)),
            Instruction::refresh(),
        ]);
        for cut in 0..bytes.len() {
            let e = decode(&bytes[..cut]).unwrap_err();
            assert_eq!(e.kind, ErrorKind::Truncated, "cut {cut}: {e}");
        }
        let mut flipped = bytes.clone();
        flipped[25] ^= 0x01; // inside the f64 of Eval1
        assert_eq!(decode(&flipped).unwrap_err().kind, ErrorKind::Corrupt);
        let mut extra = bytes.clone();
        extra.push(0);
        assert_eq!(decode(&extra).unwrap_err().kind, ErrorKind::Corrupt);
        let mut bad_op = bytes.clone();
        bad_op[20] = 0x42;
        let e = decode(&bad_op).unwrap_err();
        assert_eq!(
            (e.kind, e.location),
            (ErrorKind::UnknownOpcode, Location::Byte(20))
        );
    }
}
