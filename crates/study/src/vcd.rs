//! A per-cycle waveform (Value Change Dump) of one scanline (`cwisim vcd`).
//!
//! The trace is replayed on the cycle-stepped engine (the reference model) with a
//! [`Probe`] that watches a window of processors. From the cycle the instruction bus
//! starts issuing the first instruction of scanline `Y` to the cycle scanline `Y` leaves
//! the array, every change of the bus and of the watched processors' registers and flags
//! is written through the `vcd` crate. Only the scanlines whose tokens are in the array
//! then are stepped (`Y`, and the few before it still crossing): the fast engine runs the
//! ones before and hands its state over ([`StepFrom::Issue`]).
//!
//! The `vcd` crate's writer formats what it is given and checks nothing, so this module
//! checks what makes a dump valid: the timescale (1, 10 or 100 of a unit), strictly
//! increasing time stamps, identifier codes of printable ASCII (33–126) and unique, scope
//! and variable names without white space, and vector values that fit their width.
//!
//! Time stamps are absolute array clock cycles (the cycles `cwisim dump` prints); the
//! header says one time unit (written `1 ns`) is one cycle. Real values are written with
//! Rust's shortest round-trip formatting, so a reader that parses them as `f64` gets the
//! exact values back. Nothing non-deterministic (date, path) is written: the same
//! arguments give the same file byte for byte.

use crate::error::StudyError;
use cwisim_isa::{Instruction, Location, Opcode, OperandKind, TraceError, TraceHeader, TraceRead};
use cwisim_xproc::{
    replay_probed_numeric, LineOut, LineSink, Machine, Numeric, Probe, ProcessorState, StepFrom,
};
use std::cell::Cell;
use std::collections::BTreeSet;
use std::io::{self, Write};
use std::rc::Rc;
use vcd::{IdCode, SimulationCommand, TimescaleUnit, Value, VarType};

/// Replays `trace` on the cycle-stepped engine and records scanline `line`'s window of
/// processors `from..=to` (inclusive), from the cycle the bus starts issuing its first
/// instruction to the cycle it leaves the array. `Ok(Err(n))`: the trace outputs only `n`
/// scanlines, so `line` never comes.
pub fn record_scanline(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    line: u64,
    from: usize,
    to: usize,
) -> Result<Result<Wave, u64>, StudyError> {
    record_scanline_with_progress(trace, machine, &Numeric::F64, line, from, to, &mut |_| {})
}

/// [`record_scanline`] with registers of the format `numeric` (the waveform shows the
/// registers' own values, as reals), calling `progress` with the bytes of `trace` read so
/// far every few thousand instructions (and at the end): for a progress bar.
pub fn record_scanline_with_progress(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    numeric: &Numeric,
    line: u64,
    from: usize,
    to: usize,
    progress: &mut dyn FnMut(u64),
) -> Result<Result<Wave, u64>, StudyError> {
    let header = *trace.header();
    let timeline = machine.timeline(&header)?;
    let done = Rc::new(Cell::new(false));
    let mut probe = Recorder::new(&header, line, from, to, timeline.hop, Rc::clone(&done));
    let mut sink = LineCapture {
        line,
        from,
        to,
        channels: header.channel_count(),
        values: None,
    };
    let mut reader = UntilReady { inner: trace, done };
    let stats = replay_probed_numeric(
        &mut reader,
        machine,
        numeric,
        StepFrom::Issue(line),
        &mut probe,
        &mut sink,
        progress,
    )?;
    if probe.over_budget {
        let budget = cwisim_scene::budget::Budget::current();
        return Err(StudyError::Usage(
            budget
                .check_memory(
                    &format!(
                        "the waveform of scanline {line} over processors {from}..={to} (more than {} value changes; a narrower --x holds fewer)",
                        probe.max_log
                    ),
                    (probe.max_log as u64 + 1) * LOG_ENTRY_BYTES,
                )
                .expect_err("past the budget")
                .to_string(),
        ));
    }
    let Some(wave) = probe.finish() else {
        return Ok(Err(stats.totals.lines));
    };
    // The `out` registers must hold exactly what the replay output for the scanline.
    if !wave.out_matches(&sink.values.unwrap_or_default()) {
        return Err(StudyError::Array(io::Error::new(
            io::ErrorKind::InvalidData,
            "internal check failed: the out registers differ from the replay's scanline",
        )));
    }
    Ok(Ok(wave))
}

