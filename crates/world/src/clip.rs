//! Bézier clipping (Nishita, Kaneda, Nakamae; after Sederberg): every root in a parameter
//! interval of a polynomial given in Bernstein form, `f(t) = Σ_i y_i B_i^n(t)`, usable
//! alone.
//!
//! In the renderer, `y_i` are the paper's `Y'_i = Y_i − (y_s/R)·Z_i` (eq. 3): the signed
//! distances of a boundary curve's control points from the plane through the eye and the
//! scanline `y = y_s`; a root is where the projected curve crosses the scanline.
//!
//! # The method
//!
//! The graph `(t, f(t))` is the non-parametric Bézier curve with control points
//! `(i/n, y_i)`; it lies in their convex hull, so every root lies in the interval where
//! the hull meets the `t` axis. One **iteration** computes that interval `[a, b]` (exactly
//! as the union of the crossings of every pair of control points on opposite sides of
//! the axis, and the points on it; widened by 4 ulps so that rounding never clips a root
//! away) and restricts the curve to it by de Casteljau's algorithm (the new curve's
//! control points are those of `f` on `[a, b]`, re-parameterized to `[0, 1]`). When an
//! iteration keeps more than [`SPLIT_RATIO`] of the interval (several roots, or a root of
//! higher multiplicity, slow the clipping down), the curve is split at `t = ½` and both
//! halves are solved the same way. A piece whose control values are all `> 0` or all
//! `< 0` holds no root and is dropped (that test is not an iteration).
//!
//! # What is counted
//!
//! * **Tolerance**: in the caller's parameter (`domain`), not the piece's: a root is
//!   reported when the interval an iteration leaves is at most `tolerance` wide in the
//!   domain's units. The renderer passes the original patch's `u` or `v` as the domain,
//!   so 1e-3 keeps a 1000-pixel patch within about one pixel, the paper's reading.
//! * **Root**: the midpoint of that interval, reported when `f` is seen to cross zero
//!   around it: its values at the ends of the window `[lo − tol/8, hi + tol/8]`
//!   (clamped to the domain; evaluated on the whole curve by de Casteljau) have opposite
//!   signs, or one of them is within the evaluation's rounding bound
//!   (`4·n·ε·max|y_i|`) of zero. A crossing is what a scan converter needs; a piece
//!   narrowed to the tolerance around which `f` does not cross (a tangency, a near miss,
//!   or two roots closer than about the tolerance) is counted as *touching*
//!   ([`ClipStats::touching`]), not as a root. Roots less than `tolerance` apart are one
//!   root (two halves of a split that both end at a root on the split point give one).
//! * **Iterations of a root**: the iterations on the path from the whole curve to the
//!   root, through every split on the way ([`Root::iterations`]). The **average
//!   iterations per root** is their mean ([`ClipStats::average`], the paper's Table 1
//!   figure).
//! * **Wasted iterations**: iterations done on a piece in which no root was found in the
//!   end (a half after a split that turned out empty).
//! * **Rejected curves**: curves with no sign change at all, dropped before any
//!   iteration ([`ClipStats::rejected`]).

use std::fmt;

/// An iteration that keeps more than this fraction of the piece splits it at `½`
/// (Sederberg's 80 %: the clip converges too slowly there).
pub const SPLIT_RATIO: f64 = 0.8;

/// The highest degree solved.
pub const MAX_DEGREE: usize = 7;

/// The finest tolerance accepted (in the domain's units; below about 1e-12 of a unit
/// interval, floating point can no longer narrow the interval).
pub const MIN_TOLERANCE: f64 = 1e-12;

/// The deepest chain of splits followed; a piece deeper than this is reported as a root
/// (counted in [`ClipStats::capped`]). Each split halves the piece, so with tolerance ≥
/// [`MIN_TOLERANCE`] of the domain the cap is never reached in exact arithmetic.
pub const MAX_SPLITS: u32 = 60;

