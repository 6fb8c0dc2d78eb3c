//! `cwisim refine`: the phase table, the files it writes, sweeps, and clear refusals of
//! bad input (exit 2, the reason on the first line, nothing written).

mod common;

use common::{cwisim, cwisim_ok, read, scratch, text};

#[test]
fn refine_prints_the_phase_table_and_writes_its_files() {
    let dir = scratch("refine-pot");
    let out = cwisim_ok(
        &dir,
        &[
            "refine",
            "pot",
            "--size",
            "96x96",
            "--plot",
            "q.png",
            "--csv",
            "q.csv",
            "--trace",
            "t.cwb",
            "--frames-png",
            "frames",
            "--cost-image-dir",
            "costs",
        ],
    );
    let header = "phase    pixels  instructions  regenerated";
    assert!(out.contains(header), "{out}");
    for column in [
        "busy",
        "cumulative",
        "worst line",
        "late",
        "RMS",
        "PSNR dB",
        "display list",
    ] {
        assert!(
            out.lines()
                .any(|l| l.starts_with("phase ") && l.contains(column)),
            "{column}: {out}"
        );
    }
    for phase in ["flat", "gouraud", "phong", "aa"] {
        // a row per phase in the refined sequence and the naive one
        assert_eq!(
            out.lines()
                .filter(|l| l.starts_with(&format!("{phase} ")))
                .count(),
            2,
            "{phase}: {out}"
        );
    }
    assert!(
        out.contains("naive: every phase's renderer in full"),
        "{out}"
    );
    assert!(out.contains("× FB)"), "{out}");
    // the lower panel's scanline axis has its numbers: ink just under the axis at its
    // left end (the "0"), where only the axis title, centred, was before
    let plot = image::open(dir.join("q.png")).unwrap().to_rgb8();
    let (left, axis) = (90, plot.height() - 60);
    let ink = (axis + 6..axis + 20)
        .flat_map(|y| (left - 6..left + 6).map(move |x| (x, y)))
        .filter(|&(x, y)| plot.get_pixel(x, y).0.iter().all(|&c| c < 128))
        .count();
    assert!(ink > 5, "no tick label under the scanline axis");
    for name in [
        "phase-1-flat",
        "phase-2-gouraud",
        "phase-3-phong",
        "phase-4-aa",
    ] {
        assert!(
            dir.join("frames").join(format!("{name}.png")).exists(),
            "{name}"
        );
        assert!(
            dir.join("costs").join(format!("{name}-cost.png")).exists(),
            "{name}"
        );
    }
    assert!(read(dir.join("q.png")).starts_with(b"\x89PNG"));
    let csv = String::from_utf8(read(dir.join("q.csv"))).unwrap();
    assert!(csv.starts_with("scene,sweep,sequence,phase,"), "{csv}");
    assert_eq!(csv.lines().count(), 1 + 8, "{csv}");
    // the trace replays: four frames of 96 scanlines
    let stats = cwisim_ok(&dir, &["stats", "t.cwb"]);
    assert!(stats.contains("384 of 384 scanline(s)"), "{stats}");
}

#[test]
fn a_sweep_prints_one_table_per_value() {
    let dir = scratch("refine-sweep");
    let out = cwisim_ok(
        &dir,
        &[
            "refine",
            "--size",
            "64x64",
            "--phases",
            "flat,phong",
            "--sweep",
            "phong-angle=5,none",
            "--csv",
            "s.csv",
        ],
    );
    assert!(out.contains("pot (--phong-angle 5)"), "{out}");
    assert!(out.contains("pot (--phong-angle none)"), "{out}");
    assert!(!out.contains("\ngouraud "), "{out}");
    let csv = String::from_utf8(read(dir.join("s.csv"))).unwrap();
    // two runs of two phases, the first with its naive sequence
    assert_eq!(csv.lines().count(), 1 + 2 + 2 + 2, "{csv}");
    // the paper's first phases, before any polygon; with no output named, the plot
    // goes to SCENE-refine.png
    assert!(!dir.join("pot-refine.png").exists());
    let out = cwisim_ok(
        &dir,
        &["refine", "--size", "64x64", "--phases", "vertices,edges"],
    );
    for phase in ["vertices ", "edges "] {
        assert!(out.lines().any(|l| l.starts_with(phase)), "{phase}: {out}");
    }
    assert!(read(dir.join("pot-refine.png")).starts_with(b"\x89PNG"));
}

