//! The visits a history shows, without stepping: the fast engine runs the trace (its
//! scanlines, its statistics), and beside it the stepped engine's processors
//! (`Processor` of `cell.rs`) take each instruction's token, in trace order, over the
//! processors it reaches (and the masked ones a passing Eval unmasks), reporting to a
//! [`Probe`] the events of the scanlines asked for with their cycles in closed form
//! ([`replay_visits_numeric`]). What a token does in a processor is not restated here:
//! it is `Processor::act` (`cell.rs`), the one the stepped engine calls.
//!
//! It rests on what makes the stepped engine's hand-over sound
//! ([`crate::stepped::SteppedEngine::resume`]): tokens never overtake, each enters the
//! chain when its issue is done and the token before has moved on a hop (`docs/TIMING.md`,
//! [`crate::clock`]), and moves one processor a hop, so the token of an instruction that
//! entered at cycle `e` reaches processor `p` at `e + p · hop`, and each processor sees the
//! tokens in trace order. The processor's registers before and after a token are then
//! those of executing the instructions in order. `tests/visits.rs` holds every event to the
//! stepped engine's, cycle for cycle and bit for bit.

use crate::arith::{Arith, F32Arith, FixedArith, Native};
use crate::cell::{operands, Processor, Wave};
use crate::engine::{Engine, ReplayError};
use crate::fast::FastEngine;
use crate::machine::{Machine, MachineError, Timeline};
use crate::numeric::Numeric;
use crate::output::LineSink;
use crate::probe::{Probe, ProcessorState};
use crate::stats::{RunStats, Work};
use cwisim_isa::{Instruction, Opcode, TraceRead};

/// Instructions between progress reports.
const PROGRESS_EVERY: u64 = 4096;

/// The latest cycle a report starts from: as [`crate::replay_probed_from`], which steps
/// from there, refuses a hand-over at or beyond it, so does this.
const LATEST_START: u64 = 1 << 63;

/// Replays `reader` on the fast engine with registers of the format `numeric` (the
/// scanlines to `sink`, the statistics returned: those of [`crate::replay_numeric`]) and
/// reports to `probe` the events of scanline `first` and later that
/// [`crate::replay_probed_numeric`] with [`crate::StepFrom::Scanline`]`(first)` reports,
/// computed without stepping cycles, in a different order and leaving some out:
///
/// * [`Probe::resume`] first, as the stepped engine's hand-over tells it (the cycle the
///   last instruction before scanline `first` entered the chain, the watched processors'
///   states then), once the reader reaches scanline `first` (not at all if the trace
///   outputs fewer scanlines, where the stepped engine reports the instructions after
///   its last `Refresh`);
/// * then per instruction, in trace order: [`Probe::issue`], [`Probe::enter`], the
///   [`Probe::visit`]s of its token to watched processors, and for a `Refresh`
///   [`Probe::line_ready`];
/// * only the visits `cwisim history` shows: those that address the processor or leave
///   its [`ProcessorState`] different (`!=`: a processor holding a `NaN` is different from
///   itself); a token that passes a watched processor and changes nothing is not reported.
///   To each watched processor the visits come in the same order, with the same cycles
///   and states, as the stepped engine's.
///
/// The watched processors are asked of `probe` once, before the first instruction.
/// `progress` is called with the bytes read every few thousand instructions, and at the
/// end. A scanline `first` whose first instruction starts after cycle 2⁶³ is refused as
/// [`crate::replay_probed_from`] refuses it.
pub fn replay_visits_numeric(
    reader: &mut dyn TraceRead,
    machine: &Machine,
    numeric: &Numeric,
    first: u64,
    probe: &mut dyn Probe,
    sink: &mut dyn LineSink<f64>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let t = machine.timeline(reader.header())?;
    match numeric {
        Numeric::F64 => visits(
            reader,
            t,
            Native::<f64>::new(),
            first,
            probe,
            sink,
            progress,
        ),
        Numeric::F32 => visits(reader, t, F32Arith, first, probe, sink, progress),
        Numeric::Fixed(f) => {
            let arith = FixedArith::new(f).map_err(|e| MachineError::Invalid {
                name: "numeric".into(),
                message: e.message().to_string(),
            })?;
            visits(reader, t, arith, first, probe, sink, progress)
        }
    }
}

/// The processors, executed one instruction at a time over what it reaches.
struct Model<A: Arith> {
    arith: A,
    channels: usize,
    procs: Vec<Processor<A::Reg>>,
    /// Processors masked by a `Dis` since the last `Eval` (which unmasks every one).
    masked: Vec<usize>,
    watched: Vec<bool>,
    watched_list: Vec<usize>,
    /// Watched processors holding a `NaN` (every token's visit shows there).
    nan: Vec<usize>,
    /// Room for an instruction's visits and a state after, kept from one to the next.
    shown: Shown,
    after: ProcessorState,
}

