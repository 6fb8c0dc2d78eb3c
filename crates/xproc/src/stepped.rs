//! The cycle-stepped reference engine: advances every processor of the systolic chain
//! cycle by cycle, with the instruction bus as an explicit state machine; the cycles in
//! which nothing can happen are jumped over (`next_cycle`), so waiting for the display
//! costs a step, not a step per cycle.
//!
//! It shares nothing with the fast engine but the machine parameters and the statistics
//! bookkeeping: processors are plain structs with one flag per condition, and every
//! token (an instruction with its running forward-differencing state) visits every
//! processor, one hop at a time. What a token does in one processor is
//! `Processor::act` (`cell.rs`), the one per-processor statement of the semantics,
//! which [`crate::visits`] calls too. Obviously right, and slow: the property tests hold
//! the fast engine to it. It can also go on from the fast engine's state between scanlines
//! ([`SteppedEngine::resume`]), to step only the scanlines a study tool shows.

use crate::arith::{Arith, Native};
use crate::cell::{operands, Processor, Wave};
use crate::engine::Engine;
use crate::machine::Timeline;
use crate::output::{LineOut, LineSink};
use crate::probe::{NoProbe, Probe, ProcessorState};
use crate::sample::Sample;
use crate::stats::{LineRecords, Recorder, RunStats, Work};
use crate::window::Handover;
use cwisim_isa::{Instruction, Opcode, TraceHeader};

/// An instruction travelling along the chain.
struct Token<T, O> {
    instr: Instruction,
    /// Its number in the trace.
    index: u64,
    /// The scanline it belongs to.
    line: u64,
    /// Its value operands, converted when it entered the chain; an Eval's wave runs in
    /// them.
    wave: Wave<T>,
    /// The cycle it moves on to the next processor.
    leave_at: u64,
    /// What a `Refresh` collects as it passes.
    out: Vec<O>,
    work: Work,
}

/// What one stage of the chain holds: a token or nothing.
type Stage<A> = Option<Box<Token<<A as Arith>::Reg, <A as Arith>::Out>>>;

/// The instruction on the bus.
struct Bus {
    instr: Instruction,
    index: u64,
    line: u64,
    begin: u64,
    /// Its bus cycles.
    cost: u64,
    /// The cycle its issue is complete.
    issued_at: u64,
}

/// The cycle-stepped engine (see the module documentation), with registers of
/// arithmetic `A`.
pub struct SteppedEngine<'p, A: Arith> {
    arith: A,
    channels: usize,
    timeline: Timeline,
    recorder: Recorder,
    procs: Vec<Processor<A::Reg>>,
    /// The token in each processor's stage.
    stages: Vec<Stage<A>>,
    bus: Option<Bus>,
    /// The current cycle.
    t: u64,
    /// Whether the token moves and bus entry of cycle `t` are done.
    moved: bool,
    /// Tokens in the chain.
    in_flight: usize,
    /// Cycles stepped through (each visited once, whether or not anything happened in
    /// it): idle cycles are jumped over ([`Self::next_cycle`]), so this is at most a few
    /// per event, not the cycle count.
    steps: u64,
    /// `Refresh` instructions that have started to issue.
    refreshes_issued: u64,
    /// Scanlines that have left the array.
    lines_out: u64,
    last_exit: u64,
    /// Instructions issued so far.
    issued: u64,
    /// The first cycle a token may enter the first processor besides its being free: 0,
    /// except after a hand-over ([`Self::resume`]), where the last instruction handed
    /// over holds the first processor for a hop without being in the chain.
    free_at: u64,
    probe: &'p mut dyn Probe,
}

impl<T: Sample> SteppedEngine<'static, Native<T>> {
    /// An array of `T` registers for `header`'s width and channels, timed by `timeline`.
    pub fn new(header: &TraceHeader, timeline: Timeline) -> Self {
        SteppedEngine::with_arith(header, timeline, Native::new())
    }
}

