//! The `cwisim` command line: argument parsing, dispatch, and how errors are shown.
//!
//! [`run_cli`] is the whole program on any output streams, so tests can run it
//! in-process; [`main`] calls it with the real ones.

use crate::commands::convert::ConvertArgs;
use crate::commands::machine::MachineCmdArgs;
use crate::commands::run::RunArgs;
use crate::commands::scene::{EmitArgs, RenderArgs};
use crate::commands::{
    convert, diff, dump, fit, history, inspect, machine, refine, renderers, rtl, run, scene,
    scenes, stats, tradeoff, vcd,
};
use crate::error::CliError;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::ffi::OsString;
use std::io::Write;
use std::process::ExitCode;

const AFTER_HELP: &str = "\
Exit status: 0 on success; 1 only from `diff`, when the two sides differ; 2 for bad input \
(a malformed trace, scene or machine file, bad arguments, a size over a budget); 3 when an \
output could not be written; 4 for an internal error (a bug in cwisim); 130 when \
interrupted (partial outputs removed). Errors are one line on standard error: \
`error: FILE:LINE:COL: …` (text, JSON Lines) or `error: FILE: byte N: …` (binary); a usage \
error (an unknown option, a missing argument) is clap's message and the usage, several lines.";

/// The `cwisim` command line.
#[derive(Parser, Debug)]
#[command(
    name = "cwisim",
    version,
    about = "Cycle-level simulator of the CWI display architecture's X-processor array",
    long_about = "Cycle-level simulator of the CWI display architecture's X-processor array.\n\n\
`render` draws a scene end to end: the Y-processor (a renderer) scan-converts it into \
scanline instructions (Eval0…Eval3, Set…, Dis, Acc_mode, Refresh, Nop), and a simulated \
one-dimensional array of X-processors executes them; it writes the image and reports how \
many cycles each scanline took against the display's line period. `emit` writes the \
instructions as a trace instead, and `run` replays a trace on the array.\n\n\
Traces come in three lossless encodings, chosen by file extension: .cwt (text), .jsonl \
(JSON Lines) and .cwb (binary).\n\n\
Examples:\n  cwisim render                  # the embedded pot, to pot.png\n  \
cwisim emit pot -o pot.cwb     # its instructions, as a trace\n  \
cwisim run pot.cwb -o pot-replayed.png --stats",
    after_help = AFTER_HELP,
    propagate_version = true,
    arg_required_else_help = true
)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Replay a trace; write the image (PNG, NumPy) and the statistics
    #[command(
        long_about = "Replay a trace on the X-processor array; write the image it outputs and the statistics.\n\n\
The image holds one row per Refresh (scanline), all frames stacked top to bottom, one column \
per X-processor. -o writes an 8-bit PNG (1 channel grey, 3 channels RGB): each value is \
clamped to [0, 1] and mapped to round(v × 255), NaN to 0. --npy writes the exact values: \
NumPy float64, shape (scanlines, width, channels), C order, nothing clamped. Without -o or \
--npy no image is kept: the run only checks the trace and counts. Without TRACE, the \
embedded demo trace is replayed: a Gouraud-shaded, anti-aliased disc, 96 × 64, grey.\n\n\
Outputs are written only after the whole trace replayed without error; a malformed trace \
leaves no file behind — unless --keep-partial is given: the image outputs then hold the \
scanlines completed before the bad instruction, a warning says so, and the exit code is still \
2. --stats prints a summary to standard output; --stats-json writes the \
trace's dimensions, the machine, the timing model and the statistics (per scanline too) as \
JSON. Otherwise a successful run prints nothing. Instructions after the last Refresh never \
reach the output; a warning on standard error says so.\n\n\
Examples:\n  cwisim emit pot -o pot.cwt    # a trace to replay\n  \
cwisim run pot.cwt -o pot.png --npy pot.npy --set clock_hz=2e8 --stats",
        after_help = AFTER_HELP
    )]
    Run(RunArgs),

    /// Render a scene end to end: host, Y-processor, X-processor array, image and summary
    #[command(
        long_about = "Render a scene end to end and print a summary. SCENE is a JSON file (\"kind\": \"world\": \
meshes, camera, lights and materials in 3D; or \"kind\": \"screen\": polygons in pixels; see \
docs/SCENES.md) or the name of an embedded scene (`cwisim scenes` lists them); without SCENE \
the embedded pot is drawn.\n\n\
A world scene is projected, lit by the report's formula (per vertex for Gouraud shading, \
per face for flat) with back faces culled, and its hidden surfaces removed: \
--visibility exact cuts every triangle down to its visible fragments in object space (then \
every pixel holds the exact box-filtered coverage); --visibility eval0 sends whole \
triangles front to back and lets the array's Eval0 claim the pixels a nearer triangle fully \
covers (the hardware's way; edge pixels are approximate, see docs/VISIBILITY.md). The \
renderer (--renderer NAME; `cwisim renderers` lists them; the default, vanrij, is van Rij's \
Y-processor) splits the polygons into trapezia and emits the scanline instructions \
(box-filter coverage with van Rij's twelve DO_FILL cases, or point sampling; flat or \
Gouraud; or Phong on world scenes, lit at every pixel and sent through the span fitter \
within --shade-tolerance, docs/SHADING.md), and the X-processor array executes them on the \
machine model.\n\n\
The summary gives the polygons and trapezia, the instructions by opcode, the cycles per \
frame, the worst scanline against the display's line period, and the wall time of every \
stage. -o writes a PNG ([0, 1] clamped to 8 bits; the default, SCENE-NAME.png, when no other \
output is asked for), --npy the exact values (float64, shape (height, width, channels)), \
--trace the instruction stream (a .cwt trace is annotated with the DO_FILL case of every \
trapezium row). A progress bar shows on a terminal when a render takes over a second.\n\n\
Examples:\n  cwisim render\n  cwisim render still-life --size 960x640 -o still-life.png\n  \
cwisim render pot --visibility eval0 --shading flat --stats -o pot-eval0.png\n  \
cwisim render fig25 --trace fig25.cwt --npy fig25.npy",
        after_help = AFTER_HELP
    )]
    Render(RenderArgs),

    /// Scan-convert a scene into a trace file
    #[command(
        long_about = "Scan-convert a scene (a file or an embedded name; world scenes are projected, lit \
and their hidden surfaces removed first, as by `render`) into a trace of X-processor \
instructions, without executing it. The encoding is chosen by OUT's extension: .cwt (text, \
with a comment naming the DO_FILL case and stretches of every trapezium row), .jsonl or \
.cwb.\n\n\
Example:\n  cwisim emit fig25 -o fig25.cwt --shading flat --aa box",
        after_help = AFTER_HELP
    )]
    Emit(EmitArgs),

    /// List the embedded scenes, or print one as JSON
    #[command(
        long_about = "List the scenes built into cwisim, with what each shows; with NAME, print that \
scene's JSON file, to copy and edit.\n\n\
`cwisim scenes generate cp-bench` generates Barkan & Gordon's benchmark (docs/REPRODUCTION.md): \
--family convex|few|many, --polygons N, --vertices A..B, --seed S, --size WxH; what DETCR \
counts goes to stderr.\n\n\
Examples:\n  cwisim scenes\n  cwisim scenes pot > my-pot.json\n  \
cwisim scenes generate cp-bench --family few --polygons 1000 --vertices 100..=1000 --seed 1 -o few.json",
        after_help = AFTER_HELP
    )]
    Scenes(scenes::ScenesArgs),

    /// List the renderers (`--renderer NAME`), one line each
    #[command(
        long_about = "List the renderers cwisim knows: the Y-processor programs that turn a scene into \
scanline instructions for the X-processor array. Every command that draws a scene (render, \
emit, stats, tradeoff, fit) takes one with --renderer NAME; each gets threads, traces, \
statistics, cost images, tradeoff and fit through the same interface (docs/ARCHITECTURE.md).\n\n\
Examples:\n  cwisim renderers\n  cwisim render pot --renderer vanrij",
        after_help = AFTER_HELP
    )]
    Renderers(renderers::RenderersArgs),

    /// Speed against accuracy: one scene over a grid of settings, measured
    #[command(
        long_about = "Render one scene (a file or an embedded name; default the pot) over a grid of \
settings — shading flat/gouraud, anti-aliasing none/box, visibility exact/eval0 (world scenes), \
and the array's numeric formats — and measure each: instructions, bus-busy cycles per frame, \
the worst scanline against the line period, late scanlines, host wall time (median of \
--repeat runs), and the error against the exact image (the box-filtered Gouraud shading of \
the visible surfaces, computed independently of the scan converter and the array): max, \
RMS, PSNR. Settings on the Pareto front of RMS error against bus cycles are marked *.\n\n\
The settings run on --threads N threads (default 0: one per core), each setting's stream drawn \
once and executed in every format; rows are printed in the grid's order as they are measured, \
and the table and CSV are the same at any N but for the host times.\n\n\
--csv writes the table, --plot a PNG of error against cycles (log-log) with the front drawn. \
Formats: --numeric f64 --numeric f32 --numeric fixed:I=10.22,dI=4.28,ddI=1.35 … (default: f64, \
f32 and three fixed-point formats; docs/ACCURACY.md). The results are in docs/TRADEOFF.md.\n\n\
Examples:\n  cwisim tradeoff pot --csv pot.csv --plot pot-tradeoff.png\n  \
cwisim tradeoff fig25 --renderers vanrij --threads 1",
        after_help = AFTER_HELP
    )]
    Tradeoff(tradeoff::TradeoffArgs),

    /// Adaptive refinement (Bergman et al.) phase by phase: cost against error
    #[command(
        long_about = "Refine one world scene (a file or an embedded name; default the pot) in phases, \
each a complete frame through the array (Bergman, Fuchs, Grant and Spach, 1986; --renderer refine): \
(with --phases vertices,edges,… first depth-cued points and lines) flat, Gouraud for polygons whose vertex-intensity range exceeds --gouraud-threshold, Phong for \
polygons whose highlight vector is within --phong-angle degrees of the eye, and the box filter on \
pixels whose 3x3 range in the previous frame exceeds --aa-threshold (the previous frame's \
instructions re-sent around them, masked with Dis). Per phase it prints the pixels processed, instructions (total, regenerated), bus-busy \
and cumulative cycles, the worst scanline against the line period, late scanlines, RMS error \
and PSNR against the full-quality image (render --shading phong) and the display \
list's bytes against a frame buffer's; then the naive sequence, every phase's renderer in full \
(the paper's figure 1).\n\n\
--plot draws error against cumulative cycles (with the naive sequence) and busy cycles per \
scanline of each frame against the line period; --cost-image-dir writes each phase's cost image; \
--frames-png each frame; --ids the polygon-ID view (which polygon owns each pixel: false-colour .png, or the identifiers as .npy); --sweep NAME=V1,V2,… repeats the run per value of one threshold, the runs on --threads N \
threads (default 0: one per core), each run's table printed in order as it is done; a single \
run renders its frames on the N threads (as render --threads). The output is the same at any N. \
docs/RENDERERS.md (\"refine\") and docs/REPRODUCTION.md have the results.\n\n\
Example:\n  cwisim refine pot --plot quality.png --cost-image-dir costs/",
        after_help = AFTER_HELP
    )]
    Refine(refine::RefineArgs),

    /// The narrowest fixed-point registers that draw a scene within an error
    #[command(
        long_about = "Find the narrowest fixed-point formats of the array's registers (I, dI, ddI and \
the accumulator: integer and fraction bits each) whose output stays within --max-error of the \
exact image of the scene, drawn as the other options say. The scene is scan-converted once \
and the stream replayed in candidate formats: per register a binary search for the integer \
bits (no overflow) and the fraction bits, then the registers together, widened a bit at a \
time where it helps most. Prints the format (ready for --numeric), its error, the f64 \
array's own error (the floor no format can beat), and per register what one fraction bit \
fewer would cost — which register needs the bits. The candidates are replayed on --threads N \
threads (default 0: one per core; the scene's exact visibility too), tried in the same order \
at any N: the format, its figures and the count of replays are the same.\n\n\
Example:\n  cwisim fit pot --max-error 1/512",
        after_help = AFTER_HELP
    )]
    Fit(fit::FitArgs),

    /// Synthesizable Verilog of the array for a format and opcode set; co-simulation; area
    #[command(
        long_about = "Write synthesizable Verilog of the X-processor array: one processor (its registers, \
the adders of the forward-differencing chain, the stage that holds a token for a hop) and an array of \
them with the instruction bus and the display's deadlines exactly as docs/TIMING.md models them, \
generated from the opcode table and the fixed-point model, for a format (--numeric fixed:…) and the \
opcodes a trace or scene uses (--for TRACE|SCENE; all fourteen without it). With --for SCENE, \
--max-error E finds the format as `cwisim fit` does.\n\n\
--cosim icarus|verilator co-simulates the --for stream against the cycle-stepped engine (cwisim run \
--timing stepped --numeric fixed:…): every scanline bit for bit, every scanline's overflow events and \
ready cycle, and the cycle every token arrives at the watched processors (--watch); the first \
difference is printed with its scanline, processor, cycle and instruction (exit status 4). --area \
synthesizes one processor in Yosys and prints its cells, flip-flops and NAND2 estimate.\n\n\
--fpga DEVICE (ice40-hx8k, ice40-up5k, ice40-hx1k) wraps the array in an I/O shell that fits the \
package's pins (instruction words in 8-bit beats, scanline values out one a cycle) and places and \
routes it with Yosys's synth_ice40 and nextpnr-ice40: it prints the logic cells, flip-flops, carries \
and RAM blocks (the shell's apart from the array's), the maximum clock from nextpnr's timing \
analysis, how many processors of the design fit one device, and, with --for, the scene replayed at \
that clock (--set clock_hz=…) with its late scanlines. --fpga-processors P places P processors of \
the design (the whole width rarely fits); a design too large says so with the cells it needs. The \
tools are Debian's iverilog, verilator, yosys, nextpnr-ice40 and fpga-icestorm \
(crates/rtl/tools/install-hdl.sh installs them). The Verilog is the same byte for byte for the same \
settings. docs/HARDWARE.md describes the design.\n\n\
Examples:\n  cwisim rtl --numeric fixed:I=12.20,dI=4.28,ddI=1.36 --width 64 -o xproc.v --area\n  \
cwisim rtl --for traces/gouraud.cwt --numeric fixed:I=8.24,dI=4.28,ddI=2.30 -o g.v --cosim icarus\n  \
cwisim rtl --for pot --max-error 1/512 -o pot_xproc.v --area\n  \
cwisim rtl --for traces/gouraud.cwt --numeric fixed:I=2.15,dI=1.16,ddI=1.16,acc=2.12 -o g.v --fpga ice40-up5k",
        after_help = AFTER_HELP
    )]
    Rtl(rtl::RtlArgs),

    /// Per-scanline statistics of a trace or scene: table, plot, CSV, JSON
    #[command(
        long_about = "Per-scanline statistics of a trace (.cwt, .jsonl, .cwb, replayed as by `run`), or of \
a scene file (.json, rendered first as by `render`: Gouraud, box filter, exact visibility): instructions by \
opcode, bus (busy) and stall cycles, processor updates, and when each scanline was ready \
against the display's deadline; negative slack is an overrun, marked LATE. Prints the table \
(a column per opcode that occurs) and a totals line for the selected scanlines.\n\n\
--lines keeps some scanlines (N, A..B with B not included, A..=B or A.., counted from 0 over the whole trace). --plot \
draws a PNG: one bar per scanline, its bus cycles stacked by opcode group (count × the \
opcode's issue cost) with the stall cycles on top, the line period as a horizontal line, a \
red marker on every overrun. --csv writes the table with a column for each of the 14 \
opcodes; --stats-json the selected scanlines' records, their sums, each opcode's issue cost and \
the run's totals.\n\n\
Example:\n  cwisim stats traces/overrun.cwt --machine traces/overrun.machine.json --plot overrun.png",
        after_help = AFTER_HELP
    )]
    Stats(stats::StatsArgs),

    /// Every instruction that reached one processor on one scanline, with its registers
    #[command(
        long_about = "Pixel history: every instruction whose token reached processor X on scanline Y, \
in order, with the cycle it arrived and the processor's registers and flags just before and \
just after it acted (values as at that moment, from the cycle-stepped model).\n\n\
Example:\n  cwisim history traces/visibility.cwt --x 9 --line 0",
        after_help = AFTER_HELP
    )]
    History(history::HistoryArgs),

    /// Frames as one self-contained HTML page to explore in a browser (A/B: two runs)
    #[command(
        long_about = "Write one self-contained HTML page (no network: it opens from disk) of one \
frame or a range of them (--frames A..B, at most 64): the image, zoomable to single pixels, every \
channel's value on hover, with overlays of the cost image, the error against the exact reference \
(scenes; coloured from a floor of 1e-12, so rounding shows nothing) and the late scanlines; the \
scanline timeline (bus cycles by opcode against the line period, as `cwisim stats`) where a click \
shows the scanline's disassembly (as `cwisim dump`) and its events cycle by cycle (which \
processor each token reaches when); and a click on a pixel shows its history (as `cwisim \
history`, with the command that repeats it; with --numeric fixed:…, the raw registers too). \
Everything is computed by the cycle-stepped model. --against \"B [FLAGS]\" makes an A/B page of \
two runs of the same dimensions (a trace or a scene with its own flags), with an A − B overlay. \
Frames over 512×512 pixels hold histories for a window only (--x, --lines; the middle 256×256 by \
default); over 2048×2048 pixels in all they are refused.\n\n\
The page keeps its place in its address: `page.html#pixel=150,200` selects processor 150 on \
scanline 200, `#line=200` a scanline, `#frame=2` a frame, `#run=b` the B run; a click updates \
it and the back button returns.\n\n\
Examples:\n  cwisim inspect pot -o pot.html\n  cwisim inspect pot -o ab.html --against \"pot --aa none\"",
        after_help = AFTER_HELP
    )]
    Inspect(inspect::InspectArgs),

    /// A per-cycle waveform (VCD) of one scanline's processors and instruction bus
    #[command(
        long_about = "Write a Value Change Dump of one scanline: the chosen processors' registers and \
flags and the instruction bus (opcode and operands), cycle by cycle, for GTKWave, Surfer or \
any VCD viewer. The cycle-stepped model is replayed; the dump runs from the cycle the bus \
starts issuing the scanline's first instruction to the cycle the scanline leaves the array. \
Time stamps are absolute cycles: one time unit (written 1 ns) is one array clock cycle.\n\n\
Scope bus: opcode (8-bit code, 0 when idle), x and dx (32-bit, z when idle or not an operand), \
I, dI, ddI (real, 0 when absent), index (32-bit instruction number), busy (1 while issuing). \
Scope pN for each processor N of the window: acc, I, dI, ddI (real), has_I, has_dI, has_ddI, \
locked, masked, neg (1-bit), out (real: what N shifts out when this scanline's Refresh passes, \
0 before), token (32-bit: the instruction whose token is in N, z when none). With several \
channels each real is one per channel: I_c0, I_c1, … Tokens of other scanlines passing \
through are included.\n\n\
--x keeps a window of processors and the file small: N, A..B (B not included), A..=B or A.. \
(to the last). Without it, an array of at most 512 processors is dumped whole and a wider one \
is refused. The file is written only when the replay succeeded, and is the same byte for byte \
on every run.\n\n\
Examples:\n  cwisim vcd traces/gouraud.cwt --line 1 --x 2..=8 -o line1.vcd\n  \
cwisim vcd pot --line 200 -o l.vcd",
        after_help = AFTER_HELP
    )]
    Vcd(vcd::VcdArgs),

    /// Compare two traces or two outputs; exit 0 when equal, 1 when different
    #[command(
        long_about = "Compare two traces (the first differing scanline and instruction, and the count \
of each opcode on each side) or two outputs (.npy files, or traces replayed: per-scanline \
max and RMS difference, and --image for an error image). Exit status 0 when equal, 1 when \
different, 2 on bad input, 3 when the report or --image could not be written, so it serves in \
scripts.\n\n\
Examples:\n  cwisim diff a.cwt b.cwb --outputs\n  cwisim diff a.npy b.npy --image diff.png",
        after_help = AFTER_HELP
    )]
    Diff(diff::DiffArgs),

    /// Disassemble a trace with scanline and cycle annotations
    #[command(
        long_about = "Print a trace (any encoding) in the text form, each instruction annotated with \
its number, its scanline, the cycle the bus started issuing it and the cycle it entered \
the array. --lines keeps only some scanlines.\n\n\
Example:\n  cwisim dump trace.cwb --lines 10..13",
        after_help = AFTER_HELP
    )]
    Dump(dump::DumpArgs),

    /// Convert a trace between the .cwt, .jsonl and .cwb encodings
    #[command(
        long_about = "Convert a trace between encodings, chosen by each file's extension: .cwt (text), \
.jsonl (JSON Lines), .cwb (binary). Instructions are streamed one at a time and checked on the way; \
values are copied bit-exactly, so any chain of conversions gives back the same trace. \
The notes of the instructions (where each came from: the comment lines directly above an \
instruction of a .cwt, \"note\" in a .jsonl) are kept when OUT is .cwt or .jsonl (.cwb has no place \
for them); other comments are not (the output is the canonical form). IN and OUT must \
be different files; OUT is replaced only once the whole input converted without error.\n\n\
Examples:\n  cwisim emit pot -o pot.cwt    # a trace to convert\n  \
cwisim convert pot.cwt -o pot.cwb\n  cwisim convert pot.cwt pot.jsonl",
        after_help = AFTER_HELP
    )]
    Convert(ConvertArgs),

    /// Print the effective machine model as JSON (a starting point for --machine files)
    #[command(
        long_about = "Print the effective machine model — the defaults, or --machine, then each --set — \
as pretty JSON on standard output, ready to be saved and edited as a --machine file. One line \
on standard error gives the line period and the traversal time it implies for a trace of \
the given dimensions (--width, --height, --channels).\n\n\
Example:\n  cwisim machine --set clock_hz=2e8 --height 768 > fast.json",
        after_help = AFTER_HELP
    )]
    Machine(MachineCmdArgs),
}

