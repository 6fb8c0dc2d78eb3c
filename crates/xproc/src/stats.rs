//! Per-scanline and per-run statistics, recorded the same way by both engines.

use crate::clock::IssueTimes;
use cwisim_isa::Opcode;
use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

/// A counter per opcode; serializes as `{"SetI": n, …}` in opcode order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpcodeCounts(pub [u64; Opcode::COUNT]);

impl OpcodeCounts {
    /// The count for one opcode.
    pub fn get(&self, op: Opcode) -> u64 {
        self.0[op.index()]
    }
    /// All counts added up.
    pub fn total(&self) -> u64 {
        self.0.iter().sum()
    }
    fn add(&mut self, other: &OpcodeCounts) {
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a += b;
        }
    }
}

impl Serialize for OpcodeCounts {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(Opcode::COUNT))?;
        for op in Opcode::ALL {
            m.serialize_entry(op.name(), &self.get(*op))?;
        }
        m.end()
    }
}

/// What one scanline cost: the instructions from the previous `Refresh` (exclusive) to
/// its own `Refresh` (inclusive).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct LineStats {
    /// Scanline number over the whole trace.
    pub line: u64,
    /// Frame number.
    pub frame: u64,
    /// Row within the frame.
    pub row: u64,
    /// Instructions, by opcode.
    pub opcodes: OpcodeCounts,
    /// Instructions in all.
    pub instructions: u64,
    /// Processor-instruction pairs that Set/Eval/Dis addressed.
    pub processor_updates: u64,
    /// Channel contributions dropped because negative accumulation was off (`Acc_mode`).
    pub dropped_negative: u64,
    /// Processor contributions suppressed by an `Eval0` lock or a `Dis` mask.
    pub suppressed: u64,
    /// Overflow events of a narrow numeric format (`crate::numeric`), per channel:
    /// fixed-point wraps and saturations, `f32` results that are not finite, in operand
    /// conversions and adds. Always 0 for `f64`.
    pub overflows: u64,
    /// Bus cycles spent issuing this line's instructions.
    pub busy_cycles: u64,
    /// Cycles the bus waited: for the display to free the output registers (before a
    /// `Refresh`) or for the first processor to take the previous token.
    pub stall_cycles: u64,
    /// Cycle the line's first instruction started to issue.
    pub first_issue: u64,
    /// Cycle the `Refresh` token left the last processor: the scanline is complete.
    pub ready: u64,
    /// Cycle the display takes the scanline.
    pub deadline: u64,
    /// `deadline - ready`; negative is an overrun (a visible fault). Clamped to the
    /// range of `i64` (only a scanline whose cycles saturated can reach it:
    /// [`Totals::saturated_lines`]).
    pub slack: i64,
}

/// Totals of a run.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Totals {
    /// Instructions, by opcode (including any after the last `Refresh`).
    pub opcodes: OpcodeCounts,
    /// Instructions in all.
    pub instructions: u64,
    /// Scanlines output.
    pub lines: u64,
    /// Complete frames output.
    pub frames: u64,
    /// Scanlines of a last, incomplete frame.
    pub partial_frame_lines: u64,
    /// Scanlines not ready by their deadline.
    pub late_lines: u64,
    /// The smallest slack of any scanline (negative: the worst overrun).
    pub worst_slack: Option<i64>,
    /// The scanline with that slack.
    pub worst_line: Option<u64>,
    /// Processor updates in all.
    pub processor_updates: u64,
    /// Negative contributions dropped in all.
    pub dropped_negative: u64,
    /// Contributions suppressed by locks and masks in all.
    pub suppressed: u64,
    /// Overflow events in all (see [`LineStats::overflows`]).
    pub overflows: u64,
    /// Instructions after the last `Refresh`: executed but never output.
    pub unrefreshed_instructions: u64,
    /// Cycle the last token left the array (0 for an empty trace).
    pub cycles: u64,
    /// Scanlines output whose `ready` or `deadline` reached `u64::MAX`: cycle counts
    /// saturate there rather than wrap (`crate::machine`), so these scanlines' slack is
    /// only a bound, and if both reached it whether they were late is not known (they are
    /// not counted late). 0 unless a run outlasts 2⁶⁴ − 1 cycles.
    pub saturated_lines: u64,
}

/// Everything a run reports.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RunStats {
    /// Line period in cycles.
    pub line_period: u64,
    /// Cycles a token needs to cross the array.
    pub traversal_cycles: u64,
    /// Totals.
    pub totals: Totals,
    /// One record per scanline output.
    pub lines: Vec<LineStats>,
}

/// Where the per-scanline records of a run go ([`crate::Engine::line_records`]).
pub enum LineRecords {
    /// Into [`RunStats::lines`] (the default): memory grows with the trace.
    Keep,
    /// Nowhere: only the totals, memory flat however long the trace.
    Drop,
    /// To a function, one call per scanline output, in scanline order, as soon as the
    /// scanline is complete (a few scanlines late: [`Recorder::MARGIN`]); the records
    /// are those [`Self::Keep`] collects, and [`RunStats::lines`] stays empty. Memory
    /// stays flat.
    Send(Box<dyn FnMut(LineStats) + Send>),
}

