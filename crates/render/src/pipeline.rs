//! The pipeline: a renderer's frames, emitted in bands of rows (on threads when asked)
//! and run through the simulated X-processor array, with the wall time of each side
//! measured.
//!
//! On one thread, each band of rows is emitted straight into processors of the array's
//! ([`BandArray`]: no instruction is copied into a batch) and its scanlines are then
//! taken in by the array, in order. With `threads > 1`, `threads − 1` workers each take
//! the next band of rows of the frame and emit it; the calling thread takes the finished
//! bands in, in band order, and while the band it wants is not ready it emits the next
//! untaken band itself (so with two threads both cores emit). Each thread also executes
//! the bands it emits, on processors of its own (`cwisim_xproc::band`): the calling
//! thread only times, records and outputs their scanlines, in order. A tap that wants
//! every instruction, or an array that takes no bands (the cycle-stepped engine), gets
//! the instructions instead ([`PackedStream`] on threads), fed to the array on the
//! calling thread in batches of whole scanlines (checked once, then executed in one
//! call). Either way the array's output, statistics and cycles are those of the serial
//! stream: byte-identical at any thread count.

use crate::error::{NonFinite, RenderError};
use crate::renderer::{Counters, FramePlan, Renderer};
use cwisim_isa::{
    CheckedStream, Instruction, Opcode, OperandError, PackedStream, TraceHeader, TraceWrite,
};
use cwisim_xproc::{
    Band, BandArray, EngineWriter, Image, LineOut, LineSink, Machine, Numeric, RunStats, Timing,
};
use std::cell::RefCell;
use std::io;
use std::rc::Rc;
use std::time::{Duration, Instant};

/// The simulated array: its machine model, register format and timing engine.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ArrayConfig {
    /// The machine model (timing parameters).
    pub machine: Machine,
    /// The registers' numeric format.
    pub numeric: Numeric,
    /// The timing engine (fast, or cycle-stepped).
    pub timing: Timing,
}

/// What watches the stream besides the array.
#[derive(Default)]
pub struct Taps<'a> {
    /// Gets every instruction as the array does: a cost map, a counter. Comments reach it
    /// only on one thread (bands emitted on threads keep none); a trace file with the
    /// renderer's comments is written by [`emit`].
    pub also: Option<&'a mut dyn TraceWrite>,
    /// Told the number of scanlines done after each one.
    pub progress: Option<&'a mut dyn FnMut(u64)>,
    /// Asked after each scanline the array outputs: `true` stops the render, which then
    /// fails with [`RenderError::Cancelled`] (how the Python package honours Ctrl-C).
    pub cancel: Option<&'a dyn Fn() -> bool>,
}

/// What a render gives besides the scanlines.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The renderer's counters, summed over bands and frames.
    pub counters: Counters,
    /// The array's statistics.
    pub stats: RunStats,
    /// Wall time in the renderer (emitting instructions): the wall time the array did
    /// not take on the calling thread. With [`Self::array_in_bands`], it includes the
    /// array's execution of the bands, interleaved with their emission.
    pub renderer_time: Duration,
    /// Wall time in the array simulator on the calling thread.
    pub array_time: Duration,
    /// The scanlines were executed in bands, each on the thread that emitted it (the
    /// calling thread too, on one thread), interleaved with their emission: the array's
    /// time is only that of taking them in (timing, recording and output in order).
    pub array_in_bands: bool,
    /// The renderer's figures per pixel row, one entry per frame
    /// ([`FramePlan::row_figures`]; `Null` for a frame without them).
    pub row_figures: Vec<serde_json::Value>,
}

/// Bands per thread: enough that uneven bands balance out.
const BANDS_PER_THREAD: u32 = 8;

/// Refuses, before the first scanline, a renderer whose frames would hold more than the
/// memory budget while they are emitted ([`Renderer::frame_memory`]).
pub fn check_frame_memory(renderer: &dyn Renderer, threads: usize) -> Result<(), RenderError> {
    let bytes = renderer.frame_memory(threads);
    cwisim_scene::budget::Budget::current()
        .check_memory(&frame_memory_phrase(renderer, threads), bytes)
        .map_err(|e| RenderError::Usage(e.to_string()))
}

