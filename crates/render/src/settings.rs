//! How to draw: the settings every renderer reads, in plain types (the command line's
//! argument groups convert into them; nothing here knows about clap).

use crate::cp::Increment;
use crate::subsample::Grid;
use cwisim_scene::{Antialias, Shading};
use cwisim_world::texture::TextureFilter;
use cwisim_world::Visibility;
use std::fmt;
use std::str::FromStr;

/// An image size, `WIDTHxHEIGHT`.
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

impl fmt::Display for Size {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

/// How a scene is drawn, whatever the renderer. A renderer reads the settings that apply
/// to it and says in its description which ones it used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Shading.
    pub shading: Shading,
    /// Anti-aliasing.
    pub aa: Antialias,
    /// Hidden-surface removal for world scenes.
    pub visibility: Visibility,
    /// With eval0 visibility and Gouraud shading: how far the staircase of `Eval0`s that
    /// claims a shaded interior may stray from the Gouraud value at a pixel centre.
    pub eval0_tolerance: f64,
    /// Draw at another size (a world scene's camera keeps its vertical field of view; a
    /// screen scene is scaled).
    pub size: Option<Size>,
    /// With Phong shading: how far the span fitter's pieces may stray from the per-pixel
    /// intensity (0: one `Eval1` per pixel, exact).
    pub shade_tolerance: f64,
    /// Tessellate Bézier meshes `n` × `n` per patch instead of as the scene says.
    pub tessellate: Option<u32>,
    /// Supersampling renderers: samples per pixel side (`l`: an `l × l` grid).
    pub samples: u32,
    /// Supersampling renderers: where the samples lie.
    pub grid: Grid,
    /// Supersampling renderers: the host sums a row's sub-scanlines into one pass,
    /// rather than sending each as a pass the array accumulates.
    pub merge_subscanlines: bool,
    /// Woo & Chall: probability of a stochastic shading call (`None`: the paper's
    /// `(l − 1)/(l² − 1)`).
    pub shade_p: Option<f64>,
    /// Woo & Chall: colour difference between shading calls above which a pixel and
    /// its neighbour are forced to shade every sample (infinite: never).
    pub shade_contrast: f64,
    /// Seed of every random choice a renderer makes.
    pub seed: u64,
    /// Barkan & Gordon: how CP updates an edge's intersection from line to line.
    pub cp_increment: Increment,
    /// Barkan & Gordon's S-buffer: what it sends the array.
    pub sbuffer: SbufferMode,
    /// Barkan & Gordon's BSP display: the traversal order.
    pub bsp_order: BspOrder,
    /// Barkan & Gordon's BSP display, front to back: who keeps the unset pixels.
    pub unset: Unset,
    /// Nishita: the root finder's tolerance, in the patch parameter (`u` or `v`).
    pub root_tolerance: f64,
    /// Nishita: how far (pixels) a subpatch's projected control points may lie from the
    /// bilinear interpolation of its projected corners.
    pub flatness: f64,
    /// Nishita §5: a subpatch whose corner normals differ by more than this angle
    /// (degrees) is divided again (`None`: off, flatness alone decides).
    pub normal_angle: Option<f64>,
    /// Nishita: pixel rows per band of subpatches.
    pub band: u32,
    /// Nishita: sub-scanlines per pixel row: roots at every `1/subscan` of a row.
    pub subscan: u32,
    /// Adaptive refinement: a polygon is Gouraud-shaded when its vertex-intensity range
    /// passes this.
    pub gouraud_threshold: Threshold,
    /// Adaptive refinement: a pixel is box-filtered when the range of its 3 × 3
    /// neighbourhood in the previous frame passes this.
    pub aa_threshold: Threshold,
    /// Adaptive refinement: a polygon is Phong-shaded when the angle (degrees) between a
    /// corner's highlight vector and the direction to the eye is within this.
    pub phong_angle: Threshold,
    /// Shadows: `None` as each light of the scene says (`"shadows": true`), `Some(true)`
    /// every light casts them, `Some(false)` none does (`render --shadows on|off`).
    pub shadows: Option<bool>,
    /// Textured scenes: how a pixel reads a texture (the mean over its footprint, or the
    /// texel under its centre).
    pub texture_filter: TextureFilter,
    /// Threads the host-side preparation may use (exact visibility; 0: one per core).
    /// The polygons are the same, bit for bit, at any count. `render --threads N` sets
    /// it with the pipeline's.
    pub threads: usize,
}

