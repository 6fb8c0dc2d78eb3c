//! `cwisim history`: pixel history — every instruction that reached one processor on one
//! scanline, in order, with the cycle it arrived and the processor's registers and flags
//! just **before** and just **after** it acted there (values as at that moment).
//!
//! It replays the trace on the cycle-stepped engine (the reference model) up to the
//! scanline asked for, watching one processor.

use super::until::UntilLine;
use super::MachineArgs;
use crate::error::CliError;
use clap::Args;
use cwisim_isa::text::{format_instruction, format_value};
use cwisim_isa::{FileReader, Instruction, Opcode, TraceRead};
use cwisim_xproc::{replay_probed, NullSink, Probe, ProcessorState};
use std::io::Write;
use std::path::PathBuf;

/// The arguments of `cwisim history`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct HistoryArgs {
    /// The trace: .cwt, .jsonl or .cwb.
    #[arg(value_name = "TRACE")]
    pub trace: PathBuf,
    /// The processor (pixel column), from 0.
    #[arg(long, value_name = "X")]
    pub x: u32,
    /// The scanline, from 0 (counted over the whole trace).
    #[arg(long, value_name = "Y")]
    pub y: u64,
    /// Also list the instructions whose token only passed through the processor.
    #[arg(long)]
    pub all: bool,
    /// The machine model (for the cycles).
    #[command(flatten)]
    pub machine: MachineArgs,
}

/// One visit of a token to the watched processor.
struct Visit {
    cycle: u64,
    index: u64,
    instr: Instruction,
    addressed: bool,
    before: ProcessorState,
    after: ProcessorState,
}

struct Watch {
    x: usize,
    y: u64,
    visits: Vec<Visit>,
}

impl Probe for Watch {
    fn watches(&self, p: usize) -> bool {
        p == self.x
    }

    fn visit(
        &mut self,
        cycle: u64,
        _p: usize,
        index: u64,
        line: u64,
        instr: &Instruction,
        addressed: bool,
        before: &ProcessorState,
        after: &ProcessorState,
    ) {
        if line == self.y {
            self.visits.push(Visit {
                cycle,
                index,
                instr: *instr,
                addressed,
                before: before.clone(),
                after: after.clone(),
            });
        }
    }
}

fn values(v: &[f64]) -> String {
    v.iter()
        .map(|x| format_value(*x))
        .collect::<Vec<_>>()
        .join(",")
}

/// The registers and flags, one line: `acc=… I=… dI=… ddI=… [locked masked neg]`;
/// a preload register shows `-` when it holds no unconsumed value.
fn state(s: &ProcessorState) -> String {
    let reg = |k: usize| {
        if s.has[k] {
            values(&s.reg[k])
        } else {
            "-".to_string()
        }
    };
    let mut flags = Vec::new();
    if s.locked {
        flags.push("locked");
    }
    if s.masked {
        flags.push("masked");
    }
    if s.negative_enabled {
        flags.push("neg");
    }
    format!(
        "acc={} I={} dI={} ddI={} flags={}",
        values(&s.acc),
        reg(0),
        reg(1),
        reg(2),
        if flags.is_empty() {
            "-".to_string()
        } else {
            flags.join(",")
        }
    )
}

/// Runs `cwisim history`.
pub fn run(args: &HistoryArgs, stdout: &mut dyn Write) -> Result<(), CliError> {
    let machine = args.machine.load()?;
    let mut file = FileReader::open(&args.trace)?;
    let header = *file.header();
    if args.x >= header.width {
        return Err(CliError::Usage(format!(
            "--x {} is outside the array: {} has processors 0..={}",
            args.x,
            args.trace.display(),
            header.width - 1
        )));
    }
    let mut watch = Watch {
        x: args.x as usize,
        y: args.y,
        visits: Vec::new(),
    };
    let mut reader = UntilLine::new(&mut file, Some(args.y));
    replay_probed::<f64>(&mut reader, &machine, &mut watch, &mut NullSink)?;
    let lines = reader.lines_read();
    if lines <= args.y {
        return Err(CliError::Usage(format!(
            "--y {}: {} outputs only {lines} scanline(s) (0..={})",
            args.y,
            args.trace.display(),
            lines.saturating_sub(1)
        )));
    }
    let w = |out: &mut dyn Write, s: String| writeln!(out, "{s}").map_err(CliError::Stdout);
    w(
        stdout,
        format!(
            "# processor {} on scanline {} of {}: each instruction with the cycle its token \
arrived, and the registers before → after it acted",
            args.x,
            args.y,
            args.trace.display()
        ),
    )?;
    let mut shown = 0;
    for v in &watch.visits {
        let changed = v.before != v.after;
        if !(args.all || v.addressed || changed) {
            continue;
        }
        shown += 1;
        let how = if !v.addressed {
            "  (passes through)"
        } else if !changed
            && v.before.locked
            && matches!(
                v.instr.op,
                Opcode::Eval0 | Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3
            )
        {
            "  (suppressed: locked by Eval0)"
        } else if v.before.masked && !v.after.masked && v.before.acc == v.after.acc {
            "  (suppressed: masked by Dis)"
        } else {
            ""
        };
        w(
            stdout,
            format!(
                "cycle {:>8}  #{:<6} {}{how}",
                v.cycle,
                v.index,
                format_instruction(&v.instr)
            ),
        )?;
        w(stdout, format!("    before  {}", state(&v.before)))?;
        w(stdout, format!("    after   {}", state(&v.after)))?;
    }
    let refresh = watch
        .visits
        .iter()
        .rev()
        .find(|v| v.instr.op == Opcode::Refresh);
    if let Some(r) = refresh {
        w(stdout, format!("shifted out: {}", values(&r.before.acc)))?;
    }
    let hidden = watch.visits.len() - shown;
    if hidden > 0 {
        w(
            stdout,
            format!(
                "# {hidden} more instruction(s) passed through without acting (--all lists them)"
            ),
        )?;
    }
    Ok(())
}
