//! `cwisim fit`: the narrowest fixed-point registers that draw a scene within a given
//! error — model only what the scene requires.
//!
//! The scene is prepared and scan-converted once; the instruction stream is then replayed
//! on the array in candidate formats. For each register (I, dI, ddI, the accumulator) in
//! turn, the others held generous, a binary search finds the fewest integer bits with no
//! overflow, then the fewest fraction bits within the budget; the combination is then
//! checked together and widened a bit at a time (the register whose extra bit helps most)
//! until it holds, and finally every bit that is no longer needed is given back (one
//! register, one bit at a time, while the whole still holds): no single register can then
//! lose a bit.
//!
//! The budget is for what the registers add: the max distance, over every pixel and
//! channel, between the fixed-point array's output and the f64 array's on the same
//! stream — the exact arithmetic of that stream (f64 is exact to ~1e-16 here). The
//! Y-processor's own approximations (Gouraud at pixel centres, eval0 edges, point
//! sampling) are not the registers' doing and no format could remove them; they are
//! reported beside it, as the distance of both outputs from the exact box-filtered image.

use super::MachineArgs;
use crate::commands::tradeoff::{errors, exact_image};
use crate::draw::DrawArgs;
use crate::error::CliError;
use clap::Args;
use cwisim_isa::{Instruction, TraceWrite};
use cwisim_xproc::numeric::{FixedFormat, Numeric, Overflow, Q};
use cwisim_xproc::{ImageSink, Machine, RunStats, Timing};
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
}

/// `--overflow`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OverflowArg {
    /// Two's complement wrap-around.
    Wrap,
    /// Clamp to the register's range.
    Saturate,
}

fn parse_error_budget(s: &str) -> Result<f64, String> {
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

/// The four registers.
const REGISTERS: [&str; 4] = ["I", "dI", "ddI", "acc"];

/// The most fraction bits tried.
const MAX_FRAC: u32 = 40;
/// The most integer bits tried.
const MAX_INT: u32 = 12;

fn q(f: &FixedFormat, k: usize) -> Q {
    match k {
        0 => f.i,
        1 => f.di,
        2 => f.ddi,
        _ => f.acc,
    }
}

fn set_q(f: &mut FixedFormat, k: usize, v: Q) {
    match k {
        0 => f.i = v,
        1 => f.di = v,
        2 => f.ddi = v,
        _ => f.acc = v,
    }
}

/// A replayer of one instruction stream in candidate formats.
struct Bench<'a> {
    header: cwisim_isa::TraceHeader,
    instructions: &'a [Instruction],
    machine: &'a Machine,
    /// The f64 array's output: what the budget is measured against.
    reference: &'a [f64],
    /// The exact box-filtered image.
    exact: &'a [f64],
    runs: u64,
}

impl Bench<'_> {
    /// The image's max error and the overflows, in `numeric`.
    fn try_format(&mut self, numeric: &Numeric) -> Result<(f64, u64), CliError> {
        self.runs += 1;
        let (image, stats) = self.run(numeric)?;
        Ok((errors(&image, self.reference).0, stats.totals.overflows))
    }

    fn run(&self, numeric: &Numeric) -> Result<(Vec<f64>, RunStats), CliError> {
        let mut sink = ImageSink::new(
            self.header.width as usize,
            self.header.channel_count(),
            ImageSink::DEFAULT_LIMIT_BYTES,
        );
        let stats = {
            let mut w = cwisim_xproc::EngineWriter::with_numeric(
                &self.header,
                self.machine,
                Timing::Fast,
                numeric,
                &mut sink,
            )?;
            for i in self.instructions {
                w.write(i)
                    .map_err(|e| CliError::Usage(format!("the array failed: {e}")))?;
            }
            w.finish()
                .map_err(|e| CliError::Usage(format!("the array failed: {e}")))?;
            w.into_stats().expect("finished")
        };
        Ok((sink.finish()?.data, stats))
    }

    fn fits(&mut self, f: &FixedFormat, budget: f64) -> Result<bool, CliError> {
        let (e, overflows) = self.try_format(&Numeric::Fixed(*f))?;
        Ok(overflows == 0 && e <= budget)
    }
}

/// The result of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The narrowest format found.
    pub format: FixedFormat,
    /// Its max distance from the f64 array's output.
    pub error: f64,
    /// Its max error against the exact image.
    pub exact_error: f64,
    /// The f64 array's max error against the exact image (the Y-processor's share).
    pub f64_error: f64,
    /// For each register, the max error with one fraction bit fewer (how much it needs
    /// its last bit).
    pub one_bit_less: [f64; 4],
    /// Replays tried.
    pub runs: u64,
}

