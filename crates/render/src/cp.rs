//! Critical-points (CP) scan conversion — Barkan & Gordon, *The scanline principle*,
//! section 3 and Appendix A (`DETCR`, `MOVEUP`, `POLINE`), on cwisim's pixel-centre
//! convention. Usable alone: a polygon ([`CpPolygon`]) and its sweep state ([`CpState`])
//! give, scanline after scanline, the pairs of active edges between which pixels are set.
//!
//! * [`detcr`] — the critical points: the vertices that are local minima of `y` (the last
//!   vertex of a horizontal run, in index order), sorted by `y`.
//! * [`CpState::poline`] — the active edge table (AET) made to meet a scanline: every
//!   element follows its monotonic section upwards (`MOVEUP`, along horizontal edges
//!   too) or is deleted where the section turns down; the sections starting at new
//!   critical points are inserted in `x` order (ties by inverse slope).
//! * [`CpState::pairs`] — FILL's pairs: the pixels whose centre `x` satisfies
//!   `K1.XC ≤ x < K2.XC`.
//!
//! **Pixel centres.** The paper samples at integer scanlines `y = H`, pixels `I` with
//! `K1.XC ≤ I < K2.XC`. cwisim samples at pixel centres: row `r` is the line
//! `y = r + ½` and pixel `i` is set when its centre `i + ½` lies in `[K1.XC, K2.XC)`;
//! the sweep lines are any increasing sequence of `y` (sub-scanlines of a supersampled
//! row too). With the half-open rules (`Y[K.IND] ≤ H < Y[K.IND + K.DIR]` and
//! `XC ≤ x < XC'`) these are exactly the samples `cwisim_ypipe::dofill::sampled_span`
//! sets: every sample belongs to at most one of two polygons that share an edge.
//!
//! **The intersection update.** `MOVEUP` as printed keeps `XX += SL` along one edge
//! ([`Increment::Paper`], with `SL · ΔH` for a step `ΔH ≠ 1`, the paper's "hatching"
//! extension). The sum drifts from the edge in floating point and moves a crossing that
//! falls on a sample across it (`docs/ERRATA.md`, "Barkan & Gordon"). The default,
//! [`Increment::Direct`], recomputes `XX = X[J] + SL·(H − Y[J])` at every scanline: the
//! same value a plain edge list computes, so the spans equal a plain scan conversion
//! exactly.

use std::fmt;
use std::str::FromStr;

/// How `MOVEUP` updates an edge's intersection from one scanline to the next.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Increment {
    /// `XX = X[J] + SL · (H − Y[J])` at every scanline (the default): exact as a plain
    /// edge list.
    #[default]
    Direct,
    /// The paper's `XX = XX + SL` (times the step when the lines are not one apart),
    /// recomputed only when the section moves to a new edge.
    Paper,
}

impl Increment {
    /// Every value, in order.
    pub const ALL: [Increment; 2] = [Increment::Direct, Increment::Paper];

    /// Its one spelling.
    pub fn name(self) -> &'static str {
        match self {
            Increment::Direct => "direct",
            Increment::Paper => "paper",
        }
    }
}

impl fmt::Display for Increment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Increment {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Increment::ALL
            .into_iter()
            .find(|g| g.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown CP increment `{s}`; expected direct or paper"))
    }
}

/// `DETCR`: the critical points of the polygon with vertex ordinates `y` (cyclic), as
/// vertex indices sorted by increasing `y` (equal `y` by index).
///
/// Transcribed from Appendix A: `CAND` is set where `y` properly decreases, kept along
/// equal `y`, and where `y` then properly increases the vertex is critical; a candidate
/// still open after the loop is closed by a second pass from vertex 0. A polygon with no
/// proper decrease (all vertices on one horizontal line) has none: it is degenerate.
pub fn detcr(y: &[f64]) -> Vec<usize> {
    let n = y.len();
    let mut cr = Vec::new();
    if n < 2 {
        return cr;
    }
    let next = |i: usize| if i + 1 == n { 0 } else { i + 1 };
    let mut cand = false;
    for i in 0..n {
        let (a, b) = (y[i], y[next(i)]);
        if a > b {
            cand = true;
        } else if a < b && cand {
            cr.push(i);
            cand = false;
        }
    }
    if cand {
        for i in 0..n - 1 {
            if y[i] > y[i + 1] {
                break;
            } else if y[i] < y[i + 1] {
                cr.push(i);
                break;
            }
        }
    }
    cr.sort_by(|&a, &b| y[a].total_cmp(&y[b]).then(a.cmp(&b)));
    cr
}

