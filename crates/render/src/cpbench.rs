//! The benchmark of Barkan & Gordon's Tables 3–5: screen scenes of many polygons with
//! many vertices, in three families by their number of critical points `c` —
//!
//! * [`Family::Convex`]: vertices on an ellipse at random angles (`c = 1`);
//! * [`Family::Few`]: smooth star-like contours `r(θ) = R·(1 + a·cos(kθ + φ))`, `k` lobes,
//!   sampled at `n` even angles, kept when `DETCR` finds 1 to 5 critical points (a
//!   smooth contour's minima do not depend on `n`);
//! * [`Family::Many`]: zig-zag bands, a row of `⌊(n − 3)/2⌋` teeth on top of a box
//!   (`c = ⌊(n − 3)/2⌋ + 1 ≈ n/2`, the worst case for CP).
//!
//! Every polygon is simple by construction, has a constant depth (drawn at random, so
//! the S-buffer sees them in no particular order) and one grey intensity. The same seed
//! gives the same scene. [`detcr`] reports the actual counts.

use crate::cp::detcr;
use cwisim_scene::{Polygon, ScreenScene};
use rand_core::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;
use std::fmt;
use std::ops::RangeInclusive;
use std::str::FromStr;

/// The fewest vertices a benchmark polygon has (a zig-zag band needs 4).
pub const MIN_VERTICES: u32 = 4;
/// The most vertices a benchmark polygon has.
pub const MAX_VERTICES: u32 = 100_000;
/// The most polygons a benchmark scene has.
pub const MAX_POLYGONS: u32 = 100_000;

/// The three families of the paper's experiments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    /// Convex polygons: one critical point.
    Convex,
    /// Non-convex with few (1–5) critical points.
    Few,
    /// Non-convex with about `n/2` critical points.
    Many,
}

impl Family {
    /// Every family, in the paper's order.
    pub const ALL: [Family; 3] = [Family::Convex, Family::Few, Family::Many];

    /// Its one spelling.
    pub fn name(self) -> &'static str {
        match self {
            Family::Convex => "convex",
            Family::Few => "few",
            Family::Many => "many",
        }
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Family {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Family::ALL
            .into_iter()
            .find(|g| g.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown family `{s}`; expected convex, few or many"))
    }
}

/// Parses a vertex count `N` or a range in the command line's one range syntax
/// (docs/VOCABULARY.md): `A..B` (B not included) or `A..=B` (both included).
pub fn parse_vertices(s: &str) -> Result<RangeInclusive<u32>, String> {
    let bad = || {
        format!(
            "expected a vertex count N or a range A..B (B not included) or A..=B (such as \
100..=1000), found `{s}`"
        )
    };
    let number = |t: &str| t.trim().parse::<u32>().map_err(|_| bad());
    let (a, b) = match s.split_once("..") {
        Some((a, b)) => match b.strip_prefix('=') {
            Some(b) => (number(a)?, number(b)?),
            None => {
                let (a, end) = (number(a)?, number(b)?);
                if end <= a {
                    return Err(format!(
                        "the vertex range `{s}` is empty: the end {end} is not included \
(write {a}..={end} to include it)"
                    ));
                }
                (a, end - 1)
            }
        },
        None => {
            let n = number(s)?;
            (n, n)
        }
    };
    if a > b {
        return Err(format!("the vertex range `{s}` is empty: {a} > {b}"));
    }
    if a < MIN_VERTICES || b > MAX_VERTICES {
        return Err(format!(
            "vertex counts must lie in {MIN_VERTICES}..={MAX_VERTICES}, found `{s}`"
        ));
    }
    Ok(a..=b)
}

/// What to generate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BenchSpec {
    /// The family.
    pub family: Family,
    /// How many polygons.
    pub polygons: u32,
    /// Each polygon's vertex count, drawn uniformly from this range.
    pub vertices: RangeInclusive<u32>,
    /// The seed.
    pub seed: u64,
    /// Image width and height, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

/// What was generated, counted by `DETCR`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BenchCounts {
    /// Polygons.
    pub polygons: u64,
    /// Vertices in all.
    pub vertices: u64,
    /// Critical points in all.
    pub critical_points: u64,
    /// The fewest critical points of a polygon.
    pub min_critical: u64,
    /// The most critical points of a polygon.
    pub max_critical: u64,
}

