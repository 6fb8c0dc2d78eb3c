//! The embedded pot through the whole pipeline with every intensity 1: with exact
//! visibility no pixel is covered more than once, and the image holds exactly the area
//! of the visible fragments.

use cwisim_isa::TraceWrite;
use cwisim_scene::ScreenScene;
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, to_screen, AnyScene, Visibility};
use cwisim_xproc::{EngineWriter, ImageSink, Machine, Timing};
use cwisim_ypipe::exact::polygon_area;
use cwisim_ypipe::{emit, header, Claim, Options, Shading};

/// The pot with ambient-only light of intensity 1 (`k_a` = 1): coverage, not shading.
fn white_pot(size: u32) -> cwisim_world::WorldScene {
    let text = embedded("pot")
        .expect("pot")
        .text
        .replace(r#""ambient": 0.25"#, r#""ambient": 1"#)
        .replace(
            r#""lights": [ { "position": [4, 6, 5], "intensity": 0.85 } ],"#,
            "",
        )
        .replace(
            r#""k_a": 0.4, "k_d": 0.75, "k_s": 0.45, "n": 16"#,
            r#""k_a": 1, "k_d": 0, "k_s": 0, "n": 1"#,
        );
    let AnyScene::World(w) = parse_any(&text, None)
        .expect("reads")
        .with_size(size, size)
        .expect("size")
    else {
        panic!("a world scene")
    };
    w
}

fn render(screen: &ScreenScene, options: &Options) -> Vec<f64> {
    let h = header(screen);
    let mut sink = ImageSink::new(h.width as usize, 1, 1 << 30);
    {
        let mut w = EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink)
            .expect("machine");
        emit(screen, options, &mut w).expect("emit");
        w.finish().expect("finish");
    }
    sink.finish().expect("image").data
}

#[test]
fn exact_visibility_covers_every_pixel_at_most_once() {
    let w = white_pot(160);
    let exact = to_screen(&w, Shading::Gouraud, Visibility::Exact).expect("prepared");
    let image = render(&exact.screen, &Options::default());
    let max = image.iter().cloned().fold(0.0, f64::max);
    assert!(max <= 1.0 + 1e-9, "a pixel covered {max} times");
    assert!(
        (max - 1.0).abs() < 1e-9,
        "the pot's inside is fully covered: {max}"
    );
    let total: f64 = image.iter().sum();
    let area: f64 = exact.screen.polygons.iter().map(polygon_area).sum();
    assert!((total - area).abs() < 1e-6, "{total} vs {area}");

    // the test can tell: the eval0 approximation covers some pixels more than once
    // (a back face adds where the front ones' shared edges leave a pixel unclaimed)
    let eval0 = to_screen(&w, Shading::Gouraud, Visibility::Eval0).expect("prepared");
    let options = Options {
        claim: Claim::Eval0 { tolerance: 0.0 },
        ..Options::default()
    };
    let approx = render(&eval0.screen, &options);
    let over = approx.iter().filter(|v| **v > 1.0 + 1e-9).count();
    assert!(over > 0);
    // where both are exactly 1 (interiors), eval0 agrees
    let agree = image
        .iter()
        .zip(&approx)
        .filter(|(a, _)| (**a - 1.0).abs() < 1e-12)
        .filter(|(a, b)| (**a - **b).abs() < 1e-9)
        .count();
    let full = image.iter().filter(|a| (**a - 1.0).abs() < 1e-12).count();
    assert!(agree * 10 > full * 6, "{agree} of {full}");
}
