//! What one generated design is: the fixed-point format, the opcodes it implements, the
//! array's width and channels, and the timing constants of the instruction bus and the
//! display (`docs/TIMING.md`) — and every width and feature that follows from them.

use crate::error::RtlError;
use cwisim_isa::{Instruction, Opcode, OperandKind, TraceHeader, MAX_CHANNELS, MAX_WIDTH};
use cwisim_xproc::{FixedFormat, Machine, Register, Timeline, Q};
use std::collections::BTreeSet;

/// The timing constants the generated bus and display controller implement, taken from
/// the machine model's [`Timeline`] for one trace header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BusTiming {
    /// Cycles a token spends in each processor.
    pub hop: u64,
    /// Bus cycles to issue each opcode (by [`Opcode::index`]).
    pub cost: [u64; Opcode::COUNT],
    /// Cycles per display line period.
    pub line_period: u64,
    /// Scanlines per frame.
    pub lines_per_frame: u64,
    /// Line periods of vertical blanking per frame.
    pub vblank_lines: u64,
}

impl BusTiming {
    /// The constants of `machine` for arrays of `header`'s dimensions.
    pub fn new(machine: &Machine, header: &TraceHeader) -> Result<BusTiming, RtlError> {
        let t: Timeline = machine.timeline(header)?;
        let mut cost = [0; Opcode::COUNT];
        for op in Opcode::ALL {
            // the timeline's cost depends on the opcode alone (`Timeline::issue_cycles`)
            let mut probe = Instruction::refresh();
            probe.op = *op;
            cost[op.index()] = t.issue_cycles(&probe);
        }
        Ok(BusTiming {
            hop: t.hop,
            cost,
            line_period: t.line_period,
            lines_per_frame: t.lines_per_frame,
            vblank_lines: t.slots_per_frame - t.lines_per_frame,
        })
    }
}

/// The settings of one design.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Design {
    /// The registers' formats and overflow policy.
    pub format: FixedFormat,
    /// The opcodes implemented (always `Refresh` among them).
    pub opcodes: BTreeSet<Opcode>,
    /// Processors in the array.
    pub width: u32,
    /// Channels per register (1 grey, 3 RGB, at most 4).
    pub channels: usize,
    /// The bus and display timing.
    pub timing: BusTiming,
}

/// The opcodes a trace uses (with `Refresh`, which every complete trace has).
pub fn opcodes_used(trace: &[Instruction]) -> BTreeSet<Opcode> {
    let mut set: BTreeSet<Opcode> = trace.iter().map(|i| i.op).collect();
    set.insert(Opcode::Refresh);
    set
}

/// Every opcode of the table.
pub fn all_opcodes() -> BTreeSet<Opcode> {
    Opcode::ALL.iter().copied().collect()
}

/// Bits to hold every value in `0..=max` (at least 1).
pub(crate) fn bits_for(max: u64) -> u32 {
    (64 - max.leading_zeros()).max(1)
}

impl Design {
    /// A design, checked: a valid format, `Refresh` in the set, a width of
    /// `1..=MAX_WIDTH`, `1..=MAX_CHANNELS` channels.
    pub fn new(
        format: FixedFormat,
        opcodes: BTreeSet<Opcode>,
        width: u32,
        channels: usize,
        timing: BusTiming,
    ) -> Result<Design, RtlError> {
        format.validate()?;
        if !opcodes.contains(&Opcode::Refresh) {
            return Err(RtlError::Settings(
                "the opcode set has no Refresh: the array could never output a scanline".into(),
            ));
        }
        if width == 0 || width > MAX_WIDTH {
            return Err(RtlError::Settings(format!(
                "width {width}: an array has 1 to {MAX_WIDTH} processors"
            )));
        }
        if channels == 0 || channels > MAX_CHANNELS {
            return Err(RtlError::Settings(format!(
                "{channels} channels: a register holds 1 to {MAX_CHANNELS}"
            )));
        }
        Ok(Design {
            format,
            opcodes,
            width,
            channels,
            timing,
        })
    }

    /// Whether the design implements `op`.
    pub fn has(&self, op: Opcode) -> bool {
        self.opcodes.contains(&op)
    }

    fn any(&self, ops: &[Opcode]) -> bool {
        ops.iter().any(|o| self.has(*o))
    }

    /// The format of a register role.
    pub fn q(&self, reg: Register) -> Q {
        self.format.q(reg)
    }

    /// Width in bits of a register role.
    pub fn bits(&self, reg: Register) -> u32 {
        self.format.q(reg).width()
    }

    /// Whether tokens carry an address (any opcode with an `x` operand): `skip` and
    /// `count`.
    pub fn addressed(&self) -> bool {
        self.opcodes
            .iter()
            .any(|op| op.operands().contains(&OperandKind::X))
    }

    /// The value fields a token carries, in order, each with its bits per channel:
    /// `("v", …)`, `("d", …)`, `("dd", …)` for the opcodes that carry them.
    pub fn value_fields(&self) -> Vec<(&'static str, u32)> {
        [
            (self.carries_v(), "v", self.v_bits()),
            (self.carries_d(), "d", self.bits(Register::DI)),
            (self.carries_dd(), "dd", self.bits(Register::DDI)),
        ]
        .into_iter()
        .filter_map(|(on, name, bits)| on.then_some((name, bits)))
        .collect()
    }

    /// Whether tokens carry a value operand `I` (any opcode with an `I` operand).
    pub fn carries_v(&self) -> bool {
        self.opcodes
            .iter()
            .any(|op| op.operands().contains(&OperandKind::I))
    }

