//! What the HDL tests share: the tools (installed by the project's script when missing,
//! or skipped when `CWISIM_SKIP_HDL_TESTS=1` says so), scratch directories, traces.

#![allow(dead_code)]

use cwisim_isa::{io::read_all, FileReader, Instruction, TraceHeader, TraceRead};
use cwisim_rtl::{tools, BusTiming, Design};
use cwisim_xproc::{FixedFormat, Machine, Numeric};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Whether the HDL tools are there (installing them with crates/rtl/tools/install-hdl.sh
/// if not); `false` only when `CWISIM_SKIP_HDL_TESTS=1` asks to skip. A failed install
/// fails the test, naming the script.
pub fn hdl_tools(test: &str) -> bool {
    if std::env::var("CWISIM_SKIP_HDL_TESTS").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED: {test} (CWISIM_SKIP_HDL_TESTS=1)");
        return false;
    }
    let all = || {
        [
            "iverilog",
            "vvp",
            "verilator",
            "yosys",
            "nextpnr-ice40",
            "icepack",
        ]
        .iter()
        .all(|t| tools::find(t).is_some())
    };
    if all() {
        return true;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/install-hdl.sh");
    eprintln!("{test} needs the HDL tools: running {}", script.display());
    let status = Command::new("bash").arg(&script).status();
    if status.as_ref().is_ok_and(|s| s.success()) && all() {
        return true;
    }
    panic!(
        "{test} needs iverilog, verilator, yosys and nextpnr-ice40, and {} could not install them \
({status:?}): install Debian's iverilog, verilator, yosys, nextpnr-ice40 and fpga-icestorm packages, \
or set CWISIM_SKIP_HDL_TESTS=1 to skip the HDL tests",
        script.display()
    );
}

/// A fresh empty directory under the target directory.
pub fn scratch(name: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "rtl-{name}-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A golden trace of `traces/`.
pub fn trace(name: &str) -> (TraceHeader, Vec<Instruction>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../traces")
        .join(format!("{name}.cwt"));
    let mut r = FileReader::open(&path).unwrap();
    let header = *r.header();
    (header, read_all(&mut r).unwrap())
}

/// A fixed-point format from its string.
pub fn format(s: &str) -> FixedFormat {
    match s.parse::<Numeric>().unwrap() {
        Numeric::Fixed(f) => f,
        other => panic!("{other} is not fixed point"),
    }
}

/// The design of `format` for `trace`'s opcodes and array.
pub fn design_for(
    format: FixedFormat,
    header: &TraceHeader,
    trace: &[Instruction],
    machine: &Machine,
) -> Design {
    Design::new(
        format,
        cwisim_rtl::opcodes_used(trace),
        header.width,
        header.channel_count(),
        BusTiming::new(machine, header).unwrap(),
    )
    .unwrap()
}
