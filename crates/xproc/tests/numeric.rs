//! Numeric formats (`cwisim_xproc::numeric`): both engines against independent reference
//! models written here — fixed point with `i128` registers, `f32` with plain Rust adds —
//! bit for bit, overflow counts included; the closed form of the wrapping adder chain;
//! the analytic error bound of fixed-point forward differencing; the format strings.

mod common;

use cwisim_isa::{Instruction as In, Intensity, Opcode, TraceHeader};
use cwisim_xproc::{
    error_bound, run_numeric, wave_closed_form, FixedFormat, Machine, Numeric, Overflow, RunStats,
    Timing, Q,
};
use proptest::prelude::*;
use std::fmt::Debug;

// ---------------------------------------------------------------------------------------
// Reference models
// ---------------------------------------------------------------------------------------

/// The register arithmetic of a reference model. Registers: 0 `I`, 1 `dI`, 2 `ddI`,
/// 3 `acc`.
trait Model {
    type R: Copy + Debug;
    fn zero(&self) -> Self::R;
    /// An operand converted for register `reg`.
    fn conv(&self, reg: usize, x: f64, ovf: &mut u64) -> Self::R;
    /// `a + b` where `a` is in register `dst` (and the result goes there) and `b` in `src`.
    fn add(&self, dst: usize, src: usize, a: Self::R, b: Self::R, ovf: &mut u64) -> Self::R;
    fn negative(&self, v: Self::R) -> bool;
    fn out(&self, acc: Self::R) -> f64;
}

/// Fixed point with `i128` registers, the rules of docs/ISA.md "Numeric formats" written
/// out the long way.
struct FixedModel(FixedFormat);

impl FixedModel {
    fn q(&self, reg: usize) -> Q {
        [self.0.i, self.0.di, self.0.ddi, self.0.acc][reg]
    }

    fn wrap(r: i128, w: u32) -> i128 {
        let m = r.rem_euclid(1i128 << w);
        if m >= 1i128 << (w - 1) {
            m - (1i128 << w)
        } else {
            m
        }
    }

    fn fit(&self, reg: usize, r: i128, ovf: &mut u64) -> i128 {
        let w = self.q(reg).int_bits + self.q(reg).frac_bits;
        let (lo, hi) = (-(1i128 << (w - 1)), (1i128 << (w - 1)) - 1);
        if (lo..=hi).contains(&r) {
            return r;
        }
        *ovf += 1;
        match self.0.overflow {
            Overflow::Saturate => r.clamp(lo, hi),
            Overflow::Wrap => Self::wrap(r, w),
        }
    }
}

impl Model for FixedModel {
    type R = i128;
    fn zero(&self) -> i128 {
        0
    }
    fn conv(&self, reg: usize, x: f64, ovf: &mut u64) -> i128 {
        let q = self.q(reg);
        let w = q.int_bits + q.frac_bits;
        // scaling by a power of two is exact (the operands here stay far from f64 limits)
        let y = x * 2f64.powi(q.frac_bits as i32);
        assert!(y.is_finite());
        let r = y.round_ties_even();
        let half = 2f64.powi(w as i32 - 1);
        if r >= -half && r < half {
            return r as i128;
        }
        *ovf += 1;
        match self.0.overflow {
            Overflow::Saturate if r < 0.0 => -(1i128 << (w - 1)),
            Overflow::Saturate => (1i128 << (w - 1)) - 1,
            // fmod is exact; |remainder| < 2^w <= 2^64 converts exactly
            Overflow::Wrap => Self::wrap((r % 2f64.powi(w as i32)) as i128, w),
        }
    }
    fn add(&self, dst: usize, src: usize, a: i128, b: i128, ovf: &mut u64) -> i128 {
        let (fa, fb) = (self.q(dst).frac_bits, self.q(src).frac_bits);
        let f = fa.max(fb);
        let exact = (a << (f - fa)) + (b << (f - fb));
        // an arithmetic shift right is the floor: truncation toward -inf
        self.fit(dst, exact >> (f - fa), ovf)
    }
    fn negative(&self, v: i128) -> bool {
        v < 0
    }
    fn out(&self, acc: i128) -> f64 {
        acc as f64 * 2f64.powi(-(self.0.acc.frac_bits as i32))
    }
}

