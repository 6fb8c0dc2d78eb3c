//! `cwisim tradeoff`: one scene rendered over a grid of settings, each measured — what
//! it costs (instructions, bus cycles, the worst scanline, host time) against how far it
//! is from the exact image (max, RMS, PSNR) — with the Pareto front of error against
//! cycles marked. The measuring is `cwisim_study::tradeoff`'s; this is the command.
//!

use super::MachineArgs;
use crate::draw::{angle_or_off, AngleOrOff, SbufferArg, ShadowsArg};
use crate::error::CliError;
use crate::files::{write_atomic, Io};
use crate::output::write_rgb_png;
use crate::progress::Progress;
use clap::Args;
use cwisim_render::{Size, Source};
use cwisim_study::tradeoff::{
    csv, mark_pareto, measure_groups, merge_csv, write_table_header, write_table_row, Plan,
    Request, Shard, Step, TableLayout, DEFAULT_FORMATS, DEFAULT_TESSELLATIONS,
};
use cwisim_study::tradeoff_plot::render_tradeoff_plot;
use cwisim_xproc::Numeric;
use std::io::Write;
use std::path::PathBuf;

/// The arguments of `cwisim tradeoff`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct TradeoffArgs {
    /// The scene: a file or an embedded name (default: the pot).
    #[arg(value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// Draw at this size, WIDTHxHEIGHT (default: the scene's).
    #[arg(long, value_name = "WxH")]
    pub size: Option<Size>,
    /// For scenes with Bézier meshes: the tessellations to try (quads per patch side),
    /// comma-separated.
    #[arg(long = "tessellate", value_name = "N,…", value_delimiter = ',', default_values_t = DEFAULT_TESSELLATIONS)]
    pub tessellate: Vec<u32>,
    /// World scenes: the shadows to try, `on`, `off` or both (`on,off`): every light
    /// casting shadows, or none, for each renderer that draws them [default: as the scene
    /// says]. Each row is measured against the exact image with the same shadows.
    #[arg(long, value_enum, value_name = "on|off,…", value_delimiter = ',')]
    pub shadows: Vec<ShadowsArg>,
    /// The renderers to try, comma-separated (default: every registered renderer;
    /// `cwisim renderers` lists them).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub renderers: Vec<String>,
    /// sbuffer's modes to try at every samples value, comma-separated: host (its default,
    /// depth per sample) and abuffer (the scanline A-buffer: a samples × samples coverage
    /// mask per pixel, shown as `abuffer` in the aa column) [default: host].
    #[arg(long, value_enum, value_name = "SBUFFER,…", value_delimiter = ',')]
    pub sbuffer: Vec<SbufferArg>,
    /// nishita's normal-difference subdivision (its §5) to try at every root tolerance,
    /// comma-separated: angles in degrees and `off` (e.g. `off,20,10`; the tess column
    /// shows the angle beside the tolerance, the CSV's `normal_angle`) [default: off].
    #[arg(long = "normal-angle", value_name = "ANGLE|off,…", value_delimiter = ',', value_parser = angle_or_off)]
    pub normal_angle: Vec<AngleOrOff>,
    /// The numeric formats of the array to try: repeat the flag, or separate them with
    /// `;` (a fixed format has commas of its own): f64, f32,
    /// fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate].
    #[arg(long = "numeric", value_name = "FORMAT", value_delimiter = ';')]
    pub numeric: Vec<Numeric>,
    /// Write the table as CSV.
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,
    /// Draw error against bus cycles, the Pareto front marked, as a PNG.
    #[arg(long, value_name = "OUT.png")]
    pub plot: Option<PathBuf>,
    /// Time each setting this many times and report the median host time.
    #[arg(long, default_value_t = 3, value_name = "N")]
    pub repeat: u32,
    /// Threads: settings measured on N threads at once (0: one per core), rows printed
    /// in the grid's order as they are measured; the table and CSV are the same at any
    /// N but for the host times.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub threads: usize,
    /// Measure only part I of N of the grid (from 0: `--shard 0/4` … `--shard 3/4`), for a
    /// batch system's array of jobs, each writing its rows with --csv; `--merge` then
    /// joins the parts. A part's rows are not marked Pareto-optimal: that needs them all.
    #[arg(long, value_name = "I/N", requires = "csv")]
    pub shard: Option<Shard>,
    /// Join the CSVs of a sweep's parts (`--shard`), given in part order, into the whole
    /// sweep's: the rows in the grid's order, the Pareto front marked over them all,
    /// printed and written with --csv and --plot. Nothing is measured.
    #[arg(
        long,
        value_name = "PART.csv",
        num_args = 1..,
        conflicts_with_all = ["scene", "size", "tessellate", "shadows", "renderers", "sbuffer", "normal_angle", "numeric", "repeat", "threads", "shard"]
    )]
    pub merge: Vec<PathBuf>,
    /// The machine model.
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// Runs `cwisim tradeoff`.
pub fn run(args: &TradeoffArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    let mut io = Io::new()
        .source("scene", args.scene.as_deref())
        .machine(&args.machine);
    for part in &args.merge {
        io = io.input("part being merged", Some(part));
    }
    io.output("--csv", args.csv.as_deref())
        .output("--plot", args.plot.as_deref())
        .check()?;
    if let Some(p) = &args.plot {
        crate::cost_args::check_extension("--plot", p, "png")?;
    }
    if let Some(p) = &args.csv {
        crate::cost_args::check_extension("--csv", p, "csv")?;
    }
    if !args.merge.is_empty() {
        return merge(args, stdout);
    }
    cwisim_scene::budget::check_threads(args.threads).map_err(CliError::Usage)?;
    let shadows: Vec<bool> = args.shadows.iter().map(|&s| s == ShadowsArg::On).collect();
    if (1..shadows.len()).any(|k| shadows[..k].contains(&shadows[k])) {
        return Err(CliError::Usage(
            "--shadows: each of on and off at most once".into(),
        ));
    }
    let machine = args.machine.load()?;
    let formats: Vec<Numeric> = if args.numeric.is_empty() {
        DEFAULT_FORMATS
            .iter()
            .map(|f| f.parse().expect("the default formats parse"))
            .collect()
    } else {
        args.numeric.clone()
    };
    // rows are printed as they are measured, a progress bar on a terminal says where the
    // sweep is; the Pareto front needs every row, so it comes last
    let mut bar: Option<Progress> = None;
    let mut failed: Option<std::io::Error> = None;
    let request = Request {
        size: args.size,
        tessellations: args.tessellate.clone(),
        shadows,
        renderers: args.renderers.clone(),
        formats,
        sbuffer: args.sbuffer.iter().map(|&m| m.into()).collect(),
        normal_angles: args.normal_angle.iter().map(|a| a.0).collect(),
    };
    let plan = Plan::new(args.scene.as_deref(), &request)?;
    let layout = TableLayout::of_plan(&plan);
    let groups = match args.shard {
        Some(shard) => shard.groups(plan.groups.len()),
        None => 0..plan.groups.len(),
    };
    let provenance = plan.provenance(&machine, groups.clone());
    let mut rows = measure_groups(
        &plan,
        groups,
        &machine,
        args.repeat,
        args.threads,
        &mut |step| {
            if failed.is_some() {
                return;
            }
            let result = match step {
                Step::Start { total, skipped } => {
                    bar = Some(Progress::steps(total as u64, progress, "measuring"));
                    skipped
                        .iter()
                        .try_for_each(|(name, why)| writeln!(stdout, "skipped {name}: {why}"))
                        .and_then(|()| write_table_header(stdout, layout))
                }
                Step::Measuring { setting, .. } => {
                    // several settings may be under way: the bar counts rows printed
                    if let Some(bar) = &bar {
                        bar.message(setting);
                    }
                    Ok(())
                }
                Step::Measured { index, row, .. } => {
                    let mut write =
                        || write_table_row(stdout, row, layout).and_then(|()| stdout.flush());
                    match &mut bar {
                        Some(bar) => {
                            bar.update(index as u64 + 1);
                            // above the bar, not through it
                            bar.suspend(write)
                        }
                        None => write(),
                    }
                }
            };
            if let Err(e) = result {
                failed = Some(e);
            }
        },
    )?;
    drop(bar);
    if let Some(e) = failed {
        return Err(CliError::Stdout(e));
    }
    let name = Source::resolve(args.scene.as_deref())?.name();
    match args.shard {
        None => mark_pareto(&mut rows),
        Some(shard) => writeln!(
            stdout,
            "\npart {} of {} ({} of the grid's {} settings); the Pareto front is marked when the parts are joined: cwisim tradeoff --merge",
            shard.index,
            shard.count,
            rows.len(),
            plan.settings.len()
        )
        .map_err(CliError::Stdout)?,
    }
    let text = csv(&rows, &provenance);
    finish(args, stdout, &rows, text, &name, args.shard.is_none())
}

