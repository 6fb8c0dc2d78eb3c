//! How close each texture filter comes to the texture's true mean over a pixel: a
//! checkerboard floor receding toward the horizon (docs/TEXTURES.md), drawn by `vanrij`
//! with the box filter (the summed-area table over the footprint's bounding box) and with
//! point sampling, against 64 × 64 rays per pixel.
//!
//! ```sh
//! cargo run --release -p cwisim-render --example texture_filter -- [SIZE] [RAYS]
//! ```

// the tests' ray caster and texture reference (crates/render/tests/common)
#[path = "../tests/common/raycast.rs"]
#[allow(dead_code)]
mod raycast;

#[path = "../tests/common/footprint.rs"]
mod footprint;

use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Settings, Taps};
use cwisim_scene::Antialias;
use cwisim_world::texture::TextureFilter;
use cwisim_world::{AnyScene, WorldScene};
use cwisim_xproc::ImageSink;
use std::time::Instant;

fn rendered(w: &WorldScene, filter: TextureFilter) -> Vec<f64> {
    let settings = Settings {
        aa: Antialias::Box,
        texture_filter: filter,
        shade_tolerance: 0.0,
        ..Settings::default()
    };
    let loaded = LoadedScene::built("floor", AnyScene::World(w.clone()));
    let r = (registry::find("vanrij").unwrap().build)(loaded, &settings).unwrap();
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    render(&*r, &ArrayConfig::default(), 1, &mut sink, Taps::default()).unwrap();
    sink.finish().unwrap().data
}

fn main() {
    let mut args = std::env::args().skip(1);
    let size: u32 = args
        .next()
        .map_or(128, |a| a.parse().expect("SIZE: pixels per side"));
    let rays: usize = args
        .next()
        .map_or(64, |a| a.parse().expect("RAYS: per pixel side"));
    let w = footprint::floor(size);
    let start = Instant::now();
    let reference = footprint::reference(&w, size, rays);
    eprintln!(
        "reference: {rays}×{rays} rays per pixel, {:.1} s",
        start.elapsed().as_secs_f64()
    );
    println!("filter,pixels,rms,max");
    for filter in [TextureFilter::Box, TextureFilter::Point] {
        let (rms, max, n) = footprint::errors(&rendered(&w, filter), &reference);
        println!("{},{n},{rms:.4},{max:.4}", filter.name());
    }
}
