//! The shell proven: the trace streamed through the shell's narrow ports in Icarus
//! Verilog — the RTL of the shell and the array, or the netlist nextpnr placed and routed
//! ([`Netlist::PostRoute`], simulated with Yosys's iCE40 cell models) — and every value
//! that comes out held to the stepped engine: the same scanlines bit for bit, each from
//! the cycle the engine has its Refresh reach the last processor, shifted by the shell's
//! fixed latencies ([`Shell::start_cycle`], [`OUTPUT_LATENCY`]).

use super::shell::{Shell, OUTPUT_LATENCY, SHELL_MODULE};
use crate::compare::{refresh_indices, sign_extend};
use crate::cosim::CosimStage;
use crate::design::Design;
use crate::error::RtlError;
use crate::reference::expected;
use crate::stimulus;
use crate::tools::{run, write_file};
use crate::verilog::{self, bench, Text, Watch, STIMULUS_FILE};
use cwisim_isa::{Instruction, TraceHeader};
use cwisim_xproc::{Arith, FixedArith, Machine};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The shell testbench's module.
pub const SHELL_TESTBENCH_MODULE: &str = "cwisim_fpga_tb";
/// What it writes: `V cycle value` for each value out (`L` for a scanline's last),
/// `R cycle` when `m_overrun` rises, `E cycle` at the end, `T cycle` at the limit.
pub const SHELL_DUMP_FILE: &str = "shell_dump.txt";

/// Yosys's simulation models of the iCE40 cells (Debian's yosys package), for the
/// post-route netlist.
pub const ICE40_CELLS: &str = "/usr/share/yosys/ice40/cells_sim.v";

/// What is simulated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Netlist {
    /// The shell's and the array's Verilog.
    Rtl,
    /// The netlist nextpnr wrote after routing (`routed.json` of [`super::place_and_route`]),
    /// converted to Verilog by Yosys (`write_verilog`) and simulated with [`ICE40_CELLS`].
    PostRoute(PathBuf),
}

/// What agreed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShellAgreement {
    /// Scanlines out.
    pub scanlines: u64,
    /// Values compared bit for bit.
    pub values: u64,
    /// The shell's cycle of the array's cycle 0.
    pub start: u64,
    /// The cycles the stepped engine took (the array's).
    pub cycles: u64,
}

/// What a co-simulation through the shell found, with its times.
#[derive(Clone, Debug)]
pub struct ShellOutcome {
    /// Everything agreed, or the first difference.
    pub result: Result<ShellAgreement, ShellMismatch>,
    /// Time to compile the shell, the array and the testbench.
    pub build: Duration,
    /// Time the simulation ran.
    pub simulate: Duration,
    /// Time the stepped engine took.
    pub reference: Duration,
}

/// The first difference.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShellMismatch(pub String);

