//! `cwisim rtl`: the Verilog is written all or nothing and is the same byte for byte for
//! the same settings; bad settings are one-line errors; a trace's design co-simulates in
//! Icarus Verilog identically to the stepped engine (needs iverilog: skipped only with
//! `CWISIM_SKIP_HDL_TESTS=1`; `crates/rtl/tools/install-hdl.sh` installs it).

mod common;

use common::{cwisim, cwisim_ok, read, scratch, text, trace};

const FORMAT: &str = "fixed:I=8.24,dI=4.28,ddI=2.30";

#[test]
fn the_verilog_is_deterministic_and_follows_the_settings() {
    let dir = scratch("rtl-deterministic");
    let args = [
        "rtl",
        "--numeric",
        FORMAT,
        "--width",
        "12",
        "--channels",
        "3",
        "-o",
    ];
    let out = cwisim_ok(&dir, &[&args[..], &["a.v"]].concat());
    assert!(out.contains("width 12; 3 channel(s)"), "{out}");
    cwisim_ok(&dir, &[&args[..], &["b.v"]].concat());
    let (a, b) = (read(dir.join("a.v")), read(dir.join("b.v")));
    assert_eq!(a, b);
    let text = String::from_utf8(a).unwrap();
    assert!(text.contains("module cwisim_xproc ("), "{text}");
    assert!(text.contains("module cwisim_array ("));
    assert!(text.contains("// format:   fixed:I=8.24,dI=4.28,ddI=2.30,acc=8.24,overflow=saturate"));
    // all fourteen opcodes without --for
    assert!(text.contains("localparam [3:0] OP_SETPDDI = 4'd6;"));
    // --for: only the trace's opcodes
    cwisim_ok(
        &dir,
        &[
            "rtl",
            "--for",
            &trace("gouraud.cwt"),
            "--numeric",
            FORMAT,
            "-o",
            "g.v",
            "--testbench",
            "tb.v",
        ],
    );
    let g = String::from_utf8(read(dir.join("g.v"))).unwrap();
    assert!(g.contains("// opcodes:  Eval2 Refresh"), "{g}");
    assert!(!g.contains("OP_EVAL3"));
    assert!(String::from_utf8(read(dir.join("tb.v")))
        .unwrap()
        .contains("module cwisim_tb;"));
}

#[test]
fn bad_settings_are_one_line_errors_and_write_nothing() {
    let dir = scratch("rtl-errors");
    let g = trace("gouraud.cwt");
    let gouraud = ["rtl", "--for", &g, "--numeric", FORMAT, "-o", "x.v"];
    for (args, wants) in [
        (
            vec!["rtl", "--numeric", "f32", "-o", "x.v"],
            "fixed-point registers",
        ),
        (vec!["rtl", "-o", "x.v"], "give the registers' format"),
        (
            vec!["rtl", "--numeric", FORMAT, "--width", "0", "-o", "x.v"],
            "width",
        ),
        (
            vec![
                "rtl",
                "--for",
                &trace("gouraud.cwt"),
                "--max-error",
                "1/512",
                "-o",
                "x.v",
            ],
            "needs a scene",
        ),
        (
            vec![
                "rtl",
                "--numeric",
                FORMAT,
                "-o",
                "x.v",
                "--fpga",
                "ice40-hx9k",
            ],
            "unknown FPGA `ice40-hx9k`: the known ones are ice40-hx1k, ice40-hx8k, ice40-up5k",
        ),
        (
            [&gouraud[..], &["--fpga-shell"]].concat(),
            "--fpga-shell says how --cosim co-simulates",
        ),
        (
            [&gouraud[..], &["--cosim", "verilator", "--fpga-shell"]].concat(),
            "give --cosim icarus",
        ),
        (
            [
                &gouraud[..],
                &["--cosim", "icarus", "--fpga-shell", "--watch", "0"],
            ]
            .concat(),
            "only the scanlines come out",
        ),
    ] {
        let out = cwisim(&dir, &args);
        let (_, err) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(wants), "{args:?}: {err}");
        assert!(!dir.join("x.v").exists(), "{args:?}");
    }
}

