//! Nishita et al.'s §7: shadows on the patches, from the light's own scan of them.
//!
//! "Shadows are invisible sections when a light source is reckoned as a viewpoint": the
//! paper runs its scanline algorithm again with the light as the eye, each scan segment
//! and the light making a scan plane whose intersections with the patches, seen from the
//! light, say which sections of the segment the light does not reach. This module does
//! the two-dimensional equivalent with the machinery the camera's image uses:
//!
//! 1. **The light's scan.** A pinhole view at the light holding every control point of
//!    every patch and every vertex of the other meshes ([`cwisim_world::shadow::one_view`];
//!    a square image as many pixels a side as the camera's image is at its widest). The
//!    patches are cut into subpatches and pieces band by band in that view exactly as the
//!    camera's are ([`super::band`]: `--flatness`, `--band`, roots to `--root-tolerance`),
//!    both sides of every patch (an open surface's inside casts shadows too); the other
//!    meshes' triangles are projected into it, and exact visibility finds what the light
//!    sees: its visible fragments, each on a plane.
//! 2. **Each camera piece seen from the light.** A camera piece (or another mesh's
//!    triangle) is a flat triangle in the world; projected into the light's view it covers
//!    a triangle there. The light does not reach the parts of it behind a visible
//!    fragment that lies *in front of it* there: each fragment near it is clipped to the
//!    triangle and to the half-plane where the fragment is nearer the light (both inverse
//!    depths are affine on the light's screen, so that side is a half-plane). What is left
//!    is exact, and the shadowed parts are mapped onto the camera's screen through the
//!    piece's own plane.
//! 3. **Cut and shade** as every renderer's shadows are: the camera's visible fragments
//!    cut by the shadowed parts, each piece shaded without the lights that do not reach it
//!    ([`cwisim_world::shadow::shadowed_by`]), then box-filtered as the rest of `nishita`.
//!
//! The light's pieces and the camera's are two different cuts of one curved surface, a
//! flatness apart: where they cross, the surface would shadow itself by their difference
//! (thin dark streaks along the light's piece boundaries). So a fragment shadows a piece
//! only where it is nearer the light by more than their two cuts can differ: a relative
//! depth of `flatness · (1/f_light + 1/f_camera)`, one flatness in each view (`f` each
//! view's focal length in pixels). A quarter of that brings the streaks back on the
//! teapot; four times it leaves the handle lit for a few pixels where it meets the body.
//! A caster nearer its receiver than the margin, along the light's ray, casts no shadow
//! on it; on flat patches the cuts agree and the shadow of
//! one patch on another is the exact shadow polygon. A light that cannot see the patches
//! within one view (a lamp just over them, a light among them) is refused, located,
//! naming `vanrij`, whose shadow pass sees a scene through a cube's six views.

use super::band::{band_pieces, BandStats};
use super::PatchScene;
use crate::error::RenderError;
use crate::settings::Settings;
use cwisim_scene::{SceneError, SceneErrorKind};
use cwisim_world::camera::Camera;
use cwisim_world::face::{ScreenTriangle, Surface};
use cwisim_world::shadow::{
    bounding_box, light_triangle, one_view, world_at, Casters, Reach, ShadowTest,
};
use cwisim_world::visibility::{exact_fragments_on, Fragment};
use cwisim_world::WorldScene;
use glam::DVec3;

/// A point on a screen.
type Pt = [f64; 2];

/// Below this share of a triangle's area, a shadowed part counts as none (and above
/// one less this, as the whole).
const WHOLE: f64 = 1e-12;

/// Light-view pixels per cell of the grid the light's fragments are found by.
const CELL: f64 = 8.0;

/// What the lights' scans did, for the summary.
#[derive(Clone, Debug, Default)]
pub struct LightScanStats {
    /// What the bands of the lights' views did.
    pub bands: BandStats,
    /// Pieces of the patches in the lights' views.
    pub pieces: u64,
    /// Triangles in the lights' views: the pieces and the other meshes' triangles.
    pub triangles: u64,
    /// Fragments the lights see.
    pub fragments: u64,
    /// Fragment–triangle pairs clipped: a fragment near a camera triangle and nearer the
    /// light at one of its corners at least.
    pub clipped: u64,
}

/// `a·x + b·y + c`: an affine function on a screen.
#[derive(Clone, Copy, Debug)]
struct Affine([f64; 3]);

