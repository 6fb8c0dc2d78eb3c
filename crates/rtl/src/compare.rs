//! Holding what the generated array did ([`Observed`]) to the stepped engine
//! ([`Expected`]): every scanline's values bit for bit, each scanline's overflow events
//! and ready cycle, the cycle every token arrived at every watched processor. The first
//! difference — the earliest in cycles — is reported with its scanline, processor,
//! cycle and instruction.

use crate::design::Design;
use crate::dump::{End, Observed};
use crate::error::RtlError;
use crate::reference::Expected;
use crate::stimulus::Conversions;
use cwisim_isa::{Instruction, Opcode};
use cwisim_xproc::{Arith, FixedArith, Register};
use std::fmt;

/// A difference between the array and the stepped engine.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// What differs.
    pub what: String,
    /// The scanline, from 0.
    pub scanline: u64,
    /// The processor, where one is concerned.
    pub processor: Option<u32>,
    /// The cycle (the earlier of the two sides' where both have one).
    pub cycle: u64,
    /// The instruction: its number and text form.
    pub instruction: Option<(u64, String)>,
    /// The stepped engine's side.
    pub expected: String,
    /// The array's side.
    pub got: String,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "scanline {}", self.scanline)?;
        if let Some(p) = self.processor {
            write!(f, ", processor {p}")?;
        }
        write!(f, ", cycle {}", self.cycle)?;
        if let Some((i, text)) = &self.instruction {
            write!(f, ", instruction {i} ({text})")?;
        }
        write!(
            f,
            ": {}: the stepped engine {}, the RTL {}",
            self.what, self.expected, self.got
        )
    }
}

/// What agreed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Agreement {
    /// Scanlines compared.
    pub scanlines: u64,
    /// Output values compared (scanlines × width × channels).
    pub values: u64,
    /// Token arrivals compared (instructions × watched processors).
    pub arrivals: u64,
    /// Overflow events counted (the same on both sides), operand conversions included.
    pub overflows: u64,
    /// Those of them in the array's adders (the rest are the Y-processor's conversions).
    pub adder_overflows: u64,
    /// The cycle the last token left the array.
    pub cycles: u64,
}

/// Which scanline each instruction belongs to.
fn line_of(trace: &[Instruction]) -> Vec<u64> {
    let mut line = 0;
    trace
        .iter()
        .map(|i| {
            let l = line;
            if i.op == Opcode::Refresh {
                line += 1;
            }
            l
        })
        .collect()
}

/// The indices of `trace`'s Refresh instructions: scanline `n`'s is the `n`-th.
pub(crate) fn refresh_indices(trace: &[Instruction]) -> Vec<usize> {
    trace
        .iter()
        .enumerate()
        .filter(|(_, i)| i.op == Opcode::Refresh)
        .map(|(k, _)| k)
        .collect()
}

/// `x`'s low `bits` bits as a two's-complement number.
pub(crate) fn sign_extend(x: u64, bits: u32) -> i64 {
    if bits >= 64 {
        x as i64
    } else {
        let shift = 64 - bits;
        ((x << shift) as i64) >> shift
    }
}

