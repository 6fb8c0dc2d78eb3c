//! `cwisim scenes`: the embedded scenes, listed, or one printed as its JSON file; and
//! `cwisim scenes generate cp-bench …`, a generated benchmark scene (the logic is
//! `cwisim_render::cpbench`).

use crate::error::CliError;
use clap::{Args, Subcommand, ValueEnum};
use cwisim_render::cpbench::{self, BenchSpec, Family};
use cwisim_render::Size;
use cwisim_world::embedded::{embedded, EMBEDDED};
use std::io::Write;
use std::ops::RangeInclusive;
use std::path::PathBuf;

/// The arguments of `cwisim scenes`.
#[derive(Args, Clone, Debug, PartialEq, Eq)]
#[command(args_conflicts_with_subcommands = true)]
pub struct ScenesArgs {
    /// Print this embedded scene's JSON file (to copy and edit) instead of the list.
    #[arg(value_name = "NAME")]
    pub name: Option<String>,
    /// Generate a scene instead.
    #[command(subcommand)]
    pub command: Option<ScenesCommand>,
}

/// `cwisim scenes generate`.
#[derive(Subcommand, Clone, Debug, PartialEq, Eq)]
pub enum ScenesCommand {
    /// Generate a scene as JSON (to stdout, or to -o FILE)
    Generate(GenerateArgs),
}

/// What `generate` makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Generated {
    /// Barkan & Gordon's benchmark (Tables 3–5): many polygons of many vertices, by
    /// their number of critical points.
    CpBench,
}

/// `--family`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FamilyArg {
    /// Convex polygons (vertices on ellipses): one critical point each.
    Convex,
    /// Smooth star-like contours with 1–5 critical points.
    Few,
    /// Zig-zag bands with about n/2 critical points (CP's worst case).
    Many,
}

/// The arguments of `cwisim scenes generate`.
#[derive(Args, Clone, Debug, PartialEq, Eq)]
pub struct GenerateArgs {
    /// What to generate.
    #[arg(value_enum)]
    pub what: Generated,
    /// The family of polygons.
    #[arg(long, value_enum)]
    pub family: FamilyArg,
    /// How many polygons.
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub polygons: u32,
    /// Vertices per polygon: N, or a range A..B (B not included) or A..=B (each polygon's
    /// count drawn from it).
    #[arg(long, value_name = "A..B", value_parser = cpbench::parse_vertices, default_value = "100")]
    pub vertices: RangeInclusive<u32>,
    /// The seed: the same seed gives the same scene.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub seed: u64,
    /// Image size.
    #[arg(long, value_name = "WxH", default_value = "512x512")]
    pub size: Size,
    /// Write the scene here instead of to stdout.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// Runs `cwisim scenes`.
pub fn run(
    args: &ScenesArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    if let Some(ScenesCommand::Generate(g)) = &args.command {
        return generate(g, stdout, stderr);
    }
    match &args.name {
        None => {
            let width = EMBEDDED.iter().map(|e| e.name.len()).max().unwrap_or(0);
            for e in EMBEDDED {
                writeln!(stdout, "{:<width$}  {}", e.name, e.about).map_err(CliError::Stdout)?;
            }
        }
        Some(name) => {
            let Some(e) = embedded(name) else {
                let names: Vec<&str> = EMBEDDED.iter().map(|e| e.name).collect();
                return Err(CliError::Usage(format!(
                    "no embedded scene `{name}`; the embedded scenes are {}",
                    names.join(", ")
                )));
            };
            stdout
                .write_all(e.text.as_bytes())
                .map_err(CliError::Stdout)?;
        }
    }
    stdout.flush().map_err(CliError::Stdout)
}

fn generate(
    g: &GenerateArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    let Generated::CpBench = g.what;
    let spec = BenchSpec {
        family: match g.family {
            FamilyArg::Convex => Family::Convex,
            FamilyArg::Few => Family::Few,
            FamilyArg::Many => Family::Many,
        },
        polygons: g.polygons,
        vertices: g.vertices.clone(),
        seed: g.seed,
        width: g.size.width,
        height: g.size.height,
    };
    let (scene, counts) = cpbench::generate(&spec).map_err(CliError::Usage)?;
    let text = serde_json::to_string(&cwisim_scene::Scene::Screen(scene))
        .map_err(|e| CliError::Internal(format!("a generated scene did not serialise: {e}")))?;
    match &g.output {
        Some(path) => crate::files::write_atomic(path, |w| {
            w.write_all(text.as_bytes())
                .and_then(|()| w.write_all(b"\n"))
                .map_err(|e| CliError::write(path, e))
        })?,
        None => {
            stdout
                .write_all(text.as_bytes())
                .map_err(CliError::Stdout)?;
            stdout.write_all(b"\n").map_err(CliError::Stdout)?;
            stdout.flush().map_err(CliError::Stdout)?;
        }
    }
    // what DETCR found, for the record (stderr: stdout may be the scene)
    let _ = writeln!(stderr, "cp-bench {}: {counts}", spec.family);
    Ok(())
}
