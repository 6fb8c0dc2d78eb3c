//! `cwisim dump`, `history` and `diff` on the checked-in traces, through the binary.

mod common;

use common::{cwisim, scratch};
use std::path::{Path, PathBuf};

fn traces() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../traces")
}

fn text(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn dump_annotates_every_instruction_and_reads_back_as_the_same_trace() {
    let dir = scratch("dump_reads_back");
    let overrun = traces().join("overrun.cwt");
    let machine = traces().join("overrun.machine.json");
    let args = [
        "dump",
        overrun.to_str().unwrap(),
        "--machine",
        machine.to_str().unwrap(),
    ];
    let out = cwisim(&dir, &args);
    assert!(out.status.success());
    let dump = text(&out);
    // line 1's Refresh starts at 72, after the line's 68 bus cycles of Evals from cycle 4,
    // and is late (its deadline is 80, it leaves the array at 73 + 16 = 89)
    assert!(
        dump.contains(
            "Refresh                                          # #16 line 1 issue 72 enter 73"
        ),
        "{dump}"
    );
    assert_eq!(dump, text(&cwisim(&dir, &args)), "deterministic");
    // the dump is a valid trace: it converts to the same canonical text as the original
    std::fs::write(dir.join("dump.cwt"), &dump).unwrap();
    assert!(cwisim(&dir, &["convert", "dump.cwt", "a.cwb"])
        .status
        .success());
    assert!(
        cwisim(&dir, &["convert", overrun.to_str().unwrap(), "b.cwb"])
            .status
            .success()
    );
    assert_eq!(
        std::fs::read(dir.join("a.cwb")).unwrap(),
        std::fs::read(dir.join("b.cwb")).unwrap()
    );
    // --lines keeps only those scanlines
    let part = text(&cwisim(
        &dir,
        &["dump", overrun.to_str().unwrap(), "--lines", "2.."],
    ));
    assert!(part.contains("# --- scanline 2") && part.contains("# --- scanline 3"));
    assert!(!part.contains("line 1 issue"), "{part}");
    // --frames: overrun.cwt has 4 scanlines per frame, so frame 0 is scanlines 0..4 and
    // frame 1 does not exist
    let frame0 = text(&cwisim(
        &dir,
        &["dump", overrun.to_str().unwrap(), "--frames", "0"],
    ));
    assert_eq!(
        frame0,
        text(&cwisim(
            &dir,
            &["dump", overrun.to_str().unwrap(), "--lines", "0..4"]
        ))
    );
    let none = text(&cwisim(
        &dir,
        &["dump", overrun.to_str().unwrap(), "--frames", "1.."],
    ));
    assert!(!none.contains("# ---"), "{none}");
    let both = cwisim(
        &dir,
        &[
            "dump",
            overrun.to_str().unwrap(),
            "--frames",
            "0",
            "--lines",
            "1",
        ],
    );
    assert_eq!(both.status.code(), Some(2));
    let bad = cwisim(
        &dir,
        &["dump", overrun.to_str().unwrap(), "--lines", "3..1"],
    );
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn history_shows_each_instruction_with_registers_before_and_after() {
    let dir = scratch("history");
    let vis = traces().join("visibility.cwt");
    let out = cwisim(
        &dir,
        &["history", vis.to_str().unwrap(), "--x", "9", "--y", "0"],
    );
    assert!(out.status.success());
    let h = text(&out);
    // each visit headed by the note of its instruction: the comment lines above it
    let expected = "\
# near object: edge pixels accumulate partial coverage, the interior is claimed
cycle       15  #2      Eval1 9 1 0.375
    before  acc=0.0 I=- dI=- ddI=- flags=-
    after   acc=0.375 I=- dI=- ddI=- flags=-
# far object spans the whole line; it shows only where the near one did not claim
cycle       18  #3      Eval2 0 16 0.0625 0.0
    before  acc=0.375 I=- dI=- ddI=- flags=-
    after   acc=0.4375 I=- dI=- ddI=- flags=-
# a third object tries to claim 6..12: first claim wins on 6..8; on 9..11 Eval0 *sets*,
# overwriting the near object's partial edge pixel 9 (0.4375 -> 0.125): the edge
# error of visibility by Eval0, which the host's eval0 mode measures
cycle       20  #4      Eval0 6 6 0.125
    before  acc=0.4375 I=- dI=- ddI=- flags=-
    after   acc=0.125 I=- dI=- ddI=- flags=locked
cycle       21  #5      Refresh
    before  acc=0.125 I=- dI=- ddI=- flags=locked
    after   acc=0.0 I=- dI=- ddI=- flags=-
shifted out: 0.125
";
    assert!(h.contains(expected), "{h}");
    // preloads show in the registers until the wave consumes them
    let pre = traces().join("preload.cwt");
    let h = text(&cwisim(
        &dir,
        &["history", pre.to_str().unwrap(), "--x", "8", "--y", "1"],
    ));
    assert!(
        h.contains("after   acc=0.0 I=- dI=-0.125 ddI=- flags=-"),
        "{h}"
    );
    assert!(
        h.contains("before  acc=0.0 I=- dI=-0.125 ddI=- flags=-"),
        "{h}"
    );
    // an addressed Eval that a lock suppresses says so
    let h = text(&cwisim(
        &dir,
        &["history", vis.to_str().unwrap(), "--x", "6", "--y", "0"],
    ));
    assert!(
        h.contains("#3      Eval2 0 16 0.0625 0.0  (suppressed: locked by Eval0)"),
        "{h}"
    );
    let h = text(&cwisim(
        &dir,
        &["history", vis.to_str().unwrap(), "--x", "5", "--y", "1"],
    ));
    assert!(
        h.contains("Eval1 0 16 0.5  (suppressed: masked by Dis)"),
        "{h}"
    );
    // --all lists pass-throughs too
    let all = text(&cwisim(
        &dir,
        &[
            "history",
            vis.to_str().unwrap(),
            "--x",
            "9",
            "--y",
            "0",
            "--all",
        ],
    ));
    assert!(all.contains("(passes through)"), "{all}");
    for (args, needle) in [
        (vec!["--x", "16", "--y", "0"], "outside the array"),
        (vec!["--x", "0", "--y", "3"], "outputs only 3 scanline(s)"),
    ] {
        let mut a = vec!["history", vis.to_str().unwrap()];
        a.extend(args);
        let out = cwisim(&dir, &a);
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).contains(needle));
    }
}

