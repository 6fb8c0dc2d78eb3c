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

use cwisim_scene::{parse_scene, Scene, SceneError};
use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The most one read may take (generous: debug build, a loaded 2-core machine).
const TIME_BOUND: Duration = Duration::from_secs(2);

/// `cases` cases, and no regression files written into the source tree (a failure
/// prints its minimal input; add it as a fixed test).
fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::with_cases(cases)
    }
}

/// Numbers that break naive readers, as text.
const EXTREMES: [&str; 12] = [
    "0",
    "-0",
    "1e308",
    "-1e308",
    "1e-320",
    "4294967296",
    "18446744073709551616",
    "NaN",
    "1e999",
    "-1",
    "65537",
    "1e15",
];

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
    // path alone happens when it cannot be found in the text, e.g. under a repeated key).
    let (Some(line), Some(column)) = (e.line, e.column) else {
        prop_assert!(e.line.is_none() && e.column.is_none(), "{e:?}");
        prop_assert!(
            e.field.as_deref().is_some_and(|f| !f.is_empty()),
            "unlocated: {e:?}"
        );
        return Ok(());
    };
    let lines = text.split('\n').count() as u64;
    prop_assert!(
        line >= 1 && line <= lines,
        "{e:?}: past the last line ({lines})"
    );
    let len = text.split('\n').nth(line as usize - 1).map_or(0, str::len) as u64;
    prop_assert!(
        column >= 1 && column <= len + 1,
        "{e:?}: past the end of line {line} ({len} bytes)"
    );
    Ok(())
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

/// A mutation; its numbers are reduced modulo whatever they index.
#[derive(Clone, Debug)]
enum Mutation {
    /// XOR one byte with a non-zero mask (then read as lossy UTF-8).
    Flip(usize, u8),
    /// Keep only the first bytes.
    Truncate(usize),
    /// This input's head, then another seed's tail.
    Splice(usize, usize, usize),
    /// Insert a copy of a slice somewhere.
    Duplicate(usize, usize, usize),
    /// Replace a number token with an extreme value.
    Extreme(usize, usize),
    /// Delete a key with its value.
    DeleteKey(usize),
    /// Duplicate a key with its value.
    DuplicateKey(usize),
    /// Wrap a value in `[]`.
    Wrap(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        1 => (any::<usize>(), 1u8..=255).prop_map(|(p, m)| Mutation::Flip(p, m)),
        1 => any::<usize>().prop_map(Mutation::Truncate),
        1 => (any::<usize>(), any::<usize>(), any::<usize>())
            .prop_map(|(s, a, b)| Mutation::Splice(s, a, b)),
        1 => (any::<usize>(), 0usize..64, any::<usize>())
            .prop_map(|(s, n, at)| Mutation::Duplicate(s, n, at)),
        // the structure-aware ones, which mostly keep the JSON well-formed, weigh more
        3 => (any::<usize>(), any::<usize>()).prop_map(|(t, x)| Mutation::Extreme(t, x)),
        2 => any::<usize>().prop_map(Mutation::DeleteKey),
        2 => any::<usize>().prop_map(Mutation::DuplicateKey),
        2 => any::<usize>().prop_map(Mutation::Wrap),
    ]
}