/// Ends the trace once the probe has seen the scanline leave the array, so that a long
/// trace is replayed only as far as needed (the instructions issued up to that cycle,
/// from later scanlines too, are all replayed).
struct UntilReady<'a> {
    inner: &'a mut dyn TraceRead,
    done: Rc<Cell<bool>>,
}

impl TraceRead for UntilReady<'_> {
    fn header(&self) -> &TraceHeader {
        self.inner.header()
    }

    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        if self.done.get() {
            return Ok(None);
        }
        self.inner.next_instruction()
    }

    fn location(&self) -> Location {
        self.inner.location()
    }

    fn bytes_read(&self) -> u64 {
        self.inner.bytes_read()
    }
}

/// Keeps the window of scanline `line` as the replay outputs it.
struct LineCapture {
    line: u64,
    from: usize,
    to: usize,
    channels: usize,
    /// `(to - from + 1) × channels` values, processor-major.
    values: Option<Vec<f64>>,
}

impl LineSink<f64> for LineCapture {
    fn line(&mut self, line: LineOut<'_, f64>) {
        if line.index != self.line {
            return;
        }
        let c = self.channels;
        let mut values = Vec::with_capacity((self.to - self.from + 1) * c);
        for p in self.from..=self.to {
            for k in 0..c {
                let v = if p >= line.span.0 && p < line.span.1 {
                    line.values[(p - line.span.0) * c + k]
                } else {
                    0.0
                };
                values.push(v);
            }
        }
        self.values = Some(values);
    }
}

/// What a signal holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// A 1-bit wire.
    Bit,
    /// A wire of this many bits.
    Word(u32),
    /// A `real` variable.
    Real,
}

/// A signal's value.
#[derive(Clone, Copy, Debug)]
enum Val {
    Bit(bool),
    /// `None`: high impedance (`z`): nothing drives it.
    Word(Option<u64>),
    Real(f64),
}

impl Val {
    /// Equal values (reals bit for bit, so `-0.0` differs from `+0.0`).
    fn same(self, other: Val) -> bool {
        match (self, other) {
            (Val::Bit(a), Val::Bit(b)) => a == b,
            (Val::Word(a), Val::Word(b)) => a == b,
            (Val::Real(a), Val::Real(b)) => a.to_bits() == b.to_bits(),
            _ => false,
        }
    }
}

/// One signal of the dump.
struct SignalDef {
    /// Index into [`Layout::scopes`].
    scope: usize,
    name: String,
    kind: Kind,
}

/// Where each signal lives in the value table, and the scopes and signals in file order.
///
/// Bus: `opcode`, `x`, `dx`, `I`…, `dI`…, `ddI`…, `index`, `busy`. Each processor: `acc`…,
/// `I`…, `dI`…, `ddI`…, `has_I`, `has_dI`, `has_ddI`, `locked`, `masked`, `neg`, `out`…,
/// `token` (`…`: one per channel, suffixed `_c0`, `_c1`, … when there are several).
struct Layout {
    channels: usize,
    from: usize,
    count: usize,
    scopes: Vec<String>,
    defs: Vec<SignalDef>,
}

const REG_NAMES: [&str; 3] = ["I", "dI", "ddI"];
const HAS_NAMES: [&str; 3] = ["has_I", "has_dI", "has_ddI"];

impl Layout {
    fn new(channels: usize, from: usize, to: usize) -> Self {
        let mut l = Layout {
            channels,
            from,
            count: to - from + 1,
            scopes: Vec::new(),
            defs: Vec::new(),
        };
        l.scope("bus");
        l.def("opcode", Kind::Word(8));
        l.def("x", Kind::Word(32));
        l.def("dx", Kind::Word(32));
        for name in REG_NAMES {
            l.per_channel(name);
        }
        l.def("index", Kind::Word(32));
        l.def("busy", Kind::Bit);
        debug_assert_eq!(l.defs.len(), l.bus_len());
        for p in from..=to {
            l.scope(&format!("p{p}"));
            l.per_channel("acc");
            for name in REG_NAMES {
                l.per_channel(name);
            }
            for name in HAS_NAMES {
                l.def(name, Kind::Bit);
            }
            l.def("locked", Kind::Bit);
            l.def("masked", Kind::Bit);
            l.def("neg", Kind::Bit);
            l.per_channel("out");
            l.def("token", Kind::Word(32));
            debug_assert_eq!(l.defs.len(), l.proc_base(p) + l.proc_len());
        }
        l
    }

    fn scope(&mut self, name: &str) {
        self.scopes.push(name.to_string());
    }

