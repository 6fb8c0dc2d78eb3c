//! Reading the tools' reports: Yosys's `stat` of the hierarchy `synth_ice40 -noflatten`
//! keeps (the shell's own cells apart from the array's), nextpnr-ice40's device
//! utilisation and its timing analysis ("Max frequency for clock …").

use crate::error::RtlError;
use std::collections::BTreeMap;

/// iCE40 cells of one module (or a whole design) after `synth_ice40`, by kind.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Cells {
    /// Cells by type (`SB_LUT4`, `SB_DFFE`, …; instances of other modules excluded).
    pub by_type: BTreeMap<String, u64>,
}

impl Cells {
    fn sum(&self, pred: impl Fn(&str) -> bool) -> u64 {
        self.by_type
            .iter()
            .filter(|(t, _)| pred(t))
            .map(|(_, c)| c)
            .sum()
    }
    /// 4-input look-up tables.
    pub fn luts(&self) -> u64 {
        self.sum(|t| t == "SB_LUT4")
    }
    /// Flip-flops (every `SB_DFF*`).
    pub fn flip_flops(&self) -> u64 {
        self.sum(|t| t.starts_with("SB_DFF"))
    }
    /// Carry cells (the adders' chains).
    pub fn carries(&self) -> u64 {
        self.sum(|t| t == "SB_CARRY")
    }
    /// RAM blocks.
    pub fn ram(&self) -> u64 {
        self.sum(|t| t.starts_with("SB_RAM"))
    }
    /// A lower bound of the logic cells they take: each cell holds one LUT and one
    /// flip-flop (and the carry beside the LUT).
    pub fn cell_estimate(&self) -> u64 {
        self.luts().max(self.flip_flops())
    }
    /// `self - other`, type by type (saturating).
    pub fn minus(&self, other: &Cells) -> Cells {
        let mut by_type = self.by_type.clone();
        for (t, c) in &other.by_type {
            if let Some(v) = by_type.get_mut(t) {
                *v = v.saturating_sub(*c);
            }
        }
        Cells { by_type }
    }
}

/// The per-module statistics of Yosys's `stat` on a hierarchical design, and the
/// totals of its `design hierarchy` section: module name → its own primitive cells.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Hierarchy {
    /// Each module's own primitive cells (`SB_*`).
    pub modules: BTreeMap<String, Cells>,
    /// Each module's instances of other modules: module → (submodule → count).
    pub instances: BTreeMap<String, BTreeMap<String, u64>>,
    /// The whole design's primitive cells, every instance counted.
    pub total: Cells,
}

impl Hierarchy {
    /// The primitive cells of one instance of `module`, its submodules' included.
    pub fn with_submodules(&self, module: &str) -> Cells {
        let mut out = self.modules.get(module).cloned().unwrap_or_default();
        if let Some(subs) = self.instances.get(module) {
            for (sub, n) in subs {
                if sub == module || !self.modules.contains_key(sub) {
                    continue;
                }
                for (t, c) in self.with_submodules(sub).by_type {
                    *out.by_type.entry(t).or_default() += c * n;
                }
            }
        }
        out
    }
}

/// Reads Yosys's `stat` output (after `synth_ice40 -noflatten`).
pub fn parse_stat(text: &str) -> Result<Hierarchy, RtlError> {
    let mut h = Hierarchy::default();
    let mut current: Option<String> = None;
    let mut in_total = false;
    let mut saw_total = false;
    for (k, line) in text.lines().enumerate() {
        let t = line.trim();
        if let Some(name) = t.strip_prefix("=== ").and_then(|r| r.strip_suffix(" ===")) {
            in_total = name == "design hierarchy";
            saw_total |= in_total;
            current = (!in_total).then(|| name.to_string());
            if let Some(c) = &current {
                h.modules.entry(c.clone()).or_default();
            }
            continue;
        }
        if !t.starts_with("SB_") {
            // an instance of another module: `name   count`
            if let (Some(c), false) = (&current, t.contains(':')) {
                let mut words = t.split_whitespace();
                if let (Some(name), Some(Ok(n)), None) = (
                    words.next(),
                    words.next().map(str::parse::<u64>),
                    words.next(),
                ) {
                    *h.instances
                        .entry(c.clone())
                        .or_default()
                        .entry(name.to_string())
                        .or_default() += n;
                }
            }
            continue;
        }
        let mut words = t.split_whitespace();
        let (Some(ty), Some(count)) = (words.next(), words.next()) else {
            continue;
        };
        let count: u64 = count.parse().map_err(|_| RtlError::Parse {
            what: "yosys stat".into(),
            line: k + 1,
            message: format!("a cell count: `{t}`"),
        })?;
        let target = if in_total {
            &mut h.total
        } else if let Some(c) = &current {
            h.modules.entry(c.clone()).or_default()
        } else {
            continue;
        };
        *target.by_type.entry(ty.to_string()).or_default() += count;
    }
    if h.modules.is_empty() {
        return Err(RtlError::Parse {
            what: "yosys stat".into(),
            line: 0,
            message: "no `=== module ===` section".into(),
        });
    }
    if !saw_total {
        // one module: it is the whole design
        h.total = h.modules.values().next().cloned().unwrap_or_default();
    }
    Ok(h)
}

