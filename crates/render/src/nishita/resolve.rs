//! Visibility band by band: a piece lies within one row strip of its band, so pieces of
//! different bands can hide nothing of one another (their overlaps have no area), and
//! the exact visible fragments of the frame are those of each band's pieces resolved
//! alone — and, within a band, those of each strip between two row lines alone. Each
//! band's pieces are made, resolved strip by strip with the scan segments of
//! [`super::segments`] and dropped before the next: memory
//! holds one band's pieces per thread (the paper's active subpatches), not the frame's.
//!
//! Bands are taken by `threads` workers, one at a time, and joined in band order: the
//! fragments, counts and statistics are the same bit for bit at any thread count. On one
//! thread each band is joined to the frame's fragments as soon as it is resolved (not all
//! bands held, then joined); on several, this thread joins them in band order as the
//! workers resolve them (holding only the bands resolved ahead of their turn). Either way
//! the joined vectors keep no spare room: the fragments are held, packed band by band
//! ([`super::merged::Fragments`]), until the rows are emitted.

use super::merged::Fragments;
use super::{check_budget, KeptSurface, PatchScene, Pieces};
use crate::error::RenderError;
use crate::settings::Settings;
use cwisim_scene::PackedPolygons;
use cwisim_world::face::{ScreenTriangle, Surface};
use cwisim_world::sweep::{strip_fragments, SegmentStats};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// What resolving one band made.
#[derive(Default)]
struct Band {
    /// Its visible fragments, in order, packed.
    polygons: PackedPolygons,
    /// Each fragment's source, an index into `triangles` (kept for Phong only).
    sources: Vec<usize>,
    /// Each fragment's patch: `mesh << 32 | patch`.
    groups: Vec<u64>,
    /// Each fragment's pixel row (its strip's).
    rows: Vec<u32>,
    /// The band's triangles that some fragment is part of (Phong only; empty otherwise).
    triangles: Vec<ScreenTriangle>,
    /// How many triangles the band had.
    count: usize,
    /// Its pieces' figures (the triangles dropped unless kept).
    pieces: Pieces,
    /// What visibility did.
    stats: SegmentStats,
    /// Host time of its visibility.
    time: Duration,
}

/// The frame, resolved band by band.
pub struct Resolved {
    /// The visible fragments, band by band, packed (held until their rows are emitted),
    /// with each one's patch and pixel row (its strip's: it lies in that row, within
    /// rounding).
    pub fragments: Fragments,
    /// Phong: each fragment's source in `triangles`.
    pub sources: Vec<usize>,
    /// Phong: every band's triangles that some fragment is part of, in order.
    pub triangles: Vec<ScreenTriangle>,
    /// All triangles.
    pub count: u64,
    /// The pieces' figures (without the triangles).
    pub pieces: Pieces,
    /// What visibility did, summed band by band.
    pub stats: SegmentStats,
    /// Host time of visibility, summed over the bands (over threads).
    pub time: Duration,
}

