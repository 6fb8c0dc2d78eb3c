//! What the user runs: the whole `cwisim render` command as a library function
//! ([`cwisim_host::cli::run_cli_with`]: argument parsing, scene loading, preparation,
//! the Y-processor and the array, the PNG written), so that the suite measures the
//! command-line path and not only its stages (`cargo bench -p cwisim-render --bench
//! pipeline -- stages_1024`).
//!
//! * `cli_render/pot_1024/exact`, `cli_render/pot_1024/eval0` — `cwisim render pot
//!   --size 1024x1024 --visibility V -o pot.png --quiet`, one thread. After each, five
//!   runs without `--quiet` print the command's own stage times (its summary's `time`
//!   line) to standard error.
//!
//! * `cli_process/pot_1024/exact`, `cli_process/pot_1024/eval0` — the same command as a
//!   fresh process of the built `cwisim` binary, as a user runs it: the process's start,
//!   its first touch of every page it writes (the image, the buffers) and its exit
//!   included. Five more runs print the process's own stage times to standard error.
//!
//! * `cli_inspect/pot/1`, `cli_inspect/pot/2` — `cwisim inspect pot -o i.html --threads
//!   N` as a fresh process: the page of the pot's frame with every pixel's history (the
//!   scene drawn, its summary and reference image, the replay with the visits, the page's
//!   arrays compressed).
//!
//! The figures are in docs/PERFORMANCE.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use cwisim_host::cli::run_cli_with;
use std::ffi::OsString;
use std::hint::black_box;
use std::process::Command;
use std::time::Duration;

fn cli_render(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("cwisim-bench-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let png = dir.join("pot.png");
    let mut g = c.benchmark_group("cli_render");
    g.sample_size(20).measurement_time(Duration::from_secs(6));
    for vis in ["exact", "eval0"] {
        let args: Vec<OsString> = [
            "cwisim",
            "render",
            "pot",
            "--size",
            "1024x1024",
            "--visibility",
            vis,
            "--quiet",
            "-o",
        ]
        .iter()
        .map(OsString::from)
        .chain([png.clone().into_os_string()])
        .collect();
        let run = |args: &[OsString]| {
            let (mut out, mut err) = (Vec::new(), Vec::new());
            let code = run_cli_with(args.to_vec(), &mut out, &mut err, false);
            assert_eq!(code, 0, "{}", String::from_utf8_lossy(&err));
            out
        };
        g.bench_function(BenchmarkId::new("pot_1024", vis), |b| {
            b.iter(|| black_box(run(&args)))
        });
        // the command's own account of its stages, in this process after the warm-up
        // (the figures to hold against `stages_1024`)
        let loud: Vec<OsString> = args.iter().filter(|a| *a != "--quiet").cloned().collect();
        print_stage_times("cli_render", vis, || run(&loud));
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

fn cli_process(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("cwisim-bench-process-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let png = dir.join("pot.png");
    let mut g = c.benchmark_group("cli_process");
    g.sample_size(20).measurement_time(Duration::from_secs(6));
    for vis in ["exact", "eval0"] {
        let run = |quiet: bool| {
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_cwisim"));
            cmd.args(["render", "pot", "--size", "1024x1024", "--threads", "1"])
                .args(["--visibility", vis, "-o"])
                .arg(&png);
            if quiet {
                cmd.arg("--quiet");
            }
            let out = cmd.output().expect("the cwisim binary runs");
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            out.stdout
        };
        g.bench_function(BenchmarkId::new("pot_1024", vis), |b| {
            b.iter(|| black_box(run(true)))
        });
        print_stage_times("cli_process", vis, || run(false));
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

fn cli_inspect(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("cwisim-bench-inspect-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let page = dir.join("i.html");
    let mut g = c.benchmark_group("cli_inspect");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for threads in ["1", "2"] {
        let run = || {
            let out = Command::new(env!("CARGO_BIN_EXE_cwisim"))
                .args(["inspect", "pot", "--threads", threads, "-o"])
                .arg(&page)
                .output()
                .expect("the cwisim binary runs");
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            out.stdout
        };
        g.bench_function(BenchmarkId::new("pot", threads), |b| {
            b.iter(|| black_box(run()))
        });
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `time` line of five more runs' summaries, to standard error: the command's own
/// account of its stages, after the warm-up (the figures to hold against `stages_1024`).
fn print_stage_times(group: &str, vis: &str, mut run: impl FnMut() -> Vec<u8>) {
    for _ in 0..5 {
        let out = String::from_utf8(run()).expect("utf-8");
        let times = out.lines().find(|l| l.starts_with("time")).unwrap_or("");
        eprintln!("{group} {vis}: {times}");
    }
}

criterion_group!(benches, cli_render, cli_process, cli_inspect);
criterion_main!(benches);
