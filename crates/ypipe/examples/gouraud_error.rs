//! The report's Gouraud approximation and the exact mode against the exact box filter.
//!
//! The report's DO_FILL emits, per pixel, coverage × the Gouraud intensity at the
//! pixel's centre (van Rij 3.3; `--aa box-centre`). The true box filter is the integral
//! of the intensity over the covered area, what `--aa box` sends with the same
//! instructions. This prints, for a few shapes, the largest and the RMS per-pixel
//! difference of the report's mode (over the pixels the shape touches), and the largest
//! of the exact mode, as a Markdown table:
//!
//! ```sh
//! cargo run --release -p cwisim-ypipe --example gouraud_error
//! ```

use cwisim_isa::TraceWrite;
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_xproc::{EngineWriter, ImageSink, Machine, Timing};
use cwisim_ypipe::exact::{scene_box_filtered, scene_coverage};
use cwisim_ypipe::{emit, header, Antialias, Options};

fn scene(width: u32, height: u32, polygons: Vec<Polygon>) -> ScreenScene {
    ScreenScene {
        width,
        height,
        channels: 1,
        polygons,
    }
}

fn tri(v: [[f64; 2]; 3], i: [f64; 3]) -> Polygon {
    Polygon {
        vertices: v.to_vec(),
        intensity: i.iter().map(|x| vec![*x].into()).collect(),
        depth: None,
    }
}

fn render(s: &ScreenScene, aa: Antialias) -> Vec<f64> {
    let h = header(s);
    let mut sink = ImageSink::new(h.width as usize, 1, 1 << 30);
    {
        let mut w = EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink)
            .expect("machine");
        let options = Options {
            aa,
            ..Options::default()
        };
        emit(s, &options, &mut w).expect("emit");
        w.finish().expect("finish");
    }
    sink.finish().expect("image").data
}

fn main() {
    let shapes = [
        (
            "gentle gradient, large triangle",
            scene(
                64,
                64,
                vec![tri(
                    [[2.3, 3.1], [61.7, 9.4], [20.2, 60.8]],
                    [0.2, 0.9, 0.5],
                )],
            ),
        ),
        (
            "steep gradient (0 to 1 over 8 px)",
            scene(
                16,
                16,
                vec![tri([[2.0, 2.0], [10.0, 2.5], [3.0, 13.0]], [0.0, 1.0, 0.0])],
            ),
        ),
        (
            "sliver 0.1 px wide",
            scene(
                64,
                16,
                vec![tri(
                    [[1.0, 1.0], [62.0, 14.0], [62.0, 14.1]],
                    [0.0, 1.0, 1.0],
                )],
            ),
        ),
        (
            "sub-pixel triangle",
            scene(
                4,
                4,
                vec![tri([[1.1, 1.2], [1.9, 1.4], [1.3, 1.95]], [0.0, 1.0, 0.5])],
            ),
        ),
        (
            "figure 25 (three triangles)",
            scene(
                16,
                14,
                vec![
                    tri([[2.0, 12.0], [10.0, 12.0], [2.0, 6.0]], [1.0, 0.5, 0.75]),
                    tri([[10.0, 12.0], [10.0, 4.67], [8.55, 6.0]], [0.5, 0.25, 1.0]),
                    tri([[2.0, 6.0], [8.55, 6.0], [14.0, 1.0]], [0.75, 1.0, 0.125]),
                ],
            ),
        ),
    ];
    println!(
        "| shape | pixels | max error | RMS error | max error / max intensity | max error, exact mode |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    for (name, s) in &shapes {
        let sim = render(s, Antialias::BoxCentre);
        let exact_mode = render(s, Antialias::Box);
        let exact = scene_box_filtered(s);
        let cover = scene_coverage(s);
        let mut n = 0usize;
        let (mut max, mut sq, mut peak, mut max_exact) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for k in 0..sim.len() {
            if cover[k] > 0.0 {
                let d = (sim[k] - exact[k]).abs();
                max = max.max(d);
                max_exact = max_exact.max((exact_mode[k] - exact[k]).abs());
                sq += d * d;
                n += 1;
            }
        }
        for p in &s.polygons {
            for i in &p.intensity {
                peak = peak.max(i[0]);
            }
        }
        let rms = (sq / n.max(1) as f64).sqrt();
        println!(
            "| {name} | {n} | {max:.3e} | {rms:.3e} | {:.2} % | {max_exact:.1e} |",
            100.0 * max / peak
        );
    }
}