impl std::fmt::Debug for LineRecords {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LineRecords::Keep => "Keep",
            LineRecords::Drop => "Drop",
            LineRecords::Send(_) => "Send(..)",
        })
    }
}

/// What instructions did in the processors (one instruction's, or a scanline's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Work {
    /// Processors addressed.
    pub(crate) updates: u64,
    /// Negative contributions dropped.
    pub(crate) dropped: u64,
    /// Contributions suppressed by locks and masks.
    pub(crate) suppressed: u64,
    /// Overflow events.
    pub(crate) overflows: u64,
}

/// The issue side of one scanline, tallied by an engine that issues in order (the fast
/// engine): per instruction only the opcode is counted, and the first one noted. The
/// scanline is timed whole from the tally ([`crate::clock::Clock::issue`]) and handed to
/// the recorder once, at its `Refresh` or at the end ([`Recorder::issued`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct IssueTally {
    /// Instructions, by opcode.
    pub(crate) opcodes: OpcodeCounts,
    /// The scanline's first instruction (`None`: it has none yet).
    pub(crate) first: Option<Opcode>,
}

impl IssueTally {
    /// Counts an instruction of opcode `op`.
    #[inline(always)]
    pub(crate) fn count(&mut self, op: Opcode) {
        if self.first.is_none() {
            self.first = Some(op);
        }
        self.opcodes.0[op.index()] += 1;
    }
}

/// Collects events from an engine into [`RunStats`]. Events name the scanline they
/// belong to, since in the cycle-stepped engine work on one scanline finishes while the
/// next one is already being issued.
///
/// Memory is bounded: a scanline's record is folded into the totals once the scanline is
/// complete (a margin of [`Recorder::MARGIN`] complete scanlines stays open), so only the
/// scanlines in flight are held — unless the per-scanline records are kept for
/// [`RunStats::lines`] ([`Recorder::line_records`]; [`LineRecords::Keep`] is the default).
pub(crate) struct Recorder {
    /// Open records, from scanline `base` on.
    open: std::collections::VecDeque<LineStats>,
    base: u64,
    /// Scanlines whose `ready` has been recorded (they complete in order).
    ready_lines: u64,
    records: LineRecords,
    kept: Vec<LineStats>,
    folded: Totals,
    lines_per_frame: u64,
    last_entry: u64,
    /// Bus cycles per opcode ([`crate::machine::Timeline::issue_cycles`]).
    cost: [u64; Opcode::COUNT],
    stats: RunStats,
}

impl Recorder {
    /// Complete scanlines kept open before they are folded into the totals.
    pub(crate) const MARGIN: u64 = 2;

    pub(crate) fn new(timeline: &crate::machine::Timeline) -> Self {
        Recorder {
            open: std::collections::VecDeque::new(),
            base: 0,
            ready_lines: 0,
            records: LineRecords::Keep,
            kept: Vec::new(),
            folded: Totals::default(),
            lines_per_frame: timeline.lines_per_frame,
            last_entry: 0,
            cost: timeline.cost_table(),
            stats: RunStats {
                line_period: timeline.line_period,
                traversal_cycles: timeline.traversal(),
                ..RunStats::default()
            },
        }
    }

    /// Instructions recorded so far (by [`Self::issue`] or [`Self::issued`]).
    pub(crate) fn instructions(&self) -> u64 {
        self.folded.instructions + self.open.iter().map(|l| l.instructions).sum::<u64>()
    }

    /// Where every scanline's record goes ([`LineRecords`]). Set before the first event.
    pub(crate) fn line_records(&mut self, to: LineRecords) {
        self.records = to;
    }

    /// A complete, output scanline's record, to where [`Self::line_records`] said.
    fn output(&mut self, l: LineStats) {
        match &mut self.records {
            LineRecords::Keep => self.kept.push(l),
            LineRecords::Drop => {}
            LineRecords::Send(f) => f(l),
        }
    }

    #[inline]
    fn line_mut(&mut self, line: u64) -> &mut LineStats {
        // the common case: the scanline being issued, the last one open
        if self.open.back().is_some_and(|l| l.line == line) {
            return self.open.back_mut().expect("just seen");
        }
        self.open_line(line)
    }

    #[cold]
    fn open_line(&mut self, line: u64) -> &mut LineStats {
        assert!(
            line >= self.base,
            "an event for scanline {line}, folded already (the margin is too small)"
        );
        let i = (line - self.base) as usize;
        while self.open.len() <= i {
            let n = self.base + self.open.len() as u64;
            self.open.push_back(LineStats {
                line: n,
                frame: n / self.lines_per_frame,
                row: n % self.lines_per_frame,
                ..LineStats::default()
            });
        }
        &mut self.open[i]
    }

