//! Woo & Chall's triangle (§4): the parameterisation `D, E, F`, the parameters `s, t`,
//! the depth plane, and span ends on a sub-scanline — with the printed formulas that do
//! not survive a numerical check corrected (`docs/ERRATA.md`, "Woo & Chall").
//!
//! The paper computes span ends from its parameterisation; a sample lying on an edge is
//! then decided by rounding. Here the ends it gives are candidates only: whether a
//! sample is inside is decided by **edge functions** evaluated the same way for both
//! triangles that share an edge (exactly antisymmetric) and the top-left rule, so a
//! sample on a shared edge belongs to exactly one of them.

use cwisim_scene::Vector;

/// One triangle, oriented, with what the scanline needs of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Tri {
    /// `A, B, C` in pixels (y downward), ordered so that `(B − A) × (C − A) > 0`.
    pub points: [[f64; 2]; 3],
    /// Nearness at each vertex: larger is nearer, affine in screen space (a world
    /// triangle's `1/depth`; a screen polygon's `−depth`, or its draw order).
    pub near: [f64; 3],
    /// The intensity vector at each vertex.
    pub intensity: [Vector; 3],
    /// The surface it belongs to (a mesh, a screen polygon): `keepObj`'s key (§3.4.1).
    pub surface: u32,
    /// Which source triangle or polygon it is (for per-pixel shading).
    pub source: u32,
    /// The fraction of what lies behind that shows through it (0: opaque).
    pub transmittance: f64,
    /// The parameterisation (§4.1): `D = A`, `E = (B − A)/d`, `F = (C − A)/d` in x and
    /// y, with `d = (B − A) × (C − A)`.
    pub param: Param,
    edges: [Edge; 3],
}

/// §4.1–4.2: `D, E, F`, and the nearness plane's slopes `d_x`, `d_y`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Param {
    /// `D = A`.
    pub d: [f64; 2],
    /// `E_x, E_y`.
    pub e: [f64; 2],
    /// `F_x, F_y`.
    pub f: [f64; 2],
    /// `D_z` (nearness at `A`).
    pub dz: f64,
    /// `d_x = F_y E_z − E_y F_z`.
    pub dx: f64,
    /// `d_y = E_x F_z − F_x E_z`.
    pub dy: f64,
}

/// An edge function with a canonical orientation: evaluated from the lexicographically
/// smaller endpoint, so the two triangles sharing an edge get exactly opposite values.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Edge {
    p: [f64; 2],
    q: [f64; 2],
    /// `+1` if the triangle runs `p → q`, `−1` if `q → p`.
    sign: f64,
    /// Top-left rule: a sample exactly on this edge is inside.
    inclusive: bool,
}

impl Edge {
    fn new(a: [f64; 2], b: [f64; 2]) -> Edge {
        let (p, q, sign) = if (a[0], a[1]) <= (b[0], b[1]) {
            (a, b, 1.0)
        } else {
            (b, a, -1.0)
        };
        // y downward, interior on the side where the function is positive: a left edge
        // (interior to its right) runs upward; a top edge runs to the right.
        let inclusive = b[1] < a[1] || (b[1] == a[1] && b[0] > a[0]);
        Edge {
            p,
            q,
            sign,
            inclusive,
        }
    }

    /// Positive inside, zero on the edge.
    fn value(&self, x: f64, y: f64) -> f64 {
        self.sign
            * ((self.q[0] - self.p[0]) * (y - self.p[1])
                - (self.q[1] - self.p[1]) * (x - self.p[0]))
    }

    fn passes(&self, x: f64, y: f64) -> bool {
        let v = self.value(x, y);
        v > 0.0 || (v == 0.0 && self.inclusive)
    }
}

impl Tri {
    /// The triangle through `points`, or `None` when it has no area (or a coordinate is
    /// not finite): such a triangle covers no sample.
    pub fn new(
        points: [[f64; 2]; 3],
        near: [f64; 3],
        intensity: [Vector; 3],
        surface: u32,
        source: u32,
    ) -> Option<Tri> {
        let area = cross(points[0], points[1], points[2]);
        if area == 0.0 || !area.is_finite() || near.iter().any(|n| !n.is_finite()) {
            return None;
        }
        let (points, near, intensity) = if area > 0.0 {
            (points, near, intensity)
        } else {
            (
                [points[0], points[2], points[1]],
                [near[0], near[2], near[1]],
                [intensity[0], intensity[2], intensity[1]],
            )
        };
        let [a, b, c] = points;
        let d = cross(a, b, c);
        let e = [(b[0] - a[0]) / d, (b[1] - a[1]) / d];
        let f = [(c[0] - a[0]) / d, (c[1] - a[1]) / d];
        let (ez, fz) = (near[1] - near[0], near[2] - near[0]);
        let param = Param {
            d: a,
            e,
            f,
            dz: near[0],
            dx: f[1] * ez - e[1] * fz,
            dy: e[0] * fz - f[0] * ez,
        };
        if !(param.dx.is_finite() && param.dy.is_finite()) {
            return None;
        }
        Some(Tri {
            points,
            near,
            intensity,
            surface,
            source,
            transmittance: 0.0,
            param,
            edges: [Edge::new(a, b), Edge::new(b, c), Edge::new(c, a)],
        })
    }