/// Runs `cwisim` with `args` (program name first, like [`std::env::args_os`]), writing
/// to `stdout` and `stderr`, and returns the exit code ([`crate::error`]'s constants: 0 on
/// success, 1 only for `diff`'s "different", 2 for bad input or usage, 3 when an output
/// could not be written, 4 for an internal error).
///
/// `--help` and `--version` go to `stdout` (exit 0); usage errors to `stderr` (exit 2).
/// Every other error is one line, `error: <message>`, on `stderr`.
pub fn run_cli(
    args: impl IntoIterator<Item = OsString>,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> u8 {
    run_cli_with(args, stdout, stderr, true)
}

/// [`run_cli`], choosing whether `run` may show its progress bar (it also needs standard
/// error to be a terminal and the run to take over a second).
pub fn run_cli_with(
    args: impl IntoIterator<Item = OsString>,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
    progress: bool,
) -> u8 {
    let cli = match parse(args) {
        Ok(cli) => cli,
        Err(e) => {
            let text = e.render().to_string();
            if e.use_stderr() {
                let _ = stderr.write_all(text.as_bytes());
                let _ = stderr.flush();
                return u8::try_from(e.exit_code()).unwrap_or(crate::error::EXIT_BAD_INPUT);
            }
            // --help and --version: a closed pipe is fine, a full disk is a failure
            return match stdout
                .write_all(text.as_bytes())
                .and_then(|()| stdout.flush())
            {
                Ok(()) => 0,
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => 0,
                Err(e) => {
                    let _ = writeln!(stderr, "error: {}", CliError::Stdout(e).one_line());
                    crate::error::EXIT_WRITE_FAILED
                }
            };
        }
    };
    let result = crate::files::transaction(|| {
        // a budget variable that is not a size is refused before any work
        cwisim_scene::budget::Budget::from_env()?;
        let code = dispatch(&cli.command, stdout, stderr, progress)?;
        // what is still buffered: a reader gone keeps the command's code (`diff`'s 1)
        match stdout.flush() {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(CliError::Stdout(e)),
            _ => Ok(code),
        }
    });
    match result {
        Ok(code) => code,
        // The reader went away (`cwisim dump t.cwb | head`): nothing more to say.
        Err(CliError::Stdout(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => 0,
        Err(e) => {
            let _ = writeln!(stderr, "error: {}", e.one_line());
            let _ = stderr.flush();
            e.exit_code()
        }
    }
}

impl Command {
    /// Its drawing flags, if it draws a scene.
    fn draw_mut(&mut self) -> Option<&mut crate::draw::DrawArgs> {
        match self {
            Command::Run(a) => Some(&mut a.draw),
            Command::Render(a) => Some(&mut a.draw),
            Command::Emit(a) => Some(&mut a.draw),
            Command::Fit(a) => Some(&mut a.draw),
            Command::Stats(a) => Some(&mut a.draw),
            Command::History(a) => Some(&mut a.draw),
            Command::Inspect(a) => Some(&mut a.draw),
            Command::Vcd(a) => Some(&mut a.draw),
            Command::Rtl(a) => Some(&mut a.draw),
            Command::Diff(a) => Some(&mut a.draw),
            Command::Dump(a) => Some(&mut a.draw),
            Command::Scenes(_)
            | Command::Renderers(_)
            | Command::Tradeoff(_)
            | Command::Refine(_)
            | Command::Convert(_)
            | Command::Machine(_) => None,
        }
    }
}

/// Parses the command line, noting which drawing flags it gave
/// ([`crate::draw::DrawArgs::note_given`]): clap's derive keeps only the values.
pub fn parse(args: impl IntoIterator<Item = OsString>) -> Result<Cli, clap::Error> {
    let matches = Cli::command().try_get_matches_from(args)?;
    let mut cli = Cli::from_arg_matches(&matches).map_err(|e| e.format(&mut Cli::command()))?;
    if let (Some(draw), Some((_, sub))) = (cli.command.draw_mut(), matches.subcommand()) {
        draw.note_given(sub);
    }
    Ok(cli)
}

/// Standard output for a command whose exit code is its answer (`diff`): when the reader
/// goes away (`cwisim diff a b | head -1`) the rest of the report is dropped and the
/// command still finishes, so its code says "different" even under `pipefail`. Any other
/// write error still fails.
struct ReaderMayLeave<'a> {
    inner: &'a mut dyn Write,
    gone: bool,
}

impl<'a> ReaderMayLeave<'a> {
    fn new(inner: &'a mut dyn Write) -> Self {
        ReaderMayLeave { inner, gone: false }
    }

    fn guard<T>(&mut self, done: T, r: std::io::Result<T>) -> std::io::Result<T> {
        match r {
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
                self.gone = true;
                Ok(done)
            }
            other => other,
        }
    }
}

impl Write for ReaderMayLeave<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.gone {
            return Ok(buf.len());
        }
        let r = self.inner.write(buf);
        self.guard(buf.len(), r)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if self.gone {
            return Ok(());
        }
        let r = self.inner.flush();
        self.guard((), r)
    }
}

