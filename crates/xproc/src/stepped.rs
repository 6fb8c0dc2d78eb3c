//! The cycle-stepped reference engine: advances every processor of the systolic chain
//! every cycle, with the instruction bus as an explicit state machine.
//!
//! It shares nothing with the fast engine but the machine parameters and the statistics
//! bookkeeping: processors are plain structs with one flag per condition, and every
//! token (an instruction with its running forward-differencing state) visits every
//! processor, one hop at a time. Obviously right, and slow: the property tests hold the
//! fast engine to it.

use crate::engine::Engine;
use crate::machine::Timeline;
use crate::output::{LineOut, LineSink};
use crate::probe::{NoProbe, Probe, ProcessorState};
use crate::sample::{vector, Sample};
use crate::stats::{Recorder, RunStats};
use cwisim_isa::{Instruction, Opcode, TraceHeader, MAX_CHANNELS};

type Vector<T> = [T; MAX_CHANNELS];

/// One X-processor's registers and flags.
#[derive(Clone)]
struct Processor<T> {
    acc: Vector<T>,
    /// Preload registers `I`, `dI`, `ddI`.
    reg: [Vector<T>; 3],
    /// Whether each preload register holds a value not yet consumed.
    has: [bool; 3],
    /// Claimed by `Eval0` until `Refresh`.
    locked: bool,
    /// Masked by `Dis` for the next Eval.
    masked: bool,
    /// This processor's copy of the `Acc_mode` flag.
    negative_enabled: bool,
}

/// An instruction travelling along the chain.
struct Token<T> {
    instr: Instruction,
    /// Its number in the trace.
    index: u64,
    /// The scanline it belongs to.
    line: u64,
    /// Running value, first and second difference.
    v: Vector<T>,
    d: Vector<T>,
    dd: Vector<T>,
    /// The cycle it moves on to the next processor.
    leave_at: u64,
    /// What a `Refresh` collects as it passes.
    out: Vec<T>,
    updates: u64,
    dropped: u64,
    suppressed: u64,
}

/// The instruction on the bus.
struct Bus {
    instr: Instruction,
    index: u64,
    line: u64,
    begin: u64,
    /// The cycle its issue is complete.
    issued_at: u64,
}

/// The cycle-stepped engine (see the module documentation).
pub struct SteppedEngine<'p, T: Sample> {
    channels: usize,
    timeline: Timeline,
    recorder: Recorder,
    procs: Vec<Processor<T>>,
    /// The token in each processor's stage.
    stages: Vec<Option<Box<Token<T>>>>,
    bus: Option<Bus>,
    /// The current cycle.
    t: u64,
    /// Whether the token moves and bus entry of cycle `t` are done.
    moved: bool,
    /// `Refresh` instructions that have started to issue.
    refreshes_issued: u64,
    /// Scanlines that have left the array.
    lines_out: u64,
    last_exit: u64,
    /// Instructions issued so far.
    issued: u64,
    probe: &'p mut dyn Probe,
}

impl<T: Sample> SteppedEngine<'static, T> {
    /// An array for `header`'s width and channels, timed by `timeline`.
    pub fn new(header: &TraceHeader, timeline: Timeline) -> Self {
        // NoProbe has no state; leaking one zero-sized value costs nothing.
        SteppedEngine::with_probe(header, timeline, Box::leak(Box::new(NoProbe)))
    }
}

impl<'p, T: Sample> SteppedEngine<'p, T> {
    /// An array that reports to `probe` as it steps.
    pub fn with_probe(header: &TraceHeader, timeline: Timeline, probe: &'p mut dyn Probe) -> Self {
        let w = header.width as usize;
        let blank = Processor {
            acc: [T::ZERO; MAX_CHANNELS],
            reg: [[T::ZERO; MAX_CHANNELS]; 3],
            has: [false; 3],
            locked: false,
            masked: false,
            negative_enabled: false,
        };
        SteppedEngine {
            channels: header.channel_count(),
            recorder: Recorder::new(&timeline),
            timeline,
            procs: vec![blank; w],
            stages: (0..w).map(|_| None).collect(),
            bus: None,
            t: 0,
            moved: false,
            refreshes_issued: 0,
            lines_out: 0,
            last_exit: 0,
            issued: 0,
            probe,
        }
    }

    /// Moves tokens whose time in a stage is up, then lets the bus hand its instruction
    /// to the first processor if the issue is complete and the stage is free.
    fn move_tokens(&mut self, sink: &mut dyn LineSink<T>) {
        let t = self.t;
        let w = self.stages.len();
        for p in (0..w).rev() {
            if self.stages[p].as_ref().is_some_and(|tok| tok.leave_at == t) {
                let mut tok = self.stages[p].take().expect("checked");
                if p + 1 == w {
                    self.exit(*tok, sink);
                } else {
                    assert!(self.stages[p + 1].is_none(), "two tokens in one processor");
                    self.apply(p + 1, &mut tok);
                    tok.leave_at = t + self.timeline.hop;
                    self.stages[p + 1] = Some(tok);
                }
            }
        }
        if self.stages[0].is_none() && self.bus.as_ref().is_some_and(|b| b.issued_at <= t) {
            let bus = self.bus.take().expect("checked");
            self.probe.enter(t, bus.index);
            let cost = bus.issued_at - bus.begin;
            self.recorder
                .issue(bus.line, bus.instr.op, bus.begin, t, cost);
            let mut tok = Box::new(Token {
                v: vector(bus.instr.i()),
                d: vector(bus.instr.di()),
                dd: vector(bus.instr.ddi()),
                out: if bus.instr.op == Opcode::Refresh {
                    vec![T::ZERO; w * self.channels]
                } else {
                    Vec::new()
                },
                instr: bus.instr,
                index: bus.index,
                line: bus.line,
                leave_at: t + self.timeline.hop,
                updates: 0,
                dropped: 0,
                suppressed: 0,
            });
            self.apply(0, &mut tok);
            self.stages[0] = Some(tok);
        }
        self.moved = true;
    }