/// The iterations of one root are histogrammed in bins `0..HISTOGRAM - 1`, the last bin
/// holding `HISTOGRAM - 1` or more.
pub const HISTOGRAM: usize = 16;

/// Why a curve could not be solved.
#[derive(Clone, Debug, PartialEq)]
pub enum ClipError {
    /// The tolerance is not a finite number in `[MIN_TOLERANCE · |domain|, |domain|]`.
    Tolerance(f64),
    /// The degree is 0 or above [`MAX_DEGREE`].
    Degree(usize),
    /// A control value is not finite.
    NotFinite(usize),
    /// The domain is empty, reversed or not finite.
    Domain([f64; 2]),
}

impl fmt::Display for ClipError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ClipError::Tolerance(t) => write!(
                f,
                "Bézier clipping tolerance must be a finite number between {MIN_TOLERANCE:e} and 1 of the parameter domain, found {t}"
            ),
            ClipError::Degree(n) => write!(
                f,
                "Bézier clipping solves degrees 1 to {MAX_DEGREE}, found {n}"
            ),
            ClipError::NotFinite(i) => write!(f, "control value {i} is not finite"),
            ClipError::Domain(d) => write!(
                f,
                "the parameter domain must be a finite interval [a, b] with a < b, found {d:?}"
            ),
        }
    }
}

impl std::error::Error for ClipError {}

/// One root.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Root {
    /// The root, in the domain's parameter.
    pub t: f64,
    /// The interval (in the domain's parameter) the last iteration left: `t` is its
    /// midpoint, its width at most the tolerance.
    pub interval: [f64; 2],
    /// Iterations on the path from the whole curve to this root (see the module's
    /// documentation).
    pub iterations: u32,
}

/// What solving did; adds over curves.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ClipStats {
    /// Curves solved.
    pub curves: u64,
    /// Curves with no sign change, dropped before any iteration.
    pub rejected: u64,
    /// Roots reported.
    pub roots: u64,
    /// Iterations in all.
    pub iterations: u64,
    /// Sum of [`Root::iterations`] over the roots.
    pub root_iterations: u64,
    /// Iterations on pieces that held no root in the end.
    pub wasted: u64,
    /// Splits at `½`.
    pub splits: u64,
    /// Roots reported because [`MAX_SPLITS`] was reached.
    pub capped: u64,
    /// Pieces narrowed to the tolerance around which the curve does not cross (a
    /// tangency, a near miss, or two roots closer than the tolerance): not roots; their
    /// iterations are wasted.
    pub touching: u64,
    /// Curves identically zero (every control value 0: the curve lies in the plane);
    /// they report no root.
    pub coincident: u64,
    /// Roots by their iteration count (the last bin: that many or more).
    pub histogram: [u64; HISTOGRAM],
}

impl ClipStats {
    /// Adds `other`.
    pub fn merge(&mut self, other: &ClipStats) {
        self.curves += other.curves;
        self.rejected += other.rejected;
        self.roots += other.roots;
        self.iterations += other.iterations;
        self.root_iterations += other.root_iterations;
        self.wasted += other.wasted;
        self.splits += other.splits;
        self.capped += other.capped;
        self.touching += other.touching;
        self.coincident += other.coincident;
        for (a, b) in self.histogram.iter_mut().zip(other.histogram) {
            *a += b;
        }
    }

    /// The average iterations per root (the paper's Table 1), `None` without roots.
    pub fn average(&self) -> Option<f64> {
        (self.roots > 0).then(|| self.root_iterations as f64 / self.roots as f64)
    }
}

/// The roots of one curve, in increasing order, and what finding them did.
#[derive(Clone, Debug, PartialEq)]
pub struct Roots {
    /// The roots, increasing, at least `tolerance` apart.
    pub roots: Vec<Root>,
    /// Whether the curve is identically zero (then `roots` is empty).
    pub coincident: bool,
    /// What it did.
    pub stats: ClipStats,
}

