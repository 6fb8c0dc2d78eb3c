//! Every shell example of the README and `docs/*.md`, and every `Example:` of `cwisim --help`
//! and its subcommands' help, run against the built `cwisim`, so that none can drift from
//! the program again.
//!
//! **Documents.** Every fenced block tagged `sh`, `bash`, `shell` or `console` is cut into
//! commands: a line, with its `\` continuations, or a compound command (`for … done`,
//! `case … esac`, `{ … }`) whole; a command that reads `$?` goes with the one before it.
//! `cargo run --release -- ARGS` is `cwisim ARGS`. Each document runs in a fresh directory
//! of its own, its blocks and commands in order (a later command sees what an earlier one
//! wrote), through `sh -c` (`bash -c` for a block tagged `bash`) with the binary first on
//! `PATH` as `cwisim`; a variable a block sets (`N=1000000`) is set for its later commands.
//! A file of the repository that a command names (`traces/gouraud.cwt`,
//! `crates/…/fixtures/…`) is copied in at the same relative path first, so nothing in the
//! repository is written; what a document shows but no command makes is made first
//! ([`prepare`]: docs/RENDERERS.md's Python script and the trace it must equal). A command
//! must exit 0, or the status a `# … exits N …` comment on it states. Every flag a `cwisim`
//! command uses must be one of its subcommand's flags by its present name: an old name
//! still accepted as an alias fails here.
//!
//! What is not `cwisim` is either run because later commands read what it makes ([`SETUP`])
//! or skipped, with the reason ([`SKIPPED`]); anything else fails, so a new kind of command
//! is a decision made here. A command that takes more than about ten seconds in a debug
//! build is [`LONG`]: run only when `CWISIM_LONG_EXAMPLES=1`, which `.ci/run` sets with
//! `CWISIM_BIN` pointing at the release binary (`CWISIM_BIN` replaces the binary Cargo
//! built for this test).
//!
//! **Outputs.** In a block tagged `console`, a line `$ COMMAND` is a command and the lines
//! under it are what its standard output must show, matched with `snapbox` (`...` on a line
//! of its own for any lines, `[..]` for any text within a line). A Markdown table right
//! under a line `<!-- table from: COMMAND; varying: COLUMN, … -->` must be, row for row, the
//! table with the same header that the command prints, but for the varying columns (host
//! times). So a figure a document quotes from a command fails here when it drifts. A command
//! `cargo run --release -p PACKAGE --example NAME` whose output is checked so runs the
//! example's release binary from `CWISIM_EXAMPLES_DIR`, which `.ci/run` builds and sets;
//! without it, it is skipped, saying so.
//!
//! **Help.** The `Example:`/`Examples:` lines of every command's long help run the same way,
//! in one directory holding the files their generic names stand for ([`HELP_FILES`]).
//!
//! Run with `-- --nocapture` to see each command's time.

mod common;

use clap::CommandFactory;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Commands that are not `cwisim` and are not run here: the first words, and why.
const SKIPPED: &[(&str, &str)] = &[
    (
        "cargo test",
        "the test suite itself (the README's test command; .ci/run runs it)",
    ),
    (
        "cargo bench",
        "the benchmarks: a quarter of an hour of measuring; .ci/run compiles them (--no-run)",
    ),
    (
        "cargo run --release -p ",
        "an example program of a library crate, not cwisim; `cargo test` compiles every example",
    ),
    (
        "cargo run -p ",
        "an example program of a library crate, not cwisim; `cargo test` compiles every example",
    ),
    (
        "cargo build --release",
        "builds the binary; this test runs the one Cargo built for it (or CWISIM_BIN)",
    ),
    (
        "crates/python/install.sh",
        "installs the Python package (PyPI, a release build); .ci/run runs it into a fresh virtual environment",
    ),
    (
        "python3 -c \"import cwisim",
        "the Python package, installed by crates/python/install.sh; its tests (pytest) check it",
    ),
    (
        "python3 -m pytest",
        "the Python package's tests; .ci/run runs them after installing it",
    ),
    (
        "rustup ",
        "installs a nightly toolchain for cargo-fuzz (network); .ci/run checks the fuzz targets build",
    ),
    (
        "cargo install ",
        "installs cargo-fuzz (network); .ci/run checks the fuzz targets build",
    ),
    (
        "fuzz/seed-corpus.sh",
        "fills the fuzz corpus for cargo-fuzz, on nightly; crates/fuzzing's tests read the seeds",
    ),
    (
        "cargo +nightly fuzz",
        "cargo-fuzz on nightly, for hours; .ci/run checks the fuzz targets build",
    ),
    (
        "gtkwave ",
        "a waveform viewer (GUI); crates/host/tests/vcd.rs reads the files back with wellen",
    ),
    (
        "chromium ",
        "the browser; crates/host/tests/browser.rs opens the page in headless Chromium",
    ),
    (
        "time chromium ",
        "the browser; crates/host/tests/browser.rs opens the page in headless Chromium",
    ),
    (
        "crates/rtl/tools/install-hdl.sh",
        "installs Debian's iverilog, verilator, yosys, nextpnr-ice40 and fpga-icestorm (apt-get); .ci/run runs it before the tests",
    ),
    (
        "verilator ",
        "Verilator's lint by hand; crates/rtl/tests/lint_synth.rs lints every generated design",
    ),
    (
        "yosys ",
        "Yosys by hand; crates/rtl/tests/lint_synth.rs and `cwisim rtl --area` synthesize the designs",
    ),
    (
        "cwisim rtl --for pot --max-error 1/512 -o pot_xproc.v --cosim verilator",
        "the pot at full width under Verilator: 2 minutes on 2 cores (its time is in docs/HARDWARE.md); crates/rtl/tests/verilator.rs co-simulates in Verilator",
    ),
];

/// Commands that are not `cwisim` but are run, because the `cwisim` commands after them
/// read what they make: the first words, and a program they need (when it is missing, the
/// rest of the block is skipped, saying so).
const SETUP: &[(&str, Option<&str>)] = &[
    // docs/PERFORMANCE.md: a long trace made with the shell
    ("N=", None),
    ("{ echo \"cwisim-trace", None),
    // docs/STUDYING.md: a trace with one value changed
    ("sed ", Some("sed")),
    // docs/RENDERERS.md: the Python script of the same section writes the example's trace
    ("python3 ", Some("python3")),
];

