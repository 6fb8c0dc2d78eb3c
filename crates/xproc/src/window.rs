//! Stepping a window of scanlines: the fast engine runs the trace up to the scanlines
//! asked for and hands its state over ([`Handover`]) to the cycle-stepped engine, which
//! steps the rest with a probe ([`crate::replay_probed_from`]).
//!
//! The hand-over happens between scanlines, where the stepped engine's state is simple
//! (see [`crate::stepped::SteppedEngine::resume`]); from there the stepped engine reports
//! every event of the later scanlines, and the run's scanlines and statistics, exactly as
//! a stepped run from the start of the trace does. The property tests of
//! `tests/window.rs` hold the two to the same events, cycle for cycle.

use crate::arith::Arith;
use crate::clock::Clock;
use crate::engine::{Engine, ReplayError};
use crate::fast::FastEngine;
use crate::machine::{MachineError, Timeline};
use crate::output::LineSink;
use crate::probe::Probe;
use crate::stats::{IssueTally, Recorder, RunStats};
use crate::stepped::SteppedEngine;
use cwisim_isa::{Instruction, Opcode, TraceError, TraceHeader, TraceRead};
use std::collections::VecDeque;

/// The state of an array between two scanlines, as the fast engine hands it to the
/// cycle-stepped one ([`FastEngine::handover`], [`SteppedEngine::resume`]): what the
/// stepped engine needs to go on exactly as if it had run from the start.
pub struct Handover<A: Arith> {
    pub(crate) header: TraceHeader,
    pub(crate) timeline: Timeline,
    pub(crate) arith: A,
    /// Preload registers `I`, `dI`, `ddI`, each `width × channels`: a `Refresh` clears
    /// their flags, not their values (a probe shows them).
    pub(crate) regs: [Vec<A::Reg>; 3],
    /// Whether negative accumulation is on (`Acc_mode`).
    pub(crate) negative_enabled: bool,
    /// Scanlines output (so `Refresh` instructions issued).
    pub(crate) lines: u64,
    /// Instructions issued.
    pub(crate) instructions: u64,
    /// Cycle the last instruction entered the chain (`None` before the first).
    pub(crate) last_entry: Option<u64>,
    /// The statistics so far, every scanline before the hand-over complete.
    pub(crate) recorder: Recorder,
}

impl<A: Arith> Handover<A> {
    /// Scanlines output before the hand-over: the stepped engine goes on with scanline
    /// `lines()`.
    pub fn lines(&self) -> u64 {
        self.lines
    }

    /// Instructions executed before the hand-over: the index of the next one.
    pub fn instructions(&self) -> u64 {
        self.instructions
    }

    /// The cycle the stepped engine goes on from: the one the last instruction before
    /// the hand-over entered the chain (0 if there was none).
    pub fn cycle(&self) -> u64 {
        self.last_entry.unwrap_or(0)
    }
}

/// Which events a probed replay must report ([`crate::replay_probed_from`]): the fast
/// engine runs every scanline before them, the stepped engine the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepFrom {
    /// Every event of scanline `n` and later (`cwisim history`, `dump`, `inspect`): the
    /// stepped engine starts with scanline `n` (or at the end of a trace that outputs
    /// fewer scanlines).
    Scanline(u64),
    /// As [`Self::Scanline`], and every event of any scanline from the cycle scanline
    /// `n` starts to issue on (`cwisim vcd`: a waveform of scanline `n` shows the tokens
    /// of earlier scanlines still crossing the array). The stepped engine starts with the
    /// first scanline whose tokens may still be in the array then: at scanline `n` when
    /// the scanline before has left (a `Refresh` that waits for the display), else a
    /// scanline or a few earlier.
    Issue(u64),
}

/// The latest cycle the stepped engine goes on from: its cycle arithmetic is plain (it
/// steps one cycle at a time), and from here a few frames of the longest (2⁵⁷ cycles)
/// stay below 2⁶⁴. Only a run at the edges of the machine's ranges gets here (a line
/// period of 2⁴⁰ with 2¹⁶ blank lines: 128 frames), and a stepped run from the start never
/// would.
const LATEST_RESUME: u64 = 1 << 63;

/// Instructions between progress reports.
const PROGRESS_EVERY: u64 = 4096;

/// Reads the next instruction, calling `progress` with the bytes read every
/// [`PROGRESS_EVERY`] instructions.
fn next(
    reader: &mut dyn TraceRead,
    count: &mut u64,
    progress: &mut dyn FnMut(u64),
) -> Result<Option<Instruction>, TraceError> {
    let instr = reader.next_instruction()?;
    *count += 1;
    if count.is_multiple_of(PROGRESS_EVERY) {
        progress(reader.bytes_read());
    }
    Ok(instr)
}