/// The memory `tradeoff --merge` holds per byte of its parts (their text, the rows, the
/// merged CSV): 5.7 measured on a part of 250,000 rows (57 MB, 326 MB peak), with room
/// for parts of shorter lines (docs/LIMITS.md).
const MERGE_BYTES_PER_BYTE: u64 = 8;

/// Runs `cwisim tradeoff --merge`.
fn merge(args: &TradeoffArgs, stdout: &mut dyn Write) -> Result<(), CliError> {
    // the parts' sizes against the memory budget before any is read: the merge holds
    // their text, a row per line and the merged CSV, about MERGE_BYTES_PER_BYTE times
    // their size (measured: docs/LIMITS.md)
    let mut size = 0u64;
    for path in &args.merge {
        let meta = std::fs::metadata(path)
            .map_err(|e| CliError::Usage(format!("{}: cannot be read: {e}", path.display())))?;
        if !meta.is_file() {
            return Err(CliError::Usage(format!(
                "{}: not a regular file (a part's CSV is expected)",
                path.display()
            )));
        }
        size = size.saturating_add(meta.len());
    }
    cwisim_scene::budget::Budget::current().check_memory(
        &format!(
            "merging {} part(s) of {size} bytes (about {MERGE_BYTES_PER_BYTE} bytes held per byte read)",
            args.merge.len()
        ),
        size.saturating_mul(MERGE_BYTES_PER_BYTE),
    )?;
    let mut parts = Vec::with_capacity(args.merge.len());
    for path in &args.merge {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError::Usage(format!("{}: cannot be read: {e}", path.display())))?;
        parts.push((path.display().to_string(), text));
    }
    let (text, rows) = merge_csv(&parts)?;
    let layout = TableLayout::of_rows(&rows);
    write_table_header(stdout, layout).map_err(CliError::Stdout)?;
    for row in &rows {
        write_table_row(stdout, row, layout).map_err(CliError::Stdout)?;
    }
    writeln!(
        stdout,
        "\n{} parts joined: {} settings",
        parts.len(),
        rows.len()
    )
    .map_err(CliError::Stdout)?;
    let name = args.merge[0]
        .file_stem()
        .map_or_else(|| "merged".into(), |s| s.to_string_lossy().into_owned());
    finish(args, stdout, &rows, text, &name, true)
}

