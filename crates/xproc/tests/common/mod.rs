//! Strategies shared by the numeric-format tests, and the trace in memory and the
//! stepped-engine reference shared by the probe tests (`window.rs`, `visits.rs`).

#![allow(dead_code)]

use cwisim_isa::{Instruction, Location, Opcode, TraceError, TraceHeader, TraceRead};
use cwisim_xproc::stepped::SteppedEngine;
use cwisim_xproc::{
    Arith, Engine, F32Arith, FixedArith, FixedFormat, Image, ImageSink, Machine, Native, Numeric,
    Overflow, Probe, RunStats, Q,
};
use proptest::prelude::*;

/// Any valid `Q`: 1..=64 integer bits, the rest of at most 64 bits fraction.
pub fn any_q() -> impl Strategy<Value = Q> + Clone {
    (1u32..=64)
        .prop_flat_map(|int| (Just(int), 0..=64 - int))
        .prop_map(|(int_bits, frac_bits)| Q {
            int_bits,
            frac_bits,
        })
}

/// Tiny formats (at most 8 bits wide) that wrap or saturate all the time.
pub fn tiny_q() -> impl Strategy<Value = Q> + Clone {
    (1u32..=4, 0u32..=4).prop_map(|(int_bits, frac_bits)| Q {
        int_bits,
        frac_bits,
    })
}

/// Moderate formats: 8..=24 integer bits, 0..=30 fraction bits.
pub fn moderate_q() -> impl Strategy<Value = Q> + Clone {
    (8u32..=24, 0u32..=30).prop_map(|(int_bits, frac_bits)| Q {
        int_bits,
        frac_bits,
    })
}

pub fn overflow() -> impl Strategy<Value = Overflow> {
    prop_oneof![Just(Overflow::Wrap), Just(Overflow::Saturate)]
}

fn format_of(q: impl Strategy<Value = Q> + Clone) -> impl Strategy<Value = FixedFormat> {
    (q.clone(), q.clone(), q.clone(), q, overflow()).prop_map(|(i, di, ddi, acc, overflow)| {
        FixedFormat {
            i,
            di,
            ddi,
            acc,
            overflow,
        }
    })
}

/// A random fixed format: tiny, moderate, any, or one `Q` shared by every register.
pub fn fixed_format() -> impl Strategy<Value = FixedFormat> {
    prop_oneof![
        2 => format_of(tiny_q()),
        3 => format_of(moderate_q()),
        2 => format_of(any_q()),
        1 => (any_q(), overflow()).prop_map(|(q, overflow)| FixedFormat {
            i: q,
            di: q,
            ddi: q,
            acc: q,
            overflow,
        }),
    ]
}

/// Any numeric format, fixed point most often.
pub fn numeric() -> impl Strategy<Value = Numeric> {
    prop_oneof![
        1 => Just(Numeric::F64),
        2 => Just(Numeric::F32),
        6 => fixed_format().prop_map(Numeric::Fixed),
    ]
}

/// Operand values over every scale a format may have: small, large, huge (beyond i64 at
/// the finest scale), exact ties of dyadic grids, zeros.
pub fn value() -> impl Strategy<Value = f64> + Clone {
    prop_oneof![
        4 => -2.0f64..2.0,
        2 => (-(1i64 << 20)..(1i64 << 20), -70i32..40).prop_map(|(m, e)| m as f64 * 2f64.powi(e)),
        1 => Just(0.0),
        1 => Just(-0.0),
        1 => -1e6f64..1e6,
        1 => -1e-12f64..1e-12,
        1 => (1e15f64..1e30, any::<bool>()).prop_map(|(v, neg)| if neg { -v } else { v }),
        1 => -4e38f64..4e38,
    ]
}

/// A valid instruction for a `width`-wide array of `channels` channels, weighted towards
/// Evals, preloads and Refresh, every opcode reachable.
pub fn instruction(
    width: u32,
    channels: usize,
    value: impl Strategy<Value = f64> + Clone,
) -> impl Strategy<Value = Instruction> {
    let op = prop_oneof![
        6 => 6usize..10,    // Eval0..Eval3
        2 => Just(12usize), // Refresh
        4 => 0usize..6,     // Set*
        1 => Just(10usize), // Dis
        1 => Just(11usize), // Acc_mode
        1 => Just(13usize), // Nop
    ];
    (
        op,
        0..width,
        0..=width,
        proptest::collection::vec(value, 3 * channels),
    )
        .prop_map(move |(k, x, n, vals)| {
            let (count, period) = (n.min(width - x), n.clamp(1, 5));
            Instruction::from_operands(Opcode::ALL[k], x, count, period, &vals, channels)
        })
}

/// A trace held in memory; one "byte" per instruction.
pub struct VecReader<'a> {
    header: TraceHeader,
    instrs: &'a [Instruction],
    next: usize,
}

impl<'a> VecReader<'a> {
    pub fn new(header: &TraceHeader, instrs: &'a [Instruction]) -> Self {
        VecReader {
            header: *header,
            instrs,
            next: 0,
        }
    }
}

impl TraceRead for VecReader<'_> {
    fn header(&self) -> &TraceHeader {
        &self.header
    }
    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        let i = self.instrs.get(self.next).cloned();
        self.next += usize::from(i.is_some());
        Ok(i)
    }
    fn location(&self) -> Location {
        Location::Byte(self.next as u64)
    }
    fn bytes_read(&self) -> u64 {
        self.next as u64
    }
}

/// An image collector for `header`'s scanlines.
pub fn image_sink(header: &TraceHeader) -> ImageSink {
    ImageSink::new(
        header.width as usize,
        header.channel_count(),
        ImageSink::DEFAULT_LIMIT_BYTES,
    )
}

/// An image's values as bits (`NaN`s and signed zeros compare exactly).
pub fn image_bits(image: &Image) -> Vec<u64> {
    image.data.iter().map(|v| v.to_bits()).collect()
}

fn stepped_run<A: Arith<Out = f64>>(
    header: &TraceHeader,
    machine: &Machine,
    arith: A,
    trace: &[Instruction],
    probe: &mut dyn Probe,
) -> (RunStats, Image) {
    let timeline = machine.timeline(header).unwrap();
    let mut sink = image_sink(header);
    let mut eng = Box::new(SteppedEngine::with_probe_arith(
        header, timeline, arith, probe,
    ));
    for i in trace {
        eng.execute(i, &mut sink);
    }
    let stats = eng.finish(&mut sink);
    (stats, sink.finish().unwrap())
}

/// The reference: the stepped engine over the whole trace, from the start, with
/// registers of the format `numeric`, telling `probe`.
pub fn stepped_numeric(
    header: &TraceHeader,
    machine: &Machine,
    numeric: &Numeric,
    trace: &[Instruction],
    probe: &mut dyn Probe,
) -> (RunStats, Image) {
    match numeric {
        Numeric::F64 => stepped_run(header, machine, Native::<f64>::new(), trace, probe),
        Numeric::F32 => stepped_run(header, machine, F32Arith, trace, probe),
        Numeric::Fixed(f) => {
            stepped_run(header, machine, FixedArith::new(f).unwrap(), trace, probe)
        }
    }
}