/// What [`Renderer::frame_memory`] is for, in a refusal.
pub fn frame_memory_phrase(renderer: &dyn Renderer, threads: usize) -> String {
    let h = renderer.header();
    format!(
        "{}'s rows of {} pixels on {threads} thread(s) ({})",
        renderer.name(),
        h.width,
        renderer.settings_phrase()
    )
}

/// Renders every frame of `renderer` into the array `array`, handing its scanlines to
/// `lines`, on `threads` threads (0: as many as the machine has; 1: serially, in bands
/// of rows in stream order).
pub fn render(
    renderer: &dyn Renderer,
    array: &ArrayConfig,
    threads: usize,
    lines: &mut dyn LineSink<f64>,
    taps: Taps<'_>,
) -> Result<Rendered, RenderError> {
    let threads = cwisim_scene::budget::resolve_threads(threads);
    renderer
        .check_numeric(&array.numeric)
        .map_err(RenderError::Usage)?;
    check_frame_memory(renderer, threads)?;
    let header = renderer.header();
    let keep = renderer.needs_previous_frame() && renderer.frames() > 1;
    let frame_image = keep.then(|| Rc::new(RefCell::new(empty_image(&header))));
    let mut keeper;
    let sink: &mut dyn LineSink<f64> = match &frame_image {
        Some(frame) => {
            keeper = FrameKeeper {
                inner: lines,
                frame: Rc::clone(frame),
            };
            &mut keeper
        }
        None => lines,
    };
    let rows = Rows {
        renderer: renderer.name(),
        per_frame: header.lines,
        frames: renderer.frames(),
    };
    let mut feed = ScanlineFeed::open(&header, array, sink, taps, rows)?;
    let start = Instant::now();
    let mut counters = Counters::default();
    let mut previous: Option<Image> = None;
    let mut row_figures = Vec::new();
    for index in 0..renderer.frames() {
        let plan = renderer.frame(index, previous.as_ref())?;
        let fault = |source| RenderError::of_renderer(renderer.name(), source);
        let band = if threads > 1 {
            feed_parallel(&*plan, header.lines, threads, &mut feed, fault)?
        } else {
            feed_serial_bands(&*plan, header.lines, &mut feed, fault)?
        };
        // the frame's own counters and figures once its rows are emitted (a renderer may
        // make them as they are), first, as the frame's
        let mut frame = plan.counters();
        frame.merge(&band);
        counters.merge(&frame);
        row_figures.push(plan.row_figures().unwrap_or(serde_json::Value::Null));
        // the frame's last scanlines reach the array (and the kept frame) before the
        // next frame is planned
        if let Err(e) = feed.flush() {
            return Err(feed.array_fault(e));
        }
        drop(plan);
        if let Some(frame) = &frame_image {
            previous = Some(frame.replace(empty_image(&header)));
        }
    }
    feed.close(counters, row_figures, start.elapsed())
}

/// Emits the whole stream of `renderer`, every frame, into `sink` (a trace file, a
/// collector), serially; its counters. Frames that need the previous frame's output
/// cannot be emitted without the array: they are refused. A value that is not finite is
/// refused before it reaches `sink` ([`RenderError::Overflow`]), as the array would.
pub fn emit(renderer: &dyn Renderer, sink: &mut dyn TraceWrite) -> Result<Counters, RenderError> {
    if renderer.needs_previous_frame() && renderer.frames() > 1 {
        return Err(RenderError::Usage(format!(
            "the renderer `{}` draws each frame from the previous frame's output, so its stream exists only while it runs through the array (`cwisim render`); it cannot be emitted alone",
            renderer.name()
        )));
    }
    let header = renderer.header();
    let fault = |source| RenderError::Renderer {
        renderer: renderer.name(),
        source,
    };
    let mut guard = Finite {
        inner: sink,
        header,
        rows: Rows {
            renderer: renderer.name(),
            per_frame: header.lines,
            frames: renderer.frames(),
        },
        line: 0,
        overflow: None,
    };
    let mut counters = Counters::default();
    for index in 0..renderer.frames() {
        let plan = renderer.frame(index, None)?;
        let emitted = plan.emit_rows(0..header.lines, &mut guard);
        let emitted = emitted.map_err(|e| guard.fault(e, &fault))?;
        let mut frame = plan.counters();
        frame.merge(&emitted);
        counters.merge(&frame);
    }
    guard.inner.finish().map_err(fault)?;
    Ok(counters)
}