/// A polygon ready for CP: its vertices (cyclic, either orientation) and critical points.
#[derive(Clone, Debug, PartialEq)]
pub struct CpPolygon {
    x: Vec<f64>,
    y: Vec<f64>,
    cr: Vec<usize>,
}

impl CpPolygon {
    /// The polygon with these vertices; its critical points by [`detcr`].
    pub fn new(vertices: &[[f64; 2]]) -> CpPolygon {
        let x: Vec<f64> = vertices.iter().map(|v| v[0]).collect();
        let y: Vec<f64> = vertices.iter().map(|v| v[1]).collect();
        let cr = detcr(&y);
        CpPolygon { x, y, cr }
    }

    /// Vertex count, `n`.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether it has no vertex.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The critical points (vertex indices), sorted by `y`.
    pub fn critical_points(&self) -> &[usize] {
        &self.cr
    }

    /// Vertex `i` (modulo `n`).
    pub fn vertex(&self, i: usize) -> [f64; 2] {
        let i = i % self.len();
        [self.x[i], self.y[i]]
    }

    /// The lowest critical point's `y`: where the polygon starts (`None`: degenerate,
    /// `c = 0`).
    pub fn start_y(&self) -> Option<f64> {
        self.cr.first().map(|&i| self.y[i])
    }

    /// The largest vertex `y`.
    pub fn end_y(&self) -> f64 {
        self.y.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    fn step(&self, j: usize, dir: Dir) -> usize {
        let n = self.len();
        match dir {
            Dir::Up => {
                if j + 1 == n {
                    0
                } else {
                    j + 1
                }
            }
            Dir::Down => {
                if j == 0 {
                    n - 1
                } else {
                    j - 1
                }
            }
        }
    }

    /// The inverse slope of the edge from `j` to its neighbour in `dir`.
    fn slope(&self, j: usize, dir: Dir) -> f64 {
        let k = self.step(j, dir);
        (self.x[k] - self.x[j]) / (self.y[k] - self.y[j])
    }
}

/// Direction of advance along the vertex arrays (`K.DIR`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dir {
    /// `+1`.
    Up,
    /// `−1`.
    Down,
}

/// An element of the AET: a monotonic section met by the current scanline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// `K.IND`: the highest vertex of the section with `y ≤ H`.
    pub ind: usize,
    /// `K.DIR`: the direction leading up the section.
    pub dir: Dir,
    /// `K.XC`: where the current edge meets the scanline.
    pub xc: f64,
    /// `K.SLP`: the current edge's inverse slope (0 before the first `MOVEUP`).
    pub slp: f64,
}

impl Element {
    /// The current edge: its lower and upper vertex indices in `p`.
    pub fn edge(&self, p: &CpPolygon) -> (usize, usize) {
        (self.ind, p.step(self.ind, self.dir))
    }
}

/// What CP did, summed over polygons and scanlines.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CpStats {
    /// Vertex steps `MOVEUP` took (along edges and horizontal edges alike).
    pub moveup_steps: u64,
    /// Calls of `MOVEUP`.
    pub moveups: u64,
    /// Elements inserted into AETs.
    pub inserts: u64,
    /// AET elements `INSERT` passes over to find its place, as the paper's linked list
    /// is searched from its head: what makes CP's time `O(c²)`.
    pub insert_scans: u64,
    /// Elements deleted from AETs (sections that turned down, or sections abandoned
    /// before their first scanline).
    pub deletes: u64,
    /// Intersections computed in full (new edge, or every time with the direct update).
    pub recomputes: u64,
    /// Intersections updated by `XX += SL` (the paper's increment).
    pub increments: u64,
    /// The largest AET of one polygon.
    pub max_aet: u64,
}

impl CpStats {
    /// Adds another's counts (the maximum of the maxima).
    pub fn add(&mut self, o: &CpStats) {
        self.moveup_steps += o.moveup_steps;
        self.moveups += o.moveups;
        self.inserts += o.inserts;
        self.insert_scans += o.insert_scans;
        self.deletes += o.deletes;
        self.recomputes += o.recomputes;
        self.increments += o.increments;
        self.max_aet = self.max_aet.max(o.max_aet);
    }
}

