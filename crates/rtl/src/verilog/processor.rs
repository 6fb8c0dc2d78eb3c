//! One X-processor: its registers and flags (`docs/ISA.md`, "The processor"), what a
//! token does in it (the semantics of `cwisim_xproc`'s `Processor::act`), and the stage
//! of the systolic chain that holds the token for a hop (`docs/TIMING.md`).
//!
//! Where the token acts is found without comparators against the processor's number:
//! a token carries `skip`, the processors before its first one, and `count`, the
//! processors left in its range (a `SetP*`'s period); each processor counts them down
//! as the token passes, so every processor is the same circuit.

use super::{op_const, op_wire, Text, PROCESSOR_MODULE};
use crate::design::{bits_for, Design};
use cwisim_isa::Opcode;
use cwisim_xproc::Register;
use std::collections::BTreeSet;

/// The decode wires an expression refers to, collected as the body is written.
struct Decode<'d> {
    d: &'d Design,
    used: BTreeSet<Opcode>,
}

impl Decode<'_> {
    /// `(is_a | is_b …)` over the implemented opcodes of `ops`, or `None` if none is.
    fn any(&mut self, ops: &[Opcode]) -> Option<String> {
        let names: Vec<String> = ops
            .iter()
            .filter(|o| self.d.has(**o))
            .map(|o| {
                self.used.insert(*o);
                op_wire(*o)
            })
            .collect();
        match names.len() {
            0 => None,
            1 => Some(names[0].clone()),
            _ => Some(format!("({})", names.join(" | "))),
        }
    }
}

/// `w'd0`.
fn zero(w: u32) -> String {
    format!("{w}'d0")
}

/// Bits `[c·w + w − 1 : c·w]` of a flattened per-channel vector.
fn slot(name: &str, c: usize, w: u32, take: u32) -> String {
    let lo = c as u32 * w;
    format!("{name}[{}:{}]", lo + take - 1, lo)
}

/// `x` (of `from` bits) zero-extended to `to` bits.
fn widen(x: &str, from: u32, to: u32) -> String {
    if to > from {
        format!("{{{}'d0, {x}}}", to - from)
    } else {
        x.to_string()
    }
}

