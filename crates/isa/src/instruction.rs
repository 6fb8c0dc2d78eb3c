//! Instructions and their intensity operands.

use crate::header::{TraceHeader, MAX_CHANNELS};
use crate::opcode::{Opcode, OperandKind};
use std::fmt;

/// An intensity vector: one `f64` per channel (1 for grey, 3 for RGB).
///
/// Equality is bit-exact (`-0.0 != 0.0`), so that round trips are checked exactly.
#[derive(Clone, Copy)]
pub struct Intensity {
    len: u8,
    values: [f64; MAX_CHANNELS],
}

impl Intensity {
    /// The empty vector, used for value slots an opcode does not carry.
    pub const NONE: Intensity = Intensity {
        len: 0,
        values: [0.0; MAX_CHANNELS],
    };

    /// A vector from a slice of 1 to [`MAX_CHANNELS`] values.
    ///
    /// # Panics
    /// If `values` is empty or longer than [`MAX_CHANNELS`]; parsers check this first.
    #[inline]
    pub fn new(values: &[f64]) -> Intensity {
        assert!(
            !values.is_empty() && values.len() <= MAX_CHANNELS,
            "an intensity has 1..={MAX_CHANNELS} channels"
        );
        // every lane written (the unused ones 0) rather than a copy of `values.len()`
        // lanes: a fixed-size store, no call to `memcpy`
        let v = std::array::from_fn(|c| values.get(c).copied().unwrap_or(0.0));
        Intensity {
            len: values.len() as u8,
            values: v,
        }
    }

    /// A grey (one-channel) intensity.
    pub fn grey(v: f64) -> Intensity {
        Intensity::new(&[v])
    }

    /// The same value in each of `channels` channels.
    pub fn splat(v: f64, channels: usize) -> Intensity {
        Intensity::new(&vec![v; channels])
    }

    /// The values, one per channel.
    #[inline]
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..usize::from(self.len)]
    }

    /// The number of channels.
    #[inline]
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// True for [`Intensity::NONE`].
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl PartialEq for Intensity {
    fn eq(&self, other: &Self) -> bool {
        self.len == other.len
            && self
                .as_slice()
                .iter()
                .zip(other.as_slice())
                .all(|(a, b)| a.to_bits() == b.to_bits())
    }
}

impl Eq for Intensity {}

impl fmt::Debug for Intensity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.as_slice()).finish()
    }
}

/// One X-processor instruction.
///
/// `x` and `dx` are zero and value slots empty where the opcode has no such operand
/// ([`Opcode::operands`]). Build them with the constructors, which keep that invariant.
///
/// The record is as big as what the common instruction carries: the values of a grey
/// trace (one channel) are held inline, three `f64` slots, and any other intensities
/// (colour, or slots of unequal lengths, which [`Self::check`] refuses) are boxed
/// (48 bytes on a 64-bit target, against 136 when every slot had room for four
/// channels). Equality is bit-exact on the values.
#[derive(Clone, PartialEq, Eq)]
pub struct Instruction {
    /// The opcode.
    pub op: Opcode,
    /// First processor addressed.
    pub x: u32,
    /// Range length (`Count`) or period (`Period`).
    pub dx: u32,
    values: Values,
}

/// The `[I, dI, ddI]` slots of an [`Instruction`].
#[derive(Clone)]
enum Values {
    /// Every slot empty or of one channel: bit `s` of `present` says slot `s` carries a
    /// value, held in `v[s]` (0.0 in an empty slot).
    Grey { present: u8, v: [f64; 3] },
    /// Anything else.
    Wide(Box<[Intensity; 3]>),
}

impl PartialEq for Values {
    /// Bit-exact, as [`Intensity`]'s. A representation is canonical ([`Values::new`]),
    /// so a grey and a wide one never hold equal slots.
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Values::Grey { present: p, v: a }, Values::Grey { present: q, v: b }) => {
                p == q && a.iter().zip(b).all(|(a, b)| a.to_bits() == b.to_bits())
            }
            (Values::Wide(a), Values::Wide(b)) => a == b,
            _ => false,
        }
    }
}

impl Eq for Values {}

impl Values {
    // always inlined: built out of line, the record is returned through memory and
    // copied into its instruction with loads wider than the stores that wrote it
    #[inline(always)]
    fn new(values: [Intensity; 3]) -> Values {
        if values.iter().all(|v| v.len() <= 1) {
            let mut present = 0;
            let mut v = [0.0; 3];
            for (s, slot) in values.iter().enumerate() {
                if let [f] = slot.as_slice() {
                    present |= 1 << s;
                    v[s] = *f;
                }
            }
            Values::Grey { present, v }
        } else {
            Values::Wide(Box::new(values))
        }
    }
}

