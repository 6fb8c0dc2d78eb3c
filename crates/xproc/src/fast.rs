//! The fast engine: executes each instruction over its whole range at once and computes
//! the cycle of every event from the timing model's closed form, without stepping cycles.
//!
//! Cost follows the work in the trace: an instruction costs its range, a `Refresh` costs
//! the span of processors touched since the previous one, and an empty scanline costs
//! O(1). State is one scanline: registers and flags per processor, nothing per frame.

use crate::engine::Engine;
use crate::machine::Timeline;
use crate::output::{LineOut, LineSink};
use crate::sample::{vector, Sample};
use crate::stats::{Recorder, RunStats};
use cwisim_isa::{Instruction, Opcode, TraceHeader, MAX_CHANNELS};

const HAS_I: u8 = 1;
const HAS_DI: u8 = 2;
const HAS_DDI: u8 = 4;
const LOCKED: u8 = 8;

/// The fast engine (see the module documentation).
pub struct FastEngine<T: Sample> {
    channels: usize,
    timeline: Timeline,
    recorder: Recorder,
    /// Accumulators, `width × channels`.
    acc: Vec<T>,
    /// Preload registers `I`, `dI`, `ddI`, each `width × channels`.
    regs: [Vec<T>; 3],
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
    /// Scanlines output so far.
    line: u64,
    last_entry: Option<u64>,
}

impl<T: Sample> FastEngine<T> {
    /// An array for `header`'s width and channels, timed by `timeline`.
    pub fn new(header: &TraceHeader, timeline: Timeline) -> Self {
        let w = header.width as usize;
        let c = header.channel_count();
        FastEngine {
            channels: c,
            recorder: Recorder::new(&timeline),
            timeline,
            acc: vec![T::ZERO; w * c],
            regs: [
                vec![T::ZERO; w * c],
                vec![T::ZERO; w * c],
                vec![T::ZERO; w * c],
            ],
            flags: vec![0; w],
            mask_stamp: vec![0; w],
            evals: 0,
            negative_enabled: false,
            any_flags: false,
            dis_pending: false,
            touched: None,
            line: 0,
            last_entry: None,
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
        let begin = self.last_entry.unwrap_or(0).max(gate);
        let cost = self.timeline.issue_cycles(instr);
        let entry = (begin + cost).max(self.last_entry.map_or(0, |e| e + self.timeline.hop));
        self.recorder.issue(self.line, instr.op, begin, entry, cost);
        self.last_entry = Some(entry);
        entry
    }

    fn set(&mut self, slot: usize, p: usize, v: &[T; MAX_CHANNELS]) {
        let c = self.channels;
        self.regs[slot][p * c..p * c + c].copy_from_slice(&v[..c]);
        self.flags[p] |= 1 << slot;
    }

    fn eval0(&mut self, x: usize, dx: usize, v: &[T; MAX_CHANNELS]) -> u64 {
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

    /// Eval1 (`ORDER` 1), Eval2 (2) and Eval3 (3): forward differencing along
    /// `[x, x+dx)`, picking up preloaded registers as the wave passes them.
    fn eval<const ORDER: usize>(
        &mut self,
        x: usize,
        dx: usize,
        mut v: [T; MAX_CHANNELS],
        mut d: [T; MAX_CHANNELS],
        dd: [T; MAX_CHANNELS],
    ) -> (u64, u64) {
        let c = self.channels;
        let (mut dropped, mut suppressed) = (0u64, 0u64);
        let neg_ok = self.negative_enabled;
        if !self.any_flags && !self.dis_pending {
            // No preloads, locks or masks on this scanline: the plain adder chain.
            for p in x..x + dx {
                let acc = &mut self.acc[p * c..p * c + c];
                for k in 0..c {
                    if neg_ok || !v[k].is_negative() {
                        acc[k] = acc[k].add(v[k]);
                    } else {
                        dropped += 1;
                    }
                    if ORDER >= 2 {
                        v[k] = v[k].add(d[k]);
                    }
                    if ORDER >= 3 {
                        d[k] = d[k].add(dd[k]);
                    }
                }
            }
            return (dropped, 0);
        }
        let reads: u8 = match ORDER {
            1 => HAS_I,
            2 => HAS_I | HAS_DI,
            _ => HAS_I | HAS_DI | HAS_DDI,
        };
        let cur = self.evals + 1;
        let mut dd = dd;
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
                    if neg_ok || !v[k].is_negative() {
                        acc[k] = acc[k].add(v[k]);
                    } else {
                        dropped += 1;
                    }
                }
                if ORDER >= 2 {
                    v[k] = v[k].add(d[k]);
                }
                if ORDER >= 3 {
                    d[k] = d[k].add(dd[k]);
                }
            }
        }
        (dropped, suppressed)
    }

    fn refresh(&mut self, entry: u64, sink: &mut dyn LineSink<T>) {
        let ready = entry + self.timeline.traversal();
        self.recorder
            .ready(self.line, ready, self.timeline.deadline(self.line));
        let c = self.channels;
        let (lo, hi) = self.touched.take().unwrap_or((0, 0));
        sink.line(LineOut {
            index: self.line,
            span: (lo, hi),
            values: &self.acc[lo * c..hi * c],
        });
        self.acc[lo * c..hi * c].fill(T::ZERO);
        self.flags[lo..hi].fill(0);
        self.mask_stamp[lo..hi].fill(0);
        self.any_flags = false;
        self.dis_pending = false;
        self.line += 1;
    }
}

