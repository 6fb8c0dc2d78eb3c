//! The budgets (`CWISIM_MAX_MEMORY`, `CWISIM_MAX_OUTPUT`, the thread cap): sizes known
//! before the work are refused before it, sizes that grow with the input are refused as
//! soon as they pass the budget, each with exit 2 and a message that says what the work
//! needs and how to raise the budget; nothing is written.

mod common;

use common::{scratch, text};
use std::path::Path;
use std::process::{Command, Output};

fn cwisim_env(dir: &Path, env: &[(&str, &str)], args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .output()
        .expect("run the cwisim binary")
}

/// A trace of `lines` one-line frames, 16 processors wide.
fn many_lines(dir: &Path, name: &str, lines: usize) {
    let mut t = String::from("cwisim-trace version=1 width=16 lines=1 channels=1\n");
    for _ in 0..lines {
        t.push_str("Eval1 0 16 0.5\nRefresh\n");
    }
    std::fs::write(dir.join(name), t).unwrap();
}

fn refused(out: &Output, needle: &str) -> String {
    let (stdout, stderr) = text(out);
    assert_eq!(out.status.code(), Some(2), "{stdout}{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains(needle), "{stderr}");
    stderr
}

#[test]
fn a_budget_that_is_not_a_size_is_refused() {
    let dir = scratch("budget-bad-var");
    let out = cwisim_env(&dir, &[("CWISIM_MAX_MEMORY", "lots")], &["machine"]);
    refused(
        &out,
        "CWISIM_MAX_MEMORY=\"lots\": unknown unit `lots`; expected a number of bytes",
    );
}

#[test]
fn an_image_known_from_the_header_is_refused_before_reading() {
    let dir = scratch("budget-header");
    // the header alone: 65536 lines × 65536 × 4 values is 128 GiB of f64
    std::fs::write(
        dir.join("huge.cwt"),
        "cwisim-trace version=1 width=65536 lines=65536 channels=4\n",
    )
    .unwrap();
    let out = cwisim_env(&dir, &[], &["run", "huge.cwt", "--npy", "h.npy"]);
    let stderr = refused(
        &out,
        "needs 128.0 GiB of memory, over the budget of 4.0 GiB",
    );
    assert!(stderr.contains("CWISIM_MAX_MEMORY"), "{stderr}");
    assert!(!dir.join("h.npy").exists());
}

#[test]
fn per_scanline_records_past_the_budget_are_refused_and_a_selection_fits() {
    let dir = scratch("budget-records");
    many_lines(&dir, "t.cwt", 5000);
    let tight = [("CWISIM_MAX_MEMORY", "100K")];
    let out = cwisim_env(&dir, &tight, &["stats", "t.cwt", "--stats-json", "s.json"]);
    refused(&out, "keeping the records of 5000 scanlines");
    assert!(!dir.join("s.json").exists());
    // the scanlines asked for are all that is kept
    let out = cwisim_env(&dir, &tight, &["stats", "t.cwt", "--lines", "0..10"]);
    assert!(out.status.success(), "{:?}", text(&out));
}

#[test]
fn an_output_past_the_budget_is_refused_and_not_written() {
    let dir = scratch("budget-output");
    many_lines(&dir, "t.cwt", 2000);
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_OUTPUT", "64K")],
        &["run", "t.cwt", "--stats-json", "s.json"],
    );
    refused(&out, "--stats-json s.json would be larger than 64.0 KiB");
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(left.len(), 1, "only the trace: {left:?}");
    // within the default budget it is written
    let out = cwisim_env(&dir, &[], &["run", "t.cwt", "--stats-json", "s.json"]);
    assert!(out.status.success(), "{:?}", text(&out));
    assert!(std::fs::metadata(dir.join("s.json")).unwrap().len() > 64 << 10);
}

#[test]
fn threads_are_capped() {
    let dir = scratch("budget-threads");
    for command in [
        &["render", "fig25"][..],
        &["tradeoff", "fig25"],
        &["fit", "fig25", "--max-error", "1/512"],
        &["refine", "--sweep", "phong-angle=5,10"],
    ] {
        let args: Vec<&str> = command
            .iter()
            .copied()
            .chain(["--threads", "1000000"])
            .collect();
        let out = cwisim_env(&dir, &[], &args);
        refused(&out, "--threads 1000000: at most");
    }
}

#[test]
fn nishita_pieces_past_the_budget_are_refused_band_by_band() {
    let dir = scratch("budget-nishita");
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_MEMORY", "8M")],
        &[
            "render",
            "teapot",
            "--renderer",
            "nishita",
            "--subscan",
            "64",
            "-o",
            "t.png",
        ],
    );
    let stderr = refused(&out, "pieces (so far, at row");
    assert!(stderr.contains("--subscan 64"), "{stderr}");
    assert!(!dir.join("t.png").exists());
}