/// Commands that take over about ten seconds in a debug build, as `DOCUMENT: a piece of
/// the command`. Run only with `CWISIM_LONG_EXAMPLES=1` (and best with `CWISIM_BIN` the
/// release binary). The times: debug and release builds, 2 shared cores.
const LONG: &[&str] = &[
    // 90 s debug, 2.5 s release
    "README.md: render teapot --renderer nishita --shading phong",
    // 14 s debug, 1 s release
    "README.md: refine teapot --phases flat,phong --sweep",
    // five renderers × tessellations × settings, 150 rows: 250 s release
    "README.md: tradeoff teapot --numeric f64",
    // 240 rows: 8–10 s release on two cores
    "README.md: tradeoff pot --csv pot.csv --plot pot-tradeoff.png",
    // 100 s debug, 9 s release
    "README.md: inspect pot -o pot.html",
    // a million scanlines, 50 MB: made, converted, replayed in 3 s release
    "docs/PERFORMANCE.md: N=1000000",
    "docs/PERFORMANCE.md: yes $'Eval2",
    "docs/PERFORMANCE.md: convert long.cwt long.cwb",
    "docs/PERFORMANCE.md: run long.cwt --stats",
    // 22 s release
    "docs/RENDERERS.md: tradeoff pot --renderers vanrij,woo-chall",
    // four nishita teapots, 10–85 s debug each, 1–13 s release
    "docs/RENDERERS.md: --renderer nishita",
    // 60 s release on two threads
    "docs/RENDERERS.md: tradeoff teapot --renderers vanrij,nishita",
    "docs/TRADEOFF.md: tradeoff teapot --renderers vanrij,nishita",
    // 1000 polygons of 500 vertices through the S-buffer: 35 s debug, 3.5 s release
    "docs/REPRODUCTION.md: render many500.json",
    // 21 nishita teapots, three tolerances, flatness 16 to 0.25 px: 10–90 s debug each,
    // 35 s release in all; and the defaults' one, 2 s release
    "docs/REPRODUCTION.md: --renderer nishita --root-tolerance $t --flatness $f",
    "docs/REPRODUCTION.md: render teapot --renderer nishita -o f.png",
    // the plain and the textured teapot by nishita: 2 × 40 s debug, 2 s release; and
    // teapot-floor without and with its shadows, 2–4 s release each
    "docs/REPRODUCTION.md: --renderer nishita --threads 1",
    // teapot-floor by nishita (4 s release, 11 s at flatness 0.125) and by vanrij at four
    // tessellations (1 s release in all), and their differences
    "docs/REPRODUCTION.md: render teapot-floor --renderer nishita --npy",
    "docs/REPRODUCTION.md: --renderer vanrij --tessellate $n",
    "docs/REPRODUCTION.md: --renderer nishita --flatness 0.125",
    "docs/REPRODUCTION.md: diff nishita-fine.npy vanrij-64.npy",
    // the fine reference and four nishita teapots with the normal test: 15–30 s release
    "docs/REPRODUCTION.md: --tessellate 64 --shading phong --shade-tolerance 0 -o ref.png",
    "docs/REPRODUCTION.md: --normal-angle $a",
    // the diff of the one-sided and the two-sided teapot, which the long renders make
    // (`--renderer nishita --threads 1`, below)
    "docs/REPRODUCTION.md: diff two-sided.npy one-sided.npy",
    // still-life through the S-buffer with its shadows: 20 s debug, 0.2 s release
    "docs/REPRODUCTION.md: render still-life --renderer sbuffer",
    // eight refinements of the pot: 15 s debug, 2 s release
    "docs/REPRODUCTION.md: refine pot --sweep",
    // a session of four refinements of the pot: 0.3 s release
    "docs/REPRODUCTION.md: refine pot --events",
    // the teapot's vertex phase in ten frames, then flat: 1 s release
    "docs/REPRODUCTION.md: refine teapot --phases vertices,flat --vertex-fraction 0.1",
    // 50–200 s debug, 9–14 s release
    "docs/STUDYING.md: inspect pot -o pot.html",
    "docs/STUDYING.md: inspect pot --size 1024x1024",
    // 80 s release
    "docs/TRADEOFF.md: tradeoff pot --csv pot.csv",
    // 80 s debug, 3.5 s release
    "docs/TRADEOFF.md: tradeoff teapot --renderers vanrij",
    // twelve nishita teapots at 160², half with the normal test, and the reference: 16 s
    // release
    "docs/TRADEOFF.md: --normal-angle off,30",
    // the help's examples: 90 s release; 100 s debug, 9 s release; the whole 400-processor
    // array, 30 s debug
    "cwisim --help: cwisim tradeoff pot",
    "cwisim --help: cwisim inspect pot",
    "cwisim --help: cwisim vcd pot --line 200 -o l.vcd",
    // the hardware examples need iverilog and yosys, which .ci/run installs before the long
    // examples run (crates/rtl/tools/install-hdl.sh); each takes a few seconds
    "cwisim --help: cwisim rtl --numeric fixed:I=12.20,dI=4.28,ddI=1.36 --width 64 -o xproc.v --area",
    "cwisim --help: --cosim icarus",
    "cwisim --help: cwisim rtl --for pot --max-error 1/512 -o pot_xproc.v --area",
    "docs/HARDWARE.md: --cosim icarus --watch all",
    "docs/HARDWARE.md: --cosim icarus --work-dir run1",
    "docs/HARDWARE.md: cwisim rtl --for pot --max-error 1/512 -o pot_xproc.v --area",
    "docs/HARDWARE.md: cwisim fit pot --max-error 1/512 --area",
    // gouraud through the FPGA shell in Icarus: 4 s debug, 2 s release
    "docs/HARDWARE.md: --cosim icarus --fpga-shell",
    // place and route (nextpnr-ice40): 16 processors, 20 s debug; the pot's fit and 8
    // processors, a minute
    "cwisim --help: --fpga ice40-up5k",
    "docs/HARDWARE.md: --fpga ice40-up5k",
    "docs/HARDWARE.md: --fpga ice40-hx8k",
    // the FPGA table: four scenes on two devices, eight place-and-routes, 3 min 23 s
    // release (needs CWISIM_EXAMPLES_DIR too)
    "docs/HARDWARE.md: --example fpga_table",
];

/// Whether a command of a document is [`LONG`].
fn long_entry(doc: &str, code: &str) -> Option<usize> {
    LONG.iter().position(|entry| {
        let (d, piece) = entry.split_once(": ").expect("DOCUMENT: piece");
        d == doc && code.contains(piece)
    })
}