/// One polygon's sweep: its AET, the next critical point (`ic`), and the last scanline.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CpState {
    aet: Vec<Element>,
    ic: usize,
    last_h: Option<f64>,
}

impl CpState {
    /// A sweep not started.
    pub fn new() -> CpState {
        CpState::default()
    }

    /// The AET, in `x` order.
    pub fn aet(&self) -> &[Element] {
        &self.aet
    }

    /// Whether the sweep is over: every critical point inserted and the AET empty
    /// (after at least one scanline).
    pub fn finished(&self, p: &CpPolygon) -> bool {
        self.last_h.is_some() && self.aet.is_empty() && self.ic >= p.cr.len()
    }

    /// `MOVEUP(J, DI, XX, SL)` to the line `h`: `false` when the section turns down
    /// before reaching it (the paper's `J = −1`).
    fn moveup(
        p: &CpPolygon,
        k: &mut Element,
        h: f64,
        dh: f64,
        inc: Increment,
        stats: &mut CpStats,
    ) -> bool {
        stats.moveups += 1;
        let jold = k.ind;
        let mut j = k.ind;
        let mut j1 = p.step(j, k.dir);
        while p.y[j1] <= h {
            if p.y[j1] < p.y[j] {
                return false;
            }
            j = j1;
            j1 = p.step(j, k.dir);
            stats.moveup_steps += 1;
        }
        k.ind = j;
        if inc == Increment::Direct || k.slp == 0.0 || j != jold {
            k.slp = p.slope(j, k.dir);
            k.xc = p.x[j] + k.slp * (h - p.y[j]);
            stats.recomputes += 1;
        } else {
            k.xc += k.slp * dh;
            stats.increments += 1;
        }
        true
    }

    /// `POLINE`'s update: the AET made to meet the line `h` (greater than the last
    /// line). Existing elements move up or are deleted; the sections of every critical
    /// point with `y ≤ h` not yet inserted are followed up and inserted in `x` order.
    pub fn poline(&mut self, p: &CpPolygon, h: f64, inc: Increment, stats: &mut CpStats) {
        let dh = self.last_h.map_or(0.0, |l| h - l);
        self.last_h = Some(h);
        let before = self.aet.len();
        self.aet
            .retain_mut(|k| CpState::moveup(p, k, h, dh, inc, stats));
        stats.deletes += (before - self.aet.len()) as u64;
        while self.ic < p.cr.len() && p.y[p.cr[self.ic]] <= h {
            for dir in [Dir::Down, Dir::Up] {
                let mut k = Element {
                    ind: p.cr[self.ic],
                    dir,
                    xc: 0.0,
                    slp: 0.0,
                };
                if CpState::moveup(p, &mut k, h, dh, inc, stats) {
                    // INSERT: sorted by XC, equal XC by SL
                    let at = self.aet.partition_point(|e| (e.xc, e.slp) <= (k.xc, k.slp));
                    self.aet.insert(at, k);
                    stats.inserts += 1;
                    stats.insert_scans += at as u64;
                }
            }
            self.ic += 1;
        }
        stats.max_aet = stats.max_aet.max(self.aet.len() as u64);
    }

    /// FILL's pairs of the current AET: `(left, right)` elements, alternately.
    pub fn pairs(&self) -> impl Iterator<Item = (&Element, &Element)> {
        self.aet.chunks_exact(2).map(|c| (&c[0], &c[1]))
    }
}

/// The sample columns `[first, end)` whose positions `pos(k)` lie in `[xl, xr)`, among
/// `0..count`, for positions `pos(k) = (k + offset) · step` increasing in `k`: found by
/// arithmetic, then checked with `pos` itself so that the rule is exactly `xl ≤ pos < xr`.
pub fn columns_in(
    xl: f64,
    xr: f64,
    count: usize,
    pos: impl Fn(usize) -> f64,
    guess: impl Fn(f64) -> f64,
) -> (usize, usize) {
    if xl.partial_cmp(&xr) != Some(std::cmp::Ordering::Less) || count == 0 {
        return (0, 0);
    }
    let clampi = |v: f64| -> usize {
        if v.is_nan() || v <= 0.0 {
            0
        } else if v >= count as f64 {
            count
        } else {
            v as usize
        }
    };
    let mut first = clampi(guess(xl));
    while first > 0 && pos(first - 1) >= xl {
        first -= 1;
    }
    while first < count && pos(first) < xl {
        first += 1;
    }
    let mut end = clampi(guess(xr)).max(first);
    while end > first && pos(end - 1) >= xr {
        end -= 1;
    }
    while end < count && pos(end) < xr {
        end += 1;
    }
    (first, end)
}

