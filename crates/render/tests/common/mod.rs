//! Helpers shared by the integration tests of `cwisim-render`.

// each test binary uses a part
#![allow(dead_code)]

pub mod footprint;
pub mod raycast;

use cwisim_render::{registry, render, ArrayConfig, Counters, LoadedScene, Settings, Taps};
use cwisim_world::{parse_any, AnyScene, WorldScene};
use cwisim_xproc::ImageSink;

/// The world scene of `text`, at `size` (`None`: its own).
pub fn world(text: &str, size: Option<(u32, u32)>) -> WorldScene {
    let scene = parse_any(text, None).unwrap();
    let scene = match size {
        Some((w, h)) => scene.with_size(w, h).unwrap(),
        None => scene,
    };
    match scene {
        AnyScene::World(w) => w,
        AnyScene::Screen(_) => panic!("a world scene"),
    }
}

/// The image `vanrij` draws of `w` under `settings` (the array's exact values).
pub fn rendered(w: &WorldScene, settings: &Settings) -> Vec<f64> {
    rendered_by("vanrij", w, settings)
}

/// The image renderer `name` draws of `w` under `settings` (the array's exact values).
pub fn rendered_by(name: &str, w: &WorldScene, settings: &Settings) -> Vec<f64> {
    let loaded = LoadedScene::built("test", AnyScene::World(w.clone()));
    drawn_on(name, loaded, settings, 1).0
}

/// The image renderer `name` draws of `loaded` under `settings` on `threads` threads
/// (the array's exact values), and the frame's counters.
pub fn drawn_on(
    name: &str,
    loaded: LoadedScene,
    settings: &Settings,
    threads: usize,
) -> (Vec<f64>, Counters) {
    let r = (registry::find(name).unwrap().build)(loaded, settings).unwrap();
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let done = render(
        &*r,
        &ArrayConfig::default(),
        threads,
        &mut sink,
        Taps::default(),
    )
    .unwrap();
    (sink.finish().unwrap().data, done.counters)
}