impl Instruction {
    #[inline]
    fn with(op: Opcode, x: u32, dx: u32, i: Intensity, di: Intensity, ddi: Intensity) -> Self {
        Self::from_parts(op, x, dx, [i, di, ddi])
    }

    /// An instruction from its fields as they are, the value slots `[I, dI, ddI]` among
    /// them. Nothing is checked (decoders and fuzzers build what they read, then
    /// [`Self::check`] it).
    #[inline]
    pub fn from_parts(op: Opcode, x: u32, dx: u32, values: [Intensity; 3]) -> Self {
        Instruction {
            op,
            x,
            dx,
            values: Values::new(values),
        }
    }

    /// A grey instruction: bit `s` of `present` says slot `s` carries `v[s]`, and the
    /// other slots of `v` are 0.0 — what a decoder of a one-channel trace builds.
    #[inline]
    pub(crate) fn grey(op: Opcode, x: u32, dx: u32, present: u8, v: [f64; 3]) -> Self {
        debug_assert!((0..3).all(|s| present & (1 << s) != 0 || v[s].to_bits() == 0));
        Instruction {
            op,
            x,
            dx,
            values: Values::Grey { present, v },
        }
    }

    /// The `[I, dI, ddI]` slots of an instruction of at most one channel per slot
    /// (`0.0` in a slot it does not carry), read without a branch on which it carries;
    /// `None` for more channels.
    #[inline]
    pub fn grey_values(&self) -> Option<[f64; 3]> {
        match &self.values {
            Values::Grey { v, .. } => Some(*v),
            Values::Wide(_) => None,
        }
    }

    /// The values of slot `slot` (0 = `I`, 1 = `dI`, 2 = `ddI`), one per channel; empty
    /// for a slot the instruction does not carry.
    #[inline]
    pub fn value(&self, slot: usize) -> &[f64] {
        match &self.values {
            Values::Grey { present, v } => {
                if present & (1 << slot) != 0 {
                    std::slice::from_ref(&v[slot])
                } else {
                    &[]
                }
            }
            Values::Wide(v) => v[slot].as_slice(),
        }
    }
    /// `SetI(x, I)`.
    pub fn set_i(x: u32, i: Intensity) -> Self {
        Self::with(Opcode::SetI, x, 0, i, Intensity::NONE, Intensity::NONE)
    }
    /// `SetdI(x, dI)`.
    pub fn set_di(x: u32, di: Intensity) -> Self {
        Self::with(Opcode::SetdI, x, 0, Intensity::NONE, di, Intensity::NONE)
    }
    /// `SetddI(x, ddI)`.
    pub fn set_ddi(x: u32, ddi: Intensity) -> Self {
        Self::with(Opcode::SetddI, x, 0, Intensity::NONE, Intensity::NONE, ddi)
    }
    /// `SetPI(x, period, I)`.
    pub fn set_pi(x: u32, period: u32, i: Intensity) -> Self {
        Self::with(
            Opcode::SetPI,
            x,
            period,
            i,
            Intensity::NONE,
            Intensity::NONE,
        )
    }
    /// `SetPdI(x, period, dI)`.
    pub fn set_pdi(x: u32, period: u32, di: Intensity) -> Self {
        Self::with(
            Opcode::SetPdI,
            x,
            period,
            Intensity::NONE,
            di,
            Intensity::NONE,
        )
    }
    /// `SetPddI(x, period, ddI)`.
    pub fn set_pddi(x: u32, period: u32, ddi: Intensity) -> Self {
        Self::with(
            Opcode::SetPddI,
            x,
            period,
            Intensity::NONE,
            Intensity::NONE,
            ddi,
        )
    }
    /// `Eval0(x, dx, I)`.
    #[inline]
    pub fn eval0(x: u32, dx: u32, i: Intensity) -> Self {
        Self::with(Opcode::Eval0, x, dx, i, Intensity::NONE, Intensity::NONE)
    }
    /// `Eval1(x, dx, I)`.
    #[inline]
    pub fn eval1(x: u32, dx: u32, i: Intensity) -> Self {
        Self::with(Opcode::Eval1, x, dx, i, Intensity::NONE, Intensity::NONE)
    }
    /// `Eval2(x, dx, I, dI)`.
    #[inline]
    pub fn eval2(x: u32, dx: u32, i: Intensity, di: Intensity) -> Self {
        Self::with(Opcode::Eval2, x, dx, i, di, Intensity::NONE)
    }
    /// `Eval3(x, dx, I, dI, ddI)`.
    #[inline]
    pub fn eval3(x: u32, dx: u32, i: Intensity, di: Intensity, ddi: Intensity) -> Self {
        Self::with(Opcode::Eval3, x, dx, i, di, ddi)
    }
    /// `Dis(x, dx)`.
    pub fn dis(x: u32, dx: u32) -> Self {
        Self::with(
            Opcode::Dis,
            x,
            dx,
            Intensity::NONE,
            Intensity::NONE,
            Intensity::NONE,
        )
    }
    /// `Acc_mode()`.
    pub fn acc_mode() -> Self {
        Self::without_operands(Opcode::AccMode)
    }
    /// `Refresh()`.
    pub fn refresh() -> Self {
        Self::without_operands(Opcode::Refresh)
    }
    /// `Nop()`.
    pub fn nop() -> Self {
        Self::without_operands(Opcode::Nop)
    }
    /// An instruction of `op` taking from the operands offered what its signature uses:
    /// `x` for an `X` operand, `count` for a `Count`, `period` for a `Period`, and for
    /// each intensity operand in slot `s` (I, dI, ddI) the `channels` values
    /// `values[s × channels..(s + 1) × channels]`. Nothing is checked: generators of test
    /// streams and fuzzers keep what they offer in range, or check the result
    /// ([`Self::check`]).
    ///
    /// # Panics
    /// When `op` carries intensities and `values` holds fewer than `3 × channels`.
    pub fn from_operands(
        op: Opcode,
        x: u32,
        count: u32,
        period: u32,
        values: &[f64],
        channels: usize,
    ) -> Self {
        let mut i = Self::without_operands(op);
        for kind in op.operands() {
            match kind {
                OperandKind::X => i.x = x,
                OperandKind::Count => i.dx = count,
                OperandKind::Period => i.dx = period,
                _ => {
                    let s = kind.value_slot().expect("an intensity operand");
                    i.set_value(s, Intensity::new(&values[s * channels..(s + 1) * channels]));
                }
            }
        }
        i
    }