/// Finds the narrowest format for `instructions` within `budget` of `reference`.
fn fit_format(bench: &mut Bench<'_>, budget: f64, overflow: Overflow) -> Result<Fit, CliError> {
    let generous = Q {
        int_bits: MAX_INT,
        frac_bits: MAX_FRAC,
    };
    let wide = FixedFormat {
        i: generous,
        di: generous,
        ddi: generous,
        acc: generous,
        overflow,
    };
    if !bench.fits(&wide, budget)? {
        return Err(CliError::Usage(format!(
            "even {} registers do not reach {budget:.3e}: the budget is too tight for fixed point up to {MAX_INT}.{MAX_FRAC}",
            Numeric::Fixed(wide)
        )));
    }
    let mut chosen = wide;
    for k in 0..REGISTERS.len() {
        // the fewest integer bits, then the fewest fraction bits, the others generous
        let mut lo = 1;
        let mut hi = MAX_INT;
        while lo < hi {
            let mid = (lo + hi) / 2;
            let mut f = wide;
            set_q(
                &mut f,
                k,
                Q {
                    int_bits: mid,
                    frac_bits: MAX_FRAC,
                },
            );
            if bench.fits(&f, budget)? {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        let int_bits = lo;
        let (mut lo, mut hi) = (0, MAX_FRAC);
        while lo < hi {
            let mid = (lo + hi) / 2;
            let mut f = wide;
            set_q(
                &mut f,
                k,
                Q {
                    int_bits,
                    frac_bits: mid,
                },
            );
            if bench.fits(&f, budget)? {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        set_q(
            &mut chosen,
            k,
            Q {
                int_bits,
                frac_bits: lo,
            },
        );
    }
    // together, the errors add: widen the register whose extra bit helps most
    let mut guard = 0;
    while !bench.fits(&chosen, budget)? {
        guard += 1;
        if guard > 4 * MAX_FRAC {
            return Err(CliError::Usage("the fit did not converge".into()));
        }
        let mut best: Option<(f64, usize)> = None;
        for k in 0..REGISTERS.len() {
            let mut f = chosen;
            let old = q(&f, k);
            if old.frac_bits >= MAX_FRAC {
                continue;
            }
            set_q(
                &mut f,
                k,
                Q {
                    frac_bits: old.frac_bits + 1,
                    ..old
                },
            );
            let (e, overflows) = bench.try_format(&Numeric::Fixed(f))?;
            let e = if overflows > 0 { f64::INFINITY } else { e };
            if best.is_none_or(|(b, _)| e < b) {
                best = Some((e, k));
            }
        }
        let Some((_, k)) = best else {
            return Err(CliError::Usage("the fit did not converge".into()));
        };
        let old = q(&chosen, k);
        set_q(
            &mut chosen,
            k,
            Q {
                frac_bits: old.frac_bits + 1,
                ..old
            },
        );
    }
    // then give back every bit the others' widening made unnecessary
    loop {
        let mut changed = false;
        for k in 0..REGISTERS.len() {
            let old = q(&chosen, k);
            for smaller in [
                Q {
                    frac_bits: old.frac_bits.wrapping_sub(1),
                    ..old
                },
                Q {
                    int_bits: old.int_bits.wrapping_sub(1),
                    ..old
                },
            ] {
                if smaller.frac_bits > MAX_FRAC
                    || smaller.int_bits == 0
                    || smaller.int_bits > MAX_INT
                {
                    continue;
                }
                let mut f = chosen;
                set_q(&mut f, k, smaller);
                if bench.fits(&f, budget)? {
                    chosen = f;
                    changed = true;
                    break;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let (error, _) = bench.try_format(&Numeric::Fixed(chosen))?;
    let exact_error = errors(&bench.run(&Numeric::Fixed(chosen))?.0, bench.exact).0;
    let f64_error = errors(bench.reference, bench.exact).0;
    let mut one_bit_less = [0.0; 4];
    for (k, slot) in one_bit_less.iter_mut().enumerate() {
        let old = q(&chosen, k);
        if old.frac_bits == 0 {
            *slot = f64::NAN;
            continue;
        }
        let mut f = chosen;
        set_q(
            &mut f,
            k,
            Q {
                frac_bits: old.frac_bits - 1,
                ..old
            },
        );
        let (e, overflows) = bench.try_format(&Numeric::Fixed(f))?;
        *slot = if overflows > 0 { f64::INFINITY } else { e };
    }
    Ok(Fit {
        format: chosen,
        error,
        exact_error,
        f64_error,
        one_bit_less,
        runs: bench.runs,
    })
}

/// Runs `cwisim fit`.
pub fn run(args: &FitArgs, stdout: &mut dyn Write) -> Result<(), CliError> {
    let machine = args.machine.load()?;
    let drawn = args.draw.draw(args.scene.as_deref())?;
    let exact = exact_image(args.scene.as_deref(), args.draw.size)?;
    let header = drawn.renderer.header();
    let mut instructions: Vec<Instruction> = Vec::new();
    cwisim_render::emit(&*drawn.renderer, &mut instructions)?;
    let mut bench = Bench {
        header,
        instructions: &instructions,
        machine: &machine,
        reference: &[],
        exact: &exact,
        runs: 0,
    };
    let reference = bench.run(&Numeric::F64)?.0;
    bench.reference = &reference;
    let overflow = match args.overflow {
        OverflowArg::Wrap => Overflow::Wrap,
        OverflowArg::Saturate => Overflow::Saturate,
    };
    let fit = fit_format(&mut bench, args.max_error, overflow)?;
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
                instructions.len()
            ),
        )?;
        w(out, "budget", format!("the registers may add at most {:.4e} to any value (against the f64 array)", args.max_error))?;
        w(out, "narrowest", Numeric::Fixed(fit.format).to_string())?;
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
    .map_err(CliError::Stdout)
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
