//! Numeric formats of the X-processor registers: `f64` (the reference), `f32`, and
//! two's-complement fixed point with a format per register role.
//!
//! A [`Numeric`] is parsed from, and displayed as, a canonical one-line string:
//!
//! | string | meaning |
//! | --- | --- |
//! | `f64` | every register an IEEE binary64 (the reference; no overflow counting) |
//! | `f32` | every register an IEEE binary32 |
//! | `fixed:I=12.20,dI=4.28,ddI=1.36` | fixed point, a [`Q`] format per register |
//! | `…,acc=16.20` | the accumulator's format (default: the `I` format) |
//! | `…,overflow=wrap` | the overflow policy (default: `saturate`) |
//!
//! `M.N` is a [`Q`] format: `M` integer bits **including the sign bit** (so `M >= 1`) and
//! `N` fraction bits; the register is `M + N <= 64` bits wide and holds the multiples of
//! `2^-N` in `[-2^(M-1), 2^(M-1) - 2^-N]`. [`Numeric`]'s `Display` always writes every
//! field (`acc` and `overflow` included), and parsing that string gives the same value.
//!
//! # Semantics (also `docs/ISA.md`, "Numeric formats", and `docs/ACCURACY.md`)
//!
//! **Fixed point.** The registers `I`, `dI`, `ddI` (preloads and the wave's running `v`,
//! `d`, `dd`) and `acc` each have their own [`Q`] format.
//!
//! * *Operand conversion.* Every value operand is converted once, when its instruction
//!   enters the array, into the format of the register it is written to: the `I`
//!   operand of `Eval1`–`Eval3` and `SetI`/`SetPI` into the `I` format, `dI` operands
//!   into `dI`, `ddI` into `ddI`, and `Eval0`'s `I` (which sets `acc`) into the `acc`
//!   format. The value is **rounded to the nearest** multiple of `2^-N`, **ties to
//!   even**, computed exactly from the `f64` operand (no intermediate rounding), then the
//!   overflow policy applies. Only the operands an opcode has are converted.
//! * *Adders.* `acc ← acc + v`, `v ← v + d` and `d ← d + dd` are computed exactly at the
//!   finer of the two operands' fraction bits, then brought to the destination
//!   register's format (always the first operand's) by **truncation toward −∞** (the low
//!   bits are dropped, as a hardware adder wired to a narrower register does), then the
//!   overflow policy of the destination applies.
//! * *Overflow.* `wrap`: two's complement modulo `2^(M+N)`; `saturate`: clamped to the
//!   format's range. Every wrap or saturation (operand conversions included) is one
//!   overflow event, counted per channel in `LineStats::overflows` — including the
//!   advance at the last processor of a range, whose result is then unused (the adder
//!   still computes it).
//! * *Drop rule.* "Negative" for the `Acc_mode` drop rule is the sign of `v` in the `I`
//!   format (fixed point has no negative zero).
//! * *Output.* A scanline hands the accumulator's value to the sink as `f64`:
//!   `raw · 2^-N`, exact when the value has at most 53 significant bits (always for
//!   `acc` formats up to 53 bits wide), otherwise rounded to the nearest `f64`.
//!
//! **f32.** Every register is an `f32`; operands are rounded to `f32` on arrival (to
//! nearest, ties to even) and each add is an `f32` add (to nearest, ties to even). A
//! conversion or add whose result is not finite (±inf, or NaN from `inf − inf`) does not
//! panic; it is counted as an overflow event.
//!
//! **f64.** The reference: exactly the simulator's `f64` registers; no overflow counting
//! (trace operands are finite and an `f64` sum overflowing to ±inf shows in the output).
//!
//! # Limits
//!
//! Per register: `M >= 1` (the sign bit) and `M + N <= 64`. Nothing else: registers are
//! stored as `i64` and every adder sum is formed exactly in `i128`.
//!
//! # Closed form
//!
//! When `I`, `dI`, `ddI` and `acc` share one width and one fraction count and overflow is
//! `wrap`, every adder is integer addition modulo `2^n`, so the wave's value at step `k` is
//! `v0 + k·d0 + k(k−1)/2·dd0 (mod 2^n)` exactly: [`wave_closed_form`]. The engines still
//! add step by step, since they count overflow events (the closed form gives the values,
//! not how many times the chain wrapped) and need the value at every processor anyway.
//!
//! # Error bound
//!
//! [`error_bound`] gives the worst-case distance between a fixed-point wave and exact
//! arithmetic on the same operands (`docs/ACCURACY.md` derives it).

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::str::FromStr;

