//! Front, back or twisted: the sign of `g(u, v) = (S(u, v) − E) · (S_u × S_v)` over a
//! subpatch, exactly and conservatively.
//!
//! `S_u × S_v` is the patch's normal (outward on the teapot, `cwisim_world::bezier`), `E`
//! the eye. A point faces the eye when its normal points toward it, `(E − S)·N > 0`, that
//! is `g < 0` — the paper's condition `P · P_u × P_v < 0` with the eye at the origin
//! (§6). `g` is a polynomial of degree (8, 8); its Bernstein coefficients bound it (the
//! convex-hull property), so all coefficients `≤ 0` (some `< 0`) prove the subpatch
//! front-facing everywhere, all `≥ 0` back-facing, and mixed signs leave it *twisted*:
//! it may hold a silhouette. Unlike the paper's wedge test on projected control points,
//! this is exact under perspective (the projected patch is rational, and differences of
//! its projected control points are not the control points of its derivative): a cell
//! called front or back is one, whatever the view. Zero coefficients (at a pole, where
//! `S_u` vanishes) do not count against either side.
//!
//! The products are taken in the *scaled* Bernstein form (coefficient `c[i][j]` times
//! `C(m, i)·C(n, j)`), in which a product is a plain two-dimensional convolution; the
//! scale factors are positive, so the signs that classify are read off the scaled form
//! directly, and [`facing_coefficients`] divides them out only for those who want the
//! coefficients themselves.

use glam::DVec3;

/// How a subpatch faces the eye.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// Toward the eye everywhere.
    Front,
    /// Away from the eye everywhere.
    Back,
    /// Both signs among the coefficients: may hold a silhouette.
    Twisted,
}

/// `C(n, k)` for `n ≤ 8` (exact: small integers).
const BINOMIAL: [[f64; 9]; 9] = {
    let mut t = [[0.0; 9]; 9];
    let mut n = 0;
    while n < 9 {
        t[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + if k < n { t[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    t
};

/// A bivariate polynomial of degree `(M − 1, N − 1)` in scaled Bernstein form:
/// `s[i][j] = c[i][j]·C(M − 1, i)·C(N − 1, j)`, `i` along `u`, `j` along `v`.
type Scaled<const M: usize, const N: usize> = [[f64; N]; M];

/// One coordinate of control points `q[i][j]` (`i` along `u`) in scaled form.
fn scaled<const M: usize, const N: usize>(q: &[[DVec3; N]; M], axis: usize) -> Scaled<M, N> {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| q[i][j][axis] * BINOMIAL[M - 1][i] * BINOMIAL[N - 1][j])
    })
}

/// The product of two scaled polynomials: their convolution (`P = A + C − 1`,
/// `Q = B + D − 1`).
fn product<
    const A: usize,
    const B: usize,
    const C: usize,
    const D: usize,
    const P: usize,
    const Q: usize,
>(
    a: &Scaled<A, B>,
    b: &Scaled<C, D>,
) -> Scaled<P, Q> {
    debug_assert!(P == A + C - 1 && Q == B + D - 1);
    let mut out = [[0.0; Q]; P];
    for i1 in 0..A {
        for j1 in 0..B {
            let x = a[i1][j1];
            for i2 in 0..C {
                let row = &mut out[i1 + i2][j1..j1 + D];
                for (o, y) in row.iter_mut().zip(&b[i2]) {
                    *o += x * y;
                }
            }
        }
    }
    out
}

/// `a·b − c·d`, element by element.
fn cross_term<const M: usize, const N: usize>(ab: Scaled<M, N>, cd: &Scaled<M, N>) -> Scaled<M, N> {
    let mut out = ab;
    for (row, sub) in out.iter_mut().zip(cd) {
        for (o, s) in row.iter_mut().zip(sub) {
            *o -= s;
        }
    }
    out
}

/// `g` in scaled form, degree (8, 8), for the patch with control points
/// `points[row][col]` (`u` along a row, `v` down the rows).
fn scaled_facing(points: &[[DVec3; 4]; 4], eye: DVec3) -> Scaled<9, 9> {
    // q[i][j]: i along u (column), j along v (row)
    let p: [[DVec3; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| points[j][i] - eye));
    let su: [[DVec3; 4]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| 3.0 * (p[i + 1][j] - p[i][j])));
    let sv: [[DVec3; 3]; 4] =
        std::array::from_fn(|i| std::array::from_fn(|j| 3.0 * (p[i][j + 1] - p[i][j])));
    let [ux, uy, uz] = [0, 1, 2].map(|a| scaled(&su, a));
    let [vx, vy, vz] = [0, 1, 2].map(|a| scaled(&sv, a));
    let n: [Scaled<6, 6>; 3] = [
        cross_term(product(&uy, &vz), &product(&uz, &vy)),
        cross_term(product(&uz, &vx), &product(&ux, &vz)),
        cross_term(product(&ux, &vy), &product(&uy, &vx)),
    ];
    let mut g: Scaled<9, 9> = product(&scaled(&p, 0), &n[0]);
    for (axis, n) in n.iter().enumerate().skip(1) {
        let term: Scaled<9, 9> = product(&scaled(&p, axis), n);
        for (row, add) in g.iter_mut().zip(&term) {
            for (o, s) in row.iter_mut().zip(add) {
                *o += s;
            }
        }
    }
    g
}

