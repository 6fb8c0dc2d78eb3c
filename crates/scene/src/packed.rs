//! Many polygons held flat: every polygon's vertices in one vector, their intensities in
//! another and their depths in a third, with where each polygon ends.
//!
//! A [`Polygon`] is 72 bytes of its own and a heap block for its vertices, one for its
//! list of intensity vectors and one per vertex (and one for its depths): a grey
//! quadrilateral is 96 bytes of values in six blocks, each with the allocator's header.
//! Packed, it is its 96 bytes and 8 of index. A renderer that holds a frame of small
//! fragments until it emits their rows (nishita: 100,680 fragments on the teapot) keeps
//! them packed and unpacks a few rows' worth at a time.

use crate::{Polygon, VertexIntensity};
use std::ops::Range;

/// Polygons of `channels` intensity values per vertex, packed: [`get`](Self::get) gives
/// back each one as it was pushed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PackedPolygons {
    channels: usize,
    /// Polygon `k`'s vertices are `vertices[ends[k - 1] .. ends[k]]` (from 0 for the
    /// first).
    ends: Vec<u32>,
    vertices: Vec<[f64; 2]>,
    /// `channels` values per vertex.
    intensity: Vec<f64>,
    /// Polygon `k`'s depths, `depth[depth_ends[k - 1] .. depth_ends[k]]`: none, or as
    /// many as it has vertices.
    /// has vertices.
    depth_ends: Vec<u32>,
    depth: Vec<f64>,
}

/// Why a polygon cannot be packed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PackError {
    /// Its intensities or depths do not match its vertices and the store's channels.
    #[error("a polygon of {vertices} vertices with {intensities} intensity vector(s) (of {channels} value(s) each expected) and {depths} depth(s) cannot be packed")]
    Shape {
        /// Its vertices.
        vertices: usize,
        /// Its intensity vectors.
        intensities: usize,
        /// The store's channels.
        channels: usize,
        /// Its depths (0 without).
        depths: usize,
    },
    /// The store would hold more than `u32::MAX` vertices.
    #[error("more than {} vertices cannot be packed", u32::MAX)]
    Full,
}

impl PackedPolygons {
    /// No polygons, of `channels` values per intensity.
    pub fn new(channels: usize) -> Self {
        PackedPolygons {
            channels,
            ..PackedPolygons::default()
        }
    }

    /// Values per intensity.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Polygons held.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends `p`: one intensity vector of `channels` values per vertex, and as many
    /// depths as vertices or none.
    pub fn push(&mut self, p: &Polygon) -> Result<(), PackError> {
        let n = p.vertices.len();
        let depths = p.depth.as_ref().map_or(0, Vec::len);
        if p.intensity.len() != n
            || p.intensity.iter().any(|i| i.len() != self.channels)
            || (p.depth.is_some() && depths != n)
        {
            return Err(PackError::Shape {
                vertices: n,
                intensities: p.intensity.len(),
                channels: self.channels,
                depths,
            });
        }
        let end = u32::try_from(self.vertices.len() + n).map_err(|_| PackError::Full)?;
        let depth_end = u32::try_from(self.depth.len() + depths).map_err(|_| PackError::Full)?;
        self.vertices.extend_from_slice(&p.vertices);
        for i in &p.intensity {
            self.intensity.extend_from_slice(i);
        }
        if let Some(d) = &p.depth {
            self.depth.extend_from_slice(d);
        }
        self.ends.push(end);
        self.depth_ends.push(depth_end);
        Ok(())
    }

    /// Polygon `k`, as it was pushed; `None` past the end.
    pub fn get(&self, k: usize) -> Option<Polygon> {
        self.unpack(k..k.saturating_add(1)).pop()
    }

    /// Polygons `range`, unpacked (the part of `range` past the end left out).
    pub fn unpack(&self, range: Range<usize>) -> Vec<Polygon> {
        let mut out = Vec::new();
        self.unpack_into(range, &mut out, 0);
        out
    }

