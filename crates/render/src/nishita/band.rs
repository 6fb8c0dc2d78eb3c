//! One band of pixel rows: the subpatches that meet it, the roots of their boundaries at
//! every row line, and the straight-sided pieces between those roots.
//!
//! * **Subpatches** (the paper's §4, eqs. 5–7): each patch is subdivided as a quadtree at
//!   `½` (with the symmetric midpoint `(a + b)/2`, so that a curve and its reverse split
//!   into bit-identical halves), keeping only the cells whose control points are not all
//!   above the band's top plane nor all below its bottom plane (eq. 7's convex-hull test:
//!   conservative, a cell dropped cannot meet the band). The band's level `L` is the
//!   smallest that makes every kept cell of the mesh flat — its projected control points
//!   within `flatness` pixels of the bilinear interpolation of its projected corners, a
//!   quarter of that for a *twisted* cell (one that may hold a silhouette,
//!   [`super::classify`]) — and is the same for every patch of the mesh in the band:
//!   neighbouring cells, in one patch or across a shared patch boundary, then share
//!   whole edges with bit-identical control points, with no T-junction.
//! * **Roots** (§3, eq. 3): every cell edge (a cubic; one record per distinct edge, keyed
//!   by its control points in a canonical direction) is clipped against each row line of
//!   the band with [`cwisim_world::clip::roots`], the tolerance in the original patch's
//!   parameter. The cells on both sides of an edge take its roots and points from the one
//!   record: bit-identical, so no crack can open between them.
//! * **Pieces** (§5's scan segments; the multi-scanning integration of the report's box
//!   filter): for each row strip and cell, the cell's boundary walked around, keeping the
//!   parts inside the strip: corners inside it, and the roots where the boundary enters or
//!   leaves it (placed on the row line exactly, at the projected `x` of the surface point
//!   at the root). Consecutive kept points are joined by straight lines; the polygon is
//!   cut into triangles (ear clipping) carrying their surface points and normals.

use super::classify::{facing, Facing};
use cwisim_world::bezier::Patch;
use cwisim_world::camera::Camera;
use cwisim_world::clip::{self, ClipStats};
use glam::DVec3;
use rustc_hash::FxHashMap as HashMap;
use std::sync::Mutex;

/// The deepest quadtree level (4^7 cells per patch).
pub const MAX_LEVEL: u32 = 7;

/// What a band needs to know of the view and the settings.
#[derive(Clone, Copy, Debug)]
pub struct Params {
    /// Root tolerance, in the patch parameter.
    pub tolerance: f64,
    /// Flatness, pixels.
    pub flatness: f64,
    /// Sub-scanlines per pixel row: strips `1/subscan` of a row high.
    pub subscan: u32,
    /// §5's second test: the cosine of the largest angle a subpatch's corner normals may
    /// make with one another before it is divided again (`None`: not tested).
    pub normal_cos: Option<f64>,
}

impl Params {
    /// Row line `k` of the band whose top row is `top`: `top + k/subscan`. The band's
    /// last line is the next band's first, bit for bit (`(rows·K)/K` is exact).
    fn line(&self, top: u32, k: u32) -> f64 {
        f64::from(top) + f64::from(k) / f64::from(self.subscan)
    }
}

/// One piece of surface: a triangle with its corners' screen points, surface points and
/// (unit, not yet turned toward the eye) normals.
#[derive(Clone, Copy, Debug)]
pub struct Piece {
    /// Screen points.
    pub screen: [[f64; 2]; 3],
    /// Surface points.
    pub world: [DVec3; 3],
    /// The patch's normals there (`None` where it has none).
    pub normals: [Option<DVec3>; 3],
    /// The patch's parameters `(u, v)` at its corners.
    pub uv: [(f64, f64); 3],
    /// The patch it is part of (index in the mesh).
    pub patch: u32,
    /// How its cell faces the eye.
    pub facing: Facing,
    /// The pixel row it lies in.
    pub row: u32,
    /// The strip it lies in: `k` for the strip between the band's row lines `k` and
    /// `k + 1` (the pixel row with one sub-scanline).
    pub strip: u32,
}