/// The number tokens of text: maximal runs of `[-+.0-9eE]` holding a digit and not
/// glued to a word on the left.
fn number_tokens(b: &[u8]) -> Vec<(usize, usize)> {
    let num = |c: u8| c.is_ascii_digit() || matches!(c, b'-' | b'+' | b'.' | b'e' | b'E');
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if num(b[i]) && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')) {
            let s = i;
            while i < b.len() && num(b[i]) {
                i += 1;
            }
            if b[s..i].iter().any(u8::is_ascii_digit) {
                out.push((s, i));
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The end of the JSON string starting at `i` (a `"`).
fn skip_string(b: &[u8], mut i: usize) -> usize {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    b.len()
}

/// The end of the JSON value starting at `i` (roughly, for broken input too).
fn skip_value(b: &[u8], mut i: usize) -> usize {
    match b.get(i) {
        None => i,
        Some(b'"') => skip_string(b, i),
        Some(b'{' | b'[') => {
            let mut depth = 0usize;
            while i < b.len() {
                match b[i] {
                    b'"' => {
                        i = skip_string(b, i);
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth = depth.saturating_sub(1);
                        if depth == 0 {
                            return i + 1;
                        }
                    }
                    _ => {}
                }
                i += 1;
            }
            i
        }
        Some(_) => {
            while i < b.len() && !matches!(b[i], b',' | b']' | b'}') && !b[i].is_ascii_whitespace()
            {
                i += 1;
            }
            i
        }
    }
}

/// Every `"key": value` of JSON text: (key start, value start, value end).
fn json_members(b: &[u8]) -> Vec<(usize, usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'"' {
            let end = skip_string(b, i);
            let mut j = end;
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            if b.get(j) == Some(&b':') {
                j += 1;
                while j < b.len() && b[j].is_ascii_whitespace() {
                    j += 1;
                }
                out.push((i, j, skip_value(b, j)));
            }
            i = end;
        } else {
            i += 1;
        }
    }
    out
}

/// Every value of JSON text that is an array element or a member's value: (start, end).
fn json_values(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = json_members(b).iter().map(|m| (m.1, m.2)).collect();
    for (i, &c) in b.iter().enumerate() {
        if c == b'[' || c == b',' {
            let mut j = i + 1;
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            if j < b.len() && !matches!(b[j], b']' | b'"' | b',') {
                out.push((j, skip_value(b, j)));
            }
        }
    }
    out
}

fn apply(mut b: Vec<u8>, m: &Mutation) -> Vec<u8> {
    let pool = seeds();
    let len = b.len();
    match *m {
        Mutation::Flip(p, mask) => {
            if len > 0 {
                b[p % len] ^= mask;
            }
        }
        Mutation::Truncate(p) => b.truncate(p % (len + 1)),
        Mutation::Splice(s, p, q) => {
            let other = pool[s % pool.len()].as_bytes();
            b.truncate(p % (len + 1));
            b.extend_from_slice(&other[q % (other.len() + 1)..]);
        }
        Mutation::Duplicate(s, n, at) => {
            if len > 0 {
                let s = s % len;
                let slice = b[s..(s + n).min(len)].to_vec();
                let at = at % (len + 1);
                b.splice(at..at, slice);
            }
        }
        Mutation::Extreme(t, x) => {
            let toks = number_tokens(&b);
            if !toks.is_empty() {
                let (s, e) = toks[t % toks.len()];
                b.splice(s..e, EXTREMES[x % EXTREMES.len()].bytes());
            }
        }
        Mutation::DeleteKey(k) => {
            let members = json_members(&b);
            if !members.is_empty() {
                let (key, _, ve) = members[k % members.len()];
                // with the comma after it, or else the one before it
                let mut end = ve;
                while end < len && b[end].is_ascii_whitespace() {
                    end += 1;
                }
                let mut start = key;
                if b.get(end) == Some(&b',') {
                    end += 1;
                } else if let Some(c) = b[..key].iter().rposition(|&c| c == b',') {
                    if b[c + 1..key].iter().all(u8::is_ascii_whitespace) {
                        start = c;
                    }
                }
                b.drain(start..end);
            }
        }
        Mutation::DuplicateKey(k) => {
            let members = json_members(&b);
            if !members.is_empty() {
                let (key, _, ve) = members[k % members.len()];
                let mut copy = b[key..ve].to_vec();
                copy.extend_from_slice(b",\n");
                b.splice(key..key, copy);
            }
        }
        Mutation::Wrap(k) => {
            let values = json_values(&b);
            if !values.is_empty() {
                let (vs, ve) = values[k % values.len()];
                b.insert(ve, b']');
                b.insert(vs, b'[');
            }
        }
    }
    b
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
            b = apply(b, m);
        }
        check(&String::from_utf8_lossy(&b))?;
    }
}
