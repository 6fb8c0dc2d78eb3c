//! One pixel's history: every instruction that reached processor `x` on scanline `y`,
//! with the registers before and after it acted (`cwisim history`), computed by the
//! cycle-stepped engine through a [`Probe`]. Only scanline `y` is stepped: the fast
//! engine runs the scanlines before it and hands its state over
//! ([`cwisim_xproc::replay_probed_numeric`]).

use crate::error::StudyError;
use crate::until::UntilLine;
use cwisim_isa::text::format_value;
use cwisim_isa::{Instruction, Opcode, TraceRead};
use cwisim_xproc::{
    replay_probed_numeric, Machine, NullSink, Numeric, Probe, ProcessorState, StepFrom,
};

/// Replays `trace` up to scanline `y` and returns every visit of a token to processor
/// `x` on it. `Ok(Err(n))`: the trace outputs only `n` scanlines.
pub fn pixel_history(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    x: usize,
    y: u64,
) -> Result<Result<Vec<Visit>, u64>, StudyError> {
    pixel_history_with_progress(trace, machine, &Numeric::F64, x, y, &mut |_| {})
}

/// [`pixel_history`] with registers of the format `numeric` (the values the history shows
/// are the registers' own, as `f64`), calling `progress` with the bytes of `trace` read so
/// far every few thousand instructions (and at the end): for a progress bar.
pub fn pixel_history_with_progress(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    numeric: &Numeric,
    x: usize,
    y: u64,
    progress: &mut dyn FnMut(u64),
) -> Result<Result<Vec<Visit>, u64>, StudyError> {
    let mut watch = Watch {
        x,
        y,
        visits: Vec::new(),
    };
    let mut reader = UntilLine::new(trace, Some(y));
    replay_probed_numeric(
        &mut reader,
        machine,
        numeric,
        StepFrom::Scanline(y),
        &mut watch,
        &mut NullSink,
        progress,
    )?;
    let lines = reader.lines_read();
    if lines <= y {
        return Ok(Err(lines));
    }
    Ok(Ok(watch.visits))
}

/// One visit of a token to the watched processor.
#[derive(Clone, Debug, PartialEq)]
pub struct Visit {
    /// The cycle the token arrived.
    pub cycle: u64,
    /// The instruction's index in the trace, from 0.
    pub index: u64,
    /// The instruction.
    pub instr: Instruction,
    /// Whether it addressed this processor (else its token only passed through).
    pub addressed: bool,
    /// The processor's registers and flags before it acted.
    pub before: ProcessorState,
    /// And after.
    pub after: ProcessorState,
}

impl Visit {
    /// Whether the processor changed.
    pub fn changed(&self) -> bool {
        self.before != self.after
    }

    /// What the visit amounted to, when not a plain action: `"passes through"`,
    /// `"suppressed: locked by Eval0"`, `"suppressed: masked by Dis"`.
    pub fn note(&self) -> Option<&'static str> {
        let changed = self.changed();
        if !self.addressed {
            Some("passes through")
        } else if !changed
            && self.before.locked
            && matches!(
                self.instr.op,
                Opcode::Eval0 | Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3
            )
        {
            Some("suppressed: locked by Eval0")
        } else if self.before.masked && !self.after.masked && self.before.acc == self.after.acc {
            Some("suppressed: masked by Dis")
        } else {
            None
        }
    }
}

/// The lines `cwisim history` prints for one visit: the instruction with the cycle its
/// token arrived (and [`Visit::note`]), then the registers before and after.
pub fn visit_lines(v: &Visit) -> [String; 3] {
    let how = v.note().map_or_else(String::new, |n| format!("  ({n})"));
    [
        format!(
            "cycle {:>8}  #{:<6} {}{how}",
            v.cycle,
            v.index,
            cwisim_isa::text::format_instruction(&v.instr)
        ),
        format!("    before  {}", state(&v.before)),
        format!("    after   {}", state(&v.after)),
    ]
}