/// What a band did.
#[derive(Clone, Debug, Default)]
pub struct BandStats {
    /// Cells kept, by facing.
    pub front: u64,
    /// Back-facing cells.
    pub back: u64,
    /// Twisted cells.
    pub twisted: u64,
    /// Cells dropped by the band test (over all levels).
    pub culled: u64,
    /// Back cells of one-sided meshes, not drawn.
    pub back_culled: u64,
    /// Sum over meshes of the band's level.
    pub levels: u64,
    /// Meshes whose level reached [`MAX_LEVEL`] before every cell was flat.
    pub capped: u64,
    /// Distinct cell edges.
    pub edges: u64,
    /// The root finder's figures.
    pub clip: ClipStats,
    /// Cell × strip polygons.
    pub polygons: u64,
    /// Polygons that crossed their strip more than twice (several components, joined).
    pub split_polygons: u64,
    /// Polygons that ear clipping could not cut (not simple): cut as a fan.
    pub fans: u64,
    /// Triangles.
    pub triangles: u64,
    /// Silhouette points placed on row lines (two per polygon cut into its front and
    /// back part).
    pub silhouette_points: u64,
    /// Polygons of twisted cells with a silhouette crossing one row line only (it leaves
    /// through a cell edge): not cut.
    pub silhouettes_unsplit: u64,
    /// Host time, subpatch generation (ns).
    pub subpatch_ns: u64,
    /// Host time, roots (ns).
    pub roots_ns: u64,
    /// Host time, pieces (ns).
    pub pieces_ns: u64,
}

impl BandStats {
    /// Adds `o`.
    pub fn merge(&mut self, o: &BandStats) {
        self.front += o.front;
        self.back += o.back;
        self.twisted += o.twisted;
        self.culled += o.culled;
        self.back_culled += o.back_culled;
        self.levels += o.levels;
        self.capped += o.capped;
        self.edges += o.edges;
        self.clip.merge(&o.clip);
        self.polygons += o.polygons;
        self.split_polygons += o.split_polygons;
        self.fans += o.fans;
        self.triangles += o.triangles;
        self.silhouette_points += o.silhouette_points;
        self.silhouettes_unsplit += o.silhouettes_unsplit;
        self.subpatch_ns += o.subpatch_ns;
        self.roots_ns += o.roots_ns;
        self.pieces_ns += o.pieces_ns;
    }
}

/// A quadtree cell of a patch.
#[derive(Clone, Copy, Debug)]
pub struct Cell {
    /// The patch (index in the mesh).
    pub patch: u32,
    /// Level: the cell is `2^-level` wide in `u` and `v`.
    pub level: u32,
    /// Position `(i, j)`: `u ∈ [i, i+1]·2^-level`, `v ∈ [j, j+1]·2^-level`.
    pub index: (u32, u32),
    /// Control points, `points[row][col]` as in [`Patch`].
    pub points: [[DVec3; 4]; 4],
}

fn mid(a: DVec3, b: DVec3) -> DVec3 {
    (a + b) * 0.5
}

/// de Casteljau at `½` with the symmetric midpoint: `half(reverse(c))` is the reverse of
/// `half(c)`, bit for bit.
fn half(c: [DVec3; 4]) -> ([DVec3; 4], [DVec3; 4]) {
    let q = [mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[3])];
    let r = [mid(q[0], q[1]), mid(q[1], q[2])];
    let s = mid(r[0], r[1]);
    ([c[0], q[0], r[0], s], [s, r[1], q[2], c[3]])
}

impl Cell {
    /// Nishita's §5 test: whether two of the cell's corner normals make an angle whose
    /// cosine is below `cos` ("when the difference between the normal vectors at both
    /// endpoints is greater than a threshold, the subpatch is divided again"). A corner
    /// normal is the cross product of the tangents along the cell's two edges there (the
    /// next control point along an edge that collapses at the corner); a corner where
    /// both collapse has none, and is left out.
    pub fn normals_apart(&self, cos: f64) -> bool {
        let p = &self.points;
        let normal = |r: usize, c: usize| -> Option<DVec3> {
            let (dr, dc) = (
                if r == 0 { 1i32 } else { -1 },
                if c == 0 { 1i32 } else { -1 },
            );
            let at = |k: i32, l: i32| p[(r as i32 + k * dr) as usize][(c as i32 + l * dc) as usize];
            let corner = p[r][c];
            // along the row (u) and down the column (v), signed toward +u and +v
            let tangent = |pick: &dyn Fn(i32) -> DVec3, sign: f64| {
                (1..4)
                    .map(|k| (pick(k) - corner) * sign)
                    .find(|t| t.length_squared() > 0.0)
            };
            let u = tangent(&|k| at(0, k), f64::from(dc))?;
            let v = tangent(&|k| at(k, 0), f64::from(dr))?;
            u.cross(v).try_normalize()
        };
        let normals: Vec<DVec3> = [(0, 0), (0, 3), (3, 0), (3, 3)]
            .into_iter()
            .filter_map(|(r, c)| normal(r, c))
            .collect();
        normals
            .iter()
            .enumerate()
            .any(|(i, a)| normals[i + 1..].iter().any(|b| a.dot(*b) < cos))
    }

