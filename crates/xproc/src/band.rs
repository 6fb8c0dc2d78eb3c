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
//! A band assumes negative accumulation off at its start, as at the start of a trace,
//! unless it is started after the band before it ([`BandArray::start_after`], bands
//! emitted in order on one thread). If the stream left the bit otherwise, the engine
//! refuses the band and its instructions must run there instead; so does an engine that
//! is not between scanlines. Output, statistics and cycles are those of the serial run,
//! bit for bit (`tests/bands.rs`).

use crate::arith::Arith;
use crate::processors::{LineEnd, Processors};
use crate::sample::Sample;
use crate::stats::{IssueTally, Work};
use cwisim_isa::{refusal, Instruction, TraceHeader, TraceWrite};
use std::io;

/// Scanlines executed by a [`BandArray`], waiting to be taken in by the engine
/// ([`crate::Engine::absorb`]). Reusable: [`Band::clear`] keeps its buffers.
#[derive(Clone, Debug)]
pub struct Band<T> {
    lines: Vec<BandLine>,
    /// Every scanline's values, one after the other.
    values: Vec<T>,
    /// Instructions executed into the band.
    instructions: u64,
    negative_at_start: bool,
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

impl<T> Default for Band<T> {
    fn default() -> Self {
        Band::new()
    }
}

impl<T> Band<T> {
    /// An empty band.
    pub fn new() -> Self {
        Band {
            lines: Vec::new(),
            values: Vec::new(),
            instructions: 0,
            negative_at_start: false,
            negative_at_end: false,
        }
    }

    /// Empties the band, keeping its buffers.
    pub fn clear(&mut self) {
        self.lines.clear();
        self.values.clear();
        self.instructions = 0;
        self.negative_at_start = false;
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

    /// Whether the band assumed negative accumulation on at its start: off, unless it
    /// was started after the band before it ([`BandArray::start_after`]).
    pub fn negative_at_start(&self) -> bool {
        self.negative_at_start
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

/// Processors of their own for executing a band of whole scanlines on any thread
/// ([`crate::Engine::band_array`]): [`Self::start`] a band, write its instructions
/// ([`TraceWrite`]: each checked, then executed as it comes), [`Self::take`] it. Each
/// band starts from the state between scanlines, negative accumulation off.
pub struct BandArray<T> {
    header: TraceHeader,
    processors: Box<dyn RunScanlines<T> + Send>,
    band: Band<T>,
}

/// A band that does not hold whole scanlines ([`BandArray::take`]): the instructions
/// after its last `Refresh` are in none of its scanlines, so it cannot be taken in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("a band holds whole scanlines: its stream must end with a `Refresh`")]
pub struct OpenScanline;

impl<T: Sample> BandArray<T> {
    pub(crate) fn new<A: Arith<Out = T>>(header: &TraceHeader, processors: Processors<A>) -> Self {
        BandArray {
            header: *header,
            processors: Box::new(processors),
            band: Band::new(),
        }
    }

    /// Starts a band in `band`'s buffers (emptied; [`Band::new`] for new ones), the
    /// processors between scanlines, negative accumulation off.
    pub fn start(&mut self, band: Band<T>) {
        self.start_assuming(band, false);
    }

    /// Starts a band that follows `previous` in the stream, on one thread: it assumes
    /// negative accumulation as `previous` left it, so that the engine, having taken
    /// `previous` in, takes this one too whatever the stream did with the bit.
    pub fn start_after(&mut self, band: Band<T>, previous: &Band<T>) {
        self.start_assuming(band, previous.negative_at_end);
    }

    fn start_assuming(&mut self, band: Band<T>, negative: bool) {
        self.band = band;
        self.band.clear();
        self.band.negative_at_start = negative;
        if !self.processors.between() {
            self.processors.reset();
        }
        self.processors.set_negative(negative);
    }

    /// The band executed since [`Self::start`]; [`OpenScanline`] if its last instruction
    /// was not a `Refresh` (the band is dropped).
    pub fn take(&mut self) -> Result<Band<T>, OpenScanline> {
        let mut band = std::mem::take(&mut self.band);
        if !self.processors.between() {
            return Err(OpenScanline);
        }
        band.negative_at_end = self.processors.negative();
        Ok(band)
    }
}

impl<T: Sample> TraceWrite for BandArray<T> {
    /// Executes the instruction into the band; one that does not fit the header is an
    /// error (`InvalidInput`, worded as the array's [`crate::EngineWriter`] words it),
    /// not executed.
    #[inline]
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        instr.check(&self.header).map_err(|e| refusal(instr, &e))?;
        self.processors.step_into(instr, &mut self.band);
        self.band.instructions += 1;
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// [`Processors`] of any arithmetic, behind one type for [`BandArray`].
trait RunScanlines<T> {
    fn set_negative(&mut self, on: bool);
    fn negative(&self) -> bool;
    fn step_into(&mut self, instr: &Instruction, band: &mut Band<T>);
    fn between(&self) -> bool;
    fn reset(&mut self);
}

impl<A: Arith> RunScanlines<A::Out> for Processors<A> {
    fn set_negative(&mut self, on: bool) {
        self.set_negative_enabled(on);
    }

    fn negative(&self) -> bool {
        self.negative_enabled()
    }

    fn step_into(&mut self, instr: &Instruction, band: &mut Band<A::Out>) {
        self.execute(instr, &mut keep_in(band));
    }

    fn between(&self) -> bool {
        self.between_scanlines()
    }

    fn reset(&mut self) {
        *self = self.fresh();
    }
}

/// Keeps each scanline the processors hand out in `band`.
fn keep_in<T: Sample>(band: &mut Band<T>) -> impl FnMut(LineEnd<'_, T>) + '_ {
    |end: LineEnd<'_, T>| {
        band.values.extend_from_slice(end.values);
        band.lines.push(BandLine {
            tally: end.tally,
            work: end.work,
            span: end.span,
            values_end: band.values.len(),
        });
    }
}
