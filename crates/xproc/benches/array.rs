//! The fast engine against the cycle-stepped reference on a 1024-wide, 1024-scanline
//! trace (one frame): `cargo bench -p cwisim-xproc --bench array`.
//!
//! Each scanline carries a deterministic pseudo-random mix of Eval1/Eval2/Eval3 spans
//! (about 16 spans of 1–128 processors: ~1000 processor updates per line), a few
//! preloads and a Refresh; the machine is the default one.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use cwisim_isa::{Instruction, Intensity, TraceHeader};
use cwisim_xproc::{engine, Machine, NullSink, Timing};
use std::hint::black_box;

/// A small deterministic generator (xorshift64*), so the trace is the same every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

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
}

criterion_group!(benches, bench);
criterion_main!(benches);
