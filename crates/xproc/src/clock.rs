//! The issue model, one scanline at a time: the cycles of a scanline's instructions from
//! nothing but how many of each opcode it has and which came first.
//!
//! Within a scanline the model is additive. The bus starts an instruction when the one
//! before it has entered the chain, and the token enters the first processor when both its
//! issue is done and the previous token has moved on a hop: an instruction that is not a
//! `Refresh` enters `max(cost, hop)` cycles after the one before it (`cost` cycles after
//! the start, for the first instruction of the trace). Only a `Refresh` waits for
//! something else — the display taking the previous scanline ([`Timeline::refresh_gate`])
//! — and it ends its scanline. So a scanline's timing is its opcode counts times each
//! opcode's pace, then its `Refresh`: the fast engine times scanlines at their `Refresh`,
//! and scanlines executed elsewhere (a band on another thread, [`crate::band`]) are timed
//! in order when they are taken in, one step each.
//!
//! The cycle-stepped engine times every instruction by stepping cycles; the property
//! tests of `tests/equivalence.rs` hold the two to the same cycle of every event.

use crate::machine::Timeline;
use crate::stats::IssueTally;
use cwisim_isa::Opcode;

/// When a scanline's instructions issued ([`Clock::issue`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct IssueTimes {
    /// Cycle the scanline's first instruction started to issue.
    pub(crate) first_issue: u64,
    /// Cycle the instruction before the scanline's first entered the chain (0 for the
    /// trace's first).
    pub(crate) entry_before: u64,
    /// Cycle the scanline's last instruction entered the chain.
    pub(crate) last_entry: u64,
}

/// The issue model's state between scanlines: when the last instruction entered the chain.
#[derive(Clone, Debug)]
pub(crate) struct Clock {
    timeline: Timeline,
    /// Bus cycles per opcode.
    cost: [u64; Opcode::COUNT],
    /// Cycles from the entry of the instruction before to the entry of one of each
    /// opcode, ungated: `max(cost, hop)`.
    pace: [u64; Opcode::COUNT],
    last_entry: Option<u64>,
}

impl Clock {
    /// The clock of a trace that has not started.
    pub(crate) fn new(timeline: &Timeline) -> Clock {
        let cost = timeline.cost_table();
        Clock {
            timeline: timeline.clone(),
            cost,
            pace: cost.map(|c| c.max(timeline.hop)),
            last_entry: None,
        }
    }

    /// Cycle the last instruction so far entered the chain (`None` before the first).
    pub(crate) fn last_entry(&self) -> Option<u64> {
        self.last_entry
    }

