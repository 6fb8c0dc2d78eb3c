//! One test per opcode, pinning the semantics of `docs/ISA.md` with values worked out by
//! hand (dyadic fractions, so `f64` is exact). Each runs on both engines; a change in
//! what any instruction does makes its test fail.

use cwisim_isa::{Instruction as In, Intensity, TraceHeader};
use cwisim_xproc::{run, Machine, RunStats, Timing};

fn g(v: f64) -> Intensity {
    Intensity::grey(v)
}

/// Runs `trace` on an 8-wide grey array on both engines, checks they agree, and returns
/// the scanlines and statistics.
fn run8(trace: &[In]) -> (Vec<Vec<f64>>, RunStats) {
    run_on(TraceHeader::new(8, 4, 1).unwrap(), trace)
}

fn run_on(h: TraceHeader, trace: &[In]) -> (Vec<Vec<f64>>, RunStats) {
    let m = Machine::default();
    let (fast, fs) = run::<f64>(&h, trace, &m, Timing::Fast).unwrap();
    let (stepped, ss) = run::<f64>(&h, trace, &m, Timing::Stepped).unwrap();
    assert_eq!(fast, stepped, "fast and stepped scanlines differ");
    assert_eq!(fs, ss, "fast and stepped statistics differ");
    let row = fast.width * fast.channels;
    let rows = fast
        .data
        .chunks(row.max(1))
        .map(<[f64]>::to_vec)
        .take(fast.lines)
        .collect();
    (rows, fs)
}

#[test]
fn eval1_accumulates_a_constant_over_the_half_open_range() {
    let (rows, _) = run8(&[
        In::eval1(2, 3, g(0.5)),
        In::eval1(3, 1, g(0.25)),
        In::refresh(),
    ]);
    assert_eq!(rows[0], [0.0, 0.0, 0.5, 0.75, 0.5, 0.0, 0.0, 0.0]);
}

#[test]
fn eval2_forward_differences_from_i_at_x() {
    // value at x is I, then I + dI, I + 2 dI, …
    let (rows, _) = run8(&[In::eval2(1, 4, g(1.0), g(-0.25)), In::refresh()]);
    assert_eq!(rows[0], [0.0, 1.0, 0.75, 0.5, 0.25, 0.0, 0.0, 0.0]);
}

#[test]
fn eval3_second_order_differencing_order() {
    // I_k = I + k dI + k(k-1)/2 ddI: 0, 0.125, 0.5, 1.125 for I=0, dI=0.125, ddI=0.25
    let (rows, _) = run8(&[In::eval3(0, 4, g(0.0), g(0.125), g(0.25)), In::refresh()]);
    assert_eq!(rows[0][..5], [0.0, 0.125, 0.5, 1.125, 0.0]);
}

#[test]
fn set_i_overrides_the_running_value_from_that_processor_on() {
    let (rows, _) = run8(&[
        In::set_i(3, g(2.0)),
        In::eval2(1, 5, g(0.0), g(0.25)),
        In::refresh(),
    ]);
    // 0, 0.25, then the preload 2.0 at x=3 and the wave continues from it
    assert_eq!(rows[0], [0.0, 0.0, 0.25, 2.0, 2.25, 2.5, 0.0, 0.0]);
}

#[test]
fn set_di_and_set_ddi_override_the_differences() {
    let (rows, _) = run8(&[
        In::set_di(2, g(1.0)),
        In::eval2(0, 4, g(0.0), g(0.5)),
        In::refresh(),
    ]);
    // at x=2 dI becomes 1.0 after the value 1.0 was reached with the old dI
    assert_eq!(rows[0][..5], [0.0, 0.5, 1.0, 2.0, 0.0]);
    let (rows, _) = run8(&[
        In::set_ddi(1, g(1.0)),
        In::eval3(0, 4, g(0.0), g(0.0), g(0.0)),
        In::refresh(),
    ]);
    // ddI = 1 from x=1: values 0, 0, 0, 1
    assert_eq!(rows[0][..5], [0.0, 0.0, 0.0, 1.0, 0.0]);
}

#[test]
fn a_preload_is_consumed_by_the_first_eval_that_reads_it() {
    let (rows, _) = run8(&[
        In::set_i(1, g(0.75)),
        In::eval1(0, 3, g(0.25)),
        In::eval1(0, 3, g(0.25)),
        In::refresh(),
    ]);
    assert_eq!(rows[0][..4], [0.5, 1.0, 1.0, 0.0]);
}

#[test]
fn eval1_does_not_consume_a_di_preload_and_refresh_clears_it() {
    let (rows, _) = run8(&[
        In::set_di(1, g(1.0)),
        In::eval1(0, 2, g(0.25)),
        In::eval2(0, 3, g(0.0), g(0.0)),
        In::refresh(),
        In::eval2(0, 3, g(0.0), g(0.0)),
        In::refresh(),
    ]);
    assert_eq!(rows[0][..4], [0.25, 0.25, 1.0, 0.0]);
    assert_eq!(rows[1][..4], [0.0, 0.0, 0.0, 0.0]);
}

