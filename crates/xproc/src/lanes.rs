//! Short `Eval`s run side by side: the fast engine's answer to the adder chain's latency.
//!
//! One `Eval`'s chain is serial (each processor's `v` is the one before's plus `d`,
//! rounded as the hardware's adders round), but `Eval`s whose ranges are apart are
//! independent. On a grey array the processors ([`crate::processors`]) keep up to
//! [`LANES`] plain `Eval`s (no preload, lock or mask in play, of more than [`SHORT`] and
//! at most [`MAX_LEN`] processors each, pairwise apart) in a [`Batch`] and run them as
//! lanes of one loop ([`Batch::run`]): one step advances every lane by one processor, so
//! the lanes' chains overlap and the loop's exit is decided once for the batch, not once
//! per `Eval` (a random span length mispredicts it). Lanes pay where such `Eval`s come
//! several at a time; the processors use them on a scanline when most of the scanline
//! before was made of them.
//!
//! Nothing is reordered that could be seen: each lane is exactly its `Eval`'s chain
//! ([`crate::arith::chain_steps`], operation for operation), two lanes never touch the same
//! processor, and the batch runs before any instruction that could see its processors
//! (only a plain `Eval` apart from every pending span runs before it). A lane past its
//! span's end keeps stepping (the loop is branch-free) but adds the adders' identity, which
//! changes no bit, and what it counts there is masked out.

use crate::arith::{Arith, Counts, F32Arith, Wave};
use cwisim_isa::MAX_CHANNELS;
use std::any::Any;

/// `Eval`s a batch runs side by side.
pub(crate) const LANES: usize = 4;
/// The longest span a lane takes; a longer `Eval` runs alone.
pub(crate) const MAX_LEN: usize = 64;
/// The longest span that runs at once rather than in a lane: a lane as short would keep
/// its slot idle for most of the batch's steps, and an `Eval` of one or two processors
/// has no chain to hide. Such an `Eval` (or one longer than [`MAX_LEN`]) runs ahead of
/// the batch if it meets none of its spans, else after it.
pub(crate) const SHORT: usize = 2;
/// Spare accumulators past the array's end, which a lane past its span's end may reach.
pub(crate) const SPARE: usize = MAX_LEN;

/// Up to [`LANES`] pending `Eval`s of one channel, pairwise apart, with their operands
/// converted; a lane's registers beyond its order hold [`Arith::IDENTITY`], so that every
/// lane can advance all three.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Batch<R> {
    /// First processor of each lane's span.
    x: [usize; LANES],
    /// Processors in each lane's span (0 for an unused lane).
    len: [usize; LANES],
    /// Each lane's order, 1 to 3.
    order: [u8; LANES],
    v: [R; LANES],
    d: [R; LANES],
    dd: [R; LANES],
    /// Lanes in use.
    n: usize,
}

