//! Register arithmetic: how the engines store, convert and add register values.
//!
//! Both engines are generic over an [`Arith`]: the storage type of a register, the
//! conversion of an operand into a register role's format, the three adders of the
//! forward-differencing chain, and the conversion of an accumulator for output. Each
//! operation that overflows adds one to a counter the engine passes in.
//!
//! * [`Native`]`<T>`: a [`Sample`] type as it is (`f64`, the reference; no overflow
//!   counting). Its adders are `T::add`, unchanged, so the `f64` path is as fast as it
//!   was before numeric formats existed.
//! * [`F32Arith`]: `f32` registers, output as `f64`.
//! * [`FixedArith`]: a [`FixedFormat`], registers stored as `i64`, output as `f64`.
//!
//! The rules are those of [`crate::numeric`].

use crate::numeric::{sign_extend, FixedFormat, NumericError, Overflow, Register};
use crate::sample::Sample;
use cwisim_isa::MAX_CHANNELS;
use std::fmt::Debug;
use std::marker::PhantomData;

/// The arithmetic of the register file (see the module documentation).
pub trait Arith: Clone + Send + Sync + 'static {
    /// What one register holds.
    type Reg: Copy + Debug + Send + Sync + 'static;
    /// What a scanline hands to the sink.
    type Out: Sample;
    /// The reset value of every register.
    const ZERO: Self::Reg;
    /// The adders' identity: adding it to any register leaves its bits as they are and
    /// counts no overflow (`-0.0` for a float, `0` for fixed point).
    const IDENTITY: Self::Reg;
    /// Whether [`Self::operand`] may count an overflow; when false, converting an operand
    /// has no effect but its value (an engine may skip an unused conversion).
    const OPERAND_OVERFLOWS: bool = true;

    /// Converts an operand for register `reg`.
    fn operand(&self, reg: Register, x: f64, overflows: &mut u64) -> Self::Reg;
    /// `acc + v`, in the accumulator's format.
    fn accumulate(&self, acc: Self::Reg, v: Self::Reg, overflows: &mut u64) -> Self::Reg;
    /// `v + d`, in the `I` format.
    fn advance_v(&self, v: Self::Reg, d: Self::Reg, overflows: &mut u64) -> Self::Reg;
    /// `d + dd`, in the `dI` format.
    fn advance_d(&self, d: Self::Reg, dd: Self::Reg, overflows: &mut u64) -> Self::Reg;
    /// Whether a running value `v` (in the `I` format) is below zero.
    fn is_negative(&self, v: Self::Reg) -> bool;
    /// The value of register `reg` holding `r`, as `f64` (for probes).
    fn value(&self, reg: Register, r: Self::Reg) -> f64;
    /// An accumulator as output.
    fn out(&self, acc: Self::Reg) -> Self::Out;
    /// Accumulators as output; `buf` is scratch space the result may live in.
    fn emit<'s>(&self, acc: &'s [Self::Reg], buf: &'s mut Vec<Self::Out>) -> &'s [Self::Out] {
        buf.clear();
        buf.extend(acc.iter().map(|&r| self.out(r)));
        buf
    }

    /// The plain adder chain of one `Eval` of order `ORDER` (1–3) on processors of `C`
    /// channels, with no preload, lock or mask in its range: `acc` holds the range's
    /// accumulators (`C` per processor, processor-major) and `wave` the running
    /// registers at its first processor. Per processor and channel: `acc ← acc + v`
    /// (unless `v` is negative and `neg_ok` is false: then the contribution is dropped),
    /// then `v ← v + d` (`ORDER >= 2`), then `d ← d + dd` (`ORDER >= 3`).
    ///
    /// The default is exactly that, step by step ([`chain_steps`]); an implementation
    /// may compute it another way but must give the same registers and the same counts,
    /// bit for bit.
    #[inline]
    fn chain<const ORDER: usize, const C: usize>(
        &self,
        acc: &mut [Self::Reg],
        wave: Wave<Self::Reg>,
        neg_ok: bool,
    ) -> Counts {
        chain_steps::<Self, ORDER, C>(self, acc, wave, neg_ok)
    }
}

/// The running registers of a wave at one processor: `v`, `d`, `dd` per channel.
#[derive(Clone, Copy, Debug)]
pub struct Wave<R> {
    /// The value (`I` register role).
    pub v: [R; MAX_CHANNELS],
    /// The first difference (`dI`).
    pub d: [R; MAX_CHANNELS],
    /// The second difference (`ddI`).
    pub dd: [R; MAX_CHANNELS],
}

/// What an [`Arith::chain`] counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Contributions dropped by the `Acc_mode` rule.
    pub dropped: u64,
    /// Overflow events.
    pub overflows: u64,
}

