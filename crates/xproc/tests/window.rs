//! Stepping a window: the fast engine up to scanline `k`, then the cycle-stepped engine
//! from its state ([`replay_probed_numeric`], [`StepFrom`]), against a stepped run from
//! the start, on random traces and machines in every numeric format: the probe must see
//! every event of the scanlines it steps (cycle, processor, registers before and after)
//! exactly as the full run shows them, the processors' states handed over must be those
//! the full run has there, and the scanlines and statistics of the whole run must be
//! the same, bit for bit.

mod common;

use cwisim_isa::{Instruction, Intensity, Opcode, TraceHeader};
use cwisim_xproc::fast::FastEngine;
use cwisim_xproc::{
    replay_probed_from, replay_probed_numeric, Engine, Machine, Native, NullSink, Numeric, Probe,
    ProcessorState, StepFrom,
};
use proptest::prelude::*;
use std::collections::HashMap;

/// A processor's state with its values as bits (`NaN`s and signed zeros compare exactly).
#[derive(Clone, Debug, PartialEq, Eq)]
struct State {
    acc: Vec<u64>,
    reg: [Vec<u64>; 3],
    flags: [bool; 6],
}

impl From<&ProcessorState> for State {
    fn from(s: &ProcessorState) -> Self {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        State {
            acc: bits(&s.acc),
            reg: [bits(&s.reg[0]), bits(&s.reg[1]), bits(&s.reg[2])],
            flags: [
                s.has[0],
                s.has[1],
                s.has[2],
                s.locked,
                s.masked,
                s.negative_enabled,
            ],
        }
    }
}

/// One event a probe is told, with the scanline it belongs to.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Event {
    Issue {
        cycle: u64,
        index: u64,
        line: u64,
        op: Opcode,
    },
    Enter {
        cycle: u64,
        index: u64,
        line: u64,
    },
    Visit {
        cycle: u64,
        p: usize,
        index: u64,
        line: u64,
        addressed: bool,
        before: Box<State>,
        after: Box<State>,
    },
    Ready {
        cycle: u64,
        line: u64,
    },
}

impl Event {
    fn line(&self) -> u64 {
        match self {
            Event::Issue { line, .. }
            | Event::Enter { line, .. }
            | Event::Visit { line, .. }
            | Event::Ready { line, .. } => *line,
        }
    }
    fn cycle(&self) -> u64 {
        match self {
            Event::Issue { cycle, .. }
            | Event::Enter { cycle, .. }
            | Event::Visit { cycle, .. }
            | Event::Ready { cycle, .. } => *cycle,
        }
    }
}

/// What the hand-over told the probe: cycle, scanline, watched processors' states.
type Resumed = (u64, u64, Vec<(usize, State)>);

/// Logs every event; watches processors `watched`.
#[derive(Default)]
struct Log {
    watched: Vec<usize>,
    events: Vec<Event>,
    /// Scanline of each instruction issued (an entry names only the instruction).
    line_of: HashMap<u64, u64>,
    resumed: Vec<Resumed>,
}

impl Log {
    fn watching(watched: Vec<usize>) -> Self {
        Log {
            watched,
            ..Log::default()
        }
    }
}

impl Probe for Log {
    fn watches(&self, p: usize) -> bool {
        self.watched.contains(&p)
    }
    fn issue(&mut self, cycle: u64, index: u64, line: u64, instr: &Instruction) {
        self.line_of.insert(index, line);
        self.events.push(Event::Issue {
            cycle,
            index,
            line,
            op: instr.op,
        });
    }
    fn enter(&mut self, cycle: u64, index: u64) {
        let line = self.line_of[&index];
        self.events.push(Event::Enter { cycle, index, line });
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
        self.events.push(Event::Visit {
            cycle,
            p,
            index,
            line,
            addressed,
            before: Box::new(before.into()),
            after: Box::new(after.into()),
        });
    }
    fn line_ready(&mut self, cycle: u64, line: u64) {
        self.events.push(Event::Ready { cycle, line });
    }
    fn resume(&mut self, cycle: u64, line: u64, watched: &[(usize, ProcessorState)]) {
        let states = watched.iter().map(|(p, s)| (*p, s.into())).collect();
        self.resumed.push((cycle, line, states));
    }
}

