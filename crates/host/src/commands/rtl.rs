//! `cwisim rtl`: synthesizable Verilog of the X-processor array for a fixed-point format
//! and an opcode set — all fourteen, or those a trace or scene uses (`--for`, with the
//! format `fit` finds for `--max-error`) —, and on request its co-simulation against the
//! stepped engine (`--cosim icarus|verilator`) and the area of one processor in Yosys
//! (`--area`). The generator, the co-simulation and the area are `cwisim_rtl`'s; this is
//! the command.

use super::fit::OverflowArg;
use super::MachineArgs;
use crate::error::CliError;
use crate::files::{write_atomic, WorkDir};
use clap::Args;
use cwisim_isa::{io::read_all, TraceHeader};
use cwisim_rtl::verilog::{self, Watch};
use cwisim_rtl::{
    all_opcodes, area, cosimulate_with, fpga, opcodes_used, BusTiming, CosimStage, Design,
    RtlError, Simulator,
};
use cwisim_study::fit::fit_scene;
use cwisim_xproc::numeric::Overflow;
use cwisim_xproc::Numeric;
use std::io::Write;
use std::path::PathBuf;

/// The arguments of `cwisim rtl`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct RtlArgs {
    /// The Verilog file to write (the adders, the processor and the array).
    #[arg(short = 'o', long = "output", value_name = "OUT.v")]
    pub output: PathBuf,
    /// Generate for this trace (.cwt, .jsonl, .cwb) or scene (a .json file or an embedded
    /// name): its width, channels and the opcodes it uses; with --cosim, co-simulate it.
    #[arg(long = "for", value_name = "TRACE|SCENE")]
    pub for_input: Option<PathBuf>,
    /// The registers: fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate]
    /// (docs/ACCURACY.md). Required unless --max-error finds it.
    #[arg(long, value_name = "FORMAT")]
    pub numeric: Option<Numeric>,
    /// Find the format as `cwisim fit` does for the --for scene: the narrowest whose output
    /// stays within E of the f64 array (e.g. 1/512).
    #[arg(long, value_name = "E", value_parser = super::fit::parse_error_budget, conflicts_with = "numeric", requires = "for_input")]
    pub max_error: Option<f64>,
    /// With --max-error: what the registers do when a value does not fit.
    #[arg(long, value_enum, default_value_t = OverflowArg::Saturate)]
    pub overflow: OverflowArg,
    /// Without --for: array width (X-processors).
    #[arg(
        long,
        value_name = "W",
        default_value_t = 16,
        conflicts_with = "for_input"
    )]
    pub width: u32,
    /// Without --for: channels per intensity (1 grey, 3 RGB).
    #[arg(
        long,
        value_name = "C",
        default_value_t = 1,
        conflicts_with = "for_input"
    )]
    pub channels: u8,
    /// Without --for: scanlines per frame (the display's height) to derive the line
    /// period for.
    #[arg(
        long = "height",
        value_name = "H",
        default_value_t = 1024,
        conflicts_with = "for_input"
    )]
    pub lines: u32,
    /// Also write the co-simulation testbench (it reads stimulus.hex, as --cosim writes it
    /// into --work-dir, and writes dump.txt; docs/HARDWARE.md says how to run it by hand).
    #[arg(long, value_name = "TB.v")]
    pub testbench: Option<PathBuf>,
    /// Co-simulate the --for trace or scene in this simulator against the stepped engine,
    /// and print the first difference or what agreed (with --fpga-shell: through the
    /// FPGA's I/O shell).
    #[arg(long, value_enum, value_name = "SIM", requires = "for_input")]
    pub cosim: Option<SimArg>,
    /// With --cosim icarus: co-simulate through the FPGA's I/O shell (docs/HARDWARE.md, "The
    /// I/O shell"): the instruction words in beats of 8 bits, each scanline out one value a
    /// cycle, every value held to the stepped engine bit for bit and at the engine's cycle
    /// plus the shell's fixed latency. The machine is paced for the shell's port (each
    /// opcode's issue at least a word's beats and one cycles), and the design written is
    /// the paced one. The overflow counts do not come out through the shell's ports.
    #[arg(long)]
    pub fpga_shell: bool,
    /// Keep the co-simulation's files (design, testbench, stimulus, dump) in this new
    /// directory; otherwise they go in a temporary one, kept only on a mismatch.
    #[arg(long, value_name = "DIR", requires = "cosim")]
    pub work_dir: Option<PathBuf>,
    /// Processors whose token arrivals are compared, e.g. 0,200,399 (default: the first,
    /// the middle and the last; `all` for every one).
    #[arg(long, value_name = "P,P,…|all")]
    pub watch: Option<String>,
    /// Synthesize one processor in Yosys and print its cells, flip-flops and NAND2 estimate.
    #[arg(long)]
    pub area: bool,
    /// Place and route the array on this FPGA (ice40-hx8k, ice40-up5k, ice40-hx1k) in an
    /// I/O shell that fits its pins: Yosys synth_ice40, nextpnr-ice40; prints the logic
    /// cells (the shell's apart), flip-flops, carries, RAM blocks, the maximum clock, the
    /// processors that fit, and with --for the late scanlines at that clock.
    #[arg(long, value_name = "DEVICE")]
    pub fpga: Option<String>,
    /// With --fpga: place an array of P processors of this design (its format and
    /// opcodes) instead of the whole width, e.g. as many as the device holds.
    #[arg(long, value_name = "P", requires = "fpga")]
    pub fpga_processors: Option<u32>,
    /// With --fpga: keep the flow's files (Verilog, netlists, nextpnr's logs and
    /// bitstream) in this new directory; otherwise a temporary one.
    #[arg(long, value_name = "DIR", requires = "fpga")]
    pub fpga_dir: Option<PathBuf>,
    /// The machine model (the bus and display timing built into the design).
    #[command(flatten)]
    pub machine: MachineArgs,
    /// How to draw a --for scene.
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: crate::draw::DrawArgs,
}

