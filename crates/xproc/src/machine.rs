//! The machine model: every timing parameter of the X-processor array, as named
//! assumptions with defaults, read from JSON and overridable key by key.
//!
//! The original hardware reports are not public; `docs/TIMING.md` explains each
//! parameter, its default, and why.
//!
//! # Ranges, and why cycle counts cannot wrap
//!
//! Every parameter has a range ([`Machine::validate`], the `MAX_*` constants here),
//! generous for any display one would study, and chosen so that every quantity of one
//! instruction or one frame fits in a `u64` with room to spare:
//!
//! * an issue cost is at most `MAX_OPCODE_CYCLES + 3 × MAX_CHANNELS × MAX_VALUE_CYCLES`
//!   = 13 × 2¹⁶ < 2²⁰ cycles;
//! * a traversal is at most `MAX_WIDTH × MAX_HOP_CYCLES` = 2³² cycles;
//! * a frame is at most `(MAX_LINES + MAX_VBLANK_LINES) × MAX_LINE_PERIOD_CYCLES` = 2⁵⁷
//!   cycles, and a row's deadline within its frame at most 2⁵⁶.
//!
//! A run's cycle count has no such bound — a trace's instructions and frames are not
//! limited — so the quantities that grow with the run (deadlines, the cycle a scanline's
//! instructions enter or leave the chain, per-scanline sums) are added and multiplied
//! saturating, once per scanline: they stop at `u64::MAX` and never wrap; a slack beyond
//! `i64` is clamped; and the statistics count the scanlines that reached `u64::MAX`
//! ([`crate::Totals::saturated_lines`]). The fast engine does no cycle arithmetic per
//! instruction (it counts opcodes); the stepped engine's clock advances one cycle per
//! step and cannot come near 2⁶⁴.

use cwisim_isa::{Instruction, Opcode, TraceHeader};
use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize, Serializer};
use std::collections::BTreeMap;
use std::path::Path;

/// The fastest array clock: 1 THz (`1e12` Hz). Real arrays of this kind run at tens or
/// hundreds of MHz; a THz array is not a design anyone studies. At this clock a 1 Hz
/// display of one line still has a line period within [`MAX_LINE_PERIOD_CYCLES`].
pub const MAX_CLOCK_HZ: f64 = 1e12;

/// The highest frame rate: 1 MHz (`1e6` Hz), four orders of magnitude above any display.
pub const MAX_FRAME_RATE_HZ: f64 = 1e6;

/// The most line periods of vertical blanking: 2¹⁶, as many as the tallest trace has
/// scanlines (`cwisim_isa::MAX_LINES`); real displays blank for about 40.
pub const MAX_VBLANK_LINES: u32 = 1 << 16;

/// The longest line period, set or derived: 2⁴⁰ cycles (≈ 1.1 × 10¹²), a whole second of
/// the fastest clock ([`MAX_CLOCK_HZ`]).
pub const MAX_LINE_PERIOD_CYCLES: u64 = 1 << 40;

/// The most cycles a token spends in one processor: 2¹⁶ (real hops take one or a few).
pub const MAX_HOP_CYCLES: u32 = 1 << 16;

/// The most bus cycles of one opcode word: 2¹⁶.
pub const MAX_OPCODE_CYCLES: u32 = 1 << 16;

/// The most bus cycles of one channel value: 2¹⁶.
pub const MAX_VALUE_CYCLES: u32 = 1 << 16;

/// The timing parameters of the array and the display it drives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Machine {
    /// The array's clock, in Hz: more than 0, at most [`MAX_CLOCK_HZ`].
    pub clock_hz: f64,
    /// Frames per second the display shows: more than 0, at most [`MAX_FRAME_RATE_HZ`].
    pub frame_rate_hz: f64,
    /// Line periods of vertical blanking after each frame's scanlines: at most
    /// [`MAX_VBLANK_LINES`].
    pub vblank_lines: u32,
    /// The line period in cycles, 1 to [`MAX_LINE_PERIOD_CYCLES`]; `None` derives it from
    /// the clock, frame rate and line count:
    /// `floor(clock_hz / (frame_rate_hz * (lines + vblank_lines)))`, which must be in the
    /// same range.
    pub line_period_cycles: Option<u64>,
    /// Cycles a token (instruction and its forward-differencing state) spends in each
    /// processor of the systolic chain before it moves to the next: 1 to
    /// [`MAX_HOP_CYCLES`].
    pub hop_cycles: u32,
    /// Bus cycles for an instruction's opcode word (which carries `x` and `dx`), per
    /// opcode: 1 to [`MAX_OPCODE_CYCLES`] each. Serialized with every opcode; opcodes a
    /// machine file does not list cost 1.
    pub opcode_cycles: OpcodeCycles,
    /// Bus cycles per intensity value (one channel of one of `I`, `dI`, `ddI`): 0 (values
    /// travel free) to [`MAX_VALUE_CYCLES`].
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
            opcode_cycles: OpcodeCycles::default(),
            value_cycles: 1,
        }
    }
}