/// Whose rows a stream carries: what locates a value that is not finite.
#[derive(Clone, Copy, Debug)]
struct Rows {
    renderer: &'static str,
    per_frame: u32,
    frames: u32,
}

impl Rows {
    /// The refusal of `source`, made while the stream's `line`-th scanline (from 0, over
    /// every frame) was.
    fn overflow(&self, line: u64, mut source: NonFinite) -> RenderError {
        let per_frame = u64::from(self.per_frame.max(1));
        source.row = source.row.or(Some((line % per_frame) as u32));
        RenderError::Overflow {
            renderer: self.renderer,
            frame: (self.frames > 1).then_some((line / per_frame) as u32),
            source,
        }
    }
}

/// Passes a stream on to `inner`, refusing an instruction whose values are not finite
/// (`emit`'s sink is a trace, which must not hold one) and counting the scanlines, so that
/// the refusal names its row.
struct Finite<'a> {
    inner: &'a mut dyn TraceWrite,
    header: TraceHeader,
    rows: Rows,
    line: u64,
    overflow: Option<RenderError>,
}

impl Finite<'_> {
    /// What an emission's error is: a value that is not finite (refused here, or found by
    /// the renderer where it made it), or the renderer's fault.
    fn fault(&mut self, e: io::Error, fault: &dyn Fn(io::Error) -> RenderError) -> RenderError {
        if let Some(o) = self.overflow.take() {
            return o;
        }
        match NonFinite::carried_by(&e) {
            Some(nf) => self.rows.overflow(self.line, nf.clone()),
            None => fault(e),
        }
    }
}

impl TraceWrite for Finite<'_> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        if instr.op == Opcode::Refresh {
            self.line += 1;
        } else if let Err(OperandError::NonFinite(m)) = instr.check(&self.header) {
            let nf = NonFinite::in_instruction(instr).unwrap_or(NonFinite {
                row: None,
                stage: "emitted instruction",
                detail: m,
            });
            self.overflow = Some(self.rows.overflow(self.line, nf.clone()));
            return Err(nf.into_io());
        }
        self.inner.write(instr)
    }

    fn comment(&mut self, text: &str) -> io::Result<()> {
        self.inner.comment(text)
    }

    fn wants_comments(&self) -> bool {
        self.inner.wants_comments()
    }

    fn finish(&mut self) -> io::Result<()> {
        self.inner.finish()
    }
}

fn empty_image(header: &TraceHeader) -> Image {
    Image {
        width: header.width as usize,
        channels: header.channel_count(),
        lines: 0,
        data: Vec::new(),
    }
}

/// Passes scanlines on, and keeps the current frame's as an [`Image`] for the next frame.
struct FrameKeeper<'s> {
    inner: &'s mut dyn LineSink<f64>,
    frame: Rc<RefCell<Image>>,
}

impl LineSink<f64> for FrameKeeper<'_> {
    fn line(&mut self, line: LineOut<'_, f64>) {
        {
            let mut image = self.frame.borrow_mut();
            let (width, channels) = (image.width, image.channels);
            let start = image.data.len();
            image.data.resize(start + width * channels, 0.0);
            let row = &mut image.data[start..];
            row[line.span.0 * channels..line.span.1 * channels].copy_from_slice(line.values);
            image.lines += 1;
        }
        self.inner.line(line);
    }
}

/// The array, fed a batch of whole scanlines at a time: instructions are buffered up to
/// the first `Refresh` past [`ScanlineFeed::BATCH`] instructions, then checked in one
/// pass ([`CheckedStream::from_vec`]: once, not again by the array) and executed in one
/// call — so that the array's state, the image rows and the renderer's each stay in
/// cache for a while rather than alternating every scanline, and the array's share of
/// the wall time (its check included) is measured per batch rather than per instruction.
/// Every instruction also goes to the taps as it comes; the progress tap hears of each
/// scanline once the array has output it.
struct ScanlineFeed<'a, 's> {
    array: EngineWriter<'s, f64>,
    header: TraceHeader,
    taps: Taps<'a>,
    buffer: Vec<Instruction>,
    /// Scanlines ended (`Refresh`) in the buffer.
    buffered_lines: u64,
    array_time: Duration,
    /// Some band was executed on the thread that emitted it.
    bands_taken: bool,
    lines: u64,
    /// The array's (or a tap's) own failure, told apart from the renderer's.
    fault: Option<io::Error>,
    /// Whose rows these are.
    rows: Rows,
    /// An instruction refused for a value that is not finite: bad input, not a fault.
    overflow: Option<RenderError>,
    /// The cancel tap said stop.
    cancelled: bool,
}

