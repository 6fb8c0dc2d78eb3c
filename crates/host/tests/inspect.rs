//! `cwisim inspect`: the page's embedded data read back and held to the other tools'
//! outputs — the image to `run --npy`, the costs to `--cost-npy`, every history of the
//! window to `cwisim history` (run as the page suggests it), every scanline's disassembly
//! to `cwisim dump`, the timeline to `stats --stats-json`, the event view's cycles to the
//! histories' — over a range of frames and for the two runs of an A/B page, and the same
//! input giving the same bytes. The page in a real browser is `tests/browser.rs`.

mod common;

use common::{cwisim, cwisim_ok, scratch, text};
use cwisim_study::inspect::{page_data, read_blob};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn traces() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../traces")
}

fn page(dir: &Path, name: &str) -> Value {
    let html = std::fs::read_to_string(dir.join(name)).expect("the page");
    page_data(&html).expect("the page's data")
}

/// Run `run`'s frame `f` (counted from the page's first) of a page's data.
fn frame(data: &Value, run: usize, f: usize) -> &Value {
    &data["runs"][run]["frames"][f]
}

fn blob(v: &Value) -> Vec<u8> {
    read_blob(v.as_str().expect("a blob")).expect("base64 of zlib")
}

fn f64s(v: &Value) -> Vec<f64> {
    blob(v)
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn u32s(v: &Value) -> Vec<u32> {
    blob(v)
        .chunks(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn texts(v: &Value) -> Vec<String> {
    let t = String::from_utf8(blob(v)).unwrap();
    if t.is_empty() {
        Vec::new()
    } else {
        t.split('\n').map(str::to_string).collect()
    }
}

fn npy_f64(path: &Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    npyz::NpyFile::new(&bytes[..])
        .unwrap()
        .into_vec::<f64>()
        .unwrap()
}

fn npy_u32(path: &Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap();
    npyz::NpyFile::new(&bytes[..])
        .unwrap()
        .into_vec::<u32>()
        .unwrap()
}

/// The history lines a frame's data holds for processor `x` on scanline `line`, put
/// together from its columns as the page's script does (with `raw`, the raw integers
/// under each state, as the page shows them for fixed-point registers).
fn history_of(f: &Value, x: u64, line: u64, raw: bool) -> Vec<String> {
    let h = &f["history"];
    let strings = texts(&h["strings"]);
    let starts = u32s(&h["starts"]);
    let shifted = u32s(&h["shifted"]);
    let hidden = u32s(&h["hidden"]);
    let index = f64s(&h["visit_index"]);
    let cycle = f64s(&h["visit_cycle"]);
    let note = blob(&h["visit_note"]);
    let before = u32s(&h["visit_before"]);
    let after = u32s(&h["visit_after"]);
    let raws = raw.then(|| {
        (
            u32s(&h["raw"]["before"]),
            u32s(&h["raw"]["after"]),
            u32s(&h["raw"]["shifted"]),
        )
    });
    let instrs = texts(&f["dump"]["text"]);
    let i0 = f["dump"]["first_index"].as_u64().unwrap();
    let (x0, x1) = (h["x"][0].as_u64().unwrap(), h["x"][1].as_u64().unwrap());
    let l0 = h["lines"][0].as_u64().unwrap();
    let k = ((line - l0) * (x1 - x0) + (x - x0)) as usize;
    let notes = [
        "passes through",
        "suppressed: locked by Eval0",
        "suppressed: masked by Dis",
    ];
    let mut out = Vec::new();
    for v in starts[k] as usize..starts[k + 1] as usize {
        let how = match note[v] {
            0 => String::new(),
            n => format!("  ({})", notes[n as usize - 1]),
        };
        out.push(format!(
            "cycle {:>8}  #{:<6} {}{how}",
            cycle[v],
            index[v],
            instrs[index[v] as usize - i0 as usize]
        ));
        out.push(format!("    before  {}", strings[before[v] as usize]));
        if let Some((b, _, _)) = &raws {
            out.push(format!("       raw  {}", strings[b[v] as usize]));
        }
        out.push(format!("    after   {}", strings[after[v] as usize]));
        if let Some((_, a, _)) = &raws {
            out.push(format!("       raw  {}", strings[a[v] as usize]));
        }
    }
    if shifted[k] != u32::MAX {
        out.push(format!("shifted out: {}", strings[shifted[k] as usize]));
        if let Some((_, _, s)) = &raws {
            out.push(format!("       raw  {}", strings[s[k] as usize]));
        }
    }
    if hidden[k] > 0 {
        out.push(format!(
            "# {} more instruction(s) passed through without acting (--all lists them)",
            hidden[k]
        ));
    }
    out
}

/// The first frame of the first run's history lines.
fn page_history(data: &Value, x: u64, line: u64) -> Vec<String> {
    history_of(frame(data, 0, 0), x, line, false)
}

/// `cwisim history`'s lines without its heading, and without the notes heading its
/// visits (where each instruction came from), which the page does not show yet.
fn cli_history(dir: &Path, args: &[&str]) -> Vec<String> {
    let out = cwisim_ok(dir, args);
    out.lines()
        .filter(|l| !l.starts_with('#') || l.ends_with("(--all lists them)"))
        .map(str::to_string)
        .collect()
}

/// The `cwisim history` command the page suggests for a pixel, run: its lines.
fn suggested_history(dir: &Path, run: &Value, x: u64, line: u64) -> Vec<String> {
    let command = run["history_command"].as_str().unwrap();
    let words: Vec<&str> = command.split(' ').collect();
    assert_eq!(&words[..2], ["cwisim", "history"], "{command}");
    assert!(
        !command.contains('\''),
        "no quoting in these tests: {command}"
    );
    let (xs, ls) = (x.to_string(), line.to_string());
    let mut args: Vec<&str> = words[1..].to_vec();
    args.extend(["--x", &xs, "--line", &ls]);
    cli_history(dir, &args)
}

#[test]
fn a_trace_page_holds_what_run_history_and_dump_print() {
    let dir = scratch("inspect_trace");
    let trace = traces().join("visibility.cwt");
    let t = trace.to_str().unwrap();
    let said = cwisim_ok(&dir, &["inspect", t, "-o", "v.html"]);
    assert!(said.contains("wrote v.html: 16×3 frame 0"), "{said}");
    cwisim_ok(&dir, &["run", t, "--npy", "v.npy", "--cost-npy", "c.npy"]);
    let data = page(&dir, "v.html");
    assert_eq!(data["width"], 16);
    assert_eq!(data["lines"], 3);
    assert_eq!(data["frames"], serde_json::json!([0, 1]));
    let run = &data["runs"][0];
    assert_eq!(run["kind"], "trace");
    assert_eq!(run["label"], "");
    assert!(run["summary"].is_null() && run["formats"].is_null());
    let f = frame(&data, 0, 0);
    assert!(f["reference"].is_null());
    let image = f64s(&f["image"]);
    let npy = npy_f64(&dir.join("v.npy"));
    assert_eq!(image.len(), npy.len());
    for (a, b) in image.iter().zip(&npy) {
        assert_eq!(a.to_bits(), b.to_bits());
    }
    assert_eq!(u32s(&f["cost"]), npy_u32(&dir.join("c.npy")));

    // every pixel's history, as `cwisim history` prints it, and as the command the page
    // suggests prints it
    assert_eq!(
        run["history_command"],
        format!("cwisim history {t}"),
        "the input as given"
    );
    for line in 0..3u64 {
        for x in 0..16u64 {
            let (xs, ls) = (x.to_string(), line.to_string());
            let cli = cli_history(&dir, &["history", t, "--x", &xs, "--line", &ls]);
            assert_eq!(page_history(&data, x, line), cli, "x {x} line {line}");
        }
    }
    assert_eq!(
        page_history(&data, 9, 2),
        suggested_history(&dir, run, 9, 2)
    );
    // the example of docs/STUDYING.md: pixel 9's Eval0 overwrite is on the page
    assert!(page_history(&data, 9, 0).contains(&"shifted out: 0.125".to_string()));

    // every scanline's disassembly, as `cwisim dump --lines N` prints it
    let instrs = texts(&f["dump"]["text"]);
    let issue = f64s(&f["dump"]["issue"]);
    let enter = f64s(&f["dump"]["enter"]);
    let i0 = f["dump"]["first_index"].as_u64().unwrap() as usize;
    let dump: Vec<String> = (0..instrs.len())
        .map(|k| {
            format!(
                "{:<48} # #{} line {{}} issue {} enter {}",
                instrs[k],
                i0 + k,
                issue[k],
                enter[k]
            )
        })
        .collect();
    let starts: Vec<usize> = f["dump"]["line_start"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(starts.len(), 4);
    for line in 0..3usize {
        let ls = line.to_string();
        let cli = cwisim_ok(&dir, &["dump", t, "--lines", &ls]);
        let cli: Vec<&str> = cli
            .lines()
            .filter(|l| !l.starts_with('#') && !l.is_empty() && !l.starts_with("cwisim-trace"))
            .collect();
        let page: Vec<String> = dump[starts[line]..starts[line + 1]]
            .iter()
            .map(|l| l.replace("{}", &ls))
            .collect();
        assert_eq!(page, cli, "line {line}");
    }
}

/// The event view draws token `k` in processor `p` over cycles
/// `[enter + p·hop, enter + (p+1)·hop)`, acting where its operands name: every visit a
/// history holds is at that cycle, and the operands are the instruction's.
#[test]
fn the_event_view_has_every_tokens_cycles_and_operands() {
    let dir = scratch("inspect_events");
    let trace = traces().join("visibility.cwt");
    let t = trace.to_str().unwrap();
    for hop in [1u64, 3] {
        let set = format!("hop_cycles={hop}");
        cwisim_ok(&dir, &["inspect", t, "--set", &set, "-o", "e.html"]);
        let data = page(&dir, "e.html");
        let run = &data["runs"][0];
        assert_eq!(run["hop"], hop);
        assert!(run["history_command"]
            .as_str()
            .unwrap()
            .ends_with(&format!("--set {set}")));
        let f = frame(&data, 0, 0);
        let enter = f64s(&f["dump"]["enter"]);
        let i0 = f["dump"]["first_index"].as_u64().unwrap();
        let h = &f["history"];
        let starts = u32s(&h["starts"]);
        let index = f64s(&h["visit_index"]);
        let cycle = f64s(&h["visit_cycle"]);
        let mut checked = 0;
        for line in 0..3u64 {
            for x in 0..16u64 {
                let k = (line * 16 + x) as usize;
                for v in starts[k] as usize..starts[k + 1] as usize {
                    let e = enter[index[v] as usize - i0 as usize];
                    assert_eq!(
                        cycle[v],
                        e + (x * hop) as f64,
                        "x {x} line {line} hop {hop}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 50, "{checked}");
        // the operands, as the text of each instruction says them
        let opcodes: Vec<&str> = data["opcodes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        let (ops, xs, dxs) = (
            blob(&f["dump"]["op"]),
            u32s(&f["dump"]["x"]),
            u32s(&f["dump"]["dx"]),
        );
        for (k, text) in texts(&f["dump"]["text"]).iter().enumerate() {
            let words: Vec<&str> = text.split(' ').collect();
            assert_eq!(opcodes[ops[k] as usize], words[0]);
            let reach = data["op_reach"][ops[k] as usize].as_str().unwrap();
            if reach == "range" {
                assert_eq!(xs[k].to_string(), words[1], "{text}");
                assert_eq!(dxs[k].to_string(), words[2], "{text}");
            }
        }
    }
}

#[test]
fn the_timeline_is_stats_figures() {
    let dir = scratch("inspect_timeline");
    let trace = traces().join("overrun.cwt");
    let machine = traces().join("overrun.machine.json");
    let (t, m) = (trace.to_str().unwrap(), machine.to_str().unwrap());
    let said = cwisim_ok(&dir, &["inspect", t, "--machine", m, "-o", "o.html"]);
    assert!(said.contains("1 late scanline(s)"), "{said}");
    cwisim_ok(
        &dir,
        &["stats", t, "--machine", m, "--stats-json", "s.json"],
    );
    let stats: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).unwrap()).unwrap();
    let data = page(&dir, "o.html");
    let run = &data["runs"][0];
    assert_eq!(
        run["history_command"],
        format!("cwisim history {t} --machine {m}")
    );
    let tl = &frame(&data, 0, 0)["timeline"];
    assert_eq!(run["line_period"], stats["line_period"]);
    let recs = stats["lines"].as_array().unwrap();
    let g = data["groups"].as_array().unwrap().len();
    for (r, rec) in recs.iter().enumerate() {
        for key in ["busy_cycles", "stall_cycles", "slack", "ready", "deadline"] {
            let page_key = match key {
                "busy_cycles" => "busy",
                "stall_cycles" => "stall",
                k => k,
            };
            assert_eq!(
                tl[page_key][r].as_f64().unwrap(),
                rec[key].as_f64().unwrap(),
                "{key} of line {r}"
            );
        }
        // the stacked segments add up to the bus's busy and stall cycles
        let sum: f64 = (0..g)
            .map(|k| tl["cycles"][r * g + k].as_f64().unwrap())
            .sum();
        assert_eq!(
            sum,
            rec["busy_cycles"].as_f64().unwrap() + rec["stall_cycles"].as_f64().unwrap()
        );
    }
    assert!(tl["slack"][1].as_f64().unwrap() < 0.0, "scanline 1 is late");
}

#[test]
fn a_scene_page_has_its_summary_reference_and_is_deterministic() {
    let dir = scratch("inspect_scene");
    let args = ["inspect", "pot", "--size", "64x48", "-o", "a.html"];
    cwisim_ok(&dir, &args);
    cwisim_ok(&dir, &["inspect", "pot", "--size", "64x48", "-o", "b.html"]);
    let a = std::fs::read(dir.join("a.html")).unwrap();
    assert_eq!(a, std::fs::read(dir.join("b.html")).unwrap(), "same bytes");
    // and at any thread count, one per core included, A/B too
    for threads in ["2", "3", "0"] {
        cwisim_ok(
            &dir,
            &[
                "inspect",
                "pot",
                "--size",
                "64x48",
                "--threads",
                threads,
                "-o",
                "t.html",
            ],
        );
        let t = std::fs::read(dir.join("t.html")).unwrap();
        assert!(t == a, "--threads {threads}: not the same bytes");
    }
    let ab = |threads: &str, out: &str| {
        cwisim_ok(
            &dir,
            &[
                "inspect",
                "pot",
                "--size",
                "64x48",
                "--against",
                "pot --size 64x48 --numeric f32",
                "--threads",
                threads,
                "-o",
                out,
            ],
        );
        std::fs::read(dir.join(out)).unwrap()
    };
    assert!(
        ab("1", "ab1.html") == ab("2", "ab2.html"),
        "A/B at two threads"
    );
    let data = page(&dir, "a.html");
    let run = &data["runs"][0];
    let summary = run["summary"].as_str().unwrap();
    assert!(
        summary.starts_with("scene        pot (world, 64×48"),
        "{summary}"
    );
    assert!(summary.contains("vanrij"), "{summary}");
    assert!(!summary.contains(" ms"), "no wall times: {summary}");
    // the suggested command keeps --size
    assert_eq!(run["history_command"], "cwisim history pot --size 64x48");
    assert_eq!(
        run["reproduce"],
        serde_json::json!(["pot", "--size", "64x48"])
    );
    cwisim_ok(
        &dir,
        &["render", "pot", "--size", "64x48", "--npy", "p.npy", "-q"],
    );
    let f = frame(&data, 0, 0);
    let image = f64s(&f["image"]);
    assert_eq!(image, npy_f64(&dir.join("p.npy")));
    let reference = f64s(&f["reference"]);
    assert_eq!(reference.len(), image.len());
    let worst = image
        .iter()
        .zip(&reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst > 0.0 && worst < 0.5, "{worst}");
    for (x, line) in [(32u64, 24u64), (0, 0), (40, 30)] {
        let (xs, ls) = (x.to_string(), line.to_string());
        let cli = cli_history(
            &dir,
            &[
                "history", "pot", "--size", "64x48", "--x", &xs, "--line", &ls,
            ],
        );
        assert_eq!(page_history(&data, x, line), cli, "x {x} line {line}");
        assert_eq!(suggested_history(&dir, run, x, line), cli);
    }
}

/// The error overlay's scale starts at the page's floor: `f64` rounding (the pot's whole
/// error against its exact reference, about 1e-14) is under it and colours nothing, the
/// errors of `f32` registers are over it.
#[test]
fn rounding_is_under_the_error_floor_and_f32_is_over_it() {
    let dir = scratch("inspect_floor");
    let worst = |name: &str| {
        let data = page(&dir, name);
        assert_eq!(data["error_floor"], 1e-12);
        let f = frame(&data, 0, 0);
        let (image, reference) = (f64s(&f["image"]), f64s(&f["reference"]));
        let over = image
            .iter()
            .zip(&reference)
            .filter(|(a, b)| (*a - *b).abs() >= 1e-12)
            .count();
        let worst = image
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        (over, worst)
    };
    cwisim_ok(
        &dir,
        &["inspect", "pot", "--size", "64x48", "-o", "f64.html"],
    );
    let (over, worst64) = worst("f64.html");
    assert_eq!(over, 0, "rounding only: {worst64}");
    assert!(worst64 > 0.0 && worst64 < 1e-13, "{worst64}");
    cwisim_ok(
        &dir,
        &[
            "inspect",
            "pot",
            "--size",
            "64x48",
            "--numeric",
            "f32",
            "-o",
            "f32.html",
        ],
    );
    let (over, worst32) = worst("f32.html");
    assert!(over > 100 && worst32 > 1e-9, "{over} {worst32}");
}

/// Fixed-point registers: the page names each register's format, and under every state
/// of a history the raw integers (value × 2^N), which are the values' own.
#[test]
fn fixed_point_histories_show_the_raw_integers() {
    let dir = scratch("inspect_fixed");
    let trace = traces().join("gouraud.cwt");
    let t = trace.to_str().unwrap();
    let numeric = "fixed:I=12.20,dI=4.28,ddI=1.36,acc=16.16,overflow=wrap";
    cwisim_ok(&dir, &["inspect", t, "--numeric", numeric, "-o", "q.html"]);
    let data = page(&dir, "q.html");
    let run = &data["runs"][0];
    assert_eq!(run["numeric"], numeric);
    assert_eq!(
        run["formats"],
        serde_json::json!({"I": [12, 20], "dI": [4, 28], "ddI": [1, 36], "acc": [16, 16], "overflow": "wrap"})
    );
    assert_eq!(
        run["history_command"],
        format!("cwisim history {t} --numeric {numeric}")
    );
    let f = frame(&data, 0, 0);
    let width = data["width"].as_u64().unwrap();
    let lines = data["lines"].as_u64().unwrap();
    let mut raws = 0;
    for line in 0..lines {
        for x in (0..width).step_by(3) {
            let plain = history_of(f, x, line, false);
            // without the raw lines: `cwisim history --numeric` exactly
            let (xs, ls) = (x.to_string(), line.to_string());
            let cli = cli_history(
                &dir,
                &[
                    "history",
                    t,
                    "--numeric",
                    numeric,
                    "--x",
                    &xs,
                    "--line",
                    &ls,
                ],
            );
            assert_eq!(plain, cli, "x {x} line {line}");
            // with them: each state's registers again, as integers of their formats
            let with = history_of(f, x, line, true);
            let mut shown = with.iter().filter(|l| !l.starts_with("       raw  "));
            assert!(plain.iter().all(|l| shown.next() == Some(l)));
            for pair in with.windows(2) {
                let Some(raw) = pair[1].strip_prefix("       raw  ") else {
                    continue;
                };
                // the value shifted out is the accumulator's
                let raw = if pair[0].starts_with("shifted out: ") {
                    format!("acc={raw}")
                } else {
                    raw.to_string()
                };
                let real = pair[0]
                    .strip_prefix("    before  ")
                    .or_else(|| pair[0].strip_prefix("    after   "))
                    .map(|s| s.split(" flags=").next().unwrap().to_string())
                    .or_else(|| {
                        pair[0]
                            .strip_prefix("shifted out: ")
                            .map(|v| format!("acc={v}"))
                    })
                    .expect("a raw line under a state");
                let scale = |reg: &str| {
                    2f64.powi(match reg {
                        "acc" => 16,
                        "I" => 20,
                        "dI" => 28,
                        _ => 36,
                    })
                };
                let reals: Vec<&str> = real.split(' ').filter(|w| w.contains('=')).collect();
                let ints: Vec<&str> = raw.split(' ').collect();
                for (r, i) in reals.iter().zip(&ints) {
                    let (reg, rv) = r.split_once('=').unwrap();
                    let (reg2, iv) = i.split_once('=').unwrap();
                    assert_eq!(reg, reg2, "{real} / {raw}");
                    if rv == "-" {
                        assert_eq!(iv, "-");
                        continue;
                    }
                    let v: f64 = rv.parse().unwrap();
                    let n: i64 = iv.parse().unwrap();
                    assert_eq!(v * scale(reg), n as f64, "{real} / {raw}");
                    raws += 1;
                }
            }
        }
    }
    assert!(raws > 100, "{raws}");
}

#[test]
fn a_window_holds_only_its_histories() {
    let dir = scratch("inspect_window");
    let said = cwisim_ok(
        &dir,
        &[
            "inspect", "pot", "--size", "64x48", "--x", "10..=19", "--lines", "20..25", "-o",
            "w.html",
        ],
    );
    assert!(
        said.contains("processors 10..20 of scanlines 20..25"),
        "{said}"
    );
    let data = page(&dir, "w.html");
    let h = &frame(&data, 0, 0)["history"];
    assert_eq!(u32s(&h["starts"]).len(), 10 * 5 + 1);
    assert_eq!(u32s(&h["hidden"]).len(), 10 * 5);
    let cli = cli_history(
        &dir,
        &[
            "history", "pot", "--size", "64x48", "--x", "19", "--line", "24",
        ],
    );
    assert_eq!(page_history(&data, 19, 24), cli);
}

/// A trace of `frames` frames of 8 × 2 grey pixels, each frame's values its own.
fn frames_trace(dir: &Path, name: &str, frames: u64) {
    let mut text = String::from("cwisim-trace version=1 width=8 lines=2 channels=1\n");
    for f in 0..frames {
        let v = (f + 1) as f64 / 16.0;
        text += &format!(
            "Eval2 {} 4 {v} 0.125\nRefresh\nEval1 0 8 {v}\nEval0 {} 1 0.5\nRefresh\n",
            f % 4,
            f % 8
        );
    }
    std::fs::write(dir.join(name), text).unwrap();
}

#[test]
fn a_range_of_frames_holds_every_frame_as_run_and_history_see_it() {
    let dir = scratch("inspect_range");
    frames_trace(&dir, "five.cwt", 5);
    cwisim_ok(
        &dir,
        &["run", "five.cwt", "--npy", "all.npy", "--cost-npy", "c.npy"],
    );
    let all = npy_f64(&dir.join("all.npy"));
    let costs = npy_u32(&dir.join("c.npy"));
    for (range, first, n) in [
        ("1..4", 1u64, 3u64),
        ("1..=3", 1, 3),
        ("2..", 2, 3),
        ("0..", 0, 5),
    ] {
        let said = cwisim_ok(
            &dir,
            &["inspect", "five.cwt", "--frames", range, "-o", "r.html"],
        );
        let shown = if n == 1 {
            format!("frame {first}")
        } else {
            format!("frames {first}..{}", first + n)
        };
        assert!(said.contains(&format!("8×2 {shown},")), "{said}");
        assert!(
            said.contains(&format!("of scanlines {}..{}", 2 * first, 2 * (first + n))),
            "{said}"
        );
        let data = page(&dir, "r.html");
        assert_eq!(
            data["frames"],
            serde_json::json!([first, first + n]),
            "{range}"
        );
        assert_eq!(
            data["runs"][0]["frames"].as_array().unwrap().len(),
            n as usize
        );
        for k in 0..n {
            let f = frame(&data, 0, k as usize);
            let fr = first + k;
            assert_eq!(f["frame"], fr);
            assert_eq!(f["first_line"], 2 * fr);
            let s = (16 * fr) as usize;
            assert_eq!(f64s(&f["image"]), all[s..s + 16], "frame {fr}");
            assert_eq!(u32s(&f["cost"]), costs[s..s + 16], "frame {fr}");
            for (x, row) in [(0u64, 0u64), (3, 1), (fr % 8, 1)] {
                let line = 2 * fr + row;
                let (xs, ls) = (x.to_string(), line.to_string());
                let cli = cli_history(&dir, &["history", "five.cwt", "--x", &xs, "--line", &ls]);
                assert_eq!(history_of(f, x, line, false), cli, "x {x} line {line}");
            }
        }
    }
    // a history window over two frames holds each frame's part
    let said = cwisim_ok(
        &dir,
        &[
            "inspect", "five.cwt", "--frames", "1..4", "--lines", "3..5", "--x", "2..6", "-o",
            "w.html",
        ],
    );
    assert!(said.contains("processors 2..6 of scanlines 3..5"), "{said}");
    let data = page(&dir, "w.html");
    assert_eq!(
        frame(&data, 0, 0)["history"]["lines"],
        serde_json::json!([3, 4])
    );
    assert_eq!(
        frame(&data, 0, 1)["history"]["lines"],
        serde_json::json!([4, 5])
    );
    assert!(frame(&data, 0, 2)["history"].is_null());
    // the same bytes again
    let a = std::fs::read(dir.join("w.html")).unwrap();
    cwisim_ok(
        &dir,
        &[
            "inspect", "five.cwt", "--frames", "1..4", "--lines", "3..5", "--x", "2..6", "-o",
            "w.html",
        ],
    );
    assert_eq!(a, std::fs::read(dir.join("w.html")).unwrap());
}

/// An A/B page: two runs side by side, each as its own commands see it.
#[test]
fn an_ab_page_holds_both_runs() {
    let dir = scratch("inspect_ab");
    let b_spec = "pot --size 64x48 --renderer woo-chall --samples 2";
    let said = cwisim_ok(
        &dir,
        &[
            "inspect",
            "pot",
            "--size",
            "64x48",
            "--against",
            b_spec,
            "-o",
            "ab.html",
        ],
    );
    assert!(said.contains("late scanline(s) in A, 0 in B"), "{said}");
    let data = page(&dir, "ab.html");
    let runs = data["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    assert_eq!(
        (runs[0]["label"].as_str(), runs[1]["label"].as_str()),
        (Some("A"), Some("B"))
    );
    assert_eq!(runs[0]["name"], "pot");
    assert_eq!(runs[1]["name"], "pot");
    assert_eq!(
        runs[0]["history_command"],
        "cwisim history pot --size 64x48"
    );
    assert_eq!(
        runs[1]["history_command"],
        "cwisim history pot --renderer woo-chall --size 64x48 --samples 2"
    );
    cwisim_ok(
        &dir,
        &["render", "pot", "--size", "64x48", "--npy", "a.npy", "-q"],
    );
    cwisim_ok(
        &dir,
        &[
            "render",
            "pot",
            "--size",
            "64x48",
            "--renderer",
            "woo-chall",
            "--samples",
            "2",
            "--npy",
            "b.npy",
            "-q",
        ],
    );
    let (a, b) = (
        f64s(&frame(&data, 0, 0)["image"]),
        f64s(&frame(&data, 1, 0)["image"]),
    );
    assert_eq!(a, npy_f64(&dir.join("a.npy")));
    assert_eq!(b, npy_f64(&dir.join("b.npy")));
    assert!(a != b, "two renderers draw differently");
    for (x, line) in [(32u64, 24u64), (20, 30)] {
        for (k, run) in runs.iter().enumerate() {
            assert_eq!(
                history_of(frame(&data, k, 0), x, line, false),
                suggested_history(&dir, run, x, line),
                "run {k} x {x} line {line}"
            );
        }
    }

    // two traces: the second of the same dimensions, one value changed
    let t = traces().join("visibility.cwt");
    let text = std::fs::read_to_string(&t)
        .unwrap()
        .replace("Eval1 3 1 0.25", "Eval1 3 1 0.5");
    std::fs::write(dir.join("b.cwt"), text).unwrap();
    let ts = t.to_str().unwrap();
    cwisim_ok(&dir, &["inspect", ts, "--against", "b.cwt", "-o", "t.html"]);
    let data = page(&dir, "t.html");
    let (a, b) = (
        f64s(&frame(&data, 0, 0)["image"]),
        f64s(&frame(&data, 1, 0)["image"]),
    );
    let differ: Vec<usize> = (0..a.len()).filter(|&k| a[k] != b[k]).collect();
    assert_eq!(differ, [3], "pixel 3 of scanline 0");
    assert_eq!(data["runs"][1]["name"], "b.cwt");
    // the same bytes again
    let first = std::fs::read(dir.join("t.html")).unwrap();
    cwisim_ok(&dir, &["inspect", ts, "--against", "b.cwt", "-o", "t.html"]);
    assert_eq!(first, std::fs::read(dir.join("t.html")).unwrap());
}

#[test]
fn bad_requests_are_refused_with_exit_2() {
    let dir = scratch("inspect_refusals");
    let trace = traces().join("visibility.cwt");
    let t = trace.to_str().unwrap();
    let rgb = traces().join("rgb.cwt");
    let rgb = rgb.to_str().unwrap();
    frames_trace(&dir, "five.cwt", 5);
    frames_trace(&dir, "short.cwt", 2);
    for (args, says) in [
        (vec!["inspect", t, "-o", "x.png"], "does not end in .html"),
        (
            vec!["inspect", t, "-o", "x.html", "--frames", "1"],
            "frame 1 is not in the input",
        ),
        (
            vec!["inspect", t, "-o", "x.html", "--frames", "0..2"],
            "frame 1 is not in the input",
        ),
        (
            vec!["inspect", "five.cwt", "-o", "x.html", "--frames", "3..9"],
            "frame 5 is not in the input",
        ),
        (
            vec!["inspect", "five.cwt", "-o", "x.html", "--frames", "7.."],
            "frame 7 is not in the input",
        ),
        (
            vec!["inspect", "five.cwt", "-o", "x.html", "--frames", "0..100"],
            "more than a page holds (64)",
        ),
        (
            vec![
                "inspect",
                "pot",
                "--size",
                "1024x1024",
                "--frames",
                "0..5",
                "-o",
                "x.html",
            ],
            "it holds 4 such frame(s)",
        ),
        (
            vec![
                "inspect", "five.cwt", "-o", "x.html", "--frames", "1..3", "--lines", "1",
            ],
            "starts before frames 1..3",
        ),
        (
            vec!["inspect", t, "-o", "x.html", "--x", "3..40"],
            "outside the processors",
        ),
        (
            vec!["inspect", t, "-o", "x.html", "--lines", "5"],
            "outside the scanlines",
        ),
        (
            vec!["inspect", "pot", "--size", "2100x2100", "-o", "x.html"],
            "over the page's limit",
        ),
        (
            vec![
                "inspect",
                "pot",
                "--size",
                "1024x1024",
                "--x",
                "0..1024",
                "-o",
                "x.html",
            ],
            "at most 262144",
        ),
        (
            vec!["inspect", t, "--against", rgb, "-o", "x.html"],
            "an A/B page compares runs of the same dimensions",
        ),
        (
            vec![
                "inspect",
                "pot",
                "--size",
                "64x48",
                "--against",
                "pot",
                "-o",
                "x.html",
            ],
            "A (pot) is 64×48 with 1 channel(s) but B (pot) is",
        ),
        (
            vec!["inspect", t, "--against", "pot --bogus 3", "-o", "x.html"],
            "--bogus",
        ),
        (
            vec![
                "inspect",
                t,
                "--against",
                "b.cwt --renderer bsp",
                "-o",
                "x.html",
            ],
            "--renderer applies when the input is a scene",
        ),
        (
            vec!["inspect", t, "--against", "'unclosed", "-o", "x.html"],
            "unclosed",
        ),
        (
            vec![
                "inspect",
                "five.cwt",
                "--frames",
                "1..3",
                "--against",
                "short.cwt",
                "-o",
                "x.html",
            ],
            "B (short.cwt): frame 2 is not in the input",
        ),
        (
            vec![
                "inspect",
                "pot",
                "--size",
                "1024x1024",
                "--against",
                "pot --size 1024x1024",
                "--x",
                "0..512",
                "--lines",
                "0..512",
                "-o",
                "x.html",
            ],
            "at most 131072 in each of the two runs",
        ),
    ] {
        let out = cwisim(&dir, &args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
    assert!(!dir.join("x.html").exists());
}

#[test]
fn a_later_frame_of_a_trace_and_nothing_from_the_network() {
    let dir = scratch("inspect_frames");
    std::fs::write(
        dir.join("two.cwt"),
        "cwisim-trace version=1 width=8 lines=2 channels=1\n\
Eval2 2 4 0.5 0.125\nRefresh\nEval1 0 8 1.0\nRefresh\n\
Eval1 3 2 0.25\nRefresh\nEval1 1 1 0.75\nRefresh\n",
    )
    .unwrap();
    let said = cwisim_ok(
        &dir,
        &["inspect", "two.cwt", "--frames", "1", "-o", "f.html"],
    );
    assert!(said.contains("frame 1"), "{said}");
    let html = std::fs::read_to_string(dir.join("f.html")).unwrap();
    // self-contained: no address of anything to fetch
    for fetch in ["http:", "https:", "src=", "href=", "@import", "url("] {
        assert!(!html.contains(fetch), "the page fetches `{fetch}`");
    }
    let data = page(&dir, "f.html");
    let f = frame(&data, 0, 0);
    assert_eq!(f["first_line"], 2);
    assert_eq!(
        f64s(&f["image"])[8..16],
        [0.0, 0.75, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    );
    for (x, line) in [(1u64, 3u64), (3, 2), (0, 2)] {
        let (xs, ls) = (x.to_string(), line.to_string());
        let cli = cli_history(&dir, &["history", "two.cwt", "--x", &xs, "--line", &ls]);
        assert_eq!(history_of(f, x, line, false), cli, "x {x} line {line}");
    }
}
