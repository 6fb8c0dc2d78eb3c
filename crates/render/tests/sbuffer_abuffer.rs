//! `sbuffer --sbuffer abuffer`, Barkan & Gordon's §5.2 scanline A-buffer: against the
//! exact box-filtered image (`vanrij --aa box --visibility exact`, exact coverage of the
//! visible surfaces), whose distance must fall as the mask grows; against the S-buffer's
//! supersampling where no two polygons share a pixel's samples (the two are then the
//! same mean of the same samples); and its refusals.

mod common;

use cwisim_render::settings::SbufferMode;
use cwisim_render::subsample::Grid;
use cwisim_render::{registry, Counters, LoadedScene, Settings, Size, Source};
use cwisim_scene::Shading;
use cwisim_world::Visibility;

fn abuffer(samples: u32) -> Settings {
    Settings {
        samples,
        sbuffer: SbufferMode::Abuffer,
        ..Settings::default()
    }
}

fn loaded(name: &str, s: &Settings) -> LoadedScene {
    Source::resolve(Some(name.as_ref()))
        .unwrap()
        .load_for(s)
        .unwrap()
}

fn draw(name: &str, scene: &str, s: &Settings) -> (Vec<f64>, Counters) {
    draw_on(name, scene, s, 1)
}

fn draw_on(name: &str, scene: &str, s: &Settings, threads: usize) -> (Vec<f64>, Counters) {
    common::drawn_on(name, loaded(scene, s), s, threads)
}

fn mean_error(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() / a.len() as f64
}

/// `s` at `w × h`; still-life without its shadows (`vanrij` draws them exactly, the
/// S-buffer sampled).
fn sized(s: Settings, scene: &str, w: u32, h: u32) -> Settings {
    Settings {
        size: Some(Size {
            width: w,
            height: h,
        }),
        shadows: (scene == "still-life").then_some(false),
        ..s
    }
}

#[test]
fn its_error_against_the_exact_image_falls_with_the_mask() {
    for (scene, w, h) in [("pot", 64, 64), ("still-life", 96, 64)] {
        let exact = sized(
            Settings {
                visibility: Visibility::Exact,
                aa: cwisim_scene::Antialias::Box,
                ..Settings::default()
            },
            scene,
            w,
            h,
        );
        let (reference, _) = draw("vanrij", scene, &exact);
        let errors: Vec<f64> = [2, 4, 8]
            .iter()
            .map(|&l| {
                mean_error(
                    &draw("sbuffer", scene, &sized(abuffer(l), scene, w, h)).0,
                    &reference,
                )
            })
            .collect();
        println!("{scene}: {errors:?}");
        assert!(
            errors[1] < errors[0] && errors[2] < errors[1],
            "{scene}: 2×2, 4×4, 8×8: {errors:?}"
        );
    }
}

#[test]
fn without_shared_samples_it_is_the_s_buffer_s_supersampling() {
    // cases12's trapezia share no pixel's samples: each fragment is all a pixel's samples
    // of its polygon, and the mean of the same samples
    for l in [2, 4, 8] {
        for shading in [Shading::Flat, Shading::Gouraud] {
            let a = Settings {
                shading,
                ..abuffer(l)
            };
            let s = Settings {
                sbuffer: SbufferMode::Host,
                merge_subscanlines: true,
                ..a
            };
            let (ai, _) = draw("sbuffer", "cases12", &a);
            let (si, _) = draw("sbuffer", "cases12", &s);
            let e = ai
                .iter()
                .zip(&si)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(e < 1e-12, "{l}×{l}, {shading:?}: {e}");
        }
    }
}

#[test]
fn it_refuses_what_its_mask_cannot_hold() {
    let build = |s: &Settings| {
        (registry::find("sbuffer").unwrap().build)(loaded("pot", s), s)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    assert!(build(&abuffer(9)).contains("--samples 1 to 8"));
    assert!(build(&Settings {
        grid: Grid::Corner,
        ..abuffer(4)
    })
    .contains("--grid centre"));
    assert!(build(&abuffer(8)).is_empty());
}

#[test]
fn the_image_is_the_same_at_any_thread_count() {
    let s = sized(abuffer(4), "still-life", 96, 64);
    let (one, c) = draw("sbuffer", "still-life", &s);
    assert!(c.get("fragments").unwrap() > 0);
    for threads in [2, 3] {
        assert_eq!(draw_on("sbuffer", "still-life", &s, threads).0, one);
    }
}
