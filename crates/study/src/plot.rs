//! PNG plots: shapes drawn with `plotters` on an RGB bitmap, text set with `ab_glyph` in
//! an embedded font, the PNG encoded by the `image` crate.
//!
//! No system font is ever looked up: the font is DejaVu Sans, whose bytes the `dejavu`
//! crate embeds (DejaVu licence: the Bitstream Vera licence plus public-domain changes;
//! the licence ships in that crate). [`Label`]s are laid out here, glyph by glyph with
//! kerning, and blended into the bitmap, so a plot is the same bytes on every machine.
//! The same font is registered with plotters ([`register_fonts`]) for any text plotters
//! draws itself.
//!
//! [`render_stats_plot`] is the `cwisim stats --plot` chart: one stacked bar of bus
//! cycles per scanline, split by opcode group, against the line period.

use ab_glyph::{point, Font, FontRef, PxScale, ScaleFont};
use cwisim_isa::{Instruction, Opcode};
use cwisim_xproc::{LineStats, Timeline};
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::io::{self, Write};
use std::sync::{Once, OnceLock};

/// The font family name under which [`register_fonts`] gives plotters the embedded font.
pub const FONT: &str = "sans-serif";

/// Registers the embedded DejaVu Sans with plotters as [`FONT`]. Idempotent.
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // A valid TrueType file; were it not, plotters' text would fail with an error.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// The embedded DejaVu Sans.
fn font() -> &'static FontRef<'static> {
    static FONT_REF: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT_REF.get_or_init(|| {
        FontRef::try_from_slice(dejavu::sans::regular()).expect("the embedded font is valid")
    })
}

/// Where a label's anchor point is: its start, centre or end (left, centre, right; or top,
/// middle, bottom).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    /// Left / top.
    Start,
    /// Centre / middle (of the digits' and capitals' height).
    Center,
    /// Right / bottom.
    End,
}

/// One line of text to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// The text.
    pub text: String,
    /// The anchor point, in pixels.
    pub at: (i32, i32),
    /// Size in pixels (the em).
    pub size: f32,
    /// Horizontal alignment on the anchor.
    pub h: Align,
    /// Vertical alignment on the anchor.
    pub v: Align,
    /// Colour.
    pub color: [u8; 3],
}

impl Label {
    /// Black text whose top-left corner is at `at`.
    pub fn new(text: impl Into<String>, at: (i32, i32), size: f32) -> Label {
        Label {
            text: text.into(),
            at,
            size,
            h: Align::Start,
            v: Align::Start,
            color: [0, 0, 0],
        }
    }

    /// The same label anchored differently.
    pub fn align(mut self, h: Align, v: Align) -> Label {
        self.h = h;
        self.v = v;
        self
    }

    /// The same label in another colour.
    pub fn color(mut self, color: [u8; 3]) -> Label {
        self.color = color;
        self
    }
}

/// The advance width of `text` at `size` pixels.
pub fn text_width(text: &str, size: f32) -> f32 {
    let f = font().as_scaled(PxScale::from(size));
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = prev {
            w += f.kern(p, id);
        }
        w += f.h_advance(id);
        prev = Some(id);
    }
    w
}

