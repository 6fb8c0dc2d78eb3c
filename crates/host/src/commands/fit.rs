//! `cwisim fit`: the narrowest fixed-point registers that draw a scene within a given
//! error — model only what the scene requires. The scene is drawn once by its renderer;
//! the search is `cwisim_study::fit`'s (its documentation says how it goes and what the
//! budget measures); this is the command.

use super::MachineArgs;
use crate::draw::DrawArgs;
use crate::error::CliError;
use clap::Args;
use cwisim_study::fit::{fit_scene, q, SceneFit, REGISTERS};
use cwisim_xproc::numeric::{Numeric, Overflow};
use std::io::Write;
use std::path::PathBuf;

/// The arguments of `cwisim fit`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct FitArgs {
    /// The scene: a file or an embedded name (default: the pot).
    #[arg(value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// The largest error the registers may add at any pixel and channel, against the f64
    /// array on the same instruction stream (e.g. 0.001953125 or 1/512).
    #[arg(long, value_name = "E", value_parser = parse_error_budget)]
    pub max_error: f64,
    /// What the registers do when a value does not fit.
    #[arg(long, value_enum, default_value_t = OverflowArg::Saturate)]
    pub overflow: OverflowArg,
    /// How to draw it.
    #[command(flatten)]
    pub draw: DrawArgs,
    /// The machine model (timing only; the formats do not change cycles).
    #[command(flatten)]
    pub machine: MachineArgs,
    /// Also synthesize one X-processor of the format found, for the scene's opcodes, in
    /// Yosys (`cwisim rtl --area`; docs/HARDWARE.md): its cells, flip-flops and NAND2
    /// equivalents.
    #[arg(long)]
    pub area: bool,
    /// With --area: also place and route an array of 8 processors of the format on this
    /// FPGA (`cwisim rtl --fpga`: ice40-hx8k, ice40-up5k, ice40-hx1k) and print its
    /// maximum clock and the processors that fit one device.
    #[arg(long, value_name = "DEVICE", requires = "area")]
    pub fpga: Option<String>,
    /// Threads: the scene's exact visibility, then the candidate formats, replayed on N
    /// threads at once (0: one per core); the format found, its figures and the count of
    /// replays are the same at any N.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub threads: usize,
}

/// `--overflow`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OverflowArg {
    /// Two's complement wrap-around.
    Wrap,
    /// Clamp to the register's range.
    Saturate,
}

pub(crate) fn parse_error_budget(s: &str) -> Result<f64, String> {
    let v = match s.split_once('/') {
        Some((a, b)) => {
            let (a, b): (f64, f64) = (
                a.trim()
                    .parse()
                    .map_err(|_| format!("`{s}` is not a number or a fraction"))?,
                b.trim()
                    .parse()
                    .map_err(|_| format!("`{s}` is not a number or a fraction"))?,
            );
            a / b
        }
        None => s
            .trim()
            .parse()
            .map_err(|_| format!("`{s}` is not a number or a fraction such as 1/512"))?,
    };
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "the error budget must be finite and > 0, found {s}"
        ))
    }
}

/// The processors `fit --area --fpga` places: enough for the shell's and the bus's share
/// to be small, few enough for a minute of place and route.
const FIT_FPGA_PROCESSORS: u32 = 8;

