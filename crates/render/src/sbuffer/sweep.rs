//! The scanline principle's outer loop (section 4.1, Appendix A's S-buffer): a polygon
//! table (PT) of the polygons by the first line they meet, an active polygon table (APT)
//! in a given priority order, and one CP state per polygon, advanced line by line with
//! `POLINE`. Lines are any increasing sequence (pixel rows, or sub-scanlines).

use super::polys::Poly;
use crate::cp::{CpState, CpStats, Element, Increment};
use cwisim_scene::Vector;

/// What one line of the sweep did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LineCounts {
    /// Polygons on the APT during the line.
    pub active: u64,
    /// AET elements of all active polygons after `POLINE`.
    pub aet: u64,
}

/// The sweep over a scene's polygons.
pub struct Sweep<'a> {
    polys: &'a [Poly],
    /// `starts[j]`: the polygons whose first line is `j` (the PT).
    starts: Vec<Vec<u32>>,
    states: Vec<CpState>,
    /// The APT: polygon indices in ascending `rank`.
    active: Vec<u32>,
    rank: Vec<u32>,
    increment: Increment,
    /// What CP did.
    pub stats: CpStats,
    /// The largest APT.
    pub max_active: u64,
    /// The largest total AET on one line.
    pub max_aet: u64,
}

impl<'a> Sweep<'a> {
    /// The sweep of `polys` over `lines` lines at `y(j)` (increasing), the APT ordered by
    /// `rank` (smaller first; `None`: by index). `first_line(y)` is the first line `j`
    /// with `y(j) ≥ y` (or `lines` when none).
    pub fn new(
        polys: &'a [Poly],
        lines: usize,
        y: impl Fn(usize) -> f64,
        first_line: impl Fn(f64) -> usize,
        rank: Option<Vec<u32>>,
        increment: Increment,
    ) -> Sweep<'a> {
        let mut starts = vec![Vec::new(); lines];
        for (k, p) in polys.iter().enumerate() {
            let Some(y0) = p.cp.start_y() else { continue };
            let j = first_line(y0);
            // past the last line, or ending before its first: never met
            if j >= lines || p.cp.end_y() <= y(j) {
                continue;
            }
            starts[j].push(k as u32);
        }
        Sweep {
            polys,
            starts,
            states: vec![CpState::new(); polys.len()],
            active: Vec::new(),
            rank: rank.unwrap_or_else(|| (0..polys.len() as u32).collect()),
            increment,
            stats: CpStats::default(),
            max_active: 0,
            max_aet: 0,
        }
    }

    /// Line `j` at `y`: the polygons starting there join the APT, and the APT is walked
    /// in order — each polygon's AET made to meet the line (`POLINE`) and
    /// `visit(k, polygon, aet)` called. `visit` returns `false` to stop the walk (the
    /// front-to-back display once every pixel is set): the polygons not walked are not
    /// advanced — CP catches up over several lines at their next `POLINE`, so the work
    /// follows what is visible. Polygons whose sweep is over (or which end above the next
    /// line) leave the APT.
    pub fn line(
        &mut self,
        j: usize,
        y: f64,
        mut visit: impl FnMut(u32, &Poly, &[Element]) -> bool,
    ) -> LineCounts {
        for &k in &self.starts[j] {
            let r = self.rank[k as usize];
            let at = self.active.partition_point(|&a| self.rank[a as usize] < r);
            self.active.insert(at, k);
        }
        let mut counts = LineCounts {
            active: self.active.len() as u64,
            aet: 0,
        };
        for &k in &self.active {
            let (p, s) = (&self.polys[k as usize], &mut self.states[k as usize]);
            s.poline(&p.cp, y, self.increment, &mut self.stats);
            counts.aet += s.aet().len() as u64;
            if !visit(k, p, s.aet()) {
                break;
            }
        }
        let (polys, states) = (self.polys, &self.states);
        self.active.retain(|&k| {
            let p = &polys[k as usize];
            !states[k as usize].finished(&p.cp) && p.cp.end_y() > y
        });
        self.max_active = self.max_active.max(counts.active);
        self.max_aet = self.max_aet.max(counts.aet);
        counts
    }
}

/// The intensity where element `e` of polygon `p`'s AET meets the line `y`: interpolated
/// along its current edge.
pub fn edge_value(p: &Poly, e: &Element, y: f64, channels: usize) -> Vector {
    let (lo, hi) = e.edge(&p.cp);
    let (a, b) = (p.cp.vertex(lo), p.cp.vertex(hi));
    let t = if b[1] != a[1] {
        ((y - a[1]) / (b[1] - a[1])).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (ia, ib) = (&p.intensity[lo], &p.intensity[hi]);
    cwisim_scene::vector(channels, |c| ia[c] + t * (ib[c] - ia[c]))
}

/// A span's Gouraud values: the intensity at `xl` and the gradient across to `xr`
/// (non-finite gradients, from a span narrower than rounding, taken as 0).
pub fn span_gradient(il: &Vector, ir: &Vector, xl: f64, xr: f64, channels: usize) -> Vector {
    let w = xr - xl;
    cwisim_scene::vector(channels, |c| {
        let d = (ir[c] - il[c]) / w;
        if d.is_finite() {
            d
        } else {
            0.0
        }
    })
}
