//! Which samples get a shading call (§3.4.1–3.4.2): `keepObj`, one slot per pixel
//! column holding the surface most recently hit in that pixel on the current row and the
//! colour shaded for it. A sample is shaded when its surface differs from the slot's,
//! with probability `P` (stochastic), or when its pixel is forced; otherwise it reuses the
//! slot's colour. Every shading call compares its colour with the previous sample of the
//! pixel, the left and right neighbours' slots and, for a pixel's first sample on the
//! row, what the pixel ended the previous row with; a difference above the contrast
//! forces shading on every later sample of the pixel and of the neighbour that differed.
//!
//! The state runs from sample to sample in scan order and from row to row (the previous
//! row's colours, the stochastic draws), so one frame is shaded on one thread, in order;
//! the seed makes it reproducible.

use super::lists::{Layers, NONE};
use super::triangle::Tri;
use crate::subsample::Sampler;
use cwisim_scene::Vector;
use rand_core::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;

/// When to shade.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadeRule {
    /// Probability of a stochastic shading call at a sample whose surface has a colour
    /// in `keepObj` already.
    pub p: f64,
    /// Largest difference (any channel) between two shading calls' colours that does
    /// not force super-sampling; infinite: never forced.
    pub contrast: f64,
    /// Seed of the stochastic calls.
    pub seed: u64,
}

/// What the shading rule did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadeStats {
    /// Shading calls (`#Shading`).
    pub calls: u64,
    /// Calls made because the surface changed in the pixel (or it was its first).
    pub new_surface: u64,
    /// Calls made by the stochastic draw.
    pub stochastic: u64,
    /// Calls made because the pixel was forced.
    pub forced_calls: u64,
    /// Pixels forced to super-sample shading (counted once per row).
    pub forced_pixels: u64,
    /// Calls shading a layer behind a transparent surface (every layer is shaded).
    pub layer_calls: u64,
}

/// `keepObj` and the rest of the shading state of one frame.
pub struct RowShader {
    rule: ShadeRule,
    sampler: Sampler,
    keep: Vec<Option<(u32, Vector)>>,
    forced: Vec<bool>,
    previous_row: Vec<Option<Vector>>,
    rng: XorShiftRng,
    channels: usize,
    /// What it did so far.
    pub stats: ShadeStats,
}

impl RowShader {
    /// The state at the top of a frame.
    pub fn new(rule: ShadeRule, sampler: Sampler, channels: usize) -> RowShader {
        let w = sampler.width as usize;
        RowShader {
            rule,
            sampler,
            keep: vec![None; w],
            forced: vec![false; w],
            previous_row: vec![None; w],
            rng: XorShiftRng::seed_from_u64(rule.seed),
            channels,
            stats: ShadeStats::default(),
        }
    }

