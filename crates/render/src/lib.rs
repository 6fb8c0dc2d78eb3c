//! # cwisim-render — one interface for every renderer
//!
//! In the CWI architecture a Y-processor program turns a scene into scanline
//! instructions for the X-processor array. This crate is where such programs plug in:
//!
//! * [`renderer`] — the [`Renderer`] trait (name, header, frames, a [`FramePlan`] per
//!   frame from which any band of rows is emitted into any `TraceWrite`) and
//!   [`Counters`], a renderer's own figures by name.
//! * [`registry`] — the renderers by name ([`REGISTRY`]); adding one is its module plus
//!   one line there.
//! * [`pipeline`] — [`render`]: a renderer's frames, in bands on threads, fed to the
//!   simulated array ([`ArrayConfig`]) in batches of whole scanlines, byte-identical at any thread
//!   count, with the renderer's and the array's wall time; [`emit`](fn@emit): the stream
//!   alone, into a trace.
//! * [`source`] — which scene ([`Source`]: a file or an embedded name) and reading it.
//! * [`draw`](mod@draw) — a renderer by name built for a scene ([`draw::draw`]), the settings given
//!   checked against what it reads: what every face of cwisim (the CLI, Python) calls.
//! * [`settings`] — how to draw ([`Settings`]), in plain types.
//! * [`prepare`] — screen-space polygons from any scene ([`PolygonScene`]), what polygon
//!   renderers start from.
//! * [`phong`] — Phong shading through the array: every pixel lit on the host, each
//!   trapezium row sent through the span fitter (`vanrij --shading phong`).
//! * [`span`] — the span fitter: per-pixel targets over a run sent as the fewest
//!   `Eval1`/`Eval2`/`Eval3` pieces within a tolerance, for renderers that shade per pixel.
//! * [`subsample`] — the sub-scanline sampler: an `l × l` grid per pixel (centres, or the
//!   shared corner grid), positions and weights, for every renderer that supersamples.
//! * [`vanrij`] — van Rij's DO_FILL (`cwisim-ypipe`), the first renderer and the default.
//! * [`woochall`] — Woo & Chall's point-sampled scanline visibility (`woo-chall`).
//! * [`cp`] — Barkan & Gordon's critical-points scan conversion (`DETCR`, `MOVEUP`,
//!   `POLINE`), usable alone; [`sbuffer`] — their one-scanline depth buffer (`sbuffer`);
//!   [`bsp`] — BSP trees displayed in scanline order (`bsp`).
//! * [`nishita`] — Nishita, Kaneda & Nakamae's Bézier patches scan-converted directly
//!   (`nishita`): subpatches per band, Bézier clipping at every row line.
//!
//! ```
//! use cwisim_render::{registry, render, ArrayConfig, Settings, Source, Taps};
//! use cwisim_xproc::ImageSink;
//!
//! let source = Source::resolve(Some("fig25".as_ref())).unwrap();
//! let settings = Settings::default();
//! let loaded = source.load_for(&settings).unwrap();
//! let renderer = (registry::find("vanrij").unwrap().build)(loaded, &settings).unwrap();
//! let h = renderer.header();
//! let mut image = ImageSink::new(h.width as usize, h.channel_count(), ImageSink::DEFAULT_LIMIT_BYTES);
//! let done = render(&*renderer, &ArrayConfig::default(), 1, &mut image, Taps::default()).unwrap();
//! assert_eq!(done.stats.totals.frames, 1);
//! assert!(done.counters.get("trapezia").unwrap() > 0);
//! ```

#![warn(missing_docs)]

pub mod bsp;
pub mod cp;
pub mod cpbench;
pub mod draw;
pub mod error;
pub mod nishita;
pub mod phong;
pub mod pipeline;
pub mod prepare;
pub mod refine;
pub mod registry;
pub mod renderer;
pub mod sbuffer;
pub mod settings;
pub mod source;
pub mod span;
pub mod subsample;
pub mod summary;
pub mod vanrij;
pub mod woochall;

pub use error::{NonFinite, RenderError};
pub use pipeline::{emit, render, ArrayConfig, Rendered, Taps};
pub use prepare::PolygonScene;
pub use registry::{find, Entry, DEFAULT_RENDERER, REGISTRY};
pub use renderer::{Counters, FramePlan, Renderer};
pub use settings::{Settings, Size};
pub use source::{LoadedScene, Source, DEFAULT_SCENE};
