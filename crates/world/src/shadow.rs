//! Shadows, exactly: each visible fragment cut into the parts every shadow-casting light
//! reaches and the parts it does not (Atherton, Weiler and Greenberg's method, the one the
//! papers cite: the polygons a light sees are the visible fragments with the light as the
//! eye).
//!
//! For each light that casts shadows ([`casters`]):
//!
//! 1. **The light's view.** A pinhole camera at the light looks along the mean direction
//!    to the scene's vertices, with a field of view holding all of them. Every triangle
//!    of every mesh, front or back (an open surface's inside casts shadows too), is
//!    projected through it and [`exact_fragments`] finds what the light sees of each: the
//!    same exact polygon booleans as the camera's visibility, with their precision and
//!    their bounds on memory and depth complexity. A light that sees the scene wider than
//!    one view holds (a vertex more than 85° from the mean direction: a lamp just over a
//!    wide floor), or that the scene surrounds (a light in a room, inside a closed mesh),
//!    sees it through the six faces of a cube around it instead: each face a 90° view of
//!    the triangles' parts within its pyramid (each triangle clipped to the pyramid, the
//!    part cut into a fan). Every direction from the light lies in one pyramid, and only
//!    what lies in that pyramid can hide it, so the lit parts of a triangle are the union
//!    of its parts' lit parts, exactly. A light on a vertex is refused, located at
//!    `lights[k].position`; one on a surface's plane off its vertices sees that surface
//!    edge-on and gives it no light.
//! 2. **Back to the camera.** Each fragment the light sees lies in its triangle's plane:
//!    its vertices are mapped to the world on that plane (perspective-correct weights of
//!    the triangle's corners, as [`crate::shade`] does) and projected by the camera.
//!    Projective maps between planes keep straight edges straight, so these are the lit
//!    parts of the triangle on the screen, exactly.
//! 3. **Cut.** Each camera fragment of the triangle is cut into its intersection with the
//!    lit parts and its difference from them (one boolean each on the visibility's
//!    integer grid; holes cut away and slivers dropped and counted as visibility does).
//!    A fragment whose triangle the light sees whole is lit whole, and one it does not see
//!    at all is shadowed whole, without a boolean. With several lights the pieces are cut
//!    again for each, so a piece knows every light that reaches it ([`LightSet`]).
//! 4. **Shade.** A piece keeps its triangle's shading less the terms of the lights that
//!    do not reach it ([`crate::project::lit_corners`]): a flat face's one intensity less
//!    those lights' terms at its centroid; Gouraud's corner intensities relit without them
//!    and interpolated at the piece's vertices; Phong (per pixel) asks the shader with the
//!    piece's [`LightSet`]. A fragment every light reaches is output as it came, bit for
//!    bit.
//!
//! Whether a point is lit is decided by the geometry alone: a triangle facing away from a
//! light is shadowed by its own mesh's near side, whatever its shading normals say (a
//! smooth surface's terminator follows the facets).
//!
//! Output order: the input fragments' order, each fragment's pieces together (lit first,
//! then shadowed, light by light). Deterministic at any thread count (the light's view
//! runs on threads as [`crate::visibility::exact_fragments_on`] does).

use crate::boolean::{
    grid_for, overlay, positive, settle, Contour, Losses, Pt, Shape, MAX_CUT_DEPTH,
};
use crate::camera::Camera;
use crate::face::{ScreenTriangle, Surface};
use crate::lighting::Lighting;
use crate::project::{face_centroid, lit_corners};
use crate::scene::{CameraSpec, WorldScene, WorldSpec};
use crate::visibility::{exact_fragments_on, Fragment};
use cwisim_scene::{Polygon, SceneError, SceneErrorKind, Shading, Vector};
use glam::DVec3;
use i_overlay::core::overlay_rule::OverlayRule;
use std::collections::HashMap;

/// The most lights that may cast shadows in one scene (a [`LightSet`] has a bit for each).
pub const MAX_CASTERS: usize = 64;

/// The light's view is square, this many units a side: about a large image's pixels, so
/// that the visibility's area thresholds (1e-12 px²) mean there what they mean on screen.
const LIGHT_VIEW_SIDE: u32 = 2048;

/// Memory per triangle of one light's view: the projected triangle and what exact
/// visibility holds for it (about 1 kB per triangle, docs/PERFORMANCE.md).
const VIEW_BYTES_PER_TRIANGLE: u64 = 1536;
/// Memory per triangle and light of the lit parts kept.
const LIT_BYTES_PER_TRIANGLE: u64 = 128;

/// The smallest cosine between a vertex's direction from a light and the light view's
/// axis for one view to hold the scene (a cone under 170°); a light that sees it wider
/// sees it through a cube's six faces.
const MIN_COS: f64 = 0.087_155_742_747_658_17; // cos 85°

/// Which shadow-casting lights reach a piece: bit `i` for the `i`-th caster
/// ([`Casters::lights`]). Lights that cast no shadow reach everything.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LightSet(pub u64);

impl LightSet {
    /// Every caster reaches.
    pub const ALL: LightSet = LightSet(u64::MAX);

    /// Whether caster `i` reaches.
    pub fn has(self, i: usize) -> bool {
        self.0 >> i & 1 == 1
    }

    fn without(self, i: usize) -> LightSet {
        LightSet(self.0 & !(1 << i))
    }
}

/// The lights of a scene that cast shadows, by index into the scene's lights.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Casters {
    /// Indices into `WorldSpec::lights`, ascending.
    pub lights: Vec<usize>,
}

impl Casters {
    /// No light casts shadows.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Whether light `k` of the scene reaches a piece lit by `set`.
    pub fn reaches(&self, set: LightSet, k: usize) -> bool {
        match self.lights.iter().position(|&l| l == k) {
            Some(i) => set.has(i),
            None => true,
        }
    }
}

/// The lights of `spec` that cast shadows: those whose entry says `"shadows": true`, or
/// every light (`force: Some(true)`, `render --shadows on`) or none (`Some(false)`).
/// More than [`MAX_CASTERS`] is refused, located at the first light past the limit.
pub fn casters(spec: &WorldSpec, force: Option<bool>) -> Result<Casters, SceneError> {
    let lights: Vec<usize> = (0..spec.lights.len())
        .filter(|&k| force.unwrap_or(spec.lights[k].shadows))
        .collect();
    if lights.len() > MAX_CASTERS {
        let k = lights[MAX_CASTERS];
        return Err(SceneError::at_field(
            SceneErrorKind::Limit,
            format!("lights[{k}].shadows"),
            format!(
                "{} lights cast shadows; at most {MAX_CASTERS} may (each piece of a surface records which of them reach it)",
                lights.len()
            ),
        ));
    }
    Ok(Casters { lights })
}