/// The files the help's generic names stand for, made before its examples run (in its
/// directory, in order).
const HELP_FILES: &str = "\
cwisim emit fig25 -o scene.cwt
cwisim convert scene.cwt scene.cwb
cwisim convert scene.cwt trace.cwb
cwisim scenes fig25 > scene.json
cwisim emit fig25 -o a.cwt
cwisim emit fig25 --aa box-centre -o b.cwb
cwisim run a.cwt --npy a.npy
cwisim run b.cwb --npy b.npy";

/// The help's examples that do not exit 0: `diff` of [`HELP_FILES`]' two sides, which
/// differ.
const HELP_STATUS: &[(&str, i32)] = &[("cwisim diff ", 1)];

/// The documents that hold shell examples; a test for each below.
const DOCUMENTS: &[&str] = &[
    "README.md",
    "docs/ACCURACY.md",
    "docs/ERRATA.md",
    "docs/FUZZING.md",
    "docs/HARDWARE.md",
    "docs/PERFORMANCE.md",
    "docs/PYTHON.md",
    "docs/RENDERERS.md",
    "docs/REPRODUCTION.md",
    "docs/SHADOWS.md",
    "docs/STUDYING.md",
    "docs/TEXTURES.md",
    "docs/TIMING.md",
    "docs/TRADEOFF.md",
];

#[test]
fn readme() {
    run_document("README.md");
}

#[test]
fn accuracy() {
    run_document("docs/ACCURACY.md");
}

#[test]
fn errata() {
    run_document("docs/ERRATA.md");
}

#[test]
fn fuzzing() {
    run_document("docs/FUZZING.md");
}

#[test]
fn hardware() {
    run_document("docs/HARDWARE.md");
}

#[test]
fn performance() {
    run_document("docs/PERFORMANCE.md");
}

#[test]
fn python() {
    run_document("docs/PYTHON.md");
}

#[test]
fn renderers() {
    run_document("docs/RENDERERS.md");
}

#[test]
fn reproduction() {
    run_document("docs/REPRODUCTION.md");
}

#[test]
fn shadows() {
    run_document("docs/SHADOWS.md");
}

#[test]
fn studying() {
    run_document("docs/STUDYING.md");
}

#[test]
fn textures() {
    run_document("docs/TEXTURES.md");
}

#[test]
fn timing() {
    run_document("docs/TIMING.md");
}

#[test]
fn tradeoff() {
    run_document("docs/TRADEOFF.md");
}

/// Every document with a shell block has its test above, no block that looks like commands
/// goes untagged, and every entry of [`SKIPPED`], [`SETUP`] and [`LONG`] is still used.
#[test]
fn the_lists_are_complete_and_current() {
    let mut docs: Vec<String> = vec!["README.md".into()];
    let mut entries: Vec<_> = std::fs::read_dir(common::repo().join("docs"))
        .expect("docs/")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .map(|p| format!("docs/{}", p.file_name().unwrap().to_string_lossy()))
        .collect();
    entries.sort();
    docs.extend(entries);
    let mut with_examples = Vec::new();
    let mut used_skips = vec![false; SKIPPED.len()];
    let mut used_setup = vec![false; SETUP.len()];
    let mut used_long = vec![false; LONG.len()];
    for doc in &docs {
        let text = std::fs::read_to_string(common::repo().join(doc)).expect("read a document");
        let blocks = blocks(&text);
        for b in &blocks {
            if b.lang.is_empty() {
                for (n, line) in &b.lines {
                    let t = line.trim_start();
                    assert!(
                        !(t.starts_with("cwisim ") || t.starts_with("cargo ")),
                        "{doc}:{n}: a command in an untagged block: tag it ```sh"
                    );
                }
            }
        }
        let units: Vec<Unit> = document_units(&text);
        if !units.is_empty() {
            with_examples.push(doc.clone());
        }
        for u in &units {
            let code = rewrite(&u.code);
            for (i, (prefix, _)) in SKIPPED.iter().enumerate() {
                used_skips[i] |= code.trim_start().starts_with(prefix);
            }
            for (i, (prefix, _)) in SETUP.iter().enumerate() {
                used_setup[i] |= code.trim_start().starts_with(prefix);
            }
            if let Some(i) = long_entry(doc, &code) {
                used_long[i] = true;
            }
        }
    }
    for help in help_examples() {
        if let Some(i) = long_entry("cwisim --help", &help.code) {
            used_long[i] = true;
        }
    }
    assert_eq!(
        with_examples, DOCUMENTS,
        "the documents with shell examples: give each a test in this file"
    );
    let stale = |used: &[bool], names: Vec<String>| -> Vec<String> {
        used.iter()
            .zip(names)
            .filter(|(u, _)| !**u)
            .map(|(_, n)| n)
            .collect()
    };
    let stale: Vec<String> = [
        stale(
            &used_skips,
            SKIPPED
                .iter()
                .map(|s| format!("SKIPPED {:?}", s.0))
                .collect(),
        ),
        stale(
            &used_setup,
            SETUP.iter().map(|s| format!("SETUP {:?}", s.0)).collect(),
        ),
        stale(
            &used_long,
            LONG.iter().map(|s| format!("LONG {s:?}")).collect(),
        ),
    ]
    .concat();
    assert!(
        stale.is_empty(),
        "entries no example uses any more: {stale:#?}"
    );
}

/// Every command's help has an example, and every example runs, with today's flags.
#[test]
fn help_examples_run() {
    let root = built_root();
    // clap's own `help` aside
    for sub in root.get_subcommands().filter(|s| s.get_name() != "help") {
        let text = long_texts(sub);
        assert!(
            text.contains("Example:") || text.contains("Examples:"),
            "`cwisim {} --help` has no example",
            sub.get_name()
        );
    }
    let examples = help_examples();
    assert!(examples.len() >= root.get_subcommands().count());
    let mut runner = Runner::new("cwisim --help");
    let setup: Vec<Unit> = HELP_FILES
        .lines()
        .map(|l| Unit {
            line: 0,
            code: l.to_owned(),
            text: l.to_owned(),
            status: 0,
            block: 0,
            shell: "sh",
            check: Check::Status,
        })
        .collect();
    for u in &setup {
        runner.run(u);
    }
    assert!(
        runner.failures.is_empty(),
        "making the help's files: {:#?}",
        runner.failures
    );
    for u in &examples {
        runner.consider(u);
    }
    runner.finish();
}

// ---------------------------------------------------------------------------------------
// Documents: fenced blocks, and the commands in them

/// A fenced block: its tag, and its lines with their line numbers (from 1).
struct Block {
    lang: String,
    lines: Vec<(usize, String)>,
}

