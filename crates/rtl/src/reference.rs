//! What the co-simulation is held to: the cycle-stepped engine (`cwisim run --timing
//! stepped --numeric fixed:…`) on the same trace, with a probe on the watched processors
//! — every scanline's values, each scanline's overflow events and ready cycle, and the
//! cycle every token arrives at every watched processor.

use crate::design::Design;
use crate::error::RtlError;
use crate::verilog::Watch;
use cwisim_isa::{Instruction, TraceHeader};
use cwisim_scene::budget::Budget;
use cwisim_xproc::engine::Engine;
use cwisim_xproc::stepped::SteppedEngine;
use cwisim_xproc::{FixedArith, LineOut, LineSink, Machine, Probe};
use std::collections::BTreeMap;

/// The stepped engine's account of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expected {
    /// Every scanline's values (`width × channels`, pixel-major), as the engine outputs
    /// them (`f64`).
    pub lines: Vec<Vec<f64>>,
    /// Each scanline's overflow events (operand conversions included).
    pub overflows: Vec<u64>,
    /// The cycle each scanline left the array.
    pub ready: Vec<u64>,
    /// Per watched processor, the cycle each instruction's token arrived there (by
    /// instruction number).
    pub arrivals: BTreeMap<u32, Vec<u64>>,
    /// The cycle the last token left the array.
    pub cycles: u64,
}

struct Recorder<'w> {
    watch: &'w [u32],
    arrivals: BTreeMap<u32, Vec<u64>>,
    ready: Vec<u64>,
}

impl Probe for Recorder<'_> {
    fn watches(&self, p: usize) -> bool {
        self.watch.binary_search(&(p as u32)).is_ok()
    }
    fn visit(
        &mut self,
        cycle: u64,
        p: usize,
        _index: u64,
        _line: u64,
        _instr: &Instruction,
        _addressed: bool,
        _before: &cwisim_xproc::ProcessorState,
        _after: &cwisim_xproc::ProcessorState,
    ) {
        self.arrivals.entry(p as u32).or_default().push(cycle);
    }
    fn line_ready(&mut self, cycle: u64, _line: u64) {
        self.ready.push(cycle);
    }
}

struct Lines(Vec<Vec<f64>>);

impl LineSink<f64> for Lines {
    fn line(&mut self, line: LineOut<'_, f64>) {
        self.0.push(line.values.to_vec());
    }
}

/// Bytes the expected results of `trace` take: the scanlines' values and the watched
/// processors' arrivals.
pub fn memory_needed(d: &Design, trace: &[Instruction], watch: &Watch) -> u64 {
    let lines = trace
        .iter()
        .filter(|i| i.op == cwisim_isa::Opcode::Refresh)
        .count() as u64;
    let values = lines.saturating_mul(u64::from(d.width) * d.channels as u64);
    let arrivals = (trace.len() as u64).saturating_mul(watch.processors().len() as u64);
    values
        .saturating_add(arrivals)
        .saturating_add(lines.saturating_mul(2))
        .saturating_mul(8)
}

/// Runs the stepped engine on `trace` in the design's format.
pub fn expected(
    d: &Design,
    header: &TraceHeader,
    trace: &[Instruction],
    machine: &Machine,
    watch: &Watch,
) -> Result<Expected, RtlError> {
    Budget::current().check_memory(
        "the stepped engine's account of the co-simulated trace",
        memory_needed(d, trace, watch),
    )?;
    let arith = FixedArith::new(&d.format)?;
    let timeline = machine.timeline(header)?;
    let mut rec = Recorder {
        watch: watch.processors(),
        arrivals: watch
            .processors()
            .iter()
            .map(|p| (*p, Vec::new()))
            .collect(),
        ready: Vec::new(),
    };
    let mut sink = Lines(Vec::new());
    let stats = {
        let mut eng = Box::new(SteppedEngine::with_probe_arith(
            header, timeline, arith, &mut rec,
        ));
        for instr in trace {
            eng.execute(instr, &mut sink);
        }
        eng.finish(&mut sink)
    };
    Ok(Expected {
        lines: sink.0,
        overflows: stats.lines.iter().map(|l| l.overflows).collect(),
        ready: rec.ready,
        arrivals: rec.arrivals,
        cycles: stats.totals.cycles,
    })
}