/// The widest register, in bits.
pub const MAX_BITS: u32 = 64;

/// The number format of the array's registers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Numeric {
    /// IEEE binary64 registers: the reference.
    #[default]
    F64,
    /// IEEE binary32 registers.
    F32,
    /// Two's-complement fixed point, one format per register role.
    Fixed(FixedFormat),
}

/// Fixed-point formats of the four register roles and the overflow policy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FixedFormat {
    /// `I` preloads and the wave's running value `v`.
    pub i: Q,
    /// `dI` preloads and the running first difference `d`.
    pub di: Q,
    /// `ddI` preloads and the second difference `dd`.
    pub ddi: Q,
    /// The accumulator.
    pub acc: Q,
    /// What a result outside a register's range becomes.
    pub overflow: Overflow,
}

/// A two's-complement fixed-point format: `int_bits` integer bits **including the sign
/// bit** and `frac_bits` fraction bits; the value of a raw register `r` is `r · 2^-frac_bits`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Q {
    /// Integer bits, sign bit included (at least 1).
    pub int_bits: u32,
    /// Fraction bits.
    pub frac_bits: u32,
}

/// The overflow policy of fixed-point registers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Overflow {
    /// Two's complement modulo `2^width`.
    Wrap,
    /// Clamped to the format's range.
    #[default]
    Saturate,
}

/// One of the four register roles of an X-processor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Register {
    /// `I` and the running value `v`.
    I = 0,
    /// `dI` and the running first difference `d`.
    DI = 1,
    /// `ddI` and the second difference `dd`.
    DDI = 2,
    /// The accumulator.
    Acc = 3,
}

impl Register {
    /// The preload register written by value slot `slot` (0 `I`, 1 `dI`, 2 `ddI`).
    ///
    /// # Panics
    /// If `slot > 2`.
    pub fn of_slot(slot: usize) -> Register {
        [Register::I, Register::DI, Register::DDI][slot]
    }

    /// The register's name as in a format string (`I`, `dI`, `ddI`, `acc`).
    pub fn name(self) -> &'static str {
        ["I", "dI", "ddI", "acc"][self as usize]
    }
}

/// A format string or a format that cannot be used; the message is one line that names
/// the bad part and what was expected.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct NumericError(String);

impl NumericError {
    /// The message.
    pub fn message(&self) -> &str {
        &self.0
    }
}

const EXPECTED: &str =
    "expected f64, f32 or fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate]";

impl Q {
    /// A format, checked against the limits (`int_bits >= 1`, width at most 64 bits).
    pub fn new(int_bits: u32, frac_bits: u32) -> Result<Q, NumericError> {
        let q = Q {
            int_bits,
            frac_bits,
        };
        q.check("Q")?;
        Ok(q)
    }

    /// `int_bits + frac_bits` (saturating, so an absurd format still reports its size).
    pub fn width(self) -> u32 {
        self.int_bits.saturating_add(self.frac_bits)
    }

    /// The smallest raw value, `-2^(width-1)`.
    pub fn min_raw(self) -> i64 {
        ((-1i128) << (self.width() - 1)) as i64
    }

    /// The largest raw value, `2^(width-1) - 1`.
    pub fn max_raw(self) -> i64 {
        ((1i128 << (self.width() - 1)) - 1) as i64
    }

    /// The step between values, `2^-frac_bits`.
    pub fn quantum(self) -> f64 {
        (-(self.frac_bits as f64)).exp2()
    }

    /// Checks the limits; `name` is the register, for the message.
    fn check(self, name: &str) -> Result<(), NumericError> {
        if self.int_bits == 0 {
            return Err(NumericError(format!(
                "fixed format: {name}={self}: int_bits must be at least 1 (it includes the sign bit)"
            )));
        }
        if self.width() > MAX_BITS {
            return Err(NumericError(format!(
                "fixed format: {name}={self}: {} + {} = {} bits; a register holds at most {MAX_BITS} bits",
                self.int_bits,
                self.frac_bits,
                self.width()
            )));
        }
        Ok(())
    }
}

