//! Bands of scanlines executed ahead on their own processors (`BandArray`) and taken in
//! by the fast engine in order (`Engine::absorb`) give the serial run, bit for bit:
//! the same scanlines, the same statistics, the same cycle of every event — on random
//! traces cut into random bands, on random machines, in every numeric format. A band the
//! engine refuses (negative accumulation left on before it, or the engine caught inside
//! a scanline) has its instructions executed instead, as a pipeline would; bands chained
//! in order on one thread are never refused.

mod common;

use cwisim_isa::{Instruction, Intensity, Opcode, TraceHeader, TraceWrite};
use cwisim_xproc::{
    numeric_engine, Band, BandArray, ImageSink, Machine, Numeric, OpenScanline, RunStats, Timing,
};
use proptest::prelude::*;

/// What a run gives: the image's bits and the statistics.
type Outcome = (Vec<u64>, RunStats);

fn image_sink(header: &TraceHeader) -> ImageSink {
    ImageSink::new(header.width as usize, header.channel_count(), 1 << 24)
}

fn bits(sink: ImageSink) -> Vec<u64> {
    sink.finish()
        .unwrap()
        .data
        .iter()
        .map(|v| v.to_bits())
        .collect()
}

fn serial(
    header: &TraceHeader,
    machine: &Machine,
    numeric: &Numeric,
    trace: &[Instruction],
) -> Outcome {
    let mut sink = image_sink(header);
    let mut e = numeric_engine(header, machine, Timing::Fast, numeric).unwrap();
    e.execute_all(trace, &mut sink);
    let stats = e.finish(&mut sink);
    (bits(sink), stats)
}

/// The trace cut at `cuts` into bands; each band's whole scanlines executed on one of two
/// band arrays (reused, alternately) and taken in, its instructions after its last
/// `Refresh` executed by the engine. Returns the outcome and how many bands were refused.
fn in_bands(
    header: &TraceHeader,
    machine: &Machine,
    numeric: &Numeric,
    trace: &[Instruction],
    cuts: &[usize],
) -> (Outcome, usize) {
    let mut sink = image_sink(header);
    let mut e = numeric_engine(header, machine, Timing::Fast, numeric).unwrap();
    let mut arrays = [e.band_array().unwrap(), e.band_array().unwrap()];
    let mut spare = Band::new();
    let mut bounds: Vec<usize> = cuts.iter().map(|&c| c.min(trace.len())).collect();
    bounds.push(0);
    bounds.push(trace.len());
    bounds.sort_unstable();
    let mut refused = 0;
    for (k, w) in bounds.windows(2).enumerate() {
        let part = &trace[w[0]..w[1]];
        let whole = part
            .iter()
            .rposition(|i| i.op == Opcode::Refresh)
            .map_or(0, |i| i + 1);
        let array = &mut arrays[k % 2];
        array.start(spare);
        for i in &part[..whole] {
            array.write(i).unwrap();
        }
        let band = array.take().unwrap();
        assert_eq!(band.instructions(), whole as u64);
        if !e.absorb(&band, &mut sink) {
            refused += 1;
            e.execute_all(&part[..whole], &mut sink);
        }
        e.execute_all(&part[whole..], &mut sink);
        spare = band;
    }
    let stats = e.finish(&mut sink);
    ((bits(sink), stats), refused)
}

/// The trace cut into bands of whole scanlines (each cut moved back to just after a
/// `Refresh`), executed in order on one band array, each band started after the one
/// before ([`BandArray::start_after`]) and taken in; the instructions after the last
/// `Refresh` executed by the engine. Returns the outcome and how many bands were refused.
fn in_chained_bands(
    header: &TraceHeader,
    machine: &Machine,
    numeric: &Numeric,
    trace: &[Instruction],
    cuts: &[usize],
) -> (Outcome, usize) {
    let mut sink = image_sink(header);
    let mut e = numeric_engine(header, machine, Timing::Fast, numeric).unwrap();
    let mut array = e.band_array().unwrap();
    let after_refresh = |c: usize| {
        trace[..c.min(trace.len())]
            .iter()
            .rposition(|i| i.op == Opcode::Refresh)
            .map_or(0, |i| i + 1)
    };
    let mut bounds: Vec<usize> = cuts.iter().map(|&c| after_refresh(c)).collect();
    bounds.push(0);
    bounds.push(after_refresh(trace.len()));
    bounds.sort_unstable();
    let (mut previous, mut spare) = (Band::new(), Band::new());
    let mut refused = 0;
    for w in bounds.windows(2) {
        let part = &trace[w[0]..w[1]];
        array.start_after(spare, &previous);
        for i in part {
            array.write(i).unwrap();
        }
        let band = array.take().unwrap();
        if !e.absorb(&band, &mut sink) {
            refused += 1;
            e.execute_all(part, &mut sink);
        }
        spare = std::mem::replace(&mut previous, band);
    }
    e.execute_all(&trace[*bounds.last().unwrap()..], &mut sink);
    let stats = e.finish(&mut sink);
    ((bits(sink), stats), refused)
}

