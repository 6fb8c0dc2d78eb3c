//! `cwisim inspect`: frames as one self-contained HTML page to explore in a browser — the
//! image (values on hover, overlays of the cost, the error against a reference, the
//! difference between two runs and the late scanlines), the scanline timeline, each
//! scanline's events cycle by cycle (which processor each token reaches when) with its
//! disassembly, and the pixel history of every pixel in a window.
//!
//! Everything the page shows is computed here, by one replay per run on the fast engine
//! with a [`Probe`] told every instruction's cycles and every visit a history shows
//! ([`cwisim_xproc::replay_visits_numeric`]: the stepped engine's events, held to it by
//! its tests, without stepping cycles): the same figures as `cwisim stats`, the same
//! lines as `cwisim dump` and `cwisim history`. The page's script only decodes, draws and
//! looks up; it simulates nothing.
//!
//! A page holds one run ([`inspect`]) or two of the same dimensions, A and B
//! ([`inspect_pair`]: two traces, or one scene drawn two ways), of one frame or a range
//! of frames ([`Options::frames`]), within [`MAX_FRAME_PIXELS`], [`MAX_PAGE_FRAMES`],
//! [`MAX_HISTORY_PIXELS`] and [`MAX_PAGE_BYTES`], all checked before the replay but the
//! last.
//!
//! The data is embedded as JSON with the large arrays as base64 of zlib streams
//! (little-endian `f64` values, `u32` counts and indices, bytes, text joined by
//! newlines), which the browser inflates with its own `DecompressionStream`. The same
//! input gives the same bytes.

use crate::cost::{viridis, CostMap, CostReader};
use crate::error::StudyError;
use crate::history::{visit_note, write_state, write_values};
use crate::plot::{group_cycles, issue_costs, GROUPS, OVERRUN};
use crate::provenance::NoteRecorder;
use crate::until::UntilLine;
use cwisim_isa::note::NoteTable;
use cwisim_isa::text::format_instruction;
use cwisim_isa::{Instruction, Opcode, OperandKind, TraceHeader, TraceRead};
use cwisim_xproc::{
    replay_visits_numeric, FixedFormat, LineOut, LineSink, Machine, Numeric, Probe, ProcessorState,
    Register, Q,
};
use serde_json::{json, Value};
use std::cell::RefCell;
use std::collections::{HashMap, VecDeque};
use std::hash::{BuildHasherDefault, Hasher};
use std::io::Write;

/// The page's template: HTML, CSS and script, with the data put in at `__CWISIM_DATA__`.
const TEMPLATE: &str = include_str!("inspect.html");

/// The most pixels a page's images hold, every frame of every run together, in pixels
/// (2048 × 2048): beyond it the page would be hundreds of MB, which browsers load slowly
/// or not at all.
pub const MAX_FRAME_PIXELS: u64 = 1 << 22;

/// The most frames a page holds (of each run).
pub const MAX_PAGE_FRAMES: u64 = 64;

/// The most pixels whose history a page holds, every frame of every run together (512 ×
/// 512 = 262,144). Without `--x` and `--lines`, each frame gets histories for all its
/// pixels when its share of this fits, else for a square around its centre of at most
/// [`DEFAULT_WINDOW`] pixels a side ([`default_window_in`]); a larger window is refused.
pub const MAX_HISTORY_PIXELS: u64 = 1 << 18;

/// The side of the default history window of a frame larger than its share of
/// [`MAX_HISTORY_PIXELS`].
pub const DEFAULT_WINDOW: u64 = 256;

/// The largest page written, in bytes (128 MiB): a bigger one is refused, naming the
/// options that make it smaller.
pub const MAX_PAGE_BYTES: usize = 128 << 20;

/// Where the error and difference overlays' scale starts: a pixel whose largest
/// difference over its channels is below it is not coloured (rounding in `f64`, about
/// `1e-14`, stays invisible). The page has a control for it.
pub const ERROR_FLOOR: f64 = 1e-12;

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

/// What to put on the page besides what the replay measures: one run's.
#[derive(Clone, Debug)]
pub struct Options<'a> {
    /// The input's name, shown as the title.
    pub name: &'a str,
    /// `"trace"` or `"scene"`.
    pub kind: &'a str,
    /// The frames, `[first, end)`, from 0: at most [`MAX_PAGE_FRAMES`], their pixels
    /// (times the runs) at most [`MAX_FRAME_PIXELS`]. A page of two runs takes the
    /// first's.
    pub frames: (u64, u64),
    /// The history window, scanlines over the whole trace within the frames (a window
    /// over several frames holds each frame's part); `None`: each frame's default
    /// ([`default_window_in`]). A page of two runs takes the first's.
    pub window: Option<Window>,
    /// The render summary (a scene's), shown at the top.
    pub summary: Option<&'a str>,
    /// The reference image of the frames (`frames × lines × width × channels`) with what
    /// it is, for the error overlay.
    pub reference: Option<(&'a [f64], &'a str)>,
    /// The array's registers (the histories show their values; in fixed point also the
    /// raw integers).
    pub numeric: Numeric,
    /// The input as given and the flags that make it what the page shows (drawing flags,
    /// `--numeric`, `--machine`, `--set`, as given): the page suggests
    /// `cwisim history REPRODUCE… --x X --line Y` for a clicked pixel. Empty: the name.
    pub reproduce: &'a [String],
    /// Threads to build the page on (0: one per core); the page is the same at any
    /// count. A page of two runs takes the first's.
    pub threads: usize,
}

