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
//! allocated (a counting allocator wraps the system one). The figures are in
//! `docs/VISIBILITY.md`.

use cwisim_scene::Shading;
use cwisim_world::visibility::exact_fragments;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The system allocator, counting the bytes live and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded to the system allocator with the caller's layout.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

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
            let base = LIVE.load(Ordering::Relaxed);
            PEAK.store(base, Ordering::Relaxed);
            let start = Instant::now();
            let (fragments, stats) = exact_fragments(&tris, 1);
            let time = start.elapsed();
            let peak = PEAK.load(Ordering::Relaxed) - base;
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