impl fmt::Display for Q {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.int_bits, self.frac_bits)
    }
}

impl FixedFormat {
    /// The format of one register role.
    pub fn q(&self, reg: Register) -> Q {
        match reg {
            Register::I => self.i,
            Register::DI => self.di,
            Register::DDI => self.ddi,
            Register::Acc => self.acc,
        }
    }

    /// Checks every register's limits (a format built from its public fields may break
    /// them; a parsed one never does).
    pub fn validate(&self) -> Result<(), NumericError> {
        for reg in [Register::I, Register::DI, Register::DDI, Register::Acc] {
            self.q(reg).check(reg.name())?;
        }
        Ok(())
    }

    /// Whether all four registers share one width and one fraction count and overflow
    /// wraps: then the adder chain is integer arithmetic modulo `2^width` and
    /// [`wave_closed_form`] gives its values.
    pub fn is_uniform_wrap(&self) -> bool {
        self.overflow == Overflow::Wrap
            && [self.di, self.ddi, self.acc].iter().all(|q| *q == self.i)
    }
}

impl fmt::Display for FixedFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "fixed:I={},dI={},ddI={},acc={},overflow={}",
            self.i, self.di, self.ddi, self.acc, self.overflow
        )
    }
}

impl fmt::Display for Overflow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Overflow::Wrap => "wrap",
            Overflow::Saturate => "saturate",
        })
    }
}

impl Numeric {
    /// Checks the limits of a fixed format (see [`FixedFormat::validate`]).
    pub fn validate(&self) -> Result<(), NumericError> {
        match self {
            Numeric::Fixed(f) => f.validate(),
            _ => Ok(()),
        }
    }
}

impl fmt::Display for Numeric {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Numeric::F64 => f.write_str("f64"),
            Numeric::F32 => f.write_str("f32"),
            Numeric::Fixed(x) => x.fmt(f),
        }
    }
}

fn parse_q(key: &str, value: &str) -> Result<Q, NumericError> {
    let bad = || {
        NumericError(format!(
            "fixed format: {key}={value}: expected M.N (integer bits including the sign, fraction bits), e.g. {key}=4.28"
        ))
    };
    let (m, n) = value.split_once('.').ok_or_else(bad)?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(m) || !digits(n) {
        return Err(bad());
    }
    let (int_bits, frac_bits) = match (m.parse::<u32>(), n.parse::<u32>()) {
        (Ok(a), Ok(b)) => (a, b),
        // digits only, so too large for u32: certainly over the width limit
        _ => {
            return Err(NumericError(format!(
                "fixed format: {key}={value}: a register holds at most {MAX_BITS} bits"
            )))
        }
    };
    let q = Q {
        int_bits,
        frac_bits,
    };
    q.check(key)?;
    Ok(q)
}

impl FromStr for Numeric {
    type Err = NumericError;

