//! `cwisim machine`: print the effective machine model, and the line period it gives.

use super::MachineArgs;
use crate::error::CliError;
use clap::Args;
use cwisim_isa::TraceHeader;
use cwisim_xproc::Machine;
use std::io::Write;

/// The arguments of `cwisim machine`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct MachineCmdArgs {
    /// The machine model.
    #[command(flatten)]
    pub machine: MachineArgs,

    /// Array width (X-processors) to derive the timing for.
    #[arg(long, value_name = "W", default_value_t = 1024)]
    pub width: u32,

    /// Scanlines per frame (the display's height) to derive the line period for.
    /// `--lines` is its old name.
    #[arg(
        long = "height",
        alias = "lines",
        value_name = "H",
        default_value_t = 1024
    )]
    pub lines: u32,

    /// Channels per intensity (1 grey, 3 RGB).
    #[arg(long, value_name = "C", default_value_t = 1)]
    pub channels: u8,
}

/// Runs `cwisim machine`: the machine as pretty JSON on `stdout` (nothing else, so it
/// can be saved as a machine file), the derived timing as one line on `stderr`.
pub fn run(
    args: &MachineCmdArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    let machine = args.machine.load()?;
    let header = TraceHeader::new(args.width, args.lines, args.channels)
        .map_err(|m| CliError::Usage(format!("--width/--height/--channels: {m}")))?;
    let line = timing_line(&machine, &header)?;
    let json = serde_json::to_string_pretty(&machine).map_err(|e| CliError::Stdout(e.into()))?;
    writeln!(stdout, "{json}").map_err(CliError::Stdout)?;
    stdout.flush().map_err(CliError::Stdout)?;
    let _ = writeln!(stderr, "{line}");
    Ok(())
}

/// One line saying the line period and traversal `machine` gives for a trace of `header`'s
/// dimensions, and where the line period comes from.
pub fn timing_line(machine: &Machine, header: &TraceHeader) -> Result<String, CliError> {
    let t = machine.timeline(header)?;
    let origin = match machine.line_period_cycles {
        Some(_) => "set by line_period_cycles".to_string(),
        None => format!(
            "floor({} Hz / ({} Hz × ({} lines + {} blanking)))",
            machine.clock_hz, machine.frame_rate_hz, header.lines, machine.vblank_lines
        ),
    };
    Ok(format!(
        "line period {} cycles ({origin}); traversal {} cycles ({} processors × {} cycle(s) per hop)",
        t.line_period,
        t.traversal(),
        header.width,
        t.hop
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_line_period_is_explained() {
        let h = TraceHeader::new(1024, 1024, 1).expect("header");
        let line = timing_line(&Machine::default(), &h).expect("timeline");
        assert_eq!(
            line,
            "line period 1559 cycles (floor(100000000 Hz / (60 Hz × (1024 lines + 45 blanking)))); \
             traversal 1024 cycles (1024 processors × 1 cycle(s) per hop)"
        );
        let m = Machine::default()
            .with_overrides(&["line_period_cycles=500".into()])
            .expect("override");
        assert!(timing_line(&m, &h)
            .expect("timeline")
            .starts_with("line period 500 cycles (set by line_period_cycles)"));
    }

    #[test]
    fn stdout_is_the_machine_json_only() {
        let args = MachineCmdArgs {
            machine: MachineArgs {
                machine: None,
                set: vec!["hop_cycles=2".into()],
            },
            width: 16,
            lines: 4,
            channels: 3,
        };
        let (mut out, mut err) = (Vec::new(), Vec::new());
        run(&args, &mut out, &mut err).expect("run");
        let m: Machine = serde_json::from_slice(&out).expect("stdout is a machine");
        assert_eq!(m.hop_cycles, 2);
        let err = String::from_utf8(err).expect("utf-8");
        assert_eq!(err.lines().count(), 1);
        assert!(err.contains("traversal 32 cycles"), "{err}");
    }
}
