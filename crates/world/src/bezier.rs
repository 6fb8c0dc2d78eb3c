//! Bicubic Bézier patches: the Utah teapot and any other surface given as 4×4 control
//! points, evaluated exactly (point, partial derivatives, unit normal, subdivision and
//! control-point bounds, as the Nishita renderer's Bézier clipping will need) and
//! tessellated into triangle grids for the polygon renderers.
//!
//! Conventions: a [`Patch`] holds its control points as `points[row][col]`; the
//! parameter `u` runs along a row (the column index grows with `u`) and `v` runs down
//! the rows (the row index grows with `v`), both over `[0, 1]`:
//! `S(u, v) = Σ_row Σ_col B_row(v) · B_col(u) · points[row][col]` with the cubic
//! Bernstein polynomials `B_k`. The normal is `∂S/∂u × ∂S/∂v`, normalized: seen from
//! the side it points to, `u` grows to the right and `v` upward. On Newell's teapot
//! ([`patches_from`] on `tests/data/teapot-spd.json`, the project's copy of `shared/data/teapot-spd.json`) that is outward on every patch.
//!
//! Degenerate patches: the teapot's lid top and bottom collapse a whole row of control
//! points to one point (a pole), where `∂S/∂u` vanishes; [`Patch::normal`] takes the
//! limit of the normal there from higher-order terms (see its documentation).
//!
//! [`tessellate`] evaluates the four boundary curves with a 1D evaluator that does not
//! depend on the direction the curve is traversed in, so two patches that share a
//! boundary curve (same four control points, in the same or the reverse order) produce
//! bit-identical points along it: the triangles of neighbouring patches leave no cracks.

use glam::DVec3;

/// One bicubic Bézier patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    /// The control points, `points[row][col]`: `u` runs along a row (with `col`), `v`
    /// down the rows (with `row`). The corners are `S(0,0) = points[0][0]`,
    /// `S(1,0) = points[0][3]`, `S(0,1) = points[3][0]` and `S(1,1) = points[3][3]`.
    pub points: [[DVec3; 4]; 4],
}

/// Relative size (to the patch's control-point box diagonal `L`, squared for a cross
/// product) under which a normal or a derivative counts as vanishing. See
/// [`Patch::normal`] for why this value.
const VANISHING: f64 = 1e-8;

/// `3! / (3 − a)!`: the factor of an `a`-th derivative of a cubic in Bernstein form.
const FALLING: [f64; 4] = [1.0, 3.0, 6.0, 6.0];

/// The Bernstein polynomials of degree `d` (≤ 3) at `t`, in the first `d + 1` entries.
fn bernstein(d: usize, t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    let mut b = [1.0, 0.0, 0.0, 0.0];
    for r in 1..=d {
        for j in (1..=r).rev() {
            b[j] = s * b[j] + t * b[j - 1];
        }
        b[0] *= s;
    }
    b
}

/// The binomial coefficient `C(n, k)` for small `n`.
fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64)
}

/// One step of de Casteljau's construction.
fn lerp(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    a + (b - a) * t
}

/// The cubic Bézier curve on `c` at `t`, by de Casteljau's construction.
fn casteljau(c: [DVec3; 4], t: f64) -> DVec3 {
    let q = [
        lerp(c[0], c[1], t),
        lerp(c[1], c[2], t),
        lerp(c[2], c[3], t),
    ];
    let r = [lerp(q[0], q[1], t), lerp(q[1], q[2], t)];
    lerp(r[0], r[1], t)
}

/// Whether two points have the same bits (so `-0.0` and `0.0` differ).
fn same_bits(a: DVec3, b: DVec3) -> bool {
    a.to_array()
        .iter()
        .zip(b.to_array())
        .all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The cubic Bézier curve on `c` at the parameter `i / n` (`0 ≤ i ≤ n`, `n ≥ 1`),
/// computed so that the result does not depend on the direction of the curve:
/// `curve_at(c, i, n)` and `curve_at(reversed c, n − i, n)` have the same bits.
///
/// The ends are the end control points themselves; a curve collapsed to one point (all
/// four control points the same bits) is that point; otherwise de Casteljau runs from
/// the nearer end, with `t = min(i, n − i) / n` (a choice made on integers, so both
/// directions choose the same end and compute the same `t`), and at the midpoint
/// (`2i = n`) with the symmetric step `(a + b) · 0.5`, which is the same for `(a, b)`
/// and `(b, a)` since floating-point addition commutes.
fn curve_at(c: [DVec3; 4], i: usize, n: usize) -> DVec3 {
    debug_assert!(n >= 1 && i <= n);
    if i == 0 {
        c[0]
    } else if i == n {
        c[3]
    } else if c[1..].iter().all(|&p| same_bits(p, c[0])) {
        c[0]
    } else if 2 * i == n {
        let mid = |a: DVec3, b: DVec3| (a + b) * 0.5;
        let q = [mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[3])];
        let r = [mid(q[0], q[1]), mid(q[1], q[2])];
        mid(r[0], r[1])
    } else if 2 * i < n {
        casteljau(c, i as f64 / n as f64)
    } else {
        casteljau([c[3], c[2], c[1], c[0]], (n - i) as f64 / n as f64)
    }
}

/// Splits the cubic on `c` at `t` by de Casteljau: the halves over `[0, t]` and
/// `[t, 1]`, each reparameterized to `[0, 1]`.
fn split_curve(c: [DVec3; 4], t: f64) -> ([DVec3; 4], [DVec3; 4]) {
    let q = [
        lerp(c[0], c[1], t),
        lerp(c[1], c[2], t),
        lerp(c[2], c[3], t),
    ];
    let r = [lerp(q[0], q[1], t), lerp(q[1], q[2], t)];
    let s = lerp(r[0], r[1], t);
    ([c[0], q[0], r[0], s], [s, r[1], q[2], c[3]])
}

