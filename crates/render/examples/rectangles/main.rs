//! A custom renderer through the X-processor array: `cargo run -p cwisim-render --example
//! rectangles`. Builds three overlapping rectangles, renders them through the pipeline
//! (the same one `cwisim render` runs, here on two threads), prints what the array did,
//! and writes the stream as an annotated text trace, `rectangles.cwt`, which
//! `cwisim run`, `cwisim stats` and `cwisim diff` read like any other.

mod renderer;

use cwisim_isa::Encoding;
use cwisim_render::{emit, render, ArrayConfig, Renderer, Taps};
use cwisim_xproc::ImageSink;
use renderer::{Rect, Rectangles};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let rects = vec![
        Rect {
            x0: 2,
            y0: 1,
            x1: 12,
            y1: 6,
            value: 0.5,
        },
        Rect {
            x0: 6,
            y0: 3,
            x1: 15,
            y1: 9,
            value: 0.25,
        },
        Rect {
            x0: 0,
            y0: 7,
            x1: 4,
            y1: 10,
            value: 1.0,
        },
    ];
    let renderer = Rectangles::new(16, 10, rects)?;
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