impl Affine {
    /// The affine function taking `values` at the triangle `points` (`None`: no area).
    fn through(points: &[Pt; 3], values: [f64; 3]) -> Option<Affine> {
        let (p0, p1, p2) = (points[0], points[1], points[2]);
        let det = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let (d1, d2) = (values[1] - values[0], values[2] - values[0]);
        let a = (d1 * (p2[1] - p0[1]) - d2 * (p1[1] - p0[1])) / det;
        let b = (d2 * (p1[0] - p0[0]) - d1 * (p2[0] - p0[0])) / det;
        Some(Affine([a, b, values[0] - a * p0[0] - b * p0[1]]))
    }

    fn at(&self, p: Pt) -> f64 {
        self.0[0] * p[0] + self.0[1] * p[1] + self.0[2]
    }
}

/// The part of the polygon `poly` where `f ≥ 0` (one Sutherland–Hodgman step: a part that
/// falls apart stays one contour, joined along `f = 0` with no area there).
fn clip(poly: &[Pt], f: impl Fn(Pt) -> f64) -> Vec<Pt> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (fp, fq) = (f(p), f(q));
        if fp >= 0.0 {
            out.push(p);
        }
        if (fp > 0.0 && fq < 0.0) || (fp < 0.0 && fq > 0.0) {
            let t = fp / (fp - fq);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
    }
    if out.len() < 3 {
        out.clear();
    }
    out
}

