//! The OBJ reader on arbitrary bytes, as a world scene draws an OBJ file (seeds:
//! `fuzz/seeds/obj/`, `fuzz/seed-corpus.sh`). The input is written to a temporary file
//! that a fixed world scene names; its faults must be located in that file.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("cwisim-fuzz-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        dir
    })
}

/// A world scene drawing `mesh.obj`.
const SCENE: &str = r#"{
  "kind": "world", "width": 32, "height": 24, "channels": 1,
  "camera": { "eye": [0.3, 0.4, 6], "target": [0, 0, 0], "fov_y": 40 },
  "ambient": 0.2, "lights": [ { "position": [2, 3, 4], "intensity": 0.8 } ],
  "meshes": [ { "material": { "k_a": 0.3, "k_d": 0.6, "k_s": 0.2, "n": 8 },
                "two_sided": true, "obj": "mesh.obj" } ]
}"#;

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let path = dir().join("mesh.obj");
    std::fs::write(&path, bytes).expect("write the OBJ file");
    if let Some(e) = cwisim_fuzz::any_scene(SCENE, dir()) {
        if e.path.as_deref() == Some(path.as_path()) && e.line.is_some() {
            cwisim_fuzz::located(&String::from_utf8_lossy(bytes), &e);
        }
    }
});