/// One of the [`Settings`] a renderer may read, named by its command-line flag. A
/// renderer declares the ones it reads ([`crate::registry::Entry::uses`]); the command
/// line refuses a flag given for one that is not read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Setting {
    /// [`Settings::shading`].
    Shading,
    /// [`Settings::aa`].
    Aa,
    /// [`Settings::visibility`].
    Visibility,
    /// [`Settings::eval0_tolerance`].
    Eval0Tolerance,
    /// [`Settings::size`].
    Size,
    /// [`Settings::shade_tolerance`].
    ShadeTolerance,
    /// [`Settings::tessellate`].
    Tessellate,
    /// [`Settings::samples`].
    Samples,
    /// [`Settings::grid`].
    Grid,
    /// [`Settings::merge_subscanlines`].
    MergeSubscanlines,
    /// [`Settings::shade_p`].
    ShadeP,
    /// [`Settings::shade_contrast`].
    ShadeContrast,
    /// [`Settings::seed`].
    Seed,
    /// [`Settings::cp_increment`].
    CpIncrement,
    /// [`Settings::sbuffer`].
    Sbuffer,
    /// [`Settings::bsp_order`].
    Order,
    /// [`Settings::unset`].
    Unset,
    /// [`Settings::root_tolerance`].
    RootTolerance,
    /// [`Settings::flatness`].
    Flatness,
    /// [`Settings::normal_angle`].
    NormalAngle,
    /// [`Settings::band`].
    Band,
    /// [`Settings::subscan`].
    Subscan,
    /// [`Settings::gouraud_threshold`].
    GouraudThreshold,
    /// [`Settings::aa_threshold`].
    AaThreshold,
    /// [`Settings::phong_angle`].
    PhongAngle,
    /// [`Settings::shadows`].
    Shadows,
    /// [`Settings::texture_filter`].
    TextureFilter,
}

impl Setting {
    /// Every setting, in the order of the command line's drawing flags.
    pub const ALL: [Setting; 27] = [
        Setting::Shading,
        Setting::Aa,
        Setting::Visibility,
        Setting::Eval0Tolerance,
        Setting::Size,
        Setting::ShadeTolerance,
        Setting::Tessellate,
        Setting::Samples,
        Setting::Grid,
        Setting::MergeSubscanlines,
        Setting::ShadeP,
        Setting::ShadeContrast,
        Setting::Seed,
        Setting::CpIncrement,
        Setting::Sbuffer,
        Setting::Order,
        Setting::Unset,
        Setting::RootTolerance,
        Setting::Flatness,
        Setting::NormalAngle,
        Setting::Band,
        Setting::Subscan,
        Setting::GouraudThreshold,
        Setting::AaThreshold,
        Setting::PhongAngle,
        Setting::Shadows,
        Setting::TextureFilter,
    ];

