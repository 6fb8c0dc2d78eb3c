//! Errors found after a scene is read are located as reading errors are: a light that
//! cannot cast shadows at its JSON path's line and column in the scene file, an OBJ
//! face's fault at the face's line in the OBJ file, an OBJ `vt` out of range at its line.
//! Each is one line on standard error and exit 2.

mod common;

use common::{cwisim, png_chunk, scratch, text};
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
    // on a vertex of the first triangle
    obj_scene(&dir, [1.0, -1.0, 0.0], TWO_TRIANGLES);
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
    // a light that can is drawn, one between the triangles too (it sees them on both
    // sides, through a cube's six views)
    obj_scene(&dir, [0.0, 0.0, 0.5], TWO_TRIANGLES);
    let out = cwisim(&dir, &["render", "s.json", "-o", "x.png", "-q"]);
    assert_eq!(out.status.code(), Some(0), "{:?}", common::text(&out));
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

#[test]
fn a_texture_that_fails_to_decode_when_first_needed_is_located_and_nothing_is_written() {
    let dir = scratch("located-texture");
    // a valid header (8×8, 8-bit RGB), then image data that is not a zlib stream: the
    // scene reads (the size is the header's), the texels fail when first shaded
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(png_chunk(b"IHDR", &[0, 0, 0, 8, 0, 0, 0, 8, 8, 2, 0, 0, 0]));
    png.extend(png_chunk(b"IDAT", b"not zlib at all"));
    png.extend(png_chunk(b"IEND", &[]));
    std::fs::write(dir.join("t.png"), &png).unwrap();
    let scene = serde_json::json!({
        "kind": "world", "width": 32, "height": 24, "channels": 3,
        "camera": { "eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40 },
        "ambient": 0.5, "lights": [],
        "meshes": [ { "name": "quad", "material": { "k_a": 1, "k_d": 0, "k_s": 0, "n": 1,
                                                     "texture": { "image": "t.png" } },
                      "vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],
                      "uv": [[0, 0], [1, 0], [1, 1], [0, 1]],
                      "faces": [[0, 1, 2, 3]] } ]
    });
    let text = serde_json::to_string_pretty(&scene).unwrap();
    std::fs::write(dir.join("s.json"), &text).unwrap();
    let line = 1 + text.lines().position(|l| l.contains("\"image\"")).unwrap();
    for renderer in ["vanrij", "woo-chall", "sbuffer", "bsp", "refine"] {
        std::fs::write(dir.join("old.png"), b"the old file").unwrap();
        let stderr = refused(
            &dir,
            &["render", "s.json", "--renderer", renderer, "-o", "old.png"],
        );
        assert!(
            stderr.starts_with(&format!("error: s.json:{line}:"))
                && stderr.contains(
                    "meshes[0].material.texture.image: texture \"t.png\": not a readable PNG image"
                ),
            "{renderer}: {stderr}"
        );
        assert_eq!(
            std::fs::read(dir.join("old.png")).unwrap(),
            b"the old file",
            "{renderer}: the old output replaced"
        );
    }
}