/// `f32` registers and plain Rust `f32` adds.
struct F32Model;

impl Model for F32Model {
    type R = f32;
    fn zero(&self) -> f32 {
        0.0
    }
    fn conv(&self, _reg: usize, x: f64, ovf: &mut u64) -> f32 {
        let r = x as f32;
        *ovf += u64::from(!r.is_finite());
        r
    }
    fn add(&self, _dst: usize, _src: usize, a: f32, b: f32, ovf: &mut u64) -> f32 {
        let r = a + b;
        *ovf += u64::from(!r.is_finite());
        r
    }
    fn negative(&self, v: f32) -> bool {
        v < 0.0
    }
    fn out(&self, acc: f32) -> f64 {
        f64::from(acc)
    }
}

/// What a reference run produces.
#[derive(Debug, Default)]
struct RefRun {
    lines: Vec<Vec<f64>>,
    /// Overflow events per scanline output.
    line_overflows: Vec<u64>,
    overflows: u64,
    dropped: u64,
}

/// One row of `w` processors executing `trace` instruction by instruction, each Eval
/// processor by processor, in plain straight-line code.
fn reference<M: Model>(m: &M, w: usize, c: usize, trace: &[In]) -> RefRun {
    let z = m.zero();
    let mut acc = vec![vec![z; c]; w];
    let mut reg = vec![[vec![z; c], vec![z; c], vec![z; c]]; w];
    let mut has = vec![[false; 3]; w];
    let mut locked = vec![false; w];
    let mut masked = vec![false; w];
    let mut neg_ok = false;
    let mut run = RefRun::default();
    let mut ovf = 0u64;
    for i in trace {
        let (x, dx) = (i.x as usize, i.dx as usize);
        let conv = |r: usize, slot: usize, ovf: &mut u64| -> Vec<M::R> {
            i.value(slot).iter().map(|&v| m.conv(r, v, ovf)).collect()
        };
        match i.op {
            Opcode::SetI | Opcode::SetdI | Opcode::SetddI => {
                let s = i.op as usize - Opcode::SetI as usize;
                reg[x][s] = conv(s, s, &mut ovf);
                has[x][s] = true;
            }
            Opcode::SetPI | Opcode::SetPdI | Opcode::SetPddI => {
                let s = i.op as usize - Opcode::SetPI as usize;
                let v = conv(s, s, &mut ovf);
                for p in (x..w).step_by(dx) {
                    reg[p][s] = v.clone();
                    has[p][s] = true;
                }
            }
            Opcode::Eval0 => {
                let v = conv(3, 0, &mut ovf);
                for p in x..x + dx {
                    if !(locked[p] || masked[p]) {
                        acc[p] = v.clone();
                        locked[p] = true;
                    }
                }
                masked.fill(false);
            }
            Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                let order = 1 + i.op as usize - Opcode::Eval1 as usize;
                let mut v = conv(0, 0, &mut ovf);
                let mut d = if order >= 2 {
                    conv(1, 1, &mut ovf)
                } else {
                    vec![z; c]
                };
                let mut dd = if order >= 3 {
                    conv(2, 2, &mut ovf)
                } else {
                    vec![z; c]
                };
                for p in x..x + dx {
                    if has[p][0] {
                        v = reg[p][0].clone();
                        has[p][0] = false;
                    }
                    if order >= 2 && has[p][1] {
                        d = reg[p][1].clone();
                        has[p][1] = false;
                    }
                    if order >= 3 && has[p][2] {
                        dd = reg[p][2].clone();
                        has[p][2] = false;
                    }
                    for k in 0..c {
                        if !(locked[p] || masked[p]) {
                            if neg_ok || !m.negative(v[k]) {
                                acc[p][k] = m.add(3, 0, acc[p][k], v[k], &mut ovf);
                            } else {
                                run.dropped += 1;
                            }
                        }
                        if order >= 2 {
                            v[k] = m.add(0, 1, v[k], d[k], &mut ovf);
                        }
                        if order >= 3 {
                            d[k] = m.add(1, 2, d[k], dd[k], &mut ovf);
                        }
                    }
                }
                masked.fill(false);
            }
            Opcode::Dis => masked[x..x + dx].fill(true),
            Opcode::AccMode => neg_ok = !neg_ok,
            Opcode::Refresh => {
                run.lines
                    .push(acc.iter().flatten().map(|&r| m.out(r)).collect());
                run.line_overflows.push(ovf);
                run.overflows += ovf;
                ovf = 0;
                acc = vec![vec![z; c]; w];
                has = vec![[false; 3]; w];
                locked.fill(false);
                masked.fill(false);
            }
            Opcode::Nop => {}
        }
    }
    run.overflows += ovf;
    run
}