    /// The whole patch.
    pub fn root(patch: u32, p: &Patch) -> Cell {
        Cell {
            patch,
            level: 0,
            index: (0, 0),
            points: p.points,
        }
    }

    /// The four children: `(i, j)` → `(2i + a, 2j + b)`, in the order
    /// `(0,0), (0,1), (1,0), (1,1)` of `(a, b)`.
    pub fn split(&self) -> [Cell; 4] {
        // u first: each row
        let mut left = self.points;
        let mut right = self.points;
        for r in 0..4 {
            (left[r], right[r]) = half(self.points[r]);
        }
        let v_split = |p: &[[DVec3; 4]; 4]| {
            let mut top = *p;
            let mut bottom = *p;
            for c in 0..4 {
                let (a, b) = half([p[0][c], p[1][c], p[2][c], p[3][c]]);
                for r in 0..4 {
                    top[r][c] = a[r];
                    bottom[r][c] = b[r];
                }
            }
            (top, bottom)
        };
        let (l0, l1) = v_split(&left);
        let (r0, r1) = v_split(&right);
        let (i, j) = self.index;
        let child = |a: u32, b: u32, points| Cell {
            patch: self.patch,
            level: self.level + 1,
            index: (2 * i + a, 2 * j + b),
            points,
        };
        [
            child(0, 0, l0),
            child(0, 1, l1),
            child(1, 0, r0),
            child(1, 1, r1),
        ]
    }

    /// The cell's `(u, v)` in the patch at cell-local `(a, b)`.
    pub fn patch_uv(&self, a: f64, b: f64) -> (f64, f64) {
        let w = (-(self.level as f64)).exp2();
        (
            (f64::from(self.index.0) + a) * w,
            (f64::from(self.index.1) + b) * w,
        )
    }

    /// Its four boundary curves in cyclic order (`v = 0` along `u`, `u = 1` along `v`,
    /// `v = 1` back along `u`, `u = 0` back along `v`), and the cell-local `(u, v)` of
    /// curve parameter `t` on each.
    fn boundary(&self) -> [[DVec3; 4]; 4] {
        let p = &self.points;
        let col = |c: usize| [p[0][c], p[1][c], p[2][c], p[3][c]];
        let rev = |c: [DVec3; 4]| [c[3], c[2], c[1], c[0]];
        [p[0], col(3), rev(p[3]), rev(col(0))]
    }
}

fn boundary_uv(edge: usize, t: f64) -> (f64, f64) {
    match edge {
        0 => (t, 0.0),
        1 => (1.0, t),
        2 => (1.0 - t, 1.0),
        _ => (0.0, 1.0 - t),
    }
}

/// The view's affine screen functions of a point: `(depth, depth·x, depth·y)`.
#[derive(Clone, Copy, Debug)]
pub struct View {
    /// The camera.
    pub camera: Camera,
}

impl View {
    fn rows(&self, p: DVec3) -> (f64, f64) {
        self.camera.depth_and_scaled_row(p)
    }

    fn project(&self, p: DVec3) -> [f64; 2] {
        self.camera.project(p)
    }
}

/// Whether a cell can meet the band `[top, bottom]` (rows grow downward): not all its
/// control points strictly above the top line, nor all strictly below the bottom line.
fn meets(view: &View, c: &Cell, top: f64, bottom: f64) -> bool {
    let (mut above, mut below) = (true, true);
    for p in c.points.iter().flatten() {
        let (d, dy) = view.rows(*p);
        // s(y) = d·y − dy > 0 ⇔ the point projects above row y
        above &= d * top - dy > 0.0;
        below &= d * bottom - dy < 0.0;
    }
    !(above || below)
}

/// The cell's flatness in pixels: how far its projected control points lie from the
/// bilinear interpolation of its projected corners.
pub fn flatness(view: &View, c: &Cell) -> f64 {
    let p = &c.points;
    let q = |r: usize, col: usize| {
        let s = view.project(p[r][col]);
        glam::DVec2::new(s[0], s[1])
    };
    let (a, b, cc, d) = (q(0, 0), q(0, 3), q(3, 0), q(3, 3));
    let mut worst: f64 = 0.0;
    for r in 0..4 {
        for col in 0..4 {
            let (u, v) = (col as f64 / 3.0, r as f64 / 3.0);
            let bilinear = (a * (1.0 - u) + b * u) * (1.0 - v) + (cc * (1.0 - u) + d * u) * v;
            worst = worst.max((q(r, col) - bilinear).length());
        }
    }
    worst
}