/// [`Arith::chain`] step by step, with the arithmetic's adders: the definition every
/// implementation of `chain` must equal.
#[inline]
pub fn chain_steps<A: Arith, const ORDER: usize, const C: usize>(
    ar: &A,
    acc: &mut [A::Reg],
    wave: Wave<A::Reg>,
    neg_ok: bool,
) -> Counts {
    let Wave { mut v, mut d, dd } = wave;
    let (mut dropped, mut ovf) = (0u64, 0u64);
    for acc in acc.chunks_exact_mut(C) {
        for k in 0..C {
            if neg_ok || !ar.is_negative(v[k]) {
                acc[k] = ar.accumulate(acc[k], v[k], &mut ovf);
            } else {
                dropped += 1;
            }
            if ORDER >= 2 {
                v[k] = ar.advance_v(v[k], d[k], &mut ovf);
            }
            if ORDER >= 3 {
                d[k] = ar.advance_d(d[k], dd[k], &mut ovf);
            }
        }
    }
    Counts {
        dropped,
        overflows: ovf,
    }
}

/// Up to [`MAX_CHANNELS`] operand values for register `reg`; channels from `channels` on
/// stay zero.
#[inline]
pub(crate) fn vector<A: Arith>(
    arith: &A,
    reg: Register,
    v: &[f64],
    channels: usize,
    overflows: &mut u64,
) -> [A::Reg; MAX_CHANNELS] {
    let mut out = [A::ZERO; MAX_CHANNELS];
    for (o, x) in out.iter_mut().zip(v).take(channels) {
        *o = arith.operand(reg, *x, overflows);
    }
    out
}

/// A [`Sample`] type's own arithmetic: every register a `T`, `T::add` for every adder,
/// no overflow counting. `Native<f64>` is the reference.
pub struct Native<T>(PhantomData<fn() -> T>);

impl<T> Native<T> {
    /// The arithmetic of `T`.
    pub const fn new() -> Self {
        Native(PhantomData)
    }
}

impl<T> Default for Native<T> {
    fn default() -> Self {
        Native::new()
    }
}

impl<T> Clone for Native<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Native<T> {}

impl<T> Debug for Native<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Native<{}>", std::any::type_name::<T>())
    }
}

impl<T: Sample> Arith for Native<T> {
    type Reg = T;
    type Out = T;
    const ZERO: T = T::ZERO;
    const IDENTITY: T = T::IDENTITY;
    const OPERAND_OVERFLOWS: bool = false;

    #[inline]
    fn operand(&self, _reg: Register, x: f64, _overflows: &mut u64) -> T {
        T::from_f64(x)
    }
    #[inline]
    fn accumulate(&self, acc: T, v: T, _overflows: &mut u64) -> T {
        acc.add(v)
    }
    #[inline]
    fn advance_v(&self, v: T, d: T, _overflows: &mut u64) -> T {
        v.add(d)
    }
    #[inline]
    fn advance_d(&self, d: T, dd: T, _overflows: &mut u64) -> T {
        d.add(dd)
    }
    #[inline]
    fn is_negative(&self, v: T) -> bool {
        v.is_negative()
    }
    fn value(&self, _reg: Register, r: T) -> f64 {
        r.to_f64()
    }
    #[inline]
    fn out(&self, acc: T) -> T {
        acc
    }
    /// The accumulators themselves: no copy.
    #[inline]
    fn emit<'s>(&self, acc: &'s [T], _buf: &'s mut Vec<T>) -> &'s [T] {
        acc
    }
}

/// `f32` registers: operands rounded to `f32` on arrival, `f32` adds (to nearest, ties
/// to even); a non-finite result is an overflow event. Output as `f64` (exact).
#[derive(Clone, Copy, Debug, Default)]
pub struct F32Arith;

impl F32Arith {
    #[inline]
    fn check(r: f32, overflows: &mut u64) -> f32 {
        if !r.is_finite() {
            *overflows += 1;
        }
        r
    }
}

impl Arith for F32Arith {
    type Reg = f32;
    type Out = f64;
    const ZERO: f32 = 0.0;
    const IDENTITY: f32 = -0.0;

    #[inline]
    fn operand(&self, _reg: Register, x: f64, overflows: &mut u64) -> f32 {
        Self::check(x as f32, overflows)
    }
    #[inline]
    fn accumulate(&self, acc: f32, v: f32, overflows: &mut u64) -> f32 {
        Self::check(acc + v, overflows)
    }
    #[inline]
    fn advance_v(&self, v: f32, d: f32, overflows: &mut u64) -> f32 {
        Self::check(v + d, overflows)
    }
    #[inline]
    fn advance_d(&self, d: f32, dd: f32, overflows: &mut u64) -> f32 {
        Self::check(d + dd, overflows)
    }
    #[inline]
    fn is_negative(&self, v: f32) -> bool {
        v < 0.0
    }
    fn value(&self, _reg: Register, r: f32) -> f64 {
        f64::from(r)
    }
    #[inline]
    fn out(&self, acc: f32) -> f64 {
        f64::from(acc)
    }

