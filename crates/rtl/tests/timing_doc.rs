//! docs/TIMING.md's equations, read from the document and evaluated, held to the stepped
//! engine (whose token arrivals the generated Verilog matches cycle for cycle): the cycle
//! every instruction's token enters processor 0, the first instruction's included
//! (issue 55: the document once had it enter at max(c₀, h), where the engine and the
//! Verilog enter at c₀).

mod common;

use common::{design_for, format, trace};
use cwisim_isa::Opcode;
use cwisim_rtl::reference::expected;
use cwisim_rtl::verilog::Watch;
use cwisim_xproc::Machine;
use std::collections::BTreeMap;

/// The right-hand side of the equation for `name` in TIMING.md's block of equations.
fn equation(doc: &str, name: &str) -> String {
    let block = doc
        .split("## The equations")
        .nth(1)
        .and_then(|s| s.split("```text").nth(1))
        .and_then(|s| s.split("```").next())
        .expect("TIMING.md has its equations in a text block");
    let line = block
        .lines()
        .find(|l| l.split_whitespace().next() == Some(name))
        .unwrap_or_else(|| panic!("TIMING.md has no equation for {name}"));
    line.split_once('=').expect("an equation").1.to_string()
}

/// Evaluates `max(a, b)`, `a + b`, numbers and the variables of `vars`, from the start of
/// `s`; what follows the expression (the equation's comment) is left.
fn eval(s: &str, vars: &BTreeMap<&str, u64>) -> u64 {
    fn expr<'a>(s: &'a str, vars: &BTreeMap<&str, u64>) -> (u64, &'a str) {
        let (mut v, mut rest) = term(s, vars);
        loop {
            let t = rest.trim_start();
            match t.strip_prefix('+') {
                Some(r) => {
                    let (w, r) = term(r, vars);
                    v += w;
                    rest = r;
                }
                None => return (v, rest),
            }
        }
    }
    fn term<'a>(s: &'a str, vars: &BTreeMap<&str, u64>) -> (u64, &'a str) {
        let s = s.trim_start();
        if let Some(r) = s.strip_prefix("max(") {
            let (a, r) = expr(r, vars);
            let r = r.trim_start().strip_prefix(',').expect("max(a, b)");
            let (b, r) = expr(r, vars);
            let r = r.trim_start().strip_prefix(')').expect("max(a, b)");
            return (a.max(b), r);
        }
        let end = s
            .find(|c: char| !(c.is_alphanumeric() || "_{}-".contains(c)))
            .unwrap_or(s.len());
        let (name, rest) = s.split_at(end);
        let v = name
            .parse::<u64>()
            .ok()
            .or_else(|| vars.get(name).copied())
            .unwrap_or_else(|| panic!("TIMING.md: unknown term `{name}`"));
        (v, rest)
    }
    expr(s, vars).0
}

/// The cycles the document's equations give every token's entry into processor 0.
fn entries(doc: &str, first: &str, name: &str, machine: &Machine) -> Vec<u64> {
    let (header, instrs) = trace(name);
    let t = machine.timeline(&header).unwrap();
    let (begin_eq, entry_eq) = (equation(doc, "begin_i"), equation(doc, "entry_i"));
    let deadline = |n: u64| {
        let (f, r) = (n / t.lines_per_frame, n % t.lines_per_frame);
        (f * t.slots_per_frame + r + 1) * t.line_period
    };
    let mut out = Vec::new();
    let mut line = 0u64;
    let mut e = 0u64;
    for (i, instr) in instrs.iter().enumerate() {
        let gate = if instr.op == Opcode::Refresh && line >= 1 {
            deadline(line - 1)
        } else {
            0
        };
        let c = t.issue_cycles(instr);
        let mut vars = BTreeMap::from([("e_{i-1}", e), ("gate_i", gate), ("c_i", c), ("h", t.hop)]);
        let begin = eval(&begin_eq, &vars);
        vars.insert("begin_i", begin);
        vars.insert("begin_0", begin);
        vars.insert("c_0", c);
        e = eval(if i == 0 { first } else { &entry_eq }, &vars);
        out.push(e);
        if instr.op == Opcode::Refresh {
            line += 1;
        }
    }
    out
}

#[test]
fn the_documents_entry_equations_are_the_engines() {
    let doc = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/TIMING.md"),
    )
    .unwrap();
    let first = equation(&doc, "entry_0");
    // a hop longer than the first instruction's issue: where max(c₀, h) and c₀ differ
    let slow_hop = Machine::default()
        .with_overrides(&["hop_cycles=5".to_string()])
        .unwrap();
    for machine in [Machine::default(), slow_hop.clone()] {
        for name in ["flat", "gouraud", "visibility", "order", "periodic"] {
            let (header, instrs) = trace(name);
            let d = design_for(
                format("fixed:I=8.24,dI=4.28,ddI=2.30,acc=10.24"),
                &header,
                &instrs,
                &machine,
            );
            let want = expected(&d, &header, &instrs, &machine, &Watch::new([0], d.width)).unwrap();
            assert_eq!(
                entries(&doc, &first, name, &machine),
                want.arrivals[&0],
                "{name}, hop {}: TIMING.md's equations against the stepped engine",
                machine.hop_cycles
            );
        }
    }
    // the old equation for the first entry would fail it
    let old = entries(&doc, "max(c_0, h)", "flat", &slow_hop);
    assert_ne!(old, entries(&doc, &first, "flat", &slow_hop));
}
