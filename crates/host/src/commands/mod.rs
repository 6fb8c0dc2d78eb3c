//! The subcommands of `cwisim`, one module each, and the machine options they share.

pub mod convert;
pub mod machine;
pub mod run;

use crate::error::CliError;
use clap::Args;
use cwisim_xproc::Machine;
use std::path::PathBuf;

/// `--machine FILE` and `--set KEY=VALUE`: which machine model to simulate.
#[derive(Args, Clone, Debug, Default, PartialEq)]
pub struct MachineArgs {
    /// Machine model file (JSON; keys not given keep their defaults). Print the defaults
    /// with `cwisim machine`.
    #[arg(long, value_name = "M.json")]
    pub machine: Option<PathBuf>,

    /// Override one machine parameter, after --machine; repeatable. VALUE is JSON.
    ///
    /// Keys: clock_hz, frame_rate_hz, vblank_lines, line_period_cycles (null derives it),
    /// hop_cycles, value_cycles, opcode_cycles.NAME (e.g. opcode_cycles.Eval3). Example:
    /// --set clock_hz=2e8 --set opcode_cycles.Eval3=2
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl MachineArgs {
    /// The machine: the defaults, or the `--machine` file, then every `--set` in order.
    pub fn load(&self) -> Result<Machine, CliError> {
        let base = match &self.machine {
            Some(path) => Machine::from_file(path)?,
            None => Machine::default(),
        };
        if self.set.is_empty() {
            Ok(base)
        } else {
            Ok(base.with_overrides(&self.set)?)
        }
    }
}
