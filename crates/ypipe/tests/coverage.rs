//! The box-filter coverage the Y-processor emits, executed on the array, against the
//! exact reference: random polygons, shared edges, and the extremes.

mod common;

use common::render;
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_ypipe::exact::{polygon_area, scene_coverage};
use cwisim_ypipe::{emit, header, Options};
use proptest::prelude::*;

fn grey(vertices: Vec<[f64; 2]>) -> Polygon {
    let n = vertices.len();
    Polygon {
        vertices,
        intensity: vec![vec![1.0].into(); n],
        depth: None,
    }
}

fn scene(width: u32, height: u32, polygons: Vec<Polygon>) -> ScreenScene {
    ScreenScene {
        width,
        height,
        channels: 1,
        polygons,
    }
}

/// Per-pixel coverage (intensity 1) from the array against the exact reference.
fn check_coverage(s: &ScreenScene) -> Result<(), TestCaseError> {
    let (img, _) = render(s, &Options::default());
    let exact = scene_coverage(s);
    for (k, (a, b)) in img.iter().zip(&exact).enumerate() {
        prop_assert!(
            (a - b).abs() <= 1e-9,
            "pixel ({}, {}): simulated {a}, exact {b}",
            k % s.width as usize,
            k / s.width as usize
        );
    }
    Ok(())
}

