//! What both co-simulation testbenches write — the array's ([`super::testbench`]) and the
//! FPGA shell's (`crate::fpga::cosim`): the clock and the reset, the layout of a stimulus
//! line, and the lines that end the simulation.

use super::Text;
use crate::design::Design;

/// The clock (a period of 10 time units) and the reset, high from the start.
pub(crate) fn clock_and_reset(v: &mut Text) {
    v.line("    reg clk = 1'b0;");
    v.line("    reg rst = 1'b1;");
    v.line("    always #5 clk = ~clk;");
}

/// The parameters set at compile time (the instructions of the stimulus and the cycle
/// limit) and the words of a stimulus line, `fields`.
pub(crate) fn stimulus_parameters(v: &mut Text, fields: usize) {
    v.line("    parameter INSTRUCTIONS = 1;");
    v.line("    parameter CYCLE_LIMIT = 1000;");
    v.line(&format!("    localparam integer FIELDS = {fields};"));
}

/// The hex words of one stimulus line (`crate::stimulus::write`), in order: the array's
/// input each is for (a port, or one channel's slice of a value port) and its bits.
pub(crate) fn stimulus_words(d: &Design) -> Vec<(String, u32)> {
    let mut words = vec![("in_op".to_string(), d.op_bits())];
    if d.addressed() {
        words.push(("in_x".into(), d.skip_bits()));
        words.push(("in_dx".into(), d.count_bits()));
    }
    for (field, bits) in d.value_fields() {
        for c in 0..d.channels as u32 {
            words.push((
                format!("in_{field}[{}:{}]", (c + 1) * bits - 1, c * bits),
                bits,
            ));
        }
    }
    words
}

/// The lines that end the simulation when `condition` holds: `TAG cycle` written to the
/// dump, the dump closed (inside an `always` block).
pub(crate) fn finish_when(v: &mut Text, condition: &str, tag: char) {
    v.line(&format!("        if ({condition}) begin"));
    v.line(&format!(
        "            $fwrite(dump, \"{tag} %0d\\n\", cycle);"
    ));
    v.line("            $fclose(dump);");
    v.line("            $finish;");
    v.line("        end");
}