/// Instructions read ahead of the fast engine: whole scanlines that may still be in the
/// array when the window starts, timed by a clock of their own.
struct Ahead {
    clock: Clock,
    /// The current scanline's instructions so far.
    tally: IssueTally,
    /// Instructions read and not yet executed.
    instrs: VecDeque<Instruction>,
    /// Per whole scanline in `instrs`: its instructions, the cycle its `Refresh` leaves
    /// the array.
    lines: VecDeque<(u64, u64)>,
    /// Scanlines read (`Refresh` instructions).
    refreshes: u64,
}

impl Ahead {
    /// Takes an instruction in; a `Refresh` ends a scanline.
    fn push(&mut self, timeline: &Timeline, instr: Instruction) {
        self.tally.count(instr.op);
        let refresh = instr.op == Opcode::Refresh;
        self.instrs.push_back(instr);
        if refresh {
            let tally = std::mem::take(&mut self.tally);
            let times = self
                .clock
                .issue(self.refreshes, &tally)
                .expect("a scanline with its Refresh");
            self.lines
                .push_back((tally.opcodes.total(), timeline.exit(times.last_entry)));
            self.refreshes += 1;
        }
    }

    /// Executes on `fast` the whole scanlines whose last token leaves the array before
    /// cycle `horizon` (all of them if `None`).
    fn release<A: Arith>(
        &mut self,
        horizon: Option<u64>,
        fast: &mut FastEngine<A>,
        sink: &mut dyn LineSink<A::Out>,
    ) {
        while let Some(&(count, exit)) = self.lines.front() {
            if horizon.is_some_and(|h| exit >= h) {
                break;
            }
            self.lines.pop_front();
            for instr in self.instrs.drain(..count as usize) {
                fast.execute(&instr, sink);
            }
        }
    }
}

/// Replays `reader` with registers of arithmetic `arith`: the fast engine up to the
/// scanlines `from` asks for, then the stepped engine with `probe` from the fast
/// engine's state (see [`crate::replay_probed_from`]).
pub(crate) fn probed<A: Arith>(
    reader: &mut dyn TraceRead,
    timeline: Timeline,
    arith: A,
    from: StepFrom,
    probe: &mut dyn Probe,
    sink: &mut dyn LineSink<A::Out>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let header = *reader.header();
    let (first, in_flight) = match from {
        StepFrom::Scanline(n) => (n, false),
        StepFrom::Issue(n) => (n, true),
    };
    let mut fast = FastEngine::with_arith(&header, timeline.clone(), arith);
    let mut ahead = Ahead {
        clock: Clock::new(&timeline),
        tally: IssueTally::default(),
        instrs: VecDeque::new(),
        lines: VecDeque::new(),
        refreshes: 0,
    };
    let mut count = 0;
    let mut start = None;
    while ahead.refreshes < first {
        let Some(instr) = next(reader, &mut count, progress)? else {
            break;
        };
        ahead.push(&timeline, instr);
        // later scanlines start to issue no earlier than the last entry
        let horizon = in_flight.then(|| ahead.clock.last_entry().unwrap_or(0));
        ahead.release(horizon, &mut fast, sink);
    }
    if ahead.refreshes == first && in_flight {
        // the window's first instruction: it starts to issue right after the last entry,
        // or, a Refresh, once the display has taken the scanline before
        if let Some(instr) = next(reader, &mut count, progress)? {
            let entry = ahead.clock.last_entry().unwrap_or(0);
            let gate = if instr.op == Opcode::Refresh {
                timeline.refresh_gate(first)
            } else {
                0
            };
            start = Some(instr);
            ahead.release(Some(entry.max(gate)), &mut fast, sink);
        }
    } else {
        // every scanline before the window to the fast engine (if the trace ended before
        // it, only the instructions after the last Refresh are left to step)
        ahead.release(None, &mut fast, sink);
    }
    let Some(state) = fast.handover() else {
        unreachable!("the fast engine stops between scanlines, and takes no bands")
    };
    if state.cycle() >= LATEST_RESUME {
        return Err(ReplayError::Machine(MachineError::Invalid {
            name: "line_period_cycles".into(),
            message: format!(
                "scanline {} starts at cycle {}, beyond what the cycle-stepped engine steps \
                 to (2^63); shorten the line period or the blanking",
                state.lines(),
                state.cycle()
            ),
        }));
    }
    let mut eng = Box::new(SteppedEngine::resume(state, probe));
    for instr in ahead.instrs.iter().chain(&start) {
        eng.execute(instr, sink);
    }
    while let Some(instr) = next(reader, &mut count, progress)? {
        eng.execute(&instr, sink);
    }
    progress(reader.bytes_read());
    Ok(eng.finish(sink))
}
