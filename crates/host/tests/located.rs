//! Errors found after a scene is read are located as reading errors are: a light that
//! cannot cast shadows at its JSON path's line and column in the scene file, an OBJ
//! face's fault at the face's line in the OBJ file, an OBJ `vt` out of range at its line.
//! Each is one line on standard error and exit 2.

mod common;

use common::{cwisim, scratch, text};
use std::path::Path;

/// Runs `cwisim ARGS` in `dir`: exit 2 and the one line of standard error.
fn refused(dir: &Path, args: &[&str]) -> String {
    let out = cwisim(dir, args);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "cwisim {args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    stderr
}

/// A world scene of one OBJ mesh `m.obj`, with one light at `light`, casting shadows.
fn obj_scene(dir: &Path, light: [f64; 3], obj: &str) {
    let scene = serde_json::json!({
        "kind": "world", "width": 32, "height": 24, "channels": 1,
        "camera": { "eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40 },
        "ambient": 0.3,
        "lights": [ { "position": light, "intensity": 0.8, "shadows": true } ],
        "meshes": [ { "name": "m", "material": { "k_a": 0.5, "k_d": 0.5, "k_s": 0, "n": 1 },
                      "obj": "m.obj" } ]
    });
    std::fs::write(
        dir.join("s.json"),
        serde_json::to_string_pretty(&scene).unwrap(),
    )
    .unwrap();
    std::fs::write(dir.join("m.obj"), obj).unwrap();
}

const TWO_TRIANGLES: &str =
    "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv -1 -1 1\nv 1 -1 1\nv 0 1 1\nf 1 2 3\nf 4 5 6\n";

#[test]
fn a_light_that_cannot_cast_shadows_is_located_in_the_scene_file() {
    let dir = scratch("located-light");
    // between the two triangles: it sees them on both sides
    obj_scene(&dir, [0.0, 0.0, 0.5], TWO_TRIANGLES);
    let stderr = refused(&dir, &["render", "s.json", "-o", "x.png"]);
    let text = std::fs::read_to_string(dir.join("s.json")).unwrap();
    let line = 1 + text
        .lines()
        .position(|l| l.contains("\"position\""))
        .unwrap();
    assert!(
        stderr.starts_with(&format!("error: s.json:{line}:")),
        "{stderr}"
    );
    assert!(stderr.contains("lights[0].position: light 0"), "{stderr}");
    // a light that can is drawn
    obj_scene(&dir, [0.0, 0.5, 6.0], TWO_TRIANGLES);
    let out = cwisim(&dir, &["render", "s.json", "-o", "x.png", "-q"]);
    assert_eq!(out.status.code(), Some(0), "{:?}", common::text(&out));
}

#[test]
fn an_obj_face_s_fault_names_its_line_in_the_obj_file() {
    let dir = scratch("located-obj-face");
    // face 1, on line 6: three collinear corners
    obj_scene(
        &dir,
        [0.0, 0.5, 6.0],
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv 2 2 0\n# collinear\nf 1 2 3\nf 1 2 2\n",
    );
    let stderr = refused(&dir, &["render", "s.json", "-o", "x.png"]);
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(
        stderr.contains("m.obj:7:1: face 1: degenerate face"),
        "{stderr}"
    );
    // a zero normal given at a corner: the face that uses it
    obj_scene(
        &dir,
        [0.0, 0.5, 6.0],
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 0\nf 1//1 2//1 3//1\n\nf 1//1 2//1 3//2\n",
    );
    let stderr = refused(&dir, &["render", "s.json", "-o", "x.png"]);
    assert!(
        stderr.contains("m.obj:8:1: face 1: a given normal is zero or not finite"),
        "{stderr}"
    );
}

#[test]
fn obj_texture_coordinates_are_range_checked_as_inline_ones_are() {
    let dir = scratch("located-obj-vt");
    obj_scene(
        &dir,
        [0.0, 0.5, 6.0],
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1e300 1e300\nvt 0 1\nf 1/1 2/2 3/3\n",
    );
    let stderr = refused(&dir, &["render", "s.json", "-o", "x.png"]);
    assert!(
        stderr.contains("m.obj:5:1: expected texture coordinates within ±1e9"),
        "{stderr}"
    );
}
