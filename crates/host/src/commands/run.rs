//! `cwisim run`: replay a trace, write the image and the statistics.

use super::{ImageArgs, MachineArgs};
use crate::cost_args::{display_name, CostArgs};
use crate::demo;
use crate::error::CliError;
use crate::files::{write_atomic, Io};
use crate::progress::Progress;
use crate::range::Range;
use crate::report::{timing_name, unrefreshed_warning, write_summary, LineSpill, StatsReport};
use clap::{Args, ValueEnum};
use cwisim_isa::{Encoding, FileReader, TraceRead};
use cwisim_scene::budget::{Budget, BudgetError};
use cwisim_study::cost::{CostMap, CostReader};
use cwisim_xproc::LineStats;
use cwisim_xproc::{
    replay_streaming, LineRecords, NullSink, Numeric, ReplayError, RunStats, Timing,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The timing model, as chosen on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum TimingArg {
    /// Closed-form timing; cost proportional to the trace's work (the default).
    #[default]
    Fast,
    /// Every processor advanced every cycle: the slow reference. Same results.
    Stepped,
}

impl From<TimingArg> for Timing {
    fn from(t: TimingArg) -> Timing {
        match t {
            TimingArg::Fast => Timing::Fast,
            TimingArg::Stepped => Timing::Stepped,
        }
    }
}

/// The arguments of `cwisim run`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct RunArgs {
    /// The trace: .cwt (text), .jsonl (JSON Lines) or .cwb (binary), chosen by extension;
    /// or a scene (a .json file or an embedded name), drawn with the drawing options below
    /// and replayed as `cwisim emit`'s trace would be. Without it, the embedded demo trace
    /// (a shaded, anti-aliased disc) is replayed.
    #[arg(value_name = "TRACE|SCENE")]
    pub trace: Option<PathBuf>,

    /// Image outputs.
    #[command(flatten)]
    pub image: ImageArgs,

    /// Cost outputs: instructions per pixel.
    #[command(flatten)]
    pub cost: CostArgs,

    /// The machine model.
    #[command(flatten)]
    pub machine: MachineArgs,

    /// Timing model. Both give identical images and cycle counts.
    #[arg(long, value_enum, default_value_t = TimingArg::Fast)]
    pub timing: TimingArg,

    /// The array's registers: f64 (the reference), f32, or fixed point
    /// fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate] (M integer bits with
    /// the sign, N fraction bits; docs/ACCURACY.md).
    #[arg(long, value_name = "FORMAT", default_value = "f64")]
    pub numeric: Numeric,

    /// Print a summary of the statistics to standard output.
    #[arg(long)]
    pub stats: bool,

    /// Write the statistics, the trace's dimensions, the machine and the timing model as
    /// JSON (with one record per scanline).
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,

    /// When the trace turns out bad part way (a malformed line, a truncated file), still
    /// write the image outputs (-o, --npy) with the scanlines completed before the bad
    /// instruction, and say so; the error is reported and the exit code is 2 as without
    /// it. Statistics and cost outputs are not written for a bad trace.
    #[arg(long)]
    pub keep_partial: bool,
    /// Print nothing on standard output (errors and warnings still go to standard error).
    #[arg(short, long, conflicts_with = "stats")]
    pub quiet: bool,
    /// How to draw a scene (refused with a trace).
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: crate::draw::DrawArgs,
}

