//! The machine model: every timing parameter of the X-processor array, as named
//! assumptions with defaults, read from JSON and overridable key by key.
//!
//! The original hardware reports are not public; `docs/TIMING.md` explains each
//! parameter, its default, and why.

use cwisim_isa::{Instruction, Opcode, TraceHeader};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The timing parameters of the array and the display it drives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Machine {
    /// The array's clock, in Hz.
    pub clock_hz: f64,
    /// Frames per second the display shows.
    pub frame_rate_hz: f64,
    /// Line periods of vertical blanking after each frame's scanlines.
    pub vblank_lines: u32,
    /// The line period in cycles; `None` derives it from the clock, frame rate and line
    /// count: `floor(clock_hz / (frame_rate_hz * (lines + vblank_lines)))`.
    pub line_period_cycles: Option<u64>,
    /// Cycles a token (instruction and its forward-differencing state) spends in each
    /// processor of the systolic chain before it moves to the next.
    pub hop_cycles: u32,
    /// Bus cycles for an instruction's opcode word (which carries `x` and `dx`), per
    /// opcode; opcodes not listed cost 1.
    pub opcode_cycles: BTreeMap<String, u32>,
    /// Bus cycles per intensity value (one channel of one of `I`, `dI`, `ddI`).
    pub value_cycles: u32,
}

impl Default for Machine {
    fn default() -> Self {
        Machine {
            clock_hz: 100e6,
            frame_rate_hz: 60.0,
            vblank_lines: 45,
            line_period_cycles: None,
            hop_cycles: 1,
            opcode_cycles: BTreeMap::new(),
            value_cycles: 1,
        }
    }
}

/// A machine description that cannot be used.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum MachineError {
    /// The file could not be read.
    #[error("{path}: cannot read the machine file: {message}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The JSON does not describe a machine.
    #[error("{where_}: {message}")]
    Parse {
        /// File and line:column, or the override.
        where_: String,
        /// What was expected.
        message: String,
    },
    /// A parameter outside its range.
    #[error("machine parameter `{name}`: {message}")]
    Invalid {
        /// The parameter.
        name: String,
        /// Why.
        message: String,
    },
}

impl Machine {
    /// Reads a machine file (JSON; keys not given keep their defaults).
    pub fn from_file(path: &Path) -> Result<Machine, MachineError> {
        let text = std::fs::read_to_string(path).map_err(|e| MachineError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Machine::from_json(&text, &path.display().to_string())
    }

    /// Parses machine JSON; `origin` names it in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<Machine, MachineError> {
        let m: Machine = serde_json::from_str(text).map_err(|e| MachineError::Parse {
            where_: format!("{origin}:{}:{}", e.line(), e.column()),
            message: strip_serde_location(&e),
        })?;
        m.validate()?;
        Ok(m)
    }

    /// Applies `key=value` overrides (`value` is JSON: `2`, `1e8`, `null`), e.g.
    /// `clock_hz=2e8` or `opcode_cycles.Eval3=2`.
    pub fn with_overrides(&self, overrides: &[String]) -> Result<Machine, MachineError> {
        let mut json = serde_json::to_value(self).expect("a machine serializes");
        for o in overrides {
            let bad = |m: &str| MachineError::Parse {
                where_: format!("override `{o}`"),
                message: m.to_string(),
            };
            let (key, value) = o.split_once('=').ok_or_else(|| bad("expected KEY=VALUE"))?;
            let value: serde_json::Value = serde_json::from_str(value).map_err(|_| {
                bad("the value is not JSON (a number, true/false, null or a quoted string)")
            })?;
            let mut target = &mut json;
            let mut parts = key.split('.').peekable();
            while let Some(part) = parts.next() {
                let obj = target
                    .as_object_mut()
                    .ok_or_else(|| bad("that key has no sub-keys"))?;
                if parts.peek().is_none() {
                    if key.contains('.') || obj.contains_key(part) {
                        obj.insert(part.to_string(), value.clone());
                    } else {
                        let known: Vec<&String> = obj.keys().collect();
                        return Err(bad(&format!(
                            "unknown machine parameter `{part}`; known: {known:?}"
                        )));
                    }
                    break;
                }
                target = obj
                    .get_mut(part)
                    .ok_or_else(|| bad(&format!("unknown machine parameter `{part}`")))?;
            }
        }
        let m: Machine = serde_json::from_value(json).map_err(|e| MachineError::Parse {
            where_: "machine overrides".into(),
            message: strip_serde_location(&e),
        })?;
        m.validate()?;
        Ok(m)
    }

