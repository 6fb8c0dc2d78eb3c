//! Scene files: reading, writing back, and every refusal with its location.

use cwisim_scene::{
    load_scene, parse_scene, Polygon, Scene, SceneError, SceneErrorKind, ScreenScene,
};
use proptest::prelude::*;
use std::path::Path;

const EXAMPLE: &str = r#"{
  "kind": "screen",
  "width": 64, "height": 48, "channels": 1,
  "polygons": [
    { "vertices": [[10.5, 3.25], [40.0, 3.25], [30.0, 20.0]],
      "intensity": [[1.0], [0.5], [0.25]] }
  ]
}"#;

fn only_screen(scene: Scene) -> ScreenScene {
    match scene {
        Scene::Screen(s) => s,
    }
}

fn screen(text: &str) -> ScreenScene {
    only_screen(parse_scene(text).unwrap_or_else(|e| panic!("{e}")))
}

/// The example with `from` replaced by `to` (which must occur once).
fn variant(from: &str, to: &str) -> String {
    assert_eq!(EXAMPLE.matches(from).count(), 1, "{from}");
    EXAMPLE.replace(from, to)
}

fn err(text: &str) -> SceneError {
    parse_scene(text).expect_err("must be refused")
}

/// A scene around one polygon (grey unless the intensities say otherwise).
fn one(vertices: &str, intensity: &str, channels: u8) -> String {
    format!(
        "{{\"kind\": \"screen\", \"width\": 8, \"height\": 8, \"channels\": {channels},\n\
         \"polygons\": [{{\"vertices\": {vertices},\n\"intensity\": {intensity}}}]}}"
    )
}

#[test]
fn the_example_reads() {
    let s = screen(EXAMPLE);
    assert_eq!((s.width, s.height, s.channels), (64, 48, 1));
    assert_eq!(s.polygons.len(), 1);
    assert_eq!(
        s.polygons[0].vertices,
        vec![[10.5, 3.25], [40.0, 3.25], [30.0, 20.0]]
    );
    assert_eq!(
        s.polygons[0]
            .intensity
            .iter()
            .map(|i| i.to_vec())
            .collect::<Vec<_>>(),
        vec![vec![1.0], vec![0.5], vec![0.25]]
    );
    assert_eq!(Scene::Screen(s.clone()).kind(), "screen");
    assert_eq!(Scene::Screen(s).validate(), Ok(()));
}

#[test]
fn to_json_is_pretty_and_reads_back() {
    let s = screen(EXAMPLE);
    let json = s.to_json();
    assert_eq!(
        json,
        "{\n  \"kind\": \"screen\",\n  \"width\": 64,\n  \"height\": 48,\n  \"channels\": 1,\n  \"polygons\": [\n    {\n      \"vertices\": [[10.5, 3.25], [40.0, 3.25], [30.0, 20.0]],\n      \"intensity\": [[1.0], [0.5], [0.25]]\n    }\n  ]\n}\n"
    );
    assert_eq!(screen(&json), s);
    assert_eq!(json, screen(&json).to_json(), "deterministic");
    let empty = ScreenScene {
        polygons: vec![],
        ..s
    };
    assert_eq!(screen(&empty.to_json()), empty);
}

#[test]
fn serde_form_is_the_file_format() {
    let scene = Scene::Screen(screen(EXAMPLE));
    let json = serde_json::to_string(&scene).unwrap();
    assert!(json.starts_with("{\"kind\":\"screen\""), "{json}");
    assert_eq!(parse_scene(&json).unwrap(), scene);
    assert_eq!(serde_json::from_str::<Scene>(EXAMPLE).unwrap(), scene);
}

