//! What every fuzz target checks of a reader, the same properties as the readers'
//! property tests (`crates/{isa,scene,world}/tests/fuzz.rs`): no panic (the fuzzer sees
//! it), every refusal a non-empty printable line located in the input, and every
//! acceptance written back and read back equal. A violated property panics, which
//! libFuzzer reports as a crash with the input that caused it.

use cwisim_isa::io::read_all;
use cwisim_isa::{Encoding, Instruction, Location, TraceError, TraceHeader};
use cwisim_scene::SceneError;
use cwisim_world::{parse_any, AnyScene};
use std::path::Path;

/// Reads `bytes` as a trace in `encoding`, and checks the properties.
pub fn trace(encoding: Encoding, bytes: &[u8]) {
    match decode(encoding, bytes) {
        Err(e) => {
            message(&e.message, &e.to_string());
            assert!(e.path.is_none(), "{e:?}");
            match (encoding, e.location) {
                (Encoding::Binary, Location::Byte(b)) => {
                    assert!(
                        b <= bytes.len() as u64,
                        "{e:?} beyond {} bytes",
                        bytes.len()
                    );
                }
                (Encoding::Text | Encoding::JsonLines, Location::Line { line, column }) => {
                    let lines = bytes.iter().filter(|&&b| b == b'\n').count() as u64 + 1;
                    assert!(line >= 1 && column >= 1 && line <= lines, "{e:?}");
                }
                _ => panic!("{encoding:?}: unlocated or mislocated: {e:?}"),
            }
        }
        Ok((header, instructions)) => {
            for again in [Encoding::Text, Encoding::JsonLines, Encoding::Binary] {
                let written = encode(again, &header, &instructions);
                let back = decode(again, &written)
                    .unwrap_or_else(|e| panic!("{again:?} cannot read back its own: {e}"));
                assert_eq!(back, (header, instructions.clone()), "{again:?}");
            }
        }
    }
}

/// Reads `text` as a screen scene, and checks the properties.
pub fn screen_scene(text: &str) {
    match cwisim_scene::parse_scene(text) {
        Err(e) => scene_error(text, &e),
        Ok(scene) => {
            let json = scene.to_json();
            let back = cwisim_scene::parse_scene(&json)
                .unwrap_or_else(|e| panic!("written back, refused: {e}\n{json}"));
            assert_eq!(back, scene);
        }
    }
}

/// Reads `text` as any scene (OBJ files relative to `base`), and checks the properties.
/// Returns the refusal, if any, for the caller to look at further.
pub fn any_scene(text: &str, base: &Path) -> Option<SceneError> {
    match parse_any(text, Some(base)) {
        Err(e) => {
            message(&e.message, &e.to_string());
            if e.path.is_none() {
                located(text, &e);
            }
            Some(e)
        }
        Ok(scene) => {
            let json = match &scene {
                AnyScene::Screen(s) => s.to_json(),
                AnyScene::World(w) => {
                    serde_json::to_string_pretty(&w.spec).expect("a world scene serializes")
                }
            };
            let back = parse_any(&json, Some(base))
                .unwrap_or_else(|e| panic!("written back, refused: {e}\n{json}"));
            assert_eq!(back, scene);
            None
        }
    }
}

/// A located scene error: a line and column within `text`, or the JSON path at fault.
pub fn located(text: &str, e: &SceneError) {
    let has_field = e.field.as_deref().is_some_and(|f| !f.is_empty());
    match (e.line, e.column) {
        (Some(line), Some(column)) => {
            let lines = text.split('\n').count() as u64;
            assert!(line >= 1 && column >= 1 && line <= lines, "{e:?}");
        }
        _ => assert!(has_field, "unlocated: {e:?}"),
    }
}

fn scene_error(text: &str, e: &SceneError) {
    message(&e.message, &e.to_string());
    assert!(e.path.is_none(), "{e:?}");
    located(text, e);
}

/// One non-empty line, printable even where it echoes the input.
fn message(message: &str, display: &str) {
    assert!(!message.trim().is_empty(), "empty message: {display}");
    assert!(
        !display.contains(|c: char| c.is_control()),
        "more than one printable line: {display:?}"
    );
}

type Trace = (TraceHeader, Vec<Instruction>);

fn decode(encoding: Encoding, bytes: &[u8]) -> Result<Trace, TraceError> {
    let mut r = encoding.reader(bytes)?;
    let instructions = read_all(&mut *r)?;
    Ok((*r.header(), instructions))
}

fn encode(encoding: Encoding, header: &TraceHeader, instructions: &[Instruction]) -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut w = encoding
        .writer(&mut bytes, header)
        .expect("an in-memory writer");
    for i in instructions {
        w.write(i).expect("an in-memory write");
    }
    w.finish().expect("an in-memory finish");
    drop(w);
    bytes
}
