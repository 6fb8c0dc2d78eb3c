//! Barkan & Gordon's transparency (*The scanline principle*, §5.2), the S-buffer
//! extended: "for every pixel in the current scanline, we keep a linked list of all the
//! polygons that are transparent and not blocked by an opaque polygon. The last element
//! in the list is the closest opaque polygon. The list is ordered by increasing
//! z-values", with a background element opaque at z = ∞.
//!
//! Here a sample column's list is a small vector kept in order of the depth key (nearer
//! first). The background element is implicit: a list whose last element is transparent
//! ends on the background, opaque at z = ∞, whose colour is 0 — so it adds nothing to
//! the composite. A polygon is inserted where it is not blocked (behind the list's
//! opaque end, or tied with it: on a tie the polygon met first stays in front, as the
//! S-buffer's strict compare keeps it); an opaque one cuts off what lies behind it. The
//! sample's colour is the composite `Σ (1 − t_i) Π_{j<i} t_j · colour_i`, nearest first.

use cwisim_scene::Vector;

/// One element of a sample's list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Layer {
    /// The depth key (smaller nearer).
    pub(crate) key: f64,
    /// The polygon.
    pub(crate) owner: u32,
    /// Its transmittance (0: opaque).
    pub(crate) transmittance: f64,
    /// Its colour at the sample (set after insertion).
    pub(crate) val: Vector,
}

/// The lists of one line of samples, reused from line to line.
#[derive(Clone, Debug, Default)]
pub(crate) struct LayerLine {
    lists: Vec<Vec<Layer>>,
    /// The most elements one list held.
    pub(crate) max_len: usize,
}

impl LayerLine {
    /// Every list of `0..columns` empty (the background alone).
    pub(crate) fn reset(&mut self, columns: usize) {
        self.lists.truncate(columns);
        for l in &mut self.lists {
            l.clear();
        }
        self.lists.resize_with(columns, Vec::new);
    }

    /// The list of column `c`, nearest first.
    pub(crate) fn list(&self, c: usize) -> &[Layer] {
        &self.lists[c]
    }

    /// Inserts polygon `owner` (transmittance `t`) at depth `key` into column `c`'s
    /// list: its place, or `None` when an opaque polygon in the list blocks it. Polygons
    /// of equal key keep the order they came in; an opaque one drops what lies behind.
    pub(crate) fn insert(&mut self, c: usize, key: f64, owner: u32, t: f64) -> Option<usize> {
        let list = &mut self.lists[c];
        if list
            .last()
            .is_some_and(|l| l.transmittance == 0.0 && key >= l.key)
        {
            return None;
        }
        let at = list.partition_point(|l| l.key <= key);
        list.insert(
            at,
            Layer {
                key,
                owner,
                transmittance: t,
                val: Vector::default(),
            },
        );
        if t == 0.0 {
            list.truncate(at + 1);
        }
        self.max_len = self.max_len.max(list.len());
        Some(at)
    }

    /// Sets the colour of element `at` of column `c`'s list.
    pub(crate) fn set_val(&mut self, c: usize, at: usize, val: Vector) {
        self.lists[c][at].val = val;
    }
}

/// The composite of a list, nearest first, its colours given by `colour`:
/// `Σ (1 − t_i) Π_{j<i} t_j · colour_i` (the background behind adds 0).
pub(crate) fn composite<E>(
    list: &[Layer],
    mut colour: impl FnMut(&Layer) -> Result<Vector, E>,
) -> Result<Vector, E> {
    let mut sum = Vector::default();
    let mut through = 1.0;
    for layer in list {
        let v = colour(layer)?;
        for (s, c) in sum.iter_mut().zip(v) {
            *s += through * (1.0 - layer.transmittance) * c;
        }
        through *= layer.transmittance;
    }
    Ok(sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn owners(l: &LayerLine, c: usize) -> Vec<u32> {
        l.list(c).iter().map(|e| e.owner).collect()
    }

    #[test]
    fn the_list_ends_at_the_nearest_opaque_polygon() {
        let mut l = LayerLine::default();
        l.reset(2);
        // a transparent polygon, then an opaque one behind it, then one behind that
        assert_eq!(l.insert(0, 2.0, 0, 0.5), Some(0));
        assert_eq!(l.insert(0, 5.0, 1, 0.0), Some(1));
        assert_eq!(l.insert(0, 6.0, 2, 0.3), None);
        // a tie with the opaque end is blocked (the first met stays in front)
        assert_eq!(l.insert(0, 5.0, 3, 0.3), None);
        // a transparent one between goes in its place
        assert_eq!(l.insert(0, 3.0, 4, 0.25), Some(1));
        assert_eq!(owners(&l, 0), [0, 4, 1]);
        // an opaque one in front of all cuts the list to itself
        assert_eq!(l.insert(0, 1.0, 5, 0.0), Some(0));
        assert_eq!(owners(&l, 0), [5]);
        assert_eq!(l.max_len, 3);
        // a tie among transparent ones keeps the order they came in
        l.insert(1, 1.0, 7, 0.5);
        l.insert(1, 1.0, 8, 0.5);
        assert_eq!(owners(&l, 1), [7, 8]);
        l.reset(2);
        assert!(l.list(0).is_empty() && l.list(1).is_empty());
    }

    #[test]
    fn the_composite_weights_each_layer_by_what_lets_it_through() {
        let mut l = LayerLine::default();
        l.reset(1);
        for (owner, key, t, v) in [(0, 1.0, 0.5, 0.8), (1, 2.0, 0.5, 0.4), (2, 3.0, 0.0, 0.2)] {
            let at = l.insert(0, key, owner, t).unwrap();
            l.set_val(0, at, cwisim_scene::vector(1, |_| v));
        }
        let c = composite::<()>(l.list(0), |e| Ok(e.val)).unwrap();
        // by hand: ½·0.8 + ½·½·0.4 + ½·½·0.2
        assert!((c[0] - (0.4 + 0.1 + 0.05)).abs() < 1e-15);
        // without the opaque end, the background adds nothing
        let c = composite::<()>(&l.list(0)[..2], |e| Ok(e.val)).unwrap();
        assert!((c[0] - 0.5).abs() < 1e-15);
    }
}
