//! The one range syntax for scanlines and frames, shared by every command that takes one
//! (`--lines`, `--frames`): `N` (just N), `A-B` (A to B, both included), `A-` (A to the
//! end). Numbers count from 0; scanlines over the whole trace, frames by the trace
//! header's lines per frame.

use std::fmt;
use std::str::FromStr;

/// An inclusive range of scanline or frame numbers, possibly open at the end.
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
            t.parse::<u64>().map_err(|_| {
                format!("`{s}` is not a range: expected N, A-B or A- with whole numbers from 0 (e.g. 3, 10-20, 5-)")
            })
        };
        match s.split_once('-') {
            None => {
                let n = number(s)?;
                Ok(Range {
                    first: n,
                    last: Some(n),
                })
            }
            Some((a, "")) => Ok(Range {
                first: number(a)?,
                last: None,
            }),
            Some((a, b)) => {
                let (first, last) = (number(a)?, number(b)?);
                if last < first {
                    return Err(format!("`{s}` is empty: {last} comes before {first}"));
                }
                Ok(Range {
                    first,
                    last: Some(last),
                })
            }
        }
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.last {
            Some(l) if l == self.first => write!(f, "{l}"),
            Some(l) => write!(f, "{}-{l}", self.first),
            None => write!(f, "{}-", self.first),
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

    #[test]
    fn the_three_forms() {
        assert_eq!(
            "7".parse(),
            Ok(Range {
                first: 7,
                last: Some(7)
            })
        );
        assert_eq!(
            "3-9".parse(),
            Ok(Range {
                first: 3,
                last: Some(9)
            })
        );
        assert_eq!(
            "5-".parse(),
            Ok(Range {
                first: 5,
                last: None
            })
        );
        let r: Range = "3-9".parse().unwrap();
        assert!(r.contains(3) && r.contains(9) && !r.contains(10) && !r.contains(2));
        assert!(Range::ALL.contains(u64::MAX));
        for s in ["", "-3", "a-b", "9-3", "1-2-3", " 4"] {
            assert!(s.parse::<Range>().is_err(), "{s:?}");
        }
        assert_eq!("3-9".parse::<Range>().unwrap().to_string(), "3-9");
        assert_eq!("5-".parse::<Range>().unwrap().to_string(), "5-");
        // frames 1-2 of 4-line frames are scanlines 4-11; frame 3- is 12-
        let f: Range = "1-2".parse().unwrap();
        assert_eq!(f.frames_to_lines(4).to_string(), "4-11");
        assert_eq!(
            "3-".parse::<Range>()
                .unwrap()
                .frames_to_lines(4)
                .to_string(),
            "12-"
        );
        assert_eq!(Range::selection(Some(f), None, 4), Some(f));
        assert_eq!(
            Range::selection(None, Some(f), 4).unwrap().to_string(),
            "4-11"
        );
    }
}
