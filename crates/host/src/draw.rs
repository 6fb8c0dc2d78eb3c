//! How a scene is drawn, as the command line says it: `--renderer`, `--shading`, `--aa`,
//! `--visibility`, `--eval0-tolerance`, `--size`, the supersampling renderers' `--samples`,
//! `--grid`, `--merge-subscanlines`, `--shade-p`, `--shade-contrast`, `--seed`, and Barkan &
//! Gordon's `--cp-increment`, `--sbuffer`, `--order`, `--unset`, and refinement's thresholds and `--phong-angle` — one flattened group shared by
//! `render`, `emit`, `fit` and the commands that read a trace or a scene, converted into
//! `cwisim-render`'s plain [`Settings`].
//!
//! A flag given on the command line ([`DrawArgs::given`]) must do something: one the
//! renderer does not read (its registry entry's `uses`), one the other flags leave idle,
//! or one the scene has nothing for is refused, naming what would use it; so is any
//! drawing flag when the input is a trace ([`crate::input::drawing_applies`]).

use crate::error::CliError;
use clap::parser::ValueSource;
use clap::{ArgMatches, Args, ValueEnum};
use cwisim_render::cp::Increment;
pub use cwisim_render::draw::Drawn;
use cwisim_render::draw::SceneInput;
use cwisim_render::settings::{
    BspOrder, SbufferMode, Setting, Threshold, Unset, DEFAULT_AA_THRESHOLD,
    DEFAULT_GOURAUD_THRESHOLD, DEFAULT_PHONG_ANGLE,
};
use cwisim_render::subsample::Grid;
use cwisim_render::{registry, Settings, Size};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::texture::TextureFilter;
use cwisim_world::Visibility;
use std::path::Path;

/// `--shading`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ShadingArg {
    /// One intensity per polygon (world scenes: lit once per face): Eval1 spans.
    Flat,
    /// Interpolated along the edges and across each scanline (world scenes: lit at every
    /// vertex): Eval2 spans.
    #[default]
    Gouraud,
    /// World scenes, exact visibility: the normal and the point interpolated over each
    /// triangle and lit at every pixel, each row sent through the span fitter
    /// (--shade-tolerance).
    Phong,
    /// No shading calls (woo-chall only, the paper's "hidden" timing mode): 1 on the
    /// visible triangles' edges, 0 elsewhere.
    Hidden,
}

/// `--aa`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum AaArg {
    /// Point sampling at pixel centres.
    None,
    /// Box filter, exact: the integral of the intensity over every pixel's covered part
    /// (DO_FILL's twelve cases).
    #[default]
    Box,
    /// Box filter as van Rij's report computes it: the covered area times the intensity
    /// at the pixel centre (the same instructions; with flat shading the same image).
    BoxCentre,
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

/// `--shadows`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ShadowsArg {
    /// Every light casts shadows.
    On,
    /// No light casts shadows.
    Off,
}

/// `--texture-filter`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum TextureFilterArg {
    /// The texture's mean over the pixel's footprint (its preimage's bounding box in
    /// texture space, from a summed-area table).
    #[default]
    Box,
    /// The texel under the pixel centre.
    Point,
}

impl From<TextureFilterArg> for TextureFilter {
    fn from(f: TextureFilterArg) -> TextureFilter {
        match f {
            TextureFilterArg::Box => TextureFilter::Box,
            TextureFilterArg::Point => TextureFilter::Point,
        }
    }
}

/// `--grid`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum GridArg {
    /// l×l samples at the centres of an l×l subdivision of the pixel (at --samples 1, the
    /// pixel centre: point sampling).
    #[default]
    Centre,
    /// Woo & Chall's shared grid: l×l samples on the pixel's corners, edges and inside,
    /// trapezoid weights; samples on a pixel's edge are shared with the neighbour, so
    /// each pixel costs (l−1)² new samples. Needs --samples 2 or more.
    Corner,
}

/// `--cp-increment`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum IncrementArg {
    /// Recompute each edge's intersection at every scanline: exact as a plain edge list.
    #[default]
    Direct,
    /// The paper's XX += SL along an edge: drifts, and flips a pixel where a crossing
    /// falls on a sample (docs/ERRATA.md, BR1).
    Paper,
}

