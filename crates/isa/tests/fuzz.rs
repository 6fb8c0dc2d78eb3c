//! Fuzzing every trace reader (`.cwt`, `.jsonl`, `.cwb`) with untrusted input (proptest):
//! arbitrary bytes and strings, and structure-aware mutations of the golden traces in
//! `traces/` (converted to each encoding with the crate's writers).
//!
//! Properties of every input: the reader does not panic; it finishes in well under
//! [`TIME_BOUND`] (a bound to catch hangs, not to measure speed); every refusal is
//! located (line and column for text and JSON Lines, a byte offset within the input for
//! binary; `Location::File` only where a file could not be opened) with a one-line,
//! non-empty message; and every acceptance re-encodes, in every encoding, to a trace that
//! reads back equal. Through `FileReader`, a file reads as it does in memory, except that
//! a trace that is not a whole number of frames is refused at its end.
//!
//! Cases per run (debug, 2 cores: about 1 s in all): `arbitrary_bytes` 512 (× 3
//! encodings), `arbitrary_text` 512 (× 2), `after_a_valid_header` 512 (× 3),
//! `valid_traces_with_extreme_operands` 512 (× 3), `mutated_golden_traces` 3072 (about
//! 1024 per encoding), `file_reader` 64 (temp files), and one fixed test.

use cwisim_fuzzing::{
    config, delete_member, duplicate_member, json_members, number_tokens, EXTREMES, TIME_BOUND,
};
use cwisim_isa::io::read_all;
use cwisim_isa::{
    Encoding, ErrorKind, FileReader, Instruction, Location, Opcode, TraceError, TraceHeader,
};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

const ENCODINGS: [Encoding; 3] = [Encoding::Text, Encoding::JsonLines, Encoding::Binary];

fn enc_index(enc: Encoding) -> usize {
    ENCODINGS.iter().position(|e| *e == enc).expect("listed")
}

fn encode(enc: Encoding, header: &TraceHeader, instrs: &[Instruction]) -> Vec<u8> {
    let mut buf = Vec::new();
    {
        let mut w = enc.writer(&mut buf, header).expect("in-memory writer");
        for i in instrs {
            w.write(i).expect("in-memory write");
        }
        w.finish().expect("in-memory finish");
    }
    buf
}

type Trace = (TraceHeader, Vec<Instruction>);

fn decode(enc: Encoding, bytes: &[u8]) -> Result<Trace, TraceError> {
    let mut r = enc.reader(bytes)?;
    let v = read_all(&mut *r)?;
    Ok((*r.header(), v))
}

/// The golden traces, decoded, and as bytes of each encoding (`.1[encoding][k]`).
type Seeds = (Vec<Trace>, [Vec<Vec<u8>>; 3]);

/// The golden traces of `traces/`, decoded, and as bytes of each encoding.
fn seeds() -> &'static Seeds {
    static SEEDS: OnceLock<Seeds> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../traces");
        let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
            .expect("traces/")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "cwt"))
            .collect();
        paths.sort();
        assert!(paths.len() >= 5, "golden traces in {}", dir.display());
        let mut traces = Vec::new();
        let mut bytes: [Vec<Vec<u8>>; 3] = Default::default();
        for p in &paths {
            let text = std::fs::read(p).expect("read golden trace");
            let trace = decode(Encoding::Text, &text).unwrap_or_else(|e| panic!("{e}"));
            bytes[0].push(text);
            bytes[1].push(encode(Encoding::JsonLines, &trace.0, &trace.1));
            bytes[2].push(encode(Encoding::Binary, &trace.0, &trace.1));
            traces.push(trace);
        }
        (traces, bytes)
    })
}

/// The lines of `bytes` (split at `\n`, as the readers count them).
fn line_count(bytes: &[u8]) -> u64 {
    bytes.iter().filter(|&&b| b == b'\n').count() as u64 + 1
}

/// The message is one non-empty line, even where it echoes what the input held (an
/// unknown key, the header's `"format"`, an unknown `"op"` with an escaped `\n` in it):
/// the error's display escapes control characters.
fn check_message(e: &TraceError, _input: &[u8]) -> Result<(), TestCaseError> {
    prop_assert!(!e.message.trim().is_empty(), "empty message: {e:?}");
    prop_assert!(
        !e.to_string().contains(|c: char| c.is_control()),
        "message of more than one printable line: {e:?}"
    );
    Ok(())
}

