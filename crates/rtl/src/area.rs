//! Area: Yosys's generic synthesis (`synth -flatten`, to its internal gate library) of
//! one X-processor, its cell statistics, and an estimate in NAND2 equivalents.
//!
//! The estimate maps each generic cell to the area of the matching cell of the Nangate
//! 45 nm open cell library (drive X1), divided by NAND2_X1's 0.798 µm² — [`nand2_weight`]
//! has the table. A flip-flop with an enable counts a 2:1 multiplexer more, one with a
//! synchronous reset an AND2 more. It is an estimate of the logic before technology
//! mapping and optimization for a real library, not a layout: good for comparing designs,
//! not for a chip's size.

use crate::design::Design;
use crate::error::RtlError;
use crate::tools::run;
use crate::verilog::{self, PROCESSOR_MODULE};
use std::collections::BTreeMap;
use std::path::Path;

/// Cell statistics of one synthesized module.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Area {
    /// Cells by Yosys type (`$_AND_`, `$_DFF_P_`, …).
    pub cells: BTreeMap<String, u64>,
    /// Every cell.
    pub total: u64,
    /// The flip-flops among them.
    pub flip_flops: u64,
    /// The rest: logic gates.
    pub logic: u64,
    /// The NAND2-equivalent estimate.
    pub nand2: f64,
}

/// The NAND2 equivalents of one generic cell type; `None` for a type the table does not
/// know (an error: nothing is left out silently).
pub fn nand2_weight(cell: &str) -> Option<f64> {
    // Nangate 45 nm X1 areas (µm²) / NAND2_X1 (0.798)
    const INV: f64 = 0.532 / 0.798;
    const AND2: f64 = 1.064 / 0.798;
    const XOR2: f64 = 1.596 / 0.798;
    const MUX2: f64 = 1.862 / 0.798;
    const AOI22: f64 = 1.330 / 0.798;
    const DFF: f64 = 4.522 / 0.798;
    let w = match cell {
        "$_NOT_" => INV,
        "$_BUF_" => INV * 1.5,
        "$_NAND_" | "$_NOR_" => 1.0,
        "$_AND_" | "$_OR_" | "$_ANDNOT_" | "$_ORNOT_" | "$_AOI3_" | "$_OAI3_" => AND2,
        "$_XOR_" | "$_XNOR_" => XOR2,
        "$_MUX_" | "$_NMUX_" => MUX2,
        "$_AOI4_" | "$_OAI4_" => AOI22,
        ff if is_flip_flop(ff) => {
            let body = ff.trim_start_matches("$_");
            let enable =
                body.starts_with("DFFE") || body.starts_with("SDFFE") || body.starts_with("SDFFCE");
            let reset = body.starts_with("SDFF");
            DFF + if enable { MUX2 } else { 0.0 } + if reset { AND2 } else { 0.0 }
        }
        _ => return None,
    };
    Some(w)
}

/// Whether a generic cell type is a flip-flop (synchronous: the design has no
/// asynchronous reset).
pub fn is_flip_flop(cell: &str) -> bool {
    ["$_DFF_", "$_DFFE_", "$_SDFF_", "$_SDFFE_", "$_SDFFCE_"]
        .iter()
        .any(|p| cell.starts_with(p))
}

