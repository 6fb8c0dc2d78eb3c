//! The summary `cwisim render` prints: the scene, what the host side and the Y-processor
//! did, the array's cycles against the display, and the wall time of every stage.

use crate::prepare::{PreparedScene, VisibilityArg};
use crate::report::TraceShape;
use cwisim_isa::Opcode;
use cwisim_xproc::{Numeric, RunStats};
use cwisim_ypipe::{Antialias, EmitStats, Shading};
use std::io::{self, Write};
use std::path::Path;
use std::time::Duration;

/// Wall time of each stage of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Reading the scene, building meshes.
    pub load: Duration,
    /// Transform, lighting, culling.
    pub transform: Duration,
    /// Hidden-surface removal.
    pub visibility: Duration,
    /// Scan conversion (the Y-processor).
    pub ypipe: Duration,
    /// The array simulator.
    pub array: Duration,
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
pub fn scene_json(p: &PreparedScene) -> serde_json::Value {
    serde_json::json!({
        "name": p.source.name(),
        "kind": p.kind,
        "polygons": p.screen.polygons.len(),
        "visibility": p.visibility_mode.map(|v| match v {
            VisibilityArg::Exact => "exact",
            VisibilityArg::Eval0 => "eval0",
        }),
        "project": p.project,
        "exact_visibility": p.visibility,
    })
}

/// Writes the render summary.
pub fn write_render_summary(
    out: &mut dyn Write,
    p: &PreparedScene,
    e: &EmitStats,
    stats: &RunStats,
    numeric: &Numeric,
    t: &StageTimes,
    written: &[&Path],
) -> io::Result<()> {
    let row = |out: &mut dyn Write, label: &str, value: String| writeln!(out, "{label:<13}{value}");
    let s = &p.screen;
    let shape = TraceShape {
        width: s.width,
        lines: s.height,
        channels: s.channels,
    };
    let visibility = match p.visibility_mode {
        Some(VisibilityArg::Exact) => ", exact visibility",
        Some(VisibilityArg::Eval0) => ", eval0 visibility",
        None => "",
    };
    row(
        out,
        "scene",
        format!(
            "{} ({}, {}×{}, {}): {} shading, {}{visibility}, {numeric} registers",
            p.source.name(),
            p.kind,
            shape.width,
            shape.lines,
            channels_name(shape.channels),
            match p.options.shading {
                Shading::Flat => "flat",
                Shading::Gouraud => "Gouraud",
            },
            match p.options.aa {
                Antialias::Box => "box filter",
                Antialias::None => "point sampling",
            },
        ),
    )?;
    if let Some(g) = &p.project {
        row(
            out,
            "geometry",
            format!(
                "{} mesh(es), {} faces → {} triangles: {} back faces culled, {} drawn ({} back faces of two-sided meshes, {} edge-on dropped)",
                g.meshes,
                g.faces,
                g.triangles,
                g.culled,
                g.triangles - g.culled - g.edge_on,
                g.back_faces_drawn,
                g.edge_on
            ),
        )?;
    }
    match (&p.visibility_mode, &p.visibility) {
        (Some(VisibilityArg::Exact), Some(v)) => row(
            out,
            "visibility",
            format!(
                "exact: {} visible fragments of {} triangles ({} wholly hidden; {} occluding pairs; {} hole cuts; {} slivers dropped, {:.1e} px² in all)",
                v.fragments, v.triangles, v.hidden, v.occluding_pairs, v.hole_cuts, v.dropped_slivers, v.dropped_area
            ),
        )?,
        (Some(VisibilityArg::Eval0), _) => row(
            out,
            "visibility",
            format!(
                "eval0: triangles front to back; {} Eval0 claims, {} contributions suppressed by them",
                e.claims, stats.totals.suppressed
            ),
        )?,
        _ => {}
    }
    row(
        out,
        "Y-processor",
        format!(
            "{} polygons → {} trapezia, {} trapezium rows",
            e.polygons, e.trapezia, e.rows_filled
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
        row(
            out,
            "worst line",
            format!(
                "scanline {}: {} bus cycles{share}; {} late scanline(s), worst slack {} cycles",
                w.line,
                w.busy_cycles,
                tot.late_lines,
                tot.worst_slack.unwrap_or(0)
            ),
        )?;
    }
    let total = t.load + t.transform + t.visibility + t.ypipe + t.array + t.output;
    row(
        out,
        "time",
        format!(
            "load {} · transform & lighting {} · visibility {} · Y-processor {} · array {} · output {} · total {}",
            ms(t.load),
            ms(t.transform),
            ms(t.visibility),
            ms(t.ypipe),
            ms(t.array),
            ms(t.output),
            ms(total)
        ),
    )?;
    if !written.is_empty() {
        let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
        row(out, "wrote", names.join(", "))?;
    }
    Ok(())
}
