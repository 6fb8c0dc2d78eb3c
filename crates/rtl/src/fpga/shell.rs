//! The I/O shell: the array wrapped for a chip's pins. The array's ports are as wide as
//! its instruction word and its whole scanline (379 I/O for 16 processors of gouraud's
//! format, where a package has 256 at most); the shell brings the instruction stream in
//! and the scanlines out through narrow ports, with a fixed latency:
//!
//! * **In**: `s_data` carries [`Shell::beat_bits`] bits of the instruction word per beat
//!   (`s_valid` and `s_ready`, a beat is taken in a cycle when both are high), least
//!   significant first, [`Shell::beats`] beats a word. A complete word waits in a staging
//!   register (`s_ready` low) until the hold register, which offers it to the array
//!   ([`crate::verilog::ARRAY_MODULE`]'s `in_valid`) until the bus takes it, is free: the
//!   next word's beats come in while the bus issues the last. The array is held in reset
//!   until the first word is in the hold register: its cycle 0 (the stepped engine's) is
//!   the shell's cycle [`Shell::start_cycle`] when the beats come one a cycle from the
//!   shell's cycle 0 (the first after reset), [`INPUT_LATENCY`] cycles after the first
//!   word's last beat.
//! * **Out**: each scanline, one value (one channel of one processor's output register,
//!   processor-major) per cycle on `m_data` with `m_valid`, `m_last` on its last value —
//!   the first [`OUTPUT_LATENCY`] cycles after the Refresh token arrives at the last
//!   processor (the cycle the array's `refresh_at` has its top bit set). `m_overrun`
//!   (sticky) says a Refresh reached processor 0 while a scanline was still going out.
//!
//! The layout of the word is [`Shell::word_fields`]: the opcode in the low bits, then the
//! operands the design carries, in the array's own formats (what [`crate::stimulus`]
//! writes).

use crate::design::{bits_for, BusTiming, Design};
use crate::error::RtlError;
use crate::verilog::Text;
use cwisim_xproc::Register;

/// The shell's module (the chip's top level).
pub const SHELL_MODULE: &str = "cwisim_fpga";

/// Cycles from the Refresh token's arrival at the last processor (the array's
/// `refresh_at[W-1]`) to the scanline's first value on `m_data` (`m_valid` high): one
/// for the last processor's output register, one to start the serializer, one for the
/// output register.
pub const OUTPUT_LATENCY: u64 = 3;

/// Cycles from the cycle whose clock edge takes an instruction word's last beat to the
/// first cycle the array sees it (`in_valid`), when the hold register is free: one in
/// the staging register, one in the hold register.
pub const INPUT_LATENCY: u64 = 2;

/// The shell of one design, with its input port's width.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shell {
    /// Bits of the instruction word taken per beat.
    pub beat_bits: u32,
}

impl Default for Shell {
    fn default() -> Shell {
        Shell { beat_bits: 8 }
    }
}

impl Shell {
    /// The instruction word's fields, low bits first: name (the array's input port, less
    /// its `in_`) and bits.
    pub fn word_fields(d: &Design) -> Vec<(String, u32)> {
        let n = d.channels as u32;
        let mut f = vec![("op".to_string(), d.op_bits())];
        if d.addressed() {
            f.push(("x".into(), d.skip_bits()));
            f.push(("dx".into(), d.count_bits()));
        }
        for (name, bits) in d.value_fields() {
            f.push((name.to_string(), bits * n));
        }
        f
    }

    /// Bits of the instruction word.
    pub fn word_bits(d: &Design) -> u32 {
        Shell::word_fields(d).iter().map(|(_, b)| b).sum()
    }

    /// Beats per instruction word.
    pub fn beats(&self, d: &Design) -> u32 {
        Shell::word_bits(d).div_ceil(self.beat_bits)
    }

    /// The shell's cycle that is the array's cycle 0 when the first word's beats come one a
    /// cycle from the shell's cycle 0: its last beat's cycle and [`INPUT_LATENCY`]. The
    /// scanline the stepped engine has leave the last processor with its Refresh
    /// arriving there at cycle `a` comes out from the shell's cycle `start_cycle + a +`
    /// [`OUTPUT_LATENCY`], as long as the beats keep up with the bus.
    pub fn start_cycle(&self, d: &Design) -> u64 {
        u64::from(self.beats(d)) - 1 + INPUT_LATENCY
    }