/// `--sbuffer`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum SbufferArg {
    /// Depth on the host; each scanline's visible runs sent.
    #[default]
    Host,
    /// Study mode (f64, one sample): every run sent as FILL sets it, overwrites undone by
    /// negated draws under Acc_mode.
    Overdraw,
    /// Barkan & Gordon's §5.2 transparency: per sample, the list of the transparent
    /// polygons in front of the nearest opaque one, composited nearest first (world
    /// scenes with a material's transmittance above 0).
    Transparent,
    /// Barkan & Gordon's §5.2 scanline A-buffer: per pixel a fragment per polygon, its
    /// coverage mask --samples × --samples bits (at most 8 × 8), resolved nearest first
    /// as Carpenter resolves a pixel.
    Abuffer,
}

/// `--order`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum OrderArg {
    /// Painter's, into a host colour line; overdraw reported.
    BackToFront,
    /// Near to far, each pixel set once.
    #[default]
    FrontToBack,
}

/// `--unset`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum UnsetArg {
    /// Gordon & Chen's run-length list of unset pixels on the host: only newly set runs
    /// sent; a scanline's walk stops when the list is empty.
    #[default]
    Host,
    /// Every active span sent as Eval0: the array's lock bits are the list, the first
    /// claim wins (flat shading, one sample per pixel).
    Eval0,
}

impl From<IncrementArg> for Increment {
    fn from(g: IncrementArg) -> Increment {
        match g {
            IncrementArg::Direct => Increment::Direct,
            IncrementArg::Paper => Increment::Paper,
        }
    }
}

impl From<SbufferArg> for SbufferMode {
    fn from(g: SbufferArg) -> SbufferMode {
        match g {
            SbufferArg::Host => SbufferMode::Host,
            SbufferArg::Overdraw => SbufferMode::Overdraw,
            SbufferArg::Transparent => SbufferMode::Transparent,
            SbufferArg::Abuffer => SbufferMode::Abuffer,
        }
    }
}

impl From<OrderArg> for BspOrder {
    fn from(g: OrderArg) -> BspOrder {
        match g {
            OrderArg::BackToFront => BspOrder::BackToFront,
            OrderArg::FrontToBack => BspOrder::FrontToBack,
        }
    }
}

impl From<UnsetArg> for Unset {
    fn from(g: UnsetArg) -> Unset {
        match g {
            UnsetArg::Host => Unset::Host,
            UnsetArg::Eval0 => Unset::Eval0,
        }
    }
}

impl From<GridArg> for Grid {
    fn from(g: GridArg) -> Grid {
        match g {
            GridArg::Centre => Grid::Centre,
            GridArg::Corner => Grid::Corner,
        }
    }
}

impl From<ShadingArg> for Shading {
    fn from(s: ShadingArg) -> Shading {
        match s {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Gouraud => Shading::Gouraud,
            ShadingArg::Phong => Shading::Phong,
            ShadingArg::Hidden => Shading::Hidden,
        }
    }
}

impl From<AaArg> for Antialias {
    fn from(a: AaArg) -> Antialias {
        match a {
            AaArg::None => Antialias::None,
            AaArg::Box => Antialias::Box,
            AaArg::BoxCentre => Antialias::BoxCentre,
        }
    }
}

impl From<VisibilityArg> for Visibility {
    fn from(v: VisibilityArg) -> Visibility {
        match v {
            VisibilityArg::Exact => Visibility::Exact,
            VisibilityArg::Eval0 => Visibility::Eval0,
        }
    }
}

