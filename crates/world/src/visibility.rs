//! Visible surfaces: exact object-space fragments, or a front-to-back order.
//!
//! # Exact fragments ([`exact_fragments`])
//!
//! Each screen triangle `T` is cut down to the part of it that nothing hides:
//!
//! 1. **Candidates.** The triangles' screen bounding boxes go into a uniform grid of
//!    cells (about one triangle per cell; boxes covering more than 64 cells are kept
//!    aside and checked against every triangle). For each triangle in turn, the triangles
//!    whose boxes overlap its own are its candidate occluders; only those are compared.
//!    Nothing holds more than one triangle's candidates and pieces at a time (see
//!    "Depth complexity" below).
//! 2. **Occluder pieces.** For a pair `S`, `T`, the overlap `proj(S) ∩ proj(T)` is `S`
//!    clipped against `T`'s three edge half-planes (Sutherland–Hodgman). `1/depth` is an
//!    affine function of the screen position on each triangle (see
//!    [`ScreenTriangle`]), so `d = invz_S − invz_T` is affine too, its coefficients
//!    taken from the two triangles' barycentric forms: `S` hides `T` exactly on
//!    `overlap ∩ {d > 0}`, a convex polygon. `T` minus that is `T` minus
//!    `proj(S) ∩ {d > 0}` (the `T`-edge clip only decides *whether* `S` hides anything;
//!    the piece subtracted is not clipped to `T`, so no nearly-coincident copies of `T`'s
//!    edges reach the polygon boolean). When `d > 0` on the whole overlap the piece is
//!    simply `S`. At a triangle's own vertex its `1/depth` is taken as given, not
//!    interpolated, and a cut point is interpolated from the same end of its edge
//!    whichever triangle it belongs to: adjacent triangles of a mesh (sharing vertices
//!    and their `1/depth`) are cut at the same points of their shared edge, so their
//!    pieces join without the hair-thin gaps that would otherwise remain visible.
//!    Pieces of area ≤ 1e-13 px² are skipped (they cannot hide more than that).
//!    Two quick answers come first: a pair that an edge of one separates from the other
//!    is apart (in a mesh, most candidates are neighbours sharing an edge), and a
//!    candidate farther than `T` at all six corners of the two, by a margin far above
//!    rounding, hides nothing (`d` is affine, so it is largest at one of them; the far
//!    side of a mesh seen from both sides is a candidate of every near triangle). Either
//!    way nothing is clipped, and the clips would have found no piece.
//! 3. **Coplanar pairs.** When `|d| ≤ 1e-12 · max(invz_S, invz_T)` at every vertex of the
//!    overlap, the two are taken as coplanar and the **lower index wins**: it hides the
//!    other over the whole overlap, so exactly one of them keeps it.
//! 4. **Difference.** `visible(T) = proj(T) − ⋃ pieces`, one `i_overlay` difference per
//!    triangle with all contours oriented alike and the non-zero fill rule (overlapping
//!    pieces add up, never cancel). A triangle hidden by nothing is output as it is,
//!    and one that its pieces together cover is hidden without the boolean (the pieces'
//!    edges that no other piece shares from the other side bound what they cover: when
//!    none meets the triangle and its centroid lies in a piece, all of it is covered;
//!    `crate::cover`, conservative: else the boolean decides).
//! 5. **Holes.** The Y-processor takes simple polygons without holes. A result with holes
//!    is cut by the horizontal line through the middle of its first hole's y-range into
//!    the parts above and below (intersections with two half-planes, again with
//!    `i_overlay`), recursively, until no part has a hole. The line crosses that hole's
//!    interior, so both parts have fewer of its holes. Horizontal cut edges are invisible to the
//!    trapezoidation, and both parts get identical cut vertices (both intersections run
//!    on the same integer grid, below). As a safeguard against an endless recursion, a
//!    part still cut 64 levels deep keeps its outline and its holes are dropped (and
//!    counted, as below); this has never been observed. (A part can have a hole its parent
//!    had not: an outline that touches itself at a vertex comes out of a cut as an
//!    outline and a hole touching it; it is cut in turn.)
//! 6. **Slivers.** Contours (outlines or holes) with area below 1e-12 px² are dropped and
//!    counted, with their total area, in [`VisibilityStats`]: nothing is lost silently. A
//!    dropped outline loses that area, a dropped hole lets the fragment cover it twice.
//!    Converting the grid's points back to `f64` can leave consecutive vertices a few
//!    units in the last place apart, and the thin spikes between them can cross by as
//!    much: consecutive vertices within `1e-13 · max(1, |coordinate|)` of each other are
//!    merged, and spikes (a vertex where the boundary turns back on itself within an
//!    angle of 1e-12) removed; a polygon needs three vertices left.
//! 7. **Intensities.** Each fragment vertex gets its source triangle's affine intensity
//!    there ([`ScreenTriangle::intensity_at`]), so the fragment shades exactly as the
//!    triangle would.
//!
//! Output order is deterministic: by source index, then in `i_overlay`'s order.
//!
//! ## Threads
//!
//! Each triangle's fragments depend only on the triangle, its candidates and what is
//! built once for all (the `1/depth` planes, the grid, the box index, the first of each
//! exact copy), all read-only: [`exact_fragments_on`] cuts the triangles into contiguous
//! chunks (eight per thread, so that chunks of uneven cost balance out), which the threads
//! take one at a time, and joins the chunks' fragments in triangle order. The counts are
//! summed; the dropped slivers' areas are kept per chunk and added in triangle order, as
//! one thread adds them, so the statistics too are the same bit for bit at any thread
//! count. Each thread holds one triangle's candidates and pieces at a time, as below.
//!
//! ## Depth complexity
//!
//! Memory is the index (one entry per triangle and cell it covers) plus one triangle's
//! candidates and occluder pieces: it grows like the input, not like the number of
//! occluding pairs (which grows with the square of the layers when surfaces are stacked:
//! the pot as 16 coincident layers has 750 000 of them, and holding them all took 130 MB;
//! 600 layers took more than 24 GB). Three shortcuts leave out only what could not change
//! a fragment: an exact copy of an earlier triangle (the same vertices and `1/depth`) is
//! hidden at once, without looking at its candidates (`copies_hidden`: coincident layers
//! are made of these; the copies are found before the pass by sorting the triangles on
//! a hash of their corners, so what is kept through it is one flag a triangle); a piece
//! that holds all three vertices of the triangle (a convex piece: all of it) hides it
//! without a boolean, and its remaining candidates are skipped (`candidates_skipped`); a
//! piece equal to one already taken is dropped before the boolean.
//!
//! Time still grows faster than the layers — the booleans of nearly coincident layers
//! have many crossing edges — measured in `docs/VISIBILITY.md`
//! (`cargo run --release -p cwisim-world --example depth_complexity`).
//!
//! ## Precision
//!
//! `i_overlay` works on an integer grid. All its calls here share one grid: `i64`
//! coordinates over the square `[−m, m]²`, `m` the power of two at or above the largest
//! coordinate magnitude, with `m · 2^-61` per unit (the conservative 61-bit budget of
//! `i_overlay`'s `i64` engine) — about `4e-16` px for a 1000-pixel image, far below the
//! 1e-9 px the exact coverage tests need (the default `i32` engine would give only
//! `m · 2^-29`, about 2e-6 px). The grid is centred on the origin and scaled by a power of
//! two, so input coordinates of magnitude at least `m / 512` pass through unchanged:
//! fragments keep their triangles' vertices bit for bit. Results are extracted in
//! `i_overlay`'s OGC mode, whose outlines and holes are simple rings (a hole touching
//! its outline at a point is a separate hole, not a pinched outline).
//!
//! Triangles that cannot be drawn (zero area, or a non-finite coordinate or `1/depth`)
//! get no fragment and hide nothing; they count as hidden.
//!
//! # Front-to-back order ([`front_to_back`])
//!
//! For the array's `Eval0` visibility, where each triangle claims the pixels it fully
//! covers and hides what comes later: the triangles sorted by the depth of their
//! centroid, nearest first.

