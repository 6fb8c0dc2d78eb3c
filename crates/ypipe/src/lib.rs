//! # cwisim-ypipe — the Y-processor
//!
//! The host side of the CWI architecture that turns polygons into the scanline commands
//! of the X-processor array, as van Rij's report (CS-R9427, sections 2–3, appendix A)
//! describes:
//!
//! 1. `cwisim_scene` — screen-space scenes (JSON): polygons with per-vertex intensities.
//! 2. [`clip`] — polygons are clipped exactly to the image.
//! 3. [`trapezoid`] — each polygon becomes trapezia with horizontal top and bottom.
//! 4. [`scan`] — an edge list and an active edge table grouped by Identifier visit the
//!    trapezia row by row (Algorithms 7–8).
//! 5. [`dofill`] — each row of a trapezium becomes instructions: box-filter coverage in
//!    the twelve cases of DO_FILL ([`coverage`]), each pixel holding the exact integral
//!    of its intensity ([`integral`]) or the report's coverage × centre value; or point
//!    sampling; flat or Gouraud; optionally claiming fully covered pixels with `Eval0`
//!    ([`Claim`]).
//! 6. [`emit`](fn@emit) — the stream goes to any [`TraceWrite`] (a trace file, the
//!    array simulator, a counter), one `Refresh` per scanline.
//!
//! [`exact`] is the independent exact reference (area and box-filtered intensity of
//! polygon ∩ pixel) that the emitted streams are checked against.
//!
//! Where the project departs from the report, and why: `docs/ERRATA.md`.

#![warn(missing_docs)]

pub mod clip;
pub mod coverage;
pub mod dofill;
pub mod exact;
mod floor;
pub mod integral;
pub mod scan;
#[cfg(test)]
mod test_rng;
pub mod trapezoid;

use crate::dofill::{
    box_row_into, box_slice_to, sampled_row_into, BoxValue, Procedure, RowFill, RowOut, Shade,
};
use cwisim_isa::{Instruction, TraceHeader, TraceWrite, MAX_CHANNELS};
use cwisim_scene::ScreenScene;
use std::io;
use trapezoid::Vector;

pub use cwisim_scene::{Antialias, Shading};

/// What a polygon does to the pixels it fully covers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Claim {
    /// Accumulate, like every other pixel (the default).
    #[default]
    Accumulate,
    /// Claim them with Eval0 so that later (farther) polygons no longer accumulate there.
    /// With Gouraud shading the claimed run is a staircase of Eval0s, each holding the
    /// intensity at its centre, as long as the staircase stays within `tolerance` of the
    /// Gouraud value at every pixel centre.
    Eval0 {
        /// The largest difference allowed, per channel, between a claimed pixel's value
        /// and the Gouraud intensity at its centre (0: one `Eval0` per pixel).
        tolerance: f64,
    },
}

/// How to scan-convert.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Options {
    /// Shading.
    pub shading: Shading,
    /// Anti-aliasing: `Box` the exact box filter, `BoxCentre` the report's (coverage ×
    /// the intensity at the pixel centre), `None` point sampling.
    pub aa: Antialias,
    /// What a polygon does to the pixels it fully covers: with box filtering the runs of
    /// coverage exactly 1, with point sampling its whole span (`docs/ERRATA.md`, D9).
    pub claim: Claim,
}

/// What an emission did.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct EmitStats {
    /// Polygons in the scene.
    pub polygons: u64,
    /// Trapezia they became (after clipping).
    pub trapezia: u64,
    /// Trapezium rows filled.
    pub rows_filled: u64,
    /// Rows of each DO_FILL case, `cases[k]` for case `k + 1` (box filter only).
    pub cases: [u64; 12],
    /// Separately calculated pixels.
    pub single_pixels: u64,
    /// Middle-part stretches.
    pub middle_parts: u64,
    /// Sequence stretches.
    pub sequences: u64,
    /// Share-sequence stretches.
    pub share_sequences: u64,
    /// `Eval0` instructions claiming fully covered pixels ([`Claim::Eval0`]).
    pub claims: u64,
    /// Instructions emitted, `Refresh` included.
    pub instructions: u64,
}

