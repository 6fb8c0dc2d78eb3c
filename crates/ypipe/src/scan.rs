//! The scan-line algorithm with an edge list and an active edge table, for many
//! trapezia at once (van Rij, Algorithms 7 and 8).
//!
//! The edge list holds every trapezium's two edges as edge nodes, sorted on the row of
//! their top. Scanning rows from the top of the image down (y grows downward here; the
//! report scans upward), the nodes whose top falls in the current row enter the active
//! edge table, which is kept sorted on **Identifier, then Xmax** (section 3.4.1, figure
//! 27), so that consecutive pairs are the two edges of one trapezium. Each pair is filled
//! with DO_FILL (or point-sampled), nodes whose bottom falls in the row leave, and the
//! others are updated to the next row. (Here a node knows which side it bounds, so the
//! table is kept on Identifier then side, which pairs and orders the trapezia as the
//! report's key does and never changes while a node is active: only the nodes that
//! enter are sorted, and merged in; `AetEntry`.)
//!
//! Departure (docs/ERRATA.md): a node's Xmax is evaluated from the edge's end points at
//! the new row instead of subtracting `1/slope` once per row (and its Imax, the
//! intensity there, on demand: [`EdgeNode::i_max`]). The results are the same values up
//! to rounding, without the drift that repeated subtraction accumulates over thousands of
//! rows, and two polygons sharing an edge get bit-identical positions on it. A node also
//! keeps the edge's x at the bottom of its part of the row, which is the next row's Xmax:
//! each row's x is evaluated once, and the row's [`Slice`] comes from the two nodes of
//! its trapezium ([`scan_slices_of`]) with no further evaluation.

use crate::coverage::{Slice, SliceEdge};
use crate::floor::{ceil_i64, floor_i64};
use crate::trapezoid::{Edge, Trapezium, Vector};

/// Which side of its trapezium an edge node bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Side {
    /// The left edge.
    Left,
    /// The right edge.
    Right,
}

/// An edge node (figure 2, with the fields added in sections 3.2–3.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeNode {
    /// The trapezium it belongs to.
    pub identifier: u32,
    /// x of the edge at the top of its part of the current row.
    pub x_max: f64,
    /// Exact y of the trapezium's bottom.
    pub y_min: f64,
    /// Exact y of the trapezium's top (kept through the scan).
    pub y_top: f64,
    /// Top of the edge's part of the current row.
    pub y_max: f64,
    /// `dx/dy`.
    pub inv_slope: f64,
    /// Which side it bounds.
    pub side: Side,
    /// The bottom of the edge's part of the current row, and the edge's x there (NaN
    /// before the node's first row).
    y_low: f64,
    x_low: f64,
    /// The edge itself, and its trapezium's index in the input.
    edge: Edge,
    trapezium: usize,
}

impl EdgeNode {
    fn new(t: &Trapezium, index: usize, side: Side) -> EdgeNode {
        let edge = if side == Side::Left { t.left } else { t.right };
        EdgeNode {
            identifier: t.id,
            x_max: edge.x_at(t.y_top),
            y_min: t.y_bot,
            y_top: t.y_top,
            y_max: t.y_top,
            inv_slope: edge.inv_slope(),
            side,
            y_low: f64::NAN,
            x_low: f64::NAN,
            edge,
            trapezium: index,
        }
    }

    /// Imax: the intensity at `(x_max, y_max)`, in `channels` channels.
    pub fn i_max(&self, channels: usize) -> Vector {
        self.edge.i_at(self.y_max, channels)
    }

    /// The first pixel row the node's trapezium touches.
    fn top_row(&self) -> i64 {
        pixel_rows(self.y_top, self.y_min).0
    }

    /// The last pixel row the node's trapezium touches.
    fn bottom_row(&self) -> i64 {
        pixel_rows(self.y_top, self.y_min).1
    }

    /// Moves the node to the top of pixel row `row`: the x there is the one kept at the
    /// bottom of the row before when that was the same height (always, moving down by
    /// one row within the trapezium), else evaluated.
    #[inline]
    fn update_to(&mut self, row: i64) {
        let y = self.y_top.max(row as f64);
        self.x_max = if y.to_bits() == self.y_low.to_bits() {
            self.x_low
        } else {
            self.edge.x_at(y)
        };
        self.y_max = y;
        self.y_low = self.y_min.min(row as f64 + 1.0);
        self.x_low = self.edge.x_at(self.y_low);
    }

    /// The edge over the node's part of the current row.
    #[inline]
    fn slice_edge(&self) -> SliceEdge {
        let (a, b) = (self.x_max, self.x_low);
        SliceEdge {
            lo: a.min(b),
            hi: a.max(b),
            at_top: a,
            at_bottom: b,
        }
    }
}

