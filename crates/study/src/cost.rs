//! Cost images: per pixel, how many instructions addressed it on its scanline.
//!
//! Counted from the instruction stream alone, independently of the engines: a
//! [`CostMap`] is a [`TraceWrite`] (to sit in a [`Tee`] with the array, as `cwisim render`
//! does) and [`CostReader`] records what a [`TraceRead`] hands out (`cwisim run`).
//!
//! An instruction touches the processors it addresses: `[x, x+dx)` for `Eval0`–`Eval3` and
//! `Dis`, `x` for `SetI`/`SetdI`/`SetddI`, `x, x+dx, x+2dx, …` for the periodic sets;
//! `Refresh`, `Acc_mode` and `Nop` touch none. Locks and masks do not matter: a suppressed
//! processor was still addressed. Each `Refresh` closes a scanline, so the map has one
//! row per scanline output, like the image; instructions after the last `Refresh` belong
//! to no scanline and are not in it. A row adds up to the scanline's `processor_updates`.
//!
//! Outputs: a heat-map PNG ([`render_cost_image`]: viridis for 1…max, black for 0, one
//! array pixel an integer number of image pixels square, a colour bar with the counts) and
//! a NumPy array ([`encode_cost_npy`]: `uint32`, shape `(scanlines, width)`).

use crate::error::StudyError;
use crate::plot::{draw_on, err, nice_step, rgb, Align, Label, Rgb};
use cwisim_isa::{
    Instruction, Location, Opcode, OperandKind, TraceError, TraceHeader, TraceRead, TraceWrite,
};
use npyz::WriterBuilder;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::io::{self, Write};

/// What a cost image says of a stream that output no scanline.
pub const NO_SCANLINE: &str = "the trace output no scanline (no Refresh); nothing to write";

/// The largest cost map kept: 1 GiB of counts.
pub const COST_LIMIT_BYTES: u64 = 1 << 30;

/// Instruction counts per pixel and scanline.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CostMap {
    width: usize,
    /// Difference array of the scanline being built: `width + 1` entries.
    diff: Vec<i64>,
    /// Finished scanlines, `lines × width` counts.
    counts: Vec<u32>,
    lines: usize,
    /// Instructions since the last `Refresh`.
    pending: u64,
    limit_bytes: u64,
    overflow: Option<u64>,
}

impl CostMap {
    /// An empty map for an array `width` processors wide.
    pub fn new(width: usize) -> CostMap {
        CostMap::with_limit(width, COST_LIMIT_BYTES)
    }

    /// An empty map that refuses to grow past `limit_bytes` of counts.
    pub fn with_limit(width: usize, limit_bytes: u64) -> CostMap {
        CostMap {
            width,
            diff: vec![0; width + 1],
            counts: Vec::new(),
            lines: 0,
            pending: 0,
            limit_bytes,
            overflow: None,
        }
    }

    /// Counts one instruction (which must fit the array: [`Instruction::check`]).
    pub fn record(&mut self, instr: &Instruction) {
        let w = self.width;
        let mut touch = |a: usize, b: usize| {
            let (a, b) = (a.min(w), b.min(w));
            if a < b {
                self.diff[a] += 1;
                self.diff[b] -= 1;
            }
        };
        match instr.op.operands() {
            [OperandKind::X, OperandKind::Period, ..] => {
                let step = (instr.dx as usize).max(1);
                for p in (instr.x as usize..w).step_by(step) {
                    touch(p, p + 1);
                }
            }
            _ => {
                if let Some((a, b)) = instr.span() {
                    touch(a as usize, b as usize);
                }
            }
        }
        if instr.op == Opcode::Refresh {
            self.close_line();
        } else {
            self.pending += 1;
        }
    }

    fn close_line(&mut self) {
        self.pending = 0;
        let bytes = (self.lines as u64 + 1) * self.width as u64 * 4;
        if self.overflow.is_some() || bytes > self.limit_bytes {
            self.overflow.get_or_insert(self.lines as u64);
        } else {
            let mut run = 0i64;
            self.counts.extend(self.diff[..self.width].iter().map(|d| {
                run += d;
                u32::try_from(run).unwrap_or(u32::MAX)
            }));
        }
        self.diff.fill(0);
        self.lines += 1;
    }

    /// Processors (pixel columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Scanlines closed so far (one per `Refresh`).
    pub fn lines(&self) -> usize {
        self.lines
    }

    /// The counts, `lines × width`, row-major.
    pub fn counts(&self) -> &[u32] {
        &self.counts
    }