/// How a scene is drawn: shared by every command that draws one.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct DrawArgs {
    /// The drawing flags given on the command line (`--samples`), in the order declared
    /// here: [`DrawArgs::note_given`] fills it after parsing (empty: nothing is checked).
    #[arg(skip)]
    pub given: Vec<&'static str>,
    /// The renderer: the Y-processor program that turns the scene into instructions
    /// (`cwisim renderers` lists them).
    #[arg(long, value_name = "NAME", default_value = registry::DEFAULT_RENDERER)]
    pub renderer: String,
    /// Shading.
    #[arg(long, value_enum, default_value_t = ShadingArg::Gouraud)]
    pub shading: ShadingArg,
    /// Anti-aliasing.
    #[arg(long, value_enum, default_value_t = AaArg::Box, help_heading = TRAPEZIA)]
    pub aa: AaArg,
    /// Hidden-surface removal for world scenes, by vanrij (nishita's pieces are always
    /// resolved exactly; screen scenes are drawn as they are: their polygons add up).
    #[arg(long, value_enum, default_value_t = VisibilityArg::Exact, help_heading = TRAPEZIA)]
    pub visibility: VisibilityArg,
    /// With --visibility eval0 and Gouraud shading: how far (in intensity) the staircase
    /// of Eval0s that claims a shaded interior may stray from the Gouraud value at a pixel
    /// centre. Smaller is more exact and costs more Eval0s; 0 is one Eval0 per pixel.
    #[arg(long, value_name = "TOL", default_value_t = 1.0 / 512.0, help_heading = TRAPEZIA)]
    pub eval0_tolerance: f64,
    /// Draw at another size, WIDTHxHEIGHT (a world scene's camera keeps its vertical field
    /// of view; a screen scene is scaled).
    #[arg(long, value_name = "WxH")]
    pub size: Option<Size>,
    /// With --shading phong: how far (in intensity) the span fitter's Eval1/Eval2/Eval3
    /// pieces may stray from the per-pixel Phong value. 0 sends one Eval1 per pixel.
    /// nishita under the box filter fits a patch's row as one span with either shading:
    /// within this with Phong, within an eighth of it with Gouraud.
    #[arg(long, value_name = "E", default_value_t = 1.0 / 512.0)]
    pub shade_tolerance: f64,
    /// Tessellate the scene's Bézier meshes N×N quads per patch (1 to 64) instead of as
    /// the scene says.
    #[arg(long, value_name = "N")]
    pub tessellate: Option<u32>,
    /// Supersampling renderers: samples per pixel side, an L×L grid per pixel (1 to 64).
    #[arg(
        long,
        value_name = "L",
        default_value_t = 3,
        help_heading = SUPERSAMPLING
    )]
    pub samples: u32,
    /// Where a pixel's samples lie.
    #[arg(long, value_enum, default_value_t = GridArg::Centre, help_heading = SUPERSAMPLING)]
    pub grid: GridArg,
    /// Sum a row's L sub-scanlines on the host and send one pass per row, instead of one
    /// pass per sub-scanline that the array accumulates (the hardware way: its cost grows
    /// with L).
    #[arg(long, help_heading = SUPERSAMPLING)]
    pub merge_subscanlines: bool,
    /// Probability of a stochastic shading call at a sample whose surface the pixel has
    /// shaded already [default: the paper's (L−1)/(L²−1)].
    #[arg(long, value_name = "P", help_heading = STOCHASTIC)]
    pub shade_p: Option<f64>,
    /// Colour difference (any channel) between a shading call and the pixel's previous
    /// sample, its left or right neighbour or the row above, beyond which the pixel and
    /// that neighbour shade every later sample; `inf` never forces.
    #[arg(
        long,
        value_name = "T",
        default_value_t = 0.1,
        help_heading = STOCHASTIC
    )]
    pub shade_contrast: f64,
    /// Seed of every random choice (woo-chall's stochastic shading calls): the same seed
    /// gives the same stream.
    #[arg(long, value_name = "S", default_value_t = 0, help_heading = STOCHASTIC)]
    pub seed: u64,
    /// Barkan & Gordon's renderers (sbuffer, bsp): how critical-points scan conversion
    /// updates an edge's intersection from one scanline to the next.
    #[arg(long, value_enum, default_value_t = IncrementArg::Direct, help_heading = "Scanline principle (sbuffer, bsp)")]
    pub cp_increment: IncrementArg,
    /// What the S-buffer keeps per sample and sends the array: the nearest polygon (host),
    /// every run as set (overdraw), the transparent polygons down to the nearest opaque
    /// one, composited (transparent), or per pixel a fragment per polygon with a
    /// --samples × --samples coverage mask (abuffer).
    #[arg(long, value_enum, default_value_t = SbufferArg::Host, help_heading = "Scanline principle (sbuffer, bsp)")]
    pub sbuffer: SbufferArg,
    /// The BSP tree's traversal order.
    #[arg(long, value_enum, default_value_t = OrderArg::FrontToBack, help_heading = "Scanline principle (sbuffer, bsp)")]
    pub order: OrderArg,
    /// Front to back: where the list of unset pixels lives.
    #[arg(long, value_enum, default_value_t = UnsetArg::Host, help_heading = "Scanline principle (sbuffer, bsp)")]
    pub unset: UnsetArg,
    /// Bézier clipping's tolerance, in the patch parameter u or v (the paper's 1e-3 keeps a
    /// patch 1000 pixels across within about a pixel). Spelled --root-tolerance because
    /// `cwisim diff` has a --tolerance of its own.
    #[arg(
        long,
        value_name = "T",
        default_value_t = 1e-3,
        help_heading = "Bézier patches (nishita)"
    )]
    pub root_tolerance: f64,
    /// How far (pixels) a subpatch's projected control points may stray from the bilinear
    /// interpolation of its projected corners (a quarter of it for subpatches that may
    /// hold a silhouette).
    #[arg(
        long,
        value_name = "PX",
        default_value_t = 0.5,
        help_heading = "Bézier patches (nishita)"
    )]
    pub flatness: f64,
    /// Nishita's §5: a subpatch whose corner normals differ by more than ANGLE degrees is
    /// divided again; `off`: not [default: off, the flatness alone decides].
    #[arg(long, value_name = "ANGLE|off", value_parser = angle_or_off, help_heading = "Bézier patches (nishita)")]
    pub normal_angle: Option<AngleOrOff>,
    /// Pixel rows per band of subpatches (the paper: three or four).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 4,
        help_heading = "Bézier patches (nishita)"
    )]
    pub band: u32,
    /// Sub-scanlines per pixel row: roots at every 1/K of a row, straight pieces between.
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1,
        help_heading = "Bézier patches (nishita)"
    )]
    pub subscan: u32,
    /// Refinement's phase 2 Gouraud-shades a polygon whose vertex-intensity range (the
    /// largest over channels) exceeds T; `all` or `none`.
    #[arg(
        long,
        value_name = "T",
        default_value_t = Threshold::Above(DEFAULT_GOURAUD_THRESHOLD),
        help_heading = "Adaptive refinement (refine)"
    )]
    pub gouraud_threshold: Threshold,
    /// Refinement's anti-aliasing phase box-filters a pixel whose 3x3 neighbourhood range
    /// in the previous frame exceeds T; `all` or `none`.
    #[arg(
        long,
        value_name = "T",
        default_value_t = Threshold::Above(DEFAULT_AA_THRESHOLD),
        help_heading = "Adaptive refinement (refine)"
    )]
    pub aa_threshold: Threshold,
    /// Refinement's Phong phase lights per pixel a polygon whose highlight vector (the
    /// light mirrored in the normal) at some vertex is within DEG degrees of the
    /// direction to the eye; `all` or `none`.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = Threshold::Above(DEFAULT_PHONG_ANGLE),
        help_heading = "Adaptive refinement (refine)"
    )]
    pub phong_angle: Threshold,
    /// Shadows from every light (on) or from none (off), whatever each light's
    /// "shadows" entry in the scene says [default: as the scene says]. Exact shadow
    /// polygons, cut from the visible surfaces with the light as the eye (vanrij, refine),
    /// or the same lit parts tested at each sample (woo-chall, sbuffer, bsp).
    #[arg(long, value_enum, value_name = "on|off")]
    pub shadows: Option<ShadowsArg>,
    /// How a pixel reads a textured mesh's texture: its mean over the pixel's footprint
    /// (box), or the texel under the pixel's centre (point). The result goes through the
    /// span fitter, within --shade-tolerance, under any --shading.
    #[arg(
        long,
        value_enum,
        value_name = "box|point",
        default_value = "box",
        help_heading = "Textures (vanrij, nishita)"
    )]
    pub texture_filter: TextureFilterArg,
}