/// A star-shaped (so simple), possibly concave polygon around a centre.
fn star(cx: f64, cy: f64, radii: Vec<f64>, phase: f64, reverse: bool) -> Vec<[f64; 2]> {
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

fn coordinate(limit: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -2.0..limit + 2.0,
        // on pixel edges and centres
        1 => (-2i32..(limit as i32 + 2)).prop_map(f64::from),
        1 => (-2i32..(limit as i32 + 2)).prop_map(|v| f64::from(v) + 0.5),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn triangles_match_the_exact_area(v in proptest::collection::vec((coordinate(24.0), coordinate(16.0)), 3)) {
        let verts: Vec<[f64; 2]> = v.into_iter().map(|(x, y)| [x, y]).collect();
        check_coverage(&scene(24, 16, vec![grey(verts)]))?;
    }

    #[test]
    fn concave_polygons_match_the_exact_area(
        cx in 4.0f64..20.0, cy in 4.0f64..12.0,
        radii in proptest::collection::vec(0.5f64..9.0, 3..12),
        phase in 0.0f64..6.3, reverse in any::<bool>(),
    ) {
        let s = scene(24, 16, vec![grey(star(cx, cy, radii, phase, reverse))]);
        check_coverage(&s)?;
        let (img, _) = render(&s, &Options::default());
        let total: f64 = img.iter().sum();
        let area: f64 = scene_coverage(&s).iter().sum();
        prop_assert!((total - area).abs() <= 1e-9 * area.max(1.0));
    }

    #[test]
    fn two_triangles_sharing_an_edge_cover_exactly_once(
        a in (coordinate(20.0), coordinate(12.0)), b in (coordinate(20.0), coordinate(12.0)),
        c in (coordinate(20.0), coordinate(12.0)), d in (coordinate(20.0), coordinate(12.0)),
    ) {
        // a quad a-b-c-d split along a-c (when it is convex the halves tile it)
        let quad = [[a.0, a.1], [b.0, b.1], [c.0, c.1], [d.0, d.1]];
        let cross = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
        let signs: Vec<bool> = (0..4).map(|k| cross(quad[k], quad[(k + 1) % 4], quad[(k + 2) % 4]) > 1e-3).collect();
        prop_assume!(signs.iter().all(|s| *s) || signs.iter().all(|s| !*s));
        prop_assume!((0..4).all(|k| cross(quad[k], quad[(k + 1) % 4], quad[(k + 2) % 4]).abs() > 1e-3));
        let halves = scene(20, 12, vec![grey(vec![quad[0], quad[1], quad[2]]), grey(vec![quad[0], quad[2], quad[3]])]);
        let whole = scene(20, 12, vec![grey(quad.to_vec())]);
        let (h, _) = render(&halves, &Options::default());
        let w = scene_coverage(&whole);
        for (x, y) in h.iter().zip(&w) {
            prop_assert!((x - y).abs() <= 1e-9, "halves {x} vs whole {y}");
            prop_assert!(*x <= 1.0 + 1e-9, "more than full coverage: {x}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(100))]

    /// The report's approximation (coverage × intensity at the pixel centre) is off the
    /// true box filter by at most |grad I| × (distance between the sample point and the
    /// covered part's centroid, both inside the pixel: at most √2) × coverage.
    #[test]
    fn the_gouraud_approximation_stays_within_its_bound(
        v in proptest::collection::vec((0.0f64..24.0, 0.0f64..16.0), 3),
        i in proptest::collection::vec(0.0f64..1.0, 3),
    ) {
        let verts: Vec<[f64; 2]> = v.iter().map(|&(x, y)| [x, y]).collect();
        let det = (verts[1][0] - verts[0][0]) * (verts[2][1] - verts[0][1]) - (verts[2][0] - verts[0][0]) * (verts[1][1] - verts[0][1]);
        prop_assume!(det.abs() > 1e-3);
        // the plane's gradient
        let gx = ((i[1] - i[0]) * (verts[2][1] - verts[0][1]) - (i[2] - i[0]) * (verts[1][1] - verts[0][1])) / det;
        let gy = ((i[2] - i[0]) * (verts[1][0] - verts[0][0]) - (i[1] - i[0]) * (verts[2][0] - verts[0][0])) / det;
        let grad = gx.hypot(gy);
        let p = Polygon { vertices: verts, intensity: i.iter().map(|x| vec![*x].into()).collect(), depth: None };
        let s = scene(24, 16, vec![p]);
        let centre = Options { aa: cwisim_ypipe::Antialias::BoxCentre, ..Options::default() };
        let (img, _) = render(&s, &centre);
        let exact = cwisim_ypipe::exact::scene_box_filtered(&s);
        let cover = scene_coverage(&s);
        for k in 0..img.len() {
            let bound = grad * std::f64::consts::SQRT_2 * cover[k] + 1e-9;
            prop_assert!((img[k] - exact[k]).abs() <= bound, "pixel {k}: {} vs {} (bound {bound})", img[k], exact[k]);
        }
    }
}

#[test]
fn a_unit_square_split_on_its_diagonal_is_exactly_full() {
    let s = scene(
        8,
        8,
        vec![
            grey(vec![[1.0, 1.0], [7.0, 1.0], [7.0, 7.0]]),
            grey(vec![[1.0, 1.0], [7.0, 7.0], [1.0, 7.0]]),
        ],
    );
    let (img, _) = render(&s, &Options::default());
    for y in 1..7 {
        for x in 1..7 {
            assert!(
                (img[y * 8 + x] - 1.0).abs() < 1e-12,
                "({x}, {y}) = {}",
                img[y * 8 + x]
            );
        }
    }
}

/// The extremes: slivers, steep and flat slopes, tiny polygons, far coordinates.
#[test]
fn extremes_match_the_exact_area() {
    let cases: Vec<(&str, ScreenScene)> = vec![
        (
            "sliver 1e-7 thick",
            scene(
                32,
                8,
                vec![grey(vec![[0.5, 1.0], [30.0, 6.0], [30.0, 6.0000001]])],
            ),
        ),
        (
            "vertical sliver",
            scene(
                8,
                32,
                vec![grey(vec![
                    [3.3, 0.5],
                    [3.3000001, 0.5],
                    [3.3000001, 30.0],
                    [3.3, 30.0],
                ])],
            ),
        ),
        (
            "slope 1e6",
            scene(
                16,
                8,
                vec![grey(vec![[2.0, 1.0], [2.000001, 7.0], [9.0, 7.0]])],
            ),
        ),
        (
            "slope 1e-6",
            scene(
                64,
                8,
                vec![grey(vec![
                    [0.0, 3.0],
                    [63.0, 3.000063],
                    [63.0, 5.0],
                    [0.0, 5.0],
                ])],
            ),
        ),
        (
            "smaller than a pixel",
            scene(8, 8, vec![grey(vec![[3.2, 3.1], [3.7, 3.4], [3.3, 3.9]])]),
        ),
        (
            "inside one row",
            scene(
                16,
                4,
                vec![grey(vec![[1.5, 2.1], [12.25, 2.3], [7.0, 2.9]])],
            ),
        ),
        (
            "vertices on pixel centres",
            scene(
                16,
                16,
                vec![grey(vec![[2.5, 2.5], [12.5, 4.5], [6.5, 13.5]])],
            ),
        ),
        (
            "vertices on pixel corners",
            scene(
                16,
                16,
                vec![grey(vec![[2.0, 2.0], [12.0, 4.0], [6.0, 13.0]])],
            ),
        ),
        (
            "coordinates up to 65536",
            scene(
                32,
                32,
                vec![grey(vec![
                    [-65536.0, -3.0],
                    [65536.0, 10.5],
                    [5.0, 65536.0],
                ])],
            ),
        ),
        (
            "far outside",
            scene(
                16,
                16,
                vec![grey(vec![
                    [60000.0, 60000.0],
                    [65536.0, 60000.0],
                    [62000.0, 65536.0],
                ])],
            ),
        ),
        (
            "covering the image",
            scene(
                16,
                16,
                vec![grey(vec![[-1e6, -1e6], [1e6, -1e6], [0.0, 1e6]])],
            ),
        ),
        (
            "a 4096-wide span",
            scene(
                4096,
                3,
                vec![grey(vec![
                    [0.25, 0.5],
                    [4095.75, 0.75],
                    [4095.5, 2.5],
                    [0.5, 2.25],
                ])],
            ),
        ),
    ];
    for (name, s) in cases {
        let (img, _) = render(&s, &Options::default());
        let exact = scene_coverage(&s);
        let worst = img
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-9,
            "{name}: worst per-pixel difference {worst:e}"
        );
        assert!(
            img.iter().all(|v| v.is_finite()),
            "{name}: non-finite output"
        );
    }
}

#[test]
fn total_coverage_is_the_polygon_area() {
    let p = grey(vec![
        [1.25, 0.75],
        [14.5, 2.0],
        [11.0, 9.5],
        [6.0, 5.0],
        [2.0, 9.0],
    ]);
    let area = polygon_area(&p);
    let (img, _) = render(&scene(16, 10, vec![p]), &Options::default());
    let total: f64 = img.iter().sum();
    assert!((total - area).abs() < 1e-9, "{total} vs {area}");
}

/// Nothing is emitted for pixels the polygon does not reach, and every instruction stays
/// inside the array (EngineWriter rejects any that does not).
#[test]
fn nothing_outside_the_polygons_pixels() {
    struct Spans(Vec<(u32, u32)>);
    impl cwisim_isa::TraceWrite for Spans {
        fn write(&mut self, i: &cwisim_isa::Instruction) -> std::io::Result<()> {
            assert!((0..3).flat_map(|s| i.value(s)).all(|v| v.is_finite()));
            if let Some(span) = i.span() {
                self.0.push(span);
            } else {
                self.0.push((u32::MAX, u32::MAX)); // Refresh: next row
            }
            Ok(())
        }
        fn finish(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let s = scene(
        24,
        16,
        vec![grey(star(
            12.0,
            8.0,
            vec![7.0, 2.0, 6.5, 1.5, 7.5, 3.0, 5.0],
            0.3,
            false,
        ))],
    );
    let exact = scene_coverage(&s);
    let mut spans = Spans(Vec::new());
    emit(&s, &Options::default(), &mut spans).unwrap();
    let mut row = 0usize;
    for (x0, x1) in spans.0 {
        if x0 == u32::MAX {
            row += 1;
            continue;
        }
        for x in x0..x1 {
            assert!(
                exact[row * 24 + x as usize] > 0.0,
                "pixel ({x}, {row}) is outside the polygon"
            );
        }
    }
    assert_eq!(row, 16);
    let _ = header(&s);
}

/// Random polygons of every size reach every one of the twelve DO_FILL cases.
#[test]
fn random_polygons_reach_all_twelve_cases() {
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut seen = [0u64; 12];
    for _ in 0..300 {
        let scale = [0.8, 3.0, 12.0][(next() * 3.0) as usize % 3];
        let (cx, cy) = (4.0 + next() * 16.0, 2.0 + next() * 12.0);
        let radii: Vec<f64> = (0..3 + (next() * 5.0) as usize)
            .map(|_| scale * (0.2 + next()))
            .collect();
        let polygon = if next() < 0.5 {
            star(cx, cy, radii, next() * 6.3, next() < 0.5)
        } else {
            // a slanted band: two shallow, nearly parallel edges a few pixels apart
            let (w, d, h) = (0.3 + 4.0 * next(), 1.0 + 10.0 * next(), 0.3 + 2.0 * next());
            let skew = (next() - 0.5) * w; // keeps the edges from crossing
            vec![
                [cx - 6.0, cy],
                [cx - 6.0 + w, cy],
                [cx - 6.0 + w + d + skew, cy + h],
                [cx - 6.0 + d, cy + h],
            ]
        };
        let s = scene(24, 16, vec![grey(polygon)]);
        let (_, stats) = render(&s, &Options::default());
        for (k, n) in stats.cases.iter().enumerate() {
            seen[k] += n;
        }
    }
    assert!(seen.iter().all(|n| *n > 0), "cases reached: {seen:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(150))]

    /// Slivers thinner than 1e-6 px at any angle, and edges with slopes up to 1e6.
    #[test]
    fn slivers_and_steep_edges_match_the_exact_area(
        a in (0.0f64..24.0, 0.0f64..16.0),
        b in (0.0f64..24.0, 0.0f64..16.0),
        thickness in prop_oneof![1e-9f64..1e-6, 1e-6f64..1e-3],
        steep in any::<bool>(),
    ) {
        let (a, mut b) = ([a.0, a.1], [b.0, b.1]);
        if steep {
            // |dy/dx| up to 1e6: nearly vertical
            b[0] = a[0] + (b[1] - a[1]) * 1e-6;
        }
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        prop_assume!(len > 1e-3);
        // the third vertex a hair's breadth off the line a-b
        let c = [b[0] - dy / len * thickness, b[1] + dx / len * thickness];
        check_coverage(&scene(24, 16, vec![grey(vec![a, b, c])]))?;
    }
}
