//! Exact clipping of a polygon to an axis-aligned rectangle.
//!
//! [`clip_to_rect`] is Sutherland–Hodgman against the four half-planes, in the order
//! top (`y ≥ y0`), bottom (`y ≤ y1`), left (`x ≥ x0`), right (`x ≤ x1`): y first. Where an
//! edge leaves a half-plane, the new vertex and its intensity vector are interpolated
//! linearly along the edge (`t` measured along the edge).
//!
//! # What clipping does to the Gouraud intensity
//!
//! The scanline Gouraud intensity (van Rij 3.2: linear along each edge in y, then linear
//! across each scanline between its two crossings) is **defined on the polygon clipped to
//! the image**. Clipping in y does not change it: a cut edge is the same line, with the
//! same intensities, and the new horizontal edges cross no scanline. Clipping in x does,
//! when the vertex intensities are not coplanar (not a linear function of x and y): the
//! new vertical edge at `x0` (or `x1`) carries intensities interpolated in y between its
//! two new vertices, where the unclipped polygon would interpolate across the scanline
//! between crossings outside the image. Near the left and right image borders such a
//! polygon is therefore shaded as its clipped self; that is the project's definition. For
//! triangles, and any polygon with coplanar intensities, clipping changes nothing.
//!
//! ```
//! use cwisim_ypipe::clip::clip_to_rect;
//! use cwisim_scene::Polygon;
//! let p = Polygon::new(vec![[-2.0, 0.0], [2.0, 0.0], [2.0, 2.0]], vec![vec![0.0], vec![4.0], vec![8.0]]);
//! let c = clip_to_rect(&p, 0.0, 0.0, 10.0, 10.0);
//! assert_eq!(c.vertices, vec![[0.0, 1.0], [0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]);
//! let i: Vec<f64> = c.intensity.iter().map(|i| i[0]).collect();
//! assert_eq!(i, [4.0, 2.0, 4.0, 8.0]);
//! ```

use cwisim_scene::{Polygon, VertexIntensity};
use std::borrow::Cow;

/// The part of `p` inside the rectangle `[x0, x1] × [y0, y1]`, with intensities
/// interpolated along the cut edges.
///
/// Vertices exactly on the boundary are kept (and no duplicate is made next to them).
/// The result may be degenerate — fewer than 3 vertices, zero area, or zero-width
/// bridges along the boundary where a concave polygon leaves and re-enters — but its
/// signed area is exactly that of `p ∩ rectangle` (up to rounding). Clipping is
/// overflow-safe for any finite coordinates and intensities; a bound may be infinite
/// (that side is not clipped). A cut shared by two polygons (an edge in opposite
/// directions) gives bit-identical vertices in both.
///
/// # Panics
///
/// If `p.intensity.len() != p.vertices.len()`.
pub fn clip_to_rect(p: &Polygon, x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
    clip_to_rect_cow(p, x0, y0, x1, y1).into_owned()
}

/// [`clip_to_rect`] without a copy where nothing is cut: `p` itself, borrowed, when every
/// vertex lies in the rectangle (the common case of a polygon inside the image); the
/// clipped polygon otherwise.
///
/// # Panics
///
/// If `p.intensity.len() != p.vertices.len()`.
pub fn clip_to_rect_cow(p: &Polygon, x0: f64, y0: f64, x1: f64, y1: f64) -> Cow<'_, Polygon> {
    assert_eq!(
        p.intensity.len(),
        p.vertices.len(),
        "clip_to_rect: one intensity vector per vertex"
    );
    let inside = |v: &[f64; 2]| v[0] >= x0 && v[0] <= x1 && v[1] >= y0 && v[1] <= y1;
    if p.vertices.iter().all(inside) {
        return Cow::Borrowed(p);
    }
    let mut q = clip_half(p, 1, y0, true);
    q = clip_half(&q, 1, y1, false);
    q = clip_half(&q, 0, x0, true);
    Cow::Owned(clip_half(&q, 0, x1, false))
}