/// Control values of a piece, its degree, and its interval in the domain.
#[derive(Clone, Copy, Debug)]
struct Piece {
    y: [f64; MAX_DEGREE + 1],
    n: usize,
    lo: f64,
    hi: f64,
}

/// The roots of `f(t) = Σ y_i B_i^n(t)` (`n = y.len() − 1`) over `t ∈ [0, 1]`, mapped to
/// `domain` (`t = 0` ↦ `domain[0]`, `t = 1` ↦ `domain[1]`), to within `tolerance` in the
/// domain's units.
pub fn roots(y: &[f64], domain: [f64; 2], tolerance: f64) -> Result<Roots, ClipError> {
    roots_traced(y, domain, tolerance, &mut |_, _| {})
}

/// As [`roots`], calling `trace(depth, width)` after every iteration with the number of
/// splits above the piece and the width (domain units) of the interval it left — what
/// the convergence tests read.
pub fn roots_traced(
    y: &[f64],
    domain: [f64; 2],
    tolerance: f64,
    trace: &mut dyn FnMut(u32, f64),
) -> Result<Roots, ClipError> {
    let n = y.len().wrapping_sub(1);
    if y.is_empty() || n == 0 || n > MAX_DEGREE {
        return Err(ClipError::Degree(n.min(y.len())));
    }
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(ClipError::NotFinite(i));
    }
    let [d0, d1] = domain;
    if !(d0.is_finite() && d1.is_finite() && d0 < d1) {
        return Err(ClipError::Domain(domain));
    }
    let span = d1 - d0;
    if !(tolerance.is_finite() && tolerance >= MIN_TOLERANCE * span && tolerance <= span) {
        return Err(ClipError::Tolerance(tolerance));
    }
    let mut out = Roots {
        roots: Vec::new(),
        coincident: false,
        stats: ClipStats {
            curves: 1,
            ..ClipStats::default()
        },
    };
    if y.iter().all(|&v| v == 0.0) {
        out.coincident = true;
        out.stats.coincident = 1;
        return Ok(out);
    }
    let mut piece = Piece {
        y: [0.0; MAX_DEGREE + 1],
        n,
        lo: d0,
        hi: d1,
    };
    piece.y[..=n].copy_from_slice(y);
    if one_sign(&piece) {
        out.stats.rejected = 1;
        return Ok(out);
    }
    let mut found = Vec::new();
    let noise = 4.0 * n as f64 * f64::EPSILON * y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut solver = Solver {
        curve: y,
        domain,
        noise,
        tolerance,
        stats: &mut out.stats,
        found: &mut found,
        trace,
    };
    solver.solve(piece, 0, 0);
    // one root per cluster closer than the tolerance
    found.sort_by(|a: &Root, b: &Root| a.t.total_cmp(&b.t));
    for r in found {
        match out.roots.last_mut() {
            Some(last) if r.t - last.t <= tolerance => {
                last.iterations = last.iterations.max(r.iterations);
                last.interval[1] = last.interval[1].max(r.interval[1]);
            }
            _ => out.roots.push(r),
        }
    }
    out.stats.roots = out.roots.len() as u64;
    for r in &out.roots {
        out.stats.root_iterations += u64::from(r.iterations);
        out.stats.histogram[(r.iterations as usize).min(HISTOGRAM - 1)] += 1;
    }
    Ok(out)
}

/// All control values strictly of one sign: no root in the piece.
fn one_sign(p: &Piece) -> bool {
    let y = &p.y[..=p.n];
    y.iter().all(|&v| v > 0.0) || y.iter().all(|&v| v < 0.0)
}

struct Solver<'a> {
    /// The whole curve's control values, its domain and its evaluation noise bound.
    curve: &'a [f64],
    domain: [f64; 2],
    noise: f64,
    tolerance: f64,
    stats: &'a mut ClipStats,
    found: &'a mut Vec<Root>,
    trace: &'a mut dyn FnMut(u32, f64),
}

