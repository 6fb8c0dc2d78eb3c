//! # cwisim-study — studying what the array does, without a command line
//!
//! The measuring and drawing behind `cwisim`'s study commands, as a library (no clap, no
//! files: callers choose where results go):
//!
//! * [`cost`] — cost maps: per pixel, how many instructions addressed it on its scanline,
//!   counted from the stream alone; their heat maps and `.npy` form.
//! * [`plot`] — PNG plots with an embedded font (the same bytes on every machine), and the
//!   stats chart: bus cycles per scanline by opcode group against the line period.
//! * [`tradeoff`] — one scene over a grid of renderers and settings, each measured
//!   against the exact image, with the Pareto front; [`tradeoff_plot`] draws it.
//! * [`refine`] — Bergman et al.'s adaptive refinement measured phase by phase against
//!   the full-quality image and the naive sequence; [`refine_report`] its table, CSV and
//!   sweeps, [`refine_plot`] its chart.
//! * [`fit`] — the narrowest fixed-point registers within an error budget.
//! * [`history`] — one pixel's history: every instruction that reached it on a scanline,
//!   registers before and after; [`vcd`] — a scanline's per-cycle waveform as a Value
//!   Change Dump; both from the cycle-stepped engine's probe. [`until`] ends a trace
//!   after a given scanline.
//! * [`inspect`] — one frame as one self-contained HTML page: the image with overlays, the
//!   scanline timeline and disassembly, every pixel history of a window.
//! * [`error`] — [`StudyError`].

#![warn(missing_docs)]

pub mod cost;
pub mod error;
pub mod fit;
pub mod history;
pub mod inspect;
pub mod plot;
pub mod refine;
pub mod refine_ids;
pub mod refine_plot;
pub mod refine_report;
pub mod tradeoff;
pub mod tradeoff_plot;
pub mod until;
pub mod vcd;

pub use error::StudyError;