/// The bus cycles of each opcode's word: 1 unless set.
///
/// Serializes as a map of every opcode name to its cost, in opcode order
/// (`{"SetI": 1, …, "Nop": 1}`); deserializes from a map of some of them (the others
/// cost 1), refusing a name that is not an opcode.
#[derive(Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(try_from = "BTreeMap<String, u32>")]
pub struct OpcodeCycles([u32; Opcode::COUNT]);

impl Default for OpcodeCycles {
    fn default() -> Self {
        OpcodeCycles([1; Opcode::COUNT])
    }
}

impl OpcodeCycles {
    /// The cost of `op`'s word.
    pub fn get(&self, op: Opcode) -> u32 {
        self.0[op.index()]
    }

    /// Sets the cost of `op`'s word.
    pub fn set(&mut self, op: Opcode, cycles: u32) {
        self.0[op.index()] = cycles;
    }

    /// Every opcode with its cost, in opcode order.
    pub fn iter(&self) -> impl Iterator<Item = (Opcode, u32)> + '_ {
        Opcode::ALL.iter().map(|&op| (op, self.get(op)))
    }
}

/// The costs given, the others 1: `[(Opcode::Eval3, 2)].into()`.
impl<const N: usize> From<[(Opcode, u32); N]> for OpcodeCycles {
    fn from(costs: [(Opcode, u32); N]) -> Self {
        let mut t = OpcodeCycles::default();
        for (op, c) in costs {
            t.set(op, c);
        }
        t
    }
}

impl TryFrom<BTreeMap<String, u32>> for OpcodeCycles {
    type Error = String;

    fn try_from(costs: BTreeMap<String, u32>) -> Result<Self, String> {
        let mut t = OpcodeCycles::default();
        for (name, c) in costs {
            let op = Opcode::from_name(&name).ok_or_else(|| {
                let names: Vec<&str> = Opcode::ALL.iter().map(|op| op.name()).collect();
                format!(
                    "`opcode_cycles.{name}` is not an opcode name ({})",
                    names.join(", ")
                )
            })?;
            t.set(op, c);
        }
        Ok(t)
    }
}

impl Serialize for OpcodeCycles {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(Opcode::COUNT))?;
        for (op, c) in self.iter() {
            m.serialize_entry(op.name(), &c)?;
        }
        m.end()
    }
}

impl std::fmt::Debug for OpcodeCycles {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_map()
            .entries(self.iter().map(|(op, c)| (op.name(), c)))
            .finish()
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
    /// `clock_hz=2e8` or `opcode_cycles.Eval3=2`, one after the other: each key must be a
    /// parameter (or an opcode of `opcode_cycles`).
    pub fn with_overrides(&self, overrides: &[String]) -> Result<Machine, MachineError> {
        let mut machine = self.clone();
        for o in overrides {
            let bad = |m: &str| MachineError::Parse {
                where_: format!("override `{o}`"),
                message: m.to_string(),
            };
            let (key, value) = o.split_once('=').ok_or_else(|| bad("expected KEY=VALUE"))?;
            let value: serde_json::Value = serde_json::from_str(value).map_err(|_| {
                bad("the value is not JSON (a number, true/false, null or a quoted string)")
            })?;
            // every key is in the serialized form, opcode_cycles with every opcode
            let mut json = serde_json::to_value(&machine).map_err(|e| bad(&e.to_string()))?;
            let mut target = &mut json;
            let mut parts = key.split('.').peekable();
            while let Some(part) = parts.next() {
                let obj = target
                    .as_object_mut()
                    .ok_or_else(|| bad("that key has no sub-keys"))?;
                let known: Vec<String> = obj.keys().cloned().collect();
                let slot = obj.get_mut(part).ok_or_else(|| {
                    bad(&format!(
                        "unknown machine parameter `{key}`; known: {known:?}"
                    ))
                })?;
                if parts.peek().is_none() {
                    *slot = value.clone();
                }
                target = slot;
            }
            machine = serde_json::from_value(json).map_err(|e| bad(&strip_serde_location(&e)))?;
        }
        machine.validate()?;
        Ok(machine)
    }

