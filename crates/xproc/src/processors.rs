//! The X-processors themselves: one scanline of registers and flags per processor, and
//! every instruction executed over its whole range at once. What they do not know is
//! time: each scanline's instructions are tallied by opcode with the scanline's work, and
//! handed out at its `Refresh` with the scanline's values ([`LineEnd`]) — to the fast
//! engine, which times and records it ([`crate::fast`]), or into a band run ahead on
//! another thread ([`crate::band`]).
//!
//! At a `Refresh` every processor the scanline touched is cleared (accumulator, preload
//! flags, lock, mask), so between scanlines the state is the same whatever came before,
//! except one bit: whether negative accumulation is on (`Acc_mode`).

use crate::arith::{Arith, Wave};
use crate::lanes::{batches, Batch, MAX_LEN, SHORT, SPARE};
use crate::numeric::Register;
use crate::stats::{IssueTally, Work};
use cwisim_isa::{Instruction, Opcode, MAX_CHANNELS};
use std::hint::select_unpredictable;

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

/// A scanline as the processors shift it out at its `Refresh`.
pub(crate) struct LineEnd<'a, O> {
    /// The scanline's instructions, by opcode, its `Refresh` included.
    pub(crate) tally: IssueTally,
    /// What they did in the processors.
    pub(crate) work: Work,
    /// The processors touched, half-open: only they may hold non-zero values.
    pub(crate) span: (usize, usize),
    /// `span`'s values, pixel-major.
    pub(crate) values: &'a [O],
}

/// The processors of an array of registers of arithmetic `A` (see the module
/// documentation).
pub(crate) struct Processors<A: Arith> {
    arith: A,
    channels: usize,
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
    /// The current scanline's instructions so far.
    tally: IssueTally,
    /// The current scanline's work so far.
    work: Work,
    /// Scratch space for a scanline converted for output.
    out: Vec<A::Out>,
    /// Plain `Eval`s pending, run side by side ([`crate::lanes`]).
    batch: Box<Batch<A::Reg>>,
    /// Whether `Eval`s may be batched: on a grey array of `f64` or `f32` registers
    /// ([`crate::lanes::batches`]).
    batches: bool,
    /// Whether this scanline's plain `Eval`s run in lanes: chosen at each `Refresh` from
    /// the scanline before ([`Processors::choose_lanes`]).
    lanes_on: bool,
    /// This scanline's `Eval`s of `SHORT + 1` to `MAX_LEN` processors that lanes took,
    /// and its `Eval2`s and `Eval3`s of that length that ran by their own chains.
    batchable: u32,
    /// Every scanline runs in lanes, whatever the one before was (for tests).
    always_lanes: bool,
}

impl<A: Arith> Processors<A> {
    /// `width` processors of `channels` channels, cleared, negative accumulation off.
    pub(crate) fn new(width: usize, channels: usize, arith: A) -> Self {
        let (w, c) = (width, channels);
        // a grey array batches `Eval`s: their lanes' spare accumulators follow its own
        let spare = if c == 1 && batches::<A>() { SPARE } else { 0 };
        Processors {
            arith,
            channels: c,
            acc: vec![A::ZERO; w * c + spare],
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
            tally: IssueTally::default(),
            work: Work::default(),
            out: Vec::new(),
            batch: Box::new(Batch::new(A::ZERO)),
            batches: c == 1 && batches::<A>(),
            lanes_on: false,
            batchable: 0,
            always_lanes: false,
        }
    }

    /// The same processors with every `Eval` run by its own chain: the reference the
    /// lanes are tested against.
    #[cfg(test)]
    pub(crate) fn without_batches(mut self) -> Self {
        self.batches = false;
        self
    }

    /// Whether the current scanline runs in lanes (for tests).
    #[cfg(test)]
    pub(crate) fn lanes_on(&self) -> bool {
        self.lanes_on
    }

    /// The same processors running every scanline in lanes, whatever the one before
    /// was (for tests).
    #[cfg(test)]
    pub(crate) fn always_in_lanes(mut self) -> Self {
        self.lanes_on = self.batches;
        self.always_lanes = true;
        self
    }

    /// Processors of the same size and arithmetic, cleared.
    pub(crate) fn fresh(&self) -> Self {
        Processors::new(self.flags.len(), self.channels, self.arith.clone())
    }

    /// No instruction since the last `Refresh` (or the start): the state is that of
    /// every scanline's start.
    pub(crate) fn between_scanlines(&self) -> bool {
        self.tally.first.is_none()
    }

    /// Whether negative accumulation is on.
    pub(crate) fn negative_enabled(&self) -> bool {
        self.negative_enabled
    }

    /// Sets negative accumulation, as an even or odd number of `Acc_mode`s before would.
    pub(crate) fn set_negative_enabled(&mut self, on: bool) {
        self.negative_enabled = on;
    }