fn blocks(text: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if let Some(fence) = t.strip_prefix("```") {
            match open.take() {
                None => {
                    open = Some(Block {
                        lang: fence.trim().to_owned(),
                        lines: Vec::new(),
                    })
                }
                Some(b) => out.push(b),
            }
            continue;
        }
        if let Some(b) = open.as_mut() {
            b.lines.push((i + 1, line.to_owned()));
        }
    }
    out
}

fn is_shell(lang: &str) -> bool {
    matches!(lang, "sh" | "bash" | "shell" | "console")
}

/// The commands of a document's shell blocks, in order.
fn shell_units(blocks: &[Block]) -> Vec<Unit> {
    blocks
        .iter()
        .enumerate()
        .filter(|(_, b)| is_shell(&b.lang))
        .flat_map(|(id, b)| units(b, id))
        .collect()
}

/// A document's commands in order: its shell blocks' and its tables' ([`table_units`]).
fn document_units(text: &str) -> Vec<Unit> {
    let mut units = shell_units(&blocks(text));
    units.extend(table_units(text));
    units.sort_by_key(|u| u.line);
    units
}

/// `cargo run --release -p PACKAGE --example NAME [-- ARGS]` as the example's built binary
/// in `dir` (`.ci/run` builds the release examples and sets `CWISIM_EXAMPLES_DIR`).
fn example_command(code: &str, dir: &Path) -> Option<String> {
    let rest = code.trim_start().strip_prefix("cargo run --release -p ")?;
    let (_package, rest) = rest.split_once(' ')?;
    let rest = rest.trim_start().strip_prefix("--example ")?;
    let (name, args) = rest.split_once(' ').unwrap_or((rest, ""));
    let args = args.trim_start();
    let args = args.strip_prefix("--").unwrap_or(args).trim();
    let program = dir.join(name.trim());
    Some(
        format!("{} {args}", program.display())
            .trim_end()
            .to_owned(),
    )
}

/// One command of a block (or several that go together).
#[derive(Clone, Debug)]
struct Unit {
    /// The line it starts on.
    line: usize,
    /// As written, comments included.
    text: String,
    /// Without comments.
    code: String,
    /// The exit status it should give.
    status: i32,
    /// Which block of its document.
    block: usize,
    /// The shell that runs it: `bash` for a block tagged so, else `sh`.
    shell: &'static str,
    /// What its output must show.
    check: Check,
}

/// What a command's standard output must show.
#[derive(Clone, Debug, Default)]
enum Check {
    /// Nothing: only its exit status is checked.
    #[default]
    Status,
    /// The lines under it in a `console` block, with `...` (any lines) and `[..]` (any
    /// text within a line).
    Output(String),
    /// A table of the document: the command prints a Markdown table with the same header,
    /// and every row of the document's is in it, cell for cell but for the columns named
    /// as varying.
    Table(Table),
}

/// A Markdown table of a document that a command prints.
#[derive(Clone, Debug)]
struct Table {
    /// The header's cells.
    header: Vec<String>,
    /// The rows' cells (the separator row left out).
    rows: Vec<Vec<String>>,
    /// Columns (by header) whose cells vary from run to run: host times.
    varying: Vec<String>,
}

/// The commands of a block, the `id`th of its document.
fn units(block: &Block, id: usize) -> Vec<Unit> {
    if block.lang == "console" {
        return console_units(block, id);
    }
    let mut out: Vec<Unit> = Vec::new();
    let mut cur: Option<Unit> = None;
    let mut depth = 0i32;
    for (n, raw) in &block.lines {
        let line = raw.as_str();
        let code = without_comment(line).trim_end();
        if cur.is_none() && code.trim().is_empty() {
            continue;
        }
        let u = cur.get_or_insert_with(|| Unit {
            line: *n,
            text: String::new(),
            code: String::new(),
            status: 0,
            block: id,
            shell: if block.lang == "bash" { "bash" } else { "sh" },
            check: Check::Status,
        });
        if !u.text.is_empty() {
            u.text.push('\n');
            u.code.push('\n');
        }
        u.text.push_str(line);
        u.code.push_str(code);
        if let Some(s) = comment(line).and_then(stated_status) {
            u.status = s;
        }
        depth += nesting(code);
        if depth <= 0 && !code.ends_with('\\') {
            let u = cur.take().expect("a command");
            depth = 0;
            match out.last_mut() {
                // `case $? in …`: the status of the command before
                Some(prev) if u.code.contains("$?") => {
                    prev.text = format!("{}\n{}", prev.text, u.text);
                    prev.code = format!("{}\n{}", prev.code, u.code);
                    prev.status = u.status;
                }
                _ => out.push(u),
            }
        }
    }
    out.extend(cur);
    out
}

/// The commands of a `console` block: each line `$ COMMAND` (with its `\` continuations)
/// is one, and the lines under it are what its standard output must show ([`Check::Output`]:
/// `...` on a line of its own stands for any lines, `[..]` for any text within a line).
fn console_units(block: &Block, id: usize) -> Vec<Unit> {
    let mut out: Vec<Unit> = Vec::new();
    let mut continued = false;
    for (n, raw) in &block.lines {
        let command = raw.strip_prefix("$ ");
        if continued || command.is_some() {
            let line = command.unwrap_or(raw);
            let code = without_comment(line).trim_end();
            if continued {
                let u = out.last_mut().expect("a command before its continuation");
                u.text = format!("{}\n{line}", u.text);
                u.code = format!("{}\n{code}", u.code);
            } else {
                out.push(Unit {
                    line: *n,
                    text: line.to_owned(),
                    code: code.to_owned(),
                    status: 0,
                    block: id,
                    shell: "sh",
                    check: Check::Status,
                });
            }
            if let Some(s) = comment(line).and_then(stated_status) {
                out.last_mut().expect("a command").status = s;
            }
            continued = code.ends_with('\\');
            continue;
        }
        let Some(u) = out.last_mut() else {
            panic!("line {n}: output in a console block before any `$ ` command");
        };
        match &mut u.check {
            Check::Output(expected) => {
                expected.push('\n');
                expected.push_str(raw);
            }
            check => *check = Check::Output(raw.clone()),
        }
    }
    out
}