#[test]
fn degenerate_polygons_are_allowed() {
    // collinear, zero area, repeated vertices
    screen(&one("[[0, 0], [2, 0], [1, 0]]", "[[1], [1], [1]]", 1));
    screen(&one("[[1, 1], [1, 1], [1, 1]]", "[[1], [1], [1]]", 1));
    screen(&one(
        "[[0, 0], [4, 0], [4, 0], [4, 4], [0, 4], [0, 0]]",
        "[[1], [1], [1], [1], [1], [1]]",
        1,
    ));
    // concave, clockwise or not
    screen(&one(
        "[[0, 0], [4, 0], [2, 1], [4, 4], [0, 4]]",
        "[[1], [1], [1], [1], [1]]",
        1,
    ));
    screen(&one(
        "[[0, 4], [4, 4], [2, 1], [4, 0], [0, 0]]",
        "[[1], [1], [1], [1], [1]]",
        1,
    ));
    // collinear consecutive edges that go on straight
    screen(&one(
        "[[0, 0], [1, 0], [2, 0], [2, 2]]",
        "[[1], [1], [1], [1]]",
        1,
    ));
}

/// Refusal of `text`: its kind, `line:col` and message (the field before it when known).
fn refused(text: &str, kind: SceneErrorKind, shown: &str) {
    let e = err(text);
    assert_eq!(e.kind, kind, "{e}");
    assert_eq!(e.to_string(), shown);
}

#[test]
fn syntax_errors_are_located() {
    use SceneErrorKind::Syntax;
    refused(
        &variant("\"width\": 64", "\"width\": 64,"),
        Syntax,
        "3:15: key must be a string",
    );
    refused("", Syntax, "1:1: EOF while parsing a value");
    refused(
        "{\"kind\": \"screen\"",
        Syntax,
        "1:17: EOF while parsing an object",
    );
}

#[test]
fn numbers_that_overflow_are_refused_not_infinite() {
    let e = err(&variant("[40.0, 3.25]", "[1e999, 3.25]"));
    assert_eq!(e.kind, SceneErrorKind::Syntax);
    assert_eq!(
        e.to_string(),
        "5:39: number out of range: it overflows f64 (numbers must be finite, at most about 1.8e308)"
    );
    let e = err(&variant("[0.5]", "[-1e400]"));
    assert_eq!(e.kind, SceneErrorKind::Syntax);
    assert_eq!((e.line, e.column), (Some(6), Some(34)));
    // the largest finite number reads, and is then refused as an intensity beyond the
    // limit (`limits`)
    let e = err(&variant("[0.5]", "[1.7976931348623157e308]"));
    assert_eq!(e.kind, SceneErrorKind::Limit, "{e}");
}

#[test]
fn schema_errors_are_located() {
    use SceneErrorKind::Schema;
    refused(
        &variant("\"width\": 64", "\"width\": 64, \"depth\": 2"),
        Schema,
        "3:22: unknown field `depth`, expected one of `kind`, `width`, `height`, `channels`, `polygons`",
    );
    refused(
        &variant("{ \"vertices\"", "{ \"colour\": 1, \"vertices\""),
        Schema,
        "5:14: unknown field `colour`, expected one of `vertices`, `intensity`, `depth`",
    );
    refused(
        &variant("\"intensity\"", "\"intensities\""),
        Schema,
        "6:19: unknown field `intensities`, expected one of `vertices`, `intensity`, `depth`",
    );
    refused(
        &variant("\"width\": 64, ", ""),
        Schema,
        "8:1: missing field `width`",
    );
    refused(
        &variant("\"width\": 64", "\"width\": 64.5"),
        Schema,
        "3:15: invalid type: floating point `64.5`, expected u64",
    );
    refused(
        &variant("\"width\": 64", "\"width\": -3"),
        Schema,
        "3:13: invalid value: integer `-3`, expected u64",
    );
    refused(
        &variant(
            "\"kind\": \"screen\",",
            "\"kind\": \"screen\", \"kind\": \"screen\",",
        ),
        Schema,
        "2:26: duplicate field `kind`",
    );
    refused(
        "[1, 2]",
        Schema,
        "1:1: expected a scene object {\"kind\": …}, found an array",
    );
    refused(
        &variant(
            "{ \"vertices\": [[10.5, 3.25], [40.0, 3.25], [30.0, 20.0]],\n      \"intensity\": [[1.0], [0.5], [0.25]] }",
            "[1, 2]",
        ),
        Schema,
        "5:5: polygons[0]: expected a polygon object {\"vertices\": …, \"intensity\": …}, found an array",
    );
}

