//! `cwisim vcd`: a per-cycle waveform (Value Change Dump) of one scanline.
//!
//! The trace is replayed on the cycle-stepped engine (the reference model) with a
//! [`Probe`] that watches a window of processors. From the cycle the instruction bus
//! starts issuing the first instruction of scanline `Y` to the cycle scanline `Y` leaves
//! the array, every change of the bus and of the watched processors' registers and flags
//! is written through the `vcd` crate.
//!
//! The recording and the writing are `cwisim_study::vcd`'s (its documentation says what
//! a dump holds and what is checked); this is the command.

use super::MachineArgs;
use crate::error::CliError;
use crate::files::{write_atomic, Io};
use crate::progress::Progress;
use crate::range::{parse_range, Range};
use clap::Args;
use cwisim_study::vcd::{record_scanline_with_progress, write_vcd};
use std::path::PathBuf;

/// The widest array dumped whole when neither `--from` nor `--to` is given.
///
/// 512 covers the embedded scenes at their default sizes (a busy scanline of the pot,
/// 400 wide, is a 2.5 MB dump); wider arrays name a window.
pub const MAX_DEFAULT_WINDOW: u32 = 512;

/// The arguments of `cwisim vcd`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct VcdArgs {
    /// The trace (.cwt, .jsonl, .cwb), or a scene (a .json file or an embedded name:
    /// `cwisim scenes`) drawn with the drawing options below, as `render` draws it.
    #[arg(value_name = "TRACE|SCENE")]
    pub trace: PathBuf,

    /// The scanline, from 0 (counted over the whole trace, as `cwisim run` outputs them).
    #[arg(long, value_name = "Y")]
    pub line: u64,

    /// The processors (pixel columns) to dump: N, A..B (B not included), A..=B or A..
    /// (to the last). Default: the whole array when it is at most 512 processors wide; a wider
    /// one is refused: choose a window.
    #[arg(long = "x", value_name = "X", value_parser = parse_range, conflicts_with_all = ["from", "to"])]
    pub x: Option<Range>,

    /// First processor of the window (old spelling of `--x X0-`).
    #[arg(long, value_name = "X0", hide = true)]
    pub from: Option<u32>,

    /// Last processor of the window (old spelling of `--x …-X1`).
    #[arg(long, value_name = "X1", hide = true)]
    pub to: Option<u32>,

    /// The VCD file to write (replaced only once the replay succeeded).
    #[arg(short = 'o', long = "output", value_name = "OUT.vcd")]
    pub output: PathBuf,

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

/// Runs `cwisim vcd`.
pub fn run(args: &VcdArgs, progress: bool) -> Result<(), CliError> {
    crate::input::drawing_applies(&args.draw, &[Some(&args.trace)])?;
    Io::new()
        .source("trace being read", Some(&args.trace))
        .machine(&args.machine)
        .output("-o", Some(&args.output))
        .check()?;
    let machine = args.machine.load()?;
    let (mut file, size) = crate::input::open_sized(&args.trace, &args.draw, false)?;
    let header = *file.header();
    let (from, to) = window(args, header.width)?;
    let mut bar = Progress::new(size, progress);
    let recorded = record_scanline_with_progress(
        &mut *file,
        &machine,
        &args.numeric,
        args.line,
        from as usize,
        to as usize,
        &mut |bytes| bar.update(bytes),
    )?;
    drop(bar);
    // the rest of the file, checked though not replayed: no success on a damaged trace
    file.check_to_end()?;
    let wave = match recorded {
        Ok(wave) => wave,
        Err(lines) => {
            return Err(CliError::Usage(format!(
                "--line {}: {} outputs only {lines} scanline(s){}",
                args.line,
                args.trace.display(),
                if lines == 0 {
                    String::new()
                } else {
                    format!(" (0..={})", lines - 1)
                }
            )))
        }
    };
    write_atomic(&args.output, |w| {
        write_vcd(w, &wave).map_err(|e| CliError::write(&args.output, e))
    })
}

/// The window `(from, to)`, inclusive, checked against the array.
fn window(args: &VcdArgs, width: u32) -> Result<(u32, u32), CliError> {
    let last = width.saturating_sub(1);
    let (from, to) = match args.x {
        Some(r) => {
            // the range as the user wrote it, in the message: never a clamped copy
            let outside = || {
                CliError::Usage(format!(
                    "--x {r}: the window is outside the array: {} has processors 0..={last}",
                    args.trace.display(),
                ))
            };
            let from = u32::try_from(r.first).map_err(|_| outside())?;
            let to = match r.last {
                Some(l) => u32::try_from(l).map_err(|_| outside())?,
                None => last,
            };
            if from > to || to >= width {
                return Err(outside());
            }
            (from, to)
        }
        None => {
            if args.from.is_none() && args.to.is_none() && width > MAX_DEFAULT_WINDOW {
                return Err(CliError::Usage(format!(
                    "{} is {width} processors wide: choose at most {MAX_DEFAULT_WINDOW} with \
--x X0..X1 (or name a wider window explicitly)",
                    args.trace.display()
                )));
            }
            (args.from.unwrap_or(0), args.to.unwrap_or(last))
        }
    };
    if from > to || to >= width {
        return Err(CliError::Usage(format!(
            "--x {from}..={to}: the window is outside the array: {} has processors \
0..={last}; give --x X0..X1 with X0 < X1 <= {width}",
            args.trace.display(),
        )));
    }
    Ok((from, to))
}
