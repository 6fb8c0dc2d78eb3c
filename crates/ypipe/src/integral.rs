//! The exact box filter of one trapezium row (`--aa box`): each pixel holds
//! `∫∫ I dA` over the pixel's part of the row, `I` the row's affine intensity.
//!
//! * [`RowPlane`] — the intensity over one trapezium row as an affine function
//!   `I(x, y) = I_m + b_x·(x − x_l) + b_y·(y − y_m)`: the scanline Gouraud function at
//!   the row's middle height (value and x-gradient, as the report's mode takes them) and
//!   the y-gradient along the edges. For intensities that are planar over the polygon
//!   (triangles, the fragments of exact visibility) it *is* the Gouraud function.
//! * [`RowPlane::pixel`] — the exact integral over one pixel: the area and first
//!   moments of the row's quadrilateral within the pixel's column, taken relative to the
//!   pixel's corner, in closed form (what lies left of the right edge less what lies left
//!   of the left edge, each the integral of a clamped linear function).
//! * [`forward_differences`] — the `Eval3` operands of a run whose exact values are a
//!   quadratic in the pixel index (every sequence and share-sequence: docs/ERRATA.md,
//!   "The exact box filter"), from the values at its first, middle and last pixel.

use crate::coverage::Slice;
use crate::dofill::RowShade;
use crate::trapezoid::{vector, Trapezium, Vector};
use cwisim_isa::MAX_CHANNELS;

/// The affine intensity of one trapezium row and the row's quadrilateral.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowPlane {
    /// The intensity at `(x_l, y_m)`.
    pub i_m: Vector,
    /// `∂I/∂x`, per channel.
    pub b_x: Vector,
    /// `∂I/∂y`, per channel.
    pub b_y: Vector,
    /// The left edge's x at the middle height.
    pub x_l: f64,
    /// The middle height of the row's band.
    pub y_m: f64,
    /// Channels in use.
    pub channels: usize,
    /// The band's top and bottom.
    y0: f64,
    y1: f64,
    /// The left and right edge over the band.
    left: BandEdge,
    right: BandEdge,
}

impl RowPlane {
    /// The Gouraud plane of `t` over the band of `s`, from the row's scanline function
    /// `line` at the band's middle height `y_m` (its value at the left edge and its
    /// x-gradient, 0 where the edges meet, as in the report's mode); the y-gradient is
    /// what each edge's own intensity gradient leaves after its run in x,
    /// `dI_E/dy − b_x · dx_E/dy`, averaged over the two edges (they agree for planar
    /// intensities). A flat row needs no plane: its values are the report's. Inlined, as
    /// [`Slice::of`].
    #[inline]
    pub(crate) fn new(t: &Trapezium, s: &Slice, line: &RowShade) -> RowPlane {
        let channels = line.channels;
        let b_x = line.di;
        let along = |e: &crate::trapezoid::Edge, c: usize| {
            let dy = e.y_bot - e.y_top;
            (e.i_bot[c] - e.i_top[c]) / dy - b_x[c] * (e.x_bot - e.x_top) / dy
        };
        let b_y = vector(channels, |c| 0.5 * (along(&t.left, c) + along(&t.right, c)));
        // A gradient beyond f64 (a change of up to 1e308 across a band or a run
        // narrower than the change's ratio to f64's range: a sliver 1e-12 px wide
        // shading 0 → 1e300 across) is taken as 0: the row is then that narrow in
        // that direction, so the constant `il` is off by at most the polygon's
        // intensity range times the row's area, and no inf or NaN reaches an Eval.
        let finite = |g: Vector| vector(channels, |c| if g[c].is_finite() { g[c] } else { 0.0 });
        RowPlane {
            i_m: line.i_left,
            b_x: finite(b_x),
            b_y: finite(b_y),
            x_l: line.x_left,
            y_m: 0.5 * (s.y0 + s.y1),
            channels,
            y0: s.y0,
            y1: s.y1,
            left: BandEdge::new(s.left.at_top, s.left.at_bottom, s.y1 - s.y0),
            right: BandEdge::new(s.right.at_top, s.right.at_bottom, s.y1 - s.y0),
        }
    }