use crate::boolean::{
    area, cross, grid_for, overlay, positive, settle, Contour, Grid, Losses, Pt, MAX_CUT_DEPTH,
};
use crate::face::ScreenTriangle;
use arrayvec::ArrayVec;
use cwisim_scene::Polygon;
use cwisim_scene::Vector;
use i_overlay::core::overlay_rule::OverlayRule;
use rustc_hash::FxHashMap as HashMap;
use std::hash::{Hash, Hasher};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Occluder pieces with at most this area (px²) are skipped.
const PIECE_AREA: f64 = 1e-13;
/// Relative `1/depth` difference below which two overlapping triangles are coplanar.
const COPLANAR: f64 = 1e-12;
/// The most channels an intensity vector holds.
const MAX_CHANNELS: usize = std::mem::size_of::<Vector>() / std::mem::size_of::<f64>();

/// What [`exact_fragments_on`] holds a triangle at its peak on one thread, beyond the
/// triangles themselves: their planes, boxes and index, a flag or two, and the fragments
/// it returns. 250–282 bytes were measured on the teapot at 4 to 16 quads a patch on one
/// thread, 268–299 on two (`tests/visibility_memory.rs` holds it to this). Surfaces
/// stacked deep hold more: a triangle's candidates and pieces grow with the layers over
/// it (about 580 bytes a triangle under 16 layers).
pub const PAIRS_BYTES_PER_TRIANGLE: u64 = 300;

/// What each thread past the first adds a triangle (its stamps in the index).
pub const PAIRS_BYTES_PER_TRIANGLE_PER_THREAD: u64 = 16;

/// The memory that `triangles` screen triangles of `triangle_bytes` each and their exact
/// visibility on `threads` threads (0: one per core) hold, as
/// [`PAIRS_BYTES_PER_TRIANGLE`] counts it: what a caller checks against the memory
/// budget before projecting them.
pub fn exact_memory(triangles: u64, triangle_bytes: u64, threads: usize) -> u64 {
    let extra = cwisim_scene::budget::resolve_threads(threads).saturating_sub(1) as u64;
    let per_triangle = triangle_bytes
        .saturating_add(PAIRS_BYTES_PER_TRIANGLE)
        .saturating_add(extra.saturating_mul(PAIRS_BYTES_PER_TRIANGLE_PER_THREAD));
    triangles.saturating_mul(per_triangle)
}

/// One visible piece of a screen triangle.
#[derive(Clone, Debug, PartialEq)]
pub struct Fragment {
    /// Index of the source triangle in the input slice.
    pub source: usize,
    /// The piece: a simple polygon without holes, at least 3 vertices, with the source
    /// triangle's affine intensity at each vertex.
    pub polygon: Polygon,
}

impl Fragment {
    /// The part `vertices` of triangle `tri` (index `source`), with the triangle's affine
    /// intensity (its first `channels` entries) at each vertex.
    ///
    /// # Panics
    ///
    /// If `tri` has no area (no barycentric coordinates): a visible part has some.
    pub fn of_triangle<S>(
        source: usize,
        tri: &ScreenTriangle<S>,
        vertices: Vec<[f64; 2]>,
        channels: usize,
    ) -> Fragment {
        let intensity = vertices
            .iter()
            .map(|&p| {
                let v = tri
                    .intensity_at(p, channels)
                    .expect("a visible part's triangle has area");
                cwisim_scene::VertexIntensity::from_slice(&v[..channels])
            })
            .collect::<Vec<_>>();
        Fragment {
            source,
            polygon: Polygon::new(vertices, intensity),
        }
    }
}

/// What the visibility pass did (for the CLI summary).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct VisibilityStats {
    /// Input triangles.
    pub triangles: u64,
    /// Ordered pairs `(S, T)` where `S` hides a part of `T` (an interpenetrating pair
    /// counts twice).
    pub occluding_pairs: u64,
    /// Triangles with nothing visible (including undrawable ones).
    pub hidden: u64,
    /// Fragments output.
    pub fragments: u64,
    /// Triangles hidden as exact copies of an earlier one (the same vertices and
    /// `1/depth`: coplanar over all of it, and the lower index wins), without a look at
    /// their candidates. Counted in `hidden` too.
    pub copies_hidden: u64,
    /// Candidate occluders (triangles whose screen boxes overlap) not examined because
    /// the triangle was already wholly hidden by nearer ones: see "Depth complexity" in
    /// the module docs.
    pub candidates_skipped: u64,
    /// Horizontal cuts made to remove holes.
    pub hole_cuts: u64,
    /// Contours (outlines, holes, or what was left of one after removing spikes and
    /// duplicate vertices) dropped for having less than 1e-12 px² of area.
    pub dropped_slivers: u64,
    /// Their total area (px²).
    pub dropped_area: f64,
}

/// The visible parts of `tris`, exactly: each triangle minus the parts of it that other
/// triangles hide (see the [module docs](self) for the method, its precision, and how
/// coplanar overlaps, slivers and holes are dealt with).
///
/// The triangles are expected front-facing (either orientation is accepted) and
/// non-degenerate; each fragment's intensity vectors hold the first `channels` entries of
/// its source triangle's interpolated intensity.
///
/// # Panics
///
/// If `channels` exceeds the length of an intensity [`Vector`].
pub fn exact_fragments<S: Sync>(
    tris: &[ScreenTriangle<S>],
    channels: usize,
) -> (Vec<Fragment>, VisibilityStats) {
    exact_fragments_on(tris, channels, 1)
}

