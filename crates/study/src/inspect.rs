//! `cwisim inspect`: one frame as one self-contained HTML page to explore in a browser —
//! the image (values on hover, overlays of the cost, the error against a reference and
//! the late scanlines), the scanline timeline with each scanline's disassembly, and the
//! pixel history of every pixel in a window.
//!
//! Everything the page shows is computed here, by one replay with a [`Probe`] on the
//! cycle-stepped engine (the reference model), which steps the frame from the state the
//! fast engine hands it after the frames before: the same figures as `cwisim stats`, the
//! same lines as `cwisim dump` and `cwisim history`. The page's script only decodes,
//! draws and looks up; it simulates nothing.
//!
//! The data is embedded as JSON with the large arrays as base64 of zlib streams
//! (little-endian `f64` values, `u32` counts and indices, text joined by newlines), which
//! the browser inflates with its own `DecompressionStream`. The same input gives the same
//! bytes.

use crate::cost::{viridis, CostMap, CostReader};
use crate::error::StudyError;
use crate::history::{state, values, Visit};
use crate::plot::{group_cycles, issue_costs, GROUPS, OVERRUN};
use crate::until::UntilLine;
use cwisim_isa::text::format_instruction;
use cwisim_isa::{Instruction, Opcode, TraceRead};
use cwisim_xproc::{
    replay_probed_numeric, LineOut, LineSink, Machine, Numeric, Probe, ProcessorState, StepFrom,
};
use std::collections::{HashMap, VecDeque};
use std::io::Write;

/// The page's template: HTML, CSS and script, with the data put in at `__CWISIM_DATA__`.
const TEMPLATE: &str = include_str!("inspect.html");

/// The largest frame a page holds, in pixels (2048 × 2048): beyond it the page would be
/// hundreds of MB, which browsers load slowly or not at all.
pub const MAX_FRAME_PIXELS: u64 = 1 << 22;

/// The most pixels whose history a page holds (512 × 512 = 262,144). A larger frame gets
/// histories for a window only (the default: [`DEFAULT_WINDOW`] pixels square around the
/// centre; `--x` and `--lines` choose another); a larger window is refused.
pub const MAX_HISTORY_PIXELS: u64 = 1 << 18;

/// The side of the default history window of a frame larger than [`MAX_HISTORY_PIXELS`].
pub const DEFAULT_WINDOW: u64 = 256;

/// The largest page written, in bytes (128 MiB): a bigger one is refused, naming the
/// options that make it smaller.
pub const MAX_PAGE_BYTES: usize = 128 << 20;

/// The pixels whose histories the page holds: processors `x.0..x.1`, scanlines
/// `lines.0..lines.1` (counted over the whole trace), both ends excluded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// Processors, `[start, end)`.
    pub x: (u64, u64),
    /// Scanlines over the whole trace, `[start, end)`.
    pub lines: (u64, u64),
}

impl Window {
    /// Pixels in the window.
    pub fn pixels(&self) -> u64 {
        (self.x.1 - self.x.0) * (self.lines.1 - self.lines.0)
    }

    fn contains(&self, x: u64, line: u64) -> bool {
        (self.x.0..self.x.1).contains(&x) && (self.lines.0..self.lines.1).contains(&line)
    }
}

/// What to put on the page besides what the replay measures.
#[derive(Clone, Debug, Default)]
pub struct Options<'a> {
    /// The input's name, shown as the title.
    pub name: &'a str,
    /// `"trace"` or `"scene"`.
    pub kind: &'a str,
    /// The frame, from 0.
    pub frame: u64,
    /// The history window; `None`: the whole frame, or the default window of a big one.
    pub window: Option<Window>,
    /// The render summary (a scene's), shown at the top.
    pub summary: Option<&'a str>,
    /// The reference image of the frame (`lines × width × channels`) with what it is,
    /// for the error overlay.
    pub reference: Option<(&'a [f64], &'a str)>,
    /// The array's registers (the histories show their values).
    pub numeric: Numeric,
}

/// A written page and what it holds.
#[derive(Clone, Debug)]
pub struct Page {
    /// The HTML.
    pub html: String,
    /// The pixels with histories.
    pub window: Window,
    /// Scanlines of the frame.
    pub lines: u64,
    /// Its width.
    pub width: u64,
    /// Late scanlines of the frame.
    pub late_lines: u64,
}

