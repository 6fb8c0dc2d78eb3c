//! Every generated design linted by Verilator (`--lint-only -Wall`: zero warnings) for the
//! opcode subset of every golden trace and for all fourteen opcodes, in several formats
//! and machines; Yosys synthesizes the processor and a small array of each.

mod common;

use common::{format, hdl_tools, scratch, trace};
use cwisim_isa::TraceHeader;
use cwisim_rtl::verilog::{self, ARRAY_MODULE};
use cwisim_rtl::{all_opcodes, area, opcodes_used, tools, BusTiming, Design};
use cwisim_xproc::Machine;
use std::collections::BTreeSet;

fn subsets() -> Vec<(String, BTreeSet<cwisim_isa::Opcode>, TraceHeader)> {
    let mut out = vec![(
        "all".to_string(),
        all_opcodes(),
        TraceHeader::new(16, 4, 1).unwrap(),
    )];
    for name in [
        "antialiased",
        "flat",
        "gouraud",
        "negative",
        "overrun",
        "periodic",
        "preload",
        "rgb",
        "visibility",
    ] {
        let (h, t) = trace(name);
        out.push((name.to_string(), opcodes_used(&t), h));
    }
    out
}

#[test]
fn verilator_lints_every_subset_without_a_warning() {
    if !hdl_tools("the Verilator lint of the generated designs") {
        return;
    }
    let machines = [
        Machine::default(),
        Machine::default()
            .with_overrides(&["hop_cycles=4".into(), "opcode_cycles.Eval3=7".into()])
            .unwrap(),
    ];
    let formats = [
        "fixed:I=12.20,dI=4.28,ddI=1.36,acc=16.20",
        "fixed:I=1.0,dI=1.0,ddI=1.0,overflow=wrap",
        "fixed:I=2.62,dI=64.0,ddI=1.63,acc=40.24",
    ];
    let dir = scratch("lint");
    for (name, ops, header) in subsets() {
        for (m, machine) in machines.iter().enumerate() {
            for (f, fmt) in formats.iter().enumerate() {
                // widths 1, a power of two and not
                for width in [1, 16, 13] {
                    let h = TraceHeader::new(width, header.lines, header.channels).unwrap();
                    let d = Design::new(
                        format(fmt),
                        ops.clone(),
                        width,
                        h.channel_count(),
                        BusTiming::new(machine, &h).unwrap(),
                    )
                    .unwrap();
                    let path = dir.join(format!("{name}-{m}-{f}-{width}.v"));
                    std::fs::write(&path, verilog::design(&d)).unwrap();
                    let warnings = tools::lint(&path, ARRAY_MODULE).unwrap();
                    assert!(warnings.is_empty(), "{}: {warnings:#?}", path.display());
                }
            }
        }
    }
}

#[test]
fn yosys_synthesizes_every_subsets_processor_and_array() {
    if !hdl_tools("the Yosys synthesis of the generated designs") {
        return;
    }
    let dir = scratch("synth");
    let mut areas = Vec::new();
    for (name, ops, header) in subsets() {
        let d = Design::new(
            format("fixed:I=4.12,dI=2.14,ddI=1.15,acc=6.12"),
            ops,
            4,
            header.channel_count(),
            BusTiming::new(&Machine::default(), &header).unwrap(),
        )
        .unwrap();
        let a = area::synthesize(&d, &dir).unwrap();
        assert!(
            a.flip_flops > 0 && a.logic > 0 && a.nand2 > 0.0,
            "{name}: {a:?}"
        );
        // the array of 4 synthesizes too, and holds at least four processors' flip-flops
        let arr = area::synthesize_module(&dir, "design.v", ARRAY_MODULE).unwrap();
        assert!(
            arr.flip_flops >= 4 * a.flip_flops,
            "{name}: {arr:?} vs {a:?}"
        );
        areas.push((name, a));
    }
    // fewer opcodes, fewer gates: the flat trace's processor (Eval1, Refresh) is smaller
    // than the full one's
    let full = &areas[0].1;
    let flat = &areas.iter().find(|(n, _)| *n == "flat").unwrap().1;
    assert!(flat.nand2 < full.nand2, "{flat:?} {full:?}");
}