    /// Its flag: `--samples`.
    pub fn flag(self) -> &'static str {
        match self {
            Setting::Shading => "--shading",
            Setting::Aa => "--aa",
            Setting::Visibility => "--visibility",
            Setting::Eval0Tolerance => "--eval0-tolerance",
            Setting::Size => "--size",
            Setting::ShadeTolerance => "--shade-tolerance",
            Setting::Tessellate => "--tessellate",
            Setting::Samples => "--samples",
            Setting::Grid => "--grid",
            Setting::MergeSubscanlines => "--merge-subscanlines",
            Setting::ShadeP => "--shade-p",
            Setting::ShadeContrast => "--shade-contrast",
            Setting::Seed => "--seed",
            Setting::CpIncrement => "--cp-increment",
            Setting::Sbuffer => "--sbuffer",
            Setting::Order => "--order",
            Setting::Unset => "--unset",
            Setting::RootTolerance => "--root-tolerance",
            Setting::Flatness => "--flatness",
            Setting::NormalAngle => "--normal-angle",
            Setting::Band => "--band",
            Setting::Subscan => "--subscan",
            Setting::GouraudThreshold => "--gouraud-threshold",
            Setting::AaThreshold => "--aa-threshold",
            Setting::PhongAngle => "--phong-angle",
            Setting::Shadows => "--shadows",
            Setting::TextureFilter => "--texture-filter",
        }
    }

    /// The setting of a flag (`--samples`).
    pub fn of_flag(flag: &str) -> Option<Setting> {
        Setting::ALL.into_iter().find(|s| s.flag() == flag)
    }

    /// Its name: the flag without its dashes (`shade-tolerance`; Python spells it
    /// `shade_tolerance`).
    pub fn name(self) -> &'static str {
        &self.flag()[2..]
    }

    /// The setting called `name`, spelled with dashes or underscores
    /// (`shade-tolerance`, `shade_tolerance`).
    pub fn of_name(name: &str) -> Option<Setting> {
        let name = name.replace('_', "-");
        Setting::ALL.into_iter().find(|s| s.name() == name)
    }

    /// Sets this setting of `settings` from `value`, spelled as on the command line
    /// (`gouraud`, `box-centre`, `0.01`, `640x480`, `all`; `--merge-subscanlines` takes
    /// `true` or `false`, `--shadows` `on` or `off`). The ranges are checked with the
    /// rest by [`Settings::check`].
    pub fn set(self, settings: &mut Settings, value: &str) -> Result<(), String> {
        fn parse<T: FromStr>(value: &str, what: &str) -> Result<T, String>
        where
            T::Err: fmt::Display,
        {
            value
                .trim()
                .parse::<T>()
                .map_err(|e| format!("expected {what}, found `{value}` ({e})"))
        }
        let s = settings;
        let number = "a number";
        let count = "a whole number ≥ 0";
        match self {
            Setting::Shading => s.shading = value.parse()?,
            Setting::Aa => s.aa = value.parse()?,
            Setting::Visibility => s.visibility = value.parse()?,
            Setting::Eval0Tolerance => s.eval0_tolerance = parse(value, number)?,
            Setting::Size => s.size = Some(value.parse()?),
            Setting::ShadeTolerance => s.shade_tolerance = parse(value, number)?,
            Setting::Tessellate => s.tessellate = Some(parse(value, count)?),
            Setting::Samples => s.samples = parse(value, count)?,
            Setting::Grid => s.grid = value.parse()?,
            Setting::MergeSubscanlines => {
                s.merge_subscanlines = parse(&value.to_ascii_lowercase(), "true or false")?
            }
            Setting::ShadeP => s.shade_p = Some(parse(value, number)?),
            Setting::ShadeContrast => s.shade_contrast = parse(value, number)?,
            Setting::Seed => s.seed = parse(value, count)?,
            Setting::CpIncrement => s.cp_increment = value.parse()?,
            Setting::Sbuffer => s.sbuffer = value.parse()?,
            Setting::Order => s.bsp_order = value.parse()?,
            Setting::Unset => s.unset = value.parse()?,
            Setting::RootTolerance => s.root_tolerance = parse(value, number)?,
            Setting::Flatness => s.flatness = parse(value, number)?,
            Setting::NormalAngle => {
                s.normal_angle = match value.trim().to_ascii_lowercase().as_str() {
                    "off" => None,
                    v => Some(parse(v, "a number of degrees or off")?),
                }
            }
            Setting::Band => s.band = parse(value, count)?,
            Setting::Subscan => s.subscan = parse(value, count)?,
            Setting::GouraudThreshold => s.gouraud_threshold = value.parse()?,
            Setting::AaThreshold => s.aa_threshold = value.parse()?,
            Setting::PhongAngle => s.phong_angle = value.parse()?,
            Setting::Shadows => {
                s.shadows = Some(match value.trim().to_ascii_lowercase().as_str() {
                    "on" => true,
                    "off" => false,
                    _ => return Err(format!("expected on or off, found `{value}`")),
                })
            }
            Setting::TextureFilter => {
                s.texture_filter = TextureFilter::of_name(value.trim())
                    .ok_or_else(|| format!("expected box or point, found `{value}`"))?
            }
        }
        Ok(())
    }

    /// It concerns world scenes only: a screen scene has no depth to resolve, nothing to
    /// light per pixel and nothing to refine.
    pub fn world_only(self) -> bool {
        matches!(
            self,
            Setting::Visibility
                | Setting::Eval0Tolerance
                | Setting::ShadeTolerance
                | Setting::GouraudThreshold
                | Setting::AaThreshold
                | Setting::PhongAngle
                | Setting::Shadows
                | Setting::TextureFilter
        )
    }

    /// When the other settings of `s` leave this one nothing to do in a renderer that
    /// reads both: the setting that decides, and why. `--aa box` with Phong shading is
    /// here too: Phong's box filter is the report's, coverage × the centre's shade.
    pub fn idle_under(self, s: &Settings) -> Option<(Setting, String)> {
        let why = |by, text: &str| Some((by, text.to_string()));
        match self {
            Setting::ShadeTolerance if s.shading != Shading::Phong => why(
                Setting::Shading,
                "--shade-tolerance is the span fitter's, used with --shading phong, on textured meshes, and by nishita under the box filter",
            ),
            Setting::Eval0Tolerance
                if !(s.visibility == Visibility::Eval0 && s.shading == Shading::Gouraud) =>
            {
                why(
                    Setting::Visibility,
                    "--eval0-tolerance is used with --visibility eval0 and --shading gouraud only (a flat claim is one value)",
                )
            }
            Setting::Unset if s.bsp_order != BspOrder::FrontToBack => why(
                Setting::Order,
                "--unset is used with --order front-to-back only (back to front paints into a host colour line)",
            ),
            Setting::MergeSubscanlines if s.sbuffer == SbufferMode::Abuffer => why(
                Setting::Sbuffer,
                "--merge-subscanlines is not used with --sbuffer abuffer (the host resolves each pixel's fragments: one pass per row)",
            ),
            Setting::MergeSubscanlines if s.samples < 2 => why(
                Setting::Samples,
                "--merge-subscanlines is used with --samples 2 or more (one sub-scanline per row has nothing to merge)",
            ),
            Setting::ShadeP | Setting::ShadeContrast | Setting::Seed
                if s.shading == Shading::Hidden =>
            {
                Some((
                    Setting::Shading,
                    format!(
                        "{} is for shading calls, and --shading hidden makes none",
                        self.flag()
                    ),
                ))
            }
            Setting::Aa if s.shading == Shading::Phong && s.aa == Antialias::Box => why(
                Setting::Shading,
                "--aa box (exact) is not drawn with --shading phong: no instruction carries the exact integral of a Phong shade over a pixel; use --aa box-centre (coverage × the shade at the pixel centre, what Phong's box filter is) or --aa none",
            ),
            _ => None,
        }
    }
}

