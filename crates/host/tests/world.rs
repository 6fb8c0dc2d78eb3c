//! `cwisim render` of world scenes and embedded scenes through the real binary: the
//! default command, the pot against its reference picture, the summary, `scenes`, and
//! determinism.

mod common;

use common::{cwisim, cwisim_ok, scratch, text};
use std::path::{Path, PathBuf};

fn npy(path: &Path) -> (Vec<u64>, Vec<f64>) {
    let bytes = std::fs::read(path).expect("npy written");
    let file = npyz::NpyFile::new(&bytes[..]).expect("valid npy");
    let shape = file.shape().to_vec();
    (shape, file.into_vec::<f64>().expect("f64 data"))
}

/// The reference picture of the pot, shown in the README.
fn reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/images/pot.png")
}

#[test]
fn the_default_render_is_the_pot_with_a_summary() {
    let dir = scratch("default_render");
    let out = cwisim_ok(&dir, &["render"]);
    assert!(dir.join("pot.png").exists(), "writes pot.png by default");
    for needle in [
        "scene        pot (world, 400×400, grey): Gouraud shading, box filter (exact), exact visibility",
        "geometry     1 mesh(es), 480 faces → 928 triangles",
        "visibility   exact: ",
        "Y-processor  ",
        "instructions ",
        "cycles       ",
        "worst line   scanline ",
        "time         load ",
        "wrote        pot.png",
    ] {
        assert!(out.contains(needle), "{needle:?} in:\n{out}");
    }
    // --quiet prints nothing; -o elsewhere writes there and not pot.png
    std::fs::remove_file(dir.join("pot.png")).unwrap();
    let out = cwisim_ok(&dir, &["render", "pot", "-q", "-o", "p.png"]);
    assert!(out.is_empty(), "{out}");
    assert!(dir.join("p.png").exists() && !dir.join("pot.png").exists());
}

/// The pot at its own size against `docs/images/pot.png`, within one 8-bit step per
/// pixel (the PNG rounds each value to 1/255; a step may flip where a value sits on a
/// rounding boundary and the platform's `sin`/`cos`/`powf` differ in the last bit).
/// `CWISIM_BLESS=1 cargo test -p cwisim-host --test world` rewrites the reference.
#[test]
fn the_pot_matches_its_reference_picture() {
    let dir = scratch("pot_reference");
    cwisim_ok(
        &dir,
        &["render", "pot", "-q", "-o", "pot.png", "--npy", "pot.npy"],
    );
    if std::env::var_os("CWISIM_BLESS").is_some() {
        std::fs::copy(dir.join("pot.png"), reference()).expect("bless the reference");
    }
    let reference = image::open(reference())
        .expect("docs/images/pot.png (bless with CWISIM_BLESS=1)")
        .to_luma8();
    let (shape, values) = npy(&dir.join("pot.npy"));
    assert_eq!(shape, [400, 400, 1]);
    assert_eq!(reference.dimensions(), (400, 400));
    let mut off = 0;
    for (v, r) in values.iter().zip(reference.as_raw()) {
        let ours = (v.clamp(0.0, 1.0) * 255.0).round() as i32;
        let d = (ours - i32::from(*r)).abs();
        assert!(d <= 1, "a pixel is {d} steps off the reference");
        off += usize::from(d == 1);
    }
    assert!(off <= values.len() / 1000, "{off} pixels one step off");
    // and it is a pot: a lit object in the middle, black corners
    assert_eq!(reference.get_pixel(0, 0).0[0], 0);
    assert!(reference.get_pixel(200, 230).0[0] > 100);
}

