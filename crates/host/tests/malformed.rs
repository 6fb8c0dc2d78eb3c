//! Malformed inputs through the real binary: each must fail with exit code 2 and exactly
//! one line on standard error, `error: ` + the file name + where (`:LINE:COL` for text and
//! JSON Lines, `byte N` for binary) + what kind of fault — never a panic, never an output
//! file.

mod common;

use common::{cwisim, scratch, text};
use cwisim_isa::{Encoding, Instruction, Intensity, TraceHeader};

/// What the message must say about the kind of fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fault {
    /// The file stops early: the message says so, and does not call it corrupt.
    Truncated,
    /// The bytes contradict the format: the message names how, and does not say it ends.
    Corrupt,
    /// Any other fault (syntax, range, header, arguments…): neither of the above.
    Other,
}

const TRUNCATED_WORDS: [&str; 3] = ["file ends", "cut short", "EOF while parsing"];
const CORRUPT_WORDS: [&str; 3] = ["checksum", "magic", "trailing"];

/// Writes `bytes` to `file` in a fresh directory, runs `cwisim run FILE --npy out.npy
/// EXTRA…`, and checks the failure: `prefix` is how the one stderr line must start (the
/// file and the location), `needles` what it must contain.
fn expect_error(
    case: &str,
    file: &str,
    bytes: impl AsRef<[u8]>,
    extra: &[&str],
    prefix: &str,
    needles: &[&str],
    fault: Fault,
) {
    let dir = scratch(&format!("malformed/{case}"));
    std::fs::write(dir.join(file), bytes.as_ref()).expect("write the input");
    let mut args = vec!["run", file, "--npy", "out.npy"];
    args.extend_from_slice(extra);
    let out = cwisim(&dir, &args);
    let (stdout, stderr) = text(&out);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{case}: exit status; stderr: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{case}: {stderr}");
    assert!(stdout.is_empty(), "{case}: stdout: {stdout}");
    assert!(stderr.ends_with('\n'), "{case}: {stderr:?}");
    assert_eq!(
        stderr.lines().count(),
        1,
        "{case}: more than one line: {stderr}"
    );
    assert!(stderr.starts_with("error: "), "{case}: {stderr}");
    assert!(
        stderr.starts_with(prefix),
        "{case}: expected the prefix `{prefix}`, got: {stderr}"
    );
    for n in needles {
        assert!(stderr.contains(n), "{case}: expected `{n}` in: {stderr}");
    }
    let says_truncated = TRUNCATED_WORDS.iter().any(|w| stderr.contains(w));
    let says_corrupt = CORRUPT_WORDS.iter().any(|w| stderr.contains(w));
    match fault {
        Fault::Truncated => assert!(
            says_truncated && !says_corrupt,
            "{case}: not reported as truncated: {stderr}"
        ),
        Fault::Corrupt => assert!(
            says_corrupt && !says_truncated,
            "{case}: not reported as corrupt: {stderr}"
        ),
        Fault::Other => assert!(
            !says_corrupt && !says_truncated,
            "{case}: misreported: {stderr}"
        ),
    }
    assert!(
        !dir.join("out.npy").exists(),
        "{case}: an output was written"
    );
}

const GREY: &str = "cwisim-trace version=1 width=8 lines=2 channels=1\n";
const JSON_HEADER: &str =
    "{\"format\":\"cwisim-trace\",\"version\":1,\"width\":8,\"lines\":2,\"channels\":1}\n";

/// `GREY` followed by `body`.
fn cwt(body: &str) -> Vec<u8> {
    format!("{GREY}{body}").into_bytes()
}

/// `JSON_HEADER` followed by `body`.
fn jsonl(body: &str) -> Vec<u8> {
    format!("{JSON_HEADER}{body}").into_bytes()
}

/// A valid `.cwb` trace, 53 bytes: header 0..20, `Eval2 0 4 0.5 0.125` 20..39 (opcode,
/// x, dx, then I at 23..31 and dI at 31..39), `Refresh` at 39, end marker at 40, count
/// 41..49, checksum 49..53.
fn cwb() -> Vec<u8> {
    let header = TraceHeader::new(8, 2, 1).expect("header");
    let mut bytes = Vec::new();
    {
        let mut w = Encoding::Binary
            .writer(&mut bytes, &header)
            .expect("writer");
        w.write(&Instruction::eval2(
            0,
            4,
            Intensity::grey(0.5),
            Intensity::grey(0.125),
        ))
        .expect("write");
        w.write(&Instruction::refresh()).expect("write");
        w.finish().expect("finish");
    }
    assert_eq!(bytes.len(), 53);
    bytes
}

