//! `cwisim rtl`'s tools die with it and leave no temporary directory: SIGTERM during a
//! co-simulation stops the simulator too; a missing tool is refused before anything is
//! written; a simulator that writes nothing is said so (not "cannot write"), its files
//! removed. Needs Icarus Verilog (skipped only with `CWISIM_SKIP_HDL_TESTS=1`;
//! `crates/rtl/tools/install-hdl.sh` installs it).

mod common;

use common::{scratch, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const FORMAT: &str = "fixed:I=8.24,dI=4.28,ddI=2.30";

fn skipped() -> bool {
    let skip = std::env::var("CWISIM_SKIP_HDL_TESTS").is_ok_and(|v| v == "1");
    if skip {
        eprintln!("SKIPPED: rtl's children (CWISIM_SKIP_HDL_TESTS=1)");
    }
    skip
}

/// `cwisim rtl ARGS` in `dir`, its temporary directory `tmp`, its PATH `path` if given.
fn rtl(dir: &Path, tmp: &Path, path: Option<&str>, args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cwisim"));
    c.arg("rtl").args(args).current_dir(dir).env("TMPDIR", tmp);
    if let Some(p) = path {
        c.env("PATH", p);
    }
    c
}

/// `cwisim rtl --for traces/gouraud.cwt --numeric FORMAT --cosim icarus -o x.v EXTRA…`,
/// run to its end (see [`rtl`]).
fn cosim_gouraud(
    dir: &Path,
    tmp: &Path,
    path: Option<&str>,
    extra: &[&str],
) -> std::process::Output {
    let gouraud = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../traces/gouraud.cwt");
    let mut args = vec![
        "--for",
        gouraud.to_str().unwrap(),
        "--numeric",
        FORMAT,
        "--cosim",
        "icarus",
        "-o",
        "x.v",
    ];
    args.extend_from_slice(extra);
    rtl(dir, tmp, path, &args).output().unwrap()
}

/// The names in `dir`.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The processes whose parent is `pid` (from /proc).
fn children_of(pid: u32) -> Vec<u32> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(p) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(format!("/proc/{p}/stat")) else {
            continue;
        };
        // pid (comm) state ppid …: comm may hold spaces, so read after the last ')'
        let after = &stat[stat.rfind(')').map_or(0, |i| i + 1)..];
        let ppid = after.split_whitespace().nth(1).and_then(|s| s.parse().ok());
        if ppid == Some(pid) {
            found.push(p);
        }
    }
    found
}

fn alive(pid: u32) -> bool {
    // a zombie is gone for our purposes: it runs nothing
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|s| {
        !s[s.rfind(')').map_or(0, |i| i + 1)..]
            .trim_start()
            .starts_with('Z')
    })
}

/// A long trace: 600 scanlines of a 64-wide array, every idle cycle simulated.
fn long_trace(dir: &Path) -> PathBuf {
    let mut t = String::from("cwisim-trace version=1 width=64 lines=600 channels=1\n");
    for k in 0..600 {
        t.push_str(&format!(
            "Eval2 0 64 {} 0.001\nRefresh\n",
            f64::from(k) * 1e-3
        ));
    }
    let p = dir.join("long.cwt");
    std::fs::write(&p, t).unwrap();
    p
}

#[test]
fn sigterm_during_a_cosimulation_stops_the_simulator_and_removes_its_files() {
    if skipped() {
        return;
    }
    let dir = scratch("rtl-children-sigterm");
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    long_trace(&dir);
    let mut child = rtl(
        &dir,
        &tmp,
        None,
        &[
            "--for",
            "long.cwt",
            "--numeric",
            FORMAT,
            "--cosim",
            "icarus",
            "-o",
            "x.v",
        ],
    )
    .stdout(Stdio::null())
    .stderr(Stdio::piped())
    .spawn()
    .unwrap();
    // wait for a tool to run under it
    let start = Instant::now();
    let tools = loop {
        let c = children_of(child.id());
        if !c.is_empty() {
            break c;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "the co-simulation ended before a tool was seen"
        );
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no tool started"
        );
        std::thread::sleep(Duration::from_millis(10));
    };
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{:?}", text(&out));
    // the tools are gone too (killed with their process group), soon
    let start = Instant::now();
    while tools.iter().any(|&t| alive(t)) {
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "a tool outlived the command: {tools:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(names(&tmp).is_empty(), "left behind: {:?}", names(&tmp));
    assert!(!dir.join("x.v").exists());
}

#[test]
fn a_missing_tool_is_refused_before_anything_is_written() {
    let dir = scratch("rtl-children-missing");
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    std::fs::write(dir.join("x.v"), b"old").unwrap();
    for (flag, tool) in [("--cosim", "iverilog"), ("--area", "yosys")] {
        let mut args = vec!["--for", "long.cwt", "--numeric", FORMAT, "-o", "x.v"];
        long_trace(&dir);
        match flag {
            "--cosim" => args.extend(["--cosim", "icarus"]),
            _ => args.push("--area"),
        }
        let out = rtl(&dir, &tmp, Some("/nonexistent"), &args)
            .output()
            .unwrap();
        let (stdout, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains(&format!("`{tool}` was not found")),
            "{stderr}"
        );
        assert!(stderr.contains("install-hdl.sh"), "{stderr}");
        assert!(!stdout.contains("wrote"), "{stdout}");
        assert_eq!(std::fs::read(dir.join("x.v")).unwrap(), b"old");
        assert!(names(&tmp).is_empty(), "left behind: {:?}", names(&tmp));
    }
}

#[test]
fn a_simulator_that_writes_nothing_is_said_so_and_its_files_removed() {
    if skipped() {
        return;
    }
    let dir = scratch("rtl-children-silent");
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    // the real iverilog, and a vvp that runs nothing
    let bin = dir.join("bin");
    std::fs::create_dir(&bin).unwrap();
    let iverilog = cwisim_rtl::tools::find("iverilog").expect("iverilog (install-hdl.sh)");
    std::os::unix::fs::symlink(iverilog, bin.join("iverilog")).unwrap();
    std::fs::write(bin.join("vvp"), "#!/bin/sh\nexit 0\n").unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(bin.join("vvp"), std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = cosim_gouraud(&dir, &tmp, Some(&path), &[]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(4), "{stderr}");
    assert!(
        stderr.contains("icarus ran but left no readable"),
        "{stderr}"
    );
    assert!(!stderr.contains("cannot write"), "{stderr}");
    assert!(names(&tmp).is_empty(), "left behind: {:?}", names(&tmp));
}

#[test]
fn a_cosimulation_past_the_cycle_limit_is_refused_before_it_starts() {
    if skipped() {
        return;
    }
    let dir = scratch("rtl-children-cycles");
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let start = Instant::now();
    let out = cosim_gouraud(&dir, &tmp, None, &["--set", "clock_hz=1e12"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("the co-simulation would run 1633986942 cycles")
            && stderr.contains("over the limit of 200000000"),
        "{stderr}"
    );
    assert!(start.elapsed() < Duration::from_secs(60));
    assert!(!stdout.contains("wrote"), "{stdout}");
    assert!(!dir.join("x.v").exists());
    assert!(names(&tmp).is_empty(), "left behind: {:?}", names(&tmp));
}
