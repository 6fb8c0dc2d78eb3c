//! Robust geometric predicates: exact orientation (Shewchuk's adaptive expansion), segment
//! intersection, and polygon simplicity — what scene validation rests on.

/// `a + b` as `(sum, error)`, exactly.
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a × b` as `(product, error)`, exactly (barring underflow).
pub fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// The exact sign of `(b - a) × (c - a)`: positive when `a, b, c` turn one way, negative
/// the other, zero when collinear. Sums the six products of the expanded determinant as a
/// nonoverlapping expansion (Shewchuk's grow-expansion), whose largest component has the
/// sign of the exact sum.
pub fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    // two equal points: exactly collinear (the filter below cannot prove a zero)
    if a == b || b == c || c == a {
        return 0;
    }
    // Shewchuk's filter: the rounded determinant when its error bound proves the sign
    let left = (a[0] - c[0]) * (b[1] - c[1]);
    let right = (a[1] - c[1]) * (b[0] - c[0]);
    let det = left - right;
    let sum = if left > 0.0 && right > 0.0 {
        left + right
    } else if left < 0.0 && right < 0.0 {
        -left - right
    } else {
        0.0
    };
    const BOUND: f64 = (3.0 + 16.0 * f64::EPSILON / 2.0) * f64::EPSILON / 2.0;
    if (sum == 0.0 && det != 0.0) || (sum.is_finite() && det.abs() > BOUND * sum) {
        return if det > 0.0 { 1 } else { -1 };
    }
    let terms = [
        (b[0], c[1]),
        (-b[0], a[1]),
        (-a[0], c[1]),
        (-b[1], c[0]),
        (a[0], b[1]),
        (a[1], c[0]),
    ];
    let mut expansion: Vec<f64> = Vec::with_capacity(12);
    let mut grow = |x: f64| {
        let mut q = x;
        let mut next = Vec::with_capacity(expansion.len() + 1);
        for &e in &expansion {
            let (s, err) = two_sum(q, e);
            if err != 0.0 {
                next.push(err);
            }
            q = s;
        }
        if q != 0.0 {
            next.push(q);
        }
        expansion = next;
    };
    for (x, y) in terms {
        let (p, e) = two_product(x, y);
        grow(e);
        grow(p);
    }
    let top = expansion.last().copied().unwrap_or(0.0);
    if top > 0.0 {
        1
    } else if top < 0.0 {
        -1
    } else {
        0
    }
}

/// Whether `p`, collinear with segment `a b`, lies on it (closed).
fn within(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    (0..2).all(|k| a[k].min(b[k]) <= p[k] && p[k] <= a[k].max(b[k]))
}

/// How closed segments `p` and `q` meet: `None`, `Some(true)` for a proper crossing,
/// `Some(false)` for touching (an endpoint on the other segment, or collinear overlap).
pub fn segments_meet(p: ([f64; 2], [f64; 2]), q: ([f64; 2], [f64; 2])) -> Option<bool> {
    for k in 0..2 {
        let (plo, phi) = (p.0[k].min(p.1[k]), p.0[k].max(p.1[k]));
        let (qlo, qhi) = (q.0[k].min(q.1[k]), q.0[k].max(q.1[k]));
        if phi < qlo || qhi < plo {
            return None;
        }
    }
    let o1 = orient(p.0, p.1, q.0);
    let o2 = orient(p.0, p.1, q.1);
    let o3 = orient(q.0, q.1, p.0);
    let o4 = orient(q.0, q.1, p.1);
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return Some(true);
    }
    let touches = (o1 == 0 && within(p.0, p.1, q.0))
        || (o2 == 0 && within(p.0, p.1, q.1))
        || (o3 == 0 && within(q.0, q.1, p.0))
        || (o4 == 0 && within(q.0, q.1, p.1));
    touches.then_some(false)
}

/// Why the closed polygon `v` is not simple, naming its edges; `None` when it is simple
/// (or all its vertices lie on one line).
pub fn simplicity_fault(v: &[[f64; 2]]) -> Option<String> {
    let n = v.len();
    // The distinct-vertex cycle: drop repeats of the previous vertex (cyclically). Each
    // kept vertex remembers the original edge that leaves its last repeat.
    let start = (0..n).find(|&k| v[k] != v[(k + n - 1) % n])?; // None: all one point
    let mut kept: Vec<usize> = Vec::new();
    for s in 0..n {
        let k = (start + s) % n;
        if v[k] != v[(k + n - 1) % n] {
            kept.push(k);
        }
    }
    let m = kept.len();
    let pts: Vec<[f64; 2]> = kept.iter().map(|&k| v[k]).collect();
    // original index of the edge from kept vertex i to kept vertex i+1
    let edge_id: Vec<usize> = (0..m).map(|i| (kept[(i + 1) % m] + n - 1) % n).collect();
    // all on one line: zero area, allowed
    let (a, b) = (pts[0], pts[1]);
    if pts.iter().all(|&p| orient(a, b, p) == 0) {
        return None;
    }
    let edge = |i: usize| (pts[i], pts[(i + 1) % m]);
    let name = |i: usize, j: usize| {
        let (x, y) = (edge_id[i].min(edge_id[j]), edge_id[i].max(edge_id[j]));
        (x, y)
    };
    // adjacent edges a→b, b→c overlap when c lies back along b→a
    for i in 0..m {
        let (a, b, c) = (pts[i], pts[(i + 1) % m], pts[(i + 2) % m]);
        if orient(a, b, c) == 0 {
            let k = if a[0] != b[0] { 0 } else { 1 };
            if (a[k] < b[k]) == (c[k] < b[k]) {
                let (x, y) = name(i, (i + 1) % m);
                return Some(format!(
                    "adjacent edges {x} and {y} overlap at vertex {}",
                    kept[(i + 1) % m]
                ));
            }
        }
    }
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue; // adjacent through the closing vertex
            }
            if let Some(cross) = segments_meet(edge(i), edge(j)) {
                let (x, y) = name(i, j);
                let how = if cross { "cross" } else { "touch" };
                return Some(format!("edges {x} and {y} {how}"));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_is_exact() {
        assert_eq!(orient([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), 1);
        assert_eq!(orient([0.0, 0.0], [0.0, 1.0], [1.0, 0.0]), -1);
        // points on a line whose naive determinant rounds to nonzero
        let a = [0.1, 0.1];
        let b = [0.3, 0.3];
        let c = [1e15 / 3.0, 1e15 / 3.0];
        assert_eq!(orient(a, b, c), 0);
        // a perturbation far below the naive rounding error is still seen
        let c2 = [c[0], f64::from_bits(c[1].to_bits() + 1)];
        assert_eq!(orient(a, b, c2), 1);
        assert_eq!(orient(a, b, [0.5, 0.5 + 1e-17]), 0); // 0.5 + 1e-17 == 0.5
    }

    #[test]
    fn simplicity() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(simplicity_fault(&sq), None);
        let bow = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        assert_eq!(simplicity_fault(&bow).unwrap(), "edges 0 and 2 cross");
        let dup = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 0.0],
        ];
        assert_eq!(simplicity_fault(&dup), None);
        let line = [[0.0, 0.0], [2.0, 0.0], [1.0, 0.0]];
        assert_eq!(simplicity_fault(&line), None);
        let spike = [[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]];
        assert_eq!(
            simplicity_fault(&spike).unwrap(),
            "adjacent edges 0 and 1 overlap at vertex 1"
        );
        // a vertex touching a non-adjacent edge
        let touch = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [2.0, 0.0], [0.0, 4.0]];
        assert_eq!(simplicity_fault(&touch).unwrap(), "edges 0 and 2 touch");
    }
}