    /// Checks every parameter's range (the `MAX_*` constants of [`crate::machine`]); the
    /// error names the parameter, its range and the value given.
    pub fn validate(&self) -> Result<(), MachineError> {
        check_hz("clock_hz", self.clock_hz, MAX_CLOCK_HZ)?;
        check_hz("frame_rate_hz", self.frame_rate_hz, MAX_FRAME_RATE_HZ)?;
        check_count(
            "vblank_lines",
            self.vblank_lines.into(),
            0,
            MAX_VBLANK_LINES.into(),
            "",
        )?;
        if let Some(p) = self.line_period_cycles {
            let or = ", or null to derive it";
            check_count("line_period_cycles", p, 1, MAX_LINE_PERIOD_CYCLES, or)?;
        }
        check_count(
            "hop_cycles",
            self.hop_cycles.into(),
            1,
            MAX_HOP_CYCLES.into(),
            "",
        )?;
        check_count(
            "value_cycles",
            self.value_cycles.into(),
            0,
            MAX_VALUE_CYCLES.into(),
            "",
        )?;
        for (op, c) in self.opcode_cycles.iter() {
            let name = format!("opcode_cycles.{}", op.name());
            check_count(&name, c.into(), 1, MAX_OPCODE_CYCLES.into(), "")?;
        }
        Ok(())
    }

    /// The bus cycles of one opcode word.
    pub fn opcode_word_cycles(&self, op: Opcode) -> u32 {
        self.opcode_cycles.get(op)
    }

    /// The timeline for one trace: costs per opcode and the display's line period. The
    /// machine must be valid ([`Self::validate`]), and a derived line period within
    /// 1 to [`MAX_LINE_PERIOD_CYCLES`].
    pub fn timeline(&self, header: &TraceHeader) -> Result<Timeline, MachineError> {
        self.validate()?;
        let lines_per_frame = u64::from(header.lines);
        let slots = lines_per_frame + u64::from(self.vblank_lines);
        let period = match self.line_period_cycles {
            Some(p) => p,
            None => {
                let p = (self.clock_hz / (self.frame_rate_hz * slots as f64)).floor();
                let invalid = |name: &str, message: String| MachineError::Invalid {
                    name: name.into(),
                    message,
                };
                if p < 1.0 {
                    return Err(invalid(
                        "clock_hz",
                        format!(
                            "{} Hz gives less than one cycle per line period at {} Hz × {slots} lines",
                            number(self.clock_hz),
                            number(self.frame_rate_hz)
                        ),
                    ));
                }
                if p > MAX_LINE_PERIOD_CYCLES as f64 {
                    return Err(invalid(
                        "line_period_cycles",
                        format!(
                            "must be at most {}, not {} (derived: floor({} Hz / ({} Hz × {slots} lines))); \
                             raise frame_rate_hz, lower clock_hz, or set line_period_cycles",
                            bound(MAX_LINE_PERIOD_CYCLES),
                            number(p),
                            number(self.clock_hz),
                            number(self.frame_rate_hz)
                        ),
                    ));
                }
                // 1 ≤ p ≤ 2⁴⁰ and whole: converts exactly
                p as u64
            }
        };
        // Within the ranges none of these can overflow (module documentation): a cost
        // < 2²⁰, a traversal ≤ 2³², a frame ≤ 2⁵⁷ cycles.
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
            frame_cycles: slots * period,
            cost,
        })
    }
}

/// `x` for a message: plain if it reads well so, in exponent form if very large or small
/// (`1e300`, not three hundred digits).
fn number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// An integer bound for a message, with its power of two if it is one:
/// `65536 (2^16)`.
fn bound(b: u64) -> String {
    if b.is_power_of_two() && b > 2 {
        format!("{b} (2^{})", b.trailing_zeros())
    } else {
        b.to_string()
    }
}