#[test]
fn the_kind_must_be_known() {
    refused(
        &variant("\"screen\"", "\"world\""),
        SceneErrorKind::Kind,
        "2:11: kind: unknown scene kind \"world\"; expected \"screen\"",
    );
    refused(
        &variant("\"kind\": \"screen\",", ""),
        SceneErrorKind::Schema,
        "1:1: missing field `kind`; expected \"screen\"",
    );
    refused(
        &variant("\"screen\"", "3"),
        SceneErrorKind::Schema,
        "2:11: kind: expected a string (\"screen\"), found a number",
    );
}

#[test]
fn limits() {
    use SceneErrorKind::Limit;
    for (from, to, shown) in [
        ("\"width\": 64", "\"width\": 70000", "3:12: width: width 70000 is outside 1..=65536 pixels"),
        ("\"width\": 64", "\"width\": 0", "3:12: width: width 0 is outside 1..=65536 pixels"),
        ("\"height\": 48", "\"height\": 65537", "3:26: height: height 65537 is outside 1..=65536 pixels"),
        ("\"channels\": 1", "\"channels\": 5", "3:42: channels: channels 5 is outside 1..=4 (1 grey, 3 RGB)"),
        ("\"channels\": 1", "\"channels\": 0", "3:42: channels: channels 0 is outside 1..=4 (1 grey, 3 RGB)"),
        (
            "\"width\": 64, \"height\": 48",
            "\"width\": 65536, \"height\": 65536",
            "1:1: the image would hold 65536 × 65536 × 1 = 4294967296 values; the limit is 268435456 (2^28)",
        ),
        (
            "[40.0, 3.25]",
            "[40.0, 2e15]",
            "5:34: polygons[0].vertices[1]: coordinate 2e15 is beyond ±1e15, where f64 can no longer resolve a pixel",
        ),
        (
            "[0.5]",
            "[1e308]",
            "6:29: polygons[0].intensity[1][0]: intensity 1e308 is beyond ±1e12, the limit that keeps the renderers' arithmetic finite (intensities are nominally 0 to 1)",
        ),
        (
            "[0.5]",
            "[-1.000000000001e12]",
            "6:29: polygons[0].intensity[1][0]: intensity -1.000000000001e12 is beyond ±1e12, the limit that keeps the renderers' arithmetic finite (intensities are nominally 0 to 1)",
        ),
    ] {
        refused(&variant(from, to), Limit, shown);
    }
    // the limits themselves are fine
    screen(&variant(
        "\"width\": 64, \"height\": 48",
        "\"width\": 65536, \"height\": 4096",
    ));
    screen(&variant("[40.0, 3.25]", "[-1e15, 1e15]"));
    // the intensity limit itself is fine (a negative intensity is the renderers' to refuse)
    screen(&variant(
        "[[1.0], [0.5], [0.25]]",
        "[[1e12], [-1e12], [5e-324]]",
    ));
    // the limit per channel, named by its index
    let e = err(&one(
        "[[0, 0], [1, 0], [0, 1]]",
        "[[1, 1, 1], [1, 1, 1], [1, 1, 1.7976931348623157e308]]",
        3,
    ));
    assert_eq!(e.kind, Limit, "{e}");
    assert!(
        e.to_string().starts_with(
            "3:44: polygons[0].intensity[2][2]: intensity 1.7976931348623157e308 is beyond ±1e12"
        ),
        "{e}"
    );
    let e = err(&variant("\"width\": 64", "\"width\": 99999999999999999999"));
    assert_eq!(e.kind, SceneErrorKind::Schema, "{e}");
}

