//! DO_FILL (van Rij 3.3.1): one pixel row of one trapezium as X-processor instructions.
//!
//! The row is cut at the pixels the edges' end points fall in (the *separately
//! calculated* pixels, one `Eval1` each). Between them the covered area changes by a
//! constant amount per pixel, so each stretch is one instruction:
//!
//! | stretch | coverage | report's procedure | instruction |
//! | --- | --- | --- | --- |
//! | between the edges | constant `AC` | middle-part | `Eval2(FPx, N, FPI·AC, di·AC)` |
//! | inside one edge's span | `AC + S·X` | sequence | `Eval3(FPx, N, FPi·AC, di·S + di·AC + S·FPi, 2·di·S)` |
//! | inside both edges' spans | `AC + (S1 − S2)·X` | share-sequence | the same `Eval3`, `S = S1 − S2` |
//!
//! `FPi` is the Gouraud intensity at the first pixel's centre, `di` its change per pixel,
//! `S` the coverage increment (`1/|1/slope|`: docs/ERRATA.md). With flat shading (`di = 0`)
//! the same stretches need one order less: `Eval1` for the middle part and `Eval2` for
//! sequences.

use crate::coverage::{Case, Slice};
use crate::trapezoid::{vector, Trapezium, Vector};
use cwisim_isa::{Instruction, Intensity};
use std::fmt::Write as _;

/// How intensity varies over a trapezium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shade {
    /// One intensity for the whole polygon.
    Flat(Vector),
    /// Gouraud: interpolated along the edges, then across each scanline.
    Gouraud,
}

/// The kind of a stretch of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Procedure {
    /// A separately calculated pixel.
    Single,
    /// Constant coverage between the edges.
    MiddlePart,
    /// Inside one edge's span.
    Sequence,
    /// Inside both edges' spans.
    ShareSequence,
}

impl Procedure {
    fn name(self) -> &'static str {
        match self {
            Procedure::Single => "pixel",
            Procedure::MiddlePart => "middle",
            Procedure::Sequence => "sequence",
            Procedure::ShareSequence => "share-sequence",
        }
    }
}

/// One row's instructions, with what produced them.
#[derive(Clone, Debug, PartialEq)]
pub struct RowFill {
    /// The case of the row (box filter only).
    pub case: Option<Case>,
    /// The instructions, each with its procedure.
    pub instructions: Vec<(Procedure, Instruction)>,
    /// A one-line account, for the text trace.
    pub note: String,
}

/// The intensity model of one row: value at a pixel centre and change per pixel.
struct RowShade {
    x_left: f64,
    i_left: Vector,
    di: Vector,
    channels: usize,
}

impl RowShade {
    fn new(t: &Trapezium, shade: &Shade, y: f64, channels: usize) -> RowShade {
        match shade {
            Shade::Flat(v) => RowShade {
                x_left: 0.0,
                i_left: *v,
                di: [0.0; cwisim_isa::MAX_CHANNELS],
                channels,
            },
            Shade::Gouraud => {
                let (xl, xr) = (t.left.x_at(y), t.right.x_at(y));
                let (il, ir) = (t.left.i_at(y, channels), t.right.i_at(y, channels));
                let width = xr - xl;
                // a row where the edges meet (an apex) has no span to interpolate across
                let di = if width > 1e-12 * (1.0 + xl.abs()) {
                    vector(channels, |c| (ir[c] - il[c]) / width)
                } else {
                    [0.0; cwisim_isa::MAX_CHANNELS]
                };
                RowShade {
                    x_left: xl,
                    i_left: il,
                    di,
                    channels,
                }
            }
        }
    }

    /// Intensity at the centre of pixel column `i`.
    fn at(&self, i: i64) -> Vector {
        let dx = i as f64 + 0.5 - self.x_left;
        vector(self.channels, |c| self.i_left[c] + dx * self.di[c])
    }

    fn flat(&self) -> bool {
        self.di[..self.channels].iter().all(|d| *d == 0.0)
    }
}

fn intensity(v: &Vector, channels: usize) -> Intensity {
    Intensity::new(&v[..channels])
}

fn map(v: &Vector, channels: usize, f: impl Fn(f64, usize) -> f64) -> Intensity {
    intensity(&vector(channels, |c| f(v[c], c)), channels)
}

