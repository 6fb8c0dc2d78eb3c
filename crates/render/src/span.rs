//! The span fitter: one row's per-pixel target values over a run of pixels, sent as the
//! fewest `Eval1` / `Eval2` / `Eval3` pieces whose forward-differenced values stay within
//! a tolerance of every target — how a renderer that shades per pixel (Phong, a Bézier
//! patch's interior) feeds the array without one instruction per pixel.
//!
//! # What a piece adds
//!
//! A piece `[a, a + n)` is one instruction: `Eval1(x, n, I)` adds `I` to every pixel,
//! `Eval2` the running value `v` of `v := I; v := v + dI`, `Eval3` that of
//! `v := v + d; d := d + ddI` (`docs/ISA.md`). A piece is accepted only after it has been
//! run here with exactly the array's `f64` adder chain — the same additions in the same
//! order — and every value it carries is within `tolerance` of its pixel's target, per
//! channel (targets are ≥ 0, so a value the array drops as negative, while `Acc_mode` is
//! off, is within it too). So, in `f64`, the array's output is within the tolerance of every target
//! whatever the targets are (nothing is extrapolated), and the fixed formats add at most
//! [`cwisim_xproc::numeric::error_bound`] of the piece's order and length.
//!
//! # How pieces are chosen: greedy, longest first
//!
//! From the first pixel not yet sent, the fitter looks for the longest piece it can
//! build (lengths 1, 2, 4, 8, … until one fails, then a binary search between the last
//! that fitted and the first that did not), sends it, and goes on after it. For a family
//! of pieces closed under taking sub-runs (a polynomial that fits a run fits every part
//! of it), greedy longest-first is optimal in the number of pieces: any cover needs a
//! piece starting at the first pixel, and the longest one leaves the least to cover. The
//! fitter's pieces are close to that, not exactly: a piece is built by interpolation
//! (below), not as the minimax polynomial, so a longer run can occasionally fit where a
//! shorter one does not, and the search can miss it. Every piece sent is nevertheless
//! checked, so the guarantee above never depends on that.
//!
//! For a candidate run the cheapest form that fits is kept: a constant (`Eval1`, one
//! value per channel; the mid-range of the targets), then a line (`Eval2`; through the
//! first and last targets), then a parabola (`Eval3`; through the first, middle and last
//! targets). The line and the parabola are then shifted by the mid-range of their
//! residuals, which balances the largest errors on either side — for convex or concave
//! targets that is the minimax error of the secant.
//!
//! Tolerance 0 means exactly the targets: one `Eval1` per pixel, no search.

use crate::error::NonFinite;
use cwisim_isa::{Instruction, Intensity, TraceWrite, MAX_CHANNELS};
use std::io;

/// What fitting spans did: pieces by opcode, and the work spent finding them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpanStats {
    /// Pixels covered (each with a target: the host's shading evaluations).
    pub pixels: u64,
    /// `Eval1` pieces sent.
    pub eval1: u64,
    /// `Eval2` pieces sent.
    pub eval2: u64,
    /// `Eval3` pieces sent.
    pub eval3: u64,
    /// Candidate pieces built and checked against their targets (the fitter's own work).
    pub candidates: u64,
}

impl SpanStats {
    /// Pieces (instructions) sent.
    pub fn pieces(&self) -> u64 {
        self.eval1 + self.eval2 + self.eval3
    }

    /// Adds another fit's counts.
    pub fn add(&mut self, other: &SpanStats) {
        self.pixels += other.pixels;
        self.eval1 += other.eval1;
        self.eval2 += other.eval2;
        self.eval3 += other.eval3;
        self.candidates += other.candidates;
    }
}

/// Why a run cannot be fitted.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SpanError {
    /// The tolerance is negative or not a number.
    #[error("the span tolerance must be a number ≥ 0, found {0}")]
    Tolerance(f64),
    /// `targets` does not hold `channels` values per pixel, or `channels` is outside
    /// `1..=4`.
    #[error("{targets} target values do not make whole pixels of {channels} channel(s)")]
    Shape {
        /// Values given.
        targets: usize,
        /// Channels per pixel.
        channels: usize,
    },
    /// A target the array cannot show: not finite, or negative (the array drops negative
    /// contributions while `Acc_mode` is off, as it is unless a stream toggles it).
    #[error("pixel {pixel}, channel {channel}: target {value} is not a finite value ≥ 0")]
    Target {
        /// Pixel within the run.
        pixel: usize,
        /// Channel.
        channel: usize,
        /// The value.
        value: f64,
    },
}