    /// Without a check per add: a non-finite value stays non-finite along `v ← v + d`
    /// and `d ← d + dd` (`±inf + finite` is `±inf`, `inf − inf` and `NaN + x` are NaN),
    /// so the chains overflowed somewhere iff their last values are not finite, and an
    /// accumulator's add overflowed iff the value it left is not finite. The common
    /// case (everything finite: no events) costs one vectorized pass over `acc`; the
    /// rare case counts the events exactly again ([`F32Arith::recount`]).
    ///
    /// A dropped contribution adds `-0.0` instead, which leaves every `f32` as it is
    /// (`-0.0 + -0.0 = -0.0`; a quiet NaN stays the same NaN; registers never hold a
    /// signalling NaN, since every value comes from a conversion or an add).
    #[inline]
    fn chain<const ORDER: usize, const C: usize>(
        &self,
        acc: &mut [f32],
        wave: Wave<f32>,
        neg_ok: bool,
    ) -> Counts {
        let (dropped, mut bad, end) = if neg_ok {
            f32_chain::<ORDER, C, false>(acc, wave)
        } else {
            f32_chain::<ORDER, C, true>(acc, wave)
        };
        for k in 0..C {
            bad |= non_finite(end.v[k]) | non_finite(end.d[k]);
        }
        let overflows = if bad & 0x8000_0000 == 0 {
            0
        } else {
            Self::recount::<ORDER, C>(acc, wave, neg_ok)
        };
        Counts { dropped, overflows }
    }
}

/// Bit 31 set iff `x` is not finite: `(bits & exponent) + 2^23` carries into bit 31
/// iff the exponent is all ones.
#[inline]
fn non_finite(x: f32) -> u32 {
    (x.to_bits() & 0x7f80_0000) + 0x0080_0000
}

/// The `f32` chain without overflow checks; returns the dropped count, the OR of
/// [`non_finite`] over the accumulators it left, and the wave's registers after the
/// last processor. `DROP`: the `Acc_mode` rule is on (negative contributions are
/// dropped).
#[inline]
fn f32_chain<const ORDER: usize, const C: usize, const DROP: bool>(
    acc: &mut [f32],
    wave: Wave<f32>,
) -> (u64, u32, Wave<f32>) {
    let Wave { mut v, mut d, dd } = wave;
    let (mut dropped, mut bad) = (0u64, 0u32);
    for a in acc.chunks_exact_mut(C) {
        for k in 0..C {
            let x = v[k];
            let drop = DROP && x < 0.0;
            dropped += u64::from(drop);
            let s = a[k] + if drop { -0.0 } else { x };
            a[k] = s;
            bad |= non_finite(s);
            if ORDER >= 2 {
                v[k] += d[k];
            }
            if ORDER >= 3 {
                d[k] += dd[k];
            }
        }
    }
    (dropped, bad, Wave { v, d, dd })
}

impl F32Arith {
    /// The overflow events of an `f32` chain that has run on `acc` from `wave`: its
    /// `v`/`d` adds again, counted, and each accumulator add that left a non-finite value.
    #[cold]
    pub(crate) fn recount<const ORDER: usize, const C: usize>(
        acc: &[f32],
        wave: Wave<f32>,
        neg_ok: bool,
    ) -> u64 {
        let Wave { mut v, mut d, dd } = wave;
        let mut ovf = 0u64;
        for a in acc.chunks_exact(C) {
            for k in 0..C {
                if (neg_ok || !F32Arith.is_negative(v[k])) && !a[k].is_finite() {
                    ovf += 1;
                }
                if ORDER >= 2 {
                    v[k] = Self::check(v[k] + d[k], &mut ovf);
                }
                if ORDER >= 3 {
                    d[k] = Self::check(d[k] + dd[k], &mut ovf);
                }
            }
        }
        ovf
    }
}

/// One register's format, ready for use.
#[derive(Clone, Copy, Debug)]
struct Fit {
    frac: u32,
    width: u32,
    min: i64,
    max: i64,
    wrap: bool,
    /// `2^-frac`.
    scale: f64,
    /// `2^frac`.
    up: f64,
}

impl Fit {
    fn new(q: crate::numeric::Q, overflow: Overflow) -> Fit {
        Fit {
            frac: q.frac_bits,
            width: q.width(),
            min: q.min_raw(),
            max: q.max_raw(),
            wrap: overflow == Overflow::Wrap,
            scale: q.quantum(),
            up: f64::from(q.frac_bits).exp2(),
        }
    }

    /// An exact integer brought into range by the overflow policy.
    #[inline]
    fn fit(&self, x: i128, overflows: &mut u64) -> i64 {
        if x >= i128::from(self.min) && x <= i128::from(self.max) {
            return x as i64;
        }
        *overflows += 1;
        if self.wrap {
            sign_extend(x as u128, self.width)
        } else if x < 0 {
            self.min
        } else {
            self.max
        }
    }