    /// The smallest and largest y of the triangle.
    pub fn y_range(&self) -> (f64, f64) {
        let ys = self.points.map(|p| p[1]);
        (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]))
    }

    /// Whether sample point `(x, y)` is inside (edges by the top-left rule).
    pub fn covers(&self, x: f64, y: f64) -> bool {
        self.edges.iter().all(|e| e.passes(x, y))
    }

    /// The three edge functions at `(x, y)` (each positive inside), in edge order
    /// `AB, BC, CA`.
    pub fn edge_values(&self, x: f64, y: f64) -> [f64; 3] {
        self.edges.map(|e| e.value(x, y))
    }

    /// Nearness at `(x, y)`: the paper's direct form
    /// `z = D_z + (x − D_x) d_x + (y − D_y) d_y` (§4.2; its incremental `z += d_z`
    /// drifts along a long scanline and is not used).
    pub fn near_at(&self, x: f64, y: f64) -> f64 {
        let p = &self.param;
        p.dz + (x - p.d[0]) * p.dx + (y - p.d[1]) * p.dy
    }

    /// `s` and `t` at `(x, y)` (§4.1): `s = (x − D_x)F_y − (y − D_y)F_x`,
    /// `t = (y − D_y)E_x − (x − D_x)E_y`; the weights of `B` and `C`.
    pub fn s_t(&self, x: f64, y: f64) -> (f64, f64) {
        let p = &self.param;
        let (u, v) = (x - p.d[0], y - p.d[1]);
        (u * p.f[1] - v * p.f[0], v * p.e[0] - u * p.e[1])
    }

    /// The intensity at `(x, y)`: `(1 − s − t) I_A + s I_B + t I_C` (Gouraud; constant
    /// for flat shading, whose three vertex intensities are equal).
    pub fn intensity_at(&self, x: f64, y: f64, channels: usize) -> Vector {
        let (s, t) = self.s_t(x, y);
        let [a, b, c] = &self.intensity;
        cwisim_scene::vector(channels, |k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]))
    }

    /// The span ends on the line `y` from the parameterisation (§4.3, as corrected in
    /// `docs/ERRATA.md`): the x where the line meets `s = 0`, `t = 0` and `s + t = 1`
    /// within the triangle, smallest and largest. `None` when the line misses.
    /// Candidates: rounding near a vertex may move them by an ulp.
    pub fn span_ends(&self, y: f64) -> Option<(f64, f64)> {
        const SLACK: f64 = 1e-9;
        let p = &self.param;
        let v = y - p.d[1];
        let within = |w: f64| (-SLACK..=1.0 + SLACK).contains(&w);
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut put = |x: f64| {
            if x.is_finite() {
                lo = lo.min(x);
                hi = hi.max(x);
            }
        };
        // s = 0 (edge A–C): t = (y − D_y)[E_x − (F_x/F_y)E_y], x = (y − D_y)(F_x/F_y) + D_x
        if p.f[1] != 0.0 {
            let r = p.f[0] / p.f[1];
            if within(v * (p.e[0] - r * p.e[1])) {
                put(v * r + p.d[0]);
            }
        }
        // t = 0 (edge A–B): s = (y − D_y)[(E_x/E_y)F_y − F_x] (printed: −F_x − (E_x/E_y)F_y),
        // x = (y − D_y)(E_x/E_y) + D_x
        if p.e[1] != 0.0 {
            let r = p.e[0] / p.e[1];
            if within(v * (r * p.f[1] - p.f[0])) {
                put(v * r + p.d[0]);
            }
        }
        // s + t = 1 (edge B–C): x = (y − D_y)(F_x − E_x)/(F_y − E_y) + 1/(F_y − E_y) + D_x
        // (printed: (E_x − F_x)/(F_y − E_y)); inside when its t is in [0, 1]
        let g = p.f[1] - p.e[1];
        if g != 0.0 {
            let x = v * (p.f[0] - p.e[0]) / g + 1.0 / g + p.d[0];
            let (_, t) = self.s_t(x, y);
            if within(t) {
                put(x);
            }
        }
        (lo <= hi).then_some((lo, hi))
    }
}

