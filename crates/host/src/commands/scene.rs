//! `cwisim render` and `cwisim emit`: a scene (screen or world, a file or an embedded
//! name) through the host side and the Y-processor (`cwisim-world`, `cwisim-ypipe`), into
//! the array simulator or a trace file.

use super::{ImageArgs, MachineArgs};
use crate::commands::run::TimingArg;
use crate::cost::{display_name, CostArgs, CostMap};
use crate::error::CliError;
use crate::files::{check_outputs, same_file, write_atomic};
use crate::prepare::{prepare, DrawArgs, PreparedScene};
use crate::progress::Progress;
use crate::report::{timing_name, write_summary, StatsReport};
use crate::summary::{write_render_summary, StageTimes};
use clap::Args;
use cwisim_isa::{Encoding, Instruction, Opcode, PackedStream, TraceWrite};
use cwisim_scene::ScreenScene;
use cwisim_xproc::{EngineWriter, ImageSink, LineSink, Machine, Numeric, RunStats, Timing};
use cwisim_ypipe::{emit, emit_rows, header, EmitStats, Options, ScanPlan};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The arguments of `cwisim emit`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct EmitArgs {
    /// The scene: a JSON file ("kind": "screen" or "world") or an embedded scene's name
    /// (`cwisim scenes` lists them).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// The trace to write: .cwt (annotated text), .jsonl or .cwb, by extension.
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: PathBuf,
    /// How to draw it.
    #[command(flatten)]
    pub draw: DrawArgs,
}

/// The arguments of `cwisim render`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct RenderArgs {
    /// The scene: a JSON file ("kind": "screen" or "world") or an embedded scene's name
    /// (`cwisim scenes` lists them). Default: the embedded pot.
    #[arg(value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// Image outputs. Without -o, --npy, --trace, --cost-image or --cost-npy, the PNG goes
    /// to SCENE-NAME.png in the working directory.
    #[command(flatten)]
    pub image: ImageArgs,
    /// Cost outputs: instructions per pixel.
    #[command(flatten)]
    pub cost: CostArgs,
    /// Also write the emitted trace (.cwt annotated text, .jsonl or .cwb).
    #[arg(long, value_name = "OUT")]
    pub trace: Option<PathBuf>,
    /// How to draw it.
    #[command(flatten)]
    pub draw: DrawArgs,
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
    /// Also print the array's full statistics summary.
    #[arg(long)]
    pub stats: bool,
    /// Write the scene's, the scan conversion's and the array's statistics as JSON.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
    /// Print nothing (errors still go to standard error).
    #[arg(short, long)]
    pub quiet: bool,
    /// Threads: with N > 1, N − 1 threads scan-convert bands of scanlines while one feeds
    /// them, in order, to the array (0: one per core). The output, trace and statistics
    /// are identical to the serial run's, byte for byte.
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub threads: usize,
}

/// The array as a [`TraceWrite`] fed one scanline at a time: instructions are buffered
/// until their `Refresh` and then handed to the array, so that the array's share of the
/// wall time is measured per scanline rather than per instruction. Every instruction also
/// goes to `also` (a cost map, say) as it comes.
struct ScanlineFeed<'a, 's> {
    array: EngineWriter<'s, f64>,
    also: Option<&'a mut dyn TraceWrite>,
    buffer: Vec<Instruction>,
    array_time: Duration,
    progress: Option<&'a mut Progress>,
    lines: u64,
}

impl<'a, 's> ScanlineFeed<'a, 's> {
    /// The array for `scene`, fed scanline by scanline (and `also` the trace, if any).
    fn open(
        scene: &ScreenScene,
        machine: &Machine,
        numeric: &Numeric,
        timing: Timing,
        sink: &'s mut dyn LineSink<f64>,
        also: Option<&'a mut dyn TraceWrite>,
        progress: Option<&'a mut Progress>,
    ) -> Result<Self, CliError> {
        let h = header(scene);
        Ok(ScanlineFeed {
            array: EngineWriter::with_numeric(&h, machine, timing, numeric, sink)?,
            also,
            buffer: Vec::new(),
            array_time: Duration::ZERO,
            progress,
            lines: 0,
        })
    }

