//! Scanlines executed ahead, on another thread, and taken in by the fast engine in order.
//!
//! Between scanlines the processors' state is the same whatever came before, but for one
//! bit: whether negative accumulation is on ([`crate::processors`]). And time is additive
//! within a scanline, only its `Refresh` waiting for the display ([`crate::clock`]). So a
//! band of whole scanlines — the rows a renderer emits on one thread — can be executed
//! there by its own processors ([`BandArray`]) into a [`Band`]: each scanline's values,
//! its instructions counted by opcode, its work. The engine then takes the bands in, in
//! order ([`crate::Engine::absorb`]), timing and recording each scanline in one step, as
//! if the instructions had run there.
//!
//! A band assumes negative accumulation off at its start, as at the start of a trace. If
//! the stream left it on, the engine refuses the band and its instructions must run
//! there instead; so does an engine that is not between scanlines. Output, statistics and
//! cycles are those of the serial run, bit for bit (`tests/bands.rs`).

use crate::arith::Arith;
use crate::processors::{LineEnd, Processors};
use crate::sample::Sample;
use crate::stats::{IssueTally, Work};
use cwisim_isa::{CheckedStream, Opcode, TraceHeader};

/// Scanlines executed by a [`BandArray`], waiting to be taken in by the engine
/// ([`crate::Engine::absorb`]). Reusable: [`Band::clear`] keeps its buffers.
#[derive(Clone, Debug, Default)]
pub struct Band<T> {
    lines: Vec<BandLine>,
    /// Every scanline's values, one after the other.
    values: Vec<T>,
    /// Instructions executed into the band.
    instructions: u64,
    negative_at_end: bool,
}

/// One scanline of a [`Band`]: what the engine times and records.
#[derive(Clone, Debug)]
struct BandLine {
    tally: IssueTally,
    work: Work,
    span: (usize, usize),
    /// Where its values end in [`Band::values`].
    values_end: usize,
}

/// One scanline of a band, as [`Band::lines`] gives it.
pub(crate) struct BandLineRef<'a, T> {
    pub(crate) tally: &'a IssueTally,
    pub(crate) work: Work,
    pub(crate) span: (usize, usize),
    pub(crate) values: &'a [T],
}

impl<T> Band<T> {
    /// An empty band.
    pub fn new() -> Self {
        Band {
            lines: Vec::new(),
            values: Vec::new(),
            instructions: 0,
            negative_at_end: false,
        }
    }

    /// Empties the band, keeping its buffers.
    pub fn clear(&mut self) {
        self.lines.clear();
        self.values.clear();
        self.instructions = 0;
        self.negative_at_end = false;
    }

    /// Scanlines in the band.
    pub fn scanlines(&self) -> usize {
        self.lines.len()
    }

    /// Instructions executed into the band.
    pub fn instructions(&self) -> u64 {
        self.instructions
    }

    /// Whether the band assumed negative accumulation on at its start: never (see the
    /// module documentation).
    pub fn negative_at_start(&self) -> bool {
        false
    }

    /// Whether negative accumulation is on after the band's last scanline.
    pub fn negative_at_end(&self) -> bool {
        self.negative_at_end
    }

    /// The band's scanlines, in order.
    pub(crate) fn lines(&self) -> impl Iterator<Item = BandLineRef<'_, T>> {
        let mut start = 0;
        self.lines.iter().map(move |l| {
            let values = &self.values[start..l.values_end];
            start = l.values_end;
            BandLineRef {
                tally: &l.tally,
                work: l.work,
                span: l.span,
                values,
            }
        })
    }
}

/// Why a [`BandArray`] refused a stream (nothing of it executed).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BandError {
    /// The stream was checked against another header than the array's.
    #[error("a stream checked against a {stream_width}-wide, {stream_channels}-channel header, fed to a band of a {width}-wide, {channels}-channel array")]
    Header {
        /// The stream's width.
        stream_width: u32,
        /// The stream's channels.
        stream_channels: u8,
        /// The array's width.
        width: u32,
        /// The array's channels.
        channels: u8,
    },
    /// The stream does not end with a `Refresh`: a band holds whole scanlines.
    #[error("a band holds whole scanlines: its stream must end with a `Refresh` (this one ends with `{last}`)")]
    OpenScanline {
        /// The stream's last opcode.
        last: &'static str,
    },
}

/// Processors of their own for executing bands of whole scanlines, on any thread
/// ([`crate::Engine::band_array`]). Each band starts from the state between scanlines,
/// negative accumulation off.
pub struct BandArray<T> {
    header: TraceHeader,
    processors: Box<dyn RunScanlines<T> + Send>,
}

impl<T: Sample> BandArray<T> {
    pub(crate) fn new<A: Arith<Out = T>>(header: &TraceHeader, processors: Processors<A>) -> Self {
        BandArray {
            header: *header,
            processors: Box::new(processors),
        }
    }

    /// Executes the whole scanlines of `stream` into `band`, after any already there (an
    /// empty band starts with negative accumulation off). Refused, nothing executed, if
    /// the stream was checked against another header or does not end with a `Refresh`.
    pub fn run(&mut self, stream: &CheckedStream, band: &mut Band<T>) -> Result<(), BandError> {
        let h = stream.header();
        if h != &self.header {
            return Err(BandError::Header {
                stream_width: h.width,
                stream_channels: h.channels,
                width: self.header.width,
                channels: self.header.channels,
            });
        }
        match stream.instructions().last() {
            None => return Ok(()),
            Some(i) if i.op != Opcode::Refresh => {
                return Err(BandError::OpenScanline { last: i.op.name() })
            }
            Some(_) => {}
        }
        if band.lines.is_empty() && band.instructions == 0 {
            self.processors.set_negative(false);
        } else {
            self.processors.set_negative(band.negative_at_end);
        }
        self.processors.run_into(stream, band);
        band.instructions += stream.len() as u64;
        band.negative_at_end = self.processors.negative();
        Ok(())
    }
}

/// [`Processors`] of any arithmetic, behind one type for [`BandArray`].
trait RunScanlines<T> {
    fn set_negative(&mut self, on: bool);
    fn negative(&self) -> bool;
    fn run_into(&mut self, stream: &CheckedStream, band: &mut Band<T>);
}

impl<A: Arith> RunScanlines<A::Out> for Processors<A> {
    fn set_negative(&mut self, on: bool) {
        self.set_negative_enabled(on);
    }

    fn negative(&self) -> bool {
        self.negative_enabled()
    }

    fn run_into(&mut self, stream: &CheckedStream, band: &mut Band<A::Out>) {
        debug_assert!(self.between_scanlines());
        let (lines, values) = (&mut band.lines, &mut band.values);
        self.run(stream.instructions(), &mut |end: LineEnd<'_, A::Out>| {
            values.extend_from_slice(end.values);
            lines.push(BandLine {
                tally: end.tally,
                work: end.work,
                span: end.span,
                values_end: values.len(),
            });
        });
    }
}