#[test]
fn a_trace_co_simulates_identically_in_icarus() {
    if std::env::var("CWISIM_SKIP_HDL_TESTS").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED: cwisim rtl --cosim (CWISIM_SKIP_HDL_TESTS=1)");
        return;
    }
    let dir = scratch("rtl-cosim");
    let out = cwisim(
        &dir,
        &[
            "rtl",
            "--for",
            &trace("visibility.cwt"),
            "--numeric",
            FORMAT,
            "-o",
            "v.v",
            "--cosim",
            "icarus",
            "--watch",
            "all",
            "--work-dir",
            "run",
        ],
    );
    let (stdout, stderr) = text(&out);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stderr} (the HDL tools: crates/rtl/tools/install-hdl.sh, or CWISIM_SKIP_HDL_TESTS=1)"
    );
    assert!(
        stdout.contains("icarus: identical to the stepped engine"),
        "{stdout}"
    );
    assert!(stdout.contains("at 16 watched processor(s)"), "{stdout}");
    // --work-dir (relative to where cwisim runs) keeps the files
    for f in ["design.v", "testbench.v", "stimulus.hex", "dump.txt"] {
        assert!(dir.join("run").join(f).is_file(), "{f}");
    }
}

#[test]
fn a_trace_co_simulates_through_the_fpga_shell_at_its_latency() {
    if std::env::var("CWISIM_SKIP_HDL_TESTS").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED: cwisim rtl --cosim icarus --fpga-shell (CWISIM_SKIP_HDL_TESTS=1)");
        return;
    }
    let dir = scratch("rtl-cosim-shell");
    let args = |out: &'static str| {
        vec![
            "rtl".to_string(),
            "--for".into(),
            trace("gouraud.cwt"),
            "--numeric".into(),
            FORMAT.into(),
            "-o".into(),
            out.into(),
            "--cosim".into(),
            "icarus".into(),
        ]
    };
    let mut shell = args("s.v");
    shell.extend(["--fpga-shell".into(), "--work-dir".into(), "run".into()]);
    let shell: Vec<&str> = shell.iter().map(String::as_str).collect();
    let out = cwisim(&dir, &shell);
    let (stdout, stderr) = text(&out);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stderr} (the HDL tools: crates/rtl/tools/install-hdl.sh, or CWISIM_SKIP_HDL_TESTS=1)"
    );
    let line = |label: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(label))
            .unwrap_or_else(|| panic!("no {label} line: {stdout}"))
            .to_string()
    };
    let words = line("shell");
    assert!(words.contains("beats of 8"), "{words}");
    let cosim = line("co-sim");
    assert!(
        cosim.contains("icarus through the FPGA shell: identical to the stepped engine: 6 scanline(s), 96 value(s) bit for bit"),
        "{cosim}"
    );
    assert!(
        cosim.contains("overflow events do not come out through the shell's ports"),
        "{cosim}"
    );
    for f in [
        "design.v",
        "shell.v",
        "tb.v",
        "stimulus.hex",
        "shell_dump.txt",
    ] {
        assert!(dir.join("run").join(f).is_file(), "{f}");
    }
    // the machine is paced for the port: the design written differs from the bare one's
    let plain = args("p.v");
    let plain: Vec<&str> = plain.iter().map(String::as_str).collect();
    let bare = cwisim_ok(&dir, &plain);
    assert!(!bare.contains("through the FPGA shell"), "{bare}");
    assert_ne!(read(dir.join("s.v")), read(dir.join("p.v")));
}