impl<'a, 's> ScanlineFeed<'a, 's> {
    /// Instructions buffered before the array runs them (at the next `Refresh`): about
    /// 200 KB, a few dozen scanlines of a busy frame.
    const BATCH: usize = 4096;

    fn open(
        header: &TraceHeader,
        array: &ArrayConfig,
        sink: &'s mut dyn LineSink<f64>,
        taps: Taps<'a>,
        rows: Rows,
    ) -> Result<Self, RenderError> {
        Ok(ScanlineFeed {
            array: EngineWriter::with_numeric(
                header,
                &array.machine,
                array.timing,
                &array.numeric,
                sink,
            )?,
            header: *header,
            taps,
            buffer: Vec::new(),
            buffered_lines: 0,
            array_time: Duration::ZERO,
            bands_taken: false,
            lines: 0,
            fault: None,
            rows,
            overflow: None,
            cancelled: false,
        })
    }

    /// Finishes the array and the taps; `total` is the wall time since emission began
    /// (the renderer's share is what the array did not take: the two interleave, or
    /// overlap on threads).
    fn close(
        mut self,
        counters: Counters,
        row_figures: Vec<serde_json::Value>,
        total: Duration,
    ) -> Result<Rendered, RenderError> {
        if let Err(e) = self.finish() {
            return Err(self.array_fault(e));
        }
        let array_time = self.array_time;
        let stats = self.array.into_stats().expect("finished");
        Ok(Rendered {
            counters,
            stats,
            renderer_time: total.saturating_sub(array_time),
            array_time,
            array_in_bands: self.bands_taken,
            row_figures,
        })
    }

    /// Checks the buffered instructions and runs them through the array, then tells the
    /// progress tap of each scanline they completed.
    fn flush(&mut self) -> io::Result<()> {
        let start = Instant::now();
        let r = self.run_buffer();
        self.array_time += start.elapsed();
        r?;
        for _ in 0..std::mem::take(&mut self.buffered_lines) {
            self.line_done()?;
        }
        Ok(())
    }

    /// One more scanline output: the progress tap told, the cancel tap asked.
    fn line_done(&mut self) -> io::Result<()> {
        self.lines += 1;
        if let Some(p) = self.taps.progress.as_deref_mut() {
            p(self.lines);
        }
        if self.taps.cancel.is_some_and(|stop| stop()) {
            self.cancelled = true;
            return Err(io::Error::new(io::ErrorKind::Interrupted, "cancelled"));
        }
        Ok(())
    }

    /// The buffer checked (an instruction that does not fit is refused as
    /// [`EngineWriter`]'s `write` refuses it, and nothing of the batch runs) and run
    /// through the array; the buffer emptied for reuse.
    fn run_buffer(&mut self) -> io::Result<()> {
        let raw = std::mem::take(&mut self.buffer);
        let stream = CheckedStream::from_vec(&self.header, raw).map_err(|u| {
            if let OperandError::NonFinite(m) = &u.error {
                let instr = &u.instructions[u.index];
                let before = &u.instructions[..u.index];
                let line =
                    self.lines + before.iter().filter(|i| i.op == Opcode::Refresh).count() as u64;
                let nf = NonFinite::in_instruction(instr).unwrap_or(NonFinite {
                    row: None,
                    stage: "emitted instruction",
                    detail: m.clone(),
                });
                self.overflow = Some(self.rows.overflow(line, nf));
            }
            u.refusal()
        })?;
        let r = self.array.write_checked(&stream);
        self.buffer = stream.into_vec();
        self.buffer.clear();
        r
    }

    /// Processors for `threads` threads to execute bands of whole scanlines on
    /// ([`EngineWriter::band_array`]); `None` if the array takes no bands, or a tap
    /// wants every instruction.
    fn band_arrays(&self, threads: usize) -> Option<Vec<BandArray<f64>>> {
        if self.taps.also.is_some() {
            return None;
        }
        (0..threads).map(|_| self.array.band_array()).collect()
    }