impl<T: Sample> Engine<T> for FastEngine<T> {
    fn execute(&mut self, instr: &Instruction, sink: &mut dyn LineSink<T>) {
        let entry = self.issue(instr);
        let (x, dx) = (instr.x as usize, instr.dx as usize);
        let (mut updates, mut dropped, mut suppressed) = (0u64, 0u64, 0u64);
        match instr.op {
            Opcode::SetI | Opcode::SetdI | Opcode::SetddI => {
                let slot = instr.op as usize - Opcode::SetI as usize;
                self.set(slot, x, &vector(&instr.values[slot]));
                self.any_flags = true;
                self.touch(x, x + 1);
                updates = 1;
            }
            Opcode::SetPI | Opcode::SetPdI | Opcode::SetPddI => {
                let slot = instr.op as usize - Opcode::SetPI as usize;
                let v = vector(&instr.values[slot]);
                let width = self.flags.len();
                let mut last = x;
                for p in (x..width).step_by(dx) {
                    self.set(slot, p, &v);
                    updates += 1;
                    last = p;
                }
                self.any_flags = true;
                self.touch(x, last + 1);
            }
            Opcode::Eval0 => {
                suppressed = self.eval0(x, dx, &vector(instr.i()));
                updates = dx as u64;
                self.touch(x, x + dx);
                self.evals += 1;
            }
            Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                let (v, d, dd) = (vector(instr.i()), vector(instr.di()), vector(instr.ddi()));
                (dropped, suppressed) = match instr.op {
                    Opcode::Eval1 => self.eval::<1>(x, dx, v, d, dd),
                    Opcode::Eval2 => self.eval::<2>(x, dx, v, d, dd),
                    _ => self.eval::<3>(x, dx, v, d, dd),
                };
                updates = dx as u64;
                self.touch(x, x + dx);
                self.evals += 1;
                self.dis_pending = false;
            }
            Opcode::Dis => {
                let stamp = self.evals + 1;
                self.mask_stamp[x..x + dx].fill(stamp);
                self.dis_pending |= dx > 0;
                updates = dx as u64;
                self.touch(x, x + dx);
            }
            Opcode::AccMode => self.negative_enabled = !self.negative_enabled,
            Opcode::Refresh => {
                self.refresh(entry, sink);
                return;
            }
            Opcode::Nop => {}
        }
        if instr.op == Opcode::Eval0 {
            self.dis_pending = false;
        }
        self.recorder.work(self.line, updates, dropped, suppressed);
    }

    fn finish(self: Box<Self>, _sink: &mut dyn LineSink<T>) -> RunStats {
        let end = self.last_entry.map_or(0, |e| e + self.timeline.traversal());
        self.recorder.finish(self.line, end)
    }
}