#[test]
fn shapes() {
    use SceneErrorKind::Shape;
    refused(
        &variant(
            "[[10.5, 3.25], [40.0, 3.25], [30.0, 20.0]]",
            "[[10.5, 3.25], [40.0, 3.25]]",
        ),
        Shape,
        "5:19: polygons[0].vertices: polygon 0 has 2 vertices; a polygon needs at least 3",
    );
    refused(
        &variant("[40.0, 3.25]", "[40.0, 3.25, 1.0]"),
        Shape,
        "5:34: polygons[0].vertices[1]: expected a point [x, y], found an array of 3 values",
    );
    refused(
        &variant("[[1.0], [0.5], [0.25]]", "[[1.0], [0.5]]"),
        Shape,
        "6:20: polygons[0].intensity: expected one intensity vector per vertex (3), found 2",
    );
    refused(
        &variant("[0.5]", "[0.5, 1.0]"),
        Shape,
        "6:28: polygons[0].intensity[1]: expected 1 value (the scene's channels), found 2",
    );
    // the second polygon, on later lines, with three channels
    let text = "{\"kind\": \"screen\", \"width\": 8, \"height\": 8, \"channels\": 3, \"polygons\": [\n\
                {\"vertices\": [[0, 0], [1, 0], [0, 1]], \"intensity\": [[1, 1, 1], [1, 1, 1], [1, 1, 1]]},\n\
                {\"vertices\": [[0, 0], [1, 0], [0, 1]],\n  \"intensity\": [[1, 1, 1], [1, 1, 1], [1, 1]]}\n]}";
    refused(
        text,
        Shape,
        "4:39: polygons[1].intensity[2]: expected 3 values (the scene's channels), found 2",
    );
}

#[test]
fn self_intersections_name_the_polygon_and_edges() {
    use SceneErrorKind::SelfIntersection;
    let grey = |n: usize| format!("[{}]", vec!["[1]"; n].join(", "));
    refused(
        &one("[[0, 0], [4, 4], [4, 0], [0, 4]]", &grey(4), 1),
        SelfIntersection,
        "2:27: polygons[0].vertices: polygon 0 is not simple: edges 0 and 2 cross (edge k runs from vertex k to vertex k+1)",
    );
    // a vertex on a non-adjacent edge
    let e = err(&one(
        "[[0, 0], [4, 0], [4, 4], [2, 0], [0, 4]]",
        &grey(5),
        1,
    ));
    assert!(e.message.contains("edges 0 and 2 touch"), "{e}");
    // two non-adjacent edges through one vertex (a figure eight)
    let e = err(&one(
        "[[0, 0], [2, 2], [4, 0], [4, 4], [2, 2], [0, 4]]",
        &grey(6),
        1,
    ));
    assert!(e.message.contains("touch"), "{e}");
    // a spike: adjacent edges overlap
    let e = err(&one("[[0, 0], [4, 0], [2, 0], [2, 3]]", &grey(4), 1));
    assert!(
        e.message
            .contains("adjacent edges 0 and 1 overlap at vertex 1"),
        "{e}"
    );
    // collinear overlap of non-adjacent edges
    let e = err(&one(
        "[[0, 0], [4, 0], [4, 2], [3, 0], [1, 0], [0, 2]]",
        &grey(6),
        1,
    ));
    assert!(e.message.contains("not simple"), "{e}");
    // repeated vertices keep their original edge numbers
    let e = err(&one(
        "[[0, 0], [0, 0], [4, 4], [4, 0], [4, 0], [0, 4]]",
        &grey(6),
        1,
    ));
    assert!(e.message.contains("edges 1 and 4 cross"), "{e}");
}