impl<A: Arith> SteppedEngine<'static, A> {
    /// An array with registers of arithmetic `arith`.
    pub fn with_arith(header: &TraceHeader, timeline: Timeline, arith: A) -> Self {
        // NoProbe has no state; leaking one zero-sized value costs nothing.
        SteppedEngine::with_probe_arith(header, timeline, arith, Box::leak(Box::new(NoProbe)))
    }
}

impl<'p, T: Sample> SteppedEngine<'p, Native<T>> {
    /// An array of `T` registers that reports to `probe` as it steps.
    pub fn with_probe(header: &TraceHeader, timeline: Timeline, probe: &'p mut dyn Probe) -> Self {
        SteppedEngine::with_probe_arith(header, timeline, Native::new(), probe)
    }
}

impl<'p, A: Arith> SteppedEngine<'p, A> {
    /// An array with registers of arithmetic `arith` that reports to `probe` as it steps.
    pub fn with_probe_arith(
        header: &TraceHeader,
        timeline: Timeline,
        arith: A,
        probe: &'p mut dyn Probe,
    ) -> Self {
        let w = header.width as usize;
        let blank = Processor::blank(A::ZERO);
        SteppedEngine {
            arith,
            channels: header.channel_count(),
            recorder: Recorder::new(&timeline),
            timeline,
            procs: vec![blank; w],
            stages: (0..w).map(|_| None).collect(),
            bus: None,
            t: 0,
            moved: false,
            in_flight: 0,
            steps: 0,
            refreshes_issued: 0,
            lines_out: 0,
            last_exit: 0,
            issued: 0,
            free_at: 0,
            probe,
        }
    }

    /// The engine that goes on from the fast engine's state between scanlines
    /// ([`crate::fast::FastEngine::handover`]), reporting to `probe` (first
    /// [`Probe::resume`] with the watched processors' states).
    ///
    /// It gives every later event, scanline and statistic exactly as a stepped run from
    /// the start does. At the hand-over scanline `n`, the tokens of earlier scanlines
    /// may still be crossing the chain, but tokens never overtake, so each one that
    /// reaches a processor finds it as they all left it: accumulator zero, preload flags,
    /// lock and mask clear, the `Acc_mode` flag as the earlier `Acc_mode`s left it, the
    /// preload registers' values as last written. Nor do they delay anything but one: a
    /// token enters the chain at least a hop after the one before it and they all move a
    /// hop at a time, so only the last one handed over, which entered at the hand-over
    /// cycle, holds the first processor (for a hop). Their work and readiness are already in the
    /// statistics handed over; the chain starts empty, and the bus idle at the cycle that
    /// last token entered, where the stepped engine starts the next instruction.
    ///
    /// A hand-over at cycle 2⁶³ or later (only at the edges of the machine's ranges) is
    /// beyond it, and [`crate::replay_probed_from`] refuses one.
    pub fn resume(state: Handover<A>, probe: &'p mut dyn Probe) -> Self {
        let Handover {
            header,
            timeline,
            arith,
            regs,
            negative_enabled,
            lines,
            instructions,
            last_entry,
            recorder,
        } = state;
        let mut eng = SteppedEngine::with_probe_arith(&header, timeline, arith, probe);
        let c = eng.channels;
        for (p, pr) in eng.procs.iter_mut().enumerate() {
            for (slot, reg) in regs.iter().enumerate() {
                pr.reg[slot][..c].copy_from_slice(&reg[p * c..p * c + c]);
            }
            pr.negative_enabled = negative_enabled;
        }
        eng.recorder = recorder;
        eng.refreshes_issued = lines;
        eng.lines_out = lines;
        eng.issued = instructions;
        if let Some(entry) = last_entry {
            // the entry's cycle is done: tokens moved, and the bus took the entering one
            eng.t = entry;
            eng.moved = true;
            eng.free_at = entry.saturating_add(eng.timeline.hop);
            eng.last_exit = eng.timeline.exit(entry);
        }
        let watched: Vec<(usize, ProcessorState)> = (0..eng.procs.len())
            .filter(|&p| eng.probe.watches(p))
            .map(|p| (p, eng.state(p)))
            .collect();
        eng.probe.resume(eng.t, lines, &watched);
        eng
    }

