//! Bad texture inputs, each a located error before anything is allocated for the
//! texture: the scene file, the line and column of the value, its JSON path, and what
//! was expected. And the texture coordinates each geometry source gives.

use cwisim_world::{load_any, AnyScene};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cwisim-texin-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A scene file in `d` with one square whose material's texture is `texture` and whose
/// extra keys (`uv`) are `extra`.
fn scene(d: &Path, texture: &str, extra: &str) -> PathBuf {
    let text = format!(
        r#"{{
  "kind": "world", "width": 32, "height": 32, "channels": 3,
  "camera": {{ "eye": [0, 0, 10], "target": [0, 0, 0], "fov_y": 30 }},
  "ambient": 1,
  "meshes": [ {{
    "material": {{ "k_a": 1, "k_d": 0, "k_s": 0, "n": 1,
      "texture": {texture} }},
    "vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]],{extra}
    "faces": [[0, 1, 2, 3]] }} ] }}
"#
    );
    let path = d.join("scene.json");
    std::fs::write(&path, text).unwrap();
    path
}

const UV: &str = r#"
    "uv": [[0, 0], [1, 0], [1, 1], [0, 1]],"#;

fn error(texture: &str, extra: &str, name: &str, setup: impl FnOnce(&Path)) -> String {
    let d = dir(name);
    setup(&d);
    let path = scene(&d, texture, extra);
    load_any(&path).unwrap_err().to_string()
}

#[test]
fn a_missing_texture_names_the_scene_s_line_the_field_and_the_file() {
    let e = error(r#"{ "image": "nope.png" }"#, UV, "missing", |_| {});
    assert!(e.contains("scene.json:7:29: "), "{e}");
    assert!(
        e.contains("meshes[0].material.texture.image: texture \"nope.png\": cannot read it"),
        "{e}"
    );
}

#[test]
fn a_file_that_is_not_a_png_is_refused() {
    let e = error(r#"{ "image": "t.png" }"#, UV, "notpng", |d| {
        std::fs::write(d.join("t.png"), "P3 1 1 255 0 0 0").unwrap()
    });
    assert!(
        e.contains("texture \"t.png\": not a readable PNG image"),
        "{e}"
    );
}

#[test]
fn an_empty_file_is_refused() {
    let e = error(r#"{ "image": "t.png" }"#, UV, "empty", |d| {
        std::fs::write(d.join("t.png"), "").unwrap()
    });
    assert!(e.contains("not a readable PNG image"), "{e}");
}

#[test]
fn a_directory_is_refused() {
    let e = error(r#"{ "image": "sub" }"#, UV, "directory", |d| {
        std::fs::create_dir_all(d.join("sub")).unwrap()
    });
    assert!(e.contains("not a regular file"), "{e}");
}

#[test]
fn a_texture_over_the_texel_limit_is_refused_from_its_header() {
    let e = error(r#"{ "image": "big.png" }"#, UV, "big", |d| {
        // 2049 × 2049 black: a small file, 4,198,401 texels
        image::GrayImage::new(2049, 2049)
            .save(d.join("big.png"))
            .unwrap()
    });
    assert!(
        e.contains("2049×2049 = 4198401 texels; the limit is 4194304"),
        "{e}"
    );
}

#[test]
fn a_textured_mesh_without_texture_coordinates_is_refused() {
    let e = error(
        r#"{ "checker": { "squares": [2, 2] } }"#,
        "",
        "nouv",
        |_| {},
    );
    assert!(
        e.contains("meshes[0].material.texture: mesh \"mesh 0\" has no texture coordinates"),
        "{e}"
    );
}

#[test]
fn texture_coordinates_must_match_the_vertices() {
    let e = error(
        r#"{ "checker": { "squares": [2, 2] } }"#,
        r#"
    "uv": [[0, 0], [1, 0]],"#,
        "uvcount",
        |_| {},
    );
    assert!(
        e.contains("meshes[0].uv: expected one [u, v] per vertex (4), found 2"),
        "{e}"
    );
}