/// `text` in lines no wider than `width` pixels at `size`, broken at spaces (a word wider
/// than that alone, such as a long numeric format, also after its commas): what a legend
/// draws so that nothing runs off the canvas. A word that cannot be broken keeps a line
/// of its own.
pub fn wrap(text: &str, size: f32, width: f32) -> Vec<String> {
    let fits = |t: &str| text_width(t, size) <= width;
    // (joined to the piece before without a space, the piece)
    let mut pieces: Vec<(bool, &str)> = Vec::new();
    for word in text.split(' ') {
        if fits(word) || !word.contains(',') {
            pieces.push((false, word));
        } else {
            for (k, part) in word.split_inclusive(',').enumerate() {
                pieces.push((k > 0, part));
            }
        }
    }
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for (glued, piece) in pieces {
        let joined = match (line.is_empty(), glued) {
            (true, _) => piece.to_string(),
            (false, true) => format!("{line}{piece}"),
            (false, false) => format!("{line} {piece}"),
        };
        if line.is_empty() || fits(&joined) {
            line = joined;
        } else {
            lines.push(std::mem::replace(&mut line, piece.to_string()));
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// An RGB bitmap, 3 bytes per pixel, row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rgb {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height × 3` bytes.
    pub data: Vec<u8>,
}

impl Rgb {
    /// A white bitmap.
    pub fn white(width: u32, height: u32) -> Rgb {
        Rgb {
            width,
            height,
            data: vec![255; width as usize * height as usize * 3],
        }
    }

    /// Sets one pixel (ignored outside the bitmap).
    pub fn put(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = (y as usize * self.width as usize + x as usize) * 3;
            self.data[i..i + 3].copy_from_slice(&c);
        }
    }

    /// The colour of one pixel.
    pub fn get(&self, x: u32, y: u32) -> [u8; 3] {
        let i = (y as usize * self.width as usize + x as usize) * 3;
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    fn blend(&mut self, x: i32, y: i32, c: [u8; 3], alpha: f32) {
        if x < 0 || y < 0 || x as u32 >= self.width || y as u32 >= self.height {
            return;
        }
        let a = alpha.clamp(0.0, 1.0);
        let i = (y as usize * self.width as usize + x as usize) * 3;
        for (d, c) in self.data[i..i + 3].iter_mut().zip(c) {
            let v = f32::from(*d);
            *d = (v + (f32::from(c) - v) * a).round() as u8;
        }
    }

    /// Draws a label: glyphs laid out with the font's advances and kerning, each
    /// rasterized with coverage and blended over the bitmap.
    pub fn draw_label(&mut self, label: &Label) {
        let f = font().as_scaled(PxScale::from(label.size));
        let width = text_width(&label.text, label.size);
        let x = label.at.0 as f32
            - match label.h {
                Align::Start => 0.0,
                Align::Center => width / 2.0,
                Align::End => width,
            };
        // DejaVu's capitals and digits are 0.73 em high.
        let baseline = label.at.1 as f32
            + match label.v {
                Align::Start => f.ascent(),
                Align::Center => 0.365 * label.size,
                Align::End => f.descent(),
            };
        let (x, baseline) = (x.round(), baseline.round());
        let mut caret = 0.0;
        let mut prev = None;
        for c in label.text.chars() {
            let id = f.glyph_id(c);
            if let Some(p) = prev {
                caret += f.kern(p, id);
            }
            prev = Some(id);
            let glyph = id.with_scale_and_position(label.size, point(x + caret, baseline));
            caret += f.h_advance(id);
            if let Some(outline) = font().outline_glyph(glyph) {
                let b = outline.px_bounds();
                let (bx, by) = (b.min.x as i32, b.min.y as i32);
                outline.draw(|gx, gy, cover| {
                    self.blend(bx + gx as i32, by + gy as i32, label.color, cover);
                });
            }
        }
    }

    /// The PNG bytes (8-bit RGB).
    pub fn encode_png<W: Write>(&self, out: W) -> io::Result<()> {
        PngEncoder::new(out)
            .write_image(&self.data, self.width, self.height, ExtendedColorType::Rgb8)
            .map_err(|e| match e {
                image::ImageError::IoError(e) => e,
                other => io::Error::other(other.to_string()),
            })
    }
}

/// Draws on `rgb` with plotters (the closure gets the whole bitmap as a drawing area and
/// may collect labels), then draws the labels on top.
pub fn draw_on<F>(rgb: &mut Rgb, f: F) -> Result<(), String>
where
    F: FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>, &mut Vec<Label>) -> Result<(), String>,
{
    register_fonts();
    let (w, h) = (rgb.width, rgb.height);
    let mut labels = Vec::new();
    {
        let root = BitMapBackend::with_buffer(&mut rgb.data, (w, h)).into_drawing_area();
        f(&root, &mut labels)?;
        root.present().map_err(err)?;
    }
    for l in &labels {
        rgb.draw_label(l);
    }
    Ok(())
}

/// Whole decades around `lo..=hi` (both > 0), at least one: the ends of a log axis.
pub fn decades(lo: f64, hi: f64) -> (f64, f64) {
    let a = 10f64.powf(lo.log10().floor());
    let b = 10f64.powf((hi * 1.0001).log10().ceil()).max(a * 10.0);
    (a, b)
}

/// The direction of a log axis's decade grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogAxis {
    /// Horizontal: vertical grid lines, labels below the panel.
    X,
    /// Vertical: horizontal grid lines, labels left of the panel.
    Y,
}