/// The trace header for a scene: the image width, its height as the lines per frame.
pub fn header(scene: &ScreenScene) -> TraceHeader {
    TraceHeader::new(scene.width, scene.height, scene.channels)
        .expect("a validated scene fits a trace header")
}

/// The trapezia of a scene's polygons after clipping to the image, numbered 1, 2, … in
/// polygon order (the report's Identifier).
pub fn scene_trapezia(scene: &ScreenScene) -> Vec<trapezoid::Trapezium> {
    polygon_trapezia(
        &scene.polygons,
        scene.width,
        scene.height,
        usize::from(scene.channels),
    )
}

/// [`scene_trapezia`] of some of a scene's polygons (`polygons`, of an image
/// `width × height` with `channels` channels), numbered from 1 among them.
pub fn polygon_trapezia(
    polygons: &[cwisim_scene::Polygon],
    width: u32,
    height: u32,
    channels: usize,
) -> Vec<trapezoid::Trapezium> {
    let mut out = Vec::new();
    for (k, p) in polygons.iter().enumerate() {
        let first = out.len() as u32 + 1;
        out.extend(clipped_trapezia(
            p, k as u32, width, height, channels, first,
        ));
    }
    out
}

/// The trapezia of polygon `p` (index `k`) clipped to the image `width × height`,
/// numbered from `first`: none where nothing of it is inside.
fn clipped_trapezia(
    p: &cwisim_scene::Polygon,
    k: u32,
    width: u32,
    height: u32,
    channels: usize,
    first: u32,
) -> Vec<trapezoid::Trapezium> {
    let (w, h) = (f64::from(width), f64::from(height));
    let clipped = clip::clip_to_rect_cow(p, 0.0, 0.0, w, h);
    if clipped.vertices.len() < 3 {
        return Vec::new();
    }
    trapezoid::trapezia(&clipped, k, channels, first)
}

fn flat_intensity(p: &cwisim_scene::Polygon, channels: usize) -> [f64; MAX_CHANNELS] {
    flat_mean(&p.intensity, channels)
}

/// A flat-shaded polygon's one intensity: the mean of its vertex intensities, per
/// channel, taken as the first value plus the mean difference from it, so that a polygon
/// whose vertices agree (a lit face) keeps their value exactly. Every renderer that
/// shades flat takes it from here, so that their flat images agree to the bit.
pub fn flat_mean<V: AsRef<[f64]>>(intensity: &[V], channels: usize) -> [f64; MAX_CHANNELS] {
    let n = intensity.len().max(1) as f64;
    trapezoid::vector(channels, |c| match intensity.first() {
        Some(first) => {
            let first = first.as_ref()[c];
            first + intensity.iter().map(|v| v.as_ref()[c] - first).sum::<f64>() / n
        }
        None => 0.0,
    })
}

/// A scene made ready to scan-convert: its trapezia (clipped, numbered) and each
/// polygon's shading. Built once by [`ScanPlan::new`]; [`emit_rows`] then emits any band
/// of rows from it, so that bands can be emitted independently (in parallel) and their
/// streams concatenated into exactly [`emit`]'s.
#[derive(Clone, Debug)]
pub struct ScanPlan<'s> {
    scene: &'s ScreenScene,
    trapezia: PlannedTrapezia,
    /// Each polygon's one intensity, when the scene is shaded flat (Gouraud needs none).
    flat: Option<Vec<Vector>>,
}

/// A scene with more polygons than this has its trapezia made band by band
/// ([`ScanPlan::by_bands`]), not for the frame at once: 184 bytes a trapezium and 48
/// for its two edges in the list, which at 262,144 triangles of a mesh (122,934 visible
/// fragments, 247,613 trapezia) were 60 MB, the command's peak.
pub const BANDED_FROM_POLYGONS: usize = 1 << 16;