    /// One scanline's counts.
    pub fn row(&self, line: usize) -> &[u32] {
        &self.counts[line * self.width..(line + 1) * self.width]
    }

    /// The largest count (0 for an empty map).
    pub fn max(&self) -> u32 {
        self.counts.iter().copied().max().unwrap_or(0)
    }

    /// Instructions after the last `Refresh` (in no scanline).
    pub fn unrefreshed(&self) -> u64 {
        self.pending
    }

    /// The map, or why it could not be kept whole.
    pub fn check(&self) -> Result<(), StudyError> {
        match self.overflow {
            None => Ok(()),
            Some(line) => Err(StudyError::Usage(format!(
                "the cost map would exceed {} bytes at scanline {line} ({} counts per scanline)",
                self.limit_bytes, self.width
            ))),
        }
    }
}

impl TraceWrite for CostMap {
    fn write(&mut self, instr: &Instruction) -> io::Result<()> {
        self.record(instr);
        Ok(())
    }
    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// A [`TraceRead`] that counts every instruction it hands out into a [`CostMap`].
pub struct CostReader<'a> {
    inner: &'a mut dyn TraceRead,
    map: &'a mut CostMap,
}

impl<'a> CostReader<'a> {
    /// Wraps `inner`, recording into `map`.
    pub fn new(inner: &'a mut dyn TraceRead, map: &'a mut CostMap) -> Self {
        CostReader { inner, map }
    }
}

impl TraceRead for CostReader<'_> {
    fn header(&self) -> &TraceHeader {
        self.inner.header()
    }
    fn next_instruction(&mut self) -> Result<Option<Instruction>, TraceError> {
        let next = self.inner.next_instruction()?;
        if let Some(i) = &next {
            self.map.record(i);
        }
        Ok(next)
    }
    fn location(&self) -> Location {
        self.inner.location()
    }
    fn bytes_read(&self) -> u64 {
        self.inner.bytes_read()
    }
}

/// The `.npy` bytes of a cost map: `uint32` (`<u4`), shape `(scanlines, width)`, C order.
pub fn encode_cost_npy<W: Write>(out: W, map: &CostMap) -> io::Result<()> {
    let shape = [map.lines() as u64, map.width() as u64];
    let mut writer = npyz::WriteOptions::<u32>::new()
        .default_dtype()
        .shape(&shape)
        .writer(out)
        .begin_nd()?;
    writer.extend(map.counts().iter().copied())?;
    writer.finish()
}

/// viridis (matplotlib's, CC0) at 0, 1/16, …, 1; linear in between.
const VIRIDIS: [[u8; 3]; 17] = [
    [68, 1, 84],
    [72, 24, 106],
    [71, 45, 123],
    [66, 64, 134],
    [59, 82, 139],
    [51, 99, 141],
    [44, 114, 142],
    [38, 130, 142],
    [33, 145, 140],
    [31, 159, 136],
    [39, 173, 129],
    [61, 188, 116],
    [92, 200, 99],
    [129, 211, 77],
    [170, 220, 50],
    [213, 226, 26],
    [253, 231, 37],
];

/// The colour of pixels no instruction touched: black, darker than any viridis colour.
pub const ZERO_COLOR: [u8; 3] = [0, 0, 0];

/// viridis at `t` in `[0, 1]`.
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let f = t * 16.0;
    let i = (f.floor() as usize).min(15);
    let r = f - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |k: usize| (f64::from(a[k]) * (1.0 - r) + f64::from(b[k]) * r).round() as u8;
    [mix(0), mix(1), mix(2)]
}

/// The colour of a count when the largest is `max`: [`ZERO_COLOR`] for 0, viridis from 1
/// (dark purple) to `max` (yellow).
pub fn count_color(count: u32, max: u32) -> [u8; 3] {
    if count == 0 {
        ZERO_COLOR
    } else if max <= 1 {
        viridis(1.0)
    } else {
        viridis(f64::from(count - 1) / f64::from(max - 1))
    }
}

/// How a cost map is laid out in its PNG.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CostLayout {
    /// Image pixels per array pixel (each way).
    pub scale: u32,
    /// Top-left corner of the heat map in the image.
    pub origin: (u32, u32),
    /// The whole image.
    pub size: (u32, u32),
}