/// The decade grid of a log axis from `lo` to `hi` (as [`decades`] gives them): for every
/// power of ten a grey line across the panel, from `across.0` to `across.1` pixels, and a
/// `1e3`-style label beyond the panel's edge (below `across.1`, or left of `across.0`);
/// `at(v)` is the pixel of value `v` along the axis.
pub fn decade_grid(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    labels: &mut Vec<Label>,
    axis: LogAxis,
    (lo, hi): (f64, f64),
    at: impl Fn(f64) -> i32,
    across: (i32, i32),
) -> Result<(), String> {
    let grid = RGBColor(228, 228, 228);
    let mut v = lo;
    while v <= hi * 1.0001 {
        let p = at(v);
        let text = format!("{v:.0e}");
        let (line, label) = match axis {
            LogAxis::X => (
                vec![(p, across.0), (p, across.1)],
                Label::new(text, (p, across.1 + 8), 13.0).align(Align::Center, Align::Start),
            ),
            LogAxis::Y => (
                vec![(across.0, p), (across.1, p)],
                Label::new(text, (across.0 - 8, p), 13.0).align(Align::End, Align::Center),
            ),
        };
        root.draw(&PathElement::new(line, grid)).map_err(err)?;
        labels.push(label);
        v *= 10.0;
    }
    Ok(())
}

/// A chart with log scales on both axes.
pub type LogLogChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// The part of `root` from column `cols.0` to `cols.1` and row `rows.0` to `rows.1`.
pub fn panel_area<'b>(
    root: &DrawingArea<BitMapBackend<'b>, Shift>,
    cols: (i32, i32),
    rows: (i32, i32),
) -> DrawingArea<BitMapBackend<'b>, Shift> {
    root.clone().shrink(
        (cols.0 as u32, rows.0 as u32),
        ((cols.1 - cols.0) as u32, (rows.1 - rows.0) as u32),
    )
}

/// A log–log panel over `x` × `y` (each as [`decades`] gives them) on `area`, the part
/// of `root` at `cols` × `rows` ([`panel_area`]): both decade grids and the axes' L drawn
/// on `root`, their labels added to `labels`; the chart, to draw series on.
pub fn log_log_panel<'a, 'b>(
    root: &DrawingArea<BitMapBackend<'b>, Shift>,
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    labels: &mut Vec<Label>,
    (x, y): ((f64, f64), (f64, f64)),
    (cols, rows): ((i32, i32), (i32, i32)),
) -> Result<LogLogChart<'a, 'b>, String> {
    let chart = ChartBuilder::on(area)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(err)?;
    let at = |px: f64, py: f64| chart.backend_coord(&(px, py));
    decade_grid(root, labels, LogAxis::Y, y, |v| at(x.0, v).1, cols)?;
    decade_grid(root, labels, LogAxis::X, x, |v| at(v, y.0).0, rows)?;
    root.draw(&PathElement::new(
        vec![(cols.0, rows.0), (cols.0, rows.1), (cols.1, rows.1)],
        BLACK,
    ))
    .map_err(err)?;
    Ok(chart)
}

/// Turns a plotting error into a message.
pub fn err<E: std::fmt::Display>(e: E) -> String {
    format!("cannot draw the plot: {e}")
}

/// A step of 1, 2 or 5 × 10^k, at least `min` (and at least 1).
pub fn nice_step(min: f64) -> u64 {
    let mut step = 1u64;
    loop {
        for m in [1, 2, 5] {
            if (step * m) as f64 >= min {
                return step * m;
            }
        }
        step *= 10;
    }
}

