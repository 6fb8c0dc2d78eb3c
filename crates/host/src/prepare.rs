//! From the SCENE argument to the polygons the Y-processor takes: which scene (a file or
//! an embedded name), at which size, and — for a world scene — transform, lighting and
//! visible surfaces. Shared by `render`, `emit` and `stats`.

use crate::error::CliError;
use clap::{Args, ValueEnum};
use cwisim_scene::ScreenScene;
use cwisim_world::embedded::{embedded, EMBEDDED};
use cwisim_world::{AnyScene, ProjectStats, Visibility, VisibilityStats};
use cwisim_ypipe::{Antialias, Claim, Options, Shading};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::{Duration, Instant};

/// The embedded scene `render` draws when given none.
pub const DEFAULT_SCENE: &str = "pot";

/// `--shading`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ShadingArg {
    /// One intensity per polygon (world scenes: lit once per face): Eval1 spans.
    Flat,
    /// Interpolated along the edges and across each scanline (world scenes: lit at every
    /// vertex): Eval2 spans.
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

/// `--visibility`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum VisibilityArg {
    /// Object space: every triangle minus what hides it (polygon booleans), then exact
    /// coverage of the visible fragments.
    #[default]
    Exact,
    /// The array's own way: whole triangles front to back, each claiming the pixels it
    /// fully covers with Eval0; edge pixels are approximate.
    Eval0,
}

/// `--size WxH`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
}

impl FromStr for Size {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || format!("expected WIDTHxHEIGHT in pixels, such as 640x480; found `{s}`");
        let (w, h) = s.split_once(['x', 'X', '×']).ok_or_else(bad)?;
        let (width, height) = (
            w.trim().parse::<u32>().map_err(|_| bad())?,
            h.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if width == 0 || height == 0 {
            return Err(format!("an image needs at least 1x1 pixels; found `{s}`"));
        }
        Ok(Size { width, height })
    }
}

/// How a scene is drawn: shared by `render`, `emit` and `stats`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct DrawArgs {
    /// Shading.
    #[arg(long, value_enum, default_value_t = ShadingArg::Gouraud)]
    pub shading: ShadingArg,
    /// Anti-aliasing.
    #[arg(long, value_enum, default_value_t = AaArg::Box)]
    pub aa: AaArg,
    /// Hidden-surface removal for world scenes (screen scenes are drawn as they are:
    /// their polygons add up).
    #[arg(long, value_enum, default_value_t = VisibilityArg::Exact)]
    pub visibility: VisibilityArg,
    /// With --visibility eval0 and Gouraud shading: how far (in intensity) the staircase
    /// of Eval0s that claims a shaded interior may stray from the Gouraud value at a pixel
    /// centre. Smaller is more exact and costs more Eval0s; 0 is one Eval0 per pixel.
    #[arg(long, value_name = "TOL", default_value_t = 1.0 / 512.0)]
    pub eval0_tolerance: f64,
    /// Draw at another size, WIDTHxHEIGHT (a world scene's camera keeps its vertical field
    /// of view; a screen scene is scaled).
    #[arg(long, value_name = "WxH")]
    pub size: Option<Size>,
}

impl Default for DrawArgs {
    fn default() -> Self {
        DrawArgs {
            shading: ShadingArg::Gouraud,
            aa: AaArg::Box,
            visibility: VisibilityArg::Exact,
            eval0_tolerance: 1.0 / 512.0,
            size: None,
        }
    }
}

impl DrawArgs {
    fn shading(&self) -> Shading {
        match self.shading {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Gouraud => Shading::Gouraud,
        }
    }

    fn visibility(&self) -> Visibility {
        match self.visibility {
            VisibilityArg::Exact => Visibility::Exact,
            VisibilityArg::Eval0 => Visibility::Eval0,
        }
    }

    fn check(&self) -> Result<(), CliError> {
        if !(self.eval0_tolerance >= 0.0 && self.eval0_tolerance.is_finite()) {
            return Err(CliError::Usage(format!(
                "--eval0-tolerance must be a finite number ≥ 0, found {}",
                self.eval0_tolerance
            )));
        }
        Ok(())
    }
}

/// Where a scene came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// A scene file.
    File(PathBuf),
    /// An embedded scene, by name.
    Embedded(&'static str),
}

impl Source {
    /// A file if `arg` names one; otherwise the embedded scene of that name; none: the
    /// default scene.
    pub fn resolve(arg: Option<&Path>) -> Result<Source, CliError> {
        let Some(arg) = arg else {
            return Ok(Source::Embedded(DEFAULT_SCENE));
        };
        if arg.exists() {
            return Ok(Source::File(arg.to_path_buf()));
        }
        if let Some(e) = arg.to_str().and_then(embedded) {
            return Ok(Source::Embedded(e.name));
        }
        let names: Vec<&str> = EMBEDDED.iter().map(|e| e.name).collect();
        Err(CliError::Usage(format!(
            "{}: no such scene file, and no embedded scene of that name (embedded: {}; `cwisim scenes` describes them)",
            arg.display(),
            names.join(", ")
        )))
    }

