//! How exact cwisim's anti-aliased fill is next to its peers: for each polygon set, each
//! rasterizer's coverage image against the exact summed coverage
//! (`cwisim_ypipe::exact::coverage` per polygon), max and RMS error per pixel.
//!
//! ```text
//! cargo run --release -p cwisim-world --example peer_accuracy [SIZE]
//! ```
//!
//! SIZE defaults to 1024. What is compared, and how each peer is driven:
//! `tests/peers/mod.rs`. The timings: `cargo bench -p cwisim-world --bench peers`.

#[path = "../tests/peers/mod.rs"]
mod peers;

fn main() {
    let size: u32 = match std::env::args().nth(1) {
        None => 1024,
        Some(s) => s.parse().unwrap_or_else(|_| {
            eprintln!("usage: peer_accuracy [SIZE]");
            std::process::exit(2)
        }),
    };
    let sets = [
        ("pot", peers::pot(size), true),
        ("random", peers::random(size, 200, 0x5EED_CAFE), false),
    ];
    println!(
        "| set | polygons | edge pixels | rasterizer | mode | max abs error | RMS (all pixels) | RMS (edge pixels) |"
    );
    println!("| --- | ---: | ---: | --- | --- | ---: | ---: | ---: |");
    let mut notes = Vec::new();
    for (name, scene, one_path) in &sets {
        notes.push(format!(
            "{name}: {} polygons, the Y-processor's flat box-filtered stream is {} instructions",
            scene.polygons.len(),
            peers::ypipe_only(scene, cwisim_ypipe::Shading::Flat)
        ));
        for row in peers::accuracy(scene, *one_path) {
            let e = row.error;
            println!(
                "| {name} {size}² | {} | {} | {} | {} | {:.2e} | {:.2e} | {:.2e} |",
                scene.polygons.len(),
                e.edge_pixels,
                row.rasterizer,
                row.mode,
                e.max,
                e.rms,
                e.edge_rms
            );
        }
    }
    println!();
    for n in notes {
        println!("{n}");
    }
}
