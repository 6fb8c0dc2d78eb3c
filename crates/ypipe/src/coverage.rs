//! Box-filter coverage of one pixel row of a trapezium, and van Rij's twelve cases.
//!
//! Within pixel row `j` a trapezium is a *slice*: the band `[y0, y1]` (height `h ≤ 1`)
//! between its left and right edge. Over the band, an edge spans `[lo, hi]` in x and
//! cuts through pixels `floor(lo) ..= ceil(hi) - 1`.
//!
//! The covered area of pixel column `i` is `c(i) = D_L(i) - D_R(i)`, where `D_E(i)` is the
//! area of the pixel's part of the band that lies right of edge `E`:
//!
//! ```text
//! D_E(i) = h · ( (b - a)(a + b - 2 lo) / (2 (hi - lo))  +  max(0, i + 1 - max(i, hi)) )
//!          with a = max(i, lo), b = min(i + 1, hi)  (first term only when a < b)
//! ```
//!
//! Between the pixels an edge's end points fall in, `D_E` grows by exactly
//! `h / (hi - lo) = 1 / |1/slope|` per pixel — not `1 / (2 · |1/slope|)` as the report's
//! sequence procedure says (docs/ERRATA.md, E1).

use crate::floor::{ceil_i64, floor_i64};
use crate::trapezoid::Trapezium;

/// An edge over one slice: its x at the band's top and bottom, and its x extent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliceEdge {
    /// Smallest x of the edge within the band.
    pub lo: f64,
    /// Largest x of the edge within the band.
    pub hi: f64,
    /// The edge's x at the band's top (`y0`).
    pub at_top: f64,
    /// The edge's x at the band's bottom (`y1`).
    pub at_bottom: f64,
}

impl SliceEdge {
    /// First pixel column the edge cuts through.
    pub fn first_pixel(&self) -> i64 {
        floor_i64(self.lo)
    }

    /// Last pixel column the edge cuts through (at least the first).
    pub fn last_pixel(&self) -> i64 {
        (ceil_i64(self.hi) - 1).max(self.first_pixel())
    }

    /// `D_E(i) / h`: the fraction of the band's height, integrated over pixel `i`, that
    /// lies right of the edge.
    ///
    /// Its `max` and `min` are compares (`maxsd`, `minsd`), not `f64::max`'s NaN-aware
    /// sequence: nothing here is NaN (a slice's edges are finite), and where the two
    /// differ, the sign of a zero, it changes no bit of the result (a zero `a` or
    /// `full_from` is only ever added to or subtracted from a nonzero value, or the term
    /// is not taken).
    #[inline]
    fn right_of(&self, i: f64) -> f64 {
        #[inline(always)]
        fn larger(a: f64, b: f64) -> f64 {
            if a > b {
                a
            } else {
                b
            }
        }
        #[inline(always)]
        fn smaller(a: f64, b: f64) -> f64 {
            if a < b {
                a
            } else {
                b
            }
        }
        let (lo, hi) = (self.lo, self.hi);
        let (a, b) = (larger(i, lo), smaller(i + 1.0, hi));
        let mut s = 0.0;
        if b > a {
            s += (b - a) * (a + b - 2.0 * lo) / (2.0 * (hi - lo));
        }
        let full_from = larger(i, hi);
        if i + 1.0 > full_from {
            s += i + 1.0 - full_from;
        }
        s
    }

    /// Coverage increment per pixel inside the edge's span (`h / (hi - lo)`).
    pub fn increment(&self, h: f64) -> f64 {
        h / (self.hi - self.lo)
    }
}

/// A trapezium within one pixel row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slice {
    /// Pixel row.
    pub row: u32,
    /// Top of the covered band.
    pub y0: f64,
    /// Bottom of the covered band.
    pub y1: f64,
    /// Left edge over the band.
    pub left: SliceEdge,
    /// Right edge over the band.
    pub right: SliceEdge,
}

impl Slice {
    /// The part of `t` in pixel row `row`, or `None` when they do not overlap.
    ///
    /// Inlined: returned from a call, the record comes back through memory, written as
    /// 8-byte fields and read back with wider loads, which stall (store forwarding).
    #[inline]
    pub fn of(t: &Trapezium, row: u32) -> Option<Slice> {
        let y0 = t.y_top.max(f64::from(row));
        let y1 = t.y_bot.min(f64::from(row) + 1.0);
        if y1 <= y0 {
            return None;
        }
        let extent = |e: &crate::trapezoid::Edge| {
            let (a, b) = (e.x_at(y0), e.x_at(y1));
            SliceEdge {
                lo: a.min(b),
                hi: a.max(b),
                at_top: a,
                at_bottom: b,
            }
        };
        Some(Slice {
            row,
            y0,
            y1,
            left: extent(&t.left),
            right: extent(&t.right),
        })
    }

    /// Height of the band.
    pub fn height(&self) -> f64 {
        self.y1 - self.y0
    }