#[test]
fn scenes_built_in_code_are_validated_without_location() {
    let mut s = screen(EXAMPLE);
    s.polygons[0].vertices[2][0] = f64::NAN;
    let e = s.validate().unwrap_err();
    assert_eq!(e.kind, SceneErrorKind::NonFinite);
    assert_eq!(
        e.to_string(),
        "polygons[0].vertices[2]: expected a finite coordinate, found NaN"
    );
    let mut s = screen(EXAMPLE);
    s.polygons[0].intensity[0][0] = f64::INFINITY;
    assert_eq!(
        s.validate().unwrap_err().to_string(),
        "polygons[0].intensity[0]: expected a finite intensity, found inf"
    );
    let mut s = screen(EXAMPLE);
    s.channels = 9;
    assert_eq!(s.validate().unwrap_err().kind, SceneErrorKind::Limit);
    let p = Polygon::uniform(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], &[0.5]);
    assert!(p.intensity.iter().all(|i| i.as_slice() == [0.5]) && p.intensity.len() == 3);
}

#[test]
fn files_are_named() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let good = dir.join("scene-good.json");
    std::fs::write(&good, EXAMPLE).unwrap();
    assert_eq!(load_scene(&good).unwrap(), Scene::Screen(screen(EXAMPLE)));
    let bad = dir.join("scene-bad.json");
    std::fs::write(&bad, variant("[0.5]", "[0.5, 1.0]")).unwrap();
    let e = load_scene(&bad).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}:6:28: polygons[0].intensity[1]: expected 1 value (the scene's channels), found 2",
            bad.display()
        )
    );
    let missing = dir.join("no-such-scene.json");
    let e = load_scene(&missing).unwrap_err();
    assert_eq!(e.kind, SceneErrorKind::Io);
    assert!(
        e.to_string()
            .starts_with(&format!("{}: cannot read the scene: ", missing.display())),
        "{e}"
    );
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>().prop_filter("finite", |x| x.is_finite()),
        -100.0..100.0f64,
        Just(-0.0),
        Just(f64::MIN_POSITIVE / 4.0),
    ]
}

proptest! {
    #[test]
    fn to_json_round_trips_bit_for_bit(
        channels in 1u8..=4,
        polys in prop::collection::vec((3usize..7, any::<u64>()), 0..4),
        seed in prop::collection::vec(any_f64(), 64),
    ) {
        let mut it = seed.iter().cycle().copied();
        let polygons: Vec<Polygon> = polys
            .iter()
            .map(|&(n, _)| Polygon::new(
                (0..n).map(|_| [it.next().unwrap(), it.next().unwrap()]).collect(),
                (0..n).map(|_| (0..channels).map(|_| it.next().unwrap()).collect()).collect::<Vec<Vec<f64>>>(),
            ))
            .collect();
        let s = ScreenScene { width: 7, height: 5, channels, polygons };
        let json = s.to_json();
        let back = only_screen(serde_json::from_str::<Scene>(&json).unwrap());
        prop_assert_eq!(back.polygons.len(), s.polygons.len());
        for (a, b) in s.polygons.iter().zip(&back.polygons) {
            for (u, v) in a.vertices.iter().flatten().zip(b.vertices.iter().flatten()) {
                prop_assert_eq!(u.to_bits(), v.to_bits());
            }
            for (u, v) in a.intensity.iter().flatten().zip(b.intensity.iter().flatten()) {
                prop_assert_eq!(u.to_bits(), v.to_bits());
            }
        }
        prop_assert_eq!(back.to_json(), json);
    }

    /// Simple (star-shaped) polygons pass validation in either orientation, and their
    /// file reads back equal.
    #[test]
    fn star_polygons_validate(
        radii in prop::collection::vec(0.5f64..10.0, 3..12),
        phase in 0.0f64..1.0,
        reverse in any::<bool>(),
    ) {
        let n = radii.len();
        let mut v: Vec<[f64; 2]> = radii.iter().enumerate().map(|(k, r)| {
            let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
            [16.0 + r * a.cos(), 16.0 + r * a.sin()]
        }).collect();
        if reverse {
            v.reverse();
        }
        let s = ScreenScene { width: 32, height: 32, channels: 1, polygons: vec![Polygon::uniform(v, &[1.0])] };
        prop_assert_eq!(s.validate(), Ok(()));
        prop_assert_eq!(parse_scene(&s.to_json()), Ok(Scene::Screen(s)));
    }
}

