//! The narrowest fixed-point registers that draw a stream within a given error — model
//! only what the scene requires (`cwisim fit`).
//!
//! The stream is replayed on the array in candidate formats. For each register (I, dI,
//! ddI, the accumulator) in turn, the others held generous, a binary search finds the
//! fewest integer bits with no overflow, then the fewest fraction bits within the budget;
//! the combination is then checked together and widened a bit at a time (the register
//! whose extra bit helps most) until it holds, and finally every bit that is no longer
//! needed is given back (one register, one bit at a time, while the whole still holds)
//! and two registers changed at once (a bit fewer in each, or two of one for one of the
//! other) while that narrows the whole: a local minimum of the total width, checked against an exhaustive search on a
//! small stream in the tests.
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
use std::sync::atomic::{AtomicBool, Ordering};

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
    threads: usize,
    cancel: Option<&'a AtomicBool>,
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
            threads: 1,
            cancel: None,
        };
        bench.reference = bench.run(&Numeric::F64)?.0;
        Ok(bench)
    }

    /// The bench replaying candidates on `threads` threads (0: one per core; 1 unless
    /// told). The search goes the same way, to the same format and the same count of
    /// replays, at any count: candidates tried one after another until one holds are
    /// replayed a batch at a time, and those after the first that holds are not counted.
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = cwisim_scene::budget::resolve_threads(threads);
        self
    }

    /// The bench stopping, with [`StudyError::Cancelled`], at the first replay after
    /// `flag` is set (a Python caller's Ctrl-C).
    pub fn cancel(mut self, flag: Option<&'a AtomicBool>) -> Self {
        self.cancel = flag;
        self
    }

    /// The image's max error and the overflows, in `numeric`.
    fn try_format(&mut self, numeric: &Numeric) -> Result<(f64, u64), StudyError> {
        self.runs += 1;
        self.error_of(numeric)
    }

    /// The image's max error and the overflows, in `numeric` (not counted).
    fn error_of(&self, numeric: &Numeric) -> Result<(f64, u64), StudyError> {
        let (image, stats) = self.run(numeric)?;
        Ok((errors(&image, &self.reference).0, stats.totals.overflows))
    }

    /// `jobs` done on the bench's threads, their results in order.
    fn map<T: Sync, R: Send>(
        &self,
        jobs: &[T],
        job: impl Fn(&Bench<'_>, &T) -> Result<R, StudyError> + Sync,
    ) -> Result<Vec<R>, StudyError> {
        let mut out = Vec::with_capacity(jobs.len());
        crate::parallel::ordered(
            jobs.len(),
            self.threads,
            |k| job(self, &jobs[k]),
            |event| {
                if let crate::parallel::Event::Done(_, r) = event {
                    out.push(r);
                }
            },
        )?;
        Ok(out)
    }

    /// The errors and overflows of every format of `formats`, each replay counted.
    fn try_all(&mut self, formats: &[Numeric]) -> Result<Vec<(f64, u64)>, StudyError> {
        let out = self.map(formats, |bench, numeric| bench.error_of(numeric))?;
        self.runs += formats.len() as u64;
        Ok(out)
    }

    /// The first of `candidates` that fits `budget`, trying them in order as one thread
    /// would — a batch of as many as the bench has threads at a time —, counting the
    /// replays up to it.
    fn first_fit(
        &mut self,
        candidates: &[FixedFormat],
        budget: f64,
    ) -> Result<Option<FixedFormat>, StudyError> {
        for batch in candidates.chunks(self.threads.max(1)) {
            let fits = self.map(batch, |bench, f| {
                let (e, overflows) = bench.error_of(&Numeric::Fixed(*f))?;
                Ok(overflows == 0 && e <= budget)
            })?;
            match fits.iter().position(|&fits| fits) {
                Some(k) => {
                    self.runs += k as u64 + 1;
                    return Ok(Some(batch[k]));
                }
                None => self.runs += batch.len() as u64,
            }
        }
        Ok(None)
    }

    fn run(&self, numeric: &Numeric) -> Result<(Vec<f64>, RunStats), StudyError> {
        if self.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Err(StudyError::Cancelled);
        }
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

/// `f` with register `k` changed by `int` integer and `frac` fraction bits, if that stays
/// within the bits tried (at least one integer bit).
fn nudged(f: &FixedFormat, k: usize, int: i32, frac: i32) -> Option<FixedFormat> {
    let old = q(f, k);
    let int_bits = old.int_bits.checked_add_signed(int)?;
    let frac_bits = old.frac_bits.checked_add_signed(frac)?;
    if int_bits == 0 || int_bits > MAX_INT || frac_bits > MAX_FRAC {
        return None;
    }
    let mut out = *f;
    set_q(
        &mut out,
        k,
        Q {
            int_bits,
            frac_bits,
        },
    );
    Some(out)
}

/// Takes single bits away from `chosen`, one register at a time, while it still fits:
/// afterwards no register can lose a bit.
fn give_back(
    bench: &mut Bench<'_>,
    chosen: &mut FixedFormat,
    budget: f64,
) -> Result<(), StudyError> {
    loop {
        let mut changed = false;
        for k in 0..REGISTERS.len() {
            let candidates: Vec<FixedFormat> = [(0, -1), (-1, 0)]
                .into_iter()
                .filter_map(|(int, frac)| nudged(chosen, k, int, frac))
                .collect();
            if let Some(f) = bench.first_fit(&candidates, budget)? {
                *chosen = f;
                changed = true;
            }
        }
        if !changed {
            return Ok(());
        }
    }
}

/// One change of two registers at once that narrows `chosen` and still fits: a bit fewer
/// in each (the rounding errors of two registers can cancel, so that both losing a bit
/// holds where either alone does not), or two bits fewer in one (fraction or integer) for
/// one fraction bit more in another. `true` if one was made.
fn trade(bench: &mut Bench<'_>, chosen: &mut FixedFormat, budget: f64) -> Result<bool, StudyError> {
    let mut candidates = Vec::new();
    for a in 0..REGISTERS.len() {
        for b in a + 1..REGISTERS.len() {
            for (ia, fa) in [(0, -1), (-1, 0)] {
                for (ib, fb) in [(0, -1), (-1, 0)] {
                    candidates
                        .extend(nudged(chosen, a, ia, fa).and_then(|f| nudged(&f, b, ib, fb)));
                }
            }
        }
    }
    for from in 0..REGISTERS.len() {
        for (int, frac) in [(0, -2), (-1, -1), (-2, 0)] {
            let Some(less) = nudged(chosen, from, int, frac) else {
                continue;
            };
            for to in (0..REGISTERS.len()).filter(|&to| to != from) {
                candidates.extend(nudged(&less, to, 0, 1));
            }
        }
    }
    match bench.first_fit(&candidates, budget)? {
        Some(f) => {
            *chosen = f;
            Ok(true)
        }
        None => Ok(false),
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

/// Finds a narrow format for the bench's stream within `budget` of the f64 array: a local
/// minimum of the total width — no register can lose a bit, no two can each lose one, and
/// no register can give two bits for one more in another — not a proven global one (an
/// exhaustive search is `(12 × 41)^4` replays).
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
    // each register alone, the others generous: the fewest integer bits, then the
    // fewest fraction bits (the four searches on the bench's threads)
    let registers: Vec<usize> = (0..REGISTERS.len()).collect();
    let alone = bench.map(&registers, |bench, &k| {
        let mut runs = 0;
        let mut fits = |f: &FixedFormat| -> Result<bool, StudyError> {
            runs += 1;
            let (e, overflows) = bench.error_of(&Numeric::Fixed(*f))?;
            Ok(overflows == 0 && e <= budget)
        };
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
            if fits(&f)? {
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
            if fits(&f)? {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        Ok((
            Q {
                int_bits,
                frac_bits: lo,
            },
            runs,
        ))
    })?;
    let mut chosen = wide;
    for (k, (register, runs)) in alone.into_iter().enumerate() {
        set_q(&mut chosen, k, register);
        bench.runs += runs;
    }
    // together, the errors add: widen the register whose extra bit helps most
    let mut guard = 0;
    while !bench.fits(&chosen, budget)? {
        guard += 1;
        if guard > 4 * MAX_FRAC {
            return Err(StudyError::Usage("the fit did not converge".into()));
        }
        let wider: Vec<(usize, Numeric)> = (0..REGISTERS.len())
            .filter_map(|k| {
                let old = q(&chosen, k);
                let f = nudged(&chosen, k, 0, 1).filter(|_| old.frac_bits < MAX_FRAC)?;
                Some((k, Numeric::Fixed(f)))
            })
            .collect();
        let formats: Vec<Numeric> = wider.iter().map(|(_, f)| *f).collect();
        let mut best: Option<(f64, usize)> = None;
        for (&(k, _), (e, overflows)) in wider.iter().zip(bench.try_all(&formats)?) {
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
    // then give back every bit the others' widening made unnecessary, and trade: two
    // bits of one register for one of another, while that narrows the whole
    loop {
        give_back(bench, &mut chosen, budget)?;
        if !trade(bench, &mut chosen, budget)? {
            break;
        }
    }
    bench.runs += 1;
    let image = bench.run(&Numeric::Fixed(chosen))?.0;
    let error = errors(&image, &bench.reference).0;
    let exact_error = errors(&image, bench.exact).0;
    let f64_error = errors(&bench.reference, bench.exact).0;
    // each register with one fraction bit fewer
    let fewer: Vec<(usize, Numeric)> = (0..REGISTERS.len())
        .filter_map(|k| Some((k, Numeric::Fixed(nudged(&chosen, k, 0, -1)?))))
        .collect();
    let formats: Vec<Numeric> = fewer.iter().map(|(_, f)| *f).collect();
    let mut one_bit_less = [f64::NAN; 4];
    for (&(k, _), (e, overflows)) in fewer.iter().zip(bench.try_all(&formats)?) {
        one_bit_less[k] = if overflows > 0 { f64::INFINITY } else { e };
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

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::{Intensity, TraceHeader};

    /// The total width of a format's four registers.
    fn bits(f: &FixedFormat) -> u32 {
        (0..4).map(|k| q(f, k).int_bits + q(f, k).frac_bits).sum()
    }

    /// On a stream of Eval2 waves (I, dI and the accumulator matter; ddI is never
    /// loaded), the fit's total width is the fewest of every combination of the three
    /// registers' formats that fit, found by trying them all.
    #[test]
    fn the_fit_is_as_narrow_as_an_exhaustive_search_on_a_small_stream() {
        let header = TraceHeader::new(12, 2, 1).unwrap();
        let instructions = [
            Instruction::eval2(0, 12, Intensity::grey(0.3), Intensity::grey(0.0625)),
            Instruction::refresh(),
            Instruction::eval2(2, 7, Intensity::grey(1.7), Intensity::grey(-0.21)),
            Instruction::eval2(4, 3, Intensity::grey(0.05), Intensity::grey(0.4)),
            Instruction::refresh(),
        ];
        let machine = Machine::default();
        let budget = 1.0 / 64.0;
        let reference = {
            let b = Bench::new(header, &instructions, &machine, &[]).unwrap();
            b.reference.clone()
        };
        let mut bench = Bench::new(header, &instructions, &machine, &reference).unwrap();
        let fit = fit_format(&mut bench, budget, Overflow::Saturate).unwrap();
        // the same search, format, figures and replays on more threads
        for threads in [2, 3, 8] {
            let mut on = Bench::new(header, &instructions, &machine, &reference)
                .unwrap()
                .threads(threads);
            let again = fit_format(&mut on, budget, Overflow::Saturate).unwrap();
            assert_eq!(again.format, fit.format, "{threads}");
            assert_eq!(again.runs, fit.runs, "{threads}");
            assert_eq!(format!("{again:?}"), format!("{fit:?}"), "{threads}");
        }
        // every I × dI × acc format up to 4.12, ddI at its narrowest (1.0)
        let mut best = u32::MAX;
        let formats = || {
            (1..=4u32).flat_map(|int_bits| {
                (0..=12u32).map(move |frac_bits| Q {
                    int_bits,
                    frac_bits,
                })
            })
        };
        let narrowest_ddi = Q {
            int_bits: 1,
            frac_bits: 0,
        };
        for i in formats() {
            for di in formats() {
                for acc in formats() {
                    let f = FixedFormat {
                        i,
                        di,
                        ddi: narrowest_ddi,
                        acc,
                        overflow: Overflow::Saturate,
                    };
                    if bits(&f) < best && bench.fits(&f, budget).unwrap() {
                        best = bits(&f);
                    }
                }
            }
        }
        assert!(fit.error <= budget);
        // what the wording claims: no register can lose a bit, and no trade narrows it
        for k in 0..4 {
            for (int, frac) in [(0, -1), (-1, 0)] {
                if let Some(f) = nudged(&fit.format, k, int, frac) {
                    assert!(!bench.fits(&f, budget).unwrap(), "{}", Numeric::Fixed(f));
                }
            }
        }
        let mut traded = fit.format;
        assert!(!trade(&mut bench, &mut traded, budget).unwrap());
        assert_eq!(
            bits(&fit.format),
            best,
            "the fit {} against the fewest bits {best}",
            Numeric::Fixed(fit.format)
        );
    }
}

/// A scene's fit ([`fit_scene`]): the fit, and the stream it was found for.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFit {
    /// The fit.
    pub fit: Fit,
    /// The stream's header.
    pub header: cwisim_isa::TraceHeader,
    /// Instructions in the stream.
    pub instructions: usize,
}

/// What `cwisim fit` does: the stream `renderer` draws for the scene SCENE names (a file
/// or an embedded name, at `size`), its exact image, and the narrowest format found for
/// it within `max_error` of the f64 array ([`fit_format`]), candidates replayed on
/// `threads` threads (the result the same at any count); stopped at the next replay once
/// `cancel` is set.
#[allow(clippy::too_many_arguments)]
pub fn fit_scene(
    renderer: &dyn cwisim_render::Renderer,
    scene: Option<&std::path::Path>,
    size: Option<cwisim_render::Size>,
    machine: &Machine,
    max_error: f64,
    overflow: Overflow,
    threads: usize,
    cancel: Option<&AtomicBool>,
) -> Result<SceneFit, StudyError> {
    let header = renderer.header();
    // the images the search holds (the exact one, the f64 array's, one per thread's
    // replay), 8 bytes a value, against the memory budget before any is made; the
    // stream's once it is drawn
    let values = u64::from(header.width) * u64::from(header.lines) * header.channel_count() as u64;
    let workers = if threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        threads
    } as u64;
    let images = (workers + 2).saturating_mul(values).saturating_mul(8);
    let budget = cwisim_scene::budget::Budget::current();
    let refuse = |e: cwisim_scene::budget::BudgetError| StudyError::Usage(e.to_string());
    budget
        .check_memory(
            &format!("fit's images ({} of {values} values)", workers + 2),
            images,
        )
        .map_err(refuse)?;
    let exact = crate::tradeoff::exact_image(scene, size)?;
    let mut instructions: Vec<Instruction> = Vec::new();
    cwisim_render::emit(renderer, &mut instructions)?;
    let stream = (instructions.len() * std::mem::size_of::<Instruction>()) as u64;
    budget
        .check_memory(
            &format!(
                "fit's images and its stream of {} instructions",
                instructions.len()
            ),
            images.saturating_add(stream),
        )
        .map_err(refuse)?;
    let mut bench = Bench::new(header, &instructions, machine, &exact)?
        .threads(threads)
        .cancel(cancel);
    let fit = fit_format(&mut bench, max_error, overflow)?;
    Ok(SceneFit {
        fit,
        header,
        instructions: instructions.len(),
    })
}