/// What the shadow pass did (for the summary).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct ShadowStats {
    /// Lights casting shadows.
    pub lights: u64,
    /// Triangles projected into the lights' views (every triangle, once per light).
    pub light_triangles: u64,
    /// Fragments the lights see, over all lights.
    pub light_fragments: u64,
    /// Camera fragments taken in.
    pub fragments_in: u64,
    /// Pieces out: polygons each lit by one set of lights.
    pub pieces: u64,
    /// Pieces some shadow-casting light does not reach: the shadow polygons.
    pub shadow_polygons: u64,
    /// Polygon booleans made (an intersection and a difference per cut).
    pub booleans: u64,
    /// Horizontal cuts made to remove holes.
    pub hole_cuts: u64,
    /// Contours dropped for having less than 1e-12 px² of area.
    pub dropped_slivers: u64,
    /// Their total area (px²).
    pub dropped_area: f64,
}

/// Fragments cut by the lights that reach them.
#[derive(Clone, Debug, PartialEq)]
pub struct Shadowed {
    /// The pieces, each a simple polygon of its source triangle shaded by the lights that
    /// reach it.
    pub fragments: Vec<Fragment>,
    /// The lights that reach each piece.
    pub lit: Vec<LightSet>,
    /// What was done.
    pub stats: ShadowStats,
}

/// A light's view of the scene: one pinhole view when the light sees the scene within
/// one (under 170°), else the six faces of a cube around the light; and, per world
/// triangle, its parts in them.
struct LightView {
    views: Vec<View>,
    /// Per world triangle, its parts: `(view, triangle of the view)`.
    parts: Vec<Vec<(usize, usize)>>,
}

/// One pinhole view from a light: the triangles it holds as it sees them, and what it sees
/// of each.
struct View {
    /// The light-view triangles.
    tris: Vec<ScreenTriangle>,
    /// Per light-view triangle, the range of its fragments in `fragments`.
    ranges: Vec<std::ops::Range<usize>>,
    /// What the light sees, by source triangle.
    fragments: Vec<Fragment>,
}

/// Every fan triangle of every mesh of `scene` in the world, with its mesh and face, in
/// mesh, face and fan order.
fn world_triangles(scene: &WorldScene) -> Vec<(u32, u32, [DVec3; 3])> {
    let mut out = Vec::new();
    for (k, mesh) in scene.meshes.iter().enumerate() {
        for (f, face) in mesh.faces.iter().enumerate() {
            for tri in face.triangles() {
                let p = tri.map(|c| mesh.positions[face.corners[c] as usize]);
                out.push((k as u32, f as u32, p));
            }
        }
    }
    out
}

impl LightView {
    /// Light `k`'s view of `world` (one view, or a cube's six), or why the light cannot
    /// cast shadows (on a vertex; a cube's views over the memory budget).
    fn new(
        spec: &WorldSpec,
        k: usize,
        world: &[(u32, u32, [DVec3; 3])],
        threads: usize,
    ) -> Result<LightView, SceneError> {
        let corners: Vec<DVec3> = world.iter().flat_map(|(_, _, p)| *p).collect();
        let Some(camera) = one_view(spec, k, &corners, LIGHT_VIEW_SIDE)? else {
            // the scene around it, or wider than one view holds: the six faces of a cube
            return LightView::cube(spec, k, world, threads);
        };
        let tris: Vec<ScreenTriangle> = world
            .iter()
            .map(|&(mesh, face, world)| light_triangle(&camera, mesh, face, world))
            .collect();
        let view = View::of(tris, threads);
        Ok(LightView {
            parts: (0..world.len()).map(|j| vec![(0, j)]).collect(),
            views: vec![view],
        })
    }

    /// Light `k`'s view of `world` through the six faces of a cube around it, each a
    /// pinhole view of 90° holding the parts of the triangles within its pyramid (the
    /// triangles clipped to it, each part cut into a fan): every direction from the light
    /// is in one pyramid, and what the light sees in a direction only the triangles' parts
    /// in that pyramid can hide.
    /// Its triangles are counted first, and refused over the memory budget (at
    /// `lights[k].position`) before any is made.
    fn cube(
        spec: &WorldSpec,
        k: usize,
        world: &[(u32, u32, [DVec3; 3])],
        threads: usize,
    ) -> Result<LightView, SceneError> {
        let light = DVec3::from_array(spec.lights[k].position);
        let count: usize = CUBE_FACES
            .iter()
            .map(|&(axis, _)| {
                world
                    .iter()
                    .map(|(_, _, c)| {
                        clip_to_pyramid(&c.map(|p| p - light), axis)
                            .len()
                            .saturating_sub(2)
                    })
                    .sum::<usize>()
            })
            .sum();
        cwisim_scene::budget::Budget::current()
            .check_memory(
                &format!("light {k}'s six views ({count} triangles)"),
                (count as u64).saturating_mul(VIEW_BYTES_PER_TRIANGLE),
            )
            .map_err(|e| {
                SceneError::at_field(
                    SceneErrorKind::Limit,
                    format!("lights[{k}].position"),
                    e.to_string(),
                )
            })?;
        let mut parts = vec![Vec::new(); world.len()];
        let mut views = Vec::with_capacity(6);
        for (f, (axis, up)) in CUBE_FACES.into_iter().enumerate() {
            // a margin past the pyramid's 90°: its clipped parts lie within
            let camera = light_camera(light, axis, up, 92.0, LIGHT_VIEW_SIDE);
            let mut tris = Vec::new();
            for (j, &(mesh, face, corners)) in world.iter().enumerate() {
                let clipped = clip_to_pyramid(&corners.map(|p| p - light), axis);
                for i in 1..clipped.len().saturating_sub(1) {
                    let sub = [clipped[0], clipped[i], clipped[i + 1]].map(|d| d + light);
                    parts[j].push((f, tris.len()));
                    tris.push(light_triangle(&camera, mesh, face, sub));
                }
            }
            views.push(View::of(tris, threads));
        }
        Ok(LightView { views, parts })
    }

    /// Triangles in the view(s).
    fn triangles(&self) -> usize {
        self.views.iter().map(|v| v.tris.len()).sum()
    }

    /// Fragments the light sees.
    fn fragments(&self) -> usize {
        self.views.iter().map(|v| v.fragments.len()).sum()
    }

    /// How the light sees world triangle `j`: wholly (`Some(true)`), not at all
    /// (`Some(false)`), or in part (`None`).
    fn whole(&self, j: usize) -> Option<bool> {
        let mut seen = self.parts[j].iter().map(|&(v, t)| self.views[v].whole(t));
        let first = seen.next().unwrap_or(Some(false));
        if seen.all(|w| w == first) {
            first
        } else {
            None
        }
    }

