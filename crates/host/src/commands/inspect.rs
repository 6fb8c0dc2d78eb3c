//! `cwisim inspect`: one frame as one self-contained HTML page — the image (values on
//! hover, the cost, error and late-scanline overlays), the scanline timeline with each
//! scanline's disassembly, and the pixel histories of a window. The page is built by
//! `cwisim_study::inspect`; this module reads the arguments and the input.

use super::MachineArgs;
use crate::cost_args::{check_extension, display_name};
use crate::draw::DrawArgs;
use crate::error::CliError;
use crate::files::{check_outputs, write_atomic};
use crate::input::InputKind;
use crate::progress::Stage;
use crate::range::{parse_range, Range};
use crate::summary::{write_render_summary, StageTimes};
use clap::Args;
use cwisim_isa::{Encoding, TraceRead};
use cwisim_render::{render, ArrayConfig, Taps};
use cwisim_scene::Shading;
use cwisim_study::inspect::{check_frame, inspect, Options, Window, MAX_HISTORY_PIXELS};
use cwisim_xproc::{NullSink, Timing};
use std::io::{Cursor, Write};
use std::path::PathBuf;

/// The arguments of `cwisim inspect`.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct InspectArgs {
    /// The trace (.cwt, .jsonl, .cwb), or a scene (a .json file or an embedded name:
    /// `cwisim scenes`) drawn with the drawing options below, as `render` draws it.
    #[arg(value_name = "TRACE|SCENE")]
    pub input: PathBuf,
    /// The page to write (.html).
    #[arg(short = 'o', long = "output", value_name = "OUT.html")]
    pub output: PathBuf,
    /// The frame to show (one frame, from 0; frames of the trace header's lines per
    /// frame). Default: 0.
    #[arg(long, value_name = "RANGE", value_parser = parse_range)]
    pub frames: Option<Range>,
    /// The processors whose pixel histories the page holds: N, A..B (B not included),
    /// A..=B or A.. . Default: every one, or the middle 256 of a frame over 512×512 pixels.
    #[arg(long, value_name = "X", value_parser = parse_range)]
    pub x: Option<Range>,
    /// The scanlines (over the whole trace) whose pixel histories the page holds, in the
    /// same syntax. Default: the frame's, or its middle 256 for a frame over 512×512.
    #[arg(long, value_name = "RANGE", value_parser = parse_range)]
    pub lines: Option<Range>,
    /// The machine model (for the cycles).
    #[command(flatten)]
    pub machine: MachineArgs,

    /// The array's registers: f64 (the reference), f32, or fixed point
    /// fixed:I=M.N,dI=M.N,ddI=M.N[,acc=M.N][,overflow=wrap|saturate] (M integer bits with
    /// the sign, N fraction bits; docs/ACCURACY.md).
    #[arg(long, value_name = "FORMAT", default_value = "f64")]
    pub numeric: cwisim_xproc::Numeric,
    /// How to draw a scene (refused with a trace).
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: DrawArgs,
}

/// `[start, end)` of a range within `0..len`, or why not.
fn span(r: Range, len: u64, flag: &str, what: &str) -> Result<(u64, u64), CliError> {
    let end = r.last.map_or(len, |l| l.saturating_add(1));
    if r.first >= len || end > len {
        return Err(CliError::Usage(format!(
            "{flag} {r} is outside the {what} 0..{len}"
        )));
    }
    Ok((r.first, end))
}

/// The history window `--x` and `--lines` ask for (`None`: the page's default).
fn window(
    args: &InspectArgs,
    width: u64,
    lines: u64,
    frame: u64,
) -> Result<Option<Window>, CliError> {
    let first = frame.saturating_mul(lines);
    if args.x.is_none() && args.lines.is_none() {
        return Ok(None);
    }
    let x = match args.x {
        Some(r) => span(r, width, "--x", "processors")?,
        None => (0, width),
    };
    let l = match args.lines {
        Some(r) => {
            let (a, b) = span(r, first + lines, "--lines", "scanlines of the trace")?;
            if a < first {
                return Err(CliError::Usage(format!(
                    "--lines {r} starts before frame {frame} (scanlines {first}..{})",
                    first + lines
                )));
            }
            (a, b)
        }
        None => (first, first + lines),
    };
    let w = Window { x, lines: l };
    if w.pixels() > MAX_HISTORY_PIXELS {
        return Err(CliError::Usage(format!(
            "--x and --lines select {} pixels; a page holds the histories of at most \
{MAX_HISTORY_PIXELS} (512×512)",
            w.pixels()
        )));
    }
    Ok(Some(w))
}