/// An instruction's visits shown so far, in the order made: processor, state before. The
/// states' room is kept from one instruction to the next.
#[derive(Default)]
struct Shown {
    len: usize,
    list: Vec<(usize, ProcessorState)>,
}

impl Shown {
    /// Room for one more visit.
    fn next(&mut self) -> &mut (usize, ProcessorState) {
        if self.len == self.list.len() {
            self.list.push(Default::default());
        }
        self.len += 1;
        &mut self.list[self.len - 1]
    }

    fn items(&self) -> &[(usize, ProcessorState)] {
        &self.list[..self.len]
    }
}

impl<A: Arith> Model<A> {
    fn state(&self, p: usize) -> ProcessorState {
        self.procs[p].state(&self.arith, self.channels)
    }

    /// Processor `p`'s registers as `f64`, into `s` (in the room it has).
    fn fill_state(&self, p: usize, s: &mut ProcessorState) {
        self.procs[p].fill_state(&self.arith, self.channels, s);
    }

    /// What the token of `instr`, with running values `wave`, does in processor `p`
    /// ([`Processor::act`]; its work is not counted here, the fast engine counts it).
    #[inline]
    fn act(&mut self, p: usize, instr: &Instruction, wave: &mut Wave<A::Reg>, work: &mut Work) {
        self.procs[p].act(&self.arith, self.channels, p, instr, wave, work, &mut []);
    }

    /// Executes `instr` on every processor; with `report`, tells `probe` of each shown
    /// visit to a watched processor, its token having entered the chain at `entry`.
    #[allow(clippy::too_many_arguments)]
    fn execute(
        &mut self,
        instr: &Instruction,
        index: u64,
        line: u64,
        entry: u64,
        hop: u64,
        report: bool,
        probe: &mut dyn Probe,
    ) {
        let w = self.procs.len();
        let (x, dx) = (instr.x as usize, instr.dx as usize);
        let range = x.min(w)..x.saturating_add(dx).min(w);
        // the token's running values as it enters the chain; conversion overflows and
        // work are the fast engine's to count
        let mut wave = operands(&self.arith, self.channels, instr, &mut 0);
        let mut work = Work::default();
        // the visits shown, in the order made: processor, state before
        let mut shown = std::mem::take(&mut self.shown);
        shown.len = 0;
        let touched = |m: &Self, p: usize, shown: &mut Shown| {
            if report && m.watched[p] {
                let slot = shown.next();
                slot.0 = p;
                m.fill_state(p, &mut slot.1);
            }
        };
        // Each processor the token can change is given it (`Processor::act`), in chain
        // order, once `touched` has noted its state before; the processors left out are
        // those it leaves as they are.
        let mut unmask_all = false;
        match instr.op {
            Opcode::SetI | Opcode::SetdI | Opcode::SetddI => {
                if x < w {
                    touched(self, x, &mut shown);
                    self.act(x, instr, &mut wave, &mut work);
                }
            }
            Opcode::SetPI | Opcode::SetPdI | Opcode::SetPddI => {
                let step = dx.max(1);
                let mut p = x;
                while p < w && (p == x || dx > 0) {
                    touched(self, p, &mut shown);
                    self.act(p, instr, &mut wave, &mut work);
                    p += step;
                }
            }
            Opcode::Eval0 | Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                for p in range.clone() {
                    touched(self, p, &mut shown);
                    self.act(p, instr, &mut wave, &mut work);
                }
                unmask_all = true;
            }
            Opcode::Dis => {
                for p in range.clone() {
                    touched(self, p, &mut shown);
                    let was = self.procs[p].masked;
                    self.act(p, instr, &mut wave, &mut work);
                    if !was {
                        self.masked.push(p);
                    }
                }
            }
            Opcode::AccMode | Opcode::Refresh => {
                // addresses every processor: the watched ones shown
                for k in 0..self.watched_list.len() {
                    touched(self, self.watched_list[k], &mut shown);
                }
                for p in 0..w {
                    self.act(p, instr, &mut wave, &mut work);
                }
                if instr.op == Opcode::Refresh {
                    self.masked.clear();
                }
            }
            Opcode::Nop => {}
        }
        let addressed = shown.len;
        if unmask_all {
            // the token passes every processor and unmasks it: a change where it does
            // not address it
            for k in 0..self.masked.len() {
                let p = self.masked[k];
                if self.procs[p].masked {
                    touched(self, p, &mut shown);
                    self.act(p, instr, &mut wave, &mut work);
                }
            }
            self.masked.clear();
        }
        if report {
            self.report(
                &mut shown,
                addressed,
                (index, line, entry, hop),
                instr,
                probe,
            );
        }
        self.shown = shown;
    }

    /// Tells `probe` of the visits `shown` (the first `addressed` of them addressed), and
    /// of a visit to every watched processor holding a `NaN` besides.
    fn report(
        &mut self,
        shown: &mut Shown,
        addressed: usize,
        (index, line, entry, hop): (u64, u64, u64, u64),
        instr: &Instruction,
        probe: &mut dyn Probe,
    ) {
        // a processor holding a NaN differs from itself: every token's visit shows
        for k in 0..self.nan.len() {
            let p = self.nan[k];
            if !shown.items().iter().any(|s| s.0 == p) {
                let slot = shown.next();
                slot.0 = p;
                self.fill_state(p, &mut slot.1);
            }
        }
        let mut after = std::mem::take(&mut self.after);
        for (k, (p, before)) in shown.items().iter().enumerate() {
            self.fill_state(*p, &mut after);
            let is_nan = |s: &ProcessorState| {
                s.acc
                    .iter()
                    .chain(s.reg.iter().flatten())
                    .any(|v| v.is_nan())
            };
            match (self.nan.iter().position(|q| q == p), is_nan(&after)) {
                (None, true) => self.nan.push(*p),
                (Some(i), false) => {
                    self.nan.swap_remove(i);
                }
                _ => {}
            }
            let cycle = entry + *p as u64 * hop;
            probe.visit(cycle, *p, index, line, instr, k < addressed, before, &after);
        }
        self.after = after;
    }
}