/// `(b − a) × (c − a)`, y downward.
fn cross(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(points: [[f64; 2]; 3]) -> Tri {
        Tri::new(points, [1.0, 2.0, 3.0], [[0.0; 4]; 3], 0, 0).unwrap()
    }

    #[test]
    fn the_parameters_are_the_weights_of_b_and_c() {
        let t = tri([[1.0, 1.0], [5.0, 2.0], [2.0, 6.0]]);
        let [a, b, c] = t.points;
        assert_eq!(t.s_t(a[0], a[1]), (0.0, 0.0));
        let (s, u) = t.s_t(b[0], b[1]);
        assert!((s - 1.0).abs() < 1e-15 && u.abs() < 1e-15);
        let (s, u) = t.s_t(c[0], c[1]);
        assert!(s.abs() < 1e-15 && (u - 1.0).abs() < 1e-15);
        for k in 0..3 {
            assert!((t.near_at(t.points[k][0], t.points[k][1]) - t.near[k]).abs() < 1e-14);
        }
    }

    #[test]
    fn a_clockwise_triangle_is_turned_and_a_flat_one_refused() {
        let t = Tri::new(
            [[0.0, 0.0], [0.0, 4.0], [4.0, 0.0]],
            [1.0, 2.0, 3.0],
            [[0.0; 4]; 3],
            0,
            0,
        )
        .unwrap();
        assert_eq!(t.points[1], [4.0, 0.0]);
        assert_eq!(t.near, [1.0, 3.0, 2.0]);
        assert!(Tri::new(
            [[0.0; 2], [1.0, 1.0], [2.0, 2.0]],
            [0.0; 3],
            [[0.0; 4]; 3],
            0,
            0
        )
        .is_none());
    }

    #[test]
    fn a_sample_on_a_shared_edge_belongs_to_one_triangle() {
        // two triangles of a quad, diagonal through sample points
        let a = tri([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]);
        let b = tri([[0.0, 0.0], [4.0, 4.0], [0.0, 4.0]]);
        for k in 0..8 {
            let v = 0.5 * k as f64;
            assert!(a.covers(v, v) ^ b.covers(v, v), "({v}, {v})");
        }
        // a horizontal shared edge: the top edge of the lower triangle takes it
        let up = tri([[0.0, 0.0], [4.0, 2.0], [0.0, 2.0]]);
        let down = tri([[0.0, 2.0], [4.0, 2.0], [0.0, 4.0]]);
        assert!(!up.covers(1.0, 2.0) && down.covers(1.0, 2.0));
    }

    #[test]
    fn the_printed_span_formulas_fail_where_the_corrected_ones_hold() {
        // A = (0,0), B = (4,2), C = (1,4): y = 1 meets t = 0 (A–B) at x = 2
        let t = tri([[0.0, 0.0], [4.0, 2.0], [1.0, 4.0]]);
        let p = t.param;
        let v = 1.0 - p.d[1];
        let corrected_s = v * (p.e[0] / p.e[1] * p.f[1] - p.f[0]);
        let printed_s = v * (-p.f[0] - p.e[0] / p.e[1] * p.f[1]);
        let (s_true, _) = t.s_t(2.0, 1.0);
        assert!((corrected_s - s_true).abs() < 1e-15);
        assert!((printed_s - s_true).abs() > 0.1, "{printed_s} vs {s_true}");
        // y = 3 meets s + t = 1 (B–C) at x = 4 − 3·(3 − 2)/2 = 2.5
        let g = p.f[1] - p.e[1];
        let corrected = (3.0 - p.d[1]) * (p.f[0] - p.e[0]) / g + 1.0 / g + p.d[0];
        let printed = (3.0 - p.d[1]) * (p.e[0] - p.f[0]) / g + (1.0 / g + p.d[0]);
        assert!((corrected - 2.5).abs() < 1e-12);
        assert!((printed - 2.5).abs() > 0.5, "{printed}");
        let (lo, hi) = t.span_ends(3.0).unwrap();
        assert!(
            (lo - 0.75).abs() < 1e-12 && (hi - 2.5).abs() < 1e-12,
            "{lo} {hi}"
        );
    }
}
