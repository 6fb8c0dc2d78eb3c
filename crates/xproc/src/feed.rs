//! Driving the array from anything that emits instructions: [`EngineWriter`] is a
//! [`TraceWrite`], so a Y-processor (or any renderer) can send its stream straight to
//! the simulator instead of through a file.

use crate::engine::{engine, Engine, Timing};
use crate::machine::{Machine, MachineError};
use crate::output::LineSink;
use crate::sample::Sample;
use crate::stats::RunStats;
use cwisim_isa::{Instruction, TraceHeader, TraceWrite};
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
}

impl<T: Sample> TraceWrite for EngineWriter<'_, T> {
    /// Executes the instruction; one that does not fit the header is an error
    /// (`InvalidInput`), not executed.
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        instr.check(&self.header).map_err(|e| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{instr}: {}", e.message()),
            )
        })?;
        let engine = self
            .engine
            .as_mut()
            .ok_or_else(|| io::Error::other("instruction after finish"))?;
        engine.execute(instr, self.sink);
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
}
