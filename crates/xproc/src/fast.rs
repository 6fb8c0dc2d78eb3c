//! The fast engine: executes each instruction over its whole range at once and computes
//! the cycle of every event from the timing model's closed form, without stepping cycles.
//!
//! Cost follows the work in the trace: an instruction costs its range, a `Refresh` costs
//! the span of processors touched since the previous one, and an empty scanline costs
//! O(1). State is one scanline: registers and flags per processor, nothing per frame.

use crate::arith::{Arith, Native, Wave};
use crate::engine::Engine;
use crate::machine::Timeline;
use crate::numeric::Register;
use crate::output::{LineOut, LineSink};
use crate::sample::Sample;
use crate::stats::{IssueTally, LineRecords, Recorder, RunStats, Work};
use cwisim_isa::{Instruction, Opcode, TraceHeader, MAX_CHANNELS};

const HAS_I: u8 = 1;
const HAS_DI: u8 = 2;
const HAS_DDI: u8 = 4;
const LOCKED: u8 = 8;

/// Up to [`MAX_CHANNELS`] operand values for register `reg` on an array of `C` channels
/// (a constant, so the loop unrolls and the values stay in machine registers); channels
/// from `C` on stay zero. The same values and counts as `arith::vector`. Always inlined: an
/// array returned through memory, written element by element and read back whole,
/// stalls store-to-load forwarding.
#[inline(always)]
fn operands<A: Arith, const C: usize>(
    arith: &A,
    reg: Register,
    v: &[f64],
    overflows: &mut u64,
) -> [A::Reg; MAX_CHANNELS] {
    let mut out = [A::ZERO; MAX_CHANNELS];
    for (o, x) in out[..C].iter_mut().zip(v) {
        *o = arith.operand(reg, *x, overflows);
    }
    out
}

/// The fast engine (see the module documentation), with registers of arithmetic `A`.
pub struct FastEngine<A: Arith> {
    arith: A,
    channels: usize,
    timeline: Timeline,
    recorder: Recorder,
    /// Accumulators, `width × channels`.
    acc: Vec<A::Reg>,
    /// Preload registers `I`, `dI`, `ddI`, each `width × channels`.
    regs: [Vec<A::Reg>; 3],
    /// `HAS_*` and `LOCKED` bits per processor.
    flags: Vec<u8>,
    /// A processor is masked (`Dis`) for the next Eval when its stamp equals `evals + 1`.
    mask_stamp: Vec<u64>,
    /// Eval commands executed so far.
    evals: u64,
    negative_enabled: bool,
    /// Some processor has flags set since the last `Refresh`.
    any_flags: bool,
    /// A `Dis` is waiting for the next Eval.
    dis_pending: bool,
    /// Processors touched since the last `Refresh`, half-open.
    touched: Option<(usize, usize)>,
    /// Some processor has been masked (`Dis`) since the last `Refresh`.
    any_masks: bool,
    /// Scanlines output so far.
    line: u64,
    /// The work of the current scanline's instructions so far, recorded at its `Refresh`
    /// (or at the end): one record per scanline instead of one per instruction.
    line_work: Work,
    /// The current scanline's instructions so far, handed to the recorder with its work.
    line_issue: IssueTally,
    last_entry: Option<u64>,
    /// Scratch space for a scanline converted for output.
    out: Vec<A::Out>,
}

impl<T: Sample> FastEngine<Native<T>> {
    /// An array of `T` registers for `header`'s width and channels, timed by `timeline`.
    pub fn new(header: &TraceHeader, timeline: Timeline) -> Self {
        FastEngine::with_arith(header, timeline, Native::new())
    }
}

impl<A: Arith> FastEngine<A> {
    /// An array with registers of arithmetic `arith`.
    pub fn with_arith(header: &TraceHeader, timeline: Timeline, arith: A) -> Self {
        let w = header.width as usize;
        let c = header.channel_count();
        FastEngine {
            arith,
            channels: c,
            recorder: Recorder::new(&timeline),
            timeline,
            acc: vec![A::ZERO; w * c],
            regs: [
                vec![A::ZERO; w * c],
                vec![A::ZERO; w * c],
                vec![A::ZERO; w * c],
            ],
            flags: vec![0; w],
            mask_stamp: vec![0; w],
            evals: 0,
            negative_enabled: false,
            any_flags: false,
            dis_pending: false,
            any_masks: false,
            touched: None,
            line: 0,
            line_work: Work::default(),
            line_issue: IssueTally::default(),
            last_entry: None,
            out: Vec::new(),
        }
    }

