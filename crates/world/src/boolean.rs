//! Polygon booleans on one integer grid, and what turns their results into the simple,
//! hole-free contours the Y-processor takes: shared by exact visibility
//! ([`crate::visibility`]) and shadows ([`crate::shadow`]). The grid and the tidying rules
//! are described in `visibility`'s module docs ("Precision", steps 5 and 6).

use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay::ShapeType;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::core::solver::Solver;
use i_overlay::float::overlay::{FloatOverlay, OverlayOptions};
use i_overlay::i_float::adapter::FloatPointAdapter;
use i_overlay::i_float::float::rect::FloatRect;

/// A screen point `[x, y]`.
pub(crate) type Pt = [f64; 2];
/// A closed contour (the last vertex joins the first).
pub(crate) type Contour = Vec<Pt>;
/// An outline followed by its holes.
pub(crate) type Shape = Vec<Contour>;
/// The integer grid all polygon booleans run on.
pub(crate) type Grid = FloatPointAdapter<Pt, i64>;

/// Contours with less area (px²) are dropped.
pub(crate) const SLIVER_AREA: f64 = 1e-12;
/// A vertex where the boundary turns back within this angle (its sine) is a spike.
const SPIKE_SIN: f64 = 1e-12;
/// Consecutive vertices closer than this, relative to their coordinates' magnitude (at
/// least 1 px), are merged: a few hundred units in the last place, well above the
/// rounding of the grid's coordinates to `f64`.
const NEAR_VERTEX: f64 = 1e-13;

/// What [`settle`] cut and dropped: hole cuts, and each dropped sliver's area in the order
/// dropped (summed by the caller in a fixed order, so that totals do not depend on how
/// work was split between threads).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Losses {
    /// Horizontal cuts made to remove holes.
    pub hole_cuts: u64,
    /// The areas (px²) of the contours dropped, in order.
    pub dropped: Vec<f64>,
}

impl Losses {
    /// Counts a dropped contour of `area`.
    fn drop(&mut self, area: f64) {
        self.dropped.push(area);
    }
}

/// The grid for points `pts`: `i64` over `[−m, m]²`, `m` the power of two at or above
/// their largest magnitude (at least 1).
pub(crate) fn grid_for(pts: impl Iterator<Item = Pt>) -> Grid {
    let big = pts.fold(1.0f64, |b, p| b.max(p[0].abs()).max(p[1].abs()));
    let mut m = 1.0f64;
    while m < big {
        m *= 2.0;
    }
    let rect = FloatRect::new(-m, m, -m, m).expect("finite, ordered bounds");
    FloatPointAdapter::new_conservative(rect)
}

/// The half-extent `m` of the grid's square.
pub(crate) fn grid_extent(grid: &Grid) -> f64 {
    grid.rect().max_x
}

/// `subject ∘ clip` on the shared grid, non-zero fill, OGC-valid output (outlines with
/// positive signed area, holes negative).
pub(crate) fn overlay(grid: &Grid, subject: &Shape, clip: &Shape, rule: OverlayRule) -> Vec<Shape> {
    let capacity = subject.iter().chain(clip).map(Vec::len).sum();
    FloatOverlay::new_custom(
        grid.clone(),
        OverlayOptions::<f64, i64>::ogc(),
        Solver::default(),
        capacity,
    )
    .unsafe_add_source(subject, ShapeType::Subject)
    .unsafe_add_source(clip, ShapeType::Clip)
    .overlay(rule, FillRule::NonZero)
}

/// How many cuts deep [`settle`] goes before it drops what holes are left (counted): the
/// safeguard against an endless recursion, never reached in practice.
pub(crate) const MAX_CUT_DEPTH: usize = 64;

/// Turns one result shape (outline, then holes) into hole-free contours in `out`:
/// drops slivers, cuts holes away, tidies the outlines. `cuts_left` is how many cuts
/// deeper it may go ([`MAX_CUT_DEPTH`] at the top).
///
/// A part of a cut has fewer of its parent's holes, but may have new ones: an outline
/// that touches itself at a vertex (a pinched outline, which the overlay can give) comes
/// out of a cut as an outline and a hole touching it. Those are cut in turn; dropping
/// them instead left the part covering the hole, a point covered twice.
pub(crate) fn settle(
    grid: &Grid,
    shape: Shape,
    cuts_left: usize,
    out: &mut Vec<Contour>,
    losses: &mut Losses,
) {
    let mut contours = shape.into_iter();
    let Some(outline) = contours.next() else {
        return;
    };
    let outline_area = area(&outline);
    if outline_area < SLIVER_AREA {
        losses.drop(outline_area);
        return;
    }
    let mut holes = Vec::new();
    for h in contours {
        let a = area(&h);
        if a < SLIVER_AREA {
            losses.drop(a);
        } else {
            holes.push(h);
        }
    }
    if cuts_left == 0 {
        // never reached: the cuts did not remove the holes
        for h in holes.drain(..) {
            losses.drop(area(&h));
        }
    }
    if holes.is_empty() {
        let outline = tidy(outline);
        let a = area(&outline);
        if outline.len() < 3 || a < SLIVER_AREA {
            losses.drop(a);
        } else {
            out.push(outline);
        }
        return;
    }
    losses.hole_cuts += 1;
    let (lo, hi) = holes[0]
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[1]), hi.max(p[1]))
        });
    let cut = lo + 0.5 * (hi - lo);
    let m = grid_extent(grid);
    let whole: Shape = std::iter::once(outline).chain(holes).collect();
    for (top, bottom) in [(-m, cut), (cut, m)] {
        let half = vec![vec![[-m, top], [m, top], [m, bottom], [-m, bottom]]];
        for part in overlay(grid, &whole, &half, OverlayRule::Intersect) {
            settle(grid, part, cuts_left - 1, out, losses);
        }
    }
}

/// Removes consecutive vertices within [`NEAR_VERTEX`] (relative) of each other and spikes
/// (a vertex where the boundary turns back on itself within an angle of [`SPIKE_SIN`]),
/// repeatedly.
pub(crate) fn tidy(mut v: Contour) -> Contour {
    'again: while v.len() >= 3 {
        let n = v.len();
        for k in 0..n {
            let (a, b, c) = (v[(k + n - 1) % n], v[k], v[(k + 1) % n]);
            let (u, w) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
            let turn = u[0] * w[1] - u[1] * w[0];
            let back = u[0] * w[0] + u[1] * w[1] < 0.0;
            let near =
                u[0].abs().max(u[1].abs()) <= NEAR_VERTEX * b[0].abs().max(b[1].abs()).max(1.0);
            if near || (back && turn.abs() <= SPIKE_SIN * u[0].hypot(u[1]) * w[0].hypot(w[1])) {
                v.remove(k);
                continue 'again;
            }
        }
        break;
    }
    v
}

/// Twice the signed area of the triangle `a b c`.
pub(crate) fn cross(a: Pt, b: Pt, c: Pt) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
}

/// The signed shoelace area of a contour, relative to its first vertex.
pub(crate) fn signed_area(v: &[Pt]) -> f64 {
    if v.len() < 3 {
        return 0.0;
    }
    let o = v[0];
    let mut sum = 0.0;
    for k in 1..v.len() - 1 {
        sum += cross(o, v[k], v[k + 1]);
    }
    0.5 * sum
}

/// The absolute area of a contour.
pub(crate) fn area(v: &[Pt]) -> f64 {
    signed_area(v).abs()
}

/// The contour with positive signed area (reversed if need be).
pub(crate) fn positive(mut v: Contour) -> Contour {
    if signed_area(&v) < 0.0 {
        v.reverse();
    }
    v
}
