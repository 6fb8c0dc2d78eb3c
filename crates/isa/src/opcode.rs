//! The one declaration of the instruction set.
//!
//! Every opcode is declared once, in [`declare_opcodes!`], with its binary code, its
//! text name and its operand signature. The text, JSON Lines and binary codecs are all
//! driven by [`Opcode::operands`], so the three encodings cannot drift apart.

use std::fmt;

/// The kind of one operand, in the order it appears in every encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OperandKind {
    /// `x`: the first processor addressed, `0 <= x < width`.
    X,
    /// `dx` of a range: the number of processors `[x, x + dx)`, `x + dx <= width`.
    Count,
    /// `dx` of a periodic set: the period, `dx >= 1`.
    Period,
    /// `I`: an intensity vector (one value per channel).
    I,
    /// `dI`: a first forward difference vector.
    DI,
    /// `ddI`: a second forward difference vector.
    DDI,
}

impl OperandKind {
    /// The operand's name in the text signature and as a JSON key.
    pub const fn name(self) -> &'static str {
        match self {
            OperandKind::X => "x",
            OperandKind::Count | OperandKind::Period => "dx",
            OperandKind::I => "I",
            OperandKind::DI => "dI",
            OperandKind::DDI => "ddI",
        }
    }

    /// For the intensity operands: which of the three value slots holds it.
    pub const fn value_slot(self) -> Option<usize> {
        match self {
            OperandKind::I => Some(0),
            OperandKind::DI => Some(1),
            OperandKind::DDI => Some(2),
            _ => None,
        }
    }
}