    /// Records the current scanline's instructions and work so far (nothing if there
    /// were none, so that no record is opened for a scanline without instructions).
    fn flush_work(&mut self) {
        let tally = std::mem::take(&mut self.line_issue);
        self.recorder
            .issued(self.line, &tally, self.last_entry.unwrap_or(0));
        let w = std::mem::take(&mut self.line_work);
        if w.updates | w.dropped | w.suppressed | w.overflows != 0 {
            self.recorder.work(self.line, w);
        }
    }

    fn touch(&mut self, lo: usize, hi: usize) {
        if lo < hi {
            self.touched = Some(match self.touched {
                None => (lo, hi),
                Some((a, b)) => (a.min(lo), b.max(hi)),
            });
        }
    }

    /// The closed form of the issue model: the bus starts an instruction when the
    /// previous one has entered the chain (and, for a `Refresh`, when the display has
    /// taken the previous scanline); the token enters the first processor when both its
    /// issue is done and the previous token has moved on.
    fn issue(&mut self, instr: &Instruction) -> u64 {
        let gate = if instr.op == Opcode::Refresh {
            self.timeline.refresh_gate(self.line)
        } else {
            0
        };
        let before = self.last_entry.unwrap_or(0);
        let begin = before.max(gate);
        let cost = self.timeline.issue_cycles(instr);
        let entry = (begin + cost).max(self.last_entry.map_or(0, |e| e + self.timeline.hop));
        self.line_issue.count(instr.op, begin, before);
        self.last_entry = Some(entry);
        entry
    }

    fn set(&mut self, slot: usize, p: usize, v: &[A::Reg; MAX_CHANNELS]) {
        let c = self.channels;
        self.regs[slot][p * c..p * c + c].copy_from_slice(&v[..c]);
        self.flags[p] |= 1 << slot;
    }

    fn eval0(&mut self, x: usize, dx: usize, v: &[A::Reg; MAX_CHANNELS]) -> u64 {
        let c = self.channels;
        let cur = self.evals + 1;
        let mut suppressed = 0;
        for p in x..x + dx {
            if self.flags[p] & LOCKED != 0 || (self.dis_pending && self.mask_stamp[p] == cur) {
                suppressed += 1;
                continue;
            }
            self.acc[p * c..p * c + c].copy_from_slice(&v[..c]);
            self.flags[p] |= LOCKED;
        }
        self.any_flags |= dx > 0;
        suppressed
    }

