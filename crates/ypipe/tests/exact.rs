//! The exact reference against itself and against geometry: coverage sums to area,
//! the box filter with intensity 1 is the coverage (two independent methods), linear
//! intensities integrate to area × centroid value, clipping keeps exact areas.

use cwisim_scene::{Polygon, ScreenScene};
use cwisim_ypipe::clip::clip_to_rect;
use cwisim_ypipe::exact::{
    box_filtered, box_filtered_subdivided, coverage, gouraud_at, polygon_area, scene_box_filtered,
    scene_coverage,
};
use proptest::prelude::*;
use std::time::Instant;

const W: u32 = 24;
const H: u32 = 18;

fn grey(v: Vec<[f64; 2]>) -> Polygon {
    Polygon::uniform(v, &[1.0])
}

/// A polygon whose intensity is the linear function `f` of each vertex (one per channel).
fn linear(v: Vec<[f64; 2]>, f: &[[f64; 3]]) -> Polygon {
    let i = v
        .iter()
        .map(|p| f.iter().map(|c| c[0] + c[1] * p[0] + c[2] * p[1]).collect())
        .collect::<Vec<Vec<f64>>>();
    Polygon::new(v, i)
}

fn reversed(p: &Polygon) -> Polygon {
    let mut q = p.clone();
    q.vertices.reverse();
    q.intensity.reverse();
    q
}

fn sum(v: &[f64]) -> f64 {
    v.iter().sum()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A star-shaped (so simple), possibly concave polygon around a centre.
fn star(cx: f64, cy: f64, radii: &[f64], phase: f64, reverse: bool) -> Vec<[f64; 2]> {
    let n = radii.len();
    let mut v: Vec<[f64; 2]> = radii
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
            [cx + r * a.cos(), cy + r * a.sin()]
        })
        .collect();
    if reverse {
        v.reverse();
    }
    v
}

fn point(lo: f64, hi: f64) -> impl Strategy<Value = [f64; 2]> {
    (lo..hi, lo..hi).prop_map(|(x, y)| [x, y])
}

/// Triangles within the image.
fn inner_triangle() -> impl Strategy<Value = Vec<[f64; 2]>> {
    (
        point(0.0, f64::from(H)),
        point(0.0, f64::from(H)),
        point(0.0, f64::from(H)),
    )
        .prop_map(|(a, b, c)| vec![a, b, c])
}

/// Triangles that may reach outside the image.
fn any_triangle() -> impl Strategy<Value = Vec<[f64; 2]>> {
    (point(-10.0, 34.0), point(-10.0, 34.0), point(-10.0, 34.0)).prop_map(|(a, b, c)| vec![a, b, c])
}

fn any_star(inside: bool) -> impl Strategy<Value = Vec<[f64; 2]>> {
    let r = if inside { 0.2..8.0 } else { 0.2..20.0 };
    (
        prop::collection::vec(r, 3..14),
        0.0..1.0f64,
        any::<bool>(),
        point(8.5, 9.5),
    )
        .prop_map(|(radii, phase, rev, c)| star(c[0] + 3.0, c[1], &radii, phase, rev))
}

/// Per-pixel coverage of `v` summed, against its area, relative 1e-9.
fn sums_to_area(v: Vec<[f64; 2]>) -> Result<(), TestCaseError> {
    let p = grey(v);
    let area = polygon_area(&p);
    let total = sum(&coverage(&p, W, H));
    prop_assert!(
        (total - area).abs() <= 1e-9 * area.max(1e-3),
        "coverage {total}, area {area}"
    );
    Ok(())
}

/// Box filter with intensity 1 against coverage, per pixel, 1e-12.
fn box_is_coverage(v: Vec<[f64; 2]>) -> Result<(), TestCaseError> {
    let p = grey(v);
    let c = coverage(&p, W, H);
    let b = box_filtered(&p, W, H, 1);
    let d = max_diff(&c, &b);
    prop_assert!(d <= 1e-12, "largest per-pixel difference {d}");
    Ok(())
}

