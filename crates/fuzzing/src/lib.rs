//! # cwisim-fuzzing — mutations of valid inputs, for fuzzing cwisim's readers
//!
//! Shared by the readers' property tests (`crates/isa`, `crates/scene`, `crates/world`:
//! `tests/fuzz.rs`): byte-level mutations (flip, truncate, splice, duplicate) and
//! structure-aware ones for text and JSON (a number replaced by an extreme, a key deleted
//! or repeated, a value wrapped in `[]`), the extreme numbers, and the time bound and
//! proptest configuration every reader is held to; and [`heap`], the counting allocator
//! of the tests that measure a peak heap. A test-only crate: nothing of cwisim depends on
//! it but tests.

#![warn(missing_docs)]

pub mod heap;

use proptest::prelude::*;
use std::time::Duration;

/// The most one read may take: a bound to catch a hang, not a speed test. Generous — a
/// debug build on a 2-core machine loaded by other builds once took over 2 s for an OBJ
/// case that takes milliseconds alone (`mutated_obj_files`, which writes a temporary
/// file per case), so 2 s made the tests flaky.
pub const TIME_BOUND: Duration = Duration::from_secs(10);

/// `cases` cases, and no regression files written into the source tree (a failure
/// prints its minimal input; add it as a fixed test).
pub fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::with_cases(cases)
    }
}

/// Numbers that break naive readers, as text.
pub const EXTREMES: [&str; 13] = [
    "0",
    "-0",
    "1e308",
    "-1e308",
    "1e-320",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "NaN",
    "1e999",
    "-1",
    "65537",
    "1e15",
];

/// A mutation; its numbers are reduced modulo whatever they index.
#[derive(Clone, Debug)]
pub enum Mutation {
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

/// Any mutation, the structure-aware ones weighted more (they mostly keep JSON
/// well-formed, and so reach deeper into a reader).
pub fn mutation() -> impl Strategy<Value = Mutation> {
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
pub fn number_tokens(b: &[u8]) -> Vec<(usize, usize)> {
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
pub fn skip_string(b: &[u8], mut i: usize) -> usize {
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
pub fn skip_value(b: &[u8], mut i: usize) -> usize {
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
pub fn json_members(b: &[u8]) -> Vec<(usize, usize, usize)> {
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
pub fn json_values(b: &[u8]) -> Vec<(usize, usize)> {
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

/// JSON text without its member `k` (reduced modulo the members; none: unchanged) and
/// the comma after it, or else the one before it.
pub fn delete_member(b: &mut Vec<u8>, k: usize) {
    let members = json_members(b);
    if members.is_empty() {
        return;
    }
    let (key, _, ve) = members[k % members.len()];
    let mut end = ve;
    while end < b.len() && b[end].is_ascii_whitespace() {
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

/// JSON text with its member `k` (reduced modulo the members; none: unchanged) written
/// twice, on one line (so JSON Lines records stay one line).
pub fn duplicate_member(b: &mut Vec<u8>, k: usize) {
    let members = json_members(b);
    if members.is_empty() {
        return;
    }
    let (key, _, ve) = members[k % members.len()];
    let mut copy = b[key..ve].to_vec();
    copy.extend_from_slice(b", ");
    b.splice(key..key, copy);
}

/// Checks a refusal's place in `text`: a 1-based `line` and `column` inside it, or else
/// (neither given) a JSON path (`has_field`) naming the value at fault.
pub fn check_text_location(
    text: &str,
    line: Option<u64>,
    column: Option<u64>,
    has_field: bool,
) -> Result<(), TestCaseError> {
    let (Some(line), Some(column)) = (line, column) else {
        prop_assert!(
            line.is_none() && column.is_none(),
            "a line without a column"
        );
        prop_assert!(has_field, "unlocated");
        return Ok(());
    };
    let lines = text.split('\n').count() as u64;
    prop_assert!(
        line >= 1 && line <= lines,
        "line {line} past the last ({lines})"
    );
    let len = text.split('\n').nth(line as usize - 1).map_or(0, str::len) as u64;
    prop_assert!(
        column >= 1 && column <= len + 1,
        "column {column} past the end of line {line} ({len} bytes)"
    );
    Ok(())
}

/// `b` mutated by `m`; a splice takes its tail from one of `pool`.
pub fn apply(pool: &[String], mut b: Vec<u8>, m: &Mutation) -> Vec<u8> {
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
        Mutation::DeleteKey(k) => delete_member(&mut b, k),
        Mutation::DuplicateKey(k) => duplicate_member(&mut b, k),
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