/// Box-filtered fill of `t` in pixel row `row` of an image `width` wide.
pub fn box_row(
    t: &Trapezium,
    row: u32,
    width: u32,
    shade: &Shade,
    channels: usize,
) -> Option<RowFill> {
    let s = Slice::of(t, row)?;
    let h = s.height();
    let rs = RowShade::new(t, shade, 0.5 * (s.y0 + s.y1), channels);
    let (l0, l1, r0, r1) = s.edge_pixels();
    let mut specials = vec![l0, l1, r0, r1];
    specials.sort_unstable();
    specials.dedup();
    let in_left = |p: i64| p > l0 && p < l1;
    let in_right = |p: i64| p > r0 && p < r1;
    let (s_left, s_right) = (s.left.increment(h), s.right.increment(h));
    // (procedure, first, last, coverage increment)
    let mut stretches: Vec<(Procedure, i64, i64, f64)> = Vec::new();
    for (k, &p) in specials.iter().enumerate() {
        stretches.push((Procedure::Single, p, p, 0.0));
        if let Some(&next) = specials.get(k + 1) {
            if next - p >= 2 {
                let q = p + 1;
                let run = match (in_left(q), in_right(q)) {
                    (true, true) => (Procedure::ShareSequence, s_left - s_right),
                    (true, false) => (Procedure::Sequence, s_left),
                    (false, true) => (Procedure::Sequence, -s_right),
                    (false, false) => (Procedure::MiddlePart, 0.0),
                };
                stretches.push((run.0, q, next - 1, run.1));
            }
        }
    }
    let case = s.case();
    let mut fill = RowFill {
        case: Some(case),
        instructions: Vec::new(),
        note: String::new(),
    };
    let _ = write!(
        fill.note,
        "row {row} trapezium {} (polygon {}): case {}:",
        t.id, t.polygon, case.0
    );
    let last_pixel = i64::from(width) - 1;
    for (proc_, first, last, inc) in stretches {
        let (first, last) = (first.max(0), last.min(last_pixel));
        if first > last {
            continue;
        }
        let ac = s.coverage(first);
        if proc_ == Procedure::Single && ac == 0.0 {
            continue; // the edge only touches this pixel's border
        }
        let n = (last - first + 1) as u32;
        let x = first as u32;
        let fpi = rs.at(first);
        let instr = match proc_ {
            Procedure::Single => Instruction::eval1(x, 1, map(&fpi, channels, |v, _| v * ac)),
            Procedure::MiddlePart if rs.flat() => {
                Instruction::eval1(x, n, map(&fpi, channels, |v, _| v * ac))
            }
            Procedure::MiddlePart => Instruction::eval2(
                x,
                n,
                map(&fpi, channels, |v, _| v * ac),
                map(&rs.di, channels, |d, _| d * ac),
            ),
            _ if rs.flat() => Instruction::eval2(
                x,
                n,
                map(&fpi, channels, |v, _| v * ac),
                map(&fpi, channels, |v, _| inc * v),
            ),
            _ => Instruction::eval3(
                x,
                n,
                map(&fpi, channels, |v, _| v * ac),
                map(&fpi, channels, |v, c| {
                    rs.di[c] * inc + rs.di[c] * ac + inc * v
                }),
                map(&rs.di, channels, |d, _| 2.0 * d * inc),
            ),
        };
        if n == 1 {
            let _ = write!(fill.note, " {} {first}", proc_.name());
        } else {
            let _ = write!(fill.note, " {} {first}..={last}", proc_.name());
        }
        fill.instructions.push((proc_, instr));
    }
    if fill.instructions.is_empty() {
        return None;
    }
    Some(fill)
}

/// Point-sampled fill (no anti-aliasing) of `t` in pixel row `row`: the pixels whose
/// centre lies in the trapezium (half-open: `[x_left, x_right)` at `y = row + 0.5`, and
/// `y_top <= y < y_bot`), one `Eval1` (flat) or `Eval2` (Gouraud) — sections 3.1 and 3.2.
pub fn sampled_row(
    t: &Trapezium,
    row: u32,
    width: u32,
    shade: &Shade,
    channels: usize,
) -> Option<RowFill> {
    let y = f64::from(row) + 0.5;
    if !(t.y_top <= y && y < t.y_bot) {
        return None;
    }
    let (xl, xr) = (t.left.x_at(y), t.right.x_at(y));
    let first = ((xl - 0.5).ceil() as i64).max(0);
    let end = ((xr - 0.5).ceil() as i64).min(i64::from(width));
    if end <= first {
        return None;
    }
    let rs = RowShade::new(t, shade, y, channels);
    let (x, n) = (first as u32, (end - first) as u32);
    let fpi = rs.at(first);
    let instr = if rs.flat() {
        Instruction::eval1(x, n, intensity(&fpi, channels))
    } else {
        Instruction::eval2(x, n, intensity(&fpi, channels), intensity(&rs.di, channels))
    };
    Some(RowFill {
        case: None,
        instructions: vec![(Procedure::MiddlePart, instr)],
        note: format!(
            "row {row} trapezium {} (polygon {}): point-sampled span {first}..={}",
            t.id,
            t.polygon,
            end - 1
        ),
    })
}
