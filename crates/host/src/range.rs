//! The one range syntax for scanlines, frames and processor columns, shared by every
//! command that takes one (`--lines`, `--frames`, `--x`), written as Rust writes ranges:
//!
//! | form | selects |
//! | --- | --- |
//! | `N` | just N |
//! | `A..B` | A up to B, **B not included** (`10..20` is 10 numbers) |
//! | `A..=B` | A to B, both included |
//! | `A..` | A to the end |
//!
//! Numbers count from 0; scanlines over the whole trace, frames by the trace header's lines
//! per frame. The old spellings `A-B` (both included) and `A-` are still read, for a
//! release, so that no script breaks; ranges are always *written* in the new syntax.

use std::fmt;
use std::str::FromStr;

/// What every message about a malformed range says the syntax is.
const SYNTAX: &str =
    "expected N, A..B (B not included), A..=B or A.. with whole numbers from 0 (e.g. 3, 10..20, 5..)";

/// A range of scanline, frame or processor numbers, possibly open at the end. Kept
/// inclusive (`first..=last`) whatever syntax it was written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Range {
    /// First number in the range.
    pub first: u64,
    /// Last number in the range, or `None` for "to the end".
    pub last: Option<u64>,
}

impl Range {
    /// Every number.
    pub const ALL: Range = Range {
        first: 0,
        last: None,
    };

    /// Whether `n` is in the range.
    pub fn contains(&self, n: u64) -> bool {
        n >= self.first && self.last.is_none_or(|l| n <= l)
    }

    /// The scanlines of these frames, for a trace of `lines_per_frame` scanlines per frame.
    pub fn frames_to_lines(&self, lines_per_frame: u64) -> Range {
        Range {
            first: self.first.saturating_mul(lines_per_frame),
            last: self
                .last
                .map(|l| l.saturating_add(1).saturating_mul(lines_per_frame) - 1),
        }
    }

    /// The scanlines `--lines` or `--frames` select (clap keeps them exclusive).
    pub fn selection(
        lines: Option<Range>,
        frames: Option<Range>,
        lines_per_frame: u64,
    ) -> Option<Range> {
        frames.map(|f| f.frames_to_lines(lines_per_frame)).or(lines)
    }
}

impl FromStr for Range {
    type Err = String;

    fn from_str(s: &str) -> Result<Range, String> {
        let number = |t: &str| {
            t.parse::<u64>()
                .map_err(|_| format!("`{s}` is not a range: {SYNTAX}"))
        };
        let closed = |first: u64, last: u64| {
            if last < first {
                Err(format!("`{s}` is empty: {last} comes before {first}"))
            } else {
                Ok(Range {
                    first,
                    last: Some(last),
                })
            }
        };
        if let Some((a, b)) = s.split_once("..") {
            let first = number(a)?;
            if b.is_empty() {
                return Ok(Range { first, last: None });
            }
            if let Some(b) = b.strip_prefix('=') {
                return closed(first, number(b)?);
            }
            let end = number(b)?;
            if end <= first {
                return Err(format!(
                    "`{s}` is empty: the end {end} is not included and does not come after {first} \
(write {first}..={end} to include it)"
                ));
            }
            return closed(first, end - 1);
        }
        // The old spellings, still read: `A-B` (both included) and `A-`.
        match s.split_once('-') {
            None => {
                let n = number(s)?;
                closed(n, n)
            }
            Some((a, "")) => Ok(Range {
                first: number(a)?,
                last: None,
            }),
            Some((a, b)) => closed(number(a)?, number(b)?),
        }
    }
}

impl fmt::Display for Range {
    /// In the new syntax: `N`, `A..B` (B not included) or `A..`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.last {
            Some(l) if l == self.first => write!(f, "{l}"),
            Some(l) => match l.checked_add(1) {
                Some(end) => write!(f, "{}..{end}", self.first),
                None => write!(f, "{}..={l}", self.first),
            },
            None => write!(f, "{}..", self.first),
        }
    }
}

/// Parses a range for clap (`value_parser = parse_range`).
pub fn parse_range(s: &str) -> Result<Range, String> {
    s.parse()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closed(first: u64, last: u64) -> Range {
        Range {
            first,
            last: Some(last),
        }
    }

    #[test]
    fn the_forms() {
        assert_eq!("7".parse(), Ok(closed(7, 7)));
        assert_eq!("3..10".parse(), Ok(closed(3, 9)));
        assert_eq!("3..=9".parse(), Ok(closed(3, 9)));
        assert_eq!("4..5".parse(), Ok(closed(4, 4)));
        assert_eq!(
            "5..".parse(),
            Ok(Range {
                first: 5,
                last: None
            })
        );
        let r: Range = "3..10".parse().unwrap();
        assert!(r.contains(3) && r.contains(9) && !r.contains(10) && !r.contains(2));
        assert!(Range::ALL.contains(u64::MAX));
        for s in [
            "", "-3", "a-b", "9-3", "1-2-3", " 4", "..", "..3", "3..3", "9..3", "3..=2", "3...",
            "3..=", "1..2..3", "3..x", "3.. ",
        ] {
            assert!(s.parse::<Range>().is_err(), "{s:?}");
        }
    }

    #[test]
    fn the_old_spellings_are_still_read() {
        assert_eq!("3-9".parse(), Ok(closed(3, 9)));
        assert_eq!("5-".parse::<Range>(), "5..".parse::<Range>());
    }

    #[test]
    fn written_in_the_new_syntax_and_read_back() {
        for (typed, written) in [
            ("3-9", "3..10"),
            ("3..=9", "3..10"),
            ("5-", "5.."),
            ("4..5", "4"),
            ("7", "7"),
        ] {
            let r: Range = typed.parse().unwrap();
            assert_eq!(r.to_string(), written, "{typed}");
            assert_eq!(written.parse::<Range>(), Ok(r), "{written}");
        }
        let top = format!("0..={}", u64::MAX);
        let r: Range = top.parse().unwrap();
        assert_eq!(r.to_string(), top, "no overflow at the top");
    }

    #[test]
    fn an_empty_half_open_range_says_how_to_include_the_end() {
        let e = "5..5".parse::<Range>().unwrap_err();
        assert!(e.contains("5..=5"), "{e}");
    }

    #[test]
    fn frames_to_lines() {
        // frames 1 and 2 of 4-line frames are scanlines 4..12; frames 3.. are 12..
        let f: Range = "1..3".parse().unwrap();
        assert_eq!(f.frames_to_lines(4).to_string(), "4..12");
        assert_eq!(
            "3.."
                .parse::<Range>()
                .unwrap()
                .frames_to_lines(4)
                .to_string(),
            "12.."
        );
        assert_eq!(Range::selection(Some(f), None, 4), Some(f));
        assert_eq!(
            Range::selection(None, Some(f), 4).unwrap().to_string(),
            "4..12"
        );
    }
}