    /// An operand: rounded to the nearest multiple of `2^-frac`, ties to even, exactly,
    /// then fitted. Non-finite values (never in a checked trace) saturate, NaN to 0, and
    /// count as overflows.
    ///
    /// The common case in `f64`: `y = x · 2^frac` is exact (a power-of-two scaling of a
    /// finite value that does not overflow; a subnormal `x` only gains exponent), so when
    /// `|y| < 2^63` its rounding ([`rounded_small`] below `2^51`, [`round_ties_even`]
    /// then; both exact) is the integer [`round_scaled`] computes, and it converts to
    /// `i64` exactly. Otherwise (huge, or not finite) the bit-level path.
    #[inline]
    fn operand(&self, x: f64, overflows: &mut u64) -> i64 {
        let y = x * self.up;
        let r = if y.abs() < TWO_51 {
            rounded_small(y)
        } else if y.abs() < TWO_63 {
            round_ties_even(y) as i64
        } else {
            return self.operand_bits(x, overflows);
        };
        if r >= self.min && r <= self.max {
            return r;
        }
        self.fit(i128::from(r), overflows)
    }

    /// [`Fit::operand`] from the bits of `x`, for every `x`.
    fn operand_bits(&self, x: f64, overflows: &mut u64) -> i64 {
        if !x.is_finite() {
            *overflows += 1;
            return if x.is_nan() {
                0
            } else if x < 0.0 {
                self.min
            } else {
                self.max
            };
        }
        let (r, exact) = round_scaled(x, self.frac);
        if exact {
            self.fit(r, overflows)
        } else {
            // |x · 2^frac| >= 2^126: out of every format's range; `r` is it mod 2^128.
            *overflows += 1;
            if self.wrap {
                sign_extend(r as u128, self.width)
            } else if x < 0.0 {
                self.min
            } else {
                self.max
            }
        }
    }
}

/// `2^63`.
const TWO_63: f64 = 9_223_372_036_854_775_808.0;
/// `2^51`.
const TWO_51: f64 = 2_251_799_813_685_248.0;
/// `2^52 + 2^51`.
const MAGIC: f64 = 6_755_399_441_055_744.0;

/// `y` rounded to an integer, ties to even, as `i64`, for `|y| < 2^51`: `t = y + M`
/// with `M = 2^52 + 2^51` lies in `(2^52, 2^53]`, where the spacing is 1, so the add
/// rounds `y` at the units (ties to even, `M` being even), and the bits of `t` minus
/// those of `M` are `t − M` (the significand field counts units there, and crossing
/// into `2^53` carries into the exponent field exactly).
#[inline]
fn rounded_small(y: f64) -> i64 {
    ((y + MAGIC).to_bits() as i64).wrapping_sub(MAGIC.to_bits() as i64)
}

/// `y` rounded to an integer, ties to even, for `|y| < 2^63`: below `2^52`, adding and
/// subtracting `±2^52` (the sign of `y`) rounds at the units (the sum lies in
/// `[2^52, 2^53)` in magnitude, where the spacing is 1, and `2^52` is even, so ties go to
/// the even integer) and the subtraction is exact; from `2^52` on every `f64` is an
/// integer. (`f64::round_ties_even` is a library call on x86-64 without SSE4.1.)
#[inline]
fn round_ties_even(y: f64) -> f64 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    if y.abs() < TWO_52 {
        let c = TWO_52.copysign(y);
        (y + c) - c
    } else {
        y
    }
}

/// `round(x · 2^frac)` to the nearest integer, ties to even, computed exactly from the
/// bits of `x` (finite). Returns the integer modulo 2^128 and whether it is exact (its
/// magnitude below 2^126).
fn round_scaled(x: f64, frac: u32) -> (i128, bool) {
    let bits = x.to_bits();
    let negative = bits >> 63 != 0;
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let field = bits & ((1u64 << 52) - 1);
    // x = m · 2^e
    let (m, e) = if exp == 0 {
        (field, -1074)
    } else {
        (field | (1u64 << 52), exp - 1075)
    };
    let k = e + frac as i32;
    let m = u128::from(m);
    let (magnitude, exact) = if m == 0 {
        (0, true)
    } else if k >= 0 {
        let k = k as u32;
        let top = 128 - m.leading_zeros() + k; // bits of m · 2^k
        let value = if k >= 128 { 0 } else { m << k };
        (value, top <= 126)
    } else {
        let s = (-k) as u32;
        if s > 64 {
            // m < 2^53, so m · 2^-s < 2^-11: rounds to 0
            (0, true)
        } else {
            let q = m >> s;
            let rem = m & ((1u128 << s) - 1);
            let half = 1u128 << (s - 1);
            let up = rem > half || (rem == half && q & 1 == 1);
            (q + u128::from(up), true)
        }
    };
    let signed = if negative {
        magnitude.wrapping_neg() as i128
    } else {
        magnitude as i128
    };
    (signed, exact)
}