/// [`exact_fragments`] on `threads` threads (0: one per core; 1: on the calling thread,
/// as [`exact_fragments`]). The output and the statistics are the same for any thread
/// count, bit for bit: the triangles are cut into contiguous chunks, which threads take
/// one at a time (the calling thread among them), and the chunks' fragments are joined
/// in triangle order and their statistics summed in that order (see "Threads" in the
/// [module docs](self)).
///
/// # Panics
///
/// If `channels` exceeds the length of an intensity [`Vector`].
pub fn exact_fragments_on<S: Sync>(
    tris: &[ScreenTriangle<S>],
    channels: usize,
    threads: usize,
) -> (Vec<Fragment>, VisibilityStats) {
    assert!(
        channels <= MAX_CHANNELS,
        "{channels} channels; an intensity vector holds at most {MAX_CHANNELS}"
    );
    let threads = cwisim_scene::budget::resolve_threads(threads);
    let usable: Vec<bool> = tris.iter().map(drawable).collect();
    let planes: Vec<Plane> = tris.iter().map(Plane::of).collect();
    let grid = grid_for(
        tris.iter()
            .zip(&usable)
            .filter(|(_, &u)| u)
            .flat_map(|(t, _)| t.points),
    );
    // Triangle by triangle, so that memory holds one triangle's occluders at a time
    // (per thread) whatever the depth complexity (see "Depth complexity" in the module
    // docs).
    let index = BoxIndex::new(tris, &usable);
    let later_copy = later_copies(tris, &usable);
    let shared = Shared {
        tris,
        channels,
        usable: &usable,
        planes: &planes,
        grid: &grid,
        index: &index,
        later_copy: &later_copy,
    };
    let n = tris.len();
    let chunks = if threads > 1 {
        (threads * CHUNKS_PER_THREAD).clamp(1, n.max(1))
    } else {
        1
    };
    let tallies: Vec<Tally> = if chunks == 1 {
        vec![shared.chunk(0..n)]
    } else {
        let range = |c: usize| c * n / chunks..(c + 1) * n / chunks;
        let next = AtomicUsize::new(0);
        let slots: Vec<Mutex<Option<Tally>>> = (0..chunks).map(|_| Mutex::new(None)).collect();
        let work = || loop {
            let c = next.fetch_add(1, Ordering::Relaxed);
            if c >= chunks {
                break;
            }
            let tally = shared.chunk(range(c));
            *slots[c].lock().unwrap_or_else(|e| e.into_inner()) = Some(tally);
        };
        std::thread::scope(|scope| {
            for _ in 1..threads.min(chunks) {
                scope.spawn(work);
            }
            work();
        });
        slots
            .into_iter()
            .map(|s| {
                s.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every chunk is taken")
            })
            .collect()
    };
    // what only the chunks read, given back before their fragments are joined (the
    // frame's fragments and these were the pass's peak together)
    drop((usable, planes, grid, index, later_copy));
    let mut stats = VisibilityStats {
        triangles: n as u64,
        ..VisibilityStats::default()
    };
    // joined into the first chunk's vector (on one thread, the only one: nothing copied)
    let total: usize = tallies.iter().map(|t| t.fragments.len()).sum();
    let mut fragments = Vec::new();
    for (k, mut t) in tallies.into_iter().enumerate() {
        if k == 0 {
            fragments = std::mem::take(&mut t.fragments);
            fragments.reserve_exact(total - fragments.len());
        }
        stats.occluding_pairs += t.stats.occluding_pairs;
        stats.hidden += t.stats.hidden;
        stats.copies_hidden += t.stats.copies_hidden;
        stats.candidates_skipped += t.stats.candidates_skipped;
        stats.hole_cuts += t.losses.hole_cuts;
        stats.dropped_slivers += t.losses.dropped.len() as u64;
        // in triangle order, one at a time, as one thread adds them
        for a in t.losses.dropped {
            stats.dropped_area += a;
        }
        fragments.extend(t.fragments);
    }
    stats.fragments = fragments.len() as u64;
    (fragments, stats)
}

/// Chunks of triangles per thread: enough that chunks of uneven cost balance out.
const CHUNKS_PER_THREAD: usize = 8;

/// What every chunk of [`exact_fragments_on`] reads.
struct Shared<'a, S> {
    tris: &'a [ScreenTriangle<S>],
    channels: usize,
    usable: &'a [bool],
    planes: &'a [Plane],
    grid: &'a Grid,
    index: &'a BoxIndex,
    /// Whether each triangle is an exact copy of an earlier usable one ([`later_copies`]).
    later_copy: &'a [bool],
}

/// What one chunk of triangles gave: its fragments in order, its counts, and the areas of
/// the slivers it dropped, in order (summed by the caller, in triangle order, so that the
/// total does not depend on how the triangles were chunked).
struct Tally {
    fragments: Vec<Fragment>,
    stats: VisibilityStats,
    losses: Losses,
}

impl<S> Shared<'_, S> {
    /// The fragments of the triangles `range`.
    fn chunk(&self, range: std::ops::Range<usize>) -> Tally {
        let Shared {
            tris,
            channels,
            usable,
            planes,
            grid,
            index,
            later_copy,
        } = *self;
        let mut tally = Tally {
            fragments: Vec::new(),
            stats: VisibilityStats::default(),
            losses: Losses::default(),
        };
        let mut seen: HashMap<u64, usize> = HashMap::default();
        let mut stamp = Vec::new();
        let mut candidates = Vec::new();
        let mut pieces: Vec<Contour> = Vec::new();
        let mut spare_pieces: Vec<Contour> = Vec::new();
        let mut contours = Vec::new();
        let mut cover_scratch = crate::cover::Scratch::default();
        for k in range {
            let tri = &tris[k];
            let before = tally.fragments.len();
            if usable[k] {
                // An exact copy of an earlier triangle (the same vertices and `1/depth`, in
                // any order) is coplanar with it over all of it, and the lower index wins:
                // hidden, without looking at anything else (coincident layers are made of
                // these).
                if later_copy[k] && area(&tri.points) > PIECE_AREA {
                    tally.stats.occluding_pairs += 1;
                    tally.stats.hidden += 1;
                    tally.stats.copies_hidden += 1;
                    continue;
                }
                index.candidates(k, &mut candidates, &mut stamp);
                seen.clear();
                spare_pieces.append(&mut pieces);
                let mut covered = false;
                for (n, &c) in candidates.iter().enumerate() {
                    let Some(piece) = piece_hiding(tris, planes, c, k, &mut spare_pieces) else {
                        continue;
                    };
                    tally.stats.occluding_pairs += 1;
                    // one piece holding all of the triangle hides it: no boolean, and the
                    // remaining candidates cannot change that
                    if contains_triangle(&piece, &tri.points) {
                        spare_pieces.push(piece);
                        covered = true;
                        tally.stats.candidates_skipped += (candidates.len() - n - 1) as u64;
                        break;
                    }
                    // a piece equal to one already taken adds nothing (coincident layers
                    // give many)
                    let first = *seen.entry(bits_hash(&piece)).or_insert(pieces.len());
                    if first == pieces.len() || !same_bits(&pieces[first], &piece) {
                        pieces.push(piece);
                    } else {
                        spare_pieces.push(piece);
                    }
                }
                // the pieces together covering all of it (the far side of a mesh under
                // the near side's triangles): hidden, without the boolean
                let cut =
                    if covered || crate::cover::covers(&tri.points, &pieces, &mut cover_scratch) {
                        Some(Vec::new())
                    } else if pieces.is_empty() {
                        None
                    } else {
                        let subject = vec![positive(tri.points.to_vec())];
                        Some(overlay(grid, &subject, &pieces, OverlayRule::Difference))
                    };
                let shapes = cut.unwrap_or_else(|| vec![vec![tri.points.to_vec()]]);
                contours.clear();
                for shape in shapes {
                    settle(grid, shape, MAX_CUT_DEPTH, &mut contours, &mut tally.losses);
                }
                for c in contours.drain(..) {
                    tally
                        .fragments
                        .push(Fragment::of_triangle(k, tri, c, channels));
                }
            }
            if tally.fragments.len() == before {
                tally.stats.hidden += 1;
            }
        }
        tally
    }
}

/// The piece of triangle `front` that hides part of triangle `back`, or `None` where it
/// hides nothing (more than [`PIECE_AREA`]). The pair is looked at as `(i, j)`, `i < j`,
/// whichever of the two is asked about, so both directions come from the same overlap,
/// bit for bit. The piece is made in a contour taken from `pool` when it has one (their
/// allocations are used again from triangle to triangle).
fn piece_hiding<S>(
    tris: &[ScreenTriangle<S>],
    planes: &[Plane],
    front: usize,
    back: usize,
    pool: &mut Vec<Contour>,
) -> Option<Contour> {
    let (i, j) = (front.min(back), front.max(back));
    let (ti, tj) = (&tris[i], &tris[j]);
    if apart(ti, tj) || apart(tj, ti) {
        return None;
    }
    if farther_all_over(tris, planes, front, back) {
        return None;
    }
    clipped_piece(tris, planes, front, back, pool)
}

