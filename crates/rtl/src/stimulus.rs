//! A trace as the testbench's stimulus: one line per instruction, its operands converted
//! into the registers' formats by `cwisim_xproc`'s fixed-point model — the Y-processor's
//! job, done once when an instruction enters the array (`docs/ISA.md`, "Operand
//! conversion") — and the conversions' overflow events, which the array never sees.

use crate::design::Design;
use crate::error::RtlError;
use cwisim_isa::{Instruction, Opcode, OperandKind, TraceHeader};
use cwisim_xproc::{Arith, FixedArith, Register};
use std::io::Write;

/// What converting a trace counted.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Conversions {
    /// Overflow events of the operand conversions, per scanline (instructions after the
    /// last `Refresh` are in a last, unfinished entry).
    pub overflows_per_line: Vec<u64>,
}

/// Checks that `header` is the design's array.
pub fn check_header(d: &Design, header: &TraceHeader) -> Result<(), RtlError> {
    if header.width != d.width || header.channel_count() != d.channels {
        return Err(RtlError::Settings(format!(
            "the trace is {} processors wide with {} channel(s); the design has {} and {}",
            header.width,
            header.channel_count(),
            d.width,
            d.channels
        )));
    }
    Ok(())
}

/// `raw`'s two's-complement bits in `bits` bits, as hex.
fn hex(raw: i64, bits: u32) -> String {
    let mask = if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    };
    format!("{:x}", (raw as u64) & mask)
}

/// Writes the stimulus of `trace` for design `d` to `out`: a comment line, then one line
/// per instruction, hex words for `$readmemh`. Every instruction must be one the design
/// implements and fit its array.
pub fn write(
    d: &Design,
    header: &TraceHeader,
    trace: &[Instruction],
    out: &mut dyn Write,
) -> Result<Conversions, RtlError> {
    check_header(d, header)?;
    let arith = FixedArith::new(&d.format)?;
    let io = |e| RtlError::io("stimulus", e);
    writeln!(
        out,
        "// {} instructions for the testbench of: {}",
        trace.len(),
        d.summary()
    )
    .map_err(io)?;
    let mut conv = Conversions {
        overflows_per_line: vec![0],
    };
    let addressed = d
        .opcodes
        .iter()
        .any(|o| o.operands().contains(&OperandKind::X));
    let carries = [d.carries_v(), d.carries_d(), d.carries_dd()];
    let vw = d.v_bits();
    for (index, instr) in trace.iter().enumerate() {
        let bad = |message: String| RtlError::Trace {
            index: index as u64,
            instruction: instr.to_string(),
            message,
        };
        if !d.has(instr.op) {
            return Err(bad(format!(
                "the design leaves out {}: generate it for this trace (--for) or with every opcode",
                instr.op
            )));
        }
        instr
            .check(header)
            .map_err(|e| bad(format!("does not fit the array: {}", e.message())))?;
        let mut line = format!("{:x}", instr.op.code());
        if addressed {
            let dx = if instr.op.operands().contains(&OperandKind::Period) {
                // a period at least the width reaches `x` alone, as the width does
                instr.dx.min(d.width)
            } else if instr.op.operands().contains(&OperandKind::Count) {
                instr.dx
            } else {
                0
            };
            line.push_str(&format!(" {:x} {:x}", instr.x, dx));
        }
        let mut ovf = 0u64;
        for (slot, carried) in carries.iter().enumerate() {
            if !carried {
                continue;
            }
            let kind = [OperandKind::I, OperandKind::DI, OperandKind::DDI][slot];
            let present = instr.op.operands().contains(&kind);
            let (reg, bits) = if instr.op == Opcode::Eval0 && slot == 0 {
                (Register::Acc, d.bits(Register::Acc))
            } else {
                let reg = Register::of_slot(slot);
                (reg, d.bits(reg))
            };
            let values = instr.value(slot);
            for c in 0..d.channels {
                let raw = match values.get(c) {
                    Some(x) if present => arith.operand(reg, *x, &mut ovf),
                    _ => 0,
                };
                let field = if slot == 0 { vw } else { bits };
                line.push(' ');
                line.push_str(&hex(raw, bits.min(field)));
            }
        }
        writeln!(out, "{line}").map_err(io)?;
        let last = conv.overflows_per_line.len() - 1;
        conv.overflows_per_line[last] += ovf;
        if instr.op == Opcode::Refresh {
            conv.overflows_per_line.push(0);
        }
    }
    Ok(conv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_is_the_twos_complement_in_the_width() {
        assert_eq!(hex(-1, 4), "f");
        assert_eq!(hex(-2, 64), "fffffffffffffffe");
        assert_eq!(hex(5, 12), "5");
    }
}
