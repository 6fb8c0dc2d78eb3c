//! The pot at 1024×1024 end to end (as `pot_1024` in `benches/pipeline.rs`: from the parsed
//! scene, preparation, the Y-processor and the array into an image), with variants
//! **alternating in one process**, so that a shared machine's slow spells fall on every
//! variant alike — on a noisy machine the only comparison that holds still:
//!
//! ```text
//! cargo run --release -p cwisim-render --example pot_alternating [FRAMES]
//! ```
//!
//! For each visibility mode: one thread against two (target 7 of issue 18), and one
//! thread with the image's room reserved up front against grown as it comes
//! (`ImageSink::with_room_for`). Prints the fastest frame and the first quartile of each
//! (FRAMES of each, 40 unless given), and the ratios. docs/PERFORMANCE.md quotes it.

use cwisim_render::vanrij::VanRij;
use cwisim_render::{render, ArrayConfig, LoadedScene, PolygonScene, Settings, Taps};
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, project::project, resolve_on, AnyScene, Visibility, WorldScene};
use cwisim_xproc::ImageSink;
use cwisim_ypipe::{header, Shading};
use std::time::Instant;

fn pot(size: u32) -> WorldScene {
    let text = embedded("pot").expect("the pot is embedded").text;
    match parse_any(text, None)
        .expect("the pot reads")
        .with_size(size, size)
    {
        Ok(AnyScene::World(w)) => w,
        _ => unreachable!("the pot is a world scene of any size"),
    }
}

/// One frame on `threads` threads, the image reserved up front or not; its wall time, ms.
fn frame(w: &WorldScene, visibility: Visibility, threads: usize, reserve: bool) -> f64 {
    let start = Instant::now();
    let (triangles, _) = project(w, Shading::Gouraud).expect("the pot projects");
    let (polygons, _) = resolve_on(&triangles, w.channels(), visibility, threads);
    let screen = w.screen(polygons);
    let h = header(&screen);
    let settings = Settings {
        visibility,
        ..Settings::default()
    };
    let loaded = LoadedScene::built("pot", AnyScene::Screen(screen));
    let mut polygons = PolygonScene::new(loaded, &settings).expect("the pot prepares");
    polygons.visibility_mode = Some(visibility);
    let renderer = VanRij::from_polygons(polygons, &settings);
    let mut image = ImageSink::new(h.width as usize, h.channel_count(), 1 << 34);
    if reserve {
        image = image.with_room_for(h.lines.into());
    }
    let done = render(
        &renderer,
        &ArrayConfig::default(),
        threads,
        &mut image,
        Taps::default(),
    )
    .expect("the pot renders");
    std::hint::black_box((done.stats.totals.cycles, image.finish().expect("fits")));
    start.elapsed().as_secs_f64() * 1e3
}

/// The fastest and the first quartile of `times`, ms.
fn low(times: &mut [f64]) -> (f64, f64) {
    times.sort_by(f64::total_cmp);
    (times[0], times[times.len() / 4])
}

fn main() {
    let frames: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("FRAMES: a count of frames"))
        .unwrap_or(40)
        .max(1);
    let w = pot(1024);
    for (name, visibility) in [("eval0", Visibility::Eval0), ("exact", Visibility::Exact)] {
        // (threads, reserved): one thread reserved, two threads reserved, one thread grown
        let variants = [(1, true), (2, true), (1, false)];
        let mut times = vec![Vec::with_capacity(frames); variants.len()];
        for _ in 0..frames {
            for (k, &(threads, reserve)) in variants.iter().enumerate() {
                times[k].push(frame(&w, visibility, threads, reserve));
            }
        }
        let [one, two, grown] = [0, 1, 2].map(|k| low(&mut times[k]));
        println!(
            "{name}: one thread {:.2} / {:.2} ms, two threads {:.2} / {:.2} ms (speed-up {:.2}× / {:.2}×); \
             one thread, image grown {:.2} / {:.2} ms (reserving: {:.2}× / {:.2}×)   [fastest / first quartile]",
            one.0, one.1, two.0, two.1, one.0 / two.0, one.1 / two.1,
            grown.0, grown.1, grown.0 / one.0, grown.1 / one.1,
        );
    }
}