/// The help heading of van Rij's trapezia's flags: the pixel filter and the visibility.
const TRAPEZIA: &str = "Trapezia (vanrij, nishita)";
/// The help heading of the supersampling renderers' flags.
const SUPERSAMPLING: &str = "Supersampling (woo-chall, sbuffer, bsp)";
/// The help heading of Woo & Chall's shading calls' flags.
const STOCHASTIC: &str = "Stochastic shading calls (woo-chall)";

/// The help heading of the drawing flags in a command that reads a trace or a scene.
pub const SCENE_ONLY: &str =
    "Drawing a scene (only when the input is a scene; refused with a trace)";

impl Default for DrawArgs {
    fn default() -> Self {
        DrawArgs {
            given: Vec::new(),
            renderer: registry::DEFAULT_RENDERER.into(),
            shading: ShadingArg::Gouraud,
            aa: AaArg::Box,
            visibility: VisibilityArg::Exact,
            eval0_tolerance: 1.0 / 512.0,
            size: None,
            shade_tolerance: 1.0 / 512.0,
            tessellate: None,
            samples: 3,
            grid: GridArg::Centre,
            merge_subscanlines: false,
            shade_p: None,
            shade_contrast: 0.1,
            seed: 0,
            cp_increment: IncrementArg::Direct,
            sbuffer: SbufferArg::Host,
            order: OrderArg::FrontToBack,
            unset: UnsetArg::Host,
            root_tolerance: 1e-3,
            flatness: 0.5,
            normal_angle: None,
            band: 4,
            subscan: 1,
            gouraud_threshold: Threshold::Above(DEFAULT_GOURAUD_THRESHOLD),
            aa_threshold: Threshold::Above(DEFAULT_AA_THRESHOLD),
            phong_angle: Threshold::Above(DEFAULT_PHONG_ANGLE),
            shadows: None,
            texture_filter: TextureFilterArg::Box,
        }
    }
}