/// One line of `cwisim dump`: the instruction, its number, scanline and bus cycles.
pub fn dump_line(index: u64, line: u64, issue: u64, enter: u64, instr: &Instruction) -> String {
    format!(
        "{:<48} # #{index} line {line} issue {issue} enter {enter}",
        format_instruction(instr)
    )
}

/// The default history window of a frame `width` wide, of scanlines
/// `first..first + lines`: all of it up to [`MAX_HISTORY_PIXELS`], else a
/// [`DEFAULT_WINDOW`]-sided square around the centre.
pub fn default_window(width: u64, first: u64, lines: u64) -> Window {
    if width * lines <= MAX_HISTORY_PIXELS {
        return Window {
            x: (0, width),
            lines: (first, first + lines),
        };
    }
    let side = |n: u64| {
        let w = n.min(DEFAULT_WINDOW);
        let a = (n - w) / 2;
        (a, a + w)
    };
    let (y0, y1) = side(lines);
    Window {
        x: side(width),
        lines: (first + y0, first + y1),
    }
}

/// Distinct strings, numbered in the order first seen.
#[derive(Default)]
struct Strings {
    ids: HashMap<String, u32>,
    list: Vec<String>,
}

impl Strings {
    fn id(&mut self, s: String) -> u32 {
        if let Some(&id) = self.ids.get(&s) {
            return id;
        }
        let id = self.list.len() as u32;
        self.ids.insert(s.clone(), id);
        self.list.push(s);
        id
    }
}

/// The visits `cwisim history` lists, as columns: the instruction's number and the
/// cycle its token arrived, what it amounted to ([`NOTES`]), the states before and after
/// (numbers of strings).
#[derive(Default)]
struct Visits {
    index: Vec<f64>,
    cycle: Vec<f64>,
    note: Vec<u8>,
    before: Vec<u32>,
    after: Vec<u32>,
}

/// What a visit amounted to, numbered on the page (0: a plain action).
pub const NOTES: [&str; 3] = [
    "passes through",
    "suppressed: locked by Eval0",
    "suppressed: masked by Dis",
];

#[derive(Default, Clone)]
struct Pixel {
    visits: Vec<u32>,
    hidden: u32,
    shifted: Option<u32>,
}

/// The probe: every instruction of the frame with its cycles, and every visit to a pixel
/// of the window.
struct Collector {
    frame: (u64, u64),
    window: Window,
    pending: VecDeque<(u64, u64, u64, Instruction)>,
    first_index: Option<u64>,
    texts: Vec<String>,
    issue: Vec<f64>,
    enter: Vec<f64>,
    dump_lines: Vec<u64>,
    pixels: Vec<Pixel>,
    visits: Visits,
    strings: Strings,
}

impl Probe for Collector {
    fn watches(&self, p: usize) -> bool {
        (self.window.x.0..self.window.x.1).contains(&(p as u64))
    }

    fn issue(&mut self, cycle: u64, index: u64, line: u64, instr: &Instruction) {
        self.pending.push_back((index, line, cycle, instr.clone()));
    }

    fn enter(&mut self, cycle: u64, _index: u64) {
        let Some((index, line, issue, instr)) = self.pending.pop_front() else {
            return;
        };
        if (self.frame.0..self.frame.1).contains(&line) {
            self.first_index.get_or_insert(index);
            self.texts.push(format_instruction(&instr));
            self.issue.push(issue as f64);
            self.enter.push(cycle as f64);
            self.dump_lines.push(line);
        }
    }

    fn visit(
        &mut self,
        cycle: u64,
        p: usize,
        index: u64,
        line: u64,
        instr: &Instruction,
        addressed: bool,
        before: &ProcessorState,
        after: &ProcessorState,
    ) {
        let x = p as u64;
        if !self.window.contains(x, line) {
            return;
        }
        let w = self.window.x.1 - self.window.x.0;
        let k = ((line - self.window.lines.0) * w + (x - self.window.x.0)) as usize;
        if instr.op == Opcode::Refresh {
            self.pixels[k].shifted = Some(self.strings.id(values(&before.acc)));
        }
        if addressed || before != after {
            let v = Visit {
                cycle,
                index,
                instr: instr.clone(),
                addressed,
                before: before.clone(),
                after: after.clone(),
            };
            let note = v.note().map_or(0, |n| {
                1 + NOTES.iter().position(|&m| m == n).expect("a known note") as u8
            });
            let at = self.visits.index.len() as u32;
            self.visits.index.push(index as f64);
            self.visits.cycle.push(cycle as f64);
            self.visits.note.push(note);
            let b = self.strings.id(state(before));
            let a = self.strings.id(state(after));
            self.visits.before.push(b);
            self.visits.after.push(a);
            self.pixels[k].visits.push(at);
        } else {
            self.pixels[k].hidden += 1;
        }
    }
}

