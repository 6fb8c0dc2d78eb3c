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
//!
//! That is the report's box filter ([`BoxValue::Centre`], `--aa box-centre`): each pixel
//! holds its exact coverage times the intensity at its centre. [`BoxValue::Exact`]
//! (`--aa box`) sends the same instructions carrying the exact integral of the
//! intensity over each pixel's covered part ([`crate::integral`]): a separately
//! calculated pixel's `Eval1` holds its integral; a sequence's or share-sequence's
//! `Eval3` the quadratic in the pixel index that its integrals are (docs/ERRATA.md, "The
//! exact box filter"); a middle part is already exact. Where the intensity is constant
//! over the row both are exact and the instructions identical; where it changes down the
//! row but not along it, the report's sequence is an `Eval2` and the exact one an
//! `Eval3` (the only difference in the opcode mix; the count is the same).
//!
//! With [`Claim::Eval0`] the stretches whose pixels are all fully covered (a middle part
//! or a separately calculated pixel of coverage exactly 1) are claimed with `Eval0`
//! instead, and so is the whole span of a point-sampled row: one `Eval0` when the row is
//! flat, else a staircase of `Eval0`s ([`claim_chunk`], docs/ERRATA.md, D9).

use crate::coverage::{Case, Slice};
use crate::floor::ceil_i64;
use crate::integral::{forward_differences, RowPlane};
use crate::trapezoid::{vector, Trapezium, Vector};
use crate::Claim;
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

/// What a box-filtered pixel holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BoxValue {
    /// The integral of the intensity over the pixel's covered part (`--aa box`).
    #[default]
    Exact,
    /// The covered area times the intensity at the pixel centre: the report's
    /// approximation (`--aa box-centre`, docs/ERRATA.md, D7).
    Centre,
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
    /// Fully covered pixels claimed with `Eval0` ([`Claim::Eval0`]).
    Claim,
}

impl Procedure {
    fn name(self) -> &'static str {
        match self {
            Procedure::Single => "pixel",
            Procedure::MiddlePart => "middle",
            Procedure::Sequence => "sequence",
            Procedure::ShareSequence => "share-sequence",
            Procedure::Claim => "claim",
        }
    }
}

/// One row's instructions, with what produced them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RowFill {
    /// The case of the row (box filter only).
    pub case: Option<Case>,
    /// The instructions, each with its procedure.
    pub instructions: Vec<(Procedure, Instruction)>,
    /// A one-line account, for the text trace (empty when notes were not asked for).
    pub note: String,
}

impl RowFill {
    fn reset(&mut self, case: Option<Case>) {
        self.case = case;
        self.instructions.clear();
        self.note.clear();
    }
}

/// The intensity model of one row: the scanline function at height `y`, its value at
/// the left edge and change per pixel (what the report's values take at pixel centres,
/// and what the exact box filter's [`RowPlane`] is built on).
pub(crate) struct RowShade {
    /// The left edge's x at `y` (0 for flat shading).
    pub(crate) x_left: f64,
    /// The intensity there.
    pub(crate) i_left: Vector,
    /// The change per pixel (0 where the edges meet).
    pub(crate) di: Vector,
    /// Channels in use.
    pub(crate) channels: usize,
}

