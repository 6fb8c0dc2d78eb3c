//! Woo & Chall's three lists (§3.1–3.3): `ySortList` (every triangle, sorted once by
//! the first sub-scanline it meets), `yActiveList` (the triangles meeting the current
//! sub-scanline, with their span of sample columns, sorted by the span's first column:
//! insertion sort below 200 entries, heap sort above, as the paper chose), and
//! `xActiveList` (the spans containing the current sample). At each sample the nearest
//! triangle of `xActiveList` wins.
//!
//! The paper's y runs upward and it sorts on `maxY` decreasing; cwisim's y runs downward
//! (the scanline order), so the same list is sorted on the first sub-scanline increasing.

use super::triangle::Tri;
use crate::subsample::Sampler;

/// No triangle: the background.
pub const NONE: u32 = u32::MAX;

/// The paper's switch from insertion sort to heap sort (§3.3).
pub const INSERTION_SORT_BELOW: usize = 200;

/// What the lists saw, summed over sub-scanlines (maxima where named so).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ListStats {
    /// `m`: the most triangles on `yActiveList` at once (their y-range holds the
    /// sub-scanline: the paper's bounding-box count, its memory bound).
    pub max_active: u64,
    /// The most visible spans (runs of samples won by one triangle) on a sub-scanline.
    pub max_visible_spans: u64,
    /// Samples that hit geometry (`#Geometry`).
    pub geometry: u64,
    /// Spans computed (one per active triangle per sub-scanline).
    pub spans: u64,
    /// Depth evaluations (one per triangle of `xActiveList` per sample).
    pub depth_tests: u64,
}

/// The layers behind a transparent winner, per sample: for each such sample column, the
/// triangles behind the front one, nearest first, down to the first opaque one (or all
/// that cover it, when none is: the background ends the list). Every sample whose
/// winner is transparent has an entry, with no layer when nothing lies behind.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Layers {
    /// `(column, start, end)`: the sample's layers are `tris[start..end]`; in column order.
    pub entries: Vec<(u32, u32, u32)>,
    /// The layers of every entry, one after the other.
    pub tris: Vec<u32>,
}

impl Layers {
    fn clear(&mut self) {
        self.entries.clear();
        self.tris.clear();
    }
}

impl ListStats {
    /// Adds another stretch's figures (maxima taken, counts summed).
    pub fn merge(&mut self, o: &ListStats) {
        self.max_active = self.max_active.max(o.max_active);
        self.max_visible_spans = self.max_visible_spans.max(o.max_visible_spans);
        self.geometry += o.geometry;
        self.spans += o.spans;
        self.depth_tests += o.depth_tests;
    }
}

/// One triangle's span on a sub-scanline: sample columns `lo..=hi`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    /// First column.
    pub lo: u32,
    /// Last column.
    pub hi: u32,
    /// The triangle.
    pub tri: u32,
}

/// The lists, walked down the image one sub-scanline at a time.
pub struct Lists<'a> {
    tris: &'a [Tri],
    sampler: Sampler,
    /// `ySortList`: triangles with their sub-scanline range, by first sub-scanline.
    y_sort: Vec<(u32, u32, u32)>,
    next: usize,
    /// Triangles whose y-range holds the current sub-scanline.
    y_active: Vec<(u32, u32)>,
    /// `yActiveList`'s spans on the current sub-scanline.
    spans: Vec<Span>,
    x_active: Vec<Span>,
}

