//! Fuzzing the scene reader of every kind, [`parse_any`] (world scenes with inline meshes,
//! surfaces of revolution, Bézier patches and OBJ files; screen scenes), with untrusted
//! input (proptest): arbitrary bytes and strings, and structure-aware mutations of the
//! scenes in `crates/world/scenes/` (the teapot shrunk to `"tessellate": 1`: 64
//! triangles rather than 4,032) and of OBJ files read through a world scene (temporary
//! files under `CARGO_TARGET_TMPDIR`).
//!
//! Properties of every input: the reader does not panic; it finishes in well under
//! [`TIME_BOUND`] (a bound to catch hangs, not to measure speed); every refusal is
//! located — a line and column inside the scene's text, or else the JSON path of the
//! value at fault; for a fault of the OBJ file, that file and a line in it — with a
//! one-line, non-empty message; and every acceptance writes back (the world scene's spec
//! through serde, a screen scene through `to_json`) to text that reads back equal.
//!
//! Cases per run (debug, 2 cores: about 1.5 s in all): `arbitrary_bytes` 512,
//! `arbitrary_text` 512, `mutated_scenes` 2048, `mutated_obj_files` 768 (temp files), and
//! two fixed tests.

use cwisim_fuzzing::{apply, check_text_location, config, mutation, TIME_BOUND};
use cwisim_scene::SceneError;
use cwisim_world::{parse_any, AnyScene};
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

/// The seed scenes (every scene of `crates/world/scenes/`), as text.
fn seeds() -> &'static [String] {
    static SEEDS: OnceLock<Vec<String>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
            .expect("scenes/")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        paths.sort();
        assert!(paths.len() >= 5, "scenes in {}", dir.display());
        let texts: Vec<String> = paths
            .iter()
            .map(|p| {
                let text = std::fs::read_to_string(p).expect("seed scene");
                // the teapot, 32 patches, at 1 × 1 quads per patch: 64 triangles
                let shrunk = text.replace("\"tessellate\": 8", "\"tessellate\": 1");
                parse_any(&shrunk, None).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
                shrunk
            })
            .collect();
        assert!(
            texts.iter().any(|t| t.contains("\"tessellate\": 1")),
            "the teapot shrunk"
        );
        texts
    })
}

/// OBJ files: quads with normals, triangles with texture coordinates and negative
/// indices, a face with five corners.
const OBJ_SEEDS: [&str; 3] = [
    "# a cube\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
     vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n\
     f 1//1 4//1 3//1 2//1\nf 5//2 6//2 7//2 8//2\nf 1//3 2//3 6//3 5//3\n\
     f 4//4 8//4 7//4 3//4\nf 1//5 5//5 8//5 4//5\nf 2//6 3//6 7//6 6//6\n",
    "o tetra\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n\
     f 1/1 3/3 2/2\nf -4/1 -3/2 -1/3\ng side\nf 1/1/ 4/3 3/2\nf 2 3 4\n",
    "mtllib none.mtl\nusemtl x\nv 0 0 0 1\nv 1 0 0\nv 1.3 0.8 0\nv 0.5 1.4 0\nv -0.3 0.8 0\n\
     s off\nf 1 2 3 4 5\nl 1 2\np 3\n",
];

/// A world scene drawing the OBJ file `name`.
fn obj_scene(name: &str) -> String {
    format!(
        "{{\n  \"kind\": \"world\", \"width\": 32, \"height\": 24, \"channels\": 1,\n  \
         \"camera\": {{ \"eye\": [0.3, 0.4, 6], \"target\": [0, 0, 0], \"fov_y\": 40 }},\n  \
         \"ambient\": 0.2,\n  \"lights\": [ {{ \"position\": [2, 3, 4], \"intensity\": 0.8 }} ],\n  \
         \"meshes\": [\n    {{ \"material\": {{ \"k_a\": 0.3, \"k_d\": 0.6, \"k_s\": 0.2, \"n\": 8 }},\n      \
         \"two_sided\": true, \"obj\": {name:?} }}\n  ]\n}}\n"
    )
}

/// The directory of the OBJ files (and the base of every scene read, so that a mutated
/// `"obj"` can name nothing outside it): one, reused by every run.
fn tmp_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("world-fuzz");
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    })
}

/// The message is one non-empty printable line, even where it echoes the input (an
/// unknown key, an `"obj"` path with an escaped line break): the display escapes it.
fn check_message(_text: &str, e: &SceneError) -> Result<(), TestCaseError> {
    prop_assert!(!e.message.trim().is_empty(), "empty message: {e:?}");
    prop_assert!(
        !e.to_string().contains(|c: char| c.is_control()),
        "message of more than one printable line: {e:?}"
    );
    Ok(())
}

/// Checks that `e` is located in `text` (a line and column within it), or else names
/// the JSON path at fault.
fn check_located(text: &str, e: &SceneError) -> Result<(), TestCaseError> {
    let has_field = e.field.as_deref().is_some_and(|f| !f.is_empty());
    check_text_location(text, e.line, e.column, has_field)
        .map_err(|f| TestCaseError::fail(format!("{f}: {e:?}")))
}

