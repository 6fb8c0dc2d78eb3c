//! The summary `cwisim render` prints: the scene, what the host side and the renderer
//! did, the array's cycles against the display, and the wall time of every stage.

use crate::draw::Drawn;
use cwisim_render::summary::{render_rows, LABEL_WIDTH};
use cwisim_render::Rendered;
use cwisim_xproc::Numeric;
use std::io::{self, Write};
use std::path::Path;
use std::time::Duration;

/// Wall time of the stages the command runs around the renderer.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Reading the scene, building meshes.
    pub load: Duration,
    /// Writing the outputs.
    pub output: Duration,
}

fn ms(d: Duration) -> String {
    let ms = d.as_secs_f64() * 1e3;
    if ms >= 100.0 {
        format!("{ms:.0} ms")
    } else if ms >= 1.0 {
        format!("{ms:.1} ms")
    } else {
        format!("{ms:.2} ms")
    }
}

/// The scene part of `--stats-json`: deterministic (no times, no paths).
pub fn scene_json(d: &Drawn) -> serde_json::Value {
    let mut json = d.renderer.scene_json();
    if !json.is_object() {
        json = serde_json::json!({});
    }
    json["name"] = d.source.name().into();
    json["kind"] = d.kind.into();
    json["renderer"] = d.renderer.name().into();
    json
}

/// Writes the render summary.
pub fn write_render_summary(
    out: &mut dyn Write,
    d: &Drawn,
    rendered: &Rendered,
    numeric: &Numeric,
    t: &StageTimes,
    written: &[&Path],
) -> io::Result<()> {
    let row = |out: &mut dyn Write, label: &str, value: String| {
        writeln!(out, "{label:<width$}{value}", width = LABEL_WIDTH)
    };
    // the rows every face of cwisim prints (the Python package's `Render.summary`
    // too), then the wall times and the files written, the command's own
    for (label, text) in render_rows(d, rendered, numeric) {
        row(out, &label, text)?;
    }
    let h = d.renderer.header();
    let tot = &rendered.stats.totals;
    let stages = d.renderer.stage_times();
    let total = t.load
        + stages.iter().map(|(_, d)| *d).sum::<Duration>()
        + rendered.renderer_time
        + rendered.array_time
        + t.output;
    let mut parts = vec![format!("load {}", ms(t.load))];
    parts.extend(stages.iter().map(|(name, d)| format!("{name} {}", ms(*d))));
    if rendered.array_in_bands {
        // each thread (the only one, on one thread) ran the array on the bands it
        // emitted, interleaved with emitting; the array then took them in, in order
        parts.push(format!(
            "Y-processor and array in bands {}",
            ms(rendered.renderer_time)
        ));
        parts.push(format!("array in order {}", ms(rendered.array_time)));
    } else {
        parts.push(format!("Y-processor {}", ms(rendered.renderer_time)));
        parts.push(format!("array {}", ms(rendered.array_time)));
    }
    parts.push(format!("output {}", ms(t.output)));
    parts.push(format!("total {}", ms(total)));
    row(out, "time", parts.join(" · "))?;
    if !written.is_empty() {
        let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
        let stacked = if tot.frames > 1 {
            format!(
                " (its {} frames stacked top to bottom in the images, {} rows each)",
                tot.frames, h.lines
            )
        } else {
            String::new()
        };
        row(out, "wrote", format!("{}{stacked}", names.join(", ")))?;
    }
    Ok(())
}