#[test]
fn every_embedded_scene_renders_and_scenes_lists_them() {
    let dir = scratch("embedded");
    let list = cwisim_ok(&dir, &["scenes"]);
    for name in [
        "pot",
        "fig25",
        "cases12",
        "still-life",
        "bowl",
        "teapot",
        "teapot-floor",
    ] {
        assert!(list.lines().any(|l| l.starts_with(name)), "{list}");
        let png = format!("{name}.png");
        cwisim_ok(&dir, &["render", name, "-q", "-o", &png]);
        let img = image::open(dir.join(&png)).expect("png");
        let channels = img.color().channel_count();
        let rgb = ["still-life", "bowl"].contains(&name);
        assert_eq!(channels, if rgb { 3 } else { 1 }, "{name}");
    }
    // `scenes NAME` prints a file that renders the same as the name
    let text = cwisim_ok(&dir, &["scenes", "still-life"]);
    std::fs::write(dir.join("copy.json"), text).unwrap();
    cwisim_ok(
        &dir,
        &[
            "render",
            "copy.json",
            "-q",
            "--npy",
            "a.npy",
            "--size",
            "96x64",
        ],
    );
    cwisim_ok(
        &dir,
        &[
            "render",
            "still-life",
            "-q",
            "--npy",
            "b.npy",
            "--size",
            "96x64",
        ],
    );
    assert_eq!(
        std::fs::read(dir.join("a.npy")).unwrap(),
        std::fs::read(dir.join("b.npy")).unwrap()
    );
    let out = cwisim(&dir, &["scenes", "coffee-pot"]);
    assert_eq!(out.status.code(), Some(2));
    let out = cwisim(&dir, &["render", "coffee-pot"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no such scene file, and no embedded scene"),
        "{err}"
    );
}

#[test]
fn renders_are_deterministic_in_every_mode() {
    let dir = scratch("deterministic");
    for mode in [
        &["--visibility", "exact"][..],
        &["--visibility", "eval0"],
        &["--visibility", "eval0", "--shading", "flat", "--aa", "none"],
    ] {
        let mut outputs = Vec::new();
        for run in 0..2 {
            let npy_name = format!("r{run}.npy");
            let trace = format!("r{run}.cwb");
            let json = format!("r{run}.json");
            let mut args = vec![
                "render",
                "pot",
                "-q",
                "--size",
                "120x100",
                "--npy",
                &npy_name,
                "--trace",
                &trace,
                "--stats-json",
                &json,
            ];
            args.extend_from_slice(mode);
            cwisim_ok(&dir, &args);
            outputs.push(
                [npy_name, trace, json].map(|f| std::fs::read(dir.join(f)).expect("written")),
            );
        }
        assert_eq!(outputs[0], outputs[1], "{mode:?}");
    }
}

#[test]
fn the_stats_json_describes_the_scene() {
    let dir = scratch("stats_json");
    cwisim_ok(
        &dir,
        &[
            "render",
            "pot",
            "-q",
            "--size",
            "80x80",
            "--visibility",
            "eval0",
            "--stats-json",
            "s.json",
        ],
    );
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("s.json")).unwrap()).unwrap();
    assert_eq!(v["scene"]["name"], "pot");
    assert_eq!(v["scene"]["visibility"], "eval0");
    assert_eq!(v["scene"]["project"]["triangles"], 928);
    assert_eq!(v["renderer"], "vanrij");
    assert_eq!(v["scene"]["renderer"], "vanrij");
    assert!(v["counters"]["claims"].as_u64().unwrap() > 0);
    assert!(v["counters"]["trapezia"].as_u64().unwrap() > 0);
    assert!(v["stats"]["totals"]["suppressed"].as_u64().unwrap() > 0);
}

#[test]
fn parallel_bands_give_the_serial_output_byte_for_byte() {
    let dir = scratch("threads");
    for mode in [
        &["--visibility", "exact"][..],
        &["--visibility", "eval0", "--aa", "none"],
        &["--shading", "phong"],
    ] {
        let mut outputs = Vec::new();
        for threads in ["1", "2", "3"] {
            let (npy, trace, json) = (
                format!("t{threads}.npy"),
                format!("t{threads}.cwt"),
                format!("t{threads}.json"),
            );
            let mut args = vec![
                "render",
                "still-life",
                "-q",
                "--size",
                "150x110",
                "--threads",
                threads,
                "--npy",
                &npy,
                "--trace",
                &trace,
                "--stats-json",
                &json,
            ];
            args.extend_from_slice(mode);
            cwisim_ok(&dir, &args);
            outputs.push([npy, trace, json].map(|f| std::fs::read(dir.join(f)).expect("written")));
        }
        assert_eq!(outputs[0], outputs[1], "{mode:?}");
        assert_eq!(outputs[0], outputs[2], "{mode:?}");
    }
}

#[test]
fn scenes_generate_cp_bench_writes_a_scene_the_scanline_renderers_draw() {
    let dir = scratch("cp_bench");
    let args = [
        "scenes",
        "generate",
        "cp-bench",
        "--family",
        "many",
        "--polygons",
        "20",
        "--vertices",
        "10..30",
        "--seed",
        "4",
        "--size",
        "64x48",
    ];
    let out = cwisim(&dir, &args);
    assert!(out.status.success());
    let (stdout, stderr) = text(&out);
    assert!(stderr.contains("cp-bench many: 20 polygons"), "{stderr}");
    // the same seed, the same scene
    assert_eq!(text(&cwisim(&dir, &args)).0, stdout);
    std::fs::write(dir.join("bench.json"), &stdout).unwrap();
    for (renderer, samples) in [
        ("sbuffer", &["--samples", "1"][..]),
        ("bsp", &["--samples", "1"]),
        ("vanrij", &[]),
    ] {
        let mut args = vec!["render", "bench.json", "--renderer", renderer];
        args.extend_from_slice(samples);
        let summary = cwisim_ok(&dir, &args);
        assert!(summary.contains("scene"), "{summary}");
    }
    // bad input: exit 2, one line
    let out = cwisim(
        &dir,
        &[
            "scenes",
            "generate",
            "cp-bench",
            "--family",
            "few",
            "--vertices",
            "9..2",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("empty"));
}