/// A refinement threshold: `all` (everything passes), `none` (nothing does), or a
/// number `T ≥ 0` (a measure passes when it exceeds `T`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Threshold {
    /// Everything passes.
    All,
    /// Nothing passes.
    None,
    /// A measure passes when it is greater than this (finite, ≥ 0).
    Above(f64),
}

impl Threshold {
    /// Whether `measure` passes.
    pub fn passes(self, measure: f64) -> bool {
        match self {
            Threshold::All => true,
            Threshold::None => false,
            Threshold::Above(t) => measure > t,
        }
    }
}

impl Threshold {
    /// Whether `measure` lies within the threshold read as a tolerance (`--phong-angle`:
    /// an angle passes when it is at most `T`): `all` admits everything, a missing
    /// measure too; `none` admits nothing; a number `T` admits a measure `≤ T`.
    pub fn admits(self, measure: Option<f64>) -> bool {
        match self {
            Threshold::All => true,
            Threshold::None => false,
            Threshold::Above(t) => measure.is_some_and(|m| m <= t),
        }
    }
}

impl FromStr for Threshold {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            t if t.eq_ignore_ascii_case("all") => Ok(Threshold::All),
            t if t.eq_ignore_ascii_case("none") => Ok(Threshold::None),
            t => match t.parse::<f64>() {
                Ok(v) if v >= 0.0 && v.is_finite() => Ok(Threshold::Above(v)),
                _ => Err(format!(
                    "expected `all`, `none` or a finite number ≥ 0; found `{s}`"
                )),
            },
        }
    }
}

impl fmt::Display for Threshold {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Threshold::All => f.write_str("all"),
            Threshold::None => f.write_str("none"),
            Threshold::Above(t) => write!(f, "{t}"),
        }
    }
}