impl std::fmt::Display for ShellMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// The shell testbench: reads the stimulus (as [`crate::verilog::testbench`]'s), sends
/// each instruction word in beats, one a cycle whenever `s_ready`, and writes
/// [`SHELL_DUMP_FILE`].
pub fn testbench(d: &Design, shell: &Shell, lines: u64) -> String {
    let mut v = Text::new();
    verilog::header(
        d,
        &mut v,
        "Testbench of the CWI X-processor array through its FPGA shell",
    );
    v.line("`timescale 1ns / 1ns");
    let reads: Vec<u32> = bench::stimulus_words(d).iter().map(|w| w.1).collect();
    let b = shell.beat_bits;
    let k = shell.beats(d);
    let wa = Shell::value_bits(d);
    v.line(&format!("module {SHELL_TESTBENCH_MODULE};"));
    bench::stimulus_parameters(&mut v, reads.len());
    v.line(&format!("    localparam integer LINES = {lines};"));
    bench::clock_and_reset(&mut v);
    v.line(&format!("    reg [{}:0] s_data = {b}'d0;", b - 1));
    v.line("    reg s_valid = 1'b0;");
    v.line("    wire s_ready;");
    v.line(&format!("    wire [{}:0] m_data;", wa - 1));
    v.line("    wire m_valid, m_last, m_overrun;");
    v.line(&format!(
        "    {SHELL_MODULE} dut (.clk(clk), .rst(rst), .s_data(s_data), .s_valid(s_valid), .s_ready(s_ready), .m_data(m_data), .m_valid(m_valid), .m_last(m_last), .m_overrun(m_overrun));"
    ));
    v.line("    reg [63:0] words [0:INSTRUCTIONS*FIELDS-1];");
    v.line(&format!("    reg [{}:0] word;", k * b - 1));
    v.line("    integer dump, index, beat, done;");
    v.line("    reg [63:0] cycle;");
    v.line("    reg overrun_seen;");
    v.line("    task load;");
    v.line("        begin");
    v.line("            word = 0;");
    let mut at = 0;
    for (j, bits) in reads.iter().enumerate() {
        v.line(&format!(
            "            word[{}:{at}] = words[index*FIELDS+{j}][{}:0];",
            at + bits - 1,
            bits - 1
        ));
        at += bits;
    }
    v.line("        end");
    v.line("    endtask");
    v.line("    initial begin");
    v.line(&format!("        $readmemh(\"{STIMULUS_FILE}\", words);"));
    v.line(&format!(
        "        dump = $fopen(\"{SHELL_DUMP_FILE}\", \"w\");"
    ));
    v.line("        index = 0; beat = 0; done = 0; cycle = 0; overrun_seen = 1'b0;");
    v.line("        load;");
    v.line("        @(posedge clk);");
    v.line("        @(posedge clk);");
    v.line("        rst <= 1'b0;");
    v.line(&format!("        s_data <= word[{}:0];", b - 1));
    v.line("        s_valid <= 1'b1;");
    v.line("    end");
    v.line("    // the beats: the next one after each taken");
    v.line("    always @(posedge clk) if (!rst) begin");
    v.line("        cycle <= cycle + 64'd1;");
    v.line("        if (s_valid && s_ready) begin");
    v.line(&format!("            if (beat == {}) begin", k - 1));
    v.line("                beat = 0;");
    v.line("                index = index + 1;");
    v.line("                if (index == INSTRUCTIONS) s_valid <= 1'b0;");
    v.line("                else load;");
    v.line("            end else beat = beat + 1;");
    v.line(&format!("            s_data <= word[beat*{b} +: {b}];"));
    v.line("        end");
    v.line("    end");
    v.line("    // what comes out, sampled in the middle of each cycle (the shell's cycle 0: the first after reset)");
    v.line("    always @(negedge clk) if (!rst) begin");
    v.line("        if (m_valid) begin");
    v.line("            $fwrite(dump, \"%s %0d %h\\n\", m_last ? \"L\" : \"V\", cycle, m_data);");
    v.line("            if (m_last) done = done + 1;");
    v.line("        end");
    v.line("        if (m_overrun && !overrun_seen) begin");
    v.line("            $fwrite(dump, \"R %0d\\n\", cycle);");
    v.line("            overrun_seen = 1'b1;");
    v.line("        end");
    bench::finish_when(&mut v, "done == LINES", 'E');
    bench::finish_when(&mut v, "cycle >= CYCLE_LIMIT", 'T');
    v.line("    end");
    v.line("endmodule");
    v.into_string()
}

/// Streams `trace` through the shell of design `d` in Icarus Verilog (the RTL, or the
/// routed netlist) in the existing, empty directory `dir`, and holds every value and its
/// cycle to the stepped engine.
#[allow(clippy::too_many_arguments)]
pub fn cosimulate_shell(
    d: &Design,
    shell: &Shell,
    header: &TraceHeader,
    trace: &[Instruction],
    machine: &Machine,
    netlist: &Netlist,
    dir: &Path,
) -> Result<Result<ShellAgreement, ShellMismatch>, RtlError> {
    cosimulate_shell_with(d, shell, header, trace, machine, netlist, dir, &mut |_| {})
        .map(|o| o.result)
}

