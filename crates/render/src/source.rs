//! Which scene: a file or an embedded name, read and sized, ready for any renderer.

use crate::error::RenderError;
use crate::settings::Size;
use cwisim_world::embedded::{embedded, EMBEDDED};
use cwisim_world::AnyScene;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The embedded scene drawn when none is named.
pub const DEFAULT_SCENE: &str = "pot";

/// Where a scene came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// A scene file.
    File(PathBuf),
    /// An embedded scene, by name.
    Embedded(&'static str),
    /// A scene built in code (a test, a benchmark, a library user), by a name of its own.
    Built(String),
}

impl Source {
    /// A file if `arg` names one; otherwise the embedded scene of that name; none: the
    /// default scene. A trace file (`.cwt`, `.jsonl`, `.cwb`) is refused, saying so: it
    /// is not a scene, whatever JSON parser error reading it as one would give.
    pub fn resolve(arg: Option<&Path>) -> Result<Source, RenderError> {
        let Some(arg) = arg else {
            return Ok(Source::Embedded(DEFAULT_SCENE));
        };
        if cwisim_isa::Encoding::from_path(arg).is_ok() {
            return Err(RenderError::Usage(format!(
                "{}: a trace, not a scene: this command draws a scene (a .json scene file or an embedded scene's name; `cwisim scenes` lists them); `cwisim run {}` replays a trace",
                arg.display(),
                arg.display()
            )));
        }
        if arg.exists() {
            return Ok(Source::File(arg.to_path_buf()));
        }
        if let Some(e) = arg.to_str().and_then(embedded) {
            return Ok(Source::Embedded(e.name));
        }
        let names: Vec<&str> = EMBEDDED.iter().map(|e| e.name).collect();
        Err(RenderError::Usage(format!(
            "{}: no such scene file, and no embedded scene of that name (embedded: {}; `cwisim scenes` describes them)",
            arg.display(),
            names.join(", ")
        )))
    }

    /// A short name: the embedded name, or the file's stem.
    pub fn name(&self) -> String {
        match self {
            Source::Embedded(n) => (*n).to_string(),
            Source::Built(n) => n.clone(),
            Source::File(p) => p
                .file_stem()
                .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned()),
        }
    }

    /// The file, if the scene is one.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Source::File(p) => Some(p),
            Source::Embedded(_) | Source::Built(_) => None,
        }
    }

    /// Reads the scene (any kind) as `settings` draw it: at its `size`, its Bézier meshes
    /// at its `tessellate`, when given.
    pub fn load_for(&self, settings: &crate::Settings) -> Result<LoadedScene, RenderError> {
        self.load(settings.size)?.drawn_as(settings)
    }

    /// Reads the scene (any kind), at `size` when given. A [`Source::Built`] scene has
    /// nothing to read: build its [`LoadedScene`] with [`LoadedScene::built`].
    pub fn load(&self, size: Option<Size>) -> Result<LoadedScene, RenderError> {
        let start = Instant::now();
        let scene = match self {
            Source::File(p) => cwisim_world::load_any(p)?,
            Source::Embedded(name) => {
                let e = embedded(name)
                    .ok_or_else(|| RenderError::Usage(format!("no embedded scene `{name}`")))?;
                cwisim_world::parse_any(e.text, None)?
            }
            Source::Built(name) => {
                return Err(RenderError::Usage(format!(
                    "the scene `{name}` was built in code: there is no file to read"
                )))
            }
        };
        let scene = match size {
            Some(s) => scene
                .with_size(s.width, s.height)
                .map_err(|e| RenderError::Usage(format!("--size {s}: {e}")))?,
            None => scene,
        };
        Ok(LoadedScene {
            source: self.clone(),
            scene,
            load_time: start.elapsed(),
        })
    }
}

/// A scene read from its source, for a renderer to build on.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// Where it came from.
    pub source: Source,
    /// The scene.
    pub scene: AnyScene,
    /// Wall time of reading it (and building its meshes).
    pub load_time: Duration,
}

impl LoadedScene {
    /// A scene built in code, named `name`.
    pub fn built(name: &str, scene: AnyScene) -> LoadedScene {
        LoadedScene {
            source: Source::Built(name.to_string()),
            scene,
            load_time: Duration::ZERO,
        }
    }

    /// The scene as `settings` draw it: at their `size` and its Bézier meshes at their
    /// `tessellate`, when given and not so already. Every registered renderer starts with
    /// it, so a scene built in code ([`LoadedScene::built`]) is drawn as one read from a
    /// file with the same settings.
    pub fn drawn_as(mut self, settings: &crate::Settings) -> Result<LoadedScene, RenderError> {
        let start = Instant::now();
        if let Some(s) = settings.size {
            if self.scene.size() != (s.width, s.height) {
                self.scene = self
                    .scene
                    .with_size(s.width, s.height)
                    .map_err(|e| RenderError::Usage(format!("--size {s}: {e}")))?;
            }
        }
        if let Some(n) = settings.tessellate {
            if !self.scene.is_tessellated_at(n) {
                self.scene = self
                    .scene
                    .with_tessellation(n)
                    .map_err(|e| RenderError::Usage(format!("--tessellate {n}: {e}")))?;
            }
        }
        self.load_time += start.elapsed();
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