    /// Checks every parameter's range.
    pub fn validate(&self) -> Result<(), MachineError> {
        let invalid = |name: &str, message: &str| {
            Err(MachineError::Invalid {
                name: name.into(),
                message: message.into(),
            })
        };
        if !(self.clock_hz.is_finite() && self.clock_hz > 0.0) {
            return invalid("clock_hz", "must be a positive finite number of Hz");
        }
        if !(self.frame_rate_hz.is_finite() && self.frame_rate_hz > 0.0) {
            return invalid("frame_rate_hz", "must be a positive finite number of Hz");
        }
        if self.hop_cycles == 0 {
            return invalid("hop_cycles", "must be at least 1");
        }
        if self.line_period_cycles == Some(0) {
            return invalid(
                "line_period_cycles",
                "must be at least 1 (or null to derive it)",
            );
        }
        for (name, &c) in &self.opcode_cycles {
            if Opcode::from_name(name).is_none() {
                return invalid(
                    &format!("opcode_cycles.{name}"),
                    "is not an opcode name (SetI … Nop)",
                );
            }
            if c == 0 {
                return invalid(&format!("opcode_cycles.{name}"), "must be at least 1");
            }
        }
        Ok(())
    }

    /// The bus cycles of one opcode word.
    pub fn opcode_word_cycles(&self, op: Opcode) -> u32 {
        self.opcode_cycles.get(op.name()).copied().unwrap_or(1)
    }

    /// The timeline for one trace: costs per opcode and the display's line period.
    pub fn timeline(&self, header: &TraceHeader) -> Result<Timeline, MachineError> {
        self.validate()?;
        let lines_per_frame = u64::from(header.lines);
        let slots = lines_per_frame + u64::from(self.vblank_lines);
        let period = match self.line_period_cycles {
            Some(p) => p,
            None => {
                let p = (self.clock_hz / (self.frame_rate_hz * slots as f64)).floor();
                if p < 1.0 {
                    return Err(MachineError::Invalid {
                        name: "clock_hz".into(),
                        message: format!(
                            "{} Hz gives less than one cycle per line period at {} Hz × {slots} lines",
                            self.clock_hz, self.frame_rate_hz
                        ),
                    });
                }
                p as u64
            }
        };
        let channels = u64::from(header.channels);
        let mut cost = [0u64; Opcode::COUNT];
        for op in Opcode::ALL {
            cost[op.index()] = u64::from(self.opcode_word_cycles(*op))
                + op.value_operands() as u64 * channels * u64::from(self.value_cycles);
        }
        Ok(Timeline {
            width: u64::from(header.width),
            hop: u64::from(self.hop_cycles),
            line_period: period,
            lines_per_frame,
            slots_per_frame: slots,
            cost,
        })
    }
}

fn strip_serde_location(e: &serde_json::Error) -> String {
    let msg = e.to_string();
    msg.rsplit_once(" at line ")
        .map_or(msg.clone(), |(m, _)| m.to_string())
}

/// The model's fixed quantities for one trace, derived from a [`Machine`] and a header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Timeline {
    /// Processors in the chain.
    pub width: u64,
    /// Cycles per processor hop.
    pub hop: u64,
    /// Cycles per display line period.
    pub line_period: u64,
    /// Scanlines per frame.
    pub lines_per_frame: u64,
    /// Line periods per frame, blanking included.
    pub slots_per_frame: u64,
    cost: [u64; Opcode::COUNT],
}