/// `--sbuffer`: what the S-buffer sends the array.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SbufferMode {
    /// The depth line stays on the host; each scanline's visible runs are sent.
    #[default]
    Host,
    /// Study mode: every pixel sent as FILL sets it, an overwritten run undone by a
    /// negated draw (`Acc_mode`), so the array's work follows the pixels set.
    Overdraw,
    /// Barkan & Gordon's §5.2 transparency: per sample of the line, the list of the
    /// transparent polygons not blocked by an opaque one, nearest first, ending at the
    /// nearest opaque polygon (or the background, opaque at z = ∞), composited.
    Transparent,
    /// Barkan & Gordon's §5.2 scanline A-buffer: per pixel of the one-scanline buffer,
    /// each polygon's fragment (an `l × l` coverage mask from `--samples l`), resolved
    /// nearest first as Carpenter resolves a pixel.
    Abuffer,
}

/// `--order`: the BSP traversal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BspOrder {
    /// Painter's: far to near, into a host colour line.
    BackToFront,
    /// Near to far, each pixel set once (Gordon & Chen).
    #[default]
    FrontToBack,
}

/// `--unset`: front to back, where the list of unset pixels lives.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Unset {
    /// Gordon & Chen's run-length list on the host: only newly set runs are sent.
    #[default]
    Host,
    /// The array's lock bits: every active span sent as `Eval0`, the first claim wins.
    Eval0,
}

macro_rules! spelled {
    ($t:ty, $what:literal, $($v:ident => $s:literal),+) => {
        impl $t {
            /// Every value, in order.
            pub const ALL: &'static [$t] = &[$(<$t>::$v),+];

            /// Its one spelling.
            pub fn name(self) -> &'static str {
                match self {
                    $(<$t>::$v => $s),+
                }
            }
        }

        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }

        impl FromStr for $t {
            type Err = String;

            fn from_str(s: &str) -> Result<Self, String> {
                <$t>::ALL
                    .iter()
                    .copied()
                    .find(|v| v.name().eq_ignore_ascii_case(s))
                    .ok_or_else(|| {
                        let names: Vec<&str> = <$t>::ALL.iter().map(|v| v.name()).collect();
                        format!("unknown {} `{s}`; expected {}", $what, names.join(" or "))
                    })
            }
        }
    };
}

spelled!(SbufferMode, "S-buffer mode", Host => "host", Overdraw => "overdraw", Transparent => "transparent", Abuffer => "abuffer");
spelled!(BspOrder, "BSP order", BackToFront => "back-to-front", FrontToBack => "front-to-back");
spelled!(Unset, "unset-pixel list", Host => "host", Eval0 => "eval0");

impl Default for Settings {
    fn default() -> Self {
        Settings {
            shading: Shading::Gouraud,
            aa: Antialias::Box,
            visibility: Visibility::Exact,
            eval0_tolerance: 1.0 / 512.0,
            size: None,
            shade_tolerance: 1.0 / 512.0,
            tessellate: None,
            samples: 3,
            grid: Grid::Centre,
            merge_subscanlines: false,
            shade_p: None,
            shade_contrast: 0.1,
            seed: 0,
            cp_increment: Increment::Direct,
            sbuffer: SbufferMode::Host,
            bsp_order: BspOrder::FrontToBack,
            unset: Unset::Host,
            root_tolerance: 1e-3,
            flatness: 0.5,
            normal_angle: None,
            band: 4,
            subscan: 1,
            gouraud_threshold: Threshold::Above(DEFAULT_GOURAUD_THRESHOLD),
            aa_threshold: Threshold::Above(DEFAULT_AA_THRESHOLD),
            phong_angle: Threshold::Above(DEFAULT_PHONG_ANGLE),
            shadows: None,
            texture_filter: TextureFilter::Box,
            threads: 1,
        }
    }
}

/// `--gouraud-threshold`'s default: a vertex-intensity range of 1/32.
pub const DEFAULT_GOURAUD_THRESHOLD: f64 = 1.0 / 32.0;
/// `--aa-threshold`'s default: a 3 × 3 range of 1/16.
pub const DEFAULT_AA_THRESHOLD: f64 = 1.0 / 16.0;

/// `--phong-angle`'s default, degrees.
pub const DEFAULT_PHONG_ANGLE: f64 = 30.0;
/// The widest `--phong-angle`, degrees: every angle between two directions is within it.
pub const MAX_PHONG_ANGLE: f64 = 180.0;

