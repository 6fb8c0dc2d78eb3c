//! `cwisim inspect`: the page's embedded data read back and held to the other tools'
//! outputs — the image to `run --npy`, the costs to `--cost-npy`, every history of the
//! window to `cwisim history`, every scanline's disassembly to `cwisim dump`, the
//! timeline to `stats --stats-json` — and the same input giving the same bytes. The page in a
//! real browser is `tests/browser.rs`.

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

/// The page's history lines of processor `x` on scanline `line`, put together from its
/// columns as the page's script does.
fn page_history(data: &Value, x: u64, line: u64) -> Vec<String> {
    let h = &data["history"];
    let strings = texts(&h["strings"]);
    let starts = u32s(&h["starts"]);
    let shifted = u32s(&h["shifted"]);
    let hidden = u32s(&h["hidden"]);
    let index = f64s(&h["visit_index"]);
    let cycle = f64s(&h["visit_cycle"]);
    let note = blob(&h["visit_note"]);
    let before = u32s(&h["visit_before"]);
    let after = u32s(&h["visit_after"]);
    let instrs = texts(&data["dump"]["text"]);
    let i0 = data["dump"]["first_index"].as_u64().unwrap();
    let (x0, x1) = (h["x"][0].as_u64().unwrap(), h["x"][1].as_u64().unwrap());
    let l0 = h["lines"][0].as_u64().unwrap();
    let k = ((line - l0) * (x1 - x0) + (x - x0)) as usize;
    let mut out = Vec::new();
    for v in starts[k] as usize..starts[k + 1] as usize {
        let how = match note[v] {
            0 => String::new(),
            n => format!("  ({})", h["notes"][n as usize - 1].as_str().unwrap()),
        };
        out.push(format!(
            "cycle {:>8}  #{:<6} {}{how}",
            cycle[v],
            index[v],
            instrs[index[v] as usize - i0 as usize]
        ));
        out.push(format!("    before  {}", strings[before[v] as usize]));
        out.push(format!("    after   {}", strings[after[v] as usize]));
    }
    if shifted[k] != u32::MAX {
        out.push(format!("shifted out: {}", strings[shifted[k] as usize]));
    }
    if hidden[k] > 0 {
        out.push(format!(
            "# {} more instruction(s) passed through without acting (--all lists them)",
            hidden[k]
        ));
    }
    out
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
    assert_eq!(data["kind"], "trace");
    assert!(data["summary"].is_null() && data["reference"].is_null());
    let image = f64s(&data["image"]);
    let npy = npy_f64(&dir.join("v.npy"));
    assert_eq!(image.len(), npy.len());
    for (a, b) in image.iter().zip(&npy) {
        assert_eq!(a.to_bits(), b.to_bits());
    }
    assert_eq!(u32s(&data["cost"]), npy_u32(&dir.join("c.npy")));

    // every pixel's history, as `cwisim history` prints it
    for line in 0..3u64 {
        for x in 0..16u64 {
            let (xs, ls) = (x.to_string(), line.to_string());
            let cli = cli_history(&dir, &["history", t, "--x", &xs, "--line", &ls]);
            assert_eq!(page_history(&data, x, line), cli, "x {x} line {line}");
        }
    }
    // the example of docs/STUDYING.md: pixel 9's Eval0 overwrite is on the page
    assert!(page_history(&data, 9, 0).contains(&"shifted out: 0.125".to_string()));

    // every scanline's disassembly, as `cwisim dump --lines N` prints it
    let instrs = texts(&data["dump"]["text"]);
    let issue = f64s(&data["dump"]["issue"]);
    let enter = f64s(&data["dump"]["enter"]);
    let i0 = data["dump"]["first_index"].as_u64().unwrap() as usize;
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
    let starts: Vec<usize> = data["dump"]["line_start"]
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
    let tl = &data["timeline"];
    assert_eq!(tl["line_period"], stats["line_period"]);
    let recs = stats["lines"].as_array().unwrap();
    let g = tl["groups"].as_array().unwrap().len();
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
    let data = page(&dir, "a.html");
    let summary = data["summary"].as_str().unwrap();
    assert!(
        summary.starts_with("scene        pot (world, 64×48"),
        "{summary}"
    );
    assert!(summary.contains("vanrij"), "{summary}");
    assert!(!summary.contains(" ms"), "no wall times: {summary}");
    cwisim_ok(
        &dir,
        &["render", "pot", "--size", "64x48", "--npy", "p.npy", "-q"],
    );
    let image = f64s(&data["image"]);
    assert_eq!(image, npy_f64(&dir.join("p.npy")));
    let reference = f64s(&data["reference"]);
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
    }
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
    assert_eq!(u32s(&data["history"]["starts"]).len(), 10 * 5 + 1);
    assert_eq!(u32s(&data["history"]["hidden"]).len(), 10 * 5);
    let cli = cli_history(
        &dir,
        &[
            "history", "pot", "--size", "64x48", "--x", "19", "--line", "24",
        ],
    );
    assert_eq!(page_history(&data, 19, 24), cli);
}

#[test]
fn bad_requests_are_refused_with_exit_2() {
    let dir = scratch("inspect_refusals");
    let trace = traces().join("visibility.cwt");
    let t = trace.to_str().unwrap();
    for (args, says) in [
        (vec!["inspect", t, "-o", "x.png"], "does not end in .html"),
        (
            vec!["inspect", t, "-o", "x.html", "--frames", "1"],
            "frame 1 is not in the input",
        ),
        (
            vec!["inspect", t, "-o", "x.html", "--frames", "0..2"],
            "one frame",
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
    assert_eq!(data["first_line"], 2);
    assert_eq!(
        f64s(&data["image"])[8..16],
        [0.0, 0.75, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    );
    for (x, line) in [(1u64, 3u64), (3, 2), (0, 2)] {
        let (xs, ls) = (x.to_string(), line.to_string());
        let cli = cli_history(&dir, &["history", "two.cwt", "--x", &xs, "--line", &ls]);
        assert_eq!(page_history(&data, x, line), cli, "x {x} line {line}");
    }
}
