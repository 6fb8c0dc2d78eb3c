//! The devices: a table ([`TABLE`], `devices.txt`), not code.

use crate::error::RtlError;

/// The table of devices: name, nextpnr-ice40's device flag, package, logic cells, RAM
/// blocks, the package's user I/O.
pub const TABLE: &str = include_str!("devices.txt");

/// One FPGA with its package.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Device {
    /// Its name on the command line (`ice40-hx8k`).
    pub name: String,
    /// nextpnr-ice40's device flag, less its `--` (`hx8k`).
    pub flag: String,
    /// The package (`ct256`).
    pub package: String,
    /// Logic cells (ICESTORM_LC: a 4-input LUT, a flip-flop and a carry each).
    pub cells: u64,
    /// 4-kbit RAM blocks.
    pub ram: u64,
    /// The package's user I/O pins.
    pub io: u64,
}

/// Every device of the table, in its order.
pub fn devices() -> Vec<Device> {
    parse(TABLE).expect("devices.txt is checked by a test")
}

/// The names of the devices, for messages.
pub fn names() -> Vec<String> {
    devices().into_iter().map(|d| d.name).collect()
}

/// The device called `name`, or [`RtlError::UnknownDevice`] listing the known ones.
pub fn device(name: &str) -> Result<Device, RtlError> {
    devices()
        .into_iter()
        .find(|d| d.name == name)
        .ok_or_else(|| RtlError::UnknownDevice {
            name: name.into(),
            known: names().join(", "),
        })
}

/// Reads a device table: `#` comments, then one device a line, six fields.
pub fn parse(text: &str) -> Result<Vec<Device>, RtlError> {
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let bad = |message: String| RtlError::Parse {
            what: "the device table".into(),
            line: k + 1,
            message,
        };
        let f: Vec<&str> = t.split_whitespace().collect();
        let [name, flag, package, cells, ram, io] = f[..] else {
            return Err(bad(format!("six fields, not {}: `{t}`", f.len())));
        };
        let num = |s: &str| {
            s.parse::<u64>()
                .map_err(|_| bad(format!("a count, not `{s}`")))
        };
        out.push(Device {
            name: name.into(),
            flag: flag.into(),
            package: package.into(),
            cells: num(cells)?,
            ram: num(ram)?,
            io: num(io)?,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_reads_and_names_its_devices() {
        let all = devices();
        assert!(all.len() >= 2);
        assert_eq!(device("ice40-hx8k").unwrap().cells, 7680);
        assert_eq!(device("ice40-up5k").unwrap().cells, 5280);
        let e = device("ice40-hx9k").unwrap_err().to_string();
        assert!(e.contains("ice40-hx9k") && e.contains("ice40-up5k"), "{e}");
        assert!(parse("a b c 1 2\n").is_err());
        assert!(parse("a b c 1 2 x\n").is_err());
    }
}