/// A vertex on a cell edge, in the edge's canonical direction.
#[derive(Clone, Copy, Debug, PartialEq)]
struct EdgeVertex {
    /// Curve parameter in the canonical direction, `[0, 1]`.
    t: f64,
    screen: [f64; 2],
    world: DVec3,
    /// It closes a run inside the strip that does not end at the edge's end.
    exit: bool,
    /// It opens a run that does not start at the edge's start.
    entry: bool,
}

/// An edge's vertices per strip of the band, in its canonical direction.
struct EdgeRecord {
    strips: Vec<Vec<EdgeVertex>>,
}

fn key(c: &[DVec3; 4]) -> [u64; 12] {
    let mut k = [0u64; 12];
    for (i, p) in c.iter().enumerate() {
        for a in 0..3 {
            // +0.0 and −0.0 are one coordinate
            k[3 * i + a] = (p[a] + 0.0).to_bits();
        }
    }
    k
}

/// `(canonical curve, reversed?)`: the curve or its reverse, whichever has the smaller key.
fn canonical(c: [DVec3; 4]) -> ([DVec3; 4], bool) {
    let r = [c[3], c[2], c[1], c[0]];
    if key(&r) < key(&c) {
        (r, true)
    } else {
        (c, false)
    }
}

fn casteljau(c: &[DVec3; 4], t: f64) -> DVec3 {
    let q = [
        c[0] + t * (c[1] - c[0]),
        c[1] + t * (c[2] - c[1]),
        c[2] + t * (c[3] - c[2]),
    ];
    let r = [q[0] + t * (q[1] - q[0]), q[1] + t * (q[2] - q[1])];
    r[0] + t * (r[1] - r[0])
}

/// Roots of the canonical edge `c` at every line of the band, and its vertices per strip.
fn solve_edge(
    view: &View,
    c: &[DVec3; 4],
    top: u32,
    rows: u32,
    width: f64,
    params: &Params,
    stats: &mut ClipStats,
) -> EdgeRecord {
    let dy: Vec<(f64, f64)> = c.iter().map(|p| view.rows(*p)).collect();
    // events: (t, line)
    let mut events: Vec<(f64, u32)> = Vec::new();
    let strips = rows * params.subscan;
    for k in 0..=strips {
        let y = params.line(top, k);
        let s: [f64; 4] = std::array::from_fn(|i| dy[i].0 * y - dy[i].1);
        // a tolerance wider than the cell is the cell
        let found = clip::roots(&s, [0.0, width], params.tolerance.min(width))
            .expect("tolerance and domain checked when the renderer was built");
        stats.merge(&found.stats);
        for r in &found.roots {
            events.push(((r.t / width).clamp(0.0, 1.0), k));
        }
    }
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    // breakpoints: 0, events, 1
    let n = events.len();
    let param = |q: usize| -> f64 {
        if q == 0 {
            0.0
        } else if q == n + 1 {
            1.0
        } else {
            events[q - 1].0
        }
    };
    // strip of each sub-interval q (between breakpoints q and q + 1), by its midpoint
    let strip_of = |t: f64| -> Option<u32> {
        let p = casteljau(c, t);
        let (d, sy) = view.rows(p);
        let y = sy / d;
        let k = ((y - f64::from(top)) * f64::from(params.subscan)).floor();
        (k >= 0.0 && k < f64::from(strips)).then_some(k as u32)
    };
    let status: Vec<Option<u32>> = (0..=n)
        .map(|q| strip_of(0.5 * (param(q) + param(q + 1))))
        .collect();
    let point = |q: usize| -> (f64, [f64; 2], DVec3) {
        if q == 0 || q == n + 1 {
            let p = if q == 0 { c[0] } else { c[3] };
            (param(q), view.project(p), p)
        } else {
            let (t, line) = events[q - 1];
            let p = casteljau(c, t);
            let x = view.project(p)[0];
            (t, [x, params.line(top, line)], p)
        }
    };
    let mut lists = vec![Vec::new(); strips as usize];
    for q in 0..=n {
        let Some(k) = status[q] else { continue };
        let list: &mut Vec<EdgeVertex> = &mut lists[k as usize];
        let continuing = q > 0 && status[q - 1] == Some(k);
        if !continuing {
            let (t, screen, world) = point(q);
            list.push(EdgeVertex {
                t,
                screen,
                world,
                exit: false,
                entry: q > 0,
            });
        }
        let closes = q == n || status[q + 1] != Some(k);
        if closes {
            let (t, screen, world) = point(q + 1);
            list.push(EdgeVertex {
                t,
                screen,
                world,
                exit: q < n,
                entry: false,
            });
        }
    }
    EdgeRecord { strips: lists }
}