    /// Eval1 (`ORDER` 1), Eval2 (2) and Eval3 (3) on an array of `C` channels: the
    /// operands converted, then forward differencing along `[x, x+dx)`, picking up
    /// preloaded registers as the wave passes them. Adds its work to the scanline's
    /// (field by field, from machine registers: a `Work` written piecewise through
    /// memory and read back whole stalls store-to-load forwarding).
    fn eval<const ORDER: usize, const C: usize>(&mut self, instr: &Instruction) {
        debug_assert_eq!(C, self.channels);
        let (x, dx) = (instr.x as usize, instr.dx as usize);
        let ar = &self.arith;
        let (mut dropped, mut suppressed, mut ovf) = (0u64, 0u64, 0u64);
        let mut v = operands::<A, C>(ar, Register::I, instr.value(0), &mut ovf);
        let mut d = [A::ZERO; MAX_CHANNELS];
        if ORDER >= 2 {
            d = operands::<A, C>(ar, Register::DI, instr.value(1), &mut ovf);
        }
        let mut dd = [A::ZERO; MAX_CHANNELS];
        if ORDER >= 3 {
            dd = operands::<A, C>(ar, Register::DDI, instr.value(2), &mut ovf);
        }
        let c = C;
        let neg_ok = self.negative_enabled;
        self.line_work.updates += dx as u64;
        if !self.any_flags && !self.dis_pending {
            // No preloads, locks or masks on this scanline: the plain adder chain.
            let counts = ar.chain::<ORDER, C>(
                &mut self.acc[x * c..(x + dx) * c],
                Wave { v, d, dd },
                neg_ok,
            );
            self.line_work.dropped += counts.dropped;
            self.line_work.overflows += ovf + counts.overflows;
            return;
        }
        let reads: u8 = match ORDER {
            1 => HAS_I,
            2 => HAS_I | HAS_DI,
            _ => HAS_I | HAS_DI | HAS_DDI,
        };
        let cur = self.evals + 1;
        for p in x..x + dx {
            let f = self.flags[p];
            if f & reads != 0 {
                if f & HAS_I != 0 {
                    v[..c].copy_from_slice(&self.regs[0][p * c..p * c + c]);
                }
                if ORDER >= 2 && f & HAS_DI != 0 {
                    d[..c].copy_from_slice(&self.regs[1][p * c..p * c + c]);
                }
                if ORDER >= 3 && f & HAS_DDI != 0 {
                    dd[..c].copy_from_slice(&self.regs[2][p * c..p * c + c]);
                }
                self.flags[p] = f & !reads;
            }
            let blocked = f & LOCKED != 0 || (self.dis_pending && self.mask_stamp[p] == cur);
            if blocked {
                suppressed += 1;
            }
            let acc = &mut self.acc[p * c..p * c + c];
            for k in 0..c {
                if !blocked {
                    if neg_ok || !ar.is_negative(v[k]) {
                        acc[k] = ar.accumulate(acc[k], v[k], &mut ovf);
                    } else {
                        dropped += 1;
                    }
                }
                if ORDER >= 2 {
                    v[k] = ar.advance_v(v[k], d[k], &mut ovf);
                }
                if ORDER >= 3 {
                    d[k] = ar.advance_d(d[k], dd[k], &mut ovf);
                }
            }
        }
        self.line_work.dropped += dropped;
        self.line_work.suppressed += suppressed;
        self.line_work.overflows += ovf;
    }

    fn refresh(&mut self, entry: u64, sink: &mut dyn LineSink<A::Out>) {
        self.flush_work();
        let ready = entry + self.timeline.traversal();
        self.recorder
            .ready(self.line, ready, self.timeline.deadline(self.line));
        let c = self.channels;
        let (lo, hi) = self.touched.take().unwrap_or((0, 0));
        sink.line(LineOut {
            index: self.line,
            span: (lo, hi),
            values: self.arith.emit(&self.acc[lo * c..hi * c], &mut self.out),
        });
        self.acc[lo * c..hi * c].fill(A::ZERO);
        // flags are only set with `any_flags`, stamps only by a `Dis`
        if self.any_flags {
            self.flags[lo..hi].fill(0);
        }
        if self.any_masks {
            self.mask_stamp[lo..hi].fill(0);
        }
        self.any_flags = false;
        self.dis_pending = false;
        self.any_masks = false;
        self.line += 1;
    }
}

impl<A: Arith> FastEngine<A> {
    /// The instructions in order, on an array of `C` channels: the channel count is a
    /// constant here, decided once per batch rather than once per instruction.
    fn run<const C: usize>(&mut self, instrs: &[Instruction], sink: &mut dyn LineSink<A::Out>) {
        debug_assert_eq!(C, self.channels);
        for instr in instrs {
            self.step::<C>(instr, sink);
        }
    }

