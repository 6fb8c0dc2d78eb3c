//! `cwisim stats`: the per-scanline table, a plot, CSV and JSON.
//!
//! The input is a trace (replayed as by `cwisim run`) or a scene file (rendered as by
//! `cwisim render` with its default options: Gouraud shading, box filter). Every number
//! is a field of the run's [`LineStats`]; the plot adds the bus cycles per opcode, the
//! opcode counts × each opcode's issue cost on the machine.

use super::MachineArgs;
use crate::commands::run::{open_trace, replay_file, TimingArg};
use crate::cost_args::{check_extension, display_name};
use crate::draw::DrawArgs;
use crate::error::CliError;
use crate::files::{self, write_atomic};
use crate::range::{parse_range, Range};
use crate::report::{timing_name, unrefreshed_warning, TraceShape};
use clap::Args;
use cwisim_isa::{Opcode, TraceHeader};
use cwisim_study::plot::{issue_costs, render_stats_plot, StatsPlot};
use cwisim_xproc::{LineStats, Machine, NullSink, OpcodeCounts, RunStats, Timing, Totals};
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;

/// The arguments of `cwisim stats`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct StatsArgs {
    /// A trace (.cwt, .jsonl, .cwb), replayed; or a scene (a .json file or an embedded
    /// name: `cwisim scenes`), rendered first through the renderer and settings the
    /// drawing options give.
    #[arg(value_name = "TRACE|SCENE")]
    pub input: PathBuf,

    /// Only these scanlines (counted over the whole trace, from 0): N, A..B (B not
    /// included), A..=B or A.. (to the end).
    #[arg(long, value_name = "RANGE", value_parser = parse_range)]
    pub lines: Option<Range>,
    /// Only the scanlines of these frames, in the same syntax (frames of the trace header's
    /// lines per frame).
    #[arg(long, value_name = "RANGE", value_parser = parse_range, conflicts_with = "lines")]
    pub frames: Option<Range>,

    /// Draw the bus cycles per scanline (a PNG): one bar per scanline stacked by opcode
    /// group and stall cycles, the line period as a horizontal line, a red marker on
    /// every overrun.
    #[arg(long, value_name = "OUT.png")]
    pub plot: Option<PathBuf>,

    /// Write the table as CSV: one row per scanline, a column for each of the 14 opcodes.
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,

    /// Write the selected scanlines' records, their sums and the run's totals as JSON
    /// (the same flag as `run --stats-json` and `render --stats-json`).
    #[arg(long = "stats-json", value_name = "FILE")]
    pub stats_json: Option<PathBuf>,

    /// The machine model.
    #[command(flatten)]
    pub machine: MachineArgs,

    /// The array's registers: f64 (the reference), f32, or fixed point
    /// fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate] (M integer bits with
    /// the sign, N fraction bits; docs/ACCURACY.md).
    #[arg(long, value_name = "FORMAT", default_value = "f64")]
    pub numeric: cwisim_xproc::Numeric,

    /// Timing model. Both give identical cycle counts.
    #[arg(long, value_enum, default_value_t = TimingArg::Fast)]
    pub timing: TimingArg,

    /// How to draw a scene (refused with a trace).
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: DrawArgs,
}

use crate::input::InputKind as Input;

/// The sums over the selected scanlines: the table's last line.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Selected {
    /// Scanlines selected.
    pub lines: u64,
    /// Instructions by opcode.
    pub opcodes: OpcodeCounts,
    /// Instructions in all.
    pub instructions: u64,
    /// Bus cycles issuing.
    pub busy_cycles: u64,
    /// Bus cycles waiting.
    pub stall_cycles: u64,
    /// Processor updates.
    pub processor_updates: u64,
    /// Scanlines with negative slack.
    pub late_lines: u64,
    /// The smallest slack (none without scanlines).
    pub worst_slack: Option<i64>,
    /// The scanline with that slack.
    pub worst_line: Option<u64>,
}

