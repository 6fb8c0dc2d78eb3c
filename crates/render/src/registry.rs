//! The renderers cwisim knows, by name. Adding one is its module plus one line in
//! [`REGISTRY`].

use crate::error::RenderError;
use crate::renderer::Renderer;
use crate::settings::{Setting, Settings};
use crate::source::LoadedScene;
use cwisim_world::AnyScene;

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
    /// Under the box filter it sends every row through the span fitter whatever the
    /// shading (`nishita`: a patch's row as one span), so `--shade-tolerance` applies to
    /// Gouraud and flat shading too, not to Phong alone.
    pub fits_rows: bool,
    /// It draws textured meshes (a renderer that does not refuses a textured scene,
    /// naming those that do).
    pub textures: bool,
    /// The settings it reads (its module reads them in `build`); the command line
    /// refuses a flag given for any other.
    pub uses: &'static [Setting],
    /// How it draws, in a few words, for the refusal of a flag it does not use: "it draws
    /// trapezia with the box filter or point sampling".
    pub draws: &'static str,
}

impl Entry {
    /// Refuses settings given on the command line (`given`) that it would not use under
    /// `settings`: one it does not read, naming the renderers that do; or one the other
    /// settings leave nothing to do ([`Setting::idle_under`], when it reads the setting
    /// that decides).
    pub fn check_given(&self, given: &[Setting], settings: &Settings) -> Result<(), String> {
        for &s in given {
            if !self.uses.contains(&s) {
                let users: Vec<&str> = REGISTRY
                    .iter()
                    .filter(|e| e.uses.contains(&s))
                    .map(|e| e.name)
                    .collect();
                return Err(format!(
                    "{flag} is not used by {} ({}; {flag} is for {})",
                    self.name,
                    self.draws,
                    users.join(", "),
                    flag = s.flag()
                ));
            }
            // the span fitter's tolerance may serve a textured scene: decided with the scene
            if s == Setting::ShadeTolerance {
                continue;
            }
            match s.idle_under(settings) {
                Some((by, why)) if self.uses.contains(&by) => return Err(why),
                _ => {}
            }
        }
        Ok(())
    }

