//! `cwisim emit` and `cwisim render`: a screen-space scene through the Y-processor
//! (`cwisim-ypipe`), into a trace file or straight into the array simulator.

use super::{ImageArgs, MachineArgs};
use crate::commands::run::TimingArg;
use crate::cost::{display_name, CostArgs, CostMap, Tee};
use crate::error::CliError;
use crate::files::{check_outputs, same_file, write_atomic};
use crate::report::{timing_name, write_summary, StatsReport};
use clap::{Args, ValueEnum};
use cwisim_isa::{Encoding, TraceWrite};
use cwisim_xproc::{EngineWriter, ImageSink, LineSink, Machine, RunStats, Timing};
use cwisim_ypipe::scene::{load_scene, Scene, ScreenScene};
use cwisim_ypipe::{emit, header, Antialias, EmitStats, Options, Shading};
use std::io::Write;
use std::path::{Path, PathBuf};

/// `--shading`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ShadingArg {
    /// One intensity per polygon (the mean of its vertices'): Eval1 spans.
    Flat,
    /// Interpolated along the edges and across each scanline: Eval2 spans.
    #[default]
    Gouraud,
}

/// `--aa`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum AaArg {
    /// Point sampling at pixel centres.
    None,
    /// Box filter: the exact covered area of every pixel (DO_FILL's twelve cases).
    #[default]
    Box,
}

/// The scan-conversion options shared by `emit` and `render`.
#[derive(Args, Clone, Debug, Default, PartialEq)]
pub struct ScanArgs {
    /// Shading.
    #[arg(long, value_enum, default_value_t = ShadingArg::Gouraud)]
    pub shading: ShadingArg,
    /// Anti-aliasing.
    #[arg(long, value_enum, default_value_t = AaArg::Box)]
    pub aa: AaArg,
}

impl ScanArgs {
    /// The Y-processor's options (the default: Gouraud shading, box filter).
    pub fn options(&self) -> Options {
        Options {
            shading: match self.shading {
                ShadingArg::Flat => Shading::Flat,
                ShadingArg::Gouraud => Shading::Gouraud,
            },
            aa: match self.aa {
                AaArg::None => Antialias::None,
                AaArg::Box => Antialias::Box,
            },
        }
    }
}

/// The arguments of `cwisim emit`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct EmitArgs {
    /// The screen-space scene (JSON, "kind": "screen").
    #[arg(value_name = "SCENE.json")]
    pub scene: PathBuf,
    /// The trace to write: .cwt (annotated text), .jsonl or .cwb, by extension.
    #[arg(short = 'o', long = "output", value_name = "OUT")]
    pub output: PathBuf,
    /// Scan conversion.
    #[command(flatten)]
    pub scan: ScanArgs,
}

/// The arguments of `cwisim render`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct RenderArgs {
    /// The screen-space scene (JSON, "kind": "screen").
    #[arg(value_name = "SCENE.json")]
    pub scene: PathBuf,
    /// Image outputs.
    #[command(flatten)]
    pub image: ImageArgs,
    /// Cost outputs: instructions per pixel.
    #[command(flatten)]
    pub cost: CostArgs,
    /// Also write the emitted trace (.cwt annotated text, .jsonl or .cwb).
    #[arg(long, value_name = "OUT")]
    pub trace: Option<PathBuf>,
    /// Scan conversion.
    #[command(flatten)]
    pub scan: ScanArgs,
    /// The machine model.
    #[command(flatten)]
    pub machine: MachineArgs,
    /// Timing model. Both give identical images and cycle counts.
    #[arg(long, value_enum, default_value_t = TimingArg::Fast)]
    pub timing: TimingArg,
    /// Print a summary of the statistics to standard output.
    #[arg(long)]
    pub stats: bool,
    /// Write the scan-conversion and array statistics as JSON.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
}

/// Loads a screen-space scene file (errors are located).
pub fn load_screen(path: &Path) -> Result<ScreenScene, CliError> {
    let Scene::Screen(s) = load_scene(path)?;
    Ok(s)
}