macro_rules! declare_opcodes {
    ($( $(#[$doc:meta])* $variant:ident = $code:literal, $name:literal, [$($operand:ident),*]; )*) => {
        /// An X-processor opcode (van Rij, section 1.4).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[repr(u8)]
        pub enum Opcode {
            $( $(#[$doc])* $variant = $code, )*
        }

        impl Opcode {
            /// Every opcode, in the order of their binary codes.
            pub const ALL: &'static [Opcode] = &[$(Opcode::$variant),*];

            /// The name used in the text form, in JSON and in the report.
            pub const fn name(self) -> &'static str {
                match self { $(Opcode::$variant => $name,)* }
            }

            /// The operands, in encoding order.
            pub const fn operands(self) -> &'static [OperandKind] {
                match self { $(Opcode::$variant => &[$(OperandKind::$operand),*],)* }
            }

            /// The binary code (one byte in `.cwb`).
            pub const fn code(self) -> u8 {
                self as u8
            }

            /// The opcode with this binary code.
            pub const fn from_code(code: u8) -> Option<Opcode> {
                match code { $($code => Some(Opcode::$variant),)* _ => None }
            }

            /// The opcode with this exact (case-sensitive) name.
            pub fn from_name(name: &str) -> Option<Opcode> {
                match name { $($name => Some(Opcode::$variant),)* _ => None }
            }
        }
    };
}

declare_opcodes! {
    /// `SetI(x, I)`: preload the intensity of processor `x`.
    SetI = 0x01, "SetI", [X, I];
    /// `SetdI(x, dI)`: preload the first difference of processor `x`.
    SetdI = 0x02, "SetdI", [X, DI];
    /// `SetddI(x, ddI)`: preload the second difference of processor `x`.
    SetddI = 0x03, "SetddI", [X, DDI];
    /// `SetPI(x, dx, I)`: preload the intensity of processors `x, x+dx, x+2dx, …`.
    SetPI = 0x04, "SetPI", [X, Period, I];
    /// `SetPdI(x, dx, dI)`: preload the first difference of `x, x+dx, x+2dx, …`.
    SetPdI = 0x05, "SetPdI", [X, Period, DI];
    /// `SetPddI(x, dx, ddI)`: preload the second difference of `x, x+dx, x+2dx, …`.
    SetPddI = 0x06, "SetPddI", [X, Period, DDI];
    /// `Eval0(x, dx, I)`: set `[x, x+dx)` to `I` and lock it until `Refresh`.
    Eval0 = 0x07, "Eval0", [X, Count, I];
    /// `Eval1(x, dx, I)`: accumulate the constant `I` over `[x, x+dx)`.
    Eval1 = 0x08, "Eval1", [X, Count, I];
    /// `Eval2(x, dx, I, dI)`: accumulate a first-order forward-differenced ramp.
    Eval2 = 0x09, "Eval2", [X, Count, I, DI];
    /// `Eval3(x, dx, I, dI, ddI)`: accumulate a second-order forward-differenced curve.
    Eval3 = 0x0A, "Eval3", [X, Count, I, DI, DDI];
    /// `Dis(x, dx)`: mask `[x, x+dx)` from the next Eval command.
    Dis = 0x0B, "Dis", [X, Count];
    /// `Acc_mode()`: toggle whether negative contributions are accumulated.
    AccMode = 0x0C, "Acc_mode", [];
    /// `Refresh()`: output the scanline and reset the processors.
    Refresh = 0x0D, "Refresh", [];
    /// `Nop()`: no operation (it still occupies the instruction bus).
    Nop = 0x0E, "Nop", [];
}

impl Opcode {
    /// The number of opcodes.
    pub const COUNT: usize = Opcode::ALL.len();

    /// A dense index `0..COUNT`, for per-opcode counters.
    pub const fn index(self) -> usize {
        self as usize - 1
    }

    /// The number of intensity vectors the opcode carries (0 to 3).
    pub fn value_operands(self) -> usize {
        self.operands()
            .iter()
            .filter(|k| k.value_slot().is_some())
            .count()
    }

    /// The text signature, e.g. `Eval2 x dx I dI`.
    pub fn signature(self) -> String {
        let mut s = self.name().to_string();
        for k in self.operands() {
            s.push(' ');
            s.push_str(k.name());
        }
        s
    }

    /// The known name closest to `name` (case-insensitive match first), for error hints.
    pub fn suggest(name: &str) -> Option<Opcode> {
        let lower = name.to_ascii_lowercase();
        if let Some(op) = Opcode::ALL.iter().find(|op| {
            op.name().to_ascii_lowercase() == lower
                || op.name().replace('_', "").to_ascii_lowercase() == lower
        }) {
            return Some(*op);
        }
        Opcode::ALL
            .iter()
            .map(|op| (edit_distance(&lower, &op.name().to_ascii_lowercase()), *op))
            .filter(|(d, _)| *d <= 2)
            .min()
            .map(|(_, op)| op)
    }
}

impl fmt::Display for Opcode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_names_and_indices_are_consistent() {
        assert_eq!(Opcode::COUNT, 14);
        for (i, op) in Opcode::ALL.iter().enumerate() {
            assert_eq!(op.index(), i);
            assert_eq!(Opcode::from_code(op.code()), Some(*op));
            assert_eq!(Opcode::from_name(op.name()), Some(*op));
        }
        assert_eq!(Opcode::from_code(0), None);
        assert_eq!(Opcode::from_code(0xFF), None);
    }

    #[test]
    fn signatures_follow_the_report() {
        assert_eq!(Opcode::Eval3.signature(), "Eval3 x dx I dI ddI");
        assert_eq!(Opcode::SetPdI.signature(), "SetPdI x dx dI");
        assert_eq!(Opcode::AccMode.signature(), "Acc_mode");
        assert_eq!(Opcode::Eval2.value_operands(), 2);
    }

    #[test]
    fn suggestions_catch_case_and_typos() {
        assert_eq!(Opcode::suggest("eval2"), Some(Opcode::Eval2));
        assert_eq!(Opcode::suggest("accmode"), Some(Opcode::AccMode));
        assert_eq!(Opcode::suggest("Refrsh"), Some(Opcode::Refresh));
        assert_eq!(Opcode::suggest("Frobnicate"), None);
    }
}
