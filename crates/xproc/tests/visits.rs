//! The visits without stepping ([`replay_visits_numeric`]) against the cycle-stepped
//! engine from the start of the trace, on random traces and machines in every numeric
//! format: every issue, entry and readiness of the scanlines asked for at the same cycle,
//! to each watched processor the visits a history shows (addressed, or leaving the
//! processor different) in the same order with the same cycles, registers and flags, the
//! same hand-over as [`replay_probed_numeric`]'s, and the whole run's scanlines and
//! statistics bit for bit.

mod common;

use cwisim_isa::{Instruction, Opcode, TraceHeader};
use cwisim_xproc::{
    replay_probed_numeric, replay_visits_numeric, Machine, Numeric, Probe, ProcessorState, StepFrom,
};
use proptest::prelude::*;

/// A state with its values as bits (`NaN`s compare exactly).
fn bits(s: &ProcessorState) -> (Vec<u64>, [bool; 6]) {
    let v = s
        .acc
        .iter()
        .chain(s.reg.iter().flatten())
        .map(|x| x.to_bits())
        .collect();
    let f = [
        s.has[0],
        s.has[1],
        s.has[2],
        s.locked,
        s.masked,
        s.negative_enabled,
    ];
    (v, f)
}

type State = (Vec<u64>, [bool; 6]);

/// A hand-over: cycle, scanline, the watched processors' states.
type Resumed = (u64, u64, Vec<(usize, State)>);

/// A visit: cycle, index, line, addressed, before, after.
type Visit = (u64, u64, u64, bool, State, State);

#[derive(Default)]
struct Log {
    watched: Vec<usize>,
    /// (index, line, op, issue cycle), (index, entry cycle)
    issues: Vec<(u64, u64, Opcode, u64)>,
    enters: Vec<(u64, u64)>,
    ready: Vec<(u64, u64)>,
    /// Per watched processor, the shown visits.
    visits: Vec<Vec<Visit>>,
    resumed: Vec<Resumed>,
}

impl Log {
    fn watching(watched: &[usize]) -> Self {
        Log {
            watched: watched.to_vec(),
            visits: vec![Vec::new(); watched.len()],
            ..Log::default()
        }
    }

    /// What a window from scanline `first` must report: the events of scanline `first`
    /// and later, in trace order.
    fn after_line(&self, first: u64) -> Log {
        let line_of = |index: u64| {
            self.issues
                .iter()
                .find(|i| i.0 == index)
                .map(|i| i.1)
                .unwrap()
        };
        let mut issues: Vec<_> = self
            .issues
            .iter()
            .filter(|i| i.1 >= first)
            .copied()
            .collect();
        issues.sort();
        let mut enters: Vec<_> = self
            .enters
            .iter()
            .filter(|e| line_of(e.0) >= first)
            .copied()
            .collect();
        enters.sort();
        let mut ready: Vec<_> = self
            .ready
            .iter()
            .filter(|r| r.1 >= first)
            .copied()
            .collect();
        ready.sort_by_key(|r| r.1);
        Log {
            watched: self.watched.clone(),
            issues,
            enters,
            ready,
            visits: self
                .visits
                .iter()
                .map(|v| v.iter().filter(|v| v.2 >= first).cloned().collect())
                .collect(),
            resumed: Vec::new(),
        }
    }
}

impl Probe for Log {
    fn watches(&self, p: usize) -> bool {
        self.watched.contains(&p)
    }
    fn issue(&mut self, cycle: u64, index: u64, line: u64, instr: &Instruction) {
        self.issues.push((index, line, instr.op, cycle));
    }
    fn enter(&mut self, cycle: u64, index: u64) {
        self.enters.push((index, cycle));
    }
    fn visit(
        &mut self,
        cycle: u64,
        p: usize,
        index: u64,
        line: u64,
        _instr: &Instruction,
        addressed: bool,
        before: &ProcessorState,
        after: &ProcessorState,
    ) {
        // what `cwisim history` shows
        if addressed || before != after {
            let k = self.watched.iter().position(|&q| q == p).unwrap();
            self.visits[k].push((cycle, index, line, addressed, bits(before), bits(after)));
        }
    }
    fn line_ready(&mut self, cycle: u64, line: u64) {
        self.ready.push((cycle, line));
    }
    fn resume(&mut self, cycle: u64, line: u64, watched: &[(usize, ProcessorState)]) {
        let states = watched.iter().map(|(p, s)| (*p, bits(s))).collect();
        self.resumed.push((cycle, line, states));
    }
}