#[test]
fn pixel_aligned_rectangles() {
    let p = grey(vec![[2.0, 1.0], [5.0, 1.0], [5.0, 3.0], [2.0, 3.0]]);
    let c = coverage(&p, 8, 6);
    for j in 0..6 {
        for i in 0..8 {
            let inside = (2..5).contains(&i) && (1..3).contains(&j);
            assert_eq!(c[j * 8 + i], if inside { 1.0 } else { 0.0 }, "({i}, {j})");
        }
    }
    assert_eq!(box_filtered(&p, 8, 6, 1), c);
    // offset by fractions: the border pixels hold the exact fractions
    let p = grey(vec![[2.5, 1.0], [5.25, 1.0], [5.25, 3.5], [2.5, 3.5]]);
    let c = coverage(&p, 8, 6);
    assert_eq!(c[8 + 2], 0.5);
    assert_eq!(c[8 + 3], 1.0);
    assert_eq!(c[8 + 5], 0.25);
    assert_eq!(c[3 * 8 + 2], 0.25);
    assert_eq!(c[3 * 8 + 5], 0.125);
    assert_eq!(sum(&c), 2.75 * 2.5);
}

#[test]
fn a_triangle_in_one_pixel_row() {
    // the fixture of DO_FILL case 1: a thin triangle inside one pixel
    let p = grey(vec![[2.25, 0.0], [2.75, 0.0], [2.5, 1.0]]);
    let c = coverage(&p, 16, 1);
    assert!((c[2] - 0.25).abs() < 1e-15);
    assert_eq!(sum(&c), c[2]);
}

#[test]
fn far_outside_is_zero_and_quick() {
    let t = Instant::now();
    for (dx, dy) in [
        (1e14, 0.0),
        (-1e14, 0.0),
        (0.0, 1e14),
        (0.0, -1e14),
        (-5e14, -5e14),
    ] {
        let v = vec![
            [dx - 1e13, dy - 1e13],
            [dx + 1e13, dy - 1e13],
            [dx, dy + 1e13],
        ];
        let p = grey(v);
        assert!(coverage(&p, 1024, 1024).iter().all(|&c| c == 0.0));
        assert!(box_filtered(&p, 1024, 1024, 1).iter().all(|&c| c == 0.0));
    }
    // just beside the image
    let p = grey(vec![[-3.0, 0.0], [0.0, 0.0], [-1.0, 50.0]]);
    assert!(coverage(&p, W, H).iter().all(|&c| c == 0.0));
    assert!(box_filtered(&p, W, H, 1).iter().all(|&c| c == 0.0));
    let elapsed = t.elapsed().as_secs_f64();
    assert!(elapsed < 5.0, "took {elapsed} s (allocation only expected)");
}

#[test]
fn huge_polygons_cover_the_image_exactly() {
    let square = grey(vec![
        [-1e12, -1e12],
        [1e12, -1e12],
        [1e12, 1e12],
        [-1e12, 1e12],
    ]);
    let triangle = grey(vec![[-1e12, -1e12], [1e12, 3e11], [-3e11, 1e12]]);
    for p in [square, triangle] {
        for q in [p.clone(), reversed(&p)] {
            assert!(coverage(&q, W, H).iter().all(|&c| c == 1.0));
            let b = box_filtered(&q, W, H, 1);
            assert!(b.iter().all(|&c| (c - 1.0).abs() < 1e-14), "{b:?}");
        }
    }
    // the overflow-safe path: differences beyond f64::MAX
    let p = grey(vec![
        [-1e308, -1e308],
        [1e308, -1e308],
        [1e308, 1e308],
        [-1e308, 1e308],
    ]);
    assert!(coverage(&p, 4, 3).iter().all(|&c| c == 1.0));
    assert!(box_filtered(&p, 4, 3, 1)
        .iter()
        .all(|&c| (c - 1.0).abs() < 1e-14));
}

