//! `cwisim refine`: Bergman et al.'s adaptive refinement measured phase by phase (the
//! measuring is `cwisim_study::refine`'s; this is the command: arguments, files, the
//! table).

use super::MachineArgs;
use crate::cost_args::check_extension;
use crate::draw::ShadowsArg;
use crate::error::CliError;
use crate::files::{write_atomic, Io};
use crate::output::{write_png, write_rgb_png};
use crate::progress::Progress;
use clap::Args;
use cwisim_isa::{Instruction, TraceWrite};
use cwisim_render::refine::{parse_phases, vertex_parts, Phase};
use cwisim_render::settings::{
    Threshold, DEFAULT_AA_THRESHOLD, DEFAULT_GOURAUD_THRESHOLD, DEFAULT_PHONG_ANGLE,
};
use cwisim_render::{Settings, Size, Source};
use cwisim_study::cost::render_cost_image;
use cwisim_study::refine::{run_refines, RefineRun, RefineSetup};
use cwisim_study::refine_ids::{encode_id_npy, id_rgb};
use cwisim_study::refine_plot::render_refine_plot;
use cwisim_study::refine_report::{csv, write_table, Sweep};
use cwisim_study::refine_session::{render_session_plot, run_session, write_session};
use cwisim_world::events::EventScript;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The arguments of `cwisim refine`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct RefineArgs {
    /// The scene: a file or an embedded name (default: the pot). A world scene: a screen
    /// scene has nothing to refine.
    #[arg(value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// The phases to run, comma-separated, in this order: vertices, edges (depth-cued
    /// points and lines), flat, shadows, gouraud, phong, aa; flat before any phase
    /// refining it. The shadow phase runs after flat whenever a light casts shadows.
    #[arg(long, value_name = "LIST", default_value = "flat,gouraud,phong,aa")]
    pub phases: String,
    /// The vertex phase a fraction of the vertices at a time: 1/N splits it into N frames,
    /// each adding every N-th vertex of the model (0.1: ten frames, the paper's "10% of
    /// vertices" first, all of them last); 1 draws them all in one frame.
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub vertex_fraction: f64,
    /// The Gouraud phase shades a polygon whose vertex-intensity range exceeds T; `all`
    /// or `none`.
    #[arg(long, value_name = "T", default_value_t = Threshold::Above(DEFAULT_GOURAUD_THRESHOLD))]
    pub gouraud_threshold: Threshold,
    /// The Phong phase lights per pixel a polygon whose highlight vector at some vertex is
    /// within DEG degrees of the direction to the eye; `all` or `none`.
    #[arg(long, value_name = "DEG", default_value_t = Threshold::Above(DEFAULT_PHONG_ANGLE))]
    pub phong_angle: Threshold,
    /// The anti-aliasing phase box-filters a pixel whose 3x3 range in the previous frame
    /// exceeds T; `all` or `none`.
    #[arg(long, value_name = "T", default_value_t = Threshold::Above(DEFAULT_AA_THRESHOLD))]
    pub aa_threshold: Threshold,
    /// Draw at this size, WIDTHxHEIGHT (default: the scene's).
    #[arg(long, value_name = "WxH")]
    pub size: Option<Size>,
    /// Tessellate Bézier meshes N×N per patch (default: as the scene says).
    #[arg(long, value_name = "N")]
    pub tessellate: Option<u32>,
    /// Shadows from every light (on) or from none (off), whatever each light's "shadows"
    /// entry in the scene says [default: as the scene says]; with shadows, the shadow
    /// phase runs after flat (docs/SHADOWS.md).
    #[arg(long, value_enum, value_name = "on|off")]
    pub shadows: Option<ShadowsArg>,
    /// Phong's span fitter tolerance, in intensity.
    #[arg(long, value_name = "E", default_value_t = 1.0 / 512.0)]
    pub shade_tolerance: f64,
    /// Also write the whole stream, every phase's frame (.cwt, .jsonl or .cwb).
    #[arg(long, value_name = "OUT")]
    pub trace: Option<PathBuf>,
    /// Write each phase's frame as DIR/phase-K-NAME.png.
    #[arg(long, value_name = "DIR")]
    pub frames_png: Option<PathBuf>,
    /// Write each phase's cost image (instructions per pixel) as DIR/phase-K-NAME-cost.png.
    #[arg(long, value_name = "DIR")]
    pub cost_image_dir: Option<PathBuf>,
    /// Write the polygon-ID view: which polygon of the display list owns each pixel
    /// (the paper's ID buffer), as a false-colour .png or the identifiers as .npy
    /// (uint32; 0 none, k the display list's polygon k-1).
    #[arg(long, value_name = "OUT.png|OUT.npy")]
    pub ids: Option<PathBuf>,
    /// Write the table as CSV (one line per phase, refined and naive).
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,
    /// Draw error against cumulative cycles (with the naive sequence) and busy cycles per
    /// scanline against the line period, as a PNG. Without any output option the plot
    /// goes to SCENE-NAME-refine.png in the working directory.
    #[arg(long, value_name = "OUT.png")]
    pub plot: Option<PathBuf>,
    /// An interactive session: a script of user events (JSON: the camera or a light moved
    /// at given times, in the display's cycles or frames; docs/RENDERERS.md), the
    /// refinement restarted from its first phase at each. Prints, per event, the latency to
    /// each phase's frame and the phase reached before the next event; --plot draws the
    /// timeline.
    #[arg(long, value_name = "SCRIPT.json")]
    pub events: Option<PathBuf>,
    /// Run once per value of one threshold: NAME=V1,V2,… (NAME: gouraud-threshold,
    /// phong-angle, aa-threshold).
    #[arg(long, value_name = "NAME=V1,V2,…")]
    pub sweep: Option<Sweep>,
    /// Threads: a sweep's runs measured on N threads at once (0: one per core), each
    /// run's table printed in order as it is done; a single run's frames rendered on N
    /// threads (bands of scanlines, as `render --threads`). The output is the same at
    /// any N.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub threads: usize,
    /// The machine model.
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// `phase-K-NAME` of frame `k`.
fn stem(k: usize, run: &RefineRun) -> String {
    format!("phase-{}-{}", k + 1, run.rows[k].phase)
}

fn create_dir(flag: &str, dir: &Path) -> Result<(), CliError> {
    if dir.is_file() {
        return Err(CliError::Usage(format!(
            "{flag} {}: a file, not a directory",
            dir.display()
        )));
    }
    std::fs::create_dir_all(dir).map_err(|e| CliError::write(dir, e))
}

/// The plot `refine` writes when given no output at all: `SCENE-NAME-refine.png`.
fn default_plot(args: &RefineArgs) -> Result<Option<PathBuf>, CliError> {
    let any = args.trace.is_some()
        || args.frames_png.is_some()
        || args.cost_image_dir.is_some()
        || args.csv.is_some()
        || args.ids.is_some()
        || args.plot.is_some();
    if any {
        return Ok(args.plot.clone());
    }
    let name = Source::resolve(args.scene.as_deref())?.name();
    let what = if args.events.is_some() {
        "session"
    } else {
        "refine"
    };
    Ok(Some(PathBuf::from(format!("{name}-{what}.png"))))
}

/// Runs `cwisim refine`.
pub fn run(args: &RefineArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    let plot = default_plot(args)?;
    Io::new()
        .source("scene", args.scene.as_deref())
        .source("--events", args.events.as_deref())
        .machine(&args.machine)
        .output("--trace", args.trace.as_deref())
        .output("--csv", args.csv.as_deref())
        .output("--plot", plot.as_deref())
        .output("--ids", args.ids.as_deref())
        .check()?;
    let ids_npy = match &args.ids {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy")) => Some(true),
        Some(p) => check_extension("--ids", p, "png").map(|()| Some(false))?,
        None => None,
    };
    if let Some(p) = &plot {
        check_extension("--plot", p, "png")?;
    }
    if let Some(p) = &args.csv {
        check_extension("--csv", p, "csv")?;
    }
    let encoding = args
        .trace
        .as_deref()
        .map(crate::files::trace_output_encoding)
        .transpose()?;
    if args.events.is_some() {
        for (flag, given) in [
            ("--sweep", args.sweep.is_some()),
            ("--trace", args.trace.is_some()),
            ("--frames-png", args.frames_png.is_some()),
            ("--cost-image-dir", args.cost_image_dir.is_some()),
            ("--ids", args.ids.is_some()),
            ("--csv", args.csv.is_some()),
        ] {
            if given {
                return Err(CliError::Usage(format!(
                    "{flag} is of one refinement; --events runs a session of several (its table, and --plot its timeline): drop one of them"
                )));
            }
        }
    }
    if args.sweep.is_some() {
        for (flag, given) in [
            ("--trace", args.trace.is_some()),
            ("--frames-png", args.frames_png.is_some()),
            ("--cost-image-dir", args.cost_image_dir.is_some()),
            ("--ids", args.ids.is_some()),
        ] {
            if given {
                return Err(CliError::Usage(format!(
                    "{flag} writes one run's frames; --sweep makes several: drop one of them"
                )));
            }
        }
    }
    let phases: Vec<Phase> = parse_phases(&args.phases).map_err(CliError::Usage)?;
    let settings = Settings {
        gouraud_threshold: args.gouraud_threshold,
        phong_angle: args.phong_angle,
        aa_threshold: args.aa_threshold,
        size: args.size,
        tessellate: args.tessellate,
        shade_tolerance: args.shade_tolerance,
        shadows: args.shadows.map(|s| s == ShadowsArg::On),
        ..Settings::default()
    };
    settings.check().map_err(CliError::Usage)?;
    cwisim_scene::budget::check_threads(args.threads).map_err(CliError::Usage)?;
    let machine = args.machine.load()?;
    let runs: Vec<(Option<String>, Settings)> = match &args.sweep {
        Some(sweep) => sweep
            .values
            .iter()
            .map(|&v| {
                (
                    Some(format!("--{} {v}", sweep.name.flag())),
                    sweep.name.apply(&settings, v),
                )
            })
            .collect(),
        None => vec![(None, settings)],
    };
    for (_, s) in &runs {
        s.check().map_err(CliError::Usage)?;
    }
    let vertex_parts = vertex_parts(args.vertex_fraction).map_err(CliError::Usage)?;
    if let Some(path) = &args.events {
        let setup = RefineSetup {
            scene: args.scene.as_deref(),
            changes: &[],
            settings,
            phases,
            vertex_parts,
            machine,
            naive: false,
            cost_maps: false,
            ids: false,
            threads: 1,
            cancel: None,
        };
        return session(args, path, &setup, plot, stdout, progress);
    }
    let setups: Vec<RefineSetup> = runs
        .iter()
        .enumerate()
        .map(|(k, (_, s))| RefineSetup {
            scene: args.scene.as_deref(),
            changes: &[],
            settings: *s,
            phases: phases.clone(),
            vertex_parts,
            machine: machine.clone(),
            naive: k == 0,
            cost_maps: args.cost_image_dir.is_some(),
            ids: args.ids.is_some(),
            threads: 1,
            cancel: None,
        })
        .collect();
    let bar = std::sync::Mutex::new(Progress::scanlines(0, progress));
    let report = |lines: u64| {
        if let Ok(mut bar) = bar.lock() {
            bar.update(lines);
        }
    };
    let mut stream: Vec<Instruction> = Vec::new();
    let trace = encoding
        .is_some()
        .then_some(&mut stream as &mut dyn TraceWrite);
    // each run's table printed as it is done, in order
    let mut failed: Option<std::io::Error> = None;
    let done = run_refines(&setups, args.threads, trace, &report, |k, run| {
        if failed.is_some() {
            return;
        }
        let label = runs[k].0.as_deref();
        let write = |out: &mut dyn Write| {
            if k > 0 {
                writeln!(out)?;
            }
            write_table(out, run, label)?;
            out.flush()
        };
        let written = match bar.lock() {
            Ok(bar) => bar.suspend(|| write(stdout)),
            Err(_) => write(stdout),
        };
        if let Err(e) = written {
            failed = Some(e);
        }
    })?;
    drop(bar);
    if let Some(e) = failed {
        return Err(CliError::Stdout(e));
    }
    let results: Vec<(Option<String>, RefineRun)> = runs
        .iter()
        .map(|(label, _)| label.clone())
        .zip(done)
        .collect();
    let Some((_, first)) = results.first() else {
        return Err(CliError::Usage("nothing to run".into()));
    };
    if let (Some(path), Some(encoding)) = (&args.trace, encoding) {
        write_atomic(path, |w| {
            let mut out = encoding
                .writer(w, &first.header)
                .map_err(|e| CliError::write(path, e))?;
            for i in &stream {
                out.write(i).map_err(|e| CliError::write(path, e))?;
            }
            out.finish().map_err(|e| CliError::write(path, e))
        })?;
    }
    if let Some(dir) = &args.frames_png {
        create_dir("--frames-png", dir)?;
        for (k, frame) in first.frames.iter().enumerate() {
            write_png(&dir.join(format!("{}.png", stem(k, first))), frame)?;
        }
    }
    if let Some(dir) = &args.cost_image_dir {
        create_dir("--cost-image-dir", dir)?;
        for (k, map) in first.cost_maps.iter().enumerate() {
            let name = format!("{}, {}", first.scene, stem(k, first));
            let img = render_cost_image(map, &name)?;
            write_rgb_png(&dir.join(format!("{}-cost.png", stem(k, first))), &img)?;
        }
    }
    if let (Some(path), Some(npy), Some(ids)) = (&args.ids, ids_npy, &first.ids) {
        if npy {
            write_atomic(path, |w| {
                encode_id_npy(w, ids).map_err(|e| CliError::write(path, e))
            })?;
        } else {
            write_rgb_png(path, &id_rgb(ids))?;
        }
    }
    if let Some(path) = &args.csv {
        let text = csv(&results);
        write_atomic(path, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| CliError::write(path, e))
        })?;
    }
    if let Some(path) = &plot {
        let img = render_refine_plot(&results).map_err(CliError::Usage)?;
        write_rgb_png(path, &img)?;
    }
    let frames = first.frames.len();
    let written: Vec<String> = [
        args.trace.as_ref().map(|p| p.display().to_string()),
        args.frames_png
            .as_ref()
            .map(|d| format!("{} ({frames} frame PNGs)", d.display())),
        args.cost_image_dir
            .as_ref()
            .map(|d| format!("{} ({frames} cost images)", d.display())),
        args.ids.as_ref().map(|p| p.display().to_string()),
        args.csv.as_ref().map(|p| p.display().to_string()),
        plot.as_ref().map(|p| p.display().to_string()),
    ]
    .into_iter()
    .flatten()
    .collect();
    if !written.is_empty() {
        writeln!(stdout, "\nwrote {}", written.join(", ")).map_err(CliError::Stdout)?;
    }
    stdout.flush().map_err(CliError::Stdout)
}