    /// A short name: the embedded name, or the file's stem.
    pub fn name(&self) -> String {
        match self {
            Source::Embedded(n) => (*n).to_string(),
            Source::File(p) => p
                .file_stem()
                .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned()),
        }
    }

    /// The file, if the scene is one.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Source::File(p) => Some(p),
            Source::Embedded(_) => None,
        }
    }
}

/// Wall time of the stages before scan conversion.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrepTimes {
    /// Reading the scene and building its meshes.
    pub load: Duration,
    /// Transform, lighting and culling (world scenes).
    pub transform: Duration,
    /// Hidden-surface removal (world scenes).
    pub visibility: Duration,
}

/// A scene ready for the Y-processor.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    /// Where it came from.
    pub source: Source,
    /// `"screen"` or `"world"`.
    pub kind: &'static str,
    /// The polygons, in the order they are sent.
    pub screen: ScreenScene,
    /// The Y-processor's options.
    pub options: Options,
    /// What projection did (world scenes).
    pub project: Option<ProjectStats>,
    /// What exact visibility did (world scenes, `--visibility exact`).
    pub visibility: Option<VisibilityStats>,
    /// The visibility used (world scenes).
    pub visibility_mode: Option<VisibilityArg>,
    /// Wall times.
    pub times: PrepTimes,
}

/// Reads the scene named by `arg` (a file, an embedded name, or none: the default) and
/// makes it ready for the Y-processor as `draw` says.
pub fn prepare(arg: Option<&Path>, draw: &DrawArgs) -> Result<PreparedScene, CliError> {
    draw.check()?;
    let source = Source::resolve(arg)?;
    let start = Instant::now();
    let scene = match &source {
        Source::File(p) => cwisim_world::load_any(p)?,
        Source::Embedded(name) => {
            let e = embedded(name).expect("resolved names exist");
            cwisim_world::parse_any(e.text, None)?
        }
    };
    let scene = match draw.size {
        Some(s) => scene
            .with_size(s.width, s.height)
            .map_err(|e| CliError::Usage(format!("--size {}x{}: {e}", s.width, s.height)))?,
        None => scene,
    };
    let load = start.elapsed();
    let mut options = Options {
        shading: draw.shading(),
        aa: match draw.aa {
            AaArg::None => Antialias::None,
            AaArg::Box => Antialias::Box,
        },
        ..Options::default()
    };
    let kind = scene.kind();
    let mut times = PrepTimes {
        load,
        ..PrepTimes::default()
    };
    let (screen, project, visibility, visibility_mode) = match scene {
        AnyScene::Screen(s) => (s, None, None, None),
        AnyScene::World(w) => {
            let start = Instant::now();
            let (tris, project) = cwisim_world::project::project(&w, draw.shading())?;
            times.transform = start.elapsed();
            let start = Instant::now();
            let (polygons, vis) = cwisim_world::resolve(&tris, w.channels(), draw.visibility());
            times.visibility = start.elapsed();
            if draw.visibility == VisibilityArg::Eval0 {
                options.claim = Claim::Eval0 {
                    tolerance: draw.eval0_tolerance,
                };
            }
            let screen = ScreenScene {
                width: w.width(),
                height: w.height(),
                channels: w.channels() as u8,
                polygons,
            };
            (screen, Some(project), vis, Some(draw.visibility))
        }
    };
    Ok(PreparedScene {
        source,
        kind,
        screen,
        options,
        project,
        visibility,
        visibility_mode,
        times,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_refuse() {
        assert_eq!(
            "640x480".parse::<Size>(),
            Ok(Size {
                width: 640,
                height: 480
            })
        );
        assert!("640".parse::<Size>().unwrap_err().contains("WIDTHxHEIGHT"));
        assert!("0x4".parse::<Size>().unwrap_err().contains("at least"));
        assert!("-3x4".parse::<Size>().is_err());
    }

    #[test]
    fn names_resolve_to_files_then_embedded_scenes() {
        assert_eq!(Source::resolve(None).unwrap(), Source::Embedded("pot"));
        assert_eq!(
            Source::resolve(Some(Path::new("fig25"))).unwrap(),
            Source::Embedded("fig25")
        );
        let e = Source::resolve(Some(Path::new("no-such-scene.json"))).unwrap_err();
        assert!(e.to_string().contains("embedded: pot, fig25"), "{e}");
    }
}