fn visits<A: Arith<Out = f64>>(
    reader: &mut dyn TraceRead,
    timeline: Timeline,
    arith: A,
    first: u64,
    probe: &mut dyn Probe,
    sink: &mut dyn LineSink<f64>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let header = *reader.header();
    let w = header.width as usize;
    let watched: Vec<bool> = (0..w).map(|p| probe.watches(p)).collect();
    let blank = Processor::blank(A::ZERO);
    let mut model = Model {
        arith: arith.clone(),
        channels: header.channel_count(),
        procs: vec![blank; w],
        masked: Vec::new(),
        watched_list: (0..w).filter(|&p| watched[p]).collect(),
        watched,
        nan: Vec::new(),
        shown: Shown::default(),
        after: ProcessorState::default(),
    };
    let hop = timeline.hop;
    let mut fast = Box::new(FastEngine::with_arith(&header, timeline.clone(), arith));
    let (mut index, mut line) = (0u64, 0u64);
    let mut last_entry: Option<u64> = None;
    let mut resumed = false;
    while let Some(instr) = reader.next_instruction()? {
        if line >= first && !resumed {
            resumed = true;
            let cycle = last_entry.unwrap_or(0);
            if cycle >= LATEST_START {
                return Err(ReplayError::Machine(MachineError::Invalid {
                    name: "line_period_cycles".into(),
                    message: format!(
                        "scanline {line} starts at cycle {cycle}, beyond what the cycle-stepped \
                         engine steps to (2^63); shorten the line period or the blanking"
                    ),
                }));
            }
            let states: Vec<(usize, ProcessorState)> = model
                .watched_list
                .iter()
                .map(|&p| (p, model.state(p)))
                .collect();
            probe.resume(cycle, line, &states);
        }
        let refresh = instr.op == Opcode::Refresh;
        let gate = if refresh {
            timeline.refresh_gate(line)
        } else {
            0
        };
        let begin = last_entry.unwrap_or(0).max(gate);
        let issued = begin.saturating_add(timeline.issue_cycles(&instr));
        let entry = issued.max(last_entry.map_or(0, |e| e.saturating_add(hop)));
        last_entry = Some(entry);
        let report = resumed;
        if report {
            probe.issue(begin, index, line, &instr);
            probe.enter(entry, index);
        }
        model.execute(&instr, index, line, entry, hop, report, probe);
        if report && refresh {
            probe.line_ready(timeline.exit(entry), line);
        }
        fast.execute(&instr, sink);
        index += 1;
        line += u64::from(refresh);
        if index.is_multiple_of(PROGRESS_EVERY) {
            progress(reader.bytes_read());
        }
    }
    if line >= first && !resumed {
        let states: Vec<(usize, ProcessorState)> = model
            .watched_list
            .iter()
            .map(|&p| (p, model.state(p)))
            .collect();
        probe.resume(last_entry.unwrap_or(0), line, &states);
    }
    progress(reader.bytes_read());
    Ok(fast.finish(sink))
}