impl<R: Copy + 'static> Batch<R> {
    /// An empty batch; `zero` is the registers' reset value.
    pub(crate) fn new(zero: R) -> Self {
        Batch {
            x: [0; LANES],
            len: [0; LANES],
            order: [1; LANES],
            v: [zero; LANES],
            d: [zero; LANES],
            dd: [zero; LANES],
            n: 0,
        }
    }

    /// No `Eval` is pending.
    #[inline(always)]
    pub(crate) fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Takes an `Eval` of `order` (1–3) over `[x, x + len)` (`1 ≤ len ≤ MAX_LEN`) with
    /// running registers `v`, `d`, `dd` at its first processor (those beyond its order
    /// [`Arith::IDENTITY`]), if a lane is free and its range is apart from every pending
    /// one; `false` (nothing taken) otherwise.
    #[inline(always)]
    pub(crate) fn try_push(&mut self, order: u8, x: usize, len: usize, v: R, d: R, dd: R) -> bool {
        debug_assert!((1..=MAX_LEN).contains(&len) && (1..=3).contains(&order));
        let n = self.n;
        if n == LANES || self.meets(x, x + len) {
            return false;
        }
        self.x[n] = x;
        self.len[n] = len;
        self.order[n] = order;
        self.v[n] = v;
        self.d[n] = d;
        self.dd[n] = dd;
        self.n = n + 1;
        true
    }

    /// Whether `[x, end)` meets a pending `Eval`'s span.
    #[inline(always)]
    pub(crate) fn meets(&self, x: usize, end: usize) -> bool {
        let mut meets = false;
        for k in 0..self.n {
            meets |= (x < self.x[k] + self.len[k]) & (self.x[k] < end);
        }
        meets
    }

    /// Runs the pending `Eval`s into `acc` (a grey array's accumulators followed by
    /// [`SPARE`] spare ones) and empties the batch; returns what their chains counted,
    /// the same as running them one by one with [`Arith::chain`].
    #[allow(
        clippy::ptr_arg,
        reason = "a `Vec<f64>` is told apart by its type, a slice cannot be"
    )]
    pub(crate) fn run<A: Arith<Reg = R>>(
        &mut self,
        ar: &A,
        acc: &mut Vec<R>,
        neg_ok: bool,
    ) -> Counts {
        // one lane alone is its own chain: nothing to hide its latency behind
        let lanes = if self.n > 1 {
            f64_side_by_side(acc, self, neg_ok).or_else(|| f32_side_by_side(acc, self, neg_ok))
        } else {
            None
        };
        let counts = lanes.unwrap_or_else(|| self.one_by_one(ar, acc, neg_ok));
        self.n = 0;
        self.len = [0; LANES];
        counts
    }

    /// The pending `Eval`s in order, each by its own chain: what [`Self::run`] does with
    /// one, and where there are no lanes ([`batches`] is false there).
    fn one_by_one<A: Arith<Reg = R>>(&self, ar: &A, acc: &mut [R], neg_ok: bool) -> Counts {
        let mut total = Counts::default();
        for l in 0..self.n {
            let mut wave = Wave {
                v: [A::ZERO; MAX_CHANNELS],
                d: [A::ZERO; MAX_CHANNELS],
                dd: [A::ZERO; MAX_CHANNELS],
            };
            wave.v[0] = self.v[l];
            wave.d[0] = self.d[l];
            wave.dd[0] = self.dd[l];
            let acc = &mut acc[self.x[l]..self.x[l] + self.len[l]];
            let counts = match self.order[l] {
                1 => ar.chain::<1, 1>(acc, wave, neg_ok),
                2 => ar.chain::<2, 1>(acc, wave, neg_ok),
                _ => ar.chain::<3, 1>(acc, wave, neg_ok),
            };
            total.dropped += counts.dropped;
            total.overflows += counts.overflows;
        }
        total
    }
}

/// Whether the processors of arithmetic `A` batch their `Eval`s: `f64` or `f32`
/// registers on a machine with lanes for them ([`f64_side_by_side`],
/// [`f32_side_by_side`]). In fixed point, or without vector registers, a batch in plain
/// code costs more than the `Eval`s' own chains.
pub(crate) fn batches<A: Arith>() -> bool {
    use std::any::TypeId;
    let reg = TypeId::of::<A::Reg>();
    cfg!(target_arch = "x86_64") && (reg == TypeId::of::<f64>() || reg == TypeId::of::<f32>())
}