    /// Finishes the array and the trace; `total` is the wall time since emission began
    /// (the Y-processor's share is what the array did not take: the two interleave, or
    /// overlap on threads).
    fn close(mut self, emitted: EmitStats, total: Duration) -> Result<Rendered, CliError> {
        self.finish()
            .map_err(|e| CliError::Usage(format!("the array failed: {e}")))?;
        let array_time = self.array_time;
        let stats = self.array.into_stats().expect("finished");
        Ok(Rendered {
            emitted,
            stats,
            ypipe_time: total.saturating_sub(array_time),
            array_time,
        })
    }

    fn flush(&mut self) -> io::Result<()> {
        let start = Instant::now();
        for instr in self.buffer.drain(..) {
            self.array.write(&instr)?;
        }
        self.array_time += start.elapsed();
        Ok(())
    }
}

impl TraceWrite for ScanlineFeed<'_, '_> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        if let Some(also) = self.also.as_deref_mut() {
            also.write(instr)?;
        }
        self.buffer.push(*instr);
        if instr.op == Opcode::Refresh {
            self.flush()?;
            self.lines += 1;
            if let Some(p) = self.progress.as_deref_mut() {
                p.update(self.lines);
            }
        }
        Ok(())
    }

    fn comment(&mut self, text: &str) -> io::Result<()> {
        match self.also.as_deref_mut() {
            Some(also) => also.comment(text),
            None => Ok(()),
        }
    }

    fn wants_comments(&self) -> bool {
        self.also.as_deref().is_some_and(|a| a.wants_comments())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.flush()?;
        let start = Instant::now();
        self.array.finish()?;
        self.array_time += start.elapsed();
        if let Some(also) = self.also.as_deref_mut() {
            also.finish()?;
        }
        Ok(())
    }
}

/// What rendering a screen scene gives besides the scanlines.
pub struct Rendered {
    /// The scan conversion's statistics.
    pub emitted: EmitStats,
    /// The array's statistics.
    pub stats: RunStats,
    /// Wall time in the Y-processor (scan conversion).
    pub ypipe_time: Duration,
    /// Wall time in the array simulator.
    pub array_time: Duration,
}

/// Scan-converts `scene` straight into the array on `machine`, handing its scanlines to
/// `sink`, and every instruction also to `also` when given.
#[allow(clippy::too_many_arguments)]
pub fn render_scene<'a>(
    scene: &ScreenScene,
    options: &Options,
    machine: &Machine,
    numeric: &Numeric,
    timing: Timing,
    sink: &mut dyn LineSink<f64>,
    also: Option<&'a mut dyn TraceWrite>,
    progress: Option<&'a mut Progress>,
) -> Result<Rendered, CliError> {
    render_scene_threads(
        scene, options, machine, numeric, timing, sink, also, progress, 1,
    )
}

/// Collects a band's instructions.
/// Bands per thread: enough that uneven bands balance out.
const BANDS_PER_THREAD: u32 = 8;

/// [`render_scene`] with the Y-processor's work split into bands of scanlines emitted on
/// `threads` threads (1: serially, as the scene streams into the array). The bands'
/// streams are fed to the array in order, so the output, the trace and every statistic
/// are identical to the serial run, byte for byte.
#[allow(clippy::too_many_arguments)]
pub fn render_scene_threads<'a>(
    scene: &ScreenScene,
    options: &Options,
    machine: &Machine,
    numeric: &Numeric,
    timing: Timing,
    sink: &mut dyn LineSink<f64>,
    also: Option<&'a mut dyn TraceWrite>,
    progress: Option<&'a mut Progress>,
    threads: usize,
) -> Result<Rendered, CliError> {
    if threads > 1 {
        return render_parallel(
            scene, options, machine, numeric, timing, sink, also, progress, threads,
        );
    }
    let mut feed = ScanlineFeed::open(scene, machine, numeric, timing, sink, also, progress)?;
    let start = Instant::now();
    let emitted = emit(scene, options, &mut feed).map_err(|e| {
        CliError::Usage(format!(
            "the Y-processor emitted an invalid instruction: {e}"
        ))
    })?;
    feed.close(emitted, start.elapsed())
}

