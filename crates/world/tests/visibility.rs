//! Exact visible fragments, checked against references that share no code with
//! `visibility.rs`: exact per-pixel coverage (`cwisim_ypipe::exact`), areas by
//! inclusion–exclusion over convex intersections (clipped here), the scene validator's
//! exact simplicity test, and brute-force depth tests at sample points.

use cwisim_scene::{Polygon, ScreenScene};
use cwisim_world::face::ScreenTriangle;
use cwisim_world::visibility::{exact_fragments, Fragment, VisibilityStats};
use cwisim_ypipe::exact::{coverage, polygon_area};
use proptest::prelude::*;

type P = [f64; 2];

/// A triangle with intensity `(x, y, 1/depth)` at each vertex (channels 0..3).
fn tri(points: [P; 3], inv_depth: [f64; 3]) -> ScreenTriangle {
    let mut intensity = [[0.0; 4]; 3];
    for k in 0..3 {
        intensity[k][0] = points[k][0];
        intensity[k][1] = points[k][1];
        intensity[k][2] = inv_depth[k];
    }
    ScreenTriangle {
        points,
        inv_depth,
        intensity,
        mesh: 0,
        face: 0,
        surface: Default::default(),
    }
}

/// An axis-aligned rectangle as two triangles, at constant `1/depth`.
fn rect(x0: f64, y0: f64, x1: f64, y1: f64, inv_depth: f64) -> [ScreenTriangle; 2] {
    [
        tri([[x0, y0], [x1, y0], [x1, y1]], [inv_depth; 3]),
        tri([[x0, y0], [x1, y1], [x0, y1]], [inv_depth; 3]),
    ]
}

fn poly(v: &[P]) -> Polygon {
    Polygon::uniform(v.to_vec(), &[1.0])
}

fn area(v: &[P]) -> f64 {
    polygon_area(&poly(v))
}

