//! The three adders of the forward-differencing chain as Verilog modules, from the
//! fixed-point model's rule (`cwisim_xproc::arith`, `docs/ISA.md` "Adders"): the exact sum
//! at the finer of the two fraction counts, truncated toward −∞ into the destination's
//! format (the source's low bits dropped), then the destination's overflow policy.

use super::Text;
use cwisim_xproc::{Overflow, Q};

/// One adder `dst ← dst + src`: its module name and formats.
pub(crate) struct AdderSpec {
    /// The module's name.
    pub name: &'static str,
    /// What it computes, for the comment.
    pub what: &'static str,
    /// The destination (first operand and result).
    pub dst: Q,
    /// The source (second operand).
    pub src: Q,
    /// The destination's overflow policy.
    pub overflow: Overflow,
}

impl AdderSpec {
    /// `(right, left)`: the source is aligned to the destination's fraction bits by
    /// `(src >>> right) << left` (one of them is 0), as `cwisim_xproc`'s `Adder`.
    fn shifts(&self) -> (u32, u32) {
        let (fd, fs) = (self.dst.frac_bits, self.src.frac_bits);
        (fs.saturating_sub(fd), fd.saturating_sub(fs))
    }

    /// Bits of the exact sum: one more than the wider of the destination and the
    /// aligned source.
    pub(crate) fn sum_bits(&self) -> u32 {
        let (right, left) = self.shifts();
        self.dst.width().max(self.src.width() - right + left) + 1
    }

    /// Writes the module.
    pub(crate) fn write(&self, v: &mut Text) {
        let (wd, ws) = (self.dst.width(), self.src.width());
        let (right, left) = self.shifts();
        let sw = self.sum_bits();
        let kept = ws - right;
        v.line(&format!(
            "// {}: Q{} + Q{} -> Q{}, {} on overflow",
            self.what, self.dst, self.src, self.dst, self.overflow
        ));
        v.line(&format!(
            "// b aligned to a's {} fraction bits: its {right} low bit(s) dropped (truncation toward -inf), {left} zero bit(s) appended; the sum exact in {sw} bits.",
            self.dst.frac_bits
        ));
        v.line(&format!("module {} (", self.name));
        v.line(&format!("    input  wire [{}:0] a,", wd - 1));
        v.line(&format!("    input  wire [{}:0] b,", ws - 1));
        v.line(&format!("    output wire [{}:0] sum,", wd - 1));
        v.line("    output wire overflow");
        v.line(");");
        v.line(&format!(
            "    wire [{}:0] a_ext = {{{{{}{{a[{}]}}}}, a}};",
            sw - 1,
            sw - wd,
            wd - 1
        ));
        let tail = if left > 0 {
            format!(", {left}'b0")
        } else {
            String::new()
        };
        v.line(&format!(
            "    wire [{}:0] b_aligned = {{{{{}{{b[{}]}}}}, b[{}:{}]{tail}}};",
            sw - 1,
            sw - (kept + left),
            ws - 1,
            ws - 1,
            right
        ));
        if right > 0 {
            v.line(&format!(
                "    wire unused_dropped_bits = ^b[{}:0];",
                right - 1
            ));
        }
        v.line(&format!(
            "    wire [{}:0] exact = a_ext + b_aligned;",
            sw - 1
        ));
        v.line(&format!(
            "    // in the destination's range iff bits {}..{} are all equal",
            sw - 1,
            wd - 1
        ));
        v.line(&format!(
            "    wire fits = exact[{}:{}] == {{{}{{exact[{}]}}}};",
            sw - 1,
            wd - 1,
            sw - wd + 1,
            sw - 1
        ));
        v.line("    assign overflow = !fits;");
        match self.overflow {
            Overflow::Wrap => {
                v.line(&format!(
                    "    assign sum = exact[{}:0]; // wrap: two's complement modulo 2^{wd}",
                    wd - 1
                ));
            }
            Overflow::Saturate => {
                v.line(&format!(
                    "    assign sum = fits ? exact[{}:0] : exact[{}] ? {} : {}; // saturate",
                    wd - 1,
                    sw - 1,
                    super::binary(wd, true),
                    super::binary(wd, false)
                ));
            }
        }
        v.line("endmodule");
        v.blank();
    }
}