    fn def(&mut self, name: &str, kind: Kind) {
        self.defs.push(SignalDef {
            scope: self.scopes.len() - 1,
            name: name.to_string(),
            kind,
        });
    }

    fn per_channel(&mut self, name: &str) {
        if self.channels == 1 {
            self.def(name, Kind::Real);
        } else {
            for k in 0..self.channels {
                self.def(&format!("{name}_c{k}"), Kind::Real);
            }
        }
    }

    fn bus_len(&self) -> usize {
        5 + 3 * self.channels
    }
    fn bus_opcode(&self) -> usize {
        0
    }
    fn bus_x(&self) -> usize {
        1
    }
    fn bus_dx(&self) -> usize {
        2
    }
    fn bus_value(&self, slot: usize, k: usize) -> usize {
        3 + slot * self.channels + k
    }
    fn bus_index(&self) -> usize {
        3 + 3 * self.channels
    }
    fn bus_busy(&self) -> usize {
        4 + 3 * self.channels
    }

    fn proc_len(&self) -> usize {
        5 * self.channels + 7
    }
    fn proc_base(&self, p: usize) -> usize {
        self.bus_len() + (p - self.from) * self.proc_len()
    }
    fn acc(&self, p: usize, k: usize) -> usize {
        self.proc_base(p) + k
    }
    fn reg(&self, p: usize, slot: usize, k: usize) -> usize {
        self.proc_base(p) + self.channels * (1 + slot) + k
    }
    fn has(&self, p: usize, slot: usize) -> usize {
        self.proc_base(p) + 4 * self.channels + slot
    }
    fn locked(&self, p: usize) -> usize {
        self.proc_base(p) + 4 * self.channels + 3
    }
    fn masked(&self, p: usize) -> usize {
        self.proc_base(p) + 4 * self.channels + 4
    }
    fn neg(&self, p: usize) -> usize {
        self.proc_base(p) + 4 * self.channels + 5
    }
    fn out(&self, p: usize, k: usize) -> usize {
        self.proc_base(p) + 4 * self.channels + 6 + k
    }
    fn token(&self, p: usize) -> usize {
        self.proc_base(p) + 5 * self.channels + 6
    }

    /// The values of processor `p`'s registers and flags in `s`.
    fn state(&self, p: usize, s: &ProcessorState) -> Vec<(usize, Val)> {
        let mut sets = Vec::with_capacity(self.proc_len());
        for k in 0..self.channels {
            sets.push((self.acc(p, k), Val::Real(s.acc[k])));
            for slot in 0..3 {
                sets.push((self.reg(p, slot, k), Val::Real(s.reg[slot][k])));
            }
        }
        for slot in 0..3 {
            sets.push((self.has(p, slot), Val::Bit(s.has[slot])));
        }
        sets.push((self.locked(p), Val::Bit(s.locked)));
        sets.push((self.masked(p), Val::Bit(s.masked)));
        sets.push((self.neg(p), Val::Bit(s.negative_enabled)));
        sets
    }

    /// Every signal's value before anything happened: registers `+0.0`, flags clear,
    /// the bus idle, no token anywhere.
    fn reset_values(&self) -> Vec<Val> {
        let mut v: Vec<Val> = self
            .defs
            .iter()
            .map(|d| match d.kind {
                Kind::Bit => Val::Bit(false),
                Kind::Word(_) => Val::Word(Some(0)),
                Kind::Real => Val::Real(0.0),
            })
            .collect();
        v[self.bus_x()] = Val::Word(None);
        v[self.bus_dx()] = Val::Word(None);
        for p in self.from..self.from + self.count {
            v[self.token(p)] = Val::Word(None);
        }
        v
    }
}

/// The probe: follows every signal's value through the replay and, inside the window of
/// time, logs each change with its cycle.
/// The memory of one logged value change.
const LOG_ENTRY_BYTES: u64 = std::mem::size_of::<(u64, usize, Val)>() as u64;

struct Recorder {
    /// The trace's dimensions (for the dump's comment).
    header: TraceHeader,
    line: u64,
    hop: u64,
    layout: Layout,
    /// Every signal's current value.
    cur: Vec<Val>,
    /// The latest cycle an event was seen at.
    now: u64,
    /// Per watched processor, the cycle its token leaves (if one is in it).
    token_until: Vec<Option<u64>>,
    /// The window of time: the first issue of the scanline, and its readiness.
    start: Option<(u64, u64)>,
    end: Option<u64>,
    /// Values at the start (after the start cycle's events up to the first issue).
    initial: Vec<Val>,
    /// The most changes the log may hold (the memory budget), and whether it ran past.
    max_log: usize,
    over_budget: bool,
    /// Changes inside the window: `(cycle, signal, value)`, in the order they happened.
    log: Vec<(u64, usize, Val)>,
    done: Rc<Cell<bool>>,
}

