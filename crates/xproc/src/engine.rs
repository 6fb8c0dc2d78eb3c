//! The engine interface, the choice of timing model, and replaying a trace.

use crate::arith::{Arith, F32Arith, FixedArith, Native};
use crate::band::{Band, BandArray};
use crate::fast::FastEngine;
use crate::machine::{Machine, MachineError, Timeline};
use crate::numeric::{FixedFormat, Numeric};
use crate::output::{Image, ImageSink, LineSink};
use crate::probe::Probe;
use crate::sample::Sample;
use crate::stats::{LineRecords, RunStats};
use crate::stepped::SteppedEngine;
use crate::window::{self, StepFrom};
use cwisim_isa::{Instruction, TraceError, TraceHeader, TraceRead};

/// An X-processor array that executes instructions in order and shifts out scanlines.
pub trait Engine<T: Sample> {
    /// Issues one instruction (already checked against the trace header).
    fn execute(&mut self, instr: &Instruction, sink: &mut dyn LineSink<T>);
    /// Issues instructions in order (each already checked against the trace header): the
    /// same as one [`Self::execute`] each, in one call (an engine may decide per batch
    /// what it would otherwise decide per instruction).
    fn execute_all(&mut self, instrs: &[Instruction], sink: &mut dyn LineSink<T>) {
        for instr in instrs {
            self.execute(instr, sink);
        }
    }
    /// Processors of this array's size and arithmetic for executing bands of whole
    /// scanlines on another thread, to be taken in by [`Self::absorb`] (`crate::band`);
    /// `None` if this engine cannot take bands in (the cycle-stepped engine, which
    /// steps every instruction itself).
    fn band_array(&self) -> Option<BandArray<T>> {
        None
    }
    /// Takes in a band's scanlines as if its instructions were executed now: timed,
    /// recorded and handed to `sink` in order. `false`, nothing taken, if the band cannot
    /// be taken here (the engine is not between scanlines, or negative accumulation is
    /// not as the band assumed, or the engine takes no bands): execute its instructions
    /// instead.
    fn absorb(&mut self, band: &Band<T>, sink: &mut dyn LineSink<T>) -> bool {
        let _ = (band, sink);
        false
    }
    /// Drains the array and returns the statistics.
    fn finish(self: Box<Self>, sink: &mut dyn LineSink<T>) -> RunStats;
    /// Where every scanline's record goes: into [`RunStats::lines`] (the default),
    /// nowhere, or to a function as each scanline completes ([`LineRecords`]); the
    /// totals are the same. Call before the first instruction.
    fn line_records(&mut self, to: LineRecords);
    /// [`Self::line_records`]: [`LineRecords::Keep`] or [`LineRecords::Drop`], so that
    /// memory stays flat however long the trace.
    fn keep_line_stats(&mut self, keep: bool) {
        self.line_records(if keep {
            LineRecords::Keep
        } else {
            LineRecords::Drop
        });
    }
}

/// Which implementation of the timing model to run. Both give identical scanlines and
/// identical cycle counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Timing {
    /// Closed-form timing, work proportional to the instructions' ranges.
    #[default]
    Fast,
    /// Every processor advanced every cycle (the reference).
    Stepped,
}

/// An engine of the chosen kind for a trace.
pub fn engine<T: Sample>(
    header: &TraceHeader,
    machine: &Machine,
    timing: Timing,
) -> Result<Box<dyn Engine<T>>, MachineError> {
    let timeline = machine.timeline(header)?;
    Ok(boxed(header, timeline, timing, Native::<T>::new()))
}

fn boxed<A: Arith>(
    header: &TraceHeader,
    timeline: Timeline,
    timing: Timing,
    arith: A,
) -> Box<dyn Engine<A::Out>> {
    match timing {
        Timing::Fast => Box::new(FastEngine::with_arith(header, timeline, arith)),
        Timing::Stepped => Box::new(SteppedEngine::with_arith(header, timeline, arith)),
    }
}