fn dispatch(
    command: &Command,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
    progress: bool,
) -> Result<u8, CliError> {
    match command {
        Command::Run(args) => run::run(args, stdout, stderr, progress).map(|()| 0),
        Command::Convert(args) => convert::run(args, stdout, stderr).map(|_| 0),
        Command::Machine(args) => machine::run(args, stdout, stderr).map(|()| 0),
        Command::Render(args) => scene::run_render(args, stdout, progress).map(|()| 0),
        Command::Scenes(args) => scenes::run(args, stdout, stderr).map(|()| 0),
        Command::Renderers(args) => renderers::run(args, stdout).map(|()| 0),
        Command::Tradeoff(args) => tradeoff::run(args, stdout, progress).map(|()| 0),
        Command::Refine(args) => refine::run(args, stdout, progress).map(|()| 0),
        Command::Fit(args) => fit::run(args, stdout, progress).map(|()| 0),
        Command::Rtl(args) => rtl::run(args, stdout, progress).map(|()| 0),
        Command::Emit(args) => scene::run_emit(args, stdout).map(|()| 0),
        Command::Stats(args) => stats::run(args, stdout, stderr).map(|()| 0),
        Command::History(args) => history::run(args, stdout, progress).map(|()| 0),
        Command::Inspect(args) => inspect::run(args, stdout, progress).map(|()| 0),
        Command::Vcd(args) => vcd::run(args, progress).map(|()| 0),
        // equal: 0, different: 1, even when the reader of the report went away
        Command::Diff(args) => diff::run(args, &mut ReaderMayLeave::new(stdout)).map(|equal| {
            if equal {
                0
            } else {
                crate::error::EXIT_DIFFERENT
            }
        }),
        Command::Dump(args) => dump::run(args, stdout, progress).map(|()| 0),
    }
}

