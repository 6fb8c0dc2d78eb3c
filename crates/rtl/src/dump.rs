//! Reading what the testbench wrote (`verilog::testbench`): its dump file, line by line,
//! into what the array did.

use crate::error::RtlError;
use std::collections::BTreeMap;

/// How the simulation ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// The array fell idle after the last instruction, at this cycle.
    Idle(u64),
    /// The cycle limit was reached first.
    Limit(u64),
    /// The dump stops without saying (the simulator was cut short).
    Missing,
}

/// What the generated array did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Observed {
    /// Per watched processor, the cycle of each token's arrival, in order.
    pub arrivals: BTreeMap<u32, Vec<u64>>,
    /// Per processor, each `Refresh`'s cycle there and the accumulators it moved out
    /// (raw bits, per channel).
    pub outputs: BTreeMap<u32, Vec<(u64, Vec<u64>)>>,
    /// Each token leaving the chain: its cycle and its overflow events.
    pub exits: Vec<(u64, u64)>,
    /// How it ended.
    pub end: End,
}

/// Parses a dump. `what` names it in errors.
pub fn parse(text: &str, what: &str) -> Result<Observed, RtlError> {
    let mut obs = Observed {
        arrivals: BTreeMap::new(),
        outputs: BTreeMap::new(),
        exits: Vec::new(),
        end: End::Missing,
    };
    for (k, line) in text.lines().enumerate() {
        let bad = |message: &str| RtlError::Parse {
            what: what.to_string(),
            line: k + 1,
            message: format!("{message}: `{line}`"),
        };
        let mut words = line.split_whitespace();
        let tag = words.next().ok_or_else(|| bad("an empty line"))?;
        let dec = |w: Option<&str>| -> Result<u64, RtlError> {
            w.and_then(|w| w.parse::<u64>().ok())
                .ok_or_else(|| bad("expected a decimal number"))
        };
        match tag {
            "A" => {
                let p = dec(words.next())?;
                let cycle = dec(words.next())?;
                let p = u32::try_from(p).map_err(|_| bad("a processor beyond 2^32"))?;
                obs.arrivals.entry(p).or_default().push(cycle);
            }
            "O" => {
                let p = dec(words.next())?;
                let p = u32::try_from(p).map_err(|_| bad("a processor beyond 2^32"))?;
                let cycle = dec(words.next())?;
                let values = words
                    .map(|w| u64::from_str_radix(w, 16).map_err(|_| bad("expected hex values")))
                    .collect::<Result<Vec<u64>, _>>()?;
                obs.outputs.entry(p).or_default().push((cycle, values));
            }
            "X" => {
                let cycle = dec(words.next())?;
                let ovf = dec(words.next())?;
                obs.exits.push((cycle, ovf));
            }
            "E" => obs.end = End::Idle(dec(words.next())?),
            "T" => obs.end = End::Limit(dec(words.next())?),
            _ => return Err(bad("expected A, O, X, E or T")),
        }
    }
    Ok(obs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_record_is_read() {
        let o = parse("A 0 3\nO 1 7 ff 0\nX 9 2\nA 0 5\nE 12\n", "d").unwrap();
        assert_eq!(o.arrivals[&0], vec![3, 5]);
        assert_eq!(o.outputs[&1], vec![(7, vec![255, 0])]);
        assert_eq!(o.exits, vec![(9, 2)]);
        assert_eq!(o.end, End::Idle(12));
        let e = parse("A 0 3\nQ 1\n", "dump.txt").unwrap_err().to_string();
        assert_eq!(e, "dump.txt: line 2: expected A, O, X, E or T: `Q 1`");
        assert!(parse("O 1 7 zz\n", "d").is_err());
    }
}