    /// Takes in a band executed on another thread, after whatever is buffered; `false`
    /// if the array cannot take it (nothing taken: emit it again, into this feed).
    fn take_in(&mut self, band: &Band<f64>) -> io::Result<bool> {
        self.flush()?;
        let start = Instant::now();
        let taken = self.array.absorb(band);
        self.array_time += start.elapsed();
        if !taken? {
            return Ok(false);
        }
        self.bands_taken = true;
        for _ in 0..band.scanlines() {
            self.line_done()?;
        }
        Ok(true)
    }

    /// The scanline being made: every `Refresh` the feed has had.
    fn line_now(&self) -> u64 {
        self.lines + self.buffered_lines
    }

    /// What an error of the array's (or a tap's) is: the refusal of a value that is not
    /// finite (bad input), or the array's own fault.
    fn array_fault(&mut self, e: io::Error) -> RenderError {
        if self.cancelled {
            return RenderError::Cancelled { lines: self.lines };
        }
        match self.overflow.take() {
            Some(o) => {
                self.fault = None;
                o
            }
            None => RenderError::Array(e),
        }
    }

    /// What an error of the renderer's emission into the feed is: a value that is not
    /// finite (refused by the array, or found by the renderer where it made it), the
    /// array's or a tap's own fault, or else the renderer's (`fault`).
    fn renderer_fault(
        &mut self,
        e: io::Error,
        fault: &dyn Fn(io::Error) -> RenderError,
    ) -> RenderError {
        if self.cancelled {
            return RenderError::Cancelled { lines: self.lines };
        }
        if let Some(o) = self.overflow.take() {
            self.fault = None;
            return o;
        }
        if let Some(nf) = NonFinite::carried_by(&e) {
            return self.rows.overflow(self.line_now(), nf.clone());
        }
        match self.fault.take() {
            Some(own) => RenderError::Array(own),
            None => fault(e),
        }
    }

    /// Notes an error of the array's or a tap's own, so that it is not blamed on the
    /// renderer.
    fn own(&mut self, r: io::Result<()>) -> io::Result<()> {
        r.map_err(|e| {
            let again = io::Error::new(e.kind(), e.to_string());
            self.fault = Some(e);
            again
        })
    }
}

impl TraceWrite for ScanlineFeed<'_, '_> {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        if let Some(also) = self.taps.also.as_deref_mut() {
            // a tap (a trace, a cost map) gets no value the array would refuse as not
            // finite: that is the input's doing, refused here first
            if let Err(OperandError::NonFinite(m)) = instr.check(&self.header) {
                let nf = NonFinite::in_instruction(instr).unwrap_or(NonFinite {
                    row: None,
                    stage: "emitted instruction",
                    detail: m,
                });
                self.overflow = Some(self.rows.overflow(self.line_now(), nf.clone()));
                return Err(nf.into_io());
            }
            let r = also.write(instr);
            self.own(r)?;
        }
        self.buffer.push(instr.clone());
        if instr.op == Opcode::Refresh {
            self.buffered_lines += 1;
            if self.buffer.len() >= Self::BATCH {
                let r = self.flush();
                self.own(r)?;
            }
        }
        Ok(())
    }

    fn comment(&mut self, text: &str) -> io::Result<()> {
        match self.taps.also.as_deref_mut() {
            Some(also) => {
                let r = also.comment(text);
                self.own(r)
            }
            None => Ok(()),
        }
    }

    fn wants_comments(&self) -> bool {
        self.taps
            .also
            .as_deref()
            .is_some_and(|a| a.wants_comments())
    }

    fn finish(&mut self) -> io::Result<()> {
        self.flush()?;
        let start = Instant::now();
        self.array.finish()?;
        self.array_time += start.elapsed();
        if let Some(also) = self.taps.also.as_deref_mut() {
            also.finish()?;
        }
        Ok(())
    }
}

/// Rows per band when one thread emits and executes them ([`feed_serial_bands`]). Measured
/// on the pot at 1024² (docs/PERFORMANCE.md): 8 to 64 rows are alike, 4 rows and one band
/// for the whole frame slower; 16 rows of 1024 RGB pixels are 384 KB of values.
const SERIAL_BAND_ROWS: u32 = 16;

