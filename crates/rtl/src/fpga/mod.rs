//! The array on an FPGA: an I/O shell that fits a package's pins ([`shell`]), the open
//! iCE40 flow — Yosys's `synth_ice40`, `nextpnr-ice40`'s placement, routing and timing
//! analysis — ([`place_and_route`]), and what it reports ([`report`]): logic cells,
//! flip-flops, RAM blocks, carry chains, the shell's own logic apart from the array's, the
//! clock the routed design reaches, and how many processors of the format fit the device.
//! The devices are a table ([`device`]).

pub mod cosim;
pub mod device;
pub mod report;
pub mod shell;

pub use cosim::{
    cosimulate_shell, cosimulate_shell_with, Netlist, ShellAgreement, ShellMismatch, ShellOutcome,
};
pub use device::{device, devices, Device};
pub use report::{Cells, Hierarchy, Pnr};
pub use shell::{Shell, INPUT_LATENCY, OUTPUT_LATENCY, SHELL_MODULE};

use crate::design::Design;
use crate::error::RtlError;
use crate::tools::{run, write_file};
use crate::verilog::{self, PROCESSOR_MODULE};
use std::path::Path;

/// The programs the flow runs.
pub const PROGRAMS: &[&str] = &["yosys", "nextpnr-ice40"];

/// The seed of nextpnr's placer: fixed, so that the same design gives the same result.
pub const SEED: u64 = 1;

/// Where [`place_and_route`] is, for a progress display.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FpgaStage {
    /// Yosys's `synth_ice40`.
    Synthesize,
    /// The same design at half the width synthesized and packed: the cells a processor
    /// adds.
    Pack,
    /// nextpnr placing, routing and timing the design.
    Route,
}

/// What the flow found for one design on one device.
#[derive(Clone, Debug, PartialEq)]
pub struct FpgaReport {
    /// The device.
    pub device: Device,
    /// Processors in the array.
    pub width: u32,
    /// The pins the shell uses.
    pub pins: u32,
    /// The shell's own cells (Yosys, module [`SHELL_MODULE`]).
    pub shell: Cells,
    /// The array's cells (every other module: bus, display timing, processors).
    pub array: Cells,
    /// One processor's cells (module [`PROCESSOR_MODULE`] with its adders).
    pub processor: Cells,
    /// Logic cells the placed design uses (nextpnr's ICESTORM_LC).
    pub logic_cells: u64,
    /// RAM blocks it uses (ICESTORM_RAM).
    pub ram_blocks: u64,
    /// The maximum clock frequency nextpnr's timing analysis gives the routed design, MHz.
    pub fmax_mhz: f64,
    /// How many processors of this format fit the device, with the shell and the bus
    /// (from two widths packed: [`processors_that_fit`]).
    pub fit: u64,
}

impl FpgaReport {
    /// The largest clock the routed design runs at, Hz, rounded down to a kHz: what
    /// `--set clock_hz=` takes to replay the scene at it.
    pub fn clock_hz(&self) -> u64 {
        (self.fmax_mhz * 1000.0).floor() as u64 * 1000
    }
}

/// How many processors fit `cells` logic cells, from the cells two arrays of the same
/// design pack into: `used` for `width` processors, `used_half` for `half` (fewer): the
/// cells of a processor are the difference per processor (its share of the bus's chain
/// included), the rest (shell, bus, display timing) counted once.
pub fn processors_that_fit(cells: u64, used: u64, width: u32, used_half: u64, half: u32) -> u64 {
    if half >= width || used <= used_half {
        return 0;
    }
    let per = (used - used_half) as f64 / f64::from(width - half);
    let fixed = (used as f64 - per * f64::from(width)).max(0.0);
    ((cells as f64 - fixed) / per).floor().max(0.0) as u64
}

/// Synthesizes and packs design `d` in `shell` for `device` in `dir`: Yosys's hierarchy
/// and nextpnr's packing.
fn synthesize_and_pack(
    d: &Design,
    shell: &Shell,
    device: &Device,
    dir: &Path,
) -> Result<(Hierarchy, Pnr), RtlError> {
    write_file(&dir.join("design.v"), &verilog::design(d))?;
    write_file(&dir.join("shell.v"), &shell.verilog(d))?;
    run("yosys", &["-q", "-p", &yosys_script()], dir)?;
    let h = report::parse_stat(&read_output("yosys", &dir.join("stat.txt"))?)?;
    let args = nextpnr_args(device, true);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let log = run("nextpnr-ice40", &args, dir)?;
    write_file(&dir.join("pack.log"), &log)?;
    Ok((h, report::parse_nextpnr(&log)?))
}