    /// The arithmetic and the preload registers (`I`, `dI`, `ddI`, each `width ×
    /// channels`), taken between scanlines: the rest of the state is then every
    /// scanline's start, but a preload register keeps its value when a `Refresh` clears
    /// its flag (a probe shows it).
    pub(crate) fn into_registers(self) -> (A, [Vec<A::Reg>; 3]) {
        debug_assert!(self.between_scanlines());
        (self.arith, self.regs)
    }

    /// The instructions since the last `Refresh` and their work, taken (at the end of a
    /// trace: a scanline never refreshed).
    pub(crate) fn take_open_scanline(&mut self) -> (IssueTally, Work) {
        self.run_batch();
        (
            std::mem::take(&mut self.tally),
            std::mem::take(&mut self.work),
        )
    }

    /// Executes `instrs` in order, handing each scanline to `on_line` at its `Refresh`.
    #[inline]
    pub(crate) fn run<F: FnMut(LineEnd<'_, A::Out>)>(
        &mut self,
        instrs: &[Instruction],
        on_line: &mut F,
    ) {
        const { assert!(MAX_CHANNELS == 4) };
        // the channel count is a constant in the loop, decided once per call
        match self.channels {
            1 => self.run_with::<1, F>(instrs, on_line),
            2 => self.run_with::<2, F>(instrs, on_line),
            3 => self.run_with::<3, F>(instrs, on_line),
            _ => self.run_with::<4, F>(instrs, on_line),
        }
    }

    /// Executes one instruction, handing its scanline to `on_line` if it is a `Refresh`.
    #[inline]
    pub(crate) fn execute<F: FnMut(LineEnd<'_, A::Out>)>(
        &mut self,
        instr: &Instruction,
        on_line: &mut F,
    ) {
        match self.channels {
            1 => self.step::<1, F>(instr, on_line),
            2 => self.step::<2, F>(instr, on_line),
            3 => self.step::<3, F>(instr, on_line),
            _ => self.step::<4, F>(instr, on_line),
        }
    }

