//! Running the HDL tools: Icarus Verilog (`iverilog`, `vvp`), Verilator and Yosys, from
//! the PATH (Debian's packages, installed by `crates/rtl/tools/install-hdl.sh`).

use crate::error::RtlError;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// The process groups of the tools running now (each tool is started as the leader of a
/// group of its own, so that what it starts — Verilator's make and compilers — is in it):
/// what [`stop_children`] kills.
static RUNNING: Mutex<Vec<u32>> = Mutex::new(Vec::new());

/// Set by [`stop_children`]: the command is being interrupted, and the tools it kills die
/// of that, not of a fault.
static STOPPING: AtomicBool = AtomicBool::new(false);

/// Runs `command` to its end, as the leader of a new process group registered in
/// [`RUNNING`] while it runs; its output.
fn output_of(command: &mut Command) -> std::io::Result<Output> {
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(command, 0);
    let child = command
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()?;
    let pid = child.id();
    if let Ok(mut running) = RUNNING.lock() {
        running.push(pid);
    }
    let out = child.wait_with_output();
    if let Ok(mut running) = RUNNING.lock() {
        running.retain(|&p| p != pid);
    }
    if STOPPING.load(Ordering::SeqCst) {
        // killed by `stop_children`: the interrupting thread ends the process (its own
        // exit status and message); reporting the tool's death as a failure would race it
        loop {
            std::thread::park();
        }
    }
    out
}

/// Kills every tool running now, with whatever it started (its process group): for a
/// command interrupted by a signal, so that no simulator or synthesizer outlives it.
/// Safe to call from a signal handler's thread; does nothing when none runs.
/// A thread whose tool is killed so waits for the process to end rather than report it.
pub fn stop_children() {
    STOPPING.store(true, Ordering::SeqCst);
    let Ok(running) = RUNNING.lock() else {
        return;
    };
    for &pid in running.iter() {
        #[cfg(unix)]
        if let Ok(group) = libc::pid_t::try_from(pid) {
            // SAFETY: kill(2) takes any pid and signal number and touches no memory of
            // ours; a group already gone gives ESRCH, which is ignored
            unsafe {
                libc::kill(-group, libc::SIGKILL);
            }
        }
    }
}

/// How many tools run now (for tests).
pub fn running_children() -> usize {
    RUNNING.lock().map_or(0, |r| r.len())
}

/// The project's script that installs the tools.
pub const INSTALL_SCRIPT: &str = "crates/rtl/tools/install-hdl.sh";

/// `name` on the PATH, if there.
pub fn find(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join(name))
            .find(|p| p.is_file())
    })
}

/// `name` on the PATH, or [`RtlError::ToolMissing`].
pub fn require(name: &str) -> Result<PathBuf, RtlError> {
    find(name).ok_or_else(|| RtlError::ToolMissing { tool: name.into() })
}

/// Runs `program args…` in `dir` (its temporary directory too), as the leader of a process
/// group of its own ([`stop_children`] kills it); its standard output, or
/// [`RtlError::ToolFailed`] with the first lines of what it printed.
pub fn run(program: &str, args: &[&str], dir: &Path) -> Result<String, RtlError> {
    let bin = if program.contains('/') {
        PathBuf::from(program)
    } else {
        require(program)?
    };
    let command = format!("{program} {}", args.join(" "));
    // the tool's own temporaries (iverilog's) in `dir` too: removed with it, even when
    // the tool is killed before it could remove them
    let out = output_of(
        Command::new(&bin)
            .args(args)
            .current_dir(dir)
            .env("TMPDIR", dir),
    )
    .map_err(|e| RtlError::ToolFailed {
        command: command.clone(),
        status: "not started".into(),
        output: e.to_string(),
    })?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if !out.status.success() {
        let text: Vec<&str> = stderr.lines().chain(stdout.lines()).take(12).collect();
        return Err(RtlError::ToolFailed {
            command,
            status: out.status.to_string(),
            output: text.join(" | "),
        });
    }
    Ok(format!("{stdout}{stderr}"))
}

/// Verilator's lint of a design file: `verilator --lint-only -Wall`, the warnings it
/// printed (none is clean).
pub fn lint(design: &Path, top: &str) -> Result<Vec<String>, RtlError> {
    let dir = design.parent().unwrap_or(Path::new("."));
    let file = design
        .file_name()
        .and_then(|f| f.to_str())
        .unwrap_or("design.v");
    let bin = require("verilator")?;
    let out = output_of(
        Command::new(&bin)
            .args(["--lint-only", "-Wall", "--top-module", top, file])
            .current_dir(dir),
    )
    .map_err(|e| RtlError::io(bin.clone(), e))?;
    let text = String::from_utf8_lossy(&out.stderr).into_owned();
    let warnings: Vec<String> = text
        .lines()
        .filter(|l| l.starts_with("%Warning") || l.starts_with("%Error"))
        .map(str::to_string)
        .collect();
    if !out.status.success() && warnings.is_empty() {
        return Err(RtlError::ToolFailed {
            command: format!("verilator --lint-only -Wall --top-module {top} {file}"),
            status: out.status.to_string(),
            output: text.lines().take(12).collect::<Vec<_>>().join(" | "),
        });
    }
    Ok(warnings)
}

/// Writes `text` to `path`, an error naming the file.
pub(crate) fn write_file(path: &Path, text: &str) -> Result<(), RtlError> {
    std::fs::write(path, text).map_err(|e| RtlError::io(path, e))
}