/// One frame on one thread, in bands: each band of rows is emitted straight into the
/// array's processors ([`BandArray`]: each instruction checked and executed as it comes,
/// never copied into a batch) and its scanlines are then taken in, in order
/// ([`EngineWriter::absorb`]). Each band starts with negative accumulation as the one
/// before left it ([`BandArray::start_after`]), so the engine takes every band in. When
/// the array takes no bands or a tap wants every instruction, the rows go through the
/// feed instead, as does a band the array refuses or that failed.
fn feed_serial_bands(
    plan: &dyn FramePlan,
    rows: u32,
    feed: &mut ScanlineFeed<'_, '_>,
    fault: impl Fn(io::Error) -> RenderError,
) -> Result<Counters, RenderError> {
    let Some(mut array) = feed.band_arrays(1).and_then(|mut a| a.pop()) else {
        return emit_into_feed(plan, 0..rows, feed, &fault);
    };
    let (mut previous, mut spare) = (Band::default(), Band::default());
    let mut counters = Counters::default();
    let mut first = 0;
    while first < rows {
        let band_rows = first..first.saturating_add(SERIAL_BAND_ROWS).min(rows);
        first = band_rows.end;
        array.start_after(std::mem::take(&mut spare), &previous);
        let executed = plan
            .emit_rows(band_rows.clone(), &mut array)
            .and_then(|c| Ok((array.take().map_err(io::Error::other)?, c)));
        let taken = match executed {
            Ok((band, band_counters)) => {
                let taken = match feed.take_in(&band) {
                    Ok(t) => t,
                    Err(e) => return Err(feed.array_fault(e)),
                };
                spare = std::mem::replace(&mut previous, band);
                taken.then_some(band_counters)
            }
            Err(_) => None,
        };
        counters.merge(&match taken {
            Some(c) => c,
            None => {
                // whatever the stream did with negative accumulation, the next band
                // assumes it off (if wrong, it too is refused and emitted again here)
                previous.clear();
                emit_into_feed(plan, band_rows, feed, &fault)?
            }
        });
    }
    Ok(counters)
}

/// Rows emitted into the feed (the array, batched, and every tap); an error of the
/// array's or a tap's own is told apart from the renderer's.
fn emit_into_feed(
    plan: &dyn FramePlan,
    rows: std::ops::Range<u32>,
    feed: &mut ScanlineFeed<'_, '_>,
    fault: &dyn Fn(io::Error) -> RenderError,
) -> Result<Counters, RenderError> {
    plan.emit_rows(rows, feed)
        .map_err(|e| feed.renderer_fault(e, fault))
}

/// A band of rows as a thread emitted it: either its instructions, for the feeding thread
/// to feed to the array; or, when the array takes bands ([`EngineWriter::band_array`])
/// and no tap needs the instructions, its scanlines executed on the emitting thread's own
/// processors as it emitted them.
enum Emitted {
    Instructions(PackedStream),
    Executed(Band<f64>),
}

