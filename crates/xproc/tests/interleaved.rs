//! The fast engine given many instructions at once (`execute_all`, as a pipeline's
//! scanlines reach it, where an engine may look ahead: batch, reorder or interleave
//! independent `Eval`s) gives the same run as executing them one by one (`execute`), bit
//! for bit — the scanlines, the statistics (dropped contributions, overflow events,
//! updates) and the cycles — on random spans 0 to 64 processors long, in every numeric
//! format, with values that overflow `f32` and narrow fixed formats, negative
//! accumulation on and off, and the preloads, locks and masks that make `Eval`s depend on
//! what came before them.

mod common;

use cwisim_isa::{Instruction, Intensity, TraceHeader};
use cwisim_xproc::{numeric_engine, Machine, Numeric, RunStats, Timing};
use proptest::prelude::*;

const WIDTH: u32 = 96;

/// A run's image bits and statistics.
type Outcome = (Vec<u64>, RunStats);

fn run(numeric: &Numeric, channels: u8, trace: &[Instruction], at_once: bool) -> Outcome {
    let header = TraceHeader::new(WIDTH, 64, channels).unwrap();
    let mut sink = common::image_sink(&header);
    let mut e = numeric_engine(&header, &Machine::default(), Timing::Fast, numeric).unwrap();
    if at_once {
        e.execute_all(trace, &mut sink);
    } else {
        for i in trace {
            e.execute(i, &mut sink);
        }
    }
    let stats = e.finish(&mut sink);
    (common::image_bits(&sink.finish().unwrap()), stats)
}

/// An `Eval1`–`Eval3` of 0 to 64 processors.
fn eval(channels: usize) -> impl Strategy<Value = Instruction> {
    let value = move || {
        proptest::collection::vec(common::value(), channels).prop_map(|v| Intensity::new(&v))
    };
    (1u8..=3, 0u32..=64, 0u32..WIDTH, value(), value(), value()).prop_map(
        move |(order, dx, x, i, di, ddi)| {
            let dx = dx.min(WIDTH - x);
            match order {
                1 => Instruction::eval1(x, dx, i),
                2 => Instruction::eval2(x, dx, i, di),
                _ => Instruction::eval3(x, dx, i, di, ddi),
            }
        },
    )
}

/// Mostly runs of `Eval`s, with every other instruction now and then.
fn trace(channels: usize) -> impl Strategy<Value = Vec<Instruction>> {
    proptest::collection::vec(
        prop_oneof![
            12 => eval(channels),
            1 => Just(Instruction::refresh()),
            1 => Just(Instruction::acc_mode()),
            1 => common::instruction(WIDTH, channels, common::value()),
        ],
        0..160,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn evals_run_side_by_side_are_the_evals_run_one_by_one(
        numeric in common::numeric(),
        (channels, trace) in prop_oneof![4 => Just(1u8), 1 => Just(3u8)]
            .prop_flat_map(|c| (Just(c), trace(usize::from(c)))),
    ) {
        prop_assert_eq!(run(&numeric, channels, &trace, true), run(&numeric, channels, &trace, false));
    }
}

/// Named cases: runs of `Eval`s of each order and length (0 among them), overlapping and
/// apart, values that overflow `f32` in a chain, negative contributions dropped, a
/// preload in the middle of a run of `Eval`s.
#[test]
fn the_named_cases_are_the_one_by_one_run() {
    let g = Intensity::grey;
    let cases: Vec<Vec<Instruction>> = vec![
        vec![
            Instruction::eval1(0, 5, g(0.5)),
            Instruction::eval2(3, 9, g(0.25), g(0.125)),
            Instruction::eval3(2, 64, g(-0.5), g(0.01), g(0.001)),
            Instruction::eval2(90, 6, g(1.0), g(-0.3)),
            Instruction::eval1(0, 96, g(0.1)),
            Instruction::eval3(10, 3, g(0.2), g(0.2), g(0.2)),
            Instruction::refresh(),
        ],
        vec![
            Instruction::eval2(0, 10, g(1.0), g(0.5)),
            Instruction::eval1(5, 0, g(1.0)),
            Instruction::eval2(0, 10, g(3e38), g(3e38)),
            Instruction::eval3(0, 40, g(1.0), g(1e37), g(1e37)),
            Instruction::refresh(),
        ],
        vec![
            Instruction::acc_mode(),
            Instruction::eval2(0, 20, g(0.5), g(-0.1)),
            Instruction::eval3(4, 20, g(-0.25), g(0.05), g(-0.01)),
            Instruction::acc_mode(),
            Instruction::eval2(0, 20, g(0.5), g(-0.1)),
            Instruction::eval2(1, 20, g(0.5), g(-0.1)),
            Instruction::set_i(7, g(2.0)),
            Instruction::eval2(0, 20, g(0.5), g(-0.1)),
            Instruction::eval2(0, 20, g(0.5), g(-0.1)),
            Instruction::refresh(),
            Instruction::eval1(0, 20, g(0.5)),
            Instruction::eval1(0, 20, g(0.5)),
            Instruction::refresh(),
        ],
    ];
    for numeric in [
        "f64",
        "f32",
        "fixed:I=4.28,dI=4.28,ddI=4.28",
        "fixed:I=2.6,dI=2.6,ddI=2.6,overflow=wrap",
    ] {
        let numeric: Numeric = numeric.parse().unwrap();
        for (k, trace) in cases.iter().enumerate() {
            let (all, one) = (
                run(&numeric, 1, trace, true),
                run(&numeric, 1, trace, false),
            );
            assert_eq!(all, one, "case {k}, {numeric:?}");
        }
    }
    // the f32 chain that overflows is counted
    let f32: Numeric = "f32".parse().unwrap();
    assert!(run(&f32, 1, &cases[1], true).1.totals.overflows > 0);
}
