//! Co-simulation in Verilator: the design of all fourteen opcodes on a golden trace,
//! compiled to C++ and held to the stepped engine as under Icarus.

mod common;

use common::{format, hdl_tools, scratch, trace};
use cwisim_rtl::verilog::Watch;
use cwisim_rtl::{all_opcodes, cosimulate, BusTiming, Design, Simulator};
use cwisim_xproc::Machine;

#[test]
fn verilator_agrees_with_the_stepped_engine() {
    if !hdl_tools("the Verilator co-simulation") {
        return;
    }
    let (header, instrs) = trace("visibility");
    let machine = Machine::default();
    let d = Design::new(
        format("fixed:I=2.10,dI=1.12,ddI=1.14,acc=2.9"),
        all_opcodes(),
        header.width,
        header.channel_count(),
        BusTiming::new(&machine, &header).unwrap(),
    )
    .unwrap();
    let dir = scratch("verilator");
    let out = cosimulate(
        &d,
        &header,
        &instrs,
        &machine,
        &Watch::all(d.width),
        Simulator::Verilator,
        &dir,
    )
    .unwrap();
    match out.result {
        Ok(a) => assert!(a.values > 0 && a.arrivals > 0, "{a:?}"),
        Err(m) => panic!("{m} (files in {})", dir.display()),
    }
}