/// Writes the processor module.
pub(crate) fn write(d: &Design, out: &mut Text) {
    let c_n = d.channels;
    let (wi, wd, wdd, wa) = (
        d.bits(Register::I),
        d.bits(Register::DI),
        d.bits(Register::DDI),
        d.bits(Register::Acc),
    );
    let vw = d.v_bits();
    let (aw, cw, ow) = (d.skip_bits(), d.count_bits(), d.op_bits());
    let addressed = d.addressed();
    let order = d.order();
    let pre = [
        d.preload(0) && order >= 1,
        d.preload(1) && order >= 2,
        d.preload(2) && order >= 3,
    ];
    let (carry_v, carry_d, carry_dd) = (d.carries_v(), d.carries_d(), d.carries_dd());
    let ev_bits = bits_for(d.events_per_visit());
    let mut dec = Decode {
        d,
        used: BTreeSet::new(),
    };
    let mut b = Text::new();

    // where the token is
    let periodic = dec.any(&[Opcode::SetPI, Opcode::SetPdI, Opcode::SetPddI]);
    if addressed {
        b.line("    // where the token is: `skip` processors before its first, `count` left in its range (the period of a SetP*)");
        b.line(&format!("    wire at_first = in_skip == {};", zero(aw)));
        b.line(&format!(
            "    wire in_range = at_first && in_count != {};",
            zero(cw)
        ));
        b.line(&format!(
            "    wire [{}:0] skip_less = in_skip - {aw}'d1;",
            aw - 1
        ));
        b.line(&format!(
            "    wire [{}:0] count_less = in_count - {cw}'d1;",
            cw - 1
        ));
        match &periodic {
            Some(p) => {
                b.line(&format!("    wire periodic = {p};"));
                let period_skip = if cw > aw {
                    b.line(&format!(
                        "    wire unused_period_top = ^count_less[{}:{aw}]; // a period is at most the width",
                        cw - 1
                    ));
                    format!("count_less[{}:0]", aw - 1)
                } else {
                    "count_less".to_string()
                };
                b.line(&format!(
                    "    wire [{}:0] next_skip = periodic ? (at_first ? {period_skip} : skip_less) : (at_first ? {} : skip_less);",
                    aw - 1,
                    zero(aw)
                ));
                b.line(&format!(
                    "    wire [{}:0] next_count = in_range && !periodic ? count_less : in_count;",
                    cw - 1
                ));
            }
            None => {
                b.line(&format!(
                    "    wire [{}:0] next_skip = at_first ? {} : skip_less;",
                    aw - 1,
                    zero(aw)
                ));
                b.line(&format!(
                    "    wire [{}:0] next_count = in_range ? count_less : in_count;",
                    cw - 1
                ));
            }
        }
    }

    // the wave
    let blocked = match (d.lock(), d.mask()) {
        (true, true) => Some("(locked | masked)"),
        (true, false) => Some("locked"),
        (false, true) => Some("masked"),
        (false, false) => None,
    };
    let not_blocked = blocked.map(|b| format!(" & ~{b}")).unwrap_or_default();
    let mut events: Vec<String> = Vec::new();
    if order >= 1 {
        let evals = dec
            .any(&[Opcode::Eval1, Opcode::Eval2, Opcode::Eval3])
            .expect("order >= 1");
        b.line(
            "    // the forward-differencing wave (Eval1-3): pick up preloads, accumulate, advance",
        );
        b.line(&format!("    wire eval_hit = in_range & {evals};"));
        if order >= 2 {
            let e = dec.any(&[Opcode::Eval2, Opcode::Eval3]).expect("order");
            b.line(&format!("    wire advance_v = in_range & {e};"));
        }
        if order >= 3 {
            let e = dec.any(&[Opcode::Eval3]).expect("order");
            b.line(&format!("    wire advance_d = in_range & {e};"));
        }
        if pre[0] {
            b.line("    wire pick_i = eval_hit & has_i;");
        }
        if pre[1] {
            b.line("    wire pick_d = advance_v & has_d;");
        }
        if pre[2] {
            b.line("    wire pick_dd = advance_d & has_dd;");
        }
        let neg = if d.acc_mode() { "neg_en | " } else { "" };
        for c in 0..c_n {
            b.line(&format!("    // channel {c}"));
            let v_in = slot("in_v", c, vw, wi);
            if pre[0] {
                b.line(&format!(
                    "    wire [{}:0] v_eff_c{c} = pick_i ? pre_i_c{c} : {v_in};",
                    wi - 1
                ));
            } else {
                b.line(&format!("    wire [{}:0] v_eff_c{c} = {v_in};", wi - 1));
            }
            b.line(&format!("    wire [{}:0] acc_sum_c{c};", wa - 1));
            b.line(&format!("    wire acc_ovf_c{c};"));
            b.line(&format!(
                "    cwisim_add_acc add_acc_c{c} (.a(acc_c{c}), .b(v_eff_c{c}), .sum(acc_sum_c{c}), .overflow(acc_ovf_c{c}));"
            ));
            b.line(&format!(
                "    wire take_c{c} = eval_hit{not_blocked} & ({neg}~v_eff_c{c}[{}]); // Acc_mode's drop rule: the sign of v",
                wi - 1
            ));
            events.push(format!("(take_c{c} & acc_ovf_c{c})"));
            if order >= 2 {
                let d_in = slot("in_d", c, wd, wd);
                if pre[1] {
                    b.line(&format!(
                        "    wire [{}:0] d_eff_c{c} = pick_d ? pre_d_c{c} : {d_in};",
                        wd - 1
                    ));
                } else {
                    b.line(&format!("    wire [{}:0] d_eff_c{c} = {d_in};", wd - 1));
                }
                b.line(&format!("    wire [{}:0] v_next_c{c};", wi - 1));
                b.line(&format!("    wire v_ovf_c{c};"));
                b.line(&format!(
                    "    cwisim_add_v add_v_c{c} (.a(v_eff_c{c}), .b(d_eff_c{c}), .sum(v_next_c{c}), .overflow(v_ovf_c{c}));"
                ));
                events.push(format!("(advance_v & v_ovf_c{c})"));
            }
            if order >= 3 {
                let dd_in = slot("in_dd", c, wdd, wdd);
                if pre[2] {
                    b.line(&format!(
                        "    wire [{}:0] dd_eff_c{c} = pick_dd ? pre_dd_c{c} : {dd_in};",
                        wdd - 1
                    ));
                } else {
                    b.line(&format!("    wire [{}:0] dd_eff_c{c} = {dd_in};", wdd - 1));
                }
                b.line(&format!("    wire [{}:0] d_next_c{c};", wd - 1));
                b.line(&format!("    wire d_ovf_c{c};"));
                b.line(&format!(
                    "    cwisim_add_d add_d_c{c} (.a(d_eff_c{c}), .b(dd_eff_c{c}), .sum(d_next_c{c}), .overflow(d_ovf_c{c}));"
                ));
                events.push(format!("(advance_d & d_ovf_c{c})"));
            }
        }
        b.line("    // overflow events of this visit (one per adder and channel that overflowed)");
        let terms: Vec<String> = events.iter().map(|e| widen(e, 1, ev_bits)).collect();
        b.line(&format!("    assign events = {};", terms.join(" + ")));
    }
    let eval0_take = if d.has(Opcode::Eval0) {
        let e = dec.any(&[Opcode::Eval0]).expect("has");
        b.line(&format!(
            "    wire eval0_take = in_range & {e}{not_blocked}; // Eval0: set and lock, first claim wins"
        ));
        true
    } else {
        false
    };
    let refresh = dec.any(&[Opcode::Refresh]).expect("always implemented");

    // the registers
    b.blank();
    b.line("    always @(posedge clk) begin");
    b.line("        if (rst) begin");
    for c in 0..c_n {
        b.line(&format!("            acc_c{c} <= {};", zero(wa)));
        b.line(&format!(
            "            {} <= {};",
            slot("out", c, wa, wa),
            zero(wa)
        ));
    }
    let names = ["i", "d", "dd"];
    let widths = [wi, wd, wdd];
    for s in 0..3 {
        if pre[s] {
            b.line(&format!("            has_{} <= 1'b0;", names[s]));
            for c in 0..c_n {
                b.line(&format!(
                    "            pre_{}_c{c} <= {};",
                    names[s],
                    zero(widths[s])
                ));
            }
        }
    }
    if d.lock() {
        b.line("            locked <= 1'b0;");
    }
    if d.mask() {
        b.line("            masked <= 1'b0;");
    }
    if d.acc_mode() {
        b.line("            neg_en <= 1'b0;");
    }
    b.line("        end else if (in_arrive) begin");
    // accumulator and output
    for c in 0..c_n {
        b.line(&format!("            if ({refresh}) begin"));
        b.line(&format!(
            "                {} <= acc_c{c};",
            slot("out", c, wa, wa)
        ));
        b.line(&format!("                acc_c{c} <= {};", zero(wa)));
        b.line("            end");
        if eval0_take {
            b.line(&format!(
                "            else if (eval0_take) acc_c{c} <= {};",
                slot("in_v", c, vw, wa)
            ));
        }
        if order >= 1 {
            b.line(&format!(
                "            else if (take_c{c}) acc_c{c} <= acc_sum_c{c};"
            ));
        }
    }
    // preloads
    let sets = [
        (Opcode::SetI, Opcode::SetPI),
        (Opcode::SetdI, Opcode::SetPdI),
        (Opcode::SetddI, Opcode::SetPddI),
    ];
    let consume = ["eval_hit", "advance_v", "advance_d"];
    let field = ["in_v", "in_d", "in_dd"];
    let fw = [vw, wd, wdd];
    for s in 0..3 {
        if !pre[s] {
            continue;
        }
        let single = dec.any(&[sets[s].0]).map(|e| format!("({e} & in_range)"));
        let per = dec.any(&[sets[s].1]).map(|e| format!("({e} & at_first)"));
        let hit = [single, per]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>()
            .join(" | ");
        b.line(&format!("            if ({hit}) begin"));
        b.line(&format!("                has_{} <= 1'b1;", names[s]));
        for c in 0..c_n {
            b.line(&format!(
                "                pre_{}_c{c} <= {};",
                names[s],
                slot(field[s], c, fw[s], widths[s])
            ));
        }
        b.line("            end");
        b.line(&format!(
            "            else if ({} | {refresh}) has_{} <= 1'b0;",
            consume[s], names[s]
        ));
    }
    if d.lock() {
        b.line(&format!("            if ({refresh}) locked <= 1'b0;"));
        b.line("            else if (eval0_take) locked <= 1'b1;");
    }
    if d.mask() {
        let dis = dec.any(&[Opcode::Dis]).expect("has");
        let evals = dec
            .any(&[Opcode::Eval0, Opcode::Eval1, Opcode::Eval2, Opcode::Eval3])
            .map(|e| format!("{e} | "))
            .unwrap_or_default();
        b.line(&format!(
            "            if ({dis} & in_range) masked <= 1'b1;"
        ));
        b.line(&format!(
            "            else if ({evals}{refresh}) masked <= 1'b0; // every Eval command clears every mask"
        ));
    }
    if d.acc_mode() {
        let m = dec.any(&[Opcode::AccMode]).expect("has");
        b.line(&format!("            if ({m}) neg_en <= ~neg_en;"));
    }
    b.line("        end");
    b.line("    end");

    // the token as it leaves
    b.blank();
    b.line("    // the token, with its wave advanced, held here for a hop");
    b.line("    always @(posedge clk) begin");
    b.line("        if (rst) tok_valid <= 1'b0;");
    b.line("        else if (in_arrive) tok_valid <= 1'b1;");
    b.line("        else if (tok_leave) tok_valid <= 1'b0;");
    b.line("    end");
    if d.timing.hop > 1 {
        let hw = bits_for(d.timing.hop - 1);
        b.line(&format!("    reg [{}:0] age;", hw - 1));
        b.line("    always @(posedge clk) begin");
        b.line(&format!(
            "        if (rst || in_arrive) age <= {};",
            zero(hw)
        ));
        b.line(&format!(
            "        else if (tok_valid) age <= age + {hw}'d1;"
        ));
        b.line("    end");
        b.line(&format!(
            "    assign tok_leave = tok_valid && age == {hw}'d{};",
            d.timing.hop - 1
        ));
    } else {
        b.line("    assign tok_leave = tok_valid;");
    }
    b.line("    always @(posedge clk) begin");
    b.line("        if (in_arrive) begin");
    b.line("            tok_op <= in_op;");
    if addressed {
        b.line("            tok_skip <= next_skip;");
        b.line("            tok_count <= next_count;");
    }
    for c in 0..c_n {
        if carry_v {
            let v_full = slot("in_v", c, vw, vw);
            let mut e = v_full.clone();
            if pre[0] {
                e = format!("pick_i ? {} : {e}", widen(&format!("pre_i_c{c}"), wi, vw));
            }
            if order >= 2 {
                e = format!(
                    "advance_v ? {} : {e}",
                    widen(&format!("v_next_c{c}"), wi, vw)
                );
            }
            b.line(&format!("            {} <= {e};", slot("tok_v", c, vw, vw)));
        }
        if carry_d {
            let e = if order >= 3 {
                format!("advance_d ? d_next_c{c} : d_eff_c{c}")
            } else if order >= 2 {
                format!("d_eff_c{c}")
            } else {
                slot("in_d", c, wd, wd)
            };
            b.line(&format!("            {} <= {e};", slot("tok_d", c, wd, wd)));
        }
        if carry_dd {
            let e = if order >= 3 {
                format!("dd_eff_c{c}")
            } else {
                slot("in_dd", c, wdd, wdd)
            };
            b.line(&format!(
                "            {} <= {e};",
                slot("tok_dd", c, wdd, wdd)
            ));
        }
    }
    b.line("        end");
    b.line("    end");

    // the module: ports, declarations, decode, then the body
    let n = c_n as u32;
    out.line("// One X-processor: the registers of docs/ISA.md and the stage of the chain that holds a token for a hop.");
    out.line(&format!("module {PROCESSOR_MODULE} ("));
    let mut ports = vec![
        "    input  wire clk".to_string(),
        "    input  wire rst".to_string(),
        "    // the token arriving this cycle (from the bus or the processor to the left)"
            .to_string(),
        "    input  wire in_arrive".to_string(),
        format!("    input  wire [{}:0] in_op", ow - 1),
    ];
    if addressed {
        ports.push(format!("    input  wire [{}:0] in_skip", aw - 1));
        ports.push(format!("    input  wire [{}:0] in_count", cw - 1));
    }
    let fields = d.value_fields();
    for &(name, bits) in &fields {
        ports.push(format!("    input  wire [{}:0] in_{name}", bits * n - 1));
    }
    ports.push("    // the token held here; it moves on to the right when `tok_leave`".into());
    ports.push("    output reg  tok_valid".into());
    ports.push("    output wire tok_leave".into());
    ports.push(format!("    output reg  [{}:0] tok_op", ow - 1));
    if addressed {
        ports.push(format!("    output reg  [{}:0] tok_skip", aw - 1));
        ports.push(format!("    output reg  [{}:0] tok_count", cw - 1));
    }
    for &(name, bits) in &fields {
        ports.push(format!("    output reg  [{}:0] tok_{name}", bits * n - 1));
    }
    ports.push("    // the accumulator, per channel, as the last Refresh moved it out".into());
    ports.push(format!("    output reg  [{}:0] out", wa * n - 1));
    if order >= 1 {
        ports.push("    // overflow events of the arriving token's adders".into());
        ports.push(format!("    output wire [{}:0] events", ev_bits - 1));
    }
    // commas between ports, not after comments or the last
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
    let ow = d.op_bits();
    for op in &dec.used {
        out.line(&format!(
            "    localparam [{}:0] {} = {ow}'d{}; // {}",
            ow - 1,
            op_const(*op),
            op.code(),
            op.signature()
        ));
    }
    for op in &dec.used {
        out.line(&format!(
            "    wire {} = in_op == {};",
            op_wire(*op),
            op_const(*op)
        ));
    }
    out.line("    // registers and flags");
    for c in 0..c_n {
        out.line(&format!(
            "    reg [{}:0] acc_c{c}; // Q{}",
            wa - 1,
            d.q(Register::Acc)
        ));
    }
    let regs = [Register::I, Register::DI, Register::DDI];
    for s in 0..3 {
        if pre[s] {
            out.line(&format!("    reg has_{};", names[s]));
            for c in 0..c_n {
                out.line(&format!(
                    "    reg [{}:0] pre_{}_c{c}; // Q{}",
                    widths[s] - 1,
                    names[s],
                    d.q(regs[s])
                ));
            }
        }
    }
    if d.lock() {
        out.line("    reg locked; // claimed by Eval0 until Refresh");
    }
    if d.mask() {
        out.line("    reg masked; // masked by Dis for the next Eval");
    }
    if d.acc_mode() {
        out.line("    reg neg_en; // Acc_mode: accumulate negative contributions");
    }
    out.0.push_str(&b.into_string());
    out.line("endmodule");
    out.blank();
}