impl Patch {
    /// The patch with these control points (`points[row][col]`).
    pub fn new(points: [[DVec3; 4]; 4]) -> Patch {
        Patch { points }
    }

    /// Row `r` of control points (the curve `v = r/3` is not this row unless `r` is 0
    /// or 3; rows 0 and 3 are the boundary curves `v = 0` and `v = 1`).
    fn row(&self, r: usize) -> [DVec3; 4] {
        self.points[r]
    }

    /// Column `c` of control points (columns 0 and 3 are the boundary curves `u = 0`
    /// and `u = 1`).
    fn col(&self, c: usize) -> [DVec3; 4] {
        [0, 1, 2, 3].map(|r| self.points[r][c])
    }

    /// The point `S(u, v)`, by de Casteljau's construction (each row at `u`, then the
    /// four results at `v`).
    pub fn point(&self, u: f64, v: f64) -> DVec3 {
        casteljau([0, 1, 2, 3].map(|r| casteljau(self.row(r), u)), v)
    }

    /// The partial derivative `∂^(a+b) S / ∂u^a ∂v^b` at `(u, v)`: `a`-th forward
    /// differences of the control points along the rows and `b`-th down the columns,
    /// weighted by the Bernstein polynomials of degrees `3 − a` and `3 − b`. Zero when
    /// `a` or `b` exceeds 3. Differences of equal control points are exactly zero, so a
    /// collapsed row gives exactly `∂S/∂u = 0` along it.
    fn partial(&self, u: f64, v: f64, a: usize, b: usize) -> DVec3 {
        if a > 3 || b > 3 {
            return DVec3::ZERO;
        }
        let mut q = self.points;
        for level in 0..a {
            for row in q.iter_mut() {
                for j in 0..3 - level {
                    row[j] = row[j + 1] - row[j];
                }
            }
        }
        for level in 0..b {
            for i in 0..3 - level {
                let next = q[i + 1];
                for (p, n) in q[i].iter_mut().zip(next).take(4 - a) {
                    *p = n - *p;
                }
            }
        }
        let (bu, bv) = (bernstein(3 - a, u), bernstein(3 - b, v));
        let mut sum = DVec3::ZERO;
        for (i, row) in q.iter().enumerate().take(4 - b) {
            let mut r = DVec3::ZERO;
            for (j, p) in row.iter().enumerate().take(4 - a) {
                r += *p * bu[j];
            }
            sum += r * bv[i];
        }
        sum * (FALLING[a] * FALLING[b])
    }

    /// The partial derivative `∂S/∂u` at `(u, v)`: [`Patch::partial`]`(u, v, 1, 0)`,
    /// the same operations in the same order (so the same bits) without copying the
    /// control points — every piece corner's normal takes one.
    pub fn du(&self, u: f64, v: f64) -> DVec3 {
        let (bu, bv) = (bernstein(2, u), bernstein(3, v));
        let mut sum = DVec3::ZERO;
        for (row, weight) in self.points.iter().zip(bv) {
            let mut r = DVec3::ZERO;
            for j in 0..3 {
                r += (row[j + 1] - row[j]) * bu[j];
            }
            sum += r * weight;
        }
        sum * (FALLING[1] * FALLING[0])
    }

    /// The partial derivative `∂S/∂v` at `(u, v)`: [`Patch::partial`]`(u, v, 0, 1)`,
    /// the same operations in the same order, as [`Patch::du`].
    pub fn dv(&self, u: f64, v: f64) -> DVec3 {
        let (bu, bv) = (bernstein(3, u), bernstein(2, v));
        let mut sum = DVec3::ZERO;
        for (i, weight) in bv.into_iter().take(3).enumerate() {
            let (row, next) = (&self.points[i], &self.points[i + 1]);
            let mut r = DVec3::ZERO;
            for j in 0..4 {
                r += (next[j] - row[j]) * bu[j];
            }
            sum += r * weight;
        }
        sum * (FALLING[0] * FALLING[1])
    }