impl Default for Options<'_> {
    fn default() -> Self {
        Options {
            name: "",
            kind: "trace",
            frames: (0, 1),
            window: None,
            summary: None,
            reference: None,
            numeric: Numeric::F64,
            reproduce: &[],
            threads: 1,
        }
    }
}

/// A written page and what it holds.
#[derive(Clone, Debug)]
pub struct Page {
    /// The HTML.
    pub html: String,
    /// The frames, `[first, end)`.
    pub frames: (u64, u64),
    /// The pixels with histories: one window per frame that has any (the same in every
    /// run), in order.
    pub windows: Vec<Window>,
    /// Scanlines of a frame.
    pub lines: u64,
    /// Its width.
    pub width: u64,
    /// Late scanlines over the frames, per run.
    pub late_lines: Vec<u64>,
}

/// One line of `cwisim dump`: the instruction, its number, scanline and bus cycles.
pub fn dump_line(index: u64, line: u64, issue: u64, enter: u64, instr: &Instruction) -> String {
    format!(
        "{:<48} # #{index} line {line} issue {issue} enter {enter}",
        format_instruction(instr)
    )
}

/// The default history window of a frame `width` wide, of scanlines
/// `first..first + lines`, when the frame is the page's only one: all of it up to
/// [`MAX_HISTORY_PIXELS`], else a [`DEFAULT_WINDOW`]-sided square around the centre.
pub fn default_window(width: u64, first: u64, lines: u64) -> Window {
    default_window_in(width, first, lines, MAX_HISTORY_PIXELS)
}

/// The default history window of a frame with `budget` history pixels (its share of
/// [`MAX_HISTORY_PIXELS`] among the page's frames and runs): all of it when it fits, else
/// a square around the centre of at most [`DEFAULT_WINDOW`] pixels a side that fits.
pub fn default_window_in(width: u64, first: u64, lines: u64, budget: u64) -> Window {
    if width * lines <= budget {
        return Window {
            x: (0, width),
            lines: (first, first + lines),
        };
    }
    let side = DEFAULT_WINDOW.min(budget.isqrt()).max(1);
    let centre = |n: u64| {
        let w = n.min(side);
        let a = (n - w) / 2;
        (a, a + w)
    };
    let (y0, y1) = centre(lines);
    Window {
        x: centre(width),
        lines: (first + y0, first + y1),
    }
}

/// Distinct strings, numbered in the order first seen.
#[derive(Default)]
struct Strings {
    ids: HashMap<Box<str>, u32, BuildHasherDefault<WordHash>>,
    /// Scratch space a string is written in before it is looked up.
    buf: String,
}

impl Strings {
    fn with_capacity(n: usize) -> Self {
        Strings {
            ids: HashMap::with_capacity_and_hasher(n, BuildHasherDefault::default()),
            buf: String::new(),
        }
    }

    fn id(&mut self, s: String) -> u32 {
        self.buf = s;
        self.take_buf()
    }

    /// The number of the string `write` writes.
    fn id_of(&mut self, write: impl FnOnce(&mut String)) -> u32 {
        self.buf.clear();
        write(&mut self.buf);
        self.take_buf()
    }

    fn take_buf(&mut self) -> u32 {
        if let Some(&id) = self.ids.get(self.buf.as_str()) {
            return id;
        }
        let id = self.ids.len() as u32;
        self.ids.insert(self.buf.as_str().into(), id);
        id
    }

    /// The strings in the order of their numbers.
    fn into_list(self) -> Vec<Box<str>> {
        let mut list: Vec<(u32, Box<str>)> = self.ids.into_iter().map(|(s, k)| (k, s)).collect();
        list.sort_unstable_by_key(|e| e.0);
        list.into_iter().map(|e| e.1).collect()
    }
}

/// The string table's hash, eight bytes at a time (FxHash's step: rotate, xor, multiply):
/// its keys are the page's own text, so SipHash's guard against chosen keys is not needed,
/// and it cost a tenth of the page's time.
#[derive(Default)]
struct WordHash(u64);

impl Hasher for WordHash {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        const K: u64 = 0x517c_c1b7_2722_0a95;
        let mut h = self.0;
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let w = u64::from_le_bytes(c.try_into().expect("eight bytes"));
            h = (h.rotate_left(5) ^ w).wrapping_mul(K);
        }
        for &b in chunks.remainder() {
            h = (h.rotate_left(5) ^ u64::from(b)).wrapping_mul(K);
        }
        self.0 = h;
    }
}

/// The visits `cwisim history` lists, as columns: the instruction's number and the
/// cycle its token arrived, what it amounted to ([`NOTES`]), the states before and after
/// (numbers of strings), and in fixed point the same states as raw integers.
#[derive(Default)]
struct Visits {
    index: Vec<f64>,
    cycle: Vec<f64>,
    note: Vec<u8>,
    before: Vec<u32>,
    after: Vec<u32>,
    before_raw: Vec<u32>,
    after_raw: Vec<u32>,
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
    shifted: Option<(u32, u32)>,
    /// The numbers of the strings (shown, raw) of the state its last visit left: what the
    /// next visit finds, since the tokens between them changed nothing.
    last: Option<(u32, u32)>,
}

/// Which processors an opcode's instruction names, as the page's event view draws it:
/// `"range"` `[x, x + dx)`, `"one"` processor `x`, `"periodic"` `x, x + dx, …`, `"all"`,
/// `"none"` (`Nop`).
pub fn reach(op: Opcode) -> &'static str {
    let kinds = op.operands();
    if kinds.contains(&OperandKind::Count) {
        "range"
    } else if kinds.contains(&OperandKind::Period) {
        "periodic"
    } else if kinds.contains(&OperandKind::X) {
        "one"
    } else if op == Opcode::Nop {
        "none"
    } else {
        "all"
    }
}

