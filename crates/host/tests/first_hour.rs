//! What a new user meets in the first hour (issue 34): a command that takes a scene given
//! a trace says so; overflow and hopeless timing are said in the summaries, not only in
//! `--stats-json`.

mod common;

use common::{cwisim, repo, scratch, text};

#[test]
fn scene_commands_given_a_trace_say_they_take_a_scene() {
    let dir = scratch("first-hour-trace-as-scene");
    let trace = repo().join("traces/gouraud.cwt");
    let trace = trace.to_str().unwrap();
    for args in [
        &["fit", trace, "--max-error", "1/512"][..],
        &["tradeoff", trace],
        &["refine", trace],
        &["render", trace],
        &["emit", trace, "-o", "x.cwt"],
    ] {
        let out = cwisim(&dir, args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains("a trace, not a scene") && stderr.contains("`cwisim run"),
            "{args:?}: {stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    }
}

#[test]
fn overflow_is_in_every_summary() {
    let dir = scratch("first-hour-overflow");
    let narrow = "fixed:I=1.8,dI=1.8,ddI=1.8";
    let out = cwisim(&dir, &["render", "pot", "--numeric", narrow, "-o", "p.png"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let row = stdout
        .lines()
        .find(|l| l.starts_with("overflows"))
        .unwrap_or_else(|| panic!("no overflow row: {stdout}"));
    assert!(row.contains("overflow event(s) in"), "{row}");
    assert!(row.contains("the first in scanline"), "{row}");
    // wide registers that held say so
    let out = cwisim(
        &dir,
        &[
            "render",
            "pot",
            "--numeric",
            "fixed:I=8.40,dI=8.40,ddI=8.40",
            "-o",
            "p.png",
        ],
    );
    let (stdout, _) = text(&out);
    assert!(stdout.contains("overflows    none in fixed:"), "{stdout}");
    // f64 counts none and says nothing
    let out = cwisim(&dir, &["render", "fig25", "-o", "f.png"]);
    assert!(!text(&out).0.contains("overflows"));
    // run --stats: the trace of the narrow render
    let out = cwisim(&dir, &["emit", "pot", "-o", "p.cwb"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let out = cwisim(&dir, &["run", "p.cwb", "--numeric", narrow, "--stats"]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("overflows") && l.contains("overflow event(s)")),
        "{stdout}"
    );
}

#[test]
fn a_hopeless_line_period_is_explained() {
    let dir = scratch("first-hour-late");
    // 2048 processors at one cycle a hop: 2048 cycles, and the line period at 2048 lines is
    // 100e6 / (60 × 2093) = 796 cycles
    let out = cwisim(
        &dir,
        &["render", "fig25", "--size", "2048x2048", "-o", "f.png"],
    );
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let late = stdout
        .lines()
        .find(|l| l.starts_with("late "))
        .unwrap_or_else(|| panic!("no reason given: {stdout}"));
    assert!(late.contains("2048 cycles to cross the array"), "{late}");
    assert!(late.contains("line period of 796 cycles"), "{late}");
}

#[test]
fn the_study_tools_study_the_numeric_formats() {
    let dir = scratch("first-hour-numeric");
    let trace = repo().join("traces/gouraud.cwt");
    let t = trace.to_str().unwrap();
    let coarse = "fixed:I=2.3,dI=2.3,ddI=2.3";
    let ok = |args: &[&str]| {
        let out = cwisim(&dir, args);
        let (stdout, stderr) = text(&out);
        assert!(out.status.success(), "{args:?}: {stderr}");
        stdout
    };
    // a pixel's history shows the registers' own (quantized) values
    let exact = ok(&["history", t, "--x", "5", "--line", "2"]);
    let narrow = ok(&["history", t, "--x", "5", "--line", "2", "--numeric", coarse]);
    assert_ne!(exact, narrow);
    // so does the waveform
    ok(&["vcd", t, "--line", "2", "-o", "f64.vcd"]);
    ok(&[
        "vcd",
        t,
        "--line",
        "2",
        "-o",
        "fixed.vcd",
        "--numeric",
        coarse,
    ]);
    assert_ne!(
        std::fs::read(dir.join("f64.vcd")).unwrap(),
        std::fs::read(dir.join("fixed.vcd")).unwrap()
    );
    // stats says what the registers overflowed, or that they held
    let held = ok(&["stats", t, "--numeric", "fixed:I=4.20,dI=4.20,ddI=4.20"]);
    assert!(held.contains("overflows: none in fixed:I=4.20"), "{held}");
    std::fs::write(
        dir.join("bright.cwt"),
        "cwisim-trace version=1 width=8 lines=1 channels=1\nEval1 0 8 3.0\nRefresh\n",
    )
    .unwrap();
    let tiny = ok(&[
        "stats",
        "bright.cwt",
        "--numeric",
        "fixed:I=2.4,dI=2.4,ddI=2.4",
    ]);
    assert!(
        tiny.contains("overflows: ") && tiny.contains("overflow event(s)"),
        "{tiny}"
    );
    // outputs compared in a format: the trace against itself is equal in any format
    let out = cwisim(&dir, &["diff", t, t, "--outputs", "--numeric", coarse]);
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    // the streams do not depend on the registers: refused there
    let out = cwisim(&dir, &["diff", t, t, "--numeric", coarse]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("--numeric sets the registers"));
    // the inspect page names its registers
    ok(&["inspect", t, "-o", "p.html", "--numeric", coarse]);
    let page = std::fs::read_to_string(dir.join("p.html")).unwrap();
    assert!(page.contains("fixed:I=2.3"), "the page names the format");
}