    /// `machine` with every opcode's word cost (`opcode_cycles`) raised to at least the
    /// beats of a word and one (the port's best: a word every beats + 1 cycles): a machine whose bus the shell's input port keeps up with, so that
    /// the array through the shell runs cycle for cycle as the stepped engine says (with a
    /// narrower port the bus can wait for a word, and the port's bandwidth becomes part
    /// of the timing).
    pub fn paced(&self, d: &Design, machine: &cwisim_xproc::Machine) -> cwisim_xproc::Machine {
        let mut m = machine.clone();
        // a word every beats + 1 cycles at best: its beats, and a cycle staged before the
        // hold register takes it
        let cycles = self.beats(d) + 1;
        for op in cwisim_isa::Opcode::ALL {
            let c = m.opcode_cycles.get(*op);
            m.opcode_cycles.set(*op, c.max(cycles));
        }
        m
    }

    /// Design `d` (of a stream with `header`) and `machine` paced for the shell's port
    /// ([`Shell::paced`]): the machine, and the design with the bus timing it gives.
    pub fn pace(
        &self,
        d: &Design,
        machine: &cwisim_xproc::Machine,
        header: &cwisim_isa::TraceHeader,
    ) -> Result<(Design, cwisim_xproc::Machine), RtlError> {
        let machine = self.paced(d, machine);
        let timing = BusTiming::new(&machine, header)?;
        let paced = Design::new(d.format, d.opcodes.clone(), d.width, d.channels, timing)?;
        Ok((paced, machine))
    }

    /// Bits of one output value (the accumulator's format).
    pub fn value_bits(d: &Design) -> u32 {
        d.bits(Register::Acc)
    }

    /// The package pins the shell uses: clock, reset, the input port and its handshake,
    /// the output value with its valid, last and overrun.
    pub fn pins(&self, d: &Design) -> u32 {
        2 + self.beat_bits + 2 + Shell::value_bits(d) + 3
    }

