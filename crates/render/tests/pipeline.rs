//! The pipeline's contract with renderers: frames in order, the previous frame's output
//! handed to renderers that need it, bands on threads byte-identical to one thread, and
//! a renderer's fault reported as cwisim's, not the user's.

use cwisim_isa::{Instruction, Intensity, TraceHeader, TraceWrite};
use cwisim_render::{emit, render, ArrayConfig, Counters, FramePlan, RenderError, Renderer, Taps};
use cwisim_xproc::{Image, ImageSink};
use std::io;
use std::ops::Range;

const W: u32 = 7;
const H: u32 = 5;

/// Frame 0: a ramp per row; frame k > 0: every pixel `0.5 × previous + 0.125`, one
/// `Eval1` per pixel — it can only be drawn from the previous frame's output.
struct Refine {
    frames: u32,
}

enum Plan<'a> {
    Ramp,
    From(&'a Image),
}

impl FramePlan for Plan<'_> {
    fn counters(&self) -> Counters {
        Counters::default().with("frames", 1)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let mut pixels = 0;
        for y in rows {
            match self {
                Plan::Ramp => sink.write(&Instruction::eval2(
                    0,
                    W,
                    Intensity::grey(f64::from(y) / 8.0),
                    Intensity::grey(1.0 / 16.0),
                ))?,
                Plan::From(previous) => {
                    for x in 0..W {
                        let v = previous.data[(y * W + x) as usize];
                        sink.write(&Instruction::eval1(x, 1, Intensity::grey(0.5 * v + 0.125)))?;
                        pixels += 1;
                    }
                }
            }
            sink.write(&Instruction::refresh())?;
        }
        Ok(Counters::default().with("pixels", pixels))
    }
}

impl Renderer for Refine {
    fn name(&self) -> &'static str {
        "refine-test"
    }

    fn header(&self) -> TraceHeader {
        TraceHeader::new(W, H, 1).unwrap()
    }

    fn frames(&self) -> u32 {
        self.frames
    }

    fn needs_previous_frame(&self) -> bool {
        true
    }

    fn frame<'a>(
        &'a self,
        index: u32,
        previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        match (index, previous) {
            (0, None) => Ok(Box::new(Plan::Ramp)),
            (_, Some(p)) => {
                assert_eq!((p.width, p.lines), (W as usize, H as usize), "one frame");
                Ok(Box::new(Plan::From(p)))
            }
            (k, None) => Err(RenderError::Usage(format!(
                "frame {k} without the previous"
            ))),
        }
    }

    fn settings_phrase(&self) -> String {
        "test".into()
    }
}

fn run(r: &dyn Renderer, threads: usize) -> Result<(Image, cwisim_render::Rendered), RenderError> {
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, 1, 1 << 20);
    let done = render(
        r,
        &ArrayConfig::default(),
        threads,
        &mut sink,
        Taps::default(),
    )?;
    Ok((sink.finish()?, done))
}

#[test]
fn each_frame_is_drawn_from_the_previous_frames_output() {
    let r = Refine { frames: 3 };
    let (image, done) = run(&r, 1).unwrap();
    assert_eq!(image.lines, 3 * H as usize);
    let frame = (W * H) as usize;
    for x in 0..W as usize {
        for y in 0..H as usize {
            let first = image.data[y * W as usize + x];
            assert_eq!(first, y as f64 / 8.0 + x as f64 / 16.0);
            for k in 1..3 {
                let prev = image.data[(k - 1) * frame + y * W as usize + x];
                assert_eq!(
                    image.data[k * frame + y * W as usize + x],
                    0.5 * prev + 0.125
                );
            }
        }
    }
    assert_eq!(done.counters.get("frames"), Some(3));
    assert_eq!(done.counters.get("pixels"), Some(2 * u64::from(W * H)));
    assert_eq!(done.stats.totals.frames, 3);
    for threads in [2, 3] {
        let (again, d) = run(&r, threads).unwrap();
        assert_eq!(again.data, image.data, "{threads} threads");
        assert_eq!(d.counters, done.counters);
        assert_eq!(
            format!("{:?}", d.stats.totals),
            format!("{:?}", done.stats.totals)
        );
    }
}

#[test]
fn a_stream_alone_cannot_draw_from_the_previous_frame() {
    let mut sink: Vec<Instruction> = Vec::new();
    let e = emit(&Refine { frames: 2 }, &mut sink).unwrap_err();
    assert!(e.to_string().contains("previous frame's output"), "{e}");
    assert!(!e.is_internal());
    // one frame needs nothing before it
    emit(&Refine { frames: 1 }, &mut sink).unwrap();
    assert_eq!(sink.len(), 2 * H as usize);
}

/// A renderer that emits an instruction outside the array.
struct Broken;