/// A polygon's vertex: screen point, surface point, cell-local `(u, v)`.
#[derive(Clone, Copy, Debug)]
struct PolyVertex {
    screen: [f64; 2],
    world: DVec3,
    uv: (f64, f64),
    /// It ends a run of the cell's boundary inside the strip (the polygon then crosses
    /// the cell along a row line to the next vertex).
    exit: bool,
    /// It starts such a run.
    entry: bool,
}

/// The pieces of one mesh's patches in the band of rows `top .. top + rows`, each handed
/// to `out` as it is made.
#[allow(clippy::too_many_arguments)]
pub fn band_pieces(
    view: &View,
    patches: &[Patch],
    known: &Facings,
    two_sided: bool,
    top: u32,
    rows: u32,
    params: &Params,
    out: &mut dyn FnMut(Piece),
    stats: &mut BandStats,
) {
    let start = std::time::Instant::now();
    let (cells, level, facings) = subpatches(view, patches, known, top, rows, params, stats);
    stats.subpatch_ns += start.elapsed().as_nanos() as u64;
    if cells.is_empty() {
        return;
    }

    // roots: one record per distinct edge
    let start = std::time::Instant::now();
    let width = (-(level as f64)).exp2();
    let mut records: HashMap<[u64; 12], EdgeRecord> = HashMap::default();
    let mut cell_edges: Vec<[([u64; 12], bool); 4]> = Vec::with_capacity(cells.len());
    for (c, f) in cells.iter().zip(&facings) {
        if *f == Facing::Back && !two_sided {
            cell_edges.push([([0; 12], false); 4]);
            continue;
        }
        let b = c.boundary();
        let mut keys = [([0u64; 12], false); 4];
        for (e, curve) in b.into_iter().enumerate() {
            let (canon, reversed) = canonical(curve);
            let k = key(&canon);
            records.entry(k).or_insert_with(|| {
                solve_edge(view, &canon, top, rows, width, params, &mut stats.clip)
            });
            keys[e] = (k, reversed);
        }
        cell_edges.push(keys);
    }
    stats.edges += records.len() as u64;
    stats.roots_ns += start.elapsed().as_nanos() as u64;

    // pieces
    let start = std::time::Instant::now();
    let mut poly: Vec<PolyVertex> = Vec::new();
    let mut corners = Vec::new();
    for ((c, f), keys) in cells.iter().zip(&facings).zip(&cell_edges) {
        if *f == Facing::Back && !two_sided {
            stats.back_culled += 1;
            continue;
        }
        for k in 0..rows * params.subscan {
            poly.clear();
            let mut exits = 0;
            for (e, (key, reversed)) in keys.iter().enumerate() {
                let list = &records[key].strips[k as usize];
                let mut push = |v: &EdgeVertex, is_exit: bool, is_entry: bool| {
                    let t = if *reversed { 1.0 - v.t } else { v.t };
                    if is_exit {
                        exits += 1;
                    }
                    let pv = PolyVertex {
                        screen: v.screen,
                        world: v.world,
                        uv: boundary_uv(e, t),
                        exit: is_exit,
                        entry: is_entry,
                    };
                    if poly.last().is_some_and(|l| l.screen == pv.screen) {
                        return;
                    }
                    poly.push(pv);
                };
                if *reversed {
                    for v in list.iter().rev() {
                        push(v, v.entry, v.exit);
                    }
                } else {
                    for v in list {
                        push(v, v.exit, v.entry);
                    }
                }
            }
            while poly.len() > 1 && poly[0].screen == poly[poly.len() - 1].screen {
                poly.pop();
            }
            if poly.len() < 3 {
                continue;
            }
            stats.polygons += 1;
            if exits > 2 {
                stats.split_polygons += 1;
            }
            let patch = &patches[c.patch as usize];
            let split = if *f == Facing::Twisted {
                silhouette_split(&poly, c, patch, view, stats)
            } else {
                None
            };
            let halves;
            let parts: [&[PolyVertex]; 2] = match split {
                Some(two) => {
                    halves = two;
                    [&halves.0, &halves.1]
                }
                None => [&poly, &[]],
            };
            for part in parts {
                if part.len() < 3 {
                    continue;
                }
                emit_part(
                    part,
                    c,
                    patch,
                    *f,
                    (top + k / params.subscan, k),
                    &mut corners,
                    out,
                    stats,
                );
            }
        }
    }
    stats.pieces_ns += start.elapsed().as_nanos() as u64;
}

