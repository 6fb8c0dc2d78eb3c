//! The `cwisim` binary end to end: exact outputs, timing models agreeing, conversions,
//! determinism, and refusals that must leave no file behind.

mod common;

use common::{cwisim, cwisim_ok, read, read_npy, scratch, text, SMALL_TRACE};
use serde_json::Value;

const ROW0: [f64; 8] = [0.0, 0.0, 0.5, 0.625, 0.75, 0.875, 0.0, 0.0];
const ROW1: [f64; 8] = [1.0; 8];

#[test]
fn run_writes_the_exact_image_as_npy() {
    let dir = scratch("exact-npy");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    let stdout = cwisim_ok(&dir, &["run", "t.cwt", "--npy", "t.npy"]);
    assert!(
        stdout == "wrote t.npy: 2 scanline(s) of 8 × 1 channel(s)\n",
        "a run without --stats says only what it wrote: {stdout}"
    );
    let (shape, values) = read_npy(dir.join("t.npy"));
    assert_eq!(shape, [2, 8, 1]);
    let expected: Vec<f64> = ROW0.iter().chain(&ROW1).copied().collect();
    assert_eq!(values, expected);
}

#[test]
fn run_writes_a_grey_png_with_clamped_rounded_values() {
    let dir = scratch("png");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    cwisim_ok(&dir, &["run", "t.cwt", "-o", "t.png"]);
    let img = image::open(dir.join("t.png")).expect("a PNG");
    assert_eq!(img.color(), image::ColorType::L8);
    assert_eq!((img.width(), img.height()), (8, 2));
    // 0.625 × 255 = 159.375, 0.75 × 255 = 191.25, 0.875 × 255 = 223.125
    let expected = [
        0, 0, 128, 159, 191, 223, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255,
    ];
    assert_eq!(img.into_luma8().into_raw(), expected);
}

#[test]
fn run_reads_all_three_encodings_alike() {
    let dir = scratch("encodings");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    cwisim_ok(&dir, &["convert", "t.cwt", "t.jsonl"]);
    cwisim_ok(&dir, &["convert", "t.cwt", "t.cwb"]);
    for ext in ["cwt", "jsonl", "cwb"] {
        let trace = format!("t.{ext}");
        let npy = format!("{ext}.npy");
        let json = format!("{ext}.json");
        cwisim_ok(&dir, &["run", &trace, "--npy", &npy, "--stats-json", &json]);
    }
    assert_eq!(read(dir.join("cwt.npy")), read(dir.join("jsonl.npy")));
    assert_eq!(read(dir.join("cwt.npy")), read(dir.join("cwb.npy")));
    assert_eq!(read(dir.join("cwt.json")), read(dir.join("jsonl.json")));
    assert_eq!(read(dir.join("cwt.json")), read(dir.join("cwb.json")));
}