/// `cwisim refine --events SCRIPT`: the session of `setup`'s refinement, its table and its
/// timeline.
fn session(
    args: &RefineArgs,
    path: &Path,
    setup: &RefineSetup,
    plot: Option<PathBuf>,
    stdout: &mut dyn Write,
    progress: bool,
) -> Result<(), CliError> {
    let loaded = Source::resolve(setup.scene)?.load_for(&setup.settings)?;
    let cwisim_world::AnyScene::World(w) = &loaded.scene else {
        return Err(CliError::Usage(format!(
            "--events moves a world scene's camera and lights; {} is a screen scene",
            loaded.source.name()
        )));
    };
    let text = cwisim_scene::read_scene_text(path)?;
    let script =
        EventScript::parse(&text, &w.spec).map_err(|e| CliError::Scene(e.in_file(path)))?;
    let bar = std::sync::Mutex::new(Progress::scanlines(0, progress));
    let report = |lines: u64| {
        if let Ok(mut bar) = bar.lock() {
            bar.update(lines);
        }
    };
    let (s, _) = run_session(setup, &script, args.threads, &report)?;
    drop(bar);
    write_session(stdout, &s).map_err(CliError::Stdout)?;
    if let Some(p) = &plot {
        let img = render_session_plot(&s).map_err(CliError::Usage)?;
        write_rgb_png(p, &img)?;
        writeln!(stdout, "\nwrote {}", p.display()).map_err(CliError::Stdout)?;
    }
    stdout.flush().map_err(CliError::Stdout)
}
