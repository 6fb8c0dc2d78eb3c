//! The slab sweep: the visible parts of one strip's pieces, found along the strip — an
//! exact two-dimensional slab decomposition of straight-sided pieces, in the place of
//! Nishita's Steps 4–5 (their "scan segments" are one-dimensional spans compared on each
//! sub-scanline; docs/ERRATA.md ND6), with the box filter's exact areas kept.
//!
//! Every piece of a strip lies between its two row lines, so along the strip the pieces
//! are compared slab by slab rather than pair by pair with polygon booleans:
//!
//! 1. **Slabs.** The `x` of every piece corner cuts the strip into slabs. No corner lies
//!    inside a slab, so each piece crosses it between two of its edges, each a straight
//!    line across the slab.
//! 2. **Cells.** The slab's lines are ordered at its middle, and each cell between two
//!    consecutive lines goes to the nearest piece covering it, compared at the cell's
//!    centre (`1/depth` is affine on a piece, and larger is nearer; equal: the lower
//!    index). Consecutive cells of one piece make a run.
//! 3. **Checks.** The middle's order holds all across the slab only where lines do not
//!    cross, and only the crossings that change what is seen matter. So the slab is cut
//!    where two lines that bound a run (or a winner's own edges) cross; cut wherever any
//!    two lines cross if a piece reaches into a gap; and, where another piece is nearer
//!    than a run's winner somewhere in what they share (checked at that region's
//!    corners: the surfaces cross), done again with the line where their `1/depth` are
//!    equal as one more line (or a cut, where it is upright). Nesting is bounded: what is
//!    left at the bound is rounding. So the runs a piece wins are exactly where it is
//!    nearest.
//! 4. **Fragments.** A piece's runs, joined from slab to slab where they meet side for
//!    side, are its fragments (x-monotone polygons), with the piece's affine intensity at
//!    their corners.
//!
//! A piece is a triangle ([`strip_fragments`], `nishita`'s pieces) or any convex polygon
//! in a plane: [`strip_by_strip`] resolves a frame's triangles with it, a strip of rows at
//! a time, each triangle's part in the strip one piece (`docs/VISIBILITY.md` measures it
//! against the pair-by-pair engine, [`crate::visibility`]), and [`strip_by_strip_into`]
//! hands each band of strips on as it is done, holding only the bands in flight.
//!
//! From one slab of a strip to the next most of the work runs on: each piece's lower and
//! upper edge is followed along its chains (and a line's `y` at the slab's left end is the
//! one found at the last slab's right end), and the slab's lines start in the last slab's
//! order, put in order by insertion.
//!
//! Only the pieces crossing a slab are looked at in it (the paper's active subpatches):
//! time grows with the pieces times the slabs each crosses, not with the pairs of
//! overlapping pieces, and no polygon boolean is needed. The areas are exact up to
//! rounding: coverage, depth order and intersections are all lines.

use crate::face::ScreenTriangle;
use crate::visibility::Fragment;
use arrayvec::ArrayVec;

/// Slabs narrower than this (px) are not cut further, nor checked (rounding at a
/// crossing): what such a slab can get wrong is at most its width times the strip's
/// height. (It was 1e-9: corners 1e-9 px apart made slabs that were taken unchecked, and a
/// triangle lost 1.0e-9 px² — `a_sliver_s_narrow_slabs_are_checked`.) About nine ulps at
/// 500 px.
const MIN_WIDTH: f64 = 1e-12;

/// Two lines whose `y` differ by at most this (px) at a slab's end meet there.
const TOUCH: f64 = 1e-10;

/// Relative `1/depth` difference below which two pieces are taken as coplanar.
const COPLANAR: f64 = 1e-12;

/// The most surface-crossing lines added to one slab before it is taken as it is.
const MAX_DEPTH_LINES: usize = 16;

/// The most slabs within slabs (cuts, lines added, a slab done again) before one is taken
/// as it is: what is left then is rounding.
const MAX_NESTING: u32 = 48;

/// Fragments of at most this area (px²) are dropped, and counted.
const SLIVER: f64 = 1e-13;

/// What the scan segments of a strip did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SegmentStats {
    /// Pieces in.
    pub pieces: u64,
    /// Pieces of which nothing is visible (including those with no area).
    pub hidden: u64,
    /// Fragments out.
    pub fragments: u64,
    /// Slabs, after the cuts at crossings.
    pub slabs: u64,
    /// Cuts where two edges cross inside a slab.
    pub edge_crossings: u64,
    /// Lines (or cuts) added where two surfaces cross inside a slab.
    pub depth_crossings: u64,
    /// Fragments dropped for an area of at most 1e-13 px² (where two lines meet within
    /// rounding), and their area in all.
    pub slivers: u64,
    /// Their area (px²).
    pub sliver_area: f64,
}

impl SegmentStats {
    /// Adds `o`.
    pub fn add(&mut self, o: &SegmentStats) {
        self.pieces += o.pieces;
        self.hidden += o.hidden;
        self.fragments += o.fragments;
        self.slabs += o.slabs;
        self.edge_crossings += o.edge_crossings;
        self.depth_crossings += o.depth_crossings;
        self.slivers += o.slivers;
        self.sliver_area += o.sliver_area;
    }
}

/// A straight line through two points `p`, `q` (`p` left of `q`): a piece's edge
/// (`added` 0; every piece's copy of one edge is the same, bit for bit), or a line added
/// where two pieces' surfaces cross (`added` names the pair).
#[derive(Clone, Copy, Debug)]
struct Line {
    p: [f64; 2],
    q: [f64; 2],
    added: u64,
}

impl Line {
    /// The edge from `a` to `b` (not upright), whichever way round.
    fn edge(a: [f64; 2], b: [f64; 2]) -> Line {
        let (p, q) = if (a[0], a[1]) <= (b[0], b[1]) {
            (a, b)
        } else {
            (b, a)
        };
        Line { p, q, added: 0 }
    }

    /// Whether `self` is `o` (an edge: the same end points, bit for bit).
    fn same(&self, o: &Line) -> bool {
        self.added == 0
            && o.added == 0
            && self.p.map(f64::to_bits) == o.p.map(f64::to_bits)
            && self.q.map(f64::to_bits) == o.q.map(f64::to_bits)
    }

    /// `y` at `x`: the end points' own `y` there, so that lines meeting at a corner meet
    /// bit for bit.
    fn at(&self, x: f64) -> f64 {
        if x == self.p[0] {
            self.p[1]
        } else if x == self.q[0] {
            self.q[1]
        } else {
            let t = (x - self.p[0]) / (self.q[0] - self.p[0]);
            self.p[1] + t * (self.q[1] - self.p[1])
        }
    }
}

/// A line's `y` at a slab's two ends.
type Ends = (f64, f64);

/// Lines ordered at a slab's middle (then by their ends).
fn ends_cmp(a: &Ends, b: &Ends) -> std::cmp::Ordering {
    (a.0 + a.1)
        .total_cmp(&(b.0 + b.1))
        .then(a.0.total_cmp(&b.0))
        .then(a.1.total_cmp(&b.1))
}

/// `x` as an integer in the order of [`f64::total_cmp`] (its own transformation).
fn ordered(x: f64) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ ((((bits >> 63) as u64) >> 1) as i64)
}

/// Whether `lines` keep their order at both ends of a slab (each `y` no smaller than the
/// one before, at either end): then no two of them cross inside it, and [`crossings`]
/// would find none — one pass instead of one look at every pair.
fn in_order_at_both_ends(lines: &[Ends]) -> bool {
    lines
        .windows(2)
        .all(|w| w[0].0 <= w[1].0 && w[0].1 <= w[1].1)
}