/// Where a plan's trapezia are.
#[derive(Clone, Debug)]
enum PlannedTrapezia {
    /// The frame's, made once, and their edge list, sorted (shared by every band).
    Whole {
        trapezia: Vec<trapezoid::Trapezium>,
        edges: scan::EdgeList,
    },
    /// Made band by band, from the polygons that reach the band.
    Banded(PolygonRows),
}

/// What making a band's trapezia needs: each polygon's first Identifier (the trapezia
/// are numbered in polygon order over the frame, as [`scene_trapezia`] numbers them) and
/// the pixel rows its trapezia touch, the polygons in order of their first row.
#[derive(Clone, Debug)]
struct PolygonRows {
    /// `first_id[k]`: the Identifier of polygon `k`'s first trapezium (of the next
    /// polygon's, where it has none).
    first_id: Vec<u32>,
    /// `(first row, last row, polygon)` of each polygon with a trapezium, sorted (rows
    /// of the image: the trapezia are clipped to it).
    by_top: Vec<(u32, u32, u32)>,
    /// The frame's trapezia.
    total: u64,
}

impl PolygonRows {
    fn new(scene: &ScreenScene) -> PolygonRows {
        let channels = usize::from(scene.channels);
        let mut first_id = Vec::with_capacity(scene.polygons.len());
        let mut by_top = Vec::with_capacity(scene.polygons.len());
        let mut next = 1u32;
        for (k, p) in scene.polygons.iter().enumerate() {
            first_id.push(next);
            let made = clipped_trapezia(p, k as u32, scene.width, scene.height, channels, next);
            if let Some(rows) = made
                .iter()
                .map(|t| scan::pixel_rows(t.y_top, t.y_bot))
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
            {
                // rows of the image (a clipped trapezium's), so the clamp changes none
                let row = |r: i64| u32::try_from(r.max(0)).unwrap_or(u32::MAX);
                by_top.push((row(rows.0), row(rows.1), k as u32));
            }
            next += made.len() as u32;
        }
        by_top.sort_unstable();
        PolygonRows {
            first_id,
            by_top,
            total: u64::from(next - 1),
        }
    }

    /// The trapezia that touch pixel rows `rows`, numbered as over the frame, in the
    /// frame's order.
    fn band(&self, scene: &ScreenScene, rows: &std::ops::Range<u32>) -> Vec<trapezoid::Trapezium> {
        let (start, end) = (rows.start, rows.end);
        let reach = self.by_top.partition_point(|&(top, _, _)| top < end);
        let mut polygons: Vec<u32> = self.by_top[..reach]
            .iter()
            .filter(|&&(_, bottom, _)| bottom >= start)
            .map(|&(_, _, k)| k)
            .collect();
        polygons.sort_unstable();
        let channels = usize::from(scene.channels);
        let mut out = Vec::new();
        for k in polygons {
            let (p, first) = (&scene.polygons[k as usize], self.first_id[k as usize]);
            out.extend(
                clipped_trapezia(p, k, scene.width, scene.height, channels, first)
                    .into_iter()
                    .filter(|t| {
                        let (top, bottom) = scan::pixel_rows(t.y_top, t.y_bot);
                        top < i64::from(end) && bottom >= i64::from(start)
                    }),
            );
        }
        out
    }
}