impl Selected {
    /// The sums over `lines`.
    pub fn of(lines: &[LineStats]) -> Selected {
        let mut s = Selected::default();
        for l in lines {
            s.lines += 1;
            for (a, b) in s.opcodes.0.iter_mut().zip(l.opcodes.0) {
                *a += b;
            }
            s.instructions += l.instructions;
            s.busy_cycles += l.busy_cycles;
            s.stall_cycles += l.stall_cycles;
            s.processor_updates += l.processor_updates;
            if l.slack < 0 {
                s.late_lines += 1;
            }
            if s.worst_slack.is_none_or(|w| l.slack < w) {
                s.worst_slack = Some(l.slack);
                s.worst_line = Some(l.line);
            }
        }
        s
    }
}

/// The `--stats-json` document. Deterministic: the input's file name only, no times.
#[derive(Debug, Serialize)]
pub struct StatsDocument<'a> {
    /// The input's file name.
    pub input: String,
    /// `"trace"` or `"scene"`.
    pub kind: &'static str,
    /// The trace's dimensions.
    pub trace: TraceShape,
    /// The machine model, after `--machine` and `--set`.
    pub machine: &'a Machine,
    /// `"fast"` or `"stepped"`.
    pub timing: &'static str,
    /// Line period in cycles.
    pub line_period: u64,
    /// Cycles a token needs to cross the array.
    pub traversal_cycles: u64,
    /// Bus cycles of one instruction of each opcode, in opcode order (a line's count ×
    /// this = the line's cycles on that opcode; they add up to its `busy_cycles`).
    pub issue_cycles: OpcodeCounts,
    /// The `--lines` range (`null`: every scanline).
    pub range: Option<String>,
    /// Sums over the selected scanlines.
    pub selected: Selected,
    /// The whole run's totals.
    pub totals: &'a Totals,
    /// The selected scanlines' records.
    pub lines: &'a [LineStats],
}

/// Runs `cwisim stats`: the table to `stdout`, warnings to `stderr`, and the files asked
/// for (written only once the whole input ran without error).
pub fn run(
    args: &StatsArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    let kind = Input::of(&args.input)?;
    crate::input::drawing_applies(&args.draw, &[Some(&args.input)])?;
    check_outputs(args)?;
    let machine = args.machine.load()?;
    let timing = Timing::from(args.timing);
    let (header, stats) = match kind {
        Input::Trace => {
            let (mut reader, _) = open_trace(Some(&args.input))?;
            let header = *reader.header();
            // only the records of the scanlines asked for are kept
            let keep = Range::selection(args.lines, args.frames, u64::from(header.lines))
                .unwrap_or(Range::ALL);
            let stats = replay_file(
                &mut *reader,
                &machine,
                timing,
                &args.numeric,
                keep,
                &mut |_| {},
            )?;
            (header, stats)
        }
        Input::Scene => {
            let drawn = args.draw.draw(Some(&args.input))?;
            let array = cwisim_render::ArrayConfig {
                machine: machine.clone(),
                numeric: args.numeric,
                timing,
            };
            let rendered = cwisim_render::render(
                &*drawn.renderer,
                &array,
                1,
                &mut NullSink,
                cwisim_render::Taps::default(),
            )?;
            (drawn.renderer.header(), rendered.stats)
        }
    };
    let timeline = machine.timeline(&header)?;
    let chosen = Range::selection(args.lines, args.frames, u64::from(header.lines));
    let range = chosen.unwrap_or(Range::ALL);
    let lines: Vec<LineStats> = stats
        .lines
        .iter()
        .filter(|l| range.contains(l.line))
        .cloned()
        .collect();
    if lines.is_empty() && chosen.is_some() {
        let have = match stats.totals.lines {
            0 => "the run output no scanline".to_string(),
            1 => "the run output 1 scanline (0)".to_string(),
            n => format!("the run output {n} scanlines (0-{})", n - 1),
        };
        return Err(CliError::Usage(format!(
            "{} selects no scanline: {have}",
            match args.frames {
                Some(f) => format!("--frames {f}"),
                None => format!("--lines {range}"),
            }
        )));
    }
    let name = display_name(&args.input);
    let selected = Selected::of(&lines);

    if let Some(path) = &args.plot {
        let plot = render_stats_plot(&StatsPlot {
            name: &name,
            lines: &lines,
            line_period: stats.line_period,
            cost: issue_costs(&timeline),
        })
        .map_err(CliError::Usage)?;
        crate::output::write_rgb_png(path, &plot)?;
    }
    if let Some(path) = &args.csv {
        let text = csv(&lines);
        write_atomic(path, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| CliError::write(path, e))
        })?;
    }
    if let Some(path) = &args.stats_json {
        let cost = issue_costs(&timeline);
        let doc = StatsDocument {
            input: name.clone(),
            kind: kind.name(),
            trace: (&header).into(),
            machine: &machine,
            timing: timing_name(timing),
            line_period: stats.line_period,
            traversal_cycles: stats.traversal_cycles,
            issue_cycles: OpcodeCounts(cost),
            range: chosen.map(|r| r.to_string()),
            selected: selected.clone(),
            totals: &stats.totals,
            lines: &lines,
        };
        let mut text =
            serde_json::to_string_pretty(&doc).map_err(|e| CliError::write(path, e.into()))?;
        text.push('\n');
        write_atomic(path, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| CliError::write(path, e))
        })?;
    }
    if let Some(warning) = unrefreshed_warning(&stats) {
        let _ = writeln!(stderr, "{warning}");
    }
    let text = table(&name, &header, timing, &stats, &lines, &selected);
    stdout
        .write_all(text.as_bytes())
        .map_err(CliError::Stdout)?;
    // the registers the user is sizing: what they overflowed, or that they held
    if args.numeric != cwisim_xproc::Numeric::F64 {
        let note = crate::report::overflow_note(&stats)
            .unwrap_or_else(|| format!("none in {}", args.numeric));
        writeln!(stdout, "overflows: {note}").map_err(CliError::Stdout)?;
    }
    stdout.flush().map_err(CliError::Stdout)
}

