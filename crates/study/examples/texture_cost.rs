//! What a texture's frequency costs the array (docs/TEXTURES.md, "What a texture
//! costs"): the rows of `cwisim_study::texture_cost` as CSV on stdout, the chart as a PNG.
//!
//! ```sh
//! cargo run --release -p cwisim-study --example texture_cost -- [SIZE] [RAYS] [PLOT.png]
//! ```
//!
//! SIZE the image side (512), RAYS the reference's samples per pixel side (64).

use cwisim_study::texture_cost::{csv, measure, render_plot, CostPlan};
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let mut plan = CostPlan::default();
    if let Some(size) = args.next() {
        plan.size = size
            .parse()
            .map_err(|e| format!("SIZE: the image side in pixels ({e})"))?;
    }
    if let Some(rays) = args.next() {
        plan.rays = rays
            .parse()
            .map_err(|e| format!("RAYS: reference samples per pixel side ({e})"))?;
    }
    let plot = args.next();
    let start = std::time::Instant::now();
    let rows = measure(&plan, |done, total| {
        eprint!("\r{done}/{total} settings measured");
    })?;
    eprintln!(" in {:.1} s", start.elapsed().as_secs_f64());
    print!("{}", csv(&rows));
    if let Some(path) = plot {
        let image = render_plot(&rows)?;
        let file = std::fs::File::create(&path).map_err(|e| format!("{path}: {e}"))?;
        image.encode_png(std::io::BufWriter::new(file))?;
        eprintln!("wrote {path}");
    }
    Ok(())
}