    /// What the light sees of world triangle `j`, as contours on the camera's screen.
    fn lit_on_screen(&self, j: usize, camera: &Camera) -> Shape {
        self.parts[j]
            .iter()
            .flat_map(|&(v, t)| self.views[v].lit_on_screen(t, camera))
            .collect()
    }
}

/// Light `k`'s one pinhole view (square, `side` units a side) holding every point of
/// `points` with a margin of 1°, looking along their mean direction; `None` when one view
/// cannot hold them (a point more than 85° from that direction, or points all around the
/// light), and a refusal located at `lights[k].position` when the light is on one of them.
pub fn one_view(
    spec: &WorldSpec,
    k: usize,
    points: &[DVec3],
    side: u32,
) -> Result<Option<Camera>, SceneError> {
    let light = DVec3::from_array(spec.lights[k].position);
    let scale = points
        .iter()
        .map(|p| (*p - light).length())
        .fold(0.0f64, f64::max);
    let mut sum = DVec3::ZERO;
    for &p in points {
        let d = p - light;
        let length = d.length();
        if length.is_nan() || length <= 1e-9 * scale {
            return Err(SceneError::at_field(
                SceneErrorKind::Geometry,
                format!("lights[{k}].position"),
                format!(
                    "light {k} at {light} casts shadows, but it is on a vertex of the scene ({p}): a light on a surface lights it edge-on; move it off the surface"
                ),
            ));
        }
        sum += d / length;
    }
    let Some(axis) = sum.try_normalize() else {
        return Ok(None);
    };
    let widest = points
        .iter()
        .map(|p| (*p - light).normalize().dot(axis))
        .fold(1.0f64, f64::min);
    if widest < MIN_COS {
        return Ok(None);
    }
    let up = if axis.x.abs() < 0.5 {
        DVec3::X
    } else {
        DVec3::Y
    };
    // a margin of 1° past the widest point on every side
    let half = widest.acos() + 1f64.to_radians();
    Ok(Some(light_camera(
        light,
        axis,
        up,
        2.0 * half.to_degrees(),
        side,
    )))
}

/// A square pinhole view, `side` units a side, of `fov_y` degrees from the light at
/// `light` along `axis`.
fn light_camera(light: DVec3, axis: DVec3, up: DVec3, fov_y: f64, side: u32) -> Camera {
    Camera::new(
        &CameraSpec {
            eye: light.to_array(),
            target: (light + axis).to_array(),
            up: up.to_array(),
            fov_y,
            near: 0.0,
        },
        side,
        side,
    )
}

/// The world triangle `world` (of mesh `mesh`, face `face`) as `camera` at a light sees it.
pub fn light_triangle(camera: &Camera, mesh: u32, face: u32, world: [DVec3; 3]) -> ScreenTriangle {
    ScreenTriangle {
        points: world.map(|p| camera.project(p)),
        inv_depth: world.map(|p| 1.0 / camera.depth(p)),
        intensity: [Vector::default(); 3],
        mesh,
        face,
        surface: Surface {
            world,
            normals: [DVec3::ZERO; 3],
            uv: [[0.0; 2]; 3],
        },
    }
}

/// The faces of the cube around a light: each face's axis, and the up of its view.
const CUBE_FACES: [(DVec3, DVec3); 6] = [
    (DVec3::X, DVec3::Y),
    (DVec3::NEG_X, DVec3::Y),
    (DVec3::Y, DVec3::Z),
    (DVec3::NEG_Y, DVec3::Z),
    (DVec3::Z, DVec3::Y),
    (DVec3::NEG_Z, DVec3::Y),
];

/// The part of the triangle `d` (corners relative to the light) within the pyramid of the
/// cube face whose axis is `axis` (the points whose component along it is at least the
/// magnitude of each other component), as a convex polygon (empty: none of it).
fn clip_to_pyramid(d: &[DVec3; 3], axis: DVec3) -> Vec<DVec3> {
    let (a, others) = match axis {
        a if a.x != 0.0 => (a, [DVec3::Y, DVec3::Z]),
        a if a.y != 0.0 => (a, [DVec3::X, DVec3::Z]),
        a => (a, [DVec3::X, DVec3::Y]),
    };
    let mut poly: Vec<DVec3> = d.to_vec();
    for o in others {
        for sign in [1.0, -1.0] {
            // keep a·p − sign·o·p ≥ 0
            let side = |p: DVec3| a.dot(p) - sign * o.dot(p);
            let mut out = Vec::with_capacity(poly.len() + 1);
            for i in 0..poly.len() {
                let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
                let (sp, sq) = (side(p), side(q));
                if sp >= 0.0 {
                    out.push(p);
                }
                if (sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0) {
                    out.push(p + (q - p) * (sp / (sp - sq)));
                }
            }
            poly = out;
            if poly.len() < 3 {
                return Vec::new();
            }
        }
    }
    poly
}

impl View {
    /// The view of the light-view triangles `tris`: what the light sees of each, found on
    /// `threads` threads.
    fn of(tris: Vec<ScreenTriangle>, threads: usize) -> View {
        let (fragments, _) = exact_fragments_on(&tris, 1, threads);
        let mut ranges = vec![0..0; tris.len()];
        let mut start = 0;
        while start < fragments.len() {
            let source = fragments[start].source;
            let end = start
                + fragments[start..]
                    .iter()
                    .take_while(|f| f.source == source)
                    .count();
            ranges[source] = start..end;
            start = end;
        }
        View {
            tris,
            ranges,
            fragments,
        }
    }

    /// How the light sees light-view triangle `j`: wholly (`Some(true)`), not at all
    /// (`Some(false)`), or in part (`None`).
    fn whole(&self, j: usize) -> Option<bool> {
        let range = self.ranges[j].clone();
        if range.is_empty() {
            return Some(false);
        }
        let t = &self.tris[j];
        let one = &self.fragments[range.start].polygon.vertices;
        if range.len() == 1 && one.len() == 3 && one.iter().all(|p| t.points.contains(p)) {
            return Some(true);
        }
        None
    }

    /// What the light sees of light-view triangle `j`, as contours on the camera's screen.
    fn lit_on_screen(&self, j: usize, camera: &Camera) -> Shape {
        let t = &self.tris[j];
        self.fragments[self.ranges[j].clone()]
            .iter()
            .map(|f| {
                let contour: Contour = f
                    .polygon
                    .vertices
                    .iter()
                    .map(|&q| camera.project(world_at(t, q)))
                    .collect();
                positive(contour)
            })
            .collect()
    }
}

/// The world point of light-view triangle `t` at its screen point `q`
/// (perspective-correct, [`ScreenTriangle::perspective_weights`]; a triangle the light
/// sees has area and lies in front of it, so they exist — its centroid otherwise).
pub fn world_at(t: &ScreenTriangle, q: Pt) -> DVec3 {
    let ([w0, w1, w2], sum) = t.perspective_weights(q).unwrap_or(([1.0; 3], 3.0));
    let s = &t.surface.world;
    (w0 * s[0] + w1 * s[1] + w2 * s[2]) / sum
}

