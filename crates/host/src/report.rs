//! What `cwisim run` reports about a replay: the human summary of `--stats` and the JSON
//! document of `--stats-json`.

use cwisim_isa::{Opcode, TraceHeader};
use cwisim_xproc::{LineStats, Machine, RunStats, Timing};
use serde::Serialize;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

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

    /// [`Self::write_json`] with the per-scanline records taken from `spill` (written
    /// there as the run made them) in place of `stats.lines` (which must be empty): the
    /// same bytes as [`Self::write_json`] on the kept records, with memory flat in
    /// their number.
    pub fn write_json_spilled(
        &self,
        out: &mut dyn std::io::Write,
        spill: &mut LineSpill,
    ) -> std::io::Result<()> {
        assert!(
            self.stats.lines.is_empty(),
            "the records are in the spill, not kept"
        );
        let doc = serde_json::to_vec_pretty(self)?;
        // `lines` is the last field of `stats`, the last of the document
        const TAIL: &[u8] = b"\"lines\": []\n  }\n}";
        assert!(doc.ends_with(TAIL), "the document ends with the records");
        if spill.count == 0 {
            out.write_all(&doc)?;
            return out.write_all(b"\n");
        }
        out.write_all(&doc[..doc.len() - TAIL.len()])?;
        out.write_all(b"\"lines\": [\n")?;
        spill.copy_to(out)?;
        out.write_all(b"\n    ]\n  }\n}\n")
    }
}

/// The per-scanline records of `--stats-json`, written to a hidden file beside the output
/// (`.NAME.XXXXXX.lines.partial`, a [`crate::files::PartialFile`]) as each scanline completes, in their final form: pretty JSON
/// objects indented as the elements of `stats.lines`, separated by `,\n`. Removed when
/// dropped.
pub struct LineSpill {
    file: crate::files::PartialFile,
    out: Option<BufWriter<File>>,
    /// Bytes written, and the most the output budget allows (`CWISIM_MAX_OUTPUT`).
    bytes: u64,
    budget: cwisim_scene::budget::Budget,
    over_budget: bool,
    count: u64,
    error: Option<io::Error>,
    buf: Vec<u8>,
}

impl LineSpill {
    /// A spill beside `output` (the `--stats-json` path).
    pub fn beside(output: &Path) -> io::Result<LineSpill> {
        let name = output.file_name().ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, "the output path names no file")
        })?;
        let mut prefix = std::ffi::OsString::from(".");
        prefix.push(name);
        prefix.push(".");
        let dir = if crate::files::is_special(output) {
            // beside a device or FIFO there may be no room for a file: the temporary
            // directory instead
            std::env::temp_dir()
        } else {
            let target =
                crate::files::resolve_output(output).map_err(|e| io::Error::other(e.one_line()))?;
            match target.parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => std::path::PathBuf::from("."),
            }
        };
        let (file, out) = crate::files::PartialFile::create_in(&dir, &prefix, ".lines.partial")?;
        Ok(LineSpill {
            file,
            out: Some(BufWriter::new(out)),
            bytes: 0,
            budget: cwisim_scene::budget::Budget::current(),
            over_budget: false,
            count: 0,
            error: None,
            buf: Vec::new(),
        })
    }

    /// Appends one record (a write error is kept and reported by [`Self::copy_to`]).
    pub fn push(&mut self, line: &LineStats) {
        if self.error.is_some() || self.over_budget {
            return;
        }
        if let Err(e) = self.write_record(line) {
            self.error = Some(e);
        }
    }

    fn write_record(&mut self, line: &LineStats) -> io::Result<()> {
        let out = self.out.as_mut().expect("open until copied");
        self.buf.clear();
        serde_json::to_writer_pretty(&mut self.buf, line)?;
        if self.count > 0 {
            out.write_all(b",\n")?;
        }
        // an element of `stats.lines` is three levels deep: six spaces before each of
        // its lines (the record holds no string with a newline)
        let rows = self.buf.split(|&b| b == b'\n').count() as u64;
        self.bytes += 2 + self.buf.len() as u64 + 6 * rows;
        if self.bytes > self.budget.output_bytes {
            // nothing more on the disk: the run is refused at its end
            self.over_budget = true;
            return Ok(());
        }
        for (k, row) in self.buf.split(|&b| b == b'\n').enumerate() {
            if k > 0 {
                out.write_all(b"\n")?;
            }
            out.write_all(b"      ")?;
            out.write_all(row)?;
        }
        self.count += 1;
        Ok(())
    }

    /// The output budget the records ran past, if they did: `what` names the output.
    pub fn over_budget(&self, what: &str) -> Option<cwisim_scene::budget::BudgetError> {
        self.over_budget.then(|| {
            self.budget
                .check_output(what, self.bytes)
                .expect_err("the records ran past the budget")
        })
    }

    /// The records written so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Copies the records to `out` (once, after the run).
    fn copy_to(&mut self, out: &mut dyn Write) -> io::Result<()> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let file = self
            .out
            .take()
            .expect("copied once")
            .into_inner()
            .map_err(|e| e.into_error())?;
        drop(file);
        let mut file = File::open(self.file.path())?;
        io::copy(&mut file, out)?;
        Ok(())
    }
}

