//! `--renderer` on every command that draws a scene, and `cwisim renderers`: the
//! default is van Rij's DO_FILL, naming it changes nothing, and an unknown name is one
//! line listing the known ones, with exit code 2 and no file written.

mod common;

use common::{cwisim, cwisim_ok, read, scratch, text};
use cwisim_render::REGISTRY;

#[test]
fn renderers_lists_every_registered_one_with_the_default_marked() {
    let dir = scratch("renderers-list");
    let out = cwisim_ok(&dir, &["renderers"]);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), REGISTRY.len(), "{out}");
    for (line, e) in lines.iter().zip(REGISTRY) {
        assert!(line.starts_with(e.name), "{line}");
        assert!(line.contains(e.about), "{line}");
    }
    assert!(lines[0].starts_with("vanrij") && lines[0].ends_with("(the default)"));
}

#[test]
fn naming_the_default_renderer_changes_no_byte() {
    let dir = scratch("renderers-default");
    let args = ["--size", "64x64", "-q"];
    cwisim_ok(
        &dir,
        &[
            &["render", "pot", "--npy", "a.npy", "--trace", "a.cwt"][..],
            &args,
        ]
        .concat(),
    );
    cwisim_ok(
        &dir,
        &[
            &[
                "render",
                "pot",
                "--renderer",
                "vanrij",
                "--npy",
                "b.npy",
                "--trace",
                "b.cwt",
            ][..],
            &args,
        ]
        .concat(),
    );
    assert_eq!(read(dir.join("a.npy")), read(dir.join("b.npy")));
    assert_eq!(read(dir.join("a.cwt")), read(dir.join("b.cwt")));
    cwisim_ok(
        &dir,
        &["emit", "fig25", "-o", "c.cwt", "--renderer", "vanrij"],
    );
    cwisim_ok(&dir, &["emit", "fig25", "-o", "d.cwt"]);
    assert_eq!(read(dir.join("c.cwt")), read(dir.join("d.cwt")));
}

#[test]
fn the_summary_names_the_renderer_and_its_counters() {
    let dir = scratch("renderers-summary");
    let out = cwisim_ok(&dir, &["render", "fig25", "-o", "f.png"]);
    let row = out
        .lines()
        .find(|l| l.starts_with("Y-processor"))
        .expect("a Y-processor row");
    assert!(row.starts_with("Y-processor  vanrij: polygons "), "{row}");
    assert!(out.contains("trapezia"), "{out}");
}

#[test]
fn an_unknown_renderer_is_one_line_naming_the_known_ones() {
    let dir = scratch("renderers-unknown");
    for args in [
        &["render", "pot", "--renderer", "nishitaa", "-o", "x.png"][..],
        &["emit", "pot", "--renderer", "nishitaa", "-o", "x.cwt"],
        &[
            "fit",
            "fig25",
            "--renderer",
            "nishitaa",
            "--max-error",
            "1/512",
        ],
        &["tradeoff", "fig25", "--renderers", "vanrij,nishitaa"],
    ] {
        let out = cwisim(&dir, args);
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(
            stderr,
            "error: unknown renderer `nishitaa`; known: vanrij, woo-chall, sbuffer, bsp, nishita, refine\n",
            "{args:?}"
        );
        assert!(stdout.is_empty(), "{args:?}: {stdout}");
    }
    assert!(!dir.join("x.png").exists() && !dir.join("x.cwt").exists());
}

#[test]
fn stats_on_a_scene_takes_the_drawing_options() {
    let dir = scratch("renderers-stats");
    let fig25 = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../ypipe/tests/fixtures/fig25.json"
    );
    let gouraud = cwisim_ok(&dir, &["stats", fig25]);
    let flat = cwisim_ok(
        &dir,
        &["stats", fig25, "--shading", "flat", "--renderer", "vanrij"],
    );
    assert_ne!(
        gouraud, flat,
        "flat shading sends Eval1s where Gouraud sends Eval2s"
    );
    assert!(flat.contains("Eval1"), "{flat}");
    let out = cwisim(&dir, &["stats", fig25, "--renderer", "nishitaa"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("unknown renderer `nishitaa`"));
}

#[test]
fn nishita_draws_the_teapot_with_its_summary_and_refuses_bad_settings() {
    let dir = scratch("renderers-nishita");
    let out = cwisim_ok(
        &dir,
        &[
            "render",
            "teapot",
            "--renderer",
            "nishita",
            "--size",
            "96x96",
            "--root-tolerance",
            "1e-5",
            "--band",
            "3",
            "--subscan",
            "2",
            "-o",
            "n.png",
        ],
    );
    for label in ["subpatches", "roots", "iterations", "pieces", "host time"] {
        assert!(
            out.lines().any(|l| l.starts_with(label)),
            "no {label} row: {out}"
        );
    }
    assert!(out.contains("average iterations per root"), "{out}");
    assert!(
        out.contains("bands of 3 rows, 2 sub-scanline(s) per row"),
        "{out}"
    );
    assert!(dir.join("n.png").exists());
    for (flag, value, says) in [
        ("--root-tolerance", "0", "--root-tolerance"),
        ("--flatness", "0", "--flatness"),
        ("--band", "0", "--band"),
        ("--subscan", "100", "--subscan"),
        ("--shading", "flat", "--shading gouraud or phong"),
    ] {
        let out = cwisim(
            &dir,
            &[
                "render",
                "teapot",
                "--renderer",
                "nishita",
                flag,
                value,
                "-o",
                "x.png",
            ],
        );
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {stderr}");
        assert!(stderr.contains(says), "{flag} {value}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
    assert!(!dir.join("x.png").exists());
}

#[test]
fn refine_prints_its_phases_and_refuses_bad_thresholds() {
    let dir = scratch("renderers-refine");
    let out = cwisim_ok(
        &dir,
        &[
            "render",
            "pot",
            "--renderer",
            "refine",
            "--size",
            "64x64",
            "--gouraud-threshold",
            "0.05",
            "--aa-threshold",
            "all",
            "-o",
            "r.png",
        ],
    );
    for row in [
        "phase 1      flat:",
        "phase 2      Gouraud:",
        "phase 3      Phong:",
        "phase 4      anti-aliasing: 4096 of 4096 pixels box-filtered (100.0%),",
        "0 Dis masks",
    ] {
        assert!(out.contains(row), "no `{row}`: {out}");
    }
    assert!(dir.join("r.png").exists());
    for (flag, value, says) in [
        (
            "--gouraud-threshold",
            "lots",
            "expected `all`, `none` or a finite number",
        ),
        (
            "--aa-threshold",
            "inf",
            "expected `all`, `none` or a finite number",
        ),
        ("--shading", "phong", "--shading is not used by refine"),
        (
            "--phong-angle",
            "200",
            "--phong-angle is an angle in degrees",
        ),
        (
            "--phong-angle",
            "wide",
            "expected `all`, `none` or a finite number",
        ),
    ] {
        let out = cwisim(
            &dir,
            &[
                "render",
                "pot",
                "--renderer",
                "refine",
                flag,
                value,
                "-o",
                "x.png",
            ],
        );
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {stderr}");
        assert!(stderr.contains(says), "{flag} {value}: {stderr}");
    }
    assert!(!dir.join("x.png").exists());
    let out = cwisim(&dir, &["tradeoff", "fig25", "--renderers", "vanrij,refine"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("tradeoff measures one-frame renderers"),
        "{stderr}"
    );
}
