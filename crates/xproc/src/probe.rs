//! Watching the array cycle by cycle: the cycle-stepped engine reports what happens on
//! the bus and in chosen processors to a [`Probe`] (`cwisim history`, `cwisim vcd`),
//! from the start of the trace or from a scanline the fast engine ran up to
//! ([`Probe::resume`]).

use cwisim_isa::Instruction;

/// One X-processor's registers and flags, as `f64` (docs/ISA.md).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProcessorState {
    /// Accumulator, per channel.
    pub acc: Vec<f64>,
    /// Preload registers `I`, `dI`, `ddI`, per channel.
    pub reg: [Vec<f64>; 3],
    /// Whether each preload register holds an unconsumed value.
    pub has: [bool; 3],
    /// Claimed by `Eval0` until `Refresh`.
    pub locked: bool,
    /// Masked by `Dis` for the next Eval.
    pub masked: bool,
    /// This processor's `Acc_mode` flag.
    pub negative_enabled: bool,
}

/// Receives events from [`crate::stepped::SteppedEngine`]. Every method has an empty
/// default; `watches` says which processors to report visits for.
pub trait Probe {
    /// Whether to report tokens visiting processor `p`.
    fn watches(&self, _p: usize) -> bool {
        false
    }
    /// The bus starts issuing instruction number `index` (0-based in the trace), which
    /// belongs to scanline `line`, at `cycle`.
    fn issue(&mut self, _cycle: u64, _index: u64, _line: u64, _instr: &Instruction) {}
    /// The token of instruction `index` enters processor 0 at `cycle`.
    fn enter(&mut self, _cycle: u64, _index: u64) {}
    /// The token of instruction `index` (of scanline `line`) arrives at watched processor
    /// `p` at `cycle` and acts there, taking it from `before` to `after`. `addressed` is
    /// true when `p` is among the processors the instruction names (its range, its
    /// periodic set, or — for `Acc_mode` and `Refresh` — every processor).
    #[allow(clippy::too_many_arguments)]
    fn visit(
        &mut self,
        _cycle: u64,
        _p: usize,
        _index: u64,
        _line: u64,
        _instr: &Instruction,
        _addressed: bool,
        _before: &ProcessorState,
        _after: &ProcessorState,
    ) {
    }
    /// Scanline `line` left the last processor at `cycle`.
    fn line_ready(&mut self, _cycle: u64, _line: u64) {}
    /// The engine resumes from the fast engine's state between scanlines
    /// ([`crate::stepped::SteppedEngine::resume`], [`crate::replay_probed_from`]), before
    /// any other event: from here on, every event of scanline `line` and later is
    /// reported exactly as a stepped run from the start of the trace reports it, and none
    /// of an earlier scanline. `cycle` is when the last instruction before `line` entered
    /// the chain; `watched` holds each watched processor (in order) with the registers
    /// and flags it has once every earlier token has passed it — what the first token of
    /// scanline `line` finds there.
    fn resume(&mut self, _cycle: u64, _line: u64, _watched: &[(usize, ProcessorState)]) {}
}

/// A probe that watches nothing.
pub struct NoProbe;

impl Probe for NoProbe {}
