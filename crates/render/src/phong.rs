//! Phong shading through the array: van Rij's trapezia and coverage, with every pixel lit
//! on the host and the row sent through the [span fitter](crate::span).
//!
//! For each trapezium row (the exact visible fragments of a world scene, split into
//! trapezia and scanned with the active edge table as DO_FILL does), every pixel the row
//! reaches gets a target: its **coverage × the Phong intensity at its sample point**.
//!
//! * With the box filter the coverage is the exact covered area of the pixel (DO_FILL's
//!   coverage), and the sample point is the pixel centre, or, when the centre lies
//!   outside the fragment's **source triangle**, the point of that triangle nearest to
//!   it: the surface's own shade beside the pixel, never an extrapolation past the
//!   triangle. A pixel covered by one triangle (in one fragment or several, in any number
//!   of trapezia) so holds exactly the per-pixel Phong value at its centre; an edge pixel
//!   holds, for each triangle that covers part of it, the covered area times that
//!   triangle's shade at the point nearest the centre (the report's Gouraud box filter
//!   does the same with the centre's Gouraud value: `docs/ERRATA.md`). `--aa box` and
//!   `--aa box-centre` are the same here: unlike the Gouraud function, the Phong shade
//!   is not affine, and no instruction carries its exact integral over a pixel.
//! * With point sampling the pixels are those whose centre lies in the row (the rule
//!   every emitter shares, `cwisim_ypipe::dofill::sampled_span`), coverage 1.
//!
//! The intensity is `cwisim_world::shade::PhongShader`'s: the world point and the normal
//! interpolated perspective-correctly over the fragment's source triangle and lit by the
//! report's formula. The targets of a row go to [`fit_span`](crate::span::fit_span) with
//! the settings' `shade_tolerance`: long `Eval3` pieces over smooth interiors, short ones
//! at edges; tolerance 0 is one `Eval1` per pixel. Each piece is within the tolerance of
//! its targets, so a pixel that `m` pieces reach (its trapezia, where fragments meet) is
//! within `m ×` the tolerance of its tolerance-0 value.

use crate::error::{scene_io, NonFinite};
use crate::prepare::PhongSurfaces;
use crate::renderer::{Counters, FramePlan};
use crate::span::{fit_span, SpanStats};
use cwisim_isa::{Instruction, TraceWrite};
use cwisim_scene::{Antialias, ScreenScene};
use cwisim_world::face::ScreenTriangle;
use cwisim_ypipe::coverage::Slice;
use cwisim_ypipe::dofill::sampled_span;
use cwisim_ypipe::scan::{edge_list, scan_rows_of, EdgeList, Visit};
use cwisim_ypipe::scene_trapezia;
use cwisim_ypipe::trapezoid::Trapezium;
use std::io;
use std::ops::Range;

/// One frame of Phong shading: the trapezia and their edge list, built once.
pub struct PhongFrame<'a> {
    screen: &'a ScreenScene,
    surfaces: &'a PhongSurfaces,
    aa: Antialias,
    tolerance: f64,
    trapezia: Vec<Trapezium>,
    edges: EdgeList,
}

impl<'a> PhongFrame<'a> {
    /// The plan of `screen`'s fragments, lit from `surfaces`.
    pub fn new(
        screen: &'a ScreenScene,
        surfaces: &'a PhongSurfaces,
        aa: Antialias,
        tolerance: f64,
    ) -> PhongFrame<'a> {
        let trapezia = scene_trapezia(screen);
        PhongFrame {
            screen,
            surfaces,
            aa,
            tolerance,
            edges: edge_list(&trapezia, screen.channel_count()),
            trapezia,
        }
    }

    /// The pixels of `t` in `row` and their coverage: `(first pixel, coverages)`.
    fn row_pixels(&self, t: &Trapezium, row: u32, coverage: &mut Vec<f64>) -> Option<i64> {
        coverage.clear();
        let width = i64::from(self.screen.width);
        match self.aa {
            // Phong's box filter is coverage × the shade at the centre either way
            Antialias::Box | Antialias::BoxCentre => {
                let slice = Slice::of(t, row)?;
                let (l0, _, _, r1) = slice.edge_pixels();
                let (first, last) = (l0.max(0), r1.min(width - 1));
                if last < first {
                    return None;
                }
                coverage.extend((first..=last).map(|i| slice.coverage(i)));
                // trim pixels the row does not reach
                while coverage.last() == Some(&0.0) {
                    coverage.pop();
                }
                let lead = coverage.iter().take_while(|&&c| c == 0.0).count();
                coverage.drain(..lead);
                (!coverage.is_empty()).then_some(first + lead as i64)
            }
            Antialias::None => {
                let (first, end) = sampled_span(t, row, self.screen.width)?;
                coverage.resize((end - first) as usize, 1.0);
                Some(first)
            }
        }
    }
}