/// The pixels `[first, end)` of a row of `width` whose centres lie in `[xl, xr)`.
pub fn pixel_span(xl: f64, xr: f64, width: u32) -> (u32, u32) {
    let (a, b) = columns_in(
        xl,
        xr,
        width as usize,
        |k| k as f64 + 0.5,
        |x| (x - 0.5).ceil(),
    );
    (a as u32, b as u32)
}

/// The pixel spans of `p` on every row of an image `height` rows high and `width`
/// wide, by CP: `rows[r]` lists `(first, end)` spans in `x` order. With what CP counted.
pub fn scan_rows(
    p: &CpPolygon,
    width: u32,
    height: u32,
    inc: Increment,
) -> (Vec<Vec<(u32, u32)>>, CpStats) {
    let mut rows = vec![Vec::new(); height as usize];
    let mut stats = CpStats::default();
    let Some(y0) = p.start_y() else {
        return (rows, stats);
    };
    let first = (y0 - 0.5).ceil().max(0.0);
    if first >= f64::from(height) {
        return (rows, stats);
    }
    let mut state = CpState::new();
    for r in first as u32..height {
        state.poline(p, f64::from(r) + 0.5, inc, &mut stats);
        for (a, b) in state.pairs() {
            let (s, e) = pixel_span(a.xc, b.xc, width);
            if e > s {
                rows[r as usize].push((s, e));
            }
        }
        if state.finished(p) {
            break;
        }
    }
    (rows, stats)
}

/// The plain edge-list scan conversion the tests hold CP to: at each row centre every
/// edge with `Y[lo] ≤ y < Y[hi]` crosses at `X[lo] + (X[hi] − X[lo])/(Y[hi] − Y[lo]) ·
/// (y − Y[lo])`; the crossings, sorted, pair up. Also what the baseline counts: every
/// edge inserted and deleted once.
pub fn edge_list_rows(vertices: &[[f64; 2]], width: u32, height: u32) -> Vec<Vec<(u32, u32)>> {
    let n = vertices.len();
    let mut rows = vec![Vec::new(); height as usize];
    let mut xs = Vec::new();
    for (r, row) in rows.iter_mut().enumerate() {
        let h = r as f64 + 0.5;
        xs.clear();
        for i in 0..n {
            let (a, b) = (vertices[i], vertices[(i + 1) % n]);
            let (lo, hi) = if a[1] < b[1] { (a, b) } else { (b, a) };
            if lo[1] <= h && h < hi[1] {
                let sl = (hi[0] - lo[0]) / (hi[1] - lo[1]);
                xs.push(lo[0] + sl * (h - lo[1]));
            }
        }
        xs.sort_by(f64::total_cmp);
        for c in xs.chunks_exact(2) {
            let (s, e) = pixel_span(c[0], c[1], width);
            if e > s {
                row.push((s, e));
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn increments_parse_and_print() {
        for i in Increment::ALL {
            assert_eq!(i.to_string().parse::<Increment>(), Ok(i));
        }
        assert!("drift".parse::<Increment>().unwrap_err().contains("direct"));
    }

    #[test]
    fn pixel_spans_are_half_open_at_centres() {
        assert_eq!(pixel_span(0.5, 2.5, 10), (0, 2));
        assert_eq!(pixel_span(0.4, 2.6, 10), (0, 3));
        assert_eq!(pixel_span(0.6, 2.5, 10), (1, 2));
        assert_eq!(pixel_span(-5.0, 50.0, 10), (0, 10));
        assert_eq!(pixel_span(3.0, 3.0, 10), (0, 0));
        assert_eq!(pixel_span(f64::NAN, 3.0, 10), (0, 0));
    }
}