    /// The exact covered area of pixel column `i` in this row.
    ///
    /// The area is never negative: where the two edges (nearly) meet, the difference of
    /// their fractions can round to −1e-16 or so, which is taken as the 0 it is (a
    /// negative coverage made a per-pixel renderer's target negative: issue 53).
    pub fn coverage(&self, i: i64) -> f64 {
        let x = i as f64;
        (self.height() * (self.left.right_of(x) - self.right.right_of(x))).max(0.0)
    }

    /// The pixels the left and right edge cut through: `(L0, L1, R0, R1)`.
    pub fn edge_pixels(&self) -> (i64, i64, i64, i64) {
        (
            self.left.first_pixel(),
            self.left.last_pixel(),
            self.right.first_pixel(),
            self.right.last_pixel(),
        )
    }

    /// Which of the report's twelve cases (section 3.3.1) this row is.
    pub fn case(&self) -> Case {
        let (l0, l1, r0, r1) = self.edge_pixels();
        // The left edge never lies right of the right edge, so l0 <= r0 and l1 <= r1;
        // rounding at a shared vertex could break that by a pixel, which only the label
        // would notice.
        let (r0, r1) = (r0.max(l0), r1.max(l1));
        let (l_one, r_one) = (l0 == l1, r0 == r1);
        Case(match (l_one, r_one) {
            (true, true) => {
                if l0 == r0 {
                    1
                } else {
                    2
                }
            }
            (false, true) => {
                if r0 <= l1 {
                    3
                } else {
                    4
                }
            }
            (true, false) => {
                if l0 >= r0 {
                    5
                } else {
                    6
                }
            }
            (false, false) => {
                if l1 < r0 {
                    8
                } else if l1 == r0 {
                    7
                } else if l0 == r0 && l1 == r1 {
                    12
                } else if l0 == r0 {
                    9
                } else if l1 == r1 {
                    11
                } else {
                    10
                }
            }
        })
    }
}

/// One of the twelve ways two edges can lie in a pixel row (van Rij 3.3.1), 1 to 12.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Case(pub u8);

impl Case {
    /// The report's description of the case.
    pub fn describe(self) -> &'static str {
        match self.0 {
            1 => "both edges cut one pixel, a common one",
            2 => "both edges cut one pixel, not a common one",
            3 => "the first edge cuts several pixels, the second one; they share a pixel",
            4 => "the first edge cuts several pixels, the second one; no common pixel",
            5 => "the first edge cuts one pixel, the second several; they share a pixel",
            6 => "the first edge cuts one pixel, the second several; no common pixel",
            7 => "both edges cut several pixels and have one in common",
            8 => "both edges cut several pixels, none in common",
            9 => "both edges cut several pixels and share pixels at the beginning",
            10 => "both edges cut several pixels and share pixels in the middle",
            11 => "both edges cut several pixels and share pixels at the end",
            _ => "both edges cut several pixels and share all of them",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slice(l: (f64, f64), r: (f64, f64)) -> Slice {
        Slice {
            row: 0,
            y0: 0.0,
            y1: 1.0,
            left: SliceEdge {
                lo: l.0.min(l.1),
                hi: l.0.max(l.1),
                at_top: l.0,
                at_bottom: l.1,
            },
            right: SliceEdge {
                lo: r.0.min(r.1),
                hi: r.0.max(r.1),
                at_top: r.0,
                at_bottom: r.1,
            },
        }
    }

    #[test]
    fn the_twelve_cases() {
        let cases = [
            ((2.25, 2.5), (2.75, 2.5)),
            ((2.25, 2.75), (9.25, 9.5)),
            ((2.5, 5.5), (5.75, 5.9)),
            ((2.5, 5.5), (9.25, 9.75)),
            ((2.25, 2.5), (2.75, 6.5)),
            ((2.25, 2.5), (6.5, 10.5)),
            ((2.5, 5.5), (5.5, 9.5)),
            ((2.5, 5.5), (7.5, 10.5)),
            ((2.5, 5.5), (2.75, 8.5)),
            ((2.5, 8.5), (5.5, 11.5)),
            ((2.5, 8.5), (5.5, 8.75)),
            ((2.5, 8.5), (2.75, 8.75)),
        ];
        for (k, (l, r)) in cases.iter().enumerate() {
            assert_eq!(slice(*l, *r).case(), Case(k as u8 + 1), "case {}", k + 1);
        }
    }

    #[test]
    fn increment_inside_an_edge_is_one_over_inverse_slope() {
        // left edge from x = 2 to x = 6 over a full row: 1/slope = 4
        let s = slice((2.0, 6.0), (20.0, 20.0));
        let d = s.coverage(4) - s.coverage(3);
        assert_eq!(d, 0.25); // 1 / |1/slope|; the report's 1 / (2 |1/slope|) would be 0.125
        assert_eq!(s.coverage(3), 0.375);
        assert_eq!(s.coverage(7), 1.0);
        assert_eq!(s.coverage(1), 0.0);
    }
}
