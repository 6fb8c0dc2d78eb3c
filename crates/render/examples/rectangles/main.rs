//! A custom renderer through the X-processor array: `cargo run -p cwisim-render --example
//! rectangles`. Takes three overlapping rectangles, renders them through the pipeline
//! (the same one `cwisim render` runs, here on two threads), prints what the array did,
//! and writes the stream as a text trace, `rectangles.cwt`, which
//! `cwisim run`, `cwisim stats` and `cwisim diff` read like any other.

mod renderer;

use cwisim_isa::Encoding;
use cwisim_render::{emit, render, ArrayConfig, Renderer, Taps};
use cwisim_xproc::ImageSink;
use renderer::three_rectangles;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let renderer = three_rectangles();
    let h = renderer.header();
    let mut image = ImageSink::new(h.width as usize, h.channel_count(), 1 << 20);
    let done = render(
        &renderer,
        &ArrayConfig::default(),
        2,
        &mut image,
        Taps::default(),
    )?;
    let image = image.finish()?;
    for row in image.data.chunks(image.width) {
        let line: String = row.iter().map(|v| format!("{v:5.2}")).collect();
        println!("{line}");
    }
    println!(
        "{} instructions, {} cycles; counters {:?}",
        done.stats.totals.instructions,
        done.stats.totals.cycles,
        done.counters.iter().collect::<Vec<_>>()
    );
    let mut bytes = Vec::new();
    let mut trace = Encoding::Text.writer(&mut bytes, &h)?;
    emit(&renderer, &mut *trace)?;
    drop(trace);
    std::fs::write("rectangles.cwt", bytes)?;
    println!("wrote rectangles.cwt");
    Ok(())
}