/// The tables of a document that a command prints: a Markdown table right under a line
/// `<!-- table from: COMMAND -->` (or `<!-- table from: COMMAND; varying: COLUMN, … -->`
/// for columns, such as host times, that differ from run to run), as commands to run
/// with [`Check::Table`], at the comment's line.
fn table_units(text: &str) -> Vec<Unit> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some(rest) = line.trim().strip_prefix("<!-- table from:") else {
            continue;
        };
        let rest = rest
            .strip_suffix("-->")
            .unwrap_or_else(|| panic!("line {}: `<!-- table from: … -->` on one line", i + 1))
            .trim();
        let (command, varying) = match rest.split_once("; varying:") {
            Some((c, v)) => (
                c.trim(),
                v.split(',').map(|c| c.trim().to_owned()).collect(),
            ),
            None => (rest, Vec::new()),
        };
        let command = command.trim_matches('`');
        let rows: Vec<Vec<String>> = lines[i + 1..]
            .iter()
            .take_while(|l| l.trim_start().starts_with('|'))
            .map(|l| cells(l))
            .collect();
        assert!(
            rows.len() >= 3,
            "line {}: a Markdown table (header, separator, rows) right under the comment",
            i + 1
        );
        let header = rows[0].clone();
        for v in &varying {
            assert!(
                header.contains(v),
                "line {}: no column {v:?} in the table",
                i + 1
            );
        }
        out.push(Unit {
            line: i + 1,
            text: command.to_owned(),
            code: command.to_owned(),
            status: 0,
            block: usize::MAX,
            shell: "sh",
            check: Check::Table(Table {
                header,
                rows: rows[2..].to_vec(),
                varying,
            }),
        });
    }
    out
}

/// The cells of a Markdown table's row, trimmed.
fn cells(row: &str) -> Vec<String> {
    let row = row.trim();
    let row = row.strip_prefix('|').unwrap_or(row);
    let row = row.strip_suffix('|').unwrap_or(row);
    row.split('|').map(|c| c.trim().to_owned()).collect()
}

/// Whether `printed` (a command's output) holds `table`: a Markdown table with its header
/// whose rows are the table's, cell for cell but in the varying columns. `Err` says where
/// they part.
fn holds_table(printed: &str, table: &Table) -> Result<(), String> {
    let lines: Vec<&str> = printed.lines().collect();
    let Some(start) = lines
        .iter()
        .position(|l| l.trim_start().starts_with('|') && cells(l) == table.header)
    else {
        return Err(format!(
            "the output has no table with the header {:?}",
            table.header
        ));
    };
    let rows: Vec<Vec<String>> = lines[start + 1..]
        .iter()
        .take_while(|l| l.trim_start().starts_with('|'))
        .skip(1)
        .map(|l| cells(l))
        .collect();
    let compared: Vec<bool> = table
        .header
        .iter()
        .map(|h| !table.varying.contains(h))
        .collect();
    let same = |a: &[String], b: &[String]| {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .zip(&compared)
                .all(|((x, y), c)| !c || x == y)
    };
    let mut problems = Vec::new();
    for (k, row) in table.rows.iter().enumerate() {
        match rows.get(k) {
            Some(printed) if same(row, printed) => {}
            Some(printed) => problems.push(format!(
                "row {}: the document has\n      {}\n    the command printed\n      {}",
                k + 1,
                row.join(" | "),
                printed.join(" | ")
            )),
            None => problems.push(format!("row {}: the command printed no such row", k + 1)),
        }
    }
    if rows.len() > table.rows.len() {
        problems.push(format!(
            "the command printed {} rows, the document has {}",
            rows.len(),
            table.rows.len()
        ));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n    "))
    }
}

/// The comment of a shell line: after a `#` that begins a word, outside quotes.
fn comment(line: &str) -> Option<&str> {
    comment_at(line).map(|i| &line[i + 1..])
}

fn without_comment(line: &str) -> &str {
    comment_at(line).map_or(line, |i| &line[..i])
}

fn comment_at(line: &str) -> Option<usize> {
    let b = line.as_bytes();
    let (mut single, mut double) = (false, false);
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'\\' if !single => i += 1,
            b'\'' if !double => single = !single,
            b'"' if !single => double = !double,
            b'#' if !single && !double && (i == 0 || b[i - 1].is_ascii_whitespace()) => {
                return Some(i)
            }
            _ => {}
        }
        i += 1;
    }
    None
}