/// The widest root tolerance: the whole parameter interval.
pub const MAX_ROOT_TOLERANCE: f64 = 1.0;
/// The most rows in a band of subpatches.
pub const MAX_BAND: u32 = 4096;
/// The most sub-scanlines per row.
pub const MAX_SUBSCAN: u32 = 64;
/// The smallest `--normal-angle`, degrees: below it subpatches would be divided to the
/// deepest level everywhere a surface curves at all.
pub const MIN_NORMAL_ANGLE: f64 = 0.5;

/// The finest flatness, pixels.
pub const MIN_FLATNESS: f64 = 1e-3;

impl Settings {
    /// Refuses settings no renderer could use, saying which and why.
    pub fn check(&self) -> Result<(), String> {
        if let Threshold::Above(a) = self.phong_angle {
            if a > MAX_PHONG_ANGLE {
                return Err(format!(
                    "--phong-angle is an angle in degrees between 0 and {MAX_PHONG_ANGLE} (or `all`, `none`), found {a}"
                ));
            }
        }
        if !(self.eval0_tolerance >= 0.0 && self.eval0_tolerance.is_finite()) {
            return Err(format!(
                "--eval0-tolerance must be a finite number ≥ 0, found {}",
                self.eval0_tolerance
            ));
        }
        if !(self.shade_tolerance >= 0.0 && self.shade_tolerance.is_finite()) {
            return Err(format!(
                "--shade-tolerance must be a finite number ≥ 0, found {}",
                self.shade_tolerance
            ));
        }
        if let Some(p) = self.shade_p {
            if !(0.0..=1.0).contains(&p) {
                return Err(format!(
                    "--shade-p must be a probability in [0, 1], found {p}"
                ));
            }
        }
        let t = self.root_tolerance;
        if !(cwisim_world::clip::MIN_TOLERANCE..=MAX_ROOT_TOLERANCE).contains(&t) {
            return Err(format!(
                "--root-tolerance must be a number between {:e} and {MAX_ROOT_TOLERANCE} (of the patch parameter), found {t}",
                cwisim_world::clip::MIN_TOLERANCE
            ));
        }
        if !(self.flatness >= MIN_FLATNESS && self.flatness.is_finite()) {
            return Err(format!(
                "--flatness must be a finite number of pixels ≥ {MIN_FLATNESS}, found {}",
                self.flatness
            ));
        }
        if let Some(a) = self.normal_angle {
            if !(MIN_NORMAL_ANGLE..=180.0).contains(&a) {
                return Err(format!(
                    "--normal-angle must be between {MIN_NORMAL_ANGLE} and 180 degrees, or off, found {a}"
                ));
            }
        }
        if !(1..=MAX_BAND).contains(&self.band) {
            return Err(format!(
                "--band must be 1 to {MAX_BAND} rows, found {}",
                self.band
            ));
        }
        if !(1..=MAX_SUBSCAN).contains(&self.subscan) {
            return Err(format!(
                "--subscan must be 1 to {MAX_SUBSCAN} sub-scanlines per row, found {}",
                self.subscan
            ));
        }
        if self.shade_contrast.is_nan() || self.shade_contrast < 0.0 {
            return Err(format!(
                "--shade-contrast must be a number ≥ 0 (inf: never force), found {}",
                self.shade_contrast
            ));
        }
        Ok(())
    }
}

/// The command line's flags that are keyword arguments in Python but not drawing
/// settings: `--max-error` is `max_error=`.
const KEYWORD_FLAGS: &[&str] = &[
    "renderer",
    "renderers",
    "numeric",
    "timing",
    "machine",
    "threads",
    "max-error",
    "overflow",
    "phases",
    "repeat",
];

/// A message of the command line's, spoken to a caller of keyword arguments (the Python
/// package): each flag that is a keyword there becomes it, `--samples` → `samples=`, and
/// a value the flag takes right after it is written as Python would pass it:
/// `--shading phong` → `shading="phong"`, `--size 640x480` → `size=(640, 480)`,
/// `--shadows on` → `shadows=True`, `--samples 2` → `samples=2`. Other flags (the
/// command line's own, `--csv`) stay as they are, and so does a command quoted whole
/// (`` `cwisim render --renderer refine` ``).
pub fn keyword_spelling(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for (k, part) in text.split('`').enumerate() {
        if k > 0 {
            out.push('`');
        }
        let quoted_command = k % 2 == 1 && part.starts_with("cwisim ");
        if quoted_command {
            out.push_str(part);
        } else {
            out.push_str(&flags_as_keywords(part));
        }
    }
    out
}

