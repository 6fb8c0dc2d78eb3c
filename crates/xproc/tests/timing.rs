//! The timing model of `docs/TIMING.md`, pinned with cycle counts worked out by hand, on
//! both engines.

use cwisim_isa::{Instruction as In, Intensity, TraceHeader};
use cwisim_xproc::stepped::SteppedEngine;
use cwisim_xproc::{run, Engine, Machine, Native, NullSink, RunStats, Timing};

fn g(v: f64) -> Intensity {
    Intensity::grey(v)
}

fn stats(h: TraceHeader, m: &Machine, trace: &[In]) -> RunStats {
    let (fi, fs) = run::<f64>(&h, trace, m, Timing::Fast).unwrap();
    let (si, ss) = run::<f64>(&h, trace, m, Timing::Stepped).unwrap();
    assert_eq!(fi, si);
    assert_eq!(fs, ss);
    fs
}

#[test]
fn issue_entry_gate_ready_and_slack() {
    // width 8, hop 1, line period 10 cycles; Eval2 costs 1 + 2 values = 3, Eval1 2, Refresh 1
    let h = TraceHeader::new(8, 4, 1).unwrap();
    let m = Machine::default()
        .with_overrides(&["line_period_cycles=10".into()])
        .unwrap();
    let s = stats(
        h,
        &m,
        &[
            In::eval2(0, 4, g(0.0), g(0.0)),
            In::refresh(),
            In::eval1(0, 8, g(0.0)),
            In::refresh(),
        ],
    );
    let l0 = &s.lines[0];
    // Eval2 issues 0..3 and enters at 3; Refresh issues 3..4, enters at 4, leaves the
    // last processor at 4 + 8 = 12; the display takes line 0 at 10: 2 cycles late.
    assert_eq!((l0.first_issue, l0.busy_cycles, l0.stall_cycles), (0, 4, 0));
    assert_eq!((l0.ready, l0.deadline, l0.slack), (12, 10, -2));
    let l1 = &s.lines[1];
    // Eval1 issues 4..6 and enters at 6; the Refresh waits for the display to take line 0
    // at 10, issues 10..11, enters at 11, is ready at 19; deadline 20.
    assert_eq!((l1.first_issue, l1.busy_cycles, l1.stall_cycles), (4, 3, 4));
    assert_eq!((l1.ready, l1.deadline, l1.slack), (19, 20, 1));
    assert_eq!(s.totals.late_lines, 1);
    assert_eq!(
        (s.totals.worst_slack, s.totals.worst_line),
        (Some(-2), Some(0))
    );
    assert_eq!(s.totals.cycles, 19);
    assert_eq!(s.traversal_cycles, 8);
}

#[test]
fn slow_hops_space_the_tokens() {
    // hop 3: a token holds each processor 3 cycles, so tokens enter at most every 3 cycles
    let h = TraceHeader::new(4, 1, 1).unwrap();
    let m = Machine::default()
        .with_overrides(&["hop_cycles=3".into()])
        .unwrap();
    let s = stats(h, &m, &[In::nop(), In::nop(), In::nop(), In::refresh()]);
    // Nops enter at 1, 4, 7; Refresh at 10; ready at 10 + 4*3 = 22
    assert_eq!(s.lines[0].busy_cycles, 4);
    assert_eq!(s.lines[0].stall_cycles, 2 + 2 + 2);
    assert_eq!(s.lines[0].ready, 22);
}

#[test]
fn vertical_blanking_separates_frames() {
    let h = TraceHeader::new(4, 2, 1).unwrap();
    let m = Machine::default()
        .with_overrides(&["line_period_cycles=100".into(), "vblank_lines=3".into()])
        .unwrap();
    let s = stats(h, &m, &[In::refresh(), In::refresh(), In::refresh()]);
    let d: Vec<u64> = s.lines.iter().map(|l| l.deadline).collect();
    // frame 0: rows at slots 0, 1; frame 1 starts after 2 + 3 slots
    assert_eq!(d, [100, 200, 600]);
    // the third Refresh waits for line 1 to be taken at 200
    assert_eq!(s.lines[2].first_issue, 200);
    assert_eq!((s.totals.frames, s.totals.partial_frame_lines), (1, 1));
}

#[test]
fn rgb_pays_for_three_channels_and_grey_does_not() {
    let m = Machine::default();
    let e = |c: usize| {
        In::eval3(
            0,
            1,
            Intensity::splat(0.0, c),
            Intensity::splat(0.0, c),
            Intensity::splat(0.0, c),
        )
    };
    let grey = stats(
        TraceHeader::new(4, 1, 1).unwrap(),
        &m,
        &[e(1), In::refresh()],
    );
    let rgb = stats(
        TraceHeader::new(4, 1, 3).unwrap(),
        &m,
        &[e(3), In::refresh()],
    );
    assert_eq!(grey.lines[0].busy_cycles, 4 + 1);
    assert_eq!(rgb.lines[0].busy_cycles, 10 + 1);
}