    fn run_with<const C: usize, F: FnMut(LineEnd<'_, A::Out>)>(
        &mut self,
        instrs: &[Instruction],
        on_line: &mut F,
    ) {
        debug_assert_eq!(C, self.channels);
        for instr in instrs {
            self.step::<C, F>(instr, on_line);
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

    fn set(&mut self, slot: usize, p: usize, v: &[A::Reg; MAX_CHANNELS]) {
        let c = self.channels;
        self.regs[slot][p * c..p * c + c].copy_from_slice(&v[..c]);
        self.flags[p] |= 1 << slot;
    }

    fn eval0<const C: usize>(&mut self, x: usize, dx: usize, v: &[A::Reg; MAX_CHANNELS]) -> u64 {
        debug_assert_eq!(C, self.channels);
        let c = C;
        let cur = self.evals + 1;
        let mut suppressed = 0;
        for p in x..x + dx {
            if self.flags[p] & LOCKED != 0 || (self.dis_pending && self.mask_stamp[p] == cur) {
                suppressed += 1;
                continue;
            }
            // `C` known here: a fixed-size store, not a call to `memcpy` per pixel
            self.acc[p * c..p * c + c].copy_from_slice(&v[..C]);
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
        self.work.updates += dx as u64;
        if !self.any_flags && !self.dis_pending {
            // No preloads, locks or masks on this scanline: the plain adder chain.
            let counts = ar.chain::<ORDER, C>(
                &mut self.acc[x * c..(x + dx) * c],
                Wave { v, d, dd },
                neg_ok,
            );
            self.work.dropped += counts.dropped;
            self.work.overflows += ovf + counts.overflows;
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
        self.work.dropped += dropped;
        self.work.suppressed += suppressed;
        self.work.overflows += ovf;
    }

    /// A plain `Eval` of `order` (1–3) of more than [`SHORT`] and at most [`MAX_LEN`]
    /// processors on a scanline that runs in lanes, `values` its operands: counted and
    /// its operands converted now, its chain run with the batch ([`crate::lanes`]), which
    /// runs first if the `Eval` does not fit in it.
    #[inline(always)]
    fn queue(&mut self, instr: &Instruction, order: u8, values: [f64; 3]) {
        let (x, dx) = (instr.x as usize, instr.dx as usize);
        let ar = &self.arith;
        // a lane advances all three registers, those beyond its order by the identity:
        // the operand of `slot`, or `A::IDENTITY` (counting nothing) beyond the order
        let operand = |slot: usize, reg: Register, ovf: &mut u64| {
            let mut o = 0;
            let r = ar.operand(reg, values[slot], &mut o);
            let carried = usize::from(order) > slot;
            *ovf += select_unpredictable(carried, o, 0);
            select_unpredictable(carried, r, A::IDENTITY)
        };
        let mut ovf = 0;
        let v = operand(0, Register::I, &mut ovf);
        let d = operand(1, Register::DI, &mut ovf);
        let dd = operand(2, Register::DDI, &mut ovf);
        self.work.updates += dx as u64;
        self.work.overflows += ovf;
        self.touch(x, x + dx);
        self.evals += 1;
        if !self.batch.try_push(order, x, dx, v, d, dd) {
            self.run_batch();
            let taken = self.batch.try_push(order, x, dx, v, d, dd);
            debug_assert!(taken, "an empty batch takes any Eval");
        }
        self.batchable += 1;
    }

    /// Runs the pending `Eval`s, if any, and adds what they counted to the scanline's work.
    #[inline(always)]
    fn run_batch(&mut self) {
        if self.batch.is_empty() {
            return;
        }
        let counts = self
            .batch
            .run(&self.arith, &mut self.acc, self.negative_enabled);
        self.work.dropped += counts.dropped;
        self.work.overflows += counts.overflows;
    }

    /// Counts an `Eval2` or `Eval3` of `dx` processors run by its own chain that a lane
    /// would take (whether a preload, lock or mask was in play the tally tells:
    /// [`Self::choose_lanes`]).
    #[inline(always)]
    fn count_batchable(&mut self, dx: usize) {
        self.batchable += u32::from(dx.wrapping_sub(SHORT + 1) < MAX_LEN - SHORT);
    }

    /// Whether the next scanline runs its plain `Eval`s in lanes: if this one had no
    /// preload, lock or mask and most of its `Eval`s were what a lane takes, counting
    /// `Eval1`s only when they ran in lanes (a frame's scanlines resemble their
    /// neighbours; an `Eval1` has no chain of its own to hide, so `Eval1`s alone do not
    /// start lanes).
    /// Lanes pay where short chains come several at a time; where most `Eval`s are single
    /// pixels, `Eval0`s or behind a preload, a pending batch only costs each a check.
    /// Either way the results are the same, bit for bit: only the time differs.
    fn choose_lanes(&mut self) {
        let ops = &self.tally.opcodes;
        let count = |list: &[Opcode]| list.iter().map(|&op| ops.get(op)).sum::<u64>();
        let evals = count(&[Opcode::Eval0, Opcode::Eval1, Opcode::Eval2, Opcode::Eval3]);
        // preloads, locks and masks keep the `Eval`s after them out of lanes
        let flagged = count(&[
            Opcode::SetI,
            Opcode::SetdI,
            Opcode::SetddI,
            Opcode::SetPI,
            Opcode::SetPdI,
            Opcode::SetPddI,
            Opcode::Eval0,
            Opcode::Dis,
        ]);
        let most = flagged == 0 && 2 * u64::from(self.batchable) > evals;
        self.lanes_on = self.batches && (self.always_lanes || most);
        self.batchable = 0;
    }

    /// Hands the scanline out and clears what it touched.
    fn refresh<F: FnMut(LineEnd<'_, A::Out>)>(&mut self, on_line: &mut F) {
        self.choose_lanes();
        let c = self.channels;
        let (lo, hi) = self.touched.take().unwrap_or((0, 0));
        on_line(LineEnd {
            tally: std::mem::take(&mut self.tally),
            work: std::mem::take(&mut self.work),
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
    }

    /// One instruction on an array of `C` channels: counted, then executed over its
    /// range; its work is added to the scanline's.
    #[inline(always)]
    fn step<const C: usize, F: FnMut(LineEnd<'_, A::Out>)>(
        &mut self,
        instr: &Instruction,
        on_line: &mut F,
    ) {
        self.tally.count(instr.op);
        let (x, dx) = (instr.x as usize, instr.dx as usize);
        if dx == 0 && is_eval(instr.op) {
            self.empty_eval::<C>(instr);
            return;
        }
        if C == 1 && self.lanes_on {
            // `Eval1`–`Eval3` as 0–2, every other opcode above: no branch on the order
            let order = (instr.op as u8).wrapping_sub(Opcode::Eval1 as u8);
            let plain = order < 3 && !self.any_flags && !self.dis_pending;
            if plain && dx > SHORT && dx <= MAX_LEN {
                if let Some(values) = instr.grey_values() {
                    return self.queue(instr, order + 1, values);
                }
            }
            // Pending lanes run before anything that could see them: anything but a
            // plain `Eval` apart from all of them (one too short for a lane, or too
            // long), which runs at once.
            if !plain || self.batch.meets(x, x + dx) {
                self.run_batch();
            }
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
                w.suppressed = self.eval0::<C>(x, dx, &v);
                w.updates = dx as u64;
                self.touch(x, x + dx);
                self.evals += 1;
                self.dis_pending = false;
            }
            Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                match instr.op {
                    Opcode::Eval1 => self.eval::<1, C>(instr),
                    Opcode::Eval2 => {
                        self.count_batchable(dx);
                        self.eval::<2, C>(instr)
                    }
                    _ => {
                        self.count_batchable(dx);
                        self.eval::<3, C>(instr)
                    }
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
                self.refresh(on_line);
                return;
            }
            Opcode::Nop => {}
        }
        let l = &mut self.work;
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
            self.work.overflows += ovf;
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
