//! `cwisim render` and `cwisim emit`: a scene (screen or world, a file or an embedded
//! name) through a renderer (`cwisim-render`'s registry), into the array simulator or a
//! trace file.

use super::{ImageArgs, MachineArgs};
use crate::commands::run::TimingArg;
use crate::cost_args::{display_name, CostArgs};
use crate::draw::DrawArgs;
use crate::error::CliError;
use crate::files::{write_atomic, Io};
use crate::progress::{Progress, Stage};
use crate::report::{timing_name, write_summary, StatsReport};
use crate::summary::{write_render_summary, StageTimes};
use clap::Args;
use cwisim_isa::TraceWrite;
use cwisim_render::{render, ArrayConfig, Renderer, Taps};
use cwisim_study::cost::CostMap;
use cwisim_xproc::{Numeric, Timing};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
    /// Print nothing on standard output (errors and warnings still go to standard error).
    #[arg(short, long)]
    pub quiet: bool,
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
    /// Print nothing on standard output (errors and warnings still go to standard error).
    #[arg(short, long, conflicts_with = "stats")]
    pub quiet: bool,
    /// Threads: the Y-processor emits bands of scanlines and runs each through processors
    /// of its own, whose scanlines the array takes in, in order; with N > 1, exact
    /// visibility runs on N threads, then N threads emit and run bands while one takes
    /// them in (0: one per core). With a trace, a cost map or the stepped engine the
    /// instructions go to the array itself instead. The output, trace and statistics are
    /// identical at any N, byte for byte.
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub threads: usize,
}

/// The renderer's whole stream in one encoding, in memory (written only once complete).
fn encode(renderer: &dyn Renderer, path: &Path) -> Result<Vec<u8>, CliError> {
    let encoding = crate::files::trace_output_encoding(path)?;
    let mut bytes = Vec::new();
    {
        let mut w = encoding
            .writer(&mut bytes, &renderer.header())
            .map_err(|e| CliError::write(path, e))?;
        cwisim_render::emit(renderer, &mut *w)?;
    }
    Ok(bytes)
}

/// Runs `cwisim emit`.
pub fn run_emit(args: &EmitArgs, stdout: &mut dyn Write) -> Result<(), CliError> {
    Io::new()
        .source("scene", Some(&args.scene))
        .output("-o", Some(&args.output))
        .check()?;
    let drawn = args.draw.draw(Some(&args.scene))?;
    let bytes = encode(&*drawn.renderer, &args.output)?;
    write_atomic(&args.output, |w| {
        w.write_all(&bytes)
            .map_err(|e| CliError::write(&args.output, e))
    })?;
    if !args.quiet {
        let h = drawn.renderer.header();
        let detail = format!(
            "{}'s stream for {} × {} × {} channel(s), {} byte(s)",
            drawn.renderer.name(),
            h.width,
            h.lines,
            h.channel_count(),
            bytes.len()
        );
        if let Some(line) = crate::files::wrote_line(&[&args.output], Some(&detail)) {
            writeln!(stdout, "{line}").map_err(CliError::Stdout)?;
        }
    }
    Ok(())
}

/// The PNG path `render` writes when given no output at all.
fn default_png(args: &RenderArgs) -> Result<Option<PathBuf>, CliError> {
    let any = args.image.wanted()
        || args.trace.is_some()
        || args.cost.wanted()
        || args.stats_json.is_some();
    if any {
        return Ok(None);
    }
    let name = cwisim_render::Source::resolve(args.scene.as_deref())?.name();
    Ok(Some(PathBuf::from(format!("{name}.png"))))
}