/// `--renderer`, or the flag of a [`Setting`], from its long name (`samples`).
fn flag_of(long: &str) -> Option<&'static str> {
    match long {
        "renderer" => Some("--renderer"),
        _ => Setting::ALL
            .into_iter()
            .map(Setting::flag)
            .find(|f| f.strip_prefix("--") == Some(long)),
    }
}

impl DrawArgs {
    /// Records in [`DrawArgs::given`] the drawing flags `matches` (the subcommand's) took
    /// from the command line, not from their defaults.
    pub fn note_given(&mut self, matches: &ArgMatches) {
        let group = DrawArgs::augment_args(clap::Command::new("draw"));
        self.given = group
            .get_arguments()
            .filter(|a| matches.value_source(a.get_id().as_str()) == Some(ValueSource::CommandLine))
            .filter_map(|a| a.get_long().and_then(flag_of))
            .collect();
    }

    /// The settings given on the command line (all of [`DrawArgs::given`] but
    /// `--renderer`).
    pub fn given_settings(&self) -> Vec<Setting> {
        self.given
            .iter()
            .filter_map(|f| Setting::of_flag(f))
            .collect()
    }

    /// The library's settings.
    pub fn settings(&self) -> Settings {
        Settings {
            shading: self.shading.into(),
            aa: self.aa.into(),
            visibility: self.visibility.into(),
            eval0_tolerance: self.eval0_tolerance,
            size: self.size,
            shade_tolerance: self.shade_tolerance,
            tessellate: self.tessellate,
            samples: self.samples,
            grid: self.grid.into(),
            merge_subscanlines: self.merge_subscanlines,
            shade_p: self.shade_p,
            shade_contrast: self.shade_contrast,
            seed: self.seed,
            cp_increment: self.cp_increment.into(),
            sbuffer: self.sbuffer.into(),
            bsp_order: self.order.into(),
            unset: self.unset.into(),
            root_tolerance: self.root_tolerance,
            flatness: self.flatness,
            normal_angle: self.normal_angle.and_then(|a| a.0),
            band: self.band,
            subscan: self.subscan,
            gouraud_threshold: self.gouraud_threshold,
            aa_threshold: self.aa_threshold,
            phong_angle: self.phong_angle,
            shadows: self.shadows.map(|s| s == ShadowsArg::On),
            texture_filter: self.texture_filter.into(),
            threads: 1,
        }
    }

    /// Reads the scene SCENE names (a file, an embedded name, or none: the default) and
    /// builds the renderer for it.
    pub fn draw(&self, scene: Option<&Path>) -> Result<Drawn, CliError> {
        self.draw_on(scene, 1)
    }

