//! Bézier mesh sources in world scenes: bad ones refused with their JSON path, and the
//! embedded Utah teapot — its table equal to the shared source data, and its tessellated
//! mesh closed wherever patches meet.

use cwisim_scene::SceneErrorKind;
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, AnyScene};
use std::collections::HashMap;

/// A one-patch scene (a flat 4×4 grid of control points) with `bezier` replaced.
fn scene(bezier: &str) -> String {
    format!(
        r#"{{
  "kind": "world", "width": 32, "height": 24, "channels": 1,
  "camera": {{ "eye": [0, 0, 5], "target": [0, 0, 0], "fov_y": 40 }},
  "ambient": 0.2,
  "lights": [ {{ "position": [2, 3, 4], "intensity": 0.8 }} ],
  "meshes": [
    {{ "material": {{ "k_a": 0.3, "k_d": 0.6, "k_s": 0.2, "n": 8 }},
      "bezier": {bezier} }}
  ]
}}"#
    )
}

fn flat(patches: &str, tessellate: &str) -> String {
    let mut v = Vec::new();
    for r in 0..4 {
        for c in 0..4 {
            v.push(format!(
                "[{}, {}, 0]",
                c as f64 / 3.0 - 0.5,
                r as f64 / 3.0 - 0.5
            ));
        }
    }
    format!(
        r#"{{ "vertices": [{}], "patches": {patches}, "tessellate": {tessellate} }}"#,
        v.join(", ")
    )
}

const ONE: &str = "[[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]]";

#[test]
fn a_flat_patch_reads_and_tessellates() {
    let AnyScene::World(w) = parse_any(&scene(&flat(ONE, "3")), None).expect("good") else {
        panic!("a world scene")
    };
    let faces = &w.meshes[0].faces;
    assert_eq!(faces.len(), 2 * 3 * 3);
    for f in faces {
        for n in &f.normals {
            assert!((n.z.abs() - 1.0).abs() < 1e-12, "{n}");
        }
    }
}

#[test]
fn bad_bezier_sources_are_refused_with_their_path() {
    let cases = [
        (
            flat("[[0, 1, 2]]", "3"),
            SceneErrorKind::Shape,
            "meshes[0].bezier.patches[0]: expected 16 control-point indices (4×4, row-major), found 3",
        ),
        (
            flat("[[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 16]]", "3"),
            SceneErrorKind::Shape,
            "meshes[0].bezier.patches[0][15]: vertex index 16 is out of range: there are 16 vertices (indices from 0)",
        ),
        (
            flat("[]", "3"),
            SceneErrorKind::Shape,
            "meshes[0].bezier.patches: expected at least one patch",
        ),
        (
            flat(ONE, "0"),
            SceneErrorKind::Limit,
            "meshes[0].bezier.tessellate: expected quads per patch side in 1..=128, found 0",
        ),
        (
            flat(ONE, "129"),
            SceneErrorKind::Limit,
            "meshes[0].bezier.tessellate: expected quads per patch side in 1..=128, found 129",
        ),
        (
            flat(ONE, "3").replace("[-0.5, -0.5, 0]", "[-0.5, -0.5, 1e300]"),
            SceneErrorKind::Limit,
            "meshes[0].bezier.vertices[0]: coordinate 1e300 is beyond ±1e9",
        ),
    ];
    for (bezier, kind, shown) in cases {
        let e = parse_any(&scene(&bezier), None).expect_err("refused");
        assert_eq!(e.kind, kind, "{e}");
        assert!(e.to_string().ends_with(shown), "{e}\nexpected …{shown}");
        assert!(e.line.is_some(), "located: {e}");
    }
    // too many triangles in all
    let many = format!("[{}]", vec![&ONE[1..ONE.len() - 1]; 600].join(", "));
    let e = parse_any(&scene(&flat(&many, "64")), None).expect_err("refused");
    assert!(e.to_string().contains("the limit is 4194304"), "{e}");
    // a patch whose control points all coincide has no surface
    let dot = r#"{ "vertices": [[0, 0, 0]], "patches": [[0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]], "tessellate": 2 }"#;
    let e = parse_any(&scene(dot), None).expect_err("refused");
    assert_eq!(e.kind, SceneErrorKind::Geometry, "{e}");
    // two sources
    let both = scene(&flat(ONE, "3")).replace(r#""bezier""#, r#""obj": "x.obj", "bezier""#);
    let e = parse_any(&both, None).expect_err("refused");
    assert!(
        e.to_string().contains("expected only one geometry source"),
        "{e}"
    );
}

/// The embedded teapot's table is the shared source's, entry for entry.
#[test]
fn the_teapot_table_is_newells_with_crows_bottom() {
    let text = embedded("teapot").expect("embedded").text;
    let ours: serde_json::Value = serde_json::from_str(text).unwrap();
    let bezier = &ours["meshes"][0]["bezier"];
    // the project's copy of shared/data/teapot-spd.json (tests/data/README.md)
    let source: serde_json::Value =
        serde_json::from_str(include_str!("data/teapot-spd.json")).unwrap();
    assert_eq!(bezier["patches"], source["patches"]);
    let (a, b) = (
        bezier["vertices"].as_array().unwrap(),
        source["vertices"].as_array().unwrap(),
    );
    assert_eq!((a.len(), b.len()), (290, 290));
    for (p, q) in a.iter().zip(b) {
        for k in 0..3 {
            assert_eq!(p[k].as_f64(), q[k].as_f64());
        }
    }
    assert_eq!(bezier["patches"].as_array().unwrap().len(), 32);
}

/// The tessellated teapot is closed where patches meet: every edge (by the bits of its
/// end points) is used by two triangles, except along the open boundaries — the rim's
/// inside and the lid's outside (4 + 4 patch edges), and the handle's and the spout's
/// two ends (4 patch edges each) — which are used once: 16 patch edges of `n` segments.
/// (At `n = 1` the upper and lower halves of the handle's and the spout's cross-sections
/// both become the chord between the same two corners, so from `n = 2` on.)
#[test]
fn the_tessellated_teapot_has_no_cracks() {
    for n in [2u32, 3, 8] {
        let text = embedded("teapot")
            .unwrap()
            .text
            .replace(r#""tessellate": 8"#, &format!(r#""tessellate": {n}"#));
        let AnyScene::World(w) = parse_any(&text, None).expect("teapot") else {
            panic!("world")
        };
        let mesh = &w.meshes[0];
        let key = |i: u32| mesh.positions[i as usize].to_array().map(f64::to_bits);
        let mut uses: HashMap<([u64; 3], [u64; 3]), u32> = HashMap::new();
        for f in &mesh.faces {
            for k in 0..f.corners.len() {
                let (a, b) = (key(f.corners[k]), key(f.corners[(k + 1) % f.corners.len()]));
                *uses.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
            }
        }
        let once = uses.values().filter(|&&u| u == 1).count();
        let more = uses.values().filter(|&&u| u > 2).count();

        assert_eq!(more, 0, "n = {n}: an edge used by more than two triangles");
        assert_eq!(once, 16 * n as usize, "n = {n}: open edges");
    }
}