/// [`keyword_spelling`] of text that quotes no command.
fn flags_as_keywords(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("--") {
        let before_ok = rest[..at]
            .chars()
            .next_back()
            .or_else(|| out.chars().next_back())
            .is_none_or(|c| !(c.is_alphanumeric() || c == '-' || c == '_'));
        out.push_str(&rest[..at]);
        rest = &rest[at..];
        let name_len = rest[2..]
            .find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'))
            .unwrap_or(rest.len() - 2);
        let name = rest[2..2 + name_len].trim_end_matches('-');
        let setting = Setting::of_flag(&format!("--{name}"));
        if !before_ok || name.is_empty() || (setting.is_none() && !KEYWORD_FLAGS.contains(&name)) {
            out.push_str("--");
            rest = &rest[2..];
            continue;
        }
        rest = &rest[2 + name.len()..];
        out.push_str(&name.replace('-', "_"));
        out.push('=');
        // the value after it, if it is one the flag takes
        let Some(after) = rest.strip_prefix(' ') else {
            continue;
        };
        let token_len = after
            .find(|c: char| c.is_whitespace() || c == ')' || c == '(')
            .unwrap_or(after.len());
        let token = after[..token_len].trim_end_matches([',', ';', ':', '.']);
        if token.is_empty() {
            continue;
        }
        let numeral = token.parse::<f64>().is_ok()
            || token
                .chars()
                .all(|c| c.is_ascii_digit() || c == '.' || c == '/');
        let takes = match setting {
            Some(s) => s.set(&mut Settings::default(), token).is_ok(),
            None => {
                numeral
                    || (name == "renderer" || name == "renderers")
                        && crate::registry::REGISTRY.iter().any(|e| e.name == token)
                    || name == "numeric" && token.parse::<cwisim_xproc::Numeric>().is_ok()
                    || matches!(
                        (name, token),
                        ("timing", "fast" | "stepped") | ("overflow", "saturate" | "wrap")
                    )
            }
        };
        if !takes {
            continue;
        }
        let value = match (setting, token) {
            (Some(Setting::Shadows), "on") | (Some(Setting::MergeSubscanlines), "true") => {
                "True".to_string()
            }
            (Some(Setting::Shadows), "off") | (Some(Setting::MergeSubscanlines), "false") => {
                "False".to_string()
            }
            (Some(Setting::Size), _) if token.split_once('x').is_some() => {
                let (w, h) = token.split_once('x').unwrap_or_default();
                format!("({w}, {h})")
            }
            _ if numeral => token.to_string(),
            _ => format!("\"{token}\""),
        };
        out.push_str(&value);
        rest = &after[token.len()..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_speak_in_keywords() {
        assert_eq!(
            keyword_spelling(
                "--samples is not used by vanrij (--samples is for woo-chall, sbuffer, bsp)"
            ),
            "samples= is not used by vanrij (samples= is for woo-chall, sbuffer, bsp)"
        );
        assert_eq!(
            keyword_spelling(
                "--eval0-tolerance is used with --visibility eval0 and --shading gouraud only"
            ),
            "eval0_tolerance= is used with visibility=\"eval0\" and shading=\"gouraud\" only"
        );
        assert_eq!(
            keyword_spelling("--size 60000x60000: the image would hold"),
            "size=(60000, 60000): the image would hold"
        );
        assert_eq!(
            keyword_spelling("--merge-subscanlines is used with --samples 2 or more"),
            "merge_subscanlines= is used with samples=2 or more"
        );
        assert_eq!(
            keyword_spelling("use --renderer vanrij; --shadows off; --csv out.csv, a-- b"),
            "use renderer=\"vanrij\"; shadows=False; --csv out.csv, a-- b"
        );
        assert_eq!(keyword_spelling("nothing to change"), "nothing to change");
        // a command quoted whole is the command line's, as written
        assert_eq!(
            keyword_spelling("use `--samples 4`; `cwisim render --renderer refine` prints it"),
            "use `samples=4`; `cwisim render --renderer refine` prints it"
        );
    }

    #[test]
    fn sizes_parse_print_and_refuse() {
        let s: Size = "640x480".parse().unwrap();
        assert_eq!(
            s,
            Size {
                width: 640,
                height: 480
            }
        );
        assert_eq!(s.to_string().parse::<Size>(), Ok(s));
        assert!("640".parse::<Size>().unwrap_err().contains("WIDTHxHEIGHT"));
        assert!("0x4".parse::<Size>().unwrap_err().contains("at least"));
        assert!("-3x4".parse::<Size>().is_err());
    }

    #[test]
    fn barkan_gordon_modes_parse_and_print() {
        for m in SbufferMode::ALL {
            assert_eq!(m.to_string().parse::<SbufferMode>(), Ok(*m));
        }
        for o in BspOrder::ALL {
            assert_eq!(o.to_string().parse::<BspOrder>(), Ok(*o));
        }
        for u in Unset::ALL {
            assert_eq!(u.to_string().parse::<Unset>(), Ok(*u));
        }
        assert_eq!(
            "sideways".parse::<BspOrder>().unwrap_err(),
            "unknown BSP order `sideways`; expected back-to-front or front-to-back"
        );
    }

    #[test]
    fn thresholds_parse_print_and_refuse() {
        for (text, t) in [
            ("all", Threshold::All),
            ("NONE", Threshold::None),
            ("0.25", Threshold::Above(0.25)),
            ("0", Threshold::Above(0.0)),
        ] {
            assert_eq!(text.parse::<Threshold>(), Ok(t));
            assert_eq!(t.to_string().parse::<Threshold>(), Ok(t));
        }
        for bad in ["-1", "nan", "inf", "lots", ""] {
            assert!(bad
                .parse::<Threshold>()
                .unwrap_err()
                .contains("`all`, `none`"));
        }
        assert!(Threshold::All.passes(0.0));
        assert!(!Threshold::None.passes(1e300));
        assert!(Threshold::Above(0.5).passes(0.6));
        assert!(!Threshold::Above(0.5).passes(0.5));
        assert!(Threshold::Above(0.5).admits(Some(0.5)));
        assert!(!Threshold::Above(0.5).admits(Some(0.6)));
        assert!(!Threshold::Above(180.0).admits(None));
        assert!(Threshold::All.admits(None));
        assert!(!Threshold::None.admits(Some(0.0)));
        let wide = Settings {
            phong_angle: Threshold::Above(181.0),
            ..Settings::default()
        };
        assert!(wide.check().unwrap_err().contains("--phong-angle"));
    }

    #[test]
    fn settings_are_named_by_their_flags() {
        for s in Setting::ALL {
            assert_eq!(Setting::of_flag(s.flag()), Some(s));
        }
        assert_eq!(Setting::of_flag("--renderer"), None);
        let phong = Settings {
            shading: Shading::Phong,
            ..Settings::default()
        };
        assert_eq!(Setting::ShadeTolerance.idle_under(&phong), None);
        assert_eq!(
            Setting::Aa.idle_under(&phong).map(|(by, _)| by),
            Some(Setting::Shading)
        );
        assert!(Setting::Aa.idle_under(&Settings::default()).is_none());
    }

    #[test]
    fn tolerances_are_checked() {
        assert_eq!(Settings::default().check(), Ok(()));
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            let s = Settings {
                eval0_tolerance: bad,
                ..Settings::default()
            };
            assert!(s.check().unwrap_err().contains("--eval0-tolerance"));
        }
        for bad in [0.0, 1e-13, 2.0, f64::NAN] {
            let s = Settings {
                root_tolerance: bad,
                ..Settings::default()
            };
            assert!(s.check().unwrap_err().contains("--root-tolerance"));
        }
        for bad in [0.0, -1.0, f64::INFINITY, f64::NAN] {
            let s = Settings {
                flatness: bad,
                ..Settings::default()
            };
            assert!(s.check().unwrap_err().contains("--flatness"));
        }
        for (band, subscan, flag) in [
            (0, 1, "--band"),
            (5000, 1, "--band"),
            (4, 0, "--subscan"),
            (4, 65, "--subscan"),
        ] {
            let s = Settings {
                band,
                subscan,
                ..Settings::default()
            };
            assert!(s.check().unwrap_err().contains(flag));
        }
    }
}