/// How a light reaches one camera triangle.
#[derive(Clone, Debug, PartialEq)]
pub enum Reach {
    /// All of it.
    All,
    /// None of it.
    Nothing,
    /// The parts it sees, on the camera's screen (disjoint simple polygons, positive),
    /// with each one's bounding box `[x0, y0, x1, y1]`.
    Parts(Shape, Vec<[f64; 4]>),
    /// All of it but these parts, on the camera's screen (disjoint simple polygons,
    /// positive), with each one's bounding box.
    Unlit(Shape, Vec<[f64; 4]>),
}

impl Reach {
    /// The parts `lit` (disjoint simple polygons on the camera's screen, either
    /// orientation) a light reaches of a triangle.
    pub fn parts(lit: Vec<Vec<[f64; 2]>>) -> Reach {
        let shape: Shape = lit.into_iter().map(positive).collect();
        let boxes = boxes(&shape);
        Reach::Parts(shape, boxes)
    }

    /// All of a triangle but the parts `unlit` (disjoint simple polygons on the camera's
    /// screen, either orientation).
    pub fn unlit(unlit: Vec<Vec<[f64; 2]>>) -> Reach {
        let shape: Shape = unlit.into_iter().map(positive).collect();
        let boxes = boxes(&shape);
        Reach::Unlit(shape, boxes)
    }
}

/// The bounding box `[x0, y0, x1, y1]` of `points` (empty: an inverted, infinite box).
pub fn bounding_box(points: &[[f64; 2]]) -> [f64; 4] {
    points.iter().fold(
        [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ],
        |b, p| {
            [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ]
        },
    )
}

/// The bounding box `[x0, y0, x1, y1]` of each contour.
fn boxes(shape: &Shape) -> Vec<[f64; 4]> {
    shape.iter().map(|c| bounding_box(c)).collect()
}

/// What every shadow-casting light reaches of every camera triangle, on the screen: what
/// [`shadowed`] cuts fragments with, and what a renderer that samples points asks at each
/// sample ([`ShadowTest::lit_at`]) — the same lit parts, so the two agree.
#[derive(Clone, Debug)]
pub struct ShadowTest {
    casters: Casters,
    /// Per camera triangle, per caster.
    reach: Vec<Vec<Reach>>,
    /// Per camera triangle, flat shading's centroid (`None`: Gouraud or Phong).
    centroids: Vec<Option<DVec3>>,
    lighting: Lighting,
    materials: Vec<crate::scene::Material>,
    eye: DVec3,
    /// Triangles in the lights' views, over all lights.
    pub light_triangles: u64,
    /// Fragments the lights see, over all lights.
    pub light_fragments: u64,
}

impl ShadowTest {
    /// The lit parts of the camera's triangles `tris` (made by [`crate::project::project`]
    /// of `scene` under `shading`) for every light of `casters`; the lights' views run on
    /// `threads` threads (0: one per core). A light on a vertex is refused at
    /// `lights[k].position` (see the [module docs](self)).
    pub fn new(
        scene: &WorldScene,
        shading: Shading,
        tris: &[ScreenTriangle],
        casters: &Casters,
        threads: usize,
    ) -> Result<ShadowTest, SceneError> {
        let spec = &scene.spec;
        let camera = Camera::new(&spec.camera, scene.width(), scene.height());
        let mut test = ShadowTest::with_reach(
            scene,
            shading,
            tris,
            casters,
            vec![Vec::with_capacity(casters.lights.len()); tris.len()],
        );
        if casters.is_empty() {
            return Ok(test);
        }
        let world = world_triangles(scene);
        // one light's view at a time (its triangles and exact visibility's work), and
        // every light's lit parts kept: refused before any is made when over the budget
        let bytes = (world.len() as u64)
            .saturating_mul(VIEW_BYTES_PER_TRIANGLE.saturating_add(
                LIT_BYTES_PER_TRIANGLE.saturating_mul(casters.lights.len() as u64),
            ));
        cwisim_scene::budget::Budget::current()
            .check_memory(
                &format!(
                    "the shadow pass ({} triangles seen from {} light(s))",
                    world.len(),
                    casters.lights.len()
                ),
                bytes,
            )
            .map_err(|e| SceneError::at_field(SceneErrorKind::Limit, "lights", e.to_string()))?;
        // camera triangle → light-view triangle: the same mesh, face and corners
        let mut by_face: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (j, (mesh, face, _)) in world.iter().enumerate() {
            by_face.entry((*mesh, *face)).or_default().push(j);
        }
        let light_index: Vec<Option<usize>> = tris
            .iter()
            .map(|t| {
                by_face
                    .get(&(t.mesh, t.face))
                    .and_then(|js| js.iter().copied().find(|&j| world[j].2 == t.surface.world))
            })
            .collect();
        for &k in &casters.lights {
            let view = LightView::new(spec, k, &world, threads)?;
            test.light_triangles += view.triangles() as u64;
            test.light_fragments += view.fragments() as u64;
            for (reach, j) in test.reach.iter_mut().zip(&light_index) {
                reach.push(match j.map(|j| (j, view.whole(j))) {
                    // not a face of the scene's meshes: nothing in the light's view to
                    // shadow it by (never made by `project`)
                    None => Reach::All,
                    Some((_, Some(true))) => Reach::All,
                    Some((_, Some(false))) => Reach::Nothing,
                    Some((j, None)) => {
                        let parts = view.lit_on_screen(j, &camera);
                        let boxes = boxes(&parts);
                        Reach::Parts(parts, boxes)
                    }
                });
            }
        }
        Ok(test)
    }

    /// The test of the camera's triangles `tris` (of `scene`, shaded under `shading`) with
    /// the lit parts `reach` found elsewhere: per triangle, one [`Reach`] per light of
    /// `casters`, in their order (`nishita` finds them from the light's own scan of the
    /// patches). Its counts of the lights' triangles and fragments start at zero.
    pub fn with_reach(
        scene: &WorldScene,
        shading: Shading,
        tris: &[ScreenTriangle],
        casters: &Casters,
        reach: Vec<Vec<Reach>>,
    ) -> ShadowTest {
        let spec = &scene.spec;
        let camera = Camera::new(&spec.camera, scene.width(), scene.height());
        ShadowTest {
            casters: casters.clone(),
            reach,
            centroids: tris
                .iter()
                .map(|t| {
                    (shading == Shading::Flat)
                        .then(|| face_centroid(&scene.meshes[t.mesh as usize], t.face as usize))
                })
                .collect(),
            lighting: Lighting {
                ambient: spec.ambient.clone(),
                lights: spec.lights.clone(),
                channels: scene.channels(),
            },
            materials: spec.meshes.iter().map(|m| m.material.clone()).collect(),
            eye: camera.eye,
            light_triangles: 0,
            light_fragments: 0,
        }
    }