    /// One instruction on an array of `C` channels: issued (timed and counted), then
    /// executed over its range; its work is added to the scanline's.
    #[inline(always)]
    fn step<const C: usize>(&mut self, instr: &Instruction, sink: &mut dyn LineSink<A::Out>) {
        let entry = self.issue(instr);
        let (x, dx) = (instr.x as usize, instr.dx as usize);
        if dx == 0 && is_eval(instr.op) {
            self.empty_eval::<C>(instr);
            return;
        }
        let mut w = Work::default();
        match instr.op {
            Opcode::SetI | Opcode::SetdI | Opcode::SetddI => {
                let slot = instr.op as usize - Opcode::SetI as usize;
                let v = operands::<A, C>(
                    &self.arith,
                    Register::of_slot(slot),
                    instr.value(slot),
                    &mut w.overflows,
                );
                self.set(slot, x, &v);
                self.any_flags = true;
                self.touch(x, x + 1);
                w.updates = 1;
            }
            Opcode::SetPI | Opcode::SetPdI | Opcode::SetPddI => {
                let slot = instr.op as usize - Opcode::SetPI as usize;
                let v = operands::<A, C>(
                    &self.arith,
                    Register::of_slot(slot),
                    instr.value(slot),
                    &mut w.overflows,
                );
                let width = self.flags.len();
                let mut last = x;
                for p in (x..width).step_by(dx) {
                    self.set(slot, p, &v);
                    w.updates += 1;
                    last = p;
                }
                self.any_flags = true;
                self.touch(x, last + 1);
            }
            Opcode::Eval0 => {
                let v =
                    operands::<A, C>(&self.arith, Register::Acc, instr.value(0), &mut w.overflows);
                w.suppressed = self.eval0(x, dx, &v);
                w.updates = dx as u64;
                self.touch(x, x + dx);
                self.evals += 1;
                self.dis_pending = false;
            }
            Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                match instr.op {
                    Opcode::Eval1 => self.eval::<1, C>(instr),
                    Opcode::Eval2 => self.eval::<2, C>(instr),
                    _ => self.eval::<3, C>(instr),
                };
                self.touch(x, x + dx);
                self.evals += 1;
                self.dis_pending = false;
                // `eval` recorded its work
                return;
            }
            Opcode::Dis => {
                let stamp = self.evals + 1;
                self.mask_stamp[x..x + dx].fill(stamp);
                self.dis_pending |= dx > 0;
                self.any_masks |= dx > 0;
                w.updates = dx as u64;
                self.touch(x, x + dx);
            }
            Opcode::AccMode => self.negative_enabled = !self.negative_enabled,
            Opcode::Refresh => {
                self.refresh(entry, sink);
                return;
            }
            Opcode::Nop => {}
        }
        let l = &mut self.line_work;
        l.updates += w.updates;
        l.dropped += w.dropped;
        l.suppressed += w.suppressed;
        l.overflows += w.overflows;
    }

    /// An `Eval` of an empty range: it addresses no processor, but it is an Eval (it
    /// consumes a pending `Dis` mask) and its operands are converted (a narrow format
    /// counts their overflows) — the general path's effect, without its dispatch on the
    /// order.
    #[inline(always)]
    fn empty_eval<const C: usize>(&mut self, instr: &Instruction) {
        if A::OPERAND_OVERFLOWS {
            let mut ovf = 0;
            for slot in 0..instr.op.value_operands() {
                let reg = match instr.op {
                    Opcode::Eval0 => Register::Acc,
                    _ => Register::of_slot(slot),
                };
                operands::<A, C>(&self.arith, reg, instr.value(slot), &mut ovf);
            }
            self.line_work.overflows += ovf;
        }
        self.evals += 1;
        self.dis_pending = false;
    }
}

/// `Eval0` to `Eval3`.
#[inline(always)]
fn is_eval(op: Opcode) -> bool {
    matches!(
        op,
        Opcode::Eval0 | Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3
    )
}

impl<A: Arith> Engine<A::Out> for FastEngine<A> {
    fn line_records(&mut self, to: LineRecords) {
        self.recorder.line_records(to);
    }

    fn execute(&mut self, instr: &Instruction, sink: &mut dyn LineSink<A::Out>) {
        match self.channels {
            1 => self.step::<1>(instr, sink),
            2 => self.step::<2>(instr, sink),
            3 => self.step::<3>(instr, sink),
            _ => self.step::<4>(instr, sink),
        }
    }

    fn execute_all(&mut self, instrs: &[Instruction], sink: &mut dyn LineSink<A::Out>) {
        const { assert!(MAX_CHANNELS == 4) };
        match self.channels {
            1 => self.run::<1>(instrs, sink),
            2 => self.run::<2>(instrs, sink),
            3 => self.run::<3>(instrs, sink),
            _ => self.run::<4>(instrs, sink),
        }
    }

    fn finish(mut self: Box<Self>, _sink: &mut dyn LineSink<A::Out>) -> RunStats {
        self.flush_work();
        let end = self.last_entry.map_or(0, |e| e + self.timeline.traversal());
        self.recorder.finish(self.line, end)
    }
}