/// Runs `cwisim fit`.
pub fn run(args: &FitArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    cwisim_scene::budget::check_threads(args.threads).map_err(CliError::Usage)?;
    if args.area {
        // Yosys, before the search
        super::rtl::require_tools(&["yosys"])?;
    }
    let device = match &args.fpga {
        Some(name) => Some(super::rtl::fpga_device(name)?),
        None => None,
    };
    let machine = args.machine.load()?;
    let stage = crate::progress::Stage::new(progress, "fit: drawing the scene");
    let drawn = args.draw.draw_on(args.scene.as_deref(), args.threads)?;
    let overflow = match args.overflow {
        OverflowArg::Wrap => Overflow::Wrap,
        OverflowArg::Saturate => Overflow::Saturate,
    };
    stage.message("fit: replaying the stream in candidate formats");
    let SceneFit {
        fit,
        header,
        instructions,
    } = fit_scene(
        &*drawn.renderer,
        args.scene.as_deref(),
        args.draw.size,
        &machine,
        args.max_error,
        overflow,
        args.threads,
        None,
    )?;
    drop(stage);
    let out = stdout;
    let w = |out: &mut dyn Write, label: &str, value: String| writeln!(out, "{label:<16}{value}");
    (|| -> std::io::Result<()> {
        w(
            out,
            "scene",
            format!(
                "{} ({}, {}×{}, {} channel(s)), {} instructions",
                drawn.source.name(),
                drawn.kind,
                header.width,
                header.lines,
                header.channels,
                instructions
            ),
        )?;
        w(out, "budget", format!("the registers may add at most {:.4e} to any value (against the f64 array)", args.max_error))?;
        w(out, "registers", Numeric::Fixed(fit.format).to_string())?;
        w(out, "search", "no register can lose a bit, no two can each lose one, no register can give two for one more in another: the narrowest the search found, a local minimum (docs/TRADEOFF.md)".to_string())?;
        w(out, "its error", format!("{:.4e} against the f64 array; {:.4e} against the exact image (the f64 array alone: {:.4e}, the Y-processor's approximation)", fit.error, fit.exact_error, fit.f64_error))?;
        let total: u32 = (0..4).map(|k| {
            let q = q(&fit.format, k);
            q.int_bits + q.frac_bits
        }).sum();
        w(out, "bits", format!("{total} in all (I, dI, ddI, acc)"))?;
        let mut needs: Vec<(usize, f64)> = fit.one_bit_less.iter().cloned().enumerate().collect();
        needs.sort_by(|a, b| b.1.total_cmp(&a.1));
        for (k, e) in &fit.one_bit_less.iter().cloned().enumerate().collect::<Vec<_>>() {
            let qk = q(&fit.format, *k);
            w(
                out,
                &format!("  {}", REGISTERS[*k]),
                format!(
                    "{}.{} ({} bits); one fraction bit fewer: max error {}",
                    qk.int_bits,
                    qk.frac_bits,
                    qk.int_bits + qk.frac_bits,
                    if e.is_nan() { "-".into() } else if e.is_infinite() { "overflow".into() } else { format!("{e:.3e}") }
                ),
            )?;
        }
        let most = needs.first().map(|(k, _)| REGISTERS[*k]).unwrap_or("-");
        let top = (0..4).map(|k| q(&fit.format, k).frac_bits).max().unwrap_or(0);
        let widest: Vec<&str> = (0..4)
            .filter(|k| q(&fit.format, *k).frac_bits == top)
            .map(|k| REGISTERS[k])
            .collect();
        w(
            out,
            "needs the bits",
            format!(
                "{} ({top} fraction bits); losing one costs most in {most}",
                widest.join(" and ")
            ),
        )?;
        w(out, "replays", fit.runs.to_string())?;
        out.flush()
    })()
    .map_err(CliError::Stdout)?;
    if args.area {
        let stage = crate::progress::Stage::new(progress, "fit: synthesizing one processor");
        let a = super::rtl::scene_area(&*drawn.renderer, &machine, fit.format)?;
        drop(stage);
        w(
            out,
            "area",
            format!(
                "one processor: {} cells ({} flip-flops, {} logic), about {:.0} NAND2 equivalents (Yosys synth; docs/HARDWARE.md)",
                a.total, a.flip_flops, a.logic, a.nand2
            ),
        )
        .and_then(|()| out.flush())
        .map_err(CliError::Stdout)?;
    }
    if let Some(device) = &device {
        let stage = crate::progress::Stage::new(progress, "fit: placing and routing 8 processors");
        let (r, width) = super::rtl::scene_fpga(
            &*drawn.renderer,
            &machine,
            fit.format,
            device,
            FIT_FPGA_PROCESSORS,
        )?;
        drop(stage);
        w(
            out,
            "fpga",
            format!(
                "{} processors on the {}: {} of {} logic cells, fmax {:.2} MHz (nextpnr-ice40); about {} processors fit one device, {} for the width of {width}",
                r.width,
                device.name,
                r.logic_cells,
                device.cells,
                r.fmax_mhz,
                r.fit,
                if r.fit == 0 { "none".to_string() } else { format!("{} device(s)", u64::from(width).div_ceil(r.fit)) }
            ),
        )
        .and_then(|()| out.flush())
        .map_err(CliError::Stdout)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_parse_as_numbers_or_fractions() {
        assert_eq!(parse_error_budget("1/512"), Ok(1.0 / 512.0));
        assert_eq!(parse_error_budget("0.25"), Ok(0.25));
        assert!(parse_error_budget("0").is_err());
        assert!(parse_error_budget("1/0").is_err());
        assert!(parse_error_budget("x").is_err());
    }
}