/// `exits N` in a comment: the status the command is meant to give.
fn stated_status(comment: &str) -> Option<i32> {
    let (_, rest) = comment.split_once("exits ")?;
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// How much a line opens (`for`, `while`, `until`, `if`, `case`, `{`) or closes (`done`,
/// `fi`, `esac`, `}`) compound commands: words in command position only.
fn nesting(code: &str) -> i32 {
    let mut depth = 0;
    let mut command_position = true;
    for word in code.split_whitespace() {
        let w = word.trim_end_matches(';');
        if command_position {
            match w {
                "for" | "while" | "until" | "if" | "case" | "{" => depth += 1,
                "done" | "fi" | "esac" | "}" => depth -= 1,
                _ => {}
            }
        }
        command_position = word.ends_with(';')
            || matches!(
                word,
                "&&" | "||" | "|" | "do" | "then" | "else" | "{" | ";;"
            );
    }
    depth
}

/// `cargo run --release -- ARGS` is `cwisim ARGS`.
fn rewrite(code: &str) -> String {
    code.replace("cargo run --release -- ", "cwisim ")
}

/// Where each `cwisim` is invoked in a piece of shell: the words up to the end of its
/// command (a newline not continued, `|`, `;`, `&`, a redirection).
fn invocations(code: &str) -> Vec<Vec<String>> {
    let code = code.replace("\\\n", " ");
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    let mut from = 0;
    while let Some(at) = code[from..].find("cwisim") {
        let start = from + at;
        let end = start + "cwisim".len();
        from = end;
        let before = start.checked_sub(1).map(|i| bytes[i]);
        let after = bytes.get(end).copied();
        let word_start = before.is_none_or(|c| c.is_ascii_whitespace() || b"/;|&(".contains(&c));
        let word_end = after.is_none_or(|c| c.is_ascii_whitespace() || c == b';');
        if !(word_start && word_end) {
            continue;
        }
        let rest = &code[end..];
        let stop = rest
            .find(['\n', '|', ';', '&', '>', '<'])
            .unwrap_or(rest.len());
        out.push(
            rest[..stop]
                .split_whitespace()
                .filter(|w| *w != "\\")
                .map(str::to_owned)
                .collect(),
        );
    }
    out
}

// ---------------------------------------------------------------------------------------
// Flags: today's names

/// Every flag of a `cwisim` command line is one of its subcommand's, by its present name.
fn check_flags(root: &clap::Command, args: &[String]) -> Result<(), String> {
    let mut cmd = root;
    let mut i = 0;
    while let Some(sub) = args.get(i).and_then(|a| cmd.find_subcommand(a)) {
        cmd = sub;
        i += 1;
    }
    for a in &args[i..] {
        if a == "--" {
            break;
        }
        if let Some(long) = a.strip_prefix("--") {
            let name = long.split('=').next().unwrap_or(long);
            if cmd.get_arguments().any(|x| x.get_long() == Some(name)) {
                continue;
            }
            if let Some(x) = cmd
                .get_arguments()
                .find(|x| x.get_all_aliases().is_some_and(|al| al.contains(&name)))
            {
                return Err(format!(
                    "--{name} is the old name of --{} (`cwisim {}`)",
                    x.get_long().unwrap_or("?"),
                    cmd.get_name()
                ));
            }
            return Err(format!("`cwisim {}` has no --{name}", cmd.get_name()));
        }
        let mut chars = a.chars();
        if let (Some('-'), Some(c), None) = (chars.next(), chars.next(), chars.next()) {
            if !c.is_ascii_digit() && !cmd.get_arguments().any(|x| x.get_short() == Some(c)) {
                return Err(format!("`cwisim {}` has no -{c}", cmd.get_name()));
            }
        }
    }
    Ok(())
}

fn built_root() -> clap::Command {
    let mut root = cwisim_host::cli::Cli::command();
    root.build();
    root
}

// ---------------------------------------------------------------------------------------
// Help: the examples of every command

/// A command's long help texts.
fn long_texts(cmd: &clap::Command) -> String {
    [
        cmd.get_long_about(),
        cmd.get_about(),
        cmd.get_before_long_help(),
        cmd.get_after_long_help(),
    ]
    .into_iter()
    .flatten()
    .map(|s| s.to_string())
    .collect::<Vec<_>>()
    .join("\n")
}

/// The `cwisim …` lines after `Example:` or `Examples:` in the help of `cwisim` and of
/// every subcommand, at every depth.
fn help_examples() -> Vec<Unit> {
    fn walk(cmd: &clap::Command, path: &str, out: &mut Vec<Unit>) {
        let text = long_texts(cmd);
        let mut in_examples = false;
        for line in text.lines() {
            let t = line.trim();
            if t == "Example:" || t == "Examples:" {
                in_examples = true;
            } else if in_examples && t.starts_with("cwisim ") {
                let status = HELP_STATUS
                    .iter()
                    .find(|(p, _)| t.starts_with(p))
                    .map_or(0, |s| s.1);
                out.push(Unit {
                    line: 0,
                    text: format!("{t}    (`{path} --help`)"),
                    code: t.to_owned(),
                    status,
                    block: 0,
                    shell: "sh",
                    check: Check::Status,
                });
            } else {
                in_examples = false;
            }
        }
        for sub in cmd.get_subcommands() {
            walk(sub, &format!("{path} {}", sub.get_name()), out);
        }
    }
    let mut out = Vec::new();
    walk(&built_root(), "cwisim", &mut out);
    out
}

// ---------------------------------------------------------------------------------------
// Running

/// The binary: `CWISIM_BIN`, or the one Cargo built for this test.
fn binary() -> PathBuf {
    match std::env::var_os("CWISIM_BIN") {
        Some(p) => {
            let p = PathBuf::from(p);
            assert!(p.is_file(), "CWISIM_BIN={} is not a file", p.display());
            std::fs::canonicalize(p).expect("CWISIM_BIN")
        }
        None => PathBuf::from(env!("CARGO_BIN_EXE_cwisim")),
    }
}

fn long_examples() -> bool {
    std::env::var("CWISIM_LONG_EXAMPLES").is_ok_and(|v| v == "1")
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join(program).is_file()))
}

/// Runs one document's commands (or the help's) in a directory of its own.
struct Runner {
    name: String,
    work: PathBuf,
    path: std::ffi::OsString,
    root: clap::Command,
    failures: Vec<String>,
    /// A block whose setup could not run: the rest of it is skipped.
    skip_block: Option<usize>,
    /// The variables the current block set (`N=1000000`), for its later commands.
    variables: (usize, String),
    total: Duration,
    /// What each command whose tables a document shows printed, so that it runs once.
    printed: std::collections::HashMap<String, String>,
}

impl Runner {
    fn new(name: &str) -> Runner {
        let dir = common::scratch(&format!("doc-examples/{}", name.replace(['/', ' '], "_")));
        let bin = dir.join("bin");
        let work = dir.join("work");
        std::fs::create_dir_all(&bin).expect("bin/");
        std::fs::create_dir_all(&work).expect("work/");
        std::os::unix::fs::symlink(binary(), bin.join("cwisim")).expect("link cwisim");
        let mut paths = vec![bin];
        paths.extend(std::env::split_paths(
            &std::env::var_os("PATH").unwrap_or_default(),
        ));
        Runner {
            name: name.to_owned(),
            work,
            path: std::env::join_paths(paths).expect("PATH"),
            root: built_root(),
            failures: Vec::new(),
            skip_block: None,
            variables: (usize::MAX, String::new()),
            total: Duration::ZERO,
            printed: Default::default(),
        }
    }

    /// Where a command is: `DOCUMENT:LINE`, or the help.
    fn at(&self, u: &Unit) -> String {
        match u.line {
            0 => self.name.clone(),
            n => format!("{}:{n}", self.name),
        }
    }

    fn skip(&self, u: &Unit, why: &str) {
        println!("{}: skipped ({why}): {}", self.at(u), first_line(&u.text));
    }