/// Twice the signed area of `points`.
fn area2(points: &[Pt]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// A fragment the light sees: its polygon on the light's screen, its bounding box, and
/// its inverse depth from the light (affine there).
struct Seen {
    polygon: Vec<Pt>,
    bounds: [f64; 4],
    inv_depth: Affine,
}

/// The light's fragments, found by a grid of cells over its screen (a fragment is listed
/// in every cell its bounding box meets).
struct SeenGrid {
    seen: Vec<Seen>,
    side: usize,
    cells: Vec<Vec<u32>>,
}

impl SeenGrid {
    fn new(seen: Vec<Seen>, pixels: u32) -> SeenGrid {
        let side = ((f64::from(pixels) / CELL).ceil() as usize).max(1);
        let mut cells = vec![Vec::new(); side * side];
        for (i, s) in seen.iter().enumerate() {
            let (x0, x1) = (cell(s.bounds[0], side), cell(s.bounds[2], side));
            let (y0, y1) = (cell(s.bounds[1], side), cell(s.bounds[3], side));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    cells[y * side + x].push(i as u32);
                }
            }
        }
        SeenGrid { seen, side, cells }
    }

    /// The fragments whose bounding boxes meet the box `b`, each once, ascending.
    fn near(&self, b: [f64; 4], out: &mut Vec<u32>) {
        out.clear();
        let (x0, x1) = (cell(b[0], self.side), cell(b[2], self.side));
        let (y0, y1) = (cell(b[1], self.side), cell(b[3], self.side));
        for y in y0..=y1 {
            for x in x0..=x1 {
                for &i in &self.cells[y * self.side + x] {
                    let s = &self.seen[i as usize].bounds;
                    if s[0] <= b[2] && b[0] <= s[2] && s[1] <= b[3] && b[1] <= s[3] {
                        out.push(i);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// The grid cell of screen coordinate `t` on a grid of `side` cells (clamped to it).
fn cell(t: f64, side: usize) -> usize {
    if t.is_nan() {
        return 0;
    }
    ((t / CELL).floor().max(0.0) as usize).min(side - 1)
}

/// How the light whose visible fragments are `grid` reaches the camera triangle `t`: its
/// world triangle projected into the light's view (`view`), the parts of it behind a
/// fragment nearer the light by more than the relative depth `margin` found there, and
/// mapped onto the camera's screen through its plane.
fn reach(
    t: &ScreenTriangle,
    view: &Camera,
    camera: &Camera,
    grid: &SeenGrid,
    margin: f64,
    near: &mut Vec<u32>,
    stats: &mut LightScanStats,
) -> Reach {
    let lt = light_triangle(view, t.mesh, t.face, t.surface.world);
    let Some(own) = Affine::through(&lt.points, lt.inv_depth) else {
        // edge-on to the light: it gets none of its light
        return Reach::Nothing;
    };
    let orientation = area2(&lt.points).signum();
    let whole = area2(&lt.points).abs() / 2.0;
    let triangle = lt.points;
    grid.near(bounding_box(&triangle), near);
    let mut shadowed = Vec::new();
    let mut area = 0.0;
    for &i in near.iter() {
        let s = &grid.seen[i as usize];
        // nearer the light than the triangle by more than the margin: 1/depth greater
        let nearer = |p: Pt| s.inv_depth.at(p) - (1.0 + margin) * own.at(p);
        if s.polygon.iter().all(|&p| nearer(p) <= 0.0) && triangle.iter().all(|&p| nearer(p) <= 0.0)
        {
            continue;
        }
        stats.clipped += 1;
        let mut part = clip(&s.polygon, nearer);
        for e in 0..3 {
            if part.is_empty() {
                break;
            }
            let (a, b) = (triangle[e], triangle[(e + 1) % 3]);
            part = clip(&part, |p| {
                orientation * ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]))
            });
        }
        if part.is_empty() {
            continue;
        }
        let a = area2(&part).abs() / 2.0;
        if a > 0.0 {
            area += a;
            shadowed.push(part);
        }
    }
    if area <= WHOLE * whole {
        Reach::All
    } else if area >= (1.0 - WHOLE) * whole {
        Reach::Nothing
    } else {
        Reach::unlit(
            shadowed
                .into_iter()
                .map(|c| {
                    c.into_iter()
                        .map(|q| camera.project(world_at(&lt, q)))
                        .collect()
                })
                .collect(),
        )
    }
}

/// A light's view of a piece of a patch, as the light's pieces make it.
fn light_piece(p: &super::band::Piece, mesh: u32, camera: &Camera) -> ScreenTriangle {
    ScreenTriangle {
        points: p.screen,
        inv_depth: p.world.map(|q| 1.0 / camera.depth(q)),
        intensity: Default::default(),
        mesh,
        face: p.patch,
        surface: Surface {
            world: p.world,
            normals: [DVec3::ZERO; 3],
            uv: p.uv.map(|(u, v)| [u, v]),
        },
    }
}

/// Every triangle of the meshes of `w` that are not patches, in the world, with its mesh
/// and face (the fans [`cwisim_world::project::project`] makes).
fn other_triangles(w: &WorldScene) -> Vec<(u32, u32, [DVec3; 3])> {
    let mut out = Vec::new();
    for (k, mesh) in w.meshes.iter().enumerate() {
        if w.spec.meshes[k].bezier.is_some() {
            continue;
        }
        for (f, face) in mesh.faces.iter().enumerate() {
            for tri in face.triangles() {
                let p = tri.map(|c| mesh.positions[face.corners[c] as usize]);
                out.push((k as u32, f as u32, p));
            }
        }
    }
    out
}

/// Light `k`'s view of the scene, scanned: the patches' pieces (`scene`'s, seen from the
/// light) band by band and the other meshes' triangles `others`, resolved; its visible
/// fragments.
fn light_scan(
    settings: &Settings,
    scene: &PatchScene,
    others: &[(u32, u32, [DVec3; 3])],
    k: usize,
    view: Camera,
    side: u32,
    stats: &mut LightScanStats,
) -> Result<(Vec<ScreenTriangle>, Vec<Fragment>), RenderError> {
    let light = scene.seen_from(view, side);
    let mut tris: Vec<ScreenTriangle> = Vec::new();
    let budget = cwisim_scene::budget::Budget::current();
    for (top, rows) in light.bands(settings.band) {
        for ((mesh, patches), known) in light.meshes.iter().zip(&light.facings) {
            band_pieces(
                &light.view,
                patches,
                known,
                true,
                top,
                rows,
                &light.params,
                &mut |p| tris.push(light_piece(&p, *mesh as u32, &view)),
                &mut stats.bands,
            );
        }
        budget
            .check_memory(
                &format!(
                    "light {k}'s view of the patches ({} pieces so far, at its row {})",
                    tris.len(),
                    top + rows
                ),
                tris.len() as u64 * super::BYTES_PER_PIECE,
            )
            .map_err(|e| {
                SceneError::at_field(
                    SceneErrorKind::Limit,
                    format!("lights[{k}].position"),
                    e.to_string(),
                )
            })?;
    }
    stats.pieces += tris.len() as u64;
    tris.extend(
        others
            .iter()
            .map(|&(mesh, face, world)| light_triangle(&view, mesh, face, world)),
    );
    stats.triangles += tris.len() as u64;
    let (fragments, _) = exact_fragments_on(&tris, 1, settings.threads);
    stats.fragments += fragments.len() as u64;
    Ok((tris, fragments))
}

/// What every light of `casters` reaches of the camera's triangles `tris` of `w` (the
/// patches' pieces, `scene`'s, and the other meshes' triangles as `project` makes them)
/// that have visible `fragments`: each light's own scan of the patches ([module
/// docs](self)), cut as `settings` says (`--band`, `--flatness`, …), resolved on
/// `--threads`.
pub fn shadow_test(
    w: &WorldScene,
    settings: &Settings,
    scene: &PatchScene,
    tris: &[ScreenTriangle],
    fragments: &[Fragment],
    casters: &Casters,
    stats: &mut LightScanStats,
) -> Result<ShadowTest, RenderError> {
    let mut reaches: Vec<Vec<Reach>> = vec![Vec::with_capacity(casters.lights.len()); tris.len()];
    let mut visible = vec![false; tris.len()];
    for f in fragments {
        visible[f.source] = true;
    }
    let others = other_triangles(w);
    let camera = Camera::new(&w.spec.camera, w.width(), w.height());
    let side = w.width().max(w.height());
    let mut points: Vec<DVec3> = scene.control_points().collect();
    points.extend(others.iter().flat_map(|(_, _, p)| *p));
    for &k in &casters.lights {
        let Some(view) = one_view(&w.spec, k, &points, side)? else {
            return Err(SceneError::at_field(
                SceneErrorKind::Geometry,
                format!("lights[{k}].position"),
                format!(
                    "light {k} casts shadows on Bézier patches, but it sees the scene wider than one view holds (85° from its mean direction), or all around it: nishita scans the patches from the light through one view; use --renderer vanrij (a cube's six views of the patches tessellated, --tessellate)"
                ),
            )
            .into());
        };
        let (ltris, lfragments) = light_scan(settings, scene, &others, k, view, side, stats)?;
        let seen = lfragments
            .iter()
            .filter_map(|f| {
                let t = &ltris[f.source];
                let inv_depth = Affine::through(&t.points, t.inv_depth)?;
                Some(Seen {
                    bounds: bounding_box(&f.polygon.vertices),
                    polygon: f.polygon.vertices.clone(),
                    inv_depth,
                })
            })
            .collect();
        drop(lfragments);
        drop(ltris);
        let grid = SeenGrid::new(seen, side);
        let margin = settings.flatness * (1.0 / view.focal() + 1.0 / camera.focal());
        let mut near = Vec::new();
        for (j, t) in tris.iter().enumerate() {
            reaches[j].push(if visible[j] {
                reach(t, &view, &camera, &grid, margin, &mut near, stats)
            } else {
                Reach::All
            });
        }
    }
    let mut test = ShadowTest::with_reach(w, settings.shading, tris, casters, reaches);
    test.light_triangles = stats.triangles;
    test.light_fragments = stats.fragments;
    Ok(test)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_affine_function_takes_its_values_at_the_corners() {
        let p = [[1.0, 2.0], [7.0, 3.0], [2.0, 9.0]];
        let f = Affine::through(&p, [0.5, 0.25, 2.0]).unwrap();
        for (q, v) in p.iter().zip([0.5, 0.25, 2.0]) {
            assert!((f.at(*q) - v).abs() < 1e-14);
        }
        assert!(Affine::through(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], [1.0; 3]).is_none());
    }

    #[test]
    fn a_half_plane_clip_keeps_what_lies_on_its_side() {
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        // x ≥ 0.5: 1.5 × 2
        let c = clip(&square, |p| p[0] - 0.5);
        assert!((area2(&c).abs() / 2.0 - 3.0).abs() < 1e-15, "{c:?}");
        assert!(clip(&square, |p| p[0] - 5.0).is_empty());
        assert_eq!(clip(&square, |p| p[0] + 1.0).len(), 4);
    }

    #[test]
    fn the_grid_finds_every_fragment_a_box_meets_once() {
        let flat = Affine([0.0, 0.0, 1.0]);
        let seen: Vec<Seen> = (0..60)
            .map(|i| {
                let x = f64::from(i) * 3.0;
                let polygon = vec![[x, 10.0], [x + 20.0, 10.0], [x, 30.0]];
                Seen {
                    bounds: bounding_box(&polygon),
                    polygon,
                    inv_depth: flat,
                }
            })
            .collect();
        let boxes: Vec<[f64; 4]> = seen.iter().map(|s| s.bounds).collect();
        let grid = SeenGrid::new(seen, 200);
        let mut near = Vec::new();
        let b = [50.0, 12.0, 55.0, 14.0];
        grid.near(b, &mut near);
        let expected: Vec<u32> = (0..60u32)
            .filter(|&i| {
                let s = &boxes[i as usize];
                s[0] <= b[2] && b[0] <= s[2] && s[1] <= b[3] && b[1] <= s[3]
            })
            .collect();
        assert!(!expected.is_empty());
        assert_eq!(near, expected);
    }
}
