//! The fast engine against the cycle-stepped reference on a 1024-wide, 1024-scanline
//! trace (one frame): `cargo bench -p cwisim-xproc --bench array`.
//!
//! Each scanline carries a deterministic pseudo-random mix of Eval1/Eval2/Eval3 spans
//! (about 16 spans of 1–128 processors: ~1000 processor updates per line), a few
//! preloads and a Refresh; the machine is the default one.
//!
//! Group `numeric_frame_1024x1024`: the fast engine on the same frame in each numeric
//! format, throughput in processor updates per second. Group `wave_4096`: the 4096 values
//! of a wrapping fixed-point wave, by the adder chain and by the closed form. Group
//! `replay_overhead_1024x1024`: what an instruction costs beyond its updates.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use cwisim_isa::{CheckedStream, Instruction, Intensity, TraceHeader, TraceWrite};
use cwisim_xproc::{
    engine, numeric_engine, wave_closed_form, Arith, EngineWriter, FixedArith, Machine, NullSink,
    Numeric, Timing,
};
use std::hint::black_box;

mod common;
use common::{short_spans, Rng};

fn frame_trace(width: u32, lines: u32) -> Vec<Instruction> {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut out = Vec::new();
    let g = Intensity::grey;
    for _ in 0..lines {
        for _ in 0..16 {
            let x = rng.below(u64::from(width)) as u32;
            let dx = (1 + rng.below(128) as u32).min(width - x);
            let (i, di, ddi) = (
                rng.unit(),
                (rng.unit() - 0.5) / 64.0,
                (rng.unit() - 0.5) / 4096.0,
            );
            out.push(match rng.below(4) {
                0 => Instruction::eval1(x, dx, g(i)),
                1 => Instruction::eval3(x, dx, g(i), g(di), g(ddi)),
                _ => Instruction::eval2(x, dx, g(i), g(di)),
            });
        }
        out.push(Instruction::set_i(
            rng.below(u64::from(width)) as u32,
            g(0.5),
        ));
        out.push(Instruction::refresh());
    }
    out
}

fn replay(header: &TraceHeader, trace: &[Instruction], timing: Timing) -> u64 {
    let mut eng = engine::<f64>(header, &Machine::default(), timing).expect("default machine");
    for i in trace {
        eng.execute(i, &mut NullSink);
    }
    eng.finish(&mut NullSink).totals.cycles
}

fn bench(c: &mut Criterion) {
    let header = TraceHeader::new(1024, 1024, 1).expect("header");
    let trace = frame_trace(1024, 1024);
    assert_eq!(
        replay(&header, &trace, Timing::Fast),
        replay(&header, &trace, Timing::Stepped),
        "the engines disagree on cycles"
    );
    let mut group = c.benchmark_group("frame_1024x1024");
    group.sample_size(10);
    group.throughput(Throughput::Elements(trace.len() as u64));
    for (name, timing) in [("fast", Timing::Fast), ("stepped", Timing::Stepped)] {
        group.bench_with_input(BenchmarkId::from_parameter(name), &timing, |b, &t| {
            b.iter(|| black_box(replay(&header, black_box(&trace), t)))
        });
    }
    group.finish();

    numeric_group(c, "numeric_frame_1024x1024", &header, &trace);
    numeric_group(
        c,
        "numeric_short_spans_1024x1024",
        &header,
        &short_spans(1024, 1024, None, None),
    );
    overhead(c, &header);

    let Numeric::Fixed(f) = "fixed:I=8.24,dI=8.24,ddI=8.24,overflow=wrap"
        .parse()
        .expect("format")
    else {
        unreachable!()
    };
    let arith = FixedArith::new(&f).expect("format");
    let (v0, d0, dd0) = (123_456_789i64, -98_765i64, 4_321i64);
    let mut group = c.benchmark_group("wave_4096");
    group.throughput(Throughput::Elements(4096));
    group.bench_function("adder_chain", |b| {
        b.iter(|| {
            let (mut v, mut d, mut sum, mut o) = (black_box(v0), black_box(d0), 0i64, 0u64);
            for _ in 0..4096 {
                sum = sum.wrapping_add(v);
                v = arith.advance_v(v, d, &mut o);
                d = arith.advance_d(d, dd0, &mut o);
            }
            black_box((sum, o))
        })
    });
    group.bench_function("closed_form", |b| {
        b.iter(|| {
            let mut sum = 0i64;
            for k in 0..4096 {
                sum = sum.wrapping_add(wave_closed_form(black_box(v0), d0, dd0, k, 32).0);
            }
            black_box(sum)
        })
    });
    group.finish();
}

