//! Co-simulation: the design and its testbench written into a work directory, the trace
//! converted into the stimulus, one simulator run (Icarus Verilog or Verilator), and the
//! dump held to the stepped engine.

use crate::compare::{compare, Agreement, Mismatch};
use crate::design::Design;
use crate::dump;
use crate::error::RtlError;
use crate::reference::expected;
use crate::stimulus;
use crate::tools::{run, write_file};
use crate::verilog::{self, Watch, DUMP_FILE, STIMULUS_FILE, TESTBENCH_MODULE};
use cwisim_isa::{Instruction, TraceHeader};
use cwisim_xproc::Machine;
use std::io::BufWriter;
use std::path::Path;
use std::time::{Duration, Instant};

/// The simulator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simulator {
    /// Icarus Verilog: `iverilog` compiles, `vvp` runs.
    Icarus,
    /// Verilator: compiled to C++ (`--binary`), then run.
    Verilator,
}

impl Simulator {
    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Icarus => "icarus",
            Simulator::Verilator => "verilator",
        }
    }

    /// The programs it runs, each of which must be on the PATH.
    pub fn programs(self) -> &'static [&'static str] {
        match self {
            Simulator::Icarus => &["iverilog", "vvp"],
            Simulator::Verilator => &["verilator"],
        }
    }
}

/// What a co-simulation found, with its times.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Everything agreed, or the first difference.
    pub result: Result<Agreement, Mismatch>,
    /// Time to compile the design and testbench.
    pub build: Duration,
    /// Time the simulation ran.
    pub simulate: Duration,
    /// Time the stepped engine took.
    pub reference: Duration,
}

/// The most cycles a co-simulation may run: the simulators step every cycle, idle ones
/// too, so a machine whose line period is long (`clock_hz=1e12`) would keep them for hours.
/// A typical scene takes a few million (the pot at 400×400: 1.5 million).
pub const MAX_COSIM_CYCLES: u64 = 200_000_000;

/// Where a co-simulation is, for a progress display: its stages in order, the long ones
/// (Verilator's build, a long simulation) minutes long.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CosimStage {
    /// The stepped engine's expected outputs, and the stimulus and Verilog written.
    Reference,
    /// The simulator built from the Verilog (`iverilog`; `verilator --binary`, C++
    /// compiled: the longest).
    Build,
    /// The simulation, of about this many cycles.
    Simulate {
        /// The cycles the stepped engine took.
        cycles: u64,
    },
    /// The simulator's dump read and compared.
    Compare,
}

/// Co-simulates `trace` on design `d` with `sim` in the (existing, empty) directory
/// `dir`, watching the token arrivals at `watch`.
pub fn cosimulate(
    d: &Design,
    header: &TraceHeader,
    trace: &[Instruction],
    machine: &Machine,
    watch: &Watch,
    sim: Simulator,
    dir: &Path,
) -> Result<Outcome, RtlError> {
    cosimulate_with(d, header, trace, machine, watch, sim, dir, &mut |_| {})
}

/// [`cosimulate`], telling `stage` as each [`CosimStage`] begins.
#[allow(clippy::too_many_arguments)]
pub fn cosimulate_with(
    d: &Design,
    header: &TraceHeader,
    trace: &[Instruction],
    machine: &Machine,
    watch: &Watch,
    sim: Simulator,
    dir: &Path,
    stage: &mut dyn FnMut(CosimStage),
) -> Result<Outcome, RtlError> {
    if trace.is_empty() {
        return Err(RtlError::Settings(
            "the trace is empty: nothing to co-simulate".into(),
        ));
    }
    // absolute: the tools run in it, and the compiled simulator is named by its path
    let dir = &dir.canonicalize().map_err(|e| RtlError::io(dir, e))?;
    let started = Instant::now();
    stage(CosimStage::Reference);
    let want = expected(d, header, trace, machine, watch)?;
    let reference = started.elapsed();
    // the simulators step every cycle, idle ones too: said before, refused past the limit
    if want.cycles > MAX_COSIM_CYCLES {
        return Err(RtlError::Settings(format!(
            "the co-simulation would run {} cycles ({} scanline(s) of the machine's line period), over the limit of {MAX_COSIM_CYCLES}: the simulators step every idle cycle; a lower clock_hz (--set clock_hz=…) or a shorter trace",
            want.cycles, want.lines.len()
        )));
    }
    // generous: twice the model's cycles and then some; a hung design stops there
    let limit = want.cycles.saturating_mul(2).saturating_add(1000);
    let stim_path = dir.join(STIMULUS_FILE);
    let conv = {
        let file = std::fs::File::create(&stim_path).map_err(|e| RtlError::io(&stim_path, e))?;
        let mut w = BufWriter::new(file);
        let conv = stimulus::write(d, header, trace, &mut w)?;
        std::io::Write::flush(&mut w).map_err(|e| RtlError::io(&stim_path, e))?;
        conv
    };
    write_file(&dir.join("design.v"), &verilog::design(d))?;
    write_file(&dir.join("testbench.v"), &verilog::testbench(d, watch))?;
    let instructions = trace.len();
    let started = Instant::now();
    stage(CosimStage::Build);
    match sim {
        Simulator::Icarus => {
            run(
                "iverilog",
                &[
                    "-g2005",
                    &format!("-P{TESTBENCH_MODULE}.INSTRUCTIONS={instructions}"),
                    &format!("-P{TESTBENCH_MODULE}.CYCLE_LIMIT={limit}"),
                    "-s",
                    TESTBENCH_MODULE,
                    "-o",
                    "sim.vvp",
                    "testbench.v",
                    "design.v",
                ],
                dir,
            )?;
        }
        Simulator::Verilator => {
            run(
                "verilator",
                &[
                    "--binary",
                    &format!("-GINSTRUCTIONS={instructions}"),
                    &format!("-GCYCLE_LIMIT={limit}"),
                    "--timing",
                    "-Wno-fatal",
                    "-Wno-lint",
                    "-Wno-style",
                    "-O2",
                    "--top-module",
                    TESTBENCH_MODULE,
                    "-Mdir",
                    "obj",
                    "-o",
                    "sim",
                    "testbench.v",
                    "design.v",
                ],
                dir,
            )?;
        }
    }
    let build = started.elapsed();
    let started = Instant::now();
    stage(CosimStage::Simulate {
        cycles: want.cycles,
    });
    match sim {
        Simulator::Icarus => run("vvp", &["-n", "sim.vvp"], dir)?,
        Simulator::Verilator => {
            let bin = dir.join("obj").join("sim");
            let bin = bin.to_str().ok_or_else(|| {
                RtlError::Settings(format!("{}: not a UTF-8 path", bin.display()))
            })?;
            run(bin, &[], dir)?
        }
    };
    let simulate = started.elapsed();
    stage(CosimStage::Compare);
    let dump_path = dir.join(DUMP_FILE);
    let no_dump = |source| RtlError::NoOutput {
        tool: sim.name().into(),
        path: dump_path.clone(),
        source,
    };
    let size = std::fs::metadata(&dump_path).map_err(no_dump)?.len();
    // the text and what is parsed from it, about as much again
    cwisim_scene::budget::Budget::current()
        .check_memory("the simulator's dump", size.saturating_mul(2))?;
    let text = std::fs::read_to_string(&dump_path).map_err(no_dump)?;
    let observed = dump::parse(&text, &dump_path.display().to_string())?;
    let result = compare(d, trace, &want, &conv, &observed)?;
    Ok(Outcome {
        result,
        build,
        simulate,
        reference,
    })
}