    fn without_operands(op: Opcode) -> Self {
        Self::with(op, 0, 0, Intensity::NONE, Intensity::NONE, Intensity::NONE)
    }

    /// Slot `slot` as an [`Intensity`] ([`Intensity::NONE`] if the instruction does not
    /// carry it).
    pub fn intensity(&self, slot: usize) -> Intensity {
        match self.value(slot) {
            [] => Intensity::NONE,
            v => Intensity::new(v),
        }
    }

    /// The three slots `[I, dI, ddI]`.
    pub fn values(&self) -> [Intensity; 3] {
        [self.intensity(0), self.intensity(1), self.intensity(2)]
    }

    /// Replaces slot `slot` (nothing is checked, as [`Self::from_parts`]).
    pub fn set_value(&mut self, slot: usize, value: Intensity) {
        let mut values = self.values();
        values[slot] = value;
        self.values = Values::new(values);
    }

    /// `I` (empty if the opcode has none).
    pub fn i(&self) -> Intensity {
        self.intensity(0)
    }
    /// `dI` (empty if the opcode has none).
    pub fn di(&self) -> Intensity {
        self.intensity(1)
    }
    /// `ddI` (empty if the opcode has none).
    pub fn ddi(&self) -> Intensity {
        self.intensity(2)
    }

    /// The processors this instruction addresses, as `(first, end)` of a half-open range,
    /// for range and single-processor opcodes; `None` for periodic sets and global ones.
    pub fn span(&self) -> Option<(u32, u32)> {
        let ops = self.op.operands();
        match ops {
            [OperandKind::X, OperandKind::Count, ..] => Some((self.x, self.x + self.dx)),
            [OperandKind::X, OperandKind::Period, ..] => None,
            [OperandKind::X, ..] => Some((self.x, self.x + 1)),
            _ => None,
        }
    }

    /// Checks the operands against a trace header: ranges inside the array, periods at
    /// least 1, every carried intensity with the trace's channel count and finite values.
    #[inline]
    pub fn check(&self, header: &TraceHeader) -> Result<(), OperandError> {
        if self.fits(header) {
            return Ok(());
        }
        self.check_operands(header)
    }

