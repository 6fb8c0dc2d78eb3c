//! Driving the array from anything that emits instructions: [`EngineWriter`] is a
//! [`TraceWrite`], so a Y-processor (or any renderer) can send its stream straight to
//! the simulator instead of through a file.

use crate::band::{Band, BandArray};
use crate::engine::{engine, numeric_engine, Engine, Timing};
use crate::machine::{Machine, MachineError};
use crate::numeric::Numeric;
use crate::output::LineSink;
use crate::sample::Sample;
use crate::stats::RunStats;
use cwisim_isa::{refusal, CheckedStream, Instruction, TraceHeader, TraceWrite};
use std::io;

/// An array simulator that takes instructions through [`TraceWrite`].
pub struct EngineWriter<'a, T: Sample> {
    header: TraceHeader,
    engine: Option<Box<dyn Engine<T>>>,
    sink: &'a mut dyn LineSink<T>,
    stats: Option<RunStats>,
}

impl<'a, T: Sample> EngineWriter<'a, T> {
    /// An array for `header` on `machine`, handing scanlines to `sink`.
    pub fn new(
        header: &TraceHeader,
        machine: &Machine,
        timing: Timing,
        sink: &'a mut dyn LineSink<T>,
    ) -> Result<Self, MachineError> {
        Ok(EngineWriter {
            header: *header,
            engine: Some(engine::<T>(header, machine, timing)?),
            sink,
            stats: None,
        })
    }

    /// The statistics, after [`TraceWrite::finish`].
    pub fn into_stats(self) -> Option<RunStats> {
        self.stats
    }

    /// Executes a stream whose instructions were checked as they were appended, without
    /// checking them again: what [`TraceWrite::write`] of each would do. A stream
    /// checked against another header is refused whole (`InvalidInput`), nothing
    /// executed.
    pub fn write_checked(&mut self, stream: &CheckedStream) -> io::Result<()> {
        if stream.header() != &self.header {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "a stream checked against a {}-wide, {}-channel header, fed to a {}-wide, {}-channel array",
                    stream.header().width,
                    stream.header().channels,
                    self.header.width,
                    self.header.channels
                ),
            ));
        }
        let (engine, sink) = self.parts()?;
        engine.execute_all(stream.instructions(), sink);
        Ok(())
    }

    /// Processors for executing bands of whole scanlines on another thread
    /// ([`Engine::band_array`]); `None` for an engine that takes no bands, or after
    /// [`TraceWrite::finish`].
    pub fn band_array(&self) -> Option<BandArray<T>> {
        self.engine.as_ref()?.band_array()
    }

    /// Takes in a band's scanlines, handing them to the sink ([`Engine::absorb`]):
    /// `false`, nothing taken, if the engine cannot take this band here — execute its
    /// instructions instead.
    pub fn absorb(&mut self, band: &Band<T>) -> io::Result<bool> {
        let (engine, sink) = self.parts()?;
        Ok(engine.absorb(band, sink))
    }

    /// The engine (until [`TraceWrite::finish`]) and the sink it hands scanlines to.
    fn parts(&mut self) -> io::Result<(&mut (dyn Engine<T> + 'static), &mut dyn LineSink<T>)> {
        let engine = self
            .engine
            .as_deref_mut()
            .ok_or_else(|| io::Error::other("instruction after finish"))?;
        Ok((engine, &mut *self.sink))
    }
}

impl<'a> EngineWriter<'a, f64> {
    /// An array whose registers have the format `numeric` (see
    /// [`crate::numeric_engine`]), handing scanlines to `sink` as `f64`: the exact value
    /// of each accumulator, converted. A fixed format outside the limits is a
    /// [`MachineError::Invalid`] of the parameter `numeric`.
    pub fn with_numeric(
        header: &TraceHeader,
        machine: &Machine,
        timing: Timing,
        numeric: &Numeric,
        sink: &'a mut dyn LineSink<f64>,
    ) -> Result<Self, MachineError> {
        Ok(EngineWriter {
            header: *header,
            engine: Some(numeric_engine(header, machine, timing, numeric)?),
            sink,
            stats: None,
        })
    }
}