const LEFT: u32 = 60;
const TOP: u32 = 78;
const BOTTOM: u32 = 46;
const BAR_GAP: u32 = 28;
const BAR_W: u32 = 22;
const RIGHT: u32 = 90;
const MIN_BAR_H: u32 = 200;
/// The heat map is scaled up until it is at least this wide (when it fits [`MAX_SIDE`]).
pub const MIN_MAP_WIDTH: u32 = 256;
/// Scaling stops before the heat map is taller or wider than this.
pub const MAX_SIDE: u32 = 4096;
/// The largest cost image: 64 Mi pixels.
pub const MAX_PIXELS: u64 = 1 << 26;

/// The layout of a cost image of `width × lines` array pixels.
pub fn cost_layout(width: usize, lines: usize) -> Result<CostLayout, StudyError> {
    if width == 0 || lines == 0 {
        return Err(StudyError::Usage(NO_SCANLINE.into()));
    }
    let big = u64::from(MAX_SIDE);
    let (w, l) = (width as u64, lines as u64);
    let mut scale = MIN_MAP_WIDTH.div_ceil(width.min(MIN_MAP_WIDTH as usize) as u32);
    while scale > 1 && (w * u64::from(scale) > big || l * u64::from(scale) > big) {
        scale -= 1;
    }
    let (mw, mh) = (w * u64::from(scale), l * u64::from(scale));
    let iw = u64::from(LEFT) + mw + u64::from(BAR_GAP + BAR_W + RIGHT);
    let ih = u64::from(TOP) + mh.max(u64::from(MIN_BAR_H)) + u64::from(BOTTOM);
    if iw * ih > MAX_PIXELS || iw > u64::from(i32::MAX as u32) || ih > u64::from(i32::MAX as u32) {
        return Err(StudyError::Usage(format!(
            "a cost image of {width} × {lines} pixels would be too large ({iw} × {ih}); use --cost-npy"
        )));
    }
    Ok(CostLayout {
        scale,
        origin: (LEFT, TOP),
        size: (iw as u32, ih as u32),
    })
}