    /// [`Self::check`]'s verdict without its message, from the opcode's shape in a table:
    /// the test every sound instruction of a replay passes. The conditions are combined
    /// with `&` and `|`, not `&&` and `||`: in a stream of mixed opcodes, a branch per
    /// condition would be mispredicted at every change of shape.
    #[inline]
    fn fits(&self, header: &TraceHeader) -> bool {
        let shape = SHAPES[self.op.index()];
        let width = header.width;
        let x_outside = (shape & HAS_X != 0) & (self.x >= width);
        let past_end =
            (shape & HAS_COUNT != 0) & (u64::from(self.x) + u64::from(self.dx) > u64::from(width));
        let no_period = (shape & HAS_PERIOD != 0) & (self.dx == 0);
        let in_range = !(x_outside | past_end | no_period);
        let slots = shape >> SLOT_SHIFT;
        in_range
            & match &self.values {
                Values::Grey { present, v } => {
                    let finite = (0..3).fold(true, |ok, s| {
                        ok & ((slots & (1 << s) == 0) | v[s].is_finite())
                    });
                    ((slots == 0) | (header.channels == 1)) & (present & slots == slots) & finite
                }
                Values::Wide(w) => (0..3).all(|s| {
                    slots & (1 << s) == 0
                        || (w[s].len() == header.channel_count()
                            && w[s].as_slice().iter().all(|f| f.is_finite()))
                }),
            }
    }

    /// [`Self::check`] operand by operand, saying what is wrong.
    fn check_operands(&self, header: &TraceHeader) -> Result<(), OperandError> {
        let width = header.width;
        for kind in self.op.operands() {
            match kind {
                OperandKind::X => {
                    if self.x >= width {
                        return Err(OperandError::Range(format!(
                            "x = {} is outside the array (width {width}: 0..={})",
                            self.x,
                            width - 1
                        )));
                    }
                }
                OperandKind::Count => {
                    if u64::from(self.x) + u64::from(self.dx) > u64::from(width) {
                        return Err(OperandError::Range(format!(
                            "range [x, x+dx) = [{}, {}) reaches past the array's end ({width})",
                            self.x,
                            u64::from(self.x) + u64::from(self.dx)
                        )));
                    }
                }
                OperandKind::Period => {
                    if self.dx == 0 {
                        return Err(OperandError::Range(
                            "period dx = 0; a periodic set needs dx >= 1".into(),
                        ));
                    }
                }
                OperandKind::I | OperandKind::DI | OperandKind::DDI => {
                    let slot = kind.value_slot().expect("value operand");
                    let v = self.value(slot);
                    if v.len() != header.channel_count() {
                        return Err(OperandError::Channels(format!(
                            "{} has {} channel(s), the trace has {}",
                            kind.name(),
                            v.len(),
                            header.channels
                        )));
                    }
                    if let Some(bad) = v.iter().find(|f| !f.is_finite()) {
                        return Err(OperandError::NonFinite(format!(
                            "{} holds {bad}; values must be finite",
                            kind.name()
                        )));
                    }
                }
            }
        }
        Ok(())
    }
}

const HAS_X: u8 = 1;
const HAS_COUNT: u8 = 2;
const HAS_PERIOD: u8 = 4;
/// Bits `SLOT_SHIFT + s` of a shape: the opcode carries value slot `s`.
const SLOT_SHIFT: u32 = 3;

/// Each opcode's operands as bits ([`HAS_X`], …, and the value slots), by
/// [`Opcode::index`].
const SHAPES: [u8; Opcode::COUNT] = {
    let mut table = [0u8; Opcode::COUNT];
    let mut i = 0;
    while i < Opcode::COUNT {
        let ops = Opcode::ALL[i].operands();
        let mut k = 0;
        while k < ops.len() {
            table[i] |= match ops[k] {
                OperandKind::X => HAS_X,
                OperandKind::Count => HAS_COUNT,
                OperandKind::Period => HAS_PERIOD,
                OperandKind::I => 1 << SLOT_SHIFT,
                OperandKind::DI => 2 << SLOT_SHIFT,
                OperandKind::DDI => 4 << SLOT_SHIFT,
            };
            k += 1;
        }
        i += 1;
    }
    table
};

impl fmt::Debug for Instruction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&crate::text::format_instruction(self))
    }
}

impl fmt::Display for Instruction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&crate::text::format_instruction(self))
    }
}

/// Why an instruction's operands do not fit its trace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OperandError {
    /// A position or range outside the array, or a zero period.
    Range(String),
    /// An intensity with the wrong number of channels.
    Channels(String),
    /// NaN or an infinity.
    NonFinite(String),
}