/// One adder: `a + b` at the finer of the two fraction counts, truncated toward −∞ to
/// `a`'s format (the destination), then fitted.
#[derive(Clone, Copy, Debug)]
struct Adder {
    dst: Fit,
    /// `b` is aligned to `a` by `(b >> right) << left`; one of the two is 0.
    right: u32,
    left: u32,
}

impl Adder {
    fn new(dst: Fit, src: Fit) -> Adder {
        Adder {
            dst,
            right: src.frac.saturating_sub(dst.frac),
            left: dst.frac.saturating_sub(src.frac),
        }
    }

    /// The exact sum at the finer fraction count, floored to `a`'s: since `a` is a
    /// multiple of the dropped quantum, that is `a + floor(b / 2^(fb−fa))` when `b` is
    /// finer and `a + b·2^(fa−fb)` otherwise. `b` shifted left has at most
    /// `64 + 63` bits, so the sum fits `i128`.
    #[inline]
    fn add(&self, a: i64, b: i64, overflows: &mut u64) -> i64 {
        if self.left == 0 {
            // The common case in i64: no shift up, a sum that neither overflows i64 nor
            // leaves the destination's range.
            let (s, out) = a.overflowing_add(b >> self.right);
            if !out && s >= self.dst.min && s <= self.dst.max {
                return s;
            }
        }
        self.dst.fit(i128::from(a) + self.aligned(b), overflows)
    }

    /// `b` aligned to the destination's fraction bits, exactly: `(b >> right) << left`.
    #[inline]
    fn aligned(&self, b: i64) -> i128 {
        i128::from(b >> self.right) << self.left
    }

    /// [`Adder::aligned`] if it fits `i64`.
    #[inline]
    fn aligned_i64(&self, b: i64) -> Option<i64> {
        let y = b >> self.right;
        let z = y << self.left;
        (z >> self.left == y).then_some(z)
    }
}

/// Fixed-point arithmetic for one [`FixedFormat`]: raw `i64` registers.
#[derive(Clone, Copy, Debug)]
pub struct FixedArith {
    format: FixedFormat,
    /// The formats of `I`, `dI`, `ddI`, `acc` (by [`Register`] index).
    fits: [Fit; 4],
    acc: Adder,
    v: Adder,
    d: Adder,
    /// `acc + aligned(v)` fits `i64` for every `acc` and `v` in their formats.
    acc_in_i64: bool,
    /// The bits of `acc − acc_min` (as `u64`) that only a sum outside `acc`'s range sets:
    /// those from bit `width` on (none when `acc` is 64 bits wide).
    acc_out_bits: u64,
}

impl FixedArith {
    /// The arithmetic of `format`, checked against the limits.
    pub fn new(format: &FixedFormat) -> Result<FixedArith, NumericError> {
        format.validate()?;
        let fit = |r: Register| Fit::new(format.q(r), format.overflow);
        let fits = [
            fit(Register::I),
            fit(Register::DI),
            fit(Register::DDI),
            fit(Register::Acc),
        ];
        let acc = Adder::new(fits[3], fits[0]);
        // `aligned` is monotone, so the extremes of `I` give the extremes of its image.
        let (lo, hi) = (acc.aligned(fits[0].min), acc.aligned(fits[0].max));
        let i64_range = i128::from(i64::MIN)..=i128::from(i64::MAX);
        let acc_in_i64 = i64_range.contains(&(i128::from(fits[3].min) + lo))
            && i64_range.contains(&(i128::from(fits[3].max) + hi))
            && i64_range.contains(&lo)
            && i64_range.contains(&hi);
        let acc_out_bits = if fits[3].width >= 64 {
            0
        } else {
            u64::MAX << fits[3].width
        };
        Ok(FixedArith {
            format: *format,
            acc,
            v: Adder::new(fits[0], fits[1]),
            d: Adder::new(fits[1], fits[2]),
            fits,
            acc_in_i64,
            acc_out_bits,
        })
    }