/// One Sutherland–Hodgman pass: keeps `v[axis] ≥ bound` (`keep_ge`) or `v[axis] ≤ bound`.
fn clip_half(p: &Polygon, axis: usize, bound: f64, keep_ge: bool) -> Polygon {
    let n = p.vertices.len();
    let inside = |v: &[f64; 2]| {
        if keep_ge {
            v[axis] >= bound
        } else {
            v[axis] <= bound
        }
    };
    if p.vertices.iter().all(inside) {
        return p.clone();
    }
    let mut out = Polygon::new(
        Vec::with_capacity(n + 2),
        Vec::<VertexIntensity>::with_capacity(n + 2),
    );
    for k in 0..n {
        let prev = (k + n - 1) % n;
        let (a, b) = (&p.vertices[prev], &p.vertices[k]);
        let (a_in, b_in) = (inside(a), inside(b));
        if a_in != b_in {
            // one endpoint strictly outside; no cut when the inside one is on the bound
            let inner = if a_in { a } else { b };
            if inner[axis] != bound {
                let (v, i) = cut(p, prev, k, axis, bound);
                out.vertices.push(v);
                out.intensity.push(i);
            }
        }
        if b_in {
            out.vertices.push(*b);
            out.intensity.push(p.intensity[k].clone());
        }
    }
    out
}

/// Where edge `ka`–`kb` of `p` meets `v[axis] = bound`, and the intensity there.
/// Measured from the endpoint lower on `axis`, so that both directions of an edge give
/// the same bits.
fn cut(p: &Polygon, ka: usize, kb: usize, axis: usize, bound: f64) -> ([f64; 2], VertexIntensity) {
    let (lo, hi) = if p.vertices[ka][axis] <= p.vertices[kb][axis] {
        (ka, kb)
    } else {
        (kb, ka)
    };
    let (a, b) = (p.vertices[lo], p.vertices[hi]);
    let t = fraction(a[axis], b[axis], bound);
    let mut v = [0.0; 2];
    v[axis] = bound;
    v[1 - axis] = lerp(a[1 - axis], b[1 - axis], t);
    let i = p.intensity[lo]
        .iter()
        .zip(&p.intensity[hi])
        .map(|(&ia, &ib)| lerp(ia, ib, t))
        .collect();
    (v, i)
}

