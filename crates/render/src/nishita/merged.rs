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

use crate::error::scene_io;
use crate::phong::nearest_in;
use crate::prepare::PhongSurfaces;
use crate::renderer::{Counters, FramePlan};
use crate::span::{fit_span, SpanStats};
use cwisim_isa::{Instruction, Opcode, TraceWrite};
use cwisim_scene::{PackedPolygons, Polygon, ScreenScene};
use cwisim_ypipe::dofill::{box_slice_to, BoxValue, Procedure, RowOut, Shade};
use cwisim_ypipe::polygon_trapezia;
use cwisim_ypipe::scan::{edge_list, scan_slices_of, SliceVisit};
use cwisim_ypipe::Claim;
use std::io;
use std::ops::Range;

/// A frame's visible fragments, held until their rows are emitted: packed band by band
/// (each band's store made to its size: no store of the frame's size grows and is
/// copied), unpacked a few rows at a time; with each one's patch and pixel row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fragments {
    /// The fragments, band by band (no band empty).
    bands: Vec<PackedPolygons>,
    /// `ends[b]`: the fragments in bands `..= b`.
    ends: Vec<usize>,
    /// For each fragment: its patch (`mesh << 32 | patch`).
    pub groups: Vec<u64>,
    /// For each fragment: its pixel row (non-decreasing along the fragments when they
    /// come band by band and strip by strip; a fragment may reach one row either side,
    /// by rounding).
    pub rows: Vec<u32>,
}

impl Fragments {
    /// Fragments held.
    pub fn len(&self) -> usize {
        self.ends.last().copied().unwrap_or(0)
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends a band's fragments (their patches and rows are pushed to `groups` and
    /// `rows`).
    pub fn push_band(&mut self, mut band: PackedPolygons) {
        if band.is_empty() {
            return;
        }
        band.shrink_to_fit();
        self.ends.push(self.len() + band.len());
        self.bands.push(band);
    }

    /// Fragments `range`, unpacked (the part past the end left out).
    pub fn unpack(&self, range: Range<usize>) -> Vec<Polygon> {
        let mut out = Vec::new();
        self.unpack_into(range, &mut out);
        out
    }

    /// Fragments `range` unpacked into `out` (the part past the end left out), reusing
    /// the vectors of the polygons `out` holds ([`PackedPolygons::unpack_into`]).
    pub fn unpack_into(&self, range: Range<usize>, out: &mut Vec<Polygon>) {
        let mut filled = 0;
        let mut b = self.ends.partition_point(|&e| e <= range.start);
        while b < self.bands.len() {
            let first = if b == 0 { 0 } else { self.ends[b - 1] };
            if first >= range.end {
                break;
            }
            let local = range.start.max(first) - first..range.end.min(self.ends[b]) - first;
            filled += self.bands[b].unpack_into(local, out, filled);
            b += 1;
        }
        out.truncate(filled);
    }

    /// The bytes its vectors hold and do not use.
    pub fn spare_bytes(&self) -> usize {
        use std::mem::size_of;
        self.bands
            .iter()
            .map(PackedPolygons::spare_bytes)
            .sum::<usize>()
            + (self.bands.capacity() - self.bands.len()) * size_of::<PackedPolygons>()
            + (self.ends.capacity() - self.ends.len()) * size_of::<usize>()
            + (self.groups.capacity() - self.groups.len()) * size_of::<u64>()
            + (self.rows.capacity() - self.rows.len()) * size_of::<u32>()
    }

    /// Drops the spare capacity of its vectors.
    pub fn shrink_to_fit(&mut self) {
        self.bands.shrink_to_fit();
        self.ends.shrink_to_fit();
        self.groups.shrink_to_fit();
        self.rows.shrink_to_fit();
    }
}

/// One frame: the fragments, their patches and the rows each reaches; each few rows
/// unpack their own polygons and build their trapezia.
pub struct MergedFrame<'a> {
    /// The image's size and channels (its polygons are not read: `fragments` are).
    screen: &'a ScreenScene,
    fragments: &'a Fragments,
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
    /// The plan of `fragments` in an image of `screen`'s size and channels; Gouraud, or
    /// Phong lit from `phong`.
    pub fn new(
        screen: &'a ScreenScene,
        fragments: &'a Fragments,
        value: BoxValue,
        tolerance: f64,
        phong: Option<&'a PhongSurfaces>,
    ) -> MergedFrame<'a> {
        let rows = &fragments.rows[..];
        let ordered = rows.windows(2).all(|w| w[0] <= w[1]) && rows.len() == fragments.len();
        MergedFrame {
            screen,
            fragments,
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
        Counters::default().with("polygons", self.fragments.len() as u64)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let mut tally = Tally::default();
        // the row's slots, reused from row to row
        let mut slots: Vec<Slot> = Vec::new();
        // the chunk's fragments unpacked, their vectors reused from chunk to chunk
        let mut unpacked: Vec<Polygon> = Vec::new();
        // a few rows at a time (each row's stream does not depend on the split)
        let step = match self.rows {
            Some(_) => CHUNK_ROWS,
            None => rows.len().max(1) as u32,
        };
        let mut start = rows.start;
        while start < rows.end {
            let end = start.saturating_add(step).min(rows.end);
            self.emit_chunk(start..end, sink, &mut slots, &mut unpacked, &mut tally)?;
            start = end;
        }
        if let Some(surfaces) = &self.phong {
            surfaces.rows_done(rows);
        }
        Ok(counters(&tally))
    }
}