/// One frame in bands: `threads − 1` workers emit bands of rows (taking the next band as
/// they finish one) while this thread feeds the finished bands to the array in order,
/// emitting the next untaken band itself whenever the band it wants is not there yet.
///
/// When the array takes bands and no tap wants the instructions, each thread also
/// executes the bands it emits, on processors of its own, and this thread takes their
/// scanlines in, in order ([`EngineWriter::absorb`]); a band the array cannot take (or
/// one that failed) is emitted again here, into the array, as one thread would.
fn feed_parallel(
    plan: &dyn FramePlan,
    rows: u32,
    threads: usize,
    feed: &mut ScanlineFeed<'_, '_>,
    fault: impl Fn(io::Error) -> RenderError,
) -> Result<Counters, RenderError> {
    use std::collections::BTreeMap;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::{mpsc, Mutex};
    let n = (threads as u32 * BANDS_PER_THREAD).clamp(1, rows.max(1));
    let band_rows = |k: u32| {
        let a = (u64::from(rows) * u64::from(k) / u64::from(n)) as u32;
        let b = (u64::from(rows) * u64::from(k + 1) / u64::from(n)) as u32;
        a..b
    };
    let next_band = AtomicUsize::new(0);
    // processors for every thread that emits, if the bands are executed where emitted
    let band_arrays: Option<Mutex<Vec<BandArray<f64>>>> = feed.band_arrays(threads).map(Mutex::new);
    // buffers the feeder has emptied, for the workers to reuse: a fresh buffer per band
    // would be mapped and faulted in page by page (most bands are over the allocator's
    // mmap threshold), which costs more than the work overlapped
    let spare: Mutex<Vec<PackedStream>> = Mutex::new(Vec::new());
    let spare_bands: Mutex<Vec<Band<f64>>> = Mutex::new(Vec::new());
    // band `k` emitted (and executed, if so) into reused buffers, by whichever thread
    // takes it
    let emit_band = |k: usize| -> io::Result<(Emitted, Counters)> {
        let rows = band_rows(k as u32);
        if let Some(arrays) = &band_arrays {
            let mut array = arrays
                .lock()
                .ok()
                .and_then(|mut a| a.pop())
                .expect("processors for every thread");
            let reused = spare_bands.lock().ok().and_then(|mut s| s.pop());
            array.start(reused.unwrap_or_default());
            let done = plan.emit_rows(rows, &mut array).and_then(|counters| {
                let band = array.take().map_err(io::Error::other)?;
                Ok((Emitted::Executed(band), counters))
            });
            if let Ok(mut a) = arrays.lock() {
                a.push(array);
            }
            return done;
        }
        let reused = spare.lock().ok().and_then(|mut s| s.pop());
        let mut band = reused.unwrap_or_default();
        band.clear();
        let counters = plan.emit_rows(rows, &mut band)?;
        Ok((Emitted::Instructions(band), counters))
    };
    // this thread feeds the array: it counts as one of the `threads`
    let workers = threads.saturating_sub(1).max(1);
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel::<(usize, io::Result<(Emitted, Counters)>)>();
        for _ in 0..workers {
            let tx = tx.clone();
            let (next_band, emit_band) = (&next_band, &emit_band);
            scope.spawn(move || loop {
                let k = next_band.fetch_add(1, Ordering::Relaxed);
                if k >= n as usize {
                    break;
                }
                if tx.send((k, emit_band(k))).is_err() {
                    break; // the feeder stopped on an error
                }
            });
        }
        drop(tx);
        // feed the bands in order as they arrive; with nothing to feed, emit the next
        // band here rather than wait (the array is idle most of a frame: this thread
        // would otherwise leave its core to the workers' one band at a time)
        let mut counters = Counters::default();
        let mut waiting = BTreeMap::new();
        let mut want = 0usize;
        let mut open = true;
        while want < n as usize {
            while let Ok((k, band)) = rx.try_recv() {
                waiting.insert(k, band);
            }
            if let Some(band) = waiting.remove(&want) {
                let emitted = match band {
                    Ok((Emitted::Instructions(instructions), band_counters)) => {
                        for instr in instructions.iter() {
                            if let Err(e) = feed.write(&instr) {
                                return Err(feed.array_fault(e));
                            }
                        }
                        if let Ok(mut s) = spare.lock() {
                            s.push(instructions);
                        }
                        Ok(band_counters)
                    }
                    Ok((Emitted::Executed(band), band_counters)) => {
                        let taken = match feed.take_in(&band) {
                            Ok(t) => t,
                            Err(e) => return Err(feed.array_fault(e)),
                        };
                        if let Ok(mut s) = spare_bands.lock() {
                            s.push(band);
                        }
                        if taken {
                            Ok(band_counters)
                        } else {
                            Err(())
                        }
                    }
                    // failed on its thread: emitted again here, into the feed, which
                    // tells a value that is not finite (and its row) from a fault
                    Err(_) => Err(()),
                };
                let band_counters = match emitted {
                    Ok(c) => c,
                    // not taken, or failed on its thread: again here, as on one thread
                    Err(()) => emit_into_feed(plan, band_rows(want as u32), feed, &fault)?,
                };
                counters.merge(&band_counters);
                want += 1;
                continue;
            }
            let k = next_band.fetch_add(1, Ordering::Relaxed);
            if k < n as usize {
                waiting.insert(k, emit_band(k));
                continue;
            }
            // every band is taken: wait for the workers'
            match open.then(|| rx.recv().ok()).flatten() {
                Some((k, band)) => {
                    waiting.insert(k, band);
                }
                // the workers are done: every band is here
                None if waiting.contains_key(&want) => open = false,
                // a worker panicked without sending its band: the scope raises it
                None => break,
            }
        }
        Ok(counters)
    })
}