/// The triangles of one straight-sided polygon of a cell.
#[allow(clippy::too_many_arguments)]
fn emit_part(
    poly: &[PolyVertex],
    c: &Cell,
    patch: &Patch,
    facing: Facing,
    (row, strip): (u32, u32),
    corners: &mut Vec<((f64, f64), Option<DVec3>)>,
    out: &mut dyn FnMut(Piece),
    stats: &mut BandStats,
) {
    let tris = triangulate(poly, &mut stats.fans);
    // each corner's patch parameters and normal once, however many triangles share it
    corners.clear();
    corners.extend(poly.iter().map(|v| {
        let (u, w) = c.patch_uv(v.uv.0, v.uv.1);
        ((u, w), patch.normal(u, w))
    }));
    for t in tris {
        out(Piece {
            screen: t.map(|k| poly[k].screen),
            world: t.map(|k| poly[k].world),
            normals: t.map(|k| corners[k].1),
            uv: t.map(|k| corners[k].0),
            patch: c.patch,
            facing,
            row,
            strip,
        });
        stats.triangles += 1;
    }
}

/// §6's silhouette points: where the polygon of a twisted cell crosses the cell along a
/// row line (from a root where the boundary leaves the strip to the next where it
/// enters) between corners whose normals face opposite ways (the view component
/// `N·(E − S)` changes sign), the point where it vanishes, found by bisection along the
/// parameter chord between the two roots and placed on the row line at its projected
/// `x`. When both of the polygon's crossings (its top and bottom) hold one, the polygon
/// is cut along the chord between them into its front and its back part, each simple on
/// the screen: the outline then runs through the silhouette points. `None` otherwise
/// (counted in `silhouettes_unsplit` when only one crossing held a sign change).
fn silhouette_split(
    poly: &[PolyVertex],
    c: &Cell,
    patch: &Patch,
    view: &View,
    stats: &mut BandStats,
) -> Option<(Vec<PolyVertex>, Vec<PolyVertex>)> {
    let n = poly.len();
    let eye = view.camera.eye;
    let toward = |uv: (f64, f64)| -> f64 {
        let (u, v) = c.patch_uv(uv.0, uv.1);
        patch
            .normal(u, v)
            .map_or(0.0, |nrm| nrm.dot(eye - patch.point(u, v)))
    };
    let lerp =
        |a: (f64, f64), b: (f64, f64), t: f64| (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
    let mut crossings = 0;
    let mut found: Vec<(usize, PolyVertex)> = Vec::new();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if !(a.exit && b.entry && a.screen[1] == b.screen[1]) {
            continue;
        }
        crossings += 1;
        let (ha, hb) = (toward(a.uv), toward(b.uv));
        if ha * hb >= 0.0 {
            continue;
        }
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..52 {
            let m = 0.5 * (lo + hi);
            if (toward(lerp(a.uv, b.uv, m)) < 0.0) == (ha < 0.0) {
                lo = m;
            } else {
                hi = m;
            }
        }
        let uv = lerp(a.uv, b.uv, 0.5 * (lo + hi));
        let (u, v) = c.patch_uv(uv.0, uv.1);
        let p = patch.point(u, v);
        found.push((
            i,
            PolyVertex {
                screen: [view.project(p)[0], a.screen[1]],
                world: p,
                uv,
                exit: false,
                entry: false,
            },
        ));
    }
    if found.len() == 2 && crossings == 2 {
        let ((i1, s1), (i2, s2)) = (found[0], found[1]);
        let walk = |from: usize, to: usize| {
            let mut v = Vec::new();
            let mut k = from % n;
            loop {
                v.push(poly[k]);
                if k == to {
                    break;
                }
                k = (k + 1) % n;
            }
            v
        };
        let mut front = walk(i1 + 1, i2);
        front.extend([s2, s1]);
        let mut back = walk(i2 + 1, i1);
        back.extend([s1, s2]);
        stats.silhouette_points += 2;
        return Some((front, back));
    }
    if !found.is_empty() {
        stats.silhouettes_unsplit += 1;
    }
    None
}

/// How the quadtree cells of one mesh's patches face the eye, remembered across bands. A
/// cell meets every band its rows span and is built from its patch alike, bit for bit, in
/// each, so its facing (the degree-8 × 8 product of [`super::classify`], the costliest
/// test of a band) is computed once. A pure function of the cell, so the threads that take
/// bands share it and get the same at any thread count. One entry (about 24 bytes) per cell
/// classified.
#[derive(Debug, Default)]
pub struct Facings(Mutex<HashMap<(u32, u32, u32, u32), Facing>>);