impl<'a> Lists<'a> {
    /// `ySortList` of `tris`, sorted once.
    pub fn new(tris: &'a [Tri], sampler: Sampler) -> Lists<'a> {
        let last_line = sampler.sublines() as f64 - 1.0;
        let mut y_sort: Vec<(u32, u32, u32)> = tris
            .iter()
            .enumerate()
            .filter_map(|(k, t)| {
                let (y0, y1) = t.y_range();
                let first = sampler.index_at_or_after(y0).max(0.0);
                let last = sampler.index_at_or_before(y1).min(last_line);
                (first <= last).then_some((first as u32, last as u32, k as u32))
            })
            .collect();
        y_sort.sort_unstable();
        Lists {
            tris,
            sampler,
            y_sort,
            next: 0,
            y_active: Vec::new(),
            spans: Vec::new(),
            x_active: Vec::new(),
        }
    }

    /// Triangles that meet some sub-scanline.
    pub fn sorted(&self) -> usize {
        self.y_sort.len()
    }

    /// The winner of every sample column of sub-scanline `j` into `winners` (a triangle
    /// index, or [`NONE`]). Sub-scanlines must come in increasing order.
    /// Where the winner is transparent, the layers behind it go to `layers`.
    pub fn subline(
        &mut self,
        j: u32,
        winners: &mut Vec<u32>,
        layers: &mut Layers,
        stats: &mut ListStats,
    ) {
        let columns = self.sampler.columns();
        layers.clear();
        winners.clear();
        winners.resize(columns, NONE);
        // yActiveList: drop the finished, add the starting
        self.y_active.retain(|&(last, _)| last >= j);
        while let Some(&(first, last, k)) = self.y_sort.get(self.next) {
            if first > j {
                break;
            }
            self.next += 1;
            if last >= j {
                self.y_active.push((last, k));
            }
        }
        stats.max_active = stats.max_active.max(self.y_active.len() as u64);
        let y = self.sampler.subline_y(j as usize);
        self.spans.clear();
        for &(_, k) in &self.y_active {
            stats.spans += 1;
            if let Some((lo, hi)) = span(&self.tris[k as usize], y, &self.sampler) {
                self.spans.push(Span { lo, hi, tri: k });
            }
        }
        if self.spans.len() < INSERTION_SORT_BELOW {
            insertion_sort(&mut self.spans);
        } else {
            heap_sort(&mut self.spans);
        }
        // xActiveList: sweep the columns
        self.x_active.clear();
        let mut i = 0;
        let mut runs = 0u64;
        let mut previous = NONE;
        let Some(first) = self.spans.first() else {
            return;
        };
        let mut k = first.lo;
        loop {
            while let Some(s) = self.spans.get(i) {
                if s.lo > k {
                    break;
                }
                self.x_active.push(*s);
                i += 1;
            }
            self.x_active.retain(|s| s.hi >= k);
            if self.x_active.is_empty() {
                previous = NONE;
                match self.spans.get(i) {
                    Some(s) => {
                        k = s.lo;
                        continue;
                    }
                    None => break,
                }
            }
            let x = self.sampler.column_x(k as usize);
            let mut best = NONE;
            let mut best_near = f64::NEG_INFINITY;
            for s in &self.x_active {
                let near = self.tris[s.tri as usize].near_at(x, y);
                // nearest wins; on a tie the earlier triangle
                if near > best_near || (near == best_near && s.tri < best) {
                    best = s.tri;
                    best_near = near;
                }
            }
            stats.depth_tests += self.x_active.len() as u64;
            stats.geometry += 1;
            winners[k as usize] = best;
            if self.tris[best as usize].transmittance > 0.0 {
                self.layers_behind(best, x, y, k, layers);
            }
            if best != previous {
                runs += 1;
                previous = best;
            }
            k += 1;
            if k as usize >= columns {
                break;
            }
        }
        stats.max_visible_spans = stats.max_visible_spans.max(runs);
    }
}

impl Lists<'_> {
    /// The triangles of `xActiveList` behind `front` at `(x, y)`, nearest first, down
    /// to the first opaque one (§3: "do until visible surface is opaque").
    fn layers_behind(&self, front: u32, x: f64, y: f64, k: u32, layers: &mut Layers) {
        let start = layers.tris.len() as u32;
        let mut behind: Vec<(f64, u32)> = self
            .x_active
            .iter()
            .filter(|s| s.tri != front)
            .map(|s| (self.tris[s.tri as usize].near_at(x, y), s.tri))
            .collect();
        // nearest first; on a tie the earlier triangle, as for the winner
        behind.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let front_near = self.tris[front as usize].near_at(x, y);
        for (near, tri) in behind {
            // only what lies behind the front (a tie that lost to it counts as behind)
            if near > front_near || (near == front_near && tri < front) {
                continue;
            }
            layers.tris.push(tri);
            if self.tris[tri as usize].transmittance == 0.0 {
                break;
            }
        }
        // an entry even with no layer behind: a transparent front over the background
        // (opaque at z = ∞, colour 0) lets `1 − t` of its colour through, no more
        let end = layers.tris.len() as u32;
        layers.entries.push((k, start, end));
    }
}

/// The sample columns of `t` on the line `y`: the span ends from the parameterisation
/// (§4.3) give candidates, and the exact inside test (edge functions, top-left rule)
/// settles the samples at either end.
pub fn span(t: &Tri, y: f64, sampler: &Sampler) -> Option<(u32, u32)> {
    let (x0, x1) = t.span_ends(y)?;
    let last = sampler.columns() as i64 - 1;
    let inside = |k: i64| (0..=last).contains(&k) && t.covers(sampler.column_x(k as usize), y);
    let clamp = |v: f64| v.clamp(-1.0, last as f64 + 1.0) as i64;
    let mut lo = clamp(sampler.index_at_or_after(x0));
    let mut hi = clamp(sampler.index_at_or_before(x1));
    if lo > hi {
        // a span narrower than a sample step: at most one of the two neighbours
        let k = [hi, lo].into_iter().find(|&k| inside(k))?;
        lo = k;
        hi = k;
    }
    lo = lo.max(0);
    hi = hi.min(last);
    while lo > 0 && inside(lo - 1) {
        lo -= 1;
    }
    while lo <= hi && !inside(lo) {
        lo += 1;
    }
    while hi < last && inside(hi + 1) {
        hi += 1;
    }
    while hi >= lo && !inside(hi) {
        hi -= 1;
    }
    (lo <= hi).then_some((lo as u32, hi as u32))
}

fn key(s: &Span) -> (u32, u32) {
    (s.lo, s.tri)
}

/// Insertion sort on the first column (then the triangle, so the order is total).
pub fn insertion_sort(v: &mut [Span]) {
    for i in 1..v.len() {
        let mut j = i;
        while j > 0 && key(&v[j - 1]) > key(&v[j]) {
            v.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// Heap sort on the same key.
pub fn heap_sort(v: &mut [Span]) {
    fn sift_down(v: &mut [Span], mut root: usize, end: usize) {
        loop {
            let mut child = 2 * root + 1;
            if child >= end {
                return;
            }
            if child + 1 < end && key(&v[child]) < key(&v[child + 1]) {
                child += 1;
            }
            if key(&v[root]) >= key(&v[child]) {
                return;
            }
            v.swap(root, child);
            root = child;
        }
    }
    let n = v.len();
    for root in (0..n / 2).rev() {
        sift_down(v, root, n);
    }
    for end in (1..n).rev() {
        v.swap(0, end);
        sift_down(v, 0, end);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn both_sorts_agree_with_the_library(keys in prop::collection::vec((0u32..50, 0u32..1000), 0..400)) {
            let spans: Vec<Span> = keys.iter().map(|&(lo, tri)| Span { lo, hi: lo, tri }).collect();
            let mut want = spans.clone();
            want.sort_by_key(key);
            let mut a = spans.clone();
            insertion_sort(&mut a);
            let mut b = spans;
            heap_sort(&mut b);
            prop_assert_eq!(&a, &want);
            prop_assert_eq!(&b, &want);
        }
    }
}