/// [`cosimulate_shell`] with its times, telling `stage` as each [`CosimStage`] begins.
#[allow(clippy::too_many_arguments)]
pub fn cosimulate_shell_with(
    d: &Design,
    shell: &Shell,
    header: &TraceHeader,
    trace: &[Instruction],
    machine: &Machine,
    netlist: &Netlist,
    dir: &Path,
    stage: &mut dyn FnMut(CosimStage),
) -> Result<ShellOutcome, RtlError> {
    if trace.is_empty() {
        return Err(RtlError::Settings(
            "the trace is empty: nothing to co-simulate".into(),
        ));
    }
    let dir = &dir.canonicalize().map_err(|e| RtlError::io(dir, e))?;
    let last = d.width - 1;
    let started = Instant::now();
    stage(CosimStage::Reference);
    let want = expected(d, header, trace, machine, &Watch::new([last], d.width))?;
    let reference = started.elapsed();
    if want.cycles > crate::cosim::MAX_COSIM_CYCLES {
        return Err(RtlError::Settings(format!(
            "the co-simulation would run {} cycles ({} scanline(s) of the machine's line period), over the limit of {}: a lower clock_hz (--set clock_hz=…) or a shorter trace",
            want.cycles,
            want.lines.len(),
            crate::cosim::MAX_COSIM_CYCLES
        )));
    }
    let lines = want.lines.len() as u64;
    let mut stim = Vec::new();
    stimulus::write(d, header, trace, &mut stim)?;
    std::fs::write(dir.join(STIMULUS_FILE), &stim)
        .map_err(|e| RtlError::io(dir.join(STIMULUS_FILE), e))?;
    write_file(&dir.join("tb.v"), &testbench(d, shell, lines))?;
    let limit = want
        .cycles
        .saturating_mul(2)
        .saturating_add(1000 + 4 * u64::from(shell.beats(d)) * trace.len() as u64);
    let started = Instant::now();
    stage(CosimStage::Build);
    let mut sources: Vec<String> = vec!["tb.v".into()];
    match netlist {
        Netlist::Rtl => {
            write_file(&dir.join("design.v"), &verilog::design(d))?;
            write_file(&dir.join("shell.v"), &shell.verilog(d))?;
            sources.extend(["design.v".into(), "shell.v".into()]);
        }
        Netlist::PostRoute(routed) => {
            let routed = routed.canonicalize().map_err(|e| RtlError::io(routed, e))?;
            let r = routed.to_str().ok_or_else(|| {
                RtlError::Settings(format!("{}: not a UTF-8 path", routed.display()))
            })?;
            run(
                "yosys",
                &[
                    "-q",
                    "-p",
                    &format!(
                        "read_json {r}; rename top {SHELL_MODULE}; write_verilog -noattr post.v"
                    ),
                ],
                dir,
            )?;
            sources.extend(["post.v".into(), ICE40_CELLS.into()]);
        }
    }
    let mut args = vec![
        "-g2005".to_string(),
        format!("-P{SHELL_TESTBENCH_MODULE}.INSTRUCTIONS={}", trace.len()),
        format!("-P{SHELL_TESTBENCH_MODULE}.CYCLE_LIMIT={limit}"),
        "-s".into(),
        SHELL_TESTBENCH_MODULE.into(),
        "-o".into(),
        "shell.vvp".into(),
    ];
    if matches!(netlist, Netlist::PostRoute(_)) {
        // the cell models' timing checks and specify blocks are not needed
        args.push("-DNO_ICE40_DEFAULT_ASSIGNMENTS".into());
    }
    args.extend(sources);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    run("iverilog", &args, dir)?;
    let build = started.elapsed();
    let started = Instant::now();
    stage(CosimStage::Simulate {
        cycles: want.cycles,
    });
    run("vvp", &["-n", "shell.vvp"], dir)?;
    let simulate = started.elapsed();
    stage(CosimStage::Compare);
    let result = compare_dump(d, shell, trace, &want, &dir.join(SHELL_DUMP_FILE))?;
    Ok(ShellOutcome {
        result,
        build,
        simulate,
        reference,
    })
}