impl<'s> ScanPlan<'s> {
    /// The plan of `scene` under `options`: its trapezia made for the frame at once, or,
    /// past [`BANDED_FROM_POLYGONS`] polygons, band by band ([`ScanPlan::by_bands`]).
    /// Either way the same stream.
    pub fn new(scene: &'s ScreenScene, options: &Options) -> ScanPlan<'s> {
        if scene.polygons.len() > BANDED_FROM_POLYGONS {
            return ScanPlan::by_bands(scene, options);
        }
        let channels = usize::from(scene.channels);
        let trapezia = scene_trapezia(scene);
        ScanPlan {
            scene,
            trapezia: PlannedTrapezia::Whole {
                edges: scan::edge_list(&trapezia, channels),
                trapezia,
            },
            flat: flat_intensities(scene, options),
        }
    }

    /// The plan of `scene` under `options` whose trapezia are made band by band, each
    /// band's from the polygons that reach it, when [`emit_rows`] emits it: memory
    /// bounded by the bands being emitted, not by the frame, for what a polygon reaching
    /// several bands costs (it is cut into trapezia in each). The same stream as
    /// [`ScanPlan::new`]'s for the frame's trapezia at once, bit for bit.
    pub fn by_bands(scene: &'s ScreenScene, options: &Options) -> ScanPlan<'s> {
        ScanPlan {
            scene,
            trapezia: PlannedTrapezia::Banded(PolygonRows::new(scene)),
            flat: flat_intensities(scene, options),
        }
    }

    /// The statistics that belong to the whole scene, not to a band: polygons and
    /// trapezia.
    pub fn scene_stats(&self) -> EmitStats {
        EmitStats {
            polygons: self.scene.polygons.len() as u64,
            trapezia: match &self.trapezia {
                PlannedTrapezia::Whole { trapezia, .. } => trapezia.len() as u64,
                PlannedTrapezia::Banded(rows) => rows.total,
            },
            ..EmitStats::default()
        }
    }

    /// How polygon `k` is shaded.
    fn shade(&self, k: u32) -> Shade {
        match &self.flat {
            Some(flat) => Shade::Flat(flat[k as usize]),
            None => Shade::Gouraud,
        }
    }
}

/// Each polygon's one intensity, when `options` shade flat.
fn flat_intensities(scene: &ScreenScene, options: &Options) -> Option<Vec<Vector>> {
    let channels = usize::from(scene.channels);
    match options.shading {
        Shading::Flat => Some(
            scene
                .polygons
                .iter()
                .map(|p| flat_intensity(p, channels))
                .collect(),
        ),
        // Phong needs 3D normals per pixel, which screen polygons do not carry:
        // `cwisim-render` draws it with its own emitter; here it is drawn as Gouraud,
        // from the vertex intensities (hidden-line drawing is refused before a scene
        // gets here: renderers that resolve visibility per sample draw it)
        Shading::Gouraud | Shading::Phong | Shading::Hidden => None,
    }
}

impl EmitStats {
    /// Counts one instruction of DO_FILL made by `proc_`.
    fn count(&mut self, proc_: Procedure) {
        match proc_ {
            Procedure::Single => self.single_pixels += 1,
            Procedure::MiddlePart => self.middle_parts += 1,
            Procedure::Sequence => self.sequences += 1,
            Procedure::ShareSequence => self.share_sequences += 1,
            Procedure::Claim => self.claims += 1,
        }
        self.instructions += 1;
    }

    /// Adds a band's counts (everything but `polygons` and `trapezia`, which
    /// [`ScanPlan::scene_stats`] gives once).
    pub fn add_band(&mut self, band: &EmitStats) {
        self.rows_filled += band.rows_filled;
        for (a, b) in self.cases.iter_mut().zip(&band.cases) {
            *a += b;
        }
        self.single_pixels += band.single_pixels;
        self.middle_parts += band.middle_parts;
        self.sequences += band.sequences;
        self.share_sequences += band.share_sequences;
        self.claims += band.claims;
        self.instructions += band.instructions;
    }
}

/// A row's instructions straight into a sink, counted; the first error is kept and
/// nothing is written after it.
struct Direct<'a> {
    sink: &'a mut dyn TraceWrite,
    stats: &'a mut EmitStats,
    /// Instructions put in this row.
    put: u64,
    result: io::Result<()>,
}

impl RowOut for Direct<'_> {
    fn put(&mut self, proc_: Procedure, instr: &Instruction) {
        if self.result.is_ok() {
            self.stats.count(proc_);
            self.put += 1;
            self.result = self.sink.write(instr);
        }
    }
}