/// A fixed-point register's value as its raw integer, `value · 2^N`; marked `≈` when the
/// register is wider than an `f64`'s 53 bits and the value may have been rounded on its
/// way out.
pub fn raw_value(v: f64, q: Q) -> String {
    let r = v * (q.frac_bits as f64).exp2();
    if !(r.is_finite() && r.fract() == 0.0 && r.abs() < 63f64.exp2()) {
        return format!("≈{r}");
    }
    let exact = q.width() <= 53 || r.abs() <= 53f64.exp2();
    format!("{}{}", if exact { "" } else { "≈" }, r as i64)
}

fn raw_values(v: &[f64], q: Q) -> String {
    v.iter()
        .map(|x| raw_value(*x, q))
        .collect::<Vec<_>>()
        .join(",")
}

/// The registers of [`state`] as raw integers of their fixed-point formats:
/// `acc=… I=… dI=… ddI=…` (`-` for a preload register holding no value).
pub fn raw_state(s: &ProcessorState, f: &FixedFormat) -> String {
    let reg = |k: usize| {
        if s.has[k] {
            raw_values(&s.reg[k], f.q(Register::of_slot(k)))
        } else {
            "-".to_string()
        }
    };
    format!(
        "acc={} I={} dI={} ddI={}",
        raw_values(&s.acc, f.acc),
        reg(0),
        reg(1),
        reg(2)
    )
}

/// What the probe keeps of one frame: its instructions with their cycles and operands,
/// and the visits to the pixels of its window.
#[derive(Default)]
struct FrameLog {
    first_index: Option<u64>,
    texts: Vec<String>,
    issue: Vec<f64>,
    enter: Vec<f64>,
    lines: Vec<u64>,
    ops: Vec<u8>,
    xs: Vec<u32>,
    dxs: Vec<u32>,
    window: Option<Window>,
    pixels: Vec<Pixel>,
    visits: Visits,
    strings: Strings,
}

/// The probe: every instruction of the frames with its cycles, and every visit to a pixel
/// of a window that a history shows (the others are counted from the scanline's
/// instructions).
struct Collector {
    lines: (u64, u64),
    per_frame: u64,
    x: (u64, u64),
    pending: VecDeque<(u64, u64, u64, Instruction)>,
    frames: Vec<FrameLog>,
    fixed: Option<FixedFormat>,
}

impl Probe for Collector {
    fn watches(&self, p: usize) -> bool {
        (self.x.0..self.x.1).contains(&(p as u64))
    }

    fn issue(&mut self, cycle: u64, index: u64, line: u64, instr: &Instruction) {
        self.pending.push_back((index, line, cycle, instr.clone()));
    }

    fn enter(&mut self, cycle: u64, _index: u64) {
        let Some((index, line, issue, instr)) = self.pending.pop_front() else {
            return;
        };
        if (self.lines.0..self.lines.1).contains(&line) {
            let f = &mut self.frames[((line - self.lines.0) / self.per_frame) as usize];
            f.first_index.get_or_insert(index);
            f.texts.push(format_instruction(&instr));
            f.issue.push(issue as f64);
            f.enter.push(cycle as f64);
            f.lines.push(line);
            f.ops.push(instr.op.index() as u8);
            f.xs.push(instr.x);
            f.dxs.push(instr.dx);
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
        if !(self.lines.0..self.lines.1).contains(&line) {
            return;
        }
        let fixed = self.fixed;
        let f = &mut self.frames[((line - self.lines.0) / self.per_frame) as usize];
        let Some(window) = f.window.filter(|w| w.contains(x, line)) else {
            return;
        };
        let w = window.x.1 - window.x.0;
        let k = ((line - window.lines.0) * w + (x - window.x.0)) as usize;
        let pixel = &mut f.pixels[k];
        let strings = &mut f.strings;
        if instr.op == Opcode::Refresh {
            let shown = strings.id_of(|b| write_values(b, &before.acc));
            let raw = fixed.map_or(u32::MAX, |q| strings.id(raw_values(&before.acc, q.acc)));
            pixel.shifted = Some((shown, raw));
        }
        // every visit reported is one `cwisim history` shows (replay_visits_numeric): a
        // token between two of them changed nothing, so the state before is the one the
        // last visit left
        let note = visit_note(instr.op, addressed, before, after).map_or(0, |n| {
            1 + NOTES.iter().position(|&m| m == n).expect("a known note") as u8
        });
        let at = f.visits.index.len() as u32;
        f.visits.index.push(index as f64);
        f.visits.cycle.push(cycle as f64);
        f.visits.note.push(note);
        let (b, b_raw) = match pixel.last {
            Some(ids) => ids,
            None => (
                strings.id_of(|b| write_state(b, before)),
                fixed.map_or(u32::MAX, |q| strings.id(raw_state(before, &q))),
            ),
        };
        let (a, a_raw) = if after == before {
            (b, b_raw)
        } else {
            (
                strings.id_of(|b| write_state(b, after)),
                fixed.map_or(u32::MAX, |q| strings.id(raw_state(after, &q))),
            )
        };
        f.visits.before.push(b);
        f.visits.after.push(a);
        if fixed.is_some() {
            f.visits.before_raw.push(b_raw);
            f.visits.after_raw.push(a_raw);
        }
        pixel.last = Some((a, a_raw));
        pixel.visits.push(at);
    }
}

/// The frames' image, as the array shifts it out.
struct FrameImage {
    lines: (u64, u64),
    width: usize,
    channels: usize,
    data: Vec<f64>,
}

impl LineSink<f64> for FrameImage {
    fn line(&mut self, line: LineOut<'_, f64>) {
        if !(self.lines.0..self.lines.1).contains(&line.index) {
            return;
        }
        let row = (line.index - self.lines.0) as usize * self.width * self.channels;
        let start = row + line.span.0 * self.channels;
        self.data[start..start + line.values.len()].copy_from_slice(line.values);
    }
}

/// How hard the arrays are compressed: zlib's level 2 — level 9 makes a page a tenth
/// smaller in seven times the time (the pot's page: 4.5 s against 0.2 s of compression).
const LEVEL: u32 = 2;

/// zlib, then base64: how the page carries its arrays.
fn blob(bytes: &[u8]) -> String {
    let mut z = flate2::write::ZlibEncoder::new(
        Vec::with_capacity(bytes.len() / 4),
        flate2::Compression::new(LEVEL),
    );
    z.write_all(bytes).expect("writing to memory");
    base64(&z.finish().expect("writing to memory"))
}

/// The page's arrays, gathered while the page's data is built (each stands in the data
/// as a placeholder) and compressed together at the end, on threads ([`Blobs::fill`]):
/// each array's stream is the same on any thread, so the page is the same at any count.
#[derive(Default)]
struct Blobs(RefCell<Vec<Vec<u8>>>);

/// What a placeholder starts with: no text of the page's data holds a NUL.
const PLACEHOLDER: char = '\0';

impl Blobs {
    fn bytes(&self, bytes: Vec<u8>) -> Value {
        let mut list = self.0.borrow_mut();
        list.push(bytes);
        Value::String(format!("{PLACEHOLDER}{}", list.len() - 1))
    }