    /// Moves tokens whose time in a stage is up, then lets the bus hand its instruction
    /// to the first processor if the issue is complete and the stage is free.
    fn move_tokens(&mut self, sink: &mut dyn LineSink<A::Out>) {
        let t = self.t;
        let w = self.stages.len();
        // From the last processor to the first, each token whose time is up moves on (a
        // moved token is not visited again: the search continues below it).
        let mut end = w;
        while let Some(p) = self.stages[..end]
            .iter()
            .rposition(|s| s.as_ref().is_some_and(|tok| tok.leave_at == t))
        {
            end = p;
            let mut tok = self.stages[p].take().expect("checked");
            if p + 1 == w {
                self.in_flight -= 1;
                self.exit(*tok, sink);
            } else {
                assert!(self.stages[p + 1].is_none(), "two tokens in one processor");
                self.apply(p + 1, &mut tok);
                tok.leave_at = t.saturating_add(self.timeline.hop);
                self.stages[p + 1] = Some(tok);
            }
        }
        if self.stages[0].is_none()
            && t >= self.free_at
            && self.bus.as_ref().is_some_and(|b| b.issued_at <= t)
        {
            let bus = self.bus.take().expect("checked");
            self.probe.enter(t, bus.index);
            // the opcode's cost, also where `issued_at` saturated
            let cost = bus.cost;
            self.recorder
                .issue(bus.line, bus.instr.op, bus.begin, t, cost);
            let mut work = Work::default();
            let wave = operands(&self.arith, self.channels, &bus.instr, &mut work.overflows);
            let mut tok = Box::new(Token {
                wave,
                out: if bus.instr.op == Opcode::Refresh {
                    vec![<A::Out as Sample>::ZERO; w * self.channels]
                } else {
                    Vec::new()
                },
                instr: bus.instr,
                index: bus.index,
                line: bus.line,
                leave_at: t.saturating_add(self.timeline.hop),
                work,
            });
            self.apply(0, &mut tok);
            self.stages[0] = Some(tok);
            self.in_flight += 1;
        }
        self.moved = true;
    }

    /// The clock advances to the next cycle at which anything can happen: the earliest
    /// of a token's move, the bus's instruction entering the chain, and (`issue`, when
    /// the bus is free) the cycle the next instruction may start to issue. Nothing
    /// happens in the cycles jumped over — no token moves, the bus neither takes nor
    /// hands on an instruction, and no [`Probe`] call is made in them —, so every event,
    /// statistic and scanline is the same as when each cycle is stepped; a machine whose
    /// line period is 10⁷ cycles costs a few steps per instruction, not 10⁷ per line.
    ///
    /// Cycles saturate at `u64::MAX` (a gate there is the deadline of a scanline beyond
    /// it: `Timeline::deadline`); the additions to `t` (a cost below 2²⁰, a hop at most
    /// 2¹⁶: `crate::machine`) saturate too, and events then all happen at `u64::MAX`.
    fn next_cycle(&mut self, issue: Option<u64>) {
        let t = self.t;
        let after = t.saturating_add(1);
        let mut next = u64::MAX;
        if self.in_flight > 0 {
            if self.timeline.hop == 1 {
                // some token moves every cycle
                next = after;
            } else {
                let soonest = self.stages.iter().flatten().map(|tok| tok.leave_at).min();
                next = soonest.unwrap_or(after).max(after);
            }
        }
        if let Some(bus) = &self.bus {
            // it enters once issued and past `free_at` if the first stage is free; if it
            // is not, the token there moves first (counted above)
            let enter = bus.issued_at.max(self.free_at);
            if enter > t || self.stages[0].is_none() {
                next = next.min(enter.max(after));
            }
        }
        if let Some(gate) = issue.filter(|_| self.bus.is_none()) {
            next = next.min(gate.max(after));
        }
        self.t = next;
        self.steps += 1;
        self.moved = false;
    }

