//! The exact box filter of one trapezium row (`--aa box`): each pixel holds
//! `∫∫ I dA` over the pixel's part of the row, `I` the row's affine intensity.
//!
//! * [`RowPlane`] — the intensity over one trapezium row as an affine function
//!   `I(x, y) = I_m + b_x·(x − x_l) + b_y·(y − y_m)`: the scanline Gouraud function at
//!   the row's middle height (value and x-gradient, as the report's mode takes them) and
//!   the y-gradient along the edges. For intensities that are planar over the polygon
//!   (triangles, the fragments of exact visibility) it *is* the Gouraud function.
//! * [`RowPlane::pixel`] — the exact integral over one pixel: the row's quadrilateral
//!   clipped to the pixel's column, its area and first moments by the shoelace formulas,
//!   taken relative to the pixel's corner.
//! * [`forward_differences`] — the `Eval3` operands of a run whose exact values are a
//!   quadratic in the pixel index (every sequence and share-sequence: docs/ERRATA.md,
//!   "The exact box filter"), from the values at its first, middle and last pixel.

use crate::coverage::Slice;
use crate::dofill::Shade;
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
    /// The left and right edge's x at the top (`y0`) and at the bottom (`y1`).
    left: (f64, f64),
    right: (f64, f64),
}

impl RowPlane {
    /// The plane of `t` over the band of `s`. Flat shading: the polygon's intensity,
    /// gradients 0. Gouraud: at the middle height `y_m` the value and x-gradient of the
    /// scanline function (0 where the edges meet, as in the report's mode); the
    /// y-gradient is what each edge's own intensity gradient leaves after its run in x,
    /// `dI_E/dy − b_x · dx_E/dy`, averaged over the two edges (they agree for planar
    /// intensities).
    pub fn new(t: &Trapezium, shade: &Shade, s: &Slice, channels: usize) -> RowPlane {
        let y_m = 0.5 * (s.y0 + s.y1);
        let zero = [0.0; MAX_CHANNELS];
        let (x_l, x_r) = (t.left.x_at(y_m), t.right.x_at(y_m));
        let (i_m, b_x, b_y) = match shade {
            Shade::Flat(v) => (*v, zero, zero),
            Shade::Gouraud => {
                let (il, ir) = (t.left.i_at(y_m, channels), t.right.i_at(y_m, channels));
                let width = x_r - x_l;
                let b_x = if width > 1e-12 * (1.0 + x_l.abs()) {
                    vector(channels, |c| (ir[c] - il[c]) / width)
                } else {
                    zero
                };
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
                let finite =
                    |g: Vector| vector(channels, |c| if g[c].is_finite() { g[c] } else { 0.0 });
                (il, finite(b_x), finite(b_y))
            }
        };
        RowPlane {
            i_m,
            b_x,
            b_y,
            x_l,
            y_m,
            channels,
            y0: s.y0,
            y1: s.y1,
            left: (t.left.x_at(s.y0), t.left.x_at(s.y1)),
            right: (t.right.x_at(s.y0), t.right.x_at(s.y1)),
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
    /// relative to `(x0, y0)` (so that far-away pixels lose no precision).
    fn moments(&self, x0: f64) -> (f64, f64, f64) {
        let h = self.y1 - self.y0;
        let quad = [
            [self.left.0 - x0, 0.0],
            [self.right.0 - x0, 0.0],
            [self.right.1 - x0, h],
            [self.left.1 - x0, h],
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
        // the quadrilateral's orientation is fixed, but a clipped sliver may round either
        // way: take the moments with the area's sign
        let s = if area < 0.0 { -1.0 } else { 1.0 };
        (s * area / 2.0, s * mx / 6.0, s * my / 6.0)
    }
}

/// Clips the convex polygon `v` to `x ≥ bound` (`keep_ge`) or `x ≤ bound` into `out`;
/// returns its number of vertices (a convex polygon gains at most one per clip).
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
            // measured from the end with the smaller x, so that both clips of an edge
            // agree on its line
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
            let p = RowPlane::new(&t, &Shade::Gouraud, &s, 1);
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
}