/// The numeric formats of the `numeric_*` groups: the reference, `f32`, a uniform and a
/// mixed saturating fixed format, and a uniform wrapping one.
const FORMATS: [(&str, &str); 5] = [
    ("f64", "f64"),
    ("f32", "f32"),
    ("fixed-uniform", "fixed:I=4.28,dI=4.28,ddI=4.28"),
    ("fixed-mixed", "fixed:I=4.28,dI=4.28,ddI=1.36,acc=12.20"),
    ("fixed-wrap", "fixed:I=8.24,dI=8.24,ddI=8.24,overflow=wrap"),
];

/// The fast engine on `trace` in each of [`FORMATS`], throughput in processor updates.
fn numeric_group(c: &mut Criterion, name: &str, header: &TraceHeader, trace: &[Instruction]) {
    let updates = replay_numeric(header, trace, &Numeric::F64).processor_updates;
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    group.throughput(Throughput::Elements(updates));
    for (name, format) in FORMATS {
        let numeric: Numeric = format.parse().expect("format");
        group.bench_with_input(BenchmarkId::new("fast", name), &numeric, |b, n| {
            b.iter(|| black_box(replay_numeric(header, black_box(trace), n).cycles))
        });
    }
    group.finish();
}

/// What an instruction costs beyond its processor updates: the short-span frame with
/// every span emptied (`dx = 0`: issued, timed and counted, no processor touched),
/// replayed by the engine alone (`engine`, as `cwisim run` after its decoder's check)
/// and through [`EngineWriter`]: `checked`, one `write` per instruction, each checked
/// against the header first; `prechecked`, the stream checked once as it was buffered
/// (a [`CheckedStream`], as the pipeline buffers a renderer's scanlines: the check is
/// paid there) and executed by `write_checked` without a second check; `prechecked_dx1`,
/// the same with every span one processor long instead of empty (one update each: an
/// empty span takes a shorter path, without the dispatch on the `Eval`'s order, so this
/// is the overhead of an instruction that does work, plus one update). Throughput in
/// instructions.
fn overhead(c: &mut Criterion, header: &TraceHeader) {
    let trace: Vec<Instruction> = short_spans(header.width, header.lines, None, None)
        .into_iter()
        .map(|mut i| {
            i.dx = 0;
            i
        })
        .collect();
    let mut group = c.benchmark_group("replay_overhead_1024x1024");
    group.sample_size(10);
    group.throughput(Throughput::Elements(trace.len() as u64));
    group.bench_function("engine", |b| {
        b.iter(|| black_box(replay(header, black_box(&trace), Timing::Fast)))
    });
    group.bench_function("checked", |b| {
        b.iter(|| {
            let mut sink = NullSink;
            let mut w =
                EngineWriter::<f64>::new(header, &Machine::default(), Timing::Fast, &mut sink)
                    .expect("default machine");
            for i in black_box(&trace) {
                w.write(i).expect("fits");
            }
            w.finish().expect("finish");
            black_box(w.into_stats())
        })
    });
    let one: Vec<Instruction> = trace
        .iter()
        .map(|i| {
            let mut i = i.clone();
            if i.op != cwisim_isa::Opcode::Refresh {
                i.dx = 1;
            }
            i
        })
        .collect();
    for (name, trace) in [("prechecked", &trace), ("prechecked_dx1", &one)] {
        let stream = CheckedStream::from_vec(header, trace.clone()).expect("fits");
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut sink = NullSink;
                let mut w =
                    EngineWriter::<f64>::new(header, &Machine::default(), Timing::Fast, &mut sink)
                        .expect("default machine");
                w.write_checked(black_box(&stream)).expect("fits");
                w.finish().expect("finish");
                black_box(w.into_stats())
            })
        });
    }
    group.finish();
}

/// The fast engine on `trace` in `numeric`; the totals.
fn replay_numeric(
    header: &TraceHeader,
    trace: &[Instruction],
    numeric: &Numeric,
) -> cwisim_xproc::Totals {
    let mut eng = numeric_engine(header, &Machine::default(), Timing::Fast, numeric)
        .expect("default machine");
    for i in trace {
        eng.execute(i, &mut NullSink);
    }
    eng.finish(&mut NullSink).totals
}

criterion_group!(benches, bench);
criterion_main!(benches);
