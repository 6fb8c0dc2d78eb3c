//! `cwisim inspect`: frames as one self-contained HTML page — the image (values on
//! hover, the cost, error, difference and late-scanline overlays), the scanline timeline,
//! each scanline's events cycle by cycle with its disassembly, and the pixel histories of
//! a window; with `--against`, two runs on one page (A/B). The page is built by
//! `cwisim_study::inspect`; this module reads the arguments and the inputs.

use super::MachineArgs;
use crate::cost_args::{check_extension, display_name};
use crate::draw::DrawArgs;
use crate::error::CliError;
use crate::files::{write_atomic, Io};
use crate::input::InputKind;
use crate::progress::Stage;
use crate::range::{parse_range, Range};
use crate::summary::{write_render_summary, StageTimes};
use clap::{Args, CommandFactory, FromArgMatches, Parser, ValueEnum};
use cwisim_isa::{Opcode, TraceHeader, TraceRead};
use cwisim_render::{render, ArrayConfig, Taps};
use cwisim_scene::Shading;
use cwisim_study::inspect::{
    check_frame, check_frames, inspect, inspect_pair, Options, Page, Run, Window,
    MAX_HISTORY_PIXELS,
};
use cwisim_xproc::{Machine, NullSink, Numeric, Timing};
use std::io::Write;
use std::path::{Path, PathBuf};

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
    /// The frames to show: N, A..B (B not included), A..=B or A.. (to the end of the
    /// input); frames of the trace header's lines per frame. A page of several frames has
    /// a frame selector (at most 64 frames, 2048×2048 pixels in all). Default: 0.
    #[arg(long, value_name = "RANGE", value_parser = parse_range)]
    pub frames: Option<Range>,
    /// The processors whose pixel histories the page holds: N, A..B (B not included),
    /// A..=B or A.. . Default: every one, or the middle 256 of a frame over 512×512 pixels.
    #[arg(long, value_name = "X", value_parser = parse_range)]
    pub x: Option<Range>,
    /// The scanlines (over the whole trace) whose pixel histories the page holds, in the
    /// same syntax, within the frames shown. Default: every frame's, or the middle 256 of
    /// frames over 512×512 (less when several frames share the 512×512 budget).
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
    /// Compare with a second run B on the same page (A/B: a toggle between the runs and
    /// an overlay of their difference): B is a trace or a scene followed by its own
    /// drawing flags, --numeric, --machine and --set, quoted as one argument, e.g.
    /// --against "pot --renderer woo-chall" or --against b.cwt. Nothing of A's flags is
    /// taken; the frames and the history window are A's. Both runs must have the same
    /// width, lines and channels.
    #[arg(long, value_name = "B [FLAGS]")]
    pub against: Option<String>,
    /// Threads: a scene's exact visibility and its summary's rendering run on N threads,
    /// as `render --threads N` runs them, and the page's arrays are compressed on N
    /// threads (0: one per core). The page is identical at any N, byte for byte.
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub threads: usize,
    /// How to draw a scene (refused with a trace).
    #[command(flatten, next_help_heading = crate::draw::SCENE_ONLY)]
    pub draw: DrawArgs,
}

/// The second run of an A/B page, as `--against` spells it.
#[derive(Parser, Clone, Debug, PartialEq)]
#[command(
    name = "--against",
    disable_help_flag = true,
    disable_version_flag = true
)]
struct AgainstArgs {
    /// B: a trace or a scene.
    #[arg(value_name = "TRACE|SCENE")]
    input: PathBuf,
    #[command(flatten)]
    machine: MachineArgs,
    #[arg(long, value_name = "FORMAT", default_value = "f64")]
    numeric: Numeric,
    #[command(flatten)]
    draw: DrawArgs,
}

