//! The rows of the summary `cwisim render` prints, but for the wall times and the files
//! written: the scene, the renderer's own rows, its counters, the instructions, the
//! cycles against the display, the worst scanline, and why scanlines are late or values
//! overflowed. Library code, so that every face of cwisim (the Python package's
//! `Render.summary`) gives the rows the command line prints; `crates/python`'s tests hold
//! the two to each other, row for row.

use crate::draw::Drawn;
use crate::Counters;
use crate::Rendered;
use cwisim_isa::Opcode;
use cwisim_xproc::{Numeric, RunStats};

/// The column the command line starts a row's text at (its labels are padded to it).
pub const LABEL_WIDTH: usize = 13;

/// The widest line the command line wraps the counters' row to.
const TEXT_WIDTH: usize = 100;

/// A channel count in words.
pub fn channels_name(c: u8) -> String {
    match c {
        1 => "grey".into(),
        3 => "RGB".into(),
        n => format!("{n} channels"),
    }
}

/// A renderer's counters as text: `name value` for every non-zero counter, in the
/// renderer's order, broken into lines of at most `width` characters (the first line
/// starts after `first` characters of its own) and continued after `indent` spaces.
pub fn counters_text(counters: &Counters, first: usize, indent: usize, width: usize) -> String {
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

/// When values overflowed narrow registers: how many, in how many scanlines, the first.
pub fn overflow_note(stats: &RunStats) -> Option<String> {
    let n = stats.totals.overflows;
    if n == 0 {
        return None;
    }
    let mut hit = stats.lines.iter().filter(|l| l.overflows > 0);
    Some(match hit.next() {
        Some(first) => format!(
            "{n} overflow event(s) in {} scanline(s), the first in scanline {} (the registers are too narrow: see `cwisim fit`)",
            1 + hit.count(),
            first.line
        ),
        None => format!("{n} overflow event(s) (the registers are too narrow: see `cwisim fit`)"),
    })
}

/// When every scanline is late because a token cannot even cross the array within one
/// line period, the reason in words.
pub fn late_reason(stats: &RunStats) -> Option<String> {
    (stats.totals.late_lines > 0 && stats.traversal_cycles >= stats.line_period).then(|| {
        format!(
            "a token needs {} cycles to cross the array, not less than the line period of {} cycles: no scanline can be ready in time (a narrower image, a faster clock or a longer line period)",
            stats.traversal_cycles, stats.line_period
        )
    })
}

/// The summary's rows `(label, text)` for a scene drawn and rendered into an array of
/// `numeric` registers, in the command line's order: `scene`, the renderer's own rows,
/// `Y-processor`, `instructions`, `cycles`, `worst line`, and `late` and `overflows`
/// when they apply. A text of several lines (the counters') is wrapped as the command
/// line prints it, its lines after the first indented to [`LABEL_WIDTH`].
pub fn render_rows(d: &Drawn, rendered: &Rendered, numeric: &Numeric) -> Vec<(String, String)> {
    let mut rows: Vec<(String, String)> = Vec::new();
    let h = d.renderer.header();
    let stats = &rendered.stats;
    rows.push((
        "scene".into(),
        format!(
            "{} ({}, {}×{}, {}): {}, {numeric} registers",
            d.source.name(),
            d.kind,
            h.width,
            h.lines,
            channels_name(h.channels),
            d.renderer.settings_phrase(),
        ),
    ));
    for (label, text) in d.renderer.summary_rows(&rendered.counters, stats) {
        rows.push((label.into(), text));
    }
    let name = d.renderer.name();
    rows.push((
        "Y-processor".into(),
        format!(
            "{name}: {}",
            counters_text(
                &rendered.counters,
                LABEL_WIDTH + name.len() + 2,
                LABEL_WIDTH,
                TEXT_WIDTH
            )
        ),
    ));
    let tot = &stats.totals;
    let ops: Vec<String> = Opcode::ALL
        .iter()
        .filter(|op| tot.opcodes.get(**op) > 0)
        .map(|op| format!("{} {}", op.name(), tot.opcodes.get(*op)))
        .collect();
    rows.push((
        "instructions".into(),
        format!("{} ({})", tot.instructions, ops.join(", ")),
    ));
    let frames = tot.frames.max(1);
    let busy: u64 = stats.lines.iter().map(|l| l.busy_cycles).sum();
    rows.push((
        "cycles".into(),
        format!(
            "{} per frame ({} frame(s), {} in all; the bus busy {} of them); line period {} cycles",
            tot.cycles / frames,
            tot.frames,
            tot.cycles,
            busy,
            stats.line_period
        ),
    ));
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
        rows.push((
            "worst line".into(),
            format!(
                "{which}: {} bus cycles{share}; {} late scanline(s), worst slack {} cycles",
                w.busy_cycles,
                tot.late_lines,
                tot.worst_slack.unwrap_or(0)
            ),
        ));
    }
    if let Some(why) = late_reason(stats) {
        rows.push(("late".into(), why));
    }
    match overflow_note(stats) {
        Some(note) => rows.push(("overflows".into(), note)),
        // narrow registers that held: say so too (f64 counts none)
        None if *numeric != Numeric::F64 => {
            rows.push(("overflows".into(), format!("none in {numeric}")))
        }
        None => {}
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

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
