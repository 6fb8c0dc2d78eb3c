//! Barkan & Gordon's §5.2 scanline A-buffer measured: on `pot` (200 × 200) and
//! `still-life` (240 × 160, its shadows off), Gouraud shading, the S-buffer's
//! supersampling (`--samples l`, sub-scanlines merged by the host: one pass per row) and
//! the A-buffer (`--sbuffer abuffer --samples l`: an `l × l` coverage mask) at
//! `l` = 2, 4, 8, each against the exact box-filtered image (`vanrij --aa box
//! --visibility exact`): the mean and largest distance per value, the array
//! instructions, the A-buffer's fragments, the bytes of the one-scanline buffer (the
//! renderer's `buffer_bytes`: its elements' sizes times their count, at the row holding
//! most) and the Y-processor's host time (one run, one thread).
//!
//! ```sh
//! cargo run --release -p cwisim-render --example abuffer_table
//! ```

use cwisim_render::settings::SbufferMode;
use cwisim_render::{registry, render, ArrayConfig, Rendered, Settings, Size, Source};
use cwisim_scene::Antialias;
use cwisim_world::Visibility;
use cwisim_xproc::ImageSink;

fn draw(name: &str, scene: &str, s: &Settings) -> (Vec<f64>, Rendered) {
    let loaded = Source::resolve(Some(scene.as_ref()))
        .and_then(|src| src.load_for(s))
        .expect("an embedded scene");
    let r = (registry::find(name).expect("registered").build)(loaded, s).expect("it draws");
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let done = render(
        &*r,
        &ArrayConfig::default(),
        1,
        &mut sink,
        Default::default(),
    )
    .expect("it draws");
    (sink.finish().expect("an image").data, done)
}

fn main() {
    println!("| scene | mode | samples per pixel | mean error | largest error | instructions | fragments | buffer bytes | host ms |");
    println!("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (scene, width, height) in [("pot", 200, 200), ("still-life", 240, 160)] {
        let base = Settings {
            size: Some(Size { width, height }),
            shadows: (scene == "still-life").then_some(false),
            ..Settings::default()
        };
        let (exact, _) = draw(
            "vanrij",
            scene,
            &Settings {
                aa: Antialias::Box,
                visibility: Visibility::Exact,
                ..base
            },
        );
        for l in [2, 4, 8] {
            for (mode, settings) in [
                (
                    "S-buffer",
                    Settings {
                        samples: l,
                        merge_subscanlines: true,
                        ..base
                    },
                ),
                (
                    "A-buffer",
                    Settings {
                        samples: l,
                        sbuffer: SbufferMode::Abuffer,
                        ..base
                    },
                ),
            ] {
                let (image, done) = draw("sbuffer", scene, &settings);
                let d: Vec<f64> = image
                    .iter()
                    .zip(&exact)
                    .map(|(a, b)| (a - b).abs())
                    .collect();
                let mean = d.iter().sum::<f64>() / d.len() as f64;
                let largest = d.iter().copied().fold(0.0, f64::max);
                let c = &done.counters;
                println!(
                    "| {scene} | {mode} | {l}×{l} | {mean:.6} | {largest:.4} | {} | {} | {} | {:.1} |",
                    done.stats.totals.instructions,
                    c.get("fragments")
                        .map_or_else(|| "-".to_string(), |f| f.to_string()),
                    c.get("buffer_bytes").unwrap_or(0),
                    done.renderer_time.as_secs_f64() * 1e3,
                );
            }
        }
    }
}
