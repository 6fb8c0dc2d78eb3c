//! The sub-scanline sampler: where the `l × l` samples of a pixel lie and what each
//! weighs, shared by every renderer that supersamples (Woo & Chall; Barkan & Gordon).
//!
//! A pixel row is sampled on sub-scanlines, and each sub-scanline at sample columns; the
//! grid is separable, so a sample's weight is the product of its sub-scanline's weight
//! and its column's weight, and the weights of one pixel sum to 1.
//!
//! * [`Grid::Centre`] (the default): `l` sub-scanlines at `y = row + (j + ½)/l` and `l`
//!   columns at `x = i + (k + ½)/l`, each of weight `1/l`. At `l = 1` that is the pixel
//!   centre: the project's point sampling (`--aa none`). No sample is shared.
//! * [`Grid::Corner`] (Woo & Chall §3.4): the samples lie on the lattice of spacing
//!   `1/(l − 1)` through the pixel corners, `l` per pixel side; the trapezoid rule weighs
//!   them (`½` on the pixel's edge, `1` inside, divided by `l − 1`; so `¼` of a full
//!   sample at a corner). A sample on a pixel's edge is shared with the neighbour: a row
//!   of `w` pixels has `w(l − 1) + 1` columns, and a boundary sub-scanline feeds two rows.
//!   So an `l × l` grid costs `(l − 1)²` new samples per pixel. It needs `l ≥ 2`.
//!
//! Sample positions are computed by one function each ([`Sampler::column_x`],
//! [`Sampler::subline_y`]) so that every renderer tests the same coordinates.

use std::fmt;
use std::str::FromStr;

/// The largest `l` (samples per pixel side) a renderer accepts: `l²` samples per pixel.
pub const MAX_SAMPLES: u32 = 64;

/// Where a pixel's samples lie.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Grid {
    /// `l × l` samples at the centres of an `l × l` subdivision of the pixel.
    #[default]
    Centre,
    /// `l × l` samples on the pixel's corners, edges and inside, shared with neighbours.
    Corner,
}

impl Grid {
    /// Every value, in order.
    pub const ALL: [Grid; 2] = [Grid::Centre, Grid::Corner];

    /// Its one spelling.
    pub fn name(self) -> &'static str {
        match self {
            Grid::Centre => "centre",
            Grid::Corner => "corner",
        }
    }
}

impl fmt::Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Grid {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Grid::ALL
            .into_iter()
            .find(|g| g.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown sample grid `{s}`; expected centre or corner"))
    }
}

/// The samples of an image `width × height` pixels on an `l × l` grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampler {
    /// Samples per pixel side.
    pub l: u32,
    /// Where they lie.
    pub grid: Grid,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

impl Sampler {
    /// The sampler, or why `l` does not fit the grid.
    pub fn new(l: u32, grid: Grid, width: u32, height: u32) -> Result<Sampler, String> {
        if !(1..=MAX_SAMPLES).contains(&l) {
            return Err(format!(
                "--samples must be 1 to {MAX_SAMPLES} (samples per pixel side), found {l}"
            ));
        }
        if grid == Grid::Corner && l < 2 {
            return Err(
                "the corner grid needs --samples 2 or more (its samples lie on the pixel's corners)".into(),
            );
        }
        Ok(Sampler {
            l,
            grid,
            width,
            height,
        })
    }

    /// New samples per pixel side: `l` on the centre grid, `l − 1` on the corner grid
    /// (the other one is the neighbour's).
    pub fn step_count(&self) -> u32 {
        match self.grid {
            Grid::Centre => self.l,
            Grid::Corner => self.l - 1,
        }
    }

    /// Sample columns across the image.
    pub fn columns(&self) -> usize {
        let n = self.width as usize * self.step_count() as usize;
        match self.grid {
            Grid::Centre => n,
            Grid::Corner => n + 1,
        }
    }

    /// Sub-scanlines down the image.
    pub fn sublines(&self) -> usize {
        let n = self.height as usize * self.step_count() as usize;
        match self.grid {
            Grid::Centre => n,
            Grid::Corner => n + 1,
        }
    }

    fn position(&self, k: usize) -> f64 {
        match self.grid {
            Grid::Centre => (k as f64 + 0.5) / f64::from(self.l),
            Grid::Corner => k as f64 / f64::from(self.l - 1),
        }
    }

    /// The x of sample column `k`, pixels.
    pub fn column_x(&self, k: usize) -> f64 {
        self.position(k)
    }

    /// The y of sub-scanline `j`, pixels.
    pub fn subline_y(&self, j: usize) -> f64 {
        self.position(j)
    }

    /// The first sample index (column or sub-scanline) whose position is `≥ v`, as a
    /// float (it may be negative or beyond the image): a candidate from arithmetic, which
    /// the caller checks with its exact test (a few ulps may move a boundary by one).
    pub fn index_at_or_after(&self, v: f64) -> f64 {
        match self.grid {
            Grid::Centre => (v * f64::from(self.l) - 0.5).ceil(),
            Grid::Corner => (v * f64::from(self.l - 1)).ceil(),
        }
    }

