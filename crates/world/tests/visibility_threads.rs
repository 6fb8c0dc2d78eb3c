//! Exact visibility on threads (`exact_fragments_on`): the fragments and statistics are
//! those of one thread, bit for bit, at 1, 2, 3 threads and one per core, and the heap
//! the pass holds stays bounded by what one thread holds (one triangle's occluders per
//! thread, and the output).

mod layers;

use cwisim_scene::Shading;
use cwisim_world::face::ScreenTriangle;
use cwisim_world::visibility::{exact_fragments, exact_fragments_on, Fragment, VisibilityStats};
use std::sync::Mutex;

/// One heap measurement at a time (the counting allocator is shared by the tests).
static MEASURING: Mutex<()> = Mutex::new(());

/// Every coordinate, intensity and statistic, bit for bit (`==` on `f64` would take
/// `-0.0` for `0.0`).
fn bits(fragments: &[Fragment], stats: &VisibilityStats) -> (Vec<u64>, String) {
    let mut out = Vec::new();
    for f in fragments {
        out.push(f.source as u64);
        out.push(f.polygon.vertices.len() as u64);
        for p in &f.polygon.vertices {
            out.extend(p.iter().map(|c| c.to_bits()));
        }
        for i in &f.polygon.intensity {
            out.push(i.len() as u64);
            out.extend(i.iter().map(|c| c.to_bits()));
        }
    }
    let stats = format!(
        "{stats:?} dropped_area bits {:x}",
        stats.dropped_area.to_bits()
    );
    (out, stats)
}

/// The projected triangles of a world scene's text.
fn triangles(text: &str) -> Vec<ScreenTriangle> {
    let scene = cwisim_world::scene::parse_world(text, None).expect("a valid scene");
    cwisim_world::project::project(&scene, Shading::Gouraud)
        .expect("projects")
        .0
}

/// Checks 1, 2, 3 and 0 (one per core) threads against [`exact_fragments`]; returns the
/// statistics.
fn same_on_any_thread_count(
    name: &str,
    tris: &[ScreenTriangle],
    channels: usize,
) -> VisibilityStats {
    let (fragments, stats) = exact_fragments(tris, channels);
    let reference = bits(&fragments, &stats);
    for threads in [1, 2, 3, 0] {
        let (f, s) = exact_fragments_on(tris, channels, threads);
        assert!(
            bits(&f, &s) == reference,
            "{name}: {threads} thread(s) differ from one: {s:?} against {stats:?}"
        );
    }
    stats
}

#[test]
fn one_two_and_three_threads_give_identical_fragments_and_stats() {
    let mut scenes = 0;
    let mut total = VisibilityStats::default();
    let mut add = |s: VisibilityStats| {
        total.fragments += s.fragments;
        total.hidden += s.hidden;
        total.hole_cuts += s.hole_cuts;
        total.dropped_slivers += s.dropped_slivers;
        total.copies_hidden += s.copies_hidden;
        total.candidates_skipped += s.candidates_skipped;
    };
    for e in cwisim_world::embedded::EMBEDDED {
        let Ok(cwisim_world::AnyScene::World(w)) = cwisim_world::parse_any(e.text, None) else {
            continue;
        };
        scenes += 1;
        let (tris, _) = cwisim_world::project::project(&w, Shading::Gouraud).expect("projects");
        add(same_on_any_thread_count(e.name, &tris, 3));
    }
    assert!(scenes >= 1);
    // stacked and coincident layers: copies hidden, candidates skipped, hole cuts
    for (layers, step) in [(3, 0.0), (4, 0.02)] {
        let tris = triangles(&layers::layered_pot(layers, step));
        add(same_on_any_thread_count(
            &format!("{layers} layers, step {step}"),
            &tris,
            1,
        ));
    }
    // what the statistics summed across chunks were checked on
    assert!(total.fragments > 0 && total.hidden > 0, "{total:?}");
    assert!(
        total.copies_hidden > 0 && total.candidates_skipped > 0,
        "{total:?}"
    );
    assert!(total.dropped_slivers > 0, "{total:?}");
    // holes: small triangles in front of large ones, each cut out of its large one
    let tri = |points: [[f64; 2]; 3], w: f64| ScreenTriangle {
        points,
        inv_depth: [w; 3],
        intensity: [[points[0][0], points[1][1], w, 0.0]; 3],
        mesh: 0,
        face: 0,
        surface: Default::default(),
    };
    let mut holes = Vec::new();
    for k in 0..12 {
        let x = 130.0 * k as f64 + 0.1 * k as f64;
        holes.push(tri([[x, 0.0], [x + 100.0, 0.0], [x, 100.0]], 0.1));
        holes.push(tri(
            [[x + 20.1, 20.3], [x + 30.7, 21.1], [x + 22.2, 31.9]],
            0.5,
        ));
    }
    let s = same_on_any_thread_count("holes", &holes, 3);
    assert_eq!(s.hole_cuts, 12, "{s:?}");
    // fewer triangles than threads, and none
    let tris = triangles(&layers::layered_pot(1, 0.0));
    same_on_any_thread_count("two triangles", &tris[..2], 1);
    same_on_any_thread_count("one triangle", &tris[..1], 1);
    same_on_any_thread_count("no triangle", &[], 1);
}

#[test]
fn memory_on_threads_stays_bounded_by_one_threads() {
    let _alone = MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    let tris = triangles(&layers::layered_pot(5, 0.02));
    let (_, one) = layers::peak_heap(|| exact_fragments_on(&tris, 1, 1));
    for threads in [2, 3] {
        let (_, peak) = layers::peak_heap(|| exact_fragments_on(&tris, 1, threads));
        // each thread's scratch (one triangle's candidates and pieces, a stamp per
        // triangle) and the chunks' fragments before they are joined
        assert!(
            peak <= 2 * one + (threads - 1) * 16 * tris.len(),
            "peak heap {peak} B on {threads} threads against {one} B on one"
        );
    }
}