    /// True when the intensity is constant over the row (both gradients 0).
    pub fn constant(&self) -> bool {
        let ch = self.channels;
        self.b_x[..ch]
            .iter()
            .chain(&self.b_y[..ch])
            .all(|g| *g == 0.0)
    }

    /// True when the intensity does not change along the row (x-gradient 0).
    pub fn flat_in_x(&self) -> bool {
        self.b_x[..self.channels].iter().all(|g| *g == 0.0)
    }

    /// The intensity at `(x, y)`.
    pub fn at(&self, x: f64, y: f64) -> Vector {
        let (dx, dy) = (x - self.x_l, y - self.y_m);
        vector(self.channels, |c| {
            self.i_m[c] + self.b_x[c] * dx + self.b_y[c] * dy
        })
    }

    /// `∫∫ I dA` over pixel column `i`'s part of the row (0 where it has none).
    pub fn pixel(&self, i: i64) -> Vector {
        let x = i as f64;
        let (area, mx, my) = self.moments(x);
        if area == 0.0 {
            return [0.0; MAX_CHANNELS];
        }
        let corner = self.at(x, self.y0);
        vector(self.channels, |c| {
            area * corner[c] + self.b_x[c] * mx + self.b_y[c] * my
        })
    }

    /// Area and first moments `∫∫ (x − x0) dA`, `∫∫ (y − y0) dA` of the row's
    /// quadrilateral clipped to the column `[x0, x0 + 1]`, with the coordinates taken
    /// relative to `(x0, y0)` (so that far-away pixels lose no precision): what lies left
    /// of the right edge less what lies left of the left edge ([`BandEdge::left_of`]).
    #[inline]
    fn moments(&self, x0: f64) -> (f64, f64, f64) {
        let h = self.y1 - self.y0;
        let r = self.right.left_of(x0, h);
        let l = self.left.left_of(x0, h);
        let area = r[0] - l[0];
        // edges that cross by a rounding (an apex) leave no negative area
        if area <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        (area, r[1] - l[1], r[2] - l[2])
    }
}

/// One edge of a row over the row's band (of height `h`, `t` measured down from its
/// top): its x at the top and the bottom, and how far down the band it moves per unit
/// of x (`h / (bottom − top)`; infinite for a vertical edge), taken once per row.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BandEdge {
    top: f64,
    bottom: f64,
    dt_dx: f64,
}

impl BandEdge {
    fn new(top: f64, bottom: f64, h: f64) -> BandEdge {
        BandEdge {
            top,
            bottom,
            dt_dx: h / (bottom - top),
        }
    }

    /// Area and first moments `[∫∫ dA, ∫∫ (x − x0) dA, ∫∫ t dA]` of the part of the
    /// column `x0 ≤ x ≤ x0 + 1` over the band that lies left of the edge.
    ///
    /// At height `t` that part is `[x0, x0 + c(t)]` with `c` the edge's `x − x0`
    /// clamped to `[0, 1]`, so the three are `∫ c`, `∫ c²/2` and `∫ t·c` over the band:
    /// closed forms over at most three pieces, where `c` is 0, linear, or 1.
    #[inline]
    fn left_of(&self, x0: f64, h: f64) -> [f64; 3] {
        let (u0, u1) = (self.top - x0, self.bottom - x0);
        // the common cases first: the edge clear of the column on either side (what
        // the pieces below give for them, without their rounding at the band's ends)
        if u0 <= 0.0 && u1 <= 0.0 {
            return [0.0; 3];
        }
        if u0 >= 1.0 && u1 >= 1.0 {
            return [h, h / 2.0, h * h / 2.0];
        }
        self.crossing(u0, u1, h)
    }