/// The parallel render: `threads − 1` workers emit bands of scanlines (taking the next
/// band as they finish one) while this thread feeds the finished bands to the array in
/// order, so scan conversion and the array overlap.
#[allow(clippy::too_many_arguments)]
fn render_parallel<'a>(
    scene: &ScreenScene,
    options: &Options,
    machine: &Machine,
    numeric: &Numeric,
    timing: Timing,
    sink: &mut dyn LineSink<f64>,
    also: Option<&'a mut dyn TraceWrite>,
    progress: Option<&'a mut Progress>,
    threads: usize,
) -> Result<Rendered, CliError> {
    use std::collections::BTreeMap;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::{mpsc, Mutex};
    let start = Instant::now();
    let plan = ScanPlan::new(scene, options);
    let n = (threads as u32 * BANDS_PER_THREAD).clamp(1, scene.height.max(1));
    let band_rows = |k: u32| {
        let a = (u64::from(scene.height) * u64::from(k) / u64::from(n)) as u32;
        let b = (u64::from(scene.height) * u64::from(k + 1) / u64::from(n)) as u32;
        a..b
    };
    let mut feed = ScanlineFeed::open(scene, machine, numeric, timing, sink, also, progress)?;
    let mut stats = plan.scene_stats();
    let next_band = AtomicUsize::new(0);
    // buffers the feeder has emptied, for the workers to reuse: a fresh buffer per band
    // would be mapped and faulted in page by page (most bands are over the allocator's
    // mmap threshold), which costs more than the work overlapped
    let spare: Mutex<Vec<PackedStream>> = Mutex::new(Vec::new());
    // this thread feeds the array: it counts as one of the `threads`
    let workers = threads.saturating_sub(1).max(1);
    let failed: Result<(), CliError> = std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel::<(usize, io::Result<(PackedStream, EmitStats)>)>();
        for _ in 0..workers {
            let tx = tx.clone();
            let (plan, next_band, band_rows, spare) = (&plan, &next_band, &band_rows, &spare);
            scope.spawn(move || loop {
                let k = next_band.fetch_add(1, Ordering::Relaxed);
                if k >= n as usize {
                    break;
                }
                let reused = spare.lock().ok().and_then(|mut s| s.pop());
                let mut band = reused.unwrap_or_default();
                band.clear();
                let r = emit_rows(plan, options, band_rows(k as u32), &mut band)
                    .map(|stats| (band, stats));
                if tx.send((k, r)).is_err() {
                    break; // the feeder stopped on an error
                }
            });
        }
        drop(tx);
        // feed the bands in order as they arrive
        let mut waiting = BTreeMap::new();
        let mut want = 0usize;
        for (k, band) in rx {
            waiting.insert(k, band);
            while let Some(band) = waiting.remove(&want) {
                let (instructions, band_stats) = band.map_err(|e| {
                    CliError::Usage(format!(
                        "the Y-processor emitted an invalid instruction: {e}"
                    ))
                })?;
                stats.add_band(&band_stats);
                for instr in instructions.iter() {
                    feed.write(&instr)
                        .map_err(|e| CliError::Usage(format!("the array failed: {e}")))?;
                }
                if let Ok(mut s) = spare.lock() {
                    s.push(instructions);
                }
                want += 1;
            }
        }
        Ok(())
    });
    failed?;
    feed.close(stats, start.elapsed())
}

/// The whole trace in one encoding, in memory (written only once complete).
fn encode(scene: &ScreenScene, options: &Options, path: &Path) -> Result<Vec<u8>, CliError> {
    let encoding = Encoding::from_path(path)?;
    let mut bytes = Vec::new();
    {
        let mut w = encoding
            .writer(&mut bytes, &header(scene))
            .map_err(|e| CliError::write(path, e))?;
        emit(scene, options, &mut *w).map_err(|e| CliError::write(path, e))?;
        w.finish().map_err(|e| CliError::write(path, e))?;
    }
    Ok(bytes)
}

/// Runs `cwisim emit`.
pub fn run_emit(args: &EmitArgs) -> Result<(), CliError> {
    if same_file(&args.scene, &args.output) {
        return Err(CliError::Usage(
            "the output would overwrite the scene".into(),
        ));
    }
    let prepared = prepare(Some(&args.scene), &args.draw)?;
    let bytes = encode(&prepared.screen, &prepared.options, &args.output)?;
    write_atomic(&args.output, |w| {
        w.write_all(&bytes)
            .map_err(|e| CliError::write(&args.output, e))
    })
}

/// The PNG path `render` writes when given no output at all.
fn default_png(args: &RenderArgs, prepared: &PreparedScene) -> Option<PathBuf> {
    let any = args.image.wanted()
        || args.trace.is_some()
        || args.cost.wanted()
        || args.stats_json.is_some();
    (!any).then(|| PathBuf::from(format!("{}.png", prepared.source.name())))
}