/// Runs on both engines. A short line period: the stepped engine would otherwise idle
/// ~1500 cycles before each `Refresh` (timing is not what these tests are about).
fn run_both(h: &TraceHeader, trace: &[In], numeric: &Numeric) -> [(Vec<Vec<f64>>, RunStats); 2] {
    let m = Machine {
        line_period_cycles: Some(4),
        ..Machine::default()
    };
    [Timing::Fast, Timing::Stepped].map(|t| {
        let (image, stats) = run_numeric(h, trace, &m, t, numeric).unwrap();
        let row = image.width * image.channels;
        let rows = image.data.chunks(row).map(<[f64]>::to_vec).collect();
        (rows, stats)
    })
}

/// Runs `trace` on both engines and holds each to the reference model, bit for bit.
fn check_against<M: Model>(
    m: &M,
    h: &TraceHeader,
    trace: &[In],
    numeric: &Numeric,
) -> Result<(), TestCaseError> {
    let want = reference(m, h.width as usize, h.channel_count(), trace);
    let bits = |rows: &[Vec<f64>]| -> Vec<Vec<u64>> {
        rows.iter()
            .map(|r| r.iter().map(|v| v.to_bits()).collect())
            .collect()
    };
    for (rows, stats) in run_both(h, trace, numeric) {
        prop_assert_eq!(bits(&rows), bits(&want.lines));
        let per_line: Vec<u64> = stats.lines.iter().map(|l| l.overflows).collect();
        prop_assert_eq!(&per_line, &want.line_overflows);
        prop_assert_eq!(stats.totals.overflows, want.overflows);
        prop_assert_eq!(stats.totals.dropped_negative, want.dropped);
    }
    Ok(())
}

