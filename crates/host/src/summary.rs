//! The summary `cwisim render` prints: the scene, what the host side and the renderer
//! did, the array's cycles against the display, and the wall time of every stage.

use crate::draw::Drawn;
use crate::report::TraceShape;
use cwisim_isa::Opcode;
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

fn channels_name(c: u8) -> String {
    match c {
        1 => "grey".into(),
        3 => "RGB".into(),
        n => format!("{n} channels"),
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

/// A renderer's counters as text: `name value` for every non-zero counter, in the
/// renderer's order, broken into lines of at most `width` characters (the first line
/// starts after `first` characters of its own) and continued after `indent` spaces.
pub fn counters_text(
    counters: &cwisim_render::Counters,
    first: usize,
    indent: usize,
    width: usize,
) -> String {
    let mut out = String::new();
    let mut column = first;
    for (name, v) in counters.iter().filter(|&(_, v)| v > 0) {
        let part = format!("{} {v}", name.replace('_', " "));
        if !out.is_empty() {
            if column + 2 + part.len() > width {
                out.push_str(",\n");
                out.push_str(&" ".repeat(indent));
                column = indent;
            } else {
                out.push_str(", ");
                column += 2;
            }
        }
        column += part.chars().count();
        out.push_str(&part);
    }
    out
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
    let row = |out: &mut dyn Write, label: &str, value: String| writeln!(out, "{label:<13}{value}");
    let h = d.renderer.header();
    let shape = TraceShape {
        width: h.width,
        lines: h.lines,
        channels: h.channels,
    };
    let stats = &rendered.stats;
    row(
        out,
        "scene",
        format!(
            "{} ({}, {}×{}, {}): {}, {numeric} registers",
            d.source.name(),
            d.kind,
            shape.width,
            shape.lines,
            channels_name(shape.channels),
            d.renderer.settings_phrase(),
        ),
    )?;
    for (label, text) in d.renderer.summary_rows(&rendered.counters, stats) {
        row(out, label, text)?;
    }
    let name = d.renderer.name();
    row(
        out,
        "Y-processor",
        format!(
            "{name}: {}",
            counters_text(&rendered.counters, 13 + name.len() + 2, 13, 100)
        ),
    )?;
    let tot = &stats.totals;
    let ops: Vec<String> = Opcode::ALL
        .iter()
        .filter(|op| tot.opcodes.get(**op) > 0)
        .map(|op| format!("{} {}", op.name(), tot.opcodes.get(*op)))
        .collect();
    row(
        out,
        "instructions",
        format!("{} ({})", tot.instructions, ops.join(", ")),
    )?;
    let frames = tot.frames.max(1);
    let busy: u64 = stats.lines.iter().map(|l| l.busy_cycles).sum();
    row(
        out,
        "cycles",
        format!(
            "{} per frame ({} frame(s), {} in all; the bus busy {} of them); line period {} cycles",
            tot.cycles / frames,
            tot.frames,
            tot.cycles,
            busy,
            stats.line_period
        ),
    )?;
    let worst = stats
        .lines
        .iter()
        .max_by_key(|l| (l.busy_cycles, std::cmp::Reverse(l.line)));
    if let Some(w) = worst {
        let share = if stats.line_period > 0 {
            format!(
                " = {:.1} % of the line period",
                100.0 * w.busy_cycles as f64 / stats.line_period as f64
            )
        } else {
            String::new()
        };
        // a renderer of several frames: say which frame, and its own row
        let which = if tot.frames > 1 {
            format!("frame {}, scanline {}", w.frame, w.row)
        } else {
            format!("scanline {}", w.line)
        };
        row(
            out,
            "worst line",
            format!(
                "{which}: {} bus cycles{share}; {} late scanline(s), worst slack {} cycles",
                w.busy_cycles,
                tot.late_lines,
                tot.worst_slack.unwrap_or(0)
            ),
        )?;
    }
    if let Some(why) = crate::report::late_reason(stats) {
        row(out, "late", why)?;
    }
    match crate::report::overflow_note(stats) {
        Some(note) => row(out, "overflows", note)?,
        // narrow registers that held: say so too (f64 counts none)
        None if *numeric != Numeric::F64 => row(out, "overflows", format!("none in {numeric}"))?,
        None => {}
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_render::Counters;

    #[test]
    fn counters_wrap_and_skip_zeros() {
        let c = Counters::default()
            .with("polygons", 468)
            .with("claims", 0)
            .with("rows_filled", 9572)
            .with("share_sequences", 51);
        assert_eq!(
            counters_text(&c, 0, 0, 100),
            "polygons 468, rows filled 9572, share sequences 51"
        );
        assert_eq!(
            counters_text(&c, 4, 2, 30),
            "polygons 468,\n  rows filled 9572,\n  share sequences 51"
        );
        assert_eq!(counters_text(&Counters::default(), 0, 0, 10), "");
    }
}