/// What nextpnr-ice40 printed: the device's use and the clock it reached.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pnr {
    /// Resource → (used, available), from "Device utilisation".
    pub utilisation: BTreeMap<String, (u64, u64)>,
    /// The maximum frequency of the clock in MHz, from the last timing analysis (after
    /// routing); `None` when only packed.
    pub fmax_mhz: Option<f64>,
}

impl Pnr {
    /// Used and available of one resource (`ICESTORM_LC`), or a parse error.
    pub fn used(&self, what: &str) -> Result<(u64, u64), RtlError> {
        self.utilisation
            .get(what)
            .copied()
            .ok_or_else(|| RtlError::Parse {
                what: "nextpnr-ice40's report".into(),
                line: 0,
                message: format!("no `{what}:` line in its device utilisation"),
            })
    }
}

/// Reads nextpnr-ice40's log: `Info: \t ICESTORM_LC:   19/ 5280   0%` lines and
/// `Info: Max frequency for clock 'clk': 144.68 MHz (PASS at 1.00 MHz)`.
pub fn parse_nextpnr(text: &str) -> Result<Pnr, RtlError> {
    let mut p = Pnr::default();
    for (k, line) in text.lines().enumerate() {
        let t = line.trim_start_matches("Info:").trim();
        let bad = |message: String| RtlError::Parse {
            what: "nextpnr-ice40's log".into(),
            line: k + 1,
            message,
        };
        if let Some(rest) = t.strip_prefix("Max frequency for clock") {
            let after = rest
                .rsplit_once("':")
                .map(|(_, a)| a)
                .ok_or_else(|| bad(format!("a clock and frequency: `{t}`")))?;
            let mhz = after
                .split_whitespace()
                .next()
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| bad(format!("a frequency in MHz: `{t}`")))?;
            p.fmax_mhz = Some(mhz);
            continue;
        }
        let Some((name, rest)) = t.split_once(':') else {
            continue;
        };
        let name = name.trim();
        let plain = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_');
        if !plain {
            continue;
        }
        let Some((used, avail)) = rest.split_once('/') else {
            continue;
        };
        let avail = avail.split_whitespace().next().unwrap_or("");
        if let (Ok(u), Ok(a)) = (used.trim().parse::<u64>(), avail.parse::<u64>()) {
            p.utilisation.insert(name.to_string(), (u, a));
        }
    }
    if p.utilisation.is_empty() {
        return Err(RtlError::Parse {
            what: "nextpnr-ice40's log".into(),
            line: 0,
            message: "no device utilisation".into(),
        });
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yosys_hierarchy_is_read_module_by_module() {
        let text = "=== cwisim_fpga ===\n   Number of cells: 5\n     SB_DFF 2\n     SB_LUT4 3\n     cwisim_array 1\n\n=== cwisim_xproc ===\n     SB_CARRY 4\n     SB_LUT4 10\n\n=== design hierarchy ===\n     SB_CARRY 8\n     SB_DFF 2\n     SB_LUT4 23\n";
        let h = parse_stat(text).unwrap();
        assert_eq!(h.modules["cwisim_fpga"].luts(), 3);
        assert_eq!(h.modules["cwisim_fpga"].flip_flops(), 2);
        assert_eq!(h.modules["cwisim_xproc"].carries(), 4);
        assert_eq!(h.total.luts(), 23);
        assert_eq!(h.total.minus(&h.modules["cwisim_fpga"]).luts(), 20);
        // the processor with its adders
        let text =
            "=== add ===\n     SB_CARRY 7\n\n=== cwisim_xproc ===\n     SB_LUT4 10\n     add 2\n";
        let h = parse_stat(text).unwrap();
        assert_eq!(h.with_submodules("cwisim_xproc").carries(), 14);
        assert_eq!(h.with_submodules("cwisim_xproc").luts(), 10);
        assert!(parse_stat("nothing").is_err());
        assert!(parse_stat("=== a ===\n SB_LUT4 x\n").is_err());
    }

    #[test]
    fn nextpnr_log_gives_cells_and_the_last_fmax() {
        let text = "Info: Device utilisation:\nInfo: \t         ICESTORM_LC:    19/ 5280     0%\nInfo: \t        ICESTORM_RAM:     0/   30     0%\nInfo: Max frequency for clock 'clk$SB_IO_IN_$glb_clk': 100.00 MHz (PASS at 1.00 MHz)\nInfo: Max frequency for clock 'clk$SB_IO_IN_$glb_clk': 144.68 MHz (PASS at 1.00 MHz)\n";
        let p = parse_nextpnr(text).unwrap();
        assert_eq!(p.used("ICESTORM_LC").unwrap(), (19, 5280));
        assert_eq!(p.used("ICESTORM_RAM").unwrap(), (0, 30));
        assert_eq!(p.fmax_mhz, Some(144.68));
        assert!(p.used("SB_IO").is_err());
        assert!(parse_nextpnr("Info: nothing\n").is_err());
        assert!(parse_nextpnr("Info: Max frequency for clock 'c': fast\n").is_err());
    }
}