/// Depth: read, written back, refused where it does not fit, and evaluated on the plane.
#[test]
fn depth_is_optional_per_scene_and_checked() {
    let with = |d0: &str, d1: &str| {
        format!(
            r#"{{"kind": "screen", "width": 8, "height": 8, "channels": 1, "polygons": [
  {{"vertices": [[0, 0], [8, 0], [0, 8]], "intensity": [[1], [1], [1]], "depth": {d0}}},
  {{"vertices": [[8, 8], [8, 0], [0, 8]], "intensity": [[0], [0], [0]]{d1}}}
]}}"#
        )
    };
    let s = screen(&with("[1, 2, 3]", r#", "depth": [0.5, 0.5, 0.5]"#));
    assert_eq!(s.polygons[0].depth.as_deref(), Some(&[1.0, 2.0, 3.0][..]));
    assert_eq!(screen(&s.to_json()), s, "depth is written back");
    assert!(s.to_json().contains("\"depth\": [1.0, 2.0, 3.0]"));
    // the plane through the vertices: depth 1 + x/8 + 2y/8
    let d = s.polygons[0].depth_at([2.0, 3.0]).unwrap();
    assert!(
        (d - (1.0 + 2.0 / 8.0 + 2.0 * 3.0 / 8.0)).abs() < 1e-15,
        "{d}"
    );
    assert_eq!(s.polygons[1].depth_at([4.0, 4.0]), Some(0.5));
    // without depth: none, and nothing written
    let plain = screen(EXAMPLE);
    assert_eq!(plain.polygons[0].depth_at([1.0, 1.0]), None);
    assert!(!plain.to_json().contains("depth"));

    let e = err(&with("[1, 2, 3]", ""));
    assert_eq!(e.kind, SceneErrorKind::Shape);
    assert_eq!(e.field.as_deref(), Some("polygons[1]"));
    assert!(e.to_string().contains("all carry depth or none do"), "{e}");
    assert_eq!(e.line, Some(3), "{e}");
    let e = err(&with("[1, 2]", r#", "depth": [0, 0, 0]"#));
    assert_eq!(e.field.as_deref(), Some("polygons[0].depth"));
    assert!(
        e.to_string().contains("one depth per vertex (3), found 2"),
        "{e}"
    );
    let e = err(&with("[1, 2, \"x\"]", r#", "depth": [0, 0, 0]"#));
    assert_eq!(e.kind, SceneErrorKind::Schema, "{e}");
    let mut bad = s.clone();
    bad.polygons[1].depth = Some(vec![0.0, f64::NAN, 0.0]);
    let e = bad.validate().unwrap_err();
    assert_eq!(e.kind, SceneErrorKind::NonFinite);
    assert_eq!(e.field.as_deref(), Some("polygons[1].depth[1]"));
}

/// A repeated key is located where it repeats, whatever the first one held.
#[test]
fn a_repeated_key_is_located() {
    let e =
        err(r#"{"kind":"screen","width":4,"height":4,"channels":1,"polygons":[],"polygons":[1]}"#);
    assert_eq!(e.kind, SceneErrorKind::Schema, "{e}");
    assert!(e.to_string().contains("duplicate field `polygons`"), "{e}");
    assert_eq!((e.line, e.column.is_some()), (Some(1), true), "{e}");
}

/// Invalid UTF-8 is located by byte, line and column, and the file named.
#[test]
fn invalid_utf8_is_located() {
    let dir = std::env::temp_dir().join(format!("cwisim-scene-utf8-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.json");
    std::fs::write(&path, b"{\"kind\": \"screen\",\n  \"name\": \"caf\xe9\"}").unwrap();
    let e = cwisim_scene::load_scene(&path).unwrap_err().to_string();
    assert!(
        e.contains("bad.json") && e.contains("invalid UTF-8 at byte 33 (line 2, column 15)"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
