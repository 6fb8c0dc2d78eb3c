//! The `cwisim` command line: argument parsing, dispatch, and how errors are shown.
//!
//! [`run_cli`] is the whole program on any output streams, so tests can run it
//! in-process; [`main`] calls it with the real ones.

use crate::commands::convert::ConvertArgs;
use crate::commands::machine::MachineCmdArgs;
use crate::commands::run::RunArgs;
use crate::commands::scene::{EmitArgs, RenderArgs};
use crate::commands::{convert, machine, run, scene};
use crate::error::CliError;
use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::io::Write;
use std::process::ExitCode;

const AFTER_HELP: &str = "\
Exit status: 0 on success, 2 for a malformed trace or machine file or bad arguments, \
1 when an output could not be written. Errors are one line on standard error: \
`error: FILE:LINE:COL: …` (text, JSON Lines) or `error: FILE: byte N: …` (binary).";

/// The `cwisim` command line.
#[derive(Parser, Debug)]
#[command(
    name = "cwisim",
    version,
    about = "Cycle-level simulator of the CWI display architecture's X-processor array",
    long_about = "Cycle-level simulator of the CWI display architecture's X-processor array.\n\n\
Replays traces of scanline instructions (Eval0…Eval3, Set…, Dis, Acc_mode, Refresh, Nop) on a \
simulated one-dimensional array of X-processors, and reports the image it outputs and how \
many cycles it took against the display's line period.\n\n\
Traces come in three lossless encodings, chosen by file extension: .cwt (text), .jsonl \
(JSON Lines) and .cwb (binary).\n\n\
Example:\n  cwisim run scene.cwb -o scene.png --stats",
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
leaves no file behind. --stats prints a summary to standard output; --stats-json writes the \
trace's dimensions, the machine, the timing model and the statistics (per scanline too) as \
JSON. Otherwise a successful run prints nothing. Instructions after the last Refresh never \
reach the output; a warning on standard error says so.\n\n\
Example:\n  cwisim run scene.cwt -o scene.png --npy scene.npy --set clock_hz=2e8 --stats",
        after_help = AFTER_HELP
    )]
    Run(RunArgs),

    /// Render a screen-space scene: Y-processor, trace, X-processor array, image
    #[command(
        long_about = "Render a screen-space scene (JSON, \"kind\": \"screen\"; see docs/SCENES.md): the \
Y-processor splits its polygons into trapezia and emits the scanline instructions (box-filter \
coverage with van Rij's twelve DO_FILL cases, or point sampling; flat or Gouraud), and the \
X-processor array executes them. -o writes a PNG ([0, 1] clamped to 8 bits), --npy the exact \
values (float64, shape (height, width, channels)), --trace the instruction stream (a .cwt \
trace is annotated with the DO_FILL case of every trapezium row).\n\n\
Example:\n  cwisim render scene.json -o scene.png --trace scene.cwt --stats",
        after_help = AFTER_HELP
    )]
    Render(RenderArgs),

    /// Scan-convert a screen-space scene into a trace file
    #[command(
        long_about = "Scan-convert a screen-space scene into a trace of X-processor instructions, \
without executing it. The encoding is chosen by OUT's extension: .cwt (text, with a comment \
naming the DO_FILL case and stretches of every trapezium row), .jsonl or .cwb.\n\n\
Example:\n  cwisim emit scene.json -o scene.cwt --shading flat --aa box",
        after_help = AFTER_HELP
    )]
    Emit(EmitArgs),

    /// Convert a trace between the .cwt, .jsonl and .cwb encodings
    #[command(
        long_about = "Convert a trace between encodings, chosen by each file's extension: .cwt (text), \
.jsonl (JSON Lines), .cwb (binary). Instructions are streamed one at a time and checked on the way; \
values are copied bit-exactly, so any chain of conversions gives back the same trace. \
Comments of a .cwt input are not kept (the output is the canonical form). IN and OUT must \
be different files; OUT is replaced only once the whole input converted without error.\n\n\
Example:\n  cwisim convert scene.cwt scene.cwb",
        after_help = AFTER_HELP
    )]
    Convert(ConvertArgs),

    /// Print the effective machine model as JSON (a starting point for --machine files)
    #[command(
        long_about = "Print the effective machine model — the defaults, or --machine, then each --set — \
as pretty JSON on standard output, ready to be saved and edited as a --machine file. One line \
on standard error gives the line period and the traversal time it implies for a trace of \
the given dimensions (--width, --lines, --channels).\n\n\
Example:\n  cwisim machine --set clock_hz=2e8 --lines 768 > fast.json",
        after_help = AFTER_HELP
    )]
    Machine(MachineCmdArgs),
}

/// Runs `cwisim` with `args` (program name first, like [`std::env::args_os`]), writing
/// to `stdout` and `stderr`, and returns the exit code: 0 on success, 2 for bad input or
/// usage, 1 when an output could not be written.
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
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let text = e.render().to_string();
            let stream: &mut dyn Write = if e.use_stderr() {
                &mut *stderr
            } else {
                &mut *stdout
            };
            let _ = stream.write_all(text.as_bytes());
            let _ = stream.flush();
            return u8::try_from(e.exit_code()).unwrap_or(crate::error::EXIT_BAD_INPUT);
        }
    };
    match dispatch(&cli.command, stdout, stderr, progress) {
        Ok(()) => 0,
        Err(e) => {
            let _ = writeln!(stderr, "error: {}", e.one_line());
            let _ = stderr.flush();
            e.exit_code()
        }
    }
}

fn dispatch(
    command: &Command,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
    progress: bool,
) -> Result<(), CliError> {
    match command {
        Command::Run(args) => run::run(args, stdout, stderr, progress),
        Command::Convert(args) => convert::run(args).map(|_| ()),
        Command::Render(args) => scene::run_render(args, stdout),
        Command::Emit(args) => scene::run_emit(args),
        Command::Machine(args) => machine::run(args, stdout, stderr),
    }
}

/// The `cwisim` program: [`run_cli`] on the process's arguments and standard streams.
pub fn main() -> ExitCode {
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
    use clap::CommandFactory;

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
            assert!(out.contains("Example:"), "{args:?}: {out}");
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
            out.contains("Comments of a .cwt input are not kept"),
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
            err.starts_with("error: --width/--lines/--channels: width 0"),
            "{err}"
        );
    }
}
