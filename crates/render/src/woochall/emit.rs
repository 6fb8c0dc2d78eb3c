//! From shaded samples to the array: a pixel's value is the weighted sum of its samples'
//! colours ([`crate::subsample`]). A pixel whose samples one triangle owns is
//! **interior**: a run of interior pixels of one triangle goes through the
//! [span fitter](crate::span) — for flat and Gouraud shading with a tolerance at the
//! rounding level, so an affine run is one `Eval2` (a constant one an `Eval1`), and
//! runs the stochastic calls made uneven are split where they must be; for Phong with
//! the settings' tolerance. Every other pixel with geometry (an edge pixel) is one
//! `Eval1` holding its weighted sum.
//!
//! The `l` sub-scanlines of a row go to the array either as `l` passes the array
//! accumulates (each sub-scanline's share, weighted; the hardware does the averaging and
//! the cost grows with `l`), or merged by the host into one pass per row.

use super::lists::NONE;
use crate::span::{fit_span, SpanStats};
use crate::subsample::Sampler;
use cwisim_isa::{Instruction, Intensity, TraceWrite};
use cwisim_scene::Vector;
use std::io;

/// The relative tolerance of runs that should be exact (flat, Gouraud): the array's
/// `f64` adder chain over a run of up to `MAX_SIDE` pixels stays well inside it.
pub const EXACT_RUN_TOLERANCE: f64 = 1e-12;

/// One sub-scanline of a row: its winners and their colours.
#[derive(Clone, Debug, Default)]
pub struct Subline {
    /// Winning triangle of each sample column, or `NONE`.
    pub winners: Vec<u32>,
    /// Colour of each sample column (zero on the background).
    pub rgb: Vec<Vector>,
}

/// What a pixel holds after accumulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Class {
    /// No sample hit geometry.
    Empty,
    /// Every sample is the triangle's.
    Interior(u32),
    /// Samples of several triangles, or of the background and a triangle.
    Mixed,
}

/// What emitting did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EmitCounts {
    /// Pieces of interior runs, by opcode, and the fitter's work.
    pub runs: SpanStats,
    /// `Eval1`s of edge (mixed) pixels.
    pub edge_pixels: u64,
    /// Passes sent (sub-scanlines, or merged rows, with something in them).
    pub passes: u64,
    /// Instructions, `Refresh` included.
    pub instructions: u64,
}

impl EmitCounts {
    /// Adds another row's counts.
    pub fn add(&mut self, o: &EmitCounts) {
        self.runs.add(&o.runs);
        self.edge_pixels += o.edge_pixels;
        self.passes += o.passes;
        self.instructions += o.instructions;
    }
}

/// How a row is sent.
#[derive(Clone, Copy, Debug)]
pub struct EmitRule {
    /// One pass per row (the host sums the sub-scanlines) rather than one per
    /// sub-scanline.
    pub merge: bool,
    /// The span fitter's tolerance for interior runs (`None`: exact up to rounding).
    pub tolerance: Option<f64>,
    /// Channels.
    pub channels: usize,
}

/// Emits one pixel row from its `l` sub-scanlines (top to bottom), ending with
/// `Refresh`.
pub fn emit_row(
    sampler: &Sampler,
    sublines: &[&Subline],
    rule: &EmitRule,
    sink: &mut dyn TraceWrite,
) -> io::Result<EmitCounts> {
    let mut counts = EmitCounts::default();
    let mut targets = Vec::new();
    let mut class = Vec::new();
    if rule.merge {
        let all: Vec<(usize, &Subline)> = sublines.iter().copied().enumerate().collect();
        accumulate(sampler, &all, rule.channels, &mut targets, &mut class);
        send(&targets, &class, rule, 1, sink, &mut counts)?;
    } else {
        for (o, s) in sublines.iter().enumerate() {
            accumulate(sampler, &[(o, s)], rule.channels, &mut targets, &mut class);
            send(&targets, &class, rule, sublines.len(), sink, &mut counts)?;
        }
    }
    sink.write(&Instruction::refresh())?;
    counts.instructions += 1;
    Ok(counts)
}

/// Per pixel: the weighted sum of the samples of `sublines` (each with its offset in
/// the row) and the pixel's class.
fn accumulate(
    sampler: &Sampler,
    sublines: &[(usize, &Subline)],
    channels: usize,
    targets: &mut Vec<f64>,
    class: &mut Vec<Class>,
) {
    let width = sampler.width as usize;
    targets.clear();
    targets.resize(width * channels, 0.0);
    class.clear();
    for x in 0..width {
        let (c0, c1) = sampler.of_pixel(x as u32);
        let mut owner: Option<u32> = None;
        let (mut hit, mut mixed) = (false, false);
        let out = &mut targets[x * channels..(x + 1) * channels];
        for &(o, s) in sublines {
            let wy = sampler.weight(o);
            for k in c0..=c1 {
                let w = s.winners[k];
                if w == NONE {
                    mixed = true;
                    continue;
                }
                hit = true;
                match owner {
                    None => owner = Some(w),
                    Some(o) if o != w => mixed = true,
                    _ => {}
                }
                let weight = wy * sampler.weight(k - c0);
                for (c, v) in out.iter_mut().enumerate() {
                    *v += weight * s.rgb[k][c];
                }
            }
        }
        class.push(match (hit, mixed, owner) {
            (false, _, _) => Class::Empty,
            (true, false, Some(s)) => Class::Interior(s),
            _ => Class::Mixed,
        });
    }
}

/// Sends one pass: runs of interior pixels through the fitter, edge pixels as `Eval1`.
pub(crate) fn send(
    targets: &[f64],
    class: &[Class],
    rule: &EmitRule,
    passes: usize,
    sink: &mut dyn TraceWrite,
    counts: &mut EmitCounts,
) -> io::Result<()> {
    let ch = rule.channels;
    let before = counts.instructions;
    let mut x = 0;
    while x < class.len() {
        match class[x] {
            Class::Empty => x += 1,
            Class::Mixed => {
                let v = &targets[x * ch..(x + 1) * ch];
                if v.iter().any(|&c| c != 0.0) {
                    sink.write(&Instruction::eval1(x as u32, 1, Intensity::new(v)))?;
                    counts.edge_pixels += 1;
                    counts.instructions += 1;
                }
                x += 1;
            }
            Class::Interior(s) => {
                let start = x;
                while x < class.len() && class[x] == Class::Interior(s) {
                    x += 1;
                }
                let run = &targets[start * ch..x * ch];
                if run.iter().all(|&v| v == 0.0) {
                    // nothing to add (a black surface, a hidden-line interior)
                    continue;
                }
                let tolerance = match rule.tolerance {
                    // a pass's share of the row's tolerance
                    Some(t) => t / passes as f64,
                    None => EXACT_RUN_TOLERANCE * run.iter().fold(1.0f64, |m, v| m.max(v.abs())),
                };
                let s = fit_span(start as u32, run, ch, tolerance, sink)?;
                counts.instructions += s.pieces();
                counts.runs.add(&s);
            }
        }
    }
    if counts.instructions > before {
        counts.passes += 1;
    }
    Ok(())
}
