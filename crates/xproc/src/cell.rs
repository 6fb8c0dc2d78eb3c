//! One X-processor as the cycle-stepped engine models it, and what one token (an
//! instruction with its running forward-differencing values) does in it: the one
//! per-processor statement of the instruction semantics (`docs/ISA.md`) that the
//! stepped engine ([`crate::stepped`], a token per stage, one hop at a time) and the
//! visits without stepping ([`crate::visits`], a token over the processors it reaches)
//! both call. The fast engine's processors (`processors.rs`) execute whole ranges at
//! once and are held to these by the property tests.

use crate::arith::{vector, Arith};
use crate::numeric::Register;
use crate::probe::ProcessorState;
use crate::stats::Work;
use cwisim_isa::{Instruction, Opcode, MAX_CHANNELS};

/// A register of every channel.
pub(crate) type Vector<T> = [T; MAX_CHANNELS];

/// A token's running values: its value operands, converted when it entered the chain
/// ([`operands`]); an Eval's wave runs in them (running value, first and second
/// difference).
#[derive(Clone, Copy)]
pub(crate) struct Wave<T> {
    /// `I` (for `Eval0` in the accumulator's format).
    pub v: Vector<T>,
    /// `dI`.
    pub d: Vector<T>,
    /// `ddI`.
    pub dd: Vector<T>,
}

/// The value operands of `instr`, converted into the registers they are written to
/// (`Eval0`'s `I` into the accumulator's format); operands the opcode does not have are
/// zero. Conversion overflows are counted in `overflows`.
pub(crate) fn operands<A: Arith>(
    arith: &A,
    channels: usize,
    instr: &Instruction,
    overflows: &mut u64,
) -> Wave<A::Reg> {
    let mut out = [[A::ZERO; MAX_CHANNELS]; 3];
    for kind in instr.op.operands() {
        if let Some(slot) = kind.value_slot() {
            let reg = if instr.op == Opcode::Eval0 {
                Register::Acc
            } else {
                Register::of_slot(slot)
            };
            out[slot] = vector(arith, reg, instr.value(slot), channels, overflows);
        }
    }
    let [v, d, dd] = out;
    Wave { v, d, dd }
}

/// One X-processor's registers and flags.
#[derive(Clone)]
pub(crate) struct Processor<T> {
    pub acc: Vector<T>,
    /// Preload registers `I`, `dI`, `ddI`.
    pub reg: [Vector<T>; 3],
    /// Whether each preload register holds a value not yet consumed.
    pub has: [bool; 3],
    /// Claimed by `Eval0` until `Refresh`.
    pub locked: bool,
    /// Masked by `Dis` for the next Eval.
    pub masked: bool,
    /// This processor's copy of the `Acc_mode` flag.
    pub negative_enabled: bool,
}

impl<T: Copy> Processor<T> {
    /// A processor as at power-up: registers `zero`, every flag clear.
    pub fn blank(zero: T) -> Self {
        Processor {
            acc: [zero; MAX_CHANNELS],
            reg: [[zero; MAX_CHANNELS]; 3],
            has: [false; 3],
            locked: false,
            masked: false,
            negative_enabled: false,
        }
    }