/// The point of triangle `t` (on the screen) nearest to `p`: `p` itself when inside,
/// else the nearest point of its edges.
pub fn nearest_in(t: &ScreenTriangle, p: [f64; 2]) -> [f64; 2] {
    if t.barycentric(p)
        .is_some_and(|b| b.iter().all(|&w| w >= 0.0))
    {
        return p;
    }
    let mut best = (f64::INFINITY, p);
    for k in 0..3 {
        let (a, b) = (t.points[k], t.points[(k + 1) % 3]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let s = if len2 > 0.0 {
            (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + s * dx, a[1] + s * dy];
        let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
        if d2 < best.0 {
            best = (d2, q);
        }
    }
    best.1
}

fn counters(rows: u64, s: &SpanStats, instructions: u64) -> Counters {
    Counters::default()
        .with("rows_filled", rows)
        .with("pixels_shaded", s.pixels)
        .with("pieces", s.pieces())
        .with("eval1_pieces", s.eval1)
        .with("eval2_pieces", s.eval2)
        .with("eval3_pieces", s.eval3)
        .with("fit_candidates", s.candidates)
        .with("instructions", instructions)
}

impl FramePlan for PhongFrame<'_> {
    fn counters(&self) -> Counters {
        Counters::default()
            .with("polygons", self.screen.polygons.len() as u64)
            .with("trapezia", self.trapezia.len() as u64)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let channels = self.screen.channel_count();
        let rows_done = rows.clone();
        let mut stats = SpanStats::default();
        let (mut filled, mut instructions) = (0u64, 0u64);
        let mut result = Ok(());
        let mut coverage = Vec::new();
        let mut targets = Vec::new();
        scan_rows_of(&self.trapezia, &self.edges, rows, channels, |visit| {
            if result.is_err() {
                return;
            }
            match visit {
                Visit::Fill(row, t) => {
                    let Some(first) = self.row_pixels(t, row, &mut coverage) else {
                        return;
                    };
                    let source = self.surfaces.sources[t.polygon as usize];
                    let triangle = &self.surfaces.triangles[source];
                    targets.clear();
                    for (k, &c) in coverage.iter().enumerate() {
                        let centre = [(first + k as i64) as f64 + 0.5, f64::from(row) + 0.5];
                        let p = nearest_in(triangle, centre);
                        let shade = self.surfaces.shade_pixel(t.polygon as usize, p, centre);
                        let shade = match shade {
                            Ok(s) => s.unwrap_or_default(),
                            Err(e) => {
                                result = Err(scene_io(e));
                                return;
                            }
                        };
                        targets.extend(shade[..channels].iter().map(|v| c * v.max(0.0)));
                    }
                    filled += 1;
                    result = fit_span(first as u32, &targets, channels, self.tolerance, sink)
                        .map(|s| {
                            instructions += s.pieces();
                            stats.add(&s);
                        })
                        .map_err(|e| NonFinite::at_row(e, row));
                }
                Visit::EndOfRow(_) => {
                    instructions += 1;
                    result = sink.write(&Instruction::refresh());
                }
            }
        });
        result?;
        self.surfaces.rows_done(rows_done);
        Ok(counters(filled, &stats, instructions))
    }
}