/// [`piece_hiding`] for two triangles not [`apart`]: their overlap clipped to where
/// `front` is nearer.
fn clipped_piece<S>(
    tris: &[ScreenTriangle<S>],
    planes: &[Plane],
    front: usize,
    back: usize,
    pool: &mut Vec<Contour>,
) -> Option<Contour> {
    let mut contour = |points: &[Pt]| {
        let mut v = pool.pop().unwrap_or_default();
        v.clear();
        v.extend_from_slice(points);
        positive(v)
    };
    let (i, j) = (front.min(back), front.max(back));
    let (ti, tj) = (&tris[i], &tris[j]);
    let (mut overlap, mut spare) = (Small::new(), Small::new());
    inside_triangle(&tj.points, ti, &mut overlap, &mut spare);
    if area(&overlap) <= PIECE_AREA {
        return None;
    }
    // d > 0 where j is nearer than i
    let d = |p: Pt| inv_depth(tj, &planes[j], p) - inv_depth(ti, &planes[i], p);
    let dv: ArrayVec<f64, SMALL> = overlap.iter().map(|&p| d(p)).collect();
    let coplanar = overlap.iter().zip(&dv).all(|(&p, &dp)| {
        let scale = planes[i].at(p).abs().max(planes[j].at(p).abs());
        dp.abs() <= COPLANAR * scale
    });
    if coplanar {
        // the lower index (i) wins the whole overlap
        return (front == i).then(|| contour(&ti.points));
    }
    let sign = if front == j { 1.0 } else { -1.0 };
    let nearer = |p: Pt| sign * d(p);
    let points = tris[front].points;
    if dv.iter().all(|&v| sign * v >= 0.0) {
        // nearer all over the overlap: the clip would keep all of it (at most six
        // corners, each kept, none added), whose area is over the bound already
        return Some(contour(&points));
    }
    clip_into(&overlap, nearer, &mut spare);
    if area(&spare) <= PIECE_AREA {
        return None;
    }
    Some(contour(&clip(&points, nearer)))
}

/// How far below the triangle behind, relative to the size of the terms that make up
/// the two `1/depth` planes' values, a candidate must be at every corner for
/// [`farther_all_over`] to pass over it: a thousand times the coplanar tolerance, and
/// many orders of magnitude above rounding.
const FARTHER: f64 = 1e-9;

/// Whether triangle `front` is farther than triangle `back` all over both (so over their
/// overlap), by a margin: then it hides none of `back`, and [`piece_hiding`]'s clips would
/// find as much. The two `1/depth` planes' difference is affine, so over the hull of the
/// six corners — which holds the overlap — it is largest at a corner; each value there
/// is worked out with the size of its terms, and the margin is [`FARTHER`] of the largest
/// size. The values that [`piece_hiding`] finds at the overlap's corners (points in the
/// hull, whose terms are no larger) are within rounding of the exact ones, so they are
/// all negative and far from coplanar: it would return `None`.
///
/// About half the pairs that are not apart end here in a mesh seen from both sides (the
/// far side's triangles are candidates of the near side's): no polygon is clipped.
fn farther_all_over<S>(
    tris: &[ScreenTriangle<S>],
    planes: &[Plane],
    front: usize,
    back: usize,
) -> bool {
    let (pf, pb) = (&planes[front], &planes[back]);
    let mut size = 0.0f64;
    let mut nearest = f64::NEG_INFINITY;
    for p in tris[front].points.iter().chain(&tris[back].points) {
        let terms = |pl: &Plane| {
            let (gx, gy) = (pl.gx * (p[0] - pl.o[0]), pl.gy * (p[1] - pl.o[1]));
            (pl.at_o + gx + gy, pl.at_o.abs() + gx.abs() + gy.abs())
        };
        let ((zf, sf), (zb, sb)) = (terms(pf), terms(pb));
        nearest = nearest.max(zf - zb);
        size = size.max(sf).max(sb);
    }
    nearest < -FARTHER * size
}

/// Front-to-back order for the array's `Eval0` visibility: the indices of `tris` sorted
/// by the depth of each triangle's centroid, nearest first; ties (and non-finite depths,
/// which sort last) by index. Deterministic.
///
/// The centroid is the 3D triangle's: its depth is the mean of the vertex depths
/// `1 / inv_depth[k]` (depth being affine in 3D).
pub fn front_to_back<S>(tris: &[ScreenTriangle<S>]) -> Vec<usize> {
    let depth: Vec<f64> = tris
        .iter()
        .map(|t| {
            let d = t.inv_depth.iter().map(|w| 1.0 / w).sum::<f64>() / 3.0;
            if d.is_nan() {
                f64::INFINITY
            } else {
                d
            }
        })
        .collect();
    let mut order: Vec<usize> = (0..tris.len()).collect();
    order.sort_by(|&a, &b| depth[a].total_cmp(&depth[b]).then(a.cmp(&b)));
    order
}

/// Every triangle whole, in [`front_to_back`] order, as a fragment of itself (its
/// vertices' intensities, the first `channels` entries).
pub fn front_to_back_fragments<S>(tris: &[ScreenTriangle<S>], channels: usize) -> Vec<Fragment> {
    front_to_back(tris)
        .into_iter()
        .map(|k| {
            let t = &tris[k];
            Fragment {
                source: k,
                polygon: Polygon::new(
                    t.points.to_vec(),
                    t.intensity
                        .iter()
                        .map(|i| cwisim_scene::VertexIntensity::from_slice(&i[..channels]))
                        .collect::<Vec<_>>(),
                ),
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Geometry helpers.

/// Whether a triangle can be drawn: finite coordinates and `1/depth`, nonzero area.
fn drawable<S>(t: &ScreenTriangle<S>) -> bool {
    let a = t.doubled_area();
    a != 0.0
        && a.is_finite()
        && t.points.iter().flatten().all(|c| c.is_finite())
        && t.inv_depth.iter().all(|w| w.is_finite())
}

/// An affine function of the screen position, `at_o + gx (x − ox) + gy (y − oy)`,
/// relative to an origin near where it is used (for precision).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Plane {
    o: Pt,
    at_o: f64,
    gx: f64,
    gy: f64,
}

impl Plane {
    /// A triangle's `1/depth` (relative to its first vertex); zero for a degenerate one.
    fn of<S>(t: &ScreenTriangle<S>) -> Plane {
        let [a, b, c] = t.points;
        let [z0, z1, z2] = t.inv_depth;
        let d = t.doubled_area();
        let (gx, gy) = if d != 0.0 {
            (
                ((z1 - z0) * (c[1] - a[1]) - (z2 - z0) * (b[1] - a[1])) / d,
                ((z2 - z0) * (b[0] - a[0]) - (z1 - z0) * (c[0] - a[0])) / d,
            )
        } else {
            (0.0, 0.0)
        };
        Plane {
            o: a,
            at_o: z0,
            gx,
            gy,
        }
    }

    /// The value at `p`.
    fn at(&self, p: Pt) -> f64 {
        self.at_o + self.gx * (p[0] - self.o[0]) + self.gy * (p[1] - self.o[1])
    }
}

/// Triangle `t`'s `1/depth` at `p` (`plane` being [`Plane::of`] `t`): its vertex value,
/// exactly, at a vertex; the plane elsewhere. Triangles sharing a vertex (with the same
/// `1/depth`) thus agree there to the bit, and so do the cut points that
/// [`clip`] puts on a shared edge.
fn inv_depth<S>(t: &ScreenTriangle<S>, plane: &Plane, p: Pt) -> f64 {
    match t.points.iter().position(|&q| q == p) {
        Some(k) => t.inv_depth[k],
        None => plane.at(p),
    }
}

/// A triangle's vertices and `1/depth`, bit for bit, in a canonical order: equal for
/// exact copies whatever their vertex order.
fn copy_key<S>(t: &ScreenTriangle<S>) -> [u64; 9] {
    let mut corners: [[u64; 3]; 3] = std::array::from_fn(|v| {
        [
            t.points[v][0].to_bits(),
            t.points[v][1].to_bits(),
            t.inv_depth[v].to_bits(),
        ]
    });
    corners.sort_unstable();
    let [a, b, c] = corners;
    [a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]]
}

/// Whether each triangle is usable and an exact copy ([`copy_key`]) of a usable one of
/// lower index. Found by sorting the usable triangles by a hash of their keys (then
/// index), the keys compared only within a run of equal hashes: one pass over the
/// triangles in order and a sort of 16 bytes each, where a map of the keys held 80
/// bytes a triangle through the whole pass and was looked up at random (a cache miss a
/// triangle).
fn later_copies<S>(tris: &[ScreenTriangle<S>], usable: &[bool]) -> Vec<bool> {
    use std::hash::BuildHasher;
    let hasher = rustc_hash::FxBuildHasher;
    let mut keyed: Vec<(u64, usize)> = (0..tris.len())
        .filter(|&k| usable[k])
        .map(|k| (hasher.hash_one(copy_key(&tris[k])), k))
        .collect();
    keyed.sort_unstable();
    let mut later = vec![false; tris.len()];
    for run in keyed.chunk_by(|a, b| a.0 == b.0) {
        for (i, &(_, k)) in run.iter().enumerate().skip(1) {
            let key = copy_key(&tris[k]);
            later[k] = run[..i].iter().any(|&(_, j)| copy_key(&tris[j]) == key);
        }
    }
    later
}

/// A hash of a contour's coordinates, bit for bit.
fn bits_hash(c: &[Pt]) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in c {
        p[0].to_bits().hash(&mut h);
        p[1].to_bits().hash(&mut h);
    }
    h.finish()
}

/// Whether two contours have the same coordinates, bit for bit.
fn same_bits(a: &[Pt], b: &[Pt]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| p[0].to_bits() == q[0].to_bits() && p[1].to_bits() == q[1].to_bits())
}