/// The `cwisim` program: [`run_cli`] on the process's arguments and standard streams.
pub fn main() -> ExitCode {
    crate::files::install_interrupt_cleanup();
    let code = run_cli(
        std::env::args_os(),
        &mut std::io::stdout(),
        &mut std::io::stderr(),
    );
    ExitCode::from(code)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cli(args: &[&str]) -> (u8, String, String) {
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let argv = std::iter::once("cwisim")
            .chain(args.iter().copied())
            .map(OsString::from);
        let code = run_cli_with(argv, &mut out, &mut err, false);
        (
            code,
            String::from_utf8_lossy(&out).into_owned(),
            String::from_utf8_lossy(&err).into_owned(),
        )
    }

    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn help_goes_to_stdout_with_exit_0() {
        for args in [
            &["--help"][..],
            &["run", "--help"],
            &["convert", "--help"],
            &["machine", "--help"],
        ] {
            let (code, out, err) = cli(args);
            assert_eq!(code, 0, "{args:?}");
            assert!(out.contains("Usage: cwisim"), "{args:?}: {out}");
            assert!(out.contains("Example"), "{args:?}: {out}");
            assert!(err.is_empty());
        }
        let (code, out, _) = cli(&["--version"]);
        assert_eq!(code, 0);
        assert!(out.starts_with("cwisim "), "{out}");
    }

    #[test]
    fn run_help_documents_the_png_mapping_and_npy_layout() {
        // Help is wrapped to the terminal's width; compare with whitespace collapsed.
        let flat = |s: String| s.split_whitespace().collect::<Vec<_>>().join(" ");
        let out = flat(cli(&["run", "--help"]).1);
        assert!(out.contains("clamped to [0, 1]"), "{out}");
        assert!(out.contains("round(v × 255)"), "{out}");
        assert!(out.contains("shape (scanlines, width, channels)"), "{out}");
        let out = flat(cli(&["convert", "--help"]).1);
        assert!(
            out.contains("are kept when OUT is .cwt or .jsonl")
                && out.contains("other comments are not"),
            "{out}"
        );
    }

    #[test]
    fn usage_errors_exit_2_on_stderr() {
        for args in [
            &[][..],
            &["frobnicate"],
            &["run", "a.cwt", "b.cwt"],
            &["run", "t.cwt", "--timing", "slow"],
            &["convert", "a.cwt"],
        ] {
            let (code, out, err) = cli(args);
            assert_eq!(code, 2, "{args:?}");
            assert!(out.is_empty(), "{args:?}: {out}");
            assert!(!err.is_empty(), "{args:?}");
        }
    }

    #[test]
    fn command_errors_are_one_line() {
        let (code, out, err) = cli(&["run", "does-not-exist.cwt"]);
        assert_eq!(code, 2);
        assert!(out.is_empty());
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error: does-not-exist.cwt: cannot open"),
            "{err}"
        );
        let (code, _, err) = cli(&["machine", "--width", "0"]);
        assert_eq!(code, 2);
        assert!(
            err.starts_with("error: --width/--height/--channels: width 0"),
            "{err}"
        );
    }
}
