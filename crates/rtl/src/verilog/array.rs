//! The array: the instruction bus (`docs/TIMING.md`: one instruction at a time, issued
//! for its opcode's cycles, handed to processor 0 once issued and processor 0 is free),
//! the display's deadlines that gate each `Refresh`, and the chain of processors.

use super::{op_const, op_constants, Text, ARRAY_MODULE, PROCESSOR_MODULE};
use crate::design::{bits_for, Design};
use cwisim_isa::{Opcode, OperandKind};
use cwisim_xproc::Register;

/// Bits of a token's overflow count at the end of the chain: every visit's events.
pub(crate) fn overflow_count_bits(d: &Design) -> u32 {
    bits_for(d.events_per_visit().saturating_mul(u64::from(d.width)))
}

/// The array's ports, in the order the module declares them.
pub(crate) fn port_names(d: &Design) -> Vec<String> {
    let mut ports: Vec<String> = ["clk", "rst", "in_valid", "in_op"].map(String::from).into();
    if d.addressed() {
        ports.extend(["in_x".into(), "in_dx".into()]);
    }
    ports.extend(
        d.value_fields()
            .iter()
            .map(|(name, _)| format!("in_{name}")),
    );
    ports.extend(
        [
            "in_take",
            "cycle",
            "arrive",
            "refresh_at",
            "out_flat",
            "exit_valid",
        ]
        .map(String::from),
    );
    if d.order() >= 1 {
        ports.push("exit_overflows".into());
    }
    ports.push("idle".into());
    ports
}

/// An instance of the array named `name`, each port connected to what `connect` gives it
/// (an empty string leaves it open).
pub(crate) fn instance(d: &Design, name: &str, connect: &dyn Fn(&str) -> String, out: &mut Text) {
    let conns: Vec<String> = port_names(d)
        .iter()
        .map(|p| format!(".{p}({})", connect(p)))
        .collect();
    out.line(&format!("    {ARRAY_MODULE} {name} ("));
    out.line(&format!("        {}", conns.join(",\n        ")));
    out.line("    );");
}

