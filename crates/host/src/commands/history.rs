//! `cwisim history`: pixel history — every instruction that reached one processor on one
//! scanline, in order, with the cycle it arrived and the processor's registers and flags
//! just **before** and just **after** it acted there (values as at that moment).
//!
//! It replays the trace on the cycle-stepped engine (the reference model) up to the
//! scanline asked for, watching one processor. Each instruction is headed by its note
//! (where it came from: the renderer's `# row 3 trapezium 4 (polygon 2): case 8: …`), as
//! in the trace.

use super::MachineArgs;
use crate::error::CliError;
use crate::progress::Progress;
use clap::Args;
use cwisim_study::history::{history_lines, pixel_history_with_progress};
use std::io::Write;
use std::path::PathBuf;

/// The arguments of `cwisim history`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct HistoryArgs {
    /// The trace (.cwt, .jsonl, .cwb), or a scene (a .json file or an embedded name:
    /// `cwisim scenes`) drawn with the drawing options below, as `render` draws it.
    #[arg(value_name = "TRACE|SCENE")]
    pub trace: PathBuf,
    /// The processor (pixel column), from 0.
    #[arg(long, value_name = "X")]
    pub x: u32,
    /// The scanline, from 0 (counted over the whole trace). `--y` is its old name.
    #[arg(long = "line", alias = "y", value_name = "Y")]
    pub y: u64,
    /// Also list the instructions whose token only passed through the processor.
    #[arg(long)]
    pub all: bool,
    /// The machine model (for the cycles).
    #[command(flatten)]
    pub machine: MachineArgs,

    /// The array's registers: f64 (the reference), f32, or fixed point
    /// fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate] (M integer bits with
    /// the sign, N fraction bits; docs/ACCURACY.md).
    #[arg(long, value_name = "FORMAT", default_value = "f64")]
    pub numeric: cwisim_xproc::Numeric,
    /// How to draw a scene (refused with a trace).
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: crate::draw::DrawArgs,
}

/// Runs `cwisim history`.
pub fn run(args: &HistoryArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    crate::input::drawing_applies(&args.draw, &[Some(&args.trace)])?;
    let machine = args.machine.load()?;
    let (mut file, size) = crate::input::open_noted(&args.trace, &args.draw)?;
    let header = *file.header();
    if args.x >= header.width {
        return Err(CliError::Usage(format!(
            "--x {} is outside the array: {} has processors 0..={}",
            args.x,
            args.trace.display(),
            header.width - 1
        )));
    }
    let mut bar = Progress::new(size, progress);
    let history = pixel_history_with_progress(
        &mut *file,
        &machine,
        &args.numeric,
        args.x as usize,
        args.y,
        &mut |bytes| bar.update(bytes),
    )?;
    drop(bar);
    // the rest of the file, checked though not replayed: no success on a damaged trace
    file.check_to_end()?;
    let history = match history {
        Ok(history) => history,
        Err(lines) => {
            return Err(CliError::Usage(format!(
                "--line {}: {} outputs only {lines} scanline(s) (0..={})",
                args.y,
                args.trace.display(),
                lines.saturating_sub(1)
            )))
        }
    };
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
    for line in history_lines(&history, args.all) {
        w(stdout, line)?;
    }
    Ok(())
}
