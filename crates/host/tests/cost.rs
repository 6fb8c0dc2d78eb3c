//! Cost images (`--cost-image`, `--cost-npy` on `run` and `render`) through the real
//! binary: exact counts on hand-computed traces, the heat map's pixels, determinism.

mod common;

use common::{cwisim, cwisim_ok, fig25, read, scratch, text, trace};
use cwisim_study::cost::{cost_layout, count_color};
use serde_json::Value;
use std::path::Path;

/// The shape and counts of a cost `.npy` (which must be uint32).
fn counts(path: impl AsRef<Path>) -> (Vec<u64>, Vec<u32>) {
    let bytes = read(path);
    let npy = npyz::NpyFile::new(&bytes[..]).expect("a .npy header");
    assert_eq!(npy.dtype().descr(), "'<u4'", "uint32");
    let shape = npy.shape().to_vec();
    (shape, npy.into_vec::<u32>().expect("uint32 data"))
}

fn json(path: impl AsRef<Path>) -> Value {
    serde_json::from_slice(&read(path)).expect("JSON")
}

/// Each scanline's counts add up to its `processor_updates` in `--stats-json`.
fn assert_rows_sum_to_updates(shape: &[u64], data: &[u32], stats: &Value) {
    let lines = stats["stats"]["lines"].as_array().expect("lines");
    assert_eq!(shape[0] as usize, lines.len());
    for (row, rec) in data.chunks(shape[1] as usize).zip(lines) {
        let sum: u64 = row.iter().map(|&c| u64::from(c)).sum();
        assert_eq!(
            Value::from(sum),
            rec["processor_updates"],
            "line {}",
            rec["line"]
        );
    }
}

/// Every pixel of the heat map has the colour of its count.
fn assert_heat_map(png: &Path, shape: &[u64], data: &[u32]) {
    let img = image::open(png).expect("a PNG").into_rgb8();
    let (lines, width) = (shape[0] as usize, shape[1] as usize);
    let layout = cost_layout(width, lines).expect("layout");
    assert_eq!(img.dimensions(), layout.size);
    assert!(width as u32 * layout.scale >= 256 || layout.scale == 1);
    let max = data.iter().copied().max().unwrap_or(0);
    let (ox, oy) = layout.origin;
    for y in 0..lines as u32 * layout.scale {
        for x in 0..width as u32 * layout.scale {
            let c = data[(y / layout.scale) as usize * width + (x / layout.scale) as usize];
            assert_eq!(
                img.get_pixel(ox + x, oy + y).0,
                count_color(c, max),
                "image pixel ({x}, {y})"
            );
        }
    }
}

#[test]
fn visibility_counts_are_exact() {
    let dir = scratch("cost-visibility");
    let t = trace("visibility.cwt");
    cwisim_ok(
        &dir,
        &[
            "run",
            &t,
            "--cost-npy",
            "c.npy",
            "--cost-image",
            "c.png",
            "--stats-json",
            "s.json",
        ],
    );
    let (shape, data) = counts(dir.join("c.npy"));
    assert_eq!(shape, [3, 16]);
    // line 0: Eval1 3 1, Eval0 4 5, Eval1 9 1, Eval2 0 16, Eval0 6 6
    // line 1: Dis 4 4, Eval1 0 16, Eval1 0 16;  line 2: Eval1 0 16
    #[rustfmt::skip]
    let want: [u32; 48] = [
        1, 1, 1, 2, 2, 2, 3, 3, 3, 3, 2, 2, 1, 1, 1, 1,
        2, 2, 2, 2, 3, 3, 3, 3, 2, 2, 2, 2, 2, 2, 2, 2,
        1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1,
    ];
    assert_eq!(data, want);
    assert_rows_sum_to_updates(&shape, &data, &json(dir.join("s.json")));
    assert_heat_map(&dir.join("c.png"), &shape, &data);
}