    /// Polygons `range` unpacked into `out` from position `first` on (the part of
    /// `range` past the end left out; `first` at most `out.len()`), `out` grown where
    /// they reach past its end; returns how many. The polygons already there are
    /// overwritten in their own vectors, so that a buffer unpacked into again and again
    /// allocates only to grow; those after the last one unpacked are left as they were.
    pub fn unpack_into(&self, range: Range<usize>, out: &mut Vec<Polygon>, first: usize) -> usize {
        let first = first.min(out.len());
        let end = range.end.min(self.len());
        let start = range.start.min(end);
        for (slot, k) in (first..).zip(start..end) {
            let (a, b) = span(&self.ends, k);
            let (da, db) = span(&self.depth_ends, k);
            if slot == out.len() {
                out.push(Polygon::new(Vec::new(), Vec::<VertexIntensity>::new()));
            }
            let p = &mut out[slot];
            p.vertices.clear();
            p.vertices.extend_from_slice(&self.vertices[a..b]);
            p.intensity.resize_with(b - a, VertexIntensity::new);
            for (i, v) in p.intensity.iter_mut().zip(a..b) {
                i.clear();
                i.extend_from_slice(&self.intensity[v * self.channels..(v + 1) * self.channels]);
            }
            if db > da {
                let d = p.depth.get_or_insert_with(Vec::new);
                d.clear();
                d.extend_from_slice(&self.depth[da..db]);
            } else {
                p.depth = None;
            }
        }
        end - start
    }

    /// Drops the spare capacity of its vectors.
    pub fn shrink_to_fit(&mut self) {
        self.ends.shrink_to_fit();
        self.vertices.shrink_to_fit();
        self.intensity.shrink_to_fit();
        self.depth_ends.shrink_to_fit();
        self.depth.shrink_to_fit();
    }

    /// The bytes its vectors hold and do not use (their capacity past their length).
    pub fn spare_bytes(&self) -> usize {
        use std::mem::size_of;
        (self.ends.capacity() - self.ends.len()) * size_of::<u32>()
            + (self.vertices.capacity() - self.vertices.len()) * size_of::<[f64; 2]>()
            + (self.intensity.capacity() - self.intensity.len()) * size_of::<f64>()
            + (self.depth_ends.capacity() - self.depth_ends.len()) * size_of::<u32>()
            + (self.depth.capacity() - self.depth.len()) * size_of::<f64>()
    }

    /// The bytes its vectors hold (their capacity).
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.ends.capacity() * size_of::<u32>()
            + self.vertices.capacity() * size_of::<[f64; 2]>()
            + self.intensity.capacity() * size_of::<f64>()
            + self.depth_ends.capacity() * size_of::<u32>()
            + self.depth.capacity() * size_of::<f64>()
    }
}

