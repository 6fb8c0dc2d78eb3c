//! Fuzzing the screen-scene reader, [`parse_scene`], with untrusted input (proptest):
//! arbitrary bytes and strings, and structure-aware mutations of the screen scenes in
//! `crates/ypipe/tests/fixtures/` and `crates/world/scenes/` (fig25, cases12).
//!
//! Properties of every input: the reader does not panic; it finishes in well under
//! [`TIME_BOUND`] (a bound to catch hangs, not to measure speed); every refusal is
//! located — a line and column inside the text, or else the JSON path of the value at
//! fault — with a one-line, non-empty message;
//! and every acceptance writes back ([`Scene::to_json`]) to text that reads back equal.
//!
//! Cases per run (debug, 2 cores: about 3 s in all): `arbitrary_bytes` 512,
//! `arbitrary_text` 512, `json_shaped_text` 512, `mutated_scenes` 2048.

use cwisim_fuzzing::{apply, check_text_location, config, mutation, EXTREMES, TIME_BOUND};
use cwisim_scene::{parse_scene, Scene, SceneError};
use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;
use std::time::Instant;

/// The seed scenes (valid screen scenes), as text.
fn seeds() -> &'static [String] {
    static SEEDS: OnceLock<Vec<String>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut paths: Vec<_> = std::fs::read_dir(root.join("ypipe/tests/fixtures"))
            .expect("ypipe fixtures")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        paths.sort();
        paths.push(root.join("world/scenes/fig25.json"));
        paths.push(root.join("world/scenes/cases12.json"));
        let texts: Vec<String> = paths
            .iter()
            .map(|p| std::fs::read_to_string(p).expect("seed scene"))
            .collect();
        for (p, t) in paths.iter().zip(&texts) {
            parse_scene(t).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        }
        texts
    })
}

fn check_error(text: &str, e: &SceneError) -> Result<(), TestCaseError> {
    prop_assert!(!e.message.trim().is_empty(), "empty message: {e:?}");
    // One printable line, even where serde_json's message echoes an unknown key with an
    // escaped line break in it (`{"kind": "screen", "a\nb": 1}`): the display escapes it.
    prop_assert!(
        !e.to_string().contains(|c: char| c.is_control()),
        "message of more than one printable line: {e:?}"
    );
    prop_assert!(e.path.is_none(), "{e:?}");
    // Located: a line and column, or at least the JSON path of the value at fault (the
    // path alone happens when it cannot be found in the text).
    let has_field = e.field.as_deref().is_some_and(|f| !f.is_empty());
    check_text_location(text, e.line, e.column, has_field)
        .map_err(|f| TestCaseError::fail(format!("{f}: {e:?}")))
}

/// Reads `text` and checks every property; returns whether it was accepted.
fn check(text: &str) -> Result<bool, TestCaseError> {
    let start = Instant::now();
    let result = parse_scene(text);
    let took = start.elapsed();
    prop_assert!(took < TIME_BOUND, "{took:?} on {} bytes", text.len());
    match result {
        Err(e) => {
            check_error(text, &e)?;
            Ok(false)
        }
        Ok(scene) => {
            let json = scene.to_json();
            let back: Result<Scene, _> = parse_scene(&json);
            prop_assert!(back.is_ok(), "written back, refused: {back:?}\n{json}");
            let back = back.expect("checked");
            prop_assert_eq!(&back, &scene);
            prop_assert_eq!(back.to_json(), json, "to_json is not stable");
            Ok(true)
        }
    }
}

/// Text shaped like JSON: brackets, keys of the format, numbers, extremes.
fn json_shaped() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        Just("{".to_string()),
        Just("}".to_string()),
        Just("[".to_string()),
        Just("]".to_string()),
        Just(",".to_string()),
        Just(":".to_string()),
        Just("\n".to_string()),
        Just("\"kind\": \"screen\"".to_string()),
        Just("\"width\"".to_string()),
        Just("\"height\"".to_string()),
        Just("\"channels\"".to_string()),
        Just("\"polygons\"".to_string()),
        Just("\"vertices\"".to_string()),
        Just("\"intensity\"".to_string()),
        Just("\"depth\"".to_string()),
        (0usize..EXTREMES.len()).prop_map(|k| EXTREMES[k].to_string()),
        (-10i32..100).prop_map(|v| v.to_string()),
        (-10.0f64..100.0).prop_map(|v| v.to_string()),
        Just("null".to_string()),
        Just("\"\\u00e9\"".to_string()),
    ];
    proptest::collection::vec(piece, 0..80).prop_map(|v| v.concat())
}

proptest! {
    // 512 cases each.
    #![proptest_config(config(512))]

    #[test]
    fn arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        check(&String::from_utf8_lossy(&bytes))?;
    }

    #[test]
    fn arbitrary_text(chars in proptest::collection::vec(any::<char>(), 0..300)) {
        check(&chars.into_iter().collect::<String>())?;
    }

    #[test]
    fn json_shaped_text(text in json_shaped()) {
        check(&text)?;
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
        check(&String::from_utf8_lossy(&b))?;
    }
}