#[test]
fn orientation_does_not_matter() {
    let v = star(10.0, 9.0, &[6.0, 2.0, 7.5, 3.0, 8.0, 1.5, 5.0], 0.3, false);
    let p = linear(v, &[[0.5, 0.1, -0.05]]);
    let q = reversed(&p);
    assert!(max_diff(&coverage(&p, W, H), &coverage(&q, W, H)) < 1e-14);
    assert!(max_diff(&box_filtered(&p, W, H, 1), &box_filtered(&q, W, H, 1)) < 1e-13);
}

#[test]
fn linear_intensity_in_several_channels() {
    // a concave polygon with a planar intensity per channel
    let v = vec![
        [1.0, 1.0],
        [20.0, 2.0],
        [9.0, 6.5],
        [18.0, 16.0],
        [2.5, 14.0],
    ];
    let f = [[1.0, 0.0, 0.0], [0.25, 0.5, -0.125], [-2.0, 0.0625, 0.25]];
    let p = linear(v.clone(), &f);
    let b = box_filtered(&p, W, H, 3);
    assert_eq!(b.len(), (W * H * 3) as usize);
    // ∫ (a + b x + c y) = a A + b Mx + c My, by the polygon's moments
    let (mut a2, mut mx, mut my) = (0.0, 0.0, 0.0);
    for k in 0..v.len() {
        let (p0, p1) = (v[k], v[(k + 1) % v.len()]);
        let cross = p0[0] * p1[1] - p1[0] * p0[1];
        a2 += cross;
        mx += (p0[0] + p1[0]) * cross;
        my += (p0[1] + p1[1]) * cross;
    }
    let (area, mx, my) = (a2 / 2.0, mx / 6.0, my / 6.0);
    for (c, fc) in f.iter().enumerate() {
        let total: f64 = b.iter().skip(c).step_by(3).sum();
        let want = fc[0] * area + fc[1] * mx + fc[2] * my;
        assert!(
            (total - want).abs() < 1e-10 * want.abs().max(1.0),
            "channel {c}: {total} vs {want}"
        );
    }
    // channel 0 is intensity 1: the coverage
    let c0: Vec<f64> = b.iter().step_by(3).copied().collect();
    assert!(max_diff(&c0, &coverage(&p, W, H)) < 1e-12);
}

#[test]
fn scene_sums_add_the_polygons() {
    let a = linear(vec![[1.0, 1.0], [9.0, 2.0], [3.0, 8.0]], &[[1.0, 0.0, 0.0]]);
    let b = linear(
        vec![[5.0, 5.0], [20.0, 3.0], [12.0, 17.0]],
        &[[0.5, 0.01, 0.0]],
    );
    let s = ScreenScene {
        width: W,
        height: H,
        channels: 1,
        polygons: vec![a.clone(), b.clone()],
    };
    let c = scene_coverage(&s);
    let (ca, cb) = (coverage(&a, W, H), coverage(&b, W, H));
    assert!(c
        .iter()
        .zip(ca.iter().zip(&cb))
        .all(|(s, (x, y))| *s == x + y));
    let f = scene_box_filtered(&s);
    let (fa, fb) = (box_filtered(&a, W, H, 1), box_filtered(&b, W, H, 1));
    assert!(f
        .iter()
        .zip(fa.iter().zip(&fb))
        .all(|(s, (x, y))| *s == x + y));
}