/// Fits the run of pixels `x, x+1, …` whose targets are `targets` (pixel-major,
/// `channels` values per pixel) within `tolerance` per value, and writes the pieces to
/// `sink` in order. A target that is not finite (a shade that overflowed) is refused as
/// [`NonFinite`] (the pipeline's [`RenderError::Overflow`](crate::RenderError::Overflow),
/// bad input), naming its pixel; any other fault as [`SpanError`].
pub fn fit_span(
    x: u32,
    targets: &[f64],
    channels: usize,
    tolerance: f64,
    sink: &mut dyn TraceWrite,
) -> io::Result<SpanStats> {
    let fitter = Fitter::new(targets, channels, tolerance).map_err(|e| match e {
        // a shade that overflowed where it was made: the scene's doing, located
        SpanError::Target {
            pixel,
            channel,
            value,
        } if !value.is_finite() => NonFinite {
            row: None,
            stage: "per-pixel shading",
            detail: format!(
                "pixel {}, channel {channel}: the shade is {value}",
                u64::from(x) + pixel as u64
            ),
        }
        .into_io(),
        e => io::Error::new(io::ErrorKind::InvalidInput, e),
    })?;
    fitter.send(x, sink)
}

/// The pieces [`fit_span`] would send, with its statistics, without a sink.
pub fn fit_pieces(
    x: u32,
    targets: &[f64],
    channels: usize,
    tolerance: f64,
) -> Result<(Vec<Instruction>, SpanStats), SpanError> {
    let fitter = Fitter::new(targets, channels, tolerance)?;
    let mut out: Vec<Instruction> = Vec::new();
    let stats = fitter
        .send(x, &mut out)
        .expect("a Vec<Instruction> takes every write");
    Ok((out, stats))
}

/// One run's targets, checked.
struct Fitter<'t> {
    targets: &'t [f64],
    channels: usize,
    tolerance: f64,
}

/// A candidate piece: its order (1–3) and per-channel `I`, `dI`, `ddI`.
#[derive(Clone, Copy, Debug)]
struct Piece {
    order: u8,
    len: usize,
    i: [f64; MAX_CHANNELS],
    di: [f64; MAX_CHANNELS],
    ddi: [f64; MAX_CHANNELS],
}

impl<'t> Fitter<'t> {
    fn new(targets: &'t [f64], channels: usize, tolerance: f64) -> Result<Self, SpanError> {
        if tolerance.is_nan() || tolerance < 0.0 {
            return Err(SpanError::Tolerance(tolerance));
        }
        if !(1..=MAX_CHANNELS).contains(&channels) || !targets.len().is_multiple_of(channels) {
            return Err(SpanError::Shape {
                targets: targets.len(),
                channels,
            });
        }
        if let Some(k) = targets.iter().position(|t| !(t.is_finite() && *t >= 0.0)) {
            return Err(SpanError::Target {
                pixel: k / channels,
                channel: k % channels,
                value: targets[k],
            });
        }
        Ok(Fitter {
            targets,
            channels,
            tolerance,
        })
    }

    fn pixels(&self) -> usize {
        self.targets.len() / self.channels
    }

    fn target(&self, pixel: usize, c: usize) -> f64 {
        self.targets[pixel * self.channels + c]
    }

