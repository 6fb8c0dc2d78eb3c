//! `cwisim stats` through the real binary: the table, CSV, JSON and the plot against
//! `cwisim run --stats-json` and `cwisim render --stats-json`.

mod common;

use common::{cwisim, cwisim_ok, fig25, read, repo, scratch, text, trace};
use serde_json::Value;
use std::path::{Path, PathBuf};

const OPCODES: [&str; 14] = [
    "SetI", "SetdI", "SetddI", "SetPI", "SetPdI", "SetPddI", "Eval0", "Eval1", "Eval2", "Eval3",
    "Dis", "Acc_mode", "Refresh", "Nop",
];

const CSV_HEADER: &str = "line,frame,row,instructions,SetI,SetdI,SetddI,SetPI,SetPdI,SetPddI,Eval0,Eval1,Eval2,Eval3,Dis,Acc_mode,Refresh,Nop,busy_cycles,stall_cycles,processor_updates,ready,deadline,slack,late";

fn json(path: impl AsRef<Path>) -> Value {
    serde_json::from_slice(&read(path)).expect("JSON")
}

/// The printed table: the header's columns, then one map per row (the last: `total`),
/// and whether each row ends with `LATE`.
struct Table {
    head: Vec<String>,
    rows: Vec<Vec<String>>,
    late: Vec<bool>,
    total: String,
}

fn table(stdout: &str) -> Table {
    let mut lines = stdout.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<String> = lines
        .next()
        .expect("a header")
        .split_whitespace()
        .map(String::from)
        .collect();
    let mut rows = Vec::new();
    let mut late = Vec::new();
    let mut total = String::new();
    for l in lines {
        if l.starts_with("total") {
            total = l.to_string();
            continue;
        }
        assert!(total.is_empty(), "nothing after the totals: {l}");
        let mut cells: Vec<String> = l.split_whitespace().map(String::from).collect();
        let is_late = cells.last().is_some_and(|c| c == "LATE");
        if is_late {
            cells.pop();
        }
        assert_eq!(cells.len(), head.len(), "{l}");
        rows.push(cells);
        late.push(is_late);
    }
    assert!(!total.is_empty(), "a totals line");
    Table {
        head,
        rows,
        late,
        total,
    }
}

/// Every cell of the table equals the field of the `--stats-json` line record.
fn assert_table_matches(t: &Table, records: &[Value]) {
    assert_eq!(t.rows.len(), records.len());
    fn field(col: &str) -> Option<(&str, Option<&str>)> {
        Some(match col {
            "line" | "frame" | "row" | "instructions" | "ready" | "deadline" | "slack" => {
                (col, None)
            }
            "busy" => ("busy_cycles", None),
            "stall" => ("stall_cycles", None),
            "updates" => ("processor_updates", None),
            op if OPCODES.contains(&op) => ("opcodes", Some(op)),
            _ => return None,
        })
    }
    for ((row, rec), late) in t.rows.iter().zip(records).zip(&t.late) {
        for (col, cell) in t.head.iter().zip(row) {
            let (key, op) = field(col).unwrap_or_else(|| panic!("unknown column {col}"));
            let want = match op {
                Some(op) => &rec[key][op],
                None => &rec[key],
            };
            assert_eq!(cell, &want.to_string(), "line {} column {col}", rec["line"]);
        }
        assert_eq!(*late, rec["slack"].as_i64().expect("slack") < 0);
    }
    // an opcode column for exactly the opcodes that occur, in opcode order
    let used: Vec<&str> = OPCODES
        .iter()
        .copied()
        .filter(|op| records.iter().any(|r| r["opcodes"][op] != 0))
        .collect();
    let cols: Vec<&str> = t
        .head
        .iter()
        .map(String::as_str)
        .filter(|c| OPCODES.contains(c))
        .collect();
    assert_eq!(cols, used);
}

fn overrun_args<'a>(extra: &[&'a str], t: &'a str, m: &'a str) -> Vec<&'a str> {
    let mut args = vec!["stats", t, "--machine", m];
    args.extend_from_slice(extra);
    args
}