/// An engine of the chosen kind whose registers have the format `numeric`; scanlines
/// come out as `f64` (the accumulators' values). [`Numeric::F64`] is exactly
/// [`engine::<f64>`](engine).
///
/// A fixed format outside the limits (possible when built from its public fields) is a
/// [`MachineError::Invalid`] of the parameter `numeric`: register formats are part of
/// the machine.
pub fn numeric_engine(
    header: &TraceHeader,
    machine: &Machine,
    timing: Timing,
    numeric: &Numeric,
) -> Result<Box<dyn Engine<f64>>, MachineError> {
    let timeline = machine.timeline(header)?;
    Ok(match numeric {
        Numeric::F64 => boxed(header, timeline, timing, Native::<f64>::new()),
        Numeric::F32 => boxed(header, timeline, timing, F32Arith),
        Numeric::Fixed(f) => boxed(header, timeline, timing, fixed_arith(f)?),
    })
}

/// Why a replay stopped.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The trace is malformed.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// The machine description is unusable.
    #[error(transparent)]
    Machine(#[from] MachineError),
}

/// Replays a trace from a reader into `sink`, calling `progress` with the bytes read every
/// few thousand instructions.
pub fn replay<T: Sample>(
    reader: &mut dyn TraceRead,
    machine: &Machine,
    timing: Timing,
    sink: &mut dyn LineSink<T>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let header = *reader.header();
    let eng = engine::<T>(&header, machine, timing)?;
    drive(reader, eng, sink, progress)
}

/// [`replay`] with registers of the format `numeric` (see [`numeric_engine`]); the sink
/// receives the accumulators' values as `f64`.
pub fn replay_numeric(
    reader: &mut dyn TraceRead,
    machine: &Machine,
    timing: Timing,
    numeric: &Numeric,
    sink: &mut dyn LineSink<f64>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    replay_streaming(
        reader,
        machine,
        timing,
        numeric,
        LineRecords::Keep,
        sink,
        progress,
    )
}

/// [`replay_numeric`], choosing where the per-scanline records go (`lines`;
/// [`Engine::line_records`]). Unless they are kept, the replay holds one scanline of
/// array state and the scanlines in flight, whatever the trace's length.
pub fn replay_streaming(
    reader: &mut dyn TraceRead,
    machine: &Machine,
    timing: Timing,
    numeric: &Numeric,
    lines: LineRecords,
    sink: &mut dyn LineSink<f64>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let header = *reader.header();
    let mut eng = numeric_engine(&header, machine, timing, numeric)?;
    eng.line_records(lines);
    drive(reader, eng, sink, progress)
}

fn drive<T: Sample>(
    reader: &mut dyn TraceRead,
    mut eng: Box<dyn Engine<T>>,
    sink: &mut dyn LineSink<T>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let mut n: u64 = 0;
    while let Some(instr) = reader.next_instruction()? {
        eng.execute(&instr, sink);
        n += 1;
        if n.is_multiple_of(4096) {
            progress(reader.bytes_read());
        }
    }
    progress(reader.bytes_read());
    Ok(eng.finish(sink))
}

/// Replays a trace on the cycle-stepped engine, reporting to `probe` as it steps, from
/// the start ([`replay_probed_from`] steps only the scanlines asked for).
pub fn replay_probed<T: Sample>(
    reader: &mut dyn TraceRead,
    machine: &Machine,
    probe: &mut dyn Probe,
    sink: &mut dyn LineSink<T>,
) -> Result<RunStats, ReplayError> {
    let header = *reader.header();
    let timeline = machine.timeline(&header)?;
    let mut eng = Box::new(SteppedEngine::<Native<T>>::with_probe(
        &header, timeline, probe,
    ));
    while let Some(instr) = reader.next_instruction()? {
        eng.execute(&instr, sink);
    }
    Ok(eng.finish(sink))
}

