//! Exact visibility at high depth complexity: memory stays one triangle's occluders deep
//! (it grew with the square of the layers), and coincident layers resolve to the first.
//!
//! A counting allocator wraps the system one for this test binary (`layers/mod.rs`), to
//! measure the peak heap `exact_fragments` allocates.

mod layers;

use cwisim_scene::Shading;
use cwisim_world::visibility::{exact_fragments, Fragment, VisibilityStats};
use std::sync::Mutex;

/// One test at a time: tests run on threads, and the heap is shared (each test holds it
/// for its whole body).
static MEASURING: Mutex<()> = Mutex::new(());

/// The visible fragments of the pot as `layers` layers (radii scaled by `1 + k·step`),
/// the stats, and the peak heap the visibility pass took (bytes).
fn visible(layers: usize, step: f64) -> (Vec<Fragment>, VisibilityStats, usize) {
    let scene = cwisim_world::scene::parse_world(&layers::layered_pot(layers, step), None)
        .expect("a valid scene");
    let (tris, _) = cwisim_world::project::project(&scene, Shading::Gouraud).expect("projects");
    let ((fragments, stats), peak) = layers::peak_heap(|| exact_fragments(&tris, 1));
    (fragments, stats, peak)
}

#[test]
fn coincident_layers_resolve_to_the_first_in_memory_linear_in_the_layers() {
    let _alone = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    let (one, one_stats, one_peak) = visible(1, 0.0);
    let (eight, stats, peak) = visible(8, 0.0);
    // the lower index wins a coplanar overlap: layer 0 keeps exactly what it had alone,
    // every other layer is hidden
    assert_eq!(eight.len(), one.len());
    for (a, b) in eight.iter().zip(&one) {
        assert_eq!(a, b, "fragment of triangle {}", b.source);
    }
    assert_eq!(stats.triangles, 8 * one_stats.triangles);
    assert_eq!(
        stats.hidden,
        stats.triangles - (one_stats.triangles - one_stats.hidden)
    );
    // every triangle of layers 1 to 7 is an exact copy of one of layer 0
    assert_eq!(stats.copies_hidden, 7 * one_stats.triangles);
    // the output is the same size; what the pass holds grows at most like the input
    // (it held every occluding pair at once: 66× at 8 layers)
    assert!(
        peak <= 12 * one_peak,
        "peak heap {peak} B at 8 layers against {one_peak} B at 1"
    );
}

/// Whether `p` is inside triangle `t` (strictly, by a margin), and its `1/depth` there:
/// written here, apart from the code under test.
fn inside_triangle(t: &[[f64; 2]; 3], w: &[f64; 3], p: [f64; 2]) -> Option<f64> {
    let [a, b, c] = *t;
    let d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / d;
    let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / d;
    let l0 = 1.0 - l1 - l2;
    let margin = 1e-9;
    (l0 > margin && l1 > margin && l2 > margin).then(|| l0 * w[0] + l1 * w[1] + l2 * w[2])
}

/// Whether `p` is inside the simple polygon `v` (crossing number).
fn inside_polygon(v: &[[f64; 2]], p: [f64; 2]) -> bool {
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

#[test]
fn stacked_layers_keep_the_nearest_surface_at_every_sample_in_linear_memory() {
    let _alone = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    let (_, _, one_peak) = visible(1, 0.0);
    let layers = 5;
    let (fragments, stats, peak) = visible(layers, 0.02);
    assert!(
        peak <= 8 * one_peak,
        "peak heap {peak} B against {one_peak} B"
    );
    assert!(stats.candidates_skipped > 0, "hidden triangles stop early");
    // an independent check at sample points: the fragment there (one at most) comes from
    // the nearest triangle there, found by brute force
    let scene = cwisim_world::scene::parse_world(&layers::layered_pot(layers, 0.02), None)
        .expect("a valid scene");
    let (tris, _) = cwisim_world::project::project(&scene, Shading::Gouraud).expect("projects");
    let mut checked = 0;
    for i in 0..70 {
        for j in 0..70 {
            // off any pixel grid: irrational steps
            let p = [60.0 + i as f64 * 4.1421356, 20.0 + j as f64 * 5.2360679];
            let mut depths: Vec<(f64, usize)> = tris
                .iter()
                .enumerate()
                .filter_map(|(k, t)| inside_triangle(&t.points, &t.inv_depth, p).map(|w| (w, k)))
                .collect();
            depths.sort_by(|a, b| b.0.total_cmp(&a.0));
            let owners: Vec<usize> = fragments
                .iter()
                .filter(|f| inside_polygon(&f.polygon.vertices, p))
                .map(|f| f.source)
                .collect();
            assert!(owners.len() <= 1, "{p:?} covered by {owners:?}");
            match depths.as_slice() {
                [] => assert!(owners.is_empty(), "{p:?}: nothing there, yet {owners:?}"),
                [(w, k), rest @ ..] => {
                    // a near tie (a shared edge seen edge-on) decides nothing
                    if rest
                        .first()
                        .is_some_and(|(w2, _)| (w - w2).abs() <= 1e-9 * w)
                    {
                        continue;
                    }
                    assert_eq!(owners, vec![*k], "{p:?}");
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 1000, "{checked} samples decided");
}