    /// [`Self::left_of`] for an edge that is not clear of the column, from its `x − x0`
    /// at the band's top and bottom (`u0`, `u1`). Out of line, so that the clear cases
    /// above are decided where the integral is taken, without a call.
    #[inline(never)]
    fn crossing(&self, u0: f64, u1: f64, h: f64) -> [f64; 3] {
        let k = self.dt_dx;
        if !k.is_finite() {
            // vertical, or so steep that it moves less than f64 can tell over the band
            let c = u0.clamp(0.0, 1.0);
            return if c.is_nan() {
                [0.0; 3]
            } else {
                [h * c, h * c * c / 2.0, c * h * h / 2.0]
            };
        }
        // where the edge crosses the column's sides x0 and x0 + 1, as heights
        let (s0, s1) = (-u0 * k, (1.0 - u0) * k);
        let rising = k > 0.0;
        let (s_a, s_b) = if rising { (s0, s1) } else { (s1, s0) };
        // clamped to the band (max then min, not `clamp`: a NaN passes, no panic)
        let (t_a, t_b) = (s_a.max(0.0).min(h), s_b.max(0.0).min(h));
        // c at the ends of the linear piece: 0 or 1 where the edge crosses a side of
        // the column within the band, else its (clamped) value at the band's top or
        // bottom
        let (inner, outer) = if rising { (0.0, 1.0) } else { (1.0, 0.0) };
        let c_a = if s_a > 0.0 { inner } else { u0.clamp(0.0, 1.0) };
        let c_b = if s_b < h { outer } else { u1.clamp(0.0, 1.0) };
        let mut m = linear_piece(t_a, t_b, c_a, c_b);
        // the piece where the whole column lies left of the edge (c = 1)
        let (f_a, f_b) = if rising { (t_b, h) } else { (0.0, t_a) };
        let len = f_b - f_a;
        if len > 0.0 {
            m[0] += len;
            m[1] += len / 2.0;
            m[2] += len * (f_a + f_b) / 2.0;
        }
        m
    }
}

/// `[∫ c, ∫ c²/2, ∫ t·c]` over `[t_a, t_b]` for `c` linear from `c_a` to `c_b` (0 for
/// an empty piece).
#[inline]
fn linear_piece(t_a: f64, t_b: f64, c_a: f64, c_b: f64) -> [f64; 3] {
    let len = t_b - t_a;
    if len <= 0.0 {
        return [0.0; 3];
    }
    [
        len * (c_a + c_b) / 2.0,
        len * (c_a * c_a + c_a * c_b + c_b * c_b) / 6.0,
        len * (t_a * (2.0 * c_a + c_b) + t_b * (c_a + 2.0 * c_b)) / 6.0,
    ]
}