/// Draws the cost image: the title (`name`, the largest count), the heat map with pixel
/// column and scanline ticks, and a colour bar with the counts.
pub fn render_cost_image(map: &CostMap, name: &str) -> Result<Rgb, StudyError> {
    let layout = cost_layout(map.width(), map.lines())?;
    let (iw, ih) = layout.size;
    let s = layout.scale;
    let (ox, oy) = layout.origin;
    let (mw, mh) = (map.width() as u32 * s, map.lines() as u32 * s);
    let max = map.max();
    let bar_h = mh.max(MIN_BAR_H);
    let mut img = Rgb::white(iw, ih);
    draw_on(&mut img, |root, labels| {
        labels.push(Label::new(
            format!("{name}: instructions per pixel"),
            (12, 10),
            18.0,
        ));
        let scaled = if s > 1 {
            format!(", drawn ×{s}")
        } else {
            String::new()
        };
        labels.push(Label::new(
            format!(
                "max {max}; {} pixel columns × {} scanlines{scaled}",
                map.width(),
                map.lines()
            ),
            (12, 36),
            13.0,
        ));
        // a frame around the heat map
        let (x0, y0) = (ox as i32 - 1, oy as i32 - 1);
        let (x1, y1) = ((ox + mw) as i32, (oy + mh) as i32);
        root.draw(&Rectangle::new([(x0, y0), (x1, y1)], BLACK.stroke_width(1)))
            .map_err(err)?;
        // ticks: pixel columns along the bottom, scanlines down the left, at pixel centres
        let xs = nice_step(40.0 / f64::from(s));
        let mut x = 0;
        while x < map.width() as u64 {
            let px = (ox + x as u32 * s + s / 2) as i32;
            root.draw(&PathElement::new(vec![(px, y1), (px, y1 + 4)], BLACK))
                .map_err(err)?;
            labels.push(
                Label::new(x.to_string(), (px, y1 + 6), 12.0).align(Align::Center, Align::Start),
            );
            x += xs;
        }
        labels.push(
            Label::new("pixel column", ((ox + mw / 2) as i32, y1 + 24), 13.0)
                .align(Align::Center, Align::Start),
        );
        let ys = nice_step(20.0 / f64::from(s));
        let mut y = 0;
        while y < map.lines() as u64 {
            let py = (oy + y as u32 * s + s / 2) as i32;
            root.draw(&PathElement::new(vec![(x0 - 4, py), (x0, py)], BLACK))
                .map_err(err)?;
            labels.push(
                Label::new(y.to_string(), (x0 - 7, py), 12.0).align(Align::End, Align::Center),
            );
            y += ys;
        }
        labels.push(Label::new("scanline", (x0, y0 - 5), 13.0).align(Align::End, Align::End));

        // The colour bar: a band per count when they fit, else a band for 0 below a
        // gradient over 1..max.
        let bx = (ox + mw + BAR_GAP) as i32;
        let bw = BAR_W as i32;
        let top = oy as i32;
        let bottom = (oy + bar_h) as i32; // exclusive
        let tick = |py: i32, v: u32, labels: &mut Vec<Label>| {
            labels.push(
                Label::new(v.to_string(), (bx + bw + 8, py), 12.0)
                    .align(Align::Start, Align::Center),
            );
            root.draw(&PathElement::new(
                vec![(bx + bw, py), (bx + bw + 4, py)],
                BLACK,
            ))
            .map_err(err)
        };
        let h = f64::from(bar_h);
        let bands = u64::from(max) + 1;
        if bands as f64 * 12.0 <= h {
            // band k covers rows [edge(k + 1), edge(k))
            let edge = |k: u64| bottom - (k as f64 * h / bands as f64).round() as i32;
            let every = nice_step(bands as f64 * 16.0 / h);
            for k in 0..bands {
                let (lo, hi) = (edge(k + 1), edge(k) - 1);
                root.draw(&Rectangle::new(
                    [(bx, lo), (bx + bw - 1, hi)],
                    rgb(count_color(k as u32, max)).filled(),
                ))
                .map_err(err)?;
                if k % every == 0 || k == bands - 1 {
                    tick((lo + hi) / 2, k as u32, labels)?;
                }
            }
        } else {
            let zero_h = 14;
            let grad_bottom = bottom - zero_h - 6; // exclusive
            let grad_h = grad_bottom - top;
            root.draw(&Rectangle::new(
                [(bx, bottom - zero_h), (bx + bw - 1, bottom - 1)],
                rgb(ZERO_COLOR).filled(),
            ))
            .map_err(err)?;
            root.draw(&Rectangle::new(
                [(bx - 1, bottom - zero_h - 1), (bx + bw, bottom)],
                BLACK.stroke_width(1),
            ))
            .map_err(err)?;
            tick(bottom - zero_h / 2, 0, labels)?;
            for r in 0..grad_h {
                let t = f64::from(r) / f64::from((grad_h - 1).max(1));
                let py = grad_bottom - 1 - r;
                root.draw(&PathElement::new(
                    vec![(bx, py), (bx + bw - 1, py)],
                    rgb(viridis(t)),
                ))
                .map_err(err)?;
            }
            let at = |v: u32| {
                let t = f64::from(v - 1) / f64::from(max - 1);
                grad_bottom - 1 - (t * f64::from(grad_h - 1)).round() as i32
            };
            let step = nice_step(f64::from(max - 1) * 20.0 / f64::from(grad_h));
            let mut ticks: Vec<u32> = vec![1];
            let mut v = step;
            while v < u64::from(max) {
                if v > 1 {
                    ticks.push(v as u32);
                }
                v += step;
            }
            // the max always; drop a tick too close below it
            if ticks.len() > 1 && ticks.last().is_some_and(|&l| at(l) - at(max) < 14) {
                ticks.pop();
            }
            ticks.push(max);
            for v in ticks {
                tick(at(v), v, labels)?;
            }
            frame_bar(root, bx, bw, top, grad_bottom)?;
            labels.push(
                Label::new("count", (bx + bw / 2, top - 5), 12.0).align(Align::Center, Align::End),
            );
            return Ok(());
        }
        frame_bar(root, bx, bw, top, bottom)?;
        labels.push(
            Label::new("count", (bx + bw / 2, top - 5), 12.0).align(Align::Center, Align::End),
        );
        Ok(())
    })
    .map_err(StudyError::Plot)?;
    // The heat map itself, pixel by pixel: exactly `s × s` image pixels per array pixel.
    for line in 0..map.lines() {
        for (x, &c) in map.row(line).iter().enumerate() {
            let colour = count_color(c, max);
            for dy in 0..s {
                for dx in 0..s {
                    img.put(ox + x as u32 * s + dx, oy + line as u32 * s + dy, colour);
                }
            }
        }
    }
    Ok(img)
}