/// Replays a trace reporting to `probe` every event of the scanlines `from` asks for (and
/// later ones), as [`replay_probed`] reports them, without stepping the scanlines before:
/// the fast engine runs those and hands its state over to the cycle-stepped engine
/// ([`crate::window`]). The scanlines to `sink` and the statistics of the whole run are
/// those of [`replay_probed`], bit for bit; the probe is first told where the stepped
/// engine starts ([`Probe::resume`]). `progress` is called with the bytes read every few
/// thousand instructions, and at the end.
///
/// The replay stops at the end of `reader`: to step no further than the scanlines asked
/// for, end the reader after them.
pub fn replay_probed_from<T: Sample>(
    reader: &mut dyn TraceRead,
    machine: &Machine,
    from: StepFrom,
    probe: &mut dyn Probe,
    sink: &mut dyn LineSink<T>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let timeline = machine.timeline(reader.header())?;
    window::probed(
        reader,
        timeline,
        Native::<T>::new(),
        from,
        probe,
        sink,
        progress,
    )
}

/// [`replay_probed_from`] with registers of the format `numeric` (see
/// [`numeric_engine`]); the sink receives the accumulators' values as `f64`.
pub fn replay_probed_numeric(
    reader: &mut dyn TraceRead,
    machine: &Machine,
    numeric: &Numeric,
    from: StepFrom,
    probe: &mut dyn Probe,
    sink: &mut dyn LineSink<f64>,
    progress: &mut dyn FnMut(u64),
) -> Result<RunStats, ReplayError> {
    let t = machine.timeline(reader.header())?;
    match numeric {
        Numeric::F64 => {
            window::probed(reader, t, Native::<f64>::new(), from, probe, sink, progress)
        }
        Numeric::F32 => window::probed(reader, t, F32Arith, from, probe, sink, progress),
        Numeric::Fixed(f) => {
            let arith = fixed_arith(f)?;
            window::probed(reader, t, arith, from, probe, sink, progress)
        }
    }
}

/// The arithmetic of a fixed format; one outside the limits is a
/// [`MachineError::Invalid`] of the parameter `numeric`.
fn fixed_arith(f: &FixedFormat) -> Result<FixedArith, MachineError> {
    FixedArith::new(f).map_err(|e| MachineError::Invalid {
        name: "numeric".into(),
        message: e.message().to_string(),
    })
}

/// Runs instructions held in memory and collects the image (in `f64`).
///
/// # Panics
/// If an instruction does not fit `header` (use [`Instruction::check`] first) or the
/// image would exceed [`ImageSink::DEFAULT_LIMIT_BYTES`].
pub fn run<T: Sample>(
    header: &TraceHeader,
    instrs: &[Instruction],
    machine: &Machine,
    timing: Timing,
) -> Result<(Image, RunStats), MachineError> {
    collect(header, instrs, engine::<T>(header, machine, timing)?)
}

/// [`run`] with registers of the format `numeric` (see [`numeric_engine`]).
///
/// # Panics
/// As [`run`].
pub fn run_numeric(
    header: &TraceHeader,
    instrs: &[Instruction],
    machine: &Machine,
    timing: Timing,
    numeric: &Numeric,
) -> Result<(Image, RunStats), MachineError> {
    collect(
        header,
        instrs,
        numeric_engine(header, machine, timing, numeric)?,
    )
}

fn collect<T: Sample>(
    header: &TraceHeader,
    instrs: &[Instruction],
    mut eng: Box<dyn Engine<T>>,
) -> Result<(Image, RunStats), MachineError> {
    let mut sink = ImageSink::new(
        header.width as usize,
        header.channel_count(),
        ImageSink::DEFAULT_LIMIT_BYTES,
    );
    for i in instrs {
        debug_assert!(i.check(header).is_ok(), "{i} does not fit the header");
        eng.execute(i, &mut sink);
    }
    let stats = eng.finish(&mut sink);
    Ok((
        sink.finish().expect("image within the default limit"),
        stats,
    ))
}