#[test]
fn a_texture_is_an_image_or_a_checker_not_both_nor_neither() {
    for (texture, name) in [
        (
            r#"{ "image": "t.png", "checker": { "squares": [2, 2] } }"#,
            "both",
        ),
        (r#"{ "repeat": [2, 2] }"#, "neither"),
    ] {
        let e = error(texture, UV, name, |_| {});
        assert!(
            e.contains("meshes[0].material.texture: expected exactly one of \"image\""),
            "{e}"
        );
    }
}

#[test]
fn checker_and_repeat_out_of_range_name_their_value() {
    let e = error(
        r#"{ "checker": { "squares": [2, 0] } }"#,
        UV,
        "squares",
        |_| {},
    );
    assert!(
        e.contains(
            "meshes[0].material.texture.checker.squares[1]: expected 1..=2048 squares, found 0"
        ),
        "{e}"
    );
    let e = error(
        r#"{ "checker": { "squares": [2, 2] }, "repeat": [1, -2] }"#,
        UV,
        "repeat",
        |_| {},
    );
    assert!(e.contains("meshes[0].material.texture.repeat[1]"), "{e}");
    let e = error(
        r#"{ "checker": { "squares": [2, 2], "dark": [1, 2] } }"#,
        UV,
        "channels",
        |_| {},
    );
    assert!(e.contains("meshes[0].material.texture.checker.dark"), "{e}");
    let e = error(
        r#"{ "checker": { "squares": [2, 2], "colour": 1 } }"#,
        UV,
        "unknown",
        |_| {},
    );
    assert!(e.contains("unknown field `colour`"), "{e}");
}

#[test]
fn every_geometry_source_gives_texture_coordinates() {
    let d = dir("sources");
    std::fs::write(
        d.join("square.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    std::fs::write(
        d.join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 zero\nf 1/1 2/1 3/1\n",
    )
    .unwrap();
    let texture = r#""texture": { "checker": { "squares": [2, 2] } }"#;
    let text = |geometry: &str| {
        format!(
            r#"{{ "kind": "world", "width": 32, "height": 32, "channels": 1,
  "camera": {{ "eye": [0, 2, 12], "target": [0, 0, 0], "fov_y": 40 }}, "ambient": 1,
  "meshes": [ {{ "material": {{ "k_a": 1, "k_d": 0, "k_s": 0, "n": 1, {texture} }}, {geometry} }} ] }}"#
        )
    };
    let load = |geometry: &str| {
        let path = d.join("scene.json");
        std::fs::write(&path, text(geometry)).unwrap();
        load_any(&path)
    };
    let obj = load(r#""obj": "square.obj""#).unwrap();
    let AnyScene::World(w) = obj else { panic!() };
    assert_eq!(
        w.meshes[0].faces[0].uv[..],
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    );
    let e = load(r#""obj": "bad.obj""#).unwrap_err().to_string();
    assert!(e.contains("bad.obj:4:"), "{e}");
    let rev =
        load(r#""revolution": { "profile": [[0, 0], [1, 0], [1, 2]], "segments": 4 }"#).unwrap();
    let AnyScene::World(w) = rev else { panic!() };
    // u the angle over a turn (the seam's last face ends at u = 1), v the length along
    // the profile over its whole (1 + 2 = 3)
    let uv: Vec<[f64; 2]> = w.meshes[0]
        .faces
        .iter()
        .flat_map(|f| f.uv.clone())
        .collect();
    assert!(uv.contains(&[1.0, 1.0 / 3.0]), "{uv:?}");
    assert!(uv.contains(&[0.0, 1.0]), "{uv:?}");
    assert!(uv
        .iter()
        .all(|t| (0.0..=1.0).contains(&t[0]) && (0.0..=1.0).contains(&t[1])));
    let teapot = cwisim_world::embedded::embedded("teapot-textured").unwrap();
    let AnyScene::World(w) = cwisim_world::parse_any(teapot.text, None).unwrap() else {
        panic!()
    };
    // each patch's grid spans its own [0, 1]²
    let uv: Vec<[f64; 2]> = w.meshes[0]
        .faces
        .iter()
        .flat_map(|f| f.uv.clone())
        .collect();
    assert!(uv.contains(&[0.0, 0.0]) && uv.contains(&[1.0, 1.0]));
    assert!(uv.contains(&[0.125, 0.875]));
}

#[test]
fn textures_past_the_memory_budget_are_refused_before_any_is_built() {
    // 70 grey checkerboards of 2048 × 2048: 67 MB each with their tables, 4.7 GB in all,
    // over the default budget of 4 GiB — refused from their sizes, nothing allocated
    let meshes: Vec<String> = (0..70)
        .map(|k| {
            format!(
                r#"{{ "material": {{ "k_a": 1, "k_d": 0, "k_s": 0, "n": 1,
      "texture": {{ "checker": {{ "squares": [2048, 2048] }} }} }},
    "vertices": [[-1, -1, {k}], [1, -1, {k}], [1, 1, {k}], [-1, 1, {k}]],
    "uv": [[0, 0], [1, 0], [1, 1], [0, 1]], "faces": [[0, 1, 2, 3]] }}"#
            )
        })
        .collect();
    let text = format!(
        r#"{{ "kind": "world", "width": 32, "height": 32, "channels": 1,
  "camera": {{ "eye": [0, 0, 100], "target": [0, 0, 0], "fov_y": 30 }}, "ambient": 1,
  "meshes": [ {} ] }}"#,
        meshes.join(",\n")
    );
    let e = cwisim_world::parse_any(&text, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("meshes[63].material.texture: the scene's textures"),
        "{e}"
    );
    assert!(e.contains("over the budget"), "{e}");
}
