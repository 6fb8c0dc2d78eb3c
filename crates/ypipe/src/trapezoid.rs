//! Splitting polygons into trapezia with horizontal top and bottom (van Rij 3.3).
//!
//! Every vertex height is a cut. Between two consecutive cuts no edge starts or ends,
//! and (the polygon being simple) no two edges cross, so the edges crossing the band can
//! be sorted by x and paired left–right by the even–odd rule. Consecutive bands bounded
//! by the same two edges are merged. The trapezia of a polygon tile it with no gap and no
//! overlap: each band's pieces are exactly the polygon's spans.

use cwisim_isa::MAX_CHANNELS;
use cwisim_scene::Polygon;
pub use cwisim_scene::{vector, Vector};

/// A polygon edge, oriented downward (y grows downward), with the intensities at its ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edge {
    /// Upper end.
    pub x_top: f64,
    /// Upper end.
    pub y_top: f64,
    /// Lower end.
    pub x_bot: f64,
    /// Lower end.
    pub y_bot: f64,
    /// Intensity at the upper end.
    pub i_top: Vector,
    /// Intensity at the lower end.
    pub i_bot: Vector,
}

impl Edge {
    /// `1/slope` of the report: `dx/dy`.
    pub fn inv_slope(&self) -> f64 {
        (self.x_bot - self.x_top) / (self.y_bot - self.y_top)
    }

    /// x where the edge's line is at height `y`. Evaluated from the edge's ends every
    /// time (not stepped), so that two polygons sharing an edge get identical values.
    pub fn x_at(&self, y: f64) -> f64 {
        if y <= self.y_top {
            return self.x_top + (y - self.y_top) * self.inv_slope();
        }
        if y >= self.y_bot {
            return self.x_bot + (y - self.y_bot) * self.inv_slope();
        }
        let t = (y - self.y_top) / (self.y_bot - self.y_top);
        self.x_top + t * (self.x_bot - self.x_top)
    }

    /// The intensity interpolated (or extrapolated) linearly along the edge at height `y`.
    pub fn i_at(&self, y: f64, channels: usize) -> Vector {
        let t = (y - self.y_top) / (self.y_bot - self.y_top);
        vector(channels, |c| {
            self.i_top[c] + t * (self.i_bot[c] - self.i_top[c])
        })
    }
}

/// A trapezium: a horizontal band `[y_top, y_bot]` between a left and a right edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trapezium {
    /// The Identifier of the report's section 3.4.1: unique per trapezium in a scene.
    pub id: u32,
    /// Index of the scene polygon it comes from.
    pub polygon: u32,
    /// Top of the band.
    pub y_top: f64,
    /// Bottom of the band (`> y_top`).
    pub y_bot: f64,
    /// The left edge (its line; only the band is part of the trapezium).
    pub left: Edge,
    /// The right edge.
    pub right: Edge,
}

/// The edges of a polygon, oriented downward; horizontal and zero-length edges are left
/// out (they bound no span).
pub fn edges(p: &Polygon, channels: usize) -> Vec<Edge> {
    let n = p.vertices.len();
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let (a, b) = (k, (k + 1) % n);
        let (pa, pb) = (p.vertices[a], p.vertices[b]);
        if pa[1] == pb[1] {
            continue;
        }
        let (top, bot) = if pa[1] < pb[1] { (a, b) } else { (b, a) };
        let vec_of = |v: usize| {
            let mut x = [0.0; MAX_CHANNELS];
            x[..channels].copy_from_slice(&p.intensity[v][..channels]);
            x
        };
        out.push(Edge {
            x_top: p.vertices[top][0],
            y_top: p.vertices[top][1],
            x_bot: p.vertices[bot][0],
            y_bot: p.vertices[bot][1],
            i_top: vec_of(top),
            i_bot: vec_of(bot),
        });
    }
    out
}