    /// The unit normal at `(u, v)`: `∂S/∂u × ∂S/∂v` normalized (seen from the side it
    /// points to, `u` grows to the right and `v` upward).
    ///
    /// Where that cross product vanishes — at a pole, where a whole boundary row (or
    /// column) of control points collapses to one point and `∂S/∂u` (or `∂S/∂v`) is
    /// exactly zero along it — the normal is the limit of the normal as the point is
    /// approached from inside the patch, along a straight line in parameter space:
    /// along `v` at fixed `u` when `∂S/∂u` is the smaller derivative (a collapsed row),
    /// along `u` at fixed `v` when `∂S/∂v` is (a collapsed column), and along the
    /// diagonal toward the patch's centre when both vanish. On that line
    /// `(u, v) + h·(α, β)`, `h ≥ 0`, the cross product `C(h) = S_u × S_v` is a polynomial
    /// in `h` (degree ≤ 10), so its direction as `h → 0⁺` is exactly the direction of its
    /// first non-vanishing Taylor coefficient
    /// `c_k = (1/k!) Σ_m C(k,m) D^m S_u × D^(k−m) S_v` with `D = α∂u + β∂v`, computed
    /// from the patch's exact mixed partials. At a collapsed row (`v = 0`, `S_u ≡ 0`
    /// there) that is `c_1 = S_uv × S_v`: the normal of the first ring of the patch
    /// around the pole, in the limit.
    ///
    /// "Vanishing" is relative to the diagonal `L` of the control points' box: a
    /// coefficient counts when it exceeds `1e-8 · L²`. That balances the two errors near
    /// a pole at parameter distance `δ`: `S_u × S_v` itself carries a rounding error of
    /// about `1e-16 / δ` in its direction, the limit differs from the true normal by
    /// about `δ`; switching at `|S_u × S_v| ≈ 1e-8 · L²` (`δ ≈ 1e-8`) keeps both near
    /// `1e-8`.
    ///
    /// `None` only where the surface is genuinely degenerate: every Taylor coefficient
    /// vanishes (e.g. all control points collinear, or all the same point).
    pub fn normal(&self, u: f64, v: f64) -> Option<DVec3> {
        let (lo, hi) = self.bounds();
        let l2 = (hi - lo).length_squared();
        if !(l2 > 0.0 && l2.is_finite()) {
            return None;
        }
        let (su, sv) = (self.du(u, v), self.dv(u, v));
        let c0 = su.cross(sv);
        let enough = VANISHING * l2;
        if c0.length() > enough {
            return Some(c0.normalize());
        }
        // the limit along a line into the patch
        let inward = |t: f64| if t <= 0.5 { 1.0 } else { -1.0 };
        let small = VANISHING * l2.sqrt();
        let (alpha, beta): (f64, f64) = if su.length() <= small && sv.length() <= small {
            (inward(u), inward(v))
        } else if su.length() <= sv.length() {
            (0.0, inward(v))
        } else {
            (inward(u), 0.0)
        };
        let mut d = [[DVec3::ZERO; 5]; 5];
        for (a, row) in d.iter_mut().enumerate() {
            for (b, p) in row.iter_mut().enumerate() {
                *p = self.partial(u, v, a, b);
            }
        }
        let at = |a: usize, b: usize| {
            if a <= 4 && b <= 4 {
                d[a][b]
            } else {
                DVec3::ZERO
            }
        };
        // D^m applied to S_{u^(1-x) v^x}: Σ_r C(m,r) α^r β^(m−r) S_{u^(r+du) v^(m−r+dv)}
        let directional = |m: usize, du: usize, dv: usize| -> DVec3 {
            (0..=m)
                .map(|r| {
                    at(r + du, m - r + dv)
                        * (binomial(m, r) * alpha.powi(r as i32) * beta.powi((m - r) as i32))
                })
                .sum()
        };
        let mut factorial = 1.0;
        for k in 1..=10 {
            factorial *= k as f64;
            let c: DVec3 = (0..=k)
                .map(|m| binomial(k, m) * directional(m, 1, 0).cross(directional(k - m, 0, 1)))
                .sum::<DVec3>()
                / factorial;
            if c.length() > enough {
                return Some(c.normalize());
            }
        }
        None
    }

    /// Splits the patch at `u = t`: the parts over `u ∈ [0, t]` and `u ∈ [t, 1]`, each
    /// reparameterized to `[0, 1]` (`left.point(u, v) = self.point(t·u, v)`,
    /// `right.point(u, v) = self.point(t + (1 − t)·u, v)`), by de Casteljau on each row.
    pub fn split_u(&self, t: f64) -> (Patch, Patch) {
        let mut left = *self;
        let mut right = *self;
        for r in 0..4 {
            (left.points[r], right.points[r]) = split_curve(self.row(r), t);
        }
        (left, right)
    }

    /// Splits the patch at `v = t`: the parts over `v ∈ [0, t]` and `v ∈ [t, 1]`, each
    /// reparameterized to `[0, 1]`, by de Casteljau on each column.
    pub fn split_v(&self, t: f64) -> (Patch, Patch) {
        let mut top = *self;
        let mut bottom = *self;
        for c in 0..4 {
            let (a, b) = split_curve(self.col(c), t);
            for r in 0..4 {
                top.points[r][c] = a[r];
                bottom.points[r][c] = b[r];
            }
        }
        (top, bottom)
    }

    /// The box of the control points, `(min, max)` per coordinate. The patch lies inside
    /// it (a Bézier patch lies in the convex hull of its control points).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.points.iter().flatten().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }
}

/// A patch tessellated into an `(n + 1) × (n + 1)` grid of vertices and its triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Divisions per side (`n`).
    pub n: usize,
    /// The vertices, row by row: vertex `(i, k)` (at `u = i/n`, `v = k/n`) is at index
    /// [`Grid::index`]`(i, k) = k·(n + 1) + i`.
    pub points: Vec<DVec3>,
    /// The unit normal at each vertex ([`Patch::normal`], with its pole limit). Where the
    /// patch is genuinely degenerate ([`Patch::normal`] is `None`) it is the mean of the
    /// normals of the grid's triangles at that vertex, and zero if they have no area
    /// either.
    pub normals: Vec<DVec3>,
    /// Triangles as indices into `points`, counter-clockwise seen from the side the
    /// normals point to: each grid quad `a = (i, k)`, `b = (i+1, k)`, `c = (i+1, k+1)`,
    /// `d = (i, k+1)` gives `[a, b, c]` and `[a, c, d]`, minus any of the two that is
    /// degenerate (zero area, as at a collapsed pole, by the test the mesh builder
    /// applies: twice its area at most `1e-12` times its largest squared edge from the
    /// first corner).
    pub triangles: Vec<[u32; 3]>,
}

impl Grid {
    /// The index in [`Grid::points`] of vertex `(i, k)`, at `u = i/n`, `v = k/n`.
    pub fn index(&self, i: usize, k: usize) -> usize {
        k * (self.n + 1) + i
    }
}