/// Refuses outputs that would overwrite the input or each other, and plots that are not
/// `.png`.
fn check_outputs(args: &StatsArgs) -> Result<(), CliError> {
    if let Some(p) = &args.plot {
        check_extension("--plot", p, "png")?;
    }
    files::Io::new()
        .source("input", Some(&args.input))
        .machine(&args.machine)
        .output("--plot", args.plot.as_deref())
        .output("--csv", args.csv.as_deref())
        .output("--stats-json", args.stats_json.as_deref())
        .check()
}

/// The CSV header: the table's columns with every opcode.
pub fn csv_header() -> String {
    let mut cols = vec!["line", "frame", "row", "instructions"];
    cols.extend(Opcode::ALL.iter().map(|op| op.name()));
    cols.extend([
        "busy_cycles",
        "stall_cycles",
        "processor_updates",
        "ready",
        "deadline",
        "slack",
        "late",
    ]);
    cols.join(",")
}

/// The `--csv` text: [`csv_header`], then one row per scanline.
pub fn csv(lines: &[LineStats]) -> String {
    let mut out = csv_header();
    out.push('\n');
    for l in lines {
        let mut row = columns(l, Opcode::ALL);
        row.push(u8::from(l.slack < 0).to_string());
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// One scanline's values in the column order of the table and the CSV (before the CSV's
/// `late`): line, frame, row, instructions, `ops`' counts, busy, stall, updates, ready,
/// deadline, slack.
fn columns(l: &LineStats, ops: &[Opcode]) -> Vec<String> {
    let mut r = vec![
        l.line.to_string(),
        l.frame.to_string(),
        l.row.to_string(),
        l.instructions.to_string(),
    ];
    r.extend(ops.iter().map(|op| l.opcodes.get(*op).to_string()));
    r.extend([
        l.busy_cycles.to_string(),
        l.stall_cycles.to_string(),
        l.processor_updates.to_string(),
        l.ready.to_string(),
        l.deadline.to_string(),
        l.slack.to_string(),
    ]);
    r
}

/// The printed table: a comment line naming the input and the machine's line period, a
/// header, one row per scanline (with `LATE` on overruns), and the sums.
pub fn table(
    name: &str,
    header: &TraceHeader,
    timing: Timing,
    stats: &RunStats,
    lines: &[LineStats],
    sel: &Selected,
) -> String {
    let ops: Vec<Opcode> = Opcode::ALL
        .iter()
        .copied()
        .filter(|op| sel.opcodes.get(*op) > 0)
        .collect();
    let mut head: Vec<String> = ["line", "frame", "row", "instructions"]
        .map(String::from)
        .to_vec();
    head.extend(ops.iter().map(|op| op.name().to_string()));
    head.extend(["busy", "stall", "updates", "ready", "deadline", "slack"].map(String::from));
    let mut rows: Vec<Vec<String>> = Vec::with_capacity(lines.len() + 2);
    rows.push(head);
    for l in lines {
        rows.push(columns(l, &ops));
    }
    let mut total = vec![
        "total".to_string(),
        String::new(),
        String::new(),
        sel.instructions.to_string(),
    ];
    total.extend(ops.iter().map(|op| sel.opcodes.get(*op).to_string()));
    total.extend([
        sel.busy_cycles.to_string(),
        sel.stall_cycles.to_string(),
        sel.processor_updates.to_string(),
        String::new(),
        String::new(),
        sel.worst_slack.map_or(String::new(), |s| s.to_string()),
    ]);
    rows.push(total);

    let columns = rows[0].len();
    let widths: Vec<usize> = (0..columns)
        .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
        .collect();
    let mut out = format!(
        "# {name}: width {}, {} lines per frame, {} channel(s); timing {}; line period {} cycles, traversal {} cycles; {} of {} scanline(s)\n",
        header.width,
        header.lines,
        header.channels,
        timing_name(timing),
        stats.line_period,
        stats.traversal_cycles,
        lines.len(),
        stats.lines.len(),
    );
    let last = rows.len() - 1;
    for (i, r) in rows.iter().enumerate() {
        let cells: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(v, w)| format!("{v:>w$}"))
            .collect();
        let mut line = cells.join("  ");
        if i == last {
            line.push_str(&format!("  {} late", sel.late_lines));
        } else if i > 0 && lines[i - 1].slack < 0 {
            line.push_str("  LATE");
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(n: u64, slack: i64) -> LineStats {
        let mut l = LineStats {
            line: n,
            row: n,
            instructions: 2,
            busy_cycles: 5,
            slack,
            ..LineStats::default()
        };
        l.opcodes.0[Opcode::Eval1.index()] = 1;
        l.opcodes.0[Opcode::Refresh.index()] = 1;
        l
    }

    #[test]
    fn the_csv_header_is_stable() {
        assert_eq!(
            csv_header(),
            "line,frame,row,instructions,SetI,SetdI,SetddI,SetPI,SetPdI,SetPddI,Eval0,Eval1,Eval2,Eval3,Dis,Acc_mode,Refresh,Nop,busy_cycles,stall_cycles,processor_updates,ready,deadline,slack,late"
        );
        let text = csv(&[line(0, 3), line(1, -2)]);
        let rows: Vec<&str> = text.lines().collect();
        assert_eq!(rows.len(), 3);
        assert_eq!(
            rows[2],
            "1,0,1,2,0,0,0,0,0,0,0,1,0,0,0,0,1,0,5,0,0,0,0,-2,1"
        );
    }

    #[test]
    fn the_table_marks_late_lines_and_sums() {
        let lines = [line(0, 3), line(1, -2)];
        let sel = Selected::of(&lines);
        assert_eq!(
            (sel.late_lines, sel.worst_slack, sel.worst_line),
            (1, Some(-2), Some(1))
        );
        let h = TraceHeader::new(8, 2, 1).expect("header");
        let stats = RunStats {
            line_period: 10,
            lines: lines.to_vec(),
            ..RunStats::default()
        };
        let text = table("t.cwt", &h, Timing::Fast, &stats, &lines, &sel);
        let rows: Vec<&str> = text.lines().collect();
        assert!(rows[0].starts_with("# t.cwt: width 8"), "{text}");
        let head: Vec<&str> = rows[1].split_whitespace().collect();
        assert_eq!(
            head,
            [
                "line",
                "frame",
                "row",
                "instructions",
                "Eval1",
                "Refresh",
                "busy",
                "stall",
                "updates",
                "ready",
                "deadline",
                "slack"
            ]
        );
        assert!(!rows[2].ends_with("LATE"), "{text}");
        assert!(rows[3].ends_with("-2  LATE"), "{text}");
        assert!(rows[4].starts_with("total"), "{text}");
        assert!(rows[4].ends_with("-2  1 late"), "{text}");
        assert_eq!(rows.len(), 5);
    }
}
