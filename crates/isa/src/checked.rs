//! [`CheckedStream`]: instructions checked once against a trace header as they are
//! appended, so that whatever executes them later need not check them again.
//!
//! A renderer's stream is in range by construction, but the array cannot take that on
//! trust: [`Instruction::check`] must run once on every instruction. A stream that is
//! buffered before it is executed (the pipeline buffers scanlines between the renderer
//! and the array) checks it on the way in; the array's `EngineWriter::write_checked`
//! then executes the whole buffer without a second check. The type is the proof: an
//! instruction gets into a `CheckedStream` only through [`CheckedStream::push`].

use crate::header::TraceHeader;
use crate::instruction::{Instruction, OperandError};
use crate::io::TraceWrite;
use std::io;

/// Instructions that each fit one [`TraceHeader`] ([`Instruction::check`]), in order.
#[derive(Clone, Debug)]
pub struct CheckedStream {
    header: TraceHeader,
    instrs: Vec<Instruction>,
}

impl CheckedStream {
    /// An empty stream for `header`.
    pub fn new(header: &TraceHeader) -> CheckedStream {
        CheckedStream {
            header: *header,
            instrs: Vec::new(),
        }
    }

    /// The header every instruction was checked against.
    pub fn header(&self) -> &TraceHeader {
        &self.header
    }

    /// `instrs` as a stream for `header`, checked in one pass; or, if one does not fit,
    /// the first that does not ([`Unfit`], with the instructions handed back).
    pub fn from_vec(
        header: &TraceHeader,
        instrs: Vec<Instruction>,
    ) -> Result<CheckedStream, Unfit> {
        match instrs.iter().position(|i| i.check(header).is_err()) {
            None => Ok(CheckedStream {
                header: *header,
                instrs,
            }),
            Some(index) => {
                let error = instrs[index].check(header).expect_err("just refused");
                Err(Unfit {
                    instructions: instrs,
                    index,
                    error,
                })
            }
        }
    }

    /// The instructions, given back (to reuse their memory).
    pub fn into_vec(self) -> Vec<Instruction> {
        self.instrs
    }

    /// Appends `instr` if it fits the header; otherwise appends nothing and says why.
    #[inline]
    pub fn push(&mut self, instr: Instruction) -> Result<(), OperandError> {
        instr.check(&self.header)?;
        self.instrs.push(instr);
        Ok(())
    }

    /// The instructions, in the order pushed.
    pub fn instructions(&self) -> &[Instruction] {
        &self.instrs
    }

    /// The number of instructions.
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    /// True when the stream holds no instruction.
    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// Empties the stream, keeping its memory for reuse.
    pub fn clear(&mut self) {
        self.instrs.clear();
    }
}

/// Instructions of which one does not fit the header ([`CheckedStream::from_vec`]).
#[derive(Clone, Debug)]
pub struct Unfit {
    /// The instructions offered, unchanged.
    pub instructions: Vec<Instruction>,
    /// The first that does not fit.
    pub index: usize,
    /// Why.
    pub error: OperandError,
}

impl Unfit {
    /// The refusal of the instruction that does not fit ([`refusal`]).
    pub fn refusal(&self) -> io::Error {
        refusal(&self.instructions[self.index], &self.error)
    }
}

/// How a stream refuses an instruction that does not fit its header: an
/// [`io::ErrorKind::InvalidInput`] error reading `INSTRUCTION: MESSAGE` (the array's
/// `EngineWriter` refuses with the same error).
pub fn refusal(instr: &Instruction, e: &OperandError) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{instr}: {}", e.message()),
    )
}

/// Appends a copy of each instruction that fits (comments dropped); one that does not is
/// refused ([`refusal`]) and not appended.
impl TraceWrite for CheckedStream {
    #[inline]
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        self.push(instr.clone()).map_err(|e| refusal(instr, &e))
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Intensity;

    #[test]
    fn only_instructions_that_fit_get_in() {
        let h = TraceHeader::new(4, 1, 1).unwrap();
        let mut s = CheckedStream::new(&h);
        s.write(&Instruction::eval1(1, 3, Intensity::grey(0.5)))
            .unwrap();
        let bad = Instruction::eval1(3, 2, Intensity::grey(0.5));
        let e = s.write(&bad).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert_eq!(
            e.to_string(),
            format!("{bad}: {}", bad.check(&h).unwrap_err().message())
        );
        assert!(s
            .push(Instruction::eval1(0, 1, Intensity::grey(f64::NAN)))
            .is_err());
        assert!(s
            .push(Instruction::eval1(0, 1, Intensity::new(&[0.1, 0.2, 0.3])))
            .is_err());
        s.push(Instruction::refresh()).unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s.instructions()[1], Instruction::refresh());
        assert_eq!(s.header(), &h);
        s.clear();
        assert!(s.is_empty());
    }

    #[test]
    fn a_vector_is_checked_whole_and_refused_at_its_first_unfit_instruction() {
        let h = TraceHeader::new(4, 1, 1).unwrap();
        let g = Intensity::grey;
        let good = vec![Instruction::eval1(0, 4, g(0.5)), Instruction::refresh()];
        let s = CheckedStream::from_vec(&h, good.clone()).unwrap();
        assert_eq!(s.instructions(), &good[..]);
        assert_eq!(s.into_vec(), good);
        let bad = Instruction::set_i(4, g(0.5));
        let mixed = vec![
            good[0].clone(),
            bad.clone(),
            Instruction::eval1(3, 2, g(1.0)),
        ];
        let u = CheckedStream::from_vec(&h, mixed.clone()).unwrap_err();
        assert_eq!((u.index, &u.instructions), (1, &mixed));
        assert_eq!(u.error, bad.check(&h).unwrap_err());
        let mut one = CheckedStream::new(&h);
        assert_eq!(
            u.refusal().to_string(),
            one.write(&bad).unwrap_err().to_string()
        );
    }
}
