//! Bad world scene files: every fault is a located error naming what was expected —
//! never a panic.

use cwisim_scene::SceneErrorKind;
use cwisim_world::{load_any, parse_any};

const GOOD: &str = r#"{
  "kind": "world", "width": 32, "height": 24, "channels": 1,
  "camera": { "eye": [0, 0, 5], "target": [0, 0, 0] , "fov_y": 40 },
  "ambient": 0.2,
  "lights": [ { "position": [2, 3, 4], "intensity": 0.8 } ],
  "meshes": [
    { "material": { "k_a": 0.3, "k_d": 0.6, "k_s": 0.2, "n": 8 },
      "vertices": [[-1, -1, 0], [1, -1, 0], [0, 1, 0]],
      "faces": [[0, 1, 2]] }
  ]
}"#;

/// `GOOD` with `from` replaced by `to`; the error's display, kind and line.
fn fault(from: &str, to: &str) -> (String, SceneErrorKind, Option<u64>) {
    assert!(GOOD.contains(from), "{from}");
    let text = GOOD.replacen(from, to, 1);
    let e = parse_any(&text, None).expect_err("a fault");
    (e.to_string(), e.kind, e.line)
}

#[test]
fn the_good_scene_reads() {
    parse_any(GOOD, None).expect("good");
}