    /// [`DrawArgs::draw`], preparing the scene on `threads` threads (exact visibility;
    /// 0: one per core): the renderer is the same at any count.
    pub fn draw_on(&self, scene: Option<&Path>, threads: usize) -> Result<Drawn, CliError> {
        let settings = Settings {
            threads,
            ..self.settings()
        };
        Ok(cwisim_render::draw::draw(
            &self.renderer,
            SceneInput::Named(scene),
            &self.given_settings(),
            &settings,
        )?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_render::REGISTRY;

    #[test]
    fn every_drawing_flag_is_the_renderer_or_a_setting() {
        let group = DrawArgs::augment_args(clap::Command::new("draw"));
        let longs: Vec<&str> = group.get_arguments().filter_map(|a| a.get_long()).collect();
        for long in &longs {
            assert!(flag_of(long).is_some(), "--{long} is no setting");
        }
        for s in Setting::ALL {
            assert!(longs.contains(&&s.flag()[2..]), "{} is no flag", s.flag());
        }
        assert_eq!(longs.len(), Setting::ALL.len() + 1);
    }

    #[test]
    fn a_heading_naming_renderers_names_every_one_that_reads_its_flags() {
        let group = DrawArgs::augment_args(clap::Command::new("draw"));
        for arg in group.get_arguments() {
            let Some(heading) = arg.get_help_heading() else {
                continue;
            };
            let named = heading
                .rsplit_once('(')
                .and_then(|(_, r)| r.strip_suffix(')'))
                .unwrap_or_default();
            let named: Vec<&str> = named.split(", ").collect();
            let flag = arg.get_long().and_then(flag_of).unwrap_or_default();
            let setting = Setting::of_flag(flag).expect("a setting");
            for e in REGISTRY.iter().filter(|e| e.uses.contains(&setting)) {
                assert!(
                    named.contains(&e.name),
                    "{flag} under `{heading}`, read by {}",
                    e.name
                );
            }
        }
    }

    /// The library's [`Setting::set`] (what Python calls) reads every flag's value as the
    /// command line does: the same settings from the same words.
    #[test]
    fn the_library_reads_every_flag_s_value_as_the_command_line_does() {
        let value = |s: Setting| match s {
            Setting::Shading => "phong",
            Setting::Aa => "box-centre",
            Setting::Visibility => "eval0",
            Setting::Size => "64x48",
            Setting::Tessellate | Setting::Samples | Setting::Band | Setting::Subscan => "5",
            Setting::Grid => "corner",
            Setting::MergeSubscanlines => "true",
            Setting::Seed => "7",
            Setting::CpIncrement => "paper",
            Setting::Sbuffer => "overdraw",
            Setting::Order => "back-to-front",
            Setting::Unset => "eval0",
            Setting::GouraudThreshold | Setting::AaThreshold => "all",
            Setting::PhongAngle => "45",
            Setting::Shadows => "off",
            Setting::TextureFilter => "point",
            _ => "0.25",
        };
        for s in Setting::ALL {
            let mut args = vec!["cwisim", "render", s.flag()];
            if s != Setting::MergeSubscanlines {
                args.push(value(s));
            }
            let cli = crate::cli::parse(args.iter().map(|&a| a.into()).collect::<Vec<_>>())
                .unwrap_or_else(|e| panic!("{args:?}: {e}"));
            let crate::cli::Command::Render(r) = cli.command else {
                panic!("render");
            };
            let mut library = Settings::default();
            s.set(&mut library, value(s)).unwrap();
            assert_eq!(r.draw.settings(), library, "{}", s.flag());
            assert_ne!(library, Settings::default(), "{}", s.flag());
            assert_eq!(Setting::of_name(&s.name().replace('-', "_")), Some(s));
        }
        let mut settings = Settings::default();
        assert_eq!(
            Setting::Samples.set(&mut settings, "three"),
            Err(
                "expected a whole number ≥ 0, found `three` (invalid digit found in string)".into()
            )
        );
        assert!(Setting::Shadows.set(&mut settings, "maybe").is_err());
    }

    #[test]
    fn the_flags_given_are_noted_in_declaration_order() {
        let args = [
            "cwisim",
            "render",
            "--samples",
            "2",
            "--renderer",
            "bsp",
            "--seed=0",
        ];
        let cli = crate::cli::parse(args.map(Into::into)).expect("parses");
        let crate::cli::Command::Render(r) = cli.command else {
            panic!("render");
        };
        // a flag given with its default value counts: it was given
        assert_eq!(r.draw.given, ["--renderer", "--samples", "--seed"]);
        assert_eq!(r.draw.given_settings(), [Setting::Samples, Setting::Seed]);
    }
}

/// One value of `--normal-angle` (`render`'s, and each of `tradeoff`'s list): degrees, or
/// `off` (the test not made).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleOrOff(pub Option<f64>);

/// Parses `off` or a number of degrees as the library spells them (`Setting::set`; the
/// range is checked with the rest of the settings).
pub fn angle_or_off(text: &str) -> Result<AngleOrOff, String> {
    let mut s = Settings::default();
    cwisim_render::settings::Setting::NormalAngle.set(&mut s, text)?;
    Ok(AngleOrOff(s.normal_angle))
}