    /// Whether tokens carry a first difference (an opcode with a `dI` operand).
    pub fn carries_d(&self) -> bool {
        self.opcodes
            .iter()
            .any(|op| op.operands().contains(&OperandKind::DI))
    }

    /// Whether tokens carry a second difference (an opcode with a `ddI` operand).
    pub fn carries_dd(&self) -> bool {
        self.opcodes
            .iter()
            .any(|op| op.operands().contains(&OperandKind::DDI))
    }

    /// Bits of the token's `v` field: the `I` format, or the accumulator's if wider and
    /// `Eval0` (whose `I` sets the accumulator) is implemented.
    pub fn v_bits(&self) -> u32 {
        let i = self.bits(Register::I);
        if self.has(Opcode::Eval0) {
            i.max(self.bits(Register::Acc))
        } else {
            i
        }
    }

    /// Whether the processor has the preload register of value slot `slot` (a `Set` or
    /// `SetP` of it is implemented and an Eval that reads it).
    pub fn preload(&self, slot: usize) -> bool {
        let set = [
            [Opcode::SetI, Opcode::SetPI],
            [Opcode::SetdI, Opcode::SetPdI],
            [Opcode::SetddI, Opcode::SetPddI],
        ][slot];
        self.any(&set)
    }

    /// Whether the `Acc_mode` flag exists (else negative contributions are always dropped).
    pub fn acc_mode(&self) -> bool {
        self.has(Opcode::AccMode)
    }

    /// Whether the `Eval0` lock exists.
    pub fn lock(&self) -> bool {
        self.has(Opcode::Eval0)
    }

    /// Whether the `Dis` mask exists.
    pub fn mask(&self) -> bool {
        self.has(Opcode::Dis)
    }

    /// The highest order of the Eval1–3 implemented (0: none).
    pub fn order(&self) -> usize {
        [Opcode::Eval3, Opcode::Eval2, Opcode::Eval1]
            .iter()
            .position(|o| self.has(*o))
            .map_or(0, |k| 3 - k)
    }

    /// Bits of the `skip` field (the processors left before the token's first one).
    pub fn skip_bits(&self) -> u32 {
        bits_for(u64::from(self.width) - 1)
    }

    /// Bits of the `count` field (a range's processors left, or a period).
    pub fn count_bits(&self) -> u32 {
        bits_for(u64::from(self.width))
    }

    /// Bits of the opcode field: enough for the largest binary code of the table.
    pub fn op_bits(&self) -> u32 {
        bits_for(
            Opcode::ALL
                .iter()
                .map(|o| u64::from(o.code()))
                .max()
                .unwrap_or(1),
        )
    }

    /// The most overflow events one token can have in one processor: per channel the
    /// accumulator, `v` and `d` adders of the highest Eval.
    pub fn events_per_visit(&self) -> u64 {
        let adders = match self.order() {
            0 => 0,
            o => o as u64,
        };
        adders * self.channels as u64
    }

    /// The largest issue cost of an implemented opcode.
    pub fn max_cost(&self) -> u64 {
        self.opcodes
            .iter()
            .map(|o| self.timing.cost[o.index()])
            .max()
            .unwrap_or(1)
    }

    /// The settings as one line, for headers and reports.
    pub fn summary(&self) -> String {
        let ops: Vec<&str> = self.opcodes.iter().map(|o| o.name()).collect();
        format!(
            "{}; width {}; {} channel(s); opcodes {}; hop {} cycle(s), line period {} cycles, {} lines + {} blank per frame",
            self.format,
            self.width,
            self.channels,
            ops.join(" "),
            self.timing.hop,
            self.timing.line_period,
            self.timing.lines_per_frame,
            self.timing.vblank_lines
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_xproc::Numeric;

    pub(crate) fn format(s: &str) -> FixedFormat {
        match s.parse::<Numeric>().unwrap() {
            Numeric::Fixed(f) => f,
            _ => panic!("not fixed"),
        }
    }

    fn timing() -> BusTiming {
        BusTiming::new(&Machine::default(), &TraceHeader::new(16, 4, 1).unwrap()).unwrap()
    }

    #[test]
    fn widths_follow_the_format_and_the_array() {
        let f = format("fixed:I=4.8,dI=2.12,ddI=1.16,acc=6.10");
        let d = Design::new(f, all_opcodes(), 16, 1, timing()).unwrap();
        assert_eq!(d.v_bits(), 16);
        assert_eq!(d.skip_bits(), 4);
        assert_eq!(d.count_bits(), 5);
        assert_eq!(d.op_bits(), 4);
        assert_eq!(d.order(), 3);
        assert_eq!(d.events_per_visit(), 3);
        let mut ops = BTreeSet::from([Opcode::Eval1, Opcode::Refresh]);
        let d = Design::new(f, ops.clone(), 1, 3, timing()).unwrap();
        assert_eq!(d.v_bits(), 12);
        assert_eq!(d.skip_bits(), 1);
        assert!(!d.carries_d() && !d.preload(0) && !d.lock());
        ops.remove(&Opcode::Refresh);
        assert!(Design::new(f, ops, 4, 1, timing()).is_err());
        assert!(Design::new(f, all_opcodes(), 0, 1, timing()).is_err());
        assert!(Design::new(f, all_opcodes(), 4, 5, timing()).is_err());
    }

    #[test]
    fn the_bus_costs_are_the_machine_models() {
        let t = timing();
        assert_eq!(t.cost[Opcode::Eval3.index()], 4);
        assert_eq!(t.cost[Opcode::Refresh.index()], 1);
        assert_eq!(t.hop, 1);
    }
}
