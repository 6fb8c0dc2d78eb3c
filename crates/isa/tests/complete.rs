//! A trace file cut short is never read as a success (the issue: `head -c 50000 pot.cwt`
//! replayed 65 of the header's 400 lines and accepted `0.176…` cut to `0.`): through
//! `FileReader`, every cut of a file in every encoding is refused, unless what is left
//! is a positive whole number of frames of whole instructions.

use cwisim_isa::io::read_all;
use cwisim_isa::{
    Completeness, Encoding, ErrorKind, FileReader, Instruction, Intensity, Location, Opcode,
    TraceError, TraceHeader,
};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("isa-complete");
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(format!("{}-{name}", std::process::id()))
}

/// `scanlines` scanlines, each two `Eval`s with values of many digits and a `Refresh`
/// (the first value of scanline `k`: `0.1764321 + k/1000`).
fn scanlines(n: u32) -> Vec<Instruction> {
    let mut v = Vec::new();
    for k in 0..n {
        let a = 0.176_432_1 + f64::from(k) * 1e-3;
        v.push(Instruction::eval1(3, 2, Intensity::grey(a)));
        v.push(Instruction::eval2(
            0,
            8,
            Intensity::grey(a * 3.0),
            Intensity::grey(-a / 7.0),
        ));
        v.push(Instruction::refresh());
    }
    v
}

fn encode(enc: Encoding, header: &TraceHeader, instrs: &[Instruction]) -> Vec<u8> {
    let mut buf = Vec::new();
    let mut w = enc.writer(&mut buf, header).expect("in-memory writer");
    for i in instrs {
        w.write(i).expect("in-memory write");
    }
    w.finish().expect("in-memory finish");
    drop(w);
    buf
}

fn read_file(path: &Path, bytes: &[u8]) -> Result<Vec<Instruction>, TraceError> {
    std::fs::write(path, bytes).expect("temp file");
    let result = FileReader::open(path).and_then(|mut r| read_all(&mut r));
    std::fs::remove_file(path).ok();
    result
}

/// The issue's file: 400 lines per frame, cut after 65 scanlines' `Refresh`es, inside
/// the value (`0.241…`) of the next instruction.
#[test]
fn the_issues_file_cut_mid_number_after_a_refresh_is_refused() {
    let header = TraceHeader::new(16, 400, 1).expect("header");
    let text = String::from_utf8(encode(Encoding::Text, &header, &scanlines(400))).expect("utf-8");
    // the start of the instruction after the 65th Refresh
    let line = text
        .match_indices("Refresh\n")
        .nth(64)
        .map(|(at, r)| at + r.len())
        .expect("65 Refreshes");
    assert!(
        text[line..].starts_with("Eval1 3 2 0.2"),
        "{}",
        &text[line..line + 40]
    );
    let value = line + "Eval1 3 2 ".len();
    let path = scratch("pot.cwt");
    // cut to `0.`: the number is refused where its digit is missing
    let e = read_file(&path, &text.as_bytes()[..value + 2]).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Syntax, "{e}");
    assert_eq!(
        e.location,
        Location::Line {
            line: 197,
            column: 13
        },
        "{e}"
    );
    assert!(e.message.contains("a digit after the decimal point"), "{e}");
    // cut to `0.24`, a number: the trace is refused at its end, naming the scanlines
    let e = read_file(&path, &text.as_bytes()[..value + 4]).unwrap_err();
    assert_eq!((e.kind, e.location), (ErrorKind::Incomplete, Location::End));
    assert_eq!(
        e.to_string(),
        format!(
            "{}: the trace ends after 65 scanlines, inside frame 0 (65 of its 400 lines): it is incomplete (cut short?); the file ends at byte {}",
            path.display(),
            value + 4
        )
    );
    // cut at a line's end
    let e = read_file(&path, &text.as_bytes()[..line]).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Incomplete, "{e}");
    // --keep-partial: read to the end, and told where it ended
    std::fs::write(&path, &text.as_bytes()[..value + 4]).expect("temp file");
    let mut r = FileReader::open(&path).expect("open");
    r.allow_incomplete();
    let v = read_all(&mut r).expect("allowed");
    std::fs::remove_file(&path).ok();
    assert_eq!(v.len(), 3 * 65 + 1);
    match r.completeness() {
        Completeness::Incomplete(i) => assert_eq!((i.scanlines, i.frame()), (65, 0)),
        c => panic!("{c:?}"),
    }
    // and whole, it reads
    assert_eq!(
        read_file(&path, text.as_bytes()).expect("whole").len(),
        3 * 400
    );
}

/// Every cut of a two-frame trace, in every encoding: refused, or a positive whole
/// number of frames whose instructions are the trace's (but for a last one, after the
/// last `Refresh`, whose value a text cut may have shortened).
#[test]
fn no_cut_of_a_file_reads_as_a_partial_success() {
    let header = TraceHeader::new(8, 3, 1).expect("header");
    let trace = scanlines(6);
    for (enc, ext) in Encoding::ALL {
        let bytes = encode(enc, &header, &trace);
        let path = scratch(&format!("cut.{ext}"));
        let (mut accepted, mut incomplete) = (0, 0);
        for cut in 0..=bytes.len() {
            match read_file(&path, &bytes[..cut]) {
                Ok(v) => {
                    accepted += 1;
                    let refreshes = v.iter().filter(|i| i.op == Opcode::Refresh).count();
                    assert!(
                        refreshes == 3 || refreshes == 6,
                        "{ext} cut {cut}: {refreshes}"
                    );
                    let kept = v.len().min(trace.len());
                    let last_whole = if v.last().is_some_and(|i| i.op != Opcode::Refresh) {
                        kept - 1
                    } else {
                        kept
                    };
                    assert_eq!(v[..last_whole], trace[..last_whole], "{ext} cut {cut}");
                }
                Err(e) => {
                    assert!(cut < bytes.len(), "{ext}: the whole file refused: {e}");
                    incomplete += usize::from(e.kind == ErrorKind::Incomplete);
                }
            }
        }
        // a cut is accepted only at the end of a frame or after it, before the next
        // frame's first Refresh
        assert!(accepted >= 1, "{ext}");
        if enc == Encoding::Binary {
            // the end marker and its footer: any cut is truncated
            assert_eq!((accepted, incomplete), (1, 0));
        } else {
            assert!(incomplete > 0, "{ext}: no cut refused as incomplete");
        }
    }
}