#[test]
fn every_kind_of_instruction_counts_what_it_addresses() {
    let dir = scratch("cost-kinds");
    std::fs::write(
        dir.join("k.cwt"),
        "cwisim-trace version=1 width=10 lines=3 channels=1
SetI 2 0.5
SetdI 2 0.5
SetPI 1 4 0.25
SetPddI 9 3 0.25
Eval3 0 4 0.0 0.0 0.1
Dis 3 3
Eval1 0 10 0.5
Acc_mode
Nop
Refresh
Refresh
Eval0 5 0 0.5
Eval2 8 2 0.0 0.1
Refresh
Eval1 0 10 1.0
",
    )
    .expect("write");
    let out = cwisim(
        &dir,
        &[
            "run",
            "k.cwt",
            "--cost-npy",
            "k.npy",
            "--cost-image",
            "k.png",
            "--stats-json",
            "s.json",
        ],
    );
    let (_, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("1 instruction(s) after the last Refresh"),
        "{stderr}"
    );
    let (shape, data) = counts(dir.join("k.npy"));
    // the frame is 2 lines; the third Refresh starts frame 1: three scanlines
    assert_eq!(shape, [3, 10]);
    #[rustfmt::skip]
    let want: [u32; 30] = [
        // SetI/SetdI at 2; SetPI at 1, 5, 9; SetPddI at 9; Eval3 0..4; Dis 3..6; Eval1 all
        2, 3, 4, 3, 2, 3, 1, 1, 1, 3,
        0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
        // an empty Eval0 touches nothing; Eval2 8..10; the last Eval1 is in no scanline
        0, 0, 0, 0, 0, 0, 0, 0, 1, 1,
    ];
    assert_eq!(data, want);
    assert_rows_sum_to_updates(&shape, &data, &json(dir.join("s.json")));
    assert_heat_map(&dir.join("k.png"), &shape, &data);
}

#[test]
fn cost_outputs_are_deterministic_and_change_nothing_else() {
    let dir = scratch("cost-determinism");
    let t = trace("gouraud.cwt");
    cwisim_ok(
        &dir,
        &[
            "run",
            &t,
            "--npy",
            "plain.npy",
            "--stats-json",
            "plain.json",
        ],
    );
    let args = [
        "run",
        &t,
        "--npy",
        "i.npy",
        "--stats-json",
        "s.json",
        "--cost-image",
        "a.png",
        "--cost-npy",
        "a.npy",
    ];
    assert_eq!(
        cwisim_ok(&dir, &args),
        "wrote i.npy, a.png, a.npy, s.json: 6 scanline(s) of 16 × 1 channel(s)\n"
    );
    let (png, npy) = (read(dir.join("a.png")), read(dir.join("a.npy")));
    cwisim_ok(&dir, &args);
    assert_eq!(png, read(dir.join("a.png")), "byte-identical PNG");
    assert_eq!(npy, read(dir.join("a.npy")), "byte-identical .npy");
    assert_eq!(read(dir.join("plain.npy")), read(dir.join("i.npy")));
    assert_eq!(read(dir.join("plain.json")), read(dir.join("s.json")));
    let (shape, data) = counts(dir.join("a.npy"));
    assert_rows_sum_to_updates(&shape, &data, &json(dir.join("s.json")));
    assert_heat_map(&dir.join("a.png"), &shape, &data);
    // the stepped engine leaves the counts alone (they come from the stream)
    cwisim_ok(
        &dir,
        &["run", &t, "--timing", "stepped", "--cost-npy", "b.npy"],
    );
    assert_eq!(npy, read(dir.join("b.npy")));
}

