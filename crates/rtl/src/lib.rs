//! # cwisim-rtl — the X-processor as hardware
//!
//! Synthesizable Verilog of one X-processor and of an array of them, generated from the
//! one opcode table (`cwisim_isa::Opcode`) and the one fixed-point model
//! (`cwisim_xproc::FixedFormat`, `FixedArith`), with the instruction bus, the token
//! pipeline and the display's deadlines as `docs/TIMING.md` models them; co-simulated in
//! Icarus Verilog or Verilator against the cycle-stepped engine; synthesized by Yosys for
//! its area. `docs/HARDWARE.md` describes the design and the results.
//!
//! * [`Design`] — the settings: format, opcodes, width, channels, timing ([`BusTiming`]).
//! * [`verilog::design`], [`verilog::testbench`] — the Verilog text (deterministic).
//! * [`stimulus`] — a trace as the testbench's input, operands converted by the model.
//! * [`reference`] — the stepped engine's account of the same trace.
//! * [`dump`], [`compare`] — what the simulation did, and the first difference.
//! * [`cosim`] — all of it in one call, with either simulator ([`tools`] runs them).
//! * [`area`] — Yosys's `synth` statistics and a NAND2-equivalent estimate.
//! * [`fpga`] — the array in an I/O shell, placed and routed on an iCE40 by Yosys and
//!   nextpnr: its cells, the shell's apart, its maximum clock, the processors that fit.
//!
//! ```
//! use cwisim_isa::TraceHeader;
//! use cwisim_rtl::{all_opcodes, verilog, BusTiming, Design};
//! use cwisim_xproc::{Machine, Numeric};
//! let header = TraceHeader::new(8, 2, 1).unwrap();
//! let Numeric::Fixed(format) = "fixed:I=4.12,dI=2.14,ddI=1.15".parse::<Numeric>().unwrap() else {
//!     unreachable!()
//! };
//! let timing = BusTiming::new(&Machine::default(), &header).unwrap();
//! let design = Design::new(format, all_opcodes(), 8, 1, timing).unwrap();
//! let text = verilog::design(&design);
//! assert!(text.contains("module cwisim_xproc ("));
//! assert_eq!(text, verilog::design(&design)); // the same bytes every time
//! ```

#![warn(missing_docs)]

pub mod area;
pub mod compare;
pub mod cosim;
pub mod design;
pub mod dump;
pub mod error;
pub mod fpga;
pub mod reference;
pub mod stimulus;
pub mod tools;
pub mod verilog;

pub use compare::{Agreement, Mismatch};
pub use cosim::{cosimulate, cosimulate_with, CosimStage, Outcome, Simulator};
pub use design::{all_opcodes, opcodes_used, BusTiming, Design};
pub use error::RtlError;