    fn f64s(&self, values: &[f64]) -> Value {
        self.bytes(values.iter().flat_map(|v| v.to_le_bytes()).collect())
    }

    fn u32s(&self, values: &[u32]) -> Value {
        self.bytes(values.iter().flat_map(|v| v.to_le_bytes()).collect())
    }

    fn texts<S: std::borrow::Borrow<str>>(&self, lines: &[S]) -> Value {
        self.bytes(lines.join("\n").into_bytes())
    }

    /// Compresses every array on `threads` threads (0: one per core), the largest first,
    /// and puts each in its placeholder's place in `data`.
    fn fill(self, data: &mut Value, threads: usize) {
        let raw = self.0.into_inner();
        let threads = cwisim_scene::budget::resolve_threads(threads).clamp(1, raw.len().max(1));
        let mut order: Vec<usize> = (0..raw.len()).collect();
        order.sort_by_key(|&k| std::cmp::Reverse(raw[k].len()));
        let mut done: Vec<Option<String>> = vec![None; raw.len()];
        if threads == 1 {
            for (d, r) in done.iter_mut().zip(&raw) {
                *d = Some(blob(r));
            }
        } else {
            let next = std::sync::atomic::AtomicUsize::new(0);
            let work = || {
                let mut out = Vec::new();
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&k) = order.get(i) else { break };
                    out.push((k, blob(&raw[k])));
                }
                out
            };
            std::thread::scope(|s| {
                let handles: Vec<_> = (1..threads).map(|_| s.spawn(work)).collect();
                let mut parts = vec![work()];
                parts.extend(
                    handles
                        .into_iter()
                        .map(|h| h.join().expect("compressing in memory")),
                );
                for (k, b) in parts.into_iter().flatten() {
                    done[k] = Some(b);
                }
            });
        }
        put_blobs(data, &mut done);
    }
}

/// Replaces each placeholder in `v` by its compressed array.
fn put_blobs(v: &mut Value, done: &mut [Option<String>]) {
    match v {
        Value::String(s) => {
            if let Some(k) = s.strip_prefix(PLACEHOLDER) {
                let k: usize = k.parse().expect("a placeholder's number");
                *s = done[k].take().expect("each array once");
            }
        }
        Value::Array(a) => a.iter_mut().for_each(|v| put_blobs(v, done)),
        Value::Object(o) => o.values_mut().for_each(|v| put_blobs(v, done)),
        _ => {}
    }
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
    check_frames(width, lines, 1, 1)
}

/// Refuses a page of `frames` frames `width` × `lines` in each of `runs` runs over
/// [`MAX_PAGE_FRAMES`] or [`MAX_FRAME_PIXELS`], naming how many frames fit.
pub fn check_frames(width: u64, lines: u64, frames: u64, runs: u64) -> Result<(), StudyError> {
    let one = width * lines;
    if one > MAX_FRAME_PIXELS {
        return Err(StudyError::Usage(format!(
            "a frame of {width}×{lines} = {one} pixels is over the page's limit of {MAX_FRAME_PIXELS} (2048×2048): \
a browser could not open the page; study it with `cwisim stats`, `dump` and `history`"
        )));
    }
    if frames > MAX_PAGE_FRAMES {
        return Err(StudyError::Usage(format!(
            "{frames} frames are more than a page holds ({MAX_PAGE_FRAMES}); choose fewer with --frames A..B"
        )));
    }
    let total = one * frames * runs;
    if total > MAX_FRAME_PIXELS {
        let fit = MAX_FRAME_PIXELS / (one * runs);
        let of_runs = if runs > 1 { " in each of two runs" } else { "" };
        return Err(StudyError::Usage(format!(
            "{frames} frames of {width}×{lines}{of_runs} are {total} pixels, over the page's limit of \
{MAX_FRAME_PIXELS} (2048×2048): it holds {fit} such frame(s); choose fewer with --frames A..B"
        )));
    }
    Ok(())
}

/// `frame N` or `frames A..B`.
fn frames_text((a, b): (u64, u64)) -> String {
    if b == a + 1 {
        format!("frame {a}")
    } else {
        format!("frames {a}..{b}")
    }
}