/// One band made and resolved. `made` counts the pieces of every band made so far (on
/// any thread): the frame's fragments grow with them, so the memory budget is checked
/// against that count, as when the frame's pieces were all held at once. `S`: what the
/// band's triangles keep of their surfaces (the whole of it, [`Surface`], to keep the
/// visible ones for Phong).
fn one_band<S: KeptSurface>(
    scene: &PatchScene,
    top: u32,
    rows: u32,
    settings: &Settings,
    made: &AtomicUsize,
) -> Result<Band, RenderError> {
    let mut pieces = Pieces::<S>::default();
    scene.band(top, rows, &mut pieces)?;
    let budget = cwisim_scene::budget::Budget::current();
    let n = pieces.triangles.len();
    let so_far = made.fetch_add(n, Ordering::Relaxed) + n;
    check_budget(&budget, so_far, top + rows, settings)?;
    let start = Instant::now();
    // strip by strip, each strip's pieces in the order they were made (a stable sort of
    // their indices, then the triangles moved where it puts them, in place)
    let strip_of = std::mem::take(&mut pieces.strip);
    let mut order: Vec<u32> = (0..strip_of.len() as u32).collect();
    order.sort_by_key(|&i| strip_of[i as usize]);
    let strips: Vec<u32> = order.iter().map(|&i| strip_of[i as usize]).collect();
    drop(strip_of);
    let mut triangles = std::mem::take(&mut pieces.triangles);
    permute(&mut triangles, &order);
    drop(order);
    let mut band = Band {
        polygons: PackedPolygons::new(scene.channels()),
        count: triangles.len(),
        ..Band::default()
    };
    let mut a = 0;
    while a < triangles.len() {
        let b = a + strips[a..].partition_point(|&k| k == strips[a]);
        let fragments = strip_fragments(&triangles[a..b], scene.channels(), &mut band.stats);
        for f in fragments {
            let t = &triangles[a + f.source];
            band.groups
                .push(u64::from(t.mesh) << 32 | u64::from(t.face));
            band.rows.push(top + strips[a] / settings.subscan);
            if S::WHOLE {
                band.sources.push(a + f.source);
            }
            band.polygons.push(&f.polygon).map_err(packing)?;
        }
        a = b;
    }
    band.time = start.elapsed();
    if S::WHOLE {
        // only the triangles some fragment is part of (the others are wholly hidden:
        // more than half of them on the teapot), the sources renumbered in order
        let mut index = vec![usize::MAX; triangles.len()];
        for s in &mut band.sources {
            if index[*s] == usize::MAX {
                index[*s] = band.triangles.len();
                band.triangles.extend(S::whole(&triangles[*s]));
            }
            *s = index[*s];
        }
    }
    band.pieces = Pieces {
        stats: pieces.stats,
        bands: pieces.bands,
        patches: pieces.patches,
        ..Pieces::default()
    };
    Ok(band)
}

/// `v` rearranged so that its `i`-th element is the one that was at `order[i]`
/// (`order` a permutation of `0..v.len()`), in place: each cycle of the permutation
/// followed once, with one element set aside.
fn permute<T: Copy>(v: &mut [T], order: &[u32]) {
    debug_assert_eq!(v.len(), order.len());
    let mut done = vec![false; v.len()];
    for start in 0..v.len() {
        if done[start] {
            continue;
        }
        let first = v[start];
        let mut j = start;
        loop {
            done[j] = true;
            let k = order[j] as usize;
            if k == start {
                v[j] = first;
                break;
            }
            v[j] = v[k];
            j = k;
        }
    }
}

/// Every band of `scene` made and resolved, on `settings.threads` threads (0: one per
/// core); `keep`: keep the triangles and each fragment's source (Phong).
pub fn resolve(
    scene: &PatchScene,
    settings: &Settings,
    keep: bool,
) -> Result<Resolved, RenderError> {
    let bands = scene.bands(settings.band);
    let threads =
        cwisim_scene::budget::resolve_threads(settings.threads).clamp(1, bands.len().max(1));
    let made = AtomicUsize::new(0);
    // the whole surfaces kept only where Phong reads the visible ones
    let one_band = |top: u32, rows: u32| {
        if keep {
            one_band::<Surface>(scene, top, rows, settings, &made)
        } else {
            one_band::<()>(scene, top, rows, settings, &made)
        }
    };
    let mut out = Resolved {
        fragments: Fragments::default(),
        sources: Vec::new(),
        triangles: Vec::new(),
        count: 0,
        pieces: Pieces {
            patches: scene.patches(),
            ..Pieces::default()
        },
        stats: SegmentStats::default(),
        time: Duration::ZERO,
    };
    if threads == 1 {
        // each band joined as soon as it is resolved: one band's fragments are held
        // twice at a time, not the frame's
        for &(top, rows) in &bands {
            join(&mut out, one_band(top, rows)?);
        }
        shrink(&mut out);
        return Ok(out);
    }
    // workers resolve the bands; this thread joins them in band order as they come, so
    // that only the bands resolved ahead of their turn are held besides the frame's
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let shared = Mutex::new(Shared {
        slots: bands.iter().map(|_| None).collect(),
        running: threads,
    });
    let ready = Condvar::new();
    let mut error = None;
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                // told when it ends, even by a panic (then the join stops waiting)
                let _running = Running {
                    shared: &shared,
                    ready: &ready,
                };
                loop {
                    if failed.load(Ordering::Relaxed) {
                        break;
                    }
                    let b = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(top, rows)) = bands.get(b) else {
                        break;
                    };
                    let r = one_band(top, rows);
                    if r.is_err() {
                        // later bands are not needed: the first error in band order wins
                        failed.store(true, Ordering::Relaxed);
                    }
                    lock(&shared).slots[b] = Some(r);
                    ready.notify_all();
                }
            });
        }
        let mut state = lock(&shared);
        for b in 0..bands.len() {
            let r = loop {
                if let Some(r) = state.slots[b].take() {
                    break Some(r);
                }
                if state.running == 0 {
                    // a band no worker reached (a worker panicked): told by the scope
                    break None;
                }
                state = ready.wait(state).unwrap_or_else(|e| e.into_inner());
            };
            match r {
                Some(Ok(band)) => {
                    drop(state);
                    join(&mut out, band);
                    state = lock(&shared);
                }
                Some(Err(e)) => {
                    failed.store(true, Ordering::Relaxed);
                    error = Some(e);
                    break;
                }
                None => break,
            }
        }
    });
    if let Some(e) = error {
        return Err(e);
    }
    shrink(&mut out);
    Ok(out)
}

