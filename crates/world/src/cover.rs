//! Whether convex pieces together cover a whole triangle, decided without a polygon
//! boolean: the quick answer exact visibility ([`crate::visibility`]) asks before it
//! subtracts the pieces that hide a triangle from it. On a two-sided mesh most triangles
//! are wholly hidden — the far side under the near side's triangles — by several pieces
//! none of which holds the whole triangle, and their boolean returns nothing at the price
//! of a whole boolean (about half its time on the teapot: docs/VISIBILITY.md).
//!
//! The pieces' edges, each taken in its piece's anticlockwise direction, are put
//! together: an edge that two pieces share from opposite sides (the same two end points,
//! bit for bit, once each way round) cancels. Across a cancelled edge the number of pieces
//! over a point does not change, so the region the pieces cover is bounded by the edges
//! left over. If none of those meets the triangle, that number is the same all over it,
//! and one point of it inside a piece shows it covered. The answer is conservative:
//! `false` whenever an edge left over touches the triangle, however little (then the
//! boolean decides). Touches and sides are told by the exact predicates scene validation
//! uses (`cwisim_scene::predicates`); only the centroid is rounded, and it lies in the
//! triangle's inside, where the count is the same everywhere.

use crate::boolean::{signed_area, Contour, Pt};
use cwisim_scene::predicates::{orient, segments_meet};

/// Whether the convex, anticlockwise pieces `pieces` cover all of the triangle `t` (see
/// the [module docs](self)); `false` when that is not shown. `edges` is scratch space.
pub(crate) fn covers(t: &[Pt; 3], pieces: &[Contour], edges: &mut Vec<(Pt, Pt, bool)>) -> bool {
    if pieces.is_empty() || signed_area(t) == 0.0 {
        return false;
    }
    // each edge by its end points in (x, y) order, and whether the piece runs it that way
    edges.clear();
    for p in pieces {
        // anticlockwise, with area (not NaN)
        if p.len() < 3 || signed_area(p).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            if (a[0], a[1]) <= (b[0], b[1]) {
                edges.push((a, b, true));
            } else {
                edges.push((b, a, false));
            }
        }
    }
    // grouped by their end points' bits (any order that puts equal ones together)
    let key = |e: &(Pt, Pt, bool)| [e.0[0], e.0[1], e.1[0], e.1[1]].map(f64::to_bits);
    edges.sort_unstable_by_key(key);
    let same = |x: &(Pt, Pt, bool), y: &(Pt, Pt, bool)| key(x) == key(y);
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        let mut net = 0i64;
        while j < edges.len() && same(&edges[i], &edges[j]) {
            net += if edges[j].2 { 1 } else { -1 };
            j += 1;
        }
        if net != 0 && meets(edges[i].0, edges[i].1, t) {
            return false;
        }
        i = j;
    }
    // no edge left over meets the triangle: one inside point decides
    let c = [
        (t[0][0] + t[1][0] + t[2][0]) / 3.0,
        (t[0][1] + t[1][1] + t[2][1]) / 3.0,
    ];
    pieces
        .iter()
        .any(|p| (0..p.len()).all(|i| orient(p[i], p[(i + 1) % p.len()], c) >= 0))
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

    #[test]
    fn a_mesh_covers_a_triangle_under_it_and_a_hole_or_an_edge_does_not() {
        let mut edges = Vec::new();
        let pieces = mesh(4, &[0.13, -0.21, 0.07]);
        let t = [[0.5, 0.7], [7.1, 2.3], [3.3, 7.6]];
        assert!(covers(&t, &pieces, &mut edges));
        assert!(left_by_boolean(&t, &pieces) <= 1e-12);
        // one piece taken away: a hole the triangle shows through
        let mut holed = pieces.clone();
        holed.remove(9);
        assert!(!covers(&t, &holed, &mut edges));
        assert!(left_by_boolean(&t, &holed) > 1e-3);
        // reaching past the mesh, or touching its edge: not shown
        assert!(!covers(
            &[[0.5, 0.7], [8.5, 2.3], [3.3, 7.6]],
            &pieces,
            &mut edges
        ));
        assert!(!covers(
            &[[0.0, 0.7], [7.1, 2.3], [3.3, 7.6]],
            &pieces,
            &mut edges
        ));
        // nothing, or a piece the wrong way round: not shown
        assert!(!covers(&t, &[], &mut edges));
        let mut turned = pieces.clone();
        turned[0].reverse();
        assert!(!covers(&t, &turned, &mut edges));
        // a triangle in a hole of the pieces (a ring of them): not covered, though no
        // edge of theirs meets it and the ring's outline holds it
        let ring: Vec<Contour> = mesh(3, &[])
            .into_iter()
            .filter(|p| {
                let c = p.iter().fold([0.0, 0.0], |s, v| [s[0] + v[0], s[1] + v[1]]);
                let c = [c[0] / p.len() as f64, c[1] / p.len() as f64];
                !(c[0] > 8.0 / 3.0 && c[0] < 16.0 / 3.0 && c[1] > 8.0 / 3.0 && c[1] < 16.0 / 3.0)
            })
            .collect();
        assert!(!covers(
            &[[3.5, 3.5], [4.5, 3.5], [4.0, 4.5]],
            &ring,
            &mut edges
        ));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

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
        ) {
            let mut pieces = mesh(n, &jitter);
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
            if covers(&t, &pieces, &mut Vec::new()) {
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
            prop_assert!(covers(&t, &mesh(n, &jitter), &mut Vec::new()));
        }
    }
}