/// Runs `cwisim run`: statistics go to `stdout` (with `--stats`), warnings to `stderr`.
/// `progress` allows the progress bar (it still needs a terminal and a run of over a
/// second). Nothing is written unless the whole trace replayed without error, except with
/// `--keep-partial` (the image of the scanlines completed before the error).
pub fn run(
    args: &RunArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
    progress: bool,
) -> Result<(), CliError> {
    crate::input::drawing_applies(&args.draw, &[args.trace.as_deref()])?;
    check_paths(args)?;
    let machine = args.machine.load()?;
    let timing = Timing::from(args.timing);
    let (mut reader, size) = match args.trace.as_deref() {
        Some(path) => crate::input::open_sized(path, &args.draw, args.keep_partial)?,
        None => open_trace(None)?,
    };
    let header = *reader.header();
    args.image.check(header.channel_count())?;
    // a trace holds at least one whole frame: that much image is known now
    args.image.check_memory(
        header.width,
        header.channel_count(),
        u64::from(header.lines),
    )?;
    args.cost.check()?;
    let mut cost = args
        .cost
        .wanted()
        .then(|| CostMap::new(header.width as usize));
    let spill = match &args.stats_json {
        Some(path) => Some(Arc::new(Mutex::new(
            LineSpill::beside(path).map_err(|e| CliError::write(path, e))?,
        ))),
        None => None,
    };
    let (stats, collected) = {
        let mut bar = Progress::new(size, progress);
        let mut costed;
        let reader: &mut dyn TraceRead = match &mut cost {
            Some(map) => {
                costed = CostReader::new(&mut *reader, map);
                &mut costed
            }
            None => &mut *reader,
        };
        // per-scanline records only when asked for, and then written out as each
        // scanline completes (to a file beside the output): memory stays flat however
        // long the trace
        let keep_lines = match &spill {
            Some(spill) => {
                let spill = Arc::clone(spill);
                LineRecords::Send(Box::new(move |l| {
                    spill.lock().expect("not poisoned").push(&l)
                }))
            }
            None => LineRecords::Drop,
        };
        // only what the outputs need, with room for a frame up front
        let mut sink = args.image.sink(
            header.width as usize,
            header.channel_count(),
            u64::from(header.lines),
        );
        let result = replay_streaming(
            reader,
            &machine,
            timing,
            &args.numeric,
            keep_lines,
            &mut sink,
            &mut |bytes| bar.update(bytes),
        );
        match result {
            Ok(stats) => (stats, sink.finish()?),
            Err(ReplayError::Trace(error)) if args.keep_partial && args.image.wanted() => {
                drop(bar);
                let collected = sink.finish()?;
                let note = if collected.lines() == 0 {
                    "no scanline was completed before the error: no image written".to_string()
                } else {
                    args.image.write(&collected)?;
                    // kept although the command fails: what --keep-partial asks for
                    crate::files::commit_pending()?;
                    format!(
                        "the image is incomplete: it holds the {} scanline(s) completed \
before the error (a frame has {})",
                        collected.lines(),
                        header.lines
                    )
                };
                // A lost warning is no reason to hide the error.
                let _ = writeln!(stderr, "warning: --keep-partial: {note}");
                return Err(CliError::from(ReplayError::Trace(error)));
            }
            Err(other) => return Err(other.into()),
        }
    };
    if let (Some(incomplete), Some(path)) = (reader.incomplete(), &args.trace) {
        // A lost warning is no reason to fail the run.
        let _ = writeln!(
            stderr,
            "warning: --keep-partial: {}: {incomplete}; the outputs hold its {} scanline(s)",
            path.display(),
            incomplete.scanlines
        );
    }
    args.image.write(&collected)?;
    if let Some(cost) = &cost {
        let name = match &args.trace {
            Some(path) => display_name(path),
            None => "demo trace".to_string(),
        };
        args.cost.write(cost, &name)?;
    }
    let stats = &stats;
    if let Some(path) = &args.stats_json {
        let report = StatsReport {
            trace: (&header).into(),
            machine: &machine,
            timing: timing_name(timing),
            stats,
        };
        let spill = spill.as_ref().expect("made with --stats-json");
        let mut spill = spill.lock().expect("not poisoned");
        if let Some(e) = spill.over_budget(&format!("--stats-json {}", path.display())) {
            return Err(e.into());
        }
        write_atomic(path, |w| {
            report
                .write_json_spilled(w, &mut spill)
                .map_err(|e| CliError::write(path, e))
        })?;
    }
    if let Some(warning) = unrefreshed_warning(stats) {
        // A lost warning is no reason to fail the run.
        let _ = writeln!(stderr, "{warning}");
    }
    if args.stats {
        write_summary(stdout, &header, timing, stats).map_err(CliError::Stdout)?;
        stdout.flush().map_err(CliError::Stdout)?;
    }
    if !args.quiet {
        let [cost_image, cost_npy] = args.cost.outputs();
        let written: Vec<&Path> = [
            args.image.output.as_deref(),
            args.image.npy.as_deref(),
            cost_image.1.map(PathBuf::as_path),
            cost_npy.1.map(PathBuf::as_path),
            args.stats_json.as_deref(),
        ]
        .into_iter()
        .flatten()
        .collect();
        let detail = format!(
            "{} scanline(s) of {} × {} channel(s)",
            stats.totals.lines,
            header.width,
            header.channel_count()
        );
        if let Some(line) = crate::files::wrote_line(&written, Some(&detail)) {
            writeln!(stdout, "{line}").map_err(CliError::Stdout)?;
        }
    }
    Ok(())
}

