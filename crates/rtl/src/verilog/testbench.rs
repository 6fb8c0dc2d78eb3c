//! The co-simulation testbench: it plays the Y-processor, reading the stimulus file
//! (`crate::stimulus`) one instruction at a time as the bus takes them, and writes what
//! the array does to a dump file (`crate::dump`): the cycle each token arrives at each
//! watched processor, each processor's output as a `Refresh` passes it, each token's
//! overflow events as it leaves the chain, and the cycle the array fell idle.

use super::array::{instance, overflow_count_bits};
use super::{bench, header, Text, TESTBENCH_MODULE};
use crate::design::Design;
use cwisim_xproc::Register;

/// The stimulus file the testbench reads, in its working directory.
pub const STIMULUS_FILE: &str = "stimulus.hex";
/// The dump file it writes there.
pub const DUMP_FILE: &str = "dump.txt";

/// The processors whose token arrivals the testbench reports.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Watch(Vec<u32>);

impl Watch {
    /// Processors `ps` (sorted, without repeats; those outside the array are dropped).
    pub fn new(ps: impl IntoIterator<Item = u32>, width: u32) -> Watch {
        let mut v: Vec<u32> = ps.into_iter().filter(|p| *p < width).collect();
        v.sort_unstable();
        v.dedup();
        Watch(v)
    }

    /// The default: the first, the middle and the last processor.
    pub fn ends(width: u32) -> Watch {
        Watch::new([0, width / 2, width.saturating_sub(1)], width)
    }

    /// Every processor.
    pub fn all(width: u32) -> Watch {
        Watch::new(0..width, width)
    }

    /// The processors, in order.
    pub fn processors(&self) -> &[u32] {
        &self.0
    }

    /// `all`, or processors separated by commas (`0,200,399`), each in the array.
    pub fn parse(list: &str, width: u32) -> Result<Watch, String> {
        if list.trim() == "all" {
            return Ok(Watch::all(width));
        }
        let ps = list
            .split(',')
            .map(|p| {
                p.trim()
                    .parse::<u32>()
                    .ok()
                    .filter(|p| *p < width)
                    .ok_or_else(|| {
                        format!(
                            "`{}` is not a processor of the array (0 to {})",
                            p.trim(),
                            width.saturating_sub(1)
                        )
                    })
            })
            .collect::<Result<Vec<u32>, _>>()?;
        Ok(Watch::new(ps, width))
    }
}