/// The recorded window of one scanline, ready to be written ([`write_vcd`]).
pub struct Wave {
    layout: Layout,
    header: TraceHeader,
    line: u64,
    /// The first instruction of the scanline.
    first_index: u64,
    start: u64,
    end: u64,
    hop: u64,
    initial: Vec<Val>,
    log: Vec<(u64, usize, Val)>,
}

/// A cycle of a [`Wave`] and the signals that change in it, with their new values.
type Step = (u64, Vec<(usize, Val)>);

impl Wave {
    /// Every signal's value at the window's first cycle (the state then, with that
    /// cycle's changes), then, cycle by cycle, the signals whose value at the end of the
    /// cycle differs from before, with their new values: what the dump writes.
    fn steps(&self) -> (Vec<Val>, Vec<Step>) {
        let mut vals = self.initial.clone();
        let mut log = self.log.iter().peekable();
        while let Some(&&(t, sig, val)) = log.peek() {
            if t != self.start {
                break;
            }
            vals[sig] = val;
            log.next();
        }
        let start = vals.clone();
        let rest: Vec<_> = log.copied().collect();
        let mut steps = Vec::new();
        let mut i = 0;
        let mut next = vals.clone();
        let mut touched = Vec::new();
        while i < rest.len() {
            let t = rest[i].0;
            touched.clear();
            while i < rest.len() && rest[i].0 == t {
                let (_, sig, val) = rest[i];
                next[sig] = val;
                touched.push(sig);
                i += 1;
            }
            touched.sort_unstable();
            touched.dedup();
            let changed: Vec<(usize, Val)> = touched
                .iter()
                .copied()
                .filter(|&s| !next[s].same(vals[s]))
                .map(|s| (s, next[s]))
                .collect();
            if changed.is_empty() {
                continue;
            }
            for &(s, v) in &changed {
                vals[s] = v;
            }
            steps.push((t, changed));
        }
        (start, steps)
    }

    /// The window: the cycle the bus starts issuing the scanline, and the cycle it
    /// leaves the array.
    pub fn window(&self) -> (u64, u64) {
        (self.start, self.end)
    }

    /// Every signal as `scope.name` (`bus.opcode`, `p3.acc`, `p3.I_c1`) with its values
    /// as numbers — a bit 0 or 1, a word its value (NaN when nothing drives it), a real
    /// itself — at the window's first cycle and at each cycle it changes after: the
    /// dump's contents, for callers that want arrays (the Python package).
    pub fn signals(&self) -> Vec<(String, Vec<u64>, Vec<f64>)> {
        let number = |v: Val| match v {
            Val::Bit(b) => f64::from(u8::from(b)),
            Val::Word(Some(w)) => w as f64,
            Val::Word(None) => f64::NAN,
            Val::Real(r) => r,
        };
        let (start, steps) = self.steps();
        let mut out: Vec<(String, Vec<u64>, Vec<f64>)> = self
            .layout
            .defs
            .iter()
            .zip(&start)
            .map(|(d, &v)| {
                (
                    format!("{}.{}", self.layout.scopes[d.scope], d.name),
                    vec![self.start],
                    vec![number(v)],
                )
            })
            .collect();
        for (t, changed) in steps {
            for (s, v) in changed {
                out[s].1.push(t);
                out[s].2.push(number(v));
            }
        }
        out
    }
}

impl Recorder {
    fn new(
        header: &TraceHeader,
        line: u64,
        from: usize,
        to: usize,
        hop: u64,
        done: Rc<Cell<bool>>,
    ) -> Self {
        let layout = Layout::new(header.channel_count(), from, to);
        Recorder {
            line,
            hop,
            cur: layout.reset_values(),
            token_until: vec![None; layout.count],
            layout,
            now: 0,
            start: None,
            end: None,
            initial: Vec::new(),
            log: Vec::new(),
            max_log: usize::try_from(
                cwisim_scene::budget::Budget::current().memory_bytes / LOG_ENTRY_BYTES,
            )
            .unwrap_or(usize::MAX),
            over_budget: false,
            done,
            header: *header,
        }
    }