    /// The shell's Verilog (module [`SHELL_MODULE`], instantiating the array of
    /// [`crate::verilog::design`], which goes in the same synthesis).
    pub fn verilog(&self, d: &Design) -> String {
        let mut v = Text::new();
        crate::verilog::header(
            d,
            &mut v,
            "The CWI X-processor array's I/O shell for an FPGA",
        );
        v.line(&format!(
            "// instruction word: {} bits in {} beats of {}; scanline values of {} bits out, one a cycle",
            Shell::word_bits(d),
            self.beats(d),
            self.beat_bits,
            Shell::value_bits(d)
        ));
        v.line("// The array's ports the shell does not use are left open, hence:");
        v.line("// verilator lint_off DECLFILENAME");
        v.line("// verilator lint_off PINCONNECTEMPTY");
        v.line("`timescale 1ns / 1ns");
        v.blank();
        let b = self.beat_bits;
        let k = self.beats(d);
        let iw = Shell::word_bits(d);
        let wa = Shell::value_bits(d);
        let w = d.width;
        let n = d.channels as u32;
        let values = w * n;
        let kb = bits_for(u64::from(k.max(2) - 1));
        let ib = bits_for(u64::from(values));
        v.line(&format!("module {SHELL_MODULE} ("));
        v.line("    input  wire clk,");
        v.line("    input  wire rst,");
        v.line("    // the instruction word, least significant beat first");
        v.line(&format!("    input  wire [{}:0] s_data,", b - 1));
        v.line("    input  wire s_valid,");
        v.line("    output wire s_ready,");
        v.line("    // each scanline's values, processor-major then channel, one a cycle");
        v.line(&format!("    output reg  [{}:0] m_data,", wa - 1));
        v.line("    output reg  m_valid,");
        v.line("    output reg  m_last,");
        v.line("    output reg  m_overrun");
        v.line(");");
        v.line(&format!(
            "    reg [{}:0] word;   // the beats taken, the newest at the top",
            k * b - 1
        ));
        v.line(&format!("    reg [{}:0] beat;", kb - 1));
        v.line("    reg staged;        // `word` is complete, waiting for the hold register");
        v.line(&format!(
            "    reg [{}:0] hold;   // the word offered to the array",
            iw - 1
        ));
        v.line("    reg held;");
        v.line("    reg started;       // the first word reached the array: it runs from then on");
        v.line("    wire take;         // the array's bus takes the held word this cycle");
        v.line("    wire move = staged && (!held || take);");
        v.line("    assign s_ready = !staged;");
        v.line("    always @(posedge clk) begin");
        v.line("        if (rst) begin");
        v.line(&format!("            beat <= {kb}'d0;"));
        v.line("            staged <= 1'b0;");
        v.line("            held <= 1'b0;");
        v.line("            started <= 1'b0;");
        v.line("        end else begin");
        v.line("            if (s_valid && !staged) begin");
        if k == 1 {
            v.line("                staged <= 1'b1;");
        } else {
            v.line(&format!(
                "                beat <= (beat == {kb}'d{}) ? {kb}'d0 : beat + {kb}'d1;",
                k - 1
            ));
            v.line(&format!(
                "                if (beat == {kb}'d{}) staged <= 1'b1;",
                k - 1
            ));
        }
        v.line("            end else if (move) staged <= 1'b0;");
        v.line("            if (move) begin");
        v.line("                held <= 1'b1;");
        v.line("                started <= 1'b1;");
        v.line("            end else if (take) held <= 1'b0;");
        v.line("        end");
        v.line("    end");
        v.line("    always @(posedge clk) begin");
        if k == 1 {
            v.line("        if (s_valid && !staged) word <= s_data;");
        } else {
            v.line(&format!(
                "        if (s_valid && !staged) word <= {{s_data, word[{}:{b}]}};",
                k * b - 1
            ));
        }
        v.line(&format!("        if (move) hold <= word[{}:0];", iw - 1));
        v.line("    end");
        if k * b > iw {
            v.line(&format!(
                "    wire unused_pad = ^word[{}:{iw}]; // the last beat's spare bits",
                k * b - 1
            ));
        }
        v.blank();
        v.line(&format!("    wire [{}:0] refresh_at;", w - 1));
        v.line(&format!("    wire [{}:0] out_flat;", wa * n * w - 1));
        v.line("    wire unused_refresh_at = ^refresh_at;");
        let mut hold_bits = std::collections::BTreeMap::new();
        let mut at = 0;
        for (name, bits) in Shell::word_fields(d) {
            hold_bits.insert(
                format!("in_{name}"),
                format!("hold[{}:{at}]", at + bits - 1),
            );
            at += bits;
        }
        let connect = |port: &str| match port {
            "clk" | "refresh_at" | "out_flat" => port.to_string(),
            "rst" => "rst || !started".into(),
            "in_valid" => "held".into(),
            "in_take" => "take".into(),
            _ => hold_bits.get(port).cloned().unwrap_or_default(),
        };
        crate::verilog::instance(d, "array", &connect, &mut v);
        v.blank();
        v.line("    // the scanline out: started the cycle after the last processor's output is written");
        v.line(
            "    reg pending;       // the last processor's output register holds the new scanline",
        );
        v.line("    reg busy;");
        v.line(&format!("    reg [{}:0] index;", ib - 1));
        v.line("    always @(posedge clk) begin");
        v.line("        if (rst) begin");
        v.line("            pending <= 1'b0;");
        v.line("            busy <= 1'b0;");
        v.line(&format!("            index <= {ib}'d0;"));
        v.line("            m_valid <= 1'b0;");
        v.line("            m_last <= 1'b0;");
        v.line("            m_overrun <= 1'b0;");
        v.line("        end else begin");
        v.line(&format!("            pending <= refresh_at[{}];", w - 1));
        v.line("            m_valid <= busy;");
        v.line(&format!(
            "            m_last <= busy && index == {ib}'d{};",
            values - 1
        ));
        v.line("            if (busy && refresh_at[0]) m_overrun <= 1'b1;");
        v.line("            if (pending) begin");
        v.line("                busy <= 1'b1;");
        v.line(&format!("                index <= {ib}'d0;"));
        v.line("            end else if (busy) begin");
        v.line(&format!(
            "                if (index == {ib}'d{}) busy <= 1'b0;",
            values - 1
        ));
        v.line(&format!("                index <= index + {ib}'d1;"));
        v.line("            end");
        v.line("        end");
        v.line("    end");
        v.line("    // the values as a memory, read by index: a multiplexer tree, not a shifter");
        v.line(&format!(
            "    wire [{}:0] value [0:{}];",
            wa - 1,
            values - 1
        ));
        v.line("    genvar g;");
        v.line("    generate");
        v.line(&format!(
            "        for (g = 0; g < {values}; g = g + 1) begin : values"
        ));
        v.line(&format!(
            "            assign value[g] = out_flat[g*{wa} +: {wa}];"
        ));
        v.line("        end");
        v.line("    endgenerate");
        v.line("    always @(posedge clk) begin");
        if values.is_power_of_two() && (1u64 << (ib - 1)) == u64::from(values) {
            // the index counts one past the last value only to stop: its top bit is then set
            v.line(&format!(
                "        m_data <= value[index[{}:0]];",
                ib.max(2) - 2
            ));
        } else {
            v.line("        m_data <= value[index];");
        }
        v.line("    end");
        v.line("endmodule");
        v.into_string()
    }
}