/// `(x - a) / (b - a)` clamped to `[0, 1]`, for `a < b` and `x` between them; the
/// differences are taken of halves when they overflow.
pub(crate) fn fraction(a: f64, b: f64, x: f64) -> f64 {
    let (num, den) = if (b - a).is_finite() && (x - a).is_finite() {
        (x - a, b - a)
    } else {
        (0.5 * x - 0.5 * a, 0.5 * b - 0.5 * a)
    };
    if den > 0.0 {
        (num / den).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// `a + t (b - a)` for `t ∈ [0, 1]`, without overflow for any finite `a` and `b`.
pub(crate) fn lerp(a: f64, b: f64, t: f64) -> f64 {
    let d = b - a;
    if d.is_finite() {
        a + t * d
    } else {
        2.0 * (0.5 * a + t * (0.5 * b - 0.5 * a))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signed_area(v: &[[f64; 2]]) -> f64 {
        let n = v.len();
        (0..n)
            .map(|k| {
                let (a, b) = (v[k], v[(k + 1) % n]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            / 2.0
    }

    fn grey(v: Vec<[f64; 2]>) -> Polygon {
        let n = v.len();
        let i = (0..n).map(|k| vec![k as f64]).collect();
        Polygon::new(v, i)
    }

    #[test]
    fn a_polygon_inside_is_borrowed_and_a_cut_one_is_the_clip() {
        let inside = grey(vec![[0.0, 0.0], [4.0, 0.0], [4.0, 3.0]]);
        assert!(
            matches!(clip_to_rect_cow(&inside, 0.0, 0.0, 4.0, 3.0), Cow::Borrowed(q) if std::ptr::eq(q, &inside))
        );
        // one vertex out on each side in turn: cut, and the same polygon clip_to_rect gives
        for out in [
            [-1.0, 1.0],
            [5.0, 1.0],
            [2.0, -1.0],
            [2.0, 4.0],
            [f64::NAN, 1.0],
        ] {
            let p = grey(vec![[1.0, 1.0], [3.0, 1.0], out]);
            let c = clip_to_rect_cow(&p, 0.0, 0.0, 4.0, 3.0);
            assert!(matches!(c, Cow::Owned(_)), "{out:?}");
            let owned = clip_to_rect(&p, 0.0, 0.0, 4.0, 3.0);
            assert_eq!(format!("{:?}", c.into_owned()), format!("{owned:?}"));
        }
    }

    #[test]
    fn inside_is_unchanged_and_boundary_vertices_are_kept_once() {
        let p = grey(vec![[0.0, 0.0], [4.0, 0.0], [4.0, 3.0]]);
        assert_eq!(clip_to_rect(&p, 0.0, 0.0, 4.0, 3.0), p);
        // a vertex on the bound with its neighbours outside: no duplicates
        let p = grey(vec![[-1.0, 1.0], [0.0, 0.0], [-1.0, -1.0]]);
        let c = clip_to_rect(&p, 0.0, -5.0, 5.0, 5.0);
        assert_eq!(c.vertices, vec![[0.0, 0.0]]);
    }

    #[test]
    fn fully_outside_is_empty() {
        let p = grey(vec![[10.0, 10.0], [12.0, 10.0], [11.0, 12.0]]);
        let c = clip_to_rect(&p, 0.0, 0.0, 5.0, 5.0);
        assert!(c.vertices.is_empty() && c.intensity.is_empty());
    }

    #[test]
    fn huge_coordinates_do_not_overflow() {
        const M: f64 = 1.5e308;
        let p = Polygon::new(
            vec![[-M, -M], [M, -M], [M, M], [-M, M]],
            vec![vec![-M], vec![M], vec![M], vec![-M]],
        );
        let c = clip_to_rect(&p, 0.0, 0.0, 2.0, 1.0);
        assert!(
            (signed_area(&c.vertices).abs() - 2.0).abs() < 1e-12,
            "{c:?}"
        );
        for (v, i) in c.vertices.iter().zip(&c.intensity) {
            assert!(v.iter().all(|x| x.is_finite()) && i[0].is_finite(), "{c:?}");
        }
        // a diagonal edge from -M to +M (its differences overflow) through the corner
        let p = grey(vec![[-M, -M], [M, M], [-M, M]]);
        let c = clip_to_rect(&p, 0.0, 0.0, 1.0, 1.0);
        assert!(
            (signed_area(&c.vertices).abs() - 0.5).abs() < 1e-12,
            "{c:?}"
        );
    }

    #[test]
    fn shared_cuts_are_bit_identical() {
        let a = grey(vec![[-0.3, 0.1], [1.7, 2.9], [-1.0, 2.0]]);
        let b = grey(vec![[1.7, 2.9], [-0.3, 0.1], [3.0, 0.5]]);
        let ca = clip_to_rect(&a, 0.0, 0.0, 1.0, 1.0);
        let cb = clip_to_rect(&b, 0.0, 0.0, 1.0, 1.0);
        let on_edge: Vec<_> = ca
            .vertices
            .iter()
            .filter(|v| cb.vertices.contains(v))
            .collect();
        assert_eq!(on_edge.len(), 2, "{ca:?} {cb:?}");
    }

    #[test]
    fn intensities_follow_the_edge() {
        // an edge from (−1, 0) I=0 to (3, 4) I=8 cut at x = 0 (t = 1/4) and y = 2 (t = 1/2)
        let p = Polygon::new(
            vec![[-1.0, 0.0], [3.0, 4.0], [-1.0, 4.0]],
            vec![vec![0.0, 1.0], vec![8.0, 1.0], vec![0.0, 1.0]],
        );
        let c = clip_to_rect(&p, 0.0, -10.0, 10.0, 2.0);
        let k = c
            .vertices
            .iter()
            .position(|v| *v == [0.0, 1.0])
            .expect("x-cut");
        assert_eq!(c.intensity[k].as_slice(), [2.0, 1.0]);
        let k = c
            .vertices
            .iter()
            .position(|v| *v == [1.0, 2.0])
            .expect("y-cut");
        assert_eq!(c.intensity[k].as_slice(), [4.0, 1.0]);
    }
}