/// Where two of `lines` cross inside the slab `xa..xb` (ascending, at least
/// [`MIN_WIDTH`] from its ends).
fn crossings(lines: &[Ends], xa: f64, xb: f64) -> Vec<f64> {
    let mut cuts: Vec<f64> = Vec::new();
    for i in 0..lines.len() {
        for j in i + 1..lines.len() {
            let da = lines[i].0 - lines[j].0;
            let db = lines[i].1 - lines[j].1;
            if (da > TOUCH && db < -TOUCH) || (da < -TOUCH && db > TOUCH) {
                let xc = xa + (xb - xa) * (da / (da - db));
                if xc - xa > MIN_WIDTH && xb - xc > MIN_WIDTH {
                    cuts.push(xc);
                }
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    cuts
}

/// Whether one of the regions between two lines, `a = (lower, upper)` and `b`, lies
/// wholly above the other at both ends of a slab (so all along it): the quick part of
/// [`overlap`].
fn apart(a: (Ends, Ends), b: (Ends, Ends)) -> bool {
    (a.1 .0 <= b.0 .0 + TOUCH && a.1 .1 <= b.0 .1 + TOUCH)
        || (b.1 .0 <= a.0 .0 + TOUCH && b.1 .1 <= a.0 .1 + TOUCH)
}

/// Whether the regions between two lines, `a = (lower, upper)` and `b`, overlap
/// (more than touch) somewhere across a slab. The height of their overlap,
/// `min(upper) − max(lower)`, is concave along the slab: its largest value is at an end
/// or where the two lowers or the two uppers cross.
fn overlap(a: (Ends, Ends), b: (Ends, Ends)) -> bool {
    let at = |e: Ends, t: f64| e.0 + t * (e.1 - e.0);
    let meet = |e: Ends, f: Ends| {
        let (da, db) = (e.0 - f.0, e.1 - f.1);
        (da * db < 0.0).then(|| da / (da - db))
    };
    if apart(a, b) {
        return false;
    }
    let height = |t: f64| at(a.1, t).min(at(b.1, t)) - at(a.0, t).max(at(b.0, t));
    [Some(0.0), Some(1.0), meet(a.0, b.0), meet(a.1, b.1)]
        .into_iter()
        .flatten()
        .any(|t| height(t) > TOUCH)
}

/// The corners `(t, y)` (`t` from 0 at the slab's left end to 1 at its right) of the
/// region two pieces of a slab share, `a = (lower, upper)` and `b` (none if they share
/// nothing): it is convex, bounded below by the higher lower and above by the lower
/// upper, so its corners lie at the ends and where two of the four lines cross.
fn corners(a: (Ends, Ends), b: (Ends, Ends)) -> ([(f64, f64); 12], usize) {
    let at = |e: Ends, t: f64| e.0 + t * (e.1 - e.0);
    let meet = |e: Ends, f: Ends| {
        let (da, db) = (e.0 - f.0, e.1 - f.1);
        (da * db < 0.0).then(|| da / (da - db))
    };
    let mut out = [(0.0, 0.0); 12];
    let mut n = 0;
    let ts = [
        Some(0.0),
        Some(1.0),
        meet(a.0, b.0),
        meet(a.1, b.1),
        meet(a.0, b.1),
        meet(a.1, b.0),
    ];
    for t in ts.into_iter().flatten() {
        let lower = at(a.0, t).max(at(b.0, t));
        let upper = at(a.1, t).min(at(b.1, t));
        if upper >= lower - TOUCH {
            out[n] = (t, lower);
            out[n + 1] = (t, upper);
            n += 2;
        }
    }
    (out, n)
}

/// A piece prepared: its `1/depth` plane, its box, its edges.
struct Prepared {
    plane: Plane,
    x0: f64,
    x1: f64,
    /// Its corners' `x` (every edge's two ends, each once).
    corner_xs: ArrayVec<f64, 5>,
    /// Its lower and upper edges (indices in `edges`, left to right; upright ones in
    /// neither): where two of them cross a slab, the lower is below.
    chains: [ArrayVec<u8, 5>; 2],
    /// Its edges: a triangle's three, or a convex polygon's (a triangle's part in a
    /// strip: at most five).
    edges: ArrayVec<Line, 5>,
}

/// A piece's `1/depth` as `gx·x + gy·y + c`, and its size (for the coplanar test).
#[derive(Clone, Copy, Debug, Default)]
struct Plane {
    gx: f64,
    gy: f64,
    c: f64,
    scale: f64,
}

impl Plane {
    fn at(&self, x: f64, y: f64) -> f64 {
        self.gx * x + self.gy * y + self.c
    }
}

/// A triangle's `1/depth` as `(gx, gy, c)` (`gx·x + gy·y + c`) and the largest of its
/// three, or `None` when it cannot be drawn (no area, or not finite).
fn plane<S>(t: &ScreenTriangle<S>) -> Option<([f64; 3], f64)> {
    let [a, b, c] = t.points;
    let d = t.doubled_area();
    let finite = t.points.iter().flatten().all(|v| v.is_finite())
        && t.inv_depth.iter().all(|v| v.is_finite());
    if d == 0.0 || !d.is_finite() || !finite {
        return None;
    }
    let [z0, z1, z2] = t.inv_depth;
    let gx = ((z1 - z0) * (c[1] - a[1]) - (z2 - z0) * (b[1] - a[1])) / d;
    let gy = ((b[0] - a[0]) * (z2 - z0) - (c[0] - a[0]) * (z1 - z0)) / d;
    let scale = t.inv_depth.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    Some(([gx, gy, z0 - gx * a[0] - gy * a[1]], scale))
}

impl Prepared {
    fn of<S>(t: &ScreenTriangle<S>) -> Option<Prepared> {
        let (plane, scale) = plane(t)?;
        Some(Prepared::polygon(&t.points, plane, scale))
    }

    /// The convex polygon `corners` (3 to 5, in either orientation) in the plane
    /// `plane` (`1/depth` as `gx·x + gy·y + c`; `scale`: its size, for the coplanar test).
    fn polygon(corners: &[[f64; 2]], plane: [f64; 3], scale: f64) -> Prepared {
        let xs = corners.iter().map(|p| p[0]);
        let edges: ArrayVec<Line, 5> = (0..corners.len())
            .map(|e| Line::edge(corners[e], corners[(e + 1) % corners.len()]))
            .collect();
        // going the polygon's way round, an edge that goes the way of its orientation
        // (left to right when it is anticlockwise with y up) is a lower one
        let turn = doubled_area(corners).signum();
        let mut chains = [ArrayVec::new(), ArrayVec::new()];
        for e in 0..corners.len() {
            let dx = corners[(e + 1) % corners.len()][0] - corners[e][0];
            if dx != 0.0 {
                chains[usize::from(dx.signum() != turn)].push(e as u8);
            }
        }
        for chain in &mut chains {
            chain.sort_unstable_by(|&a, &b| {
                edges[a as usize].p[0].total_cmp(&edges[b as usize].p[0])
            });
        }
        Prepared {
            chains,
            plane: Plane {
                gx: plane[0],
                gy: plane[1],
                c: plane[2],
                scale,
            },
            x0: xs.clone().fold(f64::INFINITY, f64::min),
            x1: xs.fold(f64::NEG_INFINITY, f64::max),
            corner_xs: corners.iter().map(|p| p[0]).collect(),
            edges,
        }
    }
}

/// One piece's visible cells joined from slab to slab: its lower and upper outlines
/// (the points where their line changes), the lines they follow now, and how far.
#[derive(Clone, Debug)]
struct Chain {
    source: usize,
    lower: Vec<[f64; 2]>,
    upper: Vec<[f64; 2]>,
    lower_line: Line,
    upper_line: Line,
    x1: f64,
    /// The lower and upper lines' `y` at `x1` (as the slab that reached it found them).
    y1: [f64; 2],
}

impl Chain {
    /// Its outline: the lower points left to right, then the upper ones back, without
    /// repeated points.
    fn outline(&self) -> Vec<[f64; 2]> {
        let x1 = self.x1;
        let mut v: Vec<[f64; 2]> = Vec::with_capacity(self.lower.len() + self.upper.len() + 2);
        let ends = [[x1, self.y1[0]], [x1, self.y1[1]]];
        for p in self
            .lower
            .iter()
            .chain(&ends)
            .chain(self.upper.iter().rev())
        {
            if v.last() != Some(p) {
                v.push(*p);
            }
        }
        while v.len() > 1 && v.first() == v.last() {
            v.pop();
        }
        v
    }
}

/// Scratch space for one slab, kept between slabs.
#[derive(Default)]
struct Scratch {
    /// The pieces across the slab; the lines of the `b`-th are `lines[2b]` (lower) and
    /// `lines[2b + 1]`.
    bounds: Vec<usize>,
    lines: Vec<Line>,
    ends: Vec<Ends>,
    sorted: Vec<(i64, u32)>,
    /// Spare room for `sorted`.
    ordered: Vec<(i64, u32)>,
    order: Vec<Ends>,
    /// The index in `lines` of the line of each rank.
    by_rank: Vec<u32>,
    rank_of: Vec<usize>,
    winner: Vec<Option<usize>>,
    runs: Vec<(Option<usize>, usize, usize)>,
    bounding: Vec<Ends>,
    marked: Vec<bool>,
}

/// The visible parts of a strip's pieces `tris` (see the [module docs](self)), in
/// source order, each with its source's intensity (the first `channels` entries) at its
/// corners.
pub fn strip_fragments<S>(
    tris: &[ScreenTriangle<S>],
    channels: usize,
    stats: &mut SegmentStats,
) -> Vec<Fragment> {
    let prepared: Vec<Option<Prepared>> = tris.iter().map(Prepared::of).collect();
    visible_parts(&prepared, stats)
        .into_iter()
        .map(|(k, vertices)| Fragment::of_triangle(k, &tris[k], vertices, channels))
        .collect()
}

/// The visible parts of a strip's pieces (`None`: one that cannot be drawn), each as the
/// piece's index and its outline, in piece order (then left to right).
fn visible_parts(
    prepared: &[Option<Prepared>],
    stats: &mut SegmentStats,
) -> Vec<(usize, Vec<[f64; 2]>)> {
    stats.pieces += prepared.len() as u64;
    let mut xs: Vec<f64> = prepared
        .iter()
        .flatten()
        .flat_map(|p| p.corner_xs.iter().copied())
        .collect();
    xs.sort_unstable_by(f64::total_cmp);
    xs.dedup();
    let start = |k: usize| prepared[k].as_ref().map_or(0.0, |p| p.x0);
    let mut by_start: Vec<usize> = (0..prepared.len())
        .filter(|&k| prepared[k].is_some())
        .collect();
    by_start.sort_unstable_by(|&a, &b| start(a).total_cmp(&start(b)).then(a.cmp(&b)));
    let planes: Vec<Plane> = prepared
        .iter()
        .map(|p| p.as_ref().map_or(Plane::default(), |p| p.plane))
        .collect();
    let mut sweep = Sweep {
        prepared,
        planes: &planes,
        stats,
        chains: Vec::new(),
        open: Vec::new(),
        next: Vec::new(),
        closed: Vec::new(),
        pool: Vec::new(),
        nesting: 0,
        by_y: Vec::new(),
        listed: vec![false; prepared.len()],
        bound_of: vec![u32::MAX; prepared.len()],
        follow: vec![[Followed::START; 2]; prepared.len()],
    };
    let mut active: Vec<usize> = Vec::new();
    let mut entering = 0;
    for w in xs.windows(2) {
        let (xa, xb) = (w[0], w[1]);
        while entering < by_start.len() && start(by_start[entering]) <= xa {
            active.push(by_start[entering]);
            entering += 1;
        }
        active.retain(|&k| prepared[k].as_ref().is_some_and(|p| p.x1 > xa));
        if active.is_empty() {
            sweep.close_all();
            continue;
        }
        sweep.slab(&active, xa, xb, &[], 0, false);
    }
    sweep.close_all();
    let chains = std::mem::take(&mut sweep.chains);
    let mut closed = std::mem::take(&mut sweep.closed);
    closed.sort_by(|&a, &b| {
        let (a, b) = (&chains[a], &chains[b]);
        a.source
            .cmp(&b.source)
            .then(a.lower[0][0].total_cmp(&b.lower[0][0]))
    });
    let stats = sweep.stats;
    let mut visible = vec![false; prepared.len()];
    let mut out = Vec::with_capacity(chains.len());
    for c in closed.into_iter().map(|k| &chains[k]) {
        let vertices = c.outline();
        if vertices.len() < 3 {
            continue;
        }
        let o = vertices[0];
        let area = 0.5
            * (1..vertices.len() - 1)
                .map(|i| {
                    let (a, b) = (vertices[i], vertices[i + 1]);
                    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
                })
                .sum::<f64>()
                .abs();
        if area <= SLIVER {
            stats.slivers += 1;
            stats.sliver_area += area;
            continue;
        }
        visible[c.source] = true;
        out.push((c.source, vertices));
    }
    stats.fragments += out.len() as u64;
    stats.hidden += visible.iter().filter(|v| !**v).count() as u64;
    out
}

/// One of a piece's chains followed from slab to slab: the place in it, the edge there,
/// and that edge's `y` at the `x` last asked (so that the next slab, which starts there,
/// need not work it out again).
#[derive(Clone, Copy, Debug)]
struct Followed {
    place: u8,
    edge: u8,
    x: f64,
    y: f64,
}

impl Followed {
    /// Before the first slab: no edge, no `x` asked.
    const START: Followed = Followed {
        place: 0,
        edge: u8::MAX,
        x: f64::NAN,
        y: 0.0,
    };
}

/// The sweep's state: the chains open at the current slab's left end, those it
/// continues or starts, and those closed; scratch space for the slabs.
struct Sweep<'a> {
    prepared: &'a [Option<Prepared>],
    /// Each piece's `1/depth` plane and size, side by side (what the slabs compare).
    planes: &'a [Plane],
    stats: &'a mut SegmentStats,
    /// Every chain, open or closed; the sweep's lists hold their indices.
    chains: Vec<Chain>,
    open: Vec<usize>,
    next: Vec<usize>,
    closed: Vec<usize>,
    /// Boxed: a slab takes one and gives it back, and moving a pointer is cheaper than
    /// moving a dozen vectors' headers.
    #[allow(clippy::vec_box)]
    pool: Vec<Box<Scratch>>,
    /// Slabs within slabs now.
    nesting: u32,
    /// The active pieces' lower (0) and upper (1) lines in the order of the last slab
    /// of the sweep (not a nested one), kept from slab to slab.
    by_y: Vec<(u32, u8)>,
    /// Whether a piece is in `by_y`.
    listed: Vec<bool>,
    /// Each piece's place in the slab's bounds (`u32::MAX`: none), while ordering.
    bound_of: Vec<u32>,
    /// Each piece's lower and upper edge, followed from slab to slab.
    follow: Vec<[Followed; 2]>,
}

impl Sweep<'_> {
    /// Closes every open chain (a gap in the strip, or its end).
    fn close_all(&mut self) {
        self.closed.append(&mut self.open);
    }

    /// The slab `xa..xb` crossed by the pieces `active`, with `extra` lines where
    /// surfaces were found to cross (`added` of them so far); `all_cuts`: cut the slab
    /// where any two lines cross, not only the lines that bound what is visible.
    fn slab(
        &mut self,
        active: &[usize],
        xa: f64,
        xb: f64,
        extra: &[Line],
        added: usize,
        all_cuts: bool,
    ) {
        let mut scratch = self.pool.pop().unwrap_or_default();
        self.nesting += 1;
        self.slab_in(&mut scratch, active, xa, xb, extra, added, all_cuts);
        self.nesting -= 1;
        self.pool.push(scratch);
    }

    #[allow(clippy::too_many_arguments)]
    fn slab_in(
        &mut self,
        sc: &mut Scratch,
        active: &[usize],
        xa: f64,
        xb: f64,
        extra: &[Line],
        added: usize,
        all_cuts: bool,
    ) {
        let xm = 0.5 * (xa + xb);
        // wide enough to cut, and not nested too deep to do it again
        let wide = xb - xa > 2.0 * MIN_WIDTH && self.nesting < MAX_NESTING;
        let planes = self.planes;
        let piece = |k: usize| &planes[k];
        // a slab of the sweep itself (not one within a slab, no lines added): it starts
        // where the last one ended, and what that one found runs on
        let top = self.nesting == 1 && extra.is_empty();
        // each piece's two edges across the slab, lower first, and their ends
        sc.bounds.clear();
        sc.lines.clear();
        sc.ends.clear();
        if top {
            // the edges and their ends followed from the slab before
            self.bounds_followed(sc, active, xa, xb);
        } else {
            self.bounds_found(sc, active, xa, xb);
            sc.ends
                .extend(sc.lines.iter().map(|l| (l.at(xa), l.at(xb))));
        }
        sc.lines.extend_from_slice(extra);
        sc.ends.extend(extra.iter().map(|l| (l.at(xa), l.at(xb))));
        if all_cuts && wide {
            let cuts = crossings(&sc.ends, xa, xb);
            if !cuts.is_empty() {
                return self.cut(active, xa, xb, &cuts, extra, added, false);
            }
        }
        // the lines ordered at the middle (equal ends: one line, one rank); the first
        // key of `ends_cmp` as an integer, the rest looked up only on a tie
        sc.sorted.clear();
        sc.sorted.extend(
            sc.ends
                .iter()
                .enumerate()
                .map(|(i, e)| (ordered(e.0 + e.1), i as u32)),
        );
        if top {
            // its lines in the order of the slab before
            // (each piece's lower and upper line run on from slab to slab), with the new
            // pieces' after them, then put in order by insertion — a few steps, where a
            // sort of lines in no order mispredicts at every other comparison
            self.in_order(sc);
        } else {
            sc.sorted.sort_unstable();
        }
        let ends = &sc.ends;
        // equal first keys (rare): ordered by the rest of `ends_cmp`, then the index
        let mut i = 0;
        while i < sc.sorted.len() {
            let mut j = i + 1;
            while j < sc.sorted.len() && sc.sorted[j].0 == sc.sorted[i].0 {
                j += 1;
            }
            if j - i > 1 {
                sc.sorted[i..j].sort_unstable_by(|&(_, a), &(_, b)| {
                    ends_cmp(&ends[a as usize], &ends[b as usize]).then(a.cmp(&b))
                });
            }
            i = j;
        }
        sc.order.clear();
        sc.by_rank.clear();
        sc.rank_of.clear();
        sc.rank_of.resize(ends.len(), 0);
        for &(_, i) in &sc.sorted {
            let i = i as usize;
            if sc.order.last() != Some(&ends[i]) {
                sc.order.push(ends[i]);
                sc.by_rank.push(i as u32);
            }
            sc.rank_of[i] = sc.order.len() - 1;
        }
        let order = &sc.order;
        let cells = order.len().saturating_sub(1);
        let span = |b: usize| (sc.rank_of[2 * b], sc.rank_of[2 * b + 1]);
        // the nearest piece over each cell, at its centre
        let centre = |r: usize| {
            (
                xm,
                0.25 * (order[r].0 + order[r].1 + order[r + 1].0 + order[r + 1].1),
            )
        };
        sc.winner.clear();
        sc.winner.resize(cells, None);
        for b in 0..sc.bounds.len() {
            let (lo, hi) = span(b);
            for r in lo..hi {
                let nearer = match sc.winner[r] {
                    None => true,
                    Some(o) => {
                        let (x, y) = centre(r);
                        let (kb, ko) = (sc.bounds[b], sc.bounds[o]);
                        let (pb, po) = (piece(kb), piece(ko));
                        let (zb, zo) = (pb.at(x, y), po.at(x, y));
                        let tol = COPLANAR * pb.scale.max(po.scale);
                        if (zb - zo).abs() <= tol {
                            kb < ko
                        } else {
                            zb > zo
                        }
                    }
                };
                if nearer {
                    sc.winner[r] = Some(b);
                }
            }
        }
        // runs of one winner's cells, and the gaps between them (`None`)
        sc.runs.clear();
        let mut r = 0;
        while r < cells {
            let mut end = r + 1;
            while end < cells && sc.winner[end] == sc.winner[r] {
                end += 1;
            }
            sc.runs.push((sc.winner[r], r, end));
            r = end;
        }
        // every line in its order at both ends of the slab (the common case): then no two
        // cross inside it, checks (1) and (2) below cannot fail, and regions whose ranks
        // do not overlap lie apart all across it
        let consistent = in_order_at_both_ends(order);
        if wide && !consistent {
            // (1) the lines that bound what is visible, and the winners' own lines, must
            // not cross inside the slab: cut where they do
            // their ranks marked, then read in rank order: sorted, each once
            sc.marked.clear();
            sc.marked.resize(order.len(), false);
            for &(w, lo, hi) in &sc.runs {
                sc.marked[lo] = true;
                sc.marked[hi] = true;
                if let Some(w) = w {
                    let (a, b) = span(w);
                    sc.marked[a] = true;
                    sc.marked[b] = true;
                }
            }
            sc.bounding.clear();
            sc.bounding.extend(
                order
                    .iter()
                    .zip(&sc.marked)
                    .filter(|(_, &m)| m)
                    .map(|(e, _)| *e),
            );
            if !in_order_at_both_ends(&sc.bounding) {
                let cuts = crossings(&sc.bounding, xa, xb);
                if !cuts.is_empty() {
                    return self.cut(active, xa, xb, &cuts, extra, added, false);
                }
            }
            // (2) no piece reaches into a gap (below the lowest line, above the highest, or
            // a cell nothing covered at its centre)
            if let (Some(&lowest), Some(&highest)) = (order.first(), order.last()) {
                let gaps = sc.runs.iter().any(|r| r.0.is_none());
                for b in 0..sc.bounds.len() {
                    let (lo, hi) = (sc.ends[2 * b], sc.ends[2 * b + 1]);
                    let below = lo.0 < lowest.0 - TOUCH || lo.1 < lowest.1 - TOUCH;
                    let above = hi.0 > highest.0 + TOUCH || hi.1 > highest.1 + TOUCH;
                    let gap = gaps
                        && sc.runs.iter().any(|&(w, g0, g1)| {
                            w.is_none() && overlap((lo, hi), (order[g0], order[g1]))
                        });
                    if (below || above || gap) && !all_cuts {
                        // lines of pieces under others cross where it matters: cut at
                        // every crossing
                        return self.slab(active, xa, xb, extra, added, true);
                    }
                }
            }
        }
        if wide {
            // (3) no piece nearer than a run's winner anywhere it overlaps the run: else
            // the two surfaces cross inside the slab
            if added < MAX_DEPTH_LINES {
                for &(w, lo, hi) in &sc.runs {
                    let Some(w) = w else { continue };
                    let run = (order[lo], order[hi]);
                    let pw = piece(sc.bounds[w]);
                    for b in 0..sc.bounds.len() {
                        let own = (sc.ends[2 * b], sc.ends[2 * b + 1]);
                        if b == w {
                            continue;
                        }
                        let (b_lo, b_hi) = span(b);
                        if consistent && (b_hi <= lo || b_lo >= hi) {
                            continue;
                        }
                        if apart(own, run) {
                            continue;
                        }
                        let pb = piece(sc.bounds[b]);
                        let tol = COPLANAR * pb.scale.max(pw.scale);
                        let d = |x: f64, y: f64| pb.at(x, y) - pw.at(x, y);
                        // the winner nearer at the run's corners is nearer all over it
                        // (the difference is affine): the common case, a piece behind
                        let at_corners = [
                            d(xa, run.0 .0),
                            d(xb, run.0 .1),
                            d(xa, run.1 .0),
                            d(xb, run.1 .1),
                        ];
                        if at_corners.iter().all(|&v| v <= tol) {
                            // not nearer anywhere on the run; but a coplanar piece that
                            // comes first wins all they share (the lower index), and the
                            // cells found at the middle are cells across the slab only
                            // when no two lines cross in it
                            let tie = !all_cuts
                                && sc.bounds[b] < sc.bounds[w]
                                && at_corners.iter().any(|&v| v >= -tol)
                                && overlap(own, run)
                                && {
                                    let (common, n) = corners(own, run);
                                    common[..n]
                                        .iter()
                                        .all(|&(t, y)| d(xa + t * (xb - xa), y).abs() <= tol)
                                };
                            if tie {
                                return self.slab(active, xa, xb, extra, added, true);
                            }
                            continue;
                        }
                        if !overlap(own, run) {
                            continue;
                        }
                        let (common, n) = corners(own, run);
                        let common = &common[..n];
                        if common.iter().all(|&(t, y)| d(xa + t * (xb - xa), y) <= tol) {
                            // not nearer where they share: as near all over it (coplanar
                            // there) and first, it wins it, as above
                            if !all_cuts
                                && sc.bounds[b] < sc.bounds[w]
                                && common
                                    .iter()
                                    .all(|&(t, y)| d(xa + t * (xb - xa), y) >= -tol)
                            {
                                return self.slab(active, xa, xb, extra, added, true);
                            }
                            continue;
                        }
                        // d = ga·x + gb·y + c0 = 0: a line across the slab, or, upright,
                        // a cut; then the slab is done again with a cut wherever two
                        // lines cross (the cells found at its middle may not be cells)
                        let pair = 1 + ((sc.bounds[b] as u64) << 32 | sc.bounds[w] as u64);
                        if extra.iter().any(|l| l.added == pair) {
                            if all_cuts {
                                // done already: what is left is rounding
                                continue;
                            }
                            return self.slab(active, xa, xb, extra, added, true);
                        }
                        let (ga, gb) = (pb.gx - pw.gx, pb.gy - pw.gy);
                        let c0 = pb.c - pw.c;
                        self.stats.depth_crossings += 1;
                        let y = |x: f64| -(ga * x + c0) / gb;
                        let (ya, yb) = (y(xa), y(xb));
                        if gb != 0.0 && ya.is_finite() && yb.is_finite() {
                            let mut more = extra.to_vec();
                            more.push(Line {
                                p: [xa, ya],
                                q: [xb, yb],
                                added: pair,
                            });
                            return self.slab(active, xa, xb, &more, added + 1, true);
                        }
                        let yc = 0.25 * (run.0 .0 + run.0 .1 + run.1 .0 + run.1 .1);
                        let xc = -(gb * yc + c0) / ga;
                        if xc - xa > MIN_WIDTH && xb - xc > MIN_WIDTH {
                            return self.cut(active, xa, xb, &[xc], extra, added + 1, true);
                        }
                        // upright and outside the slab: the piece is nearer all across
                        // it, so the cells found at the middle were not cells
                        if !all_cuts {
                            return self.slab(active, xa, xb, extra, added, true);
                        }
                    }
                }
            }
        }
        self.stats.slabs += 1;
        // the pieces' own lines' reach at each end: a run's ends are kept within it (they
        // are, but where a line added between two surfaces is nearly upright and its `y`
        // at an end, a rounding away from a crossing, lies beyond every piece)
        let reach = |end: fn(&Ends) -> f64| {
            sc.ends[..2 * sc.bounds.len()]
                .iter()
                .map(end)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
                    (l.min(y), h.max(y))
                })
        };
        let (at_a, at_b) = (reach(|e| e.0), reach(|e| e.1));
        let within = |y: f64, (l, h): (f64, f64)| y.max(l).min(h);
        // each run joined to its piece's open chain where they meet, side for side
        for &(w, lo, hi) in &sc.runs {
            let Some(w) = w else { continue };
            let source = sc.bounds[w];
            let (lower, upper) = (
                sc.lines[sc.by_rank[lo] as usize],
                sc.lines[sc.by_rank[hi] as usize],
            );
            let (ya_lower, ya_upper) = (within(order[lo].0, at_a), within(order[hi].0, at_a));
            let y1 = [within(order[lo].1, at_b), within(order[hi].1, at_b)];
            let chains = &self.chains;
            let continued = self.open.iter().position(|&k| {
                let c = &chains[k];
                c.source == source
                    && c.x1 == xa
                    && c.y1[0] == ya_lower
                    && c.y1[1] == ya_upper
                    && ya_lower < ya_upper
            });
            match continued {
                Some(i) => {
                    let k = self.open.swap_remove(i);
                    let c = &mut self.chains[k];
                    if !c.lower_line.same(&lower) {
                        c.lower.push([xa, ya_lower]);
                        c.lower_line = lower;
                    }
                    if !c.upper_line.same(&upper) {
                        c.upper.push([xa, ya_upper]);
                        c.upper_line = upper;
                    }
                    c.x1 = xb;
                    c.y1 = y1;
                    self.next.push(k);
                }
                None => {
                    self.next.push(self.chains.len());
                    self.chains.push(Chain {
                        source,
                        lower: vec![[xa, ya_lower]],
                        upper: vec![[xa, ya_upper]],
                        lower_line: lower,
                        upper_line: upper,
                        x1: xb,
                        y1,
                    });
                }
            }
        }
        // what this slab did not continue is closed
        self.closed.append(&mut self.open);
        std::mem::swap(&mut self.open, &mut self.next);
    }

    /// Each of `active`'s two edges across the slab `xa..xb`, lower first, into
    /// `sc.bounds`: the two edges that cross its middle.
    fn bounds_found(&self, sc: &mut Scratch, active: &[usize], xa: f64, xb: f64) {
        let xm = 0.5 * (xa + xb);
        for &k in active {
            let piece = self.prepared[k]
                .as_ref()
                .expect("an active piece is prepared");
            let mut across = [None; 2];
            let mut n = 0;
            for l in &piece.edges {
                // p is left of (or level with) q
                if l.p[0] < xm && xm < l.q[0] && n < 2 {
                    across[n] = Some(*l);
                    n += 1;
                }
            }
            if let [Some(l0), Some(l1)] = across {
                sc.bounds.push(k);
                if l0.at(xm) <= l1.at(xm) {
                    sc.lines.extend([l0, l1]);
                } else {
                    sc.lines.extend([l1, l0]);
                }
            }
        }
    }

    /// [`Sweep::bounds_found`] for a slab of the sweep itself (no corner inside it),
    /// with the lines' ends into `sc.ends`: each piece's lower and upper edge followed
    /// along its chains from the slab before, and a line's `y` at this slab's left end
    /// the one found at the last one's right end.
    fn bounds_followed(&mut self, sc: &mut Scratch, active: &[usize], xa: f64, xb: f64) {
        let xm = 0.5 * (xa + xb);
        for &k in active {
            let piece = self.prepared[k]
                .as_ref()
                .expect("an active piece is prepared");
            let mut lines = [None; 2];
            let mut ends = [(0.0, 0.0); 2];
            for (side, chain) in piece.chains.iter().enumerate() {
                let follow = &mut self.follow[k][side];
                let mut i = follow.place as usize;
                while i < chain.len() && piece.edges[chain[i] as usize].q[0] <= xa {
                    i += 1;
                }
                follow.place = i as u8;
                let Some(&e) = chain.get(i) else { break };
                let l = piece.edges[e as usize];
                if !(l.p[0] < xm && xm < l.q[0]) {
                    break;
                }
                let ya = if follow.edge == e && follow.x == xa {
                    follow.y
                } else {
                    l.at(xa)
                };
                let yb = l.at(xb);
                *follow = Followed {
                    place: i as u8,
                    edge: e,
                    x: xb,
                    y: yb,
                };
                lines[side] = Some(l);
                ends[side] = (ya, yb);
            }
            match lines {
                [Some(l0), Some(l1)] => {
                    sc.bounds.push(k);
                    sc.lines.extend([l0, l1]);
                    sc.ends.extend(ends);
                }
                _ => {
                    // not two chains across the middle (a piece thinner than rounding):
                    // its edges found as in a slab within a slab
                    let at = sc.lines.len();
                    self.bounds_found(sc, &[k], xa, xb);
                    for i in at..sc.lines.len() {
                        let l = sc.lines[i];
                        sc.ends.push((l.at(xa), l.at(xb)));
                    }
                }
            }
        }
    }

    /// `sc.sorted` (each line's key and index, in the order of `sc.lines`) ordered by its
    /// keys and indices, starting from the order of the slab before ([`Sweep::by_y`]),
    /// which is then this slab's.
    fn in_order(&mut self, sc: &mut Scratch) {
        let bound_of = &mut self.bound_of;
        for (b, &k) in sc.bounds.iter().enumerate() {
            bound_of[k] = b as u32;
        }
        // the pieces that left, out; those that came, in (at the end)
        let listed = &mut self.listed;
        self.by_y.retain(|&(k, _)| {
            let kept = bound_of[k as usize] != u32::MAX;
            if !kept {
                listed[k as usize] = false;
            }
            kept
        });
        let kept = self.by_y.len();
        for &k in &sc.bounds {
            if !listed[k] {
                listed[k] = true;
                self.by_y.extend([(k as u32, 0), (k as u32, 1)]);
            }
        }
        // each line's key and index, side by side in that order, put in order by
        // insertion (ties of the key are settled after, as after a sort)
        let keyed = &mut sc.ordered;
        keyed.clear();
        keyed.extend(self.by_y.iter().map(|&(k, side)| {
            let i = (2 * bound_of[k as usize] + u32::from(side)) as usize;
            (sc.sorted[i].0, i as u32)
        }));
        if keyed.len() - kept > 8 {
            // many new ones (a strip's first slab): sorted as they are
            keyed.sort_unstable();
        } else {
            for i in 1..keyed.len() {
                let x = keyed[i];
                let mut j = i;
                while j > 0 && x < keyed[j - 1] {
                    keyed[j] = keyed[j - 1];
                    j -= 1;
                }
                keyed[j] = x;
            }
        }
        self.by_y.clear();
        self.by_y.extend(
            keyed
                .iter()
                .map(|&(_, i)| (sc.bounds[i as usize / 2] as u32, (i % 2) as u8)),
        );
        std::mem::swap(&mut sc.sorted, &mut sc.ordered);
        for &k in &sc.bounds {
            bound_of[k] = u32::MAX;
        }
    }

    /// The slab `xa..xb` done as the slabs between `cuts` (ascending, inside it).
    #[allow(clippy::too_many_arguments)]
    fn cut(
        &mut self,
        active: &[usize],
        xa: f64,
        xb: f64,
        cuts: &[f64],
        extra: &[Line],
        added: usize,
        all_cuts: bool,
    ) {
        self.stats.edge_crossings += cuts.len() as u64;
        let mut from = xa;
        for &c in cuts.iter().chain(std::iter::once(&xb)) {
            if c > from {
                self.slab(active, from, c, extra, added, all_cuts);
                from = c;
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Strip by strip: a frame's triangles through the slab sweep.

/// The part of the convex polygon `poly` on the side of the row line `y = c` that
/// `below` names (`y ≥ c` when true), into `out`. A point where an edge crosses the line
/// is interpolated from the edge's lower end point (in `(x, y)` order), whichever way
/// round the polygon runs it, with its `y` exactly `c`: triangles sharing an edge get the
/// same cut points, bit for bit.
fn clip_at_row(poly: &[[f64; 2]], c: f64, below: bool, out: &mut ArrayVec<[f64; 2], 5>) {
    out.clear();
    let side = |p: [f64; 2]| if below { p[1] - c } else { c - p[1] };
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
            let (p, q) = if (a[0], a[1]) <= (b[0], b[1]) {
                (a, b)
            } else {
                (b, a)
            };
            let t = (c - p[1]) / (q[1] - p[1]);
            // a triangle cut by two lines has at most five corners
            out.push([p[0] + t * (q[0] - p[0]), c]);
        }
    }
}

/// Twice the signed area of the polygon `v`.
fn doubled_area(v: &[[f64; 2]]) -> f64 {
    let o = v[0];
    (1..v.len() - 1)
        .map(|i| (v[i][0] - o[0]) * (v[i + 1][1] - o[1]) - (v[i][1] - o[1]) * (v[i + 1][0] - o[0]))
        .sum()
}

/// The exact visible fragments of a frame's `tris`, found strip by strip: the rows are
/// cut into strips `rows` pixel rows high (0 taken as 1) between the row lines `y = k·rows`, the triangles that meet a strip
/// (an active list over the triangles sorted by their tops, Woo & Chall's `ySortList`
/// and `yActiveList`) clipped to it, each part a convex piece in its triangle's plane,
/// and each strip's pieces resolved slab by slab as [`strip_fragments`] resolves them. Only one strip's pieces are held at a time. A
/// fragment lies within one strip; its `source` is the index in `tris`, its intensities
/// the source's affine intensity at its corners, as [`crate::visibility::exact_fragments`]
/// gives them (the same visible areas, cut along the row lines; ties between coplanar
/// triangles go to the lower index, as there). In source order, then strip by strip.
pub fn strip_by_strip(
    tris: &[ScreenTriangle],
    channels: usize,
    rows: u32,
) -> (Vec<Fragment>, SegmentStats) {
    strip_by_strip_on(tris, channels, rows, 1)
}

/// Strips resolved in one band (a thread takes a band at a time).
const STRIPS_PER_BAND: u32 = 16;

/// [`strip_by_strip`] on `threads` threads (0: one per core): bands of
/// [`STRIPS_PER_BAND`] strips, taken by the threads one at a time and joined in order, so
/// the fragments and the statistics are the same, bit for bit, at any thread count.
pub fn strip_by_strip_on(
    tris: &[ScreenTriangle],
    channels: usize,
    rows: u32,
    threads: usize,
) -> (Vec<Fragment>, SegmentStats) {
    let mut stats = SegmentStats::default();
    let mut out = Vec::new();
    strip_by_strip_into(tris, channels, rows, threads, |band| {
        stats.add(&band.stats);
        out.extend(band.fragments);
    });
    out.sort_by_key(|f| f.source);
    (out, stats)
}

/// One band of strips resolved: what [`strip_by_strip_into`] hands on.
#[derive(Debug)]
pub struct Band {
    /// Its place among the frame's bands, top first.
    pub index: usize,
    /// The `y` range it covers, `top..end` (on row lines).
    pub rows: (f64, f64),
    /// Its fragments, strip by strip from the top, each strip's in source order. Each
    /// lies within one strip.
    pub fragments: Vec<Fragment>,
    /// What its strips' sweeps did.
    pub stats: SegmentStats,
}

/// [`strip_by_strip_on`] without holding the frame's fragments: each band's are handed to
/// `sink` as soon as the bands above it have been, top to bottom, on the calling thread
/// (so the same bands, in the same order, at any thread count). The threads work on at
/// most `2 × threads` bands ahead of the last one handed on, so what is held besides the
/// triangles and their index (their planes, `y` ranges and order by top: 64 bytes each)
/// is bounded by the bands in flight, not by the frame.
pub fn strip_by_strip_into(
    tris: &[ScreenTriangle],
    channels: usize,
    rows: u32,
    threads: usize,
    mut sink: impl FnMut(Band),
) {
    let frame = StripFrame::new(tris, rows);
    let bands = frame.bands();
    let threads = match threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    }
    .min(bands.len())
    .max(1);
    let resolve = |index: usize| {
        let (top, end) = bands[index];
        let (fragments, stats) = frame.band(top, end, channels);
        Band {
            index,
            rows: (top, end),
            fragments,
            stats,
        }
    };
    if threads == 1 {
        (0..bands.len()).map(resolve).for_each(sink);
        return;
    }
    use std::sync::{mpsc, Condvar, Mutex};
    /// The next band to take, the next to hand on, and whether to stop (a thread
    /// panicked).
    struct Window {
        next: usize,
        handed: usize,
        stop: bool,
    }
    let ahead = 2 * threads;
    let window = Mutex::new(Window {
        next: 0,
        handed: 0,
        stop: false,
    });
    let moved = Condvar::new();
    let lock = || {
        window
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    };
    let panicked = std::thread::scope(|scope| {
        let (send, receive) = mpsc::channel();
        for _ in 0..threads {
            let send = send.clone();
            let (lock, moved, resolve, count) = (&lock, &moved, &resolve, bands.len());
            scope.spawn(move || loop {
                let index = {
                    let mut w = lock();
                    while !w.stop && w.next < count && w.next >= w.handed + ahead {
                        w = moved
                            .wait(w)
                            .unwrap_or_else(|poisoned| poisoned.into_inner());
                    }
                    if w.stop || w.next >= count {
                        break;
                    }
                    w.next += 1;
                    w.next - 1
                };
                let done =
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| resolve(index)));
                let failed = done.is_err();
                if send.send(done).is_err() || failed {
                    break;
                }
            });
        }
        drop(send);
        let mut waiting = std::collections::BTreeMap::new();
        for done in receive {
            match done {
                Ok(band) => {
                    waiting.insert(band.index, band);
                }
                Err(panic) => {
                    lock().stop = true;
                    moved.notify_all();
                    return Some(panic);
                }
            }
            let mut handed = lock().handed;
            while let Some(band) = waiting.remove(&handed) {
                sink(band);
                handed += 1;
            }
            lock().handed = handed;
            moved.notify_all();
        }
        None
    });
    if let Some(panic) = panicked {
        std::panic::resume_unwind(panic);
    }
}