/// Whether the convex polygon `piece` (positively oriented) holds every vertex of the
/// triangle `t` (on its boundary counts), so all of `t`.
fn contains_triangle(piece: &[Pt], t: &[Pt; 3]) -> bool {
    piece.len() >= 3
        && (0..piece.len()).all(|e| {
            let (a, b) = (piece[e], piece[(e + 1) % piece.len()]);
            t.iter().all(|&p| cross(a, b, p) >= 0.0)
        })
}

/// A convex polygon of at most [`SMALL`] vertices: a triangle clipped by up to five
/// half-planes, kept off the heap (there is one per candidate pair).
type Small = ArrayVec<Pt, SMALL>;
/// The most vertices of a [`Small`]: a triangle gains at most one per clip.
const SMALL: usize = 8;

/// The part of the convex polygon `poly` where `f ≥ 0`, `f` affine (Sutherland–Hodgman).
/// A vertex where `f` is exactly 0 is kept and not duplicated. A cut point is
/// interpolated from the lexicographically smaller end of its edge, so that polygons
/// sharing an edge (and `f`'s values at its ends) get the same cut point, to the bit.
///
/// `poly` is convex with fewer than [`SMALL`] vertices (a convex polygon gains at most one
/// vertex); a longer one gives the empty polygon rather than overflow.
fn clip(poly: &[Pt], f: impl Fn(Pt) -> f64) -> Small {
    let mut out = Small::new();
    clip_into(poly, f, &mut out);
    out
}

