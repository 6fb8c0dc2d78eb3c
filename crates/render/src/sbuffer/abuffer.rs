//! The scanline A-buffer (Barkan & Gordon §5.2: the S-buffer "can be extended in the same
//! way" as Carpenter's A-buffer, "the bit-masks … added only to the pixels of one
//! scanline … initialized to zero at each new scanline").
//!
//! Per pixel of the one-scanline buffer, a list of **fragments**, one per polygon that
//! covers part of it: its coverage bit mask of `l × l` bits (bit `o·l + i` is the sample
//! at `(x + (i + ½)/l, y + (o + ½)/l)`, the `--samples l` centre grid's), the sum of its
//! samples' colours (flat, Gouraud: the spans' values there) or of their positions (Phong
//! and textures: it is shaded once, at its samples' centroid), and its polygon, whose
//! depth at the pixel centre orders it. A pixel is **resolved** as Carpenter resolves one:
//! fragments nearest first, each adding its mean colour times the share of the mask's
//! bits it covers that no nearer fragment covered. Depth is one value per fragment, not
//! per sample: where two polygons cross inside a pixel, the nearer at the centre hides
//! the other over their common bits (the A-buffer's error beside supersampling's).

use cwisim_scene::Vector;

/// One polygon's part of one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Fragment {
    /// The polygon.
    pub(crate) owner: u32,
    /// Its coverage bits.
    pub(crate) mask: u64,
    /// The sum of its samples' colours.
    pub(crate) sum: Vector,
    /// The sum of its samples' positions.
    pub(crate) at: [f64; 2],
}

/// The fragments of one scanline's pixels, reused from row to row.
#[derive(Clone, Debug, Default)]
pub(crate) struct FragmentLine {
    pixels: Vec<Vec<Fragment>>,
    /// The mask's side `l` (bits `l × l`, at most 8).
    pub(crate) side: usize,
    /// The sub-scanline of the row being filled.
    pub(crate) sub: usize,
    /// Fragments held on this row.
    pub(crate) count: usize,
}

impl FragmentLine {
    /// Every pixel of `0..width` with no fragment, masks `side × side`.
    pub(crate) fn reset(&mut self, width: usize, side: usize) {
        self.pixels.truncate(width);
        for p in &mut self.pixels {
            p.clear();
        }
        self.pixels.resize_with(width, Vec::new);
        self.side = side;
        self.sub = 0;
        self.count = 0;
    }

    /// Sample column `c` of the current sub-scanline, at `(x, y)`, covered by polygon
    /// `owner` with colour `v`.
    pub(crate) fn add(&mut self, c: usize, owner: u32, v: &Vector, x: f64, y: f64) {
        let (pixel, i) = (c / self.side, c % self.side);
        let bit = 1u64 << (self.sub * self.side + i);
        let list = &mut self.pixels[pixel];
        // a polygon's fragment is the last one it touched in this pixel, or a new one
        let f = match list.iter().rposition(|f| f.owner == owner) {
            Some(k) => &mut list[k],
            None => {
                list.push(Fragment {
                    owner,
                    mask: 0,
                    sum: Vector::default(),
                    at: [0.0; 2],
                });
                self.count += 1;
                list.last_mut().expect("pushed")
            }
        };
        f.mask |= bit;
        for (s, c) in f.sum.iter_mut().zip(v) {
            *s += c;
        }
        f.at[0] += x;
        f.at[1] += y;
    }

    /// The fragments of pixel `x`.
    pub(crate) fn pixel(&self, x: usize) -> &[Fragment] {
        &self.pixels[x]
    }
}

/// A pixel resolved: its value, and the polygon that covers all of it in front of the
/// rest (`None`: an edge pixel, or empty).
pub(crate) struct Resolved {
    pub(crate) value: Vector,
    pub(crate) interior: Option<u32>,
    /// Whether any fragment covers part of it.
    pub(crate) empty: bool,
}