/// Reads `bytes` as `enc` and checks every property; returns whether it was accepted.
fn check(enc: Encoding, bytes: &[u8]) -> Result<bool, TestCaseError> {
    let start = Instant::now();
    let result = decode(enc, bytes);
    let took = start.elapsed();
    prop_assert!(
        took < TIME_BOUND,
        "{enc:?}: {took:?} on {} bytes",
        bytes.len()
    );
    match result {
        Err(e) => {
            check_message(&e, bytes)?;
            prop_assert!(e.path.is_none(), "{e:?}");
            match (enc, e.location) {
                (Encoding::Binary, Location::Byte(b)) => {
                    prop_assert!(
                        b <= bytes.len() as u64,
                        "{e:?} beyond {} bytes",
                        bytes.len()
                    );
                }
                (Encoding::Text | Encoding::JsonLines, Location::Line { line, column }) => {
                    prop_assert!(line >= 1 && column >= 1, "{e:?}");
                    prop_assert!(line <= line_count(bytes), "{e:?}: past the last line");
                }
                _ => prop_assert!(false, "{enc:?}: unlocated or mislocated: {e:?}"),
            }
            Ok(false)
        }
        Ok((header, instrs)) => {
            // accepted: every encoding writes it back and reads it back equal
            let text = encode(Encoding::Text, &header, &instrs);
            for e2 in ENCODINGS {
                let again = encode(e2, &header, &instrs);
                let back = decode(e2, &again);
                prop_assert!(back.is_ok(), "{e2:?} cannot read back: {back:?}");
                let (h2, i2) = back.expect("checked");
                prop_assert_eq!(h2, header);
                prop_assert_eq!(&i2, &instrs);
                // bit-exact, -0.0 included
                prop_assert_eq!(&encode(Encoding::Text, &h2, &i2), &text);
            }
            Ok(true)
        }
    }
}

/// A mutation; its numbers are reduced modulo whatever they index.
#[derive(Clone, Debug)]
enum Mutation {
    /// XOR one byte with a non-zero mask.
    Flip(usize, u8),
    /// Keep only the first bytes.
    Truncate(usize),
    /// This input's head, then another seed's tail.
    Splice(usize, usize, usize),
    /// Insert a copy of a slice somewhere.
    Duplicate(usize, usize, usize),
    /// Replace a number token (text, JSON Lines) or 1, 4 or 8 bytes (binary) with an
    /// extreme value.
    Extreme(usize, usize),
    /// Delete a key with its value (JSON Lines; elsewhere a slice).
    DeleteKey(usize),
    /// Duplicate a key with its value (JSON Lines; elsewhere a slice).
    DuplicateKey(usize),
    /// Wrap a value in `[]` (JSON Lines; elsewhere a number token).
    Wrap(usize),
    /// Binary: fix the end marker's count and checksum, so that the records are judged.
    Reseal,
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(p, m)| Mutation::Flip(p, m)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), any::<usize>(), any::<usize>())
            .prop_map(|(s, a, b)| Mutation::Splice(s, a, b)),
        (any::<usize>(), 0usize..64, any::<usize>())
            .prop_map(|(s, n, at)| Mutation::Duplicate(s, n, at)),
        (any::<usize>(), any::<usize>()).prop_map(|(t, x)| Mutation::Extreme(t, x)),
        any::<usize>().prop_map(Mutation::DeleteKey),
        any::<usize>().prop_map(Mutation::DuplicateKey),
        any::<usize>().prop_map(Mutation::Wrap),
        Just(Mutation::Reseal),
    ]
}

fn varint(mut v: u64) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let byte = (v & 0x7F) as u8;
        v >>= 7;
        if v == 0 {
            out.push(byte);
            return out;
        }
        out.push(byte | 0x80);
    }
}

/// Binary: the bytes of an extreme value (an f64, a u32, a varint or one byte).
fn extreme_bytes(x: usize) -> Vec<u8> {
    let t = EXTREMES[x % EXTREMES.len()];
    match (x / EXTREMES.len()) % 4 {
        0 => t.parse::<f64>().unwrap_or(f64::NAN).to_le_bytes().to_vec(),
        1 => (t.parse::<f64>().unwrap_or(0.0) as u32)
            .to_le_bytes()
            .to_vec(),
        2 => varint(t.parse::<f64>().unwrap_or(0.0) as u64),
        _ => vec![[0x00, 0xFF, 0x80, 0x7F][x % 4]],
    }
}

/// Binary: if the only fault is the end marker's count or checksum, the same bytes with
/// them fixed.
fn reseal(b: &mut [u8]) {
    let Err(e) = decode(Encoding::Binary, b) else {
        return;
    };
    let Location::Byte(at) = e.location else {
        return;
    };
    let at = at as usize;
    let marker = if e.message.contains("end marker counts") {
        at - 1
    } else if e.message.contains("checksum mismatch") {
        at - 9
    } else {
        return;
    };
    let mut count = 0u64;
    if let Ok(mut r) = Encoding::Binary.reader(&b[..]) {
        while let Ok(Some(_)) = r.next_instruction() {
            count += 1;
        }
    }
    let crc = crc32fast::hash(&b[20..marker]);
    b[marker + 1..marker + 9].copy_from_slice(&count.to_le_bytes());
    b[marker + 9..marker + 13].copy_from_slice(&crc.to_le_bytes());
}