    /// The effect in this processor, number `p`, of the token of `instr` with running
    /// values `wave`: its registers and flags, the wave advanced where the Eval covers
    /// `p`, the work counted in `work`. A `Refresh` writes the accumulator of the
    /// `channels` channels into `out[p · channels ..]` if `out` has room for it (the
    /// token's scanline; empty where it is not collected) and clears the processor.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn act<A: Arith<Reg = T>>(
        &mut self,
        arith: &A,
        channels: usize,
        p: usize,
        i: &Instruction,
        wave: &mut Wave<T>,
        work: &mut Work,
        out: &mut [A::Out],
    ) {
        let c = channels;
        let (x, dx) = (i.x as usize, i.dx as usize);
        let in_range = p >= x && p < x + dx;
        let ar = arith;
        let pr = self;
        match i.op {
            Opcode::SetI | Opcode::SetdI | Opcode::SetddI => {
                if p == x {
                    let slot = i.op as usize - Opcode::SetI as usize;
                    pr.reg[slot] = [wave.v, wave.d, wave.dd][slot];
                    pr.has[slot] = true;
                    work.updates += 1;
                }
            }
            Opcode::SetPI | Opcode::SetPdI | Opcode::SetPddI => {
                if p >= x && (p - x).is_multiple_of(dx) {
                    let slot = i.op as usize - Opcode::SetPI as usize;
                    pr.reg[slot] = [wave.v, wave.d, wave.dd][slot];
                    pr.has[slot] = true;
                    work.updates += 1;
                }
            }
            Opcode::Eval0 => {
                if in_range {
                    work.updates += 1;
                    if pr.locked || pr.masked {
                        work.suppressed += 1;
                    } else {
                        pr.acc = wave.v;
                        pr.locked = true;
                    }
                }
                pr.masked = false;
            }
            Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                let order = 1 + i.op as usize - Opcode::Eval1 as usize;
                if in_range {
                    work.updates += 1;
                    if pr.has[0] {
                        wave.v = pr.reg[0];
                        pr.has[0] = false;
                    }
                    if order >= 2 && pr.has[1] {
                        wave.d = pr.reg[1];
                        pr.has[1] = false;
                    }
                    if order >= 3 && pr.has[2] {
                        wave.dd = pr.reg[2];
                        pr.has[2] = false;
                    }
                    let blocked = pr.locked || pr.masked;
                    if blocked {
                        work.suppressed += 1;
                    }
                    for k in 0..c {
                        if !blocked {
                            if pr.negative_enabled || !ar.is_negative(wave.v[k]) {
                                pr.acc[k] =
                                    ar.accumulate(pr.acc[k], wave.v[k], &mut work.overflows);
                            } else {
                                work.dropped += 1;
                            }
                        }
                        if order >= 2 {
                            wave.v[k] = ar.advance_v(wave.v[k], wave.d[k], &mut work.overflows);
                        }
                        if order >= 3 {
                            wave.d[k] = ar.advance_d(wave.d[k], wave.dd[k], &mut work.overflows);
                        }
                    }
                }
                pr.masked = false;
            }
            Opcode::Dis => {
                if in_range {
                    pr.masked = true;
                    work.updates += 1;
                }
            }
            Opcode::AccMode => pr.negative_enabled = !pr.negative_enabled,
            Opcode::Refresh => {
                if let Some(out) = out.get_mut(p * c..p * c + c) {
                    for (o, a) in out.iter_mut().zip(&pr.acc) {
                        *o = ar.out(*a);
                    }
                }
                pr.acc = [A::ZERO; MAX_CHANNELS];
                pr.has = [false; 3];
                pr.locked = false;
                pr.masked = false;
            }
            Opcode::Nop => {}
        }
    }

    /// This processor's registers and flags as `f64`, into `s` (in the room it has).
    pub fn fill_state<A: Arith<Reg = T>>(
        &self,
        arith: &A,
        channels: usize,
        s: &mut ProcessorState,
    ) {
        let c = channels;
        let fill = |out: &mut Vec<f64>, reg: Register, x: &Vector<T>| {
            out.clear();
            out.extend(x[..c].iter().map(|r| arith.value(reg, *r)));
        };
        fill(&mut s.acc, Register::Acc, &self.acc);
        fill(&mut s.reg[0], Register::I, &self.reg[0]);
        fill(&mut s.reg[1], Register::DI, &self.reg[1]);
        fill(&mut s.reg[2], Register::DDI, &self.reg[2]);
        s.has = self.has;
        s.locked = self.locked;
        s.masked = self.masked;
        s.negative_enabled = self.negative_enabled;
    }

    /// This processor's registers and flags as `f64`.
    pub fn state<A: Arith<Reg = T>>(&self, arith: &A, channels: usize) -> ProcessorState {
        let mut s = ProcessorState::default();
        self.fill_state(arith, channels, &mut s);
        s
    }
}
