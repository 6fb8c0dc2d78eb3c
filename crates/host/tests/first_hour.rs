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