/// What the progress spinner says while `--cosim` is at `stage` with simulator `sim`.
fn cosim_stage_message(sim: Simulator, stage: CosimStage) -> String {
    let name = sim.name();
    match stage {
        CosimStage::Reference => {
            "rtl: co-simulating: the stepped engine's reference, the stimulus".to_string()
        }
        CosimStage::Build if sim == Simulator::Verilator => {
            "rtl: co-simulating: verilator building the simulator (C++, a few minutes)".to_string()
        }
        CosimStage::Build => format!("rtl: co-simulating: {name} compiling the Verilog"),
        CosimStage::Simulate { cycles } => {
            format!("rtl: co-simulating: {name} simulating {cycles} cycles")
        }
        CosimStage::Compare => "rtl: co-simulating: comparing the dump".to_string(),
    }
}

/// What the progress spinner says while `--fpga` is at `stage`.
fn fpga_stage_message(device: &fpga::Device, stage: fpga::FpgaStage) -> String {
    match stage {
        fpga::FpgaStage::Synthesize => "rtl: fpga: yosys synth_ice40".to_string(),
        fpga::FpgaStage::Pack => {
            format!("rtl: fpga: nextpnr-ice40 packing for the {}", device.name)
        }
        fpga::FpgaStage::Route => format!(
            "rtl: fpga: nextpnr-ice40 placing and routing on the {} (a minute or more)",
            device.name
        ),
    }
}

/// What the `shell` line says: the shell's port, the pace it sets and its fixed latency.
fn shell_summary(shell: &fpga::Shell, d: &Design) -> String {
    let beats = shell.beats(d);
    format!(
        "instruction words of {} bits in {beats} beats of {}, every opcode's issue paced to at least {} cycles; the array's cycle 0 is the shell's {} ({} after the first word's last beat); a scanline comes out {} cycles after its Refresh reaches the last processor, one value a cycle",
        fpga::Shell::word_bits(d),
        shell.beat_bits,
        beats + 1,
        shell.start_cycle(d),
        fpga::INPUT_LATENCY,
        fpga::OUTPUT_LATENCY
    )
}

