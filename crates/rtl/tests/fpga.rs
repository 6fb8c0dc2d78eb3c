//! The array on an FPGA: the golden traces streamed through the I/O shell (the same
//! values as the stepped engine, each at the engine's cycle shifted by the shell's fixed
//! latencies), one small design placed and routed on the iCE40 UP5K by Yosys and
//! nextpnr-ice40, and its routed netlist simulated on a golden trace.

mod common;

use common::{design_for, format, hdl_tools, scratch, trace};
use cwisim_rtl::fpga::{self, cosimulate_shell, Netlist, Shell};
use cwisim_rtl::RtlError;
use cwisim_xproc::Machine;

const WIDE: &str = "fixed:I=8.24,dI=4.28,ddI=2.30,acc=10.24";

/// The design of `trace` in `fmt`, on the default machine paced for `shell`'s port.
fn paced(
    base: Machine,
    fmt: &str,
    header: &cwisim_isa::TraceHeader,
    instrs: &[cwisim_isa::Instruction],
    shell: &Shell,
) -> (cwisim_rtl::Design, Machine) {
    let d = design_for(format(fmt), header, instrs, &base);
    shell.pace(&d, &base, header).unwrap()
}

fn shell_cosim(name: &str, fmt: &str, shell: &Shell) -> fpga::ShellAgreement {
    let (header, instrs) = trace(name);
    let (d, machine) = paced(Machine::default(), fmt, &header, &instrs, shell);
    let dir = scratch(&format!("shell-{name}"));
    match cosimulate_shell(&d, shell, &header, &instrs, &machine, &Netlist::Rtl, &dir).unwrap() {
        Ok(a) => a,
        Err(m) => panic!("{name} through the shell: {m} (files in {})", dir.display()),
    }
}

#[test]
fn golden_traces_come_through_the_shell_at_a_fixed_latency() {
    if !hdl_tools("the co-simulation through the FPGA shell") {
        return;
    }
    for name in [
        "flat",
        "gouraud",
        "periodic",
        "preload",
        "rgb",
        "visibility",
        "order",
    ] {
        let a = shell_cosim(name, WIDE, &Shell::default());
        assert!(a.scanlines > 0 && a.values > 0, "{name}: {a:?}");
    }
    // a narrower port: more beats a word, the start later by as many cycles
    let a = shell_cosim("gouraud", WIDE, &Shell { beat_bits: 5 });
    let b = shell_cosim("gouraud", WIDE, &Shell { beat_bits: 16 });
    assert!(a.start > b.start, "{a:?} {b:?}");
}

#[test]
fn a_small_design_places_routes_and_its_netlist_computes_the_same_scanlines() {
    if !hdl_tools("the FPGA place and route") {
        return;
    }
    let (header, instrs) = trace("gouraud");
    let shell = Shell::default();
    // a slow clock: a short line period, few cycles for the gate-level simulation
    let slow = Machine::default()
        .with_overrides(&["clock_hz=1e6".to_string()])
        .unwrap();
    let fmt = "fixed:I=2.15,dI=1.16,ddI=1.16,acc=2.12";
    let (d, machine) = paced(slow, fmt, &header, &instrs, &shell);
    let up5k = fpga::device("ice40-up5k").unwrap();
    let dir = scratch("pnr");
    let r = fpga::place_and_route(&d, &shell, &up5k, &dir, &mut |_| {}).unwrap();
    assert!(r.logic_cells > 0 && r.logic_cells <= up5k.cells, "{r:?}");
    assert!(r.fmax_mhz > 1.0 && r.fmax_mhz < 1000.0, "{r:?}");
    assert!(
        r.shell.luts() > 0 && r.array.luts() > r.shell.luts(),
        "{r:?}"
    );
    assert!(r.array.flip_flops() >= 16 * r.processor.flip_flops().max(1));
    assert!(r.fit >= 16, "{r:?}");
    // the routed netlist, simulated with the iCE40 cell models, against the stepped engine
    let sim = scratch("post-route");
    let routed = dir.join("routed.json");
    match cosimulate_shell(
        &d,
        &shell,
        &header,
        &instrs,
        &machine,
        &Netlist::PostRoute(routed),
        &sim,
    )
    .unwrap()
    {
        Ok(a) => assert_eq!(a.scanlines, 6, "{a:?}"),
        Err(m) => panic!("the routed netlist: {m} (files in {})", sim.display()),
    }
    // too large: said with the numbers, not an internal error
    let hx1k = fpga::device("ice40-hx1k").unwrap();
    let e =
        fpga::place_and_route(&d, &shell, &hx1k, &scratch("too-large"), &mut |_| {}).unwrap_err();
    assert!(matches!(e, RtlError::DoesNotFit { .. }), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("logic cells") && text.contains("has 1280"),
        "{text}"
    );
    assert!(!text.contains('\n'), "{text}");
    // too many pins: a port wider than the package
    let e = fpga::place_and_route(
        &d,
        &Shell { beat_bits: 40 },
        &up5k,
        &scratch("pins"),
        &mut |_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("I/O pins"), "{e}");
}