/// A reader on the trace file and its size in bytes, or on the embedded demo trace
/// ([`demo`]) when there is no file.
pub fn open_trace(path: Option<&Path>) -> Result<(Box<dyn TraceRead>, u64), CliError> {
    match path {
        Some(path) => {
            let reader = FileReader::open(path)?;
            let size = reader.size();
            Ok((Box::new(reader), size))
        }
        None => {
            let bytes = demo_trace_bytes();
            let size = bytes.len() as u64;
            let reader = Encoding::Binary.reader(std::io::Cursor::new(bytes))?;
            Ok((reader, size))
        }
    }
}

/// The demo trace encoded as `.cwb`, so that it is read, checked and replayed exactly
/// like a file.
fn demo_trace_bytes() -> Vec<u8> {
    let (header, instrs) = demo::trace();
    let mut bytes = Vec::new();
    // Writing into a Vec cannot fail.
    if let Ok(mut w) = Encoding::Binary.writer(&mut bytes, &header) {
        for i in &instrs {
            let _ = w.write(i);
        }
        let _ = w.finish();
    }
    bytes
}

/// Replays an open trace on `machine` for its statistics, every scanline's record kept.
pub fn replay_file(
    reader: &mut dyn TraceRead,
    machine: &cwisim_xproc::Machine,
    timing: Timing,
    numeric: &Numeric,
    keep: Range,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, CliError> {
    let kept = Arc::new(Mutex::new(KeptRecords::new(keep, Budget::current())));
    let to = Arc::clone(&kept);
    let mut stats = replay_streaming(
        reader,
        machine,
        timing,
        numeric,
        LineRecords::Send(Box::new(move |l| {
            to.lock().expect("not poisoned").push(l);
        })),
        &mut NullSink,
        progress,
    )?;
    let kept = std::mem::replace(
        &mut *kept.lock().expect("not poisoned"),
        KeptRecords::new(keep, Budget::current()),
    );
    stats.lines = kept.finish()?;
    Ok(stats)
}

/// The per-scanline records of the scanlines in a range, kept within the memory budget:
/// past it the records are dropped as they come and the run is refused at its end, saying
/// how many scanlines it had.
struct KeptRecords {
    range: Range,
    budget: Budget,
    lines: Vec<LineStats>,
    over: Option<u64>,
}

impl KeptRecords {
    fn new(range: Range, budget: Budget) -> Self {
        KeptRecords {
            range,
            budget,
            lines: Vec::new(),
            over: None,
        }
    }

    fn push(&mut self, line: LineStats) {
        if !self.range.contains(line.line) {
            return;
        }
        if let Some(n) = &mut self.over {
            *n += 1;
            return;
        }
        let bytes = (self.lines.len() as u64 + 1) * std::mem::size_of::<LineStats>() as u64;
        if self.budget.check_memory("", bytes).is_err() {
            self.over = Some(self.lines.len() as u64 + 1);
            self.lines = Vec::new();
            return;
        }
        self.lines.push(line);
    }

    fn finish(self) -> Result<Vec<LineStats>, CliError> {
        match self.over {
            None => Ok(self.lines),
            Some(n) => {
                let what = format!(
                    "keeping the records of {n} scanlines ({} each; --lines or --frames selects fewer)",
                    cwisim_scene::budget::human(std::mem::size_of::<LineStats>() as u64)
                );
                Err(BudgetError::Memory {
                    what,
                    needed: n.saturating_mul(std::mem::size_of::<LineStats>() as u64),
                    budget: self.budget.memory_bytes,
                }
                .into())
            }
        }
    }
}

/// Refuses outputs that would overwrite the trace or each other.
fn check_paths(args: &RunArgs) -> Result<(), CliError> {
    let [cost_image, cost_npy] = args.cost.outputs();
    Io::new()
        .input("trace being read", args.trace.as_deref())
        .machine(&args.machine)
        .output("-o", args.image.output.as_deref())
        .output("--npy", args.image.npy.as_deref())
        .output("--stats-json", args.stats_json.as_deref())
        .output(cost_image.0, cost_image.1.map(PathBuf::as_path))
        .output(cost_npy.0, cost_npy.1.map(PathBuf::as_path))
        .check()
}
