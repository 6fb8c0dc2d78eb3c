//! The numeric type of the X-processor registers, as a parameter.

use std::fmt::Debug;

/// A register value: what the accumulators and preload registers hold.
///
/// Instructions carry `f64` operands; an array of `T` converts them on arrival with
/// [`Sample::from_f64`]. `f64` is the reference; narrower formats (f32, fixed point)
/// implement this trait to plug in.
pub trait Sample: Copy + Debug + Send + Sync + 'static {
    /// The reset value.
    const ZERO: Self;
    /// Converts an operand.
    fn from_f64(v: f64) -> Self;
    /// Converts for output.
    fn to_f64(self) -> f64;
    /// The adder of the register file.
    fn add(self, other: Self) -> Self;
    /// True for values below zero (negative zero is not negative).
    fn is_negative(self) -> bool;
}

impl Sample for f64 {
    const ZERO: f64 = 0.0;
    #[inline]
    fn from_f64(v: f64) -> f64 {
        v
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn add(self, other: f64) -> f64 {
        self + other
    }
    #[inline]
    fn is_negative(self) -> bool {
        self < 0.0
    }
}

/// Up to [`cwisim_isa::MAX_CHANNELS`] values of `T`, converted from an intensity operand.
pub(crate) fn vector<T: Sample>(v: &cwisim_isa::Intensity) -> [T; cwisim_isa::MAX_CHANNELS] {
    let mut out = [T::ZERO; cwisim_isa::MAX_CHANNELS];
    for (o, x) in out.iter_mut().zip(v.as_slice()) {
        *o = T::from_f64(*x);
    }
    out
}