fn case() -> impl Strategy<Value = (Numeric, TraceHeader, Machine, Vec<Instruction>, Vec<usize>)> {
    (
        prop_oneof![3 => Just(Numeric::F64), 1 => common::numeric()],
        1u32..40,
        1u32..5,
        prop_oneof![Just(1u8), Just(3u8)],
        1u32..4,
        0u32..3,
        1u64..300,
    )
        .prop_flat_map(
            |(numeric, width, lines, channels, hop, value_cycles, period)| {
                let header = TraceHeader::new(width, lines, channels).unwrap();
                let m = Machine {
                    hop_cycles: hop,
                    value_cycles,
                    line_period_cycles: Some(period),
                    vblank_lines: 2,
                    ..Machine::default()
                };
                (
                    Just(numeric),
                    Just(header),
                    Just(m),
                    proptest::collection::vec(
                        prop_oneof![
                            // scanline ends are common, so that bands hold several
                            1 => Just(Instruction::refresh()),
                            4 => common::instruction(width, usize::from(channels), common::value()),
                        ],
                        0..120,
                    ),
                    proptest::collection::vec(0usize..120, 0..6),
                )
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn bands_taken_in_order_are_the_serial_run(
        (numeric, header, machine, trace, cuts) in case()
    ) {
        let (banded, _) = in_bands(&header, &machine, &numeric, &trace, &cuts);
        prop_assert_eq!(banded, serial(&header, &machine, &numeric, &trace));
    }

    /// Bands emitted in order on one thread, each started after the one before, are all
    /// taken in, whatever the stream does with negative accumulation.
    #[test]
    fn chained_bands_are_never_refused_and_are_the_serial_run(
        (numeric, header, machine, trace, cuts) in case()
    ) {
        let (banded, refused) = in_chained_bands(&header, &machine, &numeric, &trace, &cuts);
        prop_assert_eq!(refused, 0);
        prop_assert_eq!(banded, serial(&header, &machine, &numeric, &trace));
    }
}

/// A band after negative accumulation was left on is refused, and one after a scanline
/// left open too; the rest are taken in; the outcome is the serial run's.
#[test]
fn the_engine_refuses_a_band_it_cannot_take() {
    let h = TraceHeader::new(8, 4, 1).unwrap();
    let g = Intensity::grey;
    let trace = vec![
        Instruction::eval1(0, 8, g(0.5)),
        Instruction::refresh(),
        // band 2: leaves negative accumulation on
        Instruction::acc_mode(),
        Instruction::eval2(0, 8, g(0.5), g(-0.25)),
        Instruction::refresh(),
        // band 3 (refused: it assumed it off), turns it off again
        Instruction::eval2(0, 8, g(0.5), g(-0.25)),
        Instruction::acc_mode(),
        Instruction::refresh(),
        // band 4 (taken), then an open scanline
        Instruction::eval2(0, 8, g(0.5), g(-0.25)),
        Instruction::refresh(),
        Instruction::eval0(2, 2, g(1.0)),
        // band 5 (refused: the engine is inside a scanline)
        Instruction::eval1(0, 4, g(0.25)),
        Instruction::refresh(),
    ];
    let machine = Machine::default();
    let (banded, refused) = in_bands(&h, &machine, &Numeric::F64, &trace, &[2, 5, 8, 11]);
    assert_eq!(refused, 2);
    let reference = serial(&h, &machine, &Numeric::F64, &trace);
    assert_eq!(banded, reference);
    assert_eq!(reference.1.totals.lines, 5);
    // negative values went through in scanline 2 only
    assert!(reference.1.lines[1].dropped_negative == 0);
    assert!(reference.1.lines[3].dropped_negative > 0);
}

#[test]
fn a_band_array_refuses_an_unfit_instruction_and_an_open_scanline() {
    let h = TraceHeader::new(8, 4, 1).unwrap();
    let e = numeric_engine(&h, &Machine::default(), Timing::Fast, &Numeric::F64).unwrap();
    let mut array: BandArray<f64> = e.band_array().unwrap();
    array.start(Band::new());
    let past_the_end = Instruction::eval1(6, 4, Intensity::grey(0.5));
    assert_eq!(
        array.write(&past_the_end).unwrap_err().to_string(),
        "Eval1 6 4 0.5: range [x, x+dx) = [6, 10) reaches past the array's end (8)"
    );
    array.write(&Instruction::refresh()).unwrap();
    array
        .write(&Instruction::eval1(0, 2, Intensity::grey(0.5)))
        .unwrap();
    assert_eq!(array.take().unwrap_err(), OpenScanline);
    // the next band starts between scanlines again
    array.start(Band::new());
    array
        .write(&Instruction::eval1(0, 2, Intensity::grey(0.5)))
        .unwrap();
    array.write(&Instruction::refresh()).unwrap();
    let band = array.take().unwrap();
    assert_eq!((band.scanlines(), band.instructions()), (1, 2));
    assert!(!band.negative_at_end());
}

#[test]
fn the_stepped_engine_takes_no_bands() {
    let h = TraceHeader::new(8, 4, 1).unwrap();
    let mut e = numeric_engine(&h, &Machine::default(), Timing::Stepped, &Numeric::F64).unwrap();
    assert!(e.band_array().is_none());
    assert!(!e.absorb(&Band::new(), &mut image_sink(&h)));
}
