//! The unit tests' random numbers: a fixed-seed xorshift, so that every run draws the
//! same cases.

/// Uniform `f64`s in `[0, 1)` from `seed` (nonzero), 53 bits each.
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}
