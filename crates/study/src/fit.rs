//! The narrowest fixed-point registers that draw a stream within a given error — model
//! only what the scene requires (`cwisim fit`).
//!
//! The stream is replayed on the array in candidate formats. For each register (I, dI,
//! ddI, the accumulator) in turn, the others held generous, a binary search finds the
//! fewest integer bits with no overflow, then the fewest fraction bits within the budget;
//! the combination is then checked together and widened a bit at a time (the register
//! whose extra bit helps most) until it holds, and finally every bit that is no longer
//! needed is given back (one register, one bit at a time, while the whole still holds):
//! no single register can then lose a bit.
//!
//! The budget is for what the registers add: the max distance, over every pixel and
//! channel, between the fixed-point array's output and the f64 array's on the same
//! stream — the exact arithmetic of that stream (f64 is exact to ~1e-16 here). The
//! renderer's own approximations (Gouraud at pixel centres, eval0 edges, point sampling)
//! are not the registers' doing and no format could remove them; they are reported beside
//! it, as the distance of both outputs from the exact box-filtered image.

use crate::error::StudyError;
use crate::tradeoff::errors;
use cwisim_isa::{Instruction, TraceWrite};
use cwisim_xproc::numeric::{FixedFormat, Numeric, Overflow, Q};
use cwisim_xproc::{ImageSink, Machine, RunStats, Timing};

/// The four registers.
pub const REGISTERS: [&str; 4] = ["I", "dI", "ddI", "acc"];

/// The most fraction bits tried.
const MAX_FRAC: u32 = 40;
/// The most integer bits tried.
const MAX_INT: u32 = 12;

/// Register `k` (in [`REGISTERS`] order) of a format.
pub fn q(f: &FixedFormat, k: usize) -> Q {
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
pub struct Bench<'a> {
    header: cwisim_isa::TraceHeader,
    instructions: &'a [Instruction],
    machine: &'a Machine,
    /// The f64 array's output: what the budget is measured against.
    reference: Vec<f64>,
    /// The exact box-filtered image.
    exact: &'a [f64],
    runs: u64,
}

impl<'a> Bench<'a> {
    /// The bench of a stream for `header`, its error measured against the f64 array's
    /// output (run here once) and reported against `exact`.
    pub fn new(
        header: cwisim_isa::TraceHeader,
        instructions: &'a [Instruction],
        machine: &'a Machine,
        exact: &'a [f64],
    ) -> Result<Bench<'a>, StudyError> {
        let mut bench = Bench {
            header,
            instructions,
            machine,
            reference: Vec::new(),
            exact,
            runs: 0,
        };
        bench.reference = bench.run(&Numeric::F64)?.0;
        Ok(bench)
    }

    /// The image's max error and the overflows, in `numeric`.
    fn try_format(&mut self, numeric: &Numeric) -> Result<(f64, u64), StudyError> {
        self.runs += 1;
        let (image, stats) = self.run(numeric)?;
        Ok((errors(&image, &self.reference).0, stats.totals.overflows))
    }

    fn run(&self, numeric: &Numeric) -> Result<(Vec<f64>, RunStats), StudyError> {
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
                w.write(i).map_err(StudyError::Array)?;
            }
            w.finish().map_err(StudyError::Array)?;
            w.into_stats().expect("finished")
        };
        Ok((sink.finish()?.data, stats))
    }

    fn fits(&mut self, f: &FixedFormat, budget: f64) -> Result<bool, StudyError> {
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

/// Finds the narrowest format for the bench's stream within `budget` of the f64 array.
pub fn fit_format(
    bench: &mut Bench<'_>,
    budget: f64,
    overflow: Overflow,
) -> Result<Fit, StudyError> {
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
        return Err(StudyError::Usage(format!(
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
            return Err(StudyError::Usage("the fit did not converge".into()));
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
            return Err(StudyError::Usage("the fit did not converge".into()));
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
    let f64_error = errors(&bench.reference, bench.exact).0;
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