/// Compares; `Ok` with what agreed, or the earliest mismatch.
pub fn compare(
    d: &Design,
    trace: &[Instruction],
    expected: &Expected,
    conv: &Conversions,
    observed: &Observed,
) -> Result<Result<Agreement, Mismatch>, RtlError> {
    let arith = FixedArith::new(&d.format)?;
    let lines = line_of(trace);
    let instr = |k: usize| trace.get(k).map(|i| (k as u64, i.to_string()));
    let line = |k: usize| lines.get(k).copied().unwrap_or(expected.lines.len() as u64);
    let mut found: Vec<Mismatch> = Vec::new();

    // token arrivals at the watched processors
    let mut arrivals = 0u64;
    for (p, want) in &expected.arrivals {
        let got = observed.arrivals.get(p).map(Vec::as_slice).unwrap_or(&[]);
        let first = want.iter().zip(got).position(|(a, b)| a != b);
        match first {
            Some(k) => found.push(Mismatch {
                what: "the cycle the token arrives".into(),
                scanline: line(k),
                processor: Some(*p),
                cycle: want[k].min(got[k]),
                instruction: instr(k),
                expected: format!("at cycle {}", want[k]),
                got: format!("at cycle {}", got[k]),
            }),
            None if want.len() != got.len() => {
                let k = want.len().min(got.len());
                let cycle = want.get(k).or(got.get(k)).copied().unwrap_or(0);
                found.push(Mismatch {
                    what: "token arrivals".into(),
                    scanline: line(k),
                    processor: Some(*p),
                    cycle,
                    instruction: instr(k),
                    expected: format!("{} arrivals", want.len()),
                    got: format!("{} arrivals", got.len()),
                });
            }
            None => arrivals += want.len() as u64,
        }
    }

    // the scanlines, processor by processor
    let c_n = d.channels;
    let wa = d.bits(Register::Acc);
    let refreshes = refresh_indices(trace);
    let mut values = 0u64;
    for p in 0..d.width {
        let got = observed.outputs.get(&p).map(Vec::as_slice).unwrap_or(&[]);
        let mut bad = None;
        for (n, want) in expected.lines.iter().enumerate() {
            let Some((cycle, raw)) = got.get(n) else {
                bad = Some(Mismatch {
                    what: "the scanline's output".into(),
                    scanline: n as u64,
                    processor: Some(p),
                    cycle: expected.ready.get(n).copied().unwrap_or(0),
                    instruction: refreshes.get(n).and_then(|k| instr(*k)),
                    expected: format!("outputs {} scanline(s)", expected.lines.len()),
                    got: format!("output {}", got.len()),
                });
                break;
            };
            let want = &want[p as usize * c_n..p as usize * c_n + c_n];
            if raw.len() != c_n {
                return Err(RtlError::Parse {
                    what: "dump".into(),
                    line: 0,
                    message: format!(
                        "processor {p}'s output {n} has {} channel(s), not {c_n}",
                        raw.len()
                    ),
                });
            }
            let outs: Vec<f64> = raw.iter().map(|r| arith.out(sign_extend(*r, wa))).collect();
            if let Some(c) = (0..c_n).find(|c| outs[*c].to_bits() != want[*c].to_bits()) {
                bad = Some(Mismatch {
                    what: format!("output value, channel {c}"),
                    scanline: n as u64,
                    processor: Some(p),
                    cycle: *cycle,
                    instruction: refreshes.get(n).and_then(|k| instr(*k)),
                    expected: format!("{:e}", want[c]),
                    got: format!("{:e} (raw {})", outs[c], sign_extend(raw[c], wa)),
                });
                break;
            }
            values += c_n as u64;
        }
        if bad.is_none() && got.len() > expected.lines.len() {
            let (cycle, _) = got[expected.lines.len()];
            bad = Some(Mismatch {
                what: "the scanline's output".into(),
                scanline: expected.lines.len() as u64,
                processor: Some(p),
                cycle,
                instruction: None,
                expected: format!("outputs {} scanline(s)", expected.lines.len()),
                got: format!("output {}", got.len()),
            });
        }
        found.extend(bad);
    }

    // tokens leaving: scanlines ready, overflow events per scanline
    let mut ovf_lines = conv.overflows_per_line.clone();
    let adder_overflows: u64 = observed.exits.iter().map(|(_, o)| o).sum();
    let mut ready = Vec::new();
    for (k, (cycle, ovf)) in observed.exits.iter().enumerate() {
        let Some(i) = trace.get(k) else {
            found.push(Mismatch {
                what: "tokens leaving the array".into(),
                scanline: line(k),
                processor: None,
                cycle: *cycle,
                instruction: None,
                expected: format!("has {} token(s)", trace.len()),
                got: "has more".into(),
            });
            break;
        };
        let l = line(k) as usize;
        if l < ovf_lines.len() {
            ovf_lines[l] += ovf;
        }
        if i.op == Opcode::Refresh {
            ready.push((k, *cycle));
        }
    }
    let mut overflows = 0u64;
    for (n, want_ready) in expected.ready.iter().enumerate() {
        let k = refreshes.get(n).copied();
        match ready.get(n) {
            None => {
                found.push(Mismatch {
                    what: "the scanline leaves the array".into(),
                    scanline: n as u64,
                    processor: None,
                    cycle: *want_ready,
                    instruction: k.and_then(instr),
                    expected: format!("at cycle {want_ready}"),
                    got: "never".into(),
                });
                break;
            }
            Some((_, got_ready)) if got_ready != want_ready => found.push(Mismatch {
                what: "the cycle the scanline is ready (its Refresh leaves the last processor)"
                    .into(),
                scanline: n as u64,
                processor: None,
                cycle: *want_ready.min(got_ready),
                instruction: k.and_then(instr),
                expected: format!("at cycle {want_ready}"),
                got: format!("at cycle {got_ready}"),
            }),
            Some((_, got_ready)) => {
                let want = expected.overflows.get(n).copied().unwrap_or(0);
                let got = ovf_lines.get(n).copied().unwrap_or(0);
                if want != got {
                    found.push(Mismatch {
                        what: "overflow events of the scanline".into(),
                        scanline: n as u64,
                        processor: None,
                        cycle: *got_ready,
                        instruction: k.and_then(instr),
                        expected: format!("counts {want}"),
                        got: format!(
                            "counts {got} ({} in operand conversions)",
                            conv.overflows_per_line.get(n).copied().unwrap_or(0)
                        ),
                    });
                }
                overflows += want;
            }
        }
    }
    // how it ended
    let end_cycle = expected.cycles.saturating_add(1);
    match observed.end {
        End::Idle(c) if c != end_cycle => found.push(Mismatch {
            what: "the cycle the array falls idle".into(),
            scanline: expected.lines.len() as u64,
            processor: None,
            cycle: c.min(end_cycle),
            instruction: None,
            expected: format!(
                "at cycle {end_cycle} (the last token left at {})",
                expected.cycles
            ),
            got: format!("at cycle {c}"),
        }),
        End::Idle(_) => {}
        End::Limit(c) => found.push(Mismatch {
            what: "the simulation".into(),
            scanline: expected.lines.len() as u64,
            processor: None,
            cycle: c,
            instruction: None,
            expected: format!("ends at cycle {end_cycle}"),
            got: format!("was still busy at the cycle limit {c}"),
        }),
        End::Missing => {
            return Err(RtlError::Parse {
                what: "dump".into(),
                line: 0,
                message: "the dump ends without its last record (the simulator stopped early)"
                    .into(),
            })
        }
    }
    if let Some(first) = found.into_iter().min_by_key(|m| m.cycle) {
        return Ok(Err(first));
    }
    Ok(Ok(Agreement {
        scanlines: expected.lines.len() as u64,
        values,
        arrivals,
        overflows,
        adder_overflows,
        cycles: expected.cycles,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{all_opcodes, BusTiming};
    use crate::reference::expected;
    use crate::stimulus;
    use crate::verilog::Watch;
    use cwisim_isa::{Intensity, TraceHeader};
    use cwisim_xproc::{Machine, Numeric};
    use std::collections::BTreeMap;

    /// A design, a trace, the stepped engine's account and the conversions.
    fn setup() -> (Design, Vec<Instruction>, Expected, Conversions) {
        let header = TraceHeader::new(4, 2, 1).unwrap();
        let Numeric::Fixed(f) = "fixed:I=2.6,dI=2.6,ddI=2.6".parse::<Numeric>().unwrap() else {
            unreachable!()
        };
        let machine = Machine::default();
        let d = Design::new(
            f,
            all_opcodes(),
            4,
            1,
            BusTiming::new(&machine, &header).unwrap(),
        )
        .unwrap();
        let trace = vec![
            Instruction::eval2(1, 3, Intensity::grey(0.5), Intensity::grey(0.25)),
            Instruction::refresh(),
            Instruction::eval1(0, 4, Intensity::grey(1.75)),
            Instruction::eval1(0, 4, Intensity::grey(1.75)),
            Instruction::refresh(),
        ];
        let want = expected(&d, &header, &trace, &machine, &Watch::all(4)).unwrap();
        let conv = stimulus::write(&d, &header, &trace, &mut Vec::new()).unwrap();
        (d, trace, want, conv)
    }

    /// What a faithful simulation of `want` dumps.
    fn faithful(
        d: &Design,
        trace: &[Instruction],
        want: &Expected,
        conv: &Conversions,
    ) -> Observed {
        let arith = FixedArith::new(&d.format).unwrap();
        let scale = d.format.acc.quantum();
        let mut outputs: BTreeMap<u32, Vec<(u64, Vec<u64>)>> = BTreeMap::new();
        for (n, line) in want.lines.iter().enumerate() {
            for p in 0..d.width {
                let raw = (line[p as usize] / scale) as i64;
                assert_eq!(arith.out(raw), line[p as usize]);
                let bits = (raw as u64) & ((1u64 << d.format.acc.width()) - 1);
                outputs
                    .entry(p)
                    .or_default()
                    .push((want.ready[n] - 4 + u64::from(p), vec![bits]));
            }
        }
        // every scanline's overflow events in its Refresh's exit, less the conversions'
        let mut exits = Vec::new();
        let mut line = 0;
        for (k, i) in trace.iter().enumerate() {
            let ovf = if i.op == Opcode::Refresh {
                want.overflows[line] - conv.overflows_per_line[line]
            } else {
                0
            };
            let cycle = if i.op == Opcode::Refresh {
                want.ready[line]
            } else {
                want.arrivals[&3][k] + 1
            };
            exits.push((cycle, ovf));
            if i.op == Opcode::Refresh {
                line += 1;
            }
        }
        Observed {
            arrivals: want.arrivals.clone(),
            outputs,
            exits,
            end: End::Idle(want.cycles + 1),
        }
    }

    #[test]
    fn a_faithful_dump_agrees_and_every_kind_of_difference_is_found() {
        let (d, trace, want, conv) = setup();
        let good = faithful(&d, &trace, &want, &conv);
        let a = compare(&d, &trace, &want, &conv, &good).unwrap().unwrap();
        assert_eq!((a.scanlines, a.values, a.arrivals), (2, 8, 20));
        assert!(a.overflows > 0, "1.75 + 1.75 saturates Q2.6: {a:?}");

        // one output bit
        let mut bad = good.clone();
        bad.outputs.get_mut(&2).unwrap()[1].1[0] ^= 1;
        let m = compare(&d, &trace, &want, &conv, &bad)
            .unwrap()
            .unwrap_err();
        assert_eq!((m.scanline, m.processor), (1, Some(2)), "{m}");
        assert!(m.what.starts_with("output value"), "{m}");
        assert_eq!(m.instruction.as_ref().map(|i| i.0), Some(4));

        // a token a cycle late at processor 1: the earliest difference is reported
        let mut bad = good.clone();
        bad.arrivals.get_mut(&1).unwrap()[2] += 1;
        bad.outputs.get_mut(&3).unwrap()[1].1[0] ^= 1;
        let m = compare(&d, &trace, &want, &conv, &bad)
            .unwrap()
            .unwrap_err();
        assert_eq!((m.scanline, m.processor), (1, Some(1)), "{m}");
        assert_eq!(m.instruction.as_ref().map(|i| i.0), Some(2));
        assert_eq!(m.cycle, want.arrivals[&1][2]);
        assert!(
            m.to_string().contains("instruction 2 (Eval1 0 4 1.75)"),
            "{m}"
        );

        // overflow events, a ready cycle, the end
        let mut bad = good.clone();
        bad.exits[4].1 += 1;
        let m = compare(&d, &trace, &want, &conv, &bad)
            .unwrap()
            .unwrap_err();
        assert!(m.what.starts_with("overflow events"), "{m}");
        let mut bad = good.clone();
        bad.exits[1].0 += 1;
        let m = compare(&d, &trace, &want, &conv, &bad)
            .unwrap()
            .unwrap_err();
        assert!(m.what.contains("ready"), "{m}");
        let mut bad = good.clone();
        bad.end = End::Limit(99);
        assert!(compare(&d, &trace, &want, &conv, &bad).unwrap().is_err());
        let mut bad = good;
        bad.end = End::Missing;
        assert!(compare(&d, &trace, &want, &conv, &bad).is_err());
    }
}
