//! What a mesh holds, measured with a counting allocator: a Bézier mesh's build at most
//! `BEZIER_BUILD_BYTES_PER_TRIANGLE` a triangle (the figure checked against the memory
//! budget before a patch is tessellated), and a built mesh exactly what
//! `Mesh::held_bytes` says (what the renderers count while the meshes are held). One test
//! in this binary, so that no other test's allocations are counted with it.

// for its counting allocator and `peak_heap` (its scenes are not used here)
#[path = "layers/mod.rs"]
#[allow(dead_code)]
mod layers;

use cwisim_world::mesh::BEZIER_BUILD_BYTES_PER_TRIANGLE;
use cwisim_world::scene::parse_world;

#[test]
fn a_mesh_holds_what_the_budget_counts() {
    let text = |name: &str| {
        cwisim_world::embedded::embedded(name)
            .expect("embedded")
            .text
    };
    let teapot = parse_world(text("teapot"), None).expect("a valid scene");
    let mut largest = 0.0f64;
    for n in [4u32, 8, 16, 32] {
        let scene = teapot.clone();
        let (w, peak) = layers::peak_heap(|| scene.with_tessellation(n).expect("tessellates"));
        // the triangles the check counts: every quad two, before degenerate ones are dropped
        let counted = w.spec.meshes[0]
            .bezier
            .as_ref()
            .expect("patches")
            .triangles();
        assert!(
            peak as u64 <= counted * BEZIER_BUILD_BYTES_PER_TRIANGLE,
            "{n} × {n}: {peak} B at the peak, {} B counted",
            counted * BEZIER_BUILD_BYTES_PER_TRIANGLE
        );
        largest = largest.max(peak as f64 / counted as f64);
        let (copy, held) = layers::peak_heap(|| w.meshes[0].clone());
        assert_eq!(copy.held_bytes(), held as u64, "{n} × {n}: held bytes");
    }
    assert!(
        largest > 0.8 * BEZIER_BUILD_BYTES_PER_TRIANGLE as f64,
        "{largest:.0} B a triangle at most: {BEZIER_BUILD_BYTES_PER_TRIANGLE} counted"
    );
    // quads, whose four texture coordinates are held outside the face, and a mesh of
    // smoothed normals
    for name in ["pot", "still-life"] {
        let w = parse_world(text(name), None).expect("a valid scene");
        for m in &w.meshes {
            let (copy, held) = layers::peak_heap(|| m.clone());
            assert_eq!(copy.held_bytes(), held as u64, "{name}: {}", m.name);
        }
    }
}