#[test]
fn woo_chall_s_rows_with_the_image_past_the_budget_are_refused_before_any_row() {
    // 4000 × 4000 at --samples 8: a 48 MB PNG within 64 MB, but with woo-chall's rows
    // (64,000 sample columns) it is not (89 MB peak measured, drawn in 27 s, before)
    let dir = scratch("budget-woo-chall");
    let args = [
        "render",
        "still-life",
        "--renderer",
        "woo-chall",
        "--size",
        "4000x4000",
        "--samples",
        "8",
        "--threads",
        "2",
        "-o",
        "w.png",
    ];
    let out = cwisim_env(&dir, &[("CWISIM_MAX_MEMORY", "64M")], &args);
    let stderr = refused(&out, "woo-chall's rows of 4000 pixels on 2 thread(s)");
    assert!(stderr.contains("the image of 4000 scanline(s)"), "{stderr}");
    assert!(!dir.join("w.png").exists());
    // without an image, the rows alone are checked (by the renderer, for every caller)
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_MEMORY", "64M")],
        &[
            &args[..6],
            &[
                "--samples",
                "32",
                "--threads",
                "2",
                "--stats-json",
                "s.json",
            ],
        ]
        .concat(),
    );
    let stderr = refused(&out, "woo-chall's rows of 4000 pixels on 2 thread(s)");
    assert!(!stderr.contains("the image"), "{stderr}");
    assert!(!dir.join("s.json").exists());
}

#[test]
fn a_waveform_past_the_budget_is_refused() {
    let dir = scratch("budget-vcd");
    std::fs::write(
        dir.join("wide.cwt"),
        "cwisim-trace version=1 width=4096 lines=1 channels=1\nEval2 0 4096 0.25 0.0001\nRefresh\n",
    )
    .unwrap();
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_MEMORY", "64K")],
        &[
            "vcd", "wide.cwt", "--line", "0", "--x", "0..4096", "-o", "w.vcd",
        ],
    );
    refused(&out, "the waveform of scanline 0 over processors 0..=4095");
    assert!(!dir.join("w.vcd").exists());
    // within the default budget it is written
    let out = cwisim_env(
        &dir,
        &[],
        &[
            "vcd", "wide.cwt", "--line", "0", "--x", "0..4096", "-o", "w.vcd",
        ],
    );
    assert!(out.status.success(), "{:?}", text(&out));
}

#[test]
fn a_shadow_pass_past_the_budget_is_refused_before_any_light_s_view() {
    let dir = scratch("budget-shadows");
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_MEMORY", "4M")],
        &["render", "teapot", "--shadows", "on", "-o", "t.png"],
    );
    refused(
        &out,
        "the shadow pass (4032 triangles seen from 1 light(s))",
    );
    assert!(!dir.join("t.png").exists());
    // without shadows it fits
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_MEMORY", "4M")],
        &["render", "teapot", "-o", "t.png"],
    );
    assert!(out.status.success(), "{:?}", text(&out));
}

#[test]
fn every_command_s_outputs_are_held_to_the_output_budget() {
    // each output below is larger than 2 KiB: refused, exit 2, the file not made (nor an
    // old one replaced), the budget named
    let dir = scratch("budgets-output-every-command");
    let trace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../traces/visibility.cwt");
    let t = trace.to_str().unwrap();
    std::fs::write(dir.join("old.txt"), b"old").unwrap();
    // a trace of 8 KiB or so, outside the directory watched
    let elsewhere = scratch("budgets-output-every-command-input");
    many_lines(&elsewhere, "long.cwt", 400);
    let long = elsewhere.join("long.cwt");
    let long = long.to_str().unwrap();
    let cases: [(&str, &[&str]); 10] = [
        (
            "render --stats-json",
            &["render", "fig25", "--stats-json", "out.json"],
        ),
        (
            "render --trace",
            &[
                "render",
                "fig25",
                "--trace",
                "out.cwt",
                "--npy",
                "/dev/null",
            ],
        ),
        (
            "render -o",
            &["render", "pot", "--size", "200x200", "-o", "out.png"],
        ),
        (
            "stats --stats-json",
            &["stats", "fig25", "--stats-json", "out.json"],
        ),
        ("emit", &["emit", "fig25", "-o", "out.cwt"]),
        ("inspect", &["inspect", t, "-o", "out.html"]),
        ("vcd", &["vcd", t, "--line", "0", "-o", "out.vcd"]),
        (
            "rtl",
            &[
                "rtl",
                "--numeric",
                "fixed:I=2.15,dI=1.16,ddI=1.16",
                "-o",
                "out.v",
            ],
        ),
        (
            "tradeoff --csv",
            &[
                "tradeoff",
                "fig25",
                "--renderers",
                "vanrij",
                "--repeat",
                "1",
                "--csv",
                "out.csv",
            ],
        ),
        ("convert", &["convert", long, "out.jsonl"]),
    ];
    for (what, args) in cases {
        let out = cwisim_env(&dir, &[("CWISIM_MAX_OUTPUT", "2K")], args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
        assert!(
            stderr.contains("would be larger than 2.0 KiB") && stderr.contains("CWISIM_MAX_OUTPUT"),
            "{what}: {stderr}"
        );
        let left: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n != "old.txt")
            .collect();
        assert!(left.is_empty(), "{what} left {left:?}");
        // and within a budget that holds it, it is written
        let out = cwisim_env(&dir, &[("CWISIM_MAX_OUTPUT", "64M")], args);
        assert_eq!(out.status.code(), Some(0), "{what}: {:?}", text(&out));
        for e in std::fs::read_dir(&dir).unwrap() {
            let e = e.unwrap();
            if e.file_name() != "old.txt" {
                std::fs::remove_file(e.path()).unwrap();
            }
        }
    }
}