    /// The lights that cast shadows.
    pub fn casters(&self) -> &Casters {
        &self.casters
    }

    /// The casters that reach camera triangle `k` at screen point `p` (a point on an edge
    /// of a lit part counts as lit).
    pub fn lit_at(&self, k: usize, p: Pt) -> LightSet {
        let mut set = LightSet::ALL;
        for (i, reach) in self.reach[k].iter().enumerate() {
            let lit = match reach {
                Reach::All => true,
                Reach::Nothing => false,
                Reach::Parts(parts, boxes) => parts.iter().zip(boxes).any(|(c, b)| {
                    b[0] <= p[0] && p[0] <= b[2] && b[1] <= p[1] && p[1] <= b[3] && inside(c, p)
                }),
                Reach::Unlit(parts, boxes) => !parts.iter().zip(boxes).any(|(c, b)| {
                    b[0] <= p[0] && p[0] <= b[2] && b[1] <= p[1] && p[1] <= b[3] && inside(c, p)
                }),
            };
            if !lit {
                set = set.without(i);
            }
        }
        set
    }

    /// The casters that reach camera triangle `k` along the horizontal line `y`, ready to
    /// be asked at many `x` ([`LineLights::at`]): each lit part's crossings of the line,
    /// sorted, so that a point costs a binary search (the in/out parity along a scanline)
    /// rather than a point-in-polygon test. It agrees with [`Self::lit_at`] except at a
    /// point exactly on a lit part's right-hand edge.
    pub fn line(&self, k: usize, y: f64) -> LineLights {
        let comparisons = std::cell::Cell::new(0u64);
        let reach = self.reach[k]
            .iter()
            .map(|r| match r {
                Reach::All => LineReach::All,
                Reach::Nothing => LineReach::Nothing,
                Reach::Parts(parts, boxes) | Reach::Unlit(parts, boxes) => {
                    let mut xs = Vec::new();
                    for (c, b) in parts.iter().zip(boxes) {
                        if y < b[1] || y > b[3] {
                            continue;
                        }
                        for e in 0..c.len() {
                            let (a, b) = (c[e], c[(e + 1) % c.len()]);
                            if (a[1] > y) != (b[1] > y) {
                                xs.push(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
                            }
                        }
                    }
                    xs.sort_by(|a, b| {
                        comparisons.set(comparisons.get() + 1);
                        a.total_cmp(b)
                    });
                    LineReach::Crossings(xs, matches!(r, Reach::Unlit(..)))
                }
            })
            .collect();
        LineLights {
            reach,
            comparisons: comparisons.get(),
        }
    }

    /// The casters that reach all of camera triangle `k`, when that is the same at every
    /// point of it (each caster reaching all of it or none); `None` when some caster
    /// reaches a part of it (ask [`Self::lit_at`] point by point).
    pub fn uniform(&self, k: usize) -> Option<LightSet> {
        let mut set = LightSet::ALL;
        for (i, reach) in self.reach[k].iter().enumerate() {
            match reach {
                Reach::All => {}
                Reach::Nothing => set = set.without(i),
                Reach::Parts(..) | Reach::Unlit(..) => return None,
            }
        }
        Some(set)
    }

    /// Camera triangle `t` (number `k`)'s corner intensities by the lights of `set`
    /// ([`crate::project::lit_corners`]; `project`'s own when every light reaches).
    pub fn corners(&self, k: usize, t: &ScreenTriangle, set: LightSet) -> [Vector; 3] {
        lit_corners(
            &self.lighting,
            &self.materials[t.mesh as usize],
            self.centroids[k],
            &t.surface,
            self.eye,
            |l| self.casters.reaches(set, l),
        )
    }
}

/// How the casters reach one triangle along one horizontal line ([`ShadowTest::line`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LineLights {
    reach: Vec<LineReach>,
    comparisons: u64,
}

#[derive(Clone, Debug, PartialEq)]
enum LineReach {
    All,
    Nothing,
    /// Where the line crosses the lit (or, `true`, the unlit) parts' edges, sorted: lit
    /// where an odd (even) number of them lie to the right.
    Crossings(Vec<f64>, bool),
}

impl LineLights {
    /// How many edges of the lit parts the line crosses, over every caster that reaches a
    /// part of the triangle: the shadow edges Barkan & Gordon's §5.3 would hold in the
    /// triangle's active edge list on this line.
    pub fn crossings(&self) -> u64 {
        self.reach
            .iter()
            .map(|r| match r {
                LineReach::Crossings(xs, _) => xs.len() as u64,
                _ => 0,
            })
            .sum()
    }

    /// The comparisons sorting those crossings took (§5.3's sorting work in `POLINE`).
    pub fn comparisons(&self) -> u64 {
        self.comparisons
    }

    /// The casters that reach the line's point at `x`.
    pub fn at(&self, x: f64) -> LightSet {
        let mut set = LightSet::ALL;
        for (i, r) in self.reach.iter().enumerate() {
            let lit = match r {
                LineReach::All => true,
                LineReach::Nothing => false,
                LineReach::Crossings(xs, unlit) => {
                    ((xs.len() - xs.partition_point(|&v| v <= x)) % 2 == 1) != *unlit
                }
            };
            if !lit {
                set = set.without(i);
            }
        }
        set
    }
}

/// Whether `p` is inside the closed contour `c` or on its boundary (crossings of the
/// horizontal ray to the right, half-open in y; a point on an edge counts as inside).
fn inside(c: &[Pt], p: Pt) -> bool {
    let mut odd = false;
    for e in 0..c.len() {
        let (a, b) = (c[e], c[(e + 1) % c.len()]);
        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
        let within = |u: f64, v: f64, w: f64| u.min(v) <= w && w <= u.max(v);
        if cross == 0.0 && within(a[0], b[0], p[0]) && within(a[1], b[1], p[1]) {
            return true;
        }
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                odd = !odd;
            }
        }
    }
    odd
}

/// Cuts the camera's `fragments` of the screen triangles `tris` (made by
/// [`crate::project::project`] of `scene` under `shading`) into the pieces each set of
/// the `casters` reaches, shaded accordingly (see the [module docs](self)). The lights'
/// views run on `threads` threads (0: one per core).
pub fn shadowed(
    scene: &WorldScene,
    shading: Shading,
    tris: &[ScreenTriangle],
    fragments: Vec<Fragment>,
    casters: &Casters,
    threads: usize,
) -> Result<Shadowed, SceneError> {
    let test = ShadowTest::new(scene, shading, tris, casters, threads)?;
    Ok(shadowed_by(scene, tris, fragments, &test))
}

