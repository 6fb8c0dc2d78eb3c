//! # cwisim-host — the `cwisim` command-line tool
//!
//! The host side of the simulator: it renders scenes (through `cwisim-render`'s renderers),
//! reads trace files (`cwisim-isa`), replays them on the simulated X-processor array
//! (`cwisim-xproc`), and writes what the array shifted out as a PNG picture or an exact
//! NumPy array, with per-run statistics in text or JSON.
//!
//! * [`cli`] — the `cwisim` command line (`run`, `render`, `emit`, `scenes`, `renderers`, `tradeoff`,
//!   `fit`, `convert`, `machine`, and the study tools `stats`, `history`, `vcd`, `diff`, `dump`) and
//!   [`cli::run_cli`], which runs it in-process on any output streams.
//! * [`draw`] — `--renderer`, `--shading`, `--aa`, `--visibility`, `--size`: the flattened
//!   argument group that reads a SCENE and builds its renderer (`cwisim-render`).
//! * [`summary`] — what `cwisim render` prints: every stage's figures and wall time.
//! * [`cost_args`] — `--cost-image` and `--cost-npy`, the cost outputs of `run` and
//!   `render` (the counting and drawing are `cwisim-study`'s).
//! * [`commands`] — one module per subcommand.
//! * [`demo`] — the embedded demo trace `cwisim run` replays when given no file.
//! * [`output`] — NumPy `.npy` and PNG encoding of an [`Image`](cwisim_xproc::Image).
//! * [`report`] — the human statistics summary and the `--stats-json` document.
//! * [`files`] — writing outputs all-or-nothing, and telling whether two paths are one file.
//! * [`progress`] — the progress bars `run` and `render` show on a terminal.
//! * [`range`] — the one range syntax for `--lines` and `--frames`.
//! * [`error`] — [`CliError`], every way a command can fail, with its exit code.
//!
//! ```no_run
//! let mut out = Vec::new();
//! let mut err = Vec::new();
//! let code = cwisim_host::cli::run_cli(["cwisim", "run", "t.cwt", "--npy", "t.npy"].map(Into::into), &mut out, &mut err);
//! assert_eq!(code, 0);
//! ```

#![warn(missing_docs)]

pub mod cli;
pub mod collect;
pub mod commands;
pub mod cost_args;
pub mod demo;
pub mod draw;
pub mod error;
pub mod files;
pub mod input;
pub mod output;
pub mod progress;
pub mod range;
pub mod report;
pub mod summary;

pub use error::CliError;
