//! A phase's frame of instructions. Every row is the display list's polygons, in parts
//! (those kept as the previous frame drew them, then those the phase regenerates), each
//! part scanned on its own with its `Refresh` held back, and one `Refresh` to end the row.
//! The anti-aliasing frame re-sends the previous frame's instructions with its flagged
//! pixels masked (`Dis`), then the box filter with the others masked.

use super::display::Subset;
use super::Phase;
use crate::phong::PhongFrame;
use crate::renderer::{Counters, FramePlan};
use cwisim_isa::{Instruction, Opcode, TraceWrite};
use cwisim_scene::{Antialias, Shading};
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
        for (screen, surfaces) in subset.textured.iter().chain(&subset.phong) {
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

/// A sink that lets the Evals of one row write only where `writes` (the row's pixels) is
/// true: before an Eval whose span reaches a pixel it must not write, one `Dis` per run
/// of such pixels in the span. `Dis` lasts until the next Eval, so each mask holds for
/// exactly the Eval after it; the wave still passes through a masked processor and picks
/// up its preloads (docs/ISA.md), so every unmasked pixel gets bit for bit what the
/// stream alone gives it. An Eval that would write nothing is dropped, as long as nothing
/// but Evals (and `Acc_mode`, `Nop`) has come before it in the row: then no preload or
/// mask is pending that its wave would have consumed or cleared.
struct Masked<'s> {
    inner: &'s mut dyn TraceWrite,
    writes: &'s [bool],
    /// Whether an Eval that writes nothing may still be dropped.
    may_drop: bool,
    written: u64,
    masks: u64,
}

impl TraceWrite for Masked<'_> {
    fn write(&mut self, i: &Instruction) -> io::Result<()> {
        match i.op {
            Opcode::Eval0 | Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3 => {
                let (a, b) = i.span().map_or((0, 0), |(a, b)| (a as usize, b as usize));
                let span = &self.writes[a..b];
                if self.may_drop && !span.contains(&true) {
                    return Ok(());
                }
                let mut x = 0;
                while x < span.len() {
                    if span[x] {
                        x += 1;
                        continue;
                    }
                    let start = x;
                    while x < span.len() && !span[x] {
                        x += 1;
                    }
                    self.inner
                        .write(&Instruction::dis((a + start) as u32, (x - start) as u32))?;
                    self.masks += 1;
                }
            }
            Opcode::AccMode | Opcode::Nop | Opcode::Refresh => {}
            _ => self.may_drop = false,
        }
        self.written += 1;
        self.inner.write(i)
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Writes `row` of `parts` without their `Refresh`, masked to the pixels of `writes`:
/// `(instructions, masks)`, the masks not among the instructions.
fn emit_masked_row(
    parts: &[Part],
    row: u32,
    writes: &[bool],
    sink: &mut dyn TraceWrite,
) -> io::Result<(u64, u64)> {
    let mut masked = Masked {
        inner: sink,
        writes,
        may_drop: true,
        written: 0,
        masks: 0,
    };
    emit_row(parts, row, &mut masked)?;
    Ok((masked.written, masked.masks))
}

/// The anti-aliasing frame, per row: the previous frame's own instructions with its
/// flagged pixels masked (so the others come out bit for bit as before), then — in rows
/// with a flagged pixel — the box filter of the whole display list with the unflagged
/// pixels masked. A row with no flagged pixel is the previous frame's row; a row with
/// every pixel flagged is the box filter's.
pub struct Antialiased<'a> {
    /// The display list, box-filtered.
    pub parts: Vec<Part<'a>>,
    /// The previous frame's parts (point-sampled), in the order it sent them.
    pub previous_parts: Vec<Part<'a>>,
    /// The pixels to filter, row-major.
    pub flags: Vec<bool>,
    /// Pixel columns.
    pub width: usize,
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
        let w = self.width;
        // instructions re-sent from the previous frame and regenerated, each with its masks
        let (mut kept, mut regenerated, mut masks) = (0u64, 0u64, 0u64);
        let mut rows_count = 0u64;
        let mut keep = vec![false; w];
        for row in rows {
            rows_count += 1;
            let r = row as usize;
            let flags = &self.flags[r * w..(r + 1) * w];
            for (k, &f) in keep.iter_mut().zip(flags) {
                *k = !f;
            }
            if keep.iter().any(|&k| k) {
                let (n, m) = emit_masked_row(&self.previous_parts, row, &keep, sink)?;
                kept += n + m;
                masks += m;
            }
            if flags.iter().any(|&f| f) {
                let (n, m) = emit_masked_row(&self.parts, row, flags, sink)?;
                regenerated += n + m;
                masks += m;
            }
            sink.write(&Instruction::refresh())?;
        }
        let p = Phase::Antialias;
        Ok(Counters::default()
            .with("aa_masks", masks)
            .with(p.counter("instructions"), kept + regenerated + rows_count)
            .with(p.counter("regenerated"), regenerated))
    }
}