/// The frame's image, as the array shifts it out.
struct FrameImage {
    frame: (u64, u64),
    width: usize,
    channels: usize,
    data: Vec<f64>,
}

impl LineSink<f64> for FrameImage {
    fn line(&mut self, line: LineOut<'_, f64>) {
        if !(self.frame.0..self.frame.1).contains(&line.index) {
            return;
        }
        let row = (line.index - self.frame.0) as usize * self.width * self.channels;
        let start = row + line.span.0 * self.channels;
        self.data[start..start + line.values.len()].copy_from_slice(line.values);
    }
}

/// zlib, then base64: how the page carries its arrays.
fn blob(bytes: &[u8]) -> String {
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::new(9));
    z.write_all(bytes).expect("writing to memory");
    base64(&z.finish().expect("writing to memory"))
}

fn f64_blob(values: &[f64]) -> String {
    blob(
        &values
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<_>>(),
    )
}

fn u32_blob(values: &[u32]) -> String {
    blob(
        &values
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<_>>(),
    )
}

fn text_blob(lines: &[String]) -> String {
    blob(lines.join("\n").as_bytes())
}

/// Standard base64 with padding.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Decodes [`base64`] (for tests and tools reading a page back).
pub fn unbase64(text: &str) -> Option<Vec<u8>> {
    let val = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let t = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(t.len() * 3 / 4);
    for chunk in t.chunks(4) {
        let mut n = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            n |= val(c)? << (18 - 6 * k);
        }
        for k in 0..chunk.len().saturating_sub(1) {
            out.push((n >> (16 - 8 * k)) as u8);
        }
    }
    Some(out)
}

/// Reads one of the page's arrays back: base64, then zlib.
pub fn read_blob(text: &str) -> Option<Vec<u8>> {
    let z = unbase64(text)?;
    let mut out = Vec::new();
    let mut d = flate2::write::ZlibDecoder::new(&mut out);
    d.write_all(&z).ok()?;
    d.finish().ok()?;
    Some(out)
}

/// The embedded data of a page (the JSON between the page's data tags).
pub fn page_data(html: &str) -> Option<serde_json::Value> {
    let start = html.find(DATA_OPEN)? + DATA_OPEN.len();
    let end = start + html[start..].find("</script>")?;
    serde_json::from_str(&html[start..end]).ok()
}