/// The shell testbench's dump at `path` held to the stepped engine's `want`: every value
/// bit for bit, each at its cycle.
fn compare_dump(
    d: &Design,
    shell: &Shell,
    trace: &[Instruction],
    want: &crate::reference::Expected,
    path: &Path,
) -> Result<Result<ShellAgreement, ShellMismatch>, RtlError> {
    let last = d.width - 1;
    let refreshes = refresh_indices(trace);
    let arrivals = want.arrivals.get(&last).cloned().unwrap_or_default();
    let lines = want.lines.len() as u64;
    let text = std::fs::read_to_string(path).map_err(|source| RtlError::NoOutput {
        tool: "vvp".into(),
        path: path.to_path_buf(),
        source,
    })?;
    let arith = FixedArith::new(&d.format)?;
    let wa = Shell::value_bits(d);
    let start = shell.start_cycle(d);
    let per_line = (d.width as usize) * d.channels;
    let mut got: Vec<(u64, u64, bool)> = Vec::new();
    let mut ended = false;
    for (k, line) in text.lines().enumerate() {
        let bad = |message: String| RtlError::Parse {
            what: SHELL_DUMP_FILE.into(),
            line: k + 1,
            message,
        };
        let f: Vec<&str> = line.split_whitespace().collect();
        match f[..] {
            [tag @ ("V" | "L"), cycle, value] => {
                let cycle = cycle
                    .parse::<u64>()
                    .map_err(|_| bad(format!("a cycle: `{line}`")))?;
                let value = u64::from_str_radix(value, 16)
                    .map_err(|_| bad(format!("a value (x: unknown bits?): `{line}`")))?;
                got.push((cycle, value, tag == "L"));
            }
            ["R", cycle] => {
                return Ok(Err(ShellMismatch(format!(
                    "the shell signalled an overrun at its cycle {cycle}: a Refresh reached processor 0 while a scanline was going out"
                ))))
            }
            ["E", _] => ended = true,
            ["T", cycle] => {
                return Ok(Err(ShellMismatch(format!(
                    "the simulation reached its limit at cycle {cycle} with {} of {lines} scanline(s) out",
                    got.iter().filter(|g| g.2).count()
                ))))
            }
            _ => return Err(bad(format!("an unknown line `{line}`"))),
        }
    }
    if !ended {
        return Err(RtlError::Parse {
            what: SHELL_DUMP_FILE.into(),
            line: 0,
            message: "the dump stops without its end (the simulator was cut short)".into(),
        });
    }
    if got.len() != per_line * want.lines.len() {
        return Ok(Err(ShellMismatch(format!(
            "{} value(s) came out; the stepped engine has {} scanline(s) of {per_line}",
            got.len(),
            want.lines.len()
        ))));
    }
    for (n, line) in want.lines.iter().enumerate() {
        let arrival = refreshes
            .get(n)
            .and_then(|&i| arrivals.get(i))
            .copied()
            .ok_or_else(|| RtlError::Settings(format!("scanline {n} has no Refresh arrival")))?;
        let first = start + arrival + OUTPUT_LATENCY;
        for (j, want_value) in line.iter().enumerate() {
            let (cycle, raw, is_last) = got[n * per_line + j];
            let value = arith.out(sign_extend(raw, wa));
            let (p, c) = (j / d.channels, j % d.channels);
            if cycle != first + j as u64 {
                return Ok(Err(ShellMismatch(format!(
                    "scanline {n}, processor {p}, channel {c}: out at the shell's cycle {cycle}, expected {} (the Refresh reached the last processor at the array's cycle {arrival}; + {start} + {OUTPUT_LATENCY} + {j})",
                    first + j as u64
                ))));
            }
            if value != *want_value || is_last != (j + 1 == per_line) {
                return Ok(Err(ShellMismatch(format!(
                    "scanline {n}, processor {p}, channel {c}: {value:e} (raw {}), the stepped engine {want_value:e}",
                    sign_extend(raw, wa)
                ))));
            }
        }
    }
    Ok(Ok(ShellAgreement {
        scanlines: lines,
        values: got.len() as u64,
        start,
        cycles: want.cycles,
    }))
}