#[test]
fn render_counts_the_emitted_stream() {
    let dir = scratch("cost-render");
    let scene = fig25();
    let args = [
        "render",
        &scene,
        "--trace",
        "t.cwb",
        "--stats-json",
        "s.json",
        "--cost-image",
        "r.png",
        "--cost-npy",
        "r.npy",
    ];
    cwisim_ok(&dir, &args);
    let (png, npy) = (read(dir.join("r.png")), read(dir.join("r.npy")));
    cwisim_ok(&dir, &args);
    assert_eq!(png, read(dir.join("r.png")), "byte-identical PNG");
    assert_eq!(npy, read(dir.join("r.npy")));
    let (shape, data) = counts(dir.join("r.npy"));
    assert_eq!(shape, [14, 16]);
    assert_rows_sum_to_updates(&shape, &data, &json(dir.join("s.json")));
    assert_heat_map(&dir.join("r.png"), &shape, &data);
    // the same counts from replaying the emitted trace
    cwisim_ok(&dir, &["run", "t.cwb", "--cost-npy", "t.npy"]);
    assert_eq!(npy, read(dir.join("t.npy")));
    // a scaled-up image: 16 columns drawn 16 × 16 each
    assert_eq!(cost_layout(16, 14).expect("layout").scale, 16);
}

#[test]
fn a_trace_without_refresh_has_an_empty_map_but_no_image() {
    let dir = scratch("cost-empty");
    std::fs::write(
        dir.join("n.cwt"),
        "cwisim-trace version=1 width=5 lines=2 channels=1\nEval1 0 5 0.5\n",
    )
    .expect("write");
    // a trace without Refresh is incomplete: only --keep-partial replays it
    let out = cwisim(&dir, &["run", "n.cwt", "--cost-npy", "n.npy"]);
    assert_eq!(out.status.code(), Some(2));
    let out = cwisim(
        &dir,
        &["run", "n.cwt", "--cost-npy", "n.npy", "--keep-partial"],
    );
    assert!(out.status.success(), "{}", text(&out).1);
    let (shape, data) = counts(dir.join("n.npy"));
    assert_eq!(shape, [0, 5]);
    assert!(data.is_empty());
    let out = cwisim(
        &dir,
        &["run", "n.cwt", "--cost-image", "n.png", "--keep-partial"],
    );
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("error: the trace output no scanline"),
        "{stderr}"
    );
    assert!(!dir.join("n.png").exists());
}

#[test]
fn bad_cost_outputs_exit_2_with_one_error_line() {
    let dir = scratch("cost-bad");
    std::fs::write(dir.join("t.cwt"), common::SMALL_TRACE).expect("write");
    std::fs::write(
        dir.join("bad.cwt"),
        "cwisim-trace version=1 width=4 lines=1 channels=1\nEval1 0 4 0.5\nRefresh\nEval1 3 9 0.5\n",
    )
    .expect("write");
    std::fs::copy(fig25(), dir.join("s.json")).expect("copy the scene");
    let cases: [(&[&str], &str); 7] = [
        (
            &["run", "t.cwt", "--cost-image", "c.jpg"],
            "--cost-image writes a .png file",
        ),
        (
            &["run", "t.cwt", "--cost-npy", "c.png"],
            "--cost-npy writes a .npy file",
        ),
        (
            &["run", "t.cwt", "--cost-image", "t.cwt"],
            "would overwrite the trace",
        ),
        (
            &["run", "t.cwt", "-o", "c.png", "--cost-image", "./c.png"],
            "both name",
        ),
        (
            &[
                "run",
                "bad.cwt",
                "--cost-npy",
                "c.npy",
                "--cost-image",
                "c.png",
            ],
            "error: bad.cwt:4:",
        ),
        (
            &["render", "s.json", "--cost-image", "c.bmp"],
            "--cost-image writes a .png file",
        ),
        (
            &["render", "s.json", "--cost-npy", "s.json"],
            "would overwrite the scene",
        ),
    ];
    for (args, needle) in cases {
        let out = cwisim(&dir, args);
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stdout.is_empty(), "{args:?}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        for f in ["c.png", "c.npy", "c.jpg", "c.bmp"] {
            assert!(!dir.join(f).exists(), "{args:?} wrote {f}");
        }
    }
}
