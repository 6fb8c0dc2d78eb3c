//! The fast engine: executes each instruction over its whole range at once
//! ([`crate::processors`]) and computes the cycle of every event from the timing model's
//! closed form ([`crate::clock`]), one step per scanline, without stepping cycles.
//!
//! Cost follows the work in the trace: an instruction costs its range, a `Refresh` costs
//! the span of processors touched since the previous one, and an empty scanline costs
//! O(1). State is one scanline: registers and flags per processor, nothing per frame.
//!
//! Scanlines may also be executed ahead, in bands on other threads, and taken in here in
//! order ([`FastEngine::absorb`], [`crate::band`]): they are timed and recorded as if
//! their instructions had been executed here.

use crate::arith::{Arith, Native};
use crate::band::{Band, BandArray};
use crate::clock::Clock;
use crate::engine::Engine;
use crate::machine::Timeline;
use crate::output::{LineOut, LineSink};
use crate::processors::{LineEnd, Processors};
use crate::sample::Sample;
use crate::stats::{IssueTally, LineRecords, Recorder, RunStats, Work};
use crate::window::Handover;
use cwisim_isa::{Instruction, TraceHeader};

/// The fast engine (see the module documentation), with registers of arithmetic `A`.
pub struct FastEngine<A: Arith> {
    header: TraceHeader,
    processors: Processors<A>,
    scanlines: Scanlines,
    /// Bands were taken in: their preload registers never reached `processors`.
    absorbed: bool,
}

/// What becomes of each scanline the processors hand out: timed, recorded and output in
/// order.
struct Scanlines {
    timeline: Timeline,
    clock: Clock,
    recorder: Recorder,
    /// Scanlines output so far.
    line: u64,
}

impl Scanlines {
    /// Times and records scanline `self.line` (its instructions `tally`, their `work`),
    /// then hands its values to `sink`.
    fn output<T: Sample>(
        &mut self,
        tally: &IssueTally,
        work: Work,
        span: (usize, usize),
        values: &[T],
        sink: &mut dyn LineSink<T>,
    ) {
        let line = self.line;
        self.record_issue(tally, work);
        let entry = self
            .clock
            .last_entry()
            .expect("a scanline ends with its Refresh");
        let ready = self.timeline.exit(entry);
        self.recorder
            .ready(line, ready, self.timeline.deadline(line));
        sink.line(LineOut {
            index: line,
            span,
            values,
        });
        self.line += 1;
    }

    /// Times and records the current scanline's instructions (nothing if there are none,
    /// so that no record is opened for a scanline without instructions).
    fn record_issue(&mut self, tally: &IssueTally, work: Work) {
        let Some(times) = self.clock.issue(self.line, tally) else {
            return;
        };
        self.recorder.issued(self.line, tally, &times);
        if work != Work::default() {
            self.recorder.work(self.line, work);
        }
    }
}

impl<T: Sample> FastEngine<Native<T>> {
    /// An array of `T` registers for `header`'s width and channels, timed by `timeline`.
    pub fn new(header: &TraceHeader, timeline: Timeline) -> Self {
        FastEngine::with_arith(header, timeline, Native::new())
    }
}

impl<A: Arith> FastEngine<A> {
    /// An array with registers of arithmetic `arith`.
    pub fn with_arith(header: &TraceHeader, timeline: Timeline, arith: A) -> Self {
        FastEngine {
            header: *header,
            processors: Processors::new(header.width as usize, header.channel_count(), arith),
            scanlines: Scanlines {
                clock: Clock::new(&timeline),
                recorder: Recorder::new(&timeline),
                timeline,
                line: 0,
            },
            absorbed: false,
        }
    }

    /// The array's state for the cycle-stepped engine to go on from
    /// ([`crate::stepped::SteppedEngine::resume`]): taken between scanlines (before the
    /// first instruction, or right after a `Refresh`), it is exactly the state the
    /// stepped engine has there for every later instruction — its registers and flags,
    /// its clock, its counts and its statistics so far ([`Handover`]). `None` in the
    /// middle of a scanline, or after bands were taken in ([`Self::absorb`]: their
    /// preload registers are not here).
    pub fn handover(self) -> Option<Handover<A>> {
        if !self.processors.between_scanlines() || self.absorbed {
            return None;
        }
        let negative_enabled = self.processors.negative_enabled();
        let (arith, regs) = self.processors.into_registers();
        let s = self.scanlines;
        Some(Handover {
            header: self.header,
            instructions: s.recorder.instructions(),
            last_entry: s.clock.last_entry(),
            recorder: s.recorder,
            timeline: s.timeline,
            arith,
            regs,
            negative_enabled,
            lines: s.line,
        })
    }

    /// Takes in a band's scanlines, as if its instructions were executed here now: each
    /// timed, recorded and handed to `sink` in order. Refused (`false`, nothing taken)
    /// unless the array is between scanlines with negative accumulation as the band
    /// assumed at its start: then its instructions must be executed instead.
    pub fn absorb(&mut self, band: &Band<A::Out>, sink: &mut dyn LineSink<A::Out>) -> bool {
        if !self.processors.between_scanlines()
            || self.processors.negative_enabled() != band.negative_at_start()
        {
            return false;
        }
        for line in band.lines() {
            self.scanlines
                .output(line.tally, line.work, line.span, line.values, sink);
        }
        self.processors.set_negative_enabled(band.negative_at_end());
        self.absorbed = true;
        true
    }
}

impl<A: Arith> Engine<A::Out> for FastEngine<A> {
    fn line_records(&mut self, to: LineRecords) {
        self.scanlines.recorder.line_records(to);
    }

    fn execute(&mut self, instr: &Instruction, sink: &mut dyn LineSink<A::Out>) {
        let scanlines = &mut self.scanlines;
        self.processors
            .execute(instr, &mut |end: LineEnd<'_, A::Out>| {
                scanlines.output(&end.tally, end.work, end.span, end.values, sink)
            });
    }

    fn execute_all(&mut self, instrs: &[Instruction], sink: &mut dyn LineSink<A::Out>) {
        let scanlines = &mut self.scanlines;
        self.processors
            .run(instrs, &mut |end: LineEnd<'_, A::Out>| {
                scanlines.output(&end.tally, end.work, end.span, end.values, sink)
            });
    }

    fn band_array(&self) -> Option<BandArray<A::Out>> {
        Some(BandArray::new(&self.header, self.processors.fresh()))
    }

    fn absorb(&mut self, band: &Band<A::Out>, sink: &mut dyn LineSink<A::Out>) -> bool {
        FastEngine::absorb(self, band, sink)
    }

    fn finish(mut self: Box<Self>, _sink: &mut dyn LineSink<A::Out>) -> RunStats {
        let (tally, work) = self.processors.take_open_scanline();
        let mut s = self.scanlines;
        s.record_issue(&tally, work);
        let end = s.clock.last_entry().map_or(0, |e| s.timeline.exit(e));
        s.recorder.finish(s.line, end)
    }
}