/// Runs `cwisim render`.
pub fn run_render(
    args: &RenderArgs,
    stdout: &mut dyn Write,
    progress: bool,
) -> Result<(), CliError> {
    let [cost_image, cost_npy] = args.cost.outputs();
    let default_png = default_png(args)?;
    Io::new()
        .source("scene", args.scene.as_deref())
        .machine(&args.machine)
        .output(
            "-o",
            args.image.output.as_deref().or(default_png.as_deref()),
        )
        .output("--npy", args.image.npy.as_deref())
        .output("--trace", args.trace.as_deref())
        .output("--stats-json", args.stats_json.as_deref())
        .output(cost_image.0, cost_image.1.map(PathBuf::as_path))
        .output(cost_npy.0, cost_npy.1.map(PathBuf::as_path))
        .check()?;
    args.cost.check()?;
    cwisim_scene::budget::check_threads(args.threads).map_err(CliError::Usage)?;
    // loading, projecting, lighting and exact visibility come before the first scanline
    let stage = Stage::new(
        progress && !args.quiet,
        "render: loading and preparing the scene (visibility)",
    );
    let drawn = args.draw.draw_on(args.scene.as_deref(), args.threads)?;
    drop(stage);
    let mut image_args = args.image.clone();
    if let Some(png) = default_png {
        image_args.output = Some(png);
    }
    let renderer = &*drawn.renderer;
    let array = ArrayConfig {
        machine: args.machine.load()?,
        numeric: args.numeric,
        timing: Timing::from(args.timing),
    };
    let h = renderer.header();
    image_args.check(h.channel_count())?;
    let threads = cwisim_scene::budget::resolve_threads(args.threads);
    image_args.check_memory_with(
        h.width,
        h.channel_count(),
        frames_lines_of(renderer),
        Some((
            cwisim_render::pipeline::frame_memory_phrase(renderer, threads),
            renderer.frame_memory(threads),
        )),
    )?;
    let trace_bytes = match &args.trace {
        Some(path) => Some(encode(renderer, path)?),
        None => None,
    };
    let frames_lines = u64::from(h.lines) * u64::from(renderer.frames());
    // only what the outputs need, with room for every frame's scanlines up front: it is
    // not copied as it grows
    let mut sink = image_args.sink(h.width as usize, h.channel_count(), frames_lines);
    let mut cost = args.cost.wanted().then(|| CostMap::new(h.width as usize));
    let mut progress = Progress::scanlines(frames_lines, progress && !args.quiet);
    let rendered = render(
        renderer,
        &array,
        args.threads,
        &mut sink,
        Taps {
            also: cost.as_mut().map(|c| c as &mut dyn TraceWrite),
            progress: Some(&mut |lines| progress.update(lines)),
            cancel: None,
        },
    )?;
    drop(progress);
    let start = Instant::now();
    image_args.write(&sink.finish()?)?;
    if let Some(cost) = &cost {
        let name = match drawn.source.path() {
            Some(p) => display_name(p),
            None => drawn.source.name(),
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
            machine: &array.machine,
            timing: timing_name(array.timing),
            stats: &rendered.stats,
        };
        let mut json =
            serde_json::to_value(&report).map_err(|e| CliError::write(path, e.into()))?;
        json["renderer"] = serde_json::Value::from(renderer.name());
        json["counters"] = serde_json::to_value(&rendered.counters)
            .map_err(|e| CliError::write(path, e.into()))?;
        json["scene"] = crate::summary::scene_json(&drawn);
        if rendered.row_figures.iter().any(|f| !f.is_null()) {
            // one array of per-row objects per frame
            json["renderer_rows"] = serde_json::Value::from(rendered.row_figures.clone());
        }
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
            load: drawn.load_time,
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
        write_render_summary(stdout, &drawn, &rendered, &args.numeric, &times, &written)
            .map_err(CliError::Stdout)?;
        if args.stats {
            writeln!(stdout).map_err(CliError::Stdout)?;
            write_summary(stdout, &h, array.timing, &rendered.stats).map_err(CliError::Stdout)?;
        }
        stdout.flush().map_err(CliError::Stdout)?;
    }
    Ok(())
}

/// The scanlines of every frame a renderer draws.
fn frames_lines_of(renderer: &dyn cwisim_render::Renderer) -> u64 {
    u64::from(renderer.header().lines) * u64::from(renderer.frames())
}
