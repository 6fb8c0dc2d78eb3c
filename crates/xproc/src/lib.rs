//! # cwisim-xproc — the CWI X-processor array
//!
//! A one-dimensional array of X-processors, one per pixel column, that executes the
//! scanline commands of `cwisim-isa`: it interpolates by forward differencing,
//! accumulates, and shifts out one scanline per `Refresh`.
//!
//! * Exact semantics (`docs/ISA.md`): preload registers, `Eval0` locks, `Dis` masks,
//!   `Acc_mode`, all per processor and channel. The register type is a parameter
//!   ([`Sample`]); `f64` is the reference.
//! * Numeric formats ([`Numeric`]: `f64`, `f32`, fixed point with a format per
//!   register): [`run_numeric`], [`replay_numeric`], [`EngineWriter::with_numeric`] run
//!   the array with narrower registers, bit-exact with what the hardware's adders do,
//!   count overflows, and hand scanlines out as `f64`; [`error_bound`] gives the
//!   fixed-point error analytically (`docs/ACCURACY.md`).
//! * Cycle-level timing (`docs/TIMING.md`) from an explicit [`Machine`] model: an
//!   instruction bus feeding a systolic chain, one processor per hop, and a display that
//!   takes one scanline per line period. Two implementations: [`Timing::Stepped`]
//!   advances every processor every cycle; [`Timing::Fast`] computes the same scanlines
//!   and the same cycle of every event in closed form, with cost proportional to the work
//!   in the trace.
//! * Stepping only a window ([`replay_probed_from`]): the fast engine runs the scanlines
//!   before it and hands its state over to the stepped engine, which reports every event
//!   of the window to a [`Probe`] as a stepped run from the start does.
//! * Per-scanline statistics ([`RunStats`]): instructions by opcode, bus and stall
//!   cycles, processor updates, readiness against the display deadline.
//!
//! ```
//! use cwisim_isa::{Instruction, Intensity, TraceHeader};
//! use cwisim_xproc::{run, Machine, Timing};
//! let h = TraceHeader::new(8, 1, 1).unwrap();
//! let trace = [
//!     Instruction::eval2(2, 4, Intensity::grey(0.5), Intensity::grey(0.125)),
//!     Instruction::refresh(),
//! ];
//! let (image, stats) = run::<f64>(&h, &trace, &Machine::default(), Timing::Fast).unwrap();
//! assert_eq!(image.data, [0.0, 0.0, 0.5, 0.625, 0.75, 0.875, 0.0, 0.0]);
//! assert_eq!(stats.totals.lines, 1);
//! ```

#![warn(missing_docs)]

pub mod arith;
pub mod band;
mod cell;
mod clock;
pub mod engine;
pub mod fast;
pub mod feed;
mod lanes;
pub mod machine;
pub mod numeric;
pub mod output;
pub mod probe;
mod processors;
pub mod sample;
pub mod stats;
pub mod stepped;
pub mod visits;
pub mod window;

pub use arith::{Arith, F32Arith, FixedArith, Native};
pub use band::{Band, BandArray, OpenScanline};
pub use engine::{
    engine, numeric_engine, replay, replay_numeric, replay_probed, replay_probed_from,
    replay_probed_numeric, replay_streaming, run, run_numeric, Engine, ReplayError, Timing,
};
pub use feed::EngineWriter;
pub use machine::{Machine, MachineError, OpcodeCycles, Timeline};
pub use numeric::{
    error_bound, wave_closed_form, FixedFormat, Numeric, NumericError, Overflow, Register, Q,
};
pub use output::{Image, ImageLimit, ImageSink, LineOut, LineSink, NullSink};
pub use probe::{NoProbe, Probe, ProcessorState};
pub use sample::Sample;
pub use stats::{LineRecords, LineStats, OpcodeCounts, RunStats, Totals};
pub use visits::replay_visits_numeric;
pub use window::{Handover, StepFrom};