/// The testbench's Verilog for `design`, reporting arrivals at `watch`.
pub fn testbench(d: &Design, watch: &Watch) -> String {
    let n = d.channels as u32;
    let w = d.width;
    let (aw, cw, ow) = (d.skip_bits(), d.count_bits(), d.op_bits());
    let wa = d.bits(Register::Acc);
    let addressed = d.addressed();
    let counting = d.order() >= 1;
    let mut v = Text::new();
    header(
        d,
        &mut v,
        "Co-simulation testbench of the CWI X-processor array",
    );
    v.line(&format!(
        "// Reads {STIMULUS_FILE} ($readmemh: one instruction a line: op, x, dx, then the value fields, hex) and writes"
    ));
    v.line(&format!(
        "// {DUMP_FILE}: `A p cycle` (a token arrives at watched processor p), `O p cycle acc…` (a Refresh moved p's"
    ));
    v.line("// accumulators out), `X cycle overflows` (a token left the chain), `E cycle` (idle: done), `T cycle` (the");
    v.line("// cycle limit was reached).");
    v.line("`timescale 1ns / 1ns");
    v.line(&format!("module {TESTBENCH_MODULE};"));
    bench::clock_and_reset(&mut v);
    v.line("    reg in_valid = 1'b0;");
    v.line(&format!("    reg [{}:0] in_op = {ow}'d0;", ow - 1));
    if addressed {
        v.line(&format!("    reg [{}:0] in_x = {aw}'d0;", aw - 1));
        v.line(&format!("    reg [{}:0] in_dx = {cw}'d0;", cw - 1));
    }
    let values = d.value_fields();
    for &(field, bits) in &values {
        v.line(&format!(
            "    reg [{}:0] in_{field} = {}'d0;",
            bits * n - 1,
            bits * n
        ));
    }
    v.line("    wire in_take;");
    v.line("    wire [63:0] cycle;");
    v.line(&format!("    wire [{}:0] arrive;", w - 1));
    v.line(&format!("    wire [{}:0] refresh_at;", w - 1));
    v.line(&format!("    wire [{}:0] out_flat;", wa * n * w - 1));
    v.line("    wire exit_valid;");
    let ovw = overflow_count_bits(d);
    if counting {
        v.line(&format!("    wire [{}:0] exit_overflows;", ovw - 1));
    }
    v.line("    wire idle;");
    instance(d, "dut", &|port| port.to_string(), &mut v);
    v.blank();
    // the reader
    let reads = bench::stimulus_words(d);
    v.line("    // the stimulus: INSTRUCTIONS instructions of FIELDS hex words each (set at compile time:");
    v.line("    // iverilog -P cwisim_tb.INSTRUCTIONS=…, verilator -GINSTRUCTIONS=…)");
    bench::stimulus_parameters(&mut v, reads.len());
    v.line("    reg [63:0] words [0:INSTRUCTIONS*FIELDS-1];");
    v.line("    integer dump, next_index;");
    v.line("    // the next instruction onto the bus's inputs (or none left)");
    v.line("    task next;");
    v.line("        begin");
    v.line("            if (next_index == INSTRUCTIONS) in_valid <= 1'b0;");
    v.line("            else begin");
    v.line("                in_valid <= 1'b1;");
    for (k, (target, bits)) in reads.iter().enumerate() {
        v.line(&format!(
            "                {target} <= words[next_index*FIELDS+{k}][{}:0];",
            bits - 1
        ));
    }
    v.line("                next_index = next_index + 1;");
    v.line("            end");
    v.line("        end");
    v.line("    endtask");
    v.line("    initial begin");
    v.line(&format!("        $readmemh(\"{STIMULUS_FILE}\", words);"));
    v.line(&format!("        dump = $fopen(\"{DUMP_FILE}\", \"w\");"));
    v.line("        next_index = 0;");
    v.line("        next;");
    v.line("        @(posedge clk);");
    v.line("        @(posedge clk);");
    v.line("        rst <= 1'b0;");
    v.line("    end");
    v.line("    always @(posedge clk) if (!rst && in_take) next;");
    v.blank();
    v.line("    // what the array does, sampled in the middle of each cycle");
    v.line("    always @(negedge clk) if (!rst) begin");
    for p in watch.processors() {
        v.line(&format!(
            "        if (arrive[{p}]) $fwrite(dump, \"A {p} %0d\\n\", cycle);"
        ));
    }
    if counting {
        v.line("        if (exit_valid) $fwrite(dump, \"X %0d %0d\\n\", cycle, exit_overflows);");
    } else {
        v.line("        if (exit_valid) $fwrite(dump, \"X %0d 0\\n\", cycle);");
    }
    bench::finish_when(&mut v, "!in_valid && idle", 'E');
    bench::finish_when(&mut v, "cycle >= CYCLE_LIMIT", 'T');
    v.line("    end");
    v.line("    // each processor's output registers, the cycle after a Refresh moved them out");
    v.line("    genvar gp;");
    v.line("    generate");
    v.line(&format!(
        "        for (gp = 0; gp < {w}; gp = gp + 1) begin : watch_out"
    ));
    v.line("            reg pending = 1'b0;");
    v.line("            always @(negedge clk) begin");
    let fmt = vec!["%h"; n as usize].join(" ");
    let outs: Vec<String> = (0..n)
        .map(|c| format!("out_flat[(gp*{n}+{c})*{wa} +: {wa}]"))
        .collect();
    v.line(&format!(
        "                if (pending) $fwrite(dump, \"O %0d %0d {fmt}\\n\", gp, cycle - 64'd1, {});",
        outs.join(", ")
    ));
    v.line("                pending = !rst && refresh_at[gp];");
    v.line("            end");
    v.line("        end");
    v.line("    endgenerate");
    v.line("endmodule");
    v.into_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn watch_lists_parse_and_refuse_processors_outside_the_array() {
        assert_eq!(Watch::parse("3, 1,3", 8).unwrap().processors(), &[1, 3]);
        assert_eq!(Watch::parse("all", 3).unwrap().processors(), &[0, 1, 2]);
        assert_eq!(Watch::ends(9).processors(), &[0, 4, 8]);
        assert_eq!(Watch::ends(1).processors(), &[0]);
        assert_eq!(
            Watch::parse("1,8", 8).unwrap_err(),
            "`8` is not a processor of the array (0 to 7)"
        );
        assert!(Watch::parse("x", 8).is_err());
        assert!(Watch::parse("", 8).is_err());
    }
}