    /// Refuses what the scene (called `name`) leaves nothing to do, or what this
    /// renderer cannot draw of it: a renderer of Bézier patches on a scene without any
    /// (it would draw exactly as the default renderer); a textured scene for a renderer
    /// that draws no textures; a setting given for world scenes ([`Setting::world_only`])
    /// on a screen scene; a tessellation given for a scene without Bézier meshes; a
    /// texture filter for a scene without textures; a span tolerance that `settings`
    /// and the scene leave idle.
    pub fn check_scene(
        &self,
        given: &[Setting],
        scene: &AnyScene,
        name: &str,
        settings: &Settings,
    ) -> Result<(), String> {
        let textured = scene.is_textured();
        if textured && !self.textures {
            let users: Vec<&str> = REGISTRY
                .iter()
                .filter(|e| e.textures)
                .map(|e| e.name)
                .collect();
            return Err(format!(
                "{} does not draw textures yet, and {name} has textured meshes: use --renderer {}",
                self.name,
                users.join(" or --renderer ")
            ));
        }
        if given.contains(&Setting::ShadeTolerance) && self.uses.contains(&Setting::Shading) {
            let fitted = (self.fits_rows && settings.aa.is_box()) || textured;
            match Setting::ShadeTolerance.idle_under(settings) {
                Some((_, why)) if !fitted => return Err(format!("{why}; {name} has no texture")),
                _ => {}
            }
        }
        if self.patches && !scene.has_patches() {
            return Err(format!(
                "--renderer {} draws Bézier patches, and {name} has none: it would draw exactly as {DEFAULT_RENDERER}; use --renderer {DEFAULT_RENDERER}",
                self.name
            ));
        }
        for &s in given {
            if s.world_only() && matches!(scene, AnyScene::Screen(_)) {
                return Err(format!(
                    "{} applies to world scenes; {name} is a screen scene, its polygons drawn as they are",
                    s.flag()
                ));
            }
            if s == Setting::Tessellate && !scene.has_patches() {
                return Err(format!(
                    "--tessellate applies to Bézier meshes; {name} has none"
                ));
            }
            if s == Setting::TextureFilter && !textured && !matches!(scene, AnyScene::Screen(_)) {
                return Err(format!(
                    "--texture-filter applies to textured meshes; {name} has none (a material's \"texture\" gives one)"
                ));
            }
        }
        Ok(())
    }
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
        fits_rows: false,
        textures: true,
        uses: &[
            Setting::Shading,
            Setting::Aa,
            Setting::Visibility,
            Setting::Eval0Tolerance,
            Setting::Size,
            Setting::ShadeTolerance,
            Setting::Tessellate,
            Setting::Shadows,
            Setting::TextureFilter,
        ],
        draws: "it draws trapezia with the box filter or point sampling",
    },
    Entry {
        name: "woo-chall",
        about: crate::woochall::ABOUT,
        build: crate::woochall::WooChall::build,
        supersampled: true,
        patches: false,
        progressive: false,
        fits_rows: false,
        textures: true,
        uses: &[
            Setting::Shading,
            Setting::Size,
            Setting::ShadeTolerance,
            Setting::Tessellate,
            Setting::Samples,
            Setting::Grid,
            Setting::MergeSubscanlines,
            Setting::ShadeP,
            Setting::ShadeContrast,
            Setting::Seed,
            Setting::Shadows,
        ],
        draws: "it point-samples each pixel on an l×l grid and resolves visibility per sample",
    },
    Entry {
        name: "sbuffer",
        about: crate::sbuffer::ABOUT,
        build: crate::sbuffer::SBuffer::build,
        supersampled: true,
        patches: false,
        progressive: false,
        fits_rows: false,
        textures: true,
        uses: &[
            Setting::Shading,
            Setting::Size,
            Setting::ShadeTolerance,
            Setting::Tessellate,
            Setting::Samples,
            Setting::Grid,
            Setting::MergeSubscanlines,
            Setting::CpIncrement,
            Setting::Sbuffer,
            Setting::Shadows,
        ],
        draws: "it samples each pixel on an l×l grid into a host depth line",
    },
    Entry {
        name: "bsp",
        about: crate::bsp::ABOUT,
        build: crate::bsp::Bsp::build,
        supersampled: true,
        patches: false,
        progressive: false,
        fits_rows: false,
        textures: true,
        uses: &[
            Setting::Shading,
            Setting::Size,
            Setting::ShadeTolerance,
            Setting::Tessellate,
            Setting::Samples,
            Setting::Grid,
            Setting::MergeSubscanlines,
            Setting::CpIncrement,
            Setting::Order,
            Setting::Unset,
            Setting::Shadows,
        ],
        draws: "it samples each pixel on an l×l grid in the BSP tree's order",
    },
    Entry {
        name: "nishita",
        about: crate::nishita::ABOUT,
        build: crate::nishita::Nishita::build,
        supersampled: false,
        patches: true,
        progressive: false,
        fits_rows: true,
        textures: true,
        uses: &[
            Setting::Shading,
            Setting::Aa,
            Setting::Size,
            Setting::ShadeTolerance,
            Setting::RootTolerance,
            Setting::Flatness,
            Setting::NormalAngle,
            Setting::Band,
            Setting::Subscan,
            Setting::Shadows,
            Setting::TextureFilter,
        ],
        draws: "it cuts Bézier patches into pieces at most a row high, which no Eval0 claim could cover, and box-filters the exact visible ones as vanrij does",
    },
    Entry {
        name: "refine",
        about: crate::refine::ABOUT,
        build: crate::refine::Refine::build,
        supersampled: false,
        patches: false,
        progressive: true,
        fits_rows: false,
        textures: true,
        uses: &[
            Setting::Size,
            Setting::ShadeTolerance,
            Setting::Tessellate,
            Setting::GouraudThreshold,
            Setting::AaThreshold,
            Setting::PhongAngle,
            Setting::Shadows,
        ],
        draws: "its phases choose the shading, the filter and the visibility themselves",
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

    #[test]
    fn every_setting_is_read_by_some_renderer_and_refused_by_the_others() {
        for s in Setting::ALL {
            assert!(REGISTRY.iter().any(|e| e.uses.contains(&s)), "{s:?}");
        }
        let vanrij = find("vanrij").unwrap();
        let settings = Settings::default();
        assert_eq!(
            vanrij.check_given(&[Setting::Shading, Setting::Samples], &settings),
            Err("--samples is not used by vanrij (it draws trapezia with the box filter or point sampling; --samples is for woo-chall, sbuffer, bsp)".into())
        );
        let scene = |name: &str| {
            crate::Source::resolve(Some(name.as_ref()))
                .unwrap()
                .load(None)
                .unwrap()
                .scene
        };
        let (pot, teapot) = (scene("pot"), scene("teapot"));
        // idle only where the renderer reads the setting that decides
        let gouraud = [Setting::ShadeTolerance];
        assert_eq!(vanrij.check_given(&gouraud, &settings), Ok(()));
        assert!(vanrij
            .check_scene(&gouraud, &pot, "pot", &settings)
            .unwrap_err()
            .contains("pot has no texture"));
        assert_eq!(
            find("refine")
                .unwrap()
                .check_scene(&gouraud, &pot, "pot", &settings),
            Ok(())
        );
        // nishita fits a patch's row as one span under the box filter, whatever the shading
        let nishita = find("nishita").unwrap();
        assert_eq!(
            nishita.check_scene(&gouraud, &teapot, "teapot", &settings),
            Ok(())
        );
        let point = Settings {
            aa: cwisim_scene::Antialias::None,
            ..Settings::default()
        };
        assert!(nishita
            .check_scene(&gouraud, &teapot, "teapot", &point)
            .is_err());
        assert_eq!(vanrij.check_scene(&[], &pot, "pot", &settings), Ok(()));
        assert!(find("nishita")
            .unwrap()
            .check_scene(&[], &pot, "pot", &settings)
            .unwrap_err()
            .contains("it would draw exactly as vanrij"));
        assert!(vanrij
            .check_scene(&[Setting::Tessellate], &pot, "pot", &settings)
            .is_err());
    }
}