#[test]
fn periodic_sets_reach_every_period_to_the_array_end() {
    let (rows, s) = run8(&[
        In::set_pi(1, 3, g(1.0)),
        In::eval1(0, 8, g(0.0)),
        In::refresh(),
    ]);
    // preloads at 1, 4, 7; each sets the running value, which then stays
    assert_eq!(rows[0], [0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
    assert_eq!(s.lines[0].processor_updates, 3 + 8);
    let (rows, _) = run8(&[
        In::set_pdi(0, 4, g(0.25)),
        In::set_pi(4, 4, g(0.0)),
        In::eval2(0, 8, g(0.0), g(0.0)),
        In::refresh(),
    ]);
    assert_eq!(rows[0], [0.0, 0.25, 0.5, 0.75, 0.0, 0.25, 0.5, 0.75]);
    let (rows, _) = run8(&[
        In::set_pddi(2, 5, g(0.5)),
        In::eval3(0, 8, g(0.0), g(0.0), g(0.0)),
        In::refresh(),
    ]);
    // ddI 0.5 from x=2 (x=7 sets it again to 0.5)
    assert_eq!(rows[0], [0.0, 0.0, 0.0, 0.0, 0.5, 1.5, 3.0, 5.0]);
}

#[test]
fn eval0_sets_and_locks_until_refresh_first_claim_wins() {
    let (rows, s) = run8(&[
        In::eval1(0, 4, g(0.25)),
        In::eval0(1, 2, g(0.75)),
        In::eval1(0, 4, g(0.25)),
        In::eval0(2, 2, g(0.125)),
        In::refresh(),
        In::eval1(0, 4, g(0.25)),
        In::refresh(),
    ]);
    assert_eq!(rows[0][..5], [0.5, 0.75, 0.75, 0.125, 0.0]);
    assert_eq!(rows[1][..5], [0.25, 0.25, 0.25, 0.25, 0.0]);
    assert_eq!(s.lines[0].suppressed, 2 + 1);
}

#[test]
fn dis_masks_only_the_next_eval_command() {
    let (rows, s) = run8(&[
        In::dis(1, 2),
        In::eval1(0, 4, g(0.25)),
        In::eval1(0, 4, g(0.5)),
        In::refresh(),
    ]);
    assert_eq!(rows[0][..5], [0.75, 0.5, 0.5, 0.75, 0.0]);
    assert_eq!(s.lines[0].suppressed, 2);
    // the mask ends with the next Eval even when that Eval does not reach it
    let (rows, _) = run8(&[
        In::dis(5, 1),
        In::eval1(0, 1, g(1.0)),
        In::eval1(5, 1, g(1.0)),
        In::refresh(),
    ]);
    assert_eq!(rows[0][5], 1.0);
    // the wave still advances through a masked processor
    let (rows, _) = run8(&[
        In::dis(1, 1),
        In::eval2(0, 3, g(0.0), g(1.0)),
        In::refresh(),
    ]);
    assert_eq!(rows[0][..3], [0.0, 0.0, 2.0]);
}

#[test]
fn acc_mode_toggles_accumulation_of_negative_contributions() {
    let (rows, s) = run8(&[
        In::eval1(0, 2, g(1.0)),
        In::eval2(0, 2, g(0.5), g(-1.0)),
        In::acc_mode(),
        In::eval2(0, 2, g(0.5), g(-1.0)),
        In::acc_mode(),
        In::eval1(0, 2, g(-0.25)),
        In::refresh(),
    ]);
    // off (default): -0.5 dropped; on: 0.5 and -0.5 added; off again: -0.25 dropped
    assert_eq!(rows[0][..2], [2.0, 0.5]);
    assert_eq!(s.lines[0].dropped_negative, 1 + 2);
}

#[test]
fn acc_mode_persists_across_refresh() {
    let (rows, _) = run8(&[
        In::acc_mode(),
        In::refresh(),
        In::eval1(0, 1, g(-0.5)),
        In::refresh(),
    ]);
    assert_eq!(rows[1][0], -0.5);
}

#[test]
fn refresh_outputs_and_resets_everything() {
    let (rows, s) = run8(&[
        In::eval1(0, 8, g(0.5)),
        In::set_i(2, g(4.0)),
        In::eval0(5, 1, g(1.0)),
        In::dis(6, 1),
        In::refresh(),
        In::eval1(0, 8, g(0.25)),
        In::refresh(),
    ]);
    assert_eq!(rows[0], [0.5, 0.5, 0.5, 0.5, 0.5, 1.0, 0.5, 0.5]);
    assert_eq!(rows[1], [0.25; 8]);
    assert_eq!(s.totals.lines, 2);
}

#[test]
fn nop_changes_nothing_but_time() {
    let (rows_a, a) = run8(&[In::eval1(0, 2, g(1.0)), In::refresh()]);
    let (rows_b, b) = run8(&[In::eval1(0, 2, g(1.0)), In::nop(), In::nop(), In::refresh()]);
    assert_eq!(rows_a, rows_b);
    assert_eq!(b.lines[0].busy_cycles, a.lines[0].busy_cycles + 2);
    assert_eq!(b.lines[0].opcodes.get(cwisim_isa::Opcode::Nop), 2);
}

#[test]
fn channels_are_independent() {
    let h = TraceHeader::new(4, 1, 3).unwrap();
    let (rows, _) = run_on(
        h,
        &[
            In::eval2(
                0,
                3,
                Intensity::new(&[1.0, 0.0, 0.5]),
                Intensity::new(&[-0.5, 0.25, 0.0]),
            ),
            In::refresh(),
        ],
    );
    assert_eq!(
        rows[0],
        [1.0, 0.0, 0.5, 0.5, 0.25, 0.5, 0.0, 0.5, 0.5, 0.0, 0.0, 0.0]
    );
}

#[test]
fn instructions_after_the_last_refresh_are_reported_not_output() {
    let (rows, s) = run8(&[
        In::eval1(0, 1, g(1.0)),
        In::refresh(),
        In::eval1(0, 1, g(1.0)),
        In::nop(),
    ]);
    assert_eq!(rows.len(), 1);
    assert_eq!(s.totals.unrefreshed_instructions, 2);
    assert_eq!(s.totals.instructions, 4);
}