/// Resolves a pixel's fragments: nearest first by `key(fragment)` (a tie: the order they
/// came in), each adding `colour(fragment)` times the share of the `side²` bits it covers
/// that no nearer one did.
pub(crate) fn resolve<E>(
    fragments: &[Fragment],
    side: usize,
    channels: usize,
    key: impl Fn(&Fragment) -> f64,
    mut colour: impl FnMut(&Fragment) -> Result<Vector, E>,
) -> Result<Resolved, E> {
    let full = if side * side == 64 {
        u64::MAX
    } else {
        (1u64 << (side * side)) - 1
    };
    let mut order: Vec<(f64, usize)> = fragments
        .iter()
        .enumerate()
        .map(|(k, f)| (key(f), k))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut covered = 0u64;
    let mut value = Vector::default();
    let n = (side * side) as f64;
    for &(_, k) in &order {
        let f = &fragments[k];
        let new = f.mask & !covered;
        if new == 0 {
            continue;
        }
        let c = colour(f)?;
        let share = f64::from(new.count_ones()) / n;
        for ch in 0..channels {
            value[ch] += share * c[ch];
        }
        covered |= new;
        if covered == full {
            break;
        }
    }
    let interior = order
        .first()
        .map(|&(_, k)| &fragments[k])
        .filter(|f| f.mask == full)
        .map(|f| f.owner);
    Ok(Resolved {
        value,
        interior,
        empty: fragments.is_empty(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: f64) -> Vector {
        cwisim_scene::vector(1, |_| v)
    }

    #[test]
    fn fragments_gather_their_bits_and_resolve_nearest_first() {
        let mut l = FragmentLine::default();
        l.reset(2, 4);
        // pixel 0: polygon 1 covers the left half of each sub-scanline, polygon 0 all
        for sub in 0..4 {
            l.sub = sub;
            for c in 0..4 {
                l.add(c, 0, &grey(0.2), 0.0, 0.0);
            }
            for c in 0..2 {
                l.add(c, 1, &grey(1.0), 0.0, 0.0);
            }
        }
        assert_eq!(l.count, 2);
        let f = l.pixel(0);
        assert_eq!(f[0].mask, 0xffff);
        assert_eq!(f[1].mask, 0x3333);
        // polygon 1 in front: half of 1.0, and polygon 0 the other half
        let key = |f: &Fragment| if f.owner == 1 { 0.0 } else { 1.0 };
        let mean = |f: &Fragment| Ok::<_, ()>(grey(f.sum[0] / f64::from(f.mask.count_ones())));
        let r = resolve(f, 4, 1, key, mean).unwrap();
        assert!((r.value[0] - (0.5 * 1.0 + 0.5 * 0.2)).abs() < 1e-15);
        assert_eq!(r.interior, None);
        // polygon 0 in front: it alone, all of the pixel
        let r = resolve(f, 4, 1, |f| f64::from(f.owner), mean).unwrap();
        assert!((r.value[0] - 0.2).abs() < 1e-15);
        assert_eq!(r.interior, Some(0));
        assert!(resolve(l.pixel(1), 4, 1, key, mean).unwrap().empty);
    }

    #[test]
    fn an_eight_by_eight_mask_uses_all_64_bits() {
        let mut l = FragmentLine::default();
        l.reset(1, 8);
        for sub in 0..8 {
            l.sub = sub;
            for c in 0..8 {
                l.add(c, 3, &grey(0.5), 0.0, 0.0);
            }
        }
        assert_eq!(l.pixel(0)[0].mask, u64::MAX);
        let r = resolve(
            l.pixel(0),
            8,
            1,
            |_| 0.0,
            |f| Ok::<_, ()>(grey(f.sum[0] / 64.0)),
        )
        .unwrap();
        assert_eq!(r.interior, Some(3));
        assert!((r.value[0] - 0.5).abs() < 1e-15);
    }
}