fn check(
    header: &TraceHeader,
    machine: &Machine,
    numeric: &Numeric,
    trace: &[Instruction],
    watched: &[usize],
    first: u64,
) -> Result<(), TestCaseError> {
    let mut full = Log::watching(watched);
    let (full_stats, full_image) =
        common::stepped_numeric(header, machine, numeric, trace, &mut full);

    let mut log = Log::watching(watched);
    let mut s = common::image_sink(header);
    let mut reports = Vec::new();
    let stats = replay_visits_numeric(
        &mut common::VecReader::new(header, trace),
        machine,
        numeric,
        first,
        &mut log,
        &mut s,
        &mut |b| reports.push(b),
    )
    .unwrap();
    prop_assert_eq!(
        common::image_bits(&s.finish().unwrap()),
        common::image_bits(&full_image)
    );
    prop_assert_eq!(&stats, &full_stats);
    prop_assert!(reports.windows(2).all(|w| w[0] <= w[1]));
    prop_assert_eq!(reports.last().copied(), Some(trace.len() as u64));

    if full_stats.totals.lines < first {
        // the stepped engine reports the instructions after the last Refresh; this
        // reports nothing
        prop_assert!(log.issues.is_empty() && log.resumed.is_empty());
        return Ok(());
    }
    let want = full.after_line(first);
    let mut issues = log.issues.clone();
    issues.sort();
    prop_assert_eq!(&issues, &want.issues);
    prop_assert_eq!(&log.enters, &want.enters);
    prop_assert_eq!(&log.ready, &want.ready);
    for (k, p) in watched.iter().enumerate() {
        prop_assert_eq!(&log.visits[k], &want.visits[k], "processor {}", p);
    }

    // told once, as the stepped engine's hand-over tells it
    let mut win = Log::watching(watched);
    replay_probed_numeric(
        &mut common::VecReader::new(header, trace),
        machine,
        numeric,
        StepFrom::Scanline(first),
        &mut win,
        &mut cwisim_xproc::NullSink,
        &mut |_| {},
    )
    .unwrap();
    prop_assert_eq!(&log.resumed, &win.resumed);
    Ok(())
}

fn case() -> impl Strategy<Value = (Numeric, TraceHeader, Machine, Vec<Instruction>, Vec<usize>)> {
    (
        common::numeric(),
        1u32..24,
        1u32..4,
        prop_oneof![Just(1u8), Just(3u8)],
        prop_oneof![3 => 1u32..4, 1 => Just(57u32), 1 => Just(300u32)],
        prop_oneof![3 => 0u32..3, 1 => Just(150u32)],
        prop_oneof![3 => 1u64..300, 1 => 2000u64..20000],
        0u32..3,
    )
        .prop_flat_map(
            |(numeric, width, lines, channels, hop, value_cycles, period, vblank)| {
                let header = TraceHeader::new(width, lines, channels).unwrap();
                let m = Machine {
                    hop_cycles: hop,
                    value_cycles,
                    opcode_cycles: [(Opcode::Eval3, 1 + hop / 2), (Opcode::Refresh, 2)].into(),
                    line_period_cycles: Some(period),
                    vblank_lines: vblank,
                    ..Machine::default()
                };
                let watched = proptest::sample::subsequence(
                    (0..width as usize).collect::<Vec<_>>(),
                    0..=width as usize,
                );
                (
                    Just(numeric),
                    Just(header),
                    Just(m),
                    proptest::collection::vec(
                        common::instruction(width, usize::from(channels), common::value()),
                        0..80,
                    ),
                    watched,
                )
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn the_visits_are_the_stepped_engines(
        (numeric, header, machine, trace, watched) in case(),
        first in 0u64..12,
    ) {
        check(&header, &machine, &numeric, &trace, &watched, first)?;
    }
}

/// `f32` accumulators overflowing both ways hold a `NaN`: every token's visit differs
/// from itself there, and shows.
#[test]
fn a_nan_shows_every_visit() {
    use cwisim_isa::Intensity;
    let header = TraceHeader::new(4, 1, 1).unwrap();
    let g = Intensity::grey;
    // processor 1: +inf, then -inf added (negative accumulation on): NaN
    let trace = vec![
        Instruction::eval2(0, 2, g(3e38), g(3e38)),
        Instruction::acc_mode(),
        Instruction::eval2(0, 2, g(-3e38), g(-3e38)),
        Instruction::set_i(3, g(0.5)),
        Instruction::dis(0, 1),
        Instruction::eval1(2, 1, g(0.25)),
        Instruction::refresh(),
    ];
    check(
        &header,
        &Machine::default(),
        &Numeric::F32,
        &trace,
        &[0, 1, 3],
        0,
    )
    .unwrap();
    let mut log = Log::watching(&[1]);
    replay_visits_numeric(
        &mut common::VecReader::new(&header, &trace),
        &Machine::default(),
        &Numeric::F32,
        0,
        &mut log,
        &mut cwisim_xproc::NullSink,
        &mut |_| {},
    )
    .unwrap();
    // the instructions after the accumulator became NaN show at processor 1, addressed
    // or not
    let v = &log.visits[1 - 1];
    assert_eq!(v.iter().filter(|v| !v.3).count(), 3, "{v:?}");
}
