//! A phase's frame of instructions. Every row is the display list's polygons, in parts
//! (those kept as the previous frame drew them, then those the phase regenerates), each
//! part scanned on its own with its `Refresh` held back, and one `Refresh` to end the row.
//! The anti-aliasing frame first re-sends the previous frame's unflagged pixels as
//! `Eval0` claims.

use super::display::Subset;
use super::Phase;
use crate::phong::PhongFrame;
use crate::renderer::{Counters, FramePlan};
use cwisim_isa::{Instruction, Intensity, Opcode, TraceWrite};
use cwisim_scene::{Antialias, Shading};
use cwisim_xproc::Image;
use cwisim_ypipe::{emit_rows, Claim, Options, ScanPlan};
use std::io;
use std::ops::Range;

/// DO_FILL point-sampled (the shading phases).
pub const POINT: Options = Options {
    shading: Shading::Gouraud,
    aa: Antialias::None,
    claim: Claim::Accumulate,
};

/// DO_FILL's box filter (the anti-aliasing phase).
pub const BOX: Options = Options {
    shading: Shading::Gouraud,
    aa: Antialias::Box,
    claim: Claim::Accumulate,
};

/// One scan of some polygons: DO_FILL's or Phong's.
pub enum Part<'a> {
    /// Flat and Gouraud polygons through DO_FILL.
    Dofill(ScanPlan<'a>, &'static Options),
    /// Phong polygons lit per pixel.
    Phong(PhongFrame<'a>),
}

impl<'a> Part<'a> {
    /// The scans of `subset`, sampled as `aa` says (`None` or `Box`).
    pub fn of(subset: &'a Subset, aa: Antialias, tolerance: f64) -> Vec<Part<'a>> {
        let options = if aa == Antialias::None { &POINT } else { &BOX };
        let mut parts = vec![Part::Dofill(
            ScanPlan::new(&subset.dofill, options),
            options,
        )];
        if let Some((screen, surfaces)) = &subset.phong {
            parts.push(Part::Phong(PhongFrame::new(
                screen, surfaces, aa, tolerance,
            )));
        }
        parts
    }

    fn emit(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<()> {
        match self {
            Part::Dofill(plan, options) => emit_rows(plan, options, rows, sink).map(drop),
            Part::Phong(frame) => frame.emit_rows(rows, sink).map(drop),
        }
    }
}

/// A sink that passes every instruction but `Refresh` on, counting them and the pixels
/// their evaluations reach.
struct Held<'s> {
    inner: &'s mut dyn TraceWrite,
    instructions: u64,
    pixels: u64,
}

impl TraceWrite for Held<'_> {
    fn write(&mut self, i: &Instruction) -> io::Result<()> {
        if i.op == Opcode::Refresh {
            return Ok(());
        }
        self.instructions += 1;
        if matches!(i.op, Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3) {
            if let Some((a, b)) = i.span() {
                self.pixels += u64::from(b - a);
            }
        }
        self.inner.write(i)
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Writes `row` of `parts` without their `Refresh`: `(instructions, pixels)`.
fn emit_row(parts: &[Part], row: u32, sink: &mut dyn TraceWrite) -> io::Result<(u64, u64)> {
    let mut held = Held {
        inner: sink,
        instructions: 0,
        pixels: 0,
    };
    for part in parts {
        part.emit(row..row + 1, &mut held)?;
    }
    Ok((held.instructions, held.pixels))
}

/// A shading phase's frame: the kept parts, then the regenerated ones, row by row.
pub struct Shaded<'a> {
    /// The phase.
    pub phase: Phase,
    /// Polygons drawn as the previous frame drew them.
    pub kept: Vec<Part<'a>>,
    /// Polygons this phase regenerates.
    pub refined: Vec<Part<'a>>,
    /// How many polygons it regenerates.
    pub refined_polygons: u64,
}

impl FramePlan for Shaded<'_> {
    fn counters(&self) -> Counters {
        Counters::default().with(self.phase.counter("polygons"), self.refined_polygons)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let (mut total, mut regenerated, mut pixels) = (0, 0, 0);
        for row in rows {
            total += emit_row(&self.kept, row, sink)?.0;
            let (n, p) = emit_row(&self.refined, row, sink)?;
            sink.write(&Instruction::refresh())?;
            total += n + 1;
            regenerated += n;
            pixels += p;
        }
        let p = self.phase;
        Ok(Counters::default()
            .with(p.counter("instructions"), total)
            .with(p.counter("regenerated"), regenerated)
            .with(p.counter("pixels"), pixels))
    }
}

/// A pixel's values as bits: runs are of bit-identical values, so that a claim re-sends
/// exactly what the array output (`-0.0` is not `+0.0`).
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The anti-aliasing frame: per row, the previous frame's unflagged pixels claimed with
/// `Eval0`, then (in rows with a flagged pixel) the box filter of the whole display list.
pub struct Antialiased<'a> {
    /// The display list, box-filtered.
    pub parts: Vec<Part<'a>>,
    /// The previous frame's output.
    pub previous: &'a Image,
    /// The pixels to filter, row-major.
    pub flags: Vec<bool>,
    /// Their fragments (`super::measure::aa_fragments`).
    pub fragments: u64,
}

impl FramePlan for Antialiased<'_> {
    fn counters(&self) -> Counters {
        Counters::default()
            .with(
                "aa_pixels",
                self.flags.iter().filter(|&&f| f).count() as u64,
            )
            .with("aa_fragments", self.fragments)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let (w, ch) = (self.previous.width, self.previous.channels);
        let (mut claims, mut regenerated) = (0u64, 0u64);
        let mut rows_count = 0u64;
        for row in rows {
            rows_count += 1;
            let r = row as usize;
            let flags = &self.flags[r * w..(r + 1) * w];
            let value = |x: usize| &self.previous.data[(r * w + x) * ch..(r * w + x + 1) * ch];
            let mut x = 0;
            while x < w {
                if flags[x] {
                    x += 1;
                    continue;
                }
                // a run of equal values (bit for bit: a NaN, which equals nothing, is a
                // run of one)
                let start = x;
                x += 1;
                while x < w && !flags[x] && same_bits(value(x), value(start)) {
                    x += 1;
                }
                sink.write(&Instruction::eval0(
                    start as u32,
                    (x - start) as u32,
                    Intensity::new(value(start)),
                ))?;
                claims += 1;
            }
            if flags.iter().any(|&f| f) {
                regenerated += emit_row(&self.parts, row, sink)?.0;
            }
            sink.write(&Instruction::refresh())?;
        }
        let p = Phase::Antialias;
        Ok(Counters::default()
            .with("aa_claims", claims)
            .with(p.counter("instructions"), claims + regenerated + rows_count)
            .with(p.counter("regenerated"), regenerated))
    }
}