    /// Cycles stepped through so far: the cycles at which something could happen, not
    /// every cycle of the run (see [`Self::next_cycle`]).
    pub fn steps(&self) -> u64 {
        self.steps
    }

    fn exit(&mut self, tok: Token<A::Reg, A::Out>, sink: &mut dyn LineSink<A::Out>) {
        self.last_exit = self.t;
        self.recorder.work(tok.line, tok.work);
        if tok.instr.op == Opcode::Refresh {
            self.probe.line_ready(self.t, tok.line);
            self.recorder
                .ready(tok.line, self.t, self.timeline.deadline(tok.line));
            sink.line(LineOut {
                index: tok.line,
                span: (0, self.stages.len()),
                values: &tok.out,
            });
            self.lines_out += 1;
        }
    }

    /// What the token does in processor `p`, reported to the probe if it watches `p`.
    fn apply(&mut self, p: usize, tok: &mut Token<A::Reg, A::Out>) {
        if !self.probe.watches(p) {
            self.act(p, tok);
            return;
        }
        let before = self.state(p);
        let updates = tok.work.updates;
        self.act(p, tok);
        let after = self.state(p);
        let addressed =
            tok.work.updates > updates || matches!(tok.instr.op, Opcode::AccMode | Opcode::Refresh);
        self.probe.visit(
            self.t, p, tok.index, tok.line, &tok.instr, addressed, &before, &after,
        );
    }

    /// Processor `p`'s registers as `f64`.
    fn state(&self, p: usize) -> ProcessorState {
        self.procs[p].state(&self.arith, self.channels)
    }

    /// The token's effect in processor `p` ([`Processor::act`]).
    #[inline]
    fn act(&mut self, p: usize, tok: &mut Token<A::Reg, A::Out>) {
        self.procs[p].act(
            &self.arith,
            self.channels,
            p,
            &tok.instr,
            &mut tok.wave,
            &mut tok.work,
            &mut tok.out,
        );
    }
}

impl<A: Arith> Engine<A::Out> for SteppedEngine<'_, A> {
    fn line_records(&mut self, to: LineRecords) {
        self.recorder.line_records(to);
    }

    fn execute(&mut self, instr: &Instruction, sink: &mut dyn LineSink<A::Out>) {
        let (gate, line) = if instr.op == Opcode::Refresh {
            (
                self.timeline.refresh_gate(self.refreshes_issued),
                self.refreshes_issued,
            )
        } else {
            (0, self.refreshes_issued)
        };
        loop {
            if !self.moved {
                self.move_tokens(sink);
            }
            if self.bus.is_none() && self.t >= gate {
                let cost = self.timeline.issue_cycles(instr);
                self.probe.issue(self.t, self.issued, line, instr);
                self.bus = Some(Bus {
                    instr: instr.clone(),
                    index: self.issued,
                    line,
                    begin: self.t,
                    cost,
                    issued_at: self.t.saturating_add(cost),
                });
                if instr.op == Opcode::Refresh {
                    self.refreshes_issued += 1;
                }
                self.issued += 1;
                return;
            }
            self.next_cycle(Some(gate));
        }
    }

    fn finish(mut self: Box<Self>, sink: &mut dyn LineSink<A::Out>) -> RunStats {
        loop {
            if !self.moved {
                self.move_tokens(sink);
            }
            if self.bus.is_none() && self.stages.iter().all(Option::is_none) {
                break;
            }
            self.next_cycle(None);
        }
        // Instructions after the last Refresh never leave as a scanline, but their work
        // was counted when their tokens left the chain.
        self.recorder.finish(self.lines_out, self.last_exit)
    }
}
