//! Locating a JSON path (`polygons[3].intensity[1]`) in a scene's text, so that a fault
//! found after parsing still names its line and column.

use std::fmt;

/// 1-based line and byte column of a byte offset.
pub(crate) fn line_column(text: &str, offset: usize) -> (u64, u64) {
    let before = &text.as_bytes()[..offset.min(text.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    (line as u64, (before.len() - start + 1) as u64)
}

pub(crate) fn first_token(text: &str) -> usize {
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

#[derive(Debug, PartialEq)]
enum Segment {
    Key(String),
    Index(usize),
}

/// Splits `polygons[3].intensity[1]` into its keys and indices.
fn segments(path: &str) -> Option<Vec<Segment>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if !key.is_empty() {
            out.push(Segment::Key(key.to_string()));
        }
        while let Some(r) = rest.strip_prefix('[') {
            let close = r.find(']')?;
            out.push(Segment::Index(r[..close].parse().ok()?));
            rest = &r[close + 1..];
        }
        if !rest.is_empty() {
            return None;
        }
    }
    Some(out)
}

/// The byte offset where the value at JSON path `path` starts in `text` (valid JSON),
/// or `None` when the path is not in it.
pub fn locate(text: &str, path: &str) -> Option<usize> {
    let b = text.as_bytes();
    let mut i = first_token(text);
    let ws = |i: &mut usize| {
        while *i < b.len() && b[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    for seg in segments(path)? {
        match seg {
            Segment::Key(key) => {
                if b.get(i) != Some(&b'{') {
                    return None;
                }
                i += 1;
                loop {
                    ws(&mut i);
                    if b.get(i) != Some(&b'"') {
                        return None;
                    }
                    let end = skip_string(b, i)?;
                    let name: String = serde_json::from_str(&text[i..end]).ok()?;
                    i = end;
                    ws(&mut i);
                    if b.get(i) != Some(&b':') {
                        return None;
                    }
                    i += 1;
                    ws(&mut i);
                    if name == key {
                        break;
                    }
                    i = skip_value(b, i)?;
                    ws(&mut i);
                    if b.get(i) != Some(&b',') {
                        return None;
                    }
                    i += 1;
                }
            }
            Segment::Index(n) => {
                if b.get(i) != Some(&b'[') {
                    return None;
                }
                i += 1;
                for _ in 0..n {
                    ws(&mut i);
                    i = skip_value(b, i)?;
                    ws(&mut i);
                    if b.get(i) != Some(&b',') {
                        return None;
                    }
                    i += 1;
                }
                ws(&mut i);
                if matches!(b.get(i), None | Some(b']')) {
                    return None;
                }
            }
        }
    }
    Some(i)
}

/// The offset just past the string starting at `i` (a `"`).
fn skip_string(b: &[u8], mut i: usize) -> Option<usize> {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return Some(i + 1),
            _ => i += 1,
        }
    }
    None
}

/// The offset just past the value starting at `i`.
fn skip_value(b: &[u8], mut i: usize) -> Option<usize> {
    match b.get(i)? {
        b'"' => skip_string(b, i),
        b'{' | b'[' => {
            let mut depth = 0usize;
            while i < b.len() {
                match b[i] {
                    b'"' => {
                        i = skip_string(b, i)?;
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth -= 1;
                        if depth == 0 {
                            return Some(i + 1);
                        }
                    }
                    _ => {}
                }
                i += 1;
            }
            None
        }
        _ => {
            while i < b.len() && !matches!(b[i], b',' | b']' | b'}') && !b[i].is_ascii_whitespace()
            {
                i += 1;
            }
            Some(i)
        }
    }
}

impl fmt::Display for Segment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Segment::Key(k) => write!(f, ".{k}"),
            Segment::Index(n) => write!(f, "[{n}]"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_split_and_locate() {
        assert_eq!(
            segments("polygons[3].intensity[1]").unwrap(),
            vec![
                Segment::Key("polygons".into()),
                Segment::Index(3),
                Segment::Key("intensity".into()),
                Segment::Index(1)
            ]
        );
        let s: String = segments("a[2].b")
            .unwrap()
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(s, ".a[2].b");
        let text = "{\"a\": [1, {\"x\": \"]}\"}, [2,\n  3]], \"b\": {\"c\": null}}";
        assert_eq!(&text[locate(text, "a[2][1]").unwrap()..][..1], "3");
        assert_eq!(&text[locate(text, "b.c").unwrap()..][..4], "null");
        assert_eq!(&text[locate(text, "a[1].x").unwrap()..][..4], "\"]}\"");
        assert_eq!(locate(text, "a[3]"), None);
        assert_eq!(locate(text, "z"), None);
        assert_eq!(line_column(text, locate(text, "a[2][1]").unwrap()), (2, 3));
    }
}