/// `--cosim`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SimArg {
    /// Icarus Verilog (iverilog, vvp).
    Icarus,
    /// Verilator (compiled to C++ first).
    Verilator,
}

/// The simulator `--cosim` names.
fn sim_of(sim: SimArg) -> Simulator {
    match sim {
        SimArg::Icarus => Simulator::Icarus,
        SimArg::Verilator => Simulator::Verilator,
    }
}

/// A `cwisim_rtl` error as the command's.
fn rtl_error(e: RtlError) -> CliError {
    match e {
        RtlError::Machine(e) => CliError::Machine(e),
        RtlError::Budget(e) => CliError::Budget(e),
        RtlError::Io { path, source } => CliError::write(path, source),
        e @ (RtlError::Settings(_)
        | RtlError::UnknownDevice { .. }
        | RtlError::DoesNotFit { .. }
        | RtlError::Numeric(_)
        | RtlError::Trace { .. }
        | RtlError::ToolMissing { .. }) => CliError::Usage(e.to_string()),
        e @ (RtlError::ToolFailed { .. } | RtlError::NoOutput { .. } | RtlError::Parse { .. }) => {
            CliError::Internal(e.to_string())
        }
    }
}

/// The array in `format` for the opcodes of the stream `renderer` emits, `processors` wide
/// (at most the stream's width; `None`: all of it), and the stream's width.
fn scene_design(
    renderer: &dyn cwisim_render::Renderer,
    machine: &cwisim_xproc::Machine,
    format: cwisim_xproc::FixedFormat,
    processors: Option<u32>,
) -> Result<(Design, u32), CliError> {
    let (mut reader, _) = crate::input::emitted(renderer, false)?;
    let header = *reader.header();
    let trace = read_all(&mut *reader)?;
    let timing = BusTiming::new(machine, &header).map_err(rtl_error)?;
    let width = processors.map_or(header.width, |p| p.min(header.width));
    let design = Design::new(
        format,
        opcodes_used(&trace),
        width,
        header.channel_count(),
        timing,
    )
    .map_err(rtl_error)?;
    Ok((design, header.width))
}

/// The area of one processor in `format` for the opcodes of the stream `renderer` emits
/// (Yosys in a temporary directory): what `fit --area` prints.
pub(crate) fn scene_area(
    renderer: &dyn cwisim_render::Renderer,
    machine: &cwisim_xproc::Machine,
    format: cwisim_xproc::FixedFormat,
) -> Result<area::Area, CliError> {
    let (design, _) = scene_design(renderer, machine, format, None)?;
    let dir = WorkDir::new(None, "area")?;
    area::synthesize(&design, dir.path()).map_err(rtl_error)
}

/// The device `--fpga` names, with its tools on the PATH: checked before any work.
pub(crate) fn fpga_device(name: &str) -> Result<fpga::Device, CliError> {
    let d = fpga::device(name).map_err(rtl_error)?;
    require_tools(fpga::PROGRAMS)?;
    Ok(d)
}

/// `processors` processors (at most the width) of `format` for the opcodes of the stream
/// `renderer` emits, placed and routed on `device` in a temporary directory: what
/// `fit --area --fpga` prints, with the stream's width.
pub(crate) fn scene_fpga(
    renderer: &dyn cwisim_render::Renderer,
    machine: &cwisim_xproc::Machine,
    format: cwisim_xproc::FixedFormat,
    device: &fpga::Device,
    processors: u32,
) -> Result<(fpga::FpgaReport, u32), CliError> {
    let (design, width) = scene_design(renderer, machine, format, Some(processors))?;
    let dir = WorkDir::new(None, "fpga")?;
    let r = fpga::place_and_route(
        &design,
        &fpga::Shell::default(),
        device,
        dir.path(),
        &mut |_| {},
    )
    .map_err(rtl_error)?;
    Ok((r, width))
}