/// Runs `cwisim inspect`.
pub fn run(args: &InspectArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    let kind = InputKind::of(&args.input)?;
    crate::input::drawing_applies(&args.draw, &[Some(&args.input)])?;
    check_extension("-o", &args.output, "html")?;
    let input_file = args
        .input
        .exists()
        .then_some(("the input", args.input.as_path()));
    check_outputs(input_file, &[("-o", Some(args.output.as_path()))])?;
    let machine = args.machine.load()?;
    let frame = match args.frames {
        None => 0,
        Some(r) if r.last == Some(r.first) => r.first,
        Some(r) => {
            return Err(CliError::Usage(format!(
                "--frames {r}: a page shows one frame; give one number (--frames {})",
                r.first
            )))
        }
    };
    let name = display_name(&args.input);
    let mut summary = None;
    let mut reference = None;
    let stage = Stage::new(progress, "inspect: preparing the input");
    let (mut trace, drawn) = match kind {
        InputKind::Trace => (Some(crate::input::open(&args.input, &args.draw)?), None),
        InputKind::Scene => (None, Some(args.draw.draw(Some(&args.input))?)),
    };
    let header = match (&trace, &drawn) {
        (Some(t), _) => *t.header(),
        (None, Some(d)) => d.renderer.header(),
        (None, None) => unreachable!("a trace or a scene"),
    };
    let (width, lines) = (u64::from(header.width), u64::from(header.lines));
    check_frame(width, lines)?;
    let window = window(args, width, lines, frame)?;
    let mut reader: Box<dyn TraceRead> = match (trace.take(), drawn) {
        (Some(t), _) => t,
        (None, Some(drawn)) => {
            let renderer = &*drawn.renderer;
            let array = ArrayConfig {
                machine: machine.clone(),
                numeric: args.numeric,
                timing: Timing::Fast,
            };
            stage.message("inspect: rendering the scene for its summary");
            let rendered = render(renderer, &array, 1, &mut NullSink, Taps::default())?;
            let mut text = Vec::new();
            write_render_summary(
                &mut text,
                &drawn,
                &rendered,
                &args.numeric,
                &StageTimes::default(),
                &[],
            )
            .map_err(|e| CliError::Internal(format!("the summary in memory: {e}")))?;
            // no wall times: the page is the same on every run
            let text: Vec<&str> = std::str::from_utf8(&text)
                .map_err(|e| CliError::Internal(format!("the summary in memory: {e}")))?
                .lines()
                .filter(|l| !l.starts_with("time "))
                .collect();
            summary = Some(text.join("\n"));
            let settings = args.draw.settings();
            let what = if settings.shading == Shading::Phong {
                "Phong's best image (box filter, span tolerance 0, f64)"
            } else {
                "the exact box-filtered image of the exact visible surfaces"
            };
            stage.message("inspect: the reference image");
            let image = cwisim_study::tradeoff::reference_image(Some(&args.input), &settings)?;
            reference = Some((image, what));
            let mut bytes = Vec::new();
            {
                let mut writer = Encoding::Binary
                    .writer(&mut bytes, &header)
                    .map_err(|e| CliError::Internal(format!("encoding a stream in memory: {e}")))?;
                cwisim_render::emit(renderer, &mut *writer)?;
            }
            Encoding::Binary.reader(Cursor::new(bytes))?
        }
        (None, None) => unreachable!("a trace or a scene"),
    };
    stage.message("inspect: replaying on the stepped model, gathering every pixel's history");
    let page = inspect(
        &mut *reader,
        &machine,
        &Options {
            name: &name,
            kind: kind.name(),
            frame,
            window,
            summary: summary.as_deref(),
            reference: reference.as_ref().map(|(r, n)| (r.as_slice(), *n)),
            numeric: args.numeric,
        },
    )?;
    drop(stage);
    write_atomic(&args.output, |w| {
        w.write_all(page.html.as_bytes())
            .map_err(|e| CliError::write(&args.output, e))
    })?;
    writeln!(
        stdout,
        "wrote {}: {}×{} frame {frame}, {} late scanline(s), pixel histories for processors {}..{} \
of scanlines {}..{}; {:.1} MB",
        args.output.display(),
        page.width,
        page.lines,
        page.late_lines,
        page.window.x.0,
        page.window.x.1,
        page.window.lines.0,
        page.window.lines.1,
        page.html.len() as f64 / 1e6
    )
    .map_err(CliError::Stdout)
}