/// [`f64_side_by_side`] for `f32` registers ([`F32Arith`]: `f32` adds, a non-finite
/// result an overflow event), four lanes to a 128-bit register (SSE2). The lanes add
/// without counting and note whether any value they made is not finite; only then are
/// the events counted again, lane by lane ([`F32Arith::recount`]: an accumulator's add
/// overflowed iff the value it left is not finite, and each accumulator in a lane's span
/// holds that lane's one add — the other lanes add `-0.0` there at most).
#[allow(
    clippy::ptr_arg,
    reason = "a `Vec<f32>` is told apart by its type, a slice cannot be"
)]
fn f32_side_by_side<R: Copy + 'static>(
    acc: &mut Vec<R>,
    b: &Batch<R>,
    neg_ok: bool,
) -> Option<Counts> {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        let b = (b as &dyn Any).downcast_ref::<Batch<f32>>()?;
        let acc = (acc as &mut dyn Any).downcast_mut::<Vec<f32>>()?;
        // SAFETY: the function needs SSE2, which every x86-64 has (the cfg above holds).
        let (dropped, non_finite) = unsafe { x86::side_by_side_f32(acc, b, neg_ok) };
        let mut overflows = 0;
        if non_finite {
            for l in 0..LANES {
                let wave = Wave {
                    v: [b.v[l], 0.0, 0.0, 0.0],
                    d: [b.d[l], 0.0, 0.0, 0.0],
                    dd: [b.dd[l], 0.0, 0.0, 0.0],
                };
                let span = &acc[b.x[l]..b.x[l] + b.len[l]];
                overflows += match b.order[l] {
                    1 => F32Arith::recount::<1, 1>(span, wave, neg_ok),
                    2 => F32Arith::recount::<2, 1>(span, wave, neg_ok),
                    _ => F32Arith::recount::<3, 1>(span, wave, neg_ok),
                };
            }
        }
        Some(Counts { dropped, overflows })
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        let _ = (acc, b, neg_ok);
        None
    }
}

/// The batch's lanes side by side, one processor of every lane a step, for as many
/// steps as the longest span, if the registers are `f64` and the machine has lanes for
/// them; `None` otherwise. Per lane exactly [`crate::arith::chain_steps`]'s operations
/// (accumulate unless dropped, then `v ← v + d`, `d ← d + dd`: a lane of lower order
/// advances by the identity). Branch-free: a lane past its end goes on adding the
/// identity `-0.0` to the processors after its span (or to the spare accumulators past
/// the array's end), which leaves their bits as they are, and counts nothing.
#[allow(
    clippy::ptr_arg,
    reason = "a `Vec<f64>` is told apart by its type, a slice cannot be"
)]
fn f64_side_by_side<R: Copy + 'static>(
    acc: &mut Vec<R>,
    b: &Batch<R>,
    neg_ok: bool,
) -> Option<Counts> {
    #[cfg(target_arch = "x86_64")]
    {
        let b = (b as &dyn Any).downcast_ref::<Batch<f64>>()?;
        let acc = (acc as &mut dyn Any).downcast_mut::<Vec<f64>>()?;
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the function needs AVX2, which this machine has (just detected).
            return Some(unsafe { x86::side_by_side_avx2(acc, b, neg_ok) });
        }
        // SAFETY: the function needs SSE2, which every x86-64 has (it is part of the
        // target's baseline, so always enabled in the build: the cfg below holds).
        #[cfg(target_feature = "sse2")]
        return Some(unsafe { x86::side_by_side_sse2(acc, b, neg_ok) });
        #[cfg(not(target_feature = "sse2"))]
        return None;
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (acc, b, neg_ok);
        None
    }
}