/// The `Eval3` operands `(I, dI, ddI)` of a run of `n` pixels whose values are the
/// quadratic through `first` (pixel 0), `middle` (pixel `(n − 1) / 2`) and `last`
/// (pixel `n − 1`): the value at pixel 0 and the first and second forward differences
/// there, so that the array's wave `v, v + dI, v + 2dI + ddI, …` reproduces the
/// quadratic. Through the ends and the middle rather than the first three pixels: the
/// differences then carry no cancellation that grows with the run's length. For `n ≤ 2`
/// the quadratic is a line (`ddI = 0`) through the ends; for `n = 1` `dI = 0`.
pub fn forward_differences(n: u32, first: f64, middle: f64, last: f64) -> (f64, f64, f64) {
    match n {
        0 | 1 => (first, 0.0, 0.0),
        2 => (first, last - first, 0.0),
        _ => {
            let l = f64::from(n - 1);
            let m = f64::from((n - 1) / 2);
            let d0m = (middle - first) / m;
            let dml = (last - middle) / (l - m);
            let d0ml = (dml - d0m) / l;
            // P(k) = first + d0m·k + d0ml·k·(k − m)
            (first, d0m + d0ml * (1.0 - m), 2.0 * d0ml)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dofill::Shade;
    use crate::trapezoid::Edge;

    fn edge(top: (f64, f64), bot: (f64, f64), plane: impl Fn(f64, f64) -> f64) -> Edge {
        let mut i_top = [0.0; MAX_CHANNELS];
        let mut i_bot = [0.0; MAX_CHANNELS];
        i_top[0] = plane(top.0, top.1);
        i_bot[0] = plane(bot.0, bot.1);
        Edge {
            x_top: top.0,
            y_top: top.1,
            x_bot: bot.0,
            y_bot: bot.1,
            i_top,
            i_bot,
        }
    }

    /// `∫∫ f` over pixel `i`'s part of the row by the midpoint rule on a fine grid.
    fn brute(t: &Trapezium, row: u32, i: i64, f: impl Fn(f64, f64) -> f64) -> f64 {
        let n = 1200;
        let step = 1.0 / n as f64;
        let mut sum = 0.0;
        for a in 0..n {
            let y = f64::from(row) + (a as f64 + 0.5) * step;
            if y < t.y_top || y > t.y_bot {
                continue;
            }
            let (xl, xr) = (t.left.x_at(y), t.right.x_at(y));
            let (lo, hi) = (xl.max(i as f64), xr.min(i as f64 + 1.0));
            if hi > lo {
                // exact across x for f linear in x
                sum += step * (hi - lo) * f(0.5 * (lo + hi), y);
            }
        }
        sum
    }

    #[test]
    fn a_pixel_integral_is_area_times_the_value_at_the_centroid() {
        let plane = |x: f64, y: f64| 0.3 + 0.07 * x - 0.2 * y;
        let t = Trapezium {
            id: 1,
            polygon: 0,
            y_top: 0.25,
            y_bot: 3.0,
            left: edge((2.2, 0.25), (7.9, 3.0), plane),
            right: edge((9.4, 0.25), (8.1, 3.0), plane),
        };
        for row in 0..3 {
            let s = Slice::of(&t, row).unwrap();
            let line = RowShade::new(&t, &Shade::Gouraud, 0.5 * (s.y0 + s.y1), 1);
            let p = RowPlane::new(&t, &s, &line);
            assert!((p.b_x[0] - 0.07).abs() < 1e-14 && (p.b_y[0] + 0.2).abs() < 1e-14);
            for i in 0..12 {
                let want = brute(&t, row, i, plane);
                let got = p.pixel(i)[0];
                // the midpoint rule in y errs by O(step²) on the piecewise quadratics
                assert!(
                    (got - want).abs() < 1e-6,
                    "row {row} pixel {i}: {got} vs {want}"
                );
                let area = brute(&t, row, i, |_, _| 1.0);
                assert!((p.moments(i as f64).0 - area).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn forward_differences_reproduce_the_quadratic() {
        let q = |k: f64| 0.125 - 0.03 * k + 0.0021 * k * k;
        for n in 1..40u32 {
            let m = f64::from((n - 1) / 2);
            let (v, d, dd) = forward_differences(n, q(0.0), q(m), q(f64::from(n - 1)));
            let (mut v, mut d) = (v, d);
            for k in 0..n {
                let want = q(f64::from(k));
                assert!((v - want).abs() < 1e-14, "n {n} k {k}: {v} vs {want}");
                v += d;
                d += dd;
            }
        }
    }

    /// The clip-based moments this module computed before the closed form, kept as an
    /// oracle: the row's quadrilateral (coordinates relative to `(x0, y0)`) clipped to
    /// the column by Sutherland–Hodgman, its area and moments by the shoelace formulas.
    fn clip_moments(p: &RowPlane, x0: f64) -> (f64, f64, f64) {
        let h = p.y1 - p.y0;
        let quad = [
            [p.left.top - x0, 0.0],
            [p.right.top - x0, 0.0],
            [p.right.bottom - x0, h],
            [p.left.bottom - x0, h],
        ];
        let mut a = [[0.0; 2]; 8];
        let mut b = [[0.0; 2]; 8];
        let n = clip_x(&quad, 0.0, true, &mut a);
        let n = clip_x(&a[..n], 1.0, false, &mut b);
        let v = &b[..n];
        if n < 3 {
            return (0.0, 0.0, 0.0);
        }
        let (mut area, mut mx, mut my) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let (p, q) = (v[k], v[(k + 1) % n]);
            let cross = p[0] * q[1] - q[0] * p[1];
            area += cross;
            mx += (p[0] + q[0]) * cross;
            my += (p[1] + q[1]) * cross;
        }
        let s = if area < 0.0 { -1.0 } else { 1.0 };
        (s * area / 2.0, s * mx / 6.0, s * my / 6.0)
    }

    /// The convex polygon `v` clipped to `x ≥ bound` (`keep_ge`) or `x ≤ bound`.
    fn clip_x(v: &[[f64; 2]], bound: f64, keep_ge: bool, out: &mut [[f64; 2]; 8]) -> usize {
        let inside = |p: &[f64; 2]| {
            if keep_ge {
                p[0] >= bound
            } else {
                p[0] <= bound
            }
        };
        let mut n = 0;
        let len = v.len();
        for k in 0..len {
            let (a, b) = (v[(k + len - 1) % len], v[k]);
            let (a_in, b_in) = (inside(&a), inside(&b));
            if a_in != b_in && n < out.len() {
                let (lo, hi) = if a[0] <= b[0] { (a, b) } else { (b, a) };
                let t = (bound - lo[0]) / (hi[0] - lo[0]);
                out[n] = [bound, lo[1] + t * (hi[1] - lo[1])];
                n += 1;
            }
            if b_in && n < out.len() {
                out[n] = b;
                n += 1;
            }
        }
        n
    }

    /// The moments by quadrature, independent of both: the band is cut at every height
    /// where an edge crosses a side of the column, and on each piece — where the covered
    /// width is linear in `t` — three-point Gauss–Legendre integrates the width and the
    /// moments (polynomials of degree ≤ 2 there) exactly, up to rounding.
    fn quadrature_moments(p: &RowPlane, x0: f64) -> (f64, f64, f64) {
        let h = p.y1 - p.y0;
        let edge = |e: BandEdge| move |t: f64| (e.top - x0) + (e.bottom - e.top) * (t / h);
        let (l, r) = (edge(p.left), edge(p.right));
        let mut cuts = vec![0.0, h];
        for (a, b) in [
            (p.left.top - x0, p.left.bottom - x0),
            (p.right.top - x0, p.right.bottom - x0),
        ] {
            for side in [0.0, 1.0] {
                if b != a {
                    let t = h * ((side - a) / (b - a));
                    if t > 0.0 && t < h {
                        cuts.push(t);
                    }
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        let nodes = [-(0.6f64.sqrt()), 0.0, 0.6f64.sqrt()];
        let weights = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
        let (mut area, mut mx, mut my) = (0.0, 0.0, 0.0);
        for w in cuts.windows(2) {
            let (half, mid) = ((w[1] - w[0]) / 2.0, (w[0] + w[1]) / 2.0);
            for (z, wt) in nodes.iter().zip(&weights) {
                let t = mid + half * z;
                let (a, b) = (l(t).clamp(0.0, 1.0), r(t).clamp(0.0, 1.0));
                let width = (b - a).max(0.0);
                area += half * wt * width;
                mx += half * wt * (b * b - a * a).max(0.0) / 2.0;
                my += half * wt * t * width;
            }
        }
        (area, mx, my)
    }

    /// A row plane over the band `[y0, y0 + h]` between the left edge from `l0` (top) to
    /// `l1` (bottom) and the right edge from `r0` to `r1`; intensity 0 (only its
    /// moments are taken).
    fn row(y0: f64, h: f64, l: (f64, f64), r: (f64, f64)) -> RowPlane {
        let y1 = y0 + h;
        let h = y1 - y0; // the band's height as f64 has it
        RowPlane {
            i_m: [0.0; MAX_CHANNELS],
            b_x: [0.0; MAX_CHANNELS],
            b_y: [0.0; MAX_CHANNELS],
            x_l: 0.5 * (l.0 + l.1),
            y_m: y0 + h / 2.0,
            channels: 1,
            y0,
            y1,
            left: BandEdge::new(l.0, l.1, h),
            right: BandEdge::new(r.0, r.1, h),
        }
    }

    /// Rows that stress the integral: random ones around a pixel, and slivers 1e-12 px
    /// wide or high, huge coordinates, vertical and near-horizontal edges, edges that
    /// meet (an apex) or touch a column side, degenerate bands.
    fn stress_rows() -> Vec<RowPlane> {
        let mut next = crate::test_rng::uniform(0x2545_F491_4F6C_DD1Du64);
        let mut rows = vec![
            row(0.0, 1.0, (2.3, 2.3), (2.3 + 1e-12, 2.3 + 1e-12)),
            row(0.0, 1.0, (2.3, 5.7), (2.3 + 1e-12, 5.7 + 1e-12)),
            row(3.0, 1e-12, (0.2, 0.2 + 3e-12), (4.9, 4.9)),
            row(3.0, 1e-12, (-10.0, 2.0), (5.0, 2.5)),
            row(0.0, 1.0, (1e6 + 0.25, 1e6 + 0.75), (1e6 + 3.5, 1e6 + 1.1)),
            row(7.5e5, 0.5, (2e9 + 0.1, 2e9 + 7.9), (2e9 + 9.0, 2e9 + 9.0)),
            row(0.0, 1.0, (1.0, 1.0), (2.0, 2.0)),
            row(0.0, 1.0, (1.5, 1.5), (3.25, 3.25)),
            row(0.0, 1e-9, (-500.0, 800.0), (900.0, 2000.0)),
            row(0.0, 1.0, (1.0, 1.0 + 1e-300), (4.0, 4.0 - 1e-15)),
            row(0.0, 1.0, (2.5, 2.5), (2.5, 2.5)),
            row(0.0, 0.75, (3.0, 1.0), (3.0, 5.0)),
            row(0.0, 0.75, (1.0, 3.0), (5.0, 3.0)),
            row(0.0, 1.0, (0.0, 1.0), (1.0, 2.0)),
            row(0.0, 1.0, (1e-300, 3e-300), (0.5, 0.5 + 1e-16)),
            row(0.0, 1.0, (-1e-300, 1e-300), (1.0 - 1e-16, 1.0 + 1e-16)),
        ];
        for _ in 0..3000 {
            let h = [1.0, next(), 1e-6 * next()][(next() * 3.0) as usize];
            let spread = [1.0, 4.0, 200.0][(next() * 3.0) as usize];
            let a = (next() * spread, next() * spread);
            let w = (next() * spread * next(), next() * spread * next());
            rows.push(row(next() * 100.0, h, a, (a.0 + w.0, a.1 + w.1)));
        }
        rows
    }

    /// The columns a row's moments are checked in: every one it touches and one beyond
    /// each side.
    fn columns(p: &RowPlane) -> impl Iterator<Item = f64> {
        let lo = p.left.top.min(p.left.bottom).floor() - 1.0;
        let hi = p.right.top.max(p.right.bottom).ceil() + 1.0;
        let n = ((hi - lo) as usize).min(400);
        (0..=n).map(move |k| lo + k as f64)
    }

    #[test]
    fn the_closed_form_moments_agree_with_clipping_and_with_quadrature() {
        for p in stress_rows() {
            let h = p.y1 - p.y0;
            for x0 in columns(&p) {
                let got = p.moments(x0);
                for (name, want) in [
                    ("clipping", clip_moments(&p, x0)),
                    ("quadrature", quadrature_moments(&p, x0)),
                ] {
                    // each value is at most the band's height (times 1 or h): agreement
                    // to 1e-12 of that scale, which is rounding
                    let scale = h.max(h * h);
                    for (g, w) in [(got.0, want.0), (got.1, want.1), (got.2, want.2)] {
                        assert!(
                            (g - w).abs() <= 1e-12 * scale,
                            "{name}: {got:?} vs {want:?} in column {x0} of {p:?}"
                        );
                    }
                }
                assert!(got.0 >= 0.0 && got.0 <= h * (1.0 + 1e-15), "area {got:?}");
            }
        }
    }

    #[test]
    fn the_moments_of_full_partial_and_empty_columns() {
        // a full column: area h, centroid at its centre
        let p = row(0.0, 0.5, (1.0, 1.0), (3.0, 3.0));
        assert_eq!(p.moments(1.0), (0.5, 0.25, 0.125));
        // left of the row, right of it, and the columns the edges only touch
        assert_eq!(p.moments(-4.0), (0.0, 0.0, 0.0));
        assert_eq!(p.moments(0.0), (0.0, 0.0, 0.0));
        assert_eq!(p.moments(3.0), (0.0, 0.0, 0.0));
        // a triangle's half: the left edge from (0, 0) to (1, 1) in a unit row
        let p = row(0.0, 1.0, (0.0, 1.0), (5.0, 5.0));
        let (a, mx, my) = p.moments(0.0);
        assert!((a - 0.5).abs() < 1e-16);
        assert!((mx - 1.0 / 3.0).abs() < 1e-16, "{mx}");
        assert!((my - 1.0 / 6.0).abs() < 1e-16, "{my}");
        // edges that cross by a rounding leave nothing, not a negative area
        let p = row(0.0, 1.0, (2.5 + 1e-15, 2.5), (2.5, 2.5 + 1e-15));
        assert!(p.moments(2.0).0 >= 0.0);
        // a NaN band is no panic
        let p = row(0.0, f64::NAN, (0.0, 1.0), (3.0, 2.0));
        let _ = p.moments(0.0);
    }
}
