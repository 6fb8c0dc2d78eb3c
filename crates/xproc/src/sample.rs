//! The numeric type of the X-processor registers, as a parameter.

use std::fmt::Debug;

/// A register value: what the accumulators and preload registers hold.
///
/// Instructions carry `f64` operands; an array of `T` converts them on arrival with
/// [`Sample::from_f64`]. `f64` is the reference. A `Sample` type is its own arithmetic
/// ([`crate::arith::Native`]); formats that need a runtime description or count
/// overflows (f32 with overflow counting, fixed point: [`crate::numeric::Numeric`])
/// implement [`crate::arith::Arith`] instead and output `f64`.
pub trait Sample: Copy + Debug + Send + Sync + 'static {
    /// The reset value.
    const ZERO: Self;
    /// The adder's identity: `x.add(IDENTITY)` is `x`, bit for bit, for every `x`
    /// (`-0.0` for a float: `+0.0` would turn `-0.0` into `+0.0`).
    const IDENTITY: Self;
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
    const IDENTITY: f64 = -0.0;
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