impl Drop for LineSpill {
    fn drop(&mut self) {
        // closed before its `PartialFile` removes it
        self.out = None;
    }
}

/// The warning for instructions that came after the last `Refresh`, if there were any.
pub fn unrefreshed_warning(stats: &RunStats) -> Option<String> {
    let n = stats.totals.unrefreshed_instructions;
    (n > 0).then(|| {
        format!("warning: {n} instruction(s) after the last Refresh never reached the output (add a Refresh to see them)")
    })
}

pub use cwisim_render::summary::{late_reason, overflow_note};

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
    match late_reason(stats) {
        Some(why) => row(out, "late lines", &format!("{} ({why})", t.late_lines))?,
        None => row(out, "late lines", &t.late_lines)?,
    }
    let worst = match (t.worst_slack, t.worst_line) {
        (Some(s), Some(l)) => format!("{s} cycles (line {l})"),
        _ => "- (no scanline)".to_string(),
    };
    row(out, "worst slack", &worst)?;
    if t.saturated_lines > 0 {
        row(
            out,
            "saturated lines",
            &format!(
                "{} (their cycle counts reached 2^64 - 1: slack and lateness there are bounds)",
                t.saturated_lines
            ),
        )?;
    }
    row(out, "processor updates", &t.processor_updates)?;
    row(out, "dropped negatives", &t.dropped_negative)?;
    row(out, "suppressed", &t.suppressed)?;
    match overflow_note(stats) {
        Some(note) => row(out, "overflows", &note)?,
        None => row(out, "overflows", &0)?,
    }
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
        assert!(text.contains("overflows                 0\n"), "{text}");
        assert_eq!(text.lines().count(), 17, "{text}");
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

    /// The records spilled as the run makes them give the bytes of the document with
    /// the records kept, for none, one and many scanlines, on both engines.
    #[test]
    fn spilled_records_give_the_same_bytes() {
        let dir = std::env::temp_dir().join(format!("cwisim-spill-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let h = TraceHeader::new(8, 3, 1).expect("header");
        for lines in [0u32, 1, 7] {
            let mut trace = vec![Instruction::nop()];
            for k in 0..lines {
                trace.push(Instruction::eval1(k % 8, 1, Intensity::grey(0.25)));
                trace.push(Instruction::refresh());
            }
            trace.push(Instruction::nop());
            for timing in [Timing::Fast, Timing::Stepped] {
                let m = Machine::default();
                fn report<'a>(
                    h: &TraceHeader,
                    m: &'a Machine,
                    timing: Timing,
                    stats: &'a RunStats,
                ) -> StatsReport<'a> {
                    StatsReport {
                        trace: h.into(),
                        machine: m,
                        timing: timing_name(timing),
                        stats,
                    }
                }
                let (_, kept) = cwisim_xproc::run::<f64>(&h, &trace, &m, timing).expect("run");
                let mut expected = Vec::new();
                report(&h, &m, timing, &kept)
                    .write_json(&mut expected)
                    .expect("writes");

                let path = dir.join("stats.json");
                let spill = std::sync::Arc::new(std::sync::Mutex::new(
                    LineSpill::beside(&path).expect("spill"),
                ));
                let to = spill.clone();
                let mut e = cwisim_xproc::engine::<f64>(&h, &m, timing).expect("engine");
                e.line_records(cwisim_xproc::LineRecords::Send(Box::new(move |l| {
                    to.lock().expect("lock").push(&l)
                })));
                for i in &trace {
                    e.execute(i, &mut cwisim_xproc::NullSink);
                }
                let streamed = e.finish(&mut cwisim_xproc::NullSink);
                assert!(streamed.lines.is_empty());
                let mut spill = spill.lock().expect("lock");
                assert_eq!(spill.count(), u64::from(lines));
                let mut got = Vec::new();
                report(&h, &m, timing, &streamed)
                    .write_json_spilled(&mut got, &mut spill)
                    .expect("writes");
                assert_eq!(
                    String::from_utf8(got).expect("utf-8"),
                    String::from_utf8(expected).expect("utf-8"),
                    "{lines} lines, {timing:?}"
                );
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