    /// Classifies the command, then runs it or says why not.
    fn consider(&mut self, u: &Unit) {
        let mut code = rewrite(&u.code);
        if !Path::new("/usr/bin/time").is_file() {
            // GNU time measures; without it, the command measured still runs
            code = without_time(&code);
        }
        let head = code.trim_start();
        if self.skip_block == Some(u.block) {
            return self.skip(u, "an earlier command of its block could not run");
        }
        if !matches!(u.check, Check::Status) && head.starts_with("cargo run --release -p ") {
            // an example program whose output the document shows
            let Some(dir) = std::env::var_os("CWISIM_EXAMPLES_DIR") else {
                return self.skip(
                    u,
                    "an example whose output the document shows: CWISIM_EXAMPLES_DIR (the built release examples, as .ci/run sets it) runs it",
                );
            };
            if long_entry(&self.name, &code).is_some() && !long_examples() {
                return self.skip(u, "long: CWISIM_LONG_EXAMPLES=1 runs it");
            }
            let Some(code) = example_command(&code, Path::new(&dir)) else {
                self.failures.push(format!(
                    "{}: not `cargo run --release -p PACKAGE --example NAME [-- ARGS]`: {}",
                    self.at(u),
                    u.text
                ));
                return;
            };
            return self.run(&Unit { code, ..u.clone() });
        }
        if let Some((_, why)) = SKIPPED.iter().find(|(p, _)| head.starts_with(p)) {
            return self.skip(u, why);
        }
        let invokes = !invocations(&code).is_empty();
        if !invokes {
            match SETUP.iter().find(|(p, _)| head.starts_with(p)) {
                None => {
                    self.failures.push(format!(
                        "{}: neither a cwisim command nor listed in SETUP or SKIPPED: {}",
                        self.at(u),
                        u.text
                    ));
                    return;
                }
                Some((_, Some(program))) if !on_path(program) => {
                    self.skip_block = Some(u.block);
                    return self.skip(u, &format!("{program} is not installed"));
                }
                Some(_) => {}
            }
        }
        if long_entry(&self.name, &code).is_some() && !long_examples() {
            return self.skip(u, "long: CWISIM_LONG_EXAMPLES=1 runs it");
        }
        self.run(&Unit { code, ..u.clone() });
    }

    /// Runs a command (its `cwisim`s already spelled so) and checks its status and flags.
    fn run(&mut self, u: &Unit) {
        let at = self.at(u);
        if let Some(printed) = self.printed.get(&u.code) {
            // a command already run for another of the document's tables
            if let Err(e) = output_shows(printed, &u.check) {
                self.failures.push(format!(
                    "{at}: the table is not what the command prints\n    {}\n  {e}",
                    u.text
                ));
            }
            return;
        }
        for args in invocations(&u.code) {
            if let Err(e) = check_flags(&self.root, &args) {
                self.failures.push(format!("{at}: {e}\n    {}", u.text));
            }
        }
        self.copy_repository_files(&u.code);
        if self.variables.0 != u.block {
            self.variables = (u.block, String::new());
        }
        let script = format!("{}{}", self.variables.1, u.code);
        if is_assignment(&u.code) {
            self.variables.1 += &format!("{}\n", u.code.trim());
        }
        let (out, err) = (self.work.join("../stdout"), self.work.join("../stderr"));
        let start = Instant::now();
        let status = Command::new(u.shell)
            .arg("-c")
            .arg(&script)
            .current_dir(&self.work)
            .env("PATH", &self.path)
            .stdin(Stdio::null())
            .stdout(std::fs::File::create(&out).expect("stdout file"))
            .stderr(std::fs::File::create(&err).expect("stderr file"))
            .status()
            .expect("run sh");
        let took = start.elapsed();
        self.total += took;
        let code = status.code().unwrap_or(-1);
        println!(
            "{at}: {} {:.1} s: {}",
            if code == u.status { "ok" } else { "FAILED" },
            took.as_secs_f64(),
            first_line(&u.text)
        );
        if code == u.status {
            let printed = std::fs::read_to_string(&out).unwrap_or_default();
            if matches!(u.check, Check::Table(_)) {
                self.printed.insert(u.code.clone(), printed.clone());
            }
            if let Err(e) = output_shows(&printed, &u.check) {
                self.failures.push(format!(
                    "{at}: the output is not what the document shows\n    {}\n  {e}",
                    u.text.replace('\n', "\n    ")
                ));
            }
        } else {
            let stderr = std::fs::read_to_string(&err).unwrap_or_default();
            let tail: Vec<&str> = stderr.lines().rev().take(20).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            self.failures.push(format!(
                "{at}: exit status {code}, expected {}\n    {}\n  stderr:\n    {}",
                u.status,
                u.text.replace('\n', "\n    "),
                tail.join("\n    ")
            ));
        }
    }

    /// Copies the repository's files a command names into the working directory, at the
    /// same relative paths (unless a command made one there already); `target/release/cwisim`
    /// is the binary.
    fn copy_repository_files(&self, code: &str) {
        let repo = common::repo();
        for word in code.split(|c: char| {
            c.is_whitespace() || matches!(c, '=' | '"' | '\'' | ';' | '|' | '>' | '<' | '(' | ')')
        }) {
            if word.is_empty() || word.starts_with(['/', '-', '$']) || word.contains("..") {
                continue;
            }
            let to = self.work.join(word);
            if to.exists() {
                continue;
            }
            if word == "target/release/cwisim" {
                std::fs::create_dir_all(to.parent().unwrap()).expect("target/release/");
                std::os::unix::fs::symlink(binary(), &to).expect("link target/release/cwisim");
            } else if repo.join(word).is_file() {
                std::fs::create_dir_all(to.parent().unwrap()).expect("a directory");
                std::fs::copy(repo.join(word), &to).expect("copy a repository file");
            }
        }
    }

    fn finish(self) {
        println!(
            "{}: {:.1} s in commands",
            self.name,
            self.total.as_secs_f64()
        );
        assert!(
            self.failures.is_empty(),
            "{} example(s) failed:\n\n{}",
            self.failures.len(),
            self.failures.join("\n\n")
        );
        let _ = std::fs::remove_dir_all(self.work);
    }
}

/// Whether a command's standard output shows what its [`Check`] asks.
fn output_shows(printed: &str, check: &Check) -> Result<(), String> {
    match check {
        Check::Status => Ok(()),
        Check::Table(table) => holds_table(printed, table),
        Check::Output(expected) => snapbox::Assert::new()
            .try_eq(
                Some(&"the command's output"),
                printed.to_owned().into(),
                (expected.clone() + "\n").into(),
            )
            .map_err(|e| e.to_string()),
    }
}

/// The command without `/usr/bin/time -f FORMAT` before it.
fn without_time(code: &str) -> String {
    let Some(at) = code.find("/usr/bin/time -f ") else {
        return code.to_owned();
    };
    let rest = &code[at + "/usr/bin/time -f ".len()..];
    let quote = rest.chars().next().filter(|c| matches!(c, '\'' | '"'));
    let format_end = match quote {
        Some(q) => rest[1..].find(q).map_or(rest.len(), |i| i + 2),
        None => rest.find(' ').unwrap_or(rest.len()),
    };
    format!("{}{}", &code[..at], rest[format_end..].trim_start())
}

/// `NAME=VALUE` alone: a shell variable the block's later commands read.
fn is_assignment(code: &str) -> bool {
    let code = code.trim();
    code.split_once('=').is_some_and(|(name, value)| {
        name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            && !name.is_empty()
            && !value.contains(char::is_whitespace)
    })
}

fn first_line(text: &str) -> &str {
    text.lines().next().unwrap_or("")
}