    /// Sets a signal at `cycle`, logging the change inside the window.
    fn set(&mut self, cycle: u64, sig: usize, val: Val) {
        if self.cur[sig].same(val) {
            return;
        }
        self.cur[sig] = val;
        if self.start.is_some() {
            if self.log.len() >= self.max_log {
                // past the memory budget: stop here, refused when the replay ends
                self.over_budget = true;
                self.done.set(true);
                return;
            }
            self.log.push((cycle, sig, val));
        }
    }

    /// Whether an event at `cycle` is past the window (and so ignored); otherwise
    /// moves time on to `cycle`, letting go the tokens whose time in a processor is up.
    fn past(&mut self, cycle: u64) -> bool {
        if self.end.is_some_and(|end| cycle > end) {
            return true;
        }
        if cycle > self.now {
            self.release_due(cycle);
            self.now = cycle;
        }
        false
    }

    /// Tokens that leave their processor by `cycle` (at the cycle they leave).
    fn release_due(&mut self, cycle: u64) {
        for i in 0..self.token_until.len() {
            if let Some(until) = self.token_until[i] {
                if until <= cycle {
                    self.token_until[i] = None;
                    let sig = self.layout.token(self.layout.from + i);
                    self.set(until, sig, Val::Word(None));
                }
            }
        }
    }

    /// The window, once the scanline was ready; `None` if it never was.
    fn finish(mut self) -> Option<Wave> {
        let end = self.end?;
        let (start, first_index) = self.start?;
        self.release_due(end);
        // Stable: changes at one cycle keep the order they happened in.
        self.log.sort_by_key(|&(t, _, _)| t);
        debug_assert!(self.log.iter().all(|&(t, _, _)| t >= start && t <= end));
        Some(Wave {
            layout: self.layout,
            header: self.header,
            line: self.line,
            first_index,
            start,
            end,
            hop: self.hop,
            initial: self.initial,
            log: self.log,
        })
    }
}

impl Probe for Recorder {
    fn watches(&self, p: usize) -> bool {
        p >= self.layout.from && p < self.layout.from + self.layout.count
    }

    fn issue(&mut self, cycle: u64, index: u64, line: u64, instr: &Instruction) {
        if self.past(cycle) {
            return;
        }
        let l = &self.layout;
        let c = l.channels;
        let (op, xs, dxs, index_sig, busy) = (
            l.bus_opcode(),
            l.bus_x(),
            l.bus_dx(),
            l.bus_index(),
            l.bus_busy(),
        );
        let mut sets = vec![
            (op, Val::Word(Some(u64::from(instr.op.code())))),
            (index_sig, Val::Word(Some(index))),
            (busy, Val::Bit(true)),
        ];
        // x and dx are undriven (z) for an opcode that has no such operand.
        let has = |k: OperandKind| instr.op.operands().contains(&k);
        let x = has(OperandKind::X).then_some(u64::from(instr.x));
        let dx =
            (has(OperandKind::Count) || has(OperandKind::Period)).then_some(u64::from(instr.dx));
        sets.push((xs, Val::Word(x)));
        sets.push((dxs, Val::Word(dx)));
        for slot in 0..3 {
            let v = instr.value(slot);
            for k in 0..c {
                sets.push((
                    l.bus_value(slot, k),
                    Val::Real(v.get(k).copied().unwrap_or(0.0)),
                ));
            }
        }
        for (sig, val) in sets {
            self.set(cycle, sig, val);
        }
        if self.start.is_none() && line == self.line {
            self.start = Some((cycle, index));
            self.initial = self.cur.clone();
        }
    }

    fn enter(&mut self, cycle: u64, _index: u64) {
        if self.past(cycle) {
            return;
        }
        let l = &self.layout;
        let mut sets = vec![
            (l.bus_opcode(), Val::Word(Some(0))),
            (l.bus_busy(), Val::Bit(false)),
            (l.bus_x(), Val::Word(None)),
            (l.bus_dx(), Val::Word(None)),
        ];
        for slot in 0..3 {
            for k in 0..l.channels {
                sets.push((l.bus_value(slot, k), Val::Real(0.0)));
            }
        }
        for (sig, val) in sets {
            self.set(cycle, sig, val);
        }
    }

    fn visit(
        &mut self,
        cycle: u64,
        p: usize,
        index: u64,
        line: u64,
        instr: &Instruction,
        _addressed: bool,
        before: &ProcessorState,
        after: &ProcessorState,
    ) {
        if self.past(cycle) {
            return;
        }
        let l = &self.layout;
        let c = l.channels;
        let mut sets = l.state(p, after);
        if instr.op == Opcode::Refresh && line == self.line {
            for k in 0..c {
                sets.push((l.out(p, k), Val::Real(before.acc[k])));
            }
        }
        sets.push((l.token(p), Val::Word(Some(index))));
        for (sig, val) in sets {
            self.set(cycle, sig, val);
        }
        self.token_until[p - self.layout.from] = Some(cycle + self.hop);
    }