/// Rows emitted at a time: their fragments' trapezia are built for them alone.
const CHUNK_ROWS: u32 = 4;

impl MergedFrame<'_> {
    fn emit_chunk(
        &self,
        rows: Range<u32>,
        sink: &mut dyn TraceWrite,
        slots: &mut Vec<Slot>,
        unpacked: &mut Vec<Polygon>,
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
            None => 0..self.fragments.len(),
        };
        let base = polygons.start;
        self.fragments.unpack_into(polygons, unpacked);
        let trapezia = polygon_trapezia(unpacked, self.screen.width, self.screen.height, channels);
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
                    let group = self.fragments.groups[base + t.polygon as usize];
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
                                let shade = match surfaces.shade_pixel(
                                    base + t.polygon as usize,
                                    p,
                                    centre,
                                ) {
                                    Ok(s) => s.unwrap_or_default(),
                                    Err(e) => {
                                        result = Err(scene_io(e));
                                        return;
                                    }
                                };
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
                SliceVisit::EndOfRow(row) => {
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
                                })
                                .map_err(|e| crate::error::NonFinite::at_row(e, row));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A grey square of side 1 at `(x, 0)`.
    fn square(x: f64) -> Polygon {
        Polygon::uniform(
            vec![[x, 0.0], [x + 1.0, 0.0], [x + 1.0, 1.0], [x, 1.0]],
            &[x / 100.0],
        )
    }

    #[test]
    fn any_range_across_bands_unpacks_the_fragments_in_order() {
        let all: Vec<Polygon> = (0..10).map(|k| square(k as f64)).collect();
        // bands of 3, 0 (an empty band is not kept), 1, 4 and 2 fragments
        let mut fragments = Fragments::default();
        let mut next = 0;
        for n in [3, 0, 1, 4, 2] {
            let mut band = PackedPolygons::new(1);
            for p in &all[next..next + n] {
                band.push(p).unwrap();
            }
            next += n;
            fragments.push_band(band);
        }
        assert_eq!(fragments.len(), 10);
        assert_eq!(fragments.bands.len(), 4);
        for start in 0..=10 {
            for end in start..=12 {
                assert_eq!(
                    fragments.unpack(start..end),
                    all[start..end.min(10)].to_vec(),
                    "{start}..{end}"
                );
            }
        }
        assert!(Fragments::default().unpack(0..3).is_empty());
        // into a buffer, again and again: each time the range alone
        let mut buffer = Vec::new();
        for (start, end) in [(2, 9), (0, 3), (4, 12), (9, 10), (5, 5), (0, 10)] {
            fragments.unpack_into(start..end, &mut buffer);
            assert_eq!(buffer, all[start..end.min(10)].to_vec(), "{start}..{end}");
        }
    }
}
