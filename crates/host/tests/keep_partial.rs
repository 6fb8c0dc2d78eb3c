//! `cwisim run --keep-partial`: a trace that turns bad part way still gives the scanlines
//! completed before the bad line, and the error still names that line.

mod common;

use common::{cwisim, cwisim_ok, scratch, text};

/// `lines` good scanlines of a 6-wide, 4-line trace, then `tail`.
fn trace(lines: usize, tail: &str) -> String {
    let mut t = String::from("cwisim-trace version=1 width=6 lines=4 channels=1\n");
    for l in 0..lines {
        t.push_str(&format!(
            "Eval2 0 6 {} 0.125\nRefresh\n",
            0.1 * (l + 1) as f64
        ));
    }
    t.push_str(tail);
    t
}

/// The float64 values of a `.npy` written by cwisim (header, then little-endian f64).
fn npy_values(bytes: &[u8]) -> Vec<f64> {
    let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + header..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn the_completed_scanlines_are_kept_and_the_error_names_the_bad_line() {
    let dir = scratch("keep-partial");
    // line 1 is the header; scanlines take two lines each: the bad line is line 8
    std::fs::write(dir.join("bad.cwt"), trace(3, "Eval2 0 6 0.5\nRefresh\n")).unwrap();
    std::fs::write(dir.join("good.cwt"), trace(3, "")).unwrap();

    // without the flag: nothing written
    let out = cwisim(&dir, &["run", "bad.cwt", "-o", "a.png", "--npy", "a.npy"]);
    assert_eq!(out.status.code(), Some(2));
    let (_, stderr) = text(&out);
    assert!(stderr.contains("bad.cwt:8:"), "{stderr}");
    assert!(!dir.join("a.png").exists() && !dir.join("a.npy").exists());

    // with it: the three scanlines before the bad line, and the same error
    let out = cwisim(
        &dir,
        &[
            "run",
            "bad.cwt",
            "-o",
            "a.png",
            "--npy",
            "a.npy",
            "--keep-partial",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let (_, stderr) = text(&out);
    assert!(stderr.contains("bad.cwt:8:"), "{stderr}");
    assert!(
        stderr.contains("the image is incomplete: it holds the 3 scanline(s)"),
        "{stderr}"
    );
    let png = image::open(dir.join("a.png")).expect("a PNG").to_luma8();
    assert_eq!((png.width(), png.height()), (6, 3));
    // equal to the good prefix replayed on its own: three of a frame's four lines, an
    // incomplete trace that --keep-partial replays with a warning
    let out = cwisim(
        &dir,
        &[
            "run",
            "good.cwt",
            "-o",
            "b.png",
            "--npy",
            "b.npy",
            "--keep-partial",
        ],
    );
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert_eq!(
        stderr,
        "warning: --keep-partial: good.cwt: the trace ends after 3 scanlines, inside frame 0 \
(3 of its 4 lines); the outputs hold its 3 scanline(s)\n"
    );
    assert_eq!(
        std::fs::read(dir.join("a.png")).unwrap(),
        std::fs::read(dir.join("b.png")).unwrap()
    );
    let values = npy_values(&std::fs::read(dir.join("a.npy")).unwrap());
    assert_eq!(
        values,
        npy_values(&std::fs::read(dir.join("b.npy")).unwrap())
    );
    assert_eq!(values.len(), 3 * 6);
    assert_eq!(values[6], 0.2, "scanline 1 starts at 0.2");
}

#[test]
fn a_trace_bad_before_its_first_scanline_keeps_nothing() {
    let dir = scratch("keep-partial-none");
    std::fs::write(dir.join("bad.cwt"), trace(0, "Frobnicate 1\n")).unwrap();
    let out = cwisim(&dir, &["run", "bad.cwt", "-o", "a.png", "--keep-partial"]);
    assert_eq!(out.status.code(), Some(2));
    let (_, stderr) = text(&out);
    assert!(stderr.contains("bad.cwt:2:"), "{stderr}");
    assert!(stderr.contains("no image written"), "{stderr}");
    assert!(!dir.join("a.png").exists());
}

#[test]
fn a_truncated_binary_trace_keeps_its_complete_scanlines() {
    let dir = scratch("keep-partial-cwb");
    // one line a frame: three and four scanlines are both whole traces
    let one_a_frame = |n| trace(n, "").replace("lines=4", "lines=1");
    std::fs::write(dir.join("good.cwt"), one_a_frame(4)).unwrap();
    cwisim_ok(&dir, &["convert", "good.cwt", "good.cwb"]);
    std::fs::write(dir.join("three.cwt"), one_a_frame(3)).unwrap();
    cwisim_ok(&dir, &["convert", "three.cwt", "three.cwb"]);
    let bytes = std::fs::read(dir.join("good.cwb")).unwrap();
    let three = std::fs::read(dir.join("three.cwb")).unwrap().len();
    // the fourth scanline's records start where three.cwb's trailer does, and are longer
    // than the trailer: one byte short of three.cwb's length is inside them
    let cut = three - 1;
    std::fs::write(dir.join("cut.cwb"), &bytes[..cut]).unwrap();
    let out = cwisim(
        &dir,
        &["run", "cut.cwb", "--npy", "a.npy", "--keep-partial"],
    );
    assert_eq!(out.status.code(), Some(2));
    let (_, stderr) = text(&out);
    assert!(stderr.contains("byte"), "located by byte offset: {stderr}");
    let values = npy_values(&std::fs::read(dir.join("a.npy")).unwrap());
    assert_eq!(values.len(), 3 * 6, "the three complete scanlines");
}

#[test]
fn a_trace_cut_between_records_is_refused_unless_kept() {
    let dir = scratch("keep-partial-short");
    // `head -c` at the end of a line: every record whole, the frame short
    std::fs::write(dir.join("short.cwt"), trace(2, "")).unwrap();
    for args in [
        &["run", "short.cwt", "-o", "a.png"][..],
        &["stats", "short.cwt"],
        &["dump", "short.cwt", "--lines", "0"],
        &["history", "short.cwt", "--x", "0", "--line", "0"],
        &["vcd", "short.cwt", "--line", "0", "-o", "a.vcd"],
    ] {
        let out = cwisim(&dir, args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.ends_with(
                "error: short.cwt: the trace ends after 2 scanlines, inside frame 0 (2 of its \
4 lines): it is incomplete (cut short?); the file ends at byte 106\n"
            ),
            "{args:?}: {stderr}"
        );
        assert!(!dir.join("a.png").exists() && !dir.join("a.vcd").exists());
    }
    let out = cwisim(&dir, &["run", "short.cwt", "-o", "a.png", "--keep-partial"]);
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    let png = image::open(dir.join("a.png")).expect("a PNG").to_luma8();
    assert_eq!((png.width(), png.height()), (6, 2));
}