/// The bands resolved and not yet joined, and the workers still running.
struct Shared {
    slots: Vec<Option<Result<Band, RenderError>>>,
    running: usize,
}

fn lock(shared: &Mutex<Shared>) -> std::sync::MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(|e| e.into_inner())
}

/// A worker running: when dropped, one fewer, told to the joining thread.
struct Running<'a> {
    shared: &'a Mutex<Shared>,
    ready: &'a Condvar,
}

impl Drop for Running<'_> {
    fn drop(&mut self) {
        lock(self.shared).running -= 1;
        self.ready.notify_all();
    }
}

/// A fragment the packed store refuses: more vertices than it indexes (the memory
/// budget is far below), or a fragment not of the scene's channels — a fault of the
/// renderer either way.
fn packing(e: cwisim_scene::packed::PackError) -> RenderError {
    RenderError::Renderer {
        renderer: "nishita",
        source: std::io::Error::other(e),
    }
}

/// Appends one band's fragments, counts and statistics to `out` (bands in order).
fn join(out: &mut Resolved, band: Band) {
    let base = out.triangles.len();
    out.fragments.push_band(band.polygons);
    out.sources.extend(band.sources.iter().map(|s| s + base));
    out.fragments.groups.extend(band.groups);
    out.fragments.rows.extend(band.rows);
    out.triangles.extend(band.triangles);
    out.count += band.count as u64;
    out.pieces.stats.merge(&band.pieces.stats);
    out.pieces.bands += band.pieces.bands;
    out.stats.add(&band.stats);
    out.time += band.time;
}

/// `out`'s vectors without their spare capacity (grown band by band).
fn shrink(out: &mut Resolved) {
    out.fragments.shrink_to_fit();
    out.sources.shrink_to_fit();
    out.triangles.shrink_to_fit();
}

#[cfg(test)]
mod tests {
    use super::permute;
    use proptest::prelude::*;

    proptest! {
        /// In place, it gives what gathering by the order into a new vector gives.
        #[test]
        fn permuting_in_place_is_gathering(keys in proptest::collection::vec(0u32..6, 0..200)) {
            // the order a stable sort of the keys gives, as `one_band` makes it
            let mut order: Vec<u32> = (0..keys.len() as u32).collect();
            order.sort_by_key(|&i| keys[i as usize]);
            let values: Vec<(u32, usize)> = keys.iter().copied().zip(0..).collect();
            let gathered: Vec<(u32, usize)> = order.iter().map(|&i| values[i as usize]).collect();
            let mut permuted = values.clone();
            permute(&mut permuted, &order);
            prop_assert_eq!(permuted, gathered);
        }
    }
}
