//! The golden traces of `traces/` co-simulated in Icarus Verilog against the stepped
//! engine: every scanline bit for bit, every scanline's overflow events and ready cycle,
//! and the cycle every token arrives at every processor.

mod common;

use common::{design_for, format, hdl_tools, scratch, trace};
use cwisim_rtl::verilog::Watch;
use cwisim_rtl::{cosimulate, Simulator};
use cwisim_xproc::Machine;

fn cosim(name: &str, fmt: &str, machine: &Machine) -> cwisim_rtl::Agreement {
    let (header, instrs) = trace(name);
    let d = design_for(format(fmt), &header, &instrs, machine);
    let dir = scratch(name);
    let out = cosimulate(
        &d,
        &header,
        &instrs,
        machine,
        &Watch::all(d.width),
        Simulator::Icarus,
        &dir,
    )
    .unwrap();
    match out.result {
        Ok(a) => a,
        Err(m) => panic!("{name} in {fmt}: {m} (files in {})", dir.display()),
    }
}

#[test]
fn golden_traces_agree_bit_and_cycle_for_cycle() {
    if !hdl_tools("the Icarus co-simulation of the golden traces") {
        return;
    }
    let wide = "fixed:I=8.24,dI=4.28,ddI=2.30,acc=10.24";
    let mut used = std::collections::BTreeSet::<cwisim_isa::Opcode>::new();
    for name in [
        "antialiased",
        "flat",
        "gouraud",
        "negative",
        "order",
        "periodic",
        "preload",
        "rgb",
        "visibility",
    ] {
        let a = cosim(name, wide, &Machine::default());
        assert!(
            a.scanlines > 0 && a.values > 0 && a.arrivals > 0,
            "{name}: {a:?}"
        );
        used.extend(cwisim_rtl::opcodes_used(&trace(name).1));
    }
    // with overrun.cwt (co-simulated under its own machine below), every opcode
    used.extend(cwisim_rtl::opcodes_used(&trace("overrun").1));
    assert_eq!(used, cwisim_rtl::all_opcodes());
}

#[test]
fn narrow_formats_overflow_alike_saturating_and_wrapping() {
    if !hdl_tools("the Icarus co-simulation of overflowing formats") {
        return;
    }
    for fmt in [
        "fixed:I=1.3,dI=1.2,ddI=1.4,acc=3.1",
        "fixed:I=1.6,dI=1.8,ddI=1.9,acc=1.5",
        "fixed:I=1.6,dI=1.8,ddI=1.9,acc=1.5,overflow=wrap",
    ] {
        let mut adders = 0;
        for name in ["antialiased", "negative", "periodic", "rgb"] {
            adders += cosim(name, fmt, &Machine::default()).adder_overflows;
        }
        // the adders themselves overflowed, not only the operand conversions
        assert!(adders > 0, "{fmt}: no adder overflowed");
    }
}

#[test]
fn the_timing_model_holds_with_other_machines() {
    if !hdl_tools("the Icarus co-simulation under other machines") {
        return;
    }
    let fmt = "fixed:I=8.24,dI=4.28,ddI=2.30,acc=10.24";
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../traces/overrun.machine.json");
    let overrun = Machine::from_file(&path).unwrap();
    cosim("overrun", fmt, &overrun);
    let slow = Machine::default()
        .with_overrides(&[
            "hop_cycles=3".into(),
            "opcode_cycles.Eval2=5".into(),
            "value_cycles=2".into(),
            "line_period_cycles=90".into(),
            "vblank_lines=2".into(),
        ])
        .unwrap();
    for name in ["visibility", "rgb", "gouraud", "overrun"] {
        cosim(name, fmt, &slow);
    }
}

#[test]
fn the_widest_registers_agree() {
    if !hdl_tools("the Icarus co-simulation of 64-bit registers") {
        return;
    }
    for fmt in [
        "fixed:I=16.48,dI=16.48,ddI=16.48,acc=16.48,overflow=wrap",
        "fixed:I=1.63,dI=64.0,ddI=2.62,acc=40.24",
    ] {
        for name in ["rgb", "visibility"] {
            cosim(name, fmt, &Machine::default());
        }
    }
}

#[test]
fn a_co_simulation_tells_its_stages_in_order() {
    if !hdl_tools("the stages of an Icarus co-simulation") {
        return;
    }
    let machine = Machine::default();
    let (header, instrs) = trace("gouraud");
    let d = design_for(
        format("fixed:I=8.24,dI=4.28,ddI=2.30,acc=10.24"),
        &header,
        &instrs,
        &machine,
    );
    let dir = scratch("stages");
    let mut stages = Vec::new();
    let out = cwisim_rtl::cosimulate_with(
        &d,
        &header,
        &instrs,
        &machine,
        &Watch::all(d.width),
        Simulator::Icarus,
        &dir,
        &mut |s| stages.push(s),
    )
    .unwrap();
    assert!(out.result.is_ok(), "the gouraud trace agrees");
    use cwisim_rtl::CosimStage::*;
    assert!(
        matches!(stages[..], [Reference, Build, Simulate { cycles }, Compare] if cycles > 0),
        "{stages:?}"
    );
}