    /// The replay starts from the fast engine's state: the watched processors hold what
    /// it says (the bus is idle, no token in the window).
    fn resume(&mut self, cycle: u64, _line: u64, watched: &[(usize, ProcessorState)]) {
        for (p, state) in watched {
            for (sig, val) in self.layout.state(*p, state) {
                self.set(cycle, sig, val);
            }
        }
    }

    fn line_ready(&mut self, cycle: u64, line: u64) {
        if self.past(cycle) {
            return;
        }
        if line == self.line {
            self.end = Some(cycle);
            self.done.set(true);
        }
    }
}

impl Wave {
    /// Whether the final `out` values equal `expected` (processor-major), bit for bit.
    fn out_matches(&self, expected: &[f64]) -> bool {
        let l = &self.layout;
        let c = l.channels;
        let mut vals = self.initial.clone();
        for &(_, sig, val) in &self.log {
            vals[sig] = val;
        }
        expected.len() == l.count * c
            && (0..l.count).all(|i| {
                (0..c).all(|k| vals[l.out(l.from + i, k)].same(Val::Real(expected[i * c + k])))
            })
    }
}

/// Time stamps must strictly increase (the `vcd` writer writes whatever it is given).
struct Clock {
    last: Option<u64>,
}

impl Clock {
    fn at(&mut self, t: u64) -> io::Result<()> {
        if self.last.is_some_and(|last| t <= last) {
            return Err(invalid(format!(
                "time stamp #{t} does not follow #{}",
                self.last.unwrap_or_default()
            )));
        }
        self.last = Some(t);
        Ok(())
    }
}

fn invalid(msg: String) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("internal check failed: {msg}"),
    )
}

/// A VCD timescale is 1, 10 or 100 of a unit.
fn check_timescale(n: u32) -> io::Result<()> {
    if matches!(n, 1 | 10 | 100) {
        Ok(())
    } else {
        Err(invalid(format!("timescale {n} is not 1, 10 or 100")))
    }
}

/// An identifier code: one or more printable ASCII characters (33–126), not used before.
fn check_id(id: IdCode, seen: &mut BTreeSet<String>) -> io::Result<()> {
    let s = id.to_string();
    if s.is_empty() || !s.bytes().all(|b| (33..=126).contains(&b)) {
        return Err(invalid(format!(
            "identifier code {s:?} is not printable ASCII"
        )));
    }
    if !seen.insert(s.clone()) {
        return Err(invalid(format!("identifier code {s:?} used twice")));
    }
    Ok(())
}

/// A scope or variable name: printable ASCII without spaces, not starting with `$`.
fn check_name(name: &str) -> io::Result<()> {
    if name.is_empty() || name.starts_with('$') || !name.bytes().all(|b| (33..=126).contains(&b)) {
        return Err(invalid(format!("name {name:?} is not a VCD identifier")));
    }
    Ok(())
}

/// Writes one value change (or initial value).
fn change<W: Write>(w: &mut vcd::Writer<W>, id: IdCode, kind: Kind, val: Val) -> io::Result<()> {
    match (kind, val) {
        (Kind::Bit, Val::Bit(b)) => w.change_scalar(id, b),
        (Kind::Word(width), Val::Word(None)) => {
            debug_assert!(width > 0);
            w.change_vector(id, [Value::Z])
        }
        (Kind::Word(width), Val::Word(Some(v))) => {
            if width < 64 && v >> width != 0 {
                return Err(invalid(format!("{v} does not fit a {width}-bit wire")));
            }
            // Most significant bit first, leading zeros left out (VCD extends with 0).
            let bits = (64 - v.leading_zeros()).max(1);
            w.change_vector(id, (0..bits).rev().map(|b| Value::from(v >> b & 1 == 1)))
        }
        (Kind::Real, Val::Real(r)) => w.change_real(id, r),
        _ => Err(invalid(format!("value {val:?} for a {kind:?} signal"))),
    }
}