/// Strongly non-planar polygons (saddles of intensities; concave, and with narrow necks):
/// `box_filtered` against 64-fold finer Gauss–Legendre sub-bands, and a few pixels
/// against brute-force sampling of `gouraud_at`.
#[test]
fn non_planar_quadrature_accuracy() {
    let quads = [
        vec![[1.3, 1.1], [21.7, 3.4], [17.2, 16.6], [2.9, 12.3]],
        vec![
            [2.0, 2.0],
            [22.0, 1.0],
            [8.0, 6.0],
            [20.0, 17.0],
            [1.0, 15.5],
        ],
        vec![[-4.0, 3.0], [30.0, -2.0], [26.0, 22.0], [-2.0, 14.0]],
        // an hourglass with a narrow neck: the span's width nearly vanishes
        vec![
            [2.0, 2.0],
            [20.0, 2.0],
            [11.01, 9.0],
            [20.0, 16.0],
            [2.0, 16.0],
            [10.99, 9.0],
        ],
        vec![
            [2.0, 2.0],
            [20.0, 2.0],
            [11.3, 9.0],
            [20.0, 16.0],
            [2.0, 16.0],
            [10.7, 9.0],
        ],
        // an asymmetric neck around a column boundary: the span's interpolation has a
        // pole just beyond the band
        vec![
            [2.0, 2.0],
            [22.0, 2.0],
            [11.02, 9.0],
            [22.0, 16.0],
            [2.0, 16.0],
            [10.98, 9.0],
        ],
        vec![
            [2.0, 2.0],
            [22.0, 2.0],
            [11.0002, 9.0],
            [22.0, 16.0],
            [2.0, 16.0],
            [10.9999, 9.0],
        ],
    ];
    let mut worst = 0.0f64;
    for v in quads {
        let n = v.len();
        let i: Vec<Vec<f64>> = (0..n)
            .map(|k| vec![if k % 2 == 0 { 0.0 } else { 1.0 }, k as f64])
            .collect();
        let p = Polygon::new(v, i);
        let coarse = box_filtered(&p, W, H, 2);
        let fine = box_filtered_subdivided(&p, W, H, 2, 64);
        worst = worst.max(max_diff(&coarse, &fine));
        // brute force on a few pixels: midpoint rule over a 200×200 grid per pixel
        let q = clip_to_rect(&p, 0.0, 0.0, f64::from(W), f64::from(H));
        for (pi, pj) in [(5usize, 5usize), (10, 8), (3, 12), (0, 4)] {
            let m = 200;
            let mut acc = [0.0; 2];
            for a in 0..m {
                for b in 0..m {
                    let x = pi as f64 + (a as f64 + 0.5) / m as f64;
                    let y = pj as f64 + (b as f64 + 0.5) / m as f64;
                    if let Some(g) = gouraud_at(&q, x, y) {
                        acc[0] += g[0];
                        acc[1] += g[1];
                    }
                }
            }
            for c in 0..2 {
                let brute = acc[c] / (m * m) as f64;
                let exact = coarse[(pj * W as usize + pi) * 2 + c];
                assert!(
                    (brute - exact).abs() < 2e-3,
                    "pixel ({pi}, {pj}) channel {c}: {brute} vs {exact}"
                );
            }
        }
    }
    eprintln!(
        "non-planar quadrature: largest relative difference from 64-fold subdivision {worst:e}"
    );
    assert!(worst < 1e-12, "{worst:e}");
}

#[test]
fn gouraud_of_a_non_planar_quad_is_bilinear_along_scanlines() {
    // a trapezium, intensity 1 at the bottom-right corner only: at height y the span is
    // [0, 4 + y] from 0 to y/4, so I = x y / (4 (4 + y)), not bilinear
    let p = Polygon::new(
        vec![[0.0, 0.0], [4.0, 0.0], [8.0, 4.0], [0.0, 4.0]],
        vec![vec![0.0], vec![0.0], vec![1.0], vec![0.0]],
    );
    assert_eq!(gouraud_at(&p, 0.0, 2.0), Some(vec![0.0]));
    assert_eq!(gouraud_at(&p, 3.0, 2.0), Some(vec![0.25]));
    assert_eq!(gouraud_at(&p, 6.0, 2.0), Some(vec![0.5]));
    assert_eq!(gouraud_at(&p, 7.0, 2.0), None);
    assert_eq!(
        gouraud_at(&p, 2.0, 4.0),
        None,
        "half-open: the bottom edge's y is outside"
    );
    // clipping in y does not change the function; clipping in x does
    let y_clipped = clip_to_rect(&p, -10.0, 1.0, 10.0, 3.0);
    assert_eq!(gouraud_at(&y_clipped, 3.0, 2.0), Some(vec![0.25]));
    // x ≥ 1: the new left edge runs from 0 at (1, 0) to 1/8 at (1, 4); at y = 2 the span
    // [1, 6] goes from 1/16 to 1/2, so at x = 2 it is 0.15, not 1/6
    let x_clipped = clip_to_rect(&p, 1.0, -10.0, 10.0, 10.0);
    let g = gouraud_at(&x_clipped, 2.0, 2.0).unwrap()[0];
    assert!((g - 0.15).abs() < 1e-15, "{g}");
    assert!((gouraud_at(&p, 2.0, 2.0).unwrap()[0] - 1.0 / 6.0).abs() < 1e-15);
}