/// Splits `--against`'s text into words as a POSIX shell does: blanks separate them,
/// single quotes keep everything, double quotes keep all but `\"` and `\\`, a backslash
/// outside quotes keeps the next character.
fn split_words(text: &str) -> Result<Vec<String>, String> {
    let mut words = Vec::new();
    let mut word: Option<String> = None;
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        match c {
            c if c.is_whitespace() => {
                if let Some(w) = word.take() {
                    words.push(w);
                }
            }
            '\'' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => w.push(c),
                        None => return Err("an unclosed ' quote".into()),
                    }
                }
            }
            '"' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(c @ ('"' | '\\')) => w.push(c),
                            Some(c) => {
                                w.push('\\');
                                w.push(c);
                            }
                            None => return Err("an unclosed \" quote".into()),
                        },
                        Some(c) => w.push(c),
                        None => return Err("an unclosed \" quote".into()),
                    }
                }
            }
            '\\' => match chars.next() {
                Some(c) => word.get_or_insert_with(String::new).push(c),
                None => return Err("a \\ at the end".into()),
            },
            c => word.get_or_insert_with(String::new).push(c),
        }
    }
    words.extend(word);
    Ok(words)
}

/// Reads `--against`'s text: B and its flags, parsed as `inspect` parses its own.
fn parse_against(text: &str) -> Result<AgainstArgs, CliError> {
    let bad = |why: String| CliError::Usage(format!("--against {text:?}: {why}"));
    let words = split_words(text).map_err(bad)?;
    if words.is_empty() {
        return Err(bad("name B, a trace or a scene, and its flags".into()));
    }
    let matches = AgainstArgs::command()
        .try_get_matches_from(std::iter::once("--against".to_string()).chain(words))
        .map_err(|e| {
            // clap's message, first line, without its `error: `
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("").trim();
            bad(first.strip_prefix("error: ").unwrap_or(first).to_string())
        })?;
    let mut args = AgainstArgs::from_arg_matches(&matches).map_err(|e| bad(e.to_string()))?;
    args.draw.note_given(&matches);
    Ok(args)
}

/// A drawing flag's value as the command line gives it (`None` for a switch); `Err` for
/// a flag this function does not know (a test holds it to every flag of the group).
fn draw_value(d: &DrawArgs, flag: &str) -> Result<Option<String>, ()> {
    fn name<E: ValueEnum>(e: &E) -> Option<String> {
        e.to_possible_value().map(|p| p.get_name().to_string())
    }
    let num = |v: f64| Some(format!("{v:?}"));
    Ok(match flag {
        "--renderer" => Some(d.renderer.clone()),
        "--shading" => name(&d.shading),
        "--aa" => name(&d.aa),
        "--visibility" => name(&d.visibility),
        "--eval0-tolerance" => num(d.eval0_tolerance),
        "--size" => d.size.map(|s| s.to_string()),
        "--shade-tolerance" => num(d.shade_tolerance),
        "--tessellate" => d.tessellate.map(|n| n.to_string()),
        "--samples" => Some(d.samples.to_string()),
        "--grid" => name(&d.grid),
        "--merge-subscanlines" => None,
        "--shade-p" => d.shade_p.and_then(num),
        "--shade-contrast" => num(d.shade_contrast),
        "--seed" => Some(d.seed.to_string()),
        "--cp-increment" => name(&d.cp_increment),
        "--sbuffer" => name(&d.sbuffer),
        "--order" => name(&d.order),
        "--unset" => name(&d.unset),
        "--root-tolerance" => num(d.root_tolerance),
        "--flatness" => num(d.flatness),
        "--normal-angle" => d
            .normal_angle
            .map(|a| a.0.and_then(num).unwrap_or_else(|| "off".into())),
        "--band" => Some(d.band.to_string()),
        "--subscan" => Some(d.subscan.to_string()),
        "--gouraud-threshold" => Some(d.gouraud_threshold.to_string()),
        "--aa-threshold" => Some(d.aa_threshold.to_string()),
        "--phong-angle" => Some(d.phong_angle.to_string()),
        "--shadows" => d.shadows.as_ref().and_then(name),
        "--texture-filter" => name(&d.texture_filter),
        _ => return Err(()),
    })
}