    fn next_cycle(&mut self) {
        self.t += 1;
        self.moved = false;
    }

    fn exit(&mut self, tok: Token<T>, sink: &mut dyn LineSink<T>) {
        self.last_exit = self.t;
        self.recorder
            .work(tok.line, tok.updates, tok.dropped, tok.suppressed);
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
    fn apply(&mut self, p: usize, tok: &mut Token<T>) {
        if !self.probe.watches(p) {
            self.act(p, tok);
            return;
        }
        let before = self.state(p);
        let updates = tok.updates;
        self.act(p, tok);
        let after = self.state(p);
        let addressed =
            tok.updates > updates || matches!(tok.instr.op, Opcode::AccMode | Opcode::Refresh);
        self.probe.visit(
            self.t, p, tok.index, tok.line, &tok.instr, addressed, &before, &after,
        );
    }

    /// Processor `p`'s registers as `f64`.
    fn state(&self, p: usize) -> ProcessorState {
        let pr = &self.procs[p];
        let c = self.channels;
        let v = |x: &Vector<T>| x[..c].iter().map(|s| s.to_f64()).collect::<Vec<f64>>();
        ProcessorState {
            acc: v(&pr.acc),
            reg: [v(&pr.reg[0]), v(&pr.reg[1]), v(&pr.reg[2])],
            has: pr.has,
            locked: pr.locked,
            masked: pr.masked,
            negative_enabled: pr.negative_enabled,
        }
    }

    /// The token's effect in processor `p`.
    fn act(&mut self, p: usize, tok: &mut Token<T>) {
        let c = self.channels;
        let i = &tok.instr;
        let (x, dx) = (i.x as usize, i.dx as usize);
        let in_range = p >= x && p < x + dx;
        let pr = &mut self.procs[p];
        match i.op {
            Opcode::SetI | Opcode::SetdI | Opcode::SetddI => {
                if p == x {
                    let slot = i.op as usize - Opcode::SetI as usize;
                    pr.reg[slot] = vector(&i.values[slot]);
                    pr.has[slot] = true;
                    tok.updates += 1;
                }
            }
            Opcode::SetPI | Opcode::SetPdI | Opcode::SetPddI => {
                if p >= x && (p - x).is_multiple_of(dx) {
                    let slot = i.op as usize - Opcode::SetPI as usize;
                    pr.reg[slot] = vector(&i.values[slot]);
                    pr.has[slot] = true;
                    tok.updates += 1;
                }
            }
            Opcode::Eval0 => {
                if in_range {
                    tok.updates += 1;
                    if pr.locked || pr.masked {
                        tok.suppressed += 1;
                    } else {
                        pr.acc = tok.v;
                        pr.locked = true;
                    }
                }
                pr.masked = false;
            }
            Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                let order = 1 + i.op as usize - Opcode::Eval1 as usize;
                if in_range {
                    tok.updates += 1;
                    if pr.has[0] {
                        tok.v = pr.reg[0];
                        pr.has[0] = false;
                    }
                    if order >= 2 && pr.has[1] {
                        tok.d = pr.reg[1];
                        pr.has[1] = false;
                    }
                    if order >= 3 && pr.has[2] {
                        tok.dd = pr.reg[2];
                        pr.has[2] = false;
                    }
                    let blocked = pr.locked || pr.masked;
                    if blocked {
                        tok.suppressed += 1;
                    }
                    for k in 0..c {
                        if !blocked {
                            if pr.negative_enabled || !tok.v[k].is_negative() {
                                pr.acc[k] = pr.acc[k].add(tok.v[k]);
                            } else {
                                tok.dropped += 1;
                            }
                        }
                        if order >= 2 {
                            tok.v[k] = tok.v[k].add(tok.d[k]);
                        }
                        if order >= 3 {
                            tok.d[k] = tok.d[k].add(tok.dd[k]);
                        }
                    }
                }
                pr.masked = false;
            }
            Opcode::Dis => {
                if in_range {
                    pr.masked = true;
                    tok.updates += 1;
                }
            }
            Opcode::AccMode => pr.negative_enabled = !pr.negative_enabled,
            Opcode::Refresh => {
                tok.out[p * c..p * c + c].copy_from_slice(&pr.acc[..c]);
                pr.acc = [T::ZERO; MAX_CHANNELS];
                pr.has = [false; 3];
                pr.locked = false;
                pr.masked = false;
            }
            Opcode::Nop => {}
        }
    }
}

impl<T: Sample> Engine<T> for SteppedEngine<'_, T> {
    fn execute(&mut self, instr: &Instruction, sink: &mut dyn LineSink<T>) {
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
                    instr: *instr,
                    index: self.issued,
                    line,
                    begin: self.t,
                    issued_at: self.t + cost,
                });
                if instr.op == Opcode::Refresh {
                    self.refreshes_issued += 1;
                }
                self.issued += 1;
                return;
            }
            self.next_cycle();
        }
    }

    fn finish(mut self: Box<Self>, sink: &mut dyn LineSink<T>) -> RunStats {
        loop {
            if !self.moved {
                self.move_tokens(sink);
            }
            if self.bus.is_none() && self.stages.iter().all(Option::is_none) {
                break;
            }
            self.next_cycle();
        }
        // Instructions after the last Refresh never leave as a scanline, but their work
        // was counted when their tokens left the chain.
        self.recorder.finish(self.lines_out, self.last_exit)
    }
}