/// What the scan visits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Visit<'a> {
    /// A trapezium active in a pixel row, in active-edge-table order.
    Fill(u32, &'a Trapezium),
    /// The end of a pixel row (where the `Refresh` goes).
    EndOfRow(u32),
}

/// Scans `trapezia` (already inside the image) over pixel rows `0..height`, calling
/// `visit` for each trapezium active in a row and at the end of every row.
pub fn scan(trapezia: &[Trapezium], height: u32, channels: usize, visit: impl FnMut(Visit<'_>)) {
    scan_rows(trapezia, 0..height, channels, visit);
}

/// [`scan`] over the pixel rows `rows` only: the same visits, in the same order, as the
/// whole scan makes in those rows. Bands of rows can so be scanned independently (in
/// parallel) and their streams concatenated into exactly the whole scan's.
pub fn scan_rows(
    trapezia: &[Trapezium],
    rows: std::ops::Range<u32>,
    channels: usize,
    visit: impl FnMut(Visit<'_>),
) {
    scan_rows_of(
        trapezia,
        &edge_list(trapezia, channels),
        rows,
        channels,
        visit,
    );
}

/// The edge list of a scene's trapezia (figure 2's), sorted on the top row, then
/// Identifier, then side: each edge as its place among the trapezia's edges (`2k` the
/// left edge of trapezium `k`, `2k + 1` its right one) and the pixel rows its trapezium
/// touches, 24 bytes an edge. The scan makes an edge's [`EdgeNode`] from its trapezium
/// when it reaches it (the same node, bit for bit, in every band), so that the list the
/// bands share holds no copy of the edges; a band passes over the edges that ended above
/// it by their rows alone.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EdgeList {
    edges: Vec<ListedEdge>,
}

// `edge_list` makes the edges in its sort keys' block: the two must stay one size
const _: () = assert!(
    std::mem::size_of::<(i64, u32, Side, usize)>() == std::mem::size_of::<ListedEdge>()
        && std::mem::align_of::<(i64, u32, Side, usize)>() == std::mem::align_of::<ListedEdge>()
);

/// The first and the last pixel row a trapezium from `y_top` down to `y_bot` touches.
pub(crate) fn pixel_rows(y_top: f64, y_bot: f64) -> (i64, i64) {
    let top = floor_i64(y_top);
    (top, (ceil_i64(y_bot) - 1).max(top))
}

/// One edge of an [`EdgeList`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct ListedEdge {
    /// `2k` for the left edge of trapezium `k`, `2k + 1` for its right one.
    edge: usize,
    /// The first and the last pixel row its trapezium touches.
    top_row: i64,
    bottom_row: i64,
}

impl EdgeList {
    /// Edges in the list: two a trapezium.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// Whether it has no edge (a scene without trapezia).
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }
}

impl ListedEdge {
    /// Its trapezium's index and its side.
    fn trapezium_side(self) -> (usize, Side) {
        let side = if self.edge.is_multiple_of(2) {
            Side::Left
        } else {
            Side::Right
        };
        (self.edge / 2, side)
    }
}

/// The edge list of `trapezia`: both edges of every trapezium, sorted on the top row
/// (then Identifier, side). Built once per scene and shared by the bands of
/// [`scan_rows_of`]. (`channels` is the trapezia's: a node's intensity is taken in them
/// on demand, [`EdgeNode::i_max`].)
pub fn edge_list(trapezia: &[Trapezium], channels: usize) -> EdgeList {
    debug_assert!(channels <= cwisim_isa::MAX_CHANNELS);
    // the sort keys alone are sorted; the position in the input breaks ties, so the
    // order is the stable sort's
    let mut keys: Vec<(i64, u32, Side, usize)> = trapezia
        .iter()
        .enumerate()
        .flat_map(|(k, t)| {
            let top = pixel_rows(t.y_top, t.y_bot).0;
            [
                (top, t.id, Side::Left, 2 * k),
                (top, t.id, Side::Right, 2 * k + 1),
            ]
        })
        .collect();
    keys.sort_unstable();
    // made in the keys' own block (a key and an edge are both 24 bytes: `collect` from
    // the vector's `into_iter` reuses it), not beside it
    EdgeList {
        edges: keys
            .into_iter()
            .map(|(top_row, _, _, edge)| {
                let t = &trapezia[edge / 2];
                let bottom_row = pixel_rows(t.y_top, t.y_bot).1;
                ListedEdge {
                    edge,
                    top_row,
                    bottom_row,
                }
            })
            .collect(),
    }
}