    /// Parses `f64`, `f32` or `fixed:…` (see the module documentation); surrounding
    /// whitespace is ignored.
    fn from_str(s: &str) -> Result<Numeric, NumericError> {
        let s = s.trim();
        match s {
            "f64" => return Ok(Numeric::F64),
            "f32" => return Ok(Numeric::F32),
            _ => {}
        }
        let Some(body) = s.strip_prefix("fixed:") else {
            return Err(NumericError(format!(
                "unknown numeric format `{s}`: {EXPECTED}"
            )));
        };
        let mut regs: [Option<Q>; 4] = [None; 4];
        let mut overflow = None;
        for part in body.split(',') {
            let part = part.trim();
            if part.is_empty() {
                return Err(NumericError(format!(
                    "fixed format: `{s}` has an empty field: expected KEY=VALUE pairs separated by commas"
                )));
            }
            let Some((key, value)) = part.split_once('=') else {
                return Err(NumericError(format!(
                    "fixed format: `{part}`: expected KEY=VALUE with KEY one of I, dI, ddI, acc, overflow"
                )));
            };
            let (key, value) = (key.trim(), value.trim());
            let duplicate = || NumericError(format!("fixed format: {key} is given twice"));
            let slot = match key {
                "I" => 0,
                "dI" => 1,
                "ddI" => 2,
                "acc" => 3,
                "overflow" => {
                    if overflow.is_some() {
                        return Err(duplicate());
                    }
                    overflow = Some(match value {
                        "wrap" => Overflow::Wrap,
                        "saturate" => Overflow::Saturate,
                        _ => {
                            return Err(NumericError(format!(
                                "fixed format: overflow={value}: expected overflow=wrap or overflow=saturate"
                            )))
                        }
                    });
                    continue;
                }
                _ => {
                    return Err(NumericError(format!(
                        "fixed format: unknown key `{key}` in `{part}`: expected I, dI, ddI, acc or overflow"
                    )))
                }
            };
            if regs[slot].is_some() {
                return Err(duplicate());
            }
            regs[slot] = Some(parse_q(key, value)?);
        }
        let required = |slot: usize, name: &str| {
            regs[slot].ok_or_else(|| {
                NumericError(format!(
                    "fixed format: `{s}` has no {name}=M.N (I, dI and ddI are required)"
                ))
            })
        };
        let i = required(0, "I")?;
        let di = required(1, "dI")?;
        let ddi = required(2, "ddI")?;
        Ok(Numeric::Fixed(FixedFormat {
            i,
            di,
            ddi,
            acc: regs[3].unwrap_or(i),
            overflow: overflow.unwrap_or_default(),
        }))
    }
}

