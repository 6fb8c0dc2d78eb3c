//! What an `Eval` costs the fast engine, taken apart: synthetic frames of one order and
//! one span length against the random mixes of `benches/array.rs`'s short spans, with
//! **variants alternating in one process** (on a shared, noisy machine the only
//! comparison that holds still), and any traces given replayed the same way:
//!
//! ```text
//! cargo run --release -p cwisim-xproc --example eval_costs [--format F] [--frames N] [--only NAME] [--kernels] [TRACE...]
//! cwisim render pot --size 1024x1024 --visibility eval0 --trace pot-eval0.cwb -o pot.png
//! cargo run --release -p cwisim-xproc --example eval_costs pot-eval0.cwb
//! ```
//!
//! `--only NAME` keeps the variants whose name contains NAME (to profile one alone).
//! `--kernels` adds, on the synthetic frames, two bare `f64` adder-chain kernels outside
//! the engine (no dispatch, statistics or timing): the chain over exactly `dx`
//! processors, as the engine runs it, against a fixed window of 16 processors whose lanes
//! past `dx` add `−0.0` (which leaves every value's bits as they are) — no branch on the
//! span's length, at the price of 16 lanes of work for every span. Their accumulators are
//! held equal bit for bit.
//!
//! Each frame is 1024 scanlines of 64 `Eval`s on a 1024-wide grey array (the short-span
//! frame of the bench: spans of 4–16 processors, orders 1/2/3 in proportions 1:2:1),
//! run by `Engine::execute_all`. A trace runs twice: by `execute_all`, and instruction
//! by instruction into a `BandArray` — checked, as `cwisim render` feeds the array on
//! one thread — then taken in by the engine. Prints, per variant, the fastest frame and
//! the first quartile (FRAMES of each, 30 unless given), nanoseconds per instruction and
//! processor updates per second. docs/PERFORMANCE.md ("What an Eval costs") quotes it.

use cwisim_isa::io::read_all;
use cwisim_isa::{FileReader, Instruction, Opcode, TraceHeader, TraceWrite};
use cwisim_xproc::{numeric_engine, Band, Machine, NullSink, Numeric, Timing};
use std::path::PathBuf;
use std::time::Instant;

#[path = "../benches/common/mod.rs"]
mod common;

/// How a variant is fed to the array.
#[derive(Clone, Copy)]
enum Feed {
    /// `Engine::execute_all` on the whole frame.
    Engine,
    /// One checked `write` at a time into a `BandArray`, then `absorb`ed.
    Band,
}

struct Variant {
    name: String,
    header: TraceHeader,
    instrs: Vec<Instruction>,
    feed: Feed,
    times: Vec<f64>,
    updates: u64,
    /// A synthetic frame of `Eval1`–`Eval3` (the kernels run it), not a trace.
    synthetic: bool,
}

/// One frame of `v`; its wall time in seconds and the processor updates.
fn run(v: &Variant, numeric: &Numeric) -> (f64, u64) {
    let start = Instant::now();
    let mut engine = numeric_engine(&v.header, &Machine::default(), Timing::Fast, numeric)
        .expect("the default machine");
    match v.feed {
        Feed::Engine => engine.execute_all(&v.instrs, &mut NullSink),
        Feed::Band => {
            let mut band = engine.band_array().expect("the fast engine runs bands");
            band.start(Band::new());
            for i in &v.instrs {
                band.write(i).expect("a sound trace");
            }
            let band = band.take().expect("the trace ends with a Refresh");
            assert!(engine.absorb(&band, &mut NullSink), "a band from the start");
        }
    }
    let totals = engine.finish(&mut NullSink).totals;
    (start.elapsed().as_secs_f64(), totals.processor_updates)
}

fn main() {
    let mut numeric = Numeric::F64;
    let mut frames = 30;
    let mut traces = Vec::new();
    let mut only: Option<String> = None;
    let mut kernels = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--format" => {
                let f = args.next().expect("--format needs a numeric format");
                numeric = f.parse().unwrap_or_else(|e| panic!("--format {f}: {e}"));
            }
            "--frames" => {
                let n = args.next().expect("--frames needs a count");
                frames = n.parse().unwrap_or_else(|e| panic!("--frames {n}: {e}"));
            }
            "--kernels" => kernels = true,
            "--only" => {
                only = Some(
                    args.next()
                        .expect("--only needs a part of a variant's name"),
                )
            }
            _ => traces.push(PathBuf::from(a)),
        }
    }
    let grey = TraceHeader::new(1024, 1024, 1).expect("a header");
    let synthetic = |name: &str, order, dx| Variant {
        name: name.to_string(),
        header: grey,
        instrs: common::short_spans(1024, 1024, order, dx),
        feed: Feed::Engine,
        times: Vec::new(),
        updates: 0,
        synthetic: true,
    };
    let mut variants = vec![
        synthetic("mix, dx 4-16 (the bench)", None, None),
        synthetic("mix, dx 10", None, Some(10)),
        synthetic("Eval1, dx 4-16", Some(1), None),
        synthetic("Eval2, dx 4-16", Some(2), None),
        synthetic("Eval3, dx 4-16", Some(3), None),
        synthetic("Eval2, dx 10", Some(2), Some(10)),
        synthetic("empty (dx 0)", Some(2), Some(0)),
    ];
    for order in 1..=3 {
        for dx in [4, 16] {
            variants.push(synthetic(
                &format!("Eval{order}, dx {dx}"),
                Some(order),
                Some(dx),
            ));
        }
    }
    for path in &traces {
        let mut reader = FileReader::open(path).unwrap_or_else(|e| panic!("{e}"));
        let instrs = read_all(&mut reader).unwrap_or_else(|e| panic!("{e}"));
        let header = *cwisim_isa::TraceRead::header(&reader);
        for (feed, how) in [(Feed::Engine, "execute_all"), (Feed::Band, "band")] {
            variants.push(Variant {
                name: format!("{} ({how})", path.display()),
                header,
                instrs: instrs.clone(),
                feed,
                times: Vec::new(),
                updates: 0,
                synthetic: false,
            });
        }
    }
    if let Some(only) = &only {
        variants.retain(|v| v.name.contains(only.as_str()));
    }
    for _ in 0..frames {
        for v in &mut variants {
            let (t, updates) = run(v, &numeric);
            v.times.push(t);
            v.updates = updates;
        }
    }
    println!("{numeric}, {frames} frames each, alternating: fastest / first quartile");
    for v in &mut variants {
        v.times.sort_by(f64::total_cmp);
        let (min, q1) = (v.times[0], v.times[v.times.len() / 4]);
        println!(
            "{:36} {:7.3} / {:7.3} ms  {:5.1} ns per instruction  {:6.0} M updates/s",
            v.name,
            min * 1e3,
            q1 * 1e3,
            min * 1e9 / v.instrs.len() as f64,
            v.updates as f64 / min / 1e6,
        );
    }
    if kernels {
        compare_kernels(&variants, frames);
    }
}