fn apply(enc: Encoding, mut b: Vec<u8>, m: &Mutation) -> Vec<u8> {
    let pool = &seeds().1[enc_index(enc)];
    let len = b.len();
    match *m {
        Mutation::Flip(p, mask) => {
            if len > 0 {
                b[p % len] ^= mask;
            }
        }
        Mutation::Truncate(p) => b.truncate(p % (len + 1)),
        Mutation::Splice(s, p, q) => {
            let other = &pool[s % pool.len()];
            b.truncate(p % (len + 1));
            b.extend_from_slice(&other[q % (other.len() + 1)..]);
        }
        Mutation::Duplicate(s, n, at) => {
            if len > 0 {
                let s = s % len;
                let slice = b[s..(s + n).min(len)].to_vec();
                let at = at % (len + 1);
                b.splice(at..at, slice);
            }
        }
        Mutation::Extreme(t, x) if enc == Encoding::Binary => {
            let bytes = extreme_bytes(x);
            if len > 0 {
                let at = t % len;
                let end = (at + bytes.len()).min(len);
                b.splice(at..end, bytes);
            }
        }
        Mutation::Extreme(t, x) => {
            let toks = number_tokens(&b);
            if !toks.is_empty() {
                let (s, e) = toks[t % toks.len()];
                b.splice(s..e, EXTREMES[x % EXTREMES.len()].bytes());
            }
        }
        Mutation::DeleteKey(k) | Mutation::DuplicateKey(k) | Mutation::Wrap(k)
            if enc == Encoding::JsonLines =>
        {
            let members = json_members(&b);
            if members.is_empty() {
                return b;
            }
            match m {
                Mutation::DeleteKey(_) => delete_member(&mut b, k),
                Mutation::DuplicateKey(_) => duplicate_member(&mut b, k),
                _ => {
                    let (_, vs, ve) = members[k % members.len()];
                    b.insert(ve, b']');
                    b.insert(vs, b'[');
                }
            }
        }
        Mutation::DeleteKey(k) => {
            if len > 0 {
                let s = k % len;
                b.drain(s..(s + 1 + k % 16).min(len));
            }
        }
        Mutation::DuplicateKey(k) => return apply(enc, b, &Mutation::Duplicate(k, 16, k / 7)),
        Mutation::Wrap(k) => {
            let toks = number_tokens(&b);
            if !toks.is_empty() && enc == Encoding::Text {
                let (s, e) = toks[k % toks.len()];
                b.insert(e, b']');
                b.insert(s, b'[');
            }
        }
        Mutation::Reseal => {
            if enc == Encoding::Binary {
                reseal(&mut b);
            }
        }
    }
    b
}

fn encoding() -> impl Strategy<Value = Encoding> {
    prop_oneof![
        Just(Encoding::Text),
        Just(Encoding::JsonLines),
        Just(Encoding::Binary)
    ]
}

/// Any finite or extreme value, and any operand, for traces that are valid bytes but
/// may carry values a reader must refuse.
fn extreme_value() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<u64>().prop_map(f64::from_bits),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(-0.0),
        Just(1e308),
        Just(5e-324),
        -2.0f64..2.0,
    ]
}

proptest! {
    // 512 cases each (× 3 or 2 encodings).
    #![proptest_config(config(512))]

    #[test]
    fn arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        for enc in ENCODINGS {
            check(enc, &bytes)?;
        }
    }

    #[test]
    fn arbitrary_text(chars in proptest::collection::vec(any::<char>(), 0..300)) {
        let text: String = chars.into_iter().collect();
        check(Encoding::Text, text.as_bytes())?;
        check(Encoding::JsonLines, text.as_bytes())?;
    }

    /// A valid header (of a golden trace), then anything: the instruction readers.
    #[test]
    fn after_a_valid_header(
        seed in any::<usize>(),
        tail in proptest::collection::vec(any::<u8>(), 0..400),
        text in proptest::collection::vec(any::<char>(), 0..200),
    ) {
        let (traces, _) = seeds();
        let (header, _) = &traces[seed % traces.len()];
        let text: String = text.into_iter().collect();
        for enc in ENCODINGS {
            let mut b = encode(enc, header, &[]);
            if enc == Encoding::Binary {
                b.truncate(20);
                b.extend_from_slice(&tail);
            } else {
                b.extend_from_slice(text.as_bytes());
            }
            check(enc, &b)?;
        }
    }

    /// A valid trace whose operands are extreme: x, dx anywhere in u32, values NaN,
    /// infinite, subnormal.
    #[test]
    fn valid_traces_with_extreme_operands(
        seed in any::<usize>(),
        edits in proptest::collection::vec(
            (any::<usize>(), prop_oneof![Just(0u32), Just(u32::MAX), any::<u32>()],
             prop_oneof![Just(0u32), Just(u32::MAX), any::<u32>()],
             proptest::collection::vec(extreme_value(), 12)),
            1..4),
    ) {
        let (traces, _) = seeds();
        let (header, instrs) = &traces[seed % traces.len()];
        let mut instrs = instrs.clone();
        for (k, x, dx, vals) in edits {
            if instrs.is_empty() {
                break;
            }
            let n = instrs.len();
            let i = &mut instrs[k % n];
            i.x = x;
            i.dx = dx;
            let c = header.channel_count();
            for s in 0..3 {
                if i.value(s).len() == c {
                    i.set_value(s, cwisim_isa::Intensity::new(&vals[4 * s..4 * s + c]));
                }
            }
        }
        for enc in ENCODINGS {
            check(enc, &encode(enc, header, &instrs))?;
        }
    }
}