impl fmt::Display for BenchCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} polygons, {} vertices, {} critical points ({} to {} per polygon, {:.2} on average)",
            self.polygons,
            self.vertices,
            self.critical_points,
            self.min_critical,
            self.max_critical,
            self.critical_points as f64 / self.polygons.max(1) as f64
        )
    }
}

/// The critical points of a scene's polygons, by `DETCR`.
pub fn count(scene: &ScreenScene) -> BenchCounts {
    let mut c = BenchCounts {
        min_critical: u64::MAX,
        ..BenchCounts::default()
    };
    for p in &scene.polygons {
        let y: Vec<f64> = p.vertices.iter().map(|v| v[1]).collect();
        let k = detcr(&y).len() as u64;
        c.polygons += 1;
        c.vertices += p.vertices.len() as u64;
        c.critical_points += k;
        c.min_critical = c.min_critical.min(k);
        c.max_critical = c.max_critical.max(k);
    }
    if c.polygons == 0 {
        c.min_critical = 0;
    }
    c
}

fn unit(rng: &mut XorShiftRng) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

fn between(rng: &mut XorShiftRng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * unit(rng)
}

/// The benchmark scene `spec` describes, and its counts.
pub fn generate(spec: &BenchSpec) -> Result<(ScreenScene, BenchCounts), String> {
    if spec.polygons == 0 || spec.polygons > MAX_POLYGONS {
        return Err(format!(
            "--polygons must be 1 to {MAX_POLYGONS}, found {}",
            spec.polygons
        ));
    }
    parse_vertices(&format!(
        "{}..={}",
        spec.vertices.start(),
        spec.vertices.end()
    ))?;
    if spec.width < 16 || spec.height < 16 {
        return Err(format!(
            "a benchmark image needs at least 16x16 pixels, found {}x{}",
            spec.width, spec.height
        ));
    }
    let mut rng = XorShiftRng::seed_from_u64(spec.seed);
    let (w, h) = (f64::from(spec.width), f64::from(spec.height));
    // polygon sizes: a tenth of the image's smaller side, give or take half
    let size = w.min(h) / 10.0;
    let mut polygons = Vec::with_capacity(spec.polygons as usize);
    let span = u64::from(spec.vertices.end() - spec.vertices.start()) + 1;
    for _ in 0..spec.polygons {
        let n = spec.vertices.start() + (rng.next_u64() % span) as u32;
        let (cx, cy) = (between(&mut rng, 0.0, w), between(&mut rng, 0.0, h));
        let r = between(&mut rng, 0.5 * size, 1.5 * size);
        let vertices = match spec.family {
            Family::Convex => convex(&mut rng, n, cx, cy, r),
            Family::Few => few(&mut rng, n, cx, cy, r),
            Family::Many => zigzag(&mut rng, n, cx, cy, r),
        };
        let depth = between(&mut rng, 1.0, 100.0);
        let grey = between(&mut rng, 0.2, 1.0);
        let k = vertices.len();
        polygons.push(Polygon::uniform(vertices, &[grey]).with_depth(vec![depth; k]));
    }
    let scene = ScreenScene {
        width: spec.width,
        height: spec.height,
        channels: 1,
        polygons,
    };
    let counts = count(&scene);
    Ok((scene, counts))
}

/// `n` points on an ellipse at distinct random angles, in angle order: convex.
fn convex(rng: &mut XorShiftRng, n: u32, cx: f64, cy: f64, r: f64) -> Vec<[f64; 2]> {
    let (rx, ry) = (r, r * between(rng, 0.4, 1.0));
    let phi = between(rng, 0.0, std::f64::consts::PI);
    let (c, s) = (phi.cos(), phi.sin());
    // angles: n even steps, each jittered within its own step (so they stay distinct
    // and in order)
    let step = std::f64::consts::TAU / f64::from(n);
    (0..n)
        .map(|k| {
            let t = (f64::from(k) + between(rng, 0.1, 0.9)) * step;
            let (x, y) = (rx * t.cos(), ry * t.sin());
            [cx + x * c - y * s, cy + x * s + y * c]
        })
        .collect()
}

/// A smooth star-like contour with 1 to 5 critical points, sampled at `n` even angles.
fn few(rng: &mut XorShiftRng, n: u32, cx: f64, cy: f64, r: f64) -> Vec<[f64; 2]> {
    loop {
        let k = 2 + (rng.next_u64() % 5) as u32;
        let a = between(rng, 0.15, 0.45);
        let phi = between(rng, 0.0, std::f64::consts::TAU);
        let step = std::f64::consts::TAU / f64::from(n);
        let v: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let t = f64::from(i) * step;
                let rad = r * (1.0 + a * (f64::from(k) * t + phi).cos());
                [cx + rad * t.cos(), cy + rad * t.sin()]
            })
            .collect();
        let y: Vec<f64> = v.iter().map(|p| p[1]).collect();
        if (1..=5).contains(&detcr(&y).len()) {
            return v;
        }
    }
}