impl<T: Sample> TraceWrite for EngineWriter<'_, T> {
    /// Executes the instruction; one that does not fit the header is an error
    /// (`InvalidInput`), not executed.
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        instr.check(&self.header).map_err(|e| refusal(instr, &e))?;
        let (engine, sink) = self.parts()?;
        engine.execute(instr, sink);
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        if let Some(engine) = self.engine.take() {
            self.stats = Some(engine.finish(self.sink));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::ImageSink;
    use cwisim_isa::Intensity;

    #[test]
    fn a_stream_drives_the_array() {
        let h = TraceHeader::new(4, 1, 1).unwrap();
        let mut sink = ImageSink::new(4, 1, 1 << 20);
        let mut w =
            EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink).unwrap();
        w.write(&Instruction::eval1(1, 2, Intensity::grey(0.5)))
            .unwrap();
        assert!(w
            .write(&Instruction::eval1(3, 2, Intensity::grey(0.5)))
            .is_err());
        w.write(&Instruction::refresh()).unwrap();
        w.finish().unwrap();
        assert_eq!(w.into_stats().unwrap().totals.lines, 1);
        assert_eq!(sink.finish().unwrap().data, [0.0, 0.5, 0.5, 0.0]);
    }

    #[test]
    fn a_checked_stream_drives_the_array_as_its_instructions_do() {
        let h = TraceHeader::new(8, 2, 1).unwrap();
        let g = Intensity::grey;
        let trace = [
            Instruction::set_i(2, g(0.25)),
            Instruction::eval2(0, 6, g(0.5), g(-0.125)),
            Instruction::dis(1, 2),
            Instruction::eval0(0, 3, g(0.75)),
            Instruction::refresh(),
            Instruction::acc_mode(),
            Instruction::eval3(1, 7, g(-0.5), g(0.25), g(0.0625)),
            Instruction::refresh(),
            Instruction::eval1(4, 4, g(1.0)),
        ];
        let run = |checked: bool| {
            let mut sink = ImageSink::new(8, 1, 1 << 20);
            let mut w =
                EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink).unwrap();
            if checked {
                let mut stream = CheckedStream::new(&h);
                for i in &trace {
                    stream.write(i).unwrap();
                }
                w.write_checked(&stream).unwrap();
            } else {
                for i in &trace {
                    w.write(i).unwrap();
                }
            }
            w.finish().unwrap();
            (w.into_stats().unwrap(), sink.finish().unwrap().data)
        };
        assert_eq!(run(true), run(false));
    }

    #[test]
    fn a_stream_checked_against_another_header_is_refused() {
        let h = TraceHeader::new(8, 2, 1).unwrap();
        let mut sink = ImageSink::new(8, 1, 1 << 20);
        let mut w =
            EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink).unwrap();
        let mut wide = CheckedStream::new(&TraceHeader::new(16, 2, 1).unwrap());
        wide.push(Instruction::eval1(10, 6, Intensity::grey(0.5)))
            .unwrap();
        let e = w.write_checked(&wide).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert_eq!(
            e.to_string(),
            "a stream checked against a 16-wide, 1-channel header, fed to a 8-wide, 1-channel array"
        );
        w.finish().unwrap();
        assert_eq!(w.into_stats().unwrap().totals.instructions, 0);
    }

    #[test]
    fn a_checked_stream_after_finish_is_refused() {
        let h = TraceHeader::new(4, 1, 1).unwrap();
        let mut sink = ImageSink::new(4, 1, 1 << 20);
        let mut w =
            EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink).unwrap();
        w.finish().unwrap();
        let e = w.write_checked(&CheckedStream::new(&h)).unwrap_err();
        assert_eq!(e.to_string(), "instruction after finish");
    }

    #[test]
    fn a_stream_drives_a_fixed_point_array() {
        let h = TraceHeader::new(4, 1, 1).unwrap();
        let mut sink = ImageSink::new(4, 1, 1 << 20);
        // Q3.1: 0.3 rounds to 0.5; the range is [-4, 3.5], so 3 + 0.5 + 0.5 saturates once
        let numeric: Numeric = "fixed:I=3.1,dI=3.1,ddI=3.1".parse().unwrap();
        let mut w = EngineWriter::with_numeric(
            &h,
            &Machine::default(),
            Timing::Stepped,
            &numeric,
            &mut sink,
        )
        .unwrap();
        w.write(&Instruction::eval1(0, 2, Intensity::grey(3.0)))
            .unwrap();
        w.write(&Instruction::eval1(0, 1, Intensity::grey(0.3)))
            .unwrap();
        w.write(&Instruction::eval1(0, 1, Intensity::grey(0.3)))
            .unwrap();
        w.write(&Instruction::refresh()).unwrap();
        w.finish().unwrap();
        assert_eq!(w.into_stats().unwrap().totals.overflows, 1);
        assert_eq!(sink.finish().unwrap().data, [3.5, 3.0, 0.0, 0.0]);
    }

    #[test]
    fn a_fixed_format_outside_the_limits_is_a_machine_error() {
        let h = TraceHeader::new(4, 1, 1).unwrap();
        let mut sink = ImageSink::new(4, 1, 1 << 20);
        let q = crate::numeric::Q {
            int_bits: 0,
            frac_bits: 8,
        };
        let numeric = Numeric::Fixed(crate::numeric::FixedFormat {
            i: q,
            di: q,
            ddi: q,
            acc: q,
            overflow: crate::numeric::Overflow::Wrap,
        });
        let e =
            EngineWriter::with_numeric(&h, &Machine::default(), Timing::Fast, &numeric, &mut sink)
                .err()
                .unwrap();
        assert_eq!(
            e.to_string(),
            "machine parameter `numeric`: fixed format: I=0.8: int_bits must be at least 1 (it includes the sign bit)"
        );
    }
}