/// A frame's triangles ready to be resolved strip by strip: their planes, and the
/// drawable ones sorted by their tops.
struct StripFrame<'a> {
    tris: &'a [ScreenTriangle],
    rows: f64,
    planes: Vec<Option<([f64; 3], f64)>>,
    /// Each triangle's `y` range.
    spans: Vec<(f64, f64)>,
    by_top: Vec<usize>,
}

impl<'a> StripFrame<'a> {
    fn new(tris: &'a [ScreenTriangle], rows: u32) -> StripFrame<'a> {
        let planes: Vec<Option<([f64; 3], f64)>> = tris.iter().map(plane).collect();
        let spans: Vec<(f64, f64)> = tris
            .iter()
            .map(|t| {
                let ys = t.points.map(|p| p[1]);
                (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]))
            })
            .collect();
        // sized once: the index is 64 bytes a triangle, not up to twice as many
        let mut by_top: Vec<usize> = Vec::with_capacity(tris.len());
        by_top.extend((0..tris.len()).filter(|&k| planes[k].is_some()));
        by_top.sort_unstable_by(|&a, &b| spans[a].0.total_cmp(&spans[b].0).then(a.cmp(&b)));
        StripFrame {
            tris,
            rows: f64::from(rows.max(1)),
            planes,
            spans,
            by_top,
        }
    }

    /// The bands' `y` ranges, top to bottom: strips between the row lines `y = k·rows`,
    /// [`STRIPS_PER_BAND`] to a band, from the first that a triangle meets to the last.
    fn bands(&self) -> Vec<(f64, f64)> {
        let Some(&first) = self.by_top.first() else {
            return Vec::new();
        };
        let bottom = self
            .by_top
            .iter()
            .map(|&k| self.spans[k].1)
            .fold(f64::NEG_INFINITY, f64::max);
        let height = self.rows * f64::from(STRIPS_PER_BAND);
        let mut y0 = (self.spans[first].0 / self.rows).floor() * self.rows;
        let mut out = Vec::new();
        while y0 < bottom {
            out.push((y0, y0 + height));
            y0 += height;
        }
        out
    }

    /// The fragments of the strips from `top` down to `end`, and what their sweeps did.
    fn band(&self, top: f64, end: f64, channels: usize) -> (Vec<Fragment>, SegmentStats) {
        let (tris, spans) = (self.tris, &self.spans);
        let mut stats = SegmentStats::default();
        let mut out: Vec<Fragment> = Vec::new();
        // the active list: what meets the band, by the order of their tops
        let last = self.by_top.partition_point(|&k| spans[k].0 < end);
        let mut waiting: Vec<usize> = self.by_top[..last]
            .iter()
            .copied()
            .filter(|&k| spans[k].1 > top)
            .collect();
        waiting.reverse();
        let mut active: Vec<usize> = Vec::new();
        let (mut pieces, mut source_of) = (Vec::new(), Vec::new());
        let (mut a, mut b) = (ArrayVec::new(), ArrayVec::new());
        let mut y0 = top;
        while y0 < end {
            let y1 = y0 + self.rows;
            while waiting.last().is_some_and(|&k| spans[k].0 < y1) {
                active.extend(waiting.pop());
            }
            active.retain(|&k| spans[k].1 > y0);
            // in source order: coplanar ties go to the lower index
            active.sort_unstable();
            pieces.clear();
            source_of.clear();
            for &k in &active {
                let Some((plane, scale)) = self.planes[k] else {
                    continue;
                };
                clip_at_row(&tris[k].points, y0, true, &mut a);
                clip_at_row(&a, y1, false, &mut b);
                if b.len() >= 3 && doubled_area(&b) != 0.0 {
                    pieces.push(Some(Prepared::polygon(&b, plane, scale)));
                    source_of.push(k);
                }
            }
            out.extend(
                visible_parts(&pieces, &mut stats)
                    .into_iter()
                    .map(|(piece, vertices)| {
                        let k = source_of[piece];
                        Fragment::of_triangle(k, &tris[k], vertices, channels)
                    }),
            );
            y0 = y1;
        }
        (out, stats)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::visibility::exact_fragments;
    use proptest::prelude::*;

    fn piece(points: [[f64; 2]; 3], inv_depth: [f64; 3]) -> ScreenTriangle {
        let mut intensity = [[0.0; cwisim_isa::MAX_CHANNELS]; 3];
        for (k, p) in points.iter().enumerate() {
            intensity[k][0] = p[0];
        }
        ScreenTriangle {
            points,
            inv_depth,
            intensity,
            mesh: 0,
            face: 0,
            surface: Default::default(),
        }
    }

    fn area(v: &[[f64; 2]]) -> f64 {
        let o = v[0];
        0.5 * (1..v.len() - 1)
            .map(|i| {
                let (a, b) = (v[i], v[i + 1]);
                (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
            })
            .sum::<f64>()
            .abs()
    }

    /// Each piece's visible area, by the scan segments and by the project's exact
    /// polygon booleans (which share no code with them).
    fn areas(tris: &[ScreenTriangle]) -> (Vec<f64>, Vec<f64>) {
        let mut stats = SegmentStats::default();
        let mut ours = vec![0.0; tris.len()];
        for f in strip_fragments(tris, 1, &mut stats) {
            ours[f.source] += area(&f.polygon.vertices);
        }
        let mut exact = vec![0.0; tris.len()];
        for f in exact_fragments(tris, 1).0 {
            exact[f.source] += area(&f.polygon.vertices);
        }
        (ours, exact)
    }

    /// `1/depth` of `t` at `p` (interpolated; outside `t` too).
    fn inv_depth_at(t: &ScreenTriangle, p: [f64; 2]) -> f64 {
        let w = t.barycentric(p).expect("a piece with area");
        w[0] * t.inv_depth[0] + w[1] * t.inv_depth[1] + w[2] * t.inv_depth[2]
    }

    /// The nearest piece at `p` (the largest `1/depth` among those holding it): a ray
    /// cast.
    fn nearest(tris: &[ScreenTriangle], p: [f64; 2]) -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for (k, t) in tris.iter().enumerate() {
            let Some(w) = t.barycentric(p) else { continue };
            if w.iter().all(|&x| x > 1e-9) {
                let z = inv_depth_at(t, p);
                if best.is_none_or(|(_, b)| z > b) {
                    best = Some((k, z));
                }
            }
        }
        best.map(|b| b.0)
    }

    /// Whether `p` is in exactly one fragment when a piece holds it (none otherwise), the
    /// nearest piece's (or one as near, within rounding), by a ray cast.
    fn shows_the_nearest(
        tris: &[ScreenTriangle],
        fragments: &[Fragment],
        p: [f64; 2],
    ) -> Result<(), TestCaseError> {
        let shown: Vec<usize> = fragments
            .iter()
            .filter(|f| inside(&f.polygon.vertices, p))
            .map(|f| f.source)
            .collect();
        let want = nearest(tris, p);
        prop_assert_eq!(
            shown.len(),
            usize::from(want.is_some()),
            "{:?}: {:?} shown, {:?} nearest",
            p,
            shown,
            want
        );
        if let (Some(&s), Some(w)) = (shown.first(), want) {
            let (zs, zw) = (inv_depth_at(&tris[s], p), inv_depth_at(&tris[w], p));
            prop_assert!(
                s == w || (zs - zw).abs() < 1e-9,
                "{:?}: {} shown, {} nearest",
                p,
                s,
                w
            );
        }
        Ok(())
    }

    /// Whether `p` is inside the simple polygon `v` (its winding number is not 0).
    fn inside(v: &[[f64; 2]], p: [f64; 2]) -> bool {
        let mut winding = 0;
        for i in 0..v.len() {
            let (a, b) = (v[i], v[(i + 1) % v.len()]);
            let c = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
            if a[1] <= p[1] {
                if b[1] > p[1] && c > 0.0 {
                    winding += 1;
                }
            } else if b[1] <= p[1] && c < 0.0 {
                winding -= 1;
            }
        }
        winding != 0
    }

    /// Random pieces of a strip `0..1` high: corners on its lines or inside, planes that
    /// may cross.
    fn strip() -> impl Strategy<Value = Vec<ScreenTriangle>> {
        let corner = (0.0..20.0f64, prop_oneof![Just(0.0), Just(1.0), 0.0..1.0f64]);
        let one = (
            [corner.clone(), corner.clone(), corner],
            [0.2..1.0f64, 0.2..1.0f64, 0.2..1.0f64],
        )
            .prop_map(|(c, z)| piece(c.map(|(x, y)| [x, y]), z));
        prop::collection::vec(one, 1..12)
    }

    /// Pieces with corners on a coarse grid and a few depths: shared corners and edges,
    /// collinear edges, coplanar and coincident pieces.
    fn grid_strip() -> impl Strategy<Value = Vec<ScreenTriangle>> {
        let corner =
            (0..=16u32, 0..=4u32).prop_map(|(x, y)| [f64::from(x) / 4.0, f64::from(y) / 4.0]);
        let depth = prop_oneof![Just(0.25), Just(0.5), Just(0.75)];
        let one = (
            [corner.clone(), corner.clone(), corner],
            [depth.clone(), depth.clone(), depth],
        )
            .prop_map(|(c, z)| piece(c, z));
        prop::collection::vec(one, 1..16)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        #[test]
        fn the_integer_key_orders_as_total_cmp(a in any::<f64>(), b in any::<f64>(), pick in 0..12usize) {
            // specials half the time: zeros of both signs, infinities, NaN
            let special = [0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -f64::NAN];
            let b = special.get(pick).copied().unwrap_or(b);
            prop_assert_eq!(ordered(a).cmp(&ordered(b)), a.total_cmp(&b));
        }

        #[test]
        fn degenerate_strips_show_the_nearest_piece_everywhere(tris in grid_strip()) {
            // a ray cast is the reference (on such strips the polygon booleans covered a
            // point twice, where a pinched outline got a hole cut: fixed since, and tested
            // in crate::visibility)
            let mut stats = SegmentStats::default();
            let fragments = strip_fragments(&tris, 1, &mut stats);
            let points = (0..96).flat_map(|i| {
                (0..12).map(move |j| [f64::from(i) / 24.0 + 0.00123, f64::from(j) / 12.0 + 0.00071])
            });
            for p in points {
                shows_the_nearest(&tris, &fragments, p)?;
            }
        }

        #[test]
        fn every_piece_keeps_the_area_exact_visibility_gives_it(tris in strip()) {
            let (ours, exact) = areas(&tris);
            for (k, (a, b)) in ours.iter().zip(&exact).enumerate() {
                prop_assert!((a - b).abs() <= 1e-9, "piece {k}: {a} against {b}");
            }
        }

        #[test]
        fn each_fragment_shows_the_nearest_piece(tris in strip(), xs in prop::collection::vec((0.0..20.0f64, 0.0..1.0f64), 64)) {
            let mut stats = SegmentStats::default();
            let fragments = strip_fragments(&tris, 1, &mut stats);
            for (x, y) in xs {
                shows_the_nearest(&tris, &fragments, [x, y])?;
            }
        }
    }

    /// Random triangles over a few rows: corners anywhere, on row lines or on a coarse
    /// grid (shared corners and edges, coplanar and coincident triangles), planes that may
    /// cross.
    fn frame() -> impl Strategy<Value = Vec<ScreenTriangle>> {
        let corner = prop_oneof![
            (0.0..12.0f64, 0.0..6.0f64).prop_map(|(x, y)| [x, y]),
            (0.0..12.0f64, 0..=6u32).prop_map(|(x, y)| [x, f64::from(y)]),
            (0..=8u32, 0..=12u32).prop_map(|(x, y)| [f64::from(x) * 1.5, f64::from(y) / 2.0]),
            // within a few 1e-9 px of a grid corner: slivers, edges nearly coincident
            (0..=8u32, 0..=12u32, -3..=3i32, -3..=3i32).prop_map(|(x, y, dx, dy)| [
                f64::from(x) * 1.5 + f64::from(dx) * 1e-9,
                f64::from(y) / 2.0 + f64::from(dy) * 1e-9
            ]),
        ];
        let depth = prop_oneof![0.2..1.0f64, Just(0.5)];
        let one = (
            [corner.clone(), corner.clone(), corner],
            [depth.clone(), depth.clone(), depth],
        )
            .prop_map(|(c, z)| piece(c, z));
        prop::collection::vec(one, 1..14)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        #[test]
        fn strip_by_strip_keeps_each_triangle_s_exact_visible_area(tris in frame(), rows in 1..4u32) {
            let (fragments, _) = strip_by_strip(&tris, 1, rows);
            let mut ours = vec![0.0; tris.len()];
            for f in &fragments {
                ours[f.source] += area(&f.polygon.vertices);
            }
            let mut exact = vec![0.0; tris.len()];
            for f in exact_fragments(&tris, 1).0 {
                exact[f.source] += area(&f.polygon.vertices);
            }
            for (k, (a, b)) in ours.iter().zip(&exact).enumerate() {
                prop_assert!((a - b).abs() <= 1e-9, "triangle {k}: {a} against {b}");
            }
        }

        #[test]
        fn strip_by_strip_shows_the_nearest_triangle(tris in frame(), rows in 1..4u32, xs in prop::collection::vec((0.0..12.0f64, 0.0..6.0f64), 64)) {
            let (fragments, _) = strip_by_strip(&tris, 1, rows);
            for f in &fragments {
                let v = &f.polygon.vertices;
                let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p[1]), h.max(p[1])));
                let strip = (lo + 1e-9).div_euclid(f64::from(rows)) * f64::from(rows);
                prop_assert!(lo >= strip - 1e-9 && hi <= strip + f64::from(rows) + 1e-9, "a fragment over more than a strip: {:?}", v);
                let w = &f.polygon.intensity;
                for (p, i) in v.iter().zip(w) {
                    let want = tris[f.source].intensity_at(*p, 1).unwrap()[0];
                    prop_assert_eq!(i[0], want);
                }
            }
            for (x, y) in xs {
                shows_the_nearest(&tris, &fragments, [x, y])?;
            }
        }
    }

    #[test]
    fn strip_by_strip_gives_the_same_at_any_thread_count() {
        // 300 triangles over 100 rows: seven bands of sixteen strips
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let tris: Vec<ScreenTriangle> = (0..300)
            .map(|_| {
                let (x, y) = (next() * 90.0, next() * 90.0);
                let corner = |n: &mut dyn FnMut() -> f64| [x + n() * 12.0, y + n() * 12.0];
                piece(
                    [corner(&mut next), corner(&mut next), corner(&mut next)],
                    [0.2 + next(), 0.2 + next(), 0.2 + next()],
                )
            })
            .collect();
        let one = strip_by_strip_on(&tris, 1, 1, 1);
        assert!(one.1.pieces > 1000, "{:?}", one.1);
        for threads in [2, 3, 0] {
            assert!(
                strip_by_strip_on(&tris, 1, 1, threads) == one,
                "{threads} threads"
            );
        }
        // and the same visible areas as the pair-by-pair engine
        let mut ours = vec![0.0; tris.len()];
        for f in &one.0 {
            ours[f.source] += area(&f.polygon.vertices);
        }
        let mut exact = vec![0.0; tris.len()];
        for f in exact_fragments(&tris, 1).0 {
            exact[f.source] += area(&f.polygon.vertices);
        }
        for (k, (a, b)) in ours.iter().zip(&exact).enumerate() {
            assert!((a - b).abs() <= 1e-9, "triangle {k}: {a} against {b}");
        }
    }

    #[test]
    fn strips_cut_a_triangle_along_its_row_lines_and_an_empty_frame_has_none() {
        let tris = [piece([[0.0, 0.5], [8.0, 0.5], [0.0, 3.5]], [0.5; 3])];
        let (f, stats) = strip_by_strip(&tris, 1, 1);
        // rows 0..4: its part in each of the four strips it meets, one fragment each,
        // within its strip
        assert_eq!(f.len(), 4, "{f:?}");
        for f in &f {
            let ys: Vec<f64> = f.polygon.vertices.iter().map(|p| p[1]).collect();
            let top = ys.iter().copied().fold(f64::INFINITY, f64::min).floor();
            assert!(ys.iter().all(|&y| y >= top && y <= top + 1.0), "{ys:?}");
        }
        assert_eq!(stats.hidden, 0);
        let total: f64 = f.iter().map(|f| area(&f.polygon.vertices)).sum();
        assert!((total - 12.0).abs() < 1e-12, "{total}");
        assert_eq!(strip_by_strip(&[], 1, 1).0, Vec::new());
        let flat = [piece([[0.0, 1.0], [4.0, 1.0], [8.0, 1.0]], [0.5; 3])];
        assert_eq!(strip_by_strip(&flat, 1, 1).0, Vec::new());
    }

    #[test]
    fn coplanar_pieces_under_a_nearer_one_go_to_the_lower_index_where_it_crosses_them() {
        // pieces 3 and 4 share a plane; piece 1 hides both above its edge from (0, 0),
        // which crosses piece 3's right edge inside a slab where piece 3 is hidden at the
        // middle: the lower index kept only the cells found there (0.4722 of piece 3's
        // 0.4760 px², a ray cast: 0.4758), until a piece as near that comes first made
        // the slab be cut where its lines cross (found by strip_by_strip's proptest)
        let tris = [
            piece(
                [
                    [9.847047136733295, 2.0],
                    [0.0, 0.0],
                    [10.227541222493178, 0.7182856970284833],
                ],
                [0.2, 0.6391324882973366, 0.7204278904224009],
            ),
            piece(
                [
                    [0.0, 0.0],
                    [8.356582228752874, 2.0],
                    [11.554039290771296, 2.0],
                ],
                [0.8790750202490659, 0.8498475433966949, 0.699564487704662],
            ),
            piece(
                [[0.0, 0.0], [11.554039290771296, 2.0], [12.0, 1.5]],
                [0.8790750202490659, 0.699564487704662, 0.5877193217749725],
            ),
            piece(
                [[4.3126188161619865, 2.0], [7.5, 0.0], [5.1, 2.0]],
                [0.5; 3],
            ),
            piece([[7.5, 0.0], [5.5, 2.0], [2.603738225999041, 2.0]], [0.5; 3]),
        ];
        let (ours, exact) = areas(&tris);
        for (k, (a, b)) in ours.iter().zip(&exact).enumerate() {
            assert!((a - b).abs() <= 1e-12, "piece {k}: {a} against {b}");
        }
        assert!((ours[3] - 0.476).abs() < 1e-4, "{}", ours[3]);
    }

    /// Found by `strip_by_strip_keeps_each_triangle_s_exact_visible_area` once its frames
    /// had corners within a few 1e-9 px of a grid's: the sliver's corners cut slabs
    /// 1.6e-9 px wide, narrower than the slabs that were checked then, and triangle 0
    /// showed 17.27960954185393 px² there. Its exact visible area, computed in rationals
    /// (its triangle minus the union of the parts the others hide, by inclusion and
    /// exclusion of convex polygons clipped in `fractions.Fraction`), is
    /// 17.279609540837345 px² to the nearest double — what pair by pair gives.
    #[test]
    fn a_sliver_s_narrow_slabs_are_checked() {
        let tris = [
            piece(
                [[1.5, 1.0], [7.5, 5.5], [9.067309345837623, 0.0]],
                [0.5, 0.7053878204723274, 0.31160291056783623],
            ),
            piece(
                [
                    [0.0, 0.0],
                    [7.104811193993021, 1.5653706678210757],
                    [4.14955194220098, 0.0],
                ],
                [0.6196760231409276, 0.2, 0.7022751536259457],
            ),
            piece(
                [
                    [10.157580488494439, 0.5304101464092469],
                    [10.59303737315648, 5.165618238088459],
                    [0.0, 3.0],
                ],
                [0.5, 0.2, 0.5560897149273849],
            ),
            piece(
                [[0.0, 3.0], [6.0, 0.0], [5.999999998, 3.0000000000000004e-9]],
                [0.2; 3],
            ),
        ];
        let exact = [
            17.279609540837345,
            2.416722306158733,
            15.23574738296055,
            2.794450451985996e-9,
        ];
        for rows in 1..=3 {
            let (fragments, _) = strip_by_strip(&tris, 1, rows);
            let mut ours = [0.0; 4];
            for f in &fragments {
                ours[f.source] += area(&f.polygon.vertices);
            }
            for k in 0..4 {
                assert!(
                    (ours[k] - exact[k]).abs() <= 1e-12,
                    "rows {rows}, triangle {k}: {} against {}",
                    ours[k],
                    exact[k]
                );
            }
        }
    }

    #[test]
    fn a_piece_hidden_by_two_is_hidden_and_the_front_two_are_whole() {
        // two front pieces sharing an edge, over a larger back piece
        let tris = [
            piece([[0.0, 0.0], [10.0, 0.0], [0.0, 1.0]], [0.5; 3]),
            piece([[10.0, 0.0], [10.0, 1.0], [0.0, 1.0]], [0.5; 3]),
            piece([[2.0, 0.0], [8.0, 0.0], [5.0, 1.0]], [0.25; 3]),
        ];
        let (ours, exact) = areas(&tris);
        assert_eq!(ours[2], 0.0);
        assert!((ours[0] - 5.0).abs() < 1e-12 && (ours[1] - 5.0).abs() < 1e-12);
        assert!((ours[0] - exact[0]).abs() < 1e-12);
        let mut stats = SegmentStats::default();
        let f = strip_fragments(&tris, 1, &mut stats);
        assert_eq!(stats.hidden, 1);
        assert_eq!(f.len(), 2, "each front piece whole, in one fragment");
    }
}
