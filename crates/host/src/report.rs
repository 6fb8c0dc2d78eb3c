//! What `cwisim run` reports about a replay: the human summary of `--stats` and the JSON
//! document of `--stats-json`.

use cwisim_isa::{Opcode, TraceHeader};
use cwisim_xproc::{Machine, RunStats, Timing};
use serde::Serialize;
use std::io::{self, Write};

/// The name of a timing model on the command line and in reports.
pub fn timing_name(timing: Timing) -> &'static str {
    match timing {
        Timing::Fast => "fast",
        Timing::Stepped => "stepped",
    }
}

/// The trace dimensions, as `--stats-json` reports them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct TraceShape {
    /// X-processors (pixel columns).
    pub width: u32,
    /// Scanlines per frame.
    pub lines: u32,
    /// Values per intensity.
    pub channels: u8,
}

impl From<&TraceHeader> for TraceShape {
    fn from(h: &TraceHeader) -> Self {
        TraceShape {
            width: h.width,
            lines: h.lines,
            channels: h.channels,
        }
    }
}

/// The `--stats-json` document: everything needed to reproduce and read the numbers.
/// Deterministic: no paths, no times.
#[derive(Debug, Serialize)]
pub struct StatsReport<'a> {
    /// The trace's dimensions.
    pub trace: TraceShape,
    /// The machine model used, after `--machine` and `--set`.
    pub machine: &'a Machine,
    /// `"fast"` or `"stepped"`.
    pub timing: &'static str,
    /// The statistics.
    pub stats: &'a RunStats,
}

impl StatsReport<'_> {
    /// Pretty JSON with a trailing newline, written to `out` as it is made (no copy of
    /// the whole document in memory: a long trace's per-scanline records run to hundreds
    /// of megabytes).
    pub fn write_json(&self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        serde_json::to_writer_pretty(&mut *out, self)?;
        out.write_all(b"\n")
    }
}

/// The warning for instructions that came after the last `Refresh`, if there were any.
pub fn unrefreshed_warning(stats: &RunStats) -> Option<String> {
    let n = stats.totals.unrefreshed_instructions;
    (n > 0).then(|| {
        format!("warning: {n} instruction(s) after the last Refresh never reached the output (add a Refresh to see them)")
    })
}

/// Writes the `--stats` summary.
pub fn write_summary(
    out: &mut dyn Write,
    header: &TraceHeader,
    timing: Timing,
    stats: &RunStats,
) -> io::Result<()> {
    let t = &stats.totals;
    let row = |out: &mut dyn Write, label: &str, value: &dyn std::fmt::Display| {
        writeln!(out, "{label:<26}{value}")
    };
    row(
        out,
        "trace",
        &format!(
            "width {}, {} lines per frame, {} channel(s)",
            header.width, header.lines, header.channels
        ),
    )?;
    row(out, "timing", &timing_name(timing))?;
    row(out, "instructions", &t.instructions)?;
    for op in Opcode::ALL {
        let n = t.opcodes.get(*op);
        if n > 0 {
            row(out, &format!("  {}", op.name()), &n)?;
        }
    }
    row(out, "cycles", &t.cycles)?;
    row(out, "line period", &format!("{} cycles", stats.line_period))?;
    row(
        out,
        "traversal",
        &format!("{} cycles", stats.traversal_cycles),
    )?;
    row(
        out,
        "lines",
        &format!(
            "{} ({} frame(s) + {} line(s) of a partial frame)",
            t.lines, t.frames, t.partial_frame_lines
        ),
    )?;
    row(out, "late lines", &t.late_lines)?;
    let worst = match (t.worst_slack, t.worst_line) {
        (Some(s), Some(l)) => format!("{s} cycles (line {l})"),
        _ => "- (no scanline)".to_string(),
    };
    row(out, "worst slack", &worst)?;
    row(out, "processor updates", &t.processor_updates)?;
    row(out, "dropped negatives", &t.dropped_negative)?;
    row(out, "suppressed", &t.suppressed)?;
    row(out, "unrefreshed instructions", &t.unrefreshed_instructions)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::{Instruction, Intensity};

    fn sample() -> (TraceHeader, RunStats) {
        let h = TraceHeader::new(8, 2, 1).expect("header");
        let trace = [
            Instruction::eval2(2, 4, Intensity::grey(0.5), Intensity::grey(0.125)),
            Instruction::refresh(),
            Instruction::nop(),
        ];
        let (_, stats) =
            cwisim_xproc::run::<f64>(&h, &trace, &Machine::default(), Timing::Fast).expect("run");
        (h, stats)
    }

    #[test]
    fn summary_lists_only_used_opcodes() {
        let (h, stats) = sample();
        let mut out = Vec::new();
        write_summary(&mut out, &h, Timing::Fast, &stats).expect("write");
        let text = String::from_utf8(out).expect("utf-8");
        assert!(text.contains("\n  Eval2                   1\n"), "{text}");
        assert!(text.contains("\n  Nop                     1\n"), "{text}");
        assert!(!text.contains("Eval3"), "{text}");
        assert!(text.contains("unrefreshed instructions  1\n"), "{text}");
        assert!(text.contains("(line 0)"), "{text}");
        assert_eq!(text.lines().count(), 16, "{text}");
    }

    #[test]
    fn warning_only_when_something_was_lost() {
        let (_, stats) = sample();
        assert!(unrefreshed_warning(&stats)
            .expect("warning")
            .contains("1 instruction(s)"));
        assert_eq!(unrefreshed_warning(&RunStats::default()), None);
    }

    #[test]
    fn json_report_has_the_four_parts() {
        let (h, stats) = sample();
        let m = Machine::default();
        let mut written = Vec::new();
        StatsReport {
            trace: (&h).into(),
            machine: &m,
            timing: timing_name(Timing::Stepped),
            stats: &stats,
        }
        .write_json(&mut written)
        .expect("writes");
        let json = String::from_utf8(written).expect("utf-8");
        assert!(json.ends_with("}\n"));
        let v: serde_json::Value = serde_json::from_str(&json).expect("json");
        assert_eq!(
            v["trace"],
            serde_json::json!({"width": 8, "lines": 2, "channels": 1})
        );
        assert_eq!(v["timing"], "stepped");
        assert_eq!(v["machine"]["hop_cycles"], 1);
        assert_eq!(v["stats"]["totals"]["unrefreshed_instructions"], 1);
    }
}