/// What a page holds, decided before any replay.
struct Plan {
    width: u64,
    lines: u64,
    channels: usize,
    frames: (u64, u64),
    /// The frames' scanlines over the whole trace, `[start, end)`.
    span: (u64, u64),
    /// Each frame's history window.
    windows: Vec<Option<Window>>,
}

/// Checks the request against the limits and the header, and chooses the windows.
fn plan(header: &TraceHeader, opts: &Options<'_>, runs: u64) -> Result<Plan, StudyError> {
    let width = u64::from(header.width);
    let lines = u64::from(header.lines);
    let (f0, f1) = opts.frames;
    if f1 <= f0 {
        return Err(StudyError::Usage(format!(
            "the frames {f0}..{f1} are none: give at least one"
        )));
    }
    let n = f1 - f0;
    check_frames(width, lines, n, runs)?;
    let beyond = || StudyError::Usage(format!("frame {f1} is beyond any trace"));
    let span = (
        f0.checked_mul(lines).ok_or_else(beyond)?,
        f1.checked_mul(lines).ok_or_else(beyond)?,
    );
    let windows = match opts.window {
        Some(w) => {
            if w.x.0 >= w.x.1
                || w.x.1 > width
                || w.lines.0 < span.0
                || w.lines.1 > span.1
                || w.lines.0 >= w.lines.1
            {
                return Err(StudyError::Usage(format!(
                    "the history window (processors {}..{}, scanlines {}..{}) is not inside {} \
(processors 0..{width}, scanlines {}..{})",
                    w.x.0,
                    w.x.1,
                    w.lines.0,
                    w.lines.1,
                    frames_text(opts.frames),
                    span.0,
                    span.1
                )));
            }
            let limit = MAX_HISTORY_PIXELS / runs;
            if w.pixels() > limit {
                let shared = if runs > 1 {
                    ", shared by the two runs"
                } else {
                    ""
                };
                return Err(StudyError::Usage(format!(
                    "the history window holds {} pixels, over the limit of {limit} (512×512{shared}); \
choose a smaller one with --x and --lines",
                    w.pixels()
                )));
            }
            (f0..f1)
                .map(|f| {
                    let (a, b) = (w.lines.0.max(f * lines), w.lines.1.min((f + 1) * lines));
                    (a < b).then_some(Window {
                        x: w.x,
                        lines: (a, b),
                    })
                })
                .collect()
        }
        None => {
            let budget = MAX_HISTORY_PIXELS / (n * runs);
            (f0..f1)
                .map(|f| Some(default_window_in(width, f * lines, lines, budget)))
                .collect()
        }
    };
    Ok(Plan {
        width,
        lines,
        channels: header.channel_count(),
        frames: opts.frames,
        span,
        windows,
    })
}

/// One run's part of the page.
struct RunData {
    json: Value,
    late: u64,
}