    /// Issues scanline `line`'s instructions, counted in `tally`: all of them, ending
    /// with its `Refresh` if it has one (a scanline's `Refresh` is its last instruction;
    /// without one, they are the instructions after the trace's last `Refresh`). `None`
    /// for a tally without instructions.
    pub(crate) fn issue(&mut self, line: u64, tally: &IssueTally) -> Option<IssueTimes> {
        let first = tally.first?;
        let refresh = tally.opcodes.get(Opcode::Refresh);
        debug_assert!(refresh <= 1, "one Refresh per scanline");
        let before = self.last_entry;
        let plain = tally.opcodes.total() - refresh;
        let mut first_issue = None;
        let mut entry = before;
        // Once per scanline, not per instruction: saturating, since a run's cycles grow
        // without bound (crate::machine: they stop at u64::MAX rather than wrap).
        if plain > 0 {
            // the first instruction is not the Refresh, which comes last
            let mut counts = tally.opcodes.0;
            counts[Opcode::Refresh.index()] = 0;
            let paced = counts
                .iter()
                .zip(&self.pace)
                .fold(0u64, |sum, (n, p)| sum.saturating_add(n.saturating_mul(*p)));
            first_issue = Some(before.unwrap_or(0));
            entry = Some(match before {
                Some(b) => b.saturating_add(paced),
                // nothing before it to wait for: the trace's first enters after its cost
                // (pace ≥ cost, and paced includes the first's pace)
                None => paced - (self.pace[first.index()] - self.cost[first.index()]),
            });
        }
        if refresh > 0 {
            let begin = entry.unwrap_or(0).max(self.timeline.refresh_gate(line));
            let issued = begin.saturating_add(self.cost[Opcode::Refresh.index()]);
            first_issue.get_or_insert(begin);
            entry = Some(issued.max(entry.map_or(0, |e| e.saturating_add(self.timeline.hop))));
        }
        self.last_entry = entry;
        Some(IssueTimes {
            first_issue: first_issue.expect("an instruction issued"),
            entry_before: before.unwrap_or(0),
            last_entry: entry.expect("an instruction issued"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Machine;
    use crate::stats::{Recorder, RunStats};
    use cwisim_isa::TraceHeader;
    use proptest::prelude::*;

    /// One stream of opcodes (indices into [`Opcode::ALL`]) recorded both ways: each
    /// instruction timed by the issue model's rule, one at a time, and recorded as it
    /// issues ([`Recorder::issue`]); and each scanline tallied, timed by the [`Clock`] at
    /// its `Refresh` (and at the end) and recorded whole ([`Recorder::issued`]).
    fn both_ways(machine: &Machine, stream: &[usize]) -> (RunStats, RunStats) {
        let header = TraceHeader::new(16, 3, 1).unwrap();
        let timeline = machine.timeline(&header).unwrap();
        let (mut each, mut tallied) = (Recorder::new(&timeline), Recorder::new(&timeline));
        let mut clock = Clock::new(&timeline);
        let mut tally = IssueTally::default();
        let (mut line, mut last_entry) = (0u64, None::<u64>);
        for &k in stream {
            let op = Opcode::ALL[k];
            let gate = if op == Opcode::Refresh {
                timeline.refresh_gate(line)
            } else {
                0
            };
            let begin = last_entry.unwrap_or(0).max(gate);
            let cost = timeline.cost_table()[op.index()];
            let entry = (begin + cost).max(last_entry.map_or(0, |e| e + timeline.hop));
            each.issue(line, op, begin, entry, cost);
            tally.count(op);
            last_entry = Some(entry);
            if op == Opcode::Refresh {
                let t = std::mem::take(&mut tally);
                let times = clock.issue(line, &t).unwrap();
                assert_eq!(times.last_entry, entry);
                tallied.issued(line, &t, &times);
                let ready = timeline.exit(entry);
                each.ready(line, ready, timeline.deadline(line));
                tallied.ready(line, ready, timeline.deadline(line));
                line += 1;
            }
        }
        if let Some(times) = clock.issue(line, &tally) {
            tallied.issued(line, &tally, &times);
        }
        assert_eq!(clock.last_entry(), last_entry);
        let end = last_entry.map_or(0, |e| timeline.exit(e));
        (each.finish(line, end), tallied.finish(line, end))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// A scanline timed whole gives every record and total that timing its
        /// instructions one by one does: empty scanlines, Refresh gates that bind and
        /// ones that do not, costs below and above the hop, every opcode, instructions
        /// after the last `Refresh`.
        #[test]
        fn a_scanline_timed_whole_is_its_instructions_timed_one_by_one(
            stream in proptest::collection::vec(
                prop_oneof![3 => Just(12usize), 5 => 0usize..14],
                0..120,
            ),
            hop in 1u32..4,
            value_cycles in 0u32..3,
            refresh_cycles in 1u32..5,
            eval0_cycles in 1u32..6,
            period in 1u64..60,
        ) {
            let machine = Machine {
                hop_cycles: hop,
                value_cycles,
                opcode_cycles: [
                    (Opcode::Refresh, refresh_cycles),
                    (Opcode::Eval0, eval0_cycles),
                ]
                .into(),
                line_period_cycles: Some(period),
                ..Machine::default()
            };
            let (each, tallied) = both_ways(&machine, &stream);
            prop_assert_eq!(each, tallied);
        }
    }

    #[test]
    fn empty_scanlines_and_a_tail_after_the_last_refresh() {
        // Refresh, Refresh (two empty scanlines), Dis + Acc_mode + Refresh, then Eval1
        // and Nop never refreshed
        let stream = [12, 12, 10, 11, 12, 7, 13];
        let (each, tallied) = both_ways(&Machine::default(), &stream);
        assert_eq!(each, tallied);
        assert_eq!(tallied.lines.len(), 3);
        assert_eq!(tallied.totals.unrefreshed_instructions, 2);
        assert!(tallied.lines.iter().all(|l| l.instructions > 0));
        // the second scanline's Refresh waits for the display to take the first
        assert!(tallied.lines[1].stall_cycles > 0);
    }

    #[test]
    fn a_scanline_beyond_u64_saturates_instead_of_wrapping() {
        // 2^62 Eval3s at 13 × 2^16 cycles each: far beyond 2^64 cycles
        let header = TraceHeader::new(16, 3, 4).unwrap();
        let machine = Machine {
            opcode_cycles: [(Opcode::Eval3, 1 << 16)].into(),
            value_cycles: 1 << 16,
            ..Machine::default()
        };
        let timeline = machine.timeline(&header).unwrap();
        let mut clock = Clock::new(&timeline);
        let mut recorder = Recorder::new(&timeline);
        let mut tally = IssueTally::default();
        tally.count(Opcode::Eval3);
        tally.opcodes.0[Opcode::Eval3.index()] = 1 << 62;
        tally.count(Opcode::Refresh);
        let times = clock.issue(0, &tally).unwrap();
        assert_eq!((times.first_issue, times.last_entry), (0, u64::MAX));
        recorder.issued(0, &tally, &times);
        recorder.ready(0, timeline.exit(times.last_entry), timeline.deadline(0));
        // the next scanline starts where the clock stopped
        let mut next = IssueTally::default();
        next.count(Opcode::Nop);
        next.count(Opcode::Refresh);
        let times = clock.issue(1, &next).unwrap();
        assert_eq!((times.entry_before, times.last_entry), (u64::MAX, u64::MAX));
        recorder.issued(1, &next, &times);
        recorder.ready(1, timeline.exit(times.last_entry), timeline.deadline(1));
        let s = recorder.finish(2, u64::MAX);
        let l = &s.lines[0];
        assert_eq!(
            (l.busy_cycles, l.ready, l.slack),
            (u64::MAX, u64::MAX, i64::MIN)
        );
        assert_eq!((s.lines[1].busy_cycles, s.lines[1].stall_cycles), (2, 0));
        assert_eq!((s.totals.late_lines, s.totals.saturated_lines), (2, 2));
    }

    #[test]
    fn the_first_instruction_of_a_trace_enters_after_its_cost() {
        let header = TraceHeader::new(16, 3, 1).unwrap();
        let machine = Machine {
            hop_cycles: 3,
            ..Machine::default()
        };
        let timeline = machine.timeline(&header).unwrap();
        let mut clock = Clock::new(&timeline);
        let mut tally = IssueTally::default();
        tally.count(Opcode::Nop);
        tally.count(Opcode::Nop);
        let cost = timeline.cost_table()[Opcode::Nop.index()];
        let times = clock.issue(0, &tally).unwrap();
        // the first after its cost; the second a hop or its cost later
        assert_eq!(times.last_entry, cost + cost.max(3));
        assert_eq!((times.first_issue, times.entry_before), (0, 0));
        assert_eq!(clock.issue(0, &IssueTally::default()), None);
    }
}