impl Solver<'_> {
    /// Whether the whole curve certainly has a zero in the window `[lo − tol/8, hi +
    /// tol/8]` (clamped to the domain) around a final piece: its values at the window's
    /// ends have opposite signs, or one of them is within the evaluation noise of 0.
    fn crosses(&self, lo: f64, hi: f64) -> bool {
        let [d0, d1] = self.domain;
        let pad = 0.125 * self.tolerance;
        let at = |w: f64| {
            let t = ((w - d0) / (d1 - d0)).clamp(0.0, 1.0);
            evaluate(self.curve, t)
        };
        let (fl, fh) = (at((lo - pad).max(d0)), at((hi + pad).min(d1)));
        fl.abs() <= self.noise || fh.abs() <= self.noise || (fl < 0.0) != (fh < 0.0)
    }

    /// Solves `piece` (which has a sign change or a zero), `inherited` iterations above
    /// it, `depth` splits above it; returns the roots found in it.
    fn solve(&mut self, mut piece: Piece, inherited: u32, depth: u32) -> usize {
        let mut own = 0u32;
        loop {
            let Some([a, b]) = hull_interval(&piece.y[..=piece.n]) else {
                // cannot happen for a piece with a sign change or a zero; kept total
                self.stats.wasted += u64::from(own);
                return 0;
            };
            own += 1;
            self.stats.iterations += 1;
            let w = piece.hi - piece.lo;
            let (lo, hi) = (piece.lo + a * w, piece.lo + b * w);
            piece = Piece {
                y: restrict(&piece.y, piece.n, a, b),
                lo,
                hi: hi.max(lo),
                ..piece
            };
            let width = piece.hi - piece.lo;
            (self.trace)(depth, width);
            if width <= self.tolerance {
                if self.crosses(piece.lo, piece.hi) {
                    self.found.push(Root {
                        t: 0.5 * (piece.lo + piece.hi),
                        interval: [piece.lo, piece.hi],
                        iterations: inherited + own,
                    });
                    return 1;
                }
                self.stats.touching += 1;
                self.stats.wasted += u64::from(own);
                return 0;
            }
            if one_sign(&piece) {
                // rounding in the restriction left no sign change: no root here
                self.stats.wasted += u64::from(own);
                return 0;
            }
            if b - a > SPLIT_RATIO {
                if depth >= MAX_SPLITS {
                    self.stats.capped += 1;
                    self.found.push(Root {
                        t: 0.5 * (piece.lo + piece.hi),
                        interval: [piece.lo, piece.hi],
                        iterations: inherited + own,
                    });
                    return 1;
                }
                self.stats.splits += 1;
                let (left, right) = split_half(&piece);
                let mut count = 0;
                for half in [left, right] {
                    if !one_sign(&half) {
                        count += self.solve(half, inherited + own, depth + 1);
                    }
                }
                if count == 0 {
                    self.stats.wasted += u64::from(own);
                }
                return count;
            }
        }
    }
}

/// The interval `[a, b] ⊂ [0, 1]` where the convex hull of `(i/n, y_i)` meets the axis,
/// widened by 4 ulps of 1 on each side; `None` when it does not meet it.
pub fn hull_interval(y: &[f64]) -> Option<[f64; 2]> {
    let n = y.len() - 1;
    let x = |i: usize| i as f64 / n as f64;
    let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut take = |t: f64| {
        a = a.min(t);
        b = b.max(t);
    };
    for i in 0..=n {
        if y[i] == 0.0 {
            take(x(i));
        }
        for j in i + 1..=n {
            if (y[i] < 0.0 && y[j] > 0.0) || (y[i] > 0.0 && y[j] < 0.0) {
                take(x(i) + (x(j) - x(i)) * (y[i] / (y[i] - y[j])));
            }
        }
    }
    if a > b {
        return None;
    }
    let pad = 4.0 * f64::EPSILON;
    Some([(a - pad).max(0.0), (b + pad).min(1.0)])
}