    /// If the wave's `v` and `d` adders provably stay in range (no overflow event, so no
    /// fitting) for `n` processors from `wave` (the advances at the last processor
    /// included), and every aligned `d` and `dd` the chain adds fits `i64`: `dd` aligned
    /// to `d`'s format, per channel. Then the chain is plain `i64` arithmetic:
    ///
    /// * `d` (`ORDER` 3) gains the same `s = aligned(dd)` every step, so
    ///   `d_k = d_0 + k·s` exactly, and it stays in range for `k <= n` iff `d_n` does
    ///   (`d_0` is in range, and the range is an interval);
    /// * `v` gains `a_k = aligned(d_k)` at step `k`, a monotone function of a monotone
    ///   sequence, so every `a_k` (`k < n`) lies between `a_0` and `a_{n−1}`, and
    ///   `v_k − v_0 = Σ_{j<k} a_j` lies in `[min(0, n·a_min), max(0, n·a_max)]` for
    ///   `k <= n`.
    ///
    /// The bounds are computed with checked `i64` operations; one that overflows gives
    /// `None` (the step-by-step chain then runs, so a bound that is merely not proved
    /// costs time, never exactness).
    #[inline]
    fn quiet_wave<const ORDER: usize, const C: usize>(
        &self,
        wave: &Wave<i64>,
        n: usize,
    ) -> Option<[i64; MAX_CHANNELS]> {
        let mut steps = [0i64; MAX_CHANNELS];
        if ORDER < 2 || n == 0 {
            return Some(steps);
        }
        let n = i64::try_from(n).ok()?;
        let [fi, fd] = [self.fits[0], self.fits[1]];
        for (k, step) in steps[..C].iter_mut().enumerate() {
            let d0 = wave.d[k];
            let mut last = d0;
            if ORDER >= 3 {
                let s = self.d.aligned_i64(wave.dd[k])?;
                *step = s;
                let dn = n.checked_mul(s)?.checked_add(d0)?;
                if dn < fd.min || dn > fd.max {
                    return None;
                }
                // d_{n-1} lies between d_0 and d_n
                last = dn - s;
            }
            let (a0, a1) = (self.v.aligned_i64(d0)?, self.v.aligned_i64(last)?);
            let (lo, hi) = (a0.min(a1), a0.max(a1));
            let v0 = wave.v[k];
            let low = v0.checked_add(n.checked_mul(lo)?.min(0))?;
            let high = v0.checked_add(n.checked_mul(hi)?.max(0))?;
            if low < fi.min || high > fi.max {
                return None;
            }
        }
        Some(steps)
    }

    /// Brings accumulators holding exact `i64` sums into range: nothing to do unless a
    /// sum left the range, which `bits`, the OR of `acc − acc_min` (as `u64`) over the
    /// sums, shows: a value in range sets no bit from `width` on, one outside sets one
    /// (`width <= 63` there, since `acc + aligned(v)` fits `i64`). Returns the overflow
    /// events: one per sum outside the range, fitted as its adder would have.
    #[inline]
    fn settle(&self, acc: &mut [i64], bits: u64) -> u64 {
        if bits & self.acc_out_bits == 0 {
            return 0;
        }
        self.settle_all(acc)
    }

    #[cold]
    fn settle_all(&self, acc: &mut [i64]) -> u64 {
        let f = self.fits[3];
        let mut ovf = 0;
        for s in acc {
            *s = f.fit(i128::from(*s), &mut ovf);
        }
        ovf
    }

    /// The format.
    pub fn format(&self) -> &FixedFormat {
        &self.format
    }
}

impl Arith for FixedArith {
    type Reg = i64;
    type Out = f64;
    const ZERO: i64 = 0;
    const IDENTITY: i64 = 0;

    #[inline]
    fn operand(&self, reg: Register, x: f64, overflows: &mut u64) -> i64 {
        self.fits[reg as usize].operand(x, overflows)
    }
    #[inline]
    fn accumulate(&self, acc: i64, v: i64, overflows: &mut u64) -> i64 {
        self.acc.add(acc, v, overflows)
    }
    #[inline]
    fn advance_v(&self, v: i64, d: i64, overflows: &mut u64) -> i64 {
        self.v.add(v, d, overflows)
    }
    #[inline]
    fn advance_d(&self, d: i64, dd: i64, overflows: &mut u64) -> i64 {
        self.d.add(d, dd, overflows)
    }
    #[inline]
    fn is_negative(&self, v: i64) -> bool {
        v < 0
    }
    fn value(&self, reg: Register, r: i64) -> f64 {
        r as f64 * self.fits[reg as usize].scale
    }
    #[inline]
    fn out(&self, acc: i64) -> f64 {
        acc as f64 * self.fits[3].scale
    }

    /// As [`Arith::out`] each; for an accumulator at most 52 bits wide through
    /// [`small_to_f64`], which vectorizes (`i64 as f64` does not, before AVX-512).
    fn emit<'s>(&self, acc: &'s [i64], buf: &'s mut Vec<f64>) -> &'s [f64] {
        buf.clear();
        let scale = self.fits[3].scale;
        if self.fits[3].width <= 52 {
            buf.extend(acc.iter().map(|&r| small_to_f64(r) * scale));
        } else {
            buf.extend(acc.iter().map(|&r| r as f64 * scale));
        }
        buf
    }