/// A black frame around the colour bar's rows `[top, bottom)`.
fn frame_bar(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    bx: i32,
    bw: i32,
    top: i32,
    bottom: i32,
) -> Result<(), String> {
    root.draw(&Rectangle::new(
        [(bx - 1, top - 1), (bx + bw, bottom)],
        BLACK.stroke_width(1),
    ))
    .map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_isa::Intensity;

    fn map_of(width: usize, instrs: &[Instruction]) -> CostMap {
        let mut m = CostMap::new(width);
        for i in instrs {
            m.write(i).expect("record");
        }
        m
    }

    #[test]
    fn every_kind_of_instruction_touches_what_it_addresses() {
        let g = Intensity::grey(0.5);
        let m = map_of(
            8,
            &[
                Instruction::set_i(2, g),
                Instruction::set_pdi(1, 3, g), // 1, 4, 7
                Instruction::eval1(0, 8, g),
                Instruction::eval0(3, 2, g), // 3, 4
                Instruction::dis(6, 2),      // 6, 7
                Instruction::eval2(5, 0, g, g),
                Instruction::acc_mode(),
                Instruction::nop(),
                Instruction::refresh(),
                Instruction::refresh(),
                Instruction::set_pddi(7, 1, g), // 7
                Instruction::eval3(0, 1, g, g, g),
                Instruction::refresh(),
                Instruction::eval1(0, 8, g), // after the last Refresh
            ],
        );
        assert_eq!((m.width(), m.lines(), m.unrefreshed()), (8, 3, 1));
        assert_eq!(m.row(0), [1, 2, 2, 2, 3, 1, 2, 3]);
        assert_eq!(m.row(1), [0; 8]);
        assert_eq!(m.row(2), [1, 0, 0, 0, 0, 0, 0, 1]);
        assert_eq!(m.max(), 3);
        m.check().expect("within the limit");
    }

    #[test]
    fn a_full_map_says_so() {
        let mut m = CostMap::with_limit(4, 20);
        for _ in 0..3 {
            m.record(&Instruction::refresh());
        }
        assert_eq!(m.lines(), 3);
        assert!(m
            .check()
            .expect_err("limit")
            .to_string()
            .contains("scanline 1"));
    }

    #[test]
    fn npy_is_uint32_with_the_map_shape() {
        let m = map_of(
            3,
            &[
                Instruction::eval1(1, 2, Intensity::grey(1.0)),
                Instruction::refresh(),
            ],
        );
        let mut bytes = Vec::new();
        encode_cost_npy(&mut bytes, &m).expect("encode");
        let npy = npyz::NpyFile::new(&bytes[..]).expect("npy");
        assert_eq!(npy.shape(), &[1, 3]);
        assert_eq!(npy.into_vec::<u32>().expect("u32"), [0, 1, 1]);
    }

    #[test]
    fn colours_run_from_black_through_viridis() {
        assert_eq!(count_color(0, 5), ZERO_COLOR);
        assert_eq!(count_color(1, 5), VIRIDIS[0]);
        assert_eq!(count_color(5, 5), VIRIDIS[16]);
        assert_eq!(count_color(1, 1), VIRIDIS[16]);
        assert_eq!(viridis(0.5), VIRIDIS[8]);
        assert_ne!(ZERO_COLOR, viridis(0.0));
    }

    #[test]
    fn the_heat_map_keeps_one_square_per_pixel() {
        let g = Intensity::grey(1.0);
        let m = map_of(
            4,
            &[
                Instruction::eval1(1, 3, g),
                Instruction::eval1(3, 1, g),
                Instruction::refresh(),
                Instruction::refresh(),
            ],
        );
        let layout = cost_layout(4, 2).expect("layout");
        assert_eq!(layout.scale, 64);
        let img = render_cost_image(&m, "t.cwt").expect("draw");
        assert_eq!((img.width, img.height), layout.size);
        let (ox, oy) = layout.origin;
        for (x, c) in [(0, 0), (1, 1), (2, 1), (3, 2)] {
            for (dx, dy) in [(0, 0), (63, 63), (31, 7)] {
                assert_eq!(
                    img.get(ox + x * 64 + dx, oy + dy),
                    count_color(c, 2),
                    "x {x}"
                );
                assert_eq!(img.get(ox + x * 64 + dx, oy + 64 + dy), ZERO_COLOR);
            }
        }
        assert_eq!(render_cost_image(&m, "t.cwt").expect("again"), img);
        assert!(render_cost_image(&CostMap::new(4), "t.cwt").is_err());
    }

    #[test]
    fn big_maps_are_not_scaled_and_huge_ones_refused() {
        assert_eq!(cost_layout(1024, 768).expect("layout").scale, 1);
        assert_eq!(cost_layout(100, 10).expect("layout").scale, 3);
        assert_eq!(cost_layout(2, 3000).expect("layout").scale, 1);
        assert!(cost_layout(1 << 20, 1 << 10).is_err());
    }
}