/// One de Casteljau split at `t` of the first `n + 1` values: (left, right).
fn split(
    y: &[f64; MAX_DEGREE + 1],
    n: usize,
    t: f64,
) -> ([f64; MAX_DEGREE + 1], [f64; MAX_DEGREE + 1]) {
    let mut work = *y;
    let mut left = [0.0; MAX_DEGREE + 1];
    let mut right = [0.0; MAX_DEGREE + 1];
    left[0] = work[0];
    right[n] = work[n];
    for r in 1..=n {
        for i in 0..=n - r {
            work[i] = work[i] + t * (work[i + 1] - work[i]);
        }
        left[r] = work[0];
        right[n - r] = work[n - r];
    }
    (left, right)
}

/// The control values of the curve on `[a, b]`, re-parameterized to `[0, 1]`. The
/// restriction's end values are the curve's values at `a` and `b`.
fn restrict(y: &[f64; MAX_DEGREE + 1], n: usize, a: f64, b: f64) -> [f64; MAX_DEGREE + 1] {
    let mut c = *y;
    if b < 1.0 {
        c = split(&c, n, b).0;
    }
    if a > 0.0 {
        c = if b > 0.0 {
            split(&c, n, a / b).1
        } else {
            // the interval is the point 0: a constant curve at the value there
            [c[0]; MAX_DEGREE + 1]
        };
    }
    c
}

/// The two halves of a piece.
fn split_half(p: &Piece) -> (Piece, Piece) {
    let (l, r) = split(&p.y, p.n, 0.5);
    let mid = 0.5 * (p.lo + p.hi);
    (
        Piece {
            y: l,
            hi: mid,
            ..*p
        },
        Piece {
            y: r,
            lo: mid,
            ..*p
        },
    )
}