    /// In `i64` without a check per add when [`FixedArith::quiet_wave`] proves that `v`
    /// and `d` stay in range and every `acc + aligned(v)` fits `i64` (decided once per
    /// format): the accumulators then hold the exact sums, which
    /// [`FixedArith::settle`] fits afterwards, counting the sums outside the range (each
    /// accumulator is added to at most once per channel). A dropped contribution adds 0,
    /// which changes nothing. Otherwise [`chain_steps`].
    #[inline]
    fn chain<const ORDER: usize, const C: usize>(
        &self,
        acc: &mut [i64],
        wave: Wave<i64>,
        neg_ok: bool,
    ) -> Counts {
        let quiet = if self.acc_in_i64 {
            self.quiet_wave::<ORDER, C>(&wave, acc.len() / C)
        } else {
            None
        };
        let Some(steps) = quiet else {
            return chain_steps::<Self, ORDER, C>(self, acc, wave, neg_ok);
        };
        let (dropped, bits) = if neg_ok {
            self.fixed_chain::<ORDER, C, false>(acc, wave, steps)
        } else {
            self.fixed_chain::<ORDER, C, true>(acc, wave, steps)
        };
        Counts {
            dropped,
            overflows: self.settle(acc, bits),
        }
    }
}

impl FixedArith {
    /// The chain in plain `i64` arithmetic (see [`Arith::chain`] for `FixedArith`):
    /// `steps` are the aligned `dd`s. Returns the dropped count and the OR of
    /// `acc − acc_min` over the sums ([`FixedArith::settle`]). `DROP`: the `Acc_mode`
    /// rule is on.
    #[inline]
    fn fixed_chain<const ORDER: usize, const C: usize, const DROP: bool>(
        &self,
        acc: &mut [i64],
        wave: Wave<i64>,
        steps: [i64; MAX_CHANNELS],
    ) -> (u64, u64) {
        let Wave { mut v, mut d, .. } = wave;
        let (ra, la) = (self.acc.right, self.acc.left);
        let (rv, lv) = (self.v.right, self.v.left);
        let min = self.fits[3].min;
        let (mut dropped, mut bits) = (0u64, 0u64);
        for a in acc.chunks_exact_mut(C) {
            for k in 0..C {
                let x = v[k];
                let drop = DROP && x < 0;
                dropped += u64::from(drop);
                let s = a[k] + if drop { 0 } else { (x >> ra) << la };
                a[k] = s;
                bits |= s.wrapping_sub(min) as u64;
                if ORDER >= 2 {
                    v[k] += (d[k] >> rv) << lv;
                }
                if ORDER >= 3 {
                    d[k] += steps[k];
                }
            }
        }
        (dropped, bits)
    }
}

