//! The budgets a command works within: the memory it may take for what grows with its
//! input (images, per-scanline records, waveforms), the bytes it may write to one output,
//! and the threads it may start. Sizes are checked against them **before** allocating or
//! writing, and a refusal says what the work would need and how to raise the budget.
//!
//! The user sets them with environment variables, the same for every command:
//!
//! | variable | default | what |
//! | --- | --- | --- |
//! | `CWISIM_MAX_MEMORY` | 4 GiB | memory for what grows with the input |
//! | `CWISIM_MAX_OUTPUT` | 4 GiB | bytes of one output file (`--stats-json`, a VCD, …) |
//!
//! A size is a number of bytes with an optional unit: `512M`, `8G`, `8GiB`, `1.5G`,
//! `1e9` (`K`, `M`, `G`, `T` are powers of 1024; a `B` or `iB` after them is allowed).
//!
//! ```
//! use cwisim_scene::budget::{parse_size, Budget};
//! assert_eq!(parse_size("512M"), Ok(512 << 20));
//! assert_eq!(parse_size("1e3"), Ok(1000));
//! let b = Budget { memory_bytes: 1 << 20, output_bytes: 1 << 20 };
//! let e = b.check_memory("the image", 2 << 20).unwrap_err();
//! assert!(e.to_string().contains("CWISIM_MAX_MEMORY"));
//! ```

use std::fmt;
use std::sync::OnceLock;

/// The environment variable of the memory budget.
pub const MEMORY_VAR: &str = "CWISIM_MAX_MEMORY";
/// The environment variable of the output budget.
pub const OUTPUT_VAR: &str = "CWISIM_MAX_OUTPUT";
/// The default memory budget: 4 GiB, what a laptop can give one command.
pub const DEFAULT_MEMORY_BYTES: u64 = 4 << 30;
/// The default output budget: 4 GiB per output file.
pub const DEFAULT_OUTPUT_BYTES: u64 = 4 << 30;
/// Threads per core a command may start at most ([`max_threads`]): enough to
/// oversubscribe for a study of scaling, far from what exhausts a machine's memory (a
/// thread's stack alone is 2 MiB).
pub const THREADS_PER_CORE: usize = 8;

/// The budgets of one command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Memory for what grows with the input, in bytes.
    pub memory_bytes: u64,
    /// Bytes of one output file.
    pub output_bytes: u64,
}

impl Default for Budget {
    fn default() -> Self {
        Budget {
            memory_bytes: DEFAULT_MEMORY_BYTES,
            output_bytes: DEFAULT_OUTPUT_BYTES,
        }
    }
}

/// A size over a budget, or a budget that cannot be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BudgetError {
    /// The work would need more memory than the budget.
    #[error(
        "{what} needs {} of memory, over the budget of {} (raise it with {MEMORY_VAR}=SIZE, e.g. {MEMORY_VAR}=16G)",
        human(*needed),
        human(*budget)
    )]
    Memory {
        /// What would be allocated.
        what: String,
        /// How much.
        needed: u64,
        /// The budget.
        budget: u64,
    },
    /// An output would be larger than the budget.
    #[error(
        "{what} would be larger than {} (raise the output budget with {OUTPUT_VAR}=SIZE)",
        human(*budget)
    )]
    Output {
        /// The output.
        what: String,
        /// The budget.
        budget: u64,
    },
    /// An environment variable that is not a size.
    #[error("{var}={value:?}: {message}")]
    Variable {
        /// The variable.
        var: &'static str,
        /// Its value.
        value: String,
        /// What is wrong.
        message: String,
    },
}

impl Budget {
    /// The budgets from the environment ([`MEMORY_VAR`], [`OUTPUT_VAR`]); the defaults
    /// where a variable is not set; an error naming the variable where it is not a size.
    pub fn from_env() -> Result<Budget, BudgetError> {
        let read = |var: &'static str, default: u64| match std::env::var(var) {
            Err(_) => Ok(default),
            Ok(value) => parse_size(&value).map_err(|message| BudgetError::Variable {
                var,
                value,
                message,
            }),
        };
        Ok(Budget {
            memory_bytes: read(MEMORY_VAR, DEFAULT_MEMORY_BYTES)?,
            output_bytes: read(OUTPUT_VAR, DEFAULT_OUTPUT_BYTES)?,
        })
    }

    /// The process's budgets: [`Budget::from_env`] read once, the defaults if it fails
    /// (the CLI reports a bad variable with [`Budget::from_env`] before any work).
    pub fn current() -> Budget {
        static CURRENT: OnceLock<Budget> = OnceLock::new();
        *CURRENT.get_or_init(|| Budget::from_env().unwrap_or_default())
    }

    /// `Ok` when `bytes` of memory for `what` fit the memory budget.
    pub fn check_memory(&self, what: &str, bytes: u64) -> Result<(), BudgetError> {
        if bytes <= self.memory_bytes {
            Ok(())
        } else {
            Err(BudgetError::Memory {
                what: what.to_string(),
                needed: bytes,
                budget: self.memory_bytes,
            })
        }
    }

    /// `Ok` when `bytes` written to the output `what` fit the output budget.
    pub fn check_output(&self, what: &str, bytes: u64) -> Result<(), BudgetError> {
        if bytes <= self.output_bytes {
            Ok(())
        } else {
            Err(BudgetError::Output {
                what: what.to_string(),
                budget: self.output_bytes,
            })
        }
    }
}