/// The bus cycles of one instruction of each opcode on this timeline (by
/// [`Opcode::index`]): what [`Timeline::issue_cycles`] charges for it.
pub fn issue_costs(timeline: &Timeline) -> [u64; Opcode::COUNT] {
    let mut cost = [0; Opcode::COUNT];
    for op in Opcode::ALL {
        // The cost depends on the opcode only (and on the trace's channel count, which
        // the timeline holds).
        let mut instr = Instruction::nop();
        instr.op = *op;
        cost[op.index()] = timeline.issue_cycles(&instr);
    }
    cost
}

/// The bus cycles a scanline spent on each opcode: its count × the opcode's issue cost.
/// They add up to the line's `busy_cycles`.
pub fn opcode_cycles(line: &LineStats, cost: &[u64; Opcode::COUNT]) -> [u64; Opcode::COUNT] {
    let mut out = [0; Opcode::COUNT];
    for op in Opcode::ALL {
        out[op.index()] = line.opcodes.get(*op) * cost[op.index()];
    }
    out
}

/// One segment kind of a stacked bar.
#[derive(Clone, Copy, Debug)]
pub struct Group {
    /// Legend text.
    pub name: &'static str,
    /// The opcodes it adds up (none: the stall cycles).
    pub ops: &'static [Opcode],
    /// Fill colour.
    pub color: [u8; 3],
}

/// The segments of a bar, bottom to top: the opcode groups, then the stall cycles.
pub const GROUPS: [Group; 8] = [
    Group {
        name: "Set*",
        ops: &[
            Opcode::SetI,
            Opcode::SetdI,
            Opcode::SetddI,
            Opcode::SetPI,
            Opcode::SetPdI,
            Opcode::SetPddI,
        ],
        color: [148, 103, 189],
    },
    Group {
        name: "Eval0",
        ops: &[Opcode::Eval0],
        color: [140, 86, 75],
    },
    Group {
        name: "Eval1",
        ops: &[Opcode::Eval1],
        color: [31, 119, 180],
    },
    Group {
        name: "Eval2",
        ops: &[Opcode::Eval2],
        color: [44, 160, 44],
    },
    Group {
        name: "Eval3",
        ops: &[Opcode::Eval3],
        color: [255, 127, 14],
    },
    Group {
        name: "Dis / Acc_mode / Nop",
        ops: &[Opcode::Dis, Opcode::AccMode, Opcode::Nop],
        color: [188, 189, 34],
    },
    Group {
        name: "Refresh",
        ops: &[Opcode::Refresh],
        color: [23, 190, 207],
    },
    Group {
        name: "stall (waiting)",
        ops: &[],
        color: [199, 199, 199],
    },
];

/// The red of overrun markers (no bar segment uses it).
pub const OVERRUN: [u8; 3] = [214, 39, 40];

/// A palette entry as plotters' colour.
pub fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// A line's cycles per [`GROUPS`] entry (the last one: stall cycles).
pub fn group_cycles(line: &LineStats, cost: &[u64; Opcode::COUNT]) -> [u64; GROUPS.len()] {
    let per_op = opcode_cycles(line, cost);
    let mut out = [0; GROUPS.len()];
    for (g, group) in GROUPS.iter().enumerate() {
        out[g] = group.ops.iter().map(|op| per_op[op.index()]).sum();
    }
    out[GROUPS.len() - 1] = line.stall_cycles;
    out
}

/// The size of the `cwisim stats --plot` image.
pub const STATS_PLOT_SIZE: (u32, u32) = (1100, 560);

/// Everything the stats plot shows.
pub struct StatsPlot<'a> {
    /// The input's file name (for the title).
    pub name: &'a str,
    /// The scanlines to draw (at least one), in order.
    pub lines: &'a [LineStats],
    /// The line period: the budget line.
    pub line_period: u64,
    /// Issue cost per opcode ([`issue_costs`]).
    pub cost: [u64; Opcode::COUNT],
}