/// Tessellates a patch into an `(n + 1) × (n + 1)` grid at `u = i/n`, `v = k/n`.
///
/// Shared boundaries are watertight: the four boundary curves (rows 0 and 3, columns 0
/// and 3 of the control points) are evaluated by a 1D evaluator whose result does not
/// depend on the direction of the curve (the corners are the corner control points;
/// de Casteljau runs from the nearer end, with a parameter computed from the integers
/// `min(i, n − i)` and `n`; the midpoint uses a symmetric step), so two patches whose
/// boundaries have the same four control points, in the same or the reverse order, give
/// bit-identical vertices along them. Interior vertices use [`Patch::point`].
///
/// # Panics
///
/// If `n` is 0 or the grid would have more than `u32::MAX` vertices.
pub fn tessellate(patch: &Patch, n: usize) -> Grid {
    assert!(n >= 1, "a tessellation needs at least 1 division per side");
    let side = n + 1;
    assert!(
        side.checked_mul(side)
            .is_some_and(|c| c <= u32::MAX as usize),
        "{n} divisions per side give too many vertices"
    );
    let (row0, row3, col0, col3) = (patch.row(0), patch.row(3), patch.col(0), patch.col(3));
    let mut points = Vec::with_capacity(side * side);
    let mut normals = Vec::with_capacity(side * side);
    let mut missing = Vec::new();
    for k in 0..=n {
        for i in 0..=n {
            let p = if k == 0 {
                curve_at(row0, i, n)
            } else if k == n {
                curve_at(row3, i, n)
            } else if i == 0 {
                curve_at(col0, k, n)
            } else if i == n {
                curve_at(col3, k, n)
            } else {
                patch.point(i as f64 / n as f64, k as f64 / n as f64)
            };
            points.push(p);
            let normal = patch.normal(i as f64 / n as f64, k as f64 / n as f64);
            if normal.is_none() {
                missing.push(points.len() - 1);
            }
            normals.push(normal.unwrap_or(DVec3::ZERO));
        }
    }
    let mut triangles = Vec::with_capacity(2 * n * n);
    for k in 0..n {
        for i in 0..n {
            let a = (k * side + i) as u32;
            let (b, c, d) = (a + 1, a + 1 + side as u32, a + side as u32);
            for t in [[a, b, c], [a, c, d]] {
                let [p, q, r] = t.map(|x| points[x as usize]);
                let area2 = (q - p).cross(r - p).length();
                let scale = (q - p).length_squared().max((r - p).length_squared());
                if scale > 0.0 && area2 > 1e-12 * scale {
                    triangles.push(t);
                }
            }
        }
    }
    if !missing.is_empty() {
        let mut sums = vec![DVec3::ZERO; points.len()];
        for t in &triangles {
            let [p, q, r] = t.map(|x| points[x as usize]);
            let face = (q - p).cross(r - p);
            for x in t {
                sums[*x as usize] += face;
            }
        }
        for x in missing {
            normals[x] = sums[x].normalize_or_zero();
        }
    }
    Grid {
        n,
        points,
        normals,
        triangles,
    }
}