/// The `f64` lanes on x86-64: all four in a 256-bit register where the machine has AVX2
/// (detected when the batch runs), else two to a 128-bit register (SSE2, which every
/// x86-64 has). Each is [`super::side_by_side`] for `f64`: the same operations on the same
/// values in the same order, per lane, so the same bits.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Batch, Counts, LANES};
    use std::arch::x86_64::*;
    use std::marker::PhantomData;
    use std::ops::Add;

    /// The four lanes' accumulators, from each lane's first processor, for the batch's
    /// steps: the one place the kernels reach into the array, which it borrows.
    struct Accumulators<'a, T> {
        first: [*mut T; LANES],
        /// The longest lane's length.
        steps: usize,
        _acc: PhantomData<&'a mut [T]>,
    }

    impl<'a, T: Copy + Add<Output = T>> Accumulators<'a, T> {
        /// `b`'s lanes in `acc`, checked to stay in it for every step (a lane past its
        /// end included): every lane starts at most at the last processor, and `acc`
        /// has `SPARE ≥ MAX_LEN` accumulators after it.
        fn of(acc: &'a mut [T], b: &Batch<T>) -> Self {
            let steps = b.len.into_iter().max().unwrap_or(0);
            let top = b.x.into_iter().max().unwrap_or(0) + steps;
            assert!(
                top <= acc.len(),
                "a lane reaches past the spare accumulators"
            );
            let base = acc.as_mut_ptr();
            Accumulators {
                first: b.x.map(|x| base.wrapping_add(x)),
                steps,
                _acc: PhantomData,
            }
        }

        /// Adds `add[l]` to lane `l`'s accumulator at step `s`, one lane after another
        /// (past its end a lane may reach another's processor, so a lane's add is stored
        /// before the next lane's is read); returns the sums.
        ///
        /// # Safety
        ///
        /// `s < self.steps`.
        #[inline(always)]
        unsafe fn add(&mut self, s: usize, add: [T; LANES]) -> [T; LANES] {
            debug_assert!(s < self.steps);
            let mut sums = add;
            for (l, p) in self.first.iter().enumerate() {
                // SAFETY: `x + s < x + steps <= top <= acc.len()` for each lane's first
                // processor `x` (`s < steps` is the caller's promise, the rest checked in
                // `of`), so the pointer is in the `acc` this struct borrows mutably; no
                // reference aliases it.
                unsafe {
                    let at = p.add(s);
                    sums[l] = *at + add[l];
                    *at = sums[l];
                }
            }
            sums
        }
    }

    /// Two lanes to a register.
    #[target_feature(enable = "sse2")]
    pub(super) fn side_by_side_sse2(acc: &mut [f64], b: &Batch<f64>, neg_ok: bool) -> Counts {
        let mut accs = Accumulators::of(acc, b);
        let pair = |r: &[f64; LANES], h: usize| _mm_setr_pd(r[2 * h], r[2 * h + 1]);
        let (mut va, mut vb) = (pair(&b.v, 0), pair(&b.v, 1));
        let (mut da, mut db) = (pair(&b.d, 0), pair(&b.d, 1));
        let (dda, ddb) = (pair(&b.dd, 0), pair(&b.dd, 1));
        let lens = b.len.map(|n| n as f64);
        let (lena, lenb) = (pair(&lens, 0), pair(&lens, 1));
        let identity = _mm_set1_pd(-0.0);
        let one = _mm_set1_pd(1.0);
        // `v < threshold`: dropped (never, where negative contributions are taken)
        let threshold = _mm_set1_pd(if neg_ok { f64::NEG_INFINITY } else { 0.0 });
        let mut step = _mm_setzero_pd();
        let mut dropped = _mm_setzero_si128();
        for s in 0..accs.steps {
            // what each lane adds: its `v` if in its span and not dropped, else the identity
            let (aa, drop_a) = added(va, step, lena, threshold, identity);
            let (ab, drop_b) = added(vb, step, lenb, threshold, identity);
            dropped = _mm_sub_epi64(dropped, drop_a);
            dropped = _mm_sub_epi64(dropped, drop_b);
            va = _mm_add_pd(va, da);
            vb = _mm_add_pd(vb, db);
            da = _mm_add_pd(da, dda);
            db = _mm_add_pd(db, ddb);
            step = _mm_add_pd(step, one);
            let add = [
                _mm_cvtsd_f64(aa),
                _mm_cvtsd_f64(_mm_unpackhi_pd(aa, aa)),
                _mm_cvtsd_f64(ab),
                _mm_cvtsd_f64(_mm_unpackhi_pd(ab, ab)),
            ];
            // SAFETY: `s < accs.steps`, the loop's bound.
            unsafe { accs.add(s, add) };
        }
        let mut counts = [0i64; 2];
        // SAFETY: `counts` is 16 bytes, as an unaligned store needs.
        unsafe { _mm_storeu_si128(counts.as_mut_ptr().cast(), dropped) };
        Counts {
            dropped: (counts[0] + counts[1]) as u64,
            overflows: 0,
        }
    }

    /// Two lanes' contributions at step `step` (their `v` where they add it, else
    /// `identity`) and, as all-ones lanes (−1), where a `v` in the span is dropped
    /// (below `threshold`).
    #[inline]
    #[target_feature(enable = "sse2")]
    fn added(
        v: __m128d,
        step: __m128d,
        len: __m128d,
        threshold: __m128d,
        identity: __m128d,
    ) -> (__m128d, __m128i) {
        let active = _mm_cmplt_pd(step, len);
        let negative = _mm_cmplt_pd(v, threshold);
        let take = _mm_andnot_pd(negative, active);
        let add = _mm_or_pd(_mm_and_pd(take, v), _mm_andnot_pd(take, identity));
        (add, _mm_castpd_si128(_mm_and_pd(active, negative)))
    }

    /// All four lanes in one register.
    #[target_feature(enable = "avx2")]
    pub(super) fn side_by_side_avx2(acc: &mut [f64], b: &Batch<f64>, neg_ok: bool) -> Counts {
        let mut accs = Accumulators::of(acc, b);
        let four = |r: &[f64; LANES]| _mm256_setr_pd(r[0], r[1], r[2], r[3]);
        let (mut v, mut d, dd) = (four(&b.v), four(&b.d), four(&b.dd));
        let len = four(&b.len.map(|n| n as f64));
        let identity = _mm256_set1_pd(-0.0);
        let one = _mm256_set1_pd(1.0);
        // `v < threshold`: dropped (never, where negative contributions are taken)
        let threshold = _mm256_set1_pd(if neg_ok { f64::NEG_INFINITY } else { 0.0 });
        let mut step = _mm256_setzero_pd();
        let mut dropped = _mm256_setzero_si256();
        for s in 0..accs.steps {
            let active = _mm256_cmp_pd::<_CMP_LT_OQ>(step, len);
            let negative = _mm256_cmp_pd::<_CMP_LT_OQ>(v, threshold);
            let take = _mm256_andnot_pd(negative, active);
            // what each lane adds: its `v` if in its span and not dropped, else the identity
            let add = _mm256_blendv_pd(identity, v, take);
            let drop = _mm256_castpd_si256(_mm256_and_pd(active, negative));
            dropped = _mm256_sub_epi64(dropped, drop);
            v = _mm256_add_pd(v, d);
            d = _mm256_add_pd(d, dd);
            step = _mm256_add_pd(step, one);
            let (lo, hi) = (_mm256_castpd256_pd128(add), _mm256_extractf128_pd::<1>(add));
            let add = [
                _mm_cvtsd_f64(lo),
                _mm_cvtsd_f64(_mm_unpackhi_pd(lo, lo)),
                _mm_cvtsd_f64(hi),
                _mm_cvtsd_f64(_mm_unpackhi_pd(hi, hi)),
            ];
            // SAFETY: `s < accs.steps`, the loop's bound.
            unsafe { accs.add(s, add) };
        }
        let mut counts = [0i64; 4];
        // SAFETY: `counts` is 32 bytes, as an unaligned store needs.
        unsafe { _mm256_storeu_si256(counts.as_mut_ptr().cast(), dropped) };
        Counts {
            dropped: counts.iter().sum::<i64>() as u64,
            overflows: 0,
        }
    }

    /// The `f32` lanes, four to a register: the dropped contributions, and whether any
    /// value the lanes made (a running `v` or `d`, or an accumulator they added to) is
    /// not finite, past a lane's end included (a false alarm only costs a recount).
    #[target_feature(enable = "sse2")]
    pub(super) fn side_by_side_f32(acc: &mut [f32], b: &Batch<f32>, neg_ok: bool) -> (u64, bool) {
        let mut accs = Accumulators::of(acc, b);
        let four = |r: &[f32; LANES]| _mm_setr_ps(r[0], r[1], r[2], r[3]);
        let (mut v, mut d, dd) = (four(&b.v), four(&b.d), four(&b.dd));
        let len = four(&b.len.map(|n| n as f32));
        let identity = _mm_set1_ps(-0.0);
        let one = _mm_set1_ps(1.0);
        let threshold = _mm_set1_ps(if neg_ok { f32::NEG_INFINITY } else { 0.0 });
        // `(bits & exponent) + 2^23` carries into the sign bit iff the exponent is all ones
        let exponent = _mm_set1_epi32(0x7f80_0000);
        let carry = _mm_set1_epi32(0x0080_0000);
        let non_finite =
            |x: __m128| _mm_add_epi32(_mm_and_si128(_mm_castps_si128(x), exponent), carry);
        let mut step = _mm_setzero_ps();
        let mut dropped = _mm_setzero_si128();
        let mut bad = _mm_setzero_si128();
        for s in 0..accs.steps {
            let active = _mm_cmplt_ps(step, len);
            let negative = _mm_cmplt_ps(v, threshold);
            let take = _mm_andnot_ps(negative, active);
            let add = _mm_or_ps(_mm_and_ps(take, v), _mm_andnot_ps(take, identity));
            let drop = _mm_castps_si128(_mm_and_ps(active, negative));
            dropped = _mm_sub_epi32(dropped, drop);
            v = _mm_add_ps(v, d);
            d = _mm_add_ps(d, dd);
            step = _mm_add_ps(step, one);
            let add = [
                _mm_cvtss_f32(add),
                _mm_cvtss_f32(_mm_shuffle_ps::<0b01_01_01_01>(add, add)),
                _mm_cvtss_f32(_mm_movehl_ps(add, add)),
                _mm_cvtss_f32(_mm_shuffle_ps::<0b11_11_11_11>(add, add)),
            ];
            // SAFETY: `s < accs.steps`, the loop's bound.
            let sums = unsafe { accs.add(s, add) };
            let sums = _mm_setr_ps(sums[0], sums[1], sums[2], sums[3]);
            bad = _mm_or_si128(bad, _mm_or_si128(non_finite(v), non_finite(d)));
            bad = _mm_or_si128(bad, non_finite(sums));
        }
        let mut counts = [0i32; LANES];
        // SAFETY: `counts` is 16 bytes, as an unaligned store needs.
        unsafe { _mm_storeu_si128(counts.as_mut_ptr().cast(), dropped) };
        let bad = _mm_movemask_ps(_mm_castsi128_ps(bad)) != 0;
        (counts.iter().map(|&c| c as u64).sum(), bad)
    }
}

