//! Every way generating, co-simulating or synthesizing a design can fail.

use cwisim_scene::budget::BudgetError;
use cwisim_xproc::{MachineError, NumericError};
use std::path::PathBuf;

/// Why a design could not be generated, simulated or synthesized. Every message is one
/// line and names what it is about.
#[derive(Debug, thiserror::Error)]
pub enum RtlError {
    /// The settings cannot make a design (a numeric format that is not fixed point, an
    /// opcode set without `Refresh`, a width of 0, …).
    #[error("{0}")]
    Settings(String),
    /// The fixed-point format is outside its limits.
    #[error("{0}")]
    Numeric(#[from] NumericError),
    /// The machine model cannot time the trace.
    #[error(transparent)]
    Machine(#[from] MachineError),
    /// The work would need more memory than the budget.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// The trace does not fit the design (another width or channel count, an opcode the
    /// design leaves out).
    #[error("instruction {index} ({instruction}): {message}")]
    Trace {
        /// Its number in the trace, from 0.
        index: u64,
        /// The instruction, in the text form.
        instruction: String,
        /// What is wrong.
        message: String,
    },
    /// `--fpga` names a device the table does not have.
    #[error("unknown FPGA `{name}`: the known ones are {known}")]
    UnknownDevice {
        /// The name given.
        name: String,
        /// The names known, comma-separated.
        known: String,
    },
    /// The design is larger than the device (not an internal error: a smaller array or
    /// a larger device).
    #[error("the design does not fit the {device}: it needs {needed} {what}, the device has {there}{hint}")]
    DoesNotFit {
        /// The device.
        device: String,
        /// What runs out (`logic cells`, `I/O pins`, `RAM blocks`).
        what: String,
        /// How many the design needs.
        needed: u64,
        /// How many the device has.
        there: u64,
        /// What would fit, if known (`; about 12 processors of this format fit`).
        hint: String,
    },
    /// An HDL tool is not installed.
    #[error("`{tool}` was not found on the PATH: install it with crates/rtl/tools/install-hdl.sh (Debian's iverilog, verilator, yosys, nextpnr-ice40 and fpga-icestorm)")]
    ToolMissing {
        /// The program.
        tool: String,
    },
    /// An HDL tool ran and failed.
    #[error("`{command}` failed ({status}): {output}")]
    ToolFailed {
        /// The command line.
        command: String,
        /// Its exit status.
        status: String,
        /// The first lines of what it printed.
        output: String,
    },
    /// A tool ran without an error but left no readable output where it should have
    /// written it (a simulator that wrote no dump).
    #[error("{tool} ran but left no readable {}: {source}", path.display())]
    NoOutput {
        /// The tool.
        tool: String,
        /// The file it should have written.
        path: PathBuf,
        /// Why it cannot be read.
        source: std::io::Error,
    },
    /// A file of the co-simulation could not be written (or a file of ours read back).
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// What a simulator or Yosys wrote could not be understood.
    #[error("{what}: line {line}: {message}")]
    Parse {
        /// Which output.
        what: String,
        /// Its line, from 1.
        line: usize,
        /// What was expected.
        message: String,
    },
}

impl RtlError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> RtlError {
        RtlError::Io {
            path: path.into(),
            source,
        }
    }
}