/// `r as f64`, exactly, for `|r| <= 2^51`, in operations that vectorize: the bits of
/// `2^52 + 2^51` plus `r` are the `f64` `2^52 + 2^51 + r` (the sum stays in
/// `[2^52, 2^53)`, where the spacing is 1), and subtracting `2^52 + 2^51` is exact (`+0.0`
/// for 0, as `0 as f64`).
#[inline]
fn small_to_f64(r: i64) -> f64 {
    f64::from_bits(MAGIC.to_bits().wrapping_add(r as u64)) - MAGIC
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::{Numeric, Q};

    fn fixed(s: &str) -> FixedArith {
        match s.parse::<Numeric>().unwrap() {
            Numeric::Fixed(f) => FixedArith::new(&f).unwrap(),
            _ => panic!("not fixed"),
        }
    }

    #[test]
    fn operands_round_to_nearest_ties_to_even() {
        let a = fixed("fixed:I=8.2,dI=8.2,ddI=8.2");
        let mut o = 0;
        let r = |x: f64, o: &mut u64| a.operand(Register::I, x, o);
        // quanta of 0.25: 0.125 is a tie between 0 and 1 quantum → 0 (even)
        assert_eq!(r(0.125, &mut o), 0);
        assert_eq!(r(0.375, &mut o), 2);
        assert_eq!(r(-0.125, &mut o), 0);
        assert_eq!(r(-0.375, &mut o), -2);
        assert_eq!(r(0.126, &mut o), 1);
        assert_eq!(r(-0.2, &mut o), -1);
        assert_eq!(r(5e-324, &mut o), 0);
        assert_eq!(o, 0);
        // range [-128, 127.75]: 127.8 rounds to 511.2 → 511 quanta; 127.9 → 512 saturates
        assert_eq!(r(127.8, &mut o), 511);
        assert_eq!(r(127.9, &mut o), 511);
        assert_eq!(r(-1e300, &mut o), -512);
        assert_eq!(o, 2);
    }

    #[test]
    fn huge_operands_wrap_exactly() {
        let a = fixed("fixed:I=8.2,dI=8.2,ddI=8.2,overflow=wrap");
        let mut o = 0;
        // Q8.2 is 10 bits: 200 · 4 = 800 ≡ -224 (mod 1024)
        assert_eq!(a.operand(Register::I, 200.0, &mut o), -224);
        assert_eq!(a.operand(Register::I, -200.0, &mut o), 224);
        // beyond i128 (scaled >= 2^126) an f64 is a multiple of 2^73: ≡ 0
        assert_eq!(a.operand(Register::I, 2f64.powi(200), &mut o), 0);
        assert_eq!(a.operand(Register::I, 1.5 * 2f64.powi(126), &mut o), 0);
        assert_eq!(o, 4);
        // 2^63 in Q64.0 wraps to i64::MIN, exactly
        let b = FixedArith::new(&crate::numeric::FixedFormat {
            i: Q::new(64, 0).unwrap(),
            di: Q::new(64, 0).unwrap(),
            ddi: Q::new(64, 0).unwrap(),
            acc: Q::new(64, 0).unwrap(),
            overflow: Overflow::Wrap,
        })
        .unwrap();
        assert_eq!(b.operand(Register::I, 2f64.powi(63), &mut o), i64::MIN);
        assert_eq!(b.operand(Register::I, -(2f64.powi(63)), &mut o), i64::MIN);
        assert_eq!(b.operand(Register::I, 2f64.powi(64) + 4096.0, &mut o), 4096);
        assert_eq!(o, 6);
    }

    #[test]
    fn adders_truncate_toward_minus_infinity_into_the_destination() {
        // acc has 1 fraction bit, I has 3: acc + v drops two bits, rounding down
        let a = fixed("fixed:I=8.3,dI=8.3,ddI=8.3,acc=8.1");
        let mut o = 0;
        // 0.5 + 0.375 = 0.875 → 0.5 ; 0.5 - 0.125 = 0.375 → 0.0 ; -0.125 → -0.5
        assert_eq!(a.accumulate(1, 3, &mut o), 1);
        assert_eq!(a.accumulate(1, -1, &mut o), 0);
        assert_eq!(a.accumulate(0, -1, &mut o), -1);
        // the coarser source is shifted up, exactly
        let b = fixed("fixed:I=8.1,dI=8.1,ddI=8.1,acc=8.3");
        assert_eq!(b.accumulate(1, 1, &mut o), 5);
        assert_eq!(o, 0);
        // saturation and wrap of the destination
        // acc is Q8.1: raw [-256, 255]
        assert_eq!(a.accumulate(255, 100, &mut o), 255);
        let w = fixed("fixed:I=8.3,dI=8.3,ddI=8.3,acc=8.1,overflow=wrap");
        assert_eq!(w.accumulate(255, 4, &mut o), -256);
        assert_eq!(o, 2);
        // the widest formats: Q64.0 + Q1.63 forms the sum in i128 without loss
        let x = FixedArith::new(&crate::numeric::FixedFormat {
            i: Q::new(1, 63).unwrap(),
            di: Q::new(1, 63).unwrap(),
            ddi: Q::new(1, 63).unwrap(),
            acc: Q::new(64, 0).unwrap(),
            overflow: Overflow::Saturate,
        })
        .unwrap();
        assert_eq!(x.accumulate(i64::MAX, -1, &mut o), i64::MAX - 1);
        assert_eq!(x.accumulate(i64::MIN, i64::MIN, &mut o), i64::MIN);
        assert_eq!(o, 3);
        assert_eq!(x.accumulate(5, i64::MAX, &mut o), 5);
    }

    #[test]
    fn f32_counts_non_finite_results() {
        let a = F32Arith;
        let mut o = 0;
        assert_eq!(a.operand(Register::I, 1e39, &mut o), f32::INFINITY);
        assert_eq!(a.accumulate(f32::MAX, f32::MAX, &mut o), f32::INFINITY);
        assert!(a
            .advance_v(f32::INFINITY, f32::NEG_INFINITY, &mut o)
            .is_nan());
        assert_eq!(a.advance_d(1.0, 2.0, &mut o), 3.0);
        assert_eq!(o, 3);
        // rounding on arrival: to nearest, ties to even
        assert_eq!(a.operand(Register::I, 1.0 + 2f64.powi(-24), &mut o), 1.0);
        assert_eq!(
            a.operand(Register::I, 1.0 + 3.0 * 2f64.powi(-24), &mut o),
            1.0 + 2f32.powi(-22)
        );
    }

    proptest::proptest! {
        #[test]
        fn rounding_tricks_equal_the_standard_library(bits in proptest::prelude::any::<u64>()) {
            let y = f64::from_bits(bits);
            if y.abs() < TWO_51 {
                proptest::prop_assert_eq!(rounded_small(y), y.round_ties_even() as i64);
            }
            if y.abs() < TWO_63 {
                proptest::prop_assert_eq!(round_ties_even(y), y.round_ties_even());
            }
        }

        #[test]
        fn small_integers_convert_exactly(r in -(1i64 << 51)..=(1i64 << 51)) {
            proptest::prop_assert_eq!(small_to_f64(r).to_bits(), (r as f64).to_bits());
        }

        #[test]
        fn rounding_tricks_at_half_integers(n in -(1i64 << 50)..(1i64 << 50)) {
            let y = n as f64 + 0.5;
            proptest::prop_assert_eq!(rounded_small(y), y.round_ties_even() as i64);
            proptest::prop_assert_eq!(round_ties_even(y), y.round_ties_even());
        }
    }
}
