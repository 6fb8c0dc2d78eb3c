//! A patch's row as one span: the visible fragments of one patch on one pixel row are
//! box-filtered exactly on the host (van Rij's DO_FILL for each of their trapezia, its
//! instructions added up here as the array would add them), and the row's values over
//! the patch are sent through the [span fitter](crate::span) as the fewest
//! `Eval1`/`Eval2`/`Eval3` pieces within a tolerance
//! ([`super::Nishita::span_tolerance`]) — not one instruction run
//! per piece. The pieces of a patch meet along their shared edges, where each side's
//! DO_FILL would send a single-pixel `Eval1`; summed first, those pixels join the span.
//!
//! Each value the array accumulates is within the tolerance of the exact box-filtered
//! value of the patch there (the fitter checks every piece with the array's own adder
//! chain), so a pixel that `m` patches reach is within `m ×` the tolerance of the exact
//! image; tolerance 0 sends every pixel's exact value (one `Eval1` per pixel).
//!
//! With Phong shading (`--shading phong`, box filter) each pixel of a fragment's row
//! adds its coverage × the Phong shade at the point of the fragment's source triangle
//! nearest the pixel centre, as [`crate::phong`] computes it per trapezium; the patch's
//! row is then fitted within `--shade-tolerance` itself.
//!
//! Rows are emitted in order, the patches of a row by mesh and patch number: the stream
//! is the same for any split of the rows into bands.

use crate::phong::nearest_in;
use crate::prepare::PhongSurfaces;
use crate::renderer::{Counters, FramePlan};
use crate::span::{fit_span, SpanStats};
use cwisim_isa::{Instruction, Opcode, TraceWrite};
use cwisim_scene::ScreenScene;
use cwisim_ypipe::dofill::{box_slice_to, BoxValue, Procedure, RowOut, Shade};
use cwisim_ypipe::polygon_trapezia;
use cwisim_ypipe::scan::{edge_list, scan_slices_of, SliceVisit};
use cwisim_ypipe::Claim;
use std::io;
use std::ops::Range;

/// One frame: the fragments, their patches and the rows each reaches; each band of
/// rows builds the trapezia of its own polygons.
pub struct MergedFrame<'a> {
    screen: &'a ScreenScene,
    /// For each polygon: its patch (`mesh << 32 | patch`).
    groups: &'a [u64],
    value: BoxValue,
    tolerance: f64,
    /// Phong: the triangles, each fragment's source, the lighting.
    phong: Option<&'a PhongSurfaces>,
    /// For each polygon: its pixel row (non-decreasing along the polygons, which come
    /// band by band and strip by strip; a fragment may reach one row either side, by
    /// rounding), or `None` when they are not ordered so (then every band takes every
    /// polygon).
    rows: Option<&'a [u32]>,
}

impl<'a> MergedFrame<'a> {
    /// The plan of `screen`, whose polygon `k` is part of patch `groups[k]` and lies in
    /// pixel row `rows[k]` (within rounding); Gouraud, or Phong lit from `phong`.
    pub fn new(
        screen: &'a ScreenScene,
        groups: &'a [u64],
        rows: &'a [u32],
        value: BoxValue,
        tolerance: f64,
        phong: Option<&'a PhongSurfaces>,
    ) -> MergedFrame<'a> {
        let ordered = rows.windows(2).all(|w| w[0] <= w[1]) && rows.len() == screen.polygons.len();
        MergedFrame {
            screen,
            groups,
            value,
            tolerance,
            phong,
            rows: ordered.then_some(rows),
        }
    }
}

/// One patch's values on the row being scanned.
struct Slot {
    group: u64,
    /// Pixel-major, `channels` values per pixel, the whole width.
    values: Vec<f64>,
    /// Pixels some instruction reached.
    touched: Vec<bool>,
    /// The range touched: `lo ..= hi`.
    lo: usize,
    hi: usize,
}

