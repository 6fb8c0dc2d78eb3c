//! The fast engine against the cycle-stepped reference on random traces and random
//! machines: identical scanlines (bit for bit) and identical statistics, cycle for cycle
//! — in `f64` and in every numeric format (f32, fixed point down to formats so tiny that
//! they wrap or saturate all the time).

mod common;

use cwisim_isa::{Instruction, Opcode, TraceHeader};
use cwisim_xproc::{run, run_numeric, Machine, Numeric, Timing};
use proptest::prelude::*;

fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -2.0f64..2.0,
        1 => Just(0.0),
        1 => Just(-0.0),
        1 => -1e6f64..1e6,
        1 => -1e-12f64..1e-12,
    ]
}

fn instruction(width: u32, channels: usize) -> impl Strategy<Value = Instruction> {
    // Weighted towards Evals and Refresh, with every opcode reachable.
    let op = prop_oneof![
        6 => 6usize..10, // Eval0..Eval3
        3 => Just(12usize), // Refresh
        3 => 0usize..6,   // Set*
        1 => Just(10usize), // Dis
        1 => Just(11usize), // Acc_mode
        1 => Just(13usize), // Nop
    ];
    (
        op,
        0..width,
        0..=width,
        proptest::collection::vec(value(), 3 * channels),
    )
        .prop_map(move |(k, x, n, vals)| {
            let (count, period) = (n.min(width - x), n.clamp(1, 5));
            Instruction::from_operands(Opcode::ALL[k], x, count, period, &vals, channels)
        })
}

