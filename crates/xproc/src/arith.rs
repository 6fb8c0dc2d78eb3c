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
use cwisim_isa::{Intensity, MAX_CHANNELS};
use std::fmt::Debug;
use std::marker::PhantomData;

/// The arithmetic of the register file (see the module documentation).
pub trait Arith: Send + Sync + 'static {
    /// What one register holds.
    type Reg: Copy + Debug + Send + Sync + 'static;
    /// What a scanline hands to the sink.
    type Out: Sample;
    /// The reset value of every register.
    const ZERO: Self::Reg;

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
}

/// Up to [`MAX_CHANNELS`] operand values for register `reg`; channels from `channels` on
/// stay zero.
#[inline]
pub(crate) fn vector<A: Arith>(
    arith: &A,
    reg: Register,
    v: &Intensity,
    channels: usize,
    overflows: &mut u64,
) -> [A::Reg; MAX_CHANNELS] {
    let mut out = [A::ZERO; MAX_CHANNELS];
    for (o, x) in out.iter_mut().zip(v.as_slice()).take(channels) {
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
    fn operand(&self, x: f64, overflows: &mut u64) -> i64 {
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
        let b = i128::from(b >> self.right) << self.left;
        self.dst.fit(i128::from(a) + b, overflows)
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
        Ok(FixedArith {
            format: *format,
            acc: Adder::new(fits[3], fits[0]),
            v: Adder::new(fits[0], fits[1]),
            d: Adder::new(fits[1], fits[2]),
            fits,
        })
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
}
