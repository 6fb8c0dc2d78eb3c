//! An output may not be an input, nor two outputs one file, in any command: one check
//! (`cwisim_host::files::Io`), exit 2 before any work, the file left as it was. Inputs are
//! the trace or scene, the files a scene names (OBJ meshes, texture images), the machine
//! file and the parts `tradeoff --merge` reads.

mod common;

use common::{cwisim, read, scratch, text, SMALL_TRACE};
use std::path::Path;

/// Runs `cwisim ARGS` in `dir`, expecting a usage error (exit 2) whose message contains
/// `says`, and every file in `kept` unchanged.
fn refused(dir: &Path, args: &[&str], says: &str, kept: &[&str]) {
    let before: Vec<Vec<u8>> = kept.iter().map(|f| read(dir.join(f))).collect();
    let out = cwisim(dir, args);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "cwisim {args:?}: {stderr}");
    assert!(stderr.contains(says), "cwisim {args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "one line: {stderr}");
    for (f, b) in kept.iter().zip(before) {
        assert_eq!(read(dir.join(f)), b, "cwisim {args:?} changed {f}");
    }
}

/// The embedded pot with a second, textured mesh read from an OBJ file: a scene that
/// names two other files.
fn scene_naming_files(dir: &Path) {
    let pot = cwisim(dir, &["scenes", "pot"]);
    let mut scene: serde_json::Value = serde_json::from_slice(&pot.stdout).expect("pot JSON");
    scene["width"] = 48.into();
    scene["height"] = 48.into();
    scene["meshes"][0]["material"]["texture"] = serde_json::json!({ "image": "tex.png" });
    scene["meshes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({
            "name": "tri",
            "material": { "k_a": 0.4, "k_d": 0.75, "k_s": 0.0, "n": 1 },
            "obj": "tri.obj"
        }));
    std::fs::write(dir.join("scene.json"), scene.to_string()).unwrap();
    std::fs::write(dir.join("tri.obj"), "v -1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    // a 2×2 grey PNG
    let img = image::GrayImage::from_raw(2, 2, vec![10, 200, 200, 10]).unwrap();
    img.save(dir.join("tex.png")).unwrap();
}

#[test]
fn the_scene_files_it_names_are_inputs() {
    let dir = scratch("output-is-input-scene");
    scene_naming_files(&dir);
    // the scene draws: the check refuses only what it must
    let ok = cwisim(&dir, &["render", "scene.json", "-o", "out.png", "-q"]);
    assert_eq!(ok.status.code(), Some(0), "{:?}", text(&ok));
    let kept = ["scene.json", "tex.png", "tri.obj"];
    refused(
        &dir,
        &["render", "scene.json", "-o", "tex.png"],
        "-o tex.png would overwrite the file the scene names at meshes[0].material.texture.image",
        &kept,
    );
    refused(
        &dir,
        &["render", "scene.json", "--stats-json", "./tri.obj"],
        "would overwrite the file the scene names at meshes[1].obj",
        &kept,
    );
    refused(
        &dir,
        &["emit", "scene.json", "-o", "scene.json"],
        "would overwrite the scene",
        &kept,
    );
    refused(
        &dir,
        &["refine", "scene.json", "--ids", "tex.png"],
        "would overwrite the file the scene names",
        &kept,
    );
    refused(
        &dir,
        &["tradeoff", "scene.json", "--plot", "tex.png"],
        "would overwrite the file the scene names",
        &kept,
    );
    refused(
        &dir,
        &["stats", "scene.json", "--plot", "tex.png"],
        "would overwrite the file the input names",
        &kept,
    );
    refused(
        &dir,
        &[
            "diff",
            "pot",
            "scene.json",
            "--outputs",
            "--image",
            "tex.png",
        ],
        "would overwrite the file the side B names",
        &kept,
    );
    // a scene in another directory names files relative to it
    std::fs::create_dir(dir.join("sub")).unwrap();
    refused(
        &Path::new(&dir).join("sub"),
        &["render", "../scene.json", "-o", "../tex.png"],
        "would overwrite the file the scene names",
        &[],
    );
}

#[test]
fn the_machine_file_and_the_trace_are_inputs() {
    let dir = scratch("output-is-input-machine");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).unwrap();
    std::fs::write(dir.join("m.json"), "{\"clock_hz\": 2e8}\n").unwrap();
    let kept = ["t.cwt", "m.json"];
    refused(
        &dir,
        &[
            "run",
            "t.cwt",
            "--machine",
            "m.json",
            "--stats-json",
            "m.json",
        ],
        "--stats-json m.json would overwrite the machine file",
        &kept,
    );
    refused(
        &dir,
        &["stats", "t.cwt", "--machine", "m.json", "--csv", "m.json"],
        "would overwrite the machine file",
        &kept,
    );
    refused(
        &dir,
        &["render", "fig25", "--machine", "m.json", "--npy", "m.json"],
        "would overwrite the machine file",
        &kept,
    );
    refused(
        &dir,
        &["vcd", "t.cwt", "--line", "0", "-o", "t.cwt"],
        "would overwrite the trace being read",
        &kept,
    );
    refused(
        &dir,
        &[
            "rtl",
            "--for",
            "t.cwt",
            "--numeric",
            "fixed:I=2.15,dI=1.16,ddI=1.16",
            "-o",
            "t.cwt",
        ],
        "-o t.cwt would overwrite the --for input",
        &kept,
    );
    refused(
        &dir,
        &[
            "rtl",
            "--numeric",
            "fixed:I=2.15,dI=1.16,ddI=1.16",
            "--machine",
            "m.json",
            "-o",
            "m.json",
        ],
        "would overwrite the machine file",
        &kept,
    );
    refused(
        &dir,
        &["convert", "t.cwt", "./t.cwt"],
        "would overwrite the trace being read",
        &kept,
    );
}

#[test]
fn two_outputs_may_not_be_one_file() {
    let dir = scratch("output-is-input-twice");
    std::fs::write(dir.join("same.v"), b"old").unwrap();
    refused(
        &dir,
        &[
            "rtl",
            "--numeric",
            "fixed:I=2.15,dI=1.16,ddI=1.16",
            "-o",
            "same.v",
            "--testbench",
            "./same.v",
        ],
        "-o and --testbench both name ./same.v",
        &["same.v"],
    );
    std::fs::write(dir.join("a.csv"), b"old").unwrap();
    refused(
        &dir,
        &["tradeoff", "--merge", "a.csv", "--csv", "a.csv"],
        "--csv a.csv would overwrite the part being merged",
        &["a.csv"],
    );
    // a device may be named twice
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).unwrap();
    let out = cwisim(
        &dir,
        &[
            "run",
            "t.cwt",
            "--npy",
            "/dev/null",
            "--stats-json",
            "/dev/null",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
}