fn case() -> impl Strategy<Value = (TraceHeader, Machine, Vec<Instruction>)> {
    (
        1u32..40,
        1u32..5,
        prop_oneof![Just(1u8), Just(3u8)],
        1u32..4,
        0u32..3,
        1u32..4,
        1u64..300,
    )
        .prop_flat_map(
            |(width, lines, channels, hop, value_cycles, eval3_cycles, period)| {
                let header = TraceHeader::new(width, lines, channels).unwrap();
                // Short line periods: Refresh gates and late lines happen often, and the
                // stepped engine does not wait ~1e5 cycles per line as with the derived one.
                let m = Machine {
                    hop_cycles: hop,
                    value_cycles,
                    opcode_cycles: [(Opcode::Eval3, eval3_cycles)].into(),
                    line_period_cycles: Some(period),
                    vblank_lines: 2,
                    ..Machine::default()
                };
                (
                    Just(header),
                    Just(m),
                    proptest::collection::vec(instruction(width, usize::from(channels)), 0..80),
                )
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn fast_equals_stepped((header, machine, trace) in case()) {
        let (fi, fs) = run::<f64>(&header, &trace, &machine, Timing::Fast).unwrap();
        let (si, ss) = run::<f64>(&header, &trace, &machine, Timing::Stepped).unwrap();
        prop_assert_eq!(fi.lines, si.lines);
        let fb: Vec<u64> = fi.data.iter().map(|v| v.to_bits()).collect();
        let sb: Vec<u64> = si.data.iter().map(|v| v.to_bits()).collect();
        prop_assert_eq!(fb, sb);
        prop_assert_eq!(fs, ss);
    }
}

/// Machines whose line periods are long (up to 2⁴⁰ cycles, the limit) and hops slow: the
/// stepped engine jumps over the waiting, which must not change a cycle.
fn sparse_case() -> impl Strategy<Value = (TraceHeader, Machine, Vec<Instruction>)> {
    (
        1u32..24,
        1u32..5,
        prop_oneof![Just(1u8), Just(3u8)],
        prop_oneof![Just(1u32), 2u32..70, Just(65_536)],
        prop_oneof![1u64..2_000, 2_000u64..1_000_000_000, Just(1u64 << 40)],
        0u32..4,
    )
        .prop_flat_map(|(width, lines, channels, hop, period, vblank)| {
            let header = TraceHeader::new(width, lines, channels).unwrap();
            let m = Machine {
                hop_cycles: hop,
                line_period_cycles: Some(period),
                vblank_lines: vblank,
                ..Machine::default()
            };
            (
                Just(header),
                Just(m),
                proptest::collection::vec(instruction(width, usize::from(channels)), 0..40),
            )
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn fast_equals_stepped_over_long_line_periods((header, machine, trace) in sparse_case()) {
        let (fi, fs) = run::<f64>(&header, &trace, &machine, Timing::Fast).unwrap();
        let (si, ss) = run::<f64>(&header, &trace, &machine, Timing::Stepped).unwrap();
        let fb: Vec<u64> = fi.data.iter().map(|v| v.to_bits()).collect();
        let sb: Vec<u64> = si.data.iter().map(|v| v.to_bits()).collect();
        prop_assert_eq!(fb, sb);
        prop_assert_eq!(fs, ss);
    }
}

fn numeric_case() -> impl Strategy<Value = (Numeric, TraceHeader, Machine, Vec<Instruction>)> {
    (
        common::numeric(),
        1u32..40,
        1u32..5,
        prop_oneof![Just(1u8), Just(3u8)],
        1u32..3,
        1u64..200,
    )
        .prop_flat_map(|(numeric, width, lines, channels, hop, period)| {
            let header = TraceHeader::new(width, lines, channels).unwrap();
            let m = Machine {
                hop_cycles: hop,
                line_period_cycles: Some(period),
                vblank_lines: 1,
                ..Machine::default()
            };
            (
                Just(numeric),
                Just(header),
                Just(m),
                proptest::collection::vec(
                    common::instruction(width, usize::from(channels), common::value()),
                    0..80,
                ),
            )
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn fast_equals_stepped_in_every_numeric_format(
        (numeric, header, machine, trace) in numeric_case()
    ) {
        let (fi, fs) = run_numeric(&header, &trace, &machine, Timing::Fast, &numeric).unwrap();
        let (si, ss) = run_numeric(&header, &trace, &machine, Timing::Stepped, &numeric).unwrap();
        prop_assert_eq!(fi.lines, si.lines);
        let fb: Vec<u64> = fi.data.iter().map(|v| v.to_bits()).collect();
        let sb: Vec<u64> = si.data.iter().map(|v| v.to_bits()).collect();
        prop_assert_eq!(fb, sb);
        prop_assert_eq!(fs, ss);
    }

    #[test]
    fn numeric_f64_is_the_reference_bit_for_bit((header, machine, trace) in case()) {
        for timing in [Timing::Fast, Timing::Stepped] {
            let (ri, rs) = run::<f64>(&header, &trace, &machine, timing).unwrap();
            let (ni, ns) = run_numeric(&header, &trace, &machine, timing, &Numeric::F64).unwrap();
            let rb: Vec<u64> = ri.data.iter().map(|v| v.to_bits()).collect();
            let nb: Vec<u64> = ni.data.iter().map(|v| v.to_bits()).collect();
            prop_assert_eq!(rb, nb);
            prop_assert_eq!(&rs, &ns);
            prop_assert_eq!(ns.totals.overflows, 0);
        }
    }
}

/// Without per-scanline records the totals are the same, on both engines, and the
/// records are not kept (memory stays flat in the trace's length).
#[test]
fn streaming_statistics_have_the_same_totals() {
    use cwisim_isa::{Instruction, Intensity, TraceHeader};
    use cwisim_xproc::{numeric_engine, Machine, NullSink, Numeric, Timing};
    let h = TraceHeader::new(32, 5, 1).unwrap();
    let mut trace = Vec::new();
    for line in 0..23u32 {
        trace.push(Instruction::eval2(
            line % 7,
            20,
            Intensity::grey(0.5),
            Intensity::grey(-0.01),
        ));
        if line % 3 == 0 {
            trace.push(Instruction::eval0(2, 5, Intensity::grey(0.25)));
            trace.push(Instruction::eval1(0, 32, Intensity::grey(0.125)));
        }
        trace.push(Instruction::refresh());
    }
    trace.push(Instruction::eval1(0, 3, Intensity::grey(1.0))); // never refreshed
    for timing in [Timing::Fast, Timing::Stepped] {
        let machine = Machine::default();
        let run = |keep: bool| {
            let mut e = numeric_engine(&h, &machine, timing, &Numeric::F64).unwrap();
            e.keep_line_stats(keep);
            for i in &trace {
                e.execute(i, &mut NullSink);
            }
            e.finish(&mut NullSink)
        };
        let (kept, streamed) = (run(true), run(false));
        assert_eq!(kept.totals, streamed.totals, "{timing:?}");
        assert_eq!(kept.lines.len(), 23);
        assert!(streamed.lines.is_empty());
        assert_eq!(kept.totals.unrefreshed_instructions, 1);
        assert!(kept.totals.suppressed > 0);
    }
}