#[test]
fn the_memory_budget_holds_tradeoff_fit_refine_and_inspect() {
    // each holds whole images (8 bytes a value): past the budget it is refused before the
    // first is made, naming what; within it, it runs
    let dir = scratch("budgets-memory-studies");
    // (refine's pot is projected first: its 928 triangles' visibility, 620 KiB, within
    // 1 MiB, its two frames at 400 × 400 not)
    let cases: [(&str, &str, &str, &[&str]); 4] = [
        (
            "tradeoff",
            "tradeoff's images",
            "512K",
            &[
                "tradeoff",
                "fig25",
                "--size",
                "400x400",
                "--renderers",
                "vanrij",
                "--numeric",
                "f64",
                "--repeat",
                "1",
            ],
        ),
        (
            "fit",
            "fit's images",
            "512K",
            &[
                "fit",
                "fig25",
                "--size",
                "400x400",
                "--threads",
                "1",
                "--max-error",
                "1/64",
            ],
        ),
        (
            "refine",
            "refine's 2 frame(s) of 400×400×1 values",
            "1M",
            &[
                "refine",
                "pot",
                "--size",
                "400x400",
                "--phases",
                "flat,gouraud",
                "--csv",
                "r.csv",
            ],
        ),
        (
            "inspect",
            "the page's images",
            "512K",
            &["inspect", "fig25", "--size", "400x400", "-o", "p.html"],
        ),
    ];
    for (command, says, budget, args) in cases {
        let out = cwisim_env(&dir, &[("CWISIM_MAX_MEMORY", budget)], args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{command}: {stderr}");
        assert!(
            stderr.contains(says)
                && stderr.contains(&format!(
                    "over the budget of {}",
                    if budget == "1M" {
                        "1.0 MiB"
                    } else {
                        "512.0 KiB"
                    }
                )),
            "{command}: {stderr}"
        );
        let out = cwisim_env(&dir, &[("CWISIM_MAX_MEMORY", "256M")], args);
        assert_eq!(out.status.code(), Some(0), "{command}: {:?}", text(&out));
    }
}

/// A scene (or an event script) read from a FIFO, whose size is not known before it is
/// read, is read up to the memory budget and refused past it, not held whole.
#[test]
fn a_stream_past_the_budget_is_refused_as_it_is_read() {
    use std::io::Write;
    let dir = scratch("budget-fifo");
    let fifo = dir.join("scene.json");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo");
    assert!(made.success());
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut f = std::fs::File::options()
                .write(true)
                .open(&fifo)
                .expect("open the FIFO");
            // 1 MB of spaces: the reader stops at its 64 KB budget and closes
            let chunk = [b' '; 4096];
            for _ in 0..256 {
                if f.write_all(&chunk).is_err() {
                    break;
                }
            }
        })
    };
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_MEMORY", "64K")],
        &["render", "scene.json", "-o", "x.png"],
    );
    writer.join().expect("writer");
    refused(&out, "reading the scene file");
    assert!(!dir.join("x.png").exists());
}

/// `refine --events`: the session's runs keep their frames, checked against the budget
/// once the first run's size is known, before the others are drawn.
#[test]
fn a_session_past_the_budget_is_refused_before_its_later_runs() {
    let dir = scratch("budget-session");
    let script = common::repo().join("crates/study/fixtures/pot-session.json");
    let script = script.to_str().unwrap();
    let args = [
        "refine", "pot", "--size", "200x200", "--events", script, "--plot", "s.png",
    ];
    let out = cwisim_env(&dir, &[("CWISIM_MAX_MEMORY", "2M")], &args);
    refused(&out, "a session of 4 refinements, each keeping its frames");
    assert!(!dir.join("s.png").exists());
    let out = cwisim_env(&dir, &[("CWISIM_MAX_MEMORY", "64M")], &args);
    assert!(out.status.success(), "{:?}", text(&out));
}