#[test]
fn stepped_timing_gives_identical_image_and_statistics() {
    let dir = scratch("stepped");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    let fast = cwisim_ok(
        &dir,
        &[
            "run",
            "t.cwt",
            "--npy",
            "fast.npy",
            "--stats-json",
            "fast.json",
            "--stats",
        ],
    );
    let stepped = cwisim_ok(
        &dir,
        &[
            "run",
            "t.cwt",
            "--timing",
            "stepped",
            "--npy",
            "stepped.npy",
            "--stats-json",
            "stepped.json",
            "--stats",
        ],
    );
    assert_eq!(read(dir.join("fast.npy")), read(dir.join("stepped.npy")));
    let parse = |name: &str| -> Value {
        serde_json::from_slice(&read(dir.join(name))).expect("stats JSON")
    };
    let (f, s) = (parse("fast.json"), parse("stepped.json"));
    assert_eq!(f["timing"], "fast");
    assert_eq!(s["timing"], "stepped");
    for part in ["trace", "machine", "stats"] {
        assert_eq!(f[part], s[part], "{part} differs");
    }
    // The text summaries differ only in the timing line.
    let strip = |t: &str| {
        t.lines()
            .filter(|l| !l.starts_with("timing") && !l.starts_with("wrote"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(strip(&fast), strip(&stepped));
}

#[test]
fn stats_json_is_the_documented_document() {
    let dir = scratch("stats-json");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    cwisim_ok(
        &dir,
        &[
            "run",
            "t.cwt",
            "--stats-json",
            "s.json",
            "--set",
            "clock_hz=2e8",
        ],
    );
    let raw = String::from_utf8(read(dir.join("s.json"))).expect("UTF-8");
    assert!(raw.ends_with("}\n"), "a trailing newline");
    assert!(
        !raw.contains(dir.to_string_lossy().as_ref()),
        "no absolute paths"
    );
    let v: Value = serde_json::from_str(&raw).expect("JSON");
    let mut keys: Vec<&String> = v.as_object().expect("an object").keys().collect();
    keys.sort();
    assert_eq!(keys, ["machine", "stats", "timing", "trace"]);
    // in this order in the file
    let at = |key: &str| {
        raw.find(&format!("\n  \"{key}\": "))
            .unwrap_or_else(|| panic!("no top-level {key}"))
    };
    assert!(
        at("trace") < at("machine") && at("machine") < at("timing") && at("timing") < at("stats")
    );
    assert_eq!(
        v["trace"],
        serde_json::json!({"width": 8, "lines": 2, "channels": 1})
    );
    assert_eq!(v["machine"]["clock_hz"], 2e8);
    // floor(2e8 / (60 × (2 + 45)))
    assert_eq!(v["stats"]["line_period"], 70921);
    let t = &v["stats"]["totals"];
    assert_eq!(t["instructions"], 4);
    assert_eq!(t["lines"], 2);
    assert_eq!(t["frames"], 1);
    assert_eq!(t["late_lines"], 0);
    assert_eq!(t["unrefreshed_instructions"], 0);
    assert_eq!(t["opcodes"]["Eval2"], 1);
    assert_eq!(t["opcodes"]["Refresh"], 2);
    assert_eq!(
        v["stats"]["lines"]
            .as_array()
            .expect("per-line records")
            .len(),
        2
    );
}

#[test]
fn stats_summary_goes_to_stdout() {
    let dir = scratch("stats-text");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    let out = cwisim_ok(&dir, &["run", "t.cwt", "--stats"]);
    for line in [
        "instructions              4",
        "  Eval1                   1",
        "  Eval2                   1",
        "  Refresh                 2",
        "line period               35460 cycles",
        "lines                     2 (1 frame(s) + 0 line(s) of a partial frame)",
        "late lines                0",
        "unrefreshed instructions  0",
    ] {
        assert!(
            out.lines().any(|l| l == line),
            "no line `{line}` in:\n{out}"
        );
    }
    assert!(
        !out.contains("Eval3"),
        "opcodes never used are not listed:\n{out}"
    );
}

#[test]
fn instructions_after_the_last_refresh_are_warned_about() {
    let dir = scratch("unrefreshed");
    std::fs::write(
        dir.join("t.cwt"),
        format!("{SMALL_TRACE}Eval1 0 8 0.5\nNop\n"),
    )
    .expect("write trace");
    let out = cwisim(&dir, &["run", "t.cwt", "--npy", "t.npy", "--quiet"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0));
    assert!(stdout.is_empty());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("warning: 2 instruction(s) after the last Refresh"),
        "{stderr}"
    );
    assert_eq!(read_npy(dir.join("t.npy")).0, [2, 8, 1]);
}

#[test]
fn convert_round_trip_gives_back_the_canonical_text() {
    let dir = scratch("convert");
    // Comments and blank lines are not kept: the output is the canonical text.
    let commented = format!(
        "# a small trace\n\n{}",
        SMALL_TRACE.replace("Refresh\n", "Refresh   # end of line\n")
    );
    std::fs::write(dir.join("in.cwt"), commented).expect("write trace");
    cwisim_ok(&dir, &["convert", "in.cwt", "a.jsonl"]);
    cwisim_ok(&dir, &["convert", "a.jsonl", "b.cwb"]);
    cwisim_ok(&dir, &["convert", "b.cwb", "c.cwt"]);
    assert_eq!(
        String::from_utf8(read(dir.join("c.cwt"))).expect("UTF-8"),
        SMALL_TRACE
    );
    // and once canonical, every chain is byte-identical
    cwisim_ok(&dir, &["convert", "c.cwt", "d.cwb"]);
    assert_eq!(read(dir.join("b.cwb")), read(dir.join("d.cwb")));
    cwisim_ok(&dir, &["convert", "d.cwb", "e.jsonl"]);
    assert_eq!(read(dir.join("a.jsonl")), read(dir.join("e.jsonl")));
    // -o OUT, as every command names its output, is the same as OUT second
    cwisim_ok(&dir, &["convert", "d.cwb", "-o", "f.jsonl"]);
    assert_eq!(read(dir.join("a.jsonl")), read(dir.join("f.jsonl")));
    for bad in [
        &["convert", "d.cwb"][..],
        &["convert", "d.cwb", "g.cwt", "-o", "h.cwt"],
    ] {
        assert_eq!(cwisim(&dir, bad).status.code(), Some(2), "{bad:?}");
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn convert_refuses_to_overwrite_its_input() {
    let dir = scratch("convert-same");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    for out_name in ["t.cwt", "./t.cwt"] {
        let out = cwisim(&dir, &["convert", "t.cwt", out_name]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2));
        assert!(
            stderr.starts_with(&format!(
                "error: OUT {out_name} would overwrite the trace being read (IN)"
            )),
            "{stderr}"
        );
    }
    assert_eq!(
        String::from_utf8(read(dir.join("t.cwt"))).expect("UTF-8"),
        SMALL_TRACE
    );
}

#[test]
fn convert_of_a_malformed_trace_leaves_no_output() {
    let dir = scratch("convert-bad");
    std::fs::write(dir.join("t.cwt"), format!("{SMALL_TRACE}Eval1 0 9 1.0\n"))
        .expect("write trace");
    let out = cwisim(&dir, &["convert", "t.cwt", "t.cwb"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr.starts_with("error: t.cwt:6:7: "), "{stderr}");
    let names: Vec<_> = std::fs::read_dir(&dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(names, ["t.cwt"]);
}

#[test]
fn runs_are_deterministic() {
    let dir = scratch("deterministic");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    let args = |n: &str| {
        [
            "run",
            "t.cwt",
            "-o",
            "N.png",
            "--npy",
            "N.npy",
            "--stats-json",
            "N.json",
            "--stats",
        ]
        .map(|a| a.replace('N', n))
    };
    let first = args("1");
    let second = args("2");
    let out1 = cwisim_ok(&dir, &first.iter().map(String::as_str).collect::<Vec<_>>());
    let out2 = cwisim_ok(&dir, &second.iter().map(String::as_str).collect::<Vec<_>>());
    // the same but for the names of what each wrote
    let names = |t: &str, n: &str| t.replace(&format!("{n}."), "N.");
    assert_eq!(names(&out1, "1"), names(&out2, "2"));
    for ext in ["png", "npy", "json"] {
        assert_eq!(
            read(dir.join(format!("1.{ext}"))),
            read(dir.join(format!("2.{ext}"))),
            "{ext}"
        );
    }
}

#[test]
fn a_malformed_trace_writes_nothing_and_keeps_old_outputs() {
    let dir = scratch("no-partial");
    // The fault is on the last line: the whole image was computed before it.
    std::fs::write(
        dir.join("t.cwt"),
        format!("{SMALL_TRACE}Eval1 0 8 1.0\nRefresh\nBlit\n"),
    )
    .expect("write trace");
    std::fs::write(dir.join("old.npy"), b"keep me").expect("write old output");
    let out = cwisim(
        &dir,
        &[
            "run",
            "t.cwt",
            "-o",
            "t.png",
            "--npy",
            "old.npy",
            "--stats-json",
            "s.json",
        ],
    );
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(stdout.is_empty());
    assert!(
        stderr.starts_with("error: t.cwt:8:1: unknown opcode `Blit`"),
        "{stderr}"
    );
    assert_eq!(read(dir.join("old.npy")), b"keep me");
    assert!(!dir.join("t.png").exists());
    assert!(!dir.join("s.json").exists());
}

#[test]
fn png_needs_one_or_three_channels() {
    let dir = scratch("png-channels");
    let trace =
        "cwisim-trace version=1 width=2 lines=1 channels=4\nEval1 0 2 0.5,0.25,1.0,0.0\nRefresh\n";
    std::fs::write(dir.join("t.cwt"), trace).expect("write trace");
    let out = cwisim(&dir, &["run", "t.cwt", "-o", "t.png"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr,
        "error: PNG needs 1 or 3 channels, the trace has 4; use --npy for the exact values\n"
    );
    assert!(!dir.join("t.png").exists());
    cwisim_ok(&dir, &["run", "t.cwt", "--npy", "t.npy"]);
    assert_eq!(
        read_npy(dir.join("t.npy")),
        (
            vec![1, 2, 4],
            vec![0.5, 0.25, 1.0, 0.0, 0.5, 0.25, 1.0, 0.0]
        )
    );
}

#[test]
fn rgb_traces_make_rgb_pngs() {
    let dir = scratch("png-rgb");
    let trace =
        "cwisim-trace version=1 width=2 lines=1 channels=3\nEval1 0 2 1.0,0.5,-1.0\nRefresh\n";
    std::fs::write(dir.join("t.cwt"), trace).expect("write trace");
    cwisim_ok(&dir, &["run", "t.cwt", "-o", "t.png"]);
    let img = image::open(dir.join("t.png")).expect("a PNG");
    assert_eq!(img.color(), image::ColorType::Rgb8);
    assert_eq!(img.into_rgb8().into_raw(), [255, 128, 0, 255, 128, 0]);
}

#[test]
fn a_trace_without_refresh_is_refused_naming_the_file() {
    let dir = scratch("no-refresh");
    std::fs::write(
        dir.join("t.cwt"),
        "cwisim-trace version=1 width=8 lines=2 channels=1\nEval1 0 8 1.0\n",
    )
    .expect("write trace");
    for args in [
        &["run", "t.cwt", "-o", "t.png"][..],
        &["run", "t.cwt", "--npy", "t.npy"],
    ] {
        let out = cwisim(&dir, args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert_eq!(
            stderr,
            "error: t.cwt: the trace ends before its first scanline (no Refresh; the header \
announces 2 lines per frame): it is incomplete (cut short?); the file ends at byte 64\n"
        );
    }
    assert!(!dir.join("t.png").exists() && !dir.join("t.npy").exists());
    // --keep-partial: the image of no scanline, which a PNG cannot hold
    let out = cwisim(&dir, &["run", "t.cwt", "-o", "t.png", "--keep-partial"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.ends_with("error: the trace output no scanline (no Refresh); nothing to write\n"),
        "{stderr}"
    );
    let out = cwisim(&dir, &["run", "t.cwt", "--npy", "t.npy", "--keep-partial"]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(read_npy(dir.join("t.npy")), (vec![0, 8, 1], vec![]));
}

#[test]
fn outputs_may_not_overwrite_the_trace_or_each_other() {
    let dir = scratch("clobber");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    for (args, needle) in [
        (
            &["run", "t.cwt", "--npy", "t.cwt"][..],
            "error: --npy t.cwt would overwrite the trace being read",
        ),
        (
            &["run", "t.cwt", "--npy", "x.npy", "--stats-json", "./x.npy"],
            "error: --npy and --stats-json both name",
        ),
        (
            &["run", "t.cwt", "-o", "x.npy"],
            "error: -o writes PNG, but `x.npy` names a NumPy file; use --npy",
        ),
    ] {
        let out = cwisim(&dir, args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(stderr.starts_with(needle), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1);
    }
    assert_eq!(
        String::from_utf8(read(dir.join("t.cwt"))).expect("UTF-8"),
        SMALL_TRACE
    );
}

#[test]
fn machine_prints_pure_json_that_run_accepts() {
    let dir = scratch("machine");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    let out = cwisim(
        &dir,
        &[
            "machine",
            "--set",
            "clock_hz=2e8",
            "--set",
            "opcode_cycles.Eval3=2",
            "--lines",
            "2",
        ],
    );
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0));
    let m: Value = serde_json::from_str(&stdout).expect("stdout is JSON only");
    assert_eq!(m["clock_hz"], 2e8);
    assert_eq!(m["opcode_cycles"]["Eval3"], 2);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("line period 70921 cycles"), "{stderr}");
    std::fs::write(dir.join("m.json"), &stdout).expect("write machine");
    cwisim_ok(
        &dir,
        &[
            "run",
            "t.cwt",
            "--machine",
            "m.json",
            "--stats-json",
            "a.json",
        ],
    );
    cwisim_ok(
        &dir,
        &[
            "run",
            "t.cwt",
            "--set",
            "clock_hz=2e8",
            "--set",
            "opcode_cycles.Eval3=2",
            "--stats-json",
            "b.json",
        ],
    );
    assert_eq!(read(dir.join("a.json")), read(dir.join("b.json")));
}

#[test]
fn set_applies_after_machine() {
    let dir = scratch("set-order");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).expect("write trace");
    std::fs::write(
        dir.join("m.json"),
        "{\"line_period_cycles\": 500, \"hop_cycles\": 3}",
    )
    .expect("write machine");
    cwisim_ok(
        &dir,
        &[
            "run",
            "t.cwt",
            "--machine",
            "m.json",
            "--set",
            "line_period_cycles=700",
            "--stats-json",
            "s.json",
        ],
    );
    let v: Value = serde_json::from_slice(&read(dir.join("s.json"))).expect("JSON");
    assert_eq!(v["stats"]["line_period"], 700);
    assert_eq!(v["stats"]["traversal_cycles"], 24);
}

#[test]
fn help_and_usage_errors_through_the_binary() {
    let dir = scratch("help");
    let out = cwisim(&dir, &["run", "--help"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0));
    assert!(stdout.contains("Usage: cwisim run"), "{stdout}");
    assert!(stderr.is_empty());
    let out = cwisim(&dir, &["run", "t.cwt", "--timing", "slow"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(stdout.is_empty());
    assert!(stderr.contains("'slow'"), "{stderr}");
    let out = cwisim(&dir, &[]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn without_a_trace_run_replays_the_embedded_demo() {
    let dir = scratch("demo");
    let stdout = cwisim_ok(
        &dir,
        &["run", "-o", "demo.png", "--npy", "demo.npy", "--stats"],
    );
    assert!(
        stdout
            .starts_with("trace                     width 96, 64 lines per frame, 1 channel(s)\n"),
        "{stdout}"
    );
    assert!(
        stdout.contains("\nlate lines                0\n"),
        "{stdout}"
    );
    let (shape, values) = read_npy(dir.join("demo.npy"));
    assert_eq!(shape, [64, 96, 1]);
    assert!(
        values.iter().all(|v| (0.0..=1.0).contains(v)),
        "a shaded disc stays in [0, 1]"
    );
    // the corners are outside the disc, the centre inside
    assert_eq!(values[0], 0.0);
    assert!(values[32 * 96 + 48] > 0.5);
    let img = image::open(dir.join("demo.png")).expect("a PNG");
    assert_eq!((img.width(), img.height()), (96, 64));
    // and it is the same every time
    cwisim_ok(&dir, &["run", "--npy", "again.npy"]);
    assert_eq!(read(dir.join("demo.npy")), read(dir.join("again.npy")));
}