#[test]
fn a_sweep_is_the_same_at_any_thread_count() {
    let dir = scratch("refine-sweep-threads");
    let run = |threads: &str| {
        let (csv, plot) = (format!("s{threads}.csv"), format!("s{threads}.png"));
        let out = cwisim_ok(
            &dir,
            &[
                "refine",
                "--size",
                "48x40",
                "--sweep",
                "aa-threshold=0.05,0.1,0.2,0.4,all",
                "--threads",
                threads,
                "--csv",
                &csv,
                "--plot",
                &plot,
            ],
        );
        (
            out.replace(&format!("{csv}, {plot}"), "CSV, PLOT"),
            read(dir.join(&csv)),
            read(dir.join(&plot)),
        )
    };
    let one = run("1");
    assert_eq!(
        one.0.matches("pot (--aa-threshold ").count(),
        5,
        "{}",
        one.0
    );
    for threads in ["2", "3", "0"] {
        assert!(run(threads) == one, "--threads {threads}");
    }
    // one run: its frames on the threads, the same table, CSV and trace
    let single = |threads: &str| {
        let (csv, trace) = (format!("r{threads}.csv"), format!("r{threads}.cwb"));
        let out = cwisim_ok(
            &dir,
            &[
                "refine",
                "--size",
                "48x40",
                "--threads",
                threads,
                "--csv",
                &csv,
                "--trace",
                &trace,
            ],
        );
        (
            out.replace(&format!("{trace}, {csv}"), "TRACE, CSV"),
            read(dir.join(&csv)),
            read(dir.join(&trace)),
        )
    };
    let one = single("1");
    assert!(one.0.contains("TRACE, CSV"), "{}", one.0);
    for threads in ["2", "3"] {
        assert!(single(threads) == one, "one run, --threads {threads}");
    }
}

#[test]
fn bad_input_is_refused_in_one_line_with_exit_2() {
    let dir = scratch("refine-bad");
    for (args, says) in [
        (vec!["--phases", "gouraud,flat"], "--phases"),
        (vec!["--phases", "flat,vertices"], "out of order"),
        (
            vec!["--phases", "flat,shadows"],
            "no light of the scene casts shadows",
        ),
        (vec!["--phong-angle", "270"], "--phong-angle is an angle"),
        (vec!["--aa-threshold", "lots"], "expected `all`, `none`"),
        (vec!["--sweep", "size=1,2"], "unknown threshold `size`"),
        (
            vec!["--sweep", "aa-threshold=0.1,0.2", "--frames-png", "f"],
            "--frames-png writes one run's frames",
        ),
        (vec!["--plot", "q.jpg"], "--plot"),
        (vec!["no-such-scene"], "no-such-scene"),
        (vec!["fig25"], "fig25 is a screen scene"),
    ] {
        let mut all = vec!["refine", "--size", "32x32"];
        all.extend(&args);
        let out = cwisim(&dir, &all);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        // the message is the first line (clap adds a usage hint after its own)
        let first = stderr.lines().next().unwrap_or("");
        assert!(first.starts_with("error: "), "{args:?}: {stderr}");
        assert!(first.contains(says), "{args:?}: {stderr}");
    }
    assert!(!dir.join("f").exists());
    assert!(!dir.join("q.jpg").exists());
    assert!(!dir.join("pot-refine.png").exists());
}

#[test]
fn refine_writes_the_polygon_id_view() {
    let dir = scratch("refine-ids");
    let out = cwisim_ok(
        &dir,
        &["refine", "pot", "--size", "96x96", "--ids", "ids.npy"],
    );
    // the flat phase point-samples every fragment: its pixels are the owned ones
    let flat: u64 = out
        .lines()
        .find(|l| l.starts_with("flat "))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no flat row: {out}"));
    let bytes = read(dir.join("ids.npy"));
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(npy.shape(), &[96, 96]);
    let ids: Vec<u32> = npy.into_vec().unwrap();
    assert_eq!(ids.iter().filter(|&&k| k != 0).count() as u64, flat);
    assert!(ids.iter().all(|&k| k != u32::MAX), "no pixel is shared");
    let polygons: u32 = out
        .split(" polygons (visible fragments)")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no polygon count: {out}"));
    assert!(ids.iter().all(|&k| k <= polygons));

    cwisim_ok(
        &dir,
        &["refine", "pot", "--size", "64x64", "--ids", "ids.png"],
    );
    assert!(read(dir.join("ids.png")).starts_with(b"\x89PNG"));

    let bad = cwisim(
        &dir,
        &["refine", "pot", "--size", "64x64", "--ids", "ids.txt"],
    );
    assert_eq!(bad.status.code(), Some(2));
    let (_, err) = text(&bad);
    assert!(err.contains("--ids"), "{err}");
    assert!(!dir.join("ids.txt").exists());
}

