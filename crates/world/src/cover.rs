//! Whether convex pieces together cover a whole triangle, decided without a polygon
//! boolean: the quick answer exact visibility ([`crate::visibility`]) asks before it
//! subtracts the pieces that hide a triangle from it. On a two-sided mesh most triangles
//! are wholly hidden — the far side under the near side's triangles — by several pieces
//! none of which holds the whole triangle, and their boolean returns nothing at the price
//! of a whole boolean (about half its time on the teapot: docs/VISIBILITY.md).
//!
//! The pieces' edges, each taken in its piece's anticlockwise direction, are put
//! together: an edge that two pieces share from opposite sides (the same two end points,
//! bit for bit, once each way round) cancels, and joins the two pieces into one group.
//! Across a cancelled edge the number of a group's pieces over a point does not change,
//! so the region a group covers is bounded by its edges left over. If none of those
//! meets the triangle, that number is the same all over it, and one point of it inside
//! one of the group's pieces shows it covered. A group is one surface's mesh, so a
//! triangle under a mesh is shown covered whatever other surfaces lie over part of it
//! (their outlines, crossing the triangle, are their groups' edges, not the mesh's). The
//! answer is conservative: `false` whenever every group over the triangle's centroid has
//! an edge left over that touches the triangle, however little (then the boolean
//! decides); an edge that pieces of several groups share is left over for each. Touches
//! and sides are told by the exact predicates scene validation uses
//! (`cwisim_scene::predicates`); only the centroid is rounded, and it lies in the
//! triangle's inside, where the count is the same everywhere.

use crate::boolean::{signed_area, Contour, Pt};
use cwisim_scene::predicates::{orient, segments_meet};

/// One piece's edge by its end points in `(x, y)` order, whether the piece runs it that
/// way, and the piece's index.
type Edge = (Pt, Pt, bool, u32);

/// Scratch space for [`covers`], kept between calls.
#[derive(Default)]
pub(crate) struct Scratch {
    edges: Vec<Edge>,
    /// Union–find over the pieces: joined where they share an edge that cancels.
    parent: Vec<u32>,
    /// Whether a group of joined pieces (by its root) has an edge left over that meets
    /// the triangle.
    touched: Vec<bool>,
}

impl Scratch {
    fn root(&mut self, mut k: u32) -> u32 {
        while self.parent[k as usize] != k {
            let up = self.parent[self.parent[k as usize] as usize];
            self.parent[k as usize] = up;
            k = up;
        }
        k
    }
}

/// An edge's end points, bit for bit: equal for the same edge of two pieces.
fn key(e: &Edge) -> [u64; 4] {
    [e.0[0], e.0[1], e.1[0], e.1[1]].map(f64::to_bits)
}

/// The groups of equal edges of `edges` (sorted by [`key`]): each one's range, and
/// whether its edges cancel (as many run one way as the other).
fn groups(edges: &[Edge]) -> impl Iterator<Item = (usize, usize, bool)> + '_ {
    let mut i = 0;
    std::iter::from_fn(move || {
        (i < edges.len()).then(|| {
            let mut j = i;
            let mut net = 0i64;
            while j < edges.len() && key(&edges[j]) == key(&edges[i]) {
                net += if edges[j].2 { 1 } else { -1 };
                j += 1;
            }
            let group = (i, j, net == 0);
            i = j;
            group
        })
    })
}

/// Whether the convex, anticlockwise pieces `pieces` cover all of the triangle `t` (see
/// the [module docs](self)); `false` when that is not shown.
pub(crate) fn covers(t: &[Pt; 3], pieces: &[Contour], scratch: &mut Scratch) -> bool {
    if pieces.is_empty() || signed_area(t) == 0.0 {
        return false;
    }
    let edges = &mut scratch.edges;
    edges.clear();
    for (k, p) in pieces.iter().enumerate() {
        // anticlockwise, with area (not NaN)
        if p.len() < 3 || signed_area(p).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            if (a[0], a[1]) <= (b[0], b[1]) {
                edges.push((a, b, true, k as u32));
            } else {
                edges.push((b, a, false, k as u32));
            }
        }
    }
    // grouped by their end points' bits (any order that puts equal ones together)
    edges.sort_unstable_by_key(key);
    // the pieces joined where an edge cancels: the count of a group's pieces over a
    // point changes only across its edges left over
    scratch.parent.clear();
    scratch.parent.extend(0..pieces.len() as u32);
    let edges = std::mem::take(&mut scratch.edges);
    for (i, j, cancels) in groups(&edges) {
        if cancels {
            let first = scratch.root(edges[i].3);
            for e in &edges[i + 1..j] {
                let r = scratch.root(e.3);
                scratch.parent[r as usize] = first;
            }
        }
    }
    // a group with an edge left over that meets the triangle shows nothing (a piece's
    // edge shared by pieces of another group is left over for both: cautious)
    scratch.touched.clear();
    scratch.touched.resize(pieces.len(), false);
    let mut untouched = true;
    for (i, j, cancels) in groups(&edges) {
        if !cancels && meets(edges[i].0, edges[i].1, t) {
            untouched = false;
            for e in &edges[i..j] {
                let r = scratch.root(e.3);
                scratch.touched[r as usize] = true;
            }
        }
    }
    scratch.edges = edges;
    // no edge of a group left over meets the triangle: its count is the same all over
    // it, and one inside point in one of its pieces shows it covered
    let c = [
        (t[0][0] + t[1][0] + t[2][0]) / 3.0,
        (t[0][1] + t[1][1] + t[2][1]) / 3.0,
    ];
    (0..pieces.len()).any(|k| {
        let p = &pieces[k];
        let shows = untouched || {
            let r = scratch.root(k as u32);
            !scratch.touched[r as usize]
        };
        shows && (0..p.len()).all(|i| orient(p[i], p[(i + 1) % p.len()], c) >= 0)
    })
}