#[test]
fn a_mesh_whose_visibility_passes_the_budget_is_refused_before_it_is_projected() {
    let dir = scratch("budget-visibility");
    // the teapot at 64 quads a patch: 261,632 triangles, 118.8 MiB as exact visibility
    // counts them on one thread without their surfaces, more with them (Phong keeps them)
    let draw = |budget: &str, extra: &[&str]| {
        let mut args = vec!["render", "teapot", "--tessellate", "64", "--threads", "1"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", "t.png"]);
        cwisim_env(&dir, &[("CWISIM_MAX_MEMORY", budget)], &args)
    };
    let stderr = refused(
        &draw("100M", &[]),
        "exact visibility of the scene's 261632 triangles needs 118.8 MiB",
    );
    assert!(stderr.contains("CWISIM_MAX_MEMORY"), "{stderr}");
    // Phong keeps the surfaces (368 bytes a triangle) and the mesh (43.1 MiB) all along
    refused(
        &draw("100M", &["--shading", "phong"]),
        "exact visibility of the scene's 261632 triangles needs 209.8 MiB",
    );
    // front to back, the triangles (176 bytes each, 43.9 MiB) and the mesh they are
    // projected from
    refused(
        &draw("80M", &["--visibility", "eval0"]),
        "projecting the scene's 261632 triangles needs 87.0 MiB",
    );
    // the mesh itself, before a patch is tessellated: 224 bytes a triangle
    refused(
        &draw("40M", &["--visibility", "eval0"]),
        "meshes[0].bezier.tessellate: tessellating the 32 patches 64 × 64 (262144 triangles) needs 56.0 MiB",
    );
    assert!(!dir.join("t.png").exists());
}

#[test]
fn renderers_that_project_their_own_triangles_are_refused_before_they_project_them() {
    let dir = scratch("budget-projection");
    // the teapot at 64 quads a patch: 261,632 triangles and a mesh of 43.1 MiB; each
    // renderer's own figure a triangle (woo-chall 1,100 bytes, sbuffer 800, bsp 2,800)
    for (renderer, needs) in [
        ("woo-chall", "317.6 MiB"),
        ("sbuffer", "242.7 MiB"),
        ("bsp", "741.7 MiB"),
    ] {
        let out = cwisim_env(
            &dir,
            &[("CWISIM_MAX_MEMORY", "200M")],
            &[
                "render",
                "teapot",
                "--tessellate",
                "64",
                "--threads",
                "1",
                "--renderer",
                renderer,
                "-o",
                "t.png",
            ],
        );
        refused(
            &out,
            &format!(
                "projecting the scene's 261632 triangles for {renderer} needs {needs} of memory"
            ),
        );
    }
    assert!(!dir.join("t.png").exists());
}

#[test]
fn a_bsp_tree_whose_splits_pass_the_budget_is_stopped_as_it_grows() {
    let dir = scratch("budget-bsp-splits");
    // 150 triangles across one another at random depths (a fixed sequence): their planes
    // split them into about 13,000 pieces, far past the figure a triangle checked before
    // the tree, which a screen scene is not checked with anyway
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let polygons: Vec<serde_json::Value> = (0..150)
        .map(|_| {
            let vertices: Vec<[f64; 2]> = (0..3).map(|_| [next() * 100.0, next() * 100.0]).collect();
            let depth: Vec<f64> = (0..3).map(|_| 1.0 + next() * 9.0).collect();
            serde_json::json!({ "vertices": vertices, "intensity": [[0.5], [0.5], [0.5]], "depth": depth })
        })
        .collect();
    let scene = serde_json::json!({
        "kind": "screen", "width": 100, "height": 100, "channels": 1, "polygons": polygons
    });
    std::fs::write(dir.join("crossing.json"), scene.to_string()).unwrap();
    let draw = |budget: &str| {
        cwisim_env(
            &dir,
            &[("CWISIM_MAX_MEMORY", budget)],
            &[
                "render",
                "crossing.json",
                "--renderer",
                "bsp",
                "--threads",
                "1",
                "-o",
                "c.png",
            ],
        )
    };
    refused(
        &draw("1M"),
        "bsp's tree of the scene's 150 polygons passes the memory budget of 1.0 MiB: its splits had made 929 pieces",
    );
    assert!(!dir.join("c.png").exists());
    let out = draw("64M");
    assert!(out.status.success(), "{:?}", text(&out));
    assert!(dir.join("c.png").exists());
}
