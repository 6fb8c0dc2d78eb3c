//! docs/HARDWARE.md's FPGA table: for each scene and error budget, the format `fit` finds
//! (`cwisim rtl --max-error`), an array of it placed and routed on each device (`cwisim
//! rtl --fpga DEVICE --fpga-processors P`), and the scene replayed at the clock the routed
//! design reaches. Runs the `cwisim` binary (`CWISIM_BIN`, or target/release/cwisim) once
//! per row and prints a Markdown table; a minute or more per row.
//!
//! ```sh
//! cargo build --release -p cwisim-host --bin cwisim --example fpga_table
//! CWISIM_BIN=target/release/cwisim target/release/examples/fpga_table pot:1/512 still-life:1/512:7,5
//! ```
//!
//! Arguments: rows `SCENE:BUDGET[:P]` (default: pot:1/512), `P` the processors placed: one
//! count for every device, or one per device of `--devices` in order (`7,5`); 16 when left
//! out. A row whose processors the device does not hold shows the refusal, with the
//! processors that would fit by the report's estimate. `--devices a,b` (default:
//! ice40-hx8k,ice40-up5k).

use std::path::PathBuf;
use std::process::Command;

/// Processors placed when a row does not say: enough that the shell and the bus are a
/// small share.
const PROCESSORS: u32 = 16;

/// One row of arguments: a scene at an error budget, and the processors placed on each
/// device.
struct Row {
    scene: String,
    budget: String,
    processors: Vec<u32>,
}

impl Row {
    /// `SCENE:BUDGET[:P[,P…]]` for `devices` devices.
    fn parse(arg: &str, devices: usize) -> Result<Row, String> {
        let mut parts = arg.splitn(3, ':');
        let (Some(scene), Some(budget)) = (parts.next(), parts.next()) else {
            return Err(format!(
                "`{arg}`: give SCENE:BUDGET[:P], e.g. pot:1/512 or still-life:1/512:7,5"
            ));
        };
        let processors = match parts.next() {
            None => vec![PROCESSORS; devices],
            Some(list) => {
                let counts = list
                    .split(',')
                    .map(|p| p.trim().parse::<u32>().ok().filter(|p| *p > 0))
                    .collect::<Option<Vec<u32>>>()
                    .ok_or_else(|| {
                        format!("`{arg}`: the processors `{list}` are not counts of 1 or more")
                    })?;
                match counts.len() {
                    1 => vec![counts[0]; devices],
                    n if n == devices => counts,
                    n => {
                        return Err(format!(
                            "`{arg}`: {n} processor counts for {devices} device(s): give one, or one per device"
                        ))
                    }
                }
            }
        };
        Ok(Row {
            scene: scene.to_string(),
            budget: budget.to_string(),
            processors,
        })
    }
}

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

fn usage(message: &str) -> ! {
    eprintln!("fpga_table: {message}");
    std::process::exit(2);
}

/// The table's row for what `cwisim rtl … --fpga` printed.
fn row_of(scene: &str, budget: &str, device: &str, placed: u32, text: &str) -> String {
    let format = field(text, "design")
        .split(';')
        .next()
        .unwrap_or("?")
        .trim_end_matches(",overflow=saturate");
    let cells = field(text, "fpga")
        .split(": ")
        .nth(2)
        .and_then(|s| s.split(" of ").next())
        .unwrap_or("?");
    let fmax = field(text, "fmax").split_whitespace().next().unwrap_or("?");
    let fits = field(text, "fits");
    let per_device = fits.split_whitespace().nth(1).unwrap_or("?");
    let devices_for_width = fits
        .split("; ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .unwrap_or("?");
    let late = field(text, "at fmax")
        .split(", ")
        .nth(1)
        .map(|s| s.trim_end_matches(" scanline(s) late"))
        .unwrap_or("?");
    format!(
        "| {scene} | {budget} | `{format}` | {device} | {placed} | {cells} | {fmax} | {per_device} | {devices_for_width} | {late} |"
    )
}

fn main() {
    let mut args_rows: Vec<String> = Vec::new();
    let mut devices = vec!["ice40-hx8k".to_string(), "ice40-up5k".to_string()];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--devices" {
            let Some(list) = args.next() else {
                usage("--devices needs a list");
            };
            devices = list.split(',').map(str::to_string).collect();
        } else {
            args_rows.push(a);
        }
    }
    if args_rows.is_empty() {
        args_rows.push("pot:1/512".into());
    }
    let rows: Vec<Row> = args_rows
        .iter()
        .map(|a| Row::parse(a, devices.len()).unwrap_or_else(|e| usage(&e)))
        .collect();
    let bin = binary();
    if !bin.is_file() {
        usage(&format!(
            "no cwisim binary at {} (cargo build --release, or set CWISIM_BIN)",
            bin.display()
        ));
    }
    let dir = std::env::temp_dir().join(format!("cwisim-fpga-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    println!("| scene | error budget | format | device | processors placed | logic cells | fmax MHz | processors per device | devices for the width | late scanlines at fmax |");
    println!("| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for row in &rows {
        let (scene, budget) = (&row.scene, &row.budget);
        for (device, placed) in devices.iter().zip(&row.processors) {
            let out = Command::new(&bin)
                .args([
                    "rtl",
                    "--for",
                    scene,
                    "--max-error",
                    budget,
                    "-o",
                    "design.v",
                ])
                .args(["--fpga", device, "--fpga-processors", &placed.to_string()])
                .current_dir(&dir)
                .output()
                .expect("run cwisim");
            if out.status.success() {
                let text = String::from_utf8_lossy(&out.stdout);
                println!("{}", row_of(scene, budget, device, *placed, &text));
            } else {
                let err = String::from_utf8_lossy(&out.stderr);
                println!(
                    "| {scene} | {budget} | | {device} | {placed} | {} | | | | |",
                    err.trim().trim_start_matches("error: ")
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