impl RowShade {
    /// The scanline function of `t` at height `y` (inlined, as [`Slice::of`]).
    #[inline]
    pub(crate) fn new(t: &Trapezium, shade: &Shade, y: f64, channels: usize) -> RowShade {
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

/// The number of pixels per `Eval0` when a run whose Gouraud intensity changes by `di`
/// (per channel) per pixel is claimed as a staircase: the largest `k ≥ 1` with
/// `max_c |di[c]| · (k − 1) / 2 ≤ tolerance`, at most `n`. Each `Eval0` holds the value
/// at the middle of its `k` pixels, so no pixel centre is further than `(k − 1) / 2`
/// pixels from it. A run with `di = 0` (or a tolerance no run length reaches) is one
/// `Eval0`; a negative or NaN tolerance admits only `k = 1`.
pub fn claim_chunk(di: &[f64], tolerance: f64, n: u32) -> u32 {
    let n = n.max(1);
    let m = di.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    if m == 0.0 {
        return n;
    }
    if tolerance.is_nan() || tolerance < 0.0 {
        return 1;
    }
    let fits = |k: u32| m * f64::from(k - 1) / 2.0 <= tolerance;
    if n == 1 || fits(n) {
        return n; // a huge tolerance, or a gentle gradient: the whole run
    }
    // 2·tolerance/m, which may overflow (the cast saturates), capped at the run; then
    // correct the rounding of the division against the defining inequality
    let q = (2.0 * tolerance / m).floor() as u32;
    let mut k = q.min(n - 1) + 1;
    while k > 1 && !fits(k) {
        k -= 1;
    }
    while k < n && fits(k + 1) {
        k += 1;
    }
    k
}

/// Pushes the `Eval0`s that claim pixels `first ..= last` of a row: one when the row is
/// flat, else a staircase of [`claim_chunk`] pixels each, holding the Gouraud value at the
/// chunk's centre (the mean of its first and last pixel-centre values). Returns how many.
fn claim_run(rs: &RowShade, first: i64, last: i64, tolerance: f64, out: &mut impl RowOut) -> usize {
    let ch = rs.channels;
    let n = (last - first + 1) as u32;
    if rs.flat() {
        let instr = Instruction::eval0(first as u32, n, intensity(&rs.at(first), ch));
        out.put(Procedure::Claim, &instr);
        return 1;
    }
    let k = i64::from(claim_chunk(&rs.di[..ch], tolerance, n));
    let mut count = 0;
    let mut a = first;
    while a <= last {
        let b = (a + k - 1).min(last);
        let (va, vb) = (rs.at(a), rs.at(b));
        let centre = vector(ch, |c| 0.5 * (va[c] + vb[c]));
        let instr = Instruction::eval0(a as u32, (b - a + 1) as u32, intensity(&centre, ch));
        out.put(Procedure::Claim, &instr);
        count += 1;
        a = b + 1;
    }
    count
}

/// The first `channels` values of `v` as an [`Intensity`]. Each common channel count
/// is its own call with a constant length: with a variable one the slice's pointer and
/// length are stored as two words and read back as one 16-byte load, which stalls
/// (store forwarding) once per value.
#[inline]
fn intensity(v: &Vector, channels: usize) -> Intensity {
    match channels {
        1 => Intensity::new(&v[..1]),
        3 => Intensity::new(&v[..3]),
        _ => Intensity::new(&v[..channels]),
    }
}

#[inline]
fn map(v: &Vector, channels: usize, f: impl Fn(f64, usize) -> f64) -> Intensity {
    intensity(&vector(channels, |c| f(v[c], c)), channels)
}

/// Box-filtered fill of `t` in pixel row `row` of an image `width` wide, each pixel
/// holding what `value` says. With [`Claim::Eval0`], the stretches of coverage exactly 1
/// are claimed with `Eval0`.
#[allow(clippy::too_many_arguments)]
pub fn box_row(
    t: &Trapezium,
    row: u32,
    width: u32,
    shade: &Shade,
    channels: usize,
    claim: Claim,
    value: BoxValue,
) -> Option<RowFill> {
    let mut fill = RowFill::default();
    box_row_into(
        t, row, width, shade, channels, claim, value, true, &mut fill,
    )
    .then_some(fill)
}

/// [`box_row`] into a reused `fill` (cleared first), writing its note only when `notes`;
/// false when the row emits nothing. No allocation per row.
#[allow(clippy::too_many_arguments)]
pub fn box_row_into(
    t: &Trapezium,
    row: u32,
    width: u32,
    shade: &Shade,
    channels: usize,
    claim: Claim,
    value: BoxValue,
    notes: bool,
    fill: &mut RowFill,
) -> bool {
    fill.reset(None);
    let note = notes.then_some(&mut fill.note);
    fill.case = box_row_to(
        t,
        row,
        width,
        shade,
        channels,
        claim,
        value,
        note,
        &mut fill.instructions,
    );
    !fill.instructions.is_empty()
}

/// Where DO_FILL puts a row's instructions, each with the procedure that made it: a
/// [`RowFill`]'s list, or (what [`crate::emit_rows`] does when no notes are asked for)
/// straight into a sink, so that no instruction is built twice.
pub trait RowOut {
    /// Takes one instruction.
    fn put(&mut self, proc_: Procedure, instr: &Instruction);
}

impl RowOut for Vec<(Procedure, Instruction)> {
    fn put(&mut self, proc_: Procedure, instr: &Instruction) {
        self.push((proc_, instr.clone()));
    }
}

/// [`box_row`]'s instructions into `out`, its note appended to `note` when there is one;
/// the row's case, or `None` when the trapezium does not reach the row.
#[allow(clippy::too_many_arguments)]
pub fn box_row_to(
    t: &Trapezium,
    row: u32,
    width: u32,
    shade: &Shade,
    channels: usize,
    claim: Claim,
    value: BoxValue,
    note: Option<&mut String>,
    out: &mut impl RowOut,
) -> Option<Case> {
    let s = Slice::of(t, row)?;
    Some(box_slice_to(
        t, &s, width, shade, channels, claim, value, note, out,
    ))
}

/// [`box_row_to`] for the row's [`Slice`] of `t` already taken (what
/// [`crate::scan::scan_slices_of`] hands over); the row's case.
#[allow(clippy::too_many_arguments)]
pub fn box_slice_to(
    t: &Trapezium,
    s: &Slice,
    width: u32,
    shade: &Shade,
    channels: usize,
    claim: Claim,
    value: BoxValue,
    mut note: Option<&mut String>,
    out: &mut impl RowOut,
) -> Case {
    let row = s.row;
    let h = s.height();
    let rs = RowShade::new(t, shade, 0.5 * (s.y0 + s.y1), channels);
    // the exact values, where they differ from the report's (a varying intensity)
    let plane_of_row;
    let plane = match (value, shade) {
        (BoxValue::Exact, Shade::Gouraud) => {
            plane_of_row = RowPlane::new(t, s, &rs);
            Some(&plane_of_row).filter(|p| !p.constant())
        }
        _ => None, // a flat row's values are the report's
    };
    let (l0, l1, r0, r1) = s.edge_pixels();
    let mut specials = [l0, l1, r0, r1];
    specials.sort_unstable();
    let mut n_specials = 1;
    for k in 1..4 {
        if specials[k] != specials[n_specials - 1] {
            specials[n_specials] = specials[k];
            n_specials += 1;
        }
    }
    let specials = &specials[..n_specials];
    let in_left = |p: i64| p > l0 && p < l1;
    let in_right = |p: i64| p > r0 && p < r1;
    // (procedure, first, last, coverage increment): at most 4 pixels and 3 runs
    let mut stretches = [(Procedure::Single, 0i64, 0i64, 0.0f64); 7];
    let mut n_stretches = 0;
    for (k, &p) in specials.iter().enumerate() {
        stretches[n_stretches] = (Procedure::Single, p, p, 0.0);
        n_stretches += 1;
        if let Some(&next) = specials.get(k + 1) {
            if next - p >= 2 {
                let q = p + 1;
                // the increments only where a run needs them (a division each)
                let run = match (in_left(q), in_right(q)) {
                    (true, true) => (
                        Procedure::ShareSequence,
                        s.left.increment(h) - s.right.increment(h),
                    ),
                    (true, false) => (Procedure::Sequence, s.left.increment(h)),
                    (false, true) => (Procedure::Sequence, -s.right.increment(h)),
                    (false, false) => (Procedure::MiddlePart, 0.0),
                };
                stretches[n_stretches] = (run.0, q, next - 1, run.1);
                n_stretches += 1;
            }
        }
    }
    let case = s.case();
    if let Some(note) = note.as_mut() {
        let _ = write!(
            note,
            "row {row} trapezium {} (polygon {}): case {}:",
            t.id, t.polygon, case.0
        );
    }
    let last_pixel = i64::from(width) - 1;
    for &(proc_, first, last, inc) in &stretches[..n_stretches] {
        let (first, last) = (first.max(0), last.min(last_pixel));
        if first > last {
            continue;
        }
        let n = (last - first + 1) as u32;
        let instr = match (proc_, plane) {
            (Procedure::Sequence | Procedure::ShareSequence, Some(p)) => exact_run(p, first, last),
            _ => {
                let ac = s.coverage(first);
                if proc_ == Procedure::Single && ac == 0.0 {
                    continue; // the edge only touches this pixel's border
                }
                if let Claim::Eval0 { tolerance } = claim {
                    let full =
                        matches!(proc_, Procedure::Single | Procedure::MiddlePart) && ac == 1.0;
                    if full {
                        push_claim(&rs, first, last, tolerance, out, note.as_deref_mut());
                        continue;
                    }
                }
                match (proc_, plane) {
                    (Procedure::Single, Some(p)) => {
                        Instruction::eval1(first as u32, 1, intensity(&p.pixel(first), channels))
                    }
                    _ => centre_instruction(proc_, first as u32, n, ac, inc, &rs),
                }
            }
        };
        if let Some(note) = note.as_mut() {
            if n == 1 {
                let _ = write!(note, " {} {first}", proc_.name());
            } else {
                let _ = write!(note, " {} {first}..={last}", proc_.name());
            }
        }
        out.put(proc_, &instr);
    }
    case
}

/// The report's instruction for a stretch `x .. x + n` of procedure `proc_`: coverage
/// `ac` at its first pixel growing by `inc` per pixel, times the intensity at each pixel
/// centre (`rs` at the first, changing by `rs.di`).
fn centre_instruction(
    proc_: Procedure,
    x: u32,
    n: u32,
    ac: f64,
    inc: f64,
    rs: &RowShade,
) -> Instruction {
    let channels = rs.channels;
    let fpi = &rs.at(i64::from(x));
    match proc_ {
        Procedure::Single | Procedure::Claim => {
            Instruction::eval1(x, 1, map(fpi, channels, |v, _| v * ac))
        }
        Procedure::MiddlePart if rs.flat() => {
            Instruction::eval1(x, n, map(fpi, channels, |v, _| v * ac))
        }
        Procedure::MiddlePart => Instruction::eval2(
            x,
            n,
            map(fpi, channels, |v, _| v * ac),
            map(&rs.di, channels, |d, _| d * ac),
        ),
        _ if rs.flat() => Instruction::eval2(
            x,
            n,
            map(fpi, channels, |v, _| v * ac),
            map(fpi, channels, |v, _| inc * v),
        ),
        _ => Instruction::eval3(
            x,
            n,
            map(fpi, channels, |v, _| v * ac),
            map(fpi, channels, |v, c| {
                rs.di[c] * inc + rs.di[c] * ac + inc * v
            }),
            map(&rs.di, channels, |d, _| 2.0 * d * inc),
        ),
    }
}

/// The exact values of a sequence or share-sequence `first ..= last` as one `Eval3`:
/// the quadratic through the exact integrals at its first, middle and last pixel.
fn exact_run(p: &RowPlane, first: i64, last: i64) -> Instruction {
    let n = (last - first + 1) as u32;
    let (e0, em, el) = (
        p.pixel(first),
        p.pixel(first + (last - first) / 2),
        p.pixel(last),
    );
    let mut ops = [[0.0; cwisim_isa::MAX_CHANNELS]; 3];
    for c in 0..p.channels {
        let (v, d, dd) = forward_differences(n, e0[c], em[c], el[c]);
        ops[0][c] = v;
        ops[1][c] = d;
        ops[2][c] = dd;
    }
    let ch = p.channels;
    Instruction::eval3(
        first as u32,
        n,
        intensity(&ops[0], ch),
        intensity(&ops[1], ch),
        intensity(&ops[2], ch),
    )
}

/// Claims pixels `first ..= last` into `out`, with its note (` claim 3..=9 (2 Eval0)`)
/// appended to `note` when there is one.
fn push_claim(
    rs: &RowShade,
    first: i64,
    last: i64,
    tolerance: f64,
    out: &mut impl RowOut,
    note: Option<&mut String>,
) {
    let count = claim_run(rs, first, last, tolerance, out);
    if let Some(note) = note {
        if first == last {
            let _ = write!(note, " claim {first}");
        } else {
            let _ = write!(note, " claim {first}..={last}");
        }
        let _ = write!(note, " ({count} Eval0)");
    }
}

/// The pixels `first..end` whose centre lies in `t` in pixel row `row` (half-open:
/// `[x_left, x_right)` at `y = row + 0.5`, and `y_top <= y < y_bot`), within the image's
/// `width`; `None` when there are none. Point sampling's rule, shared by every emitter.
pub fn sampled_span(t: &Trapezium, row: u32, width: u32) -> Option<(i64, i64)> {
    let y = f64::from(row) + 0.5;
    if !(t.y_top <= y && y < t.y_bot) {
        return None;
    }
    let (xl, xr) = (t.left.x_at(y), t.right.x_at(y));
    let first = ceil_i64(xl - 0.5).max(0);
    let end = ceil_i64(xr - 0.5).min(i64::from(width));
    (end > first).then_some((first, end))
}

/// Point-sampled fill (no anti-aliasing) of `t` in pixel row `row`: the pixels whose
/// centre lies in the trapezium (half-open: `[x_left, x_right)` at `y = row + 0.5`, and
/// `y_top <= y < y_bot`), one `Eval1` (flat) or `Eval2` (Gouraud) — sections 3.1 and 3.2.
/// With [`Claim::Eval0`] the polygon owns the whole span, which is claimed with `Eval0`.
pub fn sampled_row(
    t: &Trapezium,
    row: u32,
    width: u32,
    shade: &Shade,
    channels: usize,
    claim: Claim,
) -> Option<RowFill> {
    let mut fill = RowFill::default();
    sampled_row_into(t, row, width, shade, channels, claim, true, &mut fill).then_some(fill)
}

/// [`sampled_row`] into a reused `fill` (cleared first), writing its note only when
/// `notes`; false when the row emits nothing.
#[allow(clippy::too_many_arguments)]
pub fn sampled_row_into(
    t: &Trapezium,
    row: u32,
    width: u32,
    shade: &Shade,
    channels: usize,
    claim: Claim,
    notes: bool,
    fill: &mut RowFill,
) -> bool {
    let Some((first, end)) = sampled_span(t, row, width) else {
        return false;
    };
    let y = f64::from(row) + 0.5;
    let rs = RowShade::new(t, shade, y, channels);
    fill.reset(None);
    if let Claim::Eval0 { tolerance } = claim {
        if notes {
            let _ = write!(
                fill.note,
                "row {row} trapezium {} (polygon {}): point-sampled",
                t.id, t.polygon
            );
        }
        let note = notes.then_some(&mut fill.note);
        push_claim(&rs, first, end - 1, tolerance, &mut fill.instructions, note);
        return true;
    }
    let (x, n) = (first as u32, (end - first) as u32);
    let fpi = rs.at(first);
    let instr = if rs.flat() {
        Instruction::eval1(x, n, intensity(&fpi, channels))
    } else {
        Instruction::eval2(x, n, intensity(&fpi, channels), intensity(&rs.di, channels))
    };
    fill.instructions.push((Procedure::MiddlePart, instr));
    if notes {
        let _ = write!(
            fill.note,
            "row {row} trapezium {} (polygon {}): point-sampled span {first}..={}",
            t.id,
            t.polygon,
            end - 1
        );
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn claim_vec(rs: &RowShade, first: i64, last: i64, tolerance: f64) -> Vec<Instruction> {
        let mut out = Vec::new();
        let n = claim_run(rs, first, last, tolerance, &mut out);
        assert_eq!(n, out.len());
        out.into_iter().map(|(_, i)| i).collect()
    }
    use cwisim_isa::{Opcode, MAX_CHANNELS};

    fn shade(x_left: f64, i_left: &[f64], di: &[f64]) -> RowShade {
        let mut rs = RowShade {
            x_left,
            i_left: [0.0; MAX_CHANNELS],
            di: [0.0; MAX_CHANNELS],
            channels: i_left.len(),
        };
        rs.i_left[..i_left.len()].copy_from_slice(i_left);
        rs.di[..di.len()].copy_from_slice(di);
        rs
    }

    /// The definition, by search: the largest `k` in `1..=n` with `m·(k−1)/2 ≤ tolerance`.
    fn chunk_by_search(di: &[f64], tolerance: f64, n: u32) -> u32 {
        let m = di.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        (1..=n)
            .rev()
            .find(|&k| k == 1 || m * f64::from(k - 1) / 2.0 <= tolerance)
            .unwrap()
    }

    #[test]
    fn claim_chunk_is_the_largest_k_within_the_tolerance() {
        // m·(k−1)/2 ≤ 1/512 with m = 1/256: k − 1 ≤ 1
        assert_eq!(claim_chunk(&[1.0 / 256.0], 1.0 / 512.0, 100), 2);
        assert_eq!(claim_chunk(&[-1.0 / 256.0], 1.0 / 512.0, 100), 2);
        // the largest |di| of the channels decides: 0.004·(k−1)/2 ≤ 0.01 gives k = 6
        assert_eq!(claim_chunk(&[0.001, -0.004, 0.0], 0.01, 100), 6);
        assert_eq!(claim_chunk(&[0.001, -0.004, 0.0], 0.01, 4), 4); // capped at the run
        assert_eq!(claim_chunk(&[0.01], 1.0 / 512.0, 100), 1);
        // tolerance 0: one pixel per Eval0, unless the run is flat
        assert_eq!(claim_chunk(&[1e-300], 0.0, 100), 1);
        assert_eq!(claim_chunk(&[0.0, 0.0], 0.0, 100), 100);
        // huge tolerances and tiny gradients overflow 2·tolerance/|di|: the whole run
        assert_eq!(claim_chunk(&[1e-300], 1e9, 4096), 4096);
        assert_eq!(claim_chunk(&[1e-300], f64::MAX, 4096), 4096);
        assert_eq!(claim_chunk(&[0.5], f64::INFINITY, 7), 7);
        assert_eq!(claim_chunk(&[0.5], 1e9, 7), 7);
        // nonsense tolerances admit only k = 1
        assert_eq!(claim_chunk(&[0.5], f64::NAN, 7), 1);
        assert_eq!(claim_chunk(&[0.5], -1.0, 7), 1);
        assert_eq!(claim_chunk(&[0.5], 0.25, 1), 1);
        // against the definition, over a spread of gradients, tolerances and runs
        let mut next = crate::test_rng::uniform(0x9E37_79B9_7F4A_7C15u64);
        for _ in 0..20_000 {
            let di = [(next() - 0.5) * 10f64.powf(-6.0 * next()), next() * 1e-3];
            let tolerance =
                [0.0, 1.0 / 512.0, next() * 0.05, 1.0 / 4096.0][(next() * 4.0) as usize];
            let n = 1 + (next() * 300.0) as u32;
            assert_eq!(
                claim_chunk(&di, tolerance, n),
                chunk_by_search(&di, tolerance, n),
                "di {di:?}, tolerance {tolerance}, n {n}"
            );
        }
    }

    /// The staircase, pixel by pixel: which Eval0 holds each pixel of `first..=last`.
    fn staircase(run: &[Instruction], first: i64, last: i64) -> Vec<Vec<f64>> {
        let mut values = Vec::new();
        let mut next = first;
        for i in run {
            assert_eq!(i.op, Opcode::Eval0);
            assert_eq!(i64::from(i.x), next, "the Eval0s tile the run in order");
            assert!(i.dx >= 1);
            for _ in 0..i.dx {
                values.push(i.i().as_slice().to_vec());
            }
            next += i64::from(i.dx);
        }
        assert_eq!(next, last + 1, "the Eval0s cover the whole run");
        values
    }

    #[test]
    fn the_staircase_stays_within_the_tolerance_at_every_pixel_centre() {
        let rows = [
            shade(2.3, &[0.25], &[0.011]),
            shade(-7.9, &[0.9, 0.1, 0.5], &[-0.0037, 0.0052, 0.0]),
            shade(100.0, &[0.5], &[1.0 / 4096.0]),
            shade(0.5, &[1.0, 0.0], &[-0.2, 0.2]),
        ];
        for rs in &rows {
            for tolerance in [0.0, 1.0 / 4096.0, 1.0 / 512.0, 0.01, 0.1, 1e9] {
                for (first, last) in [(3, 3), (3, 4), (0, 63), (17, 211)] {
                    let run = claim_vec(rs, first, last, tolerance);
                    let values = staircase(&run, first, last);
                    let n = (last - first + 1) as u32;
                    let k = claim_chunk(&rs.di[..rs.channels], tolerance, n);
                    assert_eq!(run.len() as u32, n.div_ceil(k), "Eval0s of {k} pixels");
                    for (j, v) in values.iter().enumerate() {
                        let want = rs.at(first + j as i64);
                        for c in 0..rs.channels {
                            let err = (v[c] - want[c]).abs();
                            assert!(
                                err <= tolerance + 1e-12,
                                "pixel {}: {} vs Gouraud {} (tolerance {tolerance})",
                                first + j as i64,
                                v[c],
                                want[c]
                            );
                        }
                    }
                    if tolerance == 0.0 {
                        assert_eq!(run.len() as u32, n, "one Eval0 per pixel");
                        for (j, v) in values.iter().enumerate() {
                            assert_eq!(v[..], rs.at(first + j as i64)[..rs.channels]);
                        }
                    }
                    if tolerance == 1e9 {
                        assert_eq!(run.len(), 1, "a huge tolerance claims the run at once");
                    }
                }
            }
        }
    }

    #[test]
    fn each_step_holds_the_value_at_its_centre() {
        // di = 0.01, tolerance 0.02: k = 5, so the steps hold the values at 2, 7, 12
        let rs = shade(0.5, &[0.0], &[0.01]);
        let run = claim_vec(&rs, 0, 13, 0.02);
        let got: Vec<(u32, u32, f64)> = run
            .iter()
            .map(|i| (i.x, i.dx, i.i().as_slice()[0]))
            .collect();
        let want = [(0, 5, 0.02), (5, 5, 0.07), (10, 4, 0.115)];
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert_eq!((g.0, g.1), (w.0, w.1));
            assert!((g.2 - w.2).abs() < 1e-15, "{g:?} vs {w:?}");
        }
    }

    #[test]
    fn a_flat_run_is_one_eval0() {
        let rs = shade(0.0, &[0.3, 0.6], &[0.0, 0.0]);
        let run = claim_vec(&rs, 5, 40, 0.0);
        assert_eq!(
            run,
            [Instruction::eval0(5, 36, Intensity::new(&[0.3, 0.6]))]
        );
    }
}