/// A zig-zag band: `⌊(n − 3)/2⌋` teeth on top of a box (one more vertex on its bottom
/// edge when `n` is even), `⌊(n − 3)/2⌋ + 1` critical points.
fn zigzag(rng: &mut XorShiftRng, n: u32, cx: f64, cy: f64, r: f64) -> Vec<[f64; 2]> {
    let teeth = (n - 3) / 2;
    let width = 2.0 * r;
    let tooth = between(rng, 0.1, 0.4) * r;
    let body = between(rng, 0.5, 1.0) * r;
    let (x0, y0) = (cx - r, cy - 0.5 * (tooth + body));
    let points = 2 * teeth + 1;
    let mut v: Vec<[f64; 2]> = (0..points)
        .map(|k| {
            let x = if points == 1 {
                x0 + 0.5 * width
            } else {
                x0 + width * f64::from(k) / f64::from(points - 1)
            };
            let y = if k % 2 == 0 { y0 } else { y0 + tooth };
            [x, y]
        })
        .collect();
    let bottom = y0 + tooth + body;
    v.push([x0 + width, bottom]);
    if n.is_multiple_of(2) {
        v.push([x0 + 0.5 * width, bottom]);
    }
    v.push([x0, bottom]);
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_scene::predicates::simplicity_fault;

    fn spec(family: Family, vertices: RangeInclusive<u32>) -> BenchSpec {
        BenchSpec {
            family,
            polygons: 30,
            vertices,
            seed: 7,
            width: 256,
            height: 256,
        }
    }

    #[test]
    fn families_have_their_critical_points_and_are_simple() {
        for n in [4u32, 5, 10, 101, 400] {
            let (s, c) = generate(&spec(Family::Convex, n..=n)).unwrap();
            assert_eq!((c.min_critical, c.max_critical), (1, 1));
            assert_eq!(c.vertices, 30 * u64::from(n));
            assert!(s
                .polygons
                .iter()
                .all(|p| simplicity_fault(&p.vertices).is_none()));
            let (s, c) = generate(&spec(Family::Few, n.max(20)..=n.max(20))).unwrap();
            assert!(c.min_critical >= 1 && c.max_critical <= 5, "{c}");
            assert!(s
                .polygons
                .iter()
                .all(|p| simplicity_fault(&p.vertices).is_none()));
            let (s, c) = generate(&spec(Family::Many, n..=n)).unwrap();
            let want = u64::from((n - 3) / 2 + 1);
            assert_eq!((c.min_critical, c.max_critical), (want, want), "n = {n}");
            assert!(s.polygons.iter().all(|p| p.vertices.len() == n as usize));
            assert!(s
                .polygons
                .iter()
                .all(|p| simplicity_fault(&p.vertices).is_none()));
            s.validate().unwrap();
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_scene() {
        let a = generate(&spec(Family::Few, 50..=90)).unwrap();
        let b = generate(&spec(Family::Few, 50..=90)).unwrap();
        assert_eq!(a, b);
        let c = generate(&BenchSpec {
            seed: 8,
            ..spec(Family::Few, 50..=90)
        })
        .unwrap();
        assert_ne!(a.0, c.0);
    }

    #[test]
    fn bad_specs_are_refused() {
        assert_eq!(parse_vertices("100..=1000"), Ok(100..=1000));
        assert_eq!(parse_vertices("100..1000"), Ok(100..=999));
        assert_eq!(parse_vertices("7"), Ok(7..=7));
        assert!(parse_vertices("10..5").unwrap_err().contains("empty"));
        assert!(parse_vertices("10..10").unwrap_err().contains("10..=10"));
        assert!(parse_vertices("10..=5").unwrap_err().contains("empty"));
        assert!(parse_vertices("10..").is_err());
        assert!(parse_vertices("3").unwrap_err().contains("must lie"));
        assert!(parse_vertices("x").unwrap_err().contains("A..B"));
        let e = generate(&BenchSpec {
            polygons: 0,
            ..spec(Family::Convex, 5..=5)
        })
        .unwrap_err();
        assert!(e.contains("--polygons"));
    }
}