/// The input as given and the flags that make a run what the page shows — the drawing
/// flags given, `--numeric`, `--machine`, `--set` — for the `cwisim history` command the
/// page suggests.
fn reproduce(
    input: &Path,
    draw: &DrawArgs,
    machine: &MachineArgs,
    numeric: &Numeric,
) -> Vec<String> {
    let mut out = vec![input.to_string_lossy().into_owned()];
    for flag in &draw.given {
        out.push(flag.to_string());
        match draw_value(draw, flag) {
            Ok(Some(v)) => out.push(v),
            Ok(None) => {}
            Err(()) => out.push("…".into()),
        }
    }
    if *numeric != Numeric::F64 {
        out.extend(["--numeric".to_string(), numeric.to_string()]);
    }
    if let Some(m) = &machine.machine {
        out.extend(["--machine".to_string(), m.to_string_lossy().into_owned()]);
    }
    for s in &machine.set {
        out.extend(["--set".to_string(), s.clone()]);
    }
    out
}

/// One run's input, opened: a trace's reader, or a scene drawn (its renderer built).
struct Opened {
    name: String,
    kind: InputKind,
    header: TraceHeader,
    source: OpenedSource,
    machine: Machine,
    numeric: Numeric,
    reproduce: Vec<String>,
}

enum OpenedSource {
    Trace(Box<dyn TraceRead>),
    Scene(crate::draw::Drawn),
}

/// What a run's page part needs besides the replay.
struct Prepared {
    name: String,
    kind: InputKind,
    summary: Option<String>,
    reference: Option<(Vec<f64>, &'static str)>,
    machine: Machine,
    numeric: Numeric,
    reproduce: Vec<String>,
}

/// Opens a run's input: cheap, so that the dimensions and the limits are checked before
/// a scene is rendered.
fn open(
    input: &Path,
    draw: &DrawArgs,
    machine_args: &MachineArgs,
    numeric: Numeric,
    threads: usize,
) -> Result<Opened, CliError> {
    let kind = InputKind::of(input)?;
    let machine = machine_args.load()?;
    let (header, source) = match kind {
        InputKind::Trace => {
            let reader = crate::input::open(input, draw)?;
            (*reader.header(), OpenedSource::Trace(reader))
        }
        InputKind::Scene => {
            let drawn = draw.draw_on(Some(input), threads)?;
            (drawn.renderer.header(), OpenedSource::Scene(drawn))
        }
    };
    check_frame(u64::from(header.width), u64::from(header.lines))?;
    Ok(Opened {
        name: display_name(input),
        kind,
        header,
        source,
        machine,
        numeric,
        reproduce: reproduce(input, draw, machine_args, &numeric),
    })
}

impl Opened {
    /// The whole frames of the input (for `--frames A..`): a scene draws one; a trace is
    /// read once more to count them.
    fn whole_frames(&self, input: &Path, draw: &DrawArgs) -> Result<u64, CliError> {
        if self.kind == InputKind::Scene {
            return Ok(1);
        }
        let mut reader = crate::input::open(input, draw)?;
        let mut lines = 0u64;
        while let Some(i) = reader.next_instruction()? {
            lines += u64::from(i.op == Opcode::Refresh);
        }
        Ok(lines / u64::from(self.header.lines.max(1)))
    }