proptest! {
    // 3072 cases, about 1024 per encoding, 1 to 4 mutations each (binary: half of them
    // resealed last, so that the records, not the checksum, are judged).
    #![proptest_config(config(3072))]

    #[test]
    fn mutated_golden_traces(
        enc in encoding(),
        seed in any::<usize>(),
        mutations in proptest::collection::vec(mutation(), 1..5),
        reseal_last in any::<bool>(),
    ) {
        let pool = &seeds().1[enc_index(enc)];
        let mut b = pool[seed % pool.len()].clone();
        for m in &mutations {
            b = apply(enc, b, m);
        }
        if reseal_last {
            b = apply(enc, b, &Mutation::Reseal);
        }
        check(enc, &b)?;
    }
}

proptest! {
    // 64 cases: files on disk, through `FileReader` (every error names the file).
    #![proptest_config(config(64))]

    #[test]
    fn file_reader(
        enc in encoding(),
        seed in any::<usize>(),
        mutations in proptest::collection::vec(mutation(), 0..3),
    ) {
        let pool = &seeds().1[enc_index(enc)];
        let mut b = pool[seed % pool.len()].clone();
        for m in &mutations {
            b = apply(enc, b, m);
        }
        let ext = Encoding::ALL[enc_index(enc)].1;
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("isa-fuzz");
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join(format!("t{}-{:?}.{ext}", std::process::id(), std::thread::current().id()));
        std::fs::write(&path, &b).expect("temp file");
        let start = Instant::now();
        let result = FileReader::open(&path).and_then(|mut r| read_all(&mut r));
        prop_assert!(start.elapsed() < TIME_BOUND);
        let in_memory = decode(enc, &b);
        std::fs::remove_file(&path).ok();
        match (result, in_memory) {
            (Ok(v), Ok((h, w))) => {
                prop_assert!(whole_frames(&h, &w), "accepted {} lines per frame: {w:?}", h.lines);
                prop_assert_eq!(v, w);
            }
            // what the in-memory reader reads, the file reader refuses at its end when
            // it is not a whole number of frames
            (Err(e), Ok((h, w))) if e.kind == ErrorKind::Incomplete => {
                prop_assert!(!whole_frames(&h, &w), "{e}");
                prop_assert_eq!(e.location, Location::End);
                prop_assert_eq!(e.path.as_deref(), Some(path.as_path()));
                check_message(&e, &b)?;
            }
            (Err(e), Err(f)) => {
                check_message(&e, &b)?;
                prop_assert_eq!(e.path.as_deref(), Some(path.as_path()));
                prop_assert_eq!(e.location, f.location);
                prop_assert!(e.to_string().starts_with(&path.display().to_string()));
            }
            (r, m) => prop_assert!(false, "file and memory disagree: {r:?} vs {m:?}"),
        }
    }
}

/// Whether a trace holds a positive whole number of frames (what `FileReader` accepts).
fn whole_frames(header: &TraceHeader, instrs: &[Instruction]) -> bool {
    let refreshes = instrs.iter().filter(|i| i.op == Opcode::Refresh).count() as u64;
    refreshes > 0 && refreshes.is_multiple_of(u64::from(header.lines))
}

/// An unknown extension and a missing file are refused, naming the file.
#[test]
fn file_level_errors_name_the_file() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("isa-fuzz");
    std::fs::create_dir_all(&dir).expect("temp dir");
    for name in [
        "missing.cwt",
        "missing.jsonl",
        "missing.cwb",
        "trace.txt",
        "noext",
    ] {
        let path = dir.join(name);
        let e = FileReader::open(&path).err().expect("refused");
        assert_eq!(e.location, Location::File, "{e}");
        assert_eq!(e.path.as_deref(), Some(path.as_path()));
        assert!(!e.message.is_empty() && !e.message.contains('\n'), "{e}");
    }
}