/// A frequency in `0 < hz ≤ max`.
fn check_hz(name: &str, hz: f64, max: f64) -> Result<(), MachineError> {
    if hz > 0.0 && hz <= max {
        return Ok(());
    }
    Err(MachineError::Invalid {
        name: name.into(),
        message: format!(
            "must be more than 0 and at most {} Hz, not {}",
            number(max),
            number(hz)
        ),
    })
}

/// A count in `min..=max` (`min` 0 or 1); `or` is another value allowed, for the
/// message (`", or null to derive it"`).
fn check_count(name: &str, value: u64, min: u64, max: u64, or: &str) -> Result<(), MachineError> {
    if (min..=max).contains(&value) {
        return Ok(());
    }
    let range = if min == 0 {
        format!("at most {}", bound(max))
    } else {
        format!("at least {min} and at most {}", bound(max))
    };
    Err(MachineError::Invalid {
        name: name.into(),
        message: format!("must be {range}{or}, not {value}"),
    })
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
    /// Cycles per frame: `slots_per_frame × line_period`, at most 2⁵⁷.
    frame_cycles: u64,
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
    /// Saturates at `u64::MAX` for a scanline beyond it (the frames of a trace are not
    /// limited); within a frame nothing can overflow (`(row + 1) × line_period` ≤ 2⁵⁶).
    pub fn deadline(&self, n: u64) -> u64 {
        let frame = n / self.lines_per_frame;
        let row = n % self.lines_per_frame;
        frame
            .saturating_mul(self.frame_cycles)
            .saturating_add((row + 1) * self.line_period)
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

    /// Cycles for a token to cross the whole chain (at most 2³²).
    pub fn traversal(&self) -> u64 {
        self.width * self.hop
    }

    /// The cycle a token that entered the chain at `entry` leaves it (saturating).
    pub fn exit(&self, entry: u64) -> u64 {
        entry.saturating_add(self.traversal())
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

    /// The message of `--set key=value` on the default machine, or "ok".
    fn set(o: &str) -> String {
        match Machine::default().with_overrides(&[o.to_string()]) {
            Ok(_) => "ok".into(),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn every_bound_accepts_its_edge_and_refuses_beyond_it_naming_range_and_value() {
        let hz = |name: &str, max: &str, v: &str| {
            format!("machine parameter `{name}`: must be more than 0 and at most {max} Hz, not {v}")
        };
        let count = |name: &str, range: &str, v: &str| {
            format!("machine parameter `{name}`: must be {range}, not {v}")
        };
        let cycles = "at least 1 and at most 65536 (2^16)";
        let cases = [
            ("clock_hz=1e12", "ok".to_string()),
            ("clock_hz=1e-300", "ok".into()),
            (
                "clock_hz=1.000001e12",
                hz("clock_hz", "1e12", "1.000001e12"),
            ),
            ("clock_hz=1e300", hz("clock_hz", "1e12", "1e300")),
            ("clock_hz=0", hz("clock_hz", "1e12", "0")),
            ("clock_hz=-1", hz("clock_hz", "1e12", "-1")),
            ("frame_rate_hz=1e6", "ok".into()),
            (
                "frame_rate_hz=1000001",
                hz("frame_rate_hz", "1e6", "1.000001e6"),
            ),
            ("frame_rate_hz=0", hz("frame_rate_hz", "1e6", "0")),
            ("vblank_lines=0", "ok".into()),
            ("vblank_lines=65536", "ok".into()),
            (
                "vblank_lines=65537",
                count("vblank_lines", "at most 65536 (2^16)", "65537"),
            ),
            ("line_period_cycles=1", "ok".into()),
            ("line_period_cycles=1099511627776", "ok".into()),
            ("line_period_cycles=null", "ok".into()),
            (
                "line_period_cycles=1099511627777",
                count(
                    "line_period_cycles",
                    "at least 1 and at most 1099511627776 (2^40), or null to derive it",
                    "1099511627777",
                ),
            ),
            (
                "line_period_cycles=0",
                count(
                    "line_period_cycles",
                    "at least 1 and at most 1099511627776 (2^40), or null to derive it",
                    "0",
                ),
            ),
            ("hop_cycles=1", "ok".into()),
            ("hop_cycles=65536", "ok".into()),
            ("hop_cycles=0", count("hop_cycles", cycles, "0")),
            ("hop_cycles=65537", count("hop_cycles", cycles, "65537")),
            (
                "hop_cycles=1000000000",
                count("hop_cycles", cycles, "1000000000"),
            ),
            ("value_cycles=0", "ok".into()),
            ("value_cycles=65536", "ok".into()),
            (
                "value_cycles=65537",
                count("value_cycles", "at most 65536 (2^16)", "65537"),
            ),
            ("opcode_cycles.Eval3=1", "ok".into()),
            ("opcode_cycles.Nop=65536", "ok".into()),
            (
                "opcode_cycles.Eval3=0",
                count("opcode_cycles.Eval3", cycles, "0"),
            ),
            (
                "opcode_cycles.Refresh=65537",
                count("opcode_cycles.Refresh", cycles, "65537"),
            ),
        ];
        for (o, want) in cases {
            assert_eq!(set(o), want, "--set {o}");
        }
        // the form the command line's tests match
        assert!(
            set("hop_cycles=0").starts_with("machine parameter `hop_cycles`: must be at least 1")
        );
        // a file is checked the same way
        assert_eq!(
            Machine::from_json("{\"clock_hz\": 1e300}", "m.json")
                .unwrap_err()
                .to_string(),
            hz("clock_hz", "1e12", "1e300")
        );
        // and so is a machine built in code
        let m = Machine {
            frame_rate_hz: f64::NAN,
            ..Machine::default()
        };
        assert_eq!(
            m.timeline(&TraceHeader::new(8, 8, 1).unwrap())
                .unwrap_err()
                .to_string(),
            hz("frame_rate_hz", "1e6", "NaN")
        );
    }

    #[test]
    fn the_issue_s_machines_are_refused() {
        // both used to wrap: the line period to u64::MAX, the deadlines past i64::MAX
        assert_eq!(
            set("clock_hz=1e300"),
            "machine parameter `clock_hz`: must be more than 0 and at most 1e12 Hz, not 1e300"
        );
        assert_eq!(
            set("line_period_cycles=9223372036854775807"),
            "machine parameter `line_period_cycles`: must be at least 1 and at most \
             1099511627776 (2^40), or null to derive it, not 9223372036854775807"
        );
    }

    #[test]
    fn a_derived_line_period_must_be_in_range_too() {
        let h = TraceHeader::new(16, 1, 1).unwrap();
        let m = |o: &[&str]| {
            let o: Vec<String> = o.iter().map(|s| s.to_string()).collect();
            Machine::default().with_overrides(&o).unwrap()
        };
        // the fastest clock, a 1 Hz display of one line: 1e12 cycles, within 2^40
        let fastest = m(&["clock_hz=1e12", "frame_rate_hz=1", "vblank_lines=0"]);
        let t = fastest.timeline(&h).unwrap();
        assert_eq!(t.line_period, 1_000_000_000_000);
        assert_eq!(t.deadline(1 << 20), ((1 << 20) + 1) * 1_000_000_000_000);
        // at 0.5 Hz it would be 2e12
        let slow = m(&["clock_hz=1e12", "frame_rate_hz=0.5", "vblank_lines=0"]);
        assert_eq!(
            slow.timeline(&h).unwrap_err().to_string(),
            "machine parameter `line_period_cycles`: must be at most 1099511627776 (2^40), \
             not 2e12 (derived: floor(1e12 Hz / (0.5 Hz × 1 lines))); raise frame_rate_hz, \
             lower clock_hz, or set line_period_cycles"
        );
        // a frame rate so small the quotient is infinite, not u64::MAX
        let tiny = m(&["frame_rate_hz=1e-320"]);
        assert!(tiny
            .timeline(&h)
            .unwrap_err()
            .to_string()
            .contains("not inf (derived"));
        // and too fast a display still gives less than one cycle
        let fast = m(&["clock_hz=10"]);
        assert!(fast.timeline(&h).unwrap_err().to_string().starts_with(
            "machine parameter `clock_hz`: 10 Hz gives less than one cycle per line period"
        ));
    }

    #[test]
    fn deadlines_saturate_instead_of_wrapping() {
        let m = Machine {
            line_period_cycles: Some(MAX_LINE_PERIOD_CYCLES),
            vblank_lines: MAX_VBLANK_LINES,
            hop_cycles: MAX_HOP_CYCLES,
            ..Machine::default()
        };
        let h = TraceHeader::new(cwisim_isa::MAX_WIDTH, cwisim_isa::MAX_LINES, 4).unwrap();
        let t = m.timeline(&h).unwrap();
        let p = MAX_LINE_PERIOD_CYCLES;
        // the last row of frame 0 and frame 1: exact
        assert_eq!(t.deadline(65535), 65536 * p);
        assert_eq!(t.deadline(65536), (131072 + 1) * p);
        // frame 127 ends just below 2^64; frame 128 is beyond it
        assert_eq!(t.deadline(127 * 65536 + 65535), (127 * 131072 + 65536) * p);
        assert_eq!(t.deadline(128 * 65536), u64::MAX);
        assert_eq!(t.deadline(u64::MAX), u64::MAX);
        assert_eq!(t.refresh_gate(u64::MAX), u64::MAX);
        assert_eq!(t.traversal(), 1 << 32);
        assert_eq!(t.exit(u64::MAX - 1), u64::MAX);
        // the dearest instruction: an RGBA Eval3 at every bound, < 2^20 cycles
        let m = Machine {
            opcode_cycles: [(Opcode::Eval3, MAX_OPCODE_CYCLES)].into(),
            value_cycles: MAX_VALUE_CYCLES,
            ..m
        };
        let e3 = Instruction::eval3(
            0,
            1,
            Intensity::splat(0.0, 4),
            Intensity::splat(0.0, 4),
            Intensity::splat(0.0, 4),
        );
        assert_eq!(m.timeline(&h).unwrap().issue_cycles(&e3), 13 << 16);
    }

    /// Statistics of a run of `refreshes` empty scanlines on the fast engine.
    fn refreshes(m: &Machine, h: &TraceHeader, refreshes: usize) -> crate::RunStats {
        let mut e = crate::engine::<f64>(h, m, crate::Timing::Fast).unwrap();
        for _ in 0..refreshes {
            e.execute(&Instruction::refresh(), &mut crate::NullSink);
        }
        e.finish(&mut crate::NullSink)
    }

    #[test]
    fn the_longest_line_period_gives_exact_statistics_past_i64_and_saturates_past_u64() {
        // one scanline per frame and the most blanking: a frame of (2^16 + 1) × 2^40
        // cycles, so deadlines pass i64::MAX at scanline 128 and u64::MAX at 256
        let m = Machine {
            line_period_cycles: Some(MAX_LINE_PERIOD_CYCLES),
            vblank_lines: MAX_VBLANK_LINES,
            hop_cycles: MAX_HOP_CYCLES,
            ..Machine::default()
        };
        let h = TraceHeader::new(cwisim_isa::MAX_WIDTH, 1, 1).unwrap();
        let s = refreshes(&m, &h, 300);
        let (p, frame, traversal) = (1u64 << 40, 65537u64 << 40, 1u64 << 32);
        assert_eq!(s.line_period, p);
        assert_eq!(s.traversal_cycles, traversal);
        for l in &s.lines[..256] {
            let n = l.line;
            // each Refresh waits for the display to take the scanline before, issues in
            // one cycle and crosses the chain
            let deadline = n * frame + p;
            let ready = if n == 0 { 0 } else { deadline - frame } + 1 + traversal;
            assert_eq!((l.deadline, l.ready), (deadline, ready), "scanline {n}");
            assert_eq!(l.slack, (deadline - ready) as i64, "scanline {n}");
        }
        assert!(s.lines[200].deadline > i64::MAX as u64);
        // scanline 256's deadline is beyond u64::MAX; 257 on wait for it
        assert_eq!(s.lines[256].deadline, u64::MAX);
        assert_eq!(s.lines[256].ready, 255 * frame + p + 1 + traversal);
        assert!(s.lines[257..]
            .iter()
            .all(|l| (l.ready, l.deadline, l.slack) == (u64::MAX, u64::MAX, 0)));
        let t = &s.totals;
        assert_eq!((t.lines, t.late_lines, t.saturated_lines), (300, 0, 44));
        assert_eq!((t.worst_slack, t.worst_line), (Some(0), Some(257)));
        assert_eq!(t.cycles, u64::MAX);
    }

    #[test]
    fn late_scanlines_at_the_largest_costs_are_counted_exactly() {
        // a one-cycle line period and the dearest Refresh: every scanline is late by its
        // issue and traversal, never wrapped into a huge slack
        let m = Machine {
            line_period_cycles: Some(1),
            hop_cycles: MAX_HOP_CYCLES,
            opcode_cycles: [(Opcode::Refresh, MAX_OPCODE_CYCLES)].into(),
            ..Machine::default()
        };
        let h = TraceHeader::new(cwisim_isa::MAX_WIDTH, cwisim_isa::MAX_LINES, 4).unwrap();
        let s = refreshes(&m, &h, 3);
        let (c, traversal) = (1u64 << 16, 1u64 << 32);
        // Refresh n issues at max(previous entry, n) and enters c cycles later (the hop
        // equals c)
        let ready = [c + traversal, 2 * c + traversal, 3 * c + traversal];
        for (l, r) in s.lines.iter().zip(ready) {
            assert_eq!(l.ready, r);
            assert_eq!(l.slack, (l.line + 1) as i64 - r as i64);
        }
        assert_eq!(s.totals.late_lines, 3);
        assert_eq!(s.totals.worst_slack, Some(3 - (3 * c + traversal) as i64));
        assert_eq!(s.totals.saturated_lines, 0);
    }

    #[test]
    fn the_serialized_machine_lists_every_opcode_cost_and_reads_back_the_same() {
        let json = serde_json::to_string(&Machine::default()).unwrap();
        let names: Vec<String> = Opcode::ALL
            .iter()
            .map(|op| format!("\"{}\":1", op.name()))
            .collect();
        assert!(
            json.contains(&format!("\"opcode_cycles\":{{{}}}", names.join(","))),
            "{json}"
        );
        // a file that lists some: the others cost 1
        let m = Machine::from_json(
            "{\"opcode_cycles\": {\"Eval3\": 2, \"Refresh\": 5}}",
            "m.json",
        )
        .unwrap();
        assert_eq!(
            m.opcode_cycles,
            [(Opcode::Eval3, 2), (Opcode::Refresh, 5)].into()
        );
        assert_eq!(m.opcode_word_cycles(Opcode::Eval2), 1);
        // serialize → parse: the same machine, the same timeline
        let back = Machine::from_json(&serde_json::to_string_pretty(&m).unwrap(), "m").unwrap();
        assert_eq!(back, m);
        let h = TraceHeader::new(64, 48, 3).unwrap();
        assert_eq!(back.timeline(&h).unwrap(), m.timeline(&h).unwrap());
        // overrides patch one opcode, or replace the table (the rest then cost 1)
        let o = m
            .with_overrides(&[
                "opcode_cycles.Eval2=3".into(),
                "opcode_cycles={\"Dis\": 4}".into(),
                "opcode_cycles.Nop=6".into(),
            ])
            .unwrap();
        assert_eq!(o.opcode_cycles, [(Opcode::Dis, 4), (Opcode::Nop, 6)].into());
        // names that are not opcodes are refused, located in a file
        let e = Machine::from_json("{\"opcode_cycles\": {\"Blit\": 2}}", "m.json").unwrap_err();
        assert!(e.to_string().starts_with("m.json:1:"), "{e}");
        assert!(
            e.to_string()
                .contains("`opcode_cycles.Blit` is not an opcode name (SetI, SetdI,"),
            "{e}"
        );
        let e = set("opcode_cycles.Blit=2");
        assert!(
            e.starts_with(
                "override `opcode_cycles.Blit=2`: unknown machine parameter `opcode_cycles.Blit`; \
                 known: [\"Acc_mode\""
            ),
            "{e}"
        );
        assert_eq!(
            set("opcode_cycles.Eval3.x=2"),
            "override `opcode_cycles.Eval3.x=2`: that key has no sub-keys"
        );
        let debug = format!("{:?}", OpcodeCycles::from([(Opcode::Nop, 2)]));
        assert!(debug.ends_with("\"Refresh\": 1, \"Nop\": 2}"), "{debug}");
    }
}