    fn send(&self, x: u32, sink: &mut dyn TraceWrite) -> io::Result<SpanStats> {
        let n = self.pixels();
        let mut stats = SpanStats {
            pixels: n as u64,
            ..SpanStats::default()
        };
        let mut a = 0;
        while a < n {
            let piece = if self.tolerance == 0.0 {
                self.exact(a)
            } else {
                self.longest(a, &mut stats.candidates)
            };
            let at = x + a as u32;
            let c = self.channels;
            let (i, di, ddi) = (
                Intensity::new(&piece.i[..c]),
                Intensity::new(&piece.di[..c]),
                Intensity::new(&piece.ddi[..c]),
            );
            let len = piece.len as u32;
            let instr = match piece.order {
                1 => {
                    stats.eval1 += 1;
                    Instruction::eval1(at, len, i)
                }
                2 => {
                    stats.eval2 += 1;
                    Instruction::eval2(at, len, i, di)
                }
                _ => {
                    stats.eval3 += 1;
                    Instruction::eval3(at, len, i, di, ddi)
                }
            };
            sink.write(&instr)?;
            a += piece.len;
        }
        Ok(stats)
    }

    /// One `Eval1` holding pixel `a`'s targets exactly.
    fn exact(&self, a: usize) -> Piece {
        let mut p = Piece {
            order: 1,
            len: 1,
            i: [0.0; MAX_CHANNELS],
            di: [0.0; MAX_CHANNELS],
            ddi: [0.0; MAX_CHANNELS],
        };
        for c in 0..self.channels {
            p.i[c] = self.target(a, c);
        }
        p
    }

    /// The longest piece from `a` the search finds (at least one pixel).
    fn longest(&self, a: usize, candidates: &mut u64) -> Piece {
        let room = self.pixels() - a;
        let mut best = self.exact(a);
        let mut ok = 1;
        let mut fail = None;
        let mut len = 2;
        while len <= room {
            match self.fit(a, len, candidates) {
                Some(p) => {
                    best = p;
                    ok = len;
                    len *= 2;
                }
                None => {
                    fail = Some(len);
                    break;
                }
            }
        }
        let mut hi = match fail {
            Some(f) => f,
            None if ok < room => room + 1,
            None => return best,
        };
        // the last length that fitted is `ok`, the first that failed (or past the room)
        // is `hi`: halve the gap
        while hi - ok > 1 {
            let mid = ok + (hi - ok) / 2;
            match self.fit(a, mid, candidates) {
                Some(p) => {
                    best = p;
                    ok = mid;
                }
                None => hi = mid,
            }
        }
        best
    }

    /// The cheapest piece over `[a, a + len)` that keeps every pixel within tolerance.
    fn fit(&self, a: usize, len: usize, candidates: &mut u64) -> Option<Piece> {
        let c = self.channels;
        // a constant: the mid-range of the targets
        let mut p = Piece {
            order: 1,
            len,
            i: [0.0; MAX_CHANNELS],
            di: [0.0; MAX_CHANNELS],
            ddi: [0.0; MAX_CHANNELS],
        };
        for ch in 0..c {
            let (lo, hi) = (a..a + len)
                .map(|k| self.target(k, ch))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), t| {
                    (l.min(t), h.max(t))
                });
            p.i[ch] = lo + (hi - lo) / 2.0;
        }
        *candidates += 1;
        if self.holds(a, &p) {
            return Some(p);
        }
        // a line through the first and last targets, then balanced
        let e = (len - 1) as f64;
        p.order = 2;
        for ch in 0..c {
            let (t0, te) = (self.target(a, ch), self.target(a + len - 1, ch));
            p.i[ch] = t0;
            p.di[ch] = (te - t0) / e;
        }
        self.balance(a, &mut p);
        *candidates += 1;
        if self.holds(a, &p) {
            return Some(p);
        }
        if len < 3 {
            return None;
        }
        // a parabola through the first, middle and last targets, then balanced
        let (m, e) = ((len - 1) / 2, len - 1);
        let (mf, ef) = (m as f64, e as f64);
        // value_k = I + k·dI + k(k−1)/2·ddI through k = 0, m, e
        let det = mf * ef * (ef - mf) / 2.0;
        p.order = 3;
        for ch in 0..c {
            let t0 = self.target(a, ch);
            let (ym, ye) = (self.target(a + m, ch) - t0, self.target(a + e, ch) - t0);
            let (bm, be) = (mf * (mf - 1.0) / 2.0, ef * (ef - 1.0) / 2.0);
            p.i[ch] = t0;
            p.di[ch] = (ym * be - ye * bm) / det;
            p.ddi[ch] = (mf * ye - ef * ym) / det;
        }
        self.balance(a, &mut p);
        *candidates += 1;
        self.holds(a, &p).then_some(p)
    }

    /// Shifts `I` by the mid-range of the residuals, per channel.
    fn balance(&self, a: usize, p: &mut Piece) {
        for ch in 0..self.channels {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            wave(p, ch, |k, v| {
                let r = self.target(a + k, ch) - v;
                lo = lo.min(r);
                hi = hi.max(r);
                true
            });
            if lo.is_finite() && hi.is_finite() {
                p.i[ch] += lo + (hi - lo) / 2.0;
            }
        }
    }

    /// Whether every value the piece's wave carries, with the array's adder chain, is
    /// within tolerance of its target. (A negative value within tolerance of a target
    /// ≥ 0 is within it whether the array adds it or drops it, so this holds in either
    /// `Acc_mode`.)
    fn holds(&self, a: usize, p: &Piece) -> bool {
        (0..self.channels).all(|ch| {
            wave(p, ch, |k, v| {
                (v - self.target(a + k, ch)).abs() <= self.tolerance
            })
        })
    }
}