fn read_output(tool: &str, path: &Path) -> Result<String, RtlError> {
    std::fs::read_to_string(path).map_err(|source| RtlError::NoOutput {
        tool: tool.into(),
        path: path.to_path_buf(),
        source,
    })
}

/// The Yosys script: the array and the shell synthesized for the iCE40 with the
/// hierarchy kept (for the statistics of each module), then flattened for nextpnr.
pub fn yosys_script() -> String {
    format!(
        "read_verilog design.v shell.v; synth_ice40 -noflatten -top {SHELL_MODULE}; tee -q -o stat.txt stat; flatten; write_json fpga.json"
    )
}

/// nextpnr-ice40's arguments for `device` (`pack_only`: no placement).
pub fn nextpnr_args(device: &Device, pack_only: bool) -> Vec<String> {
    let mut a = vec![
        format!("--{}", device.flag),
        "--package".into(),
        device.package.clone(),
        "--json".into(),
        "fpga.json".into(),
        "--seed".into(),
        SEED.to_string(),
    ];
    if pack_only {
        a.push("--pack-only".into());
    } else {
        a.extend(["--asc".into(), "fpga.asc".into()]);
        a.extend(["--write".into(), "routed.json".into()]);
    }
    a
}

/// Places and routes design `d` in shell `shell` on `device`, in the (existing, empty)
/// directory `dir` (which keeps `design.v`, `shell.v`, Yosys's `fpga.json` and `stat.txt`,
/// nextpnr's `fpga.asc`, `routed.json` and logs), telling `stage` as each step begins. A
/// design with more pins or cells than the device has is [`RtlError::DoesNotFit`], with
/// the numbers.
pub fn place_and_route(
    d: &Design,
    shell: &Shell,
    device: &Device,
    dir: &Path,
    stage: &mut dyn FnMut(FpgaStage),
) -> Result<FpgaReport, RtlError> {
    if shell.beat_bits == 0 {
        return Err(RtlError::Settings(
            "the shell's input port needs at least 1 bit".into(),
        ));
    }
    let pins = shell.pins(d);
    if u64::from(pins) > device.io {
        return Err(RtlError::DoesNotFit {
            device: device.name.clone(),
            what: "I/O pins".into(),
            needed: pins.into(),
            there: device.io,
            hint: format!(
                " ({} bits in, {} bits out, and 7 for the clock, reset and handshakes)",
                shell.beat_bits,
                Shell::value_bits(d)
            ),
        });
    }
    let dir = &dir.canonicalize().map_err(|e| RtlError::io(dir, e))?;
    stage(FpgaStage::Synthesize);
    let (h, packed) = synthesize_and_pack(d, shell, device, dir)?;
    let shell_cells = h.modules.get(SHELL_MODULE).cloned().unwrap_or_default();
    let processor = h
        .modules
        .keys()
        .filter(|m| m.as_str() == PROCESSOR_MODULE || m.ends_with(&format!("\\{PROCESSOR_MODULE}")))
        .map(|m| h.with_submodules(m))
        .max_by_key(Cells::cell_estimate)
        .ok_or_else(|| RtlError::Parse {
            what: "yosys stat".into(),
            line: 0,
            message: format!("no module {PROCESSOR_MODULE}"),
        })?;
    let array = h.total.minus(&shell_cells);
    let (used, there) = packed.used("ICESTORM_LC")?;

    // the same design at half the width (twice the width for one processor), packed:
    // the cells a processor adds
    stage(FpgaStage::Pack);
    let other = if d.width >= 2 { d.width / 2 } else { 2 };
    let mut od = d.clone();
    od.width = other;
    let odir = dir.join(format!("width-{other}"));
    std::fs::create_dir_all(&odir).map_err(|e| RtlError::io(&odir, e))?;
    let (_, opacked) = synthesize_and_pack(&od, shell, device, &odir)?;
    let (oused, _) = opacked.used("ICESTORM_LC")?;
    let fit = if other < d.width {
        processors_that_fit(device.cells, used, d.width, oused, other)
    } else {
        processors_that_fit(device.cells, oused, other, used, d.width)
    };
    if used > there.min(device.cells) {
        return Err(RtlError::DoesNotFit {
            device: device.name.clone(),
            what: "logic cells".into(),
            needed: used,
            there: there.min(device.cells),
            hint: if fit == 0 {
                format!(
                    "; not one processor of this format fits beside the shell and the bus (this array has {})",
                    d.width
                )
            } else {
                format!(
                    "; about {fit} processors of this format fit (this array has {}: --fpga-processors {fit})",
                    d.width
                )
            },
        });
    }
    let (ram, ram_there) = packed.used("ICESTORM_RAM")?;
    if ram > ram_there {
        return Err(RtlError::DoesNotFit {
            device: device.name.clone(),
            what: "RAM blocks".into(),
            needed: ram,
            there: ram_there,
            hint: String::new(),
        });
    }

    stage(FpgaStage::Route);
    let args = nextpnr_args(device, false);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let log = run("nextpnr-ice40", &args, dir)?;
    write_file(&dir.join("route.log"), &log)?;
    let routed = report::parse_nextpnr(&log)?;
    let (logic_cells, _) = routed.used("ICESTORM_LC")?;
    let (ram_blocks, _) = routed.used("ICESTORM_RAM")?;
    let fmax_mhz = routed.fmax_mhz.ok_or_else(|| RtlError::Parse {
        what: "nextpnr-ice40's log".into(),
        line: 0,
        message: "no `Max frequency for clock` line after routing".into(),
    })?;
    Ok(FpgaReport {
        device: device.clone(),
        width: d.width,
        pins,
        shell: shell_cells,
        array,
        processor,
        logic_cells,
        ram_blocks,
        fmax_mhz,
        fit,
    })
}