/// Runs `cwisim render`.
pub fn run_render(
    args: &RenderArgs,
    stdout: &mut dyn Write,
    progress: bool,
) -> Result<(), CliError> {
    let [cost_image, cost_npy] = args.cost.outputs();
    let scene_file = args
        .scene
        .as_deref()
        .filter(|p| p.exists())
        .map(|p| ("scene", p));
    check_outputs(
        scene_file,
        &[
            ("-o", args.image.output.as_deref()),
            ("--npy", args.image.npy.as_deref()),
            ("--trace", args.trace.as_deref()),
            ("--stats-json", args.stats_json.as_deref()),
            (cost_image.0, cost_image.1.map(PathBuf::as_path)),
            (cost_npy.0, cost_npy.1.map(PathBuf::as_path)),
        ],
    )?;
    args.cost.check()?;
    let prepared = prepare(args.scene.as_deref(), &args.draw)?;
    let mut image_args = args.image.clone();
    if let Some(png) = default_png(args, &prepared) {
        image_args.output = Some(png);
    }
    let scene = &prepared.screen;
    let machine = args.machine.load()?;
    let timing = Timing::from(args.timing);
    let h = header(scene);
    image_args.check(h.channel_count())?;
    let trace_bytes = match &args.trace {
        Some(path) => Some(encode(scene, &prepared.options, path)?),
        None => None,
    };
    let mut sink = ImageSink::new(
        h.width as usize,
        h.channel_count(),
        ImageSink::DEFAULT_LIMIT_BYTES,
    );
    let mut cost = args.cost.wanted().then(|| CostMap::new(h.width as usize));
    let mut progress = Progress::scanlines(u64::from(h.lines), progress && !args.quiet);
    let threads = match args.threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    let rendered = render_scene_threads(
        scene,
        &prepared.options,
        &machine,
        &args.numeric,
        timing,
        &mut sink,
        cost.as_mut().map(|c| c as &mut dyn TraceWrite),
        Some(&mut progress),
        threads,
    )?;
    drop(progress);
    let start = Instant::now();
    let image = sink.finish()?;
    image_args.write(&image)?;
    if let Some(cost) = &cost {
        let name = match prepared.source.path() {
            Some(p) => display_name(p),
            None => prepared.source.name(),
        };
        args.cost.write(cost, &name)?;
    }
    if let (Some(path), Some(bytes)) = (&args.trace, &trace_bytes) {
        write_atomic(path, |w| {
            w.write_all(bytes).map_err(|e| CliError::write(path, e))
        })?;
    }
    if let Some(path) = &args.stats_json {
        let report = StatsReport {
            trace: (&h).into(),
            machine: &machine,
            timing: timing_name(timing),
            stats: &rendered.stats,
        };
        let mut json =
            serde_json::to_value(&report).map_err(|e| CliError::write(path, e.into()))?;
        json["emit"] =
            serde_json::to_value(&rendered.emitted).map_err(|e| CliError::write(path, e.into()))?;
        json["scene"] = crate::summary::scene_json(&prepared);
        json["numeric"] = serde_json::Value::from(args.numeric.to_string());
        let text = serde_json::to_string_pretty(&json)
            .map_err(|e| CliError::write(path, e.into()))?
            + "\n";
        write_atomic(path, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| CliError::write(path, e))
        })?;
    }
    let output_time = start.elapsed();
    if !args.quiet {
        let times = StageTimes {
            load: prepared.times.load,
            transform: prepared.times.transform,
            visibility: prepared.times.visibility,
            ypipe: rendered.ypipe_time,
            array: rendered.array_time,
            output: output_time,
        };
        let written: Vec<&Path> = [
            image_args.output.as_deref(),
            image_args.npy.as_deref(),
            args.trace.as_deref(),
            args.stats_json.as_deref(),
            cost_image.1.map(PathBuf::as_path),
            cost_npy.1.map(PathBuf::as_path),
        ]
        .into_iter()
        .flatten()
        .collect();
        write_render_summary(
            stdout,
            &prepared,
            &rendered.emitted,
            &rendered.stats,
            &args.numeric,
            &times,
            &written,
        )
        .map_err(CliError::Stdout)?;
        if args.stats {
            writeln!(stdout).map_err(CliError::Stdout)?;
            write_summary(stdout, &h, timing, &rendered.stats).map_err(CliError::Stdout)?;
        }
        stdout.flush().map_err(CliError::Stdout)?;
    }
    Ok(())
}