#[test]
fn diff_exit_codes_and_reports() {
    let dir = scratch("diff");
    let vis = traces().join("visibility.cwt");
    let v = vis.to_str().unwrap();
    // the same trace in another encoding is equal
    assert!(cwisim(&dir, &["convert", v, "v.cwb"]).status.success());
    let same = cwisim(&dir, &["diff", v, "v.cwb"]);
    assert_eq!(same.status.code(), Some(0), "{}", text(&same));
    // a changed instruction: the first difference names it and its scanline
    let changed = std::fs::read_to_string(&vis)
        .unwrap()
        .replace("Eval1 0 16 0.25", "Eval1 0 16 0.375");
    std::fs::write(dir.join("w.cwt"), changed).unwrap();
    let d = cwisim(&dir, &["diff", v, "w.cwt"]);
    assert_eq!(d.status.code(), Some(1));
    let report = text(&d);
    assert!(
        report.contains("first difference: instruction #8, scanline 1"),
        "{report}"
    );
    assert!(
        report.contains("  A: Eval1 0 16 0.25\n  B: Eval1 0 16 0.375"),
        "{report}"
    );
    // outputs: per-scanline max and RMS; only scanline 1 differs, by 0.125 everywhere
    // (the changed Eval1 comes after the one the Dis masks)
    let o = cwisim(
        &dir,
        &["diff", v, "w.cwt", "--outputs", "--image", "err.png"],
    );
    assert_eq!(o.status.code(), Some(1));
    let report = text(&o);
    assert!(
        report.contains("       1   1.250000e-1   1.250000e-1"),
        "{report}"
    );
    assert!(report.contains("1 of 3 scanline(s) differ"), "{report}");
    let img = image::open(dir.join("err.png")).unwrap().to_luma8();
    assert_eq!(img.dimensions(), (16, 3));
    assert_eq!(img.get_pixel(0, 1).0[0], 255);
    assert_eq!(img.get_pixel(15, 1).0[0], 255);
    assert_eq!(img.get_pixel(0, 0).0[0], 0);
    // a tolerance above the difference makes them equal; .npy against a trace works
    assert_eq!(
        cwisim(
            &dir,
            &["diff", v, "w.cwt", "--outputs", "--tolerance", "0.2"]
        )
        .status
        .code(),
        Some(0)
    );
    assert!(cwisim(&dir, &["run", v, "--npy", "v.npy"]).status.success());
    assert_eq!(cwisim(&dir, &["diff", "v.npy", v]).status.code(), Some(0));
    assert_eq!(
        cwisim(&dir, &["diff", "v.npy", "w.cwt"]).status.code(),
        Some(1)
    );
    // bad input: 2
    for args in [
        vec!["diff", v, "nope.cwt"],
        vec!["diff", v, "v.npy", "--tolerance=-1"],
        vec!["diff", v, "v.cwb", "--image", "x.png"],
    ] {
        let out = cwisim(&dir, &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert_eq!(String::from_utf8_lossy(&out.stderr).lines().count(), 1);
    }
}