#[test]
fn missing_fields_and_unknown_keys() {
    let (m, k, line) = fault(r#""ambient": 0.2,"#, "");
    assert_eq!(k, SceneErrorKind::Schema, "{m}");
    assert!(m.contains("missing field `ambient`"), "{m}");
    assert!(line.is_some(), "{m}");
    let (m, _, line) = fault(r#""n": 8"#, r#""n": 8, "shininess": 3"#);
    assert!(m.contains("unknown field `shininess`"), "{m}");
    assert_eq!(line, Some(7), "{m}");
    let (m, _, _) = fault(r#""fov_y": 40"#, r#""fov": 40"#);
    assert!(m.contains("unknown field `fov`"), "{m}");
}

#[test]
fn unknown_kinds_list_the_known_ones() {
    let (m, k, _) = fault(r#""kind": "world""#, r#""kind": "solid""#);
    assert_eq!(k, SceneErrorKind::Kind);
    assert!(
        m.contains(r#"unknown scene kind "solid"; expected "screen" or "world""#),
        "{m}"
    );
    assert!(m.starts_with("2:11: kind:"), "{m}");
}

#[test]
fn nan_infinity_and_huge_numbers() {
    let (m, k, line) = fault("[2, 3, 4]", "[2, NaN, 4]");
    assert_eq!((k, line), (SceneErrorKind::Syntax, Some(5)), "{m}");
    let (m, k, _) = fault("[2, 3, 4]", "[2, 1e999, 4]");
    assert_eq!(k, SceneErrorKind::Syntax, "{m}");
    assert!(m.contains("overflows f64"), "{m}");
    let (m, k, _) = fault("[2, 3, 4]", "[2, 3e12, 4]");
    assert_eq!(k, SceneErrorKind::Limit, "{m}");
    assert!(m.contains("lights[0].position"), "{m}");
}

#[test]
fn empty_meshes_and_sources() {
    let (m, k, _) = fault(r#""faces": [[0, 1, 2]]"#, r#""faces": []"#);
    assert_eq!(k, SceneErrorKind::Geometry, "{m}");
    assert!(m.contains("has no faces"), "{m}");
    let (m, _, _) = fault(
        r#""vertices": [[-1, -1, 0], [1, -1, 0], [0, 1, 0]],"#,
        r#""vertices": [],"#,
    );
    assert!(m.contains("meshes[0].vertices"), "{m}");
    let start = GOOD.find(r#""meshes""#).unwrap();
    let text = format!("{}\"meshes\": []\n}}", &GOOD[..start]);
    let e = parse_any(&text, None).expect_err("no meshes");
    assert!(e.to_string().contains("at least one mesh"), "{e}");
    let (m, _, _) = fault(
        r#""faces": [[0, 1, 2]] }"#,
        r#""faces": [[0, 1, 2]], "obj": "x.obj" }"#,
    );
    assert!(m.contains("only one geometry source"), "{m}");
}

#[test]
fn degenerate_triangles_and_bad_indices() {
    let (m, k, line) = fault("[0, 1, 0]]", "[3, -1, 0]]");
    assert_eq!(k, SceneErrorKind::Geometry, "{m}");
    assert!(m.contains("meshes[0].faces[0]: degenerate face"), "{m}");
    assert_eq!(line, Some(9), "{m}");
    let (m, k, _) = fault("[[0, 1, 2]]", "[[0, 1, 3]]");
    assert_eq!(k, SceneErrorKind::Shape);
    assert!(
        m.contains("meshes[0].faces[0][2]: vertex index 3 is out of range"),
        "{m}"
    );
}

#[test]
fn a_camera_inside_or_behind_an_object_is_refused() {
    // the camera nearly in the triangle's plane: nearer than `near`
    let (m, k, line) = fault(r#""eye": [0, 0, 5]"#, r#""eye": [0, 0, 0.0001]"#);
    assert_eq!(k, SceneErrorKind::Geometry, "{m}");
    assert!(m.contains("too close to the camera"), "{m}");
    assert!(
        m.contains("the camera is inside or behind the object"),
        "{m}"
    );
    assert_eq!(line, Some(7), "{m}");
    // a closed box around the camera
    let (m, k, _) = fault(
        r#""vertices": [[-1, -1, 0], [1, -1, 0], [0, 1, 0]],
      "faces": [[0, 1, 2]]"#,
        r#""vertices": [[-9,-9,-4],[9,-9,-4],[9,9,-4],[-9,9,-4],[-9,-9,9],[9,-9,9],[9,9,9],[-9,9,9]],
      "faces": [[0,3,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]]"#,
    );
    assert_eq!(k, SceneErrorKind::Geometry, "{m}");
    assert!(
        m.contains("vertex 4 of mesh \"mesh 0\" at [-9, -9, 9] is behind the camera"),
        "{m}"
    );
}

#[test]
fn camera_and_material_limits() {
    let (m, _, _) = fault(r#""fov_y": 40"#, r#""fov_y": 180"#);
    assert!(m.contains("camera.fov_y"), "{m}");
    // a field of view so narrow that projection would overflow: refused at its path, in
    // its file, before anything is projected
    let (m, _, _) = fault(r#""fov_y": 40"#, r#""fov_y": 1e-300"#);
    assert!(
        m.contains(
            "camera.fov_y: expected a field of view from 0.001 to under 180 degrees, found 1e-300"
        ),
        "{m}"
    );
    let (m, _, _) = fault(r#""target": [0, 0, 0]"#, r#""target": [0, 0, 5]"#);
    assert!(m.contains("looks at its own position"), "{m}");
    let (m, _, _) = fault(r#""k_d": 0.6"#, r#""k_d": [0.6, 0.2]"#);
    assert!(
        m.contains("meshes[0].material.k_d: expected one number or 1"),
        "{m}"
    );
    let (m, _, _) = fault(r#""n": 8"#, r#""n": -1"#);
    assert!(m.contains("specular exponent"), "{m}");
}

#[test]
fn lighting_terms_beyond_the_intensity_limit_are_refused_at_their_path() {
    const BEYOND: &str = "is beyond 1e12, the limit of every intensity and lighting term (it keeps the lighting and the renderers' arithmetic finite; terms are nominally 0 to 1)";
    for (from, to, shown) in [
        (
            r#""ambient": 0.2"#,
            r#""ambient": 1.7976931348623157e308"#,
            "4:14: ambient: 1.7976931348623157e308",
        ),
        (
            r#""intensity": 0.8"#,
            r#""intensity": 1e308"#,
            "5:53: lights[0].intensity: 1e308",
        ),
        (
            r#""k_a": 0.3"#,
            r#""k_a": 1.000000000001e12"#,
            "7:28: meshes[0].material.k_a: 1.000000000001e12",
        ),
        (
            r#""k_d": 0.6"#,
            r#""k_d": 1e13"#,
            "7:40: meshes[0].material.k_d: 1e13",
        ),
        (
            r#""k_s": 0.2"#,
            r#""k_s": 1e300"#,
            "7:52: meshes[0].material.k_s: 1e300",
        ),
    ] {
        let (m, k, _) = fault(from, to);
        assert_eq!(k, SceneErrorKind::Limit, "{m}");
        assert_eq!(m, format!("{shown} {BEYOND}"));
    }
    // per channel: the channel's own path
    let text = GOOD
        .replacen(r#""channels": 1"#, r#""channels": 3"#, 1)
        .replacen(r#""intensity": 0.8"#, r#""intensity": [0.8, 0.8, 2e12]"#, 1);
    let m = parse_any(&text, None).expect_err("a fault").to_string();
    assert_eq!(m, format!("5:64: lights[0].intensity[2]: 2e12 {BEYOND}"));
    // the limit itself is fine, as is any finite shininess
    for (from, to) in [
        (r#""ambient": 0.2"#, r#""ambient": 1e12"#),
        (r#""intensity": 0.8"#, r#""intensity": 1e12"#),
        (r#""k_a": 0.3"#, r#""k_a": 1e12"#),
        (r#""n": 8"#, r#""n": 1.7976931348623157e308"#),
    ] {
        parse_any(&GOOD.replacen(from, to, 1), None).expect("within the limits");
    }
    // a scene built in code is never validated: projection checks its lighting terms
    let cwisim_world::AnyScene::World(mut w) = parse_any(GOOD, None).expect("good") else {
        panic!("a world scene")
    };
    w.spec.meshes[0].material.k_d = cwisim_world::scene::PerChannel::All(f64::MAX);
    let e = cwisim_world::project::project(&w, cwisim_scene::Shading::Gouraud).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("meshes[0].material.k_d: 1.7976931348623157e308 {BEYOND}")
    );
}

#[test]
fn obj_errors_name_the_obj_file_and_line() {
    let dir = std::env::temp_dir().join(format!("cwisim-world-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let scene = GOOD.replace(
        r#""vertices": [[-1, -1, 0], [1, -1, 0], [0, 1, 0]],
      "faces": [[0, 1, 2]]"#,
        r#""obj": "m.obj""#,
    );
    std::fs::write(dir.join("s.json"), &scene).unwrap();
    let e = load_any(&dir.join("s.json")).expect_err("bad obj");
    let m = e.to_string();
    assert!(m.contains("m.obj:4:1:"), "{m}");
    std::fs::write(dir.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    load_any(&dir.join("s.json")).expect("good obj");
    let missing = scene.replace("m.obj", "gone.obj");
    std::fs::write(dir.join("s.json"), missing).unwrap();
    let e = load_any(&dir.join("s.json")).expect_err("missing obj");
    assert_eq!(e.kind, SceneErrorKind::Io, "{e}");
}

#[test]
fn a_number_or_list_of_neither_form_says_what_is_expected() {
    // (read by hand: an untagged enum would say only that no variant matched)
    let (m, k, line) = fault(r#""k_d": 0.6"#, r#""k_d": "red""#);
    assert_eq!((k, line), (SceneErrorKind::Schema, Some(7)), "{m}");
    assert!(
        m.contains(
            r#"invalid type: string "red", expected a number, or a list of numbers (one per channel)"#
        ),
        "{m}"
    );
    assert!(!m.contains("variant"), "{m}");
    let (m, _, _) = fault(r#""k_d": 0.6"#, r#""k_d": [0.6, "x", 1]"#);
    assert!(
        m.contains(r#"invalid type: string "x", expected f64"#),
        "{m}"
    );
    let (m, _, _) = fault(r#""ambient": 0.2"#, r#""ambient": {"r": 1}"#);
    assert!(
        m.contains("invalid type: map, expected a number, or a list"),
        "{m}"
    );
    // both forms still read
    parse_any(&GOOD.replacen(r#""k_d": 0.6"#, r#""k_d": [0.6]"#, 1), None).expect("a list");
    let scaled = r#""faces": [[0, 1, 2]], "transform": { "scale": "#;
    for (scale, ok) in [
        ("2", true),
        ("[1, 2, 1]", true),
        ("[1, 2]", false),
        ("true", false),
    ] {
        let text = GOOD.replacen(r#""faces": [[0, 1, 2]]"#, &format!("{scaled}{scale} }}"), 1);
        match parse_any(&text, None) {
            Ok(_) => assert!(ok, "{scale}"),
            Err(e) => {
                assert!(!ok, "{scale}: {e}");
                assert!(
                    e.to_string()
                        .contains("expected a number, or a list of 3 numbers (one per axis)"),
                    "{e}"
                );
            }
        }
    }
}