    /// A scene: its summary (as `render` prints it, without wall times), its reference
    /// image and its stream; the reader.
    fn finish(
        self,
        draw: &DrawArgs,
        input: &Path,
        threads: usize,
        stage: &Stage,
    ) -> Result<(Prepared, Box<dyn TraceRead>), CliError> {
        let mut prepared = Prepared {
            name: self.name,
            kind: self.kind,
            summary: None,
            reference: None,
            machine: self.machine,
            numeric: self.numeric,
            reproduce: self.reproduce,
        };
        let drawn = match self.source {
            OpenedSource::Trace(reader) => return Ok((prepared, reader)),
            OpenedSource::Scene(drawn) => drawn,
        };
        let renderer = &*drawn.renderer;
        let array = ArrayConfig {
            machine: prepared.machine.clone(),
            numeric: prepared.numeric,
            timing: Timing::Fast,
        };
        stage.message("inspect: rendering the scene for its summary");
        let rendered = render(renderer, &array, threads, &mut NullSink, Taps::default())?;
        let mut text = Vec::new();
        write_render_summary(
            &mut text,
            &drawn,
            &rendered,
            &prepared.numeric,
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
        prepared.summary = Some(text.join("\n"));
        let settings = draw.settings();
        let what = if settings.shading == Shading::Phong {
            "Phong's best image (box filter, span tolerance 0, f64)"
        } else {
            "the exact box-filtered image of the exact visible surfaces"
        };
        stage.message("inspect: the reference image");
        let image = cwisim_study::tradeoff::reference_image(Some(input), &settings)?;
        prepared.reference = Some((image, what));
        // with its notes: the page shows where each instruction came from
        let (reader, _) = crate::input::emitted(renderer, true)?;
        Ok((prepared, reader))
    }
}

impl Prepared {
    fn options<'a>(
        &'a self,
        frames: (u64, u64),
        window: Option<Window>,
        threads: usize,
    ) -> Options<'a> {
        Options {
            name: &self.name,
            kind: self.kind.name(),
            frames,
            window,
            summary: self.summary.as_deref(),
            reference: self.reference.as_ref().map(|(r, n)| (r.as_slice(), *n)),
            numeric: self.numeric,
            reproduce: &self.reproduce,
            threads,
        }
    }
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
    frames: (u64, u64),
    runs: u64,
) -> Result<Option<Window>, CliError> {
    let first = frames.0.saturating_mul(lines);
    let end = frames.1.saturating_mul(lines);
    if args.x.is_none() && args.lines.is_none() {
        return Ok(None);
    }
    let x = match args.x {
        Some(r) => span(r, width, "--x", "processors")?,
        None => (0, width),
    };
    let l = match args.lines {
        Some(r) => {
            let (a, b) = span(r, end, "--lines", "scanlines of the trace")?;
            if a < first {
                let which = if frames.1 == frames.0 + 1 {
                    format!("frame {}", frames.0)
                } else {
                    format!("frames {}..{}", frames.0, frames.1)
                };
                return Err(CliError::Usage(format!(
                    "--lines {r} starts before {which} (scanlines {first}..{end})"
                )));
            }
            (a, b)
        }
        None => (first, end),
    };
    let w = Window { x, lines: l };
    let limit = MAX_HISTORY_PIXELS / runs;
    if w.pixels() > limit {
        let of = if runs > 1 {
            " in each of the two runs"
        } else {
            ""
        };
        return Err(CliError::Usage(format!(
            "--x and --lines select {} pixels; a page holds the histories of at most \
{limit}{of} (512×512 in all)",
            w.pixels()
        )));
    }
    Ok(Some(w))
}

/// `processors A..B of scanlines C..D, E..F`: the windows, contiguous ones merged.
fn windows_text(windows: &[Window]) -> String {
    /// Processors, and the scanline ranges with those processors.
    type Part = ((u64, u64), Vec<(u64, u64)>);
    let mut parts: Vec<Part> = Vec::new();
    for w in windows {
        match parts.last_mut() {
            Some((x, lines)) if *x == w.x => match lines.last_mut() {
                Some(l) if l.1 == w.lines.0 => l.1 = w.lines.1,
                _ => lines.push(w.lines),
            },
            _ => parts.push((w.x, vec![w.lines])),
        }
    }
    if parts.is_empty() {
        return "no pixel histories".into();
    }
    let text: Vec<String> = parts
        .iter()
        .map(|(x, lines)| {
            let l: Vec<String> = lines.iter().map(|(a, b)| format!("{a}..{b}")).collect();
            format!("processors {}..{} of scanlines {}", x.0, x.1, l.join(", "))
        })
        .collect();
    format!("pixel histories for {}", text.join("; "))
}