/// Builds patches from control points and 4×4 index lists (row-major: entry `j` is
/// `points[j / 4][j % 4]`), the shape of `tests/data/teapot-spd.json`'s `vertices` and
/// `patches`.
///
/// Errors name the fault: an index out of range (patch `k`, entry `j`), or a vertex that
/// is not finite.
pub fn patches_from(vertices: &[[f64; 3]], patches: &[[usize; 16]]) -> Result<Vec<Patch>, String> {
    if let Some((i, v)) = vertices
        .iter()
        .enumerate()
        .find(|(_, v)| !v.iter().all(|c| c.is_finite()))
    {
        return Err(format!("vertex {i} is not finite: {v:?}"));
    }
    patches
        .iter()
        .enumerate()
        .map(|(k, indices)| {
            let mut points = [[DVec3::ZERO; 4]; 4];
            for (j, &index) in indices.iter().enumerate() {
                let v = vertices.get(index).ok_or_else(|| {
                    format!(
                        "patch {k}, entry {j} (row {}, column {}): vertex index {index} is out of range: there are {} vertices (indices from 0)",
                        j / 4,
                        j % 4,
                        vertices.len()
                    )
                })?;
                points[j / 4][j % 4] = DVec3::from_array(*v);
            }
            Ok(Patch { points })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Deserialize)]
    struct Teapot {
        vertices: Vec<[f64; 3]>,
        patches: Vec<[usize; 16]>,
        patch_groups: Vec<String>,
    }

    /// The project's copy of `shared/data/teapot-spd.json` (public domain), so that the
    /// tests read nothing outside the repository.
    const TEAPOT: &str = include_str!("../tests/data/teapot-spd.json");

    fn teapot_data() -> Teapot {
        serde_json::from_str(TEAPOT).unwrap()
    }

    fn teapot() -> Vec<Patch> {
        let t = teapot_data();
        patches_from(&t.vertices, &t.patches).unwrap()
    }

    /// splitmix64: a small deterministic generator for the random patches.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 53) as f64
        }

        /// In `[-1, 1)`.
        fn coord(&mut self) -> f64 {
            2.0 * self.next() - 1.0
        }

        fn point(&mut self) -> DVec3 {
            DVec3::new(self.coord(), self.coord(), self.coord())
        }

        fn patch(&mut self) -> Patch {
            let mut points = [[DVec3::ZERO; 4]; 4];
            for p in points.iter_mut().flatten() {
                *p = self.point();
            }
            Patch { points }
        }
    }

    #[test]
    fn the_teapot_data_is_32_patches_on_290_vertices_each_used() {
        let t = teapot_data();
        assert_eq!(t.vertices.len(), 290);
        assert_eq!(t.patches.len(), 32);
        assert_eq!(t.patch_groups.len(), 32);
        let mut used = vec![0usize; t.vertices.len()];
        for (k, p) in t.patches.iter().enumerate() {
            for (j, &i) in p.iter().enumerate() {
                assert!(i < t.vertices.len(), "patch {k} entry {j}: {i}");
                used[i] += 1;
            }
        }
        let unused: Vec<usize> = (0..used.len()).filter(|&i| used[i] == 0).collect();
        assert!(unused.is_empty(), "unused vertices {unused:?}");
        assert_eq!(teapot().len(), 32);
    }

    #[test]
    fn a_flat_patch_is_its_bilinear_map_with_the_planes_normal() {
        // four corners on the plane z = 0.5x + 0.25y + 1, not a parallelogram; control
        // points uniformly spaced by the bilinear map (a degree-elevated bilinear patch)
        let plane = |x: f64, y: f64| DVec3::new(x, y, 0.5 * x + 0.25 * y + 1.0);
        let (c00, c10, c01, c11) = (
            plane(0.0, 0.0),
            plane(2.0, 0.5),
            plane(-0.5, 1.5),
            plane(3.0, 3.0),
        );
        // c10 is at u = 1, v = 0
        let bilinear = |u: f64, v: f64| {
            (c00 * (1.0 - u) + c10 * u) * (1.0 - v) + (c01 * (1.0 - u) + c11 * u) * v
        };
        let mut points = [[DVec3::ZERO; 4]; 4];
        for (r, row) in points.iter_mut().enumerate() {
            for (c, p) in row.iter_mut().enumerate() {
                *p = bilinear(c as f64 / 3.0, r as f64 / 3.0);
            }
        }
        let patch = Patch::new(points);
        // du × dv = (c10 − c00) × (c01 − c00) at (0, 0): (2, .5, 1.125) × (−.5, 1.5, .125)
        // has z = 3.25 > 0, so the normal is the upward plane normal (−0.5, −0.25, 1)
        let up = DVec3::new(-0.5, -0.25, 1.0).normalize();
        for k in 0..=10 {
            for i in 0..=10 {
                let (u, v) = (i as f64 / 10.0, k as f64 / 10.0);
                let p = patch.point(u, v);
                assert!((p - bilinear(u, v)).length() < 1e-14, "{u} {v}: {p}");
                let du = (c10 - c00) * (1.0 - v) + (c11 - c01) * v;
                let dv = (c01 - c00) * (1.0 - u) + (c11 - c10) * u;
                assert!((patch.du(u, v) - du).length() < 1e-13, "{u} {v}");
                assert!((patch.dv(u, v) - dv).length() < 1e-13, "{u} {v}");
                let n = patch.normal(u, v).unwrap();
                assert!((n - up).length() < 1e-14, "{u} {v}: {n}");
            }
        }
        let g = tessellate(&patch, 4);
        assert_eq!(g.points.len(), 25);
        assert_eq!(g.triangles.len(), 32);
        for t in &g.triangles {
            let [p, q, r] = t.map(|x| g.points[x as usize]);
            assert!(
                (q - p).cross(r - p).dot(up) > 0.0,
                "counter-clockwise from the front"
            );
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        // coordinates in [−1, 1]: a third derivative is 6·(third differences) ≤ 6·8 = 48
        // per coordinate, so the central difference's truncation error h²/6·|S'''| is
        // ≤ 8e-10 at h = 1e-5, and its rounding error about 1e-16·|S|/h ≈ 1e-11; 1e-8
        // leaves a margin of 10 and still catches a wrong factor or index at once
        // (derivatives here are of order 1)
        let mut rng = Rng(7);
        let h = 1e-5;
        for _ in 0..50 {
            let patch = rng.patch();
            for _ in 0..20 {
                let (u, v) = (
                    h + (1.0 - 2.0 * h) * rng.next(),
                    h + (1.0 - 2.0 * h) * rng.next(),
                );
                let du = (patch.point(u + h, v) - patch.point(u - h, v)) / (2.0 * h);
                let dv = (patch.point(u, v + h) - patch.point(u, v - h)) / (2.0 * h);
                assert!((patch.du(u, v) - du).length() < 1e-8, "{u} {v}");
                assert!((patch.dv(u, v) - dv).length() < 1e-8, "{u} {v}");
                // the mixed and higher partials the pole limit uses, against differences
                // of the first derivatives (same error budget)
                let duv = (patch.du(u, v + h) - patch.du(u, v - h)) / (2.0 * h);
                let dvv = (patch.dv(u, v + h) - patch.dv(u, v - h)) / (2.0 * h);
                let dvvv =
                    (patch.partial(u, v + h, 0, 2) - patch.partial(u, v - h, 0, 2)) / (2.0 * h);
                assert!((patch.partial(u, v, 1, 1) - duv).length() < 1e-8);
                assert!((patch.partial(u, v, 0, 2) - dvv).length() < 1e-8);
                assert!((patch.partial(u, v, 0, 3) - dvvv).length() < 1e-8);
                assert_eq!(patch.partial(u, v, 0, 4), DVec3::ZERO);
                let n = patch.normal(u, v).unwrap();
                let c = patch.du(u, v).cross(patch.dv(u, v));
                assert!((n - c.normalize()).length() < 1e-12);
            }
        }
    }

    #[test]
    fn first_derivatives_are_the_general_partial_bit_for_bit() {
        // du and dv skip partial's copy of the control points; the teapot's corners
        // (poles included: exact zeros) and random patches give the same bits
        let mut rng = Rng(11);
        let patches: Vec<Patch> = (0..50).map(|_| rng.patch()).chain(teapot()).collect();
        for patch in &patches {
            for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)]
                .into_iter()
                .chain((0..20).map(|_| (rng.next(), rng.next())))
            {
                for (fast, general) in [
                    (patch.du(u, v), patch.partial(u, v, 1, 0)),
                    (patch.dv(u, v), patch.partial(u, v, 0, 1)),
                ] {
                    assert_eq!(
                        fast.to_array().map(f64::to_bits),
                        general.to_array().map(f64::to_bits)
                    );
                }
            }
        }
    }

    #[test]
    fn split_halves_reproduce_the_surface() {
        let mut rng = Rng(11);
        for _ in 0..20 {
            let patch = rng.patch();
            let t = 0.05 + 0.9 * rng.next();
            let (l, r) = patch.split_u(t);
            let (top, bottom) = patch.split_v(t);
            for k in 0..=8 {
                for i in 0..=8 {
                    let (u, v) = (i as f64 / 8.0, k as f64 / 8.0);
                    let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
                    assert!(close(l.point(u, v), patch.point(t * u, v)), "{t} {u} {v}");
                    assert!(close(r.point(u, v), patch.point(t + (1.0 - t) * u, v)));
                    assert!(close(top.point(u, v), patch.point(u, t * v)));
                    assert!(close(bottom.point(u, v), patch.point(u, t + (1.0 - t) * v)));
                }
            }
            // the halves' boxes lie in the whole's, and cover the split point
            let (lo, hi) = patch.bounds();
            for half in [l, r, top, bottom] {
                let (a, b) = half.bounds();
                assert!(a.cmpge(lo).all() && b.cmple(hi).all());
            }
            let s = patch.point(t, 0.3);
            let (a, b) = l.bounds();
            assert!(s.cmpge(a - 1e-12).all() && s.cmple(b + 1e-12).all());
        }
    }

    #[test]
    fn bounds_are_the_control_point_box() {
        let mut rng = Rng(3);
        let patch = rng.patch();
        let (lo, hi) = patch.bounds();
        let all: Vec<DVec3> = patch.points.iter().flatten().copied().collect();
        for axis in 0..3 {
            let min = all.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
            let max = all
                .iter()
                .map(|p| p[axis])
                .fold(f64::NEG_INFINITY, f64::max);
            assert_eq!((lo[axis], hi[axis]), (min, max));
        }
        for k in 0..=6 {
            for i in 0..=6 {
                let p = patch.point(i as f64 / 6.0, k as f64 / 6.0);
                assert!(p.cmpge(lo).all() && p.cmple(hi).all());
            }
        }
    }

    /// The boundary curves of a patch, as (edge, control points in the grid's order):
    /// 0 = row 0 (`v = 0`, along `u`), 1 = row 3 (`v = 1`), 2 = column 0 (`u = 0`, along
    /// `v`), 3 = column 3 (`u = 1`).
    fn edges(p: &Patch) -> [[DVec3; 4]; 4] {
        [p.row(0), p.row(3), p.col(0), p.col(3)]
    }

    /// The grid index of the `t`-th vertex (`0..=n`) along edge `e`.
    fn edge_vertex(g: &Grid, e: usize, t: usize) -> usize {
        let n = g.n;
        match e {
            0 => g.index(t, 0),
            1 => g.index(t, n),
            2 => g.index(0, t),
            _ => g.index(n, t),
        }
    }

    fn bits(p: DVec3) -> [u64; 3] {
        p.to_array().map(f64::to_bits)
    }

    /// Every pair of patch boundaries with the same four control points: `(patch,
    /// edge, patch, edge, reversed)`.
    fn shared_edges(patches: &[Patch]) -> Vec<(usize, usize, usize, usize, bool)> {
        let key = |c: &[DVec3; 4]| c.map(bits);
        let mut out = Vec::new();
        for (a, pa) in patches.iter().enumerate() {
            for (b, pb) in patches.iter().enumerate().skip(a + 1) {
                for (ea, ca) in edges(pa).iter().enumerate() {
                    for (eb, cb) in edges(pb).iter().enumerate() {
                        let mut rev = *cb;
                        rev.reverse();
                        if key(ca) == key(cb) {
                            out.push((a, ea, b, eb, false));
                        } else if key(ca) == key(&rev) {
                            out.push((a, ea, b, eb, true));
                        }
                    }
                }
            }
        }
        out
    }

    fn assert_watertight(
        patches: &[Patch],
        shared: &[(usize, usize, usize, usize, bool)],
        n: usize,
    ) {
        let grids: Vec<Grid> = patches.iter().map(|p| tessellate(p, n)).collect();
        for &(a, ea, b, eb, reversed) in shared {
            for t in 0..=n {
                let s = if reversed { n - t } else { t };
                let (pa, pb) = (
                    grids[a].points[edge_vertex(&grids[a], ea, t)],
                    grids[b].points[edge_vertex(&grids[b], eb, s)],
                );
                assert_eq!(
                    bits(pa),
                    bits(pb),
                    "n = {n}: patch {a} edge {ea} vertex {t} = {pa:?}, patch {b} edge {eb} vertex {s} = {pb:?}"
                );
            }
        }
    }

    #[test]
    fn the_teapot_tessellation_is_watertight() {
        let patches = teapot();
        let shared = shared_edges(&patches);
        let collapsed = |(a, ea, _, _, _): &(usize, usize, usize, usize, bool)| {
            let c = edges(&patches[*a])[*ea];
            c.iter().all(|p| *p == c[0])
        };
        // The teapot has 52 shared boundary curves, each between exactly two patches (4
        // of them reversed: the body's bottom rows against Crow's bottom patches), plus
        // the two poles — the lid top and the bottom centre, a collapsed row shared by 4
        // patches each, 2 × 6 pairs. The other 16 boundaries are open (the rim's inner
        // edge, the lid's outer edge, the ends of the handle and the spout).
        let curves: Vec<_> = shared.iter().filter(|s| !collapsed(s)).collect();
        assert_eq!(curves.len(), 52);
        assert_eq!(curves.iter().filter(|s| s.4).count(), 4);
        assert_eq!(shared.len() - curves.len(), 12);
        let mut per_patch_edge = std::collections::HashMap::new();
        for &(a, ea, b, eb, _) in &shared {
            *per_patch_edge.entry((a, ea)).or_insert(0) += 1;
            *per_patch_edge.entry((b, eb)).or_insert(0) += 1;
        }
        assert_eq!(per_patch_edge.len(), 32 * 4 - 16);
        for n in [1, 3, 8, 16] {
            assert_watertight(&patches, &shared, n);
        }
    }

    #[test]
    fn reversed_shared_edges_meet_bit_for_bit_at_any_division() {
        // patches with random control points, glued along every pairing of their four
        // boundaries, in both directions
        let mut rng = Rng(99);
        let mut naive_cracks = 0;
        for _ in 0..4 {
            let a = rng.patch();
            for ea in 0..4 {
                for eb in 0..4 {
                    for reversed in [false, true] {
                        let mut c = edges(&a)[ea];
                        if reversed {
                            c.reverse();
                        }
                        let mut b = rng.patch();
                        for (r, p) in c.iter().enumerate() {
                            match eb {
                                0 => b.points[0][r] = *p,
                                1 => b.points[3][r] = *p,
                                2 => b.points[r][0] = *p,
                                _ => b.points[r][3] = *p,
                            }
                        }
                        let pair = [a, b];
                        for n in [1, 2, 3, 5, 7, 10, 16, 49] {
                            assert_watertight(&pair, &[(0, ea, 1, eb, reversed)], n);
                        }
                        // the problem is real: plain evaluation (Patch::point at u = i/n
                        // on one side, u = (n − i)/n on the reversed other) does crack
                        if reversed && ea == 0 && eb == 0 {
                            let n = 7;
                            for t in 0..=n {
                                let pa = a.point(t as f64 / n as f64, 0.0);
                                let pb = b.point((n - t) as f64 / n as f64, 0.0);
                                naive_cracks += usize::from(bits(pa) != bits(pb));
                            }
                        }
                    }
                }
            }
        }
        assert!(
            naive_cracks > 0,
            "the test would not tell a naive evaluator apart"
        );
    }

    #[test]
    fn pole_normals_are_the_limit_of_the_ring_around() {
        let patches = teapot();
        let groups = teapot_data().patch_groups;
        // lid top 20..=23 and bottom 28..=31: row 0 collapsed, ∂S/∂u = 0 there
        let poles: Vec<usize> = (0..32)
            .filter(|&k| {
                let r = patches[k].points[0];
                r.iter().all(|p| *p == r[0])
            })
            .collect();
        assert_eq!(poles, [20, 21, 22, 23, 28, 29, 30, 31]);
        let n = 16;
        for &k in &poles {
            let patch = &patches[k];
            let expected = if groups[k] == "lid" {
                DVec3::Z
            } else {
                -DVec3::Z
            };
            let g = tessellate(patch, n);
            for i in 0..=n {
                let u = i as f64 / n as f64;
                assert_eq!(patch.du(u, 0.0), DVec3::ZERO, "patch {k}: a real pole");
                let m = patch.normal(u, 0.0).unwrap();
                assert!(m.is_finite() && (m.length() - 1.0).abs() < 1e-12);
                // the lid's knob top and the bottom are flat: the limit is ±z
                assert!((m - expected).length() < 1e-12, "patch {k} at u = {u}: {m}");
                // and it is the limit: the normal just inside agrees
                let inside = patch.du(u, 1e-6).cross(patch.dv(u, 1e-6)).normalize();
                assert!((m - inside).length() < 1e-5, "patch {k}: {m} vs {inside}");
                let (pole, ring) = (g.normals[g.index(i, 0)], g.normals[g.index(i, 1)]);
                assert_eq!(pole, m);
                assert!(
                    pole.dot(ring) > 0.9,
                    "patch {k} vertex {i}: {pole} vs {ring}"
                );
            }
            // the pole's quads lose their degenerate triangle
            assert_eq!(g.triangles.len(), 2 * n * n - n, "patch {k}");
        }
    }

    #[test]
    fn a_cone_apex_and_a_collapsed_column_take_their_own_limits() {
        // a cone: row 0 collapsed to the apex, the other rows circles-ish around z; the
        // limit along v at fixed u is the normal of that generator line, which differs
        // with u (the apex is a true cone point, not a smooth pole)
        let ring = |r: f64, z: f64| {
            [
                DVec3::new(r, 0.0, z),
                DVec3::new(r, r, z),
                DVec3::new(0.0, r, z),
                DVec3::new(-r, r, z),
            ]
        };
        // (a negative zero in the apex: the tessellated pole keeps its exact bits)
        let apex = DVec3::new(-0.0, 0.0, 1.0);
        let cone = Patch::new([
            [apex; 4],
            ring(1.0 / 3.0, 2.0 / 3.0),
            ring(2.0 / 3.0, 1.0 / 3.0),
            ring(1.0, 0.0),
        ]);
        for u in [0.0, 0.3, 1.0] {
            let m = cone.normal(u, 0.0).unwrap();
            let inside = cone.du(u, 1e-6).cross(cone.dv(u, 1e-6)).normalize();
            assert!((m - inside).length() < 1e-5, "{u}: {m} vs {inside}");
        }
        assert!((cone.normal(0.0, 0.0).unwrap() - cone.normal(1.0, 0.0).unwrap()).length() > 0.5);
        for n in [2, 3, 8] {
            let g = tessellate(&cone, n);
            for i in 0..=n {
                assert_eq!(
                    bits(g.points[g.index(i, 0)]),
                    bits(apex),
                    "n = {n}, vertex {i}"
                );
            }
            assert_eq!(g.triangles.len(), 2 * n * n - n);
        }
        // the same surface with rows and columns swapped: the pole is column 0 now, the
        // normal flips (u and v trade places) and takes its limit along u
        let mut t = cone;
        for r in 0..4 {
            for c in 0..4 {
                t.points[r][c] = cone.points[c][r];
            }
        }
        for v in [0.0, 0.3, 1.0] {
            let m = t.normal(0.0, v).unwrap();
            assert!((m + cone.normal(v, 0.0).unwrap()).length() < 1e-12, "{v}");
        }
        // and at a pole at v = 1 (rows reversed) the limit is taken from below
        let mut flipped = cone;
        flipped.points.reverse();
        for u in [0.0, 0.5, 1.0] {
            let m = flipped.normal(u, 1.0).unwrap();
            let inside = flipped
                .du(u, 1.0 - 1e-6)
                .cross(flipped.dv(u, 1.0 - 1e-6))
                .normalize();
            assert!((m - inside).length() < 1e-5, "{u}: {m} vs {inside}");
        }
    }

    #[test]
    fn a_degenerate_patch_has_no_normal() {
        // all control points on one line: no tangent plane anywhere
        let mut points = [[DVec3::ZERO; 4]; 4];
        for (r, row) in points.iter_mut().enumerate() {
            for (c, p) in row.iter_mut().enumerate() {
                *p = DVec3::new(1.0, 2.0, -1.0) * ((r * r + c) as f64);
            }
        }
        let line = Patch::new(points);
        for (u, v) in [(0.0, 0.0), (0.5, 0.5), (0.2, 0.9), (1.0, 0.0)] {
            assert_eq!(line.normal(u, v), None, "{u} {v}");
        }
        let g = tessellate(&line, 4);
        assert!(g.triangles.is_empty());
        assert!(g.normals.iter().all(|n| *n == DVec3::ZERO));
        let point = Patch::new([[DVec3::ONE; 4]; 4]);
        assert_eq!(point.normal(0.5, 0.5), None);
    }

    /// The tessellations of some patches as one surface: vertices merged by their bits,
    /// every hole closed by a fan from the centroid of its boundary loop (turned the way
    /// the surface's own triangles run along it). Returns the signed volume enclosed
    /// (`Σ p₀·(p₁ × p₂) / 6`: positive when the triangles run counter-clockwise seen
    /// from outside) and the number of holes; panics if a directed edge is used twice
    /// (triangles of neighbours disagreeing in orientation, or a non-manifold seam).
    fn closed_volume(grids: &[Grid]) -> (f64, usize) {
        use std::collections::HashMap;
        let mut ids: HashMap<[u64; 3], usize> = HashMap::new();
        let mut points = Vec::new();
        let mut tris = Vec::new();
        for g in grids {
            let local: Vec<usize> = g
                .points
                .iter()
                .map(|p| {
                    *ids.entry(bits(*p)).or_insert_with(|| {
                        points.push(*p);
                        points.len() - 1
                    })
                })
                .collect();
            tris.extend(g.triangles.iter().map(|t| t.map(|x| local[x as usize])));
        }
        let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
        for t in &tris {
            for e in 0..3 {
                *directed.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(
            directed.values().all(|&c| c == 1),
            "an edge is used twice in one direction"
        );
        let boundary: Vec<(usize, usize)> = directed
            .keys()
            .filter(|(a, b)| !directed.contains_key(&(*b, *a)))
            .copied()
            .collect();
        // loops: connected components of the boundary edges
        let mut parent: Vec<usize> = (0..points.len()).collect();
        fn root(parent: &mut [usize], mut x: usize) -> usize {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        }
        for &(a, b) in &boundary {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            parent[ra] = rb;
        }
        let mut centroids: HashMap<usize, (DVec3, usize)> = HashMap::new();
        let mut seen = std::collections::HashSet::new();
        for &(a, _) in &boundary {
            if seen.insert(a) {
                let c = centroids
                    .entry(root(&mut parent, a))
                    .or_insert((DVec3::ZERO, 0));
                c.0 += points[a];
                c.1 += 1;
            }
        }
        let volume = |p: DVec3, q: DVec3, r: DVec3| p.dot(q.cross(r)) / 6.0;
        let mut v: f64 = tris
            .iter()
            .map(|t| volume(points[t[0]], points[t[1]], points[t[2]]))
            .sum();
        for &(a, b) in &boundary {
            let (sum, count) = centroids[&root(&mut parent, a)];
            v += volume(sum / count as f64, points[b], points[a]);
        }
        (v, centroids.len())
    }

    #[test]
    fn the_teapot_faces_outward() {
        // Each part, tessellated, its holes capped, encloses a positive volume: its
        // triangles run counter-clockwise seen from outside, and they agree with the
        // normals, so the normals point outward. The pot (rim, body, bottom) has one hole
        // (inside the rim), the lid one (its underside), the handle and the spout two
        // (their ends).
        let patches = teapot();
        let groups = teapot_data().patch_groups;
        let n = 8;
        let grids: Vec<Grid> = patches.iter().map(|p| tessellate(p, n)).collect();
        for g in &grids {
            for t in &g.triangles {
                let [p, q, r] = t.map(|x| g.points[x as usize]);
                let mean: DVec3 = t.iter().map(|&x| g.normals[x as usize]).sum();
                assert!((q - p).cross(r - p).dot(mean) > 0.0);
            }
        }
        let part = |names: &[&str]| -> Vec<Grid> {
            (0..32)
                .filter(|&k| names.contains(&groups[k].as_str()))
                .map(|k| grids[k].clone())
                .collect()
        };
        for (names, holes, min_volume) in [
            (&["rim", "body", "bottom"][..], 1, 10.0),
            (&["lid"][..], 1, 0.5),
            (&["handle"][..], 2, 0.05),
            (&["spout"][..], 2, 0.1),
        ] {
            let (volume, found) = closed_volume(&part(names));
            assert_eq!(found, holes, "{names:?}");
            assert!(volume > min_volume, "{names:?}: volume {volume}");
        }
        // the check can fail: one patch turned inside out breaks it
        let mut flipped = part(&["spout"]);
        for t in &mut flipped[0].triangles {
            t.swap(1, 2);
        }
        let result = std::panic::catch_unwind(|| closed_volume(&flipped));
        assert!(result.is_err());
    }

    #[test]
    fn patches_from_refuses_a_bad_index_naming_it() {
        let t = teapot_data();
        let mut bad = t.patches.clone();
        bad[5][9] = 290;
        let e = patches_from(&t.vertices, &bad).unwrap_err();
        assert!(e.contains("patch 5, entry 9"), "{e}");
        assert!(e.contains("290") && e.contains("out of range"), "{e}");
        let mut vertices = t.vertices.clone();
        vertices[4][1] = f64::NAN;
        let e = patches_from(&vertices, &t.patches).unwrap_err();
        assert!(e.contains("vertex 4"), "{e}");
        // and the good data gives the control points in row-major order
        let patches = patches_from(&t.vertices, &t.patches).unwrap();
        assert_eq!(
            patches[1].points[2][1],
            DVec3::from_array(t.vertices[t.patches[1][9]])
        );
    }
}