/// Runs the trace both ways and checks every promise of the window; the scanline the
/// stepped engine started with.
fn check_window(
    header: &TraceHeader,
    machine: &Machine,
    numeric: &Numeric,
    trace: &[Instruction],
    watched: &[usize],
    from: StepFrom,
) -> Result<u64, TestCaseError> {
    let mut full = Log::watching(watched.to_vec());
    let (full_stats, full_image) =
        common::stepped_numeric(header, machine, numeric, trace, &mut full);

    let mut win = Log::watching(watched.to_vec());
    let mut sink = common::image_sink(header);
    let mut reports = Vec::new();
    let mut reader = common::VecReader::new(header, trace);
    let win_stats = replay_probed_numeric(
        &mut reader,
        machine,
        numeric,
        from,
        &mut win,
        &mut sink,
        &mut |b| reports.push(b),
    )
    .unwrap();
    let win_image = sink.finish().unwrap();

    // the whole run's scanlines and statistics, records of every scanline included
    prop_assert_eq!(
        common::image_bits(&win_image),
        common::image_bits(&full_image)
    );
    prop_assert_eq!(&win_stats, &full_stats);
    // progress: never backwards, ending with the whole trace
    prop_assert!(reports.windows(2).all(|w| w[0] <= w[1]));
    prop_assert_eq!(reports.last().copied(), Some(trace.len() as u64));

    // told once where the stepped engine starts
    prop_assert_eq!(win.resumed.len(), 1);
    let (cycle, j, states) = win.resumed[0].clone();
    let lines = full_stats.totals.lines;
    let (k, exact) = match from {
        StepFrom::Scanline(k) => (k, true),
        StepFrom::Issue(k) => (k, false),
    };
    if exact {
        prop_assert_eq!(j, k.min(lines));
    } else {
        prop_assert!(j <= k.min(lines));
    }

    // every event of scanline j and later, in the same order, and nothing else
    let later: Vec<Event> = full
        .events
        .iter()
        .filter(|e| e.line() >= j)
        .cloned()
        .collect();
    prop_assert_eq!(&win.events, &later);

    // Issue(k): nothing of the scanlines not stepped happens once scanline k issues
    if !exact {
        let start = full
            .events
            .iter()
            .find(|e| matches!(e, Event::Issue { line, .. } if *line == k));
        if let Some(start) = start {
            let s = start.cycle();
            prop_assert!(full.events.iter().all(|e| e.line() >= j || e.cycle() < s));
        }
    }

    // the hand-over cycle: the entry of the last instruction before scanline j
    let last_entry = full
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Enter { cycle, line, .. } if *line < j => Some(*cycle),
            _ => None,
        })
        .max();
    prop_assert_eq!(cycle, last_entry.unwrap_or(0));

    // the states handed over: what the last earlier token left, what the first later
    // token finds
    prop_assert_eq!(
        states.iter().map(|s| s.0).collect::<Vec<_>>(),
        watched.to_vec()
    );
    for (p, state) in &states {
        let visits = || {
            full.events.iter().filter_map(|e| match e {
                Event::Visit {
                    p: q,
                    line,
                    before,
                    after,
                    ..
                } if q == p => Some((*line, before, after)),
                _ => None,
            })
        };
        if let Some((_, _, after)) = visits().rfind(|v| v.0 < j) {
            prop_assert_eq!(&**after, state);
        }
        if let Some((_, before, _)) = visits().find(|v| v.0 >= j) {
            prop_assert_eq!(&**before, state);
        }
    }
    Ok(j)
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
                // Line periods shorter than a traversal: tokens of several scanlines in
                // the array at once, Refresh gates, late scanlines.
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
                    0..=(width as usize).min(3),
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
    fn a_window_after_the_fast_engine_is_the_full_stepped_run(
        (numeric, header, machine, trace, watched) in case(),
        k in 0u64..12,
        in_flight in any::<bool>(),
    ) {
        let from = if in_flight { StepFrom::Issue(k) } else { StepFrom::Scanline(k) };
        check_window(&header, &machine, &numeric, &trace, &watched, from)?;
    }
}

/// One scanline per frame and nothing but `Refresh`es: each waits for the display, so
/// the scanline before has left the array when the window starts, and only the window is
/// stepped, both ways.
#[test]
fn only_the_window_is_stepped_when_the_scanline_before_has_left() {
    let header = TraceHeader::new(16, 1, 1).unwrap();
    let machine = Machine {
        line_period_cycles: Some(1000),
        ..Machine::default()
    };
    let trace = vec![Instruction::refresh(); 300];
    for from in [StepFrom::Scanline(299), StepFrom::Issue(299)] {
        let j = check_window(&header, &machine, &Numeric::F64, &trace, &[0, 15], from).unwrap();
        assert_eq!(j, 299, "{from:?}");
    }
}

/// The scanline before leaves the array at the very cycle the window's `Refresh` starts
/// to issue: a waveform steps it (its `line_ready` is at that cycle), a history not.
#[test]
fn a_scanline_leaving_as_the_window_starts_is_stepped_for_a_waveform() {
    // Refresh costs 4 and enters 4 cycles after its gate; it leaves the 16 processors 16
    // cycles later, at the next gate (a line period of 20, no blanking)
    let header = TraceHeader::new(16, 1, 1).unwrap();
    let machine = Machine {
        hop_cycles: 1,
        opcode_cycles: [(Opcode::Refresh, 4)].into(),
        line_period_cycles: Some(20),
        vblank_lines: 0,
        ..Machine::default()
    };
    let trace = vec![Instruction::refresh(); 12];
    let j = check_window(
        &header,
        &machine,
        &Numeric::F64,
        &trace,
        &[15],
        StepFrom::Issue(9),
    )
    .unwrap();
    assert_eq!(j, 8);
    let j = check_window(
        &header,
        &machine,
        &Numeric::F64,
        &trace,
        &[15],
        StepFrom::Scanline(9),
    )
    .unwrap();
    assert_eq!(j, 9);
}

