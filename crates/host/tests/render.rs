//! `cwisim render` and `cwisim emit` through the real binary.

mod common;

use common::{cwisim, scratch};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_ypipe::exact::scene_coverage;
use proptest::prelude::*;
use std::path::Path;

fn npy(path: &Path) -> (Vec<u64>, Vec<f64>) {
    let bytes = std::fs::read(path).expect("npy written");
    let file = npyz::NpyFile::new(&bytes[..]).expect("valid npy");
    let shape = file.shape().to_vec();
    (shape, file.into_vec::<f64>().expect("f64 data"))
}

fn write_scene(dir: &Path, name: &str, s: &ScreenScene) {
    std::fs::write(dir.join(name), s.to_json()).expect("write scene");
}

fn ones(vertices: Vec<[f64; 2]>) -> Polygon {
    Polygon::uniform(vertices, &[1.0])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// The issue's acceptance test: rendered coverage (intensity 1) equals an exact area
    /// computation within 1e-9, through the CLI and the .npy file.
    #[test]
    fn render_npy_matches_the_exact_area(
        v in proptest::collection::vec((-3.0f64..35.0, -3.0f64..27.0), 3..6),
    ) {
        // a fan around the centroid, sorted by angle: a simple (star-shaped) polygon
        let (cx, cy) = (v.iter().map(|p| p.0).sum::<f64>() / v.len() as f64, v.iter().map(|p| p.1).sum::<f64>() / v.len() as f64);
        let mut pts: Vec<[f64; 2]> = v.iter().map(|&(x, y)| [x, y]).collect();
        pts.sort_by(|a, b| (a[1] - cy).atan2(a[0] - cx).total_cmp(&(b[1] - cy).atan2(b[0] - cx)));
        let scene = ScreenScene { width: 32, height: 24, channels: 1, polygons: vec![ones(pts)] };
        prop_assume!(scene.validate().is_ok());
        let dir = scratch("render_npy_matches_the_exact_area");
        write_scene(&dir, "s.json", &scene);
        let out = cwisim(&dir, &["render", "s.json", "--npy", "s.npy"]);
        prop_assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let (shape, data) = npy(&dir.join("s.npy"));
        prop_assert_eq!(shape, vec![24, 32, 1]);
        let exact = scene_coverage(&scene);
        for (a, b) in data.iter().zip(&exact) {
            prop_assert!((a - b).abs() <= 1e-9, "{a} vs {b}");
        }
    }
}

#[test]
fn render_equals_emit_then_run_and_is_deterministic() {
    let dir = scratch("render_equals_emit_then_run");
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../ypipe/tests/fixtures");
    std::fs::copy(fixtures.join("fig25.json"), dir.join("fig25.json")).unwrap();
    for (i, flags) in [
        &["--shading", "gouraud", "--aa", "box"][..],
        &["--shading", "flat", "--aa", "none"],
    ]
    .iter()
    .enumerate()
    {
        let trace = format!("t{i}.cwb");
        let mut args = vec![
            "render",
            "fig25.json",
            "--npy",
            "a.npy",
            "--trace",
            "t.cwt",
            "-o",
            "a.png",
        ];
        args.extend_from_slice(flags);
        assert!(cwisim(&dir, &args).status.success());
        let first = std::fs::read(dir.join("a.npy")).unwrap();
        let first_trace = std::fs::read(dir.join("t.cwt")).unwrap();
        let first_png = std::fs::read(dir.join("a.png")).unwrap();
        assert!(cwisim(&dir, &args).status.success());
        assert_eq!(
            first,
            std::fs::read(dir.join("a.npy")).unwrap(),
            "render is deterministic"
        );
        assert_eq!(first_trace, std::fs::read(dir.join("t.cwt")).unwrap());
        assert_eq!(first_png, std::fs::read(dir.join("a.png")).unwrap());
        let mut emit = vec!["emit", "fig25.json", "-o", trace.as_str()];
        emit.extend_from_slice(flags);
        assert!(cwisim(&dir, &emit).status.success());
        assert!(cwisim(&dir, &["run", &trace, "--npy", "b.npy"])
            .status
            .success());
        assert_eq!(
            first,
            std::fs::read(dir.join("b.npy")).unwrap(),
            "render = emit + run"
        );
    }
    let text = std::fs::read_to_string(dir.join("t.cwt")).unwrap();
    assert!(
        text.contains("point-sampled span"),
        "the last trace is point-sampled"
    );
}