#[test]
fn fit_reports_the_area_of_the_format_it_finds() {
    if std::env::var("CWISIM_SKIP_HDL_TESTS").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED: cwisim fit --area (CWISIM_SKIP_HDL_TESTS=1)");
        return;
    }
    let dir = scratch("rtl-fit-area");
    let out = cwisim_ok(&dir, &["fit", "fig25", "--max-error", "1/256", "--area"]);
    let area = out
        .lines()
        .find(|l| l.starts_with("area"))
        .unwrap_or_else(|| panic!("no area line: {out}"));
    assert!(
        area.contains("one processor:") && area.contains("NAND2 equivalents"),
        "{area}"
    );
    // the same processor as `cwisim rtl --area` for the format fit found
    let format = out
        .lines()
        .find_map(|l| l.strip_prefix("registers"))
        .unwrap()
        .trim()
        .to_string();
    let rtl = cwisim_ok(
        &dir,
        &[
            "rtl",
            "--for",
            "fig25",
            "--numeric",
            &format,
            "-o",
            "f.v",
            "--area",
        ],
    );
    let cells = |s: &str| {
        s.split("one processor:")
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(
        cells(area),
        cells(rtl.lines().find(|l| l.starts_with("area")).unwrap())
    );
}

#[test]
fn fpga_without_its_tools_names_the_script() {
    let dir = scratch("rtl-fpga-no-tools");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args([
            "rtl",
            "--numeric",
            FORMAT,
            "-o",
            "x.v",
            "--fpga",
            "ice40-up5k",
        ])
        .current_dir(&dir)
        .env("PATH", dir.join("no-tools-here"))
        .output()
        .unwrap();
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("crates/rtl/tools/install-hdl.sh") && err.contains("nextpnr-ice40"),
        "{err}"
    );
    assert!(!dir.join("x.v").exists());
}

#[test]
fn fpga_reports_a_placed_design_and_refuses_one_too_large() {
    if std::env::var("CWISIM_SKIP_HDL_TESTS").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED: cwisim rtl --fpga (CWISIM_SKIP_HDL_TESTS=1)");
        return;
    }
    let dir = scratch("rtl-fpga");
    let g = trace("gouraud.cwt");
    let small = "fixed:I=2.15,dI=1.16,ddI=1.16,acc=2.12";
    // too large: one line with the numbers, exit 2, nothing written
    let out = cwisim(
        &dir,
        &[
            "rtl",
            "--for",
            &g,
            "--numeric",
            small,
            "-o",
            "x.v",
            "--fpga",
            "ice40-hx1k",
        ],
    );
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("does not fit the ice40-hx1k") && err.contains("the device has 1280"),
        "{err}"
    );
    assert!(!dir.join("x.v").exists());
    // 4 processors of it on the UP5K, the scene replayed at the clock reached
    let out = cwisim_ok(
        &dir,
        &[
            "rtl",
            "--for",
            &g,
            "--numeric",
            small,
            "-o",
            "x.v",
            "--fpga",
            "ice40-up5k",
            "--fpga-processors",
            "4",
        ],
    );
    let line = |label: &str| {
        out.lines()
            .find(|l| l.starts_with(label))
            .unwrap_or_else(|| panic!("no {label} line: {out}"))
            .to_string()
    };
    assert!(
        line("fpga").contains("ice40-up5k (sg48): 4 processor(s)"),
        "{out}"
    );
    assert!(
        line("shell").contains("LUTs") && line("array").contains("carries"),
        "{out}"
    );
    let fmax: f64 = line("fmax")
        .split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{out}"));
    assert!(fmax > 1.0, "{out}");
    let clock = format!("--set clock_hz={}", (fmax * 1000.0).floor() as u64 * 1000);
    assert!(
        line("at fmax").contains(&clock) && line("at fmax").contains("of 6 scanline(s) late"),
        "{out}"
    );
    assert!(
        line("fits").contains("devices") || line("fits").contains("device(s)"),
        "{out}"
    );
    assert!(dir.join("x.v").is_file());
}