/// [`scan_rows`] with the scene's [`edge_list`] built already (`channels`, the
/// trapezia's, as there: the scan itself takes no intensities).
pub fn scan_rows_of(
    trapezia: &[Trapezium],
    edge_list: &EdgeList,
    rows: std::ops::Range<u32>,
    channels: usize,
    mut visit: impl FnMut(Visit<'_>),
) {
    debug_assert!(channels <= cwisim_isa::MAX_CHANNELS);
    scan_slices_of(trapezia, edge_list, rows, |v| match v {
        SliceVisit::Fill(s, t) => visit(Visit::Fill(s.row, t)),
        SliceVisit::EndOfRow(row) => visit(Visit::EndOfRow(row)),
    });
}

/// What [`scan_slices_of`] visits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SliceVisit<'a> {
    /// A trapezium active in a pixel row, in active-edge-table order, with its part of
    /// the row: what [`Slice::of`] gives, from the scan's own evaluations of the edges.
    Fill(&'a Slice, &'a Trapezium),
    /// The end of a pixel row (where the `Refresh` goes).
    EndOfRow(u32),
}

/// [`scan_rows_of`] with each trapezium's [`Slice`] of the row (bit for bit
/// [`Slice::of`]'s); a trapezium whose band misses the row (`Slice::of` gives `None`)
/// is not visited.
pub fn scan_slices_of(
    trapezia: &[Trapezium],
    edge_list: &EdgeList,
    rows: std::ops::Range<u32>,
    mut visit: impl FnMut(SliceVisit<'_>),
) {
    let mut next = 0;
    // the active nodes, kept where they were put (a slot freed by a node that leaves is
    // reused), and the AET proper: their keys, sorted
    let mut nodes: Vec<EdgeNode> = Vec::new();
    let mut free: Vec<usize> = Vec::new();
    let mut aet: Vec<AetEntry> = Vec::new();
    let (mut fresh, mut merged): (Vec<AetEntry>, Vec<AetEntry>) = (Vec::new(), Vec::new());
    for row in rows {
        let r = i64::from(row);
        // 4.1: insert the nodes whose trapezium starts in this row (and, when a band
        // starts below a trapezium's top, those that started above and still go on)
        fresh.clear();
        while next < edge_list.len() && edge_list.edges[next].top_row <= r {
            let listed = edge_list.edges[next];
            if listed.bottom_row >= r {
                let (k, side) = listed.trapezium_side();
                let mut node = EdgeNode::new(&trapezia[k], k, side);
                debug_assert_eq!(
                    (node.top_row(), node.bottom_row()),
                    (listed.top_row, listed.bottom_row)
                );
                node.update_to(r);
                let slot = match free.pop() {
                    Some(slot) => {
                        nodes[slot] = node;
                        slot
                    }
                    None => {
                        nodes.push(node);
                        nodes.len() - 1
                    }
                };
                fresh.push(AetEntry::of(&node, slot));
            }
            next += 1;
        }
        if !fresh.is_empty() {
            fresh.sort_unstable();
            merge_into(&aet, &fresh, &mut merged);
            std::mem::swap(&mut aet, &mut merged);
        }
        // 4.2: each pair of nodes is one trapezium, its left edge first
        for pair in aet.chunks_exact(2) {
            debug_assert_eq!(pair[0].trapezium, pair[1].trapezium);
            let (left, right) = (&nodes[pair[0].slot], &nodes[pair[1].slot]);
            debug_assert_eq!((left.side, right.side), (Side::Left, Side::Right));
            // `Slice::of`'s band: the nodes' y_max is max(y_top, row), y_low
            // min(y_bot, row + 1)
            let (y0, y1) = (left.y_max, left.y_low);
            if y1 <= y0 {
                continue;
            }
            let slice = Slice {
                row,
                y0,
                y1,
                left: left.slice_edge(),
                right: right.slice_edge(),
            };
            visit(SliceVisit::Fill(&slice, &trapezia[pair[0].trapezium]));
        }
        visit(SliceVisit::EndOfRow(row));
        // 4.3: remove the nodes whose trapezium ends in this row; 4.5: update the rest
        // (in the one pass)
        aet.retain(|e| {
            let node = &mut nodes[e.slot];
            if node.bottom_row() > r {
                node.update_to(r + 1);
                true
            } else {
                free.push(e.slot);
                false
            }
        });
    }
}

/// An active node's place in the AET: its key — Identifier, then (for identifiers that
/// repeat) the trapezium's index, then the side —, and the slot it is kept in. Sorted
/// on the key, the two nodes of a trapezium are neighbours, the left one first, and the
/// trapezia come in Identifier order, the order of the report's key (Identifier, then
/// Xmax): a node knows its side, so Xmax, which tells the report the two edges of a
/// pair apart, need not be compared, and the key never changes while the node is
/// active — only the nodes that enter are sorted, and merged in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct AetEntry {
    identifier: u32,
    trapezium: usize,
    side: Side,
    slot: usize,
}