/// `f(t)` by de Casteljau's algorithm (what the tests compare with).
pub fn evaluate(y: &[f64], t: f64) -> f64 {
    let mut w = y.to_vec();
    let n = w.len();
    for r in 1..n {
        for i in 0..n - r {
            w[i] += t * (w[i + 1] - w[i]);
        }
    }
    w[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift64*).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The Bernstein coefficients of `k·Π (t − r_j)` (power basis → Bernstein).
    fn from_roots(k: f64, rs: &[f64]) -> Vec<f64> {
        // power coefficients, low first
        let mut p = vec![k];
        for &r in rs {
            let mut q = vec![0.0; p.len() + 1];
            for (i, &c) in p.iter().enumerate() {
                q[i + 1] += c;
                q[i] -= r * c;
            }
            p = q;
        }
        let n = p.len() - 1;
        let binom =
            |n: usize, k: usize| (0..k).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64);
        // b_i = Σ_{j ≤ i} C(i,j)/C(n,j) p_j
        (0..=n)
            .map(|i| (0..=i).map(|j| binom(i, j) / binom(n, j) * p[j]).sum())
            .collect()
    }

    /// Sign changes on a dense grid, each narrowed by bisection to 1e-14: the reference.
    fn reference(y: &[f64], samples: usize) -> Vec<f64> {
        let f = |t: f64| evaluate(y, t);
        let mut out = Vec::new();
        let mut t0 = 0.0;
        let mut f0 = f(t0);
        if f0 == 0.0 {
            out.push(0.0);
        }
        for k in 1..=samples {
            let t1 = k as f64 / samples as f64;
            let f1 = f(t1);
            if f1 == 0.0 {
                out.push(t1);
            } else if f0 != 0.0 && (f0 < 0.0) != (f1 < 0.0) {
                let (mut a, mut b, fa) = (t0, t1, f0);
                while b - a > 1e-14 {
                    let m = 0.5 * (a + b);
                    let fm = f(m);
                    if fm == 0.0 {
                        a = m;
                        b = m;
                        break;
                    }
                    if (fm < 0.0) == (fa < 0.0) {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                out.push(0.5 * (a + b));
            }
            t0 = t1;
            f0 = f1;
        }
        out
    }

    fn assert_matches(y: &[f64], tol: f64, expect: &[f64], what: &str) {
        let got = roots(y, [0.0, 1.0], tol).unwrap();
        let ts: Vec<f64> = got.roots.iter().map(|r| r.t).collect();
        assert_eq!(
            ts.len(),
            expect.len(),
            "{what}: {y:?} at {tol:e}: clipping {ts:?}, expected {expect:?}"
        );
        for (t, e) in ts.iter().zip(expect) {
            assert!(
                (t - e).abs() <= tol,
                "{what}: {y:?} at {tol:e}: root {t} vs {e}"
            );
        }
        assert_eq!(got.stats.roots as usize, ts.len());
        assert_eq!(
            got.stats.root_iterations,
            got.roots
                .iter()
                .map(|r| u64::from(r.iterations))
                .sum::<u64>()
        );
    }

    #[test]
    fn random_cubics_with_simple_roots_match_sampling_and_bisection() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        for case in 0..2000 {
            // roots spread over [-0.5, 1.5], at least 1e-3 apart
            let mut rs: Vec<f64> = (0..3).map(|_| rng.next() * 2.0 - 0.5).collect();
            rs.sort_by(f64::total_cmp);
            if rs.windows(2).any(|w| w[1] - w[0] < 1e-3) {
                continue;
            }
            // and away from the ends, so that sampling sees every crossing
            if rs.iter().any(|r| r.abs() < 1e-6 || (r - 1.0).abs() < 1e-6) {
                continue;
            }
            let y = from_roots(if case % 2 == 0 { 1.0 } else { -3.0 }, &rs);
            let expect = reference(&y, 20_000);
            let inside: Vec<f64> = rs
                .iter()
                .copied()
                .filter(|r| (0.0..=1.0).contains(r))
                .collect();
            assert_eq!(expect.len(), inside.len(), "reference {expect:?} vs {rs:?}");
            for tol in [1e-3, 1e-5, 1e-7, 1e-10] {
                assert_matches(&y, tol, &expect, "simple");
            }
        }
    }

    #[test]
    fn random_cubics_match_sampling_and_bisection() {
        // plain random control values: whatever their roots
        let mut rng = Rng(99);
        for _ in 0..3000 {
            let y: Vec<f64> = (0..4).map(|_| rng.next() * 2.0 - 1.0).collect();
            let expect = reference(&y, 20_000);
            // roots closer than the sampling step would be missed by the reference: skip
            let g = roots(&y, [0.0, 1.0], 1e-9).unwrap();
            if g.roots.windows(2).any(|w| w[1].t - w[0].t < 3e-3) {
                continue;
            }
            for tol in [1e-3, 1e-5, 1e-7] {
                // roots within the tolerance of each other merge: compare at a tolerance
                // that separates them
                assert_matches(&y, tol, &expect, "random");
            }
        }
    }

    #[test]
    fn endpoint_roots_are_found_once() {
        // exact zeros at an end
        assert_matches(&[0.0, 1.0, 2.0, 3.0], 1e-7, &[0.0], "t=0");
        assert_matches(
            &[3.0, 1.0, -2.0, 0.0],
            1e-7,
            &[0.5, 1.0],
            "t=1 after a crossing",
        );
        let y = from_roots(1.0, &[0.0, 0.4, 1.0]);
        assert_eq!(y[0], 0.0);
        let r = roots(&y, [0.0, 1.0], 1e-7).unwrap();
        let ts: Vec<f64> = r.roots.iter().map(|r| r.t).collect();
        assert_eq!(ts.len(), 3, "{ts:?}");
        assert!(ts[0].abs() <= 1e-7 && (ts[1] - 0.4).abs() <= 1e-7 && (ts[2] - 1.0).abs() <= 1e-7);
        // a root exactly on the split point ½ is one root
        let y = [-1.0, 4.0, -4.0, 1.0];
        assert_eq!(evaluate(&y, 0.5), 0.0);
        let r = roots(&y, [0.0, 1.0], 1e-7).unwrap();
        assert!(r.stats.splits >= 1, "{:?}", r.stats);
        let ts: Vec<f64> = r.roots.iter().map(|r| r.t).collect();
        assert_eq!(ts.len(), 3, "{ts:?}");
        assert!((ts[1] - 0.5).abs() <= 1e-7, "{ts:?}");
        // two roots closer than the tolerance do not cross as a pair: no root
        let y = from_roots(1.0, &[0.5, 0.5 + 1e-9, 2.0]);
        let r = roots(&y, [0.0, 1.0], 1e-7).unwrap();
        assert!(r.roots.is_empty() && r.stats.touching >= 1, "{:?}", r);
    }

    #[test]
    fn double_and_near_tangent_roots() {
        let mut rng = Rng(7);
        for _ in 0..500 {
            let r = 0.05 + 0.9 * rng.next();
            let s = 2.0 + rng.next();
            // a double root does not cross: no root while the tolerance window's ends
            // are clearly positive; at 1e-7 they are within rounding of 0 and it may be
            // reported, once, near r — never two, never elsewhere
            for tol in [1e-3, 1e-5, 1e-7] {
                let y = from_roots(1.0, &[r, r, s]);
                let got = roots(&y, [0.0, 1.0], tol).unwrap();
                assert!(got.roots.len() <= 1, "double {r}: {:?}", got.roots);
                if tol > 1e-7 {
                    assert!(got.roots.is_empty() && got.stats.touching >= 1, "{got:?}");
                }
                for root in &got.roots {
                    // the double root is ill-conditioned: √ε away at worst
                    assert!((root.t - r).abs() <= tol.max(1e-7), "double {r}: {root:?}");
                }
            }
            // near-tangent: two simple roots δ apart, δ above the tolerance: both found
            for (tol, delta) in [(1e-3, 3e-3), (1e-5, 3e-5), (1e-7, 3e-7)] {
                let y = from_roots(1.0, &[r, r + delta, s]);
                let got = roots(&y, [0.0, 1.0], tol).unwrap();
                let ts: Vec<f64> = got.roots.iter().map(|q| q.t).collect();
                assert_eq!(ts.len(), 2, "near-tangent {r} δ {delta}: {ts:?}");
                assert!(
                    (ts[0] - r).abs() <= tol && (ts[1] - r - delta).abs() <= tol,
                    "{ts:?}"
                );
            }
        }
    }

    #[test]
    fn triple_roots_are_one_root_within_the_conditioning_limit() {
        let mut rng = Rng(11);
        for _ in 0..300 {
            let r = 0.05 + 0.9 * rng.next();
            let y = from_roots(1.0, &[r, r, r]);
            // |f| ≤ ε·max|y| for |t − r| ≲ ε^(1/3) ≈ 6e-6: nothing tells roots apart there
            let got = roots(&y, [0.0, 1.0], 1e-5).unwrap();
            assert_eq!(got.roots.len(), 1, "triple {r}: {:?}", got.roots);
            assert!((got.roots[0].t - r).abs() <= 1e-5, "{:?}", got.roots);
            let fine = roots(&y, [0.0, 1.0], 1e-7).unwrap();
            assert!(!fine.roots.is_empty());
            for q in &fine.roots {
                assert!((q.t - r).abs() <= 2e-5, "triple {r}: {q:?}");
            }
        }
    }

    #[test]
    fn simple_roots_converge_quadratically() {
        let mut rng = Rng(5);
        let mut checked = 0;
        for _ in 0..500 {
            let rs = [rng.next(), rng.next() * 3.0 + 1.5, -1.0 - rng.next()];
            let y = from_roots(1.0, &rs);
            let mut widths = Vec::new();
            let got = roots_traced(&y, [0.0, 1.0], 1e-12, &mut |_, w| widths.push(w)).unwrap();
            assert_eq!(got.roots.len(), 1);
            assert!((got.roots[0].t - rs[0]).abs() <= 1e-12);
            // from the first interval below 1e-2 on, each width is at most K·(previous)²
            let Some(start) = widths.iter().position(|&w| w < 1e-2) else {
                continue;
            };
            let tail = &widths[start..];
            // quadratic: 1e-2 → 1e-12 in at most 4 steps (linear halving would need 33)
            assert!(tail.len() <= 5, "{widths:?}");
            for w in tail.windows(2) {
                if w[0] > 1e-7 {
                    assert!(w[1] <= 1e3 * w[0] * w[0], "not quadratic: {widths:?}");
                }
            }
            checked += 1;
        }
        assert!(checked > 400);
    }

    #[test]
    fn a_linear_clip_converges_in_one_iteration() {
        // a straight line: the hull is the curve, one iteration pins the root
        let r = roots(&[-1.0, 1.0], [0.0, 1.0], 1e-7).unwrap();
        assert_eq!(r.roots.len(), 1);
        assert!((r.roots[0].t - 0.5).abs() < 1e-15);
        assert_eq!(r.roots[0].iterations, 1);
        // and the domain maps the parameter
        let r = roots(&[-1.0, 3.0], [2.0, 4.0], 1e-7).unwrap();
        assert!((r.roots[0].t - 2.5).abs() < 1e-12);
    }

    #[test]
    fn tolerance_is_in_the_domain() {
        // the same curve over a domain 1e-3 wide needs fewer iterations at 1e-3 (one
        // clip leaves less than 1e-3 of the domain) than over [0, 1]
        let y = from_roots(1.0, &[0.37, 3.0, -2.0]);
        let wide = roots(&y, [0.0, 1.0], 1e-3).unwrap();
        let narrow = roots(&y, [0.5, 0.501], 1e-3).unwrap();
        assert_eq!(narrow.roots[0].iterations, 1);
        assert!(wide.roots[0].iterations > 1);
        assert!((narrow.roots[0].t - (0.5 + 0.37e-3)).abs() <= 1e-3);
    }

    #[test]
    fn no_root_curves_and_wasted_iterations() {
        let r = roots(&[1.0, 2.0, 0.5, 3.0], [0.0, 1.0], 1e-3).unwrap();
        assert_eq!(
            (r.stats.rejected, r.stats.iterations, r.roots.len()),
            (1, 0, 0)
        );
        // a hull that crosses the axis, a curve that does not: clipping finds nothing,
        // every iteration is wasted
        let y = [1.0, -0.2, -0.2, 1.0];
        assert!((0..=100).all(|k| evaluate(&y, k as f64 / 100.0) > 0.0));
        let r = roots(&y, [0.0, 1.0], 1e-7).unwrap();
        assert!(r.roots.is_empty());
        assert!(r.stats.iterations > 0);
        assert_eq!(r.stats.wasted, r.stats.iterations);
        assert_eq!(r.stats.average(), None);
        // identically zero
        let r = roots(&[0.0; 4], [0.0, 1.0], 1e-3).unwrap();
        assert!(r.coincident && r.roots.is_empty());
    }

    #[test]
    fn bad_input_is_refused() {
        assert_eq!(roots(&[1.0], [0.0, 1.0], 1e-3), Err(ClipError::Degree(0)));
        assert_eq!(roots(&[], [0.0, 1.0], 1e-3), Err(ClipError::Degree(0)));
        assert_eq!(
            roots(&[1.0; 9], [0.0, 1.0], 1e-3),
            Err(ClipError::Degree(8))
        );
        assert_eq!(
            roots(&[1.0, f64::NAN], [0.0, 1.0], 1e-3),
            Err(ClipError::NotFinite(1))
        );
        for t in [0.0, -1.0, 1e-13, 2.0, f64::NAN] {
            assert!(matches!(
                roots(&[1.0, -1.0], [0.0, 1.0], t),
                Err(ClipError::Tolerance(_))
            ));
        }
        assert!(matches!(
            roots(&[1.0, -1.0], [1.0, 1.0], 1e-3),
            Err(ClipError::Domain(_))
        ));
        assert!(ClipError::Tolerance(0.0).to_string().contains("tolerance"));
    }
}