/// The Pareto front printed (`front`), and the CSV (`text`) and the plot written.
fn finish(
    args: &TradeoffArgs,
    stdout: &mut dyn Write,
    rows: &[cwisim_study::tradeoff::Row],
    text: String,
    name: &str,
    front: bool,
) -> Result<(), CliError> {
    if front {
        print_front(stdout, rows, TableLayout::of_rows(rows))?;
    }
    let mut written = Vec::new();
    if let Some(path) = &args.csv {
        write_atomic(path, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| CliError::write(path, e))
        })?;
        written.push(path.display().to_string());
    }
    if let Some(path) = &args.plot {
        let img = render_tradeoff_plot(rows, name).map_err(CliError::Usage)?;
        write_rgb_png(path, &img)?;
        written.push(path.display().to_string());
    }
    if !written.is_empty() {
        writeln!(stdout, "wrote {}", written.join(", ")).map_err(CliError::Stdout)?;
    }
    stdout.flush().map_err(CliError::Stdout)
}

/// The Pareto front of `rows`, as a table.
fn print_front(
    stdout: &mut dyn Write,
    rows: &[cwisim_study::tradeoff::Row],
    layout: TableLayout,
) -> Result<(), CliError> {
    let front: Vec<_> = rows.iter().filter(|r| r.pareto).collect();
    writeln!(
        stdout,
        "\nPareto front (no other setting has fewer busy cycles, register bits and RMS error \
all at once): {} of {} settings",
        front.len(),
        rows.len()
    )
    .map_err(CliError::Stdout)?;
    write_table_header(stdout, layout).map_err(CliError::Stdout)?;
    for row in front {
        write_table_row(stdout, row, layout).map_err(CliError::Stdout)?;
    }
    Ok(())
}
