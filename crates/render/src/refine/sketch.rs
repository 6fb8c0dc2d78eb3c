//! The paper's first two phases: the model's vertices as depth-cued points, then the
//! edges of its triangles as depth-cued one-pixel lines — each a complete frame of
//! `Eval1` runs (one per run of equal values in a row), nothing else drawn.
//!
//! The points and lines are those of the projected triangles (front faces, and the back
//! faces of two-sided meshes), clipped to the image: the paper's "visible points" are
//! those inside the view volume, before any hidden-surface removal. The depth cue is
//! linear in depth, [`NEAR`] at the nearest corner of the scene to [`FAR`] at the
//! farthest, in every channel; where points or lines meet in a pixel, the nearest (the
//! brightest) wins.

use crate::renderer::{Counters, FramePlan};
use cwisim_isa::{Instruction, Intensity, TraceWrite};
use cwisim_world::face::ScreenTriangle;
use std::collections::BTreeSet;
use std::io;
use std::ops::Range;

/// The depth cue's intensity at the nearest depth.
pub const NEAR: f64 = 1.0;
/// The depth cue's intensity at the farthest depth.
pub const FAR: f64 = 0.25;

/// Lit pixels, row by row: `(x, intensity)` sorted by `x`, one per pixel.
#[derive(Clone, Debug, Default)]
pub struct Sketch {
    rows: Vec<Vec<(u32, f64)>>,
    /// Points or lines drawn (distinct vertices, or distinct edges).
    pub elements: u64,
}

/// The depth range of the triangles' corners.
fn depth_range(tris: &[ScreenTriangle]) -> (f64, f64) {
    tris.iter()
        .flat_map(|t| t.inv_depth)
        .filter(|&i| i > 0.0 && i.is_finite())
        .map(|i| 1.0 / i)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
            (lo.min(z), hi.max(z))
        })
}

/// The depth cue of depth `z` in `range`.
pub fn depth_cue(z: f64, (near, far): (f64, f64)) -> f64 {
    if far > near {
        NEAR - (NEAR - FAR) * ((z - near) / (far - near)).clamp(0.0, 1.0)
    } else {
        NEAR
    }
}

/// A screen point's bits, for finding equal points.
fn key(p: [f64; 2]) -> (u64, u64) {
    (p[0].to_bits(), p[1].to_bits())
}

impl Sketch {
    fn new(height: u32) -> Sketch {
        Sketch {
            rows: vec![Vec::new(); height as usize],
            elements: 0,
        }
    }

    /// Lights pixel `p` (screen coordinates) at `v`, if it lies in the image.
    fn plot(&mut self, p: [f64; 2], width: u32, v: f64) {
        let (x, y) = (p[0].floor(), p[1].floor());
        if x >= 0.0 && y >= 0.0 && x < f64::from(width) && (y as usize) < self.rows.len() {
            self.rows[y as usize].push((x as u32, v));
        }
    }

    /// One value per pixel, the brightest, in `x` order.
    fn settle(mut self) -> Sketch {
        for row in &mut self.rows {
            row.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
            row.dedup_by_key(|p| p.0);
        }
        self
    }

    /// The distinct corners of `tris` as depth-cued points in a `width × height` image.
    pub fn points(tris: &[ScreenTriangle], width: u32, height: u32) -> Sketch {
        Sketch::points_part(tris, width, height, 1, 1)
    }

    /// Part `part` (from 1) of `parts` of the distinct corners of `tris`, as depth-cued
    /// points: those whose index among the distinct corners (in the triangles' order) is
    /// below `part` modulo `parts` — every `parts`-th corner in the first part, spread over
    /// the whole model, and all of them in the last.
    pub fn points_part(
        tris: &[ScreenTriangle],
        width: u32,
        height: u32,
        part: u32,
        parts: u32,
    ) -> Sketch {
        let range = depth_range(tris);
        let mut s = Sketch::new(height);
        let mut seen = BTreeSet::new();
        let mut index = 0u64;
        for t in tris {
            for k in 0..3 {
                if seen.insert(key(t.points[k])) {
                    if index % u64::from(parts.max(1)) < u64::from(part) {
                        s.elements += 1;
                        s.plot(t.points[k], width, depth_cue(1.0 / t.inv_depth[k], range));
                    }
                    index += 1;
                }
            }
        }
        s.settle()
    }

    /// The distinct edges of `tris` as depth-cued one-pixel lines: each sampled at
    /// `n + 1` evenly spaced points, `n` the edge's longer side in pixels (rounded up),
    /// so that consecutive samples are at most one pixel apart along either axis; the
    /// depth interpolated perspective-correctly (`1/z` is affine on the screen).
    pub fn edges(tris: &[ScreenTriangle], width: u32, height: u32) -> Sketch {
        let range = depth_range(tris);
        let mut s = Sketch::new(height);
        let mut seen = BTreeSet::new();
        for t in tris {
            for k in 0..3 {
                let (i, j) = (k, (k + 1) % 3);
                let (a, b) = (t.points[i], t.points[j]);
                let edge = if key(a) <= key(b) {
                    (key(a), key(b))
                } else {
                    (key(b), key(a))
                };
                if !seen.insert(edge) {
                    continue;
                }
                s.elements += 1;
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let n = dx.abs().max(dy.abs()).ceil().clamp(1.0, 1e6) as u32;
                for step in 0..=n {
                    let u = f64::from(step) / f64::from(n);
                    let inv = t.inv_depth[i] + u * (t.inv_depth[j] - t.inv_depth[i]);
                    let p = [a[0] + u * dx, a[1] + u * dy];
                    s.plot(p, width, depth_cue(1.0 / inv, range));
                }
            }
        }
        s.settle()
    }

    /// Lit pixels in all.
    pub fn pixels(&self) -> u64 {
        self.rows.iter().map(|r| r.len() as u64).sum()
    }

    /// Row `y`'s lit pixels.
    pub fn row(&self, y: usize) -> &[(u32, f64)] {
        self.rows.get(y).map_or(&[], Vec::as_slice)
    }
}

/// A sketch's frame: per row, one `Eval1` per run of equal values, then `Refresh`.
pub struct SketchFrame<'a> {
    /// What it draws.
    pub sketch: &'a Sketch,
    /// Values per intensity.
    pub channels: usize,
    /// Counter names: instructions, regenerated, pixels, elements.
    pub names: [&'static str; 4],
}

impl FramePlan for SketchFrame<'_> {
    fn counters(&self) -> Counters {
        Counters::default()
            .with(self.names[2], self.sketch.pixels())
            .with(self.names[3], self.sketch.elements)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let (mut total, mut evals) = (0u64, 0u64);
        for y in rows {
            let row = self.sketch.row(y as usize);
            let mut k = 0;
            while k < row.len() {
                let (x, v) = row[k];
                let mut end = k + 1;
                while end < row.len()
                    && row[end].0 == x + (end - k) as u32
                    && row[end].1.to_bits() == v.to_bits()
                {
                    end += 1;
                }
                sink.write(&Instruction::eval1(
                    x,
                    (end - k) as u32,
                    Intensity::splat(v, self.channels),
                ))?;
                evals += 1;
                k = end;
            }
            sink.write(&Instruction::refresh())?;
            total += 1;
        }
        Ok(Counters::default()
            .with(self.names[0], total + evals)
            .with(self.names[1], evals))
    }
}