/// Writes the array module.
pub(crate) fn write(d: &Design, out: &mut Text) {
    let n = d.channels as u32;
    let w = d.width;
    let (aw, cw, ow) = (d.skip_bits(), d.count_bits(), d.op_bits());
    let wa = d.bits(Register::Acc);
    let addressed = d.addressed();
    let fields = d.value_fields();
    let counting = d.order() >= 1;
    let ovw = overflow_count_bits(d);
    let ev_bits = bits_for(d.events_per_visit());
    let rw = bits_for(d.max_cost() - 1);
    let t = &d.timing;
    let row_bits = bits_for(t.lines_per_frame - 1);

    out.line(
        "// The array: the instruction bus, the display's deadlines, and the chain of processors.",
    );
    out.line(&format!("module {ARRAY_MODULE} ("));
    let mut ports = vec![
        "    input  wire clk".to_string(),
        "    input  wire rst".to_string(),
        "    // the Y-processor's next instruction, operands converted to the registers' formats"
            .to_string(),
        "    input  wire in_valid".to_string(),
        format!("    input  wire [{}:0] in_op", ow - 1),
    ];
    if addressed {
        ports.push(format!("    input  wire [{}:0] in_x", aw - 1));
        ports.push(format!("    input  wire [{}:0] in_dx", cw - 1));
    }
    for &(name, bits) in &fields {
        ports.push(format!("    input  wire [{}:0] in_{name}", bits * n - 1));
    }
    ports.push("    // the bus starts issuing it this cycle".into());
    ports.push("    output wire in_take".into());
    ports.push("    // the cycle count (0 in the first cycle after reset)".into());
    ports.push("    output reg  [63:0] cycle".into());
    ports.push("    // a token arrives at processor p (bit p) this cycle; a Refresh does".into());
    ports.push(format!("    output wire [{}:0] arrive", w - 1));
    ports.push(format!("    output wire [{}:0] refresh_at", w - 1));
    ports.push("    // every processor's output register (processor-major, then channel)".into());
    ports.push(format!("    output wire [{}:0] out_flat", wa * n * w - 1));
    ports.push(
        "    // a token leaves the last processor this cycle, with its overflow events".into(),
    );
    ports.push("    output wire exit_valid".into());
    if counting {
        ports.push(format!("    output wire [{}:0] exit_overflows", ovw - 1));
    }
    ports.push("    // nothing on the bus or in the chain".into());
    ports.push("    output wire idle".into());
    let real: Vec<usize> = (0..ports.len())
        .filter(|&k| !ports[k].trim_start().starts_with("//"))
        .collect();
    let last = *real.last().expect("ports");
    for (k, p) in ports.iter().enumerate() {
        if real.contains(&k) && k != last {
            out.line(&format!("{p},"));
        } else {
            out.line(p);
        }
    }
    out.line(");");
    op_constants(d, out, "    ");
    out.line(&format!("    localparam integer W = {w};"));
    out.blank();

    // the bus
    out.line("    // The instruction bus: one instruction at a time; `bus_remain` counts its issue cycles down.");
    out.line("    reg bus_busy;");
    out.line(&format!("    reg [{}:0] bus_remain;", rw - 1));
    out.line(&format!("    reg [{}:0] bus_op;", ow - 1));
    if addressed {
        out.line(&format!("    reg [{}:0] bus_skip;", aw - 1));
        out.line(&format!("    reg [{}:0] bus_count;", cw - 1));
    }
    for &(name, bits) in &fields {
        out.line(&format!("    reg [{}:0] bus_{name};", bits * n - 1));
    }
    out.line(&format!(
        "    wire [{}:0] leave;    // the token in processor p moves on this cycle",
        w - 1
    ));
    out.line(&format!(
        "    wire [{}:0] arrive_w; // a token arrives at processor p this cycle",
        w - 1
    ));
    out.line(&format!("    wire [{}:0] tok_valid;", w - 1));
    out.line(&format!(
        "    wire bus_issued = bus_busy && bus_remain == {rw}'d0;"
    ));
    out.line("    // processor 0 is free when empty or when its token moves on this cycle (tokens move first)");
    out.line("    wire p0_free = !tok_valid[0] || leave[0];");
    out.line("    wire bus_enter = bus_issued && p0_free;");
    out.line("    wire bus_free = !bus_busy || bus_enter;");
    out.blank();
    out.line("    // The display: a Refresh of scanline n >= 1 waits for the deadline of scanline n - 1,");
    out.line(&format!(
        "    // deadline(n) = (frame * ({} + {}) + row + 1) * {} (docs/TIMING.md).",
        t.lines_per_frame, t.vblank_lines, t.line_period
    ));
    out.line("    reg [63:0] refresh_gate;  // the gate of the next Refresh");
    out.line("    reg [63:0] next_deadline; // the deadline of the scanline the next Refresh ends");
    out.line(&format!("    reg [{}:0] row;", row_bits - 1));
    let period = t.line_period;
    let frame_step = period.saturating_add(t.vblank_lines.saturating_mul(period));
    out.line(&format!(
        "    wire is_refresh_in = in_op == {};",
        op_const(Opcode::Refresh)
    ));
    out.line("    wire gate_open = !is_refresh_in || cycle >= refresh_gate;");
    out.line("    assign in_take = in_valid && bus_free && gate_open;");
    out.blank();
    out.line("    // issue cycles of each opcode, minus one (the machine model's opcode_cycles and value_cycles)");
    out.line(&format!("    reg [{}:0] in_cost_less_one;", rw - 1));
    out.line("    always @(*) begin");
    out.line("        case (in_op)");
    for op in Opcode::ALL.iter().filter(|o| d.has(**o)) {
        out.line(&format!(
            "            {}: in_cost_less_one = {rw}'d{};",
            op_const(*op),
            t.cost[op.index()] - 1
        ));
    }
    out.line(&format!("            default: in_cost_less_one = {rw}'d0;"));
    out.line("        endcase");
    out.line("    end");
    if addressed {
        let ranged: Vec<String> = Opcode::ALL
            .iter()
            .filter(|o| {
                d.has(**o)
                    && o.operands()
                        .iter()
                        .any(|k| matches!(k, OperandKind::Count | OperandKind::Period))
            })
            .map(|o| format!("in_op == {}", op_const(*o)))
            .collect();
        out.line("    // opcodes without a dx operand address one processor: a range of 1");
        if ranged.is_empty() {
            out.line(&format!("    wire [{}:0] in_count = {cw}'d1;", cw - 1));
            out.line("    wire unused_dx = ^in_dx;");
        } else {
            out.line(&format!(
                "    wire [{}:0] in_count = ({}) ? in_dx : {cw}'d1;",
                cw - 1,
                ranged.join(" || ")
            ));
        }
    }
    out.blank();
    out.line("    always @(posedge clk) begin");
    out.line("        if (rst) begin");
    out.line("            cycle <= 64'd0;");
    out.line("            bus_busy <= 1'b0;");
    out.line(&format!("            bus_remain <= {rw}'d0;"));
    out.line("            refresh_gate <= 64'd0;");
    out.line(&format!("            next_deadline <= 64'd{period};"));
    out.line(&format!("            row <= {row_bits}'d0;"));
    out.line("        end else begin");
    out.line("            cycle <= cycle + 64'd1;");
    out.line("            if (in_take) begin");
    out.line("                bus_busy <= 1'b1;");
    out.line("                bus_remain <= in_cost_less_one;");
    out.line("                if (is_refresh_in) begin");
    out.line("                    refresh_gate <= next_deadline;");
    out.line(&format!(
        "                    if (row == {row_bits}'d{}) begin",
        t.lines_per_frame - 1
    ));
    out.line(&format!(
        "                        next_deadline <= next_deadline + 64'd{frame_step};"
    ));
    out.line(&format!("                        row <= {row_bits}'d0;"));
    out.line("                    end else begin");
    out.line(&format!(
        "                        next_deadline <= next_deadline + 64'd{period};"
    ));
    out.line(&format!(
        "                        row <= row + {row_bits}'d1;"
    ));
    out.line("                    end");
    out.line("                end");
    out.line("            end else if (bus_enter) bus_busy <= 1'b0;");
    out.line(&format!(
        "            else if (bus_busy && bus_remain != {rw}'d0) bus_remain <= bus_remain - {rw}'d1;"
    ));
    out.line("        end");
    out.line("    end");
    out.line("    always @(posedge clk) begin");
    out.line("        if (in_take) begin");
    out.line("            bus_op <= in_op;");
    if addressed {
        out.line("            bus_skip <= in_x;");
        out.line("            bus_count <= in_count;");
    }
    for &(name, _) in &fields {
        out.line(&format!("            bus_{name} <= in_{name};"));
    }
    out.line("        end");
    out.line("    end");
    out.blank();

    // the chain
    out.line("    // The chain: entry p of each chain_* vector is the token arriving at processor p; entry W leaves the array.");
    let chain = |out: &mut Text, name: &str, bits: u32, first: &str| {
        out.line(&format!(
            "    wire [{}:0] chain_{name};",
            bits * (w + 1) - 1
        ));
        out.line(&format!(
            "    assign chain_{name}[{}:0] = {first};",
            bits - 1
        ));
    };
    if w == 1 {
        out.line("    assign arrive_w = bus_enter;");
    } else {
        out.line(&format!(
            "    assign arrive_w = {{leave[{}:0], bus_enter}};",
            w - 2
        ));
    }
    chain(out, "op", ow, "bus_op");
    if addressed {
        chain(out, "skip", aw, "bus_skip");
        chain(out, "count", cw, "bus_count");
    }
    for &(name, bits) in &fields {
        chain(out, name, bits * n, &format!("bus_{name}"));
    }
    if counting {
        chain(out, "ovf", ovw, &format!("{ovw}'d0"));
    }
    out.line(&format!("    wire [{}:0] chain_is_refresh;", w - 1));
    out.line("    genvar p;");
    out.line("    generate");
    out.line("        for (p = 0; p < W; p = p + 1) begin : proc");
    if counting {
        out.line(&format!("            wire [{}:0] events;", ev_bits - 1));
    }
    out.line(&format!("            {PROCESSOR_MODULE} xp ("));
    let mut conns = vec![
        ".clk(clk)".to_string(),
        ".rst(rst)".into(),
        ".in_arrive(arrive_w[p])".into(),
        format!(".in_op(chain_op[p*{ow} +: {ow}])"),
    ];
    if addressed {
        conns.push(format!(".in_skip(chain_skip[p*{aw} +: {aw}])"));
        conns.push(format!(".in_count(chain_count[p*{cw} +: {cw}])"));
    }
    for &(name, bits) in &fields {
        let bits = bits * n;
        conns.push(format!(".in_{name}(chain_{name}[p*{bits} +: {bits}])"));
    }
    conns.push(".tok_valid(tok_valid[p])".into());
    conns.push(".tok_leave(leave[p])".into());
    conns.push(format!(".tok_op(chain_op[(p+1)*{ow} +: {ow}])"));
    if addressed {
        conns.push(format!(".tok_skip(chain_skip[(p+1)*{aw} +: {aw}])"));
        conns.push(format!(".tok_count(chain_count[(p+1)*{cw} +: {cw}])"));
    }
    for &(name, bits) in &fields {
        let bits = bits * n;
        conns.push(format!(".tok_{name}(chain_{name}[(p+1)*{bits} +: {bits}])"));
    }
    conns.push(format!(".out(out_flat[p*{} +: {}])", wa * n, wa * n));
    if counting {
        conns.push(".events(events)".into());
    }
    for (k, c) in conns.iter().enumerate() {
        let sep = if k + 1 == conns.len() { "" } else { "," };
        out.line(&format!("                {c}{sep}"));
    }
    out.line("            );");
    if counting {
        out.line("            // a diagnostic count of the token's overflow events, carried beside it (not part of a processor)");
        out.line(&format!("            reg [{}:0] ovf;", ovw - 1));
        out.line("            always @(posedge clk) begin");
        let ext = if ovw > ev_bits {
            format!("{{{}'d0, events}}", ovw - ev_bits)
        } else {
            "events".to_string()
        };
        out.line(&format!(
            "                if (arrive_w[p]) ovf <= chain_ovf[p*{ovw} +: {ovw}] + {ext};"
        ));
        out.line("            end");
        out.line(&format!(
            "            assign chain_ovf[(p+1)*{ovw} +: {ovw}] = ovf;"
        ));
    }
    out.line(&format!(
        "            assign chain_is_refresh[p] = chain_op[p*{ow} +: {ow}] == {};",
        op_const(Opcode::Refresh)
    ));
    out.line("        end");
    out.line("    endgenerate");
    out.line("    assign arrive = arrive_w;");
    out.line("    assign refresh_at = arrive & chain_is_refresh;");
    out.line(&format!("    assign exit_valid = leave[{}];", w - 1));
    if counting {
        out.line(&format!(
            "    assign exit_overflows = chain_ovf[W*{ovw} +: {ovw}];"
        ));
    }
    out.line("    assign idle = !bus_busy && ~|tok_valid;");
    // the last token fields leave the array unused
    let mut leftovers = vec![format!("chain_op[W*{ow} +: {ow}]")];
    if addressed {
        leftovers.push(format!("chain_skip[W*{aw} +: {aw}]"));
        leftovers.push(format!("chain_count[W*{cw} +: {cw}]"));
    }
    for &(name, bits) in &fields {
        let bits = bits * n;
        leftovers.push(format!("chain_{name}[W*{bits} +: {bits}]"));
    }
    out.line(&format!(
        "    wire unused_leaving = ^{{{}}};",
        leftovers.join(", ")
    ));
    out.line("endmodule");
    out.blank();
}