/// Scan-converts a scene into `sink`: every scanline's instructions, then its `Refresh`
/// (one per image row, empty rows included). Text sinks also get a comment per
/// trapezium row naming its DO_FILL case and stretches.
pub fn emit(
    scene: &ScreenScene,
    options: &Options,
    sink: &mut dyn TraceWrite,
) -> io::Result<EmitStats> {
    let plan = ScanPlan::new(scene, options);
    let mut stats = plan.scene_stats();
    stats.add_band(&emit_rows(&plan, options, 0..scene.height, sink)?);
    Ok(stats)
}

/// The pixel rows `rows` of [`emit`]'s stream, each ending with its `Refresh`. The
/// statistics count this band only (`polygons` and `trapezia` are 0: see
/// [`ScanPlan::scene_stats`]).
pub fn emit_rows(
    plan: &ScanPlan<'_>,
    options: &Options,
    rows: std::ops::Range<u32>,
    sink: &mut dyn TraceWrite,
) -> io::Result<EmitStats> {
    let scene = plan.scene;
    let channels = usize::from(scene.channels);
    // the band's own trapezia and edge list, where the plan makes them band by band
    let band;
    let (trapezia, edges) = match &plan.trapezia {
        PlannedTrapezia::Whole { trapezia, edges } => (trapezia, edges),
        PlannedTrapezia::Banded(polygons) => {
            let trapezia = polygons.band(scene, &rows);
            band = (scan::edge_list(&trapezia, channels), trapezia);
            (&band.1, &band.0)
        }
    };
    let mut stats = EmitStats::default();
    let mut result = Ok(());
    let notes = sink.wants_comments();
    let mut fill = RowFill::default();
    scan::scan_slices_of(trapezia, edges, rows, |visit| {
        if result.is_err() {
            return;
        }
        match visit {
            scan::SliceVisit::Fill(slice, t) => {
                let row = slice.row;
                let shade = &plan.shade(t.polygon);
                let (w, claim) = (scene.width, options.claim);
                let value = match options.aa {
                    Antialias::Box => Some(BoxValue::Exact),
                    Antialias::BoxCentre => Some(BoxValue::Centre),
                    Antialias::None => None,
                };
                if let (Some(value), false) = (value, notes) {
                    // no note to write first: straight into the sink
                    let mut direct = Direct {
                        sink: &mut *sink,
                        stats: &mut stats,
                        put: 0,
                        result: Ok(()),
                    };
                    let case = box_slice_to(
                        t,
                        slice,
                        w,
                        shade,
                        channels,
                        claim,
                        value,
                        None,
                        &mut direct,
                    );
                    let put = direct.put;
                    result = direct.result;
                    if put > 0 {
                        stats.rows_filled += 1;
                        stats.cases[usize::from(case.0) - 1] += 1;
                    }
                    return;
                }
                let filled = match value {
                    Some(value) => {
                        box_row_into(t, row, w, shade, channels, claim, value, notes, &mut fill)
                    }
                    None => sampled_row_into(t, row, w, shade, channels, claim, notes, &mut fill),
                };
                if !filled {
                    return;
                }
                stats.rows_filled += 1;
                if let Some(case) = fill.case {
                    stats.cases[usize::from(case.0) - 1] += 1;
                }
                let commented = if notes {
                    sink.comment(&fill.note)
                } else {
                    Ok(())
                };
                result = commented.and_then(|()| {
                    for (proc_, instr) in &fill.instructions {
                        stats.count(*proc_);
                        sink.write(instr)?;
                    }
                    Ok(())
                });
            }
            scan::SliceVisit::EndOfRow(_) => {
                stats.instructions += 1;
                result = sink.write(&Instruction::refresh());
            }
        }
    });
    result?;
    Ok(stats)
}
