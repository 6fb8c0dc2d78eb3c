//! `cwisim diff A B`: compare two traces, or two outputs.
//!
//! * Two traces (`.cwt`, `.jsonl`, `.cwb`, in any mix of encodings): the instruction
//!   streams — the first differing instruction and its scanline, and the count of each
//!   opcode on each side.
//! * Two outputs (`.npy` files, or traces replayed with `--output`): per scanline the max
//!   and RMS difference, and `--image` for an error image.
//!
//! Exit status 0 when equal, 1 when different, 2 on bad input.

use super::MachineArgs;
use crate::error::CliError;
use clap::Args;
use cwisim_isa::Opcode;
use cwisim_xproc::{Image, ImageSink, OpcodeCounts, Timing};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The arguments of `cwisim diff`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct DiffArgs {
    /// The first trace or output (.cwt, .jsonl, .cwb, .npy), or a scene (a .json file or
    /// an embedded name) drawn with the drawing options below.
    #[arg(value_name = "A")]
    pub a: PathBuf,
    /// The second trace, output or scene.
    #[arg(value_name = "B")]
    pub b: PathBuf,
    /// Compare what two traces output (replayed) instead of their instructions.
    /// `--output` is its old name.
    #[arg(long = "outputs", alias = "output")]
    pub output: bool,
    /// Differences up to this much count as equal (outputs only).
    #[arg(long, value_name = "T", default_value_t = 0.0)]
    pub tolerance: f64,
    /// Write the error image: per pixel the largest difference over the channels, black
    /// for none, white for the largest in the image (outputs only).
    #[arg(long, value_name = "OUT.png")]
    pub image: Option<PathBuf>,
    /// The machine model (for replaying traces).
    #[command(flatten)]
    pub machine: MachineArgs,

    /// The array's registers: f64 (the reference), f32, or fixed point
    /// fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate] (M integer bits with
    /// the sign, N fraction bits; docs/ACCURACY.md).
    #[arg(long, value_name = "FORMAT", default_value = "f64")]
    pub numeric: cwisim_xproc::Numeric,
    /// How to draw a scene (refused when neither input is one).
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: crate::draw::DrawArgs,
}