/// Runs `cwisim inspect`.
pub fn run(args: &InspectArgs, stdout: &mut dyn Write, progress: bool) -> Result<(), CliError> {
    InputKind::of(&args.input)?;
    crate::input::drawing_applies(&args.draw, &[Some(&args.input)])?;
    check_extension("-o", &args.output, "html")?;
    let against = args.against.as_deref().map(parse_against).transpose()?;
    if let Some(b) = &against {
        InputKind::of(&b.input)?;
        crate::input::drawing_applies(&b.draw, &[Some(&b.input)])?;
    }
    let mut io = Io::new()
        .source("input", Some(&args.input))
        .machine(&args.machine);
    if let Some(b) = &against {
        io = io.source("input B", Some(&b.input)).machine(&b.machine);
    }
    io.output("-o", Some(&args.output)).check()?;

    let stage = Stage::new(progress, "inspect: preparing the input");
    let threads = cwisim_scene::budget::check_threads(args.threads).map_err(CliError::Usage)?;
    let a = open(
        &args.input,
        &args.draw,
        &args.machine,
        args.numeric,
        threads,
    )?;
    let mut b = match &against {
        Some(spec) => Some(open(
            &spec.input,
            &spec.draw,
            &spec.machine,
            spec.numeric,
            threads,
        )?),
        None => None,
    };
    if let Some(b) = &b {
        cwisim_study::inspect::check_same_dimensions((&a.name, &a.header), (&b.name, &b.header))?;
    }
    let (width, lines) = (u64::from(a.header.width), u64::from(a.header.lines));
    let beyond = |f: u64| CliError::Usage(format!("--frames: frame {f} is beyond any trace"));
    let frames = match args.frames {
        None => (0, 1),
        Some(r) => match r.last {
            Some(l) => (r.first, l.checked_add(1).ok_or_else(|| beyond(l))?),
            None => {
                stage.message("inspect: counting the frames of the input");
                let whole = a.whole_frames(&args.input, &args.draw)?;
                let next = r.first.checked_add(1).ok_or_else(|| beyond(r.first))?;
                (r.first, whole.max(next))
            }
        },
    };
    let runs = if b.is_some() { 2 } else { 1 };
    // the limits, before any scene is rendered or anything replayed
    check_frames(width, lines, frames.1.saturating_sub(frames.0), runs)?;
    // the frames' images and references (8 bytes a value) and costs (4 a pixel), of every
    // run, against the memory budget before any is made
    let pixels = width
        .saturating_mul(lines)
        .saturating_mul(frames.1.saturating_sub(frames.0))
        .saturating_mul(runs);
    let channels = a.header.channel_count() as u64;
    cwisim_scene::budget::Budget::current().check_memory(
        &format!("the page's images ({pixels} pixels of {channels} channel(s), with their references and costs)"),
        pixels.saturating_mul(16 * channels + 4),
    )?;
    let window = window(args, width, lines, frames, runs)?;
    let (a, mut reader_a) = a.finish(&args.draw, &args.input, threads, &stage)?;
    let mut b = match (b.take(), &against) {
        (Some(b), Some(spec)) => Some(b.finish(&spec.draw, &spec.input, threads, &stage)?),
        _ => None,
    };
    stage.message("inspect: replaying, gathering every pixel's history");
    let page: Page = match &mut b {
        None => inspect(
            &mut *reader_a,
            &a.machine,
            &a.options(frames, window, threads),
        )?,
        Some((b, reader_b)) => inspect_pair(
            Run {
                trace: &mut *reader_a,
                machine: &a.machine,
                opts: a.options(frames, window, threads),
            },
            Run {
                trace: &mut **reader_b,
                machine: &b.machine,
                opts: b.options(frames, window, threads),
            },
            &mut |_| {},
        )?,
    };
    drop(stage);
    write_atomic(&args.output, |w| {
        w.write_all(page.html.as_bytes())
            .map_err(|e| CliError::write(&args.output, e))
    })?;
    let frames_text = if page.frames.1 == page.frames.0 + 1 {
        format!("frame {}", page.frames.0)
    } else {
        format!("frames {}..{}", page.frames.0, page.frames.1)
    };
    let late = match page.late_lines.as_slice() {
        [a, b] => format!("{a} late scanline(s) in A, {b} in B"),
        l => format!("{} late scanline(s)", l.iter().sum::<u64>()),
    };
    writeln!(
        stdout,
        "wrote {}: {}×{} {frames_text}, {late}, {}; {:.1} MB",
        args.output.display(),
        page.width,
        page.lines,
        windows_text(&page.windows),
        page.html.len() as f64 / 1e6
    )
    .map_err(CliError::Stdout)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::{parse, Command};

    fn parsed(args: &[&str]) -> Command {
        parse(args.iter().map(|s| s.into()))
            .expect("parses")
            .command
    }

    #[test]
    fn words_split_as_a_shell_splits_them() {
        assert_eq!(
            split_words(r#"pot --size 64x48  'my scene.json' "a \"b\"" c\ d"#).unwrap(),
            ["pot", "--size", "64x48", "my scene.json", "a \"b\"", "c d"]
        );
        assert_eq!(split_words("''").unwrap(), [""]);
        assert!(split_words("'open").is_err());
    }

    #[test]
    fn every_drawing_flag_is_known_to_the_suggested_command() {
        let group = DrawArgs::augment_args(clap::Command::new("draw"));
        let d = DrawArgs::default();
        for arg in group.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            assert!(
                draw_value(&d, &format!("--{long}")).is_ok(),
                "--{long} is not repeated in the suggested `cwisim history`"
            );
        }
    }

    #[test]
    fn the_suggested_history_command_repeats_the_pages_flags() {
        let Command::Inspect(i) = parsed(&[
            "cwisim",
            "inspect",
            "teapot",
            "-o",
            "x.html",
            "--size=64x48",
            "--renderer",
            "woo-chall",
            "--samples",
            "2",
            "--shade-p",
            "0.25",
            "--shade-contrast",
            "inf",
            "--seed",
            "7",
            "--grid",
            "corner",
            "--merge-subscanlines",
            "--tessellate",
            "5",
            "--numeric",
            "fixed:I=12.20,dI=4.28,ddI=1.36",
            "--set",
            "hop_cycles=2",
            "--machine",
            "m.json",
        ]) else {
            panic!("inspect")
        };
        let words = reproduce(&i.input, &i.draw, &i.machine, &i.numeric);
        assert_eq!(words[0], "teapot");
        assert!(
            words.windows(2).any(|w| w == ["--size", "64x48"]),
            "{words:?}"
        );
        let mut line = vec!["cwisim", "history"];
        line.extend(words.iter().map(String::as_str));
        line.extend(["--x", "3", "--line", "4"]);
        let Command::History(h) = parsed(&line) else {
            panic!("history")
        };
        assert_eq!(h.draw, i.draw, "{words:?}");
        assert_eq!(h.numeric, i.numeric);
        assert_eq!(h.machine, i.machine);
        assert_eq!(h.trace, i.input);
    }

    #[test]
    fn against_reads_b_and_its_own_flags() {
        let b = parse_against("pot --size 64x48 --renderer woo-chall --numeric f32").unwrap();
        assert_eq!(b.input, PathBuf::from("pot"));
        assert_eq!(b.draw.renderer, "woo-chall");
        assert_eq!(b.draw.given, ["--renderer", "--size"]);
        assert_eq!(b.numeric, Numeric::F32);
        let e = parse_against("pot --bogus 3").unwrap_err().to_string();
        assert!(e.contains("--bogus") && !e.contains('\n'), "{e}");
        let e = parse_against("  ").unwrap_err().to_string();
        assert!(e.contains("name B"), "{e}");
    }
}
