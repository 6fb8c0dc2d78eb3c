//! Woo & Chall's Tables 1 and 2, measured on cwisim's own scenes at the paper's
//! 640×480: `n`, `m`, `m/n`; then per sampling mode `#Geometry`, `#Shading`, what each
//! costs the array, and the image error against the exact box-filtered reference; and
//! the convergence of point sampling to the exact coverage as `l` grows.
//!
//! ```sh
//! cargo run --release -p cwisim-study --example woo_chall_tables
//! ```
//!
//! Prints Markdown (the tables of `docs/REPRODUCTION.md`).

use cwisim_render::subsample::Grid;
use cwisim_render::{registry, Settings, Size};
use cwisim_scene::Shading;
use cwisim_study::tradeoff::{errors, measure, reference_image, Setting};
use cwisim_xproc::{Machine, Numeric};
use std::path::Path;

const SIZE: Size = Size {
    width: 640,
    height: 480,
};

/// The scenes: the teapot tessellated to the paper's scene sizes, and the others.
const SCENES: [(&str, Option<u32>, &str); 6] = [
    ("teapot", Some(8), "Spirals (n = 4,320)"),
    ("teapot", Some(9), "Room (n = 5,178)"),
    ("teapot", Some(17), "Rockets (n = 18,020)"),
    ("teapot", Some(21), "Lamp (n = 29,057)"),
    ("pot", None, "-"),
    ("still-life", None, "-"),
];

struct Mode {
    name: &'static str,
    shading: Shading,
    samples: u32,
    grid: Grid,
}

const MODES: [Mode; 6] = [
    Mode {
        name: "hidden",
        shading: Shading::Hidden,
        samples: 1,
        grid: Grid::Centre,
    },
    Mode {
        name: "1×1",
        shading: Shading::Gouraud,
        samples: 1,
        grid: Grid::Centre,
    },
    Mode {
        name: "3×3 centre",
        shading: Shading::Gouraud,
        samples: 3,
        grid: Grid::Centre,
    },
    Mode {
        name: "3×3 corner",
        shading: Shading::Gouraud,
        samples: 3,
        grid: Grid::Corner,
    },
    Mode {
        name: "4×4 centre",
        shading: Shading::Gouraud,
        samples: 4,
        grid: Grid::Centre,
    },
    Mode {
        name: "4×4 corner",
        shading: Shading::Gouraud,
        samples: 4,
        grid: Grid::Corner,
    },
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let machine = Machine::default();
    let woo = registry::find("woo-chall")?;
    let mut table1 = String::from(
        "| cwisim scene | stands for | n | m | m/n | most visible spans on a scanline |\n| --- | --- | ---: | ---: | ---: | ---: |\n",
    );
    let mut table2 = String::from(
        "| cwisim scene | sampling | #Geometry | ratio to 1×1 | #Shading | shading/geometry | forced pixels | instructions | Eval1 share | busy cycles | worst line | host ms | max error | RMS error |\n| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for (scene, tessellate, stands_for) in SCENES {
        let name = match tessellate {
            Some(n) => format!("{scene} ×{n}"),
            None => scene.to_string(),
        };
        let path = Path::new(scene);
        let base = Settings {
            size: Some(SIZE),
            tessellate,
            // still-life's main light casts shadows; the tables were measured without
            // them (as the paper's Table 2 runs shade no shadows)
            shadows: (scene == "still-life").then_some(false),
            ..Settings::default()
        };
        let reference = reference_image(Some(path), &base)?;
        let mut geometry_1 = 0u64;
        for mode in &MODES {
            let setting = Setting {
                renderer: woo,
                settings: Settings {
                    shading: mode.shading,
                    samples: mode.samples,
                    grid: mode.grid,
                    ..base
                },
                numeric: Numeric::F64,
            };
            let m = measure(Some(path), &setting, &machine)?;
            let c = |k: &str| m.counters.get(k).unwrap_or(0);
            if mode.name == "1×1" {
                geometry_1 = c("geometry");
            }
            if mode.name == "hidden" {
                let (n, active) = (c("triangles"), c("max_active"));
                table1.push_str(&format!(
                    "| {name} | {stands_for} | {n} | {active} | {:.1}% | {} |\n",
                    100.0 * active as f64 / n as f64,
                    c("max_visible_spans")
                ));
            }
            let instructions = m.stats.totals.instructions;
            let eval1 = c("edge_pixels") + c("run_eval1");
            let worst = m
                .stats
                .lines
                .iter()
                .map(|l| l.busy_cycles)
                .max()
                .unwrap_or(0);
            let busy: u64 = m.stats.lines.iter().map(|l| l.busy_cycles).sum();
            let (max, rms) = if mode.shading == Shading::Hidden {
                ("-".to_string(), "-".to_string())
            } else {
                let (max, rms, _) = errors(&m.image, &reference);
                (format!("{max:.2e}"), format!("{rms:.2e}"))
            };
            let ratio = if geometry_1 > 0 {
                format!("{:.2}", c("geometry") as f64 / geometry_1 as f64)
            } else {
                "-".into()
            };
            table2.push_str(&format!(
                "| {name} | {} | {} | {ratio} | {} | {:.3} | {} | {instructions} | {:.1}% | {busy} | {:.1}% | {:.0} | {max} | {rms} |\n",
                mode.name,
                c("geometry"),
                c("shading"),
                c("shading") as f64 / c("geometry").max(1) as f64,
                c("forced_pixels"),
                100.0 * eval1 as f64 / instructions.max(1) as f64,
                100.0 * worst as f64 / m.stats.line_period.max(1) as f64,
                m.time.as_secs_f64() * 1e3,
            ));
        }
    }
    println!("## Table 1\n\n{table1}\n## Table 2\n\n{table2}");

    // convergence: every sample shaded (P = 1), so the error is the sampling's alone
    println!("\n## Convergence (teapot ×8, Gouraud, P = 1, centre grid)\n");
    println!("| l | samples per pixel | max error | RMS error |\n| ---: | ---: | ---: | ---: |");
    let path = Path::new("teapot");
    let base = Settings {
        size: Some(SIZE),
        tessellate: Some(8),
        shade_p: Some(1.0),
        ..Settings::default()
    };
    let reference = reference_image(Some(path), &base)?;
    let mut points = Vec::new();
    for l in [1u32, 2, 4, 8, 16] {
        let setting = Setting {
            renderer: woo,
            settings: Settings { samples: l, ..base },
            numeric: Numeric::F64,
        };
        let m = measure(Some(path), &setting, &machine)?;
        let (max, rms, _) = errors(&m.image, &reference);
        println!("| {l} | {} | {max:.2e} | {rms:.2e} |", l * l);
        points.push((f64::from(l).ln(), rms.ln()));
    }
    let fit = &points[1..];
    let n = fit.len() as f64;
    let (mx, my) = (
        fit.iter().map(|p| p.0).sum::<f64>() / n,
        fit.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = fit.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / fit.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    println!("\nlog-log slope of the RMS error over l = 2…16: {slope:.2}");
    Ok(())
}