/// The widest span the window kernel takes; wider ones run the loop.
const WINDOW: usize = 16;

/// An `Eval`'s `I`, `dI`, `ddI` as its order uses them, `−0.0` where it has none (adding
/// `−0.0` leaves every `f64` as it is, so every order runs as an `Eval3`).
fn wave_of(i: &Instruction) -> (f64, f64, f64) {
    let slot = |k: usize| i.value(k).first().copied().unwrap_or(-0.0);
    let d = if i.op == Opcode::Eval1 { -0.0 } else { slot(1) };
    let dd = if i.op == Opcode::Eval3 { slot(2) } else { -0.0 };
    (slot(0), d, dd)
}

/// The chain over exactly `dx` processors (negative contributions dropped, as with
/// negative accumulation off); at each `Refresh` the accumulators are cleared.
fn loop_kernel(instrs: &[Instruction], acc: &mut [f64]) -> u64 {
    let mut dropped = 0;
    for i in instrs {
        if i.op == Opcode::Refresh {
            acc.fill(0.0);
            continue;
        }
        let (mut v, mut d, dd) = wave_of(i);
        let x = i.x as usize;
        for a in &mut acc[x..x + i.dx as usize] {
            if v < 0.0 {
                dropped += 1;
            } else {
                *a += v;
            }
            v += d;
            d += dd;
        }
    }
    dropped
}

/// The same chain over a fixed window of [`WINDOW`] processors for every span that fits
/// one: the lanes past `dx` (and a dropped contribution) add `−0.0`.
fn window_kernel(instrs: &[Instruction], acc: &mut [f64]) -> u64 {
    let mut dropped = 0;
    for i in instrs {
        if i.op == Opcode::Refresh {
            acc.fill(0.0);
            continue;
        }
        let (x, dx) = (i.x as usize, i.dx as usize);
        if dx > WINDOW {
            dropped += loop_kernel(std::slice::from_ref(i), acc);
            continue;
        }
        let (mut v, mut d, dd) = wave_of(i);
        let window: &mut [f64; WINDOW] = (&mut acc[x..x + WINDOW])
            .try_into()
            .expect("room for a window at every processor");
        for (k, a) in window.iter_mut().enumerate() {
            let inside = k < dx;
            let drop = v < 0.0;
            dropped += u64::from(inside & drop);
            *a += if inside & !drop { v } else { -0.0 };
            v += d;
            d += dd;
        }
    }
    dropped
}

/// Both kernels on each synthetic frame, alternating; their accumulators held equal.
fn compare_kernels(variants: &[Variant], frames: usize) {
    type Kernel = fn(&[Instruction], &mut [f64]) -> u64;
    let kernels: [Kernel; 2] = [loop_kernel, window_kernel];
    println!("bare f64 kernels (--kernels), {frames} frames each: fastest, ns per Eval");
    for v in variants.iter().filter(|v| v.synthetic) {
        let mut best = [f64::INFINITY; 2];
        for _ in 0..frames {
            let mut results = Vec::new();
            for (k, kernel) in kernels.iter().enumerate() {
                // room for a window at the last processor
                let mut acc = vec![0.0; v.header.width as usize + WINDOW];
                let start = Instant::now();
                let dropped = kernel(&v.instrs, &mut acc);
                best[k] = best[k].min(start.elapsed().as_secs_f64());
                results.push((dropped, acc.iter().map(|a| a.to_bits()).collect::<Vec<_>>()));
            }
            assert_eq!(results[0], results[1], "{}: the kernels agree", v.name);
        }
        let evals = v.instrs.iter().filter(|i| i.op != Opcode::Refresh).count();
        let ns = |t: f64| t * 1e9 / evals as f64;
        println!(
            "{:36} loop {:5.1}   window {:5.1}",
            v.name,
            ns(best[0]),
            ns(best[1])
        );
    }
}