/// Twice the signed area, plain shoelace.
fn doubled_signed(v: &[P]) -> f64 {
    (0..v.len())
        .map(|k| {
            let (a, b) = (v[k], v[(k + 1) % v.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// `a ∩ b` for convex `a`, `b` (Sutherland–Hodgman over `b`'s edges).
fn convex_intersection(a: &[P], b: &[P]) -> Vec<P> {
    let mut b = b.to_vec();
    if doubled_signed(&b) < 0.0 {
        b.reverse();
    }
    let mut out = a.to_vec();
    for k in 0..b.len() {
        if out.is_empty() {
            break;
        }
        let (e0, e1) = (b[k], b[(k + 1) % b.len()]);
        let side = |p: P| (e1[0] - e0[0]) * (p[1] - e0[1]) - (e1[1] - e0[1]) * (p[0] - e0[0]);
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (cur, next) = (input[i], input[(i + 1) % input.len()]);
            let (sc, sn) = (side(cur), side(next));
            if sc >= 0.0 {
                out.push(cur);
            }
            if (sc >= 0.0) != (sn >= 0.0) {
                let t = sc / (sc - sn);
                out.push([
                    cur[0] + t * (next[0] - cur[0]),
                    cur[1] + t * (next[1] - cur[1]),
                ]);
            }
        }
    }
    out
}

/// Per-pixel coverage of the union of convex polygons, by inclusion–exclusion.
fn union_coverage(polys: &[Vec<P>], w: u32, h: u32) -> Vec<f64> {
    let mut out = vec![0.0; (w * h) as usize];
    for mask in 1u32..(1 << polys.len()) {
        let mut members = (0..polys.len()).filter(|k| mask & (1 << k) != 0);
        let mut v = polys[members.next().unwrap()].clone();
        for k in members {
            v = convex_intersection(&v, &polys[k]);
        }
        if v.len() < 3 {
            continue;
        }
        let sign = if mask.count_ones() % 2 == 1 {
            1.0
        } else {
            -1.0
        };
        for (o, c) in out.iter_mut().zip(coverage(&poly(&v), w, h)) {
            *o += sign * c;
        }
    }
    out
}

/// The area of the union of convex polygons, by inclusion–exclusion.
fn union_area(polys: &[Vec<P>]) -> f64 {
    let mut total = 0.0;
    for mask in 1u32..(1 << polys.len()) {
        let mut members = (0..polys.len()).filter(|k| mask & (1 << k) != 0);
        let mut v = polys[members.next().unwrap()].clone();
        for k in members {
            v = convex_intersection(&v, &polys[k]);
        }
        let sign = if mask.count_ones() % 2 == 1 {
            1.0
        } else {
            -1.0
        };
        total += sign * area(&v);
    }
    total
}

/// Sum of the exact per-pixel coverage of the fragments whose source passes `keep`.
fn fragment_coverage(frags: &[Fragment], keep: impl Fn(usize) -> bool, w: u32, h: u32) -> Vec<f64> {
    let mut out = vec![0.0; (w * h) as usize];
    for f in frags.iter().filter(|f| keep(f.source)) {
        for (o, c) in out.iter_mut().zip(coverage(&f.polygon, w, h)) {
            *o += c;
        }
    }
    out
}

fn assert_images_close(got: &[f64], want: &[f64], w: u32, tol: f64, what: &str) {
    for (k, (g, e)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - e).abs() <= tol,
            "{what}: pixel ({}, {}) has {g}, expected {e} (off by {:e})",
            k as u32 % w,
            k as u32 / w,
            (g - e).abs()
        );
    }
}

fn visible_area(frags: &[Fragment], source: usize) -> f64 {
    frags
        .iter()
        .filter(|f| f.source == source)
        .map(|f| polygon_area(&f.polygon))
        .sum()
}

/// Crossing-number point-in-polygon test.
fn contains(v: &[P], p: P) -> bool {
    let mut inside = false;
    for k in 0..v.len() {
        let (a, b) = (v[k], v[(k + 1) % v.len()]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

fn segment_distance(p: P, a: P, b: P) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

/// Brute force: which triangle is seen at `p` (`Some(None)`: none covers it), or `None`
/// when `p` is within 1e-7 of a triangle edge or of a line of equal depth.
fn owner(tris: &[ScreenTriangle], p: P) -> Option<Option<usize>> {
    const NEAR: f64 = 1e-7;
    let mut covering = Vec::new();
    for (k, t) in tris.iter().enumerate() {
        for e in 0..3 {
            if segment_distance(p, t.points[e], t.points[(e + 1) % 3]) < NEAR {
                return None;
            }
        }
        if t.barycentric(p).unwrap().iter().all(|&w| w > 0.0) {
            covering.push(k);
        }
    }
    let z = |k: usize, q: P| tris[k].inv_depth_at(q).unwrap();
    for (i, &a) in covering.iter().enumerate() {
        for &b in &covering[i + 1..] {
            let d = |q: P| z(a, q) - z(b, q);
            let (gx, gy) = (d([p[0] + 1.0, p[1]]) - d(p), d([p[0], p[1] + 1.0]) - d(p));
            if d(p).abs() < NEAR * gx.hypot(gy) || d(p) == 0.0 {
                return None;
            }
        }
    }
    Some(
        covering
            .into_iter()
            .max_by(|&a, &b| z(a, p).total_cmp(&z(b, p))),
    )
}

/// Points of a low-discrepancy sequence in `[x0, x0 + w) × [y0, y0 + h)`, irrationally
/// offset.
fn samples(n: usize, x0: f64, y0: f64, w: f64, h: f64) -> impl Iterator<Item = P> {
    let (a, b) = (0.618_033_988_749_894_8, std::f64::consts::SQRT_2 - 1.0);
    (0..n).map(move |k| {
        let k = k as f64;
        let fx = (k * a + 0.123_456_789 * std::f64::consts::PI).fract();
        let fy = (k * b + 0.271_828_182_845 * std::f64::consts::E).fract();
        [x0 + w * fx, y0 + h * fy]
    })
}

/// Every sample point that is clearly inside or outside lies in exactly the fragment of
/// the nearest covering triangle, or in none. Returns how many points were checked.
fn check_ownership(
    tris: &[ScreenTriangle],
    frags: &[Fragment],
    points: impl Iterator<Item = P>,
) -> usize {
    let mut checked = 0;
    for p in points {
        let Some(want) = owner(tris, p) else { continue };
        let holders: Vec<usize> = frags
            .iter()
            .filter(|f| contains(&f.polygon.vertices, p))
            .map(|f| f.source)
            .collect();
        match want {
            None => assert!(
                holders.is_empty(),
                "{p:?} is uncovered but in fragments of {holders:?}"
            ),
            Some(k) => assert_eq!(holders, vec![k], "at {p:?}"),
        }
        checked += 1;
    }
    checked
}

/// What every result must satisfy: simple hole-free polygons (the scene validator's
/// exact test) with ≥ 3 vertices, intensities from the source, consistent statistics,
/// and the same result on a second run.
fn check_well_formed(
    tris: &[ScreenTriangle],
    frags: &[Fragment],
    stats: &VisibilityStats,
    channels: usize,
) {
    for f in frags {
        assert!(f.polygon.vertices.len() >= 3);
        assert_eq!(f.polygon.intensity.len(), f.polygon.vertices.len());
        for (p, i) in f.polygon.vertices.iter().zip(&f.polygon.intensity) {
            let want = tris[f.source].intensity_at(*p, channels).unwrap();
            assert_eq!(i.len(), channels);
            for c in 0..channels {
                assert!((i[c] - want[c]).abs() <= 1e-12 * (1.0 + want[c].abs()));
            }
            // the intensity (x, y, 1/depth) reproduces the point: the right source
            for (c, v) in [p[0], p[1]].into_iter().enumerate().take(channels) {
                assert!((i[c] - v).abs() <= 1e-9, "{i:?} at {p:?}");
            }
        }
    }
    let scene = ScreenScene {
        width: 64,
        height: 64,
        channels: channels as u8,
        polygons: frags.iter().map(|f| f.polygon.clone()).collect(),
    };
    if let Err(e) = scene.validate() {
        panic!("fragments are not a valid screen scene: {e}");
    }
    assert!(
        frags.windows(2).all(|w| w[0].source <= w[1].source),
        "ordered by source"
    );
    assert_eq!(stats.triangles, tris.len() as u64);
    assert_eq!(stats.fragments, frags.len() as u64);
    let sources: std::collections::BTreeSet<usize> = frags.iter().map(|f| f.source).collect();
    assert_eq!(stats.hidden, (tris.len() - sources.len()) as u64);
    assert!(stats.dropped_area <= 1e-12 * stats.dropped_slivers as f64);
    assert_eq!(
        exact_fragments(tris, channels),
        (frags.to_vec(), stats.clone()),
        "deterministic"
    );
}

#[test]
fn two_overlapping_squares_exact() {
    let (w, h) = (48, 40);
    let back: [f64; 4] = [10.3, 7.7, 30.1, 25.9];
    let front = [20.45, 15.2, 41.7, 33.35];
    // the overlap, by min/max
    let both = [
        back[0].max(front[0]),
        back[1].max(front[1]),
        back[2].min(front[2]),
        back[3].min(front[3]),
    ];
    let square = |r: [f64; 4]| poly(&[[r[0], r[1]], [r[2], r[1]], [r[2], r[3]], [r[0], r[3]]]);
    let want_front = coverage(&square(front), w, h);
    let want_back: Vec<f64> = coverage(&square(back), w, h)
        .iter()
        .zip(coverage(&square(both), w, h))
        .map(|(a, b)| a - b)
        .collect();
    let b = rect(back[0], back[1], back[2], back[3], 0.25);
    let f = rect(front[0], front[1], front[2], front[3], 0.5);
    // back first, then front first: the same pictures
    for (tris, back_ids) in [
        ([b[0], b[1], f[0], f[1]], [0, 1]),
        ([f[0], f[1], b[0], b[1]], [2, 3]),
    ] {
        let (frags, stats) = exact_fragments(&tris, 3);
        check_well_formed(&tris, &frags, &stats, 3);
        let is_back = |k: usize| back_ids.contains(&k);
        assert_images_close(
            &fragment_coverage(&frags, |k| !is_back(k), w, h),
            &want_front,
            w,
            1e-9,
            "front",
        );
        assert_images_close(
            &fragment_coverage(&frags, is_back, w, h),
            &want_back,
            w,
            1e-9,
            "back",
        );
        // each (front, back) pair whose projections overlap is one occluding pair
        let overlapping = (0..4)
            .filter(|&i| !is_back(i))
            .flat_map(|i| back_ids.map(|j| (i, j)))
            .filter(|&(i, j)| area(&convex_intersection(&tris[i].points, &tris[j].points)) > 0.0)
            .count();
        assert_eq!(overlapping, 3, "one front half misses one back half");
        assert_eq!(stats.occluding_pairs, overlapping as u64);
        assert_eq!(
            (stats.hidden, stats.hole_cuts, stats.dropped_slivers),
            (0, 0, 0)
        );
        // the front triangles are untouched, vertex for vertex
        for f in frags.iter().filter(|f| !is_back(f.source)) {
            assert_eq!(f.polygon.vertices, tris[f.source].points.to_vec());
        }
    }
}

#[test]
fn interpenetrating_triangles_split_where_depths_are_equal() {
    let (w, h) = (48, 48);
    // A: 1/depth = 0.2 + 0.02 y (nearer further down); B: 0.5. Equal on y = 15.
    let pa = [[5.0, 5.0], [45.0, 5.0], [25.0, 40.0]];
    let pb = [[5.0, 35.0], [45.0, 35.0], [25.0, 0.0]];
    let a = tri(pa, pa.map(|p| 0.2 + 0.02 * p[1]));
    let b = tri(pb, [0.5; 3]);
    assert_eq!(a.inv_depth_at([25.0, 15.0]), Some(0.5));
    let tris = [a, b];
    let (frags, stats) = exact_fragments(&tris, 3);
    check_well_formed(&tris, &frags, &stats, 3);
    assert_eq!(stats.occluding_pairs, 2);

    let big = 1000.0;
    let above = [[-big, -big], [big, -big], [big, 15.0], [-big, 15.0]]; // y ≤ 15: B nearer
    let below = [[-big, 15.0], [big, 15.0], [big, big], [-big, big]]; // y ≥ 15: A nearer
    let ab = convex_intersection(&pa, &pb);
    let a_hidden = convex_intersection(&ab, &above);
    let b_hidden = convex_intersection(&ab, &below);
    assert!(
        area(&a_hidden) > 10.0 && area(&b_hidden) > 10.0,
        "a real interpenetration"
    );
    let minus =
        |x: Vec<f64>, y: Vec<f64>| -> Vec<f64> { x.iter().zip(y).map(|(p, q)| p - q).collect() };
    let want_a = minus(coverage(&poly(&pa), w, h), coverage(&poly(&a_hidden), w, h));
    let want_b = minus(coverage(&poly(&pb), w, h), coverage(&poly(&b_hidden), w, h));
    assert_images_close(
        &fragment_coverage(&frags, |k| k == 0, w, h),
        &want_a,
        w,
        1e-9,
        "A",
    );
    assert_images_close(
        &fragment_coverage(&frags, |k| k == 1, w, h),
        &want_b,
        w,
        1e-9,
        "B",
    );

    let total: f64 = frags.iter().map(|f| polygon_area(&f.polygon)).sum();
    let union = area(&pa) + area(&pb) - area(&ab);
    assert!((total - union).abs() < 1e-9, "{total} vs {union}");
    // both sides have vertices on the line of equal depth, inside the other triangle
    for k in 0..2 {
        assert!(frags
            .iter()
            .filter(|f| f.source == k)
            .flat_map(|f| &f.polygon.vertices)
            .any(|p| (p[1] - 15.0).abs() < 1e-12 && p[0] > 10.0 && p[0] < 40.0));
    }
    assert!(check_ownership(&tris, &frags, samples(4000, 0.0, 0.0, 50.0, 45.0)) > 3000);
}

#[test]
fn cyclic_overlap_of_three_triangles() {
    // a pinwheel of three long thin triangles about (50, 50): each one's line passes 5
    // px from the centre; 1/depth grows along each towards its base, so each is nearer
    // than the next where they cross, and no order of whole triangles is right
    let (cx, cy, r, len, wide) = (50.0, 50.0, 5.0, 40.0, 8.0);
    let tris: Vec<ScreenTriangle> = (0..3)
        .map(|k| {
            let t = f64::from(k) * 2.0 * std::f64::consts::PI / 3.0;
            let (n, d) = ([t.cos(), t.sin()], [-t.sin(), t.cos()]);
            let at = |s: f64, o: f64| {
                [
                    cx + (r + o) * n[0] + s * d[0],
                    cy + (r + o) * n[1] + s * d[1],
                ]
            };
            let z = |s: f64| 0.5 + 0.005 * s;
            tri(
                [at(-len, 0.0), at(len, wide), at(len, -wide)],
                [z(-len), z(len), z(len)],
            )
        })
        .collect();
    // the set-up is cyclic: at the crossing of the centre lines of k and k+1, k is nearer
    let s = r * 3f64.sqrt();
    for k in 0..3 {
        let t = k as f64 * 2.0 * std::f64::consts::PI / 3.0;
        let p = [
            cx + r * t.cos() - s * t.sin(),
            cy + r * t.sin() + s * t.cos(),
        ];
        let next = (k + 1) % 3;
        assert!(tris[k].barycentric(p).unwrap().iter().all(|&w| w > 0.0));
        assert!(tris[next].barycentric(p).unwrap().iter().all(|&w| w > 0.0));
        assert!(tris[k].inv_depth_at(p).unwrap() > tris[next].inv_depth_at(p).unwrap() + 0.05);
    }
    let (frags, stats) = exact_fragments(&tris, 2);
    check_well_formed(&tris, &frags, &stats, 2);
    assert_eq!(stats.occluding_pairs, 3);
    for (k, t) in tris.iter().enumerate() {
        let seen = visible_area(&frags, k);
        let full = area(&t.points);
        assert!(
            seen > 0.5 * full && seen < full - 1.0,
            "triangle {k}: {seen} of {full}"
        );
    }
    let polys: Vec<Vec<P>> = tris.iter().map(|t| t.points.to_vec()).collect();
    let cover = fragment_coverage(&frags, |_| true, 100, 100);
    assert_images_close(
        &cover,
        &union_coverage(&polys, 100, 100),
        100,
        1e-9,
        "union",
    );
    assert!(check_ownership(&tris, &frags, samples(6000, 0.0, 0.0, 100.0, 100.0)) > 5000);
}

#[test]
fn small_near_triangles_inside_a_far_one_are_holes_cut_away() {
    let (w, h) = (64, 64);
    let big = [[1.3, 2.1], [62.7, 3.3], [4.9, 61.1]];
    let smalls = [
        [[10.1, 10.3], [20.7, 11.1], [12.2, 21.9]],
        [[30.3, 8.9], [40.1, 9.7], [33.3, 17.7]],
        // y-ranges overlapping the first: one cut may open two holes
        [[11.1, 30.2], [21.3, 29.9], [15.5, 40.4]],
    ];
    for count in 1..=3 {
        let mut tris = vec![tri(big, [0.1, 0.15, 0.12])];
        tris.extend(smalls[..count].iter().map(|&p| tri(p, [0.5, 0.6, 0.55])));
        let (frags, stats) = exact_fragments(&tris, 2);
        check_well_formed(&tris, &frags, &stats, 2);
        assert!(stats.hole_cuts >= 1);
        assert!(frags.iter().filter(|f| f.source == 0).count() as u64 > stats.hole_cuts);
        let mut want_far = coverage(&poly(&big), w, h);
        for (k, s) in smalls[..count].iter().enumerate() {
            let got = fragment_coverage(&frags, |j| j == k + 1, w, h);
            let want = coverage(&poly(s), w, h);
            assert_images_close(&got, &want, w, 1e-9, "near");
            for (f, c) in want_far.iter_mut().zip(want) {
                *f -= c;
            }
        }
        assert_images_close(
            &fragment_coverage(&frags, |j| j == 0, w, h),
            &want_far,
            w,
            1e-9,
            "far",
        );
        let expected = area(&big) - smalls[..count].iter().map(|s| area(s)).sum::<f64>();
        assert!((visible_area(&frags, 0) - expected).abs() < 1e-9);
    }
}

#[test]
fn fully_hidden_triangle_has_no_fragment() {
    let near = tri([[0.0, 0.0], [50.0, 0.0], [0.0, 50.0]], [0.9; 3]);
    let far = tri([[5.5, 5.5], [20.25, 6.0], [7.0, 19.75]], [0.2, 0.3, 0.4]);
    let tris = [far, near];
    let (frags, stats) = exact_fragments(&tris, 1);
    check_well_formed(&tris, &frags, &stats, 1);
    assert_eq!(frags.len(), 1);
    assert_eq!(frags[0].source, 1);
    assert_eq!((stats.hidden, stats.occluding_pairs), (1, 1));
}

/// A random triangle in `[0, 60]²` with `1/depth` in `[0.1, 1]` per vertex (so pairs
/// may interpenetrate), either orientation, not too thin.
fn triangle() -> impl Strategy<Value = ScreenTriangle> {
    (
        prop::array::uniform3(prop::array::uniform2(0.0..60.0f64)),
        prop::array::uniform3(0.1..1.0f64),
    )
        .prop_map(|(points, inv_depth)| tri(points, inv_depth))
        .prop_filter("not too thin", |t| {
            let p = t.points;
            let longest = (0..3)
                .map(|k| (p[k][0] - p[(k + 1) % 3][0]).hypot(p[k][1] - p[(k + 1) % 3][1]))
                .fold(0.0, f64::max);
            t.doubled_area().abs() > 0.05 * longest * longest
        })
}

/// Brute force for coplanar triangles: the lowest index covering `p` (`Some(None)`:
/// none), or `None` within 1e-7 of an edge.
fn lowest_owner(tris: &[ScreenTriangle], p: P) -> Option<Option<usize>> {
    let near = tris
        .iter()
        .any(|t| (0..3).any(|e| segment_distance(p, t.points[e], t.points[(e + 1) % 3]) < 1e-7));
    (!near).then(|| {
        tris.iter()
            .position(|t| t.barycentric(p).unwrap().iter().all(|&w| w > 0.0))
    })
}

/// Two meshes, each a `cells × cells` grid of jittered quads (two triangles each)
/// tiling a random parallelogram, with smooth bumpy `1/depth` surfaces that cross each
/// other; returns the triangles and the two parallelograms.
fn two_meshes(seed: u64, cells: usize) -> (Vec<ScreenTriangle>, [Vec<P>; 2]) {
    let mut rng = Rng(seed);
    let mut tris = Vec::new();
    let mut outlines = [Vec::new(), Vec::new()];
    for outline in &mut outlines {
        let t = std::f64::consts::TAU * rng.next();
        let (l1, l2) = (30.0 + 30.0 * rng.next(), 30.0 + 30.0 * rng.next());
        let t2 = t + std::f64::consts::FRAC_PI_2 + 0.6 * (rng.next() - 0.5);
        let (e1, e2) = ([l1 * t.cos(), l1 * t.sin()], [l2 * t2.cos(), l2 * t2.sin()]);
        // centred near (64, 64): the two overlap broadly
        let c = [
            64.0 + 16.0 * (rng.next() - 0.5),
            64.0 + 16.0 * (rng.next() - 0.5),
        ];
        let o = [c[0] - 0.5 * (e1[0] + e2[0]), c[1] - 0.5 * (e1[1] + e2[1])];
        let (gx, gy) = (0.01 * (rng.next() - 0.5), 0.01 * (rng.next() - 0.5));
        let (bump, phase) = (0.04 * rng.next(), std::f64::consts::TAU * rng.next());
        let z = |p: P| {
            0.5 + gx * (p[0] - 40.0)
                + gy * (p[1] - 40.0)
                + bump * (0.2 * p[0] + phase).sin() * (0.15 * p[1]).cos()
        };
        let n = cells;
        let mut grid = vec![[0.0; 2]; (n + 1) * (n + 1)];
        for j in 0..=n {
            for i in 0..=n {
                let inner = |k: usize| k > 0 && k < n;
                let (mut u, mut v) = (i as f64, j as f64);
                if inner(i) && inner(j) {
                    u += 0.3 * (rng.next() - 0.5);
                    v += 0.3 * (rng.next() - 0.5);
                }
                let (u, v) = (u / n as f64, v / n as f64);
                grid[j * (n + 1) + i] =
                    [o[0] + u * e1[0] + v * e2[0], o[1] + u * e1[1] + v * e2[1]];
            }
        }
        for j in 0..n {
            for i in 0..n {
                let at = |di: usize, dj: usize| grid[(j + dj) * (n + 1) + i + di];
                let (a, b, c, d) = (at(0, 0), at(1, 0), at(1, 1), at(0, 1));
                for points in [[a, b, c], [a, c, d]] {
                    tris.push(tri(points, points.map(z)));
                }
            }
        }
        *outline = vec![
            o,
            [o[0] + e1[0], o[1] + e1[1]],
            [o[0] + e1[0] + e2[0], o[1] + e1[1] + e2[1]],
            [o[0] + e2[0], o[1] + e2[1]],
        ];
    }
    (tris, outlines)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_triangles_partition_the_union_by_nearest(
        tris in prop::collection::vec(triangle(), 3..=8),
    ) {
        let (frags, stats) = exact_fragments(&tris, 3);
        check_well_formed(&tris, &frags, &stats, 3);
        let polys: Vec<Vec<P>> = tris.iter().map(|t| t.points.to_vec()).collect();
        // (a) the fragments cover the union of the triangles exactly once
        let total: f64 = frags.iter().map(|f| polygon_area(&f.polygon)).sum();
        let union = union_area(&polys);
        prop_assert!((total - union).abs() < 1e-6, "fragments {} vs union {}", total, union);
        let cover = fragment_coverage(&frags, |_| true, 64, 64);
        assert_images_close(&cover, &union_coverage(&polys, 64, 64), 64, 1e-9, "union");
        // (b) each point is in the fragment of the nearest triangle there, only
        check_ownership(&tris, &frags, samples(1500, -1.0, -1.0, 62.0, 62.0));
    }

    #[test]
    fn coplanar_triangles_go_to_the_lowest_index(
        mut tris in prop::collection::vec(triangle(), 3..=7),
    ) {
        // one plane for all, and an exact duplicate of the first at the end
        let z = |p: P| 0.5 + 0.004 * p[0] - 0.003 * p[1];
        for t in &mut tris {
            *t = tri(t.points, t.points.map(z));
        }
        tris.push(tris[0]);
        let (frags, stats) = exact_fragments(&tris, 3);
        check_well_formed(&tris, &frags, &stats, 3);
        prop_assert!(stats.hidden >= 1);
        prop_assert!(frags.iter().all(|f| f.source != tris.len() - 1));
        let polys: Vec<Vec<P>> = tris.iter().map(|t| t.points.to_vec()).collect();
        let cover = fragment_coverage(&frags, |_| true, 64, 64);
        assert_images_close(&cover, &union_coverage(&polys, 64, 64), 64, 1e-9, "union");
        for p in samples(1500, -1.0, -1.0, 62.0, 62.0) {
            let Some(want) = lowest_owner(&tris, p) else { continue };
            let holders: Vec<usize> =
                frags.iter().filter(|f| contains(&f.polygon.vertices, p)).map(|f| f.source).collect();
            prop_assert_eq!(holders, want.into_iter().collect::<Vec<_>>(), "at {:?}", p);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn crossing_meshes_tile_their_union(seed in any::<u64>()) {
        let (tris, [a, b]) = two_meshes(seed, 5);
        let (frags, stats) = exact_fragments(&tris, 3);
        check_well_formed(&tris, &frags, &stats, 3);
        // the meshes tile their parallelograms: the union is convex pieces' union
        let (w, h) = (128, 128);
        let want: Vec<f64> = union_coverage(&[a, b], w, h);
        let got = fragment_coverage(&frags, |_| true, w, h);
        assert_images_close(&got, &want, w, 1e-9, "union of the meshes");
        check_ownership(&tris, &frags, samples(3000, 0.0, 0.0, 128.0, 128.0));
    }
}

/// A splitmix64 stream of uniform floats in `[0, 1)`.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn two_thousand_small_triangles() {
    let mut rng = Rng(7);
    let tris: Vec<ScreenTriangle> = (0..2000)
        .map(|_| {
            let (cx, cy, size) = (
                640.0 * rng.next(),
                480.0 * rng.next(),
                10.0 + 40.0 * rng.next(),
            );
            let mut points = [[0.0; 2]; 3];
            for p in &mut points {
                *p = [
                    cx + size * (rng.next() - 0.5),
                    cy + size * (rng.next() - 0.5),
                ];
            }
            let base = 0.1 + 0.8 * rng.next();
            let inv_depth = [0; 3].map(|_| base + 0.1 * rng.next());
            tri(points, inv_depth)
        })
        .filter(|t| t.doubled_area().abs() > 0.5)
        .collect();
    let start = std::time::Instant::now();
    let (frags, stats) = exact_fragments(&tris, 3);
    let took = start.elapsed();
    eprintln!("{} triangles: {took:?}, {stats:?}", tris.len());
    assert!(stats.occluding_pairs > 1000 && stats.hidden > 0);
    // validation in 640 × 480: the 64 × 64 of check_well_formed is only a size
    let scene = ScreenScene {
        width: 640,
        height: 480,
        channels: 3,
        polygons: frags.iter().map(|f| f.polygon.clone()).collect(),
    };
    scene.validate().unwrap();
    assert!(frags.iter().all(|f| f.polygon.vertices.len() >= 3));
    let total: f64 = frags.iter().map(|f| polygon_area(&f.polygon)).sum();
    let sum: f64 = tris.iter().map(|t| area(&t.points)).sum();
    assert!(total < sum);
    assert!(check_ownership(&tris, &frags, samples(5_000, 0.0, 0.0, 640.0, 480.0)) > 4_000);
}

/// The built-in world scenes (real meshes: shared edges and vertices, a pot seen into
/// its opening): valid fragments, each sample point owned by the nearest triangle.
#[test]
fn embedded_world_scenes_give_valid_exact_fragments() {
    let mut worlds = 0;
    for e in cwisim_world::embedded::EMBEDDED {
        let Ok(cwisim_world::AnyScene::World(w)) = cwisim_world::parse_any(e.text, None) else {
            continue;
        };
        worlds += 1;
        let (tris, _) = cwisim_world::project::project(&w, cwisim_ypipe::Shading::Gouraud).unwrap();
        let (frags, stats) = exact_fragments(&tris, 3);
        assert!(
            stats.occluding_pairs > 0 && stats.fragments > 0,
            "{}",
            e.name
        );
        let scene = ScreenScene {
            width: w.width(),
            height: w.height(),
            channels: 3,
            polygons: frags.iter().map(|f| f.polygon.clone()).collect(),
        };
        if let Err(err) = scene.validate() {
            panic!("{}: {err}", e.name);
        }
        assert!(stats.dropped_area <= 1e-12 * stats.dropped_slivers as f64);
        let (fw, fh) = (f64::from(w.width()), f64::from(w.height()));
        assert!(check_ownership(&tris, &frags, samples(3000, 0.0, 0.0, fw, fh)) > 2500);
    }
    assert!(worlds >= 1);
}