/// Cuts the camera's `fragments` of the screen triangles `tris` into the pieces each set
/// of `test`'s lights reaches, shaded accordingly: [`shadowed`] with lit parts found
/// elsewhere ([`ShadowTest::with_reach`]).
pub fn shadowed_by(
    scene: &WorldScene,
    tris: &[ScreenTriangle],
    fragments: Vec<Fragment>,
    test: &ShadowTest,
) -> Shadowed {
    let channels = scene.channels();
    let casters = &test.casters;
    let mut stats = ShadowStats {
        lights: casters.lights.len() as u64,
        fragments_in: fragments.len() as u64,
        ..ShadowStats::default()
    };
    if casters.is_empty() {
        stats.pieces = fragments.len() as u64;
        let lit = vec![LightSet::ALL; fragments.len()];
        return Shadowed {
            fragments,
            lit,
            stats,
        };
    }
    stats.light_triangles = test.light_triangles;
    stats.light_fragments = test.light_fragments;
    let grid = grid_for(tris.iter().flat_map(|t| t.points));
    let mut losses = Losses::default();
    let mut out = Shadowed {
        fragments: Vec::with_capacity(fragments.len()),
        lit: Vec::with_capacity(fragments.len()),
        stats: ShadowStats::default(),
    };
    // the corner intensities per light set of the current source triangle (its
    // fragments come together)
    let mut relit_source = usize::MAX;
    let mut relit: HashMap<LightSet, [Vector; 3]> = HashMap::new();
    for fragment in fragments {
        let k = fragment.source;
        let t = &tris[k];
        if k != relit_source {
            relit_source = k;
            relit.clear();
        }
        let mut pieces: Vec<(Contour, LightSet)> =
            vec![(fragment.polygon.vertices.clone(), LightSet::ALL)];
        for (i, reach) in test.reach[k].iter().enumerate() {
            match reach {
                Reach::All => {}
                Reach::Nothing => {
                    for piece in &mut pieces {
                        piece.1 = piece.1.without(i);
                    }
                }
                Reach::Parts(parts, _) | Reach::Unlit(parts, _) => {
                    // the lit parts: what the parts listed are (lit) or what they leave
                    let (lit, unlit) = match reach {
                        Reach::Parts(..) => (OverlayRule::Intersect, OverlayRule::Difference),
                        _ => (OverlayRule::Difference, OverlayRule::Intersect),
                    };
                    let mut next = Vec::with_capacity(pieces.len() * 2);
                    for (contour, set) in pieces {
                        let subject = vec![positive(contour)];
                        for (rule, set) in [(lit, set), (unlit, set.without(i))] {
                            stats.booleans += 1;
                            let mut contours = Vec::new();
                            for shape in overlay(&grid, &subject, parts, rule) {
                                settle(&grid, shape, MAX_CUT_DEPTH, &mut contours, &mut losses);
                            }
                            next.extend(contours.into_iter().map(|c| (c, set)));
                        }
                    }
                    pieces = next;
                }
            }
        }
        if let [(_, LightSet::ALL)] = pieces.as_slice() {
            // every light reaches all of it: the fragment as it came
            out.fragments.push(fragment);
            out.lit.push(LightSet::ALL);
            continue;
        }
        for (contour, set) in pieces {
            let corners = *relit.entry(set).or_insert_with(|| test.corners(k, t, set));
            let shaded = ScreenTriangle {
                intensity: corners,
                ..*t
            };
            let intensity = contour
                .iter()
                .map(|&p| {
                    let v = shaded
                        .intensity_at(p, channels)
                        .expect("a visible triangle has nonzero area");
                    cwisim_scene::VertexIntensity::from_slice(&v[..channels])
                })
                .collect::<Vec<_>>();
            out.fragments.push(Fragment {
                source: k,
                polygon: Polygon::new(contour, intensity),
            });
            out.lit.push(set);
        }
    }
    stats.pieces = out.fragments.len() as u64;
    stats.shadow_polygons = out.lit.iter().filter(|&&s| s != LightSet::ALL).count() as u64;
    stats.hole_cuts = losses.hole_cuts;
    stats.dropped_slivers = losses.dropped.len() as u64;
    stats.dropped_area = losses.dropped.iter().sum();
    out.stats = stats;
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::project::project;

    /// A floor, and a box standing on it, lit by `lights` (JSON).
    fn scene(lights: &str) -> WorldScene {
        let text = format!(
            r#"{{"kind": "world", "width": 40, "height": 30, "channels": 1,
"camera": {{"eye": [0, 4, 6], "target": [0, 0, 0], "fov_y": 40}},
"ambient": 0.2, "lights": {lights},
"meshes": [
  {{"material": {{"k_a": 0.5, "k_d": 0.7, "k_s": 0, "n": 1}},
    "vertices": [[-3, 0, -3], [-3, 0, 3], [3, 0, 3], [3, 0, -3]], "faces": [[0, 1, 2, 3]]}},
  {{"material": {{"k_a": 0.5, "k_d": 0.7, "k_s": 0, "n": 1}},
    "vertices": [[-0.5, 0.2, -0.5], [0.5, 0.2, -0.5], [0.5, 0.2, 0.5], [-0.5, 0.2, 0.5],
                 [-0.5, 1.2, -0.5], [0.5, 1.2, -0.5], [0.5, 1.2, 0.5], [-0.5, 1.2, 0.5]],
    "faces": [[0, 1, 2, 3], [4, 7, 6, 5], [0, 4, 5, 1], [1, 5, 6, 2], [2, 6, 7, 3], [3, 7, 4, 0]]}}
]}}"#
        );
        crate::scene::parse_world(&text, None).unwrap()
    }

    fn cut(w: &WorldScene, force: Option<bool>) -> Result<Shadowed, SceneError> {
        let (tris, _) = project(w, Shading::Flat)?;
        let (fragments, _) = crate::visibility::exact_fragments(&tris, 1);
        shadowed(
            w,
            Shading::Flat,
            &tris,
            fragments,
            &casters(&w.spec, force)?,
            1,
        )
    }

    fn area(v: &[Pt]) -> f64 {
        crate::boolean::area(v)
    }

    #[test]
    fn a_light_overhead_shadows_the_floor_under_the_box_exactly() {
        let w = scene(r#"[{"position": [0, 10, 0], "intensity": 0.8, "shadows": true}]"#);
        let s = cut(&w, None).unwrap();
        assert_eq!(s.stats.lights, 1);
        // the shadow on the floor: the box's top square projected from the light onto
        // y = 0, scaled by 10 / (10 − 1.2), then projected by the camera
        let camera = Camera::new(&w.spec.camera, 40, 30);
        let half = 0.5 * 10.0 / 8.8;
        let square: Vec<Pt> = [[-half, -half], [half, -half], [half, half], [-half, half]]
            .iter()
            .map(|&[x, z]| camera.project(DVec3::new(x, 0.0, z)))
            .collect();
        // the floor's shadowed pieces and the box's front face hiding part of it: the
        // floor's shadow plus its lit part add up to the floor's visible area
        let floor: Vec<usize> = (0..s.fragments.len())
            .filter(|&k| s.fragments[k].source < 2)
            .collect();
        let dark: f64 = floor
            .iter()
            .filter(|&&k| !s.lit[k].has(0))
            .map(|&k| area(&s.fragments[k].polygon.vertices))
            .sum();
        assert!(
            dark > 0.0 && dark < area(&square),
            "{dark} {}",
            area(&square)
        );
        // every shadowed floor piece lies within the projected square
        let sign = {
            let [a, b, c, _] = [square[0], square[1], square[2], square[3]];
            ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).signum()
        };
        for &k in &floor {
            if !s.lit[k].has(0) {
                for p in &s.fragments[k].polygon.vertices {
                    let inside = (0..4).all(|e| {
                        let (a, b) = (square[e], square[(e + 1) % 4]);
                        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
                        cross.abs() <= 1e-9 || cross.signum() == sign
                    });
                    assert!(inside, "{p:?} {square:?}");
                }
            }
        }
        // the floor's shadow has the ambient term alone, its lit part more
        let ambient = 0.2 * 0.5;
        for k in &floor {
            let v = s.fragments[*k].polygon.intensity[0][0];
            if !s.lit[*k].has(0) {
                assert_eq!(v, ambient);
            } else {
                assert!(v > ambient);
            }
        }
        // the same scene without shadows: the fragments as they came, all lit
        let plain = cut(&w, Some(false)).unwrap();
        assert!(plain.lit.iter().all(|&l| l == LightSet::ALL));
        assert_eq!(plain.stats.shadow_polygons, 0);
    }

    #[test]
    fn the_test_at_a_point_agrees_with_the_pieces_cut() {
        let w = scene(
            r#"[{"position": [0, 10, 0], "intensity": 0.8, "shadows": true},
                {"position": [-6, 3, 1], "intensity": 0.3},
                {"position": [5, 4, 4], "intensity": 0.5, "shadows": true}]"#,
        );
        let (tris, _) = project(&w, Shading::Gouraud).unwrap();
        let casters = casters(&w.spec, None).unwrap();
        assert_eq!(casters.lights, [0, 2]);
        let (fragments, _) = crate::visibility::exact_fragments(&tris, 1);
        let s = shadowed(&w, Shading::Gouraud, &tris, fragments, &casters, 1).unwrap();
        let test = ShadowTest::new(&w, Shading::Gouraud, &tris, &casters, 1).unwrap();
        let mut sets = std::collections::BTreeSet::new();
        for (f, &set) in s.fragments.iter().zip(&s.lit) {
            // a point well inside the piece: its first fan triangle's centroid
            let v = &f.polygon.vertices;
            let (a, b, c) = (v[0], v[1], v[2]);
            if crate::boolean::area(&[a, b, c]) < 1e-3 {
                continue;
            }
            let p = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
            assert_eq!(test.lit_at(f.source, p), set, "{f:?}");
            // and along the line through it, by the crossings
            assert_eq!(test.line(f.source, p[1]).at(p[0]), set, "{f:?}");
            sets.insert(set);
            // the light that casts no shadow reaches every piece
            assert!(casters.reaches(set, 1));
        }
        // lit by both, by one, by the other and by neither all occur
        assert!(sets.len() >= 3, "{sets:?}");
    }

    #[test]
    fn a_light_on_a_vertex_is_refused_where_it_is() {
        let w = scene(r#"[{"position": [0.5, 1.2, 0.5], "intensity": 0.8, "shadows": true}]"#);
        let e = cut(&w, None).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("lights[0].position"), "{e}");
        assert!(e.to_string().contains("on a vertex of the scene"), "{e}");
        // the same light without shadows draws as before
        assert!(cut(&w, Some(false)).is_ok());
    }

    /// Whether the segment from `p` to `light` meets triangle `t` strictly between its
    /// ends (Möller–Trumbore): the independent reference, a ray cast.
    fn blocks(p: DVec3, light: DVec3, t: &[DVec3; 3]) -> bool {
        let dir = light - p;
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let h = dir.cross(e2);
        let a = e1.dot(h);
        if a.abs() < 1e-14 {
            return false;
        }
        let f = 1.0 / a;
        let s = p - t[0];
        let u = f * s.dot(h);
        let q = s.cross(e1);
        let v = f * dir.dot(q);
        let along = f * e2.dot(q);
        u >= 0.0 && v >= 0.0 && u + v <= 1.0 && along > 1e-9 && along < 1.0 - 1e-9
    }

    /// Every piece of the scene `w` cut by its one light is lit exactly where a ray cast
    /// from a point inside it to the light meets no triangle; how many pieces were
    /// checked, lit and shadowed.
    fn agrees_with_a_ray_cast(w: &WorldScene) -> (usize, usize, usize) {
        let (tris, _) = project(w, Shading::Flat).unwrap();
        let (fragments, _) = crate::visibility::exact_fragments(&tris, 1);
        let s = shadowed(
            w,
            Shading::Flat,
            &tris,
            fragments,
            &casters(&w.spec, None).unwrap(),
            1,
        )
        .unwrap();
        let light = DVec3::from_array(w.spec.lights[0].position);
        let world: Vec<[DVec3; 3]> = world_triangles(w).into_iter().map(|t| t.2).collect();
        let (mut checked, mut lit, mut dark) = (0, 0, 0);
        for (f, set) in s.fragments.iter().zip(&s.lit) {
            let v = &f.polygon.vertices;
            // a point well inside the piece: its largest fan triangle's centroid
            let Some((a, b, c)) = (1..v.len() - 1)
                .map(|i| (v[0], v[i], v[i + 1]))
                .max_by(|x, y| area(&[x.0, x.1, x.2]).total_cmp(&area(&[y.0, y.1, y.2])))
            else {
                continue;
            };
            if area(&[a, b, c]) < 1e-2 {
                continue;
            }
            let p = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
            let t = &tris[f.source];
            let (wts, sum) = t.perspective_weights(p).unwrap();
            let q = (wts[0] * t.surface.world[0]
                + wts[1] * t.surface.world[1]
                + wts[2] * t.surface.world[2])
                / sum;
            let shadowed = world.iter().any(|t| blocks(q, light, t));
            assert_eq!(
                set.has(0),
                !shadowed,
                "the piece at {p:?} (world {q}) of {f:?}"
            );
            checked += 1;
            if shadowed {
                dark += 1;
            } else {
                lit += 1;
            }
        }
        (checked, lit, dark)
    }

    /// A floor `side` units across at `y = 0`, a camera at `eye` looking at `target`, a
    /// light at `light` casting shadows, and more `meshes` (JSON).
    fn wide_scene(
        side: f64,
        eye: [f64; 3],
        target: [f64; 3],
        light: [f64; 3],
        meshes: &str,
    ) -> WorldScene {
        let h = side / 2.0;
        let text = format!(
            r#"{{"kind": "world", "width": 160, "height": 120, "channels": 1,
"camera": {{"eye": {eye:?}, "target": {target:?}, "fov_y": 50}},
"ambient": 0.2, "lights": [{{"position": {light:?}, "intensity": 0.8, "shadows": true}}],
"meshes": [
  {{"material": {{"k_a": 0.5, "k_d": 0.7, "k_s": 0, "n": 1}},
    "vertices": [[-{h}, 0, -{h}], [-{h}, 0, {h}], [{h}, 0, {h}], [{h}, 0, -{h}]], "faces": [[0, 1, 2, 3]]}}{meshes}
]}}"#
        );
        crate::scene::parse_world(&text, None).unwrap()
    }

    /// A caster triangle (JSON mesh) with corners `c`.
    fn caster(c: [[f64; 3]; 3]) -> String {
        format!(
            r#", {{"material": {{"k_a": 0.5, "k_d": 0.7, "k_s": 0, "n": 1}}, "vertices": {c:?}, "faces": [[0, 1, 2]]}}"#
        )
    }

    #[test]
    fn a_light_just_above_a_wide_floor_casts_the_analytic_shadow_of_a_triangle() {
        // the light 1 above a floor 40 across sees it up to 88° from straight down: one
        // view cannot hold it; the caster's shadow straddles two faces of the cube
        let light = [0.0, 1.0, 0.0];
        let c = [[0.3, 0.5, -0.2], [1.0, 0.5, 0.1], [0.4, 0.5, 0.6]];
        let w = wide_scene(40.0, [12.0, 25.0, 0.0], [1.5, 0.0, 0.2], light, &caster(c));
        assert_eq!(views(&w), 6);
        let (checked, lit, dark) = agrees_with_a_ray_cast(&w);
        assert!(checked > 3 && lit > 0 && dark > 0, "{checked} {lit} {dark}");
        // the shadow on the floor: the caster's corners projected from the light onto
        // y = 0 (twice as far: it is half way down), then by the camera; seen whole (the
        // caster does not hide it from this eye)
        let camera = Camera::new(&w.spec.camera, 160, 120);
        let shadow: Vec<Pt> = c
            .iter()
            .map(|&[x, y, z]| {
                let k = light[1] / (light[1] - y);
                camera.project(DVec3::new(k * x, 0.0, k * z))
            })
            .collect();
        let (tris, _) = project(&w, Shading::Flat).unwrap();
        let (fragments, _) = crate::visibility::exact_fragments(&tris, 1);
        let s = shadowed(
            &w,
            Shading::Flat,
            &tris,
            fragments,
            &casters(&w.spec, None).unwrap(),
            1,
        )
        .unwrap();
        let floor_dark: f64 = s
            .fragments
            .iter()
            .zip(&s.lit)
            .filter(|(f, l)| tris[f.source].mesh == 0 && !l.has(0))
            .map(|(f, _)| area(&f.polygon.vertices))
            .sum();
        let expect = area(&shadow);
        assert!(
            (floor_dark - expect).abs() <= 1e-9 * expect.max(1.0),
            "shadow {floor_dark} px², analytic {expect} px²"
        );
    }

    #[test]
    fn a_light_surrounded_by_casters_on_all_sides_shadows_exactly() {
        // six triangles around the light (above, below, and on four sides), over a floor
        let light = [0.0, 2.0, 0.0];
        let around = [
            caster([[-0.3, 2.6, -0.2], [0.3, 2.6, -0.2], [0.0, 2.6, 0.3]]),
            caster([[-0.3, 1.5, -0.2], [0.3, 1.5, -0.2], [0.0, 1.5, 0.3]]),
            caster([[0.6, 1.8, -0.3], [0.6, 2.3, 0.0], [0.6, 1.8, 0.3]]),
            caster([[-0.6, 1.8, -0.3], [-0.6, 2.3, 0.0], [-0.6, 1.8, 0.3]]),
            caster([[-0.3, 1.8, 0.6], [0.3, 1.8, 0.6], [0.0, 2.3, 0.6]]),
            caster([[-0.3, 1.8, -0.6], [0.3, 1.8, -0.6], [0.0, 2.3, -0.6]]),
        ]
        .concat();
        let w = wide_scene(12.0, [0.0, 9.0, 7.0], [0.0, 0.0, 0.0], light, &around);
        assert_eq!(views(&w), 6);
        let (checked, lit, dark) = agrees_with_a_ray_cast(&w);
        assert!(
            checked >= 8 && lit > 0 && dark > 0,
            "{checked} {lit} {dark}"
        );
    }

    #[test]
    fn a_light_inside_a_closed_box_lights_its_inside_and_shadows_all_outside() {
        // the box of `scene`, the light inside it: drawn through the cube's six views
        let w = scene(r#"[{"position": [0, 0.7, 0], "intensity": 0.8, "shadows": true}]"#);
        assert_eq!(views(&w), 6);
        let (tris, _) = project(&w, Shading::Flat).unwrap();
        let s = cut(&w, None).unwrap();
        // the floor, all outside the box, is dark; the box's faces are lit (from inside:
        // the geometry decides, the lighting formula then gives them no diffuse term)
        for (f, l) in s.fragments.iter().zip(&s.lit) {
            assert_eq!(l.has(0), tris[f.source].mesh == 1, "{f:?}");
        }
        assert!(agrees_with_a_ray_cast(&w).0 > 0);
    }

    /// The views light 0 of `w` sees the scene through: 1, or a cube's 6.
    fn views(w: &WorldScene) -> usize {
        LightView::new(&w.spec, 0, &world_triangles(w), 1)
            .map(|v| v.views.len())
            .unwrap()
    }

    #[test]
    fn more_casters_than_a_light_set_holds_are_refused_at_the_first_beyond() {
        let one = r#"{"position": [0, 10, 0], "intensity": 0.01, "shadows": true}"#;
        let lights = format!("[{}]", vec![one; MAX_CASTERS + 1].join(", "));
        let w = scene(&lights);
        let e = casters(&w.spec, None).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("lights[64].shadows"), "{e}");
        assert!(
            e.to_string().contains("65 lights cast shadows; at most 64"),
            "{e}"
        );
        assert_eq!(casters(&w.spec, Some(false)).unwrap().lights.len(), 0);
    }
}