impl AetEntry {
    fn of(node: &EdgeNode, slot: usize) -> AetEntry {
        AetEntry {
            identifier: node.identifier,
            trapezium: node.trapezium,
            side: node.side,
            slot,
        }
    }
}

/// The sorted `a` and `b` merged into `out` (cleared first).
fn merge_into(a: &[AetEntry], b: &[AetEntry], out: &mut Vec<AetEntry>) {
    out.clear();
    out.reserve(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if b[j] < a[i] {
            out.push(b[j]);
            j += 1;
        } else {
            out.push(a[i]);
            i += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coverage::Slice;
    use crate::trapezoid::trapezia;
    use cwisim_scene::Polygon;

    /// Why the AET is sorted on Identifier first (section 3.4.1): when trapezia share a
    /// row and their x ranges overlap (overlapping polygons, or the ties at a shared vertex
    /// of the report's figure 25, where it scans with rounded rows), sorting on Xmax alone
    /// pairs edges of different trapezia. Grouped by Identifier, every pair is one
    /// trapezium.
    #[test]
    fn overlapping_trapezia_need_the_identifier() {
        let tri = |v: [[f64; 2]; 3]| Polygon {
            vertices: v.to_vec(),
            intensity: vec![vec![1.0].into(); 3],
            depth: None,
        };
        let mut ts = trapezia(&tri([[2.0, 0.0], [10.0, 0.0], [6.0, 8.0]]), 0, 1, 1);
        ts.extend(trapezia(
            &tri([[5.0, 0.0], [13.0, 0.0], [9.0, 8.0]]),
            1,
            1,
            2,
        ));
        let mut nodes: Vec<EdgeNode> = ts
            .iter()
            .enumerate()
            .flat_map(|(k, t)| {
                [
                    EdgeNode::new(t, k, Side::Left),
                    EdgeNode::new(t, k, Side::Right),
                ]
            })
            .collect();
        nodes.sort_by(|p, q| p.x_max.total_cmp(&q.x_max));
        assert!(
            nodes
                .chunks_exact(2)
                .any(|p| p[0].identifier != p[1].identifier),
            "sorted on Xmax alone, a pair mixes the two triangles"
        );
        let mut filled = Vec::new();
        scan(&ts, 8, 1, |v| {
            if let Visit::Fill(row, t) = v {
                filled.push((row, t.id));
            }
        });
        for row in 0..8 {
            let ids: Vec<u32> = filled
                .iter()
                .filter(|(r, _)| *r == row)
                .map(|(_, id)| *id)
                .collect();
            assert_eq!(
                ids,
                [1, 2],
                "row {row}: each trapezium once, in Identifier order"
            );
        }
    }

    /// Van Rij's figures 26 and 27 (docs/REPRODUCTION.md): the report's figure-25 points
    /// read as P = ADE, Q = ABC, R = DEF and transferred to cwisim's frame
    /// (`tests/fixtures/fig25-report.json`: the report's scanline 6 is row 7). Sorted on
    /// Xmax alone, row 7's nodes pair P–R, Q–P, R–Q (figure 26, the report's "between an
    /// edge of triangle P and one of R, then … P and … Q and last … R and … Q"); sorted on
    /// Identifier then Xmax, each triangle's own two edges (figure 27).
    #[test]
    fn figure_26_pairs_across_triangles_on_xmax_alone() {
        let tri = |v: [[f64; 2]; 3]| Polygon {
            vertices: v.to_vec(),
            intensity: vec![vec![1.0].into(); 3],
            depth: None,
        };
        let polygons = [
            tri([[2.5, 1.5], [2.5, 7.5], [9.05, 7.5]]),
            tri([[2.5, 1.5], [10.5, 1.5], [10.5, 8.83]]),
            tri([[2.5, 7.5], [9.05, 7.5], [14.5, 12.5]]),
        ];
        let mut ts = Vec::new();
        for (k, p) in polygons.iter().enumerate() {
            let id = ts.len() as u32 + 1;
            ts.extend(trapezia(p, k as u32, 1, id));
        }
        assert_eq!(
            ts.len(),
            3,
            "each triangle one trapezium, as the report numbers them"
        );
        let row = 7;
        let mut nodes: Vec<EdgeNode> = ts
            .iter()
            .enumerate()
            .filter(|(_, t)| t.y_top < row as f64 + 1.0 && t.y_bot > row as f64)
            .flat_map(|(k, t)| {
                [
                    EdgeNode::new(t, k, Side::Left),
                    EdgeNode::new(t, k, Side::Right),
                ]
            })
            .collect();
        for n in &mut nodes {
            n.update_to(row);
        }
        assert_eq!(nodes.len(), 6, "all three triangles meet the row");
        let pairs = |nodes: &[EdgeNode]| -> Vec<(u32, u32)> {
            nodes
                .chunks_exact(2)
                .map(|p| (p[0].identifier, p[1].identifier))
                .collect()
        };
        let (p, q, r) = (1, 2, 3);
        // a stable sort: ties in table order, as the report's insertion keeps them
        nodes.sort_by(|a, b| a.x_max.total_cmp(&b.x_max));
        assert_eq!(pairs(&nodes), [(p, r), (q, p), (r, q)], "figure 26");
        nodes.sort_by(|a, b| {
            (a.identifier, a.x_max)
                .partial_cmp(&(b.identifier, b.x_max))
                .expect("finite")
        });
        assert_eq!(pairs(&nodes), [(p, p), (q, q), (r, r)], "figure 27");
    }

    /// The scan's slices are [`Slice::of`]'s bit for bit, for every trapezium it visits
    /// in every row, and it visits exactly those [`scan_rows_of`] does whose band meets
    /// the row: random polygons, slivers, rows starting mid-trapezium, huge coordinates.
    #[test]
    fn the_scans_slices_are_slice_of_bit_for_bit() {
        let mut next = crate::test_rng::uniform(0x0DDB_1A5E_5BAD_5EEDu64);
        let poly = |v: Vec<[f64; 2]>| Polygon {
            intensity: vec![vec![0.5].into(); v.len()],
            vertices: v,
            depth: None,
        };
        let mut polygons = vec![
            poly(vec![[0.5, 0.25], [40.0, 0.25 + 1e-12], [20.0, 30.7]]),
            poly(vec![[3.0, 2.0], [3.0 + 1e-12, 2.0], [3.0, 19.0]]),
            poly(vec![[1e9, 1.5], [1e9 + 7.25, 1.5], [1e9 + 3.0, 9.0]]),
            poly(vec![[2.0, 5.0], [9.0, 5.0], [9.0, 6.0], [2.0, 6.0]]),
        ];
        for _ in 0..200 {
            let n = 3 + (next() * 3.0) as usize;
            let (cx, cy) = (next() * 60.0, next() * 60.0);
            // a convex polygon: points on an ellipse in angle order
            let (a, b) = (0.1 + next() * 20.0, 0.1 + next() * 20.0);
            let mut angles: Vec<f64> = (0..n).map(|_| next() * std::f64::consts::TAU).collect();
            angles.sort_by(f64::total_cmp);
            polygons.push(poly(
                angles
                    .iter()
                    .map(|t| [cx + a * t.cos(), cy + b * t.sin()])
                    .collect(),
            ));
        }
        let mut ts = Vec::new();
        for (k, p) in polygons.iter().enumerate() {
            let first = ts.len() as u32 + 1;
            ts.extend(trapezia(p, k as u32, 1, first));
        }
        let edges = edge_list(&ts, 1);
        for rows in [0..90, 7..90, 13..14] {
            let mut want = Vec::new();
            scan_rows_of(&ts, &edges, rows.clone(), 1, |v| {
                if let Visit::Fill(row, t) = v {
                    if let Some(s) = Slice::of(t, row) {
                        want.push((t.id, s));
                    }
                }
            });
            let mut got = Vec::new();
            scan_slices_of(&ts, &edges, rows, |v| {
                if let SliceVisit::Fill(s, t) = v {
                    got.push((t.id, *s));
                }
            });
            assert!(!want.is_empty());
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                // bit for bit (`==` on f64 would let -0.0 pass for 0.0)
                assert_eq!(format!("{g:?}"), format!("{w:?}"));
                let bits = |s: &Slice| {
                    [
                        s.y0,
                        s.y1,
                        s.left.lo,
                        s.left.hi,
                        s.left.at_top,
                        s.left.at_bottom,
                        s.right.lo,
                        s.right.hi,
                        s.right.at_top,
                        s.right.at_bottom,
                    ]
                    .map(f64::to_bits)
                };
                assert_eq!((g.0, bits(&g.1)), (w.0, bits(&w.1)));
            }
        }
    }
}