/// Runs every shell example of a document, in order, in a directory of its own.
fn run_document(doc: &str) {
    let text = std::fs::read_to_string(common::repo().join(doc)).expect("read the document");
    let mut runner = Runner::new(doc);
    prepare(doc, &text, &runner.work);
    for u in document_units(&text) {
        runner.consider(&u);
    }
    runner.finish();
}

/// Files a document's examples read that the document shows but no command of it makes.
fn prepare(doc: &str, text: &str, work: &Path) {
    if doc == "docs/RENDERERS.md" {
        // section 4(b): the Python script shown, and the example's blessed trace (its
        // snapshot), which the script's output must equal
        let blocks = blocks(text);
        let python: Vec<&Block> = blocks.iter().filter(|b| b.lang == "python").collect();
        assert_eq!(python.len(), 1, "{doc}: one Python block, rectangles.py");
        let script: Vec<&str> = python[0].lines.iter().map(|(_, l)| l.as_str()).collect();
        std::fs::write(work.join("rectangles.py"), script.join("\n") + "\n")
            .expect("rectangles.py");
        let snap = std::fs::read_to_string(
            common::repo()
                .join("crates/render/tests/snapshots/example_renderer__rectangles_cwt.snap"),
        )
        .expect("the rectangles snapshot");
        let trace = snap.splitn(3, "---\n").nth(2).expect("a snapshot body");
        std::fs::create_dir_all(work.join("expected")).expect("expected/");
        std::fs::write(work.join("expected/rectangles.cwt"), trace)
            .expect("expected/rectangles.cwt");
    }
}

/// A block tagged `lang` of these lines, numbered from 1.
fn block_of(lang: &str, lines: &[&str]) -> Block {
    Block {
        lang: lang.into(),
        lines: lines
            .iter()
            .enumerate()
            .map(|(i, l)| (i + 1, (*l).to_owned()))
            .collect(),
    }
}

#[test]
fn console_blocks_and_tables_give_the_output_to_check() {
    let block = block_of(
        "console",
        &[
            "$ cwisim render fig25 -o f.png \\",
            "    --threads 1   # exits 0",
            "...",
            "instructions 70 (Eval1 45, Eval2 7, Eval3 4, Refresh 14)",
            "...",
            "$ cwisim scenes pot > pot.json",
            "$ cwisim tradeoff fig25",
            "vanrij [..] 95 [..]",
        ],
    );
    let units = units(&block, 0);
    assert_eq!(units.len(), 3);
    assert_eq!(
        units[0].code,
        "cwisim render fig25 -o f.png \\\n    --threads 1"
    );
    let Check::Output(expected) = &units[0].check else {
        panic!("the lines under the command are its output")
    };
    assert_eq!(expected.lines().count(), 3);
    assert!(matches!(units[1].check, Check::Status));
    let printed = "scene x\ninstructions 70 (Eval1 45, Eval2 7, Eval3 4, Refresh 14)\ncycles 1\n";
    assert!(output_shows(printed, &units[0].check).is_ok());
    let drifted = printed.replace("Eval2 7", "Eval2 8");
    assert!(output_shows(&drifted, &units[0].check).is_err());
    assert!(output_shows("vanrij  - 95  1.0\n", &units[2].check).is_ok());
    assert!(output_shows("vanrij  - 96  1.0\n", &units[2].check).is_err());

    let doc =
        "text\n\n<!-- table from: cargo run --release -p p --example e -- 1 2; varying: ms -->\n\
               | a | ms |\n| --- | ---: |\n| x | 1.0 |\n| y | 2.0 |\n\nmore\n";
    let tables = table_units(doc);
    assert_eq!(tables.len(), 1);
    assert_eq!(tables[0].line, 3);
    assert_eq!(
        example_command(&tables[0].code, Path::new("/ex")).as_deref(),
        Some("/ex/e 1 2")
    );
    let table = |printed: &str| output_shows(printed, &tables[0].check);
    assert!(table("## T\n\n| a | ms |\n| --- | --- |\n| x | 9.9 |\n| y | 0.1 |\n").is_ok());
    assert!(table("| a | ms |\n| --- | --- |\n| x | 9.9 |\n| z | 0.1 |\n").is_err());
    assert!(table("| a | ms |\n| --- | --- |\n| x | 9.9 |\n").is_err());
    assert!(table("| a | ms |\n| --- | --- |\n| x | 9.9 |\n| y | 0.1 |\n| w | 0 |\n").is_err());
    assert!(table("| b | ms |\n| --- | --- |\n| x | 9.9 |\n| y | 0.1 |\n").is_err());
}

#[test]
fn the_parser_reads_shell_as_the_documents_write_it() {
    let block = block_of(
        "sh",
        &[
            "# a comment line",
            "cwisim run a.cwt \\",
            "  --stats   # exits 2: a note",
            "for t in 1 2; do",
            "  cwisim render --size ${t}0x10 -q",
            "done   # after",
            "cwisim diff a b > d.txt",
            "case $? in",
            "  *) exit 2 ;;",
            "esac",
            "N=3",
            "{ echo \"cwisim-trace x\"",
            "  yes 'a # b' | head -n $((3 * N)); } > long.cwt",
        ],
    );
    let units = units(&block, 0);
    let lines: Vec<usize> = units.iter().map(|u| u.line).collect();
    assert_eq!(lines, [2, 4, 7, 11, 12]);
    assert_eq!(units[0].status, 2);
    assert_eq!(units[0].code, "cwisim run a.cwt \\\n  --stats");
    assert!(units[2].code.ends_with("esac"));
    assert!(units[4].code.ends_with("> long.cwt"));
    assert!(is_assignment(&units[3].code));
    assert_eq!(invocations(&units[4].code), Vec::<Vec<String>>::new());
    assert_eq!(invocations(&units[0].code), [["run", "a.cwt", "--stats"]]);
    assert_eq!(
        without_time("/usr/bin/time -f '%M KB' cwisim run x.cwt"),
        "cwisim run x.cwt"
    );
    let root = built_root();
    let args = |s: &str| s.split(' ').map(str::to_owned).collect::<Vec<_>>();
    assert!(check_flags(&root, &args("history t.cwt --x 1 --line 0")).is_ok());
    assert!(check_flags(&root, &args("history t.cwt --x 1 --y 0")).is_err());
    assert!(check_flags(
        &root,
        &args("scenes generate cp-bench --family few -o f.json")
    )
    .is_ok());
    assert!(check_flags(&root, &args("stats t.cwt --json s.json")).is_err());
}