    /// The last sample index whose position is `≤ v` (a candidate, as above).
    pub fn index_at_or_before(&self, v: f64) -> f64 {
        match self.grid {
            Grid::Centre => (v * f64::from(self.l) - 0.5).floor(),
            Grid::Corner => (v * f64::from(self.l - 1)).floor(),
        }
    }

    /// The sample indices of pixel `p` (a column or a row), first and last inclusive:
    /// `l` of them; on the corner grid the first and the last are shared.
    pub fn of_pixel(&self, p: u32) -> (usize, usize) {
        let s = self.step_count() as usize;
        let first = p as usize * s;
        match self.grid {
            Grid::Centre => (first, first + s - 1),
            Grid::Corner => (first, first + s),
        }
    }

    /// The weight, within its pixel, of the sample `index − first` places into the
    /// pixel along one axis: the `l` weights sum to 1.
    pub fn weight(&self, offset: usize) -> f64 {
        match self.grid {
            Grid::Centre => 1.0 / f64::from(self.l),
            Grid::Corner => {
                let inner = f64::from(self.l - 1);
                if offset == 0 || offset == (self.l - 1) as usize {
                    0.5 / inner
                } else {
                    1.0 / inner
                }
            }
        }
    }

    /// The pixel (column or row) that first computes sample index `k`: on the corner
    /// grid a shared sample belongs to the pixel before it (left, or above), which
    /// reaches it first in scan order.
    pub fn owner(&self, k: usize) -> u32 {
        match self.grid {
            Grid::Centre => (k / self.l as usize) as u32,
            Grid::Corner => (k.saturating_sub(1) / (self.l - 1) as usize) as u32,
        }
    }

    /// The probability of Woo & Chall's stochastic shading call (§3.4.2),
    /// `P = (l − 1)/(l² − 1) = 1/(l + 1)` (taken as its limit at `l = 1`, where each
    /// pixel has one sample and is shaded anyway).
    pub fn paper_shade_probability(&self) -> f64 {
        1.0 / (f64::from(self.l) + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_samples_tile_the_row() {
        for grid in Grid::ALL {
            for l in 1..=9 {
                let Ok(s) = Sampler::new(l, grid, 5, 3) else {
                    assert!(grid == Grid::Corner && l == 1);
                    continue;
                };
                let (a, b) = s.of_pixel(2);
                assert_eq!(b - a + 1, l as usize);
                let sum: f64 = (0..l as usize).map(|o| s.weight(o)).sum();
                assert!((sum - 1.0).abs() < 1e-15, "{grid} {l}: {sum}");
                // samples of pixel 2 lie in [2, 3]; centre samples strictly inside
                for k in a..=b {
                    let x = s.column_x(k);
                    assert!((2.0..=3.0).contains(&x));
                    if grid == Grid::Centre {
                        assert!(x > 2.0 && x < 3.0);
                    }
                }
                // every column has an owner whose samples include it
                for k in 0..s.columns() {
                    let o = s.owner(k).min(s.width - 1);
                    let (a, b) = s.of_pixel(o);
                    assert!((a..=b).contains(&k), "{grid} l={l} k={k} owner {o}");
                }
                assert_eq!(s.owner(s.columns() - 1), s.width - 1);
            }
        }
        let s = Sampler::new(1, Grid::Centre, 4, 4).unwrap();
        assert_eq!(s.column_x(3), 3.5);
        let c = Sampler::new(3, Grid::Corner, 4, 4).unwrap();
        assert_eq!((c.columns(), c.sublines()), (9, 9));
        assert_eq!(c.weight(0), 0.25);
        assert_eq!(c.weight(1), 0.5);
    }

    #[test]
    fn index_candidates_bracket_positions() {
        for grid in Grid::ALL {
            let s = Sampler::new(4, grid, 10, 10).unwrap();
            for v in [0.0, 0.1, 0.125, 0.375, 2.5, 7.99] {
                let lo = s.index_at_or_after(v) as usize;
                assert!(s.column_x(lo) >= v);
                assert!(lo == 0 || s.column_x(lo - 1) < v);
                let hi = s.index_at_or_before(v);
                if hi >= 0.0 {
                    assert!(s.column_x(hi as usize) <= v);
                    assert!(s.column_x(hi as usize + 1) > v);
                }
            }
        }
    }

    #[test]
    fn bad_sample_counts_are_refused() {
        assert!(Sampler::new(0, Grid::Centre, 1, 1)
            .unwrap_err()
            .contains("--samples"));
        assert!(Sampler::new(65, Grid::Centre, 1, 1).is_err());
        assert!(Sampler::new(1, Grid::Corner, 1, 1)
            .unwrap_err()
            .contains("corner"));
        assert_eq!("corner".parse::<Grid>(), Ok(Grid::Corner));
        assert!("middle"
            .parse::<Grid>()
            .unwrap_err()
            .contains("centre or corner"));
    }

    #[test]
    fn the_paper_probability_is_its_formula() {
        for l in 2..=8u32 {
            let s = Sampler::new(l, Grid::Centre, 1, 1).unwrap();
            let printed = f64::from(l - 1) / f64::from(l * l - 1);
            assert!((s.paper_shade_probability() - printed).abs() < 1e-15);
        }
    }
}