fn trace_case() -> impl Strategy<Value = (TraceHeader, Vec<In>)> {
    (1u32..24, prop_oneof![Just(1u8), Just(3u8)]).prop_flat_map(|(width, channels)| {
        (
            Just(TraceHeader::new(width, 4, channels).unwrap()),
            proptest::collection::vec(
                common::instruction(width, usize::from(channels), common::value()),
                0..60,
            ),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn fixed_point_engines_are_bit_exact_with_the_integer_reference(
        format in common::fixed_format(),
        (h, trace) in trace_case(),
    ) {
        check_against(&FixedModel(format), &h, &trace, &Numeric::Fixed(format))?;
    }

    #[test]
    fn f32_engines_equal_plain_f32_adds((h, trace) in trace_case()) {
        check_against(&F32Model, &h, &trace, &Numeric::F32)?;
    }
}

// ---------------------------------------------------------------------------------------
// Worked examples
// ---------------------------------------------------------------------------------------

fn g(v: f64) -> Intensity {
    Intensity::grey(v)
}

fn fixed(s: &str) -> Numeric {
    s.parse().unwrap()
}

/// Scanline 0 and the statistics, after checking both engines agree.
fn line0(numeric: &Numeric, trace: &[In]) -> (Vec<f64>, RunStats) {
    let h = TraceHeader::new(6, 1, 1).unwrap();
    let [(fast, fs), (stepped, ss)] = run_both(&h, trace, numeric);
    assert_eq!(fast, stepped);
    assert_eq!(fs, ss);
    (fast[0].clone(), fs)
}

#[test]
fn truncation_is_toward_minus_infinity() {
    // I has no fraction bits: v + 0.75 drops the 0.75 every step; v - 0.25 drops to the
    // next integer below every step.
    let n = fixed("fixed:I=4.0,dI=4.2,ddI=4.2,acc=8.0");
    let (row, _) = line0(&n, &[In::eval2(0, 4, g(1.0), g(0.75)), In::refresh()]);
    assert_eq!(row, [1.0, 1.0, 1.0, 1.0, 0.0, 0.0]);
    let (row, s) = line0(
        &n,
        &[
            In::acc_mode(),
            In::eval2(0, 4, g(0.0), g(-0.25)),
            In::refresh(),
        ],
    );
    assert_eq!(row, [0.0, -1.0, -2.0, -3.0, 0.0, 0.0]);
    assert_eq!(s.totals.overflows, 0);
}

#[test]
fn wrap_and_saturate_count_every_event_even_the_last_advance() {
    // Q3.0 holds -4..=3: 2, 3, then 3 + 1 overflows
    let (row, s) = line0(
        &fixed("fixed:I=3.0,dI=3.0,ddI=3.0,acc=8.0,overflow=wrap"),
        &[
            In::acc_mode(),
            In::eval2(0, 4, g(2.0), g(1.0)),
            In::refresh(),
        ],
    );
    assert_eq!(row, [2.0, 3.0, -4.0, -3.0, 0.0, 0.0]);
    assert_eq!(s.totals.overflows, 1);
    let (row, s) = line0(
        &fixed("fixed:I=3.0,dI=3.0,ddI=3.0,acc=8.0"),
        &[In::eval2(0, 4, g(2.0), g(1.0)), In::refresh()],
    );
    assert_eq!(row, [2.0, 3.0, 3.0, 3.0, 0.0, 0.0]);
    // v2, v3 and the advance after the last processor (unused, still computed)
    assert_eq!(s.totals.overflows, 3);
    assert_eq!(s.lines[0].overflows, 3);
}

#[test]
fn operand_conversions_count_and_eval0_uses_the_acc_format() {
    // I is Q2.0 (-2..=1); acc is Q8.4, so Eval0's 5.3 fits the accumulator (as 5.3125)
    let n = fixed("fixed:I=2.0,dI=2.0,ddI=2.0,acc=8.4");
    let (row, s) = line0(
        &n,
        &[
            In::eval0(0, 1, g(5.3)),
            In::eval1(1, 1, g(5.3)),
            In::set_pi(2, 2, g(-7.0)),
            In::acc_mode(),
            In::eval1(2, 3, g(0.0)),
            In::refresh(),
        ],
    );
    assert_eq!(row, [5.3125, 1.0, -2.0, -2.0, -2.0, 0.0]);
    // Eval1's 5.3 and SetPI's -7.0, converted once each (SetPI writes two processors)
    assert_eq!(s.totals.overflows, 2);
}

#[test]
fn f32_overflow_to_infinity_is_counted_not_a_panic() {
    let (row, s) = line0(
        &Numeric::F32,
        &[
            In::eval2(0, 3, g(3e38), g(3e38)),
            In::eval1(4, 1, g(1e39)),
            In::refresh(),
        ],
    );
    assert_eq!(row[0], 3e38f32 as f64);
    assert_eq!(row[1], f64::INFINITY);
    assert_eq!(row[4], f64::INFINITY);
    // v1 = 6e38 (inf), v2, v3 (advances of inf stay inf), acc of p1 and p2; the operand
    // 1e39 and acc of p4
    assert_eq!(s.totals.overflows, 7);
}

// ---------------------------------------------------------------------------------------
// Closed form
// ---------------------------------------------------------------------------------------

fn sign_extend(x: i128, bits: u32) -> i128 {
    let m = x.rem_euclid(1i128 << bits);
    if m >= 1i128 << (bits - 1) {
        m - (1i128 << bits)
    } else {
        m
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The closed form against the adder chain run step by step, modulo 2^bits.
    #[test]
    fn closed_form_equals_the_sequential_adder_chain(
        bits in 1u32..=64,
        v0 in any::<i64>(),
        d0 in any::<i64>(),
        dd0 in any::<i64>(),
        k in prop_oneof![0u64..70, 0u64..=(1 << 20)],
    ) {
        let (mut v, mut d) = (sign_extend(v0.into(), bits), sign_extend(d0.into(), bits));
        let dd = sign_extend(dd0.into(), bits);
        for _ in 0..k {
            v = sign_extend(v + d, bits);
            d = sign_extend(d + dd, bits);
        }
        let (cv, cd) = wave_closed_form(v0, d0, dd0, k, bits);
        prop_assert_eq!((i128::from(cv), i128::from(cd)), (v, d));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// In a uniform wrapping format, the engines' Eval3 at processor `x + k` is the closed
    /// form at step k.
    #[test]
    fn engines_follow_the_closed_form_in_a_uniform_wrapping_format(
        int_bits in 1u32..=20,
        frac_bits in 0u32..=33,
        raws in proptest::array::uniform3(any::<i64>()),
        width in 1u32..300,
    ) {
        let q = Q { int_bits, frac_bits };
        let bits = int_bits + frac_bits;
        let format = FixedFormat { i: q, di: q, ddi: q, acc: q, overflow: Overflow::Wrap };
        prop_assert!(format.is_uniform_wrap());
        let raw = raws.map(|r| sign_extend(r.into(), bits) as i64);
        let scale = 2f64.powi(-(frac_bits as i32));
        let h = TraceHeader::new(width, 1, 1).unwrap();
        let trace = [
            In::acc_mode(),
            In::eval3(
                0,
                width,
                g(raw[0] as f64 * scale),
                g(raw[1] as f64 * scale),
                g(raw[2] as f64 * scale),
            ),
            In::refresh(),
        ];
        for (rows, _) in run_both(&h, &trace, &Numeric::Fixed(format)) {
            for (k, got) in rows[0].iter().enumerate() {
                let (v, _) = wave_closed_form(raw[0], raw[1], raw[2], k as u64, bits);
                prop_assert_eq!(*got, v as f64 * scale, "k = {}", k);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Error bound
// ---------------------------------------------------------------------------------------

/// A fixed format that does not overflow on the operands of `bounded_eval`.
fn roomy_format() -> impl Strategy<Value = FixedFormat> {
    let q = || {
        (17u32..=24, 0u32..=40).prop_map(|(int_bits, frac_bits)| Q {
            int_bits,
            frac_bits,
        })
    };
    (q(), q(), q(), q(), common::overflow()).prop_map(|(i, di, ddi, acc, overflow)| FixedFormat {
        i,
        di,
        ddi,
        acc,
        overflow,
    })
}

/// Multiples of 2^-24 below `2^max_exp` in magnitude: every sum the f64 reference forms
/// on them stays exact, so the reference is the exact value.
fn dyadic(max_exp: i32) -> impl Strategy<Value = f64> {
    let lim = 1i64 << (24 + max_exp);
    (-lim..lim).prop_map(|m| m as f64 * 2f64.powi(-24))
}

/// An Eval of order 0..=3 somewhere in a 64-wide row, with operands from `dyadic`.
fn bounded_eval() -> impl Strategy<Value = (u32, In)> {
    (
        0u32..=3,
        0u32..64,
        0u32..=64,
        dyadic(8),
        dyadic(3),
        dyadic(-2),
    )
        .prop_map(|(order, x, n, i, di, ddi)| {
            let dx = n.min(64 - x);
            let instr = match order {
                0 => In::eval0(x, dx, g(i)),
                1 => In::eval1(x, dx, g(i)),
                2 => In::eval2(x, dx, g(i), g(di)),
                _ => In::eval3(x, dx, g(i), g(di), g(ddi)),
            };
            (order, instr)
        })
}

/// A preload of `I`, `dI` or `ddI` with operands from `dyadic`, somewhere in the row.
fn bounded_preload() -> impl Strategy<Value = In> {
    (0usize..3, 0u32..64, dyadic(8), dyadic(3), dyadic(-2)).prop_map(|(slot, x, i, di, ddi)| {
        match slot {
            0 => In::set_i(x, g(i)),
            1 => In::set_di(x, g(di)),
            _ => In::set_ddi(x, g(ddi)),
        }
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// |fixed − exact| at every pixel is within the sum of the bounds of the Evals that
    /// reached it (each at its own distance from the Eval's x), preloads or not.
    #[test]
    fn measured_error_stays_within_the_analytic_bound(
        format in roomy_format(),
        evals in proptest::collection::vec(bounded_eval(), 1..6),
        preloads in proptest::collection::vec(bounded_preload(), 0..6),
        acc_mode in any::<bool>(),
    ) {
        // Eval0 overwrites and locks, so it only comes alone.
        let evals: Vec<(u32, In)> = if evals[0].0 == 0 {
            evals[..1].to_vec()
        } else {
            evals.into_iter().filter(|(o, _)| *o != 0).collect()
        };
        let mut trace: Vec<In> = preloads;
        if acc_mode {
            trace.push(In::acc_mode());
        }
        trace.extend(evals.iter().map(|(_, e)| e.clone()));
        trace.push(In::refresh());
        let h = TraceHeader::new(64, 1, 1).unwrap();
        let (exact, _) = run_numeric(&h, &trace, &Machine::default(), Timing::Fast, &Numeric::F64).unwrap();
        for (rows, stats) in run_both(&h, &trace, &Numeric::Fixed(format)) {
            prop_assert_eq!(stats.totals.overflows, 0);
            for (p, (got, want)) in rows[0].iter().zip(&exact.data).enumerate() {
                let bound: f64 = evals
                    .iter()
                    .filter(|(_, e)| (e.x as usize..(e.x + e.dx) as usize).contains(&p))
                    .map(|(o, e)| error_bound(&format, *o, (p - e.x as usize + 1) as u64))
                    .sum();
                let err = (got - want).abs();
                prop_assert!(err <= bound, "pixel {}: |{} - {}| = {} > {}", p, got, want, err, bound);
            }
        }
    }
}

/// Operands chosen so that every rounding goes down by (almost) half a quantum and every
/// truncation drops (almost) a whole quantum: the error reaches the bound up to the
/// 2^-30 margins that keep the rounding off the ties.
#[test]
fn the_bound_is_reached() {
    let eps = 2f64.powi(-30);
    let tri = |k: f64| k * (k - 1.0) / 2.0;
    // I quarter steps, dI sixteenths, ddI 64ths, acc as I. I = 1/8 is a tie and rounds to
    // 0 (even); dI = 3/16 + 1/32 - eps rounds to 3/16, ddI = 3/64 + 1/128 - eps to 3/64.
    // Then d + dd truncates back to 3/16 and v + d back to 0: the fixed wave stays 0.
    let f = FixedFormat {
        i: Q::new(16, 2).unwrap(),
        di: Q::new(16, 4).unwrap(),
        ddi: Q::new(16, 6).unwrap(),
        acc: Q::new(16, 2).unwrap(),
        overflow: Overflow::Saturate,
    };
    let (i, di, ddi) = (0.125, 7.0 / 32.0 - eps, 7.0 / 128.0 - eps);
    let h = TraceHeader::new(40, 1, 1).unwrap();
    for order in [2u32, 3] {
        let e = if order == 2 {
            In::eval2(0, 40, g(i), g(di))
        } else {
            In::eval3(0, 40, g(i), g(di), g(ddi))
        };
        for (rows, _) in run_both(&h, &[e, In::refresh()], &Numeric::Fixed(f)) {
            for k in 0..40u64 {
                let kf = k as f64;
                let exact = i + kf * di + if order == 3 { tri(kf) * ddi } else { 0.0 };
                let err = (rows[0][k as usize] - exact).abs();
                let bound = error_bound(&f, order, k + 1);
                let slack = (kf + tri(kf)) * eps * 2.0 + bound * 2f64.powi(-39);
                assert!(
                    err <= bound && err >= bound - slack,
                    "order {order} k {k}: {err} vs {bound}"
                );
            }
        }
    }
    // Eval1 with a coarser accumulator: I = 7/8 - eps rounds to 3/4, and acc (halves)
    // truncates that to 1/2: the error is 3/8 - eps; the bound q_I/2 + t_A = 1/8 + 1/4.
    let f = FixedFormat {
        acc: Q::new(8, 1).unwrap(),
        ..f
    };
    let h = TraceHeader::new(1, 1, 1).unwrap();
    let trace = [In::eval1(0, 1, g(0.875 - eps)), In::refresh()];
    for (rows, _) in run_both(&h, &trace, &Numeric::Fixed(f)) {
        assert_eq!(rows[0][0], 0.5);
        assert_eq!(error_bound(&f, 1, 1), 0.375 * (1.0 + 2f64.powi(-40)));
    }
}

#[test]
fn the_bound_formula() {
    let f = FixedFormat {
        i: Q::new(12, 4).unwrap(),
        di: Q::new(8, 8).unwrap(),
        ddi: Q::new(4, 12).unwrap(),
        acc: Q::new(16, 2).unwrap(),
        overflow: Overflow::Wrap,
    };
    let up = 1.0 + 2f64.powi(-40);
    let (qa, qi, qd, qdd) = (0.25, 1.0 / 16.0, 1.0 / 256.0, 1.0 / 4096.0);
    let (ta, ti, td) = (qa - qi, qi - qd, qd - qdd);
    assert_eq!(error_bound(&f, 3, 0), 0.0);
    assert_eq!(error_bound(&f, 0, 9), qa / 2.0 * up);
    assert_eq!(error_bound(&f, 1, 9), (qi / 2.0 + ta) * up);
    assert_eq!(
        error_bound(&f, 2, 9),
        (qi / 2.0 + 8.0 * (qd / 2.0 + ti) + ta) * up
    );
    assert_eq!(
        error_bound(&f, 3, 9),
        (qi / 2.0 + 8.0 * (qd / 2.0 + ti) + 28.0 * (qdd / 2.0 + td) + ta) * up
    );
    // finer destinations lose nothing in their adders
    let g = FixedFormat {
        i: Q::new(8, 20).unwrap(),
        acc: Q::new(8, 30).unwrap(),
        ..f
    };
    assert_eq!(
        error_bound(&g, 2, 5),
        (2f64.powi(-21) + 4.0 * (qd / 2.0)) * up
    );
}

/// The example table of docs/ACCURACY.md (log2 of the bound, to one decimal).
#[test]
fn the_documented_examples() {
    let rows = [
        ("fixed:I=12.20,dI=4.28,ddI=1.36", [-21.0, -10.0, -8.4]),
        ("fixed:I=4.28,dI=4.28,ddI=4.28", [-29.0, -19.0, -10.0]),
        (
            "fixed:I=4.28,dI=4.28,ddI=1.36,acc=12.20",
            [-20.0, -18.4, -9.0],
        ),
        (
            "fixed:I=2.30,dI=2.30,ddI=1.38,acc=12.20",
            [-20.0, -19.4, -11.0],
        ),
    ];
    for (s, want) in rows {
        let Numeric::Fixed(f) = fixed(s) else {
            panic!("{s}")
        };
        for (order, w) in (1..=3).zip(want) {
            let got = (error_bound(&f, order, 1024).log2() * 10.0).round() / 10.0;
            assert_eq!(got, w, "{s} Eval{order}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Format strings
// ---------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn every_format_round_trips_through_its_string(n in common::numeric()) {
        let s = n.to_string();
        prop_assert_eq!(s.parse::<Numeric>().unwrap(), n);
        let json = serde_json::to_string(&n).unwrap();
        prop_assert_eq!(json, format!("\"{s}\""));
    }

    #[test]
    fn acc_and_overflow_default_to_the_i_format_and_saturate(
        i in common::any_q(), di in common::any_q(), ddi in common::any_q(),
    ) {
        let n: Numeric = format!("fixed:I={i},dI={di},ddI={ddi}").parse().unwrap();
        prop_assert_eq!(n, Numeric::Fixed(FixedFormat { i, di, ddi, acc: i, overflow: Overflow::Saturate }));
    }
}

#[test]
fn canonical_strings() {
    assert_eq!(Numeric::F64.to_string(), "f64");
    assert_eq!(Numeric::F32.to_string(), "f32");
    let n: Numeric = " fixed:ddI=1.36, dI=4.28,overflow=wrap,I=12.20 "
        .parse()
        .unwrap();
    assert_eq!(
        n.to_string(),
        "fixed:I=12.20,dI=4.28,ddI=1.36,acc=12.20,overflow=wrap"
    );
}

#[test]
fn every_error_message() {
    let cases = [
        (
            "f16",
            "unknown numeric format `f16`: expected f64, f32 or fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate]",
        ),
        (
            "",
            "unknown numeric format ``: expected f64, f32 or fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate]",
        ),
        (
            "fixed:",
            "fixed format: `fixed:` has an empty field: expected KEY=VALUE pairs separated by commas",
        ),
        (
            "fixed:I=12.20,,dI=4.28",
            "fixed format: `fixed:I=12.20,,dI=4.28` has an empty field: expected KEY=VALUE pairs separated by commas",
        ),
        (
            "fixed:I=12.20,dI",
            "fixed format: `dI`: expected KEY=VALUE with KEY one of I, dI, ddI, acc, overflow",
        ),
        (
            "fixed:I=12.20,dd=1.2",
            "fixed format: unknown key `dd` in `dd=1.2`: expected I, dI, ddI, acc or overflow",
        ),
        (
            "fixed:I=12.20,dI=4.x",
            "fixed format: dI=4.x: expected M.N (integer bits including the sign, fraction bits), e.g. dI=4.28",
        ),
        (
            "fixed:I=12",
            "fixed format: I=12: expected M.N (integer bits including the sign, fraction bits), e.g. I=4.28",
        ),
        (
            "fixed:I=-1.20",
            "fixed format: I=-1.20: expected M.N (integer bits including the sign, fraction bits), e.g. I=4.28",
        ),
        (
            "fixed:I=12.20,dI=4.28,ddI=0.36",
            "fixed format: ddI=0.36: int_bits must be at least 1 (it includes the sign bit)",
        ),
        (
            "fixed:I=40.30,dI=4.28,ddI=1.36",
            "fixed format: I=40.30: 40 + 30 = 70 bits; a register holds at most 64 bits",
        ),
        (
            "fixed:I=12.99999999999,dI=4.28,ddI=1.36",
            "fixed format: I=12.99999999999: a register holds at most 64 bits",
        ),
        (
            "fixed:I=12.20,dI=4.28,ddI=1.36,acc=1.64",
            "fixed format: acc=1.64: 1 + 64 = 65 bits; a register holds at most 64 bits",
        ),
        (
            "fixed:I=12.20,dI=4.28,ddI=1.36,overflow=clamp",
            "fixed format: overflow=clamp: expected overflow=wrap or overflow=saturate",
        ),
        (
            "fixed:I=12.20,dI=4.28,I=1.2",
            "fixed format: I is given twice",
        ),
        (
            "fixed:I=12.20,overflow=wrap,overflow=wrap",
            "fixed format: overflow is given twice",
        ),
        (
            "fixed:I=12.20,dI=4.28",
            "fixed format: `fixed:I=12.20,dI=4.28` has no ddI=M.N (I, dI and ddI are required)",
        ),
        (
            "fixed:dI=4.28,ddI=1.36",
            "fixed format: `fixed:dI=4.28,ddI=1.36` has no I=M.N (I, dI and ddI are required)",
        ),
    ];
    for (input, message) in cases {
        let e = input.parse::<Numeric>().unwrap_err();
        assert_eq!(e.to_string(), message, "for `{input}`");
        assert!(!e.to_string().contains('\n'));
    }
    assert!(serde_json::from_str::<Numeric>("\"f8\"")
        .unwrap_err()
        .to_string()
        .starts_with("unknown numeric format `f8`"));
}