/// The trapezia of one polygon, numbered from `first_id`.
pub fn trapezia(p: &Polygon, polygon: u32, channels: usize, first_id: u32) -> Vec<Trapezium> {
    let edges = edges(p, channels);
    let mut cuts: Vec<f64> = p.vertices.iter().map(|v| v[1]).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut out: Vec<Trapezium> = Vec::new();
    // the edge pairs of the previous band, to merge bands bounded by the same edges
    let mut open: Vec<(usize, usize, usize)> = Vec::new(); // (left edge, right edge, index in out)
    for band in cuts.windows(2) {
        let (y0, y1) = (band[0], band[1]);
        let mid = 0.5 * (y0 + y1);
        let mut crossing: Vec<(f64, usize)> = edges
            .iter()
            .enumerate()
            .filter(|(_, e)| e.y_top <= y0 && e.y_bot >= y1)
            .map(|(k, e)| (e.x_at(mid), k))
            .collect();
        crossing.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut next_open = Vec::new();
        for pair in crossing.chunks_exact(2) {
            let (l, r) = (pair[0].1, pair[1].1);
            if let Some(&(_, _, idx)) = open.iter().find(|(a, b, _)| *a == l && *b == r) {
                out[idx].y_bot = y1;
                next_open.push((l, r, idx));
            } else {
                next_open.push((l, r, out.len()));
                out.push(Trapezium {
                    id: first_id + out.len() as u32,
                    polygon,
                    y_top: y0,
                    y_bot: y1,
                    left: edges[l],
                    right: edges[r],
                });
            }
        }
        open = next_open;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn poly(v: &[[f64; 2]]) -> Polygon {
        Polygon {
            vertices: v.to_vec(),
            intensity: vec![vec![1.0].into(); v.len()],
            depth: None,
        }
    }

    fn area(t: &Trapezium) -> f64 {
        let h = t.y_bot - t.y_top;
        let w_top = t.right.x_at(t.y_top) - t.left.x_at(t.y_top);
        let w_bot = t.right.x_at(t.y_bot) - t.left.x_at(t.y_bot);
        0.5 * h * (w_top + w_bot)
    }

    #[test]
    fn a_quad_with_a_middle_vertex_gives_merged_trapezia() {
        // the report's figure 7: a polygon that becomes two triangles and a trapezium
        let p = poly(&[[0.0, 0.0], [4.0, 2.0], [3.0, 6.0], [-1.0, 4.0]]);
        let ts = trapezia(&p, 0, 1, 1);
        assert_eq!(ts.len(), 3);
        let total: f64 = ts.iter().map(area).sum();
        assert!((total - 18.0).abs() < 1e-12, "{total}");
        assert_eq!(ts.iter().map(|t| t.id).collect::<Vec<_>>(), [1, 2, 3]);
    }

    #[test]
    fn a_concave_polygon_splits_into_side_by_side_trapezia() {
        // a "U": two prongs joined at the bottom
        let p = poly(&[
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 2.0],
            [2.0, 2.0],
            [2.0, 0.0],
            [3.0, 0.0],
            [3.0, 3.0],
            [0.0, 3.0],
        ]);
        let ts = trapezia(&p, 0, 1, 1);
        let total: f64 = ts.iter().map(area).sum();
        assert!((total - 7.0).abs() < 1e-12, "{total}");
        assert!(ts.iter().filter(|t| t.y_bot == 2.0).count() == 2);
    }

    #[test]
    fn orientation_does_not_matter() {
        let a = poly(&[[0.0, 0.0], [4.0, 1.0], [1.0, 5.0]]);
        let mut b = a.clone();
        b.vertices.reverse();
        let (ta, tb) = (trapezia(&a, 0, 1, 1), trapezia(&b, 0, 1, 1));
        let (sa, sb): (f64, f64) = (ta.iter().map(area).sum(), tb.iter().map(area).sum());
        assert!(
            (sa - sb).abs() < 1e-12 && (sa - 9.5).abs() < 1e-12,
            "{sa} {sb}"
        );
    }
}