impl OperandError {
    /// The message.
    pub fn message(&self) -> &str {
        match self {
            OperandError::Range(m) | OperandError::Channels(m) | OperandError::NonFinite(m) => m,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey_header(width: u32) -> TraceHeader {
        TraceHeader::new(width, 4, 1).unwrap()
    }

    #[test]
    fn ranges_are_half_open_and_checked() {
        let h = grey_header(16);
        assert!(Instruction::eval1(0, 16, Intensity::grey(1.0))
            .check(&h)
            .is_ok());
        assert!(Instruction::eval1(15, 1, Intensity::grey(1.0))
            .check(&h)
            .is_ok());
        assert!(Instruction::eval1(15, 0, Intensity::grey(1.0))
            .check(&h)
            .is_ok());
        assert!(matches!(
            Instruction::eval1(15, 2, Intensity::grey(1.0)).check(&h),
            Err(OperandError::Range(_))
        ));
        assert!(matches!(
            Instruction::set_i(16, Intensity::grey(1.0)).check(&h),
            Err(OperandError::Range(_))
        ));
        assert!(matches!(
            Instruction::set_pi(3, 0, Intensity::grey(1.0)).check(&h),
            Err(OperandError::Range(_))
        ));
        assert_eq!(
            Instruction::eval2(3, 4, Intensity::grey(0.0), Intensity::grey(0.0)).span(),
            Some((3, 7))
        );
        assert_eq!(
            Instruction::set_di(5, Intensity::grey(0.0)).span(),
            Some((5, 6))
        );
        assert_eq!(Instruction::refresh().span(), None);
    }

    #[test]
    fn channels_and_finiteness_are_checked() {
        let h = grey_header(8);
        assert!(matches!(
            Instruction::eval1(0, 1, Intensity::new(&[1.0, 2.0, 3.0])).check(&h),
            Err(OperandError::Channels(_))
        ));
        assert!(matches!(
            Instruction::eval1(0, 1, Intensity::grey(f64::NAN)).check(&h),
            Err(OperandError::NonFinite(_))
        ));
    }

    #[test]
    fn the_record_is_as_big_as_a_grey_instruction_carries() {
        // op, x, dx and three f64s (33 bytes), the slots present and the variant
        assert!(std::mem::size_of::<Instruction>() <= 48);
        let grey = Instruction::eval3(
            1,
            2,
            Intensity::grey(0.5),
            Intensity::grey(-0.0),
            Intensity::grey(0.25),
        );
        assert!(matches!(grey.values, Values::Grey { present: 7, .. }));
        assert_eq!(grey.value(1)[0].to_bits(), (-0.0f64).to_bits());
        assert_ne!(
            grey,
            Instruction::eval3(
                1,
                2,
                Intensity::grey(0.5),
                Intensity::grey(0.0),
                Intensity::grey(0.25)
            )
        );
        let rgb = Instruction::eval1(0, 4, Intensity::new(&[0.1, 0.2, 0.3]));
        assert!(matches!(rgb.values, Values::Wide(_)));
        assert_eq!(rgb.value(0), &[0.1, 0.2, 0.3]);
        assert_eq!(rgb.value(1), &[] as &[f64]);
        assert_eq!(rgb.i(), Intensity::new(&[0.1, 0.2, 0.3]));
        assert_eq!(Instruction::refresh().value(0), &[] as &[f64]);
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config {
            failure_persistence: None,
            ..proptest::test_runner::Config::with_cases(2000)
        })]

        /// The table's verdict is the operand-by-operand one.
        #[test]
        fn fits_is_check_without_the_message(
            op in 0..Opcode::COUNT,
            x in 0u32..20,
            dx in 0u32..20,
            lens in proptest::array::uniform3(0usize..5),
            bad in 0usize..16,
            channels in 1u8..=4,
        ) {
            let h = TraceHeader::new(16, 4, channels).unwrap();
            let mut k = 0;
            let values = lens.map(|n| {
                if n == 0 {
                    return Intensity::NONE;
                }
                let v: Vec<f64> = (0..n)
                    .map(|_| {
                        k += 1;
                        if k == bad { f64::NAN } else { 0.5 }
                    })
                    .collect();
                Intensity::new(&v)
            });
            let i = Instruction::from_parts(Opcode::ALL[op], x, dx, values);
            proptest::prop_assert_eq!(i.fits(&h), i.check_operands(&h).is_ok(), "{:?}", i);
        }
    }

    #[test]
    fn intensity_equality_is_bit_exact() {
        assert_ne!(Intensity::grey(0.0), Intensity::grey(-0.0));
        assert_eq!(Intensity::grey(0.1), Intensity::grey(0.1));
    }
}
