//! How exact visibility's time and memory grow with depth complexity: the pot drawn as
//! `L` layers of one surface, for three families of layers —
//!
//! - `coincident`: `L` copies of the same surface (every layer ties with every other);
//! - `near`: each layer's radii scaled by `1 + k·1e-9` (nearly coincident: no longer ties,
//!   but depths within a few ulps of each other);
//! - `stacked`: each layer's radii scaled by `1 + k·0.02` (parallel shells, each hiding the
//!   next).
//!
//! ```text
//! cargo run --release -p cwisim-world --example depth_complexity [LAYERS…]
//! ```
//!
//! LAYERS default to 1 2 4 8 16 32. Prints a Markdown table: layers, triangles, candidate
//! pairs, occluding pairs, fragments, wall time of `exact_fragments` and the peak heap it
//! allocated (a counting allocator wraps the system one: `tests/layers/mod.rs`). The figures are in
//! `docs/VISIBILITY.md`.

use cwisim_scene::Shading;
use cwisim_world::visibility::exact_fragments;
use std::time::Instant;

#[path = "../tests/layers/mod.rs"]
mod layers;

fn main() {
    let layers: Vec<usize> = {
        let given: Result<Vec<usize>, _> = std::env::args().skip(1).map(|s| s.parse()).collect();
        match given {
            Ok(v) if v.is_empty() => vec![1, 2, 4, 8, 16, 32],
            Ok(v) => v,
            Err(_) => {
                eprintln!("usage: depth_complexity [LAYERS…]");
                std::process::exit(2)
            }
        }
    };
    println!(
        "| family | layers | triangles | occluding pairs | skipped candidates | fragments | hidden | time (ms) | peak heap (MB) |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (family, step) in [("coincident", 0.0), ("near", 1e-9), ("stacked", 0.02)] {
        for &l in &layers {
            let scene = cwisim_world::scene::parse_world(&layers::layered_pot(l, step), None)
                .expect("a valid scene");
            let (tris, _) =
                cwisim_world::project::project(&scene, Shading::Gouraud).expect("projects");
            let start = Instant::now();
            let ((fragments, stats), peak) = layers::peak_heap(|| exact_fragments(&tris, 1));
            let time = start.elapsed();
            drop(fragments);
            println!(
                "| {family} | {l} | {} | {} | {} | {} | {} | {:.1} | {:.1} |",
                stats.triangles,
                stats.occluding_pairs,
                stats.candidates_skipped,
                stats.fragments,
                stats.hidden,
                time.as_secs_f64() * 1e3,
                peak as f64 / 1e6
            );
        }
    }
}