/// [`clip`] into `out` (cleared first), without moving a [`Small`] around.
fn clip_into(poly: &[Pt], f: impl Fn(Pt) -> f64, out: &mut Small) {
    out.clear();
    let n = poly.len();
    if n >= SMALL {
        return;
    }
    let mut values = [0.0; SMALL];
    for (v, &p) in values.iter_mut().zip(poly) {
        *v = f(p);
    }
    for k in 0..n {
        let prev = (k + n - 1) % n;
        let (a, fa, b, fb) = (poly[prev], values[prev], poly[k], values[k]);
        if (fa > 0.0 && fb < 0.0) || (fa < 0.0 && fb > 0.0) {
            let ((p, fp), (q, fq)) = if a < b {
                ((a, fa), (b, fb))
            } else {
                ((b, fb), (a, fa))
            };
            let t = fp / (fp - fq);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
        if fb >= 0.0 {
            out.push(b);
        }
    }
}

/// Whether an edge of triangle `t` has all three corners of `o` on its outside or on it:
/// the two share no area. The common candidate pair of a mesh — two neighbours whose
/// boxes overlap — ends here, without clipping.
fn apart<S>(t: &ScreenTriangle<S>, o: &ScreenTriangle<S>) -> bool {
    let s = t.doubled_area().signum();
    (0..3).any(|k| {
        let (a, b) = (t.points[k], t.points[(k + 1) % 3]);
        o.points.iter().all(|&p| s * cross(a, b, p) <= 0.0)
    })
}

/// The convex polygon `poly` clipped to the triangle `t` (either orientation), into
/// `out`; `spare` is scratch space.
fn inside_triangle<S>(poly: &[Pt], t: &ScreenTriangle<S>, out: &mut Small, spare: &mut Small) {
    let s = t.doubled_area().signum();
    let edge = |k: usize| {
        let (a, b) = (t.points[k], t.points[(k + 1) % 3]);
        move |p: Pt| s * cross(a, b, p)
    };
    // poly → spare → out → spare… ending in out after three clips. Fewer than three points
    // left after a clip (a triangle sharing an edge of `t` from outside keeps just that
    // edge's two ends) have no area, and nor has anything clipped from them: their overlap
    // is none, so the clipping stops there.
    clip_into(poly, edge(0), out);
    if out.len() < 3 {
        out.clear();
        return;
    }
    clip_into(out, edge(1), spare);
    if spare.len() < 3 {
        out.clear();
        return;
    }
    clip_into(spare, edge(2), out);
    if out.len() < 3 {
        out.clear();
    }
}

/// The usable triangles' screen bounding boxes in a uniform grid of cells, to find the
/// triangles whose boxes overlap a given one's (touching counts) without listing every
/// overlapping pair at once: memory is one entry per (triangle, cell it covers), the
/// cells' lists packed in one array.
struct BoxIndex {
    /// Each triangle's box `[x0, y0, x1, y1]`.
    boxes: Vec<[f64; 4]>,
    /// The grid's lower corner and cell size.
    origin: Pt,
    cell: Pt,
    /// Cells along `x` and along `y`.
    side: [usize; 2],
    /// `starts[c]..starts[c + 1]` indexes `cells`' entries for cell `c` (row-major).
    starts: Vec<usize>,
    /// Triangle indices, cell by cell, ascending within a cell.
    entries: Vec<u32>,
    /// Triangles whose boxes cover more than [`BIG_BOX_CELLS`] cells: checked against
    /// every triangle rather than entered in each cell.
    big: Vec<u32>,
    /// Usable triangles.
    usable: Vec<bool>,
}

/// A box covering more cells than this is kept in [`BoxIndex::big`].
const BIG_BOX_CELLS: usize = 64;

impl BoxIndex {
    fn new<S>(tris: &[ScreenTriangle<S>], usable: &[bool]) -> BoxIndex {
        let boxes: Vec<[f64; 4]> = tris
            .iter()
            .map(|t| {
                let xs = t.points.map(|p| p[0]);
                let ys = t.points.map(|p| p[1]);
                [
                    xs.iter().copied().fold(f64::INFINITY, f64::min),
                    ys.iter().copied().fold(f64::INFINITY, f64::min),
                    xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    ys.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                ]
            })
            .collect();
        let used = || boxes.iter().zip(usable).filter(|(_, &u)| u).map(|(b, _)| b);
        let count = used().count();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for b in used() {
            lo = [lo[0].min(b[0]), lo[1].min(b[1])];
            hi = [hi[0].max(b[2]), hi[1].max(b[3])];
        }
        // about one triangle per cell, at most 1024 cells along each axis, the cells shaped
        // like the average box: a row strip of small pieces (nishita's) is one cell high and
        // hundreds wide, where a square grid would enter every piece in a whole column of
        // cells and list each cell's neighbours many times over
        let mean = |axis: usize| {
            let sum: f64 = used().map(|b| b[axis + 2] - b[axis]).sum();
            sum / count.max(1) as f64
        };
        let (width, height) = (hi[0] - lo[0], hi[1] - lo[1]);
        let (box_w, box_h) = (mean(0), mean(1));
        let ratio = (width * box_h) / (height * box_w);
        let along_x = if ratio.is_finite() && ratio > 0.0 {
            (count as f64 * ratio).sqrt()
        } else {
            (count as f64).sqrt()
        };
        let along_x = (along_x.ceil() as usize).clamp(1, 1024);
        let along_y = (count.div_ceil(along_x)).clamp(1, 1024);
        let side = [along_x, along_y];
        let size = |a: f64, b: f64, n: usize| {
            let s = (b - a) / n as f64;
            if s > 0.0 && s.is_finite() {
                s
            } else {
                1.0
            }
        };
        let mut index = BoxIndex {
            origin: if count > 0 { lo } else { [0.0; 2] },
            cell: if count > 0 {
                [size(lo[0], hi[0], side[0]), size(lo[1], hi[1], side[1])]
            } else {
                [1.0; 2]
            },
            side,
            starts: vec![0; side[0] * side[1] + 1],
            entries: Vec::new(),
            big: Vec::new(),
            boxes,
            usable: usable.to_vec(),
        };
        // two passes: count each cell's entries, then fill them in triangle order
        let mut fill = vec![0usize; side[0] * side[1]];
        for pass in 0..2 {
            for k in 0..index.boxes.len() {
                if !index.usable[k] {
                    continue;
                }
                let ([x0, y0], [x1, y1]) = index.cells_of(&index.boxes[k]);
                if (x1 - x0 + 1) * (y1 - y0 + 1) > BIG_BOX_CELLS {
                    if pass == 0 {
                        index.big.push(k as u32);
                    }
                    continue;
                }
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let c = y * side[0] + x;
                        if pass == 0 {
                            index.starts[c + 1] += 1;
                        } else {
                            index.entries[index.starts[c] + fill[c]] = k as u32;
                            fill[c] += 1;
                        }
                    }
                }
            }
            if pass == 0 {
                for c in 0..side[0] * side[1] {
                    index.starts[c + 1] += index.starts[c];
                }
                index.entries = vec![0; index.starts[side[0] * side[1]]];
            }
        }
        index
    }

    /// The first and last cell `[x, y]` a box covers (clamped to the grid).
    fn cells_of(&self, b: &[f64; 4]) -> ([usize; 2], [usize; 2]) {
        let at = |v: f64, axis: usize| {
            let c = ((v - self.origin[axis]) / self.cell[axis]).floor();
            c.clamp(0.0, (self.side[axis] - 1) as f64) as usize
        };
        ([at(b[0], 0), at(b[1], 1)], [at(b[2], 0), at(b[3], 1)])
    }

    /// Whether the boxes of `a` and `b` overlap (touching counts).
    fn overlap(&self, a: usize, b: usize) -> bool {
        let (p, q) = (&self.boxes[a], &self.boxes[b]);
        p[0] <= q[2] && q[0] <= p[2] && p[1] <= q[3] && q[1] <= p[3]
    }

    /// Into `out` (cleared first): the usable triangles other than `k` whose boxes
    /// overlap `k`'s, in index order. `stamp` is scratch space kept between calls.
    fn candidates(&self, k: usize, out: &mut Vec<usize>, stamp: &mut Vec<usize>) {
        out.clear();
        // stamp[c] == k + 1: c already looked at for k (no sort to drop repeats)
        stamp.resize(self.boxes.len(), 0);
        let mark = k + 1;
        let mut take = |c: usize| {
            if stamp[c] != mark {
                stamp[c] = mark;
                if c != k && self.overlap(c, k) {
                    out.push(c);
                }
            }
        };
        let ([x0, y0], [x1, y1]) = self.cells_of(&self.boxes[k]);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let c = y * self.side[0] + x;
                for &e in &self.entries[self.starts[c]..self.starts[c + 1]] {
                    take(e as usize);
                }
            }
        }
        for &e in &self.big {
            take(e as usize);
        }
        // in index order, whatever the grid's shape
        out.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boolean::{grid_extent, tidy};
    use proptest::prelude::*;

    fn tri(points: [Pt; 3], inv_depth: [f64; 3]) -> ScreenTriangle {
        let mut intensity = [[0.0; MAX_CHANNELS]; 3];
        for (k, p) in points.iter().enumerate() {
            intensity[k][0] = p[0];
            intensity[k][1] = p[1];
        }
        ScreenTriangle {
            points,
            inv_depth,
            intensity,
            mesh: 0,
            face: 0,
            surface: Default::default(),
        }
    }

    /// A triangle with a notch that touches its outline at a vertex (a pinched outline)
    /// and a hole: the cut of the hole gave a part whose new hole (the notch) was dropped,
    /// and the triangle covered the notch's points, which another triangle's fragment
    /// covers too (181 of 40,000 sample points here).
    #[test]
    fn a_pinched_outline_with_a_hole_covers_each_point_once() {
        let tris = [
            tri([[3.5, 0.0], [0.5, 1.0], [1.0, 0.0]], [0.75, 0.75, 0.5]),
            tri([[1.5, 0.0], [1.75, 0.25], [1.5, 0.75]], [0.25, 0.75, 0.75]),
            tri([[0.5, 0.25], [1.5, 0.0], [3.25, 0.25]], [0.25, 0.75, 0.25]),
        ];
        let (frags, stats) = exact_fragments(&tris, 1);
        assert!(stats.hole_cuts > 0);
        let inside = |v: &[Pt], p: Pt| {
            let mut winding = 0;
            for i in 0..v.len() {
                let (a, b) = (v[i], v[(i + 1) % v.len()]);
                let c = cross(a, b, p);
                if a[1] <= p[1] {
                    if b[1] > p[1] && c > 0.0 {
                        winding += 1;
                    }
                } else if b[1] <= p[1] && c < 0.0 {
                    winding -= 1;
                }
            }
            winding != 0
        };
        for i in 0..400 {
            for j in 0..100 {
                let p = [
                    f64::from(i) / 100.0 + 0.00123,
                    f64::from(j) / 100.0 + 0.00071,
                ];
                // the nearest triangle holding p, by a ray cast
                let nearest = tris
                    .iter()
                    .enumerate()
                    .filter_map(|(k, t)| {
                        let w = t.barycentric(p)?;
                        w.iter().all(|&x| x > 0.0).then(|| {
                            (
                                k,
                                w[0] * t.inv_depth[0]
                                    + w[1] * t.inv_depth[1]
                                    + w[2] * t.inv_depth[2],
                            )
                        })
                    })
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|n| n.0);
                let shown: Vec<usize> = frags
                    .iter()
                    .filter(|f| inside(&f.polygon.vertices, p))
                    .map(|f| f.source)
                    .collect();
                assert_eq!(shown, Vec::from_iter(nearest), "at {p:?}");
            }
        }
    }

    #[test]
    fn plane_reproduces_inv_depth_and_differences() {
        let t = tri([[1.5, 2.25], [9.0, 3.0], [4.0, 11.0]], [0.5, 0.25, 0.125]);
        let s = tri([[0.0, 0.0], [12.0, 1.0], [2.0, 10.0]], [0.3, 0.2, 0.6]);
        let (pt, ps) = (Plane::of(&t), Plane::of(&s));
        let d = |p: Pt| inv_depth(&s, &ps, p) - inv_depth(&t, &pt, p);
        for k in 0..3 {
            assert_eq!(inv_depth(&t, &pt, t.points[k]), t.inv_depth[k]);
        }
        for p in [
            [1.5, 2.25],
            [9.0, 3.0],
            [4.0, 11.0],
            [3.3, 4.4],
            [-7.0, 20.0],
        ] {
            let (zt, zs) = (t.inv_depth_at(p).unwrap(), s.inv_depth_at(p).unwrap());
            assert!((pt.at(p) - zt).abs() < 1e-15, "{p:?}");
            assert!((ps.at(p) - zs).abs() < 1e-15, "{p:?}");
            assert!((d(p) - (zs - zt)).abs() < 1e-15, "{p:?}");
        }
    }

    #[test]
    fn clip_keeps_the_nonnegative_side_without_duplicates() {
        let square = vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        let half = clip(&square, |p| 1.0 - p[0]);
        assert_eq!(
            half.to_vec(),
            vec![[0.0, 0.0], [1.0, 0.0], [1.0, 2.0], [0.0, 2.0]]
        );
        assert_eq!(area(&half), 2.0);
        // through two vertices: no duplicated vertex
        let diag = clip(&square, |p| p[1] - p[0]);
        assert_eq!(diag.to_vec(), vec![[0.0, 0.0], [2.0, 2.0], [0.0, 2.0]]);
        assert!(clip(&square, |p| -1.0 - p[0]).is_empty());
        // clipped to a triangle, either orientation
        let t = tri([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]], [1.0; 3]);
        let mut r = t;
        r.points.swap(1, 2);
        for t in [t, r] {
            let (mut out, mut spare) = (Small::new(), Small::new());
            inside_triangle(&square, &t, &mut out, &mut spare);
            assert_eq!(area(&out), 2.0);
        }
    }

    #[test]
    fn tidy_removes_duplicates_and_spikes_only() {
        let v = vec![
            [0.0, 0.0],
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 4.0],
            [6.0, 4.0], // spike out and back
            [4.0, 4.0],
            [2.0, 4.0], // collinear, kept
            [0.0, 4.0],
        ];
        assert_eq!(
            tidy(v),
            vec![[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [2.0, 4.0], [0.0, 4.0]]
        );
        let flat = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]];
        assert!(tidy(flat).len() < 3);
    }

    /// The pairs `(i, j)`, `i < j`, the box index finds, sorted.
    fn indexed_pairs(tris: &[ScreenTriangle], usable: &[bool]) -> Vec<(usize, usize)> {
        let index = BoxIndex::new(tris, usable);
        let (mut out, mut stamp) = (Vec::new(), Vec::new());
        let mut pairs = Vec::new();
        for k in (0..tris.len()).filter(|&k| usable[k]) {
            index.candidates(k, &mut out, &mut stamp);
            pairs.extend(out.iter().filter(|&&c| c > k).map(|&c| (k, c)));
        }
        pairs.sort();
        pairs
    }

    /// The pairs `(i, j)`, `i < j`, of usable triangles whose boxes overlap, by brute force.
    fn brute_pairs(tris: &[ScreenTriangle], usable: &[bool]) -> Vec<(usize, usize)> {
        let mut expected = Vec::new();
        for i in (0..tris.len()).filter(|&k| usable[k]) {
            for j in (i + 1..tris.len()).filter(|&k| usable[k]) {
                let (a, b) = (tris[i].points, tris[j].points);
                let overlap = |k: usize| {
                    a.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min)
                        <= b.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max)
                        && b.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min)
                            <= a.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max)
                };
                if overlap(0) && overlap(1) {
                    expected.push((i, j));
                }
            }
        }
        expected
    }

    #[test]
    fn the_box_index_finds_exactly_the_overlapping_boxes() {
        let t = |x: f64, y: f64| tri([[x, y], [x + 2.0, y], [x, y + 2.0]], [1.0; 3]);
        let tris = [
            t(0.0, 0.0),
            t(1.0, 1.0),
            t(5.0, 0.0),
            t(1.5, 10.0),
            t(2.0, 2.0),
        ];
        let pairs = indexed_pairs(&tris, &[true; 5]);
        assert_eq!(pairs, brute_pairs(&tris, &[true; 5]));
        assert_eq!(pairs, vec![(0, 1), (0, 4), (1, 4)]);
        // unusable triangles take no part
        let usable = [true, false, true, true, true];
        assert_eq!(indexed_pairs(&tris, &usable), vec![(0, 4)]);
    }

    #[test]
    fn the_box_index_agrees_with_brute_force_on_small_big_and_far_triangles() {
        // a deterministic mix: small triangles, ones spanning many cells (the big list),
        // far outliers that stretch the grid, touching boxes, some unusable
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for round in 0..20 {
            let n = 5 + round * 7;
            let mut tris = Vec::new();
            for k in 0..n {
                let (x, y) = (next() * 100.0, next() * 100.0);
                let size = match k % 5 {
                    0 => 60.0 * next(),
                    1 => 1e-3,
                    _ => 6.0 * next() + 0.5,
                };
                let (x, y) = if k % 17 == 3 {
                    (x * 1e6, -y * 1e6)
                } else {
                    (x, y)
                };
                tris.push(tri([[x, y], [x + size, y], [x, y + size]], [1.0; 3]));
            }
            // two boxes that only touch
            tris.push(tri([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]], [1.0; 3]));
            tris.push(tri([[2.0, 2.0], [4.0, 2.0], [2.0, 4.0]], [1.0; 3]));
            let usable: Vec<bool> = (0..tris.len()).map(|k| k % 11 != 7).collect();
            assert_eq!(
                indexed_pairs(&tris, &usable),
                brute_pairs(&tris, &usable),
                "round {round}"
            );
        }
    }

    #[test]
    fn grid_keeps_input_vertices_exact() {
        let g = grid_for([[10.3, 7.7], [41.7, 33.35]].into_iter());
        assert_eq!(grid_extent(&g), 64.0);
        let a = vec![vec![[10.3, 7.7], [30.1, 7.7], [30.1, 25.9], [10.3, 25.9]]];
        let b = vec![vec![
            [20.45, 15.2],
            [41.7, 15.2],
            [41.7, 33.35],
            [20.45, 33.35],
        ]];
        let r = overlay(&g, &a, &b, OverlayRule::Difference);
        assert_eq!(r.len(), 1);
        let mut got = r[0][0].clone();
        got.sort_by(|p, q| p.partial_cmp(q).unwrap());
        let expected = [
            [10.3, 7.7],
            [10.3, 25.9],
            [20.45, 15.2],
            [20.45, 25.9],
            [30.1, 7.7],
            [30.1, 15.2],
        ];
        assert_eq!(got, expected);
    }

    #[test]
    fn coplanar_overlap_goes_to_the_lower_index() {
        // two triangles of the plane 1/depth = 0.5 + 0.01 x − 0.02 y
        let z = |p: Pt| 0.5 + 0.01 * p[0] - 0.02 * p[1];
        let pa = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]];
        let pb = [[2.0, 1.0], [12.0, 2.0], [3.0, 9.0]];
        let a = tri(pa, pa.map(z));
        let b = tri(pb, pb.map(z));
        let (mut out, mut spare) = (Small::new(), Small::new());
        inside_triangle(&pb, &a, &mut out, &mut spare);
        let overlap = area(&out);
        for (tris, winner) in [([a, b], 0), ([b, a], 0)] {
            let (frags, stats) = exact_fragments(&tris, 1);
            assert_eq!(stats.occluding_pairs, 1);
            let visible = |k: usize| -> f64 {
                frags
                    .iter()
                    .filter(|f| f.source == k)
                    .map(|f| area(&f.polygon.vertices))
                    .sum()
            };
            let loser = 1 - winner;
            assert_eq!(visible(winner), area(&tris[winner].points));
            let expected = area(&tris[loser].points) - overlap;
            assert!(
                (visible(loser) - expected).abs() < 1e-12,
                "{}",
                visible(loser)
            );
        }
    }

    #[test]
    fn hole_cut_gives_identical_vertices_on_both_sides() {
        let big = tri([[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]], [0.1; 3]);
        let small = tri([[20.1, 20.3], [30.7, 21.1], [22.2, 31.9]], [0.5; 3]);
        let (frags, stats) = exact_fragments(&[big, small], 2);
        assert_eq!(stats.hole_cuts, 1);
        assert_eq!(stats.dropped_slivers, 0);
        let far: Vec<&Fragment> = frags.iter().filter(|f| f.source == 0).collect();
        assert_eq!(far.len(), 2);
        // the cut's y: the middle of the hole's y-range
        let cut = 20.3 + 0.5 * (31.9 - 20.3);
        let on_cut = |f: &Fragment| -> Vec<Pt> {
            let mut v: Vec<Pt> = f
                .polygon
                .vertices
                .iter()
                .copied()
                .filter(|p| p[1] == cut)
                .collect();
            v.sort_by(|p, q| p.partial_cmp(q).unwrap());
            v
        };
        let (upper, lower) = (on_cut(far[0]), on_cut(far[1]));
        assert_eq!(upper.len(), 4, "{:?}", far[0].polygon.vertices);
        assert_eq!(upper, lower);
        // and the intensities follow the source's affine intensity (x, y)
        for f in &frags {
            for (p, i) in f.polygon.vertices.iter().zip(&f.polygon.intensity) {
                assert!((i[0] - p[0]).abs() < 1e-12 && (i[1] - p[1]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn front_to_back_sorts_by_centroid_depth_then_index() {
        let t = |w: [f64; 3]| tri([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], w);
        // depths: 2, 4/3 (mean of 1, 1, 2), 2, 1, NaN
        let tris = [
            t([0.5; 3]),
            t([1.0, 1.0, 0.5]),
            t([0.5; 3]),
            t([1.0; 3]),
            t([f64::NAN; 3]),
        ];
        assert_eq!(front_to_back(&tris), vec![3, 1, 0, 2, 4]);
        assert!(front_to_back::<()>(&[]).is_empty());
    }

    #[test]
    fn undrawable_triangles_are_hidden_and_hide_nothing() {
        let good = tri([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]], [0.1; 3]);
        let flat = tri([[0.0, 0.0], [10.0, 10.0], [5.0, 5.0]], [0.9; 3]);
        let mut nan = good;
        nan.inv_depth[1] = f64::NAN;
        let (frags, stats) = exact_fragments(&[flat, good, nan], 1);
        assert_eq!(frags.len(), 1);
        assert_eq!(frags[0].source, 1);
        assert_eq!(frags[0].polygon.vertices, good.points.to_vec());
        assert_eq!((stats.hidden, stats.occluding_pairs), (2, 0));
    }

    /// Triangles near one another in `[0, 8]²` with `1/depth` in `(0, 1]`, some of them
    /// steep (`1/depth` changing a thousandfold across them), some coplanar with others.
    fn pair() -> impl Strategy<Value = (ScreenTriangle, ScreenTriangle)> {
        let point = || (0u32..=16, 0u32..=16).prop_map(|(x, y)| [x as f64 * 0.5, y as f64 * 0.5]);
        let depth = prop_oneof![
            (1u32..=1000).prop_map(|d| d as f64 * 1e-3),
            (1u32..=1000).prop_map(|d| 1.0 - d as f64 * 1e-12),
        ];
        let one = || {
            (
                [point(), point(), point()],
                [depth.clone(), depth.clone(), depth.clone()],
            )
                .prop_map(|(points, inv_depth)| tri(points, inv_depth))
        };
        (one(), one(), any::<bool>()).prop_map(|(a, mut b, same_plane)| {
            if same_plane {
                // b in a's plane, where it lies
                let plane = Plane::of(&a);
                b.inv_depth = b.points.map(|p| plane.at(p));
            }
            (a, b)
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        /// The shortcut passes over a candidate only where the clips would find it hides
        /// nothing, either way round.
        #[test]
        fn a_candidate_farther_all_over_hides_nothing_of_what_the_clips_find(
            (a, b) in pair(),
        ) {
            let tris = [a, b];
            let planes: Vec<Plane> = tris.iter().map(Plane::of).collect();
            prop_assume!(tris.iter().all(drawable));
            for (front, back) in [(0, 1), (1, 0)] {
                if farther_all_over(&tris, &planes, front, back) {
                    prop_assert!(clipped_piece(&tris, &planes, front, back, &mut Vec::new()).is_none());
                }
            }
        }
    }

    #[test]
    fn the_shortcut_takes_a_farther_triangle_and_not_one_in_its_plane_or_crossing_it() {
        let (near, far) = (
            tri([[0.0, 0.0], [8.0, 0.0], [0.0, 8.0]], [0.5; 3]),
            tri([[1.0, 1.0], [9.0, 1.0], [1.0, 9.0]], [0.25; 3]),
        );
        let tris = [near, far, near, tri(far.points, [0.1, 0.9, 0.9])];
        let planes: Vec<Plane> = tris.iter().map(Plane::of).collect();
        assert!(farther_all_over(&tris, &planes, 1, 0));
        assert!(!farther_all_over(&tris, &planes, 0, 1));
        // the same plane: the lower index wins what they share, the clips decide
        assert!(!farther_all_over(&tris, &planes, 2, 0));
        // crossing surfaces: nearer in part
        assert!(!farther_all_over(&tris, &planes, 3, 0));
        assert!(clipped_piece(&tris, &planes, 3, 0, &mut Vec::new()).is_some());
    }

    #[test]
    fn later_copies_are_copies_of_a_usable_triangle_of_lower_index_in_any_vertex_order() {
        let a = tri([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]], [0.5, 0.25, 0.125]);
        let turned = tri(
            [a.points[1], a.points[2], a.points[0]],
            [a.inv_depth[1], a.inv_depth[2], a.inv_depth[0]],
        );
        let other_depth = tri(a.points, [0.5, 0.25, 0.25]);
        let mut broken = a;
        broken.inv_depth[0] = f64::NAN;
        // the unusable one comes first and counts for nothing; the usable copies after
        // the first are later copies, whatever their vertex order
        let tris = [broken, other_depth, a, turned, a, broken];
        let usable: Vec<bool> = tris.iter().map(drawable).collect();
        assert_eq!(
            later_copies(&tris, &usable),
            vec![false, false, false, true, true, false]
        );
        assert!(later_copies::<()>(&[], &[]).is_empty());
    }
}