/// This machine's cores (1 if it cannot tell).
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The thread count `--threads N` stands for: `N`, or one per core for 0 (its meaning in
/// every command and library call that takes a thread count).
pub fn resolve_threads(threads: usize) -> usize {
    match threads {
        0 => cores(),
        n => n,
    }
}

/// The most threads a command may start on this machine: [`THREADS_PER_CORE`] × its
/// cores.
pub fn max_threads() -> usize {
    THREADS_PER_CORE * cores()
}

/// `threads` if a command may start that many ([`max_threads`]; 0 means one per core),
/// else a message for the flag that asked.
pub fn check_threads(threads: usize) -> Result<usize, String> {
    let max = max_threads();
    if threads <= max {
        Ok(threads)
    } else {
        Err(format!(
            "--threads {threads}: at most {max} ({THREADS_PER_CORE} per core of this machine's {}); 0 means one per core",
            max / THREADS_PER_CORE
        ))
    }
}

/// Reads a size: a number of bytes (`4096`, `1e9`) with an optional unit `K`, `M`, `G`,
/// `T` (powers of 1024, optionally followed by `B` or `iB`; case-insensitive).
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let scale: u64 = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "k" | "kb" | "kib" => 1 << 10,
        "m" | "mb" | "mib" => 1 << 20,
        "g" | "gb" | "gib" => 1 << 30,
        "t" | "tb" | "tib" => 1 << 40,
        other => {
            return Err(format!(
                "unknown unit `{other}`; expected a number of bytes with K, M, G or T (e.g. 8G)"
            ))
        }
    };
    let value: f64 = number.trim().parse().map_err(|_| {
        format!("expected a number of bytes with an optional unit (e.g. 8G), not `{t}`")
    })?;
    let bytes = value * scale as f64;
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("`{t}` is not a size from 1 byte to 16 EiB"));
    }
    Ok(bytes as u64)
}

/// Bytes for a person: `512 B`, `3.7 GiB`.
pub fn human(bytes: u64) -> HumanBytes {
    HumanBytes(bytes)
}

/// A byte count shown with a binary unit ([`human`]).
#[derive(Clone, Copy, Debug)]
pub struct HumanBytes(pub u64);

impl fmt::Display for HumanBytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
        if self.0 < 1024 {
            return write!(f, "{} B", self.0);
        }
        let mut v = self.0 as f64 / 1024.0;
        let mut unit = 0;
        while v >= 1024.0 && unit + 1 < UNITS.len() {
            v /= 1024.0;
            unit += 1;
        }
        write!(f, "{v:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_units_and_refuse_nonsense() {
        assert_eq!(parse_size("4096"), Ok(4096));
        assert_eq!(parse_size("8G"), Ok(8 << 30));
        assert_eq!(parse_size("8GiB"), Ok(8 << 30));
        assert_eq!(parse_size("8gb"), Ok(8 << 30));
        assert_eq!(parse_size(" 1.5K "), Ok(1536));
        assert_eq!(parse_size("1e9"), Ok(1_000_000_000));
        assert_eq!(parse_size("2T"), Ok(2 << 40));
        for bad in [
            "", "G", "-1G", "0", "0.5", "8X", "1e30", "inf", "nan", "8 G B",
        ] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn refusals_say_what_is_needed_and_how_to_raise_the_budget() {
        let b = Budget {
            memory_bytes: 1 << 30,
            output_bytes: 100,
        };
        assert!(b.check_memory("x", 1 << 30).is_ok());
        let e = b.check_memory("the image (65536 × 65536 × 4 values)", 128 << 30);
        assert_eq!(
            e.unwrap_err().to_string(),
            "the image (65536 × 65536 × 4 values) needs 128.0 GiB of memory, over the budget \
of 1.0 GiB (raise it with CWISIM_MAX_MEMORY=SIZE, e.g. CWISIM_MAX_MEMORY=16G)"
        );
        assert!(b.check_output("o", 100).is_ok());
        assert_eq!(
            b.check_output("s.json", 101).unwrap_err().to_string(),
            "s.json would be larger than 100 B (raise the output budget with CWISIM_MAX_OUTPUT=SIZE)"
        );
    }

    #[test]
    fn threads_are_capped_at_a_multiple_of_the_cores() {
        let max = max_threads();
        assert!(max >= THREADS_PER_CORE);
        assert_eq!(check_threads(0), Ok(0));
        assert_eq!(check_threads(max), Ok(max));
        let e = check_threads(1_000_000).unwrap_err();
        assert!(e.starts_with("--threads 1000000: at most"), "{e}");
    }

    #[test]
    fn human_bytes() {
        assert_eq!(human(0).to_string(), "0 B");
        assert_eq!(human(1023).to_string(), "1023 B");
        assert_eq!(human(1536).to_string(), "1.5 KiB");
        assert_eq!(human(4 << 30).to_string(), "4.0 GiB");
    }
}
