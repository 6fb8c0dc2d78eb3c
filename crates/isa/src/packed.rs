//! [`PackedStream`]: instructions held compactly in memory.
//!
//! An [`Instruction`] is 48 bytes (three inline `f64` slots, colour boxed), whatever it
//! carries: a grey `Refresh` carries none of them. A stream that is buffered before it is
//! replayed — a band of scanlines emitted on one thread and fed to the array on another —
//! moves through memory at that size. A packed stream keeps a 12-byte head per instruction (opcode, operand
//! lengths, `x`, `dx`) and only the values the instruction carries, bit for bit: the
//! instructions read back equal the ones written.

use crate::io::TraceWrite;
use crate::{Instruction, Intensity, Opcode};
use std::io;

/// An instruction without its values: the opcode, the length of each intensity slot
/// (0 for a slot the opcode does not carry) and the two integer operands.
#[derive(Clone, Copy, Debug)]
struct Head {
    op: Opcode,
    lens: [u8; 3],
    x: u32,
    dx: u32,
}

/// Instructions stored compactly; see the module documentation.
#[derive(Clone, Debug, Default)]
pub struct PackedStream {
    heads: Vec<Head>,
    values: Vec<f64>,
}

impl PackedStream {
    /// An empty stream.
    pub fn new() -> PackedStream {
        PackedStream::default()
    }

    /// Empties the stream, keeping its memory for reuse.
    pub fn clear(&mut self) {
        self.heads.clear();
        self.values.clear();
    }

    /// The number of instructions.
    pub fn len(&self) -> usize {
        self.heads.len()
    }

    /// True when the stream holds no instruction.
    pub fn is_empty(&self) -> bool {
        self.heads.is_empty()
    }

    /// Appends `instr`.
    pub fn push(&mut self, instr: &Instruction) {
        let mut lens = [0u8; 3];
        for (s, len) in lens.iter_mut().enumerate() {
            let v = instr.value(s);
            *len = v.len() as u8;
            self.values.extend_from_slice(v);
        }
        self.heads.push(Head {
            op: instr.op,
            lens,
            x: instr.x,
            dx: instr.dx,
        });
    }

    /// The instructions, in order, equal to those pushed.
    pub fn iter(&self) -> impl Iterator<Item = Instruction> + '_ {
        let mut at = 0;
        self.heads.iter().map(move |h| {
            let mut slot = |len: u8| {
                if len == 0 {
                    return Intensity::NONE;
                }
                let v = Intensity::new(&self.values[at..at + usize::from(len)]);
                at += usize::from(len);
                v
            };
            let values = [slot(h.lens[0]), slot(h.lens[1]), slot(h.lens[2])];
            Instruction::from_parts(h.op, h.x, h.dx, values)
        })
    }
}

impl TraceWrite for PackedStream {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        self.push(instr);
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn intensity() -> impl Strategy<Value = Intensity> {
        prop_oneof![
            Just(Intensity::NONE),
            proptest::collection::vec(any::<f64>(), 1..=crate::MAX_CHANNELS)
                .prop_map(|v| Intensity::new(&v)),
        ]
    }

    fn instruction() -> impl Strategy<Value = Instruction> {
        (
            0usize..Opcode::ALL.len(),
            any::<u32>(),
            any::<u32>(),
            [intensity(), intensity(), intensity()],
        )
            .prop_map(|(op, x, dx, values)| Instruction::from_parts(Opcode::ALL[op], x, dx, values))
    }

    proptest! {
        #[test]
        fn instructions_read_back_bit_for_bit(
            stream in proptest::collection::vec(instruction(), 0..40),
        ) {
            let mut packed = PackedStream::new();
            for i in &stream {
                packed.write(i).unwrap();
            }
            prop_assert_eq!(packed.len(), stream.len());
            let back: Vec<Instruction> = packed.iter().collect();
            prop_assert_eq!(back.len(), stream.len());
            for (a, b) in back.iter().zip(&stream) {
                // bit for bit: NaN payloads and signed zeros too
                prop_assert_eq!(a.op, b.op);
                prop_assert_eq!((a.x, a.dx), (b.x, b.dx));
                for (p, q) in a.values().iter().zip(&b.values()) {
                    let bits = |v: &Intensity| v.as_slice().iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                    prop_assert_eq!(bits(p), bits(q));
                }
            }
            packed.clear();
            prop_assert!(packed.is_empty());
            prop_assert_eq!(packed.iter().count(), 0);
        }
    }
}
