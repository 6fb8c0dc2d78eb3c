//! docs/HARDWARE.md's FPGA table: for each scene and error budget, the format `fit` finds
//! (`cwisim rtl --max-error`), 16 processors of it placed and routed on each device
//! (`cwisim rtl --fpga DEVICE --fpga-processors 16`; as many as fit when 16 do not), and
//! the scene replayed at the clock the routed design reaches. Runs the `cwisim` binary (`CWISIM_BIN`, or
//! target/release/cwisim) once per row and prints a Markdown table; minutes per row.
//!
//! ```sh
//! cargo build --release && cargo run --release -p cwisim-host --example fpga_table -- pot:1/512 teapot:1/256
//! ```
//!
//! Arguments: `SCENE:BUDGET` pairs (default: pot:1/512); `--devices a,b` (default:
//! ice40-hx8k,ice40-up5k).

use std::path::PathBuf;
use std::process::Command;

/// Processors placed for each row: enough that the shell and the bus are a small share.
const PROCESSORS: &str = "16";

fn binary() -> PathBuf {
    std::env::var_os("CWISIM_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/release/cwisim")
        })
}

/// The value after `label` on its line of `out`, or "?".
fn field<'a>(out: &'a str, label: &str) -> &'a str {
    out.lines()
        .find_map(|l| l.strip_prefix(label))
        .map(str::trim)
        .unwrap_or("?")
}

fn main() {
    let mut rows: Vec<(String, String)> = Vec::new();
    let mut devices = vec!["ice40-hx8k".to_string(), "ice40-up5k".to_string()];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--devices" {
            let Some(list) = args.next() else {
                eprintln!("fpga_table: --devices needs a list");
                std::process::exit(2);
            };
            devices = list.split(',').map(str::to_string).collect();
        } else if let Some((scene, budget)) = a.split_once(':') {
            rows.push((scene.to_string(), budget.to_string()));
        } else {
            eprintln!("fpga_table: `{a}`: give SCENE:BUDGET pairs, e.g. pot:1/512");
            std::process::exit(2);
        }
    }
    if rows.is_empty() {
        rows.push(("pot".into(), "1/512".into()));
    }
    let bin = binary();
    if !bin.is_file() {
        eprintln!(
            "fpga_table: no cwisim binary at {} (cargo build --release, or set CWISIM_BIN)",
            bin.display()
        );
        std::process::exit(2);
    }
    let dir = std::env::temp_dir().join(format!("cwisim-fpga-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    println!("| scene | error budget | format | device | processors placed | logic cells | fmax MHz | processors per device | devices for the width | late scanlines at fmax |");
    println!("| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (scene, budget) in &rows {
        for device in &devices {
            let run = |processors: &str| {
                Command::new(&bin)
                    .args([
                        "rtl",
                        "--for",
                        scene,
                        "--max-error",
                        budget,
                        "-o",
                        "design.v",
                        "--fpga",
                        device,
                        "--fpga-processors",
                        processors,
                    ])
                    .current_dir(&dir)
                    .output()
                    .expect("run cwisim")
            };
            let mut out = run(PROCESSORS);
            let mut placed = PROCESSORS.to_string();
            if !out.status.success() {
                // too large: as many as the device holds, as the error says
                let err = String::from_utf8_lossy(&out.stderr).into_owned();
                if let Some(p) = err
                    .split("--fpga-processors ")
                    .nth(1)
                    .and_then(|r| r.split(')').next())
                {
                    placed = p.to_string();
                    out = run(p);
                }
            }
            let text = String::from_utf8_lossy(&out.stdout);
            if !out.status.success() {
                let err = String::from_utf8_lossy(&out.stderr);
                println!(
                    "| {scene} | {budget} | | {device} | | {} | | | | |",
                    err.trim().trim_start_matches("error: ")
                );
                continue;
            }
            let format = field(&text, "design")
                .split(';')
                .next()
                .unwrap_or("?")
                .trim_end_matches(",overflow=saturate");
            let fpga = field(&text, "fpga");
            let cells = fpga
                .split(": ")
                .nth(2)
                .and_then(|s| s.split(" of ").next())
                .unwrap_or("?");
            let fmax = field(&text, "fmax")
                .split_whitespace()
                .next()
                .unwrap_or("?");
            let fits = field(&text, "fits");
            let per_device = fits.split_whitespace().nth(1).unwrap_or("?");
            let devices_for_width = fits
                .split("; ")
                .nth(1)
                .and_then(|s| s.split_whitespace().next())
                .unwrap_or("?");
            let at = field(&text, "at fmax");
            let late = at
                .split(", ")
                .nth(1)
                .map(|s| s.trim_end_matches(" late"))
                .unwrap_or("?");
            println!(
                "| {scene} | {budget} | `{format}` | {device} | {placed} | {cells} | {fmax} | {per_device} | {devices_for_width} | {late} |"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