/// A scene replayed at a clock: its scanlines and how many were late.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Replay {
    /// The clock, Hz.
    pub clock_hz: u64,
    /// The cycles of a line period at that clock.
    pub line_period: u64,
    /// Scanlines output.
    pub lines: u64,
    /// Scanlines not ready by their deadline.
    pub late: u64,
}

struct Discard;

impl cwisim_xproc::LineSink<f64> for Discard {
    fn line(&mut self, _: cwisim_xproc::LineOut<'_, f64>) {}
}

/// Replays `trace` in `format` on `machine` with its clock set to `clock_hz` (the fast
/// timing, the same results as the stepped engine's): the late scanlines at the clock
/// the chip reaches, as `cwisim run --set clock_hz=… --numeric …` reports them.
pub fn replay_at(
    header: &cwisim_isa::TraceHeader,
    trace: &[cwisim_isa::Instruction],
    machine: &cwisim_xproc::Machine,
    format: cwisim_xproc::FixedFormat,
    clock_hz: u64,
) -> Result<Replay, RtlError> {
    let mut m = machine.clone();
    m.clock_hz = clock_hz as f64;
    m.validate()?;
    let line_period = m.timeline(header)?.line_period;
    let mut eng = cwisim_xproc::engine::numeric_engine(
        header,
        &m,
        cwisim_xproc::engine::Timing::Fast,
        &cwisim_xproc::Numeric::Fixed(format),
    )?;
    for instr in trace {
        eng.execute(instr, &mut Discard);
    }
    let stats = eng.finish(&mut Discard);
    Ok(Replay {
        clock_hz,
        line_period,
        lines: stats.totals.lines,
        late: stats.totals.late_lines,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn processors_that_fit_follow_the_cells_a_processor_adds() {
        // 16 processors in 3400 cells, 8 in 1800: 200 a processor, 200 for the rest
        assert_eq!(processors_that_fit(7680, 3400, 16, 1800, 8), 37);
        assert_eq!(processors_that_fit(1280, 3400, 16, 1800, 8), 5);
        assert_eq!(processors_that_fit(100, 3400, 16, 1800, 8), 0);
        assert_eq!(processors_that_fit(7680, 3400, 16, 3400, 8), 0);
        assert_eq!(processors_that_fit(7680, 3400, 8, 1800, 16), 0);
    }
}