#[test]
fn default_machine_is_in_time_for_a_light_1024_wide_line() {
    let h = TraceHeader::new(1024, 1024, 1).unwrap();
    let s = stats(
        h,
        &Machine::default(),
        &[In::eval2(0, 1024, g(0.0), g(0.001)), In::refresh()],
    );
    // 1559-cycle line period; Eval2 3 + Refresh 1 + 1024 hops = 1028
    assert_eq!(s.line_period, 1559);
    assert_eq!(s.lines[0].ready, 1028);
    assert_eq!(s.lines[0].slack, 1559 - 1028);
}

/// A few instructions per scanline on a machine whose line period is `period` cycles,
/// with `hop` cycles per hop: mostly idle cycles, waiting for the display.
fn sparse_trace(lines: u32) -> (TraceHeader, Vec<In>) {
    let h = TraceHeader::new(6, lines, 1).unwrap();
    let mut trace = Vec::new();
    for l in 0..lines {
        let v = f64::from(l + 1) / 8.0;
        trace.push(In::eval1(1, 4, g(v)));
        trace.push(In::eval2(0, 6, g(v), g(0.25)));
        trace.push(In::refresh());
    }
    (h, trace)
}

#[test]
fn the_stepped_engine_jumps_over_idle_cycles() {
    // line period 10⁶ cycles, hop 3: stepping every cycle takes 3 × 10⁶ steps before the
    // last Refresh issues; stepping from event to event a handful per instruction
    let (h, trace) = sparse_trace(4);
    let m = Machine::default()
        .with_overrides(&["line_period_cycles=1000000".into(), "hop_cycles=3".into()])
        .unwrap();
    let mut eng = SteppedEngine::<Native<f64>>::new(&h, m.timeline(&h).unwrap());
    let mut sink = NullSink;
    for i in &trace {
        eng.execute(i, &mut sink);
    }
    // every token visits 6 processors: 7 moves each, each at a cycle of its own at most,
    // plus the issue and the bus entry of each instruction
    let bound = trace.len() as u64 * (7 + 2);
    assert!(
        eng.steps() <= bound,
        "{} cycles stepped, more than {bound}: idle cycles are not jumped over",
        eng.steps()
    );
    let stepped = Box::new(eng).finish(&mut sink);
    assert_eq!(stepped.lines[3].deadline, 4_000_000);
    // the same statistics as the fast engine's (`stats` compares the images too)
    assert_eq!(stats(h, &m, &trace), stepped);
}

#[test]
fn a_terahertz_clock_replays_on_the_stepped_engine_as_on_the_fast_one() {
    // clock 1e12 Hz (the limit) at 60 Hz over 4 + 10 lines: a line period of about
    // 1.2 × 10⁹ cycles, which only jumping over idle cycles makes steppable
    let (h, trace) = sparse_trace(4);
    for hop in ["hop_cycles=1", "hop_cycles=65536"] {
        let m = Machine::default()
            .with_overrides(&["clock_hz=1e12".into(), "vblank_lines=10".into(), hop.into()])
            .unwrap();
        let period = m.timeline(&h).unwrap().line_period;
        assert!(period > 1_000_000_000, "{period}");
        let s = stats(h, &m, &trace);
        assert_eq!(s.lines[3].deadline, 4 * period);
        assert_eq!(s.totals.late_lines, 0);
    }
}

#[test]
fn the_stepped_engine_reaches_and_saturates_at_the_longest_line_periods() {
    // one scanline per frame, the longest line period and the most blanking: deadlines pass
    // u64::MAX at scanline 256, which the stepped engine reaches by jumping over the
    // waiting; both engines saturate there alike
    let m = Machine::default()
        .with_overrides(&[
            "line_period_cycles=1099511627776".into(),
            "vblank_lines=65536".into(),
            "hop_cycles=65536".into(),
        ])
        .unwrap();
    let h = TraceHeader::new(2, 1, 1).unwrap();
    let trace: Vec<In> = (0..300)
        .flat_map(|_| [In::eval1(0, 2, g(0.5)), In::refresh()])
        .collect();
    let s = stats(h, &m, &trace);
    assert_eq!(s.lines[256].deadline, u64::MAX);
    assert_eq!(s.totals.saturated_lines, 44);
    assert_eq!(s.totals.cycles, u64::MAX);
}