const DATA_OPEN: &str = "<script id=\"data\" type=\"application/json\">";

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Refuses a frame over [`MAX_FRAME_PIXELS`] (callers that draw a scene check before
/// drawing it).
pub fn check_frame(width: u64, lines: u64) -> Result<(), StudyError> {
    if width * lines > MAX_FRAME_PIXELS {
        return Err(StudyError::Usage(format!(
            "a frame of {width}×{lines} = {} pixels is over the page's limit of {MAX_FRAME_PIXELS} (2048×2048): \
a browser could not open the page; study it with `cwisim stats`, `dump` and `history`",
            width * lines
        )));
    }
    Ok(())
}

/// Replays `trace` up to the end of frame `opts.frame` and builds the page: the frames
/// before on the fast engine, the frame on the cycle-stepped engine from the fast
/// engine's state ([`cwisim_xproc::replay_probed_from`]). Refuses (as
/// [`StudyError::Usage`]) a frame beyond the trace, a frame over [`MAX_FRAME_PIXELS`], a
/// window outside the frame or over [`MAX_HISTORY_PIXELS`], and a page over
/// [`MAX_PAGE_BYTES`].
pub fn inspect(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    opts: &Options<'_>,
) -> Result<Page, StudyError> {
    inspect_with_progress(trace, machine, opts, &mut |_| {})
}

/// [`inspect`], calling `progress` with the bytes of `trace` read so far every few
/// thousand instructions (and at the end): for a progress bar.
pub fn inspect_with_progress(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    opts: &Options<'_>,
    progress: &mut dyn FnMut(u64),
) -> Result<Page, StudyError> {
    let header = *trace.header();
    let width = u64::from(header.width);
    let lines = u64::from(header.lines);
    let channels = header.channel_count();
    check_frame(width, lines)?;
    let first = opts
        .frame
        .checked_mul(lines)
        .ok_or_else(|| StudyError::Usage(format!("frame {} is beyond any trace", opts.frame)))?;
    let frame = (first, first + lines);
    let window = match opts.window {
        Some(w) => w,
        None => default_window(width, first, lines),
    };
    if window.x.0 >= window.x.1
        || window.x.1 > width
        || window.lines.0 < frame.0
        || window.lines.1 > frame.1
        || window.lines.0 >= window.lines.1
    {
        return Err(StudyError::Usage(format!(
            "the history window (processors {}..{}, scanlines {}..{}) is not inside frame {} \
(processors 0..{width}, scanlines {}..{})",
            window.x.0, window.x.1, window.lines.0, window.lines.1, opts.frame, frame.0, frame.1
        )));
    }
    if window.pixels() > MAX_HISTORY_PIXELS {
        return Err(StudyError::Usage(format!(
            "the history window holds {} pixels, over the limit of {MAX_HISTORY_PIXELS} (512×512); \
choose a smaller one with --x and --lines",
            window.pixels()
        )));
    }
    if let Some((r, _)) = opts.reference {
        if r.len() as u64 != width * lines * channels as u64 {
            return Err(StudyError::Usage(format!(
                "the reference image holds {} values, the frame {width}×{lines}×{channels}",
                r.len()
            )));
        }
    }

    let mut collector = Collector {
        frame,
        window,
        pending: VecDeque::new(),
        first_index: None,
        texts: Vec::new(),
        issue: Vec::new(),
        enter: Vec::new(),
        dump_lines: Vec::new(),
        visits: Visits::default(),
        pixels: vec![Pixel::default(); window.pixels() as usize],
        strings: Strings::default(),
    };
    let mut image = FrameImage {
        frame,
        width: width as usize,
        channels,
        data: vec![0.0; (width * lines) as usize * channels],
    };
    let mut cost = CostMap::new(width as usize);
    let (stats, read) = {
        let mut until = UntilLine::new(trace, Some(frame.1 - 1));
        let stats = {
            let mut reader = CostReader::new(&mut until, &mut cost);
            replay_probed_numeric(
                &mut reader,
                machine,
                &opts.numeric,
                StepFrom::Scanline(first),
                &mut collector,
                &mut image,
                progress,
            )?
        };
        (stats, until.lines_read())
    };
    if read < frame.1 {
        let frames = read / lines;
        return Err(StudyError::Usage(format!(
            "frame {} is not in the input: it outputs {read} scanline(s), {frames} whole frame(s) of {lines}",
            opts.frame
        )));
    }
    cost.check()?;
    let costs: Vec<u32> = (frame.0..frame.1)
        .flat_map(|l| cost.row(l as usize).iter().copied())
        .collect();

    // the timeline: the frame's scanline records
    let timeline_m = machine.timeline(&header)?;
    let op_cost = issue_costs(&timeline_m);
    let recs: Vec<_> = stats
        .lines
        .iter()
        .filter(|l| (frame.0..frame.1).contains(&l.line))
        .collect();
    let mut groups = Vec::new();
    for l in &recs {
        groups.extend(group_cycles(l, &op_cost).iter().map(|&c| c as f64));
    }
    let col = |f: &dyn Fn(&cwisim_xproc::LineStats) -> f64| -> Vec<f64> {
        recs.iter().map(|l| f(l)).collect()
    };
    let late = recs.iter().filter(|l| l.slack < 0).count() as u64;

    // the disassembly, by scanline
    let mut line_start = vec![0u32; lines as usize + 1];
    for &l in &collector.dump_lines {
        line_start[(l - frame.0) as usize + 1] += 1;
    }
    for k in 0..lines as usize {
        line_start[k + 1] += line_start[k];
    }

    // the histories: per pixel its visits (consecutive), the value shifted out and how
    // many visits it left out
    let mut starts = Vec::with_capacity(collector.pixels.len() + 1);
    let mut order: Vec<u32> = Vec::with_capacity(collector.visits.index.len());
    let mut shifted = Vec::with_capacity(collector.pixels.len());
    let mut hidden = Vec::with_capacity(collector.pixels.len());
    starts.push(0u32);
    for p in &collector.pixels {
        order.extend(&p.visits);
        starts.push(order.len() as u32);
        shifted.push(p.shifted.unwrap_or(u32::MAX));
        hidden.push(p.hidden);
    }
    let v = &collector.visits;
    let pick_f = |c: &[f64]| order.iter().map(|&k| c[k as usize]).collect::<Vec<_>>();
    let pick_u = |c: &[u32]| order.iter().map(|&k| c[k as usize]).collect::<Vec<_>>();
    let notes: Vec<u8> = order.iter().map(|&k| v.note[k as usize]).collect();

    let lut: Vec<String> = (0..256)
        .map(|k| {
            let c = viridis(k as f64 / 255.0);
            format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
        })
        .collect();
    let hex = |c: [u8; 3]| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]);
    let data = serde_json::json!({
        "name": opts.name,
        "kind": opts.kind,
        "numeric": opts.numeric.to_string(),
        "width": width,
        "lines": lines,
        "channels": channels,
        "frame": opts.frame,
        "first_line": first,
        "summary": opts.summary,
        "image": f64_blob(&image.data),
        "reference": opts.reference.map(|(r, _)| f64_blob(r)),
        "reference_name": opts.reference.map(|(_, n)| n),
        "cost": u32_blob(&costs),
        "viridis": lut,
        "timeline": {
            "line_period": stats.line_period,
            "groups": GROUPS.iter().map(|g| serde_json::json!({"name": g.name, "color": hex(g.color)})).collect::<Vec<_>>(),
            "overrun_color": hex(OVERRUN),
            "cycles": groups,
            "busy": col(&|l| l.busy_cycles as f64),
            "stall": col(&|l| l.stall_cycles as f64),
            "instructions": col(&|l| l.instructions as f64),
            "updates": col(&|l| l.processor_updates as f64),
            "first_issue": col(&|l| l.first_issue as f64),
            "ready": col(&|l| l.ready as f64),
            "deadline": col(&|l| l.deadline as f64),
            "slack": col(&|l| l.slack as f64),
        },
        "dump": {
            "first_index": collector.first_index.unwrap_or(0),
            "text": text_blob(&collector.texts),
            "issue": f64_blob(&collector.issue),
            "enter": f64_blob(&collector.enter),
            "line_start": line_start,
        },
        "history": {
            "x": [window.x.0, window.x.1],
            "lines": [window.lines.0, window.lines.1],
            "strings": text_blob(&collector.strings.list),
            "starts": u32_blob(&starts),
            "shifted": u32_blob(&shifted),
            "hidden": u32_blob(&hidden),
            "notes": NOTES,
            "visit_index": f64_blob(&pick_f(&v.index)),
            "visit_cycle": f64_blob(&pick_f(&v.cycle)),
            "visit_note": blob(&notes),
            "visit_before": u32_blob(&pick_u(&v.before)),
            "visit_after": u32_blob(&pick_u(&v.after)),
        },
    });
    // no `</script>` inside the script element: every `<` as its JSON escape
    let json = data.to_string().replace('<', "\\u003c");
    let title = format!("cwisim inspect: {} frame {}", opts.name, opts.frame);
    let html = TEMPLATE
        .replace("__CWISIM_TITLE__", &html_escape(&title))
        .replace("__CWISIM_DATA__", &json);
    if html.len() > MAX_PAGE_BYTES {
        return Err(StudyError::Usage(format!(
            "the page would be {} MB, over the limit of {} MB: choose a smaller history window (--x, --lines)",
            html.len() >> 20,
            MAX_PAGE_BYTES >> 20
        )));
    }
    Ok(Page {
        html,
        window,
        lines,
        width,
        late_lines: late,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_every_length() {
        let bytes: Vec<u8> = (0..=255u8).collect();
        for n in 0..40 {
            let b = base64(&bytes[..n]);
            assert_eq!(b.len(), n.div_ceil(3) * 4);
            assert_eq!(unbase64(&b).unwrap(), &bytes[..n], "length {n}");
        }
        assert_eq!(base64(b"Man"), "TWFu");
        assert_eq!(base64(b"Ma"), "TWE=");
        assert_eq!(base64(b"M"), "TQ==");
    }

    #[test]
    fn the_default_window_is_the_frame_or_its_centre() {
        let w = default_window(100, 0, 100);
        assert_eq!((w.x, w.lines), ((0, 100), (0, 100)));
        let w = default_window(1024, 2048, 1024);
        assert_eq!(w.x, (384, 640));
        assert_eq!(w.lines, (2048 + 384, 2048 + 640));
        assert_eq!(w.pixels(), DEFAULT_WINDOW * DEFAULT_WINDOW);
    }
}