struct BrokenPlan;

impl FramePlan for BrokenPlan {
    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        for _ in rows {
            sink.write(&Instruction::eval1(W - 1, 2, Intensity::grey(1.0)))?;
            sink.write(&Instruction::refresh())?;
        }
        Ok(Counters::default())
    }
}

impl Renderer for Broken {
    fn name(&self) -> &'static str {
        "broken"
    }

    fn header(&self) -> TraceHeader {
        TraceHeader::new(W, H, 1).unwrap()
    }

    fn frame<'a>(
        &'a self,
        _: u32,
        _: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        Ok(Box::new(BrokenPlan))
    }

    fn settings_phrase(&self) -> String {
        "broken".into()
    }
}

#[test]
fn a_renderers_bad_instruction_is_an_internal_fault() {
    for threads in [1, 2] {
        let e = run(&Broken, threads).expect_err("refused");
        assert!(e.is_internal(), "{e}");
        assert!(e.to_string().contains("the array failed"), "{e}");
    }
}

/// One frame of many scanlines, each of many instructions: the array is fed in several
/// batches.
#[derive(Default)]
struct Stripes;

impl FramePlan for Stripes {
    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        for y in rows {
            for k in 0..20 {
                let x = (y * 7 + k * 3) % (Self::WIDTH - 4);
                sink.write(&Instruction::eval1(
                    x,
                    4,
                    Intensity::grey(f64::from(k) / 32.0),
                ))?;
            }
            sink.write(&Instruction::refresh())?;
        }
        Ok(Counters::default())
    }
}

/// A renderer of one frame, planned by `P` (a unit type) alone, `WIDTH × LINES`.
trait OneFrame: FramePlan + Default + 'static {
    const NAME: &'static str;
    const WIDTH: u32;
    const LINES: u32;
}

impl OneFrame for Stripes {
    const NAME: &'static str = "stripes";
    const WIDTH: u32 = 64;
    const LINES: u32 = 300;
}

/// [`OneFrame`] as a renderer.
struct Single<P>(P);

impl<P: OneFrame> Renderer for Single<P> {
    fn name(&self) -> &'static str {
        P::NAME
    }

    fn header(&self) -> TraceHeader {
        TraceHeader::new(P::WIDTH, P::LINES, 1).unwrap()
    }

    fn frame<'a>(
        &'a self,
        _: u32,
        _: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        Ok(Box::new(P::default()))
    }

    fn settings_phrase(&self) -> String {
        P::NAME.into()
    }
}

/// Counts the scanlines the array outputs.
struct Counting<'c>(&'c std::cell::Cell<u64>);

impl cwisim_xproc::LineSink<f64> for Counting<'_> {
    fn line(&mut self, _: cwisim_xproc::LineOut<'_, f64>) {
        self.0.set(self.0.get() + 1);
    }
}

/// The taps of a render of `Stripes` on `threads` threads, with or without a tap that
/// hears every instruction (without one, the bands run through the array on their own
/// threads): what that tap heard, the progress told, the scanlines output, the result.
fn tapped(
    threads: usize,
    hear: bool,
) -> (Vec<Instruction>, Vec<u64>, u64, cwisim_render::Rendered) {
    let output = std::cell::Cell::new(0);
    let mut heard: Vec<Instruction> = Vec::new();
    let mut told = Vec::new();
    let mut progress = |n: u64| {
        assert!(
            output.get() >= n,
            "told of scanline {n} before the array output it"
        );
        told.push(n);
    };
    let done = render(
        &Single(Stripes),
        &ArrayConfig::default(),
        threads,
        &mut Counting(&output),
        Taps {
            also: hear.then_some(&mut heard as &mut dyn TraceWrite),
            progress: Some(&mut progress),
            cancel: None,
        },
    )
    .unwrap();
    (heard, told, output.get(), done)
}

#[test]
fn the_taps_hear_every_instruction_and_every_scanline_once_it_is_output() {
    let mut emitted: Vec<Instruction> = Vec::new();
    emit(&Single(Stripes), &mut emitted).unwrap();
    let every_line: Vec<u64> = (1..=u64::from(Stripes::LINES)).collect();
    for (threads, hear) in [(1, true), (1, false), (2, true), (2, false), (3, false)] {
        let (heard, told, output, done) = tapped(threads, hear);
        let what = format!("{threads} threads, hearing {hear}");
        assert_eq!(
            heard,
            if hear { emitted.clone() } else { Vec::new() },
            "{what}"
        );
        assert_eq!(told, every_line, "{what}");
        assert_eq!(output, u64::from(Stripes::LINES), "{what}");
        assert_eq!(
            done.stats.totals.instructions,
            emitted.len() as u64,
            "{what}"
        );
        // without a tap that hears them, the bands ran through the array on their threads
        assert_eq!(done.array_in_bands, !hear, "{what}");
    }
}