/// The values a piece's wave carries at its pixels for channel `ch`, in order, with the
/// array's additions (`v := v + d`, then `d := d + dd`); stops when `f` says so.
fn wave(p: &Piece, ch: usize, mut f: impl FnMut(usize, f64) -> bool) -> bool {
    let (mut v, mut d, dd) = (p.i[ch], p.di[ch], p.ddi[ch]);
    for k in 0..p.len {
        if !f(k, v) {
            return false;
        }
        if p.order >= 2 {
            v += d;
        }
        if p.order >= 3 {
            d += dd;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::Opcode;

    #[test]
    fn tolerance_zero_is_one_eval1_per_pixel() {
        let (pieces, stats) = fit_pieces(3, &[0.5, 0.25, 0.25, 1.0], 1, 0.0).unwrap();
        assert_eq!(pieces.len(), 4);
        assert!(pieces.iter().all(|p| p.op == Opcode::Eval1 && p.dx == 1));
        assert_eq!(pieces[0].x, 3);
        assert_eq!((stats.pixels, stats.eval1, stats.candidates), (4, 4, 0));
    }

    #[test]
    fn constants_lines_and_parabolas_are_one_piece_each() {
        let constant: Vec<f64> = vec![0.3; 40];
        let line: Vec<f64> = (0..40).map(|k| 0.1 + 0.01 * k as f64).collect();
        let parabola: Vec<f64> = (0..40)
            .map(|k| 0.2 + 0.003 * k as f64 + 0.0004 * (k * k) as f64)
            .collect();
        for (targets, op) in [
            (&constant, Opcode::Eval1),
            (&line, Opcode::Eval2),
            (&parabola, Opcode::Eval3),
        ] {
            let (pieces, stats) = fit_pieces(0, targets, 1, 1e-9).unwrap();
            assert_eq!(pieces.len(), 1, "{pieces:?}");
            assert_eq!(pieces[0].op, op);
            assert_eq!(pieces[0].dx, 40);
            assert_eq!(stats.pieces(), 1);
        }
    }

    #[test]
    fn bad_input_is_refused() {
        assert_eq!(
            fit_pieces(0, &[0.5], 1, -1.0).unwrap_err(),
            SpanError::Tolerance(-1.0)
        );
        assert!(matches!(
            fit_pieces(0, &[0.5, 0.5, 0.5], 2, 0.1).unwrap_err(),
            SpanError::Shape { .. }
        ));
        assert_eq!(
            fit_pieces(0, &[0.5, -0.25], 1, 0.1)
                .unwrap_err()
                .to_string(),
            "pixel 1, channel 0: target -0.25 is not a finite value ≥ 0"
        );
        assert!(fit_pieces(0, &[f64::NAN], 1, 0.1).is_err());
        // an empty run sends nothing
        assert_eq!(fit_pieces(0, &[], 3, 0.1).unwrap().0.len(), 0);
    }
}