/// Whether `cwisim history` lists a visit (with `all`, every one; else those that
/// address the processor or change it).
pub fn shown(v: &Visit, all: bool) -> bool {
    all || v.addressed || v.changed()
}

/// The line after the visits: the value the scanline's `Refresh` shifted out (its
/// accumulator just before).
pub fn shifted_out_line(acc: &[f64]) -> String {
    format!("shifted out: {}", values(acc))
}

/// The last line when visits were left out.
pub fn hidden_line(hidden: usize) -> String {
    format!("# {hidden} more instruction(s) passed through without acting (--all lists them)")
}

/// Everything `cwisim history` prints after its heading: each shown visit's lines, the
/// value shifted out, and how many visits were left out. The `inspect` page holds the same
/// lines for every pixel of its window.
pub fn history_lines(visits: &[Visit], all: bool) -> Vec<String> {
    let mut out = Vec::new();
    let mut shown_count = 0;
    for v in visits.iter().filter(|v| shown(v, all)) {
        shown_count += 1;
        out.extend(visit_lines(v));
    }
    if let Some(r) = visits.iter().rev().find(|v| v.instr.op == Opcode::Refresh) {
        out.push(shifted_out_line(&r.before.acc));
    }
    let hidden = visits.len() - shown_count;
    if hidden > 0 {
        out.push(hidden_line(hidden));
    }
    out
}

struct Watch {
    x: usize,
    y: u64,
    visits: Vec<Visit>,
}

impl Probe for Watch {
    fn watches(&self, p: usize) -> bool {
        p == self.x
    }

    fn visit(
        &mut self,
        cycle: u64,
        _p: usize,
        index: u64,
        line: u64,
        instr: &Instruction,
        addressed: bool,
        before: &ProcessorState,
        after: &ProcessorState,
    ) {
        if line == self.y {
            self.visits.push(Visit {
                cycle,
                index,
                instr: instr.clone(),
                addressed,
                before: before.clone(),
                after: after.clone(),
            });
        }
    }
}

/// Values as the text trace writes them, comma-separated.
pub fn values(v: &[f64]) -> String {
    v.iter()
        .map(|x| format_value(*x))
        .collect::<Vec<_>>()
        .join(",")
}

/// The registers and flags, one line: `acc=… I=… dI=… ddI=… [locked masked neg]`;
/// a preload register shows `-` when it holds no unconsumed value.
pub fn state(s: &ProcessorState) -> String {
    let reg = |k: usize| {
        if s.has[k] {
            values(&s.reg[k])
        } else {
            "-".to_string()
        }
    };
    let mut flags = Vec::new();
    if s.locked {
        flags.push("locked");
    }
    if s.masked {
        flags.push("masked");
    }
    if s.negative_enabled {
        flags.push("neg");
    }
    format!(
        "acc={} I={} dI={} ddI={} flags={}",
        values(&s.acc),
        reg(0),
        reg(1),
        reg(2),
        if flags.is_empty() {
            "-".to_string()
        } else {
            flags.join(",")
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::window_tests::{machines, reader, trace};
    use cwisim_xproc::replay_probed;

    /// Every pixel's history, with the scanlines before it on the fast engine, is the
    /// history a stepped run from the start of the trace gives.
    #[test]
    fn every_history_is_that_of_a_stepped_run_from_the_start() {
        let text = trace();
        for machine in machines() {
            for y in 0..13 {
                for x in 0..16 {
                    let windowed = pixel_history(&mut reader(&text), &machine, x, y).unwrap();
                    let mut watch = Watch {
                        x,
                        y,
                        visits: Vec::new(),
                    };
                    replay_probed::<f64>(&mut reader(&text), &machine, &mut watch, &mut NullSink)
                        .unwrap();
                    if y < 12 {
                        assert!(!watch.visits.is_empty());
                        assert_eq!(windowed, Ok(watch.visits), "({x}, {y})");
                    } else {
                        assert_eq!(windowed, Err(12));
                    }
                }
            }
        }
    }
}