#[test]
fn annotated_text_names_the_cases() {
    let dir = scratch("annotated_text_names_the_cases");
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../ypipe/tests/fixtures");
    std::fs::copy(fixtures.join("case09.json"), dir.join("c.json")).unwrap();
    assert!(cwisim(&dir, &["emit", "c.json", "-o", "c.cwt"])
        .status
        .success());
    let text = std::fs::read_to_string(dir.join("c.cwt")).unwrap();
    assert!(
        text.contains("case 9: pixel 2 share-sequence 3..=4"),
        "{text}"
    );
}

#[test]
fn bad_scenes_exit_2_with_a_located_message() {
    let dir = scratch("bad_scenes_exit_2");
    let cases: [(&str, &str, &str); 9] = [
        (
            "two.json",
            r#"{"kind":"screen","width":8,"height":4,"channels":1,"polygons":[{"vertices":[[0,0],[4,0]],"intensity":[[1],[1]]}]}"#,
            "at least 3",
        ),
        ("kind.json", r#"{"kind":"solid"}"#, "expected \"screen\" or \"world\""),
        ("world.json", r#"{"kind":"world"}"#, "missing field `width`"),
        (
            "inside.json",
            r#"{"kind":"world","width":8,"height":4,"channels":1,"camera":{"eye":[0,0,0],"target":[0,0,-1],"fov_y":60},"ambient":1,
"meshes":[{"material":{"k_a":1,"k_d":0,"k_s":0,"n":1},"vertices":[[-1,-1,-1],[1,-1,-1],[0,1,1]],"faces":[[0,1,2]]}]}"#,
            "inside.json:2:11: meshes[0]: vertex 2 of mesh \"mesh 0\" at [0, 1, 1] is behind the camera",
        ),
        (
            "degenerate.json",
            r#"{"kind":"world","width":8,"height":4,"channels":1,"camera":{"eye":[0,0,5],"target":[0,0,0],"fov_y":60},"ambient":1,
"meshes":[{"material":{"k_a":1,"k_d":0,"k_s":0,"n":1},"vertices":[[0,0,0],[1,1,0],[2,2,0]],"faces":[[0,1,2]]}]}"#,
            "meshes[0].faces[0]: degenerate face",
        ),
        (
            "nan.json",
            r#"{"kind":"screen","width":8,"height":4,"channels":1,"polygons":[{"vertices":[[0,0],[4,0],[1e999,3]],"intensity":[[1],[1],[1]]}]}"#,
            "overflows f64",
        ),
        (
            "bowtie.json",
            r#"{"kind":"screen","width":8,"height":4,"channels":1,"polygons":[{"vertices":[[0,0],[4,0],[0,3],[4,3]],"intensity":[[1],[1],[1],[1]]}]}"#,
            "not simple",
        ),
        (
            "rgb.json",
            r#"{"kind":"screen","width":8,"height":4,"channels":3,"polygons":[{"vertices":[[0,0],[4,0],[2,3]],"intensity":[[1],[1],[1]]}]}"#,
            "channel",
        ),
        (
            "extra.json",
            r#"{"kind":"screen","width":8,"height":4,"channels":1,"colour":2,"polygons":[]}"#,
            "colour",
        ),
    ];
    for (name, text, needle) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        for cmd in [
            &["render", name, "-o", "x.png"][..],
            &["emit", name, "-o", "x.cwt"],
        ] {
            let out = cwisim(&dir, cmd);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{name}: {err}");
            assert_eq!(err.lines().count(), 1, "{name}: {err}");
            assert!(err.starts_with(&format!("error: {name}:")), "{name}: {err}");
            assert!(err.contains(needle), "{name}: {err}");
            assert!(!err.contains("panicked"));
            assert!(!dir.join("x.png").exists() && !dir.join("x.cwt").exists());
        }
    }
}