/// The Bernstein coefficients of `g = (S − E)·(S_u × S_v)` for the patch with control
/// points `points[row][col]` (`u` along a row, `v` down the rows): 81 of them, `i`
/// (along `u`) major.
pub fn facing_coefficients(points: &[[DVec3; 4]; 4], eye: DVec3) -> Vec<f64> {
    let g = scaled_facing(points, eye);
    (0..9)
        .flat_map(|i| (0..9).map(move |j| (i, j)))
        .map(|(i, j)| g[i][j] / (BINOMIAL[8][i] * BINOMIAL[8][j]))
        .collect()
}

/// How the patch with these control points faces `eye`.
pub fn facing(points: &[[DVec3; 4]; 4], eye: DVec3) -> Facing {
    let g = scaled_facing(points, eye);
    let neg = g.iter().flatten().any(|&x| x < 0.0);
    let pos = g.iter().flatten().any(|&x| x > 0.0);
    match (neg, pos) {
        (true, false) => Facing::Front,
        (false, true) => Facing::Back,
        _ => Facing::Twisted,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_world::bezier::Patch;

    fn bernstein(n: usize, i: usize, t: f64) -> f64 {
        BINOMIAL[n][i] * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32)
    }

    /// A wavy patch over the unit square in z = 0 ± bumps.
    fn wavy() -> Patch {
        let mut pts = [[DVec3::ZERO; 4]; 4];
        for (r, row) in pts.iter_mut().enumerate() {
            for (c, p) in row.iter_mut().enumerate() {
                let z = [
                    [0.0, 0.3, -0.2, 0.1],
                    [0.2, -0.4, 0.5, 0.0],
                    [-0.1, 0.6, -0.3, 0.2],
                    [0.0, 0.1, 0.2, -0.1],
                ][r][c];
                *p = DVec3::new(c as f64 / 3.0, r as f64 / 3.0, z);
            }
        }
        Patch::new(pts)
    }

    #[test]
    fn the_coefficients_are_the_polynomial() {
        let patch = wavy();
        let eye = DVec3::new(0.3, -0.7, 2.5);
        let g = facing_coefficients(&patch.points, eye);
        assert_eq!(g.len(), 81);
        for (u, v) in [(0.0, 0.0), (0.3, 0.8), (0.71, 0.12), (1.0, 0.5)] {
            let direct = (patch.point(u, v) - eye).dot(patch.du(u, v).cross(patch.dv(u, v)));
            let bern: f64 = (0..9)
                .flat_map(|i| (0..9).map(move |j| (i, j)))
                .map(|(i, j)| g[i * 9 + j] * bernstein(8, i, u) * bernstein(8, j, v))
                .sum();
            assert!(
                (direct - bern).abs() < 1e-12 * (1.0 + direct.abs()),
                "{direct} {bern}"
            );
        }
    }

    #[test]
    fn a_flat_patch_is_front_from_its_normal_side_and_back_from_the_other() {
        // the unit square in z = 0: S_u × S_v = +z
        let mut pts = [[DVec3::ZERO; 4]; 4];
        for (r, row) in pts.iter_mut().enumerate() {
            for (c, p) in row.iter_mut().enumerate() {
                *p = DVec3::new(c as f64 / 3.0, r as f64 / 3.0, 0.0);
            }
        }
        assert_eq!(facing(&pts, DVec3::new(0.5, 0.5, 3.0)), Facing::Front);
        assert_eq!(facing(&pts, DVec3::new(0.5, 0.5, -3.0)), Facing::Back);
        // edge-on, the eye in the patch's plane beside it: g ≡ 0 → not proven either way
        assert_eq!(facing(&pts, DVec3::new(5.0, 0.5, 0.0)), Facing::Twisted);
        // the wavy patch seen at a grazing angle holds both signs
        let w = wavy();
        assert_eq!(
            facing(&w.points, DVec3::new(0.5, 0.5, 0.05)),
            Facing::Twisted
        );
    }

    #[test]
    fn front_and_back_are_proven_on_a_dense_grid() {
        let w = wavy();
        for eye in [
            DVec3::new(0.5, 0.5, 4.0),
            DVec3::new(0.4, 0.6, -4.0),
            DVec3::new(3.0, 0.2, 0.6),
        ] {
            let f = facing(&w.points, eye);
            for a in 0..=40 {
                for b in 0..=40 {
                    let (u, v) = (a as f64 / 40.0, b as f64 / 40.0);
                    let g = (w.point(u, v) - eye).dot(w.du(u, v).cross(w.dv(u, v)));
                    match f {
                        Facing::Front => assert!(g <= 0.0),
                        Facing::Back => assert!(g >= 0.0),
                        Facing::Twisted => {}
                    }
                }
            }
        }
    }
}
