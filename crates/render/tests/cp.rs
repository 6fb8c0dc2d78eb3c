//! Critical-points scan conversion (`cwisim_render::cp`) against a plain edge-list scan
//! conversion, and `DETCR` on the cases the paper warns about.

use cwisim_render::cp::{detcr, edge_list_rows, scan_rows, CpPolygon, CpState, Increment};
use cwisim_scene::predicates::simplicity_fault;
use proptest::prelude::*;

/// A star-shaped polygon: `n` vertices at increasing angles around `(cx, cy)` with random
/// radii, snapped to a grid of `1/q` pixels (so that vertices fall on pixel centres and
/// rows, edges are horizontal, and `y` repeats), in either orientation, from any start.
fn polygon() -> impl Strategy<Value = Vec<[f64; 2]>> {
    (3usize..40, 1u32..=4, any::<bool>(), 0usize..40).prop_flat_map(|(n, q, reverse, rot)| {
        (
            proptest::collection::vec((0.0f64..1.0, 0.5f64..12.0), n),
            8.0f64..24.0,
            8.0f64..24.0,
        )
            .prop_map(move |(rays, cx, cy)| {
                let q = f64::from(q);
                let mut angles: Vec<f64> = rays.iter().map(|r| r.0).collect();
                angles.sort_by(f64::total_cmp);
                let mut v: Vec<[f64; 2]> = angles
                    .iter()
                    .zip(&rays)
                    .map(|(a, r)| {
                        let t = a * std::f64::consts::TAU;
                        let snap = |c: f64| (c * 2.0 * q).round() / (2.0 * q);
                        [snap(cx + r.1 * t.cos()), snap(cy + r.1 * t.sin())]
                    })
                    .collect();
                v.dedup();
                if reverse {
                    v.reverse();
                }
                let len = v.len().max(1);
                v.rotate_left(rot % len);
                v
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    /// The direct update: CP's spans are the edge list's at every row, bit for bit.
    #[test]
    fn cp_direct_equals_the_edge_list(v in polygon()) {
        prop_assume!(v.len() >= 3 && simplicity_fault(&v).is_none());
        let p = CpPolygon::new(&v);
        let (cp, stats) = scan_rows(&p, 32, 32, Increment::Direct);
        let plain = edge_list_rows(&v, 32, 32);
        prop_assert_eq!(&cp, &plain);
        // every element inserted is deleted once the sweep is over (or the image ends)
        prop_assert!(stats.deletes <= stats.inserts);
        prop_assert_eq!(stats.increments, 0);
    }
}

#[test]
fn detcr_convex_has_one_critical_point_in_both_orientations_from_any_start() {
    // a convex octagon, and with a horizontal bottom edge
    let oct: Vec<[f64; 2]> = (0..8)
        .map(|k| {
            let t = (k as f64 + 0.3) * std::f64::consts::TAU / 8.0;
            [10.0 + 5.0 * t.cos(), 10.0 + 5.0 * t.sin()]
        })
        .collect();
    let flat_bottom = vec![[2.0, 1.0], [6.0, 1.0], [8.0, 4.0], [4.0, 7.0], [0.0, 4.0]];
    for base in [oct, flat_bottom] {
        for reverse in [false, true] {
            for rot in 0..base.len() {
                let mut v = base.clone();
                if reverse {
                    v.reverse();
                }
                v.rotate_left(rot);
                let y: Vec<f64> = v.iter().map(|p| p[1]).collect();
                let cr = detcr(&y);
                assert_eq!(cr.len(), 1, "{v:?}: {cr:?}");
                let min = y.iter().copied().fold(f64::INFINITY, f64::min);
                assert_eq!(y[cr[0]], min);
            }
        }
    }
}

#[test]
fn detcr_takes_the_last_vertex_of_a_horizontal_bottom_and_loops_around() {
    // bottom run 4, 0, 1 (wrapping): vertex 1 is the last of it in index order, found by
    // the second pass from vertex 0
    let y = [1.0, 1.0, 5.0, 9.0, 1.0];
    assert_eq!(detcr(&y), vec![1]);
    // the run starts at 0: the first pass finds it
    let y = [1.0, 1.0, 5.0, 9.0, 5.0];
    assert_eq!(detcr(&y), vec![1]);
    // the whole polygon on one horizontal line: none (degenerate)
    assert!(detcr(&[3.0, 3.0, 3.0, 3.0]).is_empty());
    // collinear on a slope: one critical point, and no pixel
    let v = [[0.0, 0.0], [4.0, 4.0], [8.0, 8.0], [4.0, 4.0]];
    let p = CpPolygon::new(&v);
    assert_eq!(p.critical_points().len(), 1);
    let (rows, _) = scan_rows(&p, 16, 16, Increment::Direct);
    assert!(rows.iter().all(|r| r.is_empty()));
}

/// A zig-zag band with `teeth` teeth along the bottom: `teeth` critical points.
fn zigzag(teeth: usize) -> Vec<[f64; 2]> {
    let mut v = Vec::new();
    for k in 0..=2 * teeth {
        let y = if k % 2 == 0 { 10.0 } else { 2.0 };
        v.push([k as f64, y]);
    }
    v.push([2.0 * teeth as f64, 20.0]);
    v.push([0.0, 20.0]);
    v
}

#[test]
fn detcr_counts_the_teeth_of_a_zigzag() {
    for teeth in [1, 2, 7, 50] {
        let v = zigzag(teeth);
        let y: Vec<f64> = v.iter().map(|p| p[1]).collect();
        // the tips (y = 2) are the minima of y; the corners between them (y = 10) maxima
        let tips = y.iter().filter(|&&v| v == 2.0).count();
        let cr = detcr(&y);
        assert_eq!(cr.len(), tips, "{teeth} teeth");
        assert_eq!(cr.len(), teeth);
        let p = CpPolygon::new(&v);
        assert_eq!(
            scan_rows(&p, 128, 32, Increment::Direct).0,
            edge_list_rows(&v, 128, 32)
        );
    }
}

#[test]
fn moveup_follows_horizontal_edges_and_deletes_sections_that_turn_down() {
    // a bottom edge, a horizontal step in the right side, and a notch in the top whose
    // tip (6, 6) is a second critical point
    let v = [
        [0.0, 0.0],
        [8.0, 0.0],
        [8.0, 4.0],
        [12.0, 4.0],
        [12.0, 10.0],
        [7.0, 10.0],
        [6.0, 6.0],
        [5.0, 10.0],
        [0.0, 10.0],
    ];
    let p = CpPolygon::new(&v);
    assert_eq!(p.critical_points(), &[1, 6]);
    let mut s = CpState::new();
    let mut stats = Default::default();
    s.poline(&p, 0.5, Increment::Direct, &mut stats);
    let xs = |s: &CpState| s.aet().iter().map(|k| k.xc).collect::<Vec<_>>();
    assert_eq!(xs(&s), [0.0, 8.0]);
    // past the step: the right section went along the horizontal edge to x = 12
    s.poline(&p, 4.5, Increment::Direct, &mut stats);
    assert_eq!(xs(&s), [0.0, 12.0]);
    // past the notch's tip: its two sections are inserted between
    s.poline(&p, 7.5, Increment::Direct, &mut stats);
    assert_eq!(xs(&s), [0.0, 5.625, 6.375, 12.0]);
    assert_eq!(stats.inserts, 4);
    // past the top: every section turned down
    s.poline(&p, 10.5, Increment::Direct, &mut stats);
    assert!(s.finished(&p));
    assert_eq!(stats.deletes, 4);
    // the step along the horizontal edge (8,4)→(12,4) is one of the MOVEUP steps
    assert!(stats.moveup_steps >= 2);
}

/// The pixels where two row sets differ.
fn differing(a: &[Vec<(u32, u32)>], b: &[Vec<(u32, u32)>], width: u32) -> u64 {
    let mask = |row: &Vec<(u32, u32)>| {
        let mut m = vec![false; width as usize];
        for &(s, e) in row {
            m[s as usize..e as usize].iter_mut().for_each(|v| *v = true);
        }
        m
    };
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let (x, y) = (mask(x), mask(y));
            x.iter().zip(&y).filter(|(p, q)| p != q).count() as u64
        })
        .sum()
}

#[test]
fn the_papers_increment_flips_a_pixel_where_a_crossing_hits_a_centre() {
    // the right edge (0, 0)→(3, 13) meets row 6's line y = 6.5 at exactly x = 1.5, the
    // centre of pixel 1, which lies outside [xl, xr); the paper's XX += SL gives
    // 1.5000000000000002 there and sets it
    let v = [[0.0, 0.0], [3.0, 13.0], [0.0, 13.0]];
    let p = CpPolygon::new(&v);
    let (direct, _) = scan_rows(&p, 8, 16, Increment::Direct);
    let (paper, stats) = scan_rows(&p, 8, 16, Increment::Paper);
    assert_eq!(direct, edge_list_rows(&v, 8, 16));
    assert_eq!(direct[6], [(0, 1)]);
    assert_eq!(paper[6], [(0, 2)]);
    assert_eq!(differing(&direct, &paper, 8), 1);
    assert!(stats.increments > 0);
}

/// `--nocapture` prints the measurement quoted in docs/ERRATA.md (BR1).
#[test]
fn the_papers_increment_measured_on_random_polygons() {
    use rand_core::Rng;
    use rand_core::SeedableRng;
    use rand_xorshift::XorShiftRng;
    let mut rng = XorShiftRng::seed_from_u64(21);
    let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let (mut polygons, mut flipped_polygons, mut flips, mut pixels) = (0u64, 0u64, 0u64, 0u64);
    for _ in 0..2000 {
        let n = 3 + (unit() * 30.0) as usize;
        let mut angles: Vec<f64> = (0..n).map(|_| unit()).collect();
        angles.sort_by(f64::total_cmp);
        let (cx, cy) = (32.0 + unit() * 4.0, 32.0 + unit() * 4.0);
        let v: Vec<[f64; 2]> = angles
            .iter()
            .map(|a| {
                let (t, r) = (a * std::f64::consts::TAU, 4.0 + unit() * 26.0);
                let snap = |c: f64| (c * 8.0).round() / 8.0;
                [snap(cx + r * t.cos()), snap(cy + r * t.sin())]
            })
            .collect();
        if simplicity_fault(&v).is_some() {
            continue;
        }
        let p = CpPolygon::new(&v);
        let (direct, _) = scan_rows(&p, 64, 64, Increment::Direct);
        let (paper, _) = scan_rows(&p, 64, 64, Increment::Paper);
        assert_eq!(direct, edge_list_rows(&v, 64, 64));
        let d = differing(&direct, &paper, 64);
        polygons += 1;
        flips += d;
        flipped_polygons += u64::from(d > 0);
        pixels += direct
            .iter()
            .flatten()
            .map(|&(s, e)| u64::from(e - s))
            .sum::<u64>();
    }
    println!(
        "paper increment: {flips} pixels flipped of {pixels} set, in {flipped_polygons} of {polygons} polygons (vertices on a 1/8 grid)"
    );
    // on a 1/8 grid crossings land on centres often: the drift must show
    assert!(flips > 0 && flipped_polygons > 0);
}