/// [`cwb`] with `f` applied.
fn cwb_with(f: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut b = cwb();
    f(&mut b);
    b
}

macro_rules! malformed {
    ($( $name:ident: $file:expr, $bytes:expr, [$($extra:expr),*], $prefix:expr, [$($needle:expr),*], $fault:ident; )*) => {
        $(
            #[test]
            fn $name() {
                expect_error(stringify!($name), $file, $bytes, &[$($extra),*], $prefix, &[$($needle),*], Fault::$fault);
            }
        )*
        /// The number of cases above.
        const CASES: usize = [$(stringify!($name)),*].len();
    };
}

malformed! {
    // --- .cwt: the header
    cwt_empty_file: "t.cwt", b"", [],
        "error: t.cwt:1:1: ", ["the file ends before the header line"], Truncated;
    cwt_comments_only: "t.cwt", b"# nothing but a comment\n\n", [],
        "error: t.cwt:1:1: ", ["the file ends before the header line"], Truncated;
    cwt_missing_header: "t.cwt", b"Eval1 0 8 1.0\nRefresh\n", [],
        "error: t.cwt:1:1: ", ["expected the header", "found `Eval1`"], Other;
    cwt_bad_magic_word: "t.cwt", b"cwisim-trac version=1 width=8 lines=2 channels=1\n", [],
        "error: t.cwt:1:1: ", ["found `cwisim-trac`"], Other;
    cwt_unknown_header_key: "t.cwt", b"cwisim-trace version=1 width=8 lines=2 channels=1 depth=3\n", [],
        "error: t.cwt:1:51: ", ["unknown header key `depth`"], Other;
    cwt_header_key_twice: "t.cwt", b"cwisim-trace version=1 width=8 width=8 lines=2 channels=1\n", [],
        "error: t.cwt:1:32: ", ["`width` given twice"], Other;
    cwt_header_value_not_a_number: "t.cwt", b"cwisim-trace version=1 width=eight lines=2 channels=1\n", [],
        "error: t.cwt:1:30: ", ["unsigned integer for `width`", "`eight`"], Other;
    cwt_absurd_width: "t.cwt", b"cwisim-trace version=1 width=4000000000 lines=2 channels=1\n", [],
        "error: t.cwt:1:24: ", ["width 4000000000 is outside 1..=65536"], Other;
    cwt_width_beyond_u64: "t.cwt", b"cwisim-trace version=1 width=99999999999999999999 lines=2 channels=1\n", [],
        "error: t.cwt:1:30: ", ["unsigned integer for `width`"], Other;
    cwt_width_zero: "t.cwt", b"cwisim-trace version=1 width=0 lines=2 channels=1\n", [],
        "error: t.cwt:1:24: ", ["width 0 is outside 1..=65536"], Other;
    cwt_nine_channels: "t.cwt", b"cwisim-trace version=1 width=8 lines=2 channels=9\n", [],
        "error: t.cwt:1:40: ", ["channels 9 is outside 1..=4"], Other;
    cwt_unsupported_version: "t.cwt", b"cwisim-trace version=7 width=8 lines=2 channels=1\n", [],
        "error: t.cwt:1:14: ", ["unsupported trace format version 7"], Other;
    // --- .cwt: instructions
    cwt_unknown_opcode: "t.cwt", cwt("Evl1 0 8 1.0\n"), [],
        "error: t.cwt:2:1: ", ["unknown opcode `Evl1`", "did you mean `Eval1`?"], Other;
    cwt_opcode_in_wrong_case: "t.cwt", cwt("Eval1 0 8 1.0\nrefresh\n"), [],
        "error: t.cwt:3:1: ", ["unknown opcode `refresh`", "did you mean `Refresh`?"], Other;
    cwt_too_few_operands: "t.cwt", cwt("Eval2 0 4 1.0\n"), [],
        "error: t.cwt:2:14: ", ["`Eval2 x dx I dI` takes 4 operand(s), found 3"], Other;
    cwt_too_many_operands: "t.cwt", cwt("Refresh 3\n"), [],
        "error: t.cwt:2:9: ", ["`Refresh` takes 0 operand(s), found 1"], Other;
    cwt_negative_x: "t.cwt", cwt("Eval1 -1 4 1.0\n"), [],
        "error: t.cwt:2:7: ", ["expected an unsigned integer for `x`, found `-1`"], Other;
    cwt_x_past_the_array: "t.cwt", cwt("SetI 8 1.0\n"), [],
        "error: t.cwt:2:6: ", ["x = 8 is outside the array (width 8"], Other;
    cwt_dx_past_the_array: "t.cwt", cwt("Eval1 4 5 1.0\n"), [],
        "error: t.cwt:2:7: ", ["[4, 9) reaches past the array's end (8)"], Other;
    cwt_x_beyond_u32: "t.cwt", cwt("Eval1 4294967296 1 1.0\n"), [],
        "error: t.cwt:2:7: ", ["does not fit in 32 bits"], Other;
    cwt_setpi_period_zero: "t.cwt", cwt("SetPI 0 0 1.0\n"), [],
        "error: t.cwt:2:7: ", ["SetPI: period dx = 0"], Other;
    cwt_nan_value: "t.cwt", cwt("Eval1 0 8 NaN\n"), [],
        "error: t.cwt:2:11: ", ["finite number for `I`, found `NaN`"], Other;
    cwt_inf_value: "t.cwt", cwt("Eval2 0 8 0.5 -inf\n"), [],
        "error: t.cwt:2:15: ", ["finite number for `dI`, found `-inf`"], Other;
    cwt_overflowing_value: "t.cwt", cwt("Eval1 0 8 1e999\n"), [],
        "error: t.cwt:2:11: ", ["`I` = 1e999 overflows f64"], Other;
    cwt_not_a_number: "t.cwt", cwt("Eval1 0 8 0.5.5\n"), [],
        "error: t.cwt:2:14: ", ["expected the end of the number in the number `0.5.5` for `I`, found `.`"], Other;
    cwt_grey_value_in_rgb_trace: "t.cwt", b"cwisim-trace version=1 width=8 lines=2 channels=3\nEval1 0 8 0.5\n", [],
        "error: t.cwt:2:11: ", ["I has 1 channel value(s)", "the trace has 3"], Other;
    cwt_non_utf8_bytes: "t.cwt", [&cwt("Refresh\nEval1 0 8 ")[..], b"\xff\xfe\n"].concat(), [],
        "error: t.cwt:3:11: ", ["invalid UTF-8"], Other;
    // --- .jsonl
    jsonl_empty_file: "t.jsonl", b"", [],
        "error: t.jsonl:1:1: ", ["the file is empty"], Other;
    jsonl_invalid_json: "t.jsonl", jsonl("{\"op\": Refresh}\n"), [],
        "error: t.jsonl:2:8: ", ["invalid JSON record", "expected value"], Other;
    jsonl_truncated_record: "t.jsonl", jsonl("{\"op\":\"Refresh\"}\n{\"op\":\"Eval1\",\"x\":0,\"dx\":1,"), [],
        "error: t.jsonl:3:", ["invalid JSON record", "EOF while parsing"], Truncated;
    jsonl_unknown_key: "t.jsonl", jsonl("{\"op\":\"Refresh\",\"y\":0}\n"), [],
        "error: t.jsonl:2:", ["unknown field `y`"], Other;
    jsonl_operand_it_does_not_take: "t.jsonl", jsonl("{\"op\":\"Refresh\",\"x\":0}\n"), [],
        "error: t.jsonl:2:1: ", ["`Refresh` has no operand \"x\""], Other;
    jsonl_missing_operand: "t.jsonl", jsonl("{\"op\":\"Eval1\",\"x\":0,\"I\":[1.0]}\n"), [],
        "error: t.jsonl:2:1: ", ["`Eval1 x dx I` lacks operand \"dx\""], Other;
    jsonl_unknown_opcode: "t.jsonl", jsonl("{\"op\":\"Evl2\",\"x\":0,\"dx\":1,\"I\":[1.0],\"dI\":[0.0]}\n"), [],
        "error: t.jsonl:2:1: ", ["unknown opcode \"Evl2\"", "did you mean \"Eval2\"?"], Other;
    jsonl_wrong_channel_count: "t.jsonl", jsonl("{\"op\":\"Eval1\",\"x\":0,\"dx\":1,\"I\":[1.0,0.5,0.0]}\n"), [],
        "error: t.jsonl:2:1: ", ["channel"], Other;
    jsonl_bad_header_format: "t.jsonl", b"{\"format\":\"cwisim-trac\",\"version\":1,\"width\":8,\"lines\":2,\"channels\":1}\n", [],
        "error: t.jsonl:1:1: ", ["header \"format\" is \"cwisim-trac\", expected \"cwisim-trace\""], Other;
    jsonl_header_missing_field: "t.jsonl", b"{\"format\":\"cwisim-trace\",\"version\":1,\"width\":8,\"lines\":2}\n", [],
        "error: t.jsonl:1:", ["expected the header object", "missing field `channels`"], Other;
    // --- .cwb
    cwb_empty_file: "t.cwb", b"", [],
        "error: t.cwb: byte 0: ", ["the file ends inside the 20-byte header"], Truncated;
    cwb_bad_magic: "t.cwb", cwb_with(|b| b[7] = b'X'), [],
        "error: t.cwb: byte 0: ", ["bad magic", "CWBTRACE"], Corrupt;
    cwb_text_given_binary_extension: "t.cwb", cwt("Refresh\n"), [],
        "error: t.cwb: byte 0: ", ["bad magic"], Corrupt;
    cwb_truncated_header: "t.cwb", &cwb()[..12], [],
        "error: t.cwb: byte 12: ", ["the file ends inside the 20-byte header"], Truncated;
    cwb_truncated_mid_record: "t.cwb", &cwb()[..30], [],
        "error: t.cwb: byte 30: ", ["the file ends inside the operand `I` of Eval2", "record 1 starting at byte 20"], Truncated;
    cwb_missing_end_marker: "t.cwb", &cwb()[..40], [],
        "error: t.cwb: byte 40: ", ["without the end marker", "cut short"], Truncated;
    cwb_truncated_footer: "t.cwb", &cwb()[..45], [],
        "error: t.cwb: byte 45: ", ["the file ends inside the end marker"], Truncated;
    cwb_checksum_mismatch: "t.cwb", cwb_with(|b| b[25] ^= 0x01), [],
        "error: t.cwb: byte 49: ", ["checksum mismatch"], Corrupt;
    cwb_unknown_opcode_byte: "t.cwb", cwb_with(|b| b[20] = 0x42), [],
        "error: t.cwb: byte 20: ", ["unknown opcode byte 0x42"], Other;
    cwb_trailing_bytes: "t.cwb", cwb_with(|b| b.extend_from_slice(b"\0\0")), [],
        "error: t.cwb: byte 53: ", ["trailing bytes after the end marker"], Corrupt;
    cwb_absurd_width: "t.cwb", cwb_with(|b| b[12..16].copy_from_slice(&u32::MAX.to_le_bytes())), [],
        "error: t.cwb: byte 12: ", ["width 4294967295 is outside 1..=65536"], Other;
    cwb_x_past_the_array: "t.cwb", cwb_with(|b| b[21] = 9), [],
        "error: t.cwb: byte 20: ", ["x = 9 is outside the array"], Other;
    // --- files and machines
    unknown_extension: "t.txt", cwt("Refresh\n"), [],
        "error: t.txt: unknown input extension `.txt`", [".cwt", ".jsonl", ".cwb", ".json"], Other;
    machine_file_missing: "t.cwt", cwt("Refresh\n"), ["--machine", "m.json"],
        "error: m.json: cannot read the machine file", [], Other;
    set_hop_cycles_zero: "t.cwt", cwt("Refresh\n"), ["--set", "hop_cycles=0"],
        "error: machine parameter `hop_cycles`: must be at least 1", [], Other;
    set_unknown_key: "t.cwt", cwt("Refresh\n"), ["--set", "clok_hz=1e8"],
        "error: override `clok_hz=1e8`: unknown machine parameter `clok_hz`", [], Other;
    set_value_not_json: "t.cwt", cwt("Refresh\n"), ["--set", "clock_hz=fast"],
        "error: override `clock_hz=fast`: the value is not JSON", [], Other;
    clock_too_slow_for_the_display: "t.cwt", cwt("Refresh\n"), ["--set", "clock_hz=10"],
        "error: machine parameter `clock_hz`: 10 Hz gives less than one cycle per line period", [], Other;
}

#[test]
fn nonexistent_file() {
    let dir = scratch("malformed/nonexistent_file");
    let out = cwisim(&dir, &["run", "missing.cwt", "--npy", "out.npy"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(stdout.is_empty());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: missing.cwt: cannot open: "),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
    assert!(!dir.join("out.npy").exists());
}

#[test]
fn machine_file_with_an_unknown_key_is_located() {
    let dir = scratch("malformed/machine_unknown_key");
    std::fs::write(dir.join("t.cwt"), cwt("Refresh\n")).expect("write trace");
    std::fs::write(
        dir.join("m.json"),
        "{\n  \"clock_hz\": 1e8,\n  \"clok\": 1\n}\n",
    )
    .expect("write machine");
    let out = cwisim(
        &dir,
        &["run", "t.cwt", "--machine", "m.json", "--npy", "out.npy"],
    );
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error: m.json:3:"), "{stderr}");
    assert!(stderr.contains("unknown field `clok`"), "{stderr}");
    assert!(!stderr.contains("panicked"));
    assert!(!dir.join("out.npy").exists());
}

// Keep the coverage from shrinking unnoticed: at least 24 malformed inputs.
const _: () = assert!(CASES >= 24);