/// Draws the stats plot: x the scanline, y cycles; per scanline a bar stacked from the
/// [`GROUPS`] (bottom to top), a horizontal line at the line period, a red marker with the
/// slack above every scanline that overran its deadline; the legend on the right.
///
/// Fails when a scanline's opcode cycles do not add up to its `busy_cycles` (the costs
/// are not the machine's), or there is no scanline.
pub fn render_stats_plot(p: &StatsPlot<'_>) -> Result<Rgb, String> {
    let (first, last) = match (p.lines.first(), p.lines.last()) {
        (Some(a), Some(b)) => (a.line, b.line),
        _ => return Err("no scanline to plot".into()),
    };
    let groups: Vec<[u64; GROUPS.len()]> =
        p.lines.iter().map(|l| group_cycles(l, &p.cost)).collect();
    for (l, g) in p.lines.iter().zip(&groups) {
        let busy: u64 = g[..GROUPS.len() - 1].iter().sum();
        if busy != l.busy_cycles {
            return Err(format!(
                "scanline {}: the opcodes' cycles add up to {busy}, the engine counted {} busy cycles",
                l.line, l.busy_cycles
            ));
        }
    }
    let used: Vec<bool> = (0..GROUPS.len())
        .map(|g| groups.iter().any(|c| c[g] > 0))
        .collect();
    let top = groups
        .iter()
        .map(|g| g.iter().sum::<u64>())
        .max()
        .unwrap_or(0)
        .max(p.line_period)
        .max(1) as f64;
    let late = p.lines.iter().filter(|l| l.slack < 0).count();
    let ymax = top * if late == 0 { 1.06 } else { 1.16 };
    let (x0, x1) = (first as f64 - 0.5, last as f64 + 0.5);
    let n = p.lines.len() as u64;
    // the slack above each marker, while the bars are wide enough for it
    let label_late = n <= 24;

    let (w, h) = STATS_PLOT_SIZE;
    // the plotting area, in pixels
    let (left, right, upper, lower) = (78i32, w as i32 - 250, 96i32, h as i32 - 56);
    let mut img = Rgb::white(w, h);
    draw_on(&mut img, |root, labels| {
        labels.push(Label::new(
            format!("{}: bus cycles per scanline", p.name),
            (16, 12),
            22.0,
        ));
        let late_text = match late {
            0 => "no overrun".to_string(),
            1 => "1 scanline late".to_string(),
            k => format!("{k} scanlines late"),
        };
        labels.push(Label::new(
            format!(
                "line period (the budget) {} cycles; scanlines {first}–{last}; {late_text}",
                p.line_period
            ),
            (16, 42),
            15.0,
        ));
        let area = root.clone().shrink(
            (left as u32, upper as u32),
            ((right - left) as u32, (lower - upper) as u32),
        );
        let mut chart = ChartBuilder::on(&area)
            .build_cartesian_2d(x0..x1, 0f64..ymax)
            .map_err(err)?;

        // grid and y ticks
        let ystep = nice_step(ymax / 9.0);
        let grid = rgb([228, 228, 228]);
        let mut y = 0u64;
        while (y as f64) <= ymax {
            let (_, py) = chart.backend_coord(&(x0, y as f64));
            root.draw(&PathElement::new(vec![(left, py), (right, py)], grid))
                .map_err(err)?;
            root.draw(&PathElement::new(vec![(left - 5, py), (left, py)], BLACK))
                .map_err(err)?;
            labels.push(
                Label::new(y.to_string(), (left - 8, py), 14.0).align(Align::End, Align::Center),
            );
            y += ystep;
        }
        labels
            .push(Label::new("cycles", (left - 8, upper - 10), 15.0).align(Align::End, Align::End));
        // x ticks at scanlines
        let xstep = nice_step(n as f64 / 16.0);
        let mut x = first.div_ceil(xstep) * xstep;
        while x <= last {
            let (px, _) = chart.backend_coord(&(x as f64, 0.0));
            root.draw(&PathElement::new(vec![(px, lower), (px, lower + 5)], BLACK))
                .map_err(err)?;
            labels.push(
                Label::new(x.to_string(), (px, lower + 8), 14.0).align(Align::Center, Align::Start),
            );
            x += xstep;
        }
        labels.push(
            Label::new("scanline", ((left + right) / 2, lower + 30), 15.0)
                .align(Align::Center, Align::Start),
        );

        // the stacked bars, one series per group
        let half = if n > 200 { 0.5 } else { 0.4 };
        for (g, group) in GROUPS.iter().enumerate() {
            if !used[g] {
                continue;
            }
            let color = rgb(group.color);
            let bars = p.lines.iter().zip(&groups).filter_map(|(l, c)| {
                let below: u64 = c[..g].iter().sum();
                (c[g] > 0).then(|| {
                    let x = l.line as f64;
                    Rectangle::new(
                        [(x - half, below as f64), (x + half, (below + c[g]) as f64)],
                        color.filled(),
                    )
                })
            });
            chart.draw_series(bars).map_err(err)?;
        }
        // the axes, then the budget
        root.draw(&PathElement::new(
            vec![(left, upper), (left, lower), (right, lower)],
            BLACK,
        ))
        .map_err(err)?;
        let period = p.line_period as f64;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x0, period), (x1, period)],
                BLACK.stroke_width(2),
            )))
            .map_err(err)?;
        // the overruns: a red triangle pointing down at the bar, the slack above it
        for (l, c) in p.lines.iter().zip(&groups).filter(|(l, _)| l.slack < 0) {
            let top = c.iter().sum::<u64>().max(p.line_period) as f64;
            let (px, py) = chart.backend_coord(&(l.line as f64, top));
            root.draw(&Polygon::new(
                vec![(px - 7, py - 18), (px + 7, py - 18), (px, py - 5)],
                rgb(OVERRUN).filled(),
            ))
            .map_err(err)?;
            if label_late {
                labels.push(
                    Label::new(l.slack.to_string(), (px, py - 21), 13.0)
                        .align(Align::Center, Align::End)
                        .color(OVERRUN),
                );
            }
        }

        // the legend, top to bottom as the bars stack bottom to top
        let lx = right + 28;
        let mut y = upper;
        labels.push(Label::new("bus cycles", (lx, y), 15.0).align(Align::Start, Align::Center));
        y += 26;
        for (g, group) in GROUPS.iter().enumerate().rev() {
            if !used[g] {
                continue;
            }
            root.draw(&Rectangle::new(
                [(lx, y - 7), (lx + 16, y + 7)],
                rgb(group.color).filled(),
            ))
            .map_err(err)?;
            labels.push(
                Label::new(group.name, (lx + 26, y), 14.0).align(Align::Start, Align::Center),
            );
            y += 23;
        }
        y += 8;
        root.draw(&PathElement::new(
            vec![(lx, y), (lx + 16, y)],
            BLACK.stroke_width(2),
        ))
        .map_err(err)?;
        labels.push(
            Label::new(
                format!("line period ({})", p.line_period),
                (lx + 26, y),
                14.0,
            )
            .align(Align::Start, Align::Center),
        );
        y += 23;
        root.draw(&Polygon::new(
            vec![(lx + 1, y - 6), (lx + 15, y - 6), (lx + 8, y + 7)],
            rgb(OVERRUN).filled(),
        ))
        .map_err(err)?;
        labels.push(
            Label::new("overrun: slack < 0", (lx + 26, y), 14.0).align(Align::Start, Align::Center),
        );
        Ok(())
    })?;
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::{Intensity, TraceHeader};
    use cwisim_xproc::{run, Machine, Timing};

    fn overrun() -> (Timeline, cwisim_xproc::RunStats) {
        let h = TraceHeader::new(16, 4, 3).expect("header");
        let g = |v| Intensity::splat(v, 3);
        let trace = [
            Instruction::set_i(3, g(0.5)),
            Instruction::set_pdi(1, 4, g(0.5)),
            Instruction::eval1(0, 16, g(0.25)),
            Instruction::refresh(),
            Instruction::eval2(0, 8, g(0.0), g(0.1)),
            Instruction::eval3(0, 16, g(0.0), g(0.0), g(0.001)),
            Instruction::eval3(0, 16, g(0.0), g(0.0), g(0.001)),
            Instruction::dis(2, 3),
            Instruction::acc_mode(),
            Instruction::eval0(0, 5, g(0.5)),
            Instruction::nop(),
            Instruction::refresh(),
            Instruction::refresh(),
        ];
        let m = Machine::from_json(
            r#"{"line_period_cycles": 30, "opcode_cycles": {"Eval3": 3, "Refresh": 2}}"#,
            "test",
        )
        .expect("machine");
        let (_, stats) = run::<f64>(&h, &trace, &m, Timing::Fast).expect("run");
        (m.timeline(&h).expect("timeline"), stats)
    }

    #[test]
    fn opcode_cycles_add_up_to_the_busy_cycles() {
        let (t, stats) = overrun();
        let cost = issue_costs(&t);
        assert_eq!(cost[Opcode::Eval3.index()], 3 + 9);
        assert_eq!(cost[Opcode::Refresh.index()], 2);
        assert_eq!(cost[Opcode::SetPdI.index()], 1 + 3);
        for l in &stats.lines {
            let per_op = opcode_cycles(l, &cost);
            assert_eq!(per_op.iter().sum::<u64>(), l.busy_cycles, "line {}", l.line);
            let g = group_cycles(l, &cost);
            assert_eq!(g[..7].iter().sum::<u64>(), l.busy_cycles);
            assert_eq!(g[7], l.stall_cycles);
        }
        assert!(stats.lines.iter().any(|l| l.slack < 0), "{stats:?}");
    }

    #[test]
    fn the_plot_has_its_size_and_is_deterministic() {
        let (t, stats) = overrun();
        let plot = StatsPlot {
            name: "t.cwt",
            lines: &stats.lines,
            line_period: t.line_period,
            cost: issue_costs(&t),
        };
        let a = render_stats_plot(&plot).expect("plot");
        let b = render_stats_plot(&plot).expect("plot");
        assert_eq!((a.width, a.height), STATS_PLOT_SIZE);
        assert_eq!(a, b);
        // text was drawn, and the overrun marker
        assert!(a.data.chunks(3).any(|p| p == [0, 0, 0]));
        assert!(a.data.chunks(3).any(|p| p == OVERRUN));
        let mut png = Vec::new();
        a.encode_png(&mut png).expect("png");
        let decoded = image::load_from_memory(&png).expect("decodes");
        assert_eq!((decoded.width(), decoded.height()), STATS_PLOT_SIZE);
        assert!(render_stats_plot(&StatsPlot { lines: &[], ..plot }).is_err());
    }

    #[test]
    fn wrong_costs_are_caught() {
        let (t, stats) = overrun();
        let mut cost = issue_costs(&t);
        cost[Opcode::Eval1.index()] += 1;
        let plot = StatsPlot {
            name: "t.cwt",
            lines: &stats.lines,
            line_period: t.line_period,
            cost,
        };
        let e = render_stats_plot(&plot).expect_err("mismatch");
        assert!(e.contains("busy cycles"), "{e}");
    }

    #[test]
    fn labels_are_laid_out_and_anchored() {
        let w = text_width("cycles", 14.0);
        assert!(w > 30.0 && w < 60.0, "{w}");
        let mut img = Rgb::white(120, 40);
        img.draw_label(&Label::new("10", (60, 20), 14.0).align(Align::End, Align::Center));
        let inked: Vec<(u32, u32)> = (0..40)
            .flat_map(|y| (0..120).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get(x, y) != [255, 255, 255])
            .collect();
        let (xmin, xmax) = (
            inked.iter().map(|p| p.0).min(),
            inked.iter().map(|p| p.0).max(),
        );
        let (ymin, ymax) = (
            inked.iter().map(|p| p.1).min(),
            inked.iter().map(|p| p.1).max(),
        );
        assert!(xmax <= Some(60) && xmin >= Some(44), "{xmin:?}..{xmax:?}");
        // digits 10 px high, centred on y = 20
        let (ymin, ymax) = (ymin.expect("ink"), ymax.expect("ink"));
        assert!((9..=11).contains(&(ymax - ymin)), "{ymin}..{ymax}");
        assert!((19..=21).contains(&((ymin + ymax) / 2)), "{ymin}..{ymax}");
    }
}
