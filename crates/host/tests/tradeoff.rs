//! `cwisim tradeoff` and `cwisim fit` through the real binary.

mod common;

use common::{cwisim, cwisim_ok, patch_scene, scratch, text};
use cwisim_scene::{parse_scene, Scene};
use cwisim_ypipe::exact::scene_box_filtered;
use std::path::Path;

fn npy(path: &Path) -> Vec<f64> {
    let bytes = std::fs::read(path).expect("npy written");
    npyz::NpyFile::new(&bytes[..])
        .expect("valid npy")
        .into_vec::<f64>()
        .expect("f64 data")
}

struct CsvRow {
    fields: Vec<String>,
}

impl CsvRow {
    fn get(&self, header: &[String], name: &str) -> String {
        let k = header.iter().position(|h| h == name).expect(name);
        self.fields[k].trim_matches('"').to_string()
    }
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<CsvRow>) {
    let text = std::fs::read_to_string(path).expect("csv");
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            // the numeric format is quoted and holds commas
            let mut fields = Vec::new();
            let mut cur = String::new();
            let mut quoted = false;
            for c in l.chars() {
                match c {
                    '"' => quoted = !quoted,
                    ',' if !quoted => fields.push(std::mem::take(&mut cur)),
                    _ => cur.push(c),
                }
            }
            fields.push(cur);
            CsvRow { fields }
        })
        .collect();
    (header, rows)
}

