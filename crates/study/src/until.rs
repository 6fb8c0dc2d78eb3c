//! A reader that ends a trace after a given scanline's `Refresh`, so that tools
//! studying early scanlines do not replay the rest of a long trace.

use cwisim_isa::{Instruction, Location, Opcode, TraceError, TraceHeader, TraceRead};

/// Reads `inner` up to and including the `Refresh` that ends scanline `last`.
pub struct UntilLine<'a> {
    inner: &'a mut dyn TraceRead,
    last: Option<u64>,
    refreshes: u64,
}

impl<'a> UntilLine<'a> {
    /// Stops after scanline `last` (`None`: reads everything).
    pub fn new(inner: &'a mut dyn TraceRead, last: Option<u64>) -> Self {
        UntilLine {
            inner,
            last,
            refreshes: 0,
        }
    }

    /// Scanlines the instructions read so far output.
    pub fn lines_read(&self) -> u64 {
        self.refreshes
    }
}

impl TraceRead for UntilLine<'_> {
    fn header(&self) -> &TraceHeader {
        self.inner.header()
    }

    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        if self.last.is_some_and(|l| self.refreshes > l) {
            return Ok(None);
        }
        let next = self.inner.next_instruction()?;
        if next.as_ref().is_some_and(|i| i.op == Opcode::Refresh) {
            self.refreshes += 1;
        }
        Ok(next)
    }

    fn location(&self) -> Location {
        self.inner.location()
    }

    fn bytes_read(&self) -> u64 {
        self.inner.bytes_read()
    }

    fn note(&self) -> Option<cwisim_isa::Note<'_>> {
        self.inner.note()
    }
}