impl Serialize for Numeric {
    /// The canonical string.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Numeric {
    /// From the string form.
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Numeric, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// The wave's value `v` and first difference `d` after `k` steps of the adder chain
/// `v ← v + d`, `d ← d + dd`, in integer arithmetic modulo `2^bits` (two's complement):
/// `v = v0 + k·d0 + k(k−1)/2·dd0`, `d = d0 + k·dd0 (mod 2^bits)`, sign-extended.
///
/// This equals the fixed-point engines' chain bit for bit when all registers share one
/// format and overflow wraps ([`FixedFormat::is_uniform_wrap`]); the raw values are the
/// registers' integers (`value · 2^frac_bits`). Only the low `bits` bits of the inputs
/// matter.
///
/// # Panics
/// If `bits` is 0 or more than 64.
pub fn wave_closed_form(v0: i64, d0: i64, dd0: i64, k: u64, bits: u32) -> (i64, i64) {
    assert!((1..=MAX_BITS).contains(&bits), "bits must be 1..=64");
    // k(k-1)/2 exactly: halve the even factor first; the product of two u64 fits u128.
    let (a, b) = if k.is_multiple_of(2) {
        (k / 2, k.saturating_sub(1))
    } else {
        (k, (k - 1) / 2)
    };
    let tri = u128::from(a) * u128::from(b);
    let k = u128::from(k);
    // Arithmetic modulo 2^128 keeps every low bit right; reduce to `bits` at the end.
    let (v0, d0, dd0) = (v0 as i128 as u128, d0 as i128 as u128, dd0 as i128 as u128);
    let v = v0
        .wrapping_add(k.wrapping_mul(d0))
        .wrapping_add(tri.wrapping_mul(dd0));
    let d = d0.wrapping_add(k.wrapping_mul(dd0));
    (sign_extend(v, bits), sign_extend(d, bits))
}

/// The low `bits` bits of `x` as a two's-complement number.
pub(crate) fn sign_extend(x: u128, bits: u32) -> i64 {
    let s = 128 - bits;
    (((x << s) as i128) >> s) as i64
}

/// The worst-case error of a fixed-point wave, as `docs/ACCURACY.md` derives it: an
/// upper bound on `|acc − exact|` for the contribution of one `Eval` of `order` (0 for
/// `Eval0`, 1–3 for `Eval1`–`Eval3`) to each of the first `n` processors of its range,
/// where `exact` is the same contribution computed in exact arithmetic from the same
/// (`f64`) operands.
///
/// It holds when no overflow occurs and no preload interrupts the wave, with or without
/// `Acc_mode` (a contribution dropped on one side of zero and kept on the other is
/// within it too). Contributions of several Evals to one accumulator add up, so the
/// bound for a pixel is the sum of the bounds of the Evals that reached it, each at its
/// own `n` (its distance from the Eval's `x`, plus one).
///
/// With `q_R = 2^-frac_bits(R)` and the truncation losses `t_A = max(0, q_acc − q_I)`,
/// `t_I = max(0, q_I − q_dI)`, `t_D = max(0, q_dI − q_ddI)`, and `m = n − 1`:
///
/// | order | bound |
/// | --- | --- |
/// | 0 | `q_acc/2` |
/// | 1 | `q_I/2 + t_A` |
/// | 2 | `q_I/2 + m·(q_dI/2 + t_I) + t_A` |
/// | 3 | `q_I/2 + m·(q_dI/2 + t_I) + m(m−1)/2·(q_ddI/2 + t_D) + t_A` |
///
/// `n = 0` gives 0. The result is rounded up (by a relative `2^-40`) so that it stays an
/// upper bound despite its own `f64` rounding.
///
/// # Panics
/// If `order > 3`.
pub fn error_bound(format: &FixedFormat, order: u32, n: u64) -> f64 {
    assert!(order <= 3, "order is 0..=3 (Eval0..Eval3)");
    if n == 0 {
        return 0.0;
    }
    let q = |r: Register| format.q(r).quantum();
    let (qa, qi, qd, qdd) = (
        q(Register::Acc),
        q(Register::I),
        q(Register::DI),
        q(Register::DDI),
    );
    let loss = |dst: f64, src: f64| (dst - src).max(0.0);
    let (ta, ti, td) = (loss(qa, qi), loss(qi, qd), loss(qd, qdd));
    let m = (n - 1) as f64;
    let bound = match order {
        0 => qa / 2.0,
        1 => qi / 2.0 + ta,
        2 => qi / 2.0 + m * (qd / 2.0 + ti) + ta,
        _ => qi / 2.0 + m * (qd / 2.0 + ti) + m * (m - 1.0) / 2.0 * (qdd / 2.0 + td) + ta,
    };
    bound * (1.0 + (-40f64).exp2())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_canonical_form() {
        let n: Numeric = "fixed:I=12.20,dI=4.28,ddI=1.36".parse().unwrap();
        assert_eq!(
            n.to_string(),
            "fixed:I=12.20,dI=4.28,ddI=1.36,acc=12.20,overflow=saturate"
        );
        assert_eq!(n.to_string().parse::<Numeric>().unwrap(), n);
        assert_eq!(" f32 ".parse::<Numeric>().unwrap(), Numeric::F32);
        assert_eq!(
            serde_json::to_string(&Numeric::F64).unwrap(),
            "\"f64\"".to_string()
        );
        let back: Numeric = serde_json::from_str(&serde_json::to_string(&n).unwrap()).unwrap();
        assert_eq!(back, n);
    }

    #[test]
    fn q_ranges() {
        let q = Q::new(1, 63).unwrap();
        assert_eq!((q.min_raw(), q.max_raw()), (i64::MIN, i64::MAX));
        let q = Q::new(3, 2).unwrap();
        assert_eq!((q.min_raw(), q.max_raw(), q.quantum()), (-16, 15, 0.25));
        assert!(Q::new(0, 4).is_err());
        assert!(Q::new(60, 5).is_err());
    }

    #[test]
    fn closed_form_small_cases() {
        // v: 5, 5+3, 5+3+(3+2), … = 5, 8, 13, 20 for d0 = 3, dd0 = 2
        assert_eq!(wave_closed_form(5, 3, 2, 0, 64), (5, 3));
        assert_eq!(wave_closed_form(5, 3, 2, 3, 64), (20, 9));
        // modulo 2^4: 20 → 4; 9 → -7
        assert_eq!(wave_closed_form(5, 3, 2, 3, 4), (4, -7));
        // the k(k-1)/2 term for the largest k
        let (v, _) = wave_closed_form(0, 0, 1, u64::MAX, 64);
        let exact = (u128::from(u64::MAX) * u128::from(u64::MAX - 1) / 2) as u64 as i64;
        assert_eq!(v, exact);
    }
}