#[test]
fn the_table_and_json_equal_the_stats_json_of_run() {
    let dir = scratch("stats-overrun");
    let (t, m) = (trace("overrun.cwt"), trace("overrun.machine.json"));
    cwisim_ok(
        &dir,
        &["run", &t, "--machine", &m, "--stats-json", "run.json"],
    );
    let run = json(dir.join("run.json"));
    let out = cwisim_ok(
        &dir,
        &overrun_args(&["--stats-json", "s.json", "--csv", "s.csv"], &t, &m),
    );
    let records = run["stats"]["lines"].as_array().expect("lines");
    let tab = table(&out);
    assert_table_matches(&tab, records);
    // the one late line: line 1, slack -9
    assert_eq!(tab.late, [false, true, false, false]);
    assert_eq!(
        tab.rows[1][tab.head.iter().position(|c| c == "slack").unwrap()],
        "-9"
    );
    let total: Vec<&str> = tab.total.split_whitespace().collect();
    assert_eq!(total.first(), Some(&"total"));
    assert_eq!(total[total.len() - 3..], ["-9", "1", "late"]);
    assert_eq!(
        total[1],
        run["stats"]["totals"]["instructions"].to_string(),
        "{}",
        tab.total
    );
    assert!(
        out.starts_with("# overrun.cwt: width 16, 4 lines per frame"),
        "{out}"
    );

    let s = json(dir.join("s.json"));
    assert_eq!(s["input"], "overrun.cwt");
    assert_eq!(s["kind"], "trace");
    assert_eq!(s["trace"], run["trace"]);
    assert_eq!(s["machine"], run["machine"]);
    assert_eq!(s["timing"], "fast");
    assert_eq!(s["line_period"], 40);
    assert_eq!(s["lines"], run["stats"]["lines"]);
    assert_eq!(s["totals"], run["stats"]["totals"]);
    assert_eq!(s["range"], Value::Null);
    assert_eq!(s["selected"]["late_lines"], 1);
    assert_eq!(s["selected"]["worst_slack"], -9);
    assert_eq!(s["selected"]["worst_line"], 1);
    // the per-opcode bus cycles (count × issue cost) add up to each line's busy cycles
    for rec in records {
        let busy: u64 = OPCODES
            .iter()
            .map(|op| {
                rec["opcodes"][op].as_u64().unwrap() * s["issue_cycles"][op].as_u64().unwrap()
            })
            .sum();
        assert_eq!(
            Value::from(busy),
            rec["busy_cycles"],
            "line {}",
            rec["line"]
        );
    }
    // Eval3 costs its 2-cycle word and 3 values
    assert_eq!(s["issue_cycles"]["Eval3"], 5);
    assert_eq!(s["issue_cycles"]["Refresh"], 1);

    let csv = String::from_utf8(read(dir.join("s.csv"))).expect("UTF-8");
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows[0], CSV_HEADER);
    assert_eq!(rows.len(), 1 + records.len());
    for (row, rec) in rows[1..].iter().zip(records) {
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), 25, "{row}");
        assert_eq!(cells[0], rec["line"].to_string());
        for (i, op) in OPCODES.iter().enumerate() {
            assert_eq!(cells[4 + i], rec["opcodes"][op].to_string(), "{op}");
        }
        assert_eq!(cells[18], rec["busy_cycles"].to_string());
        assert_eq!(cells[23], rec["slack"].to_string());
        assert_eq!(
            cells[24],
            if rec["slack"].as_i64() < Some(0) {
                "1"
            } else {
                "0"
            }
        );
    }
}