    /// Shades the samples of one sub-scanline `y` of the current row: `rgb[k]` for every
    /// column `k` (zero on the background). `shade(tri, x, y)` is one shading call.
    ///
    /// Where the winner is transparent, the sample's colour is the layers' composite:
    /// `Σ (1 − t_i) Π_{j<i} t_j · colour_i`, nearest first, the front layer shaded by the
    /// rule above (`keepObj` keeps the front surface's colour) and every layer behind it
    /// by its own shading call.
    pub fn subline(
        &mut self,
        y: f64,
        winners: &[u32],
        layers: &Layers,
        tris: &[Tri],
        rgb: &mut Vec<Vector>,
        mut shade: impl FnMut(&Tri, f64, f64) -> Vector,
    ) {
        rgb.clear();
        rgb.resize(winners.len(), [0.0; cwisim_isa::MAX_CHANNELS]);
        let mut next_layered = layers.entries.iter().peekable();
        for (k, &w) in winners.iter().enumerate() {
            if w == NONE {
                continue;
            }
            let tri = &tris[w as usize];
            let x = self.sampler.owner(k) as usize;
            // the draw is made at every sample with geometry, so the stream does not
            // depend on the other reasons to shade
            let draw = (self.rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
            let slot = self.keep[x];
            let new_surface = slot.is_none_or(|(s, _)| s != tri.surface);
            let stochastic = draw < self.rule.p;
            let forced = self.forced[x];
            let colour = if new_surface || stochastic || forced {
                self.stats.calls += 1;
                if new_surface {
                    self.stats.new_surface += 1;
                } else if forced {
                    self.stats.forced_calls += 1;
                } else {
                    self.stats.stochastic += 1;
                }
                let colour = shade(tri, self.sampler.column_x(k), y);
                self.compare(x, slot.map(|(_, c)| c), &colour);
                colour
            } else {
                slot.map(|(_, c)| c).unwrap_or_default()
            };
            self.keep[x] = Some((tri.surface, colour));
            rgb[k] = colour;
            if let Some(&(_, start, end)) = next_layered.next_if(|e| e.0 as usize == k) {
                let sx = self.sampler.column_x(k);
                let mut through = tri.transmittance;
                let mut sum = colour.map(|c| (1.0 - through) * c);
                for &behind in &layers.tris[start as usize..end as usize] {
                    let layer = &tris[behind as usize];
                    let c = shade(layer, sx, y);
                    self.stats.calls += 1;
                    self.stats.layer_calls += 1;
                    for (s, v) in sum.iter_mut().zip(c) {
                        *s += through * (1.0 - layer.transmittance) * v;
                    }
                    through *= layer.transmittance;
                }
                rgb[k] = sum;
            }
        }
    }

    fn differs(&self, a: &Vector, b: &Vector) -> bool {
        (0..self.channels).any(|c| (a[c] - b[c]).abs() > self.rule.contrast)
    }

    /// §3.4.2's comparison after a shading call in pixel `x`.
    fn compare(&mut self, x: usize, own: Option<Vector>, colour: &Vector) {
        if self.rule.contrast.is_infinite() {
            return;
        }
        let before = own.or(self.previous_row[x]);
        if before.is_some_and(|b| self.differs(&b, colour)) {
            self.forced[x] = true;
        }
        for n in [x.wrapping_sub(1), x + 1] {
            if let Some(Some((_, c))) = self.keep.get(n) {
                if self.differs(c, colour) {
                    self.forced[x] = true;
                    self.forced[n] = true;
                }
            }
        }
    }

    /// Ends a row: what each pixel ended with becomes the previous row, and `keepObj`
    /// is nulled (§3.4.1: at least one shading call per pixel and row).
    pub fn end_row(&mut self) {
        for x in 0..self.keep.len() {
            self.previous_row[x] = self.keep[x].map(|(_, c)| c);
            self.keep[x] = None;
            if self.forced[x] {
                self.stats.forced_pixels += 1;
                self.forced[x] = false;
            }
        }
    }
}

/// `--shading hidden` (§6: hidden-line removal, visibility without shading calls): a
/// sample with geometry is 1 in every channel where its triangle differs from its left
/// neighbour's or from the one above it (`above`: the previous sub-scanline's winners,
/// empty at the top of the image), 0 elsewhere; the background is 0.
pub fn hidden_subline(winners: &[u32], above: &[u32], channels: usize, rgb: &mut Vec<Vector>) {
    rgb.clear();
    rgb.resize(winners.len(), [0.0; cwisim_isa::MAX_CHANNELS]);
    for (k, &w) in winners.iter().enumerate() {
        if w == NONE {
            continue;
        }
        let left = if k > 0 { winners[k - 1] } else { NONE };
        let up = above.get(k).copied().unwrap_or(NONE);
        if w != left || w != up {
            rgb[k] = cwisim_scene::vector(channels, |_| 1.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_lines_mark_where_the_triangle_changes() {
        let n = NONE;
        let mut rgb = Vec::new();
        hidden_subline(&[n, 1, 1, 1, 2, 2], &[n, 1, 1, 2, 2, 2], 1, &mut rgb);
        let got: Vec<f64> = rgb.iter().map(|v| v[0]).collect();
        assert_eq!(got, [0.0, 1.0, 0.0, 1.0, 1.0, 0.0]);
        // the top of the image: every sample with geometry is an edge
        hidden_subline(&[1, 1], &[], 1, &mut rgb);
        assert_eq!(rgb.iter().map(|v| v[0]).collect::<Vec<_>>(), [1.0, 1.0]);
    }
}
