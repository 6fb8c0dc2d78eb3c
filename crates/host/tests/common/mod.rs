//! Helpers shared by the integration tests: scratch directories and running the real
//! `cwisim` binary in them.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The canonical text of the small test trace: an 8-processor grey array, two scanlines.
pub const SMALL_TRACE: &str = "\
cwisim-trace version=1 width=8 lines=2 channels=1
Eval2 2 4 0.5 0.125
Refresh
Eval1 0 8 1.0
Refresh
";

/// An empty directory for one test, under Cargo's per-target scratch directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cwisim-host")
        .join(name);
    if dir.exists() {
        std::fs::remove_dir_all(&dir).expect("clear the scratch dir");
    }
    std::fs::create_dir_all(&dir).expect("create the scratch dir");
    dir
}

/// Runs `cwisim ARGS` with `dir` as its working directory (so messages name files
/// relative to it).
pub fn cwisim(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run the cwisim binary")
}

/// Standard output and standard error as text.
pub fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs `cwisim ARGS`, asserting success and an empty standard error.
pub fn cwisim_ok(dir: &Path, args: &[&str]) -> String {
    let out = cwisim(dir, args);
    let (stdout, stderr) = text(&out);
    assert_eq!(
        out.status.code(),
        Some(0),
        "cwisim {args:?} failed: {stderr}"
    );
    assert!(
        stderr.is_empty(),
        "cwisim {args:?} wrote to stderr: {stderr}"
    );
    stdout
}

/// Reads a file that must exist.
pub fn read(path: impl AsRef<Path>) -> Vec<u8> {
    let path = path.as_ref();
    std::fs::read(path).unwrap_or_else(|e| panic!("read {}: {e}", path.display()))
}

/// The shape and values of a `.npy` file.
pub fn read_npy(path: impl AsRef<Path>) -> (Vec<u64>, Vec<f64>) {
    let bytes = read(path);
    let npy = npyz::NpyFile::new(&bytes[..]).expect("a .npy header");
    let shape = npy.shape().to_vec();
    (shape, npy.into_vec::<f64>().expect("float64 data"))
}

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A checked-in example trace, by file name, as a command-line argument.
pub fn trace(name: &str) -> String {
    repo()
        .join("traces")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// The scene of the report's figure 25, as a command-line argument.
pub fn fig25() -> String {
    repo()
        .join("crates/ypipe/tests/fixtures/fig25.json")
        .to_string_lossy()
        .into_owned()
}

/// A PNG chunk: length, type, data, CRC.
pub fn png_chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut c = (data.len() as u32).to_be_bytes().to_vec();
    c.extend_from_slice(kind);
    c.extend_from_slice(data);
    let mut crc = crc32fast::Hasher::new();
    crc.update(kind);
    crc.update(data);
    c.extend_from_slice(&crc.finalize().to_be_bytes());
    c
}

/// A small world scene of two bicubic Bézier patches, 32×32: a flat one, and a dome in
/// front of it, partly hiding it (drawn after it: overdraw has something to undo).
pub fn patch_scene() -> String {
    let mut vertices = Vec::new();
    for (x0, z0, bump, size) in [(0.9, -0.8, 0.3, 2.4), (0.0, 0.0, 1.2, 2.0)] {
        for j in 0..4 {
            for i in 0..4 {
                let inner = (1..=2).contains(&i) && (1..=2).contains(&j);
                let x = x0 + size * (f64::from(i) - 1.5) / 3.0;
                let y = size * (f64::from(j) - 1.5) / 3.0;
                let z = z0 + if inner { bump } else { 0.0 };
                vertices.push(format!("[{x}, {y}, {z}]"));
            }
        }
    }
    let indices = |r: std::ops::Range<u32>| r.map(|k| k.to_string()).collect::<Vec<_>>().join(", ");
    format!(
        r#"{{"kind": "world", "width": 32, "height": 32, "channels": 1,
"camera": {{"eye": [0.3, 0.4, 5], "target": [0.2, 0, 0], "up": [0, 1, 0], "fov_y": 40}},
"ambient": 0.2, "lights": [{{"position": [2, 3, 6], "intensity": 0.8}}],
"meshes": [{{"material": {{"k_a": 0.4, "k_d": 0.7, "k_s": 0.6, "n": 20}}, "two_sided": true,
  "bezier": {{"tessellate": 3, "vertices": [{}], "patches": [[{}], [{}]]}}}}]}}"#,
        vertices.join(", "),
        indices(0..16),
        indices(16..32)
    )
}