/// Refuses, before any work, a run whose tools are not installed: `programs`, each on the
/// PATH.
pub(crate) fn require_tools(programs: &[&str]) -> Result<(), CliError> {
    for p in programs {
        cwisim_rtl::tools::require(p).map_err(rtl_error)?;
    }
    Ok(())
}

/// Runs `cwisim rtl`.
pub fn run(args: &RtlArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    crate::input::drawing_applies(&args.draw, &[args.for_input.as_deref()])?;
    if args.fpga_shell {
        match args.cosim {
            Some(SimArg::Icarus) => {}
            Some(SimArg::Verilator) => {
                return Err(CliError::Usage(
                    "--fpga-shell co-simulates through the shell in Icarus Verilog: give --cosim icarus (--cosim verilator co-simulates the bare array)".into(),
                ))
            }
            None => {
                return Err(CliError::Usage(
                    "--fpga-shell says how --cosim co-simulates (through the FPGA's I/O shell): give --cosim icarus".into(),
                ))
            }
        }
        if args.watch.is_some() && args.testbench.is_none() {
            return Err(CliError::Usage(
                "--watch chooses the processors whose token arrivals --cosim compares; through the shell (--fpga-shell) only the scanlines come out".into(),
            ));
        }
    }
    // the tools, before anything is written or drawn
    if let Some(sim) = args.cosim {
        require_tools(sim_of(sim).programs())?;
    }
    if args.area {
        require_tools(&["yosys"])?;
    }
    let device = match &args.fpga {
        Some(name) => Some(fpga_device(name)?),
        None => None,
    };
    if args.watch.is_some() && args.cosim.is_none() && args.testbench.is_none() {
        return Err(CliError::Usage(
            "--watch chooses the processors whose token arrivals --cosim compares and --testbench writes: give one of them".into(),
        ));
    }
    crate::files::Io::new()
        .source("--for input", args.for_input.as_deref())
        .machine(&args.machine)
        .output("-o", Some(&args.output))
        .output("--testbench", args.testbench.as_deref())
        .check()?;
    let machine = args.machine.load()?;
    let out = stdout;
    let say = |out: &mut dyn Write, label: &str, value: String| {
        writeln!(out, "{label:<12}{value}").map_err(CliError::Stdout)
    };
    // the stream, the format
    let mut fit_error = None;
    let (header, trace) = match &args.for_input {
        Some(input) => {
            let stage = crate::progress::Stage::new(progress, "rtl: reading the stream");
            let (mut file, size) = crate::input::open_sized(input, &args.draw, false)?;
            cwisim_scene::budget::Budget::current().check_memory(
                "the stream held in memory (about 8 times its encoded size)",
                size.saturating_mul(8),
            )?;
            let header = *file.header();
            let trace = read_all(&mut *file)?;
            drop(stage);
            (header, Some(trace))
        }
        None => (
            TraceHeader::new(args.width, args.lines, args.channels)
                .map_err(|e| CliError::Usage(format!("--width/--height/--channels: {e}")))?,
            None,
        ),
    };
    let format = match (args.numeric, args.max_error) {
        (Some(Numeric::Fixed(f)), _) => f,
        (Some(other), _) => {
            return Err(CliError::Usage(format!(
                "--numeric {other}: the hardware has fixed-point registers; give fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N]"
            )))
        }
        (None, Some(budget)) => {
            let input = args.for_input.as_deref().expect("clap: requires --for");
            if crate::input::InputKind::of(input)? != crate::input::InputKind::Scene {
                return Err(CliError::Usage(format!(
                    "--max-error needs a scene to fit (the exact image is the reference); {} is a trace: give --numeric",
                    input.display()
                )));
            }
            let stage = crate::progress::Stage::new(progress, "rtl: fitting the registers");
            let drawn = args.draw.draw(Some(input))?;
            let overflow = match args.overflow {
                OverflowArg::Wrap => Overflow::Wrap,
                OverflowArg::Saturate => Overflow::Saturate,
            };
            let found = fit_scene(&*drawn.renderer, Some(input), args.draw.size, &machine, budget, overflow, 0, None)?;
            drop(stage);
            fit_error = Some(found.fit.error);
            found.fit.format
        }
        (None, None) => {
            return Err(CliError::Usage(
                "give the registers' format: --numeric fixed:… or, with --for SCENE, --max-error E".into(),
            ))
        }
    };
    let opcodes = match &trace {
        Some(t) => opcodes_used(t),
        None => all_opcodes(),
    };
    let timing = BusTiming::new(&machine, &header).map_err(rtl_error)?;
    let design = Design::new(
        format,
        opcodes,
        header.width,
        header.channel_count(),
        timing,
    )
    .map_err(rtl_error)?;
    let shell = fpga::Shell::default();
    // through the shell: the machine paced for its port, and the design with it
    let (design, machine) = if args.fpga_shell {
        shell.pace(&design, &machine, &header).map_err(rtl_error)?
    } else {
        (design, machine)
    };
    let text = verilog::design(&design);
    write_atomic(&args.output, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| CliError::write(&args.output, e))
    })?;
    let watch = match args.watch.as_deref() {
        None => Watch::ends(design.width),
        Some(list) => Watch::parse(list, design.width)
            .map_err(|e| CliError::Usage(format!("--watch {list}: {e}")))?,
    };
    if let Some(tb) = &args.testbench {
        let text = verilog::testbench(&design, &watch);
        write_atomic(tb, |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| CliError::write(tb, e))
        })?;
    }
    say(out, "design", design.summary())?;
    if let Some(e) = fit_error {
        say(
            out,
            "fit",
            format!("max error {e:.4e} against the f64 array"),
        )?;
    }
    if args.area {
        let dir = WorkDir::new(None, "area")?;
        let a = area::synthesize(&design, dir.path()).map_err(rtl_error)?;
        drop(dir);
        say(
            out,
            "area",
            format!(
                "one processor: {} cells ({} flip-flops, {} logic), about {:.0} NAND2 equivalents (Yosys synth; docs/HARDWARE.md has the mapping)",
                a.total, a.flip_flops, a.logic, a.nand2
            ),
        )?;
    }
    if let Some(device) = &device {
        let placed = match args.fpga_processors {
            None => design.clone(),
            Some(p) => Design::new(
                design.format,
                design.opcodes.clone(),
                p,
                design.channels,
                design.timing.clone(),
            )
            .map_err(|e| CliError::Usage(format!("--fpga-processors {p}: {e}")))?,
        };
        let dir = WorkDir::new(args.fpga_dir.as_deref(), "fpga")?;
        let stage = crate::progress::Stage::new(progress, "rtl: fpga");
        let r = fpga::place_and_route(&placed, &shell, device, dir.path(), &mut |now| {
            stage.message(&fpga_stage_message(device, now))
        })
        .map_err(rtl_error)?;
        drop(stage);
        drop(dir);
        let (shell_c, array_c, proc_c) = (&r.shell, &r.array, &r.processor);
        say(
            out,
            "fpga",
            format!(
                "{} ({}): {} processor(s) in the shell: {} of {} logic cells, {} of {} RAM blocks, {} of {} pins (nextpnr-ice40, seed {})",
                device.name,
                device.package,
                r.width,
                r.logic_cells,
                device.cells,
                r.ram_blocks,
                device.ram,
                r.pins,
                device.io,
                fpga::SEED
            ),
        )?;
        for (label, c) in [
            ("array", array_c),
            ("shell", shell_c),
            ("processor", proc_c),
        ] {
            say(
                out,
                label,
                format!(
                    "{} LUTs, {} flip-flops, {} carries, {} RAM blocks (Yosys synth_ice40)",
                    c.luts(),
                    c.flip_flops(),
                    c.carries(),
                    c.ram()
                ),
            )?;
        }
        say(
            out,
            "fmax",
            format!(
                "{:.2} MHz (nextpnr-ice40's timing analysis of the routed design)",
                r.fmax_mhz
            ),
        )?;
        let full = design.width;
        say(
            out,
            "fits",
            format!(
                "about {} processors of this design on one {}; {} device(s) for the full width of {}",
                r.fit,
                device.name,
                if r.fit == 0 {
                    "no number of".to_string()
                } else {
                    u64::from(full).div_ceil(r.fit).to_string()
                },
                full
            ),
        )?;
        let clock = r.clock_hz();
        match &trace {
            Some(t) => {
                let rep = fpga::replay_at(&header, t, &machine, design.format, clock)
                    .map_err(rtl_error)?;
                say(
                    out,
                    "at fmax",
                    format!(
                        "--set clock_hz={clock}: line period {} cycles, {} of {} scanline(s) late",
                        rep.line_period, rep.late, rep.lines
                    ),
                )?;
            }
            None => say(
                out,
                "at fmax",
                format!("replay a scene at it with --set clock_hz={clock}"),
            )?,
        }
    }
    if let (Some(sim), Some(trace)) = (args.cosim, &trace) {
        let sim = sim_of(sim);
        if args.fpga_shell {
            say(out, "shell", shell_summary(&shell, &design))?;
        }
        let dir = WorkDir::new(args.work_dir.as_deref(), "cosim")?;
        let stage = crate::progress::Stage::new(progress, "rtl: co-simulating");
        let tell = &mut |now| stage.message(&cosim_stage_message(sim, now));
        // what agreed or the first difference, and the times: build, simulation, engine
        let (result, times) = if args.fpga_shell {
            let o = fpga::cosimulate_shell_with(
                &design,
                &shell,
                &header,
                trace,
                &machine,
                &fpga::Netlist::Rtl,
                dir.path(),
                tell,
            )
            .map_err(rtl_error)?;
            let result = o.result.map(|a| format!(
                "icarus through the FPGA shell: identical to the stepped engine: {} scanline(s), {} value(s) bit for bit, each out at the shell's cycle {} + a + {} + k (a: the engine's cycle its Refresh reaches the last processor, k: its place in the scanline), {} cycles of the array; overflow events do not come out through the shell's ports",
                a.scanlines,
                a.values,
                a.start,
                fpga::OUTPUT_LATENCY,
                a.cycles
            ));
            (
                result.map_err(|m| m.to_string()),
                [o.build, o.simulate, o.reference],
            )
        } else {
            let o = cosimulate_with(
                &design,
                &header,
                trace,
                &machine,
                &watch,
                sim,
                dir.path(),
                tell,
            )
            .map_err(rtl_error)?;
            let result = o.result.map(|a| format!(
                "{}: identical to the stepped engine: {} scanline(s), {} value(s) bit for bit, {} token arrival(s) at {} watched processor(s), {} overflow event(s) ({} in the adders), {} cycles",
                sim.name(),
                a.scanlines,
                a.values,
                a.arrivals,
                watch.processors().len(),
                a.overflows,
                a.adder_overflows,
                a.cycles
            ));
            (
                result.map_err(|m| m.to_string()),
                [o.build, o.simulate, o.reference],
            )
        };
        drop(stage);
        match result {
            Ok(agreed) => {
                drop(dir);
                say(out, "co-sim", agreed)?;
                let [build, simulate, reference] = times.map(|t| t.as_secs_f64());
                say(
                    out,
                    "times",
                    format!("build {build:.1} s, simulation {simulate:.1} s, stepped engine {reference:.1} s"),
                )?;
            }
            Err(m) => {
                // kept, for a look
                let dir = dir.keep();
                let through = if args.fpga_shell {
                    " through the FPGA shell"
                } else {
                    ""
                };
                return Err(CliError::Internal(format!(
                    "the {} co-simulation{through} differs from the stepped engine: {m} (files in {})",
                    sim.name(),
                    dir.display()
                )));
            }
        }
    }
    // last: the files are written only when the whole command succeeded (a transaction)
    let mut written = vec![args.output.display().to_string()];
    written.extend(args.testbench.iter().map(|t| t.display().to_string()));
    say(out, "wrote", written.join(", "))?;
    Ok(())
}