impl Timeline {
    /// Bus cycles to issue `instr`.
    pub fn issue_cycles(&self, instr: &Instruction) -> u64 {
        self.cost[instr.op.index()]
    }

    /// Bus cycles per opcode, indexed by [`Opcode::index`].
    pub(crate) fn cost_table(&self) -> [u64; Opcode::COUNT] {
        self.cost
    }

    /// The cycle at which the display takes scanline `n` (counted over the whole trace):
    /// the end of the line period before its display slot. It must be ready by then.
    pub fn deadline(&self, n: u64) -> u64 {
        let frame = n / self.lines_per_frame;
        let row = n % self.lines_per_frame;
        (frame * self.slots_per_frame + row + 1) * self.line_period
    }

    /// The earliest cycle the `Refresh` that ends scanline `n` may start to issue: the
    /// display must have taken scanline `n - 1` out of the output registers.
    pub fn refresh_gate(&self, n: u64) -> u64 {
        if n == 0 {
            0
        } else {
            self.deadline(n - 1)
        }
    }

    /// Cycles for a token to cross the whole chain.
    pub fn traversal(&self) -> u64 {
        self.width * self.hop
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::Intensity;

    #[test]
    fn defaults_give_the_documented_line_period() {
        let h = TraceHeader::new(1024, 1024, 1).unwrap();
        let t = Machine::default().timeline(&h).unwrap();
        // 100 MHz / (60 Hz * (1024 + 45)) = 1559.03…
        assert_eq!(t.line_period, 1559);
        assert_eq!(t.deadline(0), 1559);
        assert_eq!(t.deadline(1023), 1024 * 1559);
        // the first line of frame 1 comes after 45 blank line periods
        assert_eq!(t.deadline(1024), (1069 + 1) * 1559);
        assert_eq!(t.refresh_gate(0), 0);
        assert_eq!(t.refresh_gate(5), t.deadline(4));
    }

    #[test]
    fn issue_cost_counts_value_words_per_channel() {
        let m = Machine::default();
        let grey = m.timeline(&TraceHeader::new(8, 1, 1).unwrap()).unwrap();
        let rgb = m.timeline(&TraceHeader::new(8, 1, 3).unwrap()).unwrap();
        let e3 = Instruction::eval3(
            0,
            1,
            Intensity::grey(0.0),
            Intensity::grey(0.0),
            Intensity::grey(0.0),
        );
        assert_eq!(grey.issue_cycles(&e3), 4);
        assert_eq!(rgb.issue_cycles(&e3), 10);
        assert_eq!(grey.issue_cycles(&Instruction::refresh()), 1);
    }

    #[test]
    fn overrides_and_validation() {
        let m = Machine::default()
            .with_overrides(&[
                "clock_hz=2e8".into(),
                "opcode_cycles.Eval3=3".into(),
                "line_period_cycles=500".into(),
            ])
            .unwrap();
        assert_eq!(m.clock_hz, 2e8);
        assert_eq!(m.opcode_word_cycles(Opcode::Eval3), 3);
        assert_eq!(m.line_period_cycles, Some(500));
        assert!(Machine::default()
            .with_overrides(&["clok_hz=1".into()])
            .is_err());
        assert!(Machine::default()
            .with_overrides(&["hop_cycles=0".into()])
            .is_err());
        assert!(Machine::default()
            .with_overrides(&["opcode_cycles.Blit=2".into()])
            .is_err());
        assert!(Machine::from_json("{\"clock_hz\": -1}", "m.json").is_err());
        let e = Machine::from_json("{\"clock\": 1}", "m.json").unwrap_err();
        assert!(e.to_string().starts_with("m.json:1:"), "{e}");
    }
}