fn is_npy(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// Runs `cwisim diff`; `Ok(true)` when equal.
pub fn run(args: &DiffArgs, stdout: &mut dyn Write) -> Result<bool, CliError> {
    crate::input::drawing_applies(&args.draw, &[Some(&args.a), Some(&args.b)])?;
    if !(args.tolerance >= 0.0 && args.tolerance.is_finite()) {
        return Err(CliError::Usage(format!(
            "--tolerance {} must be a finite number ≥ 0",
            args.tolerance
        )));
    }
    let outputs = args.output || is_npy(&args.a) || is_npy(&args.b);
    let replays = outputs && !(is_npy(&args.a) && is_npy(&args.b));
    if !replays && args.numeric != cwisim_xproc::Numeric::F64 {
        return Err(CliError::Usage(
            "--numeric sets the registers a trace is replayed on: it applies with --outputs, to a side that is a trace or a scene".into(),
        ));
    }
    if !outputs && args.image.is_some() {
        return Err(CliError::Usage(
            "--image compares outputs: add --outputs, or give .npy files".into(),
        ));
    }
    if let Some(p) = &args.image {
        crate::cost_args::check_extension("--image", p, "png")?;
    }
    crate::files::Io::new()
        .source("side A", Some(&args.a))
        .source("side B", Some(&args.b))
        .output("--image", args.image.as_deref())
        .check()?;
    if outputs {
        let a = load_output(&args.a, args)?;
        let b = load_output(&args.b, args)?;
        compare_outputs(&a, &b, args, stdout)
    } else {
        compare_traces(&args.a, &args.b, &args.draw, stdout)
    }
}

fn out(stdout: &mut dyn Write, s: String) -> Result<(), CliError> {
    writeln!(stdout, "{s}").map_err(CliError::Stdout)
}

fn counts_line(c: &OpcodeCounts) -> String {
    let parts: Vec<String> = Opcode::ALL
        .iter()
        .filter(|op| c.get(**op) > 0)
        .map(|op| format!("{op} {}", c.get(*op)))
        .collect();
    if parts.is_empty() {
        "no instructions".into()
    } else {
        parts.join(", ")
    }
}

fn compare_traces(
    a: &Path,
    b: &Path,
    draw: &crate::draw::DrawArgs,
    stdout: &mut dyn Write,
) -> Result<bool, CliError> {
    let (mut ra, mut rb) = (crate::input::open(a, draw)?, crate::input::open(b, draw)?);
    let (ha, hb) = (*ra.header(), *rb.header());
    let mut equal = true;
    if ha != hb {
        equal = false;
        out(
            stdout,
            format!(
                "headers differ: A is {} wide, {} lines, {} channel(s); B is {} wide, {} lines, {} channel(s)",
                ha.width, ha.lines, ha.channels, hb.width, hb.lines, hb.channels
            ),
        )?;
    }
    let (mut ca, mut cb) = (OpcodeCounts::default(), OpcodeCounts::default());
    let (mut index, mut line) = (0u64, 0u64);
    let mut first: Option<String> = None;
    loop {
        let (ia, ib) = (ra.next_instruction()?, rb.next_instruction()?);
        if ia.is_none() && ib.is_none() {
            break;
        }
        if let Some(i) = &ia {
            ca.0[i.op.index()] += 1;
        }
        if let Some(i) = &ib {
            cb.0[i.op.index()] += 1;
        }
        if first.is_none() && ia != ib {
            let show = |i: &Option<cwisim_isa::Instruction>| {
                i.as_ref()
                    .map_or("(end of trace)".to_string(), |i| i.to_string())
            };
            first = Some(format!(
                "first difference: instruction #{index}, scanline {line}\n  A: {}\n  B: {}",
                show(&ia),
                show(&ib)
            ));
        }
        if ia.as_ref().is_some_and(|i| i.op == Opcode::Refresh) {
            line += 1;
        }
        index += 1;
    }
    if let Some(f) = first {
        equal = false;
        out(stdout, f)?;
    }
    out(stdout, format!("A: {}", counts_line(&ca)))?;
    out(stdout, format!("B: {}", counts_line(&cb)))?;
    out(
        stdout,
        if equal {
            "the traces are equal".into()
        } else {
            "the traces differ".into()
        },
    )?;
    Ok(equal)
}

fn load_output(path: &Path, args: &DiffArgs) -> Result<Image, CliError> {
    if is_npy(path) {
        return read_npy(path);
    }
    let machine = args.machine.load()?;
    let mut reader = crate::input::open(path, &args.draw)?;
    let h = *reader.header();
    // two images are held at once: each gets half the memory budget
    let mut sink = ImageSink::new(
        h.width as usize,
        h.channel_count(),
        cwisim_scene::budget::Budget::current().memory_bytes / 2,
    );
    cwisim_xproc::replay_numeric(
        &mut *reader,
        &machine,
        Timing::Fast,
        &args.numeric,
        &mut sink,
        &mut |_| {},
    )?;
    Ok(sink.finish()?)
}

fn read_npy(path: &Path) -> Result<Image, CliError> {
    let bad = |m: String| CliError::Usage(format!("{}: {m}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| bad(format!("cannot read: {e}")))?;
    let file =
        npyz::NpyFile::new(&bytes[..]).map_err(|e| bad(format!("not a NumPy .npy file: {e}")))?;
    let shape: Vec<u64> = file.shape().to_vec();
    let (lines, width, channels) = match shape[..] {
        [l, w] => (l, w, 1),
        [l, w, c] => (l, w, c),
        _ => {
            return Err(bad(format!(
                "shape {shape:?}; expected (scanlines, width) or (scanlines, width, channels)"
            )))
        }
    };
    if file.order() != npyz::Order::C {
        return Err(bad("Fortran order; expected C order".into()));
    }
    let data = file
        .into_vec::<f64>()
        .map_err(|e| bad(format!("expected float64 values: {e}")))?;
    Ok(Image {
        width: width as usize,
        channels: channels as usize,
        lines: lines as usize,
        data,
    })
}

fn compare_outputs(
    a: &Image,
    b: &Image,
    args: &DiffArgs,
    stdout: &mut dyn Write,
) -> Result<bool, CliError> {
    if (a.lines, a.width, a.channels) != (b.lines, b.width, b.channels) {
        out(
            stdout,
            format!(
                "shapes differ: A is ({}, {}, {}), B is ({}, {}, {}) (scanlines, width, channels)",
                a.lines, a.width, a.channels, b.lines, b.width, b.channels
            ),
        )?;
        return Ok(false);
    }
    let row = a.width * a.channels;
    let mut differing = 0usize;
    let (mut worst, mut sum_sq) = (0.0f64, 0.0f64);
    let mut table = Vec::new();
    for l in 0..a.lines {
        let (ra, rb) = (
            &a.data[l * row..(l + 1) * row],
            &b.data[l * row..(l + 1) * row],
        );
        let (mut max, mut sq) = (0.0f64, 0.0f64);
        for (x, y) in ra.iter().zip(rb) {
            let d = if x == y || (x.is_nan() && y.is_nan()) {
                0.0
            } else {
                (x - y).abs()
            };
            let d = if d.is_nan() { f64::INFINITY } else { d };
            max = max.max(d);
            sq += d * d;
        }
        sum_sq += sq;
        worst = worst.max(max);
        if max > args.tolerance {
            differing += 1;
            table.push(format!(
                "{l:>8}  {max:>12.6e}  {:>12.6e}",
                (sq / row.max(1) as f64).sqrt()
            ));
        }
    }
    let equal = differing == 0;
    if !equal {
        out(
            stdout,
            format!("{:>8}  {:>12}  {:>12}", "scanline", "max |A-B|", "RMS"),
        )?;
        for t in table {
            out(stdout, t)?;
        }
    }
    let rms = (sum_sq / a.data.len().max(1) as f64).sqrt();
    out(
        stdout,
        format!(
            "{} of {} scanline(s) differ (tolerance {}); max |A-B| {worst:.6e}, RMS {rms:.6e}",
            differing, a.lines, args.tolerance
        ),
    )?;
    if let Some(path) = &args.image {
        write_error_image(path, a, b, worst)?;
    }
    Ok(equal)
}

fn write_error_image(path: &Path, a: &Image, b: &Image, worst: f64) -> Result<(), CliError> {
    if a.lines == 0 || a.width == 0 {
        return Err(CliError::Usage(
            "the outputs hold no scanline: no error image to write".into(),
        ));
    }
    let scale = if worst > 0.0 && worst.is_finite() {
        1.0 / worst
    } else {
        0.0
    };
    let data = a
        .data
        .chunks(a.channels)
        .zip(b.data.chunks(b.channels))
        .map(|(p, q)| {
            let d = p
                .iter()
                .zip(q)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            if d.is_finite() {
                d * scale
            } else {
                1.0
            }
        })
        .collect();
    let errors = Image {
        width: a.width,
        channels: 1,
        lines: a.lines,
        data,
    };
    crate::output::write_png(path, &errors)
}