/// Scanlines whose `Refresh` does not wait and a chain longer than a line period: for a
/// waveform (`Issue`) the scanlines still crossing the array are stepped too, for a
/// history (`Scanline`) not.
#[test]
fn tokens_in_flight_are_stepped_for_a_waveform_only() {
    let header = TraceHeader::new(32, 4, 1).unwrap();
    let machine = Machine {
        hop_cycles: 3,
        line_period_cycles: Some(20),
        ..Machine::default()
    };
    let g = Intensity::grey;
    let mut trace = Vec::new();
    for line in 0..40u32 {
        trace.push(Instruction::set_i(line % 32, g(0.25)));
        trace.push(Instruction::eval2(0, 32, g(0.5), g(-0.01)));
        if line % 5 == 0 {
            trace.push(Instruction::acc_mode());
        }
        trace.push(Instruction::refresh());
    }
    let j = check_window(
        &header,
        &machine,
        &Numeric::F64,
        &trace,
        &[3, 31],
        StepFrom::Scanline(30),
    )
    .unwrap();
    assert_eq!(j, 30);
    let j = check_window(
        &header,
        &machine,
        &Numeric::F64,
        &trace,
        &[3, 31],
        StepFrom::Issue(30),
    )
    .unwrap();
    assert!(j < 30 && j > 20, "{j}");
}

/// A window beyond the end of the trace steps only what follows the last `Refresh`.
#[test]
fn a_window_beyond_the_end() {
    let header = TraceHeader::new(8, 2, 1).unwrap();
    let g = Intensity::grey;
    let mut trace = vec![Instruction::eval1(0, 8, g(0.5)), Instruction::refresh()];
    trace.push(Instruction::eval1(2, 3, g(0.25))); // never refreshed
    for from in [StepFrom::Scanline(5), StepFrom::Issue(5)] {
        let j = check_window(
            &header,
            &Machine::default(),
            &Numeric::F64,
            &trace,
            &[2],
            from,
        )
        .unwrap();
        assert_eq!(j, 1);
    }
}

/// At the edges of the machine's ranges the fast engine reaches cycles the stepped engine
/// cannot go on from: refused, not wrapped.
#[test]
fn a_window_beyond_2_pow_63_cycles_is_refused() {
    let header = TraceHeader::new(8, 1, 1).unwrap();
    let machine = Machine {
        line_period_cycles: Some(1 << 40),
        vblank_lines: 1 << 16,
        ..Machine::default()
    };
    let trace = vec![Instruction::refresh(); 140];
    let mut reader = common::VecReader::new(&header, &trace);
    let err = replay_probed_from::<f64>(
        &mut reader,
        &machine,
        StepFrom::Scanline(139),
        &mut Log::default(),
        &mut NullSink,
        &mut |_| {},
    )
    .unwrap_err();
    assert!(
        err.to_string().contains("scanline 139 starts at cycle"),
        "{err}"
    );
}

/// `replay_probed_from` is `replay_probed_numeric` in `f64`.
#[test]
fn the_native_entry_point_is_the_numeric_one_in_f64() {
    let header = TraceHeader::new(8, 2, 1).unwrap();
    let g = Intensity::grey;
    let trace: Vec<_> = (0..6)
        .flat_map(|l| [Instruction::eval1(l, 3, g(0.5)), Instruction::refresh()])
        .collect();
    let run = |numeric: bool| {
        let mut log = Log::watching(vec![1, 4]);
        let mut reader = common::VecReader::new(&header, &trace);
        let from = StepFrom::Scanline(3);
        let stats = if numeric {
            replay_probed_numeric(
                &mut reader,
                &Machine::default(),
                &Numeric::F64,
                from,
                &mut log,
                &mut NullSink,
                &mut |_| {},
            )
        } else {
            replay_probed_from::<f64>(
                &mut reader,
                &Machine::default(),
                from,
                &mut log,
                &mut NullSink,
                &mut |_| {},
            )
        }
        .unwrap();
        (stats, log.events, log.resumed)
    };
    assert_eq!(run(true), run(false));
}

/// The fast engine hands over only between scanlines.
#[test]
fn no_hand_over_in_the_middle_of_a_scanline() {
    let header = TraceHeader::new(8, 2, 1).unwrap();
    let timeline = Machine::default().timeline(&header).unwrap();
    let fast = |instrs: &[Instruction]| {
        let mut fast = FastEngine::<Native<f64>>::new(&header, timeline.clone());
        for i in instrs {
            fast.execute(i, &mut NullSink);
        }
        fast.handover()
    };
    let eval = Instruction::eval1(0, 8, Intensity::grey(0.5));
    assert!(fast(std::slice::from_ref(&eval)).is_none());
    let state = fast(&[eval, Instruction::refresh()]).expect("between scanlines");
    assert_eq!((state.lines(), state.instructions()), (1, 2));
    assert!(state.cycle() > 0);
    let state = fast(&[]).expect("before the first instruction");
    assert_eq!(
        (state.lines(), state.instructions(), state.cycle()),
        (0, 0, 0)
    );
}
