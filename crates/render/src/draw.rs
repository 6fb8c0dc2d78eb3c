//! A scene drawn by a renderer, as every face of cwisim asks for it (the command line's
//! `render`, `emit`, `stats`, `fit`; the Python package's `render`): the renderer by
//! name, the settings given by name checked against what it reads, the scene read (a
//! file, an embedded name, or JSON text) and sized, and the renderer built. One place,
//! so that the faces refuse and accept the same things with the same messages.

use crate::error::RenderError;
use crate::registry;
use crate::renderer::Renderer;
use crate::settings::{Setting, Settings};
use crate::source::{LoadedScene, Source, DEFAULT_SCENE};
use std::path::Path;
use std::time::{Duration, Instant};

/// Where the scene comes from.
#[derive(Clone, Copy, Debug)]
pub enum SceneInput<'a> {
    /// A file if it names one, else an embedded scene's name ([`Source::resolve`]);
    /// `None`: the default scene.
    Named(Option<&'a Path>),
    /// A scene as JSON text (a world or screen scene file's contents), called `name` in
    /// messages and summaries.
    Text {
        /// Its name.
        name: &'a str,
        /// The JSON.
        text: &'a str,
    },
}

/// A renderer built for a scene, with where the scene came from.
pub struct Drawn {
    /// Where the scene came from.
    pub source: Source,
    /// `"screen"` or `"world"`.
    pub kind: &'static str,
    /// Wall time of reading it.
    pub load_time: Duration,
    /// The renderer, built for it.
    pub renderer: Box<dyn Renderer>,
}

/// Draws `scene` with the renderer called `renderer` under `settings`, of which those in
/// `given` were asked for explicitly: a setting the renderer does not read, or that the
/// others leave idle, or that the scene has nothing for, is refused naming what would
/// use it ([`registry::Entry::check_given`], [`registry::Entry::check_scene`]).
pub fn draw(
    renderer: &str,
    scene: SceneInput<'_>,
    given: &[Setting],
    settings: &Settings,
) -> Result<Drawn, RenderError> {
    let entry = registry::find(renderer)?;
    entry
        .check_given(given, settings)
        .map_err(RenderError::Usage)?;
    settings.check().map_err(RenderError::Usage)?;
    let scene_text = |source: &Source| -> Option<String> {
        match (scene, source) {
            (SceneInput::Text { text, .. }, _) => Some((*text).to_string()),
            (_, Source::File(p)) => cwisim_scene::read_scene_text(p).ok(),
            (_, Source::Embedded(name)) => {
                cwisim_world::embedded::embedded(name).map(|e| e.text.to_string())
            }
            (_, Source::Built(_)) => None,
        }
    };
    let (loaded, name) = match scene {
        SceneInput::Named(path) => (
            Source::resolve(path)?.load_for(settings)?,
            path.map_or_else(|| DEFAULT_SCENE.to_string(), |p| p.display().to_string()),
        ),
        SceneInput::Text { name, text } => {
            let start = Instant::now();
            let parsed = cwisim_world::parse_any(text, None)?;
            let mut loaded = LoadedScene::built(name, parsed).drawn_as(settings)?;
            loaded.load_time += start.elapsed();
            (loaded, name.to_string())
        }
    };
    entry
        .check_scene(given, &loaded.scene, &name, settings)
        .map_err(RenderError::Usage)?;
    let source = loaded.source.clone();
    build(entry, loaded, settings).map_err(|e| match e {
        // a refusal of a field found while building (a light that cannot cast shadows):
        // located in the scene's text, as a reading error is
        RenderError::Scene(se) if se.line.is_none() && se.field.is_some() => {
            let Some(text) = scene_text(&source) else {
                return RenderError::Scene(se);
            };
            let located = cwisim_scene::locate_error(&text, se);
            RenderError::Scene(match source.path() {
                Some(p) if located.path.is_none() => located.in_file(p),
                _ => located,
            })
        }
        e => e,
    })
}

/// Builds `entry`'s renderer for a loaded scene.
pub fn build(
    entry: &registry::Entry,
    loaded: LoadedScene,
    settings: &Settings,
) -> Result<Drawn, RenderError> {
    let (source, kind, load_time) = (loaded.source.clone(), loaded.scene.kind(), loaded.load_time);
    Ok(Drawn {
        source,
        kind,
        load_time,
        renderer: (entry.build)(loaded, settings)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_named_scene_and_its_text_draw_the_same_stream() {
        let text = cwisim_world::embedded::embedded("fig25").unwrap().text;
        let settings = Settings::default();
        let named = draw(
            "vanrij",
            SceneInput::Named(Some(Path::new("fig25"))),
            &[],
            &settings,
        )
        .unwrap();
        let inline = draw(
            "vanrij",
            SceneInput::Text {
                name: "fig25",
                text,
            },
            &[],
            &settings,
        )
        .unwrap();
        let stream = |d: &Drawn| {
            let mut out: Vec<cwisim_isa::Instruction> = Vec::new();
            crate::emit(&*d.renderer, &mut out).unwrap();
            out
        };
        assert_eq!(stream(&named), stream(&inline));
        assert_eq!(inline.source, Source::Built("fig25".into()));
    }

    #[test]
    fn refusals_name_what_is_wrong() {
        let settings = Settings::default();
        let bad = draw(
            "vanrij",
            SceneInput::Text {
                name: "mine",
                text: "{\"kind\": \"world\"",
            },
            &[],
            &settings,
        );
        assert!(bad.is_err());
        let unknown = draw("nope", SceneInput::Named(None), &[], &settings);
        assert!(unknown
            .err()
            .unwrap()
            .to_string()
            .starts_with("unknown renderer `nope`"));
        let unused = draw(
            "vanrij",
            SceneInput::Named(None),
            &[Setting::Samples],
            &settings,
        );
        assert!(unused
            .err()
            .unwrap()
            .to_string()
            .starts_with("--samples is not used by vanrij"));
    }
}