/// Whether the segment `a`–`b` meets the triangle `t` (its inside or its edges,
/// touching included), exactly.
fn meets(a: Pt, b: Pt, t: &[Pt; 3]) -> bool {
    // beside the triangle's box: apart (comparing coordinates is exact)
    let beside = (0..2).any(|k| {
        let (lo, hi) = (a[k].min(b[k]), a[k].max(b[k]));
        hi < t[0][k].min(t[1][k]).min(t[2][k]) || lo > t[0][k].max(t[1][k]).max(t[2][k])
    });
    if beside {
        return false;
    }
    let turn = orient(t[0], t[1], t[2]);
    let inside = |p: Pt| (0..3).all(|i| orient(t[i], t[(i + 1) % 3], p) * turn >= 0);
    inside(a)
        || inside(b)
        || (0..3).any(|i| segments_meet((a, b), (t[i], t[(i + 1) % 3])).is_some())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boolean::{area, grid_for, overlay, positive};
    use i_overlay::core::overlay_rule::OverlayRule;
    use proptest::prelude::*;

    /// What the polygon boolean (which shares no code with [`covers`]) leaves of `t`
    /// after `pieces` (px²).
    fn left_by_boolean(t: &[Pt; 3], pieces: &[Contour]) -> f64 {
        let grid = grid_for(
            t.iter()
                .copied()
                .chain(pieces.iter().flat_map(|p| p.iter().copied())),
        );
        overlay(
            &grid,
            &vec![positive(t.to_vec())],
            &pieces.to_vec(),
            OverlayRule::Difference,
        )
        .iter()
        .map(|shape| {
            let (outline, holes) = shape.split_first().expect("an outline");
            area(outline) - holes.iter().map(|h| area(h)).sum::<f64>()
        })
        .sum()
    }

    /// A mesh of `n × n` squares over `[0, 8]²`, each cut into two anticlockwise
    /// triangles, its inner corners moved by `jitter`.
    fn mesh(n: usize, jitter: &[f64]) -> Vec<Contour> {
        let s = 8.0 / n as f64;
        let at = |i: usize, j: usize| {
            let inner = i > 0 && i < n && j > 0 && j < n;
            let d = if inner && !jitter.is_empty() {
                jitter[(i * 31 + j * 17) % jitter.len()]
            } else {
                0.0
            };
            [i as f64 * s + d, j as f64 * s - d]
        };
        let mut out = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                out.push(positive(vec![a, b, c]));
                out.push(positive(vec![a, c, d]));
            }
        }
        out
    }

    /// A 3 × 3 mesh over `[0, 8]²` without its middle square: a ring of pieces around a
    /// hole.
    fn ring() -> Vec<Contour> {
        mesh(3, &[])
            .into_iter()
            .filter(|p| {
                let c = p.iter().fold([0.0, 0.0], |s, v| [s[0] + v[0], s[1] + v[1]]);
                let c = [c[0] / p.len() as f64, c[1] / p.len() as f64];
                !(c[0] > 8.0 / 3.0 && c[0] < 16.0 / 3.0 && c[1] > 8.0 / 3.0 && c[1] < 16.0 / 3.0)
            })
            .collect()
    }

    #[test]
    fn a_mesh_covers_a_triangle_under_it_and_a_hole_or_an_edge_does_not() {
        let mut scratch = Scratch::default();
        let pieces = mesh(4, &[0.13, -0.21, 0.07]);
        let t = [[0.5, 0.7], [7.1, 2.3], [3.3, 7.6]];
        assert!(covers(&t, &pieces, &mut scratch));
        assert!(left_by_boolean(&t, &pieces) <= 1e-12);
        // one piece taken away: a hole the triangle shows through
        let mut holed = pieces.clone();
        holed.remove(9);
        assert!(!covers(&t, &holed, &mut scratch));
        assert!(left_by_boolean(&t, &holed) > 1e-3);
        // reaching past the mesh, or touching its edge: not shown
        assert!(!covers(
            &[[0.5, 0.7], [8.5, 2.3], [3.3, 7.6]],
            &pieces,
            &mut scratch
        ));
        assert!(!covers(
            &[[0.0, 0.7], [7.1, 2.3], [3.3, 7.6]],
            &pieces,
            &mut scratch
        ));
        // nothing, or a piece the wrong way round: not shown
        assert!(!covers(&t, &[], &mut scratch));
        let mut turned = pieces.clone();
        turned[0].reverse();
        assert!(!covers(&t, &turned, &mut scratch));
        // a triangle in a hole of the pieces (a ring of them): not covered, though no
        // edge of theirs meets it and the ring's outline holds it
        let ring = ring();
        assert!(!covers(
            &[[3.5, 3.5], [4.5, 3.5], [4.0, 4.5]],
            &ring,
            &mut scratch
        ));
    }

    /// `pieces` moved by `(dx, dy)` and scaled about the origin by `scale`.
    fn moved(pieces: &[Contour], dx: f64, dy: f64, scale: f64) -> Vec<Contour> {
        pieces
            .iter()
            .map(|p| {
                p.iter()
                    .map(|v| [v[0] * scale + dx, v[1] * scale + dy])
                    .collect()
            })
            .collect()
    }

    #[test]
    fn a_mesh_covers_a_triangle_under_it_whatever_another_surface_over_part_of_it_adds() {
        let mut scratch = Scratch::default();
        let t = [[0.5, 0.7], [7.1, 2.3], [3.3, 7.6]];
        // a whole mesh under the triangle, and a smaller one (another surface, sharing no
        // edge with it) whose outline crosses the triangle
        let mut pieces = mesh(4, &[0.13, -0.21, 0.07]);
        pieces.extend(moved(&mesh(2, &[0.05]), 2.2, 1.9, 0.4));
        assert!(covers(&t, &pieces, &mut scratch));
        assert!(left_by_boolean(&t, &pieces) <= 1e-12);
        // each of two halves of a mesh over half of the triangle, sharing no edge: their
        // outlines cross it, so it is not shown (though the boolean leaves nothing)
        let halves: Vec<Contour> = mesh(4, &[])
            .into_iter()
            .enumerate()
            .map(|(k, p)| {
                if k < 16 {
                    p
                } else {
                    // the right half, its corners moved by a rounding: no edge in common
                    p.iter().map(|v| [v[0], v[1] * (1.0 + 1e-15)]).collect()
                }
            })
            .collect();
        assert!(!covers(&t, &halves, &mut scratch));
        // a ring of pieces whose hole holds the triangle, and a piece over the
        // triangle's middle reaching out of it: not covered, though no edge of the ring
        // meets the triangle and the middle's centre lies in a piece
        let mut ring = ring();
        let small = [[3.5, 3.5], [4.5, 3.5], [4.0, 4.5]];
        ring.push(positive(vec![[3.9, 3.6], [4.1, 3.6], [4.0, 4.9]]));
        assert!(!covers(&small, &ring, &mut scratch));
        assert!(left_by_boolean(&small, &ring) > 1e-3);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1000))]

        /// Where it says covered, the boolean leaves nothing: random meshes with moved
        /// corners, overlapping copies, random triangles in and around them, a random
        /// piece taken away.
        #[test]
        fn covered_means_the_boolean_leaves_nothing(
            n in 1..5usize,
            jitter in prop::collection::vec(-0.3..0.3f64, 0..6),
            t in [(-1.0..9.0f64, -1.0..9.0f64), (-1.0..9.0f64, -1.0..9.0f64), (-1.0..9.0f64, -1.0..9.0f64)],
            drop in prop::option::of(0..32usize),
            twice in prop::option::of(0..32usize),
            other in prop::option::of((1..4usize, -2.0..6.0f64, -2.0..6.0f64, 0.2..1.2f64)),
        ) {
            let mut pieces = mesh(n, &jitter);
            // another surface, sharing no edge with the first (or some, by chance)
            if let Some((m, dx, dy, scale)) = other {
                pieces.extend(moved(&mesh(m, &jitter), dx, dy, scale));
            }
            if let Some(k) = twice {
                if k < pieces.len() {
                    pieces.push(pieces[k].clone());
                }
            }
            if let Some(k) = drop {
                if k < pieces.len() {
                    pieces.remove(k);
                }
            }
            let t = t.map(|(x, y)| [x, y]);
            if covers(&t, &pieces, &mut Scratch::default()) {
                let left = left_by_boolean(&t, &pieces);
                prop_assert!(left <= 1e-12, "covered, but the boolean leaves {left} px²");
            }
        }

        /// A triangle well inside a whole mesh is shown covered: the check is not merely
        /// cautious.
        #[test]
        fn a_whole_mesh_covers_what_lies_well_inside_it(
            n in 1..5usize,
            jitter in prop::collection::vec(-0.3..0.3f64, 0..6),
            t in [(0.5..7.5f64, 0.5..7.5f64), (0.5..7.5f64, 0.5..7.5f64), (0.5..7.5f64, 0.5..7.5f64)],
        ) {
            let t = t.map(|(x, y)| [x, y]);
            prop_assume!(area(&t) > 1e-6);
            prop_assert!(covers(&t, &mesh(n, &jitter), &mut Scratch::default()));
        }
    }
}