/// Reads `text` (OBJ files relative to the temporary directory; `obj` is the file and
/// its text, when the scene names one) and checks every property; returns whether it
/// was accepted.
fn check(text: &str, obj: Option<(&Path, &str)>) -> Result<bool, TestCaseError> {
    let base = tmp_dir();
    let start = Instant::now();
    let result = parse_any(text, Some(base));
    let took = start.elapsed();
    prop_assert!(took < TIME_BOUND, "{took:?} on {} bytes", text.len());
    match result {
        Err(e) => {
            check_message(text, &e)?;
            match (&e.path, obj) {
                (None, _) => check_located(text, &e)?,
                (Some(p), Some((path, obj_text))) if p == path => {
                    // a fault of the OBJ file: located in it (a missing file, or one too
                    // large, is the file as a whole)
                    if e.kind != cwisim_scene::SceneErrorKind::Io {
                        prop_assert!(e.line.is_some(), "unlocated in the OBJ file: {e:?}");
                        check_located(obj_text, &e)?;
                    }
                }
                (Some(p), _) => {
                    // a mutated "obj" naming another file: it does not exist
                    prop_assert!(p.starts_with(base), "{e:?}");
                    prop_assert_eq!(e.kind, cwisim_scene::SceneErrorKind::Io, "{:?}", e);
                }
            }
            Ok(false)
        }
        Ok(scene) => {
            let json = match &scene {
                AnyScene::Screen(s) => s.to_json(),
                AnyScene::World(w) => serde_json::to_string_pretty(&w.spec).expect("serializes"),
            };
            let back = parse_any(&json, Some(base));
            prop_assert!(back.is_ok(), "written back, refused: {back:?}\n{json}");
            prop_assert_eq!(back.expect("checked"), scene);
            Ok(true)
        }
    }
}

proptest! {
    // 512 cases each.
    #![proptest_config(config(512))]

    #[test]
    fn arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        check(&String::from_utf8_lossy(&bytes), None)?;
    }

    #[test]
    fn arbitrary_text(chars in proptest::collection::vec(any::<char>(), 0..300)) {
        check(&chars.into_iter().collect::<String>(), None)?;
    }
}

proptest! {
    // 2048 cases, 1 to 4 mutations each.
    #![proptest_config(config(2048))]

    #[test]
    fn mutated_scenes(
        seed in any::<usize>(),
        mutations in proptest::collection::vec(mutation(), 1..5),
    ) {
        let pool = seeds();
        let mut b = pool[seed % pool.len()].clone().into_bytes();
        for m in &mutations {
            b = apply(pool, b, m);
        }
        check(&String::from_utf8_lossy(&b), None)?;
    }
}

proptest! {
    // 768 cases: a mutated OBJ file (1 to 4 mutations) drawn by a world scene.
    #![proptest_config(config(768))]

    #[test]
    fn mutated_obj_files(
        seed in any::<usize>(),
        mutations in proptest::collection::vec(mutation(), 1..5),
    ) {
        let pool: Vec<String> = OBJ_SEEDS.iter().map(|s| s.to_string()).collect();
        let mut b = pool[seed % pool.len()].clone().into_bytes();
        for m in &mutations {
            b = apply(&pool, b, m);
        }
        let name = format!("{:?}.obj", std::thread::current().id())
            .replace(|c: char| !c.is_ascii_alphanumeric() && c != '.', "");
        let path = tmp_dir().join(&name);
        std::fs::write(&path, &b).expect("temp OBJ file");
        let obj_text = String::from_utf8_lossy(&b);
        let result = check(&obj_scene(&name), Some((&path, &obj_text)));
        std::fs::remove_file(&path).ok();
        result?;
    }
}

/// The OBJ seeds are good meshes.
#[test]
fn obj_seeds_read() {
    for (k, obj) in OBJ_SEEDS.iter().enumerate() {
        let name = format!("seed{k}.obj");
        std::fs::write(tmp_dir().join(&name), obj).expect("temp OBJ file");
        parse_any(&obj_scene(&name), Some(tmp_dir())).unwrap_or_else(|e| panic!("seed {k}: {e}"));
    }
}

/// Found by `mutated_obj_files`: a bad statement on a last line without its newline was
/// refused with no line (tobj reads to the end of the file before it fails there), and
/// after a face with a bad index, at that face's line.
#[test]
fn obj_faults_on_an_unterminated_last_line_are_located() {
    for (k, (obj, line)) in [
        ("mtllib none.mtl\nusemtl x\nv", 3),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nvn 1 x", 5),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\nv 1 x", 5),
        // and an index fault, found once the whole file is read, at its face
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\nf 1 2 3", 4),
    ]
    .into_iter()
    .enumerate()
    {
        let name = format!("last-line{k}.obj");
        std::fs::write(tmp_dir().join(&name), obj).expect("temp OBJ file");
        let e = parse_any(&obj_scene(&name), Some(tmp_dir())).expect_err("refused");
        assert_eq!(
            e.path.as_deref(),
            Some(tmp_dir().join(&name).as_path()),
            "{e}"
        );
        assert_eq!((e.line, e.column), (Some(line), Some(1)), "{k}: {e}");
    }
}
