//! Woo & Chall's Figure 10 measured in bytes: `textures4`'s four textures, their checkers
//! made `N × N` texels so that the texels dominate the heap, drawn by every renderer that
//! draws them (each texture decoded at its first shading call and dropped after the last
//! row its triangles reach), one thread each. A counting allocator gives each render's
//! peak heap beyond the scene read (the texels, their tables and the render's own
//! buffers), printed against one texture's bytes.
//!
//! ```text
//! cargo run --release -p cwisim-render --example texture_residency [N]
//! ```
//!
//! N defaults to 512 (12.6 MB a texture). The figures are in docs/REPRODUCTION.md.

use cwisim_fuzzing::heap::{peak_heap, Counting};
use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Settings, Taps};
use cwisim_world::embedded::embedded;
use cwisim_world::parse_any;
use cwisim_xproc::NullSink;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(512, |s| s.parse().expect("N is a whole number"));
    let mut v: serde_json::Value =
        serde_json::from_str(embedded("textures4").expect("embedded").text).expect("a scene");
    for m in v["meshes"].as_array_mut().expect("meshes") {
        if let Some(c) = m.pointer_mut("/material/texture/checker") {
            c["squares"] = serde_json::json!([n, n]);
        }
    }
    let text = v.to_string();
    let texture = (n * n + (n + 1) * (n + 1)) * 3 * 8;
    println!(
        "| renderer | textures decoded | peak heap of the render | in textures of {:.1} MB |",
        texture as f64 / 1e6
    );
    println!("| --- | ---: | ---: | ---: |");
    for entry in registry::REGISTRY.iter().filter(|e| e.textures) {
        let renderer = entry.name;
        let scene = parse_any(&text, None).expect("a valid scene");
        let cwisim_world::AnyScene::World(w) = &scene else {
            unreachable!("textures4 is a world scene")
        };
        let store = std::sync::Arc::clone(&w.textures);
        // (a renderer of Bézier patches refuses a scene without them)
        let Ok(r) = (entry.build)(LoadedScene::built("textures4", scene), &Settings::default())
        else {
            continue;
        };
        let (_, peak) = peak_heap(|| {
            render(
                &*r,
                &ArrayConfig::default(),
                1,
                &mut NullSink,
                Taps::default(),
            )
            .expect("drawn")
        });
        println!(
            "| `{renderer}` | {} | {:.1} MB | {:.2} |",
            store.loads(),
            peak as f64 / 1e6,
            peak as f64 / texture as f64
        );
    }
}