    /// Adds a record to the totals; `refreshed`: the scanline was output.
    fn fold(t: &mut Totals, l: &LineStats, refreshed: bool) {
        t.opcodes.add(&l.opcodes);
        t.instructions += l.instructions;
        t.processor_updates += l.processor_updates;
        t.dropped_negative += l.dropped_negative;
        t.suppressed += l.suppressed;
        t.overflows += l.overflows;
        if refreshed {
            if l.slack < 0 {
                t.late_lines += 1;
            }
            if l.ready == u64::MAX || l.deadline == u64::MAX {
                t.saturated_lines += 1;
            }
            if t.worst_slack.is_none_or(|w| l.slack < w) {
                t.worst_slack = Some(l.slack);
                t.worst_line = Some(l.line);
            }
        } else {
            t.unrefreshed_instructions += l.instructions;
        }
    }

    /// Folds the complete scanlines beyond the margin.
    fn retire(&mut self) {
        while self.base + Self::MARGIN < self.ready_lines {
            let Some(l) = self.open.pop_front() else {
                break;
            };
            Self::fold(&mut self.folded, &l, true);
            self.output(l);
            self.base += 1;
        }
    }

    /// An instruction of scanline `line` started issuing at `begin` and entered the first
    /// processor at `entry` after `cost` bus cycles.
    ///
    /// The stepped engine calls this per instruction; it jumps over idle cycles, so its
    /// entries can reach `u64::MAX` (where they saturate): the sums saturate.
    #[inline]
    pub(crate) fn issue(&mut self, line: u64, op: Opcode, begin: u64, entry: u64, cost: u64) {
        // saturating, as [`Self::issued`]: past `u64::MAX` entries all saturate there
        let stall = (entry - self.last_entry).saturating_sub(cost);
        self.last_entry = entry;
        let l = self.line_mut(line);
        if l.instructions == 0 {
            l.first_issue = begin;
        }
        l.instructions += 1;
        l.opcodes.0[op.index()] += 1;
        l.busy_cycles = l.busy_cycles.saturating_add(cost);
        l.stall_cycles = l.stall_cycles.saturating_add(stall);
    }

    /// The instructions of scanline `line`, tallied by the engine ([`IssueTally`]) and
    /// timed whole ([`crate::clock::Clock::issue`]). The same record as one
    /// [`Self::issue`] per instruction: the busy cycles are each opcode's count times its
    /// cost, and the stall cycles — `entry − previous entry − cost` summed over the
    /// scanline — telescope to its last entry less the entry before its first, less the
    /// busy cycles.
    ///
    /// Once per scanline: saturating, as the cycles of [`crate::clock::Clock::issue`] are.
    pub(crate) fn issued(&mut self, line: u64, tally: &IssueTally, times: &IssueTimes) {
        let busy = tally
            .opcodes
            .0
            .iter()
            .zip(&self.cost)
            .fold(0u64, |sum, (n, c)| sum.saturating_add(n.saturating_mul(*c)));
        let l = self.line_mut(line);
        if l.instructions == 0 {
            l.first_issue = times.first_issue;
        }
        l.instructions += tally.opcodes.total();
        l.opcodes.add(&tally.opcodes);
        l.busy_cycles = l.busy_cycles.saturating_add(busy);
        let stall = (times.last_entry - times.entry_before).saturating_sub(busy);
        l.stall_cycles = l.stall_cycles.saturating_add(stall);
        self.last_entry = times.last_entry;
    }

    /// Work an instruction of scanline `line` did in the processors.
    pub(crate) fn work(&mut self, line: u64, w: Work) {
        let l = self.line_mut(line);
        l.processor_updates += w.updates;
        l.dropped_negative += w.dropped;
        l.suppressed += w.suppressed;
        l.overflows += w.overflows;
    }

    /// Scanline `line` is complete at `ready`; the display takes it at `deadline`.
    /// Scanlines complete in order.
    pub(crate) fn ready(&mut self, line: u64, ready: u64, deadline: u64) {
        let l = self.line_mut(line);
        l.ready = ready;
        l.deadline = deadline;
        // exact in i128, clamped to i64 (only a saturated scanline can be beyond it)
        l.slack = (i128::from(deadline) - i128::from(ready)).clamp(i64::MIN.into(), i64::MAX.into())
            as i64;
        self.ready_lines = self.ready_lines.max(line + 1);
        self.retire();
    }

    /// The totals, once every token has left the array at cycle `end`; `refreshed` is
    /// the number of scanlines output.
    pub(crate) fn finish(mut self, refreshed: u64, end: u64) -> RunStats {
        let mut t = std::mem::take(&mut self.folded);
        t.cycles = end;
        let open = std::mem::take(&mut self.open);
        for l in open {
            let output = l.line < refreshed;
            Self::fold(&mut t, &l, output);
            if output {
                self.output(l);
            }
        }
        t.lines = refreshed;
        t.frames = refreshed / self.lines_per_frame;
        t.partial_frame_lines = refreshed % self.lines_per_frame;
        self.stats.totals = t;
        self.stats.lines = self.kept;
        self.stats
    }
}