/// Scan-converts `scene` straight into the array on `machine`, handing its scanlines to
/// `sink`, and every instruction also to `also` (after the array took it) when given.
/// Returns the scan conversion's and the array's statistics.
pub fn render_scene(
    scene: &ScreenScene,
    options: &Options,
    machine: &Machine,
    timing: Timing,
    sink: &mut dyn LineSink<f64>,
    also: Option<&mut dyn TraceWrite>,
) -> Result<(EmitStats, RunStats), CliError> {
    let h = header(scene);
    let mut array = EngineWriter::<f64>::new(&h, machine, timing, sink)?;
    let emitted: EmitStats = match also {
        None => emit(scene, options, &mut array),
        Some(second) => emit(
            scene,
            options,
            &mut Tee {
                first: &mut array,
                second,
            },
        ),
    }
    .map_err(|e| {
        CliError::Usage(format!(
            "the Y-processor emitted an invalid instruction: {e}"
        ))
    })?;
    array
        .finish()
        .map_err(|e| CliError::Usage(format!("the array failed: {e}")))?;
    Ok((emitted, array.into_stats().expect("finished")))
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
    let scene = load_screen(&args.scene)?;
    let bytes = encode(&scene, &args.scan.options(), &args.output)?;
    write_atomic(&args.output, |w| {
        w.write_all(&bytes)
            .map_err(|e| CliError::write(&args.output, e))
    })
}

/// Runs `cwisim render`.
pub fn run_render(args: &RenderArgs, stdout: &mut dyn Write) -> Result<(), CliError> {
    let [cost_image, cost_npy] = args.cost.outputs();
    check_outputs(
        Some(("scene", args.scene.as_path())),
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
    let scene = load_screen(&args.scene)?;
    let options = args.scan.options();
    let machine = args.machine.load()?;
    let timing = Timing::from(args.timing);
    let h = header(&scene);
    args.image.check(h.channel_count())?;
    let trace_bytes = match &args.trace {
        Some(path) => Some(encode(&scene, &options, path)?),
        None => None,
    };
    let mut sink = ImageSink::new(
        h.width as usize,
        h.channel_count(),
        ImageSink::DEFAULT_LIMIT_BYTES,
    );
    let mut cost = args.cost.wanted().then(|| CostMap::new(h.width as usize));
    let (emitted, stats) = render_scene(
        &scene,
        &options,
        &machine,
        timing,
        &mut sink,
        cost.as_mut().map(|c| c as &mut dyn TraceWrite),
    )?;
    let image = sink.finish()?;
    args.image.write(&image)?;
    if let Some(cost) = &cost {
        args.cost.write(cost, &display_name(&args.scene))?;
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
            stats: &stats,
        };
        let mut json =
            serde_json::to_value(&report).map_err(|e| CliError::write(path, e.into()))?;
        json["emit"] =
            serde_json::to_value(&emitted).map_err(|e| CliError::write(path, e.into()))?;
        let text = serde_json::to_string_pretty(&json)
            .map_err(|e| CliError::write(path, e.into()))?
            + "\n";
        write_atomic(path, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| CliError::write(path, e))
        })?;
    }
    if args.stats {
        write_emit_summary(stdout, &emitted).map_err(CliError::Stdout)?;
        write_summary(stdout, &h, timing, &stats).map_err(CliError::Stdout)?;
        stdout.flush().map_err(CliError::Stdout)?;
    }
    Ok(())
}

fn write_emit_summary(out: &mut dyn Write, e: &EmitStats) -> std::io::Result<()> {
    writeln!(out, "{:<26}{}", "polygons", e.polygons)?;
    writeln!(out, "{:<26}{}", "trapezia", e.trapezia)?;
    writeln!(out, "{:<26}{}", "trapezium rows", e.rows_filled)?;
    let cases: Vec<String> = e
        .cases
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(k, n)| format!("{}:{n}", k + 1))
        .collect();
    if !cases.is_empty() {
        writeln!(
            out,
            "{:<26}{}",
            "DO_FILL cases (case:rows)",
            cases.join(" ")
        )?;
    }
    writeln!(
        out,
        "{:<26}{} pixels, {} middle parts, {} sequences, {} share-sequences",
        "procedures", e.single_pixels, e.middle_parts, e.sequences, e.share_sequences
    )
}
