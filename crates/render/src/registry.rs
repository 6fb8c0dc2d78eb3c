//! The renderers cwisim knows, by name. Adding one is its module plus one line in
//! [`REGISTRY`].

use crate::error::RenderError;
use crate::renderer::Renderer;
use crate::settings::Settings;
use crate::source::LoadedScene;

/// How a renderer is built: from a scene read from its source, under settings.
pub type Build = fn(LoadedScene, &Settings) -> Result<Box<dyn Renderer>, RenderError>;

/// A registered renderer: its name, one line about it, and how to build it.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// `--renderer NAME`.
    pub name: &'static str,
    /// One line for `cwisim renderers`.
    pub about: &'static str,
    /// Makes the renderer of a scene under settings.
    pub build: Build,
    /// It samples each pixel on an `l × l` grid (`Settings::samples`, `grid`, …) and
    /// resolves visibility itself: `Settings::aa` and `visibility` do not apply to it.
    pub supersampled: bool,
    /// It draws a world scene's Bézier patches directly (`--tessellate` does not apply
    /// to them): `tradeoff`'s axis for it is the root tolerance.
    pub patches: bool,
    /// It draws several frames, each refining the previous one's output (`refine`):
    /// `tradeoff`, which measures one frame against the exact image, leaves it out.
    pub progressive: bool,
}

/// The renderer used when none is named.
pub const DEFAULT_RENDERER: &str = "vanrij";

/// Every renderer, the default first.
pub const REGISTRY: &[Entry] = &[
    Entry {
        name: "vanrij",
        about: crate::vanrij::ABOUT,
        build: crate::vanrij::VanRij::build,
        supersampled: false,
        patches: false,
        progressive: false,
    },
    Entry {
        name: "woo-chall",
        about: crate::woochall::ABOUT,
        build: crate::woochall::WooChall::build,
        supersampled: true,
        patches: false,
        progressive: false,
    },
    Entry {
        name: "sbuffer",
        about: crate::sbuffer::ABOUT,
        build: crate::sbuffer::SBuffer::build,
        supersampled: true,
        patches: false,
        progressive: false,
    },
    Entry {
        name: "bsp",
        about: crate::bsp::ABOUT,
        build: crate::bsp::Bsp::build,
        supersampled: true,
        patches: false,
        progressive: false,
    },
    Entry {
        name: "nishita",
        about: crate::nishita::ABOUT,
        build: crate::nishita::Nishita::build,
        supersampled: false,
        patches: true,
        progressive: false,
    },
    Entry {
        name: "refine",
        about: crate::refine::ABOUT,
        build: crate::refine::Refine::build,
        supersampled: false,
        patches: false,
        progressive: true,
    },
];

/// The registered names, in order.
pub fn names() -> Vec<&'static str> {
    REGISTRY.iter().map(|e| e.name).collect()
}

/// The renderer registered as `name`; an unknown name is an error listing the known ones.
pub fn find(name: &str) -> Result<&'static Entry, RenderError> {
    REGISTRY
        .iter()
        .find(|e| e.name == name)
        .ok_or_else(|| RenderError::UnknownRenderer {
            name: name.to_string(),
            known: names(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found() {
        let mut names = names();
        assert_eq!(names[0], DEFAULT_RENDERER);
        for n in &names {
            assert_eq!(find(n).unwrap().name, *n);
        }
        names.sort();
        names.dedup();
        assert_eq!(names.len(), REGISTRY.len());
        // every entry builds a renderer that answers to the entry's name
        let source = crate::Source::resolve(Some("fig25".as_ref())).unwrap();
        for entry in REGISTRY {
            let settings = crate::Settings::default();
            let renderer = (entry.build)(source.load(None).unwrap(), &settings).unwrap();
            assert_eq!(renderer.name(), entry.name);
        }
        let e = find("nishita-typo").unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "unknown renderer `nishita-typo`; known: {}",
                super::names().join(", ")
            )
        );
    }
}