impl Facings {
    /// How `c` faces the eye.
    pub fn of(&self, view: &View, c: &Cell) -> Facing {
        let key = (c.patch, c.level, c.index.0, c.index.1);
        let known = |m: &Mutex<HashMap<_, Facing>>| {
            m.lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .get(&key)
                .copied()
        };
        if let Some(f) = known(&self.0) {
            return f;
        }
        let f = facing(&c.points, view.camera.eye);
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .insert(key, f);
        f
    }
}

/// The subpatches of `patches` that meet the band of rows `top .. top + rows`: the
/// quadtree cells of the band's level (the smallest that makes every kept cell flat,
/// twisted ones to a quarter of the flatness, at most [`MAX_LEVEL`]), the level, and
/// how each cell faces the eye.
pub fn subpatches(
    view: &View,
    patches: &[Patch],
    known: &Facings,
    top: u32,
    rows: u32,
    params: &Params,
    stats: &mut BandStats,
) -> (Vec<Cell>, u32, Vec<Facing>) {
    let (ytop, ybottom) = (f64::from(top), f64::from(top + rows));
    let mut cells: Vec<Cell> = Vec::new();
    for (k, p) in patches.iter().enumerate() {
        let c = Cell::root(k as u32, p);
        if meets(view, &c, ytop, ybottom) {
            cells.push(c);
        } else {
            stats.culled += 1;
        }
    }
    if cells.is_empty() {
        return (cells, 0, Vec::new());
    }
    let mut level = 0;
    let mut facings: Vec<Option<Facing>> = vec![None; cells.len()];
    loop {
        let mut done = true;
        for (c, f) in cells.iter().zip(facings.iter_mut()) {
            let flat = flatness(view, c);
            if flat > params.flatness {
                done = false;
                break;
            }
            if params
                .normal_cos
                .is_some_and(|cos| c.level < MAX_LEVEL && c.normals_apart(cos))
            {
                done = false;
                break;
            }
            if flat > 0.25 * params.flatness {
                let fc = known.of(view, c);
                *f = Some(fc);
                if fc == Facing::Twisted {
                    done = false;
                    break;
                }
            }
        }
        if done {
            break;
        }
        if level == MAX_LEVEL {
            stats.capped += 1;
            break;
        }
        let mut next = Vec::with_capacity(cells.len() * 4);
        for c in &cells {
            for child in c.split() {
                if meets(view, &child, ytop, ybottom) {
                    next.push(child);
                } else {
                    stats.culled += 1;
                }
            }
        }
        cells = next;
        facings = vec![None; cells.len()];
        level += 1;
    }
    stats.levels += u64::from(level);
    let facings: Vec<Facing> = cells
        .iter()
        .zip(facings)
        .map(|(c, f)| f.unwrap_or_else(|| known.of(view, c)))
        .collect();
    for f in &facings {
        match f {
            Facing::Front => stats.front += 1,
            Facing::Back => stats.back += 1,
            Facing::Twisted => stats.twisted += 1,
        }
    }
    (cells, level, facings)
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Ear clipping of a polygon given in order; a polygon that is not simple (no ear left)
/// is finished as a fan, counted in `fans`. Zero-area triangles are left out.
fn triangulate(poly: &[PolyVertex], fans: &mut u64) -> Vec<[usize; 3]> {
    let n = poly.len();
    let p = |i: usize| poly[i].screen;
    let area2: f64 = (0..n)
        .map(|i| cross([0.0, 0.0], p(i), p((i + 1) % n)))
        .sum();
    let sign = if area2 < 0.0 { -1.0 } else { 1.0 };
    let mut idx: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    while idx.len() > 3 {
        let m = idx.len();
        let mut cut = None;
        for k in 0..m {
            let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            if sign * cross(p(a), p(b), p(c)) <= 0.0 {
                continue;
            }
            let inside = idx.iter().any(|&o| {
                o != a
                    && o != b
                    && o != c
                    && sign * cross(p(a), p(b), p(o)) >= 0.0
                    && sign * cross(p(b), p(c), p(o)) >= 0.0
                    && sign * cross(p(c), p(a), p(o)) >= 0.0
            });
            if !inside {
                cut = Some(k);
                break;
            }
        }
        match cut {
            Some(k) => {
                let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
                out.push([a, b, c]);
                idx.remove(k);
            }
            None => {
                // collinear leftovers or a polygon that is not simple: a fan
                let nonzero = idx
                    .windows(3)
                    .any(|w| cross(p(w[0]), p(w[1]), p(w[2])) != 0.0);
                if nonzero {
                    *fans += 1;
                }
                for k in 1..idx.len() - 1 {
                    out.push([idx[0], idx[k], idx[k + 1]]);
                }
                idx.clear();
                break;
            }
        }
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
    out.retain(|&[a, b, c]| cross(p(a), p(b), p(c)) != 0.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift64*).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn point(&mut self) -> DVec3 {
            DVec3::new(
                self.next() * 7.0 - 3.0,
                self.next() * 5.0,
                self.next() * 3.0 - 9.0,
            )
        }
    }

    fn bits(c: &[DVec3]) -> Vec<u64> {
        c.iter()
            .flat_map(|p| p.to_array().map(f64::to_bits))
            .collect()
    }

    #[test]
    fn half_of_the_reverse_is_the_reverse_of_half_bit_for_bit() {
        let mut rng = Rng(17);
        for _ in 0..1000 {
            let c = [rng.point(), rng.point(), rng.point(), rng.point()];
            let r = [c[3], c[2], c[1], c[0]];
            let (a, b) = half(c);
            let (ra, rb) = half(r);
            let rev = |x: [DVec3; 4]| [x[3], x[2], x[1], x[0]];
            assert_eq!(bits(&rev(b)), bits(&ra));
            assert_eq!(bits(&rev(a)), bits(&rb));
            // and the canonical direction is one curve either way
            assert_eq!(key(&canonical(c).0), key(&canonical(r).0));
        }
    }

    #[test]
    fn neighbouring_cells_share_their_edges_bit_for_bit() {
        let mut rng = Rng(5);
        let mut pts = [[DVec3::ZERO; 4]; 4];
        for row in pts.iter_mut() {
            for p in row.iter_mut() {
                *p = rng.point();
            }
        }
        let patch = Patch::new(pts);
        // two levels: 16 cells, every neighbour pair across parents too
        let mut cells = vec![Cell::root(0, &patch)];
        for _ in 0..2 {
            cells = cells.iter().flat_map(|c| c.split()).collect();
        }
        let at = |i: u32, j: u32| cells.iter().find(|c| c.index == (i, j)).unwrap();
        let mut pairs = 0;
        for i in 0..4 {
            for j in 0..4 {
                let c = at(i, j);
                let [bottom, right, top, _] = c.boundary();
                if i + 1 < 4 {
                    // u = 1 of (i, j) is u = 0 of (i + 1, j), traversed the other way
                    let n = at(i + 1, j).boundary()[3];
                    assert_eq!(bits(&right), bits(&[n[3], n[2], n[1], n[0]]));
                    pairs += 1;
                }
                if j + 1 < 4 {
                    let n = at(i, j + 1).boundary()[0];
                    assert_eq!(bits(&top), bits(&[n[3], n[2], n[1], n[0]]));
                    pairs += 1;
                }
                let _ = bottom;
            }
        }
        assert_eq!(pairs, 24);
    }

    #[test]
    fn ear_clipping_tiles_convex_and_concave_polygons() {
        let v = |x: f64, y: f64| PolyVertex {
            screen: [x, y],
            world: DVec3::ZERO,
            uv: (0.0, 0.0),
            exit: false,
            entry: false,
        };
        let area = |p: &[PolyVertex]| {
            let n = p.len();
            0.5 * (0..n)
                .map(|i| cross([0.0, 0.0], p[i].screen, p[(i + 1) % n].screen))
                .sum::<f64>()
                .abs()
        };
        for poly in [
            vec![v(0.0, 0.0), v(4.0, 0.0), v(4.0, 1.0), v(0.0, 1.0)],
            // concave (an L), and with a collinear vertex
            vec![
                v(0.0, 0.0),
                v(2.0, 0.0),
                v(4.0, 0.0),
                v(4.0, 1.0),
                v(1.0, 1.0),
                v(1.0, 3.0),
                v(0.0, 3.0),
            ],
            // clockwise
            vec![
                v(0.0, 0.0),
                v(0.0, 1.0),
                v(3.0, 1.0),
                v(2.0, 0.5),
                v(3.0, 0.0),
            ],
        ] {
            let mut fans = 0;
            let tris = triangulate(&poly, &mut fans);
            let sum: f64 = tris
                .iter()
                .map(|&[a, b, c]| 0.5 * cross(poly[a].screen, poly[b].screen, poly[c].screen).abs())
                .sum();
            assert!(
                (sum - area(&poly)).abs() < 1e-12,
                "{sum} vs {}",
                area(&poly)
            );
            assert_eq!(fans, 0);
        }
    }
}