/// Adds DO_FILL's instructions into a slot, as the array's adder chain would (in
/// `f64`; a negative contribution dropped, as the array does without `Acc_mode`).
struct Adder<'s> {
    slot: &'s mut Slot,
    channels: usize,
    width: usize,
}

impl RowOut for Adder<'_> {
    fn put(&mut self, _proc: Procedure, instr: &Instruction) {
        let order = match instr.op {
            Opcode::Eval1 => 1,
            Opcode::Eval2 => 2,
            Opcode::Eval3 => 3,
            _ => return,
        };
        let ch = self.channels;
        let (x, n) = (instr.x as usize, instr.dx as usize);
        let end = (x + n).min(self.width);
        if end <= x {
            return;
        }
        let slot = &mut *self.slot;
        for c in 0..ch {
            let get = |s: usize| instr.value(s).get(c).copied().unwrap_or(0.0);
            let (mut v, mut d) = (get(0), if order >= 2 { get(1) } else { 0.0 });
            let dd = if order == 3 { get(2) } else { 0.0 };
            for p in x..end {
                if v >= 0.0 {
                    slot.values[p * ch + c] += v;
                }
                if order >= 2 {
                    v += d;
                }
                if order == 3 {
                    d += dd;
                }
            }
        }
        for t in &mut slot.touched[x..end] {
            *t = true;
        }
        slot.lo = slot.lo.min(x);
        slot.hi = slot.hi.max(end - 1);
    }
}

/// What a frame's rows did.
#[derive(Default)]
struct Tally {
    trapezia: u64,
    rows_filled: u64,
    spans: u64,
    fit: SpanStats,
    instructions: u64,
}

fn counters(t: &Tally) -> Counters {
    Counters::default()
        .with("trapezia", t.trapezia)
        .with("rows filled", t.rows_filled)
        .with("patch spans", t.spans)
        .with("pixels fitted", t.fit.pixels)
        .with("span Eval1", t.fit.eval1)
        .with("span Eval2", t.fit.eval2)
        .with("span Eval3", t.fit.eval3)
        .with("span candidates", t.fit.candidates)
        .with("instructions", t.instructions)
}

impl FramePlan for MergedFrame<'_> {
    fn counters(&self) -> Counters {
        Counters::default().with("polygons", self.screen.polygons.len() as u64)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let mut tally = Tally::default();
        // the row's slots, reused from row to row
        let mut slots: Vec<Slot> = Vec::new();
        // a few rows at a time (each row's stream does not depend on the split)
        let step = match self.rows {
            Some(_) => CHUNK_ROWS,
            None => rows.len().max(1) as u32,
        };
        let mut start = rows.start;
        while start < rows.end {
            let end = start.saturating_add(step).min(rows.end);
            self.emit_chunk(start..end, sink, &mut slots, &mut tally)?;
            start = end;
        }
        Ok(counters(&tally))
    }
}

/// Rows emitted at a time: their fragments' trapezia are built for them alone.
const CHUNK_ROWS: u32 = 8;