#[test]
fn the_arrays_refusal_of_a_renderers_instruction_is_its_own_message() {
    for threads in [1, 2] {
        let e = run(&Broken, threads).expect_err("refused");
        assert_eq!(
            e.to_string(),
            "the array failed: Eval1 6 2 1.0: range [x, x+dx) = [6, 8) reaches past the array's end (7)"
        );
    }
}

/// Rows whose `Eval2` ramps go negative, with `Acc_mode` toggled at the end of every
/// fifth row: negative accumulation is left on across whole stretches of scanlines, so
/// that bands executed on their own threads start with the wrong assumption and must be
/// emitted again into the array.
#[derive(Default)]
struct Toggling;

impl OneFrame for Toggling {
    const NAME: &'static str = "toggling";
    const WIDTH: u32 = 32;
    const LINES: u32 = 120;
}

impl FramePlan for Toggling {
    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        for y in rows {
            sink.write(&Instruction::eval2(
                0,
                Self::WIDTH,
                Intensity::grey(0.5),
                Intensity::grey(-f64::from(y % 7 + 1) / 32.0),
            ))?;
            sink.write(&Instruction::refresh())?;
            if y % 5 == 4 {
                sink.write(&Instruction::acc_mode())?;
            }
        }
        Ok(Counters::default())
    }
}

/// The stream of `r` emitted whole and executed by the engine, instruction by instruction:
/// the serial run, with no bands.
fn unbanded(r: &dyn Renderer) -> (Image, cwisim_xproc::RunStats) {
    let h = r.header();
    let mut stream: Vec<Instruction> = Vec::new();
    emit(r, &mut stream).unwrap();
    let mut sink = ImageSink::new(h.width as usize, 1, 1 << 20);
    let config = ArrayConfig::default();
    let mut engine =
        cwisim_xproc::numeric_engine(&h, &config.machine, config.timing, &config.numeric).unwrap();
    for instr in &stream {
        engine.execute(instr, &mut sink);
    }
    let stats = engine.finish(&mut sink);
    (sink.finish().unwrap(), stats)
}

#[test]
fn bands_that_start_with_negative_accumulation_on_are_byte_identical() {
    let (image, done) = run(&Single(Toggling), 1).unwrap();
    // some scanlines kept their negative values, some dropped them
    assert!(image.data.iter().any(|v| *v < 0.0));
    assert!(done.stats.totals.dropped_negative > 0);
    // one thread's bands are the unbanded run's
    let bits = |i: &Image| i.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let (reference, stats) = unbanded(&Single(Toggling));
    assert_eq!(bits(&image), bits(&reference));
    assert_eq!(done.stats, stats);
    assert!(done.array_in_bands);
    for threads in [2, 3, 5] {
        let (again, d) = run(&Single(Toggling), threads).unwrap();
        assert_eq!(bits(&again), bits(&image), "{threads} threads");
        assert_eq!(d.stats, done.stats, "{threads} threads");
    }
}

/// The cancel tap stops a render after the scanline it says stop at, on any number of
/// threads, with [`RenderError::Cancelled`] (no image, no statistics).
#[test]
fn a_render_stops_when_the_cancel_tap_says_so() {
    for (threads, hear) in [(1, true), (1, false), (2, true), (2, false), (3, false)] {
        let output = std::cell::Cell::new(0u64);
        let asked = std::cell::Cell::new(0u64);
        let mut heard: Vec<Instruction> = Vec::new();
        let stop = || {
            asked.set(asked.get() + 1);
            asked.get() == 5
        };
        let e = render(
            &Single(Stripes),
            &ArrayConfig::default(),
            threads,
            &mut Counting(&output),
            Taps {
                also: hear.then_some(&mut heard as &mut dyn TraceWrite),
                progress: None,
                cancel: Some(&stop),
            },
        )
        .expect_err("cancelled");
        let what = format!("{threads} threads, hearing {hear}");
        assert!(
            matches!(e, RenderError::Cancelled { lines: 5 }),
            "{what}: {e}"
        );
        assert_eq!(asked.get(), 5, "{what}: asked once per scanline, no more");
        assert!(
            output.get() >= 5 && output.get() < u64::from(Stripes::LINES),
            "{what}"
        );
    }
    // never asked to stop: the whole frame, as without the tap
    let never = || false;
    let output = std::cell::Cell::new(0u64);
    render(
        &Single(Stripes),
        &ArrayConfig::default(),
        2,
        &mut Counting(&output),
        Taps {
            cancel: Some(&never),
            ..Taps::default()
        },
    )
    .unwrap();
    assert_eq!(output.get(), u64::from(Stripes::LINES));
}