#[test]
fn tradeoff_measures_against_the_exact_image_and_marks_the_pareto_front() {
    let dir = scratch("tradeoff");
    let out = cwisim_ok(
        &dir,
        &[
            "tradeoff",
            "fig25",
            "--repeat",
            "1",
            "--numeric",
            "f64",
            "--numeric",
            "f32",
            "--numeric",
            "fixed:I=2.6,dI=2.6,ddI=2.6,overflow=wrap",
            "--csv",
            "t.csv",
            "--plot",
            "t.png",
        ],
    );
    assert!(out.contains("pareto"), "{out}");
    let (header, rows) = read_csv(&dir.join("t.csv"));
    // a screen scene: vanrij's (shading × aa, and box-centre with Gouraud) × formats, then
    // each supersampling renderer's (woo-chall, sbuffer, bsp) shading × samples × formats
    assert_eq!(rows.len(), (2 * 2 + 1) * 3 + 3 * (2 * 4 * 3));
    for supersampled in ["woo-chall", "sbuffer", "bsp"] {
        assert_eq!(
            rows.iter()
                .filter(|r| r.get(&header, "renderer") == supersampled)
                .count(),
            2 * 4 * 3,
            "{supersampled}"
        );
    }
    // the exact box filter and the report's: the same instructions and cycles, errors of
    // rounding against the report's approximation
    let gouraud_f64 = |aa: &str| {
        rows.iter()
            .find(|r| {
                r.get(&header, "renderer") == "vanrij"
                    && r.get(&header, "shading") == "gouraud"
                    && r.get(&header, "aa") == aa
                    && r.get(&header, "numeric") == "f64"
            })
            .unwrap_or_else(|| panic!("the Gouraud {aa} f64 row"))
    };
    let (exact_row, centre_row) = (gouraud_f64("box"), gouraud_f64("box-centre"));
    for column in ["instructions", "busy_cycles"] {
        assert_eq!(
            exact_row.get(&header, column),
            centre_row.get(&header, column)
        );
    }
    let error = |r: &CsvRow| -> f64 { r.get(&header, "max_error").parse().unwrap() };
    assert!(error(exact_row) < 1e-9, "{}", error(exact_row));
    assert!(error(centre_row) > 1e-2, "{}", error(centre_row));
    // the f64, Gouraud, box-filter row against an independent computation of the same
    // error: the array's image (render --npy) against the exact box filter
    cwisim_ok(&dir, &["render", "fig25", "-q", "--npy", "f.npy"]);
    let image = npy(&dir.join("f.npy"));
    let text = cwisim_ok(&dir, &["scenes", "fig25"]);
    let Scene::Screen(scene) = parse_scene(&text).unwrap();
    let exact = scene_box_filtered(&scene);
    let max = image
        .iter()
        .zip(&exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let row = rows
        .iter()
        .find(|r| {
            r.get(&header, "renderer") == "vanrij"
                && r.get(&header, "shading") == "gouraud"
                && r.get(&header, "aa") == "box"
                && r.get(&header, "numeric") == "f64"
        })
        .expect("the reference row");
    let reported: f64 = row.get(&header, "max_error").parse().unwrap();
    assert!((reported - max).abs() < 1e-15, "{reported} vs {max}");
    // the Pareto marks: exactly the undominated rows in (cycles, bits, RMS)
    let pts: Vec<(u64, u64, f64, bool)> = rows
        .iter()
        .map(|r| {
            (
                r.get(&header, "busy_cycles").parse().unwrap(),
                r.get(&header, "register_bits").parse().unwrap(),
                r.get(&header, "rms_error").parse().unwrap(),
                r.get(&header, "pareto") == "true",
            )
        })
        .collect();
    for &(c, b, e, p) in &pts {
        let dominated = pts
            .iter()
            .any(|&(c2, b2, e2, _)| c2 <= c && b2 <= b && e2 <= e && (c2 < c || b2 < b || e2 < e));
        assert_eq!(p, !dominated, "({c}, {b}, {e})");
    }
    assert!(pts.iter().any(|p| p.3));
    let plot = image::open(dir.join("t.png")).expect("plot");
    assert_eq!((plot.width(), plot.height()), (1100, 700));
}

#[test]
fn fit_finds_formats_that_hold_and_cannot_lose_a_bit() {
    let dir = scratch("fit");
    let out = cwisim_ok(&dir, &["fit", "fig25", "--max-error", "1/512"]);
    let format = out
        .lines()
        .find_map(|l| l.strip_prefix("registers"))
        .expect("a format")
        .trim()
        .to_string();
    // the format, used by render, stays within the budget of the f64 array
    cwisim_ok(&dir, &["render", "fig25", "-q", "--npy", "f64.npy"]);
    cwisim_ok(
        &dir,
        &[
            "render",
            "fig25",
            "-q",
            "--npy",
            "fx.npy",
            "--numeric",
            &format,
        ],
    );
    let (a, b) = (npy(&dir.join("f64.npy")), npy(&dir.join("fx.npy")));
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1.0 / 512.0, "{format}: {worst}");
    assert!(worst > 0.0, "a narrow format is not exact");
    // and no register can lose a fraction bit
    let mut checked = 0;
    for line in out.lines().filter(|l| l.contains("one fraction bit fewer")) {
        let cost = line.rsplit("max error ").next().unwrap().trim();
        if cost == "-" {
            continue;
        }
        if cost != "overflow" {
            let e: f64 = cost.parse().unwrap();
            assert!(e > 1.0 / 512.0, "{line}");
        }
        checked += 1;
    }
    assert!(checked >= 3, "{out}");
    let bad = cwisim(&dir, &["fit", "fig25", "--max-error", "0"]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn a_renderer_that_would_repeat_another_is_skipped_saying_so_and_rows_stream() {
    let dir = scratch("tradeoff-skip");
    let out = cwisim_ok(
        &dir,
        &[
            "tradeoff",
            "fig25",
            "--repeat",
            "1",
            "--numeric",
            "f64",
            "--renderers",
            "vanrij,nishita",
            "--csv",
            "t.csv",
        ],
    );
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(
        lines[0],
        "skipped nishita: the scene has no Bézier patches, so it would draw exactly as vanrij"
    );
    assert!(lines[1].starts_with("renderer "), "{out}");
    let (header, rows) = read_csv(&dir.join("t.csv"));
    assert!(rows.iter().all(|r| r.get(&header, "renderer") == "vanrij"));
    // the streamed rows, then the Pareto front again, then what was written
    assert!(out.contains(
        "Pareto front (no other setting has fewer busy cycles, register bits and RMS error all at once): "
    ));
    assert_eq!(lines.last().copied(), Some("wrote t.csv"), "{out}");
    let streamed = lines[2..].iter().take_while(|l| !l.is_empty()).count();
    assert_eq!(streamed, rows.len(), "{out}");
}

/// `text` with the CSV's column `host_ms`, or the table's column headed `host ms`,
/// taken out: the host times, the one thing that differs from run to run.
fn without_host_times(text: &str, csv: bool) -> String {
    let mut out = String::new();
    let mut column = None;
    for line in text.lines() {
        let fields: Vec<&str> = if csv {
            line.split(',').collect()
        } else {
            line.split_whitespace().collect()
        };
        if column.is_none() {
            column = if csv {
                fields.iter().position(|f| *f == "host_ms")
            } else {
                // `host ms`: two words of the header, 14th of a row
                (fields.first() == Some(&"renderer")).then_some(13)
            };
        }
        let keep: Vec<&str> = fields
            .iter()
            .enumerate()
            .filter(|&(k, _)| {
                let row = csv || fields.len() >= 17;
                !(row && Some(k) == column)
            })
            .map(|(_, f)| *f)
            .collect();
        out.push_str(&keep.join(" "));
        out.push('\n');
    }
    out
}

#[test]
fn tradeoff_is_the_same_at_any_thread_count_but_for_host_times() {
    let dir = scratch("tradeoff-threads");
    let run = |threads: &str| {
        let csv = format!("t{threads}.csv");
        let out = cwisim_ok(
            &dir,
            &[
                "tradeoff",
                "pot",
                "--size",
                "48x40",
                "--repeat",
                "2",
                "--numeric",
                "f64;f32",
                "--renderers",
                "vanrij,woo-chall",
                "--threads",
                threads,
                "--csv",
                &csv,
            ],
        );
        let text = std::fs::read_to_string(dir.join(&csv)).unwrap();
        (
            without_host_times(&out.replace(&csv, "t.csv"), false),
            without_host_times(&text, true),
        )
    };
    let one = run("1");
    assert!(one.1.lines().count() > 20, "{}", one.1);
    assert!(one.0.contains("Pareto front"), "{}", one.0);
    for threads in ["2", "3", "0"] {
        assert_eq!(run(threads), one, "--threads {threads}");
    }
}

#[test]
fn fit_is_the_same_at_any_thread_count() {
    let dir = scratch("fit-threads");
    let run = |threads: &str| {
        cwisim_ok(
            &dir,
            &[
                "fit",
                "pot",
                "--size",
                "64x48",
                "--max-error",
                "1e-4",
                "--threads",
                threads,
            ],
        )
    };
    let one = run("1");
    assert!(one.contains("replays"), "{one}");
    for threads in ["2", "3", "0"] {
        assert_eq!(run(threads), one, "--threads {threads}");
    }
}

/// The shadows axis: each renderer that draws shadows measured with them on and off, each
/// row against the exact image with the same shadows (so the exact settings stay exact);
/// a value that could not be drawn is refused.
#[test]
fn the_shadows_axis_measures_each_side_against_its_own_exact_image() {
    let dir = scratch("tradeoff-shadows");
    cwisim_ok(
        &dir,
        &[
            "tradeoff",
            "pot",
            "--size",
            "40x40",
            "--renderers",
            "vanrij,sbuffer",
            "--shadows",
            "on,off",
            "--repeat",
            "1",
            "--numeric",
            "f64",
            "--csv",
            "t.csv",
        ],
    );
    let (header, rows) = read_csv(&dir.join("t.csv"));
    for renderer in ["vanrij", "sbuffer"] {
        let of = |on: &str| {
            rows.iter()
                .filter(|r| {
                    r.get(&header, "renderer") == renderer && r.get(&header, "shadows") == on
                })
                .count()
        };
        assert!(of("on") > 0 && of("on") == of("off"), "{renderer}");
    }
    // vanrij's exact box filter is exact with either
    for on in ["on", "off"] {
        let exact = rows
            .iter()
            .find(|r| {
                r.get(&header, "renderer") == "vanrij"
                    && r.get(&header, "shading") == "gouraud"
                    && r.get(&header, "aa") == "box"
                    && r.get(&header, "visibility") == "exact"
                    && r.get(&header, "shadows") == on
            })
            .unwrap();
        let e: f64 = exact.get(&header, "max_error").parse().unwrap();
        assert!(e < 1e-9, "shadows {on}: {e}");
    }
    // the shadows show: the same setting differs between the two
    let instructions = |on: &str| {
        rows.iter()
            .find(|r| {
                r.get(&header, "renderer") == "vanrij"
                    && r.get(&header, "shading") == "flat"
                    && r.get(&header, "aa") == "box"
                    && r.get(&header, "visibility") == "exact"
                    && r.get(&header, "shadows") == on
            })
            .unwrap()
            .get(&header, "instructions")
    };
    assert_ne!(instructions("on"), instructions("off"));
    for (args, says) in [
        (vec!["fig25", "--shadows", "on"], "the scene has no lights"),
        (
            vec!["pot", "--shadows", "on,on"],
            "each of on and off at most once",
        ),
    ] {
        let mut all = vec!["tradeoff"];
        all.extend(&args);
        let out = cwisim(&dir, &all);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
}

/// `--shard I/N` parts joined by `--merge` are the sweep in one go, row for row (host
/// times aside); a part alone marks no Pareto front.
#[test]
fn shards_joined_by_merge_are_the_whole_sweep() {
    let dir = scratch("tradeoff-shards");
    let grid = [
        "fig25",
        "--renderers",
        "vanrij,sbuffer",
        "--numeric",
        "f64;f32",
        "--repeat",
        "1",
    ];
    let run = |extra: &[&str]| cwisim_ok(&dir, &[&["tradeoff"][..], &grid, extra].concat());
    run(&["--csv", "whole.csv"]);
    for k in 0..3 {
        let part = format!("part-{k}.csv");
        let out = run(&["--shard", &format!("{k}/3"), "--csv", &part]);
        assert!(out.contains(&format!("part {k} of 3")), "{out}");
        let (header, rows) = read_csv(&dir.join(&part));
        assert!(rows.iter().all(|r| r.get(&header, "pareto") == "false"));
    }
    let out = cwisim_ok(
        &dir,
        &[
            "tradeoff",
            "--merge",
            "part-0.csv",
            "part-1.csv",
            "part-2.csv",
            "--csv",
            "merged.csv",
        ],
    );
    assert!(out.contains("3 parts joined"), "{out}");
    let (h1, whole) = read_csv(&dir.join("whole.csv"));
    let (h2, merged) = read_csv(&dir.join("merged.csv"));
    assert_eq!(h1, h2);
    assert_eq!(whole.len(), merged.len());
    for (a, b) in whole.iter().zip(&merged) {
        for name in h1.iter().filter(|n| *n != "host_ms") {
            assert_eq!(a.get(&h1, name), b.get(&h2, name), "{name}");
        }
    }
    // a file that is not a part is refused, located
    std::fs::write(dir.join("other.csv"), "x,y\n1,2\n").unwrap();
    let out = cwisim(&dir, &["tradeoff", "--merge", "part-0.csv", "other.csv"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("other.csv:1: not a tradeoff CSV"),
        "{stderr}"
    );
}

#[test]
fn merge_is_budgeted_before_any_part_is_read_and_refuses_what_is_not_a_file() {
    let dir = scratch("tradeoff-merge-budget");
    std::fs::write(dir.join("big.csv"), "x,y\n".repeat(1000)).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args(["tradeoff", "--merge", "big.csv", "--csv", "out.csv"])
        .current_dir(&dir)
        .env("CWISIM_MAX_MEMORY", "8000")
        .output()
        .unwrap();
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("merging 1 part(s) of 4000 bytes"),
        "{stderr}"
    );
    assert!(!dir.join("out.csv").exists());
    // within the budget, the part is read, and found not to be a tradeoff CSV
    let out = cwisim(
        &dir,
        &["tradeoff", "--merge", "big.csv", "--csv", "out.csv"],
    );
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(
            "big.csv:1: not a tradeoff CSV of this cwisim: column 1 is `x`, expected `renderer`"
        ),
        "{stderr}"
    );
    let out = cwisim(&dir, &["tradeoff", "--merge", "/dev/null"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("/dev/null: not a regular file"), "{stderr}");
}

#[test]
fn the_a_buffer_s_mask_is_an_axis_its_rows_parse_back_and_bad_modes_are_refused() {
    let dir = scratch("tradeoff-abuffer");
    let out = cwisim_ok(
        &dir,
        &[
            "tradeoff",
            "pot",
            "--size",
            "32x32",
            "--renderers",
            "sbuffer",
            "--sbuffer",
            "host,abuffer",
            "--numeric",
            "f64",
            "--repeat",
            "1",
            "--csv",
            "ab.csv",
        ],
    );
    let (header, rows) = read_csv(&dir.join("ab.csv"));
    // per shading, the samples axis once for each mode
    let abuffer: Vec<&CsvRow> = rows
        .iter()
        .filter(|r| r.get(&header, "aa") == "abuffer")
        .collect();
    assert_eq!(abuffer.len(), 12, "{out}");
    assert_eq!(rows.len(), 24, "{out}");
    // its Gouraud error falls from a 2×2 to an 8×8 mask
    let rms = |l: &str| -> f64 {
        abuffer
            .iter()
            .find(|r| r.get(&header, "shading") == "gouraud" && r.get(&header, "samples") == l)
            .unwrap()
            .get(&header, "rms_error")
            .parse()
            .unwrap()
    };
    assert!(rms("8") < rms("2"), "{out}");
    // the CSV is read back (a sweep joined from one part)
    let merged = cwisim_ok(&dir, &["tradeoff", "--merge", "ab.csv"]);
    assert!(merged.contains("abuffer"), "{merged}");
    for (args, says) in [
        (&["--sbuffer", "transparent"][..], "--sbuffer transparent"),
        (
            &["--sbuffer", "abuffer", "--renderers", "vanrij"][..],
            "leaves sbuffer out",
        ),
        (&["--sbuffer", "abuffer,abuffer"][..], "at most once"),
    ] {
        let out = cwisim(
            &dir,
            &[&["tradeoff", "pot", "--size", "16x16"][..], args].concat(),
        );
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(says), "{stderr}");
    }
}

#[test]
fn nishita_s_normal_angle_is_an_axis_its_rows_parse_back_and_bad_angles_are_refused() {
    let dir = scratch("tradeoff-normal-angle");
    std::fs::write(dir.join("patches.json"), patch_scene()).unwrap();
    let out = cwisim_ok(
        &dir,
        &[
            "tradeoff",
            "patches.json",
            "--renderers",
            "nishita",
            "--normal-angle",
            "off,10",
            "--numeric",
            "f64",
            "--repeat",
            "1",
            "--csv",
            "na.csv",
        ],
    );
    let (header, rows) = read_csv(&dir.join("na.csv"));
    // the root tolerances × the angles × Phong and Gouraud
    assert_eq!(rows.len(), 12, "{out}");
    let angles: Vec<String> = rows
        .iter()
        .map(|r| r.get(&header, "normal_angle"))
        .collect();
    assert_eq!(angles.iter().filter(|a| a.is_empty()).count(), 6, "{out}");
    assert_eq!(angles.iter().filter(|a| *a == "10").count(), 6, "{out}");
    // the table shows the angle beside the tolerance, the columns after it lined up
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("nishita")).collect();
    assert!(lines.iter().any(|l| l.contains("1e-5 10°")), "{out}");
    let shading_at = |l: &str| {
        ["phong", "gouraud"]
            .iter()
            .filter_map(|s| l.find(s).map(|b| l[..b].chars().count()))
            .min()
    };
    assert!(
        lines.iter().all(|l| shading_at(l) == shading_at(lines[0])),
        "{out}"
    );
    // the test divides further: more pieces where it is on, the same error or less
    let pieces = |k: usize| -> u64 {
        rows[k]
            .get(&header, "counter_piece_triangles")
            .parse()
            .unwrap()
    };
    let (off, on) = (
        rows.iter()
            .position(|r| r.get(&header, "normal_angle").is_empty())
            .unwrap(),
        rows.iter()
            .position(|r| r.get(&header, "normal_angle") == "10")
            .unwrap(),
    );
    assert!(pieces(on) > pieces(off), "{out}");
    // the CSV is read back (a sweep joined from one part), the angle in the table
    let merged = cwisim_ok(&dir, &["tradeoff", "--merge", "na.csv"]);
    assert!(merged.contains("1e-3 10°"), "{merged}");
    for (args, says) in [
        (
            &["--normal-angle", "sharp"][..],
            "expected a number of degrees or off",
        ),
        (
            &["--normal-angle", "0.1"][..],
            "--normal-angle must be between",
        ),
        (&["--normal-angle", "10,10"][..], "at most once"),
        (
            &["--normal-angle", "10", "--renderers", "vanrij"][..],
            "leaves nishita out",
        ),
    ] {
        let out = cwisim(&dir, &[&["tradeoff", "patches.json"][..], args].concat());
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(says), "{stderr}");
    }
    let out = cwisim(
        &dir,
        &["tradeoff", "pot", "--size", "16x16", "--normal-angle", "10"],
    );
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("the scene has none"), "{stderr}");
    // `render --normal-angle off` is the test left off, as the default
    for (name, extra) in [
        ("default.npy", &[][..]),
        ("off.npy", &["--normal-angle", "off"][..]),
    ] {
        cwisim_ok(
            &dir,
            &[
                &[
                    "render",
                    "patches.json",
                    "--renderer",
                    "nishita",
                    "-q",
                    "--npy",
                    name,
                ][..],
                extra,
            ]
            .concat(),
        );
    }
    assert_eq!(
        std::fs::read(dir.join("default.npy")).unwrap(),
        std::fs::read(dir.join("off.npy")).unwrap()
    );
}
