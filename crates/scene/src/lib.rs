//! # cwisim-scene — what to draw, shared by every renderer
//!
//! The ground floor under the renderers: the scene *files* and the vocabulary they share.
//!
//! * [`screen`] — screen scenes (`"kind": "screen"`): polygons already in screen space,
//!   one intensity vector per vertex and optionally a depth per vertex (smaller is
//!   nearer, affine in screen space), so that visibility renderers run on 2D test scenes.
//! * [`error`] — [`SceneError`]: every fault names the file, the line and column, the
//!   JSON path (`polygons[3].intensity[1]`), what was expected and what was found;
//!   [`read_kind`], [`locate_error`] and [`json_error`] are what every reader of a scene
//!   kind builds on (world scenes in `cwisim-world` too), so that all errors look alike.
//! * [`locate`] — a JSON path located in the text.
//! * [`packed`] — [`PackedPolygons`]: many polygons held flat, a few heap blocks for all.
//! * [`predicates`] — exact orientation, segment intersection, polygon simplicity.
//! * [`settings`] — [`Shading`] and [`Antialias`], the drawing settings every renderer
//!   and command names the same way.
//! * [`budget`] — the memory, output and thread budgets every command works within
//!   (`CWISIM_MAX_MEMORY`, `CWISIM_MAX_OUTPUT`), checked before allocating.
//! * [`grid`] — a generated tessellated surface (`N × N` warped quads, every edge
//!   shared), the benchmarks' scene.
//!
//! The limits are declared here once, from `cwisim-isa`'s trace header: a scene is
//! drawn into a trace, so it can be no larger than a trace can carry.
//!
//! Coordinates: x grows to the right, y downward; pixel column `i` covers `[i, i+1)`,
//! pixel row `j` covers `[j, j+1)`, and row 0 is the first scanline output.
//!
//! ```
//! use cwisim_scene::{parse_scene, Scene};
//! let text = r#"{"kind": "screen", "width": 4, "height": 3, "channels": 1,
//!   "polygons": [{"vertices": [[0, 0], [4, 0], [0, 3]], "intensity": [[1], [0], [0]]}]}"#;
//! let Scene::Screen(s) = parse_scene(text).unwrap();
//! assert_eq!((s.width, s.height, s.polygons.len()), (4, 3, 1));
//! assert_eq!(parse_scene(&s.to_json()).unwrap(), Scene::Screen(s));
//!
//! let err = parse_scene(r#"{"kind": "solid"}"#).unwrap_err();
//! assert_eq!(err.to_string(), r#"1:10: kind: unknown scene kind "solid"; expected "screen""#);
//! ```

#![warn(missing_docs)]

pub mod budget;
pub mod error;
pub mod grid;
pub mod locate;
pub mod packed;
pub mod predicates;
pub mod screen;
pub mod settings;

pub use error::{describe_json, json_error, locate_error, read_kind, SceneError, SceneErrorKind};
pub use packed::PackedPolygons;
pub use screen::{
    check_intensity, load_scene, parse_scene, read_scene_text, Polygon, Scene, ScreenScene,
    VertexIntensity,
};
pub use settings::{Antialias, Shading};

/// The scene kinds this crate reads, as the `kind` key names them.
pub const SCENE_KINDS: &[&str] = &["screen"];
/// The widest image, and the tallest (pixels): what a trace header can carry.
pub const MAX_SIDE: u32 = cwisim_isa::MAX_WIDTH;
const _: () = assert!(cwisim_isa::MAX_WIDTH == cwisim_isa::MAX_LINES);
/// The most channels per intensity: what an instruction can carry.
pub const MAX_CHANNELS: u8 = cwisim_isa::MAX_CHANNELS as u8;
/// The most values (`width × height × channels`) an image may hold: 2^28.
pub const MAX_VALUES: u64 = 1 << 28;
/// The largest coordinate magnitude accepted. At 1e15 the spacing of `f64` is 0.125
/// pixel; beyond it a coordinate can no longer resolve a pixel.
pub const MAX_COORDINATE: f64 = 1e15;
/// The largest intensity magnitude accepted (per vertex, per channel; world scenes hold
/// their ambient, light and material terms to it too). Intensities are nominally in
/// `[0, 1]`; the limit leaves room for high dynamic range while every renderer's
/// arithmetic on intensities — flat means, coverage × intensity, forward differences over
/// a 65 536-pixel row, lighting sums — stays far inside `f64` (the bound argument:
/// `docs/LIMITS.md`, "Intensities").
pub const MAX_INTENSITY: f64 = 1e12;

/// A channel vector: up to [`MAX_CHANNELS`] values, the unused ones 0.
pub type Vector = [f64; cwisim_isa::MAX_CHANNELS];

/// The vector whose first `channels` entries are `f(c)` (the rest 0).
#[inline]
pub fn vector(channels: usize, f: impl Fn(usize) -> f64) -> Vector {
    std::array::from_fn(|c| if c < channels { f(c) } else { 0.0 })
}