#[test]
fn every_checked_in_trace_matches_run_on_both_timings() {
    let dir = scratch("stats-all-traces");
    let mut seen = 0;
    let mut names: Vec<PathBuf> = std::fs::read_dir(repo().join("traces"))
        .expect("traces/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "cwt"))
        .collect();
    names.sort();
    for path in names {
        let t = path.to_string_lossy().into_owned();
        let machine = path.with_extension("machine.json");
        let mut extra: Vec<String> = Vec::new();
        if machine.exists() {
            extra = vec!["--machine".into(), machine.to_string_lossy().into_owned()];
        }
        let with = |args: &[&str]| -> Vec<String> {
            args.iter()
                .map(|s| s.to_string())
                .chain(extra.iter().cloned())
                .collect()
        };
        let run_args = with(&["run", &t, "--stats-json", "run.json"]);
        let run_args: Vec<&str> = run_args.iter().map(String::as_str).collect();
        let out = cwisim(&dir, &run_args);
        assert!(out.status.success(), "{}", text(&out).1);
        let run = json(dir.join("run.json"));
        for timing in ["fast", "stepped"] {
            let args = with(&["stats", &t, "--stats-json", "s.json", "--timing", timing]);
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let out = cwisim(&dir, &args);
            assert!(out.status.success(), "{}", text(&out).1);
            let (stdout, _) = text(&out);
            assert_table_matches(&table(&stdout), run["stats"]["lines"].as_array().unwrap());
            let s = json(dir.join("s.json"));
            assert_eq!(s["lines"], run["stats"]["lines"], "{t} {timing}");
            assert_eq!(s["totals"], run["stats"]["totals"], "{t} {timing}");
            assert_eq!(s["timing"], timing);
        }
        seen += 1;
    }
    assert!(seen >= 8, "{seen} traces");
}

#[test]
fn a_scene_is_rendered_first_like_render_does() {
    let dir = scratch("stats-scene");
    let scene = fig25();
    cwisim_ok(&dir, &["render", &scene, "--stats-json", "render.json"]);
    let render = json(dir.join("render.json"));
    let out = cwisim_ok(
        &dir,
        &["stats", &scene, "--stats-json", "s.json", "--csv", "s.csv"],
    );
    let records = render["stats"]["lines"].as_array().expect("lines");
    assert_eq!(records.len(), 14);
    assert_table_matches(&table(&out), records);
    let s = json(dir.join("s.json"));
    assert_eq!(s["kind"], "scene");
    assert_eq!(s["input"], "fig25.json");
    assert_eq!(s["lines"], render["stats"]["lines"]);
    assert_eq!(s["totals"], render["stats"]["totals"]);
    let csv = String::from_utf8(read(dir.join("s.csv"))).expect("UTF-8");
    assert_eq!(csv.lines().next(), Some(CSV_HEADER));
    assert_eq!(csv.lines().count(), 15);
}

#[test]
fn lines_selects_exactly_the_range() {
    let dir = scratch("stats-lines");
    let (t, m) = (trace("overrun.cwt"), trace("overrun.machine.json"));
    cwisim_ok(
        &dir,
        &["run", &t, "--machine", &m, "--stats-json", "run.json"],
    );
    let run = json(dir.join("run.json"));
    let all = run["stats"]["lines"].as_array().expect("lines");
    // overrun.cwt has 4 scanlines per frame: --frames 0 is scanlines 0..4
    let by_frame = cwisim_ok(&dir, &overrun_args(&["--frames", "0"], &t, &m));
    let by_lines = cwisim_ok(&dir, &overrun_args(&["--lines", "0..4"], &t, &m));
    assert_eq!(by_frame, by_lines);
    // the old spelling (both ends included) reads the same
    let old = cwisim_ok(&dir, &overrun_args(&["--lines", "0-3"], &t, &m));
    assert_eq!(old, by_lines);
    // each range as typed, and as the JSON writes it back (always the new syntax)
    for (range, written, want) in [
        ("1..3", "1..3", 1..3),
        ("1..=2", "1..3", 1..3),
        ("1-2", "1..3", 1..3),
        ("3", "3", 3..4),
        ("2..", "2..", 2..4),
        ("2-", "2..", 2..4),
        ("0..10", "0..10", 0..4),
    ] {
        let out = cwisim_ok(
            &dir,
            &overrun_args(
                &["--lines", range, "--csv", "s.csv", "--stats-json", "s.json"],
                &t,
                &m,
            ),
        );
        let tab = table(&out);
        assert_table_matches(&tab, &all[want.clone()]);
        let firsts: Vec<&str> = tab.rows.iter().map(|r| r[0].as_str()).collect();
        let expected: Vec<String> = want.clone().map(|n| n.to_string()).collect();
        assert_eq!(firsts, expected, "--lines {range}");
        let csv = String::from_utf8(read(dir.join("s.csv"))).expect("UTF-8");
        let lines: Vec<&str> = csv
            .lines()
            .skip(1)
            .map(|r| r.split(',').next().unwrap())
            .collect();
        assert_eq!(lines, expected, "--lines {range}");
        assert_eq!(csv.lines().next(), Some(CSV_HEADER));
        let s = json(dir.join("s.json"));
        assert_eq!(s["lines"].as_array().unwrap()[..], all[want.clone()]);
        assert_eq!(s["range"], written, "--lines {range}");
        assert_eq!(s["selected"]["lines"], want.len());
        // the totals stay the run's
        assert_eq!(s["totals"], run["stats"]["totals"]);
    }
    // 1..3 holds the late line, 2.. does not
    let out = cwisim_ok(&dir, &overrun_args(&["--lines", "2.."], &t, &m));
    assert!(!out.contains("LATE"), "{out}");
    assert!(out.contains("  0 late"), "{out}");
}

#[test]
fn the_plot_decodes_and_is_deterministic() {
    let dir = scratch("stats-plot");
    let (t, m) = (trace("overrun.cwt"), trace("overrun.machine.json"));
    cwisim_ok(&dir, &overrun_args(&["--plot", "a.png"], &t, &m));
    cwisim_ok(&dir, &overrun_args(&["--plot", "b.png"], &t, &m));
    let (a, b) = (read(dir.join("a.png")), read(dir.join("b.png")));
    assert_eq!(a, b, "byte-identical");
    let img = image::load_from_memory_with_format(&a, image::ImageFormat::Png).expect("a PNG");
    assert_eq!((img.width(), img.height()), (1100, 560));
    let rgb = img.into_rgb8();
    let red = |img: &image::RgbImage| img.pixels().filter(|p| p.0 == [214, 39, 40]).count();
    // the Eval3 orange is there, and the overrun red (in the legend and on line 1)
    assert!(rgb.pixels().any(|p| p.0 == [255, 127, 14]));
    assert!(red(&rgb) > 0);
    // a selection, and a scene, plot too; 2-3 has no overrun: red in the legend only
    cwisim_ok(
        &dir,
        &overrun_args(&["--plot", "c.png", "--lines", "2-3"], &t, &m),
    );
    let c = image::open(dir.join("c.png")).expect("a PNG").into_rgb8();
    assert!(
        red(&c) > 0 && red(&c) < red(&rgb),
        "{} {}",
        red(&c),
        red(&rgb)
    );
    assert!(
        !c.pixels().any(|p| p.0 == [255, 127, 14]),
        "no Eval3 in 2-3"
    );
    cwisim_ok(&dir, &["stats", &fig25(), "--plot", "d.png"]);
    let d = image::open(dir.join("d.png")).expect("a PNG");
    assert_eq!((d.width(), d.height()), (1100, 560));
}

#[test]
fn outputs_are_deterministic_and_hold_no_paths() {
    let dir = scratch("stats-determinism");
    let (t, m) = (trace("overrun.cwt"), trace("overrun.machine.json"));
    let args = overrun_args(&["--stats-json", "s.json", "--csv", "s.csv"], &t, &m);
    let first = cwisim_ok(&dir, &args);
    let (j, c) = (read(dir.join("s.json")), read(dir.join("s.csv")));
    assert_eq!(first, cwisim_ok(&dir, &args));
    assert_eq!(j, read(dir.join("s.json")));
    assert_eq!(c, read(dir.join("s.csv")));
    let repo = repo().canonicalize().expect("repo");
    for text in [String::from_utf8(j).unwrap(), first] {
        assert!(!text.contains(repo.to_string_lossy().as_ref()), "{text}");
        assert!(!text.contains(dir.to_string_lossy().as_ref()), "{text}");
    }
}

#[test]
fn bad_input_exits_2_with_one_error_line() {
    let dir = scratch("stats-bad");
    std::fs::write(dir.join("t.cwt"), common::SMALL_TRACE).expect("write");
    std::fs::write(dir.join("t.txt"), common::SMALL_TRACE).expect("write");
    std::fs::write(
        dir.join("bad.cwt"),
        "cwisim-trace version=1 width=4 lines=1 channels=1\nEval1 3 9 0.5\n",
    )
    .expect("write");
    let cases: [(&[&str], &str); 10] = [
        (&["stats", "t.cwt", "--lines", "5..2"], "5..2"),
        (&["stats", "t.cwt", "--lines", "x"], "not a range"),
        (&["stats", "t.cwt", "--lines=-3"], "not a range"),
        (
            &["stats", "t.txt"],
            "error: t.txt: unknown input extension `.txt`",
        ),
        (
            &["stats", "t.cwt", "--lines", "7.."],
            "error: --lines 7.. selects no scanline",
        ),
        (
            &["stats", "t.cwt", "--plot", "p.svg"],
            "--plot writes a .png file",
        ),
        (
            &["stats", "t.cwt", "--csv", "t.cwt"],
            "would overwrite the input",
        ),
        (
            &["stats", "t.cwt", "--csv", "o.x", "--stats-json", "./o.x"],
            "both name",
        ),
        (&["stats", "missing.cwt"], "error: missing.cwt: cannot open"),
        (&["stats", "bad.cwt", "--csv", "o.csv"], "error: bad.cwt:2:"),
    ];
    for (args, needle) in cases {
        let out = cwisim(&dir, args);
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stdout.is_empty(), "{args:?}: {stdout}");
        let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
        assert_eq!(errors.len(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(
        !dir.join("o.csv").exists(),
        "a malformed trace writes nothing"
    );
    assert!(!dir.join("p.svg").exists());
}