/// A word for a POSIX shell: as it is when it needs no quoting, else in single quotes.
pub fn shell_word(s: &str) -> String {
    let plain = !s.is_empty()
        && s.chars().all(|c| {
            c.is_ascii_alphanumeric()
                || matches!(c, '_' | '.' | '/' | ':' | '=' | ',' | '+' | '@' | '%' | '-')
        });
    if plain {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// `cwisim history` with the input and the flags that make it the run on the page: the
/// page appends `--x X --line Y`.
fn history_command(opts: &Options<'_>) -> String {
    let words: Vec<String> = if opts.reproduce.is_empty() {
        vec![shell_word(opts.name)]
    } else {
        opts.reproduce.iter().map(|w| shell_word(w)).collect()
    };
    format!("cwisim history {}", words.join(" "))
}

/// The fixed-point formats as `[M, N]` per register, for the page.
fn formats_json(numeric: &Numeric) -> Value {
    match numeric {
        Numeric::Fixed(f) => {
            let q = |q: Q| json!([q.int_bits, q.frac_bits]);
            json!({
                "I": q(f.i), "dI": q(f.di), "ddI": q(f.ddi), "acc": q(f.acc),
                "overflow": f.overflow.to_string(),
            })
        }
        _ => Value::Null,
    }
}

/// Replays one run over the plan's frames and gathers its part of the page.
fn gather(
    trace: &mut dyn TraceRead,
    machine: &Machine,
    opts: &Options<'_>,
    plan: &Plan,
    blobs: &Blobs,
    progress: &mut dyn FnMut(u64),
) -> Result<RunData, StudyError> {
    let header = *trace.header();
    let (width, lines, channels) = (plan.width, plan.lines, plan.channels);
    let n = plan.frames.1 - plan.frames.0;
    let frame_values = (width * lines) as usize * channels;
    if let Some((r, _)) = opts.reference {
        if r.len() != frame_values * n as usize {
            return Err(StudyError::Usage(format!(
                "the reference image holds {} values, the {} {n}×{width}×{lines}×{channels}",
                r.len(),
                if n == 1 { "frame" } else { "frames" }
            )));
        }
    }
    let x = plan
        .windows
        .iter()
        .flatten()
        .map(|w| w.x)
        .next()
        .unwrap_or((0, 0));
    let mut collector = Collector {
        lines: plan.span,
        per_frame: lines,
        x,
        pending: VecDeque::new(),
        frames: plan
            .windows
            .iter()
            .map(|w| {
                let pixels = w.map_or(0, |w| w.pixels() as usize);
                FrameLog {
                    window: *w,
                    pixels: vec![Pixel::default(); pixels],
                    // about one new state per pixel: room up front, not grown by rehashing
                    strings: Strings::with_capacity(pixels),
                    ..FrameLog::default()
                }
            })
            .collect(),
        fixed: match opts.numeric {
            Numeric::Fixed(f) => Some(f),
            _ => None,
        },
    };
    let mut image = FrameImage {
        lines: plan.span,
        width: width as usize,
        channels,
        data: vec![0.0; frame_values * n as usize],
    };
    let mut cost = CostMap::new(width as usize);
    // where each instruction came from (the trace's notes), by instruction index
    let notes = RefCell::new(NoteTable::new());
    let (stats, read) = {
        let mut until = UntilLine::new(trace, Some(plan.span.1 - 1));
        let stats = {
            let mut noted = NoteRecorder::new(&mut until, &notes, plan.span.0);
            let mut reader = CostReader::new(&mut noted, &mut cost);
            replay_visits_numeric(
                &mut reader,
                machine,
                &opts.numeric,
                plan.span.0,
                &mut collector,
                &mut image,
                progress,
            )?
        };
        (stats, until.lines_read())
    };
    if read < plan.span.1 {
        let whole = read / lines;
        return Err(StudyError::Usage(format!(
            "frame {} is not in the input: it outputs {read} scanline(s), {whole} whole frame(s) of {lines}",
            whole.max(plan.frames.0)
        )));
    }
    cost.check()?;

    let timeline_m = machine.timeline(&header)?;
    let op_cost = issue_costs(&timeline_m);
    let notes = notes.into_inner();
    // the notes' texts, each once, in the order met; an instruction names its note by
    // its place in this list, plus one (0: no note)
    let mut provenance: Vec<String> = Vec::new();
    let mut note_id: HashMap<u64, u32> = HashMap::new();
    let mut late = 0;
    let mut frames = Vec::with_capacity(n as usize);
    for (fi, log) in collector.frames.into_iter().enumerate() {
        let first_index = log.first_index.unwrap_or(0);
        let prov: Vec<u32> = (0..log.texts.len() as u64)
            .map(|i| match notes.get(first_index + i) {
                Some(note) => *note_id.entry(note.serial).or_insert_with(|| {
                    provenance.push(note.text.to_string());
                    provenance.len() as u32
                }),
                None => 0,
            })
            .collect();
        let frame = plan.frames.0 + fi as u64;
        let first = frame * lines;
        let recs: Vec<_> = stats
            .lines
            .iter()
            .filter(|l| (first..first + lines).contains(&l.line))
            .collect();
        late += recs.iter().filter(|l| l.slack < 0).count() as u64;
        let costs: Vec<u32> = (first..first + lines)
            .flat_map(|l| cost.row(l as usize).iter().copied())
            .collect();
        let values = &image.data[fi * frame_values..(fi + 1) * frame_values];
        let reference = opts
            .reference
            .map(|(r, _)| &r[fi * frame_values..(fi + 1) * frame_values]);
        frames.push(frame_json(
            frame,
            first,
            lines,
            log,
            &prov,
            values,
            reference,
            &costs,
            &recs,
            &op_cost,
            collector.fixed.is_some(),
            blobs,
        ));
    }
    let json = json!({
        "name": opts.name,
        "kind": opts.kind,
        "numeric": opts.numeric.to_string(),
        "formats": formats_json(&opts.numeric),
        "summary": opts.summary,
        "reference_name": opts.reference.map(|(_, n)| n),
        "reproduce": opts.reproduce,
        "history_command": history_command(opts),
        "provenance": provenance,
        "line_period": stats.line_period,
        "hop": machine.hop_cycles,
        "op_cost": op_cost.to_vec(),
        "frames": frames,
    });
    Ok(RunData { json, late })
}

/// One frame of one run: the image, the costs, the timeline, the disassembly with each
/// instruction's cycles and operands, and the histories of its window.
#[allow(clippy::too_many_arguments)]
fn frame_json(
    frame: u64,
    first: u64,
    lines: u64,
    log: FrameLog,
    prov: &[u32],
    image: &[f64],
    reference: Option<&[f64]>,
    costs: &[u32],
    recs: &[&cwisim_xproc::LineStats],
    op_cost: &[u64; Opcode::COUNT],
    fixed: bool,
    blobs: &Blobs,
) -> Value {
    let mut groups = Vec::new();
    for l in recs {
        groups.extend(group_cycles(l, op_cost).iter().map(|&c| c as f64));
    }
    let col = |f: &dyn Fn(&cwisim_xproc::LineStats) -> f64| -> Vec<f64> {
        recs.iter().map(|l| f(l)).collect()
    };

    // the disassembly, by scanline
    let mut line_start = vec![0u32; lines as usize + 1];
    for &l in &log.lines {
        line_start[(l - first) as usize + 1] += 1;
    }
    for k in 0..lines as usize {
        line_start[k + 1] += line_start[k];
    }

    let strings = log.strings.into_list();
    let history = log.window.map(|window| {
        // per pixel its visits (consecutive), the value shifted out and how many visits
        // it left out
        let mut starts = Vec::with_capacity(log.pixels.len() + 1);
        let mut order: Vec<u32> = Vec::with_capacity(log.visits.index.len());
        let mut shifted = Vec::with_capacity(log.pixels.len());
        let mut shifted_raw = Vec::with_capacity(log.pixels.len());
        let mut hidden = Vec::with_capacity(log.pixels.len());
        starts.push(0u32);
        for p in &log.pixels {
            order.extend(&p.visits);
            starts.push(order.len() as u32);
            shifted.push(p.shifted.map_or(u32::MAX, |s| s.0));
            shifted_raw.push(p.shifted.map_or(u32::MAX, |s| s.1));
        }
        // the visits not shown: every token of the pixel's scanline passes it
        let w = (window.x.1 - window.x.0) as usize;
        for (k, p) in log.pixels.iter().enumerate() {
            let l = (window.lines.0 - first) as usize + k / w;
            hidden.push(line_start[l + 1] - line_start[l] - p.visits.len() as u32);
        }
        let v = &log.visits;
        let pick_f = |c: &[f64]| order.iter().map(|&k| c[k as usize]).collect::<Vec<_>>();
        let pick_u = |c: &[u32]| order.iter().map(|&k| c[k as usize]).collect::<Vec<_>>();
        let notes: Vec<u8> = order.iter().map(|&k| v.note[k as usize]).collect();
        json!({
            "x": [window.x.0, window.x.1],
            "lines": [window.lines.0, window.lines.1],
            "strings": blobs.texts(&strings),
            "starts": blobs.u32s(&starts),
            "shifted": blobs.u32s(&shifted),
            "hidden": blobs.u32s(&hidden),
            "visit_index": blobs.f64s(&pick_f(&v.index)),
            "visit_cycle": blobs.f64s(&pick_f(&v.cycle)),
            "visit_note": blobs.bytes(notes),
            "visit_before": blobs.u32s(&pick_u(&v.before)),
            "visit_after": blobs.u32s(&pick_u(&v.after)),
            "raw": fixed.then(|| json!({
                "before": blobs.u32s(&pick_u(&v.before_raw)),
                "after": blobs.u32s(&pick_u(&v.after_raw)),
                "shifted": blobs.u32s(&shifted_raw),
            })),
        })
    });
    json!({
        "frame": frame,
        "first_line": first,
        "image": blobs.f64s(image),
        "reference": reference.map(|r| blobs.f64s(r)),
        "cost": blobs.u32s(costs),
        "timeline": {
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
            "first_index": log.first_index.unwrap_or(0),
            "text": blobs.texts(&log.texts),
            "issue": blobs.f64s(&log.issue),
            "enter": blobs.f64s(&log.enter),
            "op": blobs.bytes(log.ops),
            "x": blobs.u32s(&log.xs),
            "dx": blobs.u32s(&log.dxs),
            "prov": blobs.u32s(prov),
            "line_start": line_start,
        },
        "history": history,
    })
}

/// Replays `trace` up to the end of the frames `opts.frames` on the fast engine, with the
/// events of the frames' scanlines that the cycle-stepped engine reports
/// ([`cwisim_xproc::replay_visits_numeric`]), and builds the page. Refuses (as
/// [`StudyError::Usage`]) a frame beyond the trace, frames over [`MAX_PAGE_FRAMES`] or
/// [`MAX_FRAME_PIXELS`], a window outside the frames or over [`MAX_HISTORY_PIXELS`], and
/// a page over [`MAX_PAGE_BYTES`].
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
    let plan = plan(trace.header(), opts, 1)?;
    let blobs = Blobs::default();
    let run = gather(trace, machine, opts, &plan, &blobs, progress)?;
    let title = format!("cwisim inspect: {} {}", opts.name, frames_text(plan.frames));
    assemble(&plan, vec![run], blobs, opts.threads, &title)
}

/// One run of an A/B page: its input, machine and options.
pub struct Run<'a, 'b> {
    /// The trace (or a scene's stream).
    pub trace: &'b mut dyn TraceRead,
    /// The machine model.
    pub machine: &'b Machine,
    /// The run's options; the frames and the window are the first run's.
    pub opts: Options<'a>,
}

/// Refuses two runs of an A/B page whose dimensions differ (width, lines, channels),
/// naming both: checked before either is rendered or replayed.
pub fn check_same_dimensions(
    (a_name, a): (&str, &TraceHeader),
    (b_name, b): (&str, &TraceHeader),
) -> Result<(), StudyError> {
    let dims = |h: &TraceHeader| (h.width, h.lines, h.channel_count());
    if dims(a) == dims(b) {
        return Ok(());
    }
    let text = |h: &TraceHeader| {
        format!(
            "{}×{} with {} channel(s)",
            h.width,
            h.lines,
            h.channel_count()
        )
    };
    Err(StudyError::Usage(format!(
        "A ({a_name}) is {} but B ({b_name}) is {}: an A/B page compares runs of the same dimensions",
        text(a),
        text(b)
    )))
}

/// An A/B page: two runs of the same dimensions (two traces, or one scene drawn two
/// ways) over the same frames, each with everything [`inspect`] gathers, and on the page
/// a toggle between them and an overlay of their difference. Refuses runs of different
/// width, lines or channels before replaying either; the limits hold for both together
/// (each run has half of [`MAX_HISTORY_PIXELS`]).
pub fn inspect_pair(
    a: Run<'_, '_>,
    b: Run<'_, '_>,
    progress: &mut dyn FnMut(u64),
) -> Result<Page, StudyError> {
    let (ha, hb) = (*a.trace.header(), *b.trace.header());
    check_same_dimensions((a.opts.name, &ha), (b.opts.name, &hb))?;
    let plan = plan(&ha, &a.opts, 2)?;
    let b_opts = Options {
        frames: a.opts.frames,
        window: a.opts.window,
        ..b.opts.clone()
    };
    let blobs = Blobs::default();
    let ra = gather(a.trace, a.machine, &a.opts, &plan, &blobs, progress)?;
    let rb = gather(b.trace, b.machine, &b_opts, &plan, &blobs, progress).map_err(|e| match e {
        StudyError::Usage(m) => StudyError::Usage(format!("B ({}): {m}", b.opts.name)),
        e => e,
    })?;
    let title = format!(
        "cwisim inspect: {} against {} {}",
        a.opts.name,
        b.opts.name,
        frames_text(plan.frames)
    );
    assemble(&plan, vec![ra, rb], blobs, a.opts.threads, &title)
}

/// Puts the runs into the template.
fn assemble(
    plan: &Plan,
    runs: Vec<RunData>,
    blobs: Blobs,
    threads: usize,
    title: &str,
) -> Result<Page, StudyError> {
    let lut: Vec<String> = (0..256)
        .map(|k| {
            let c = viridis(k as f64 / 255.0);
            format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
        })
        .collect();
    let hex = |c: [u8; 3]| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]);
    let op_group: Vec<usize> = Opcode::ALL
        .iter()
        .map(|op| {
            GROUPS
                .iter()
                .position(|g| g.ops.contains(op))
                .expect("every opcode in a group")
        })
        .collect();
    let late: Vec<u64> = runs.iter().map(|r| r.late).collect();
    let labels = if runs.len() == 2 {
        ["A", "B"]
    } else {
        ["", ""]
    };
    let runs: Vec<Value> = runs
        .into_iter()
        .zip(labels)
        .map(|(mut r, label)| {
            r.json["label"] = json!(label);
            r.json
        })
        .collect();
    let mut data = json!({
        "width": plan.width,
        "lines": plan.lines,
        "channels": plan.channels,
        "frames": [plan.frames.0, plan.frames.1],
        "viridis": lut,
        "groups": GROUPS.iter().map(|g| json!({"name": g.name, "color": hex(g.color)})).collect::<Vec<_>>(),
        "overrun_color": hex(OVERRUN),
        "opcodes": Opcode::ALL.iter().map(|op| op.name()).collect::<Vec<_>>(),
        "op_group": op_group,
        "op_reach": Opcode::ALL.iter().map(|op| reach(*op)).collect::<Vec<_>>(),
        "notes": NOTES,
        "error_floor": ERROR_FLOOR,
        "runs": runs,
    });
    blobs.fill(&mut data, threads);
    // no `</script>` inside the script element: every `<` as its JSON escape
    let json = data.to_string().replace('<', "\\u003c");
    let html = TEMPLATE
        .replace("__CWISIM_TITLE__", &html_escape(title))
        .replace("__CWISIM_DATA__", &json);
    if html.len() > MAX_PAGE_BYTES {
        return Err(StudyError::Usage(format!(
            "the page would be {} MB, over the limit of {} MB: choose a smaller history window (--x, --lines) or fewer frames (--frames)",
            html.len() >> 20,
            MAX_PAGE_BYTES >> 20
        )));
    }
    Ok(Page {
        html,
        frames: plan.frames,
        windows: plan.windows.iter().flatten().copied().collect(),
        lines: plan.lines,
        width: plan.width,
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
        // a frame's share of the budget among several: four 400×400 frames get 256×256
        // each, sixteen 128×128
        let w = default_window_in(400, 0, 400, MAX_HISTORY_PIXELS / 4);
        assert_eq!(w.pixels(), 256 * 256);
        let w = default_window_in(400, 400, 400, MAX_HISTORY_PIXELS / 16);
        assert_eq!((w.x, w.lines), ((136, 264), (536, 664)));
        // small frames whole
        let w = default_window_in(16, 3, 3, MAX_HISTORY_PIXELS / 64);
        assert_eq!((w.x, w.lines), ((0, 16), (3, 6)));
    }

    #[test]
    fn the_frames_are_checked_together() {
        assert!(check_frames(2048, 2048, 1, 1).is_ok());
        let e = check_frames(1024, 1024, 5, 1).unwrap_err().to_string();
        assert!(e.contains("it holds 4 such frame(s)"), "{e}");
        let e = check_frames(1024, 1024, 3, 2).unwrap_err().to_string();
        assert!(
            e.contains("in each of two runs") && e.contains("holds 2 such"),
            "{e}"
        );
        let e = check_frames(4, 4, MAX_PAGE_FRAMES + 1, 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than a page holds"), "{e}");
    }

    #[test]
    fn raw_values_are_the_registers_integers() {
        let q = Q::new(12, 20).unwrap();
        assert_eq!(raw_value(0.375, q), "393216");
        assert_eq!(raw_value(-1.0, q), "-1048576");
        assert_eq!(raw_value(0.0, q), "0");
        // wider than an f64's mantissa: exact only when the value is small enough
        let wide = Q::new(4, 60).unwrap();
        assert_eq!(raw_value(0.5, wide), "≈576460752303423488");
        assert_eq!(raw_value(1.0 / 1024.0, wide), "1125899906842624");
    }

    #[test]
    fn shell_words_are_quoted_when_they_need_it() {
        assert_eq!(shell_word("pot"), "pot");
        assert_eq!(shell_word("fixed:I=12.20,dI=4.28"), "fixed:I=12.20,dI=4.28");
        assert_eq!(shell_word("my scene.json"), "'my scene.json'");
        assert_eq!(shell_word("it's"), "'it'\\''s'");
        assert_eq!(shell_word(""), "''");
    }

    #[test]
    fn every_opcode_reaches_what_its_operands_say() {
        assert_eq!(reach(Opcode::Eval3), "range");
        assert_eq!(reach(Opcode::Dis), "range");
        assert_eq!(reach(Opcode::SetPdI), "periodic");
        assert_eq!(reach(Opcode::SetI), "one");
        assert_eq!(reach(Opcode::Refresh), "all");
        assert_eq!(reach(Opcode::AccMode), "all");
        assert_eq!(reach(Opcode::Nop), "none");
    }
}
