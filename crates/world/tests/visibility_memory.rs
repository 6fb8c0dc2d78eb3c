//! What exact visibility pair by pair holds a triangle, measured with a counting
//! allocator: at most `PAIRS_BYTES_PER_TRIANGLE` (and `PAIRS_BYTES_PER_TRIANGLE_PER_THREAD`
//! for each thread past the first) on the teapot from 992 to 16,256 triangles, the figure
//! the renderers check against the memory budget before projecting. One test in this
//! binary, so that no other test's allocations are counted with it.

// for its counting allocator and `peak_heap` (its scenes are not used here)
#[path = "layers/mod.rs"]
#[allow(dead_code)]
mod layers;

use cwisim_scene::Shading;
use cwisim_world::visibility::{
    exact_fragments_on, exact_memory, PAIRS_BYTES_PER_TRIANGLE, PAIRS_BYTES_PER_TRIANGLE_PER_THREAD,
};

#[test]
fn pairs_hold_what_the_budget_check_counts_a_triangle() {
    let teapot = cwisim_world::embedded::embedded("teapot")
        .expect("embedded")
        .text;
    let scene = cwisim_world::scene::parse_world(teapot, None).expect("a valid scene");
    let mut largest = 0.0f64;
    for n in [4, 8, 16] {
        let w = scene.clone().with_tessellation(n).expect("tessellates");
        let (tris, _) =
            cwisim_world::project::project_plain(&w, Shading::Gouraud).expect("projects");
        for threads in [1, 2] {
            let ((fragments, _), peak) =
                layers::peak_heap(|| exact_fragments_on(&tris, 1, threads));
            assert!(!fragments.is_empty());
            let allowed = exact_memory(tris.len() as u64, 0, threads);
            assert!(
                peak as u64 <= allowed,
                "{} triangles on {threads} thread(s): {peak} B at the peak, {allowed} B counted",
                tris.len()
            );
            eprintln!(
                "{} triangles, {threads} thread(s): {:.0} B a triangle at the peak",
                tris.len(),
                peak as f64 / tris.len() as f64
            );
            largest = largest.max(peak as f64 / tris.len() as f64);
        }
    }
    // the count is the figure, not a bound far above it
    assert!(
        largest > 0.8 * PAIRS_BYTES_PER_TRIANGLE as f64,
        "{largest:.0} B a triangle at most: {PAIRS_BYTES_PER_TRIANGLE} counted"
    );
    // and the triangles' own bytes and each further thread are counted on top
    assert_eq!(
        exact_memory(10, 176, 3),
        10 * (176 + PAIRS_BYTES_PER_TRIANGLE + 2 * PAIRS_BYTES_PER_TRIANGLE_PER_THREAD)
    );
}