#[cfg(test)]
mod tests {
    use crate::arith::{Arith, F32Arith, Native};
    use crate::processors::{LineEnd, Processors};
    use cwisim_isa::{Instruction, Intensity};
    use proptest::prelude::*;

    const WIDTH: usize = 100;
    const F64: Native<f64> = Native::new();

    /// Which scanlines run in lanes.
    #[derive(Clone, Copy)]
    enum Lanes {
        /// Every one.
        Always,
        /// Those the processors choose from the scanline before.
        Chosen,
        /// None: every `Eval` by its own chain, the reference.
        Never,
    }

    /// Every scanline the processors hand out (values as bits, tally, work), and the
    /// open scanline's tally and work at the end.
    fn replay<A: Arith<Out = f64>>(arith: A, trace: &[Instruction], lanes: Lanes) -> Vec<String> {
        let p = Processors::new(WIDTH, 1, arith);
        let mut p = match lanes {
            Lanes::Always => p.always_in_lanes(),
            Lanes::Chosen => p,
            Lanes::Never => p.without_batches(),
        };
        let mut out = Vec::new();
        for instr in trace {
            p.execute(instr, &mut |end: LineEnd<'_, f64>| {
                let bits: Vec<u64> = end.values.iter().map(|v| v.to_bits()).collect();
                out.push(format!(
                    "{:?} {:?} {:?} {bits:?}",
                    end.tally, end.work, end.span
                ));
            });
        }
        let (tally, work) = p.take_open_scanline();
        out.push(format!("{tally:?} {work:?}"));
        out
    }

    /// A value of any sign and size the chains cannot take past `f64`'s range in 64
    /// processors, zeros of both signs among them.
    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            4 => -1.0..1.0f64,
            1 => -1e300..1e300f64,
            1 => -1e-300..1e-300f64,
            1 => Just(0.0),
            1 => Just(-0.0),
        ]
    }

    /// Mostly `Eval1`–`Eval3` of 0 to 70 processors (past a lane's 64), apart and
    /// overlapping, with now and then every instruction that ends a batch or makes the
    /// `Eval`s after it depend on the processors' state.
    fn instruction() -> impl Strategy<Value = Instruction> {
        let g = Intensity::grey;
        let eval = (
            1u8..=3,
            0usize..WIDTH,
            0usize..=70,
            value(),
            value(),
            value(),
        )
            .prop_map(move |(order, x, dx, i, di, ddi)| {
                let (x, dx) = (x as u32, dx.min(WIDTH - x) as u32);
                match order {
                    1 => Instruction::eval1(x, dx, g(i)),
                    2 => Instruction::eval2(x, dx, g(i), g(di)),
                    _ => Instruction::eval3(x, dx, g(i), g(di), g(ddi)),
                }
            });
        let at = 0u32..WIDTH as u32;
        prop_oneof![
            24 => eval,
            2 => Just(Instruction::refresh()),
            2 => Just(Instruction::acc_mode()),
            1 => (at.clone(), value()).prop_map(move |(x, v)| Instruction::set_di(x, g(v))),
            1 => (at.clone(), 0u32..8).prop_map(|(x, dx)| Instruction::dis(x, dx.min(WIDTH as u32 - x))),
            1 => (at, 0u32..8, value())
                .prop_map(move |(x, dx, v)| Instruction::eval0(x, dx.min(WIDTH as u32 - x), g(v))),
            1 => Just(Instruction::nop()),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The lanes give what each `Eval`'s own chain gives, bit for bit, with the same
        /// counts: every length from 0 to past a lane's, every order, negative
        /// contributions dropped and taken, lanes ending at the array's last processor.
        #[test]
        fn evals_side_by_side_are_the_evals_one_by_one(
            trace in proptest::collection::vec(instruction(), 0..120),
        ) {
            let reference = replay(F64, &trace, Lanes::Never);
            prop_assert_eq!(&replay(F64, &trace, Lanes::Always), &reference);
            prop_assert_eq!(&replay(F64, &trace, Lanes::Chosen), &reference);
            let reference = replay(F32Arith, &trace, Lanes::Never);
            prop_assert_eq!(&replay(F32Arith, &trace, Lanes::Always), &reference);
            prop_assert_eq!(&replay(F32Arith, &trace, Lanes::Chosen), &reference);
        }
    }

    /// The processors choose lanes for a scanline after one made of `Eval`s a lane
    /// takes, and not after one of single pixels or one with a lock; the image and
    /// counts are the reference's either way.
    #[test]
    fn lanes_are_chosen_from_the_scanline_before() {
        let g = Intensity::grey;
        let short = |k: u32| Instruction::eval2(k * 12, 9, g(0.5 - f64::from(k) * 0.1), g(-0.03));
        let mut trace = Vec::new();
        for line in 0..6 {
            match line {
                // single pixels, then a lock: lanes stay off after both
                1 => trace.extend((0..20).map(|k| Instruction::eval1(k * 3, 1, g(0.25)))),
                3 => trace.push(Instruction::eval0(97, 2, g(1.0))),
                _ => {}
            }
            trace.extend((0..8).map(short));
            trace.push(Instruction::refresh());
        }
        let mut p = Processors::new(WIDTH, 1, F64);
        let mut chosen = Vec::new();
        for instr in &trace {
            p.execute(instr, &mut |_: LineEnd<'_, f64>| {});
            if instr.op == cwisim_isa::Opcode::Refresh {
                chosen.push(p.lanes_on());
            }
        }
        // after each scanline: lanes for the next one?
        assert_eq!(chosen, [true, false, true, false, true, true]);
        assert_eq!(
            replay(F64, &trace, Lanes::Chosen),
            replay(F64, &trace, Lanes::Never)
        );
    }

    /// Four lanes of every length from 1 to 64 ending at the array's last processor
    /// and beyond the others: a lane past its end reaches the spare accumulators.
    #[test]
    fn lanes_reach_the_spare_accumulators_and_change_nothing() {
        let g = Intensity::grey;
        for len in 1..=64u32 {
            let x = WIDTH as u32 - len;
            let trace = [
                Instruction::eval2(0, 1, g(0.5), g(0.25)),
                Instruction::eval3(2, 64, g(-0.5), g(0.03), g(0.001)),
                Instruction::eval1(x, len, g(0.75)),
                Instruction::eval2(70 - len.min(3), 1, g(-0.0), g(-1.0)),
                Instruction::refresh(),
            ];
            assert_eq!(
                replay(F64, &trace, Lanes::Always),
                replay(F64, &trace, Lanes::Never),
                "len {len}"
            );
            let f32 = (
                replay(F32Arith, &trace, Lanes::Always),
                replay(F32Arith, &trace, Lanes::Never),
            );
            assert_eq!(f32.0, f32.1, "f32, len {len}");
        }
    }
}

/// Each of the machine's kernels against the lanes one by one, on random batches: both
/// run here whatever the batch path picks on this machine (AVX2 only where it is).
#[cfg(all(test, target_arch = "x86_64"))]
mod kernels {
    use super::{f32_side_by_side, x86, Batch, LANES, MAX_LEN, SPARE};
    use crate::arith::{F32Arith, Native};
    use proptest::prelude::*;

    const WIDTH: usize = 90;

    /// Up to four lanes, pairwise apart, as a batch would take them.
    fn batch() -> impl Strategy<Value = Batch<f64>> {
        let lane = (
            1u8..=3,
            0usize..WIDTH,
            1usize..=MAX_LEN,
            -2.0..2.0f64,
            -0.2..0.2f64,
            -0.02..0.02f64,
        );
        proptest::collection::vec(lane, 1..=LANES).prop_map(|lanes| {
            let mut b = Batch::new(0.0);
            for (order, x, len, v, d, dd) in lanes {
                let len = len.min(WIDTH - x);
                let d = if order >= 2 { d } else { -0.0 };
                let dd = if order >= 3 { dd } else { -0.0 };
                b.try_push(order, x, len, v, d, dd);
            }
            b
        })
    }

    fn accumulators() -> impl Strategy<Value = Vec<f64>> {
        proptest::collection::vec(prop_oneof![Just(0.0), -1.0..1.0f64], WIDTH + SPARE)
    }

    /// `b` in `f32`, with the lanes' values scaled by `scale` (large ones overflow).
    fn narrowed(b: &Batch<f64>, scale: f32) -> Batch<f32> {
        let mut n = Batch::new(0.0f32);
        for l in 0..b.n {
            let (v, d, dd) = (b.v[l] as f32, b.d[l] as f32, b.dd[l] as f32);
            n.try_push(
                b.order[l],
                b.x[l],
                b.len[l],
                v * scale,
                d * scale,
                dd * scale,
            );
        }
        n
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        #[test]
        fn every_kernel_is_the_lanes_one_by_one(b in batch(), acc in accumulators(), neg_ok: bool) {
            let mut want = acc.clone();
            let counts = b.one_by_one(&Native::<f64>::new(), &mut want, neg_ok);
            let bits = |a: &[f64]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            let mut sse2 = acc.clone();
            // SAFETY: SSE2 is part of every x86-64.
            let got = unsafe { x86::side_by_side_sse2(&mut sse2, &b, neg_ok) };
            prop_assert_eq!(got, counts);
            prop_assert_eq!(bits(&sse2), bits(&want));
            // `f32`, at values that stay finite and at values that overflow
            for scale in [1.0f32, 1e38] {
                let b = narrowed(&b, scale);
                let acc: Vec<f32> = acc.iter().map(|&a| a as f32 * scale).collect();
                let mut want = acc.clone();
                let counts = b.one_by_one(&F32Arith, &mut want, neg_ok);
                let mut lanes = acc.clone();
                let got = f32_side_by_side(&mut lanes, &b, neg_ok);
                prop_assert_eq!(got, Some(counts));
                let bits = |a: &[f32]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(bits(&lanes), bits(&want));
            }
            if std::is_x86_feature_detected!("avx2") {
                let mut avx2 = acc.clone();
                // SAFETY: detected just above.
                let got = unsafe { x86::side_by_side_avx2(&mut avx2, &b, neg_ok) };
                prop_assert_eq!(got, counts);
                prop_assert_eq!(bits(&avx2), bits(&want));
            }
        }
    }
}