impl MergedFrame<'_> {
    fn emit_chunk(
        &self,
        rows: Range<u32>,
        sink: &mut dyn TraceWrite,
        slots: &mut Vec<Slot>,
        tally: &mut Tally,
    ) -> io::Result<()> {
        let channels = self.screen.channel_count();
        let width = self.screen.width as usize;
        let mut result = Ok(());
        // the active slots: the first `active`
        let mut active = 0;
        // the trapezia of the polygons reaching these rows only (a fragment's vertices
        // may stray from its strip by rounding: one row either side): memory bounded by the
        // band, not the frame (a polygon keeps its order among them, so a row's
        // trapezia are visited as they would be among the frame's)
        let polygons = match &self.rows {
            Some(r) => {
                let (start, end) = (i64::from(rows.start), i64::from(rows.end));
                let first = r.partition_point(|&row| i64::from(row) + 1 < start);
                let last = r.partition_point(|&row| i64::from(row) - 1 < end);
                first..last.max(first)
            }
            None => 0..self.screen.polygons.len(),
        };
        let base = polygons.start;
        let trapezia = polygon_trapezia(
            &self.screen.polygons[polygons],
            self.screen.width,
            self.screen.height,
            channels,
        );
        let edges = edge_list(&trapezia, channels);
        // each trapezium counted once, in the chunk of its fragment's own row
        tally.trapezia += match &self.rows {
            Some(r) => trapezia
                .iter()
                .filter(|t| {
                    let row = i64::from(r[base + t.polygon as usize]);
                    (i64::from(rows.start)..i64::from(rows.end)).contains(&row)
                })
                .count() as u64,
            None => trapezia.len() as u64,
        };
        scan_slices_of(&trapezia, &edges, rows, |visit| {
            if result.is_err() {
                return;
            }
            match visit {
                SliceVisit::Fill(slice, t) => {
                    let group = self.groups[base + t.polygon as usize];
                    let k = match slots[..active].iter().position(|s| s.group == group) {
                        Some(k) => k,
                        None => {
                            if active == slots.len() {
                                slots.push(Slot {
                                    group,
                                    values: vec![0.0; width * channels],
                                    touched: vec![false; width],
                                    lo: usize::MAX,
                                    hi: 0,
                                });
                            }
                            let s = &mut slots[active];
                            s.group = group;
                            s.lo = usize::MAX;
                            s.hi = 0;
                            active += 1;
                            active - 1
                        }
                    };
                    match self.phong {
                        None => {
                            let mut adder = Adder {
                                slot: &mut slots[k],
                                channels,
                                width,
                            };
                            box_slice_to(
                                t,
                                slice,
                                self.screen.width,
                                &Shade::Gouraud,
                                channels,
                                Claim::Accumulate,
                                self.value,
                                None,
                                &mut adder,
                            );
                        }
                        Some(surfaces) => {
                            let triangle =
                                &surfaces.triangles[surfaces.sources[base + t.polygon as usize]];
                            let slot = &mut slots[k];
                            let (l0, _, _, r1) = slice.edge_pixels();
                            let (first, last) = (l0.max(0), r1.min(width as i64 - 1));
                            for i in first..=last {
                                let c = slice.coverage(i);
                                if c == 0.0 {
                                    continue;
                                }
                                let centre = [i as f64 + 0.5, f64::from(slice.row) + 0.5];
                                let p = nearest_in(triangle, centre);
                                let shade = surfaces
                                    .shade_pixel(base + t.polygon as usize, p, centre)
                                    .unwrap_or_default();
                                let i = i as usize;
                                for (v, s) in slot.values[i * channels..(i + 1) * channels]
                                    .iter_mut()
                                    .zip(&shade[..channels])
                                {
                                    *v += c * s.max(0.0);
                                }
                                slot.touched[i] = true;
                                slot.lo = slot.lo.min(i);
                                slot.hi = slot.hi.max(i);
                            }
                        }
                    }
                    tally.rows_filled += 1;
                }
                SliceVisit::EndOfRow(_) => {
                    slots[..active].sort_by_key(|s| s.group);
                    for s in &mut slots[..active] {
                        if s.lo > s.hi {
                            continue;
                        }
                        let mut p = s.lo;
                        while p <= s.hi && result.is_ok() {
                            if !s.touched[p] {
                                p += 1;
                                continue;
                            }
                            let q = p + s.touched[p..=s.hi].iter().take_while(|&&t| t).count();
                            let targets = &s.values[p * channels..q * channels];
                            result = fit_span(p as u32, targets, channels, self.tolerance, sink)
                                .map(|f| {
                                    tally.instructions += f.pieces();
                                    tally.fit.add(&f);
                                    tally.spans += 1;
                                });
                            p = q;
                        }
                        s.values[s.lo * channels..(s.hi + 1) * channels].fill(0.0);
                        s.touched[s.lo..=s.hi].fill(false);
                    }
                    active = 0;
                    if result.is_ok() {
                        tally.instructions += 1;
                        result = sink.write(&Instruction::refresh());
                    }
                }
            }
        });
        result
    }
}