#[test]
fn clipping_to_pixel_aligned_rects_matches_coverage() {
    let v = star(
        11.0,
        8.0,
        &[6.0, 2.0, 9.0, 3.0, 8.0, 1.5, 5.0, 4.0],
        0.1,
        true,
    );
    let p = grey(v);
    let c = coverage(&p, W, H);
    for (x0, y0, x1, y1) in [(0, 0, W, H), (3, 2, 9, 11), (10, 0, 24, 7), (5, 5, 6, 6)] {
        let q = clip_to_rect(&p, x0 as f64, y0 as f64, x1 as f64, y1 as f64);
        let mut want = 0.0;
        for j in y0..y1 {
            for i in x0..x1 {
                want += c[(j * W + i) as usize];
            }
        }
        let got = polygon_area(&q);
        assert!(
            (got - want).abs() < 1e-12 * want.max(1.0),
            "{got} vs {want}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn triangle_coverage_sums_to_area(v in inner_triangle()) {
        sums_to_area(v)?;
    }

    #[test]
    fn concave_coverage_sums_to_area(v in any_star(true)) {
        sums_to_area(v)?;
    }

    #[test]
    fn box_filter_of_one_is_coverage_triangles(v in any_triangle()) {
        box_is_coverage(v)?;
    }

    #[test]
    fn box_filter_of_one_is_coverage_concave(v in any_star(false)) {
        box_is_coverage(v)?;
    }

    /// ∑ box_filtered = area × I(centroid) for a triangle with a linear intensity.
    #[test]
    fn linear_triangles_integrate_to_the_centroid_value(
        v in inner_triangle(),
        f in (-2.0..2.0f64, -0.2..0.2f64, -0.2..0.2f64),
    ) {
        let p = linear(v.clone(), &[[f.0, f.1, f.2]]);
        let area = polygon_area(&p);
        let centroid = [(v[0][0] + v[1][0] + v[2][0]) / 3.0, (v[0][1] + v[1][1] + v[2][1]) / 3.0];
        let want = area * (f.0 + f.1 * centroid[0] + f.2 * centroid[1]);
        let got = sum(&box_filtered(&p, W, H, 1));
        let scale = area * (f.0.abs() + 24.0 * (f.1.abs() + f.2.abs())).max(1e-3);
        prop_assert!((got - want).abs() <= 1e-10 * scale.max(1e-6), "{got} vs {want}");
    }

    /// The scanline Gouraud intensity of a triangle is the linear (barycentric) one.
    #[test]
    fn gouraud_of_triangles_is_barycentric(
        v in any_triangle(),
        i in prop::collection::vec(-5.0..5.0f64, 3),
        (s, t) in (0.0..1.0f64, 0.0..1.0f64),
    ) {
        let (a, b, c) = (v[0], v[1], v[2]);
        let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        prop_assume!(det.abs() > 1e-3);
        // a point strictly inside, by barycentric weights
        let (s, t) = if s + t > 1.0 { (1.0 - s, 1.0 - t) } else { (s, t) };
        prop_assume!(s > 1e-6 && t > 1e-6 && s + t < 1.0 - 1e-6);
        let x = a[0] + s * (b[0] - a[0]) + t * (c[0] - a[0]);
        let y = a[1] + s * (b[1] - a[1]) + t * (c[1] - a[1]);
        let want = i[0] + s * (i[1] - i[0]) + t * (i[2] - i[0]);
        let p = Polygon::new(v.clone(), i.iter().map(|&k| vec![k]).collect());
        let got = gouraud_at(&p, x, y).expect("inside");
        prop_assert!((got[0] - want).abs() < 1e-9, "{} vs {want}", got[0]);
        // and through image clipping, when the point is in the image
        if (0.0..f64::from(W)).contains(&x) && (0.0..f64::from(H)).contains(&y) {
            let q = clip_to_rect(&p, 0.0, 0.0, f64::from(W), f64::from(H));
            if let Some(g) = gouraud_at(&q, x, y) {
                prop_assert!((g[0] - want).abs() < 1e-9, "clipped: {} vs {want}", g[0]);
            }
        }
    }

    /// Two triangles sharing an edge (either orientation each) add up to their union.
    #[test]
    fn shared_edges_add_up(
        v in (point(-6.0, 30.0), point(-6.0, 30.0), point(-6.0, 30.0), point(-6.0, 30.0)),
        flip in any::<(bool, bool)>(),
    ) {
        let (a, b, c, d) = v;
        // a convex quad a b c d (skip others): split along a–c
        let turn = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
        let turns = [turn(a, b, c), turn(b, c, d), turn(c, d, a), turn(d, a, b)];
        prop_assume!(turns.iter().all(|&t| t > 1e-2) || turns.iter().all(|&t| t < -1e-2));
        let mut t1 = grey(vec![a, b, c]);
        let mut t2 = grey(vec![a, c, d]);
        if flip.0 { t1 = reversed(&t1); }
        if flip.1 { t2 = reversed(&t2); }
        let quad = grey(vec![a, b, c, d]);
        let union = coverage(&quad, W, H);
        let (c1, c2) = (coverage(&t1, W, H), coverage(&t2, W, H));
        let parts: Vec<f64> = c1.iter().zip(&c2).map(|(x, y)| x + y).collect();
        prop_assert!(max_diff(&parts, &union) < 1e-12);
        let (b1, b2) = (box_filtered(&t1, W, H, 1), box_filtered(&t2, W, H, 1));
        let parts: Vec<f64> = b1.iter().zip(&b2).map(|(x, y)| x + y).collect();
        prop_assert!(max_diff(&parts, &union) < 1e-12);
    }

    /// Clipping keeps exactly the area inside: the nine regions cut by a rectangle's
    /// lines (outer ones unbounded) share out the polygon's area.
    #[test]
    fn clipping_partitions_the_area(
        v in any_star(false),
        r in (2.0..10.0f64, 2.0..10.0f64, 12.0..22.0f64, 11.0..16.0f64),
    ) {
        let p = grey(v);
        let (x0, y0, x1, y1) = r;
        let inf = f64::INFINITY;
        let xs = [(-inf, x0), (x0, x1), (x1, inf)];
        let ys = [(-inf, y0), (y0, y1), (y1, inf)];
        let mut total = 0.0;
        for &(ya, yb) in &ys {
            for &(xa, xb) in &xs {
                let q = clip_to_rect(&p, xa, ya, xb, yb);
                total += polygon_area(&q);
                for v in &q.vertices {
                    prop_assert!(xa <= v[0] && v[0] <= xb && ya <= v[1] && v[1] <= yb);
                }
            }
        }
        let area = polygon_area(&p);
        prop_assert!((total - area).abs() <= 1e-12 * area, "{total} vs {area}");
        // the middle region against the pixel coverage when its bounds are integers
        let (x0, y0, x1, y1) = (x0.floor(), y0.floor(), x1.floor(), y1.floor());
        let inner = polygon_area(&clip_to_rect(&p, x0, y0, x1, y1));
        let c = coverage(&p, W, H);
        let mut want = 0.0;
        for j in y0 as usize..y1 as usize {
            for i in x0 as usize..x1 as usize {
                want += c[j * W as usize + i];
            }
        }
        prop_assert!((inner - want).abs() <= 1e-12 * area.max(1.0), "{inner} vs {want}");
    }
}