/// Where item `k` of a packed vector lies, from the vector of the items' ends.
fn span(ends: &[u32], k: usize) -> (usize, usize) {
    let start = if k == 0 { 0 } else { ends[k - 1] as usize };
    (start, ends[k] as usize)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn polygon(channels: usize) -> impl Strategy<Value = Polygon> {
        (3usize..8, any::<bool>()).prop_flat_map(move |(n, with_depth)| {
            (
                proptest::collection::vec([-1e3f64..1e3, -1e3f64..1e3], n),
                proptest::collection::vec(proptest::collection::vec(0f64..1.0, channels), n),
                proptest::collection::vec(0.1f64..10.0, if with_depth { n } else { 0 }),
            )
                .prop_map(move |(vertices, intensity, depth)| Polygon {
                    vertices,
                    intensity: intensity.into_iter().map(Into::into).collect(),
                    depth: with_depth.then_some(depth),
                })
        })
    }

    /// A channel count and two lists of polygons of that many channels.
    fn two_lists() -> impl Strategy<Value = (usize, Vec<Polygon>, Vec<Polygon>)> {
        (1usize..4).prop_flat_map(|c| {
            (
                Just(c),
                proptest::collection::vec(polygon(c), 0..12),
                proptest::collection::vec(polygon(c), 0..12),
            )
        })
    }

    proptest! {
        /// Every polygon comes back as it was pushed, bit for bit, alone or in a range.
        #[test]
        fn every_polygon_comes_back_as_pushed((channels, a, b) in two_lists()) {
            let mut packed = PackedPolygons::new(channels);
            for p in &a {
                packed.push(p).unwrap();
            }
            for p in &b {
                packed.push(p).unwrap();
            }
            packed.shrink_to_fit();
            let all: Vec<Polygon> = a.iter().chain(&b).cloned().collect();
            prop_assert_eq!(packed.len(), all.len());
            prop_assert_eq!(packed.unpack(0..all.len() + 3), all.clone());
            for (k, p) in all.iter().enumerate() {
                prop_assert_eq!(packed.get(k), Some(p.clone()));
            }
            prop_assert_eq!(packed.get(all.len()), None);
            let mid = all.len() / 2;
            prop_assert_eq!(packed.unpack(mid..all.len()), all[mid..].to_vec());
            // into a buffer holding other polygons: overwritten, grown where they reach
            // past its end, the ones after left as they were
            let mut buffer = b.clone();
            let first = 1.min(b.len());
            let n = packed.unpack_into(mid..all.len() + 1, &mut buffer, 1);
            prop_assert_eq!(n, all.len() - mid);
            prop_assert_eq!(buffer.len(), b.len().max(first + n));
            prop_assert_eq!(&buffer[..first], &b[..first]);
            prop_assert_eq!(&buffer[first..first + n], &all[mid..]);
            prop_assert_eq!(&buffer[first + n..], &b[(first + n).min(b.len())..]);
            let before: Vec<Polygon> = a.iter().chain(&b).chain(&a).cloned().collect();
            let mut buffer = before.clone();
            prop_assert_eq!(packed.unpack_into(0..mid, &mut buffer, 0), mid);
            prop_assert_eq!(&buffer[..mid], &all[..mid]);
            prop_assert_eq!(&buffer[mid..], &before[mid..]);
        }
    }

    #[test]
    fn a_polygon_of_the_wrong_shape_is_refused_and_nothing_is_kept() {
        let mut packed = PackedPolygons::new(2);
        let square = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let good = Polygon::uniform(square.clone(), &[0.5, 0.25]);
        packed.push(&good).unwrap();
        let before = packed.clone();
        // one channel where the store has two
        let grey = Polygon::uniform(square.clone(), &[0.5]);
        assert_eq!(
            packed.push(&grey),
            Err(PackError::Shape {
                vertices: 4,
                intensities: 4,
                channels: 2,
                depths: 0
            })
        );
        // three intensity vectors for four vertices
        let mut short = good.clone();
        short.intensity.pop();
        assert!(packed.push(&short).is_err());
        // two depths for four vertices
        let shallow = good.clone().with_depth(vec![1.0, 2.0]);
        assert!(packed.push(&shallow).is_err());
        // a depth list with no depths (it would come back without one)
        let empty = good.clone().with_depth(Vec::new());
        assert!(packed.push(&empty).is_err());
        assert_eq!(packed, before);
        assert_eq!(packed.get(0), Some(good));
    }

    #[test]
    fn a_default_store_takes_polygons_and_packed_is_smaller() {
        let mut packed = PackedPolygons {
            channels: 1,
            ..PackedPolygons::default()
        };
        assert!(packed.is_empty());
        let quad = Polygon::uniform(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], &[1.0]);
        for _ in 0..1000 {
            packed.push(&quad).unwrap();
        }
        packed.shrink_to_fit();
        assert_eq!(packed.len(), 1000);
        assert_eq!(packed.get(999).as_ref(), Some(&quad));
        // 4 × (16 + 8) bytes of vertex and intensity and 8 of ends per polygon
        assert_eq!(packed.heap_bytes(), 1000 * 4 * 2 + 4000 * 24);
        assert_eq!(packed.spare_bytes(), 0);
        packed.push(&quad).unwrap();
        assert!(packed.spare_bytes() > 0);
    }
}