#[test]
fn shadows_on_adds_the_shadow_phase_after_flat() {
    let dir = scratch("refine-shadows");
    let out = cwisim_ok(
        &dir,
        &["refine", "still-life", "--size", "96x64", "--shadows", "on"],
    );
    let phases: Vec<&str> = out
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .filter(|w| ["flat", "shadows", "gouraud", "phong", "aa"].contains(w))
        .take(5)
        .collect();
    assert_eq!(
        phases,
        ["flat", "shadows", "gouraud", "phong", "aa"],
        "{out}"
    );
    // as embedded, still-life's main light casts: the phase is there; off, it is not
    let out = cwisim_ok(&dir, &["refine", "still-life", "--size", "96x64"]);
    assert!(out.lines().any(|l| l.starts_with("shadows ")), "{out}");
    let out = cwisim_ok(
        &dir,
        &[
            "refine",
            "still-life",
            "--size",
            "96x64",
            "--shadows",
            "off",
        ],
    );
    assert!(!out.lines().any(|l| l.starts_with("shadows ")), "{out}");
    // the pot casts none: --shadows off would change nothing, and is refused
    let out = cwisim(
        &dir,
        &["refine", "pot", "--size", "96x64", "--shadows", "off"],
    );
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--shadows off: no light of the scene casts shadows"),
        "{stderr}"
    );
}

/// `--events`: the session's table and timeline; a bad script is a located error, exit 2,
/// nothing written.
#[test]
fn an_event_script_runs_a_session_and_bad_ones_are_located() {
    let dir = scratch("refine-events");
    std::fs::write(
        dir.join("drag.json"),
        r#"{"unit": "frames", "end": 8, "events": [
  {"at": 1.5, "camera": {"eye": [1, 3.2, 4.9]}},
  {"at": 3, "light": 0, "position": [-4, 6, 5]}
]}"#,
    )
    .unwrap();
    let out = cwisim_ok(
        &dir,
        &[
            "refine",
            "pot",
            "--size",
            "64x64",
            "--events",
            "drag.json",
            "--plot",
            "s.png",
        ],
    );
    assert!(out.contains("session of pot: 3 run(s)"), "{out}");
    assert!(out.contains("run 1 at cycle"), "{out}");
    assert!(out.contains("events[0]: camera eye [1, 3.2, 4.9]"), "{out}");
    assert!(out.contains("no: interrupted"), "{out}");
    assert!(read(dir.join("s.png")).starts_with(b"\x89PNG"));
    for (script, expected) in [
        (
            r#"{"unit": "frames", "end": 8, "events": [{"at": 0, "camera": {"fov_y": 30}}]}"#,
            "bad.json:1:48: events[0].at: an event's time must be after 0",
        ),
        (
            r#"{"unit": "frames", "end": 8, "events": [{"at": 2, "zoom": 3}]}"#,
            "unknown field `zoom`",
        ),
        (
            r#"{"unit": "frames", "end": 8, "events": [{"at": 9, "camera": {"fov_y": 30}}]}"#,
            "bad.json:1:48: events[0].at: the event at 9 frames is past the session's end (8)",
        ),
    ] {
        std::fs::write(dir.join("bad.json"), script).unwrap();
        let o = cwisim(
            &dir,
            &["refine", "pot", "--events", "bad.json", "--plot", "bad.png"],
        );
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(expected), "{err}");
        assert!(!dir.join("bad.png").exists());
    }
    let o = cwisim(
        &dir,
        &["refine", "pot", "--events", "drag.json", "--csv", "x.csv"],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("--csv is of one refinement"));
}
