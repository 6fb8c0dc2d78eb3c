//! The scan-line algorithm with an edge list and an active edge table, for many
//! trapezia at once (van Rij, Algorithms 7 and 8).
//!
//! The edge list holds every trapezium's two edges as edge nodes, sorted on the row of
//! their top. Scanning rows from the top of the image down (y grows downward here; the
//! report scans upward), the nodes whose top falls in the current row enter the active
//! edge table, which is kept sorted on **Identifier, then Xmax** (section 3.4.1, figure
//! 27), so that consecutive pairs are the two edges of one trapezium. Each pair is filled
//! with DO_FILL (or point-sampled), nodes whose bottom falls in the row leave, and the
//! others are updated to the next row.
//!
//! Departure (docs/ERRATA.md): a node's Xmax and Imax are evaluated from the edge's end
//! points at the new row instead of subtracting `1/slope` and `di/dy` once per row. The
//! results are the same values up to rounding, without the drift that repeated
//! subtraction accumulates over thousands of rows, and two polygons sharing an edge get
//! bit-identical positions on it.

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
    /// Intensity at `(x_max, y_max)`.
    pub i_max: Vector,
    /// Which side it bounds.
    pub side: Side,
    /// The edge itself, and its trapezium's index in the input.
    edge: Edge,
    trapezium: usize,
}

impl EdgeNode {
    fn new(t: &Trapezium, index: usize, side: Side, channels: usize) -> EdgeNode {
        let edge = if side == Side::Left { t.left } else { t.right };
        EdgeNode {
            identifier: t.id,
            x_max: edge.x_at(t.y_top),
            y_min: t.y_bot,
            y_top: t.y_top,
            y_max: t.y_top,
            inv_slope: edge.inv_slope(),
            i_max: edge.i_at(t.y_top, channels),
            side,
            edge,
            trapezium: index,
        }
    }

    /// The first pixel row the node's trapezium touches.
    fn top_row(&self) -> i64 {
        floor_i64(self.y_top)
    }

    /// The last pixel row the node's trapezium touches.
    fn bottom_row(&self) -> i64 {
        (ceil_i64(self.y_min) - 1).max(self.top_row())
    }

    /// Moves the node to the top of pixel row `row`.
    fn update_to(&mut self, row: i64, channels: usize) {
        self.y_max = self.y_top.max(row as f64);
        self.x_max = self.edge.x_at(self.y_max);
        self.i_max = self.edge.i_at(self.y_max, channels);
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

/// The edge list of `trapezia`: both edges of every trapezium, sorted on the top row
/// (then Identifier, side). Built once per scene and shared by the bands of
/// [`scan_rows_of`].
pub fn edge_list(trapezia: &[Trapezium], channels: usize) -> Vec<EdgeNode> {
    // the sort keys alone are sorted (the nodes are big to move); the position in the
    // input breaks ties, so the order is the stable sort's
    let mut keys: Vec<(i64, u32, Side, usize)> = trapezia
        .iter()
        .enumerate()
        .flat_map(|(k, t)| {
            let top = floor_i64(t.y_top);
            [
                (top, t.id, Side::Left, 2 * k),
                (top, t.id, Side::Right, 2 * k + 1),
            ]
        })
        .collect();
    keys.sort_unstable();
    keys.iter()
        .map(|&(_, _, side, n)| EdgeNode::new(&trapezia[n / 2], n / 2, side, channels))
        .collect()
}

/// [`scan_rows`] with the scene's [`edge_list`] built already.
pub fn scan_rows_of(
    trapezia: &[Trapezium],
    edge_list: &[EdgeNode],
    rows: std::ops::Range<u32>,
    channels: usize,
    mut visit: impl FnMut(Visit<'_>),
) {
    let mut next = 0;
    let mut aet: Vec<EdgeNode> = Vec::new();
    for row in rows {
        let r = i64::from(row);
        // 4.1: insert the nodes whose trapezium starts in this row (and, when a band
        // starts below a trapezium's top, those that started above and still go on)
        while next < edge_list.len() && edge_list[next].top_row() <= r {
            let mut node = edge_list[next];
            if node.bottom_row() >= r {
                node.update_to(r, channels);
                aet.push(node);
            }
            next += 1;
        }
        // sorted on Identifier, then Xmax (the side breaks ties at a shared apex)
        aet.sort_by(|a, b| {
            a.identifier
                .cmp(&b.identifier)
                .then(a.x_max.total_cmp(&b.x_max))
                .then(a.side.cmp(&b.side))
        });
        // 4.2: each pair of nodes is one trapezium
        for pair in aet.chunks_exact(2) {
            debug_assert_eq!(pair[0].identifier, pair[1].identifier);
            visit(Visit::Fill(row, &trapezia[pair[0].trapezium]));
        }
        visit(Visit::EndOfRow(row));
        // 4.3: remove the nodes whose trapezium ends in this row; 4.5: update the rest
        aet.retain(|n| n.bottom_row() > r);
        for n in &mut aet {
            n.update_to(r + 1, channels);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
            intensity: vec![vec![1.0]; 3],
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
                    EdgeNode::new(t, k, Side::Left, 1),
                    EdgeNode::new(t, k, Side::Right, 1),
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
}
