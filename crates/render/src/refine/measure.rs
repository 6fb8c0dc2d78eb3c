//! What the phases measure: a polygon at one intensity, its vertex-intensity range (the
//! Gouraud test), and the 3 × 3 range of a frame's output (the anti-aliasing test).

use crate::settings::Threshold;
use cwisim_scene::{Polygon, VertexIntensity};
use cwisim_xproc::Image;

/// The polygon at one intensity: the mean of its vertex intensities, per channel (the
/// flat value every renderer takes, `cwisim_ypipe::flat_mean`).
pub fn flattened(p: &Polygon) -> Polygon {
    let channels = p.intensity.first().map_or(0, |i| i.len());
    let mean =
        VertexIntensity::from_slice(&cwisim_ypipe::flat_mean(&p.intensity, channels)[..channels]);
    Polygon {
        vertices: p.vertices.clone(),
        intensity: vec![mean; p.intensity.len()],
        depth: p.depth.clone(),
    }
}

/// The polygon's vertex-intensity range: the largest, over channels, of max − min over
/// its vertices (the Gouraud test's measure).
pub fn intensity_range(p: &Polygon) -> f64 {
    let channels = p.intensity.first().map_or(0, |i| i.len());
    (0..channels)
        .map(|c| {
            let (lo, hi) = p
                .intensity
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v[c]), hi.max(v[c]))
                });
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// The anti-aliasing test: for each pixel of `image` (`lines × width`), whether the range
/// (max − min, largest over channels) of its 3 × 3 neighbourhood, clipped to the image,
/// passes `threshold`.
pub fn aa_flags(image: &Image, lines: usize, threshold: Threshold) -> Vec<bool> {
    let (w, ch) = (image.width, image.channels);
    let mut flags = vec![false; w * lines];
    for y in 0..lines {
        for x in 0..w {
            let mut range = 0.0f64;
            for c in 0..ch {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for ny in y.saturating_sub(1)..(y + 2).min(lines) {
                    for nx in x.saturating_sub(1)..(x + 2).min(w) {
                        let v = image.data[(ny * w + nx) * ch + c];
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
                range = range.max(hi - lo);
            }
            flags[y * w + x] = threshold.passes(range);
        }
    }
    flags
}

/// The least area (px²) of a pixel a polygon must cover to count as one of its
/// fragments: below it the overlap is a rounding sliver, not a surface.
pub const FRAGMENT_AREA: f64 = 1e-9;

/// The anti-aliasing phase's fragments (the paper's A-buffer fragments): pairs of a
/// flagged pixel and a polygon of `screen` covering more than [`FRAGMENT_AREA`] of it,
/// the exact covered area summed over the polygon's trapezia.
pub fn aa_fragments(screen: &cwisim_scene::ScreenScene, flags: &[bool]) -> u64 {
    use cwisim_ypipe::coverage::Slice;
    let w = screen.width as usize;
    let mut pieces: Vec<(u32, u32, u32, f64)> = Vec::new();
    for t in cwisim_ypipe::scene_trapezia(screen) {
        let first = t.y_top.floor().max(0.0) as u32;
        let end = (t.y_bot.ceil() as u32).min(screen.height);
        for row in first..end {
            let Some(slice) = Slice::of(&t, row) else {
                continue;
            };
            let (l0, _, _, r1) = slice.edge_pixels();
            for x in l0.max(0)..=r1.min(w as i64 - 1) {
                if flags[row as usize * w + x as usize] {
                    pieces.push((row, x as u32, t.polygon, slice.coverage(x)));
                }
            }
        }
    }
    pieces.sort_by_key(|a| (a.0, a.1, a.2));
    let mut count = 0;
    let mut k = 0;
    while k < pieces.len() {
        let key = (pieces[k].0, pieces[k].1, pieces[k].2);
        let mut area = 0.0;
        while k < pieces.len() && (pieces[k].0, pieces[k].1, pieces[k].2) == key {
            area += pieces[k].3;
            k += 1;
        }
        if area > FRAGMENT_AREA {
            count += 1;
        }
    }
    count
}