/// Writes the whole dump.
pub fn write_vcd(out: &mut dyn Write, wave: &Wave) -> io::Result<()> {
    let l = &wave.layout;
    let mut w = vcd::Writer::new(out);
    w.version(concat!("cwisim ", env!("CARGO_PKG_VERSION")))?;
    let comment = format!(
        "cwisim vcd: scanline {} of a trace {} processors wide, {} channel(s); processors \
{}..={}. One time unit is one array clock cycle; time stamps are absolute cycles: #{} the \
bus starts issuing the scanline's first instruction (number {}), #{} the scanline leaves \
the array. Tokens stay {} cycle(s) in each processor.",
        wave.line,
        wave.header.width,
        l.channels,
        l.from,
        l.from + l.count - 1,
        wave.start,
        wave.first_index,
        wave.end,
        wave.hop,
    );
    if comment.contains("$end") {
        return Err(invalid("the comment holds $end".into()));
    }
    w.comment(&comment)?;
    check_timescale(1)?;
    w.timescale(1, TimescaleUnit::NS)?;
    check_name("cwisim")?;
    w.add_module("cwisim")?;
    let mut ids = Vec::with_capacity(l.defs.len());
    let mut seen = BTreeSet::new();
    let mut open: Option<usize> = None;
    for def in &l.defs {
        if open != Some(def.scope) {
            if open.is_some() {
                w.upscope()?;
            }
            check_name(&l.scopes[def.scope])?;
            w.add_module(&l.scopes[def.scope])?;
            open = Some(def.scope);
        }
        check_name(&def.name)?;
        let (ty, width) = match def.kind {
            Kind::Bit => (VarType::Wire, 1),
            Kind::Word(n) => (VarType::Wire, n),
            Kind::Real => (VarType::Real, 64),
        };
        let id = w.add_var(ty, width, &def.name, None)?;
        check_id(id, &mut seen)?;
        ids.push(id);
    }
    if open.is_some() {
        w.upscope()?;
    }
    w.upscope()?;
    w.enddefinitions()?;

    let (vals, steps) = wave.steps();
    let mut clock = Clock { last: None };
    clock.at(wave.start)?;
    w.timestamp(wave.start)?;
    w.begin(SimulationCommand::Dumpvars)?;
    for (i, def) in l.defs.iter().enumerate() {
        change(&mut w, ids[i], def.kind, vals[i])?;
    }
    w.end()?;
    for (t, changed) in steps {
        clock.at(t)?;
        w.timestamp(t)?;
        for (s, v) in changed {
            change(&mut w, ids[s], l.defs[s].kind, v)?;
        }
    }
    // Mark the end of the window even when nothing changes then.
    if clock.last.is_some_and(|last| last < wave.end) {
        clock.at(wave.end)?;
        w.timestamp(wave.end)?;
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::window_tests::{machines, reader, trace};
    use cwisim_xproc::replay_probed;

    /// [`record_scanline`]'s steps, on the stepped engine from the start of the trace.
    fn record_from_the_start(
        text: &str,
        machine: &Machine,
        line: u64,
        from: usize,
        to: usize,
    ) -> Option<Wave> {
        let mut trace = reader(text);
        let header = *trace.header();
        let hop = machine.timeline(&header).unwrap().hop;
        let done = Rc::new(Cell::new(false));
        let mut probe = Recorder::new(&header, line, from, to, hop, Rc::clone(&done));
        let mut sink = LineCapture {
            line,
            from,
            to,
            channels: header.channel_count(),
            values: None,
        };
        let mut reader = UntilReady {
            inner: &mut trace,
            done,
        };
        replay_probed::<f64>(&mut reader, machine, &mut probe, &mut sink).unwrap();
        probe.finish()
    }

    fn vcd_text(wave: &Wave) -> String {
        let mut out = Vec::new();
        write_vcd(&mut out, wave).unwrap();
        String::from_utf8(out).unwrap()
    }

    /// Every scanline's waveform, with the scanlines before it on the fast engine, is
    /// byte for byte the one a stepped run from the start of the trace gives — also when
    /// the tokens of earlier scanlines are still crossing the window.
    #[test]
    fn every_waveform_is_that_of_a_stepped_run_from_the_start() {
        let text = trace();
        for machine in machines() {
            for line in 0..13 {
                for (from, to) in [(0, 15), (2, 4), (14, 15)] {
                    let windowed =
                        record_scanline(&mut reader(&text), &machine, line, from, to).unwrap();
                    let full = record_from_the_start(&text, &machine, line, from, to);
                    match (windowed, full) {
                        (Ok(w), Some(f)) => {
                            assert_eq!(vcd_text(&w), vcd_text(&f), "{line} {from}..={to}")
                        }
                        (Err(n), None) => assert_eq!((line, n), (12, 12)),
                        _ => panic!("scanline {line}: one replay found it, the other not"),
                    }
                }
            }
        }
    }

    #[test]
    fn timescales_other_than_1_10_100_are_refused() {
        for n in [1, 10, 100] {
            assert!(check_timescale(n).is_ok());
        }
        for n in [0, 2, 5, 1000] {
            assert!(check_timescale(n).is_err());
        }
    }

    #[test]
    fn time_must_strictly_increase() {
        let mut clock = Clock { last: None };
        clock.at(5).expect("first");
        clock.at(6).expect("later");
        assert!(clock.at(6).is_err());
        assert!(clock.at(3).is_err());
    }

    #[test]
    fn generated_identifiers_are_printable_and_unique() {
        let mut seen = BTreeSet::new();
        let mut id = IdCode::FIRST;
        for _ in 0..20_000 {
            check_id(id, &mut seen).expect("valid");
            id = id.next();
        }
        assert!(check_id(IdCode::FIRST, &mut seen).is_err(), "a repeat");
    }

    #[test]
    fn names_with_spaces_or_dollars_are_refused() {
        assert!(check_name("p12").is_ok());
        assert!(check_name("has_dI").is_ok());
        for bad in ["", "a b", "$end", "tab\t", "é"] {
            assert!(check_name(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn vectors_are_written_msb_first_without_leading_zeros_and_must_fit() {
        let mut w = vcd::Writer::new(Vec::new());
        let id = IdCode::FIRST;
        change(&mut w, id, Kind::Word(8), Val::Word(Some(0x0D))).expect("fits");
        change(&mut w, id, Kind::Word(8), Val::Word(Some(0))).expect("zero");
        change(&mut w, id, Kind::Word(32), Val::Word(None)).expect("z");
        change(&mut w, id, Kind::Bit, Val::Bit(true)).expect("bit");
        change(&mut w, id, Kind::Real, Val::Real(-0.0)).expect("real");
        assert!(change(&mut w, id, Kind::Word(8), Val::Word(Some(256))).is_err());
        assert!(change(&mut w, id, Kind::Real, Val::Bit(true)).is_err());
        let buf = std::mem::take(w.writer());
        assert_eq!(
            String::from_utf8(buf).expect("ascii"),
            "b1101 !\nb0 !\nbz !\n1!\nr-0 !\n"
        );
    }

    #[test]
    fn reals_are_written_so_that_they_read_back_exactly() {
        for v in [0.1, 1.0 / 3.0, -2.5e-7, 1e21, f64::MIN_POSITIVE, -0.0] {
            let mut w = vcd::Writer::new(Vec::new());
            w.change_real(IdCode::FIRST, v).expect("write");
            let buf = std::mem::take(w.writer());
            let text = String::from_utf8(buf).expect("ascii");
            let num = text
                .trim_start_matches('r')
                .split(' ')
                .next()
                .expect("value");
            let back: f64 = num.parse().expect("a number");
            assert_eq!(back.to_bits(), v.to_bits(), "{text}");
        }
    }

    #[test]
    fn the_layout_indexes_every_signal_once() {
        for channels in [1, 3] {
            let l = Layout::new(channels, 4, 6);
            let mut all = vec![
                l.bus_opcode(),
                l.bus_x(),
                l.bus_dx(),
                l.bus_index(),
                l.bus_busy(),
            ];
            for slot in 0..3 {
                for k in 0..channels {
                    all.push(l.bus_value(slot, k));
                }
            }
            for p in 4..=6 {
                for k in 0..channels {
                    all.push(l.acc(p, k));
                    all.push(l.out(p, k));
                    for slot in 0..3 {
                        all.push(l.reg(p, slot, k));
                    }
                }
                for slot in 0..3 {
                    all.push(l.has(p, slot));
                }
                all.extend([l.locked(p), l.masked(p), l.neg(p), l.token(p)]);
            }
            all.sort_unstable();
            assert_eq!(all, (0..l.defs.len()).collect::<Vec<_>>());
            assert_eq!(l.defs[l.token(6)].name, "token");
            assert_eq!(l.defs[l.has(5, 1)].name, "has_dI");
            let name = |i: usize| l.defs[i].name.as_str();
            if channels == 3 {
                assert_eq!(name(l.bus_value(1, 2)), "dI_c2");
                assert_eq!(name(l.out(4, 1)), "out_c1");
                assert_eq!(name(l.reg(5, 2, 0)), "ddI_c0");
            } else {
                assert_eq!(name(l.bus_value(0, 0)), "I");
                assert_eq!(name(l.acc(6, 0)), "acc");
            }
        }
    }
}