/// Reads the cell counts of Yosys's `stat` output.
pub fn parse_stat(text: &str) -> Result<Area, RtlError> {
    let mut area = Area::default();
    let mut total = None;
    for (k, line) in text.lines().enumerate() {
        let t = line.trim();
        let bad = |message: String| RtlError::Parse {
            what: "yosys stat".into(),
            line: k + 1,
            message,
        };
        if let Some(rest) = t.strip_prefix("Number of cells:") {
            total = Some(
                rest.trim()
                    .parse::<u64>()
                    .map_err(|_| bad(format!("a cell count: `{t}`")))?,
            );
            area.cells.clear();
            continue;
        }
        if t.starts_with("$_") {
            let mut words = t.split_whitespace();
            let (Some(name), Some(count)) = (words.next(), words.next()) else {
                return Err(bad(format!("a cell type and count: `{t}`")));
            };
            let count: u64 = count
                .parse()
                .map_err(|_| bad(format!("a cell count: `{t}`")))?;
            let weight = nand2_weight(name).ok_or_else(|| {
                bad(format!(
                    "cell type {name} has no NAND2 weight (crates/rtl/src/area.rs)"
                ))
            })?;
            *area.cells.entry(name.to_string()).or_default() += count;
            area.nand2 += weight * count as f64;
        }
    }
    let total = total.ok_or_else(|| RtlError::Parse {
        what: "yosys stat".into(),
        line: 0,
        message: "no `Number of cells:` line".into(),
    })?;
    let counted: u64 = area.cells.values().sum();
    if counted != total {
        return Err(RtlError::Parse {
            what: "yosys stat".into(),
            line: 0,
            message: format!("{total} cells, but the types listed add up to {counted}"),
        });
    }
    area.total = total;
    area.flip_flops = area
        .cells
        .iter()
        .filter(|(n, _)| is_flip_flop(n))
        .map(|(_, c)| c)
        .sum();
    area.logic = total - area.flip_flops;
    // the sum of the weights in a fixed order, so the figure is the same every run
    area.nand2 = area
        .cells
        .iter()
        .map(|(n, c)| nand2_weight(n).unwrap_or(0.0) * *c as f64)
        .sum();
    Ok(area)
}

/// The statistics file [`script`] writes.
pub const STAT_FILE: &str = "stat.txt";

/// The Yosys script that synthesizes module `top` of `file` and writes its statistics
/// to [`STAT_FILE`].
pub fn script(file: &str, top: &str) -> String {
    format!("read_verilog {file}; synth -flatten -top {top}; tee -q -o {STAT_FILE} stat")
}

/// Synthesizes module `top` of the Verilog file `file` in directory `dir` (`yosys -q -p`
/// [`script`]) and reads its statistics.
pub fn synthesize_module(dir: &Path, file: &str, top: &str) -> Result<Area, RtlError> {
    run("yosys", &["-q", "-p", &script(file, top)], dir)?;
    let stat = dir.join(STAT_FILE);
    let text = std::fs::read_to_string(&stat).map_err(|source| RtlError::NoOutput {
        tool: "yosys".into(),
        path: stat.clone(),
        source,
    })?;
    parse_stat(&text)
}

/// Synthesizes one processor of design `d` in Yosys, in directory `dir`.
pub fn synthesize(d: &Design, dir: &Path) -> Result<Area, RtlError> {
    let path = dir.join("design.v");
    std::fs::write(&path, verilog::design(d)).map_err(|e| RtlError::io(&path, e))?;
    synthesize_module(dir, "design.v", PROCESSOR_MODULE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_output_is_read_and_weighed() {
        let text = "\n=== cwisim_xproc ===\n\n   Number of wires:                 10\n   Number of cells:                  6\n     $_AND_                          2\n     $_NOT_                          1\n     $_SDFFE_PP0P_                   2\n     $_DFF_P_                        1\n";
        let a = parse_stat(text).unwrap();
        assert_eq!(a.total, 6);
        assert_eq!(a.flip_flops, 3);
        assert_eq!(a.logic, 3);
        let want = 2.0 * 1.064 / 0.798
            + 0.532 / 0.798
            + 2.0 * (4.522 + 1.862 + 1.064) / 0.798
            + 4.522 / 0.798;
        assert!((a.nand2 - want).abs() < 1e-9, "{} {want}", a.nand2);
        assert!(parse_stat("Number of cells: 2\n $_FOO_ 2\n").is_err());
        assert!(parse_stat("Number of cells: 3\n $_AND_ 2\n").is_err());
        assert!(parse_stat("nothing\n").is_err());
    }
}
