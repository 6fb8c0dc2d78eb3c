//! `nishita`: Nishita, Kaneda & Nakamae, *High-quality rendering of parametric surfaces
//! by using a robust scanline algorithm* — bicubic Bézier patches scan-converted
//! directly, band by band, with Bézier clipping finding where subpatch boundaries cross
//! the row lines, and the straight-sided pieces between those roots filled exactly by the
//! box filter.
//!
//! * [`band`] — one band of rows: the subpatches that meet it (a quadtree cut to the band
//!   and to a flatness tolerance), the roots of their edges at every row line
//!   ([`cwisim_world::clip`]), and the pieces between them.
//! * [`classify`] — front, back or twisted: the sign of `(S − E)·(S_u × S_v)` over a
//!   subpatch, exactly (Bernstein coefficients of degree 8 × 8).
//!
//! * [`cwisim_world::sweep`] — visibility along one strip between two row lines: the paper's scan
//!   segments, slab by slab between the pieces' corners, exact (no polygon boolean).
//! * [`resolve`] — the bands made and resolved strip by strip, on `--threads`.
//! * [`merged`] — a patch's visible fragments on a pixel row box-filtered on the host and
//!   sent through the span fitter as one span.
//! * [`shadow`] — the paper's §7: the patches scanned again from each light that casts
//!   shadows, and the camera's pieces cut where the light does not reach them.
//!
//! The pieces of every band — triangles with their surface points and the patch's own
//! normals at their corners — go through the scan segments of their strip and then
//! through the box filter, Gouraud (the lighting at each piece corner) or Phong (lit per
//! pixel from the normals interpolated over the piece, through the span fitter). A screen
//! scene has no patches: it is drawn as `vanrij` draws it; meshes of a world scene that
//! are not Bézier patches are projected as `vanrij` projects them and share the project's
//! exact visibility (`cwisim_world::visibility::exact_fragments`) with the pieces.
//!
//! `docs/RENDERERS.md` says how it reads the paper; `docs/ERRATA.md` what it corrects.

pub mod band;
pub mod classify;
pub mod merged;
pub mod resolve;
pub mod shadow;

use crate::error::RenderError;
use crate::prepare::{PhongSurfaces, PolygonScene};
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::Settings;
use crate::source::LoadedScene;
use crate::vanrij::VanRij;
use band::{band_pieces, BandStats, Facings, Params, View};
use classify::Facing;
use cwisim_isa::{TraceHeader, TraceWrite};
use cwisim_scene::{SceneError, SceneErrorKind, Shading, MAX_COORDINATE};
use cwisim_world::camera::Camera;
use cwisim_world::clip::HISTOGRAM;
use cwisim_world::face::{ScreenTriangle, Surface};
use cwisim_world::lighting::Lighting;
use cwisim_world::shade::PhongShader;
use cwisim_world::{AnyScene, Visibility, WorldScene};
use cwisim_xproc::{Image, RunStats};
use glam::DVec3;
use std::io;
use std::ops::Range;
use std::time::{Duration, Instant};

/// The registry's one line about it.
pub const ABOUT: &str = "Nishita, Kaneda & Nakamae: Bézier patches scan-converted directly — subpatches per band (--band, --flatness), Bézier clipping of their edges at every row line (--root-tolerance, --subscan), straight-sided pieces box-filtered exactly, exact visibility, Gouraud or Phong, shadows from the light's own scan of the patches (§7)";

/// The histogram counters' names: roots by iterations (the last: that many or more).
const HISTOGRAM_NAMES: [&str; HISTOGRAM] = [
    "roots_0_iterations",
    "roots_1_iteration",
    "roots_2_iterations",
    "roots_3_iterations",
    "roots_4_iterations",
    "roots_5_iterations",
    "roots_6_iterations",
    "roots_7_iterations",
    "roots_8_iterations",
    "roots_9_iterations",
    "roots_10_iterations",
    "roots_11_iterations",
    "roots_12_iterations",
    "roots_13_iterations",
    "roots_14_iterations",
    "roots_15_or_more_iterations",
];

/// Where a piece comes from: mesh, patch, and the patch parameters `(u, v)` at its
/// corners.
pub type Origin = (u32, u32, [(f64, f64); 3]);

/// The memory one piece takes, with what exact visibility makes of it: twice its
/// triangle's own record (about 650 bytes; measured: the teapot's 229,624 pieces took
/// 195 MB in all, about 850 bytes each, and at `--subscan 64` a run with room took 7.5 GB).
const BYTES_PER_PIECE: u64 = 2 * std::mem::size_of::<ScreenTriangle>() as u64
    + std::mem::size_of::<Facing>() as u64
    + std::mem::size_of::<Origin>() as u64;

/// What drawing the patches made, before visibility. `S`: what a triangle keeps of its
/// surface ([`Surface`], or `()` where nothing reads it: then `facing` and `origin`
/// are not kept either).
#[derive(Clone, Debug)]
pub struct Pieces<S = Surface> {
    /// The pieces as screen triangles (surface points, normals toward the eye, lit
    /// corners), band by band.
    pub triangles: Vec<ScreenTriangle<S>>,
    /// For each triangle: how its subpatch faces the eye (empty where `S` is `()`).
    pub facing: Vec<Facing>,
    /// For each triangle: its mesh, patch and the patch parameters at its corners (empty
    /// where `S` is `()`).
    pub origin: Vec<Origin>,
    /// For each triangle: the strip of its band it lies in ([`band::Piece::strip`]).
    pub strip: Vec<u32>,
    /// What the bands did.
    pub stats: BandStats,
    /// Bands.
    pub bands: u64,
    /// Patches.
    pub patches: u64,
}

impl<S> Default for Pieces<S> {
    fn default() -> Self {
        Pieces {
            triangles: Vec::new(),
            facing: Vec::new(),
            origin: Vec::new(),
            strip: Vec::new(),
            stats: BandStats::default(),
            bands: 0,
            patches: 0,
        }
    }
}

/// What the pieces of a band keep of their triangles' surfaces: all of it
/// ([`Surface`]: Phong and textures read it, per pixel) or nothing (`()`: 192 bytes a
/// triangle fewer, and no record of each piece's origin).
pub trait KeptSurface: Copy + Send + Sync + 'static {
    /// Whether it is the whole surface.
    const WHOLE: bool;
    /// What it keeps of `surface`.
    fn of(surface: Surface) -> Self;
    /// The triangle with its whole surface, where it kept it.
    fn whole(t: &ScreenTriangle<Self>) -> Option<ScreenTriangle>;
}

impl KeptSurface for Surface {
    const WHOLE: bool = true;
    fn of(surface: Surface) -> Self {
        surface
    }
    fn whole(t: &ScreenTriangle<Self>) -> Option<ScreenTriangle> {
        Some(*t)
    }
}

impl KeptSurface for () {
    const WHOLE: bool = false;
    fn of(_: Surface) -> Self {}
    fn whole(_: &ScreenTriangle<Self>) -> Option<ScreenTriangle> {
        None
    }
}

/// What drawing the patches of a world scene needs, prepared once: the view, the
/// settings, the lighting and every Bézier mesh's placed patches (checked).
pub struct PatchScene<'w> {
    w: &'w WorldScene,
    camera: Camera,
    view: View,
    /// The rows of its image.
    rows: u32,
    params: Params,
    lighting: Lighting,
    meshes: Vec<(usize, Vec<cwisim_world::bezier::Patch>)>,
    /// For each of `meshes`: how its cells face the eye, as the bands find out.
    facings: Vec<Facings>,
}

impl<'w> PatchScene<'w> {
    /// The patches of `w`, checked (in front of the camera, within the coordinate limit).
    pub fn new(w: &'w WorldScene, settings: &Settings) -> Result<PatchScene<'w>, RenderError> {
        // a scene built in code was never validated: its lighting terms are checked here
        w.spec.check_lighting()?;
        let camera = Camera::new(&w.spec.camera, w.width(), w.height());
        let view = View { camera };
        let params = Params {
            tolerance: settings.root_tolerance,
            flatness: settings.flatness,
            subscan: settings.subscan,
            normal_cos: settings.normal_angle.map(|a| a.to_radians().cos()),
        };
        let lighting = Lighting {
            ambient: w.spec.ambient.clone(),
            lights: w.spec.lights.clone(),
            channels: w.channels(),
        };
        let mut meshes = Vec::new();
        for (k, m) in w.spec.meshes.iter().enumerate() {
            let Some(patches) = cwisim_world::mesh::placed_patches(m) else {
                continue;
            };
            let patches = patches.map_err(|e| {
                SceneError::at_field(SceneErrorKind::Geometry, format!("meshes[{k}].bezier"), e)
            })?;
            for (pi, p) in patches.iter().enumerate() {
                for (i, q) in p.points.iter().flatten().enumerate() {
                    let depth = camera.depth(*q);
                    if depth < camera.near || depth.is_nan() {
                        return Err(SceneError::at_field(
                            SceneErrorKind::Geometry,
                            format!("meshes[{k}].bezier.patches[{pi}]"),
                            format!(
                                "control point {i} at {q} is {} the camera (depth {depth:.6}, near {}): a patch must lie in front of the camera; move the camera",
                                if depth < 0.0 { "behind" } else { "too close to" },
                                camera.near
                            ),
                        )
                        .into());
                    }
                    let s = camera.project(*q);
                    if !(s[0].abs() <= MAX_COORDINATE && s[1].abs() <= MAX_COORDINATE) {
                        return Err(SceneError::at_field(
                            SceneErrorKind::Limit,
                            format!("meshes[{k}].bezier.patches[{pi}]"),
                            format!("control point {i} projects to {s:?}, beyond ±{MAX_COORDINATE:e} pixels"),
                        )
                        .into());
                    }
                }
            }
            meshes.push((k, patches));
        }
        let facings = meshes.iter().map(|_| Facings::default()).collect();
        Ok(PatchScene {
            w,
            camera,
            view,
            rows: w.height(),
            params,
            lighting,
            meshes,
            facings,
        })
    }

    /// The same patches seen by `camera` (a light's view, `side` rows), their facings not
    /// yet known.
    pub fn seen_from(&self, camera: Camera, side: u32) -> PatchScene<'w> {
        PatchScene {
            w: self.w,
            camera,
            view: View { camera },
            rows: side,
            params: self.params,
            lighting: self.lighting.clone(),
            meshes: self.meshes.clone(),
            facings: self.meshes.iter().map(|_| Facings::default()).collect(),
        }
    }

    /// Every control point of every patch.
    pub fn control_points(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.meshes
            .iter()
            .flat_map(|(_, p)| p.iter())
            .flat_map(|p| p.points.iter().flatten().copied())
    }

    /// The scene's intensity channels.
    pub fn channels(&self) -> usize {
        self.w.channels()
    }

    /// Patches, over all meshes.
    pub fn patches(&self) -> u64 {
        self.meshes.iter().map(|(_, p)| p.len() as u64).sum()
    }

    /// The bands of rows: `(top, rows)`, top to bottom.
    pub fn bands(&self, band: u32) -> Vec<(u32, u32)> {
        let height = self.rows;
        let mut out = Vec::new();
        let mut top = 0;
        while top < height {
            let rows = band.min(height - top);
            out.push((top, rows));
            top += rows;
        }
        out
    }

    /// The pieces of every Bézier mesh in the band of rows `top .. top + rows`, mesh by
    /// mesh, appended to `out` (its `stats` counting what the band did): each made into
    /// its triangle as it is made, keeping of its surface what `S` keeps.
    pub fn band<S: KeptSurface>(
        &self,
        top: u32,
        rows: u32,
        out: &mut Pieces<S>,
    ) -> Result<(), RenderError> {
        for ((k, patches), known) in self.meshes.iter().zip(&self.facings) {
            let m = &self.w.spec.meshes[*k];
            // the first piece lit to a value that is not finite, in the order they come
            let mut unlit: Option<SceneError> = None;
            let (triangles, facing, origin, strip) = (
                &mut out.triangles,
                &mut out.facing,
                &mut out.origin,
                &mut out.strip,
            );
            let mut take = |p: band::Piece| {
                if unlit.is_some() {
                    return;
                }
                let Some(t) = triangle(&p, *k as u32, m, &self.camera, &self.lighting) else {
                    return;
                };
                for i in &t.intensity {
                    if let Err(e) = cwisim_world::lighting::check_lit(i, self.w.channels(), || {
                        (
                            format!("meshes[{k}].bezier.patches[{}]", p.patch),
                            "a piece of the patch".to_string(),
                        )
                    }) {
                        unlit = Some(e);
                        return;
                    }
                }
                triangles.push(t.map_surface(S::of));
                if S::WHOLE {
                    facing.push(p.facing);
                    origin.push((*k as u32, p.patch, p.uv));
                }
                strip.push(p.strip);
            };
            band_pieces(
                &self.view,
                patches,
                known,
                m.two_sided,
                top,
                rows,
                &self.params,
                &mut take,
                &mut out.stats,
            );
            if let Some(e) = unlit {
                return Err(e.into());
            }
        }
        out.bands += 1;
        Ok(())
    }
}

/// The pieces of every Bézier mesh of `w`, band by band (rows `0..height`; within a
/// band, mesh by mesh).
pub fn pieces(w: &WorldScene, settings: &Settings) -> Result<Pieces, RenderError> {
    pieces_of(&PatchScene::new(w, settings)?, settings)
}

/// The pieces of every patch of `scene`, band by band (as [`pieces`]).
fn pieces_of(scene: &PatchScene, settings: &Settings) -> Result<Pieces, RenderError> {
    let mut out = Pieces {
        patches: scene.patches(),
        ..Pieces::default()
    };
    let budget = cwisim_scene::budget::Budget::current();
    for (top, rows) in scene.bands(settings.band) {
        scene.band(top, rows, &mut out)?;
        // the pieces, and what exact visibility makes of them, within the memory
        // budget: checked band by band, before the next band's pieces are made
        check_budget(&budget, out.triangles.len(), top + rows, settings)?;
    }
    Ok(out)
}

/// `pieces` pieces at once (and what exact visibility makes of them) within the memory
/// budget.
fn check_budget(
    budget: &cwisim_scene::budget::Budget,
    pieces: usize,
    row: u32,
    settings: &Settings,
) -> Result<(), RenderError> {
    budget
        .check_memory(
            &format!(
                "drawing {pieces} pieces (so far, at row {row}; --subscan {} and --flatness {} set how many)",
                settings.subscan, settings.flatness
            ),
            pieces as u64 * BYTES_PER_PIECE,
        )
        .map_err(|e| RenderError::Usage(e.to_string()))
}

/// A piece as a screen triangle: normals turned toward the eye (two-sided meshes), or
/// `None` for a back-facing piece of a one-sided mesh.
fn triangle(
    p: &band::Piece,
    mesh: u32,
    m: &cwisim_world::scene::MeshSpec,
    camera: &Camera,
    lighting: &Lighting,
) -> Option<ScreenTriangle> {
    let eye = camera.eye;
    let geometric = (p.world[1] - p.world[0]).cross(p.world[2] - p.world[0]);
    let fallback = geometric.try_normalize().unwrap_or(DVec3::Z);
    let mut normals = p.normals.map(|n| n.unwrap_or(fallback));
    if !m.two_sided {
        // the patch's orientation decides: a triangle whose corners face away is culled
        let away = normals
            .iter()
            .zip(&p.world)
            .all(|(n, w)| n.dot(eye - *w) < 0.0);
        if away {
            return None;
        }
    } else {
        for (n, w) in normals.iter_mut().zip(&p.world) {
            if n.dot(eye - *w) < 0.0 {
                *n = -*n;
            }
        }
    }
    let intensity =
        std::array::from_fn(|c| lighting.intensity(&m.material, p.world[c], normals[c], eye));
    Some(ScreenTriangle {
        points: p.screen,
        inv_depth: p.world.map(|q| 1.0 / camera.depth(q)),
        intensity,
        mesh,
        face: p.patch,
        surface: Surface {
            world: p.world,
            normals,
            uv: p.uv.map(|(u, v)| [u, v]),
        },
    })
}

/// Nishita et al.'s renderer of a scene.
pub struct Nishita {
    inner: VanRij,
    /// What the patches made (empty for a scene without patches).
    stats: BandStats,
    bands: u64,
    patches: u64,
    triangles: u64,
    settings: Settings,
    /// Host time of the visibility pass.
    visibility_time: Duration,
    /// The visible fragments, packed, with each one's patch and pixel row, when a
    /// patch's row goes through the span fitter as one span ([`merged`]: box filter, a
    /// few rows at a time; `inner`'s scene then has no polygons of its own); `None` when
    /// the polygons are drawn as `vanrij` draws them (`inner`'s).
    merged: Option<merged::Fragments>,
    /// What the scan segments did, when the scene is all patches (visibility strip by
    /// strip, [`cwisim_world::sweep`]); `None` when its other meshes share exact visibility with
    /// the pieces.
    segments: Option<cwisim_world::sweep::SegmentStats>,
    /// What the lights' scans of the patches did, when a light casts shadows on them.
    light: Option<shadow::LightScanStats>,
}

/// Whether `w` has a Bézier mesh.
fn has_patches(w: &WorldScene) -> bool {
    w.spec.meshes.iter().any(|m| m.bezier.is_some())
}

/// A world scene is shaded smoothly: its patches' normals are the surface's own.
fn check_smooth(shading: Shading) -> Result<(), RenderError> {
    match shading {
        Shading::Gouraud | Shading::Phong => Ok(()),
        other => Err(RenderError::Usage(format!(
            "--renderer nishita shades its patches smoothly: --shading gouraud or phong (found {other})"
        ))),
    }
}

impl Nishita {
    /// The renderer of `loaded` under `settings`.
    /// `settings.visibility` is not read (the registry's entry does not list it): the
    /// pieces are at most a row high, so no `Eval0` claim could cover a pixel, and
    /// visibility is always exact.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<Nishita, RenderError> {
        let settings = &Settings {
            visibility: Visibility::Exact,
            ..*settings
        };
        let loaded = loaded.drawn_as(settings)?;
        settings.check().map_err(RenderError::Usage)?;
        if matches!(loaded.scene, AnyScene::World(_)) {
            check_smooth(settings.shading)?;
        }
        let w = match &loaded.scene {
            AnyScene::World(w) if has_patches(w) => w.clone(),
            _ => {
                // no patches: the polygons as vanrij draws them (with its shadows)
                let scene = PolygonScene::new(loaded, settings)?;
                return Ok(Nishita {
                    inner: VanRij::from_polygons(scene, settings),
                    stats: BandStats::default(),
                    bands: 0,
                    patches: 0,
                    triangles: 0,
                    settings: *settings,
                    visibility_time: Duration::ZERO,
                    merged: None,
                    segments: None,
                    light: None,
                });
            }
        };
        // the lights that cast shadows on the patches (§7: the light's own scan)
        let casters = crate::prepare::world_casters(&w, settings)?;
        let mut shadows = None;
        let mut shadow_time = Duration::ZERO;
        let mut light = None;
        // Phong, or a texture under any shading: lit per pixel
        let phong = settings.shading == Shading::Phong || w.textures.any();
        let shader = || PhongShader::for_shading(&w, settings.shading);
        // meshes that are not patches: projected as vanrij projects them
        let others: Vec<usize> = (0..w.spec.meshes.len())
            .filter(|&k| w.spec.meshes[k].bezier.is_none())
            .collect();
        let channels = w.channels();
        let mut project = None;
        let mut merged = None;
        let mut segments = None;
        let (made, count, polygons, vis, surfaces, geometry_time, visibility_time) = if others
            .is_empty()
            && casters.is_empty()
        {
            // only patches, exact visibility: band by band (`resolve`)
            let start = Instant::now();
            let scene = PatchScene::new(&w, settings)?;
            let r = resolve::resolve(&scene, settings, phong)?;
            let total = start.elapsed();
            let polygons = if settings.aa.is_box() {
                merged = Some(r.fragments);
                Vec::new()
            } else {
                r.fragments.unpack(0..r.fragments.len())
            };
            let surfaces = phong.then(|| {
                PhongSurfaces::new(r.triangles, r.sources, shader())
                    .filtered(settings.texture_filter)
            });
            segments = Some(r.stats);
            (
                r.pieces,
                r.count,
                polygons,
                None,
                surfaces,
                total.saturating_sub(r.time),
                r.time,
            )
        } else {
            let start = Instant::now();
            let scene = PatchScene::new(&w, settings)?;
            let made = pieces_of(&scene, settings)?;
            let geometry_time = start.elapsed();
            let mut tris = made.triangles;
            if !others.is_empty() {
                let mut sub = w.clone();
                sub.spec.meshes = others.iter().map(|&k| w.spec.meshes[k].clone()).collect();
                sub.meshes = others.iter().map(|&k| w.meshes[k].clone()).collect();
                let (more, stats) = cwisim_world::project::project(&sub, settings.shading)?;
                tris.extend(more.into_iter().map(|mut t| {
                    t.mesh = others[t.mesh as usize] as u32;
                    t
                }));
                project = Some(stats);
            }
            let start = Instant::now();
            let (polygons, vis, surfaces) = if !casters.is_empty() {
                let (fragments, stats) =
                    cwisim_world::visibility::exact_fragments_on(&tris, channels, settings.threads);
                let visible = start.elapsed();
                let mut scan = shadow::LightScanStats::default();
                let test = shadow::shadow_test(
                    &w, settings, &scene, &tris, &fragments, &casters, &mut scan,
                )?;
                let shadowed = cwisim_world::shadow::shadowed_by(&w, &tris, fragments, &test);
                shadow_time = start.elapsed().saturating_sub(visible);
                shadows = Some(shadowed.stats);
                light = Some(scan);
                let sources: Vec<usize> = shadowed.fragments.iter().map(|f| f.source).collect();
                let surfaces = phong.then(|| {
                    let mut s = PhongSurfaces::new(tris.clone(), sources, shader())
                        .filtered(settings.texture_filter);
                    s.shadows = Some(crate::prepare::PolygonLights {
                        casters: casters.clone(),
                        lit: shadowed.lit,
                    });
                    s
                });
                let polygons = shadowed.fragments.into_iter().map(|f| f.polygon).collect();
                (polygons, Some(stats), surfaces)
            } else if phong {
                let (fragments, stats) =
                    cwisim_world::visibility::exact_fragments_on(&tris, channels, settings.threads);
                let sources = fragments.iter().map(|f| f.source).collect();
                let polygons = fragments.into_iter().map(|f| f.polygon).collect();
                (
                    polygons,
                    Some(stats),
                    Some(
                        PhongSurfaces::new(tris.clone(), sources, shader())
                            .filtered(settings.texture_filter),
                    ),
                )
            } else {
                let (p, s) = cwisim_world::resolve_on(
                    &tris,
                    channels,
                    settings.visibility,
                    settings.threads,
                );
                (p, s, None)
            };
            let visibility_time = start.elapsed().saturating_sub(shadow_time);
            let made = Pieces {
                triangles: Vec::new(),
                facing: Vec::new(),
                origin: Vec::new(),
                strip: Vec::new(),
                ..made
            };
            (
                made,
                tris.len() as u64,
                polygons,
                vis,
                surfaces,
                geometry_time,
                visibility_time,
            )
        };
        let scene = PolygonScene {
            source: loaded.source,
            kind: "world",
            screen: w.screen(polygons),
            project,
            visibility: vis,
            visibility_mode: Some(settings.visibility),
            load_time: loaded.load_time,
            transform_time: geometry_time,
            visibility_time,
            shadows,
            shadow_time,
            phong: surfaces,
            transparent_meshes: w
                .spec
                .meshes
                .iter()
                .filter(|m| m.material.transmittance > 0.0)
                .count() as u64,
            ignored_depths: false,
        };
        Ok(Nishita {
            inner: VanRij::from_polygons(scene, settings),
            stats: made.stats,
            bands: made.bands,
            patches: made.patches,
            triangles: count,
            settings: *settings,
            visibility_time,
            merged,
            segments,
            light,
        })
    }

    /// The span fitter's tolerance for a patch's row under Gouraud shading: an eighth
    /// of `--shade-tolerance` (1/4096 at the default), so that the fitter adds little to
    /// the error against the reference (RMS 1.054e-3 to 1.06e-3 on the teapot; at the
    /// whole 1/512 it was 1.18e-3).
    /// With Phong shading, `--shade-tolerance` itself.
    pub fn span_tolerance(&self) -> f64 {
        match self.settings.shading {
            Shading::Phong => self.settings.shade_tolerance,
            _ => self.settings.shade_tolerance / 8.0,
        }
    }

    /// For the registry.
    pub fn build(
        loaded: LoadedScene,
        settings: &Settings,
    ) -> Result<Box<dyn Renderer>, RenderError> {
        Ok(Box::new(Nishita::new(loaded, settings)?))
    }

    /// What the patches made: subpatches, roots and iterations, pieces.
    pub fn band_stats(&self) -> &BandStats {
        &self.stats
    }

    /// The scene it draws: its polygons are the visible fragments of its pieces, but
    /// for the box filter, where they are held packed ([`Nishita::fragments`]) and the
    /// scene has none of its own.
    pub fn polygons(&self) -> &PolygonScene {
        self.inner.polygons()
    }

    /// The visible fragments, packed, with each one's patch and pixel row, when a patch's
    /// row is sent as one span (the box filter on Bézier patches); `None` otherwise.
    pub fn fragments(&self) -> Option<&merged::Fragments> {
        self.merged.as_ref()
    }

    /// Its own counters (the frame's, besides the Y-processor's).
    pub fn counters(&self) -> Counters {
        let s = &self.stats;
        let c = &s.clip;
        let mut out = Counters::default()
            .with("patches", self.patches)
            .with("bands", self.bands)
            .with("subpatches_front", s.front)
            .with("subpatches_back", s.back)
            .with("subpatches_twisted", s.twisted)
            .with("subpatches_back_culled", s.back_culled)
            .with("levels_capped", s.capped)
            .with("edges", s.edges)
            .with("curves", c.curves)
            .with("curves_rejected", c.rejected)
            .with("roots", c.roots)
            .with("iterations", c.iterations)
            .with("root_iterations", c.root_iterations)
            .with("wasted_iterations", c.wasted)
            .with("touching", c.touching)
            .with("clip_splits", c.splits)
            .with("straight_pieces", s.polygons)
            .with("straight_pieces_split", s.split_polygons)
            .with("silhouette_points", s.silhouette_points)
            .with("silhouettes_unsplit", s.silhouettes_unsplit)
            .with("piece_triangles", self.triangles);
        if let Some(g) = &self.segments {
            out = out
                .with("visible_fragments", g.fragments)
                .with("pieces_hidden", g.hidden)
                .with("segment_slabs", g.slabs)
                .with("segment_edge_crossings", g.edge_crossings)
                .with("segment_depth_crossings", g.depth_crossings)
                .with("segment_slivers", g.slivers);
        }
        if let Some(l) = &self.light {
            let b = &l.bands;
            out = out
                .with("light_subpatches", b.front + b.back + b.twisted)
                .with("light_roots", b.clip.roots)
                .with("light_pieces", l.pieces);
        }
        for (name, n) in HISTOGRAM_NAMES.iter().zip(c.histogram) {
            out.add(name, n);
        }
        out
    }
}

struct Frame<'a> {
    inner: Box<dyn FramePlan + 'a>,
    own: Counters,
}

impl FramePlan for Frame<'_> {
    fn counters(&self) -> Counters {
        let mut c = self.own.clone();
        c.merge(&self.inner.counters());
        c
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        self.inner.emit_rows(rows, sink)
    }
}

impl Renderer for Nishita {
    fn name(&self) -> &'static str {
        "nishita"
    }

    fn header(&self) -> TraceHeader {
        self.inner.header()
    }

    fn frame<'a>(
        &'a self,
        index: u32,
        previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        let inner: Box<dyn FramePlan + 'a> = match &self.merged {
            Some(fragments) => Box::new(merged::MergedFrame::new(
                &self.inner.polygons().screen,
                fragments,
                if self.settings.aa == cwisim_scene::Antialias::BoxCentre {
                    cwisim_ypipe::dofill::BoxValue::Centre
                } else {
                    cwisim_ypipe::dofill::BoxValue::Exact
                },
                self.span_tolerance(),
                self.inner.polygons().phong.as_ref(),
            )),
            None => self.inner.frame(index, previous)?,
        };
        Ok(Box::new(Frame {
            inner,
            own: self.counters(),
        }))
    }

    fn settings_phrase(&self) -> String {
        let s = &self.settings;
        let merged = match self.merged {
            Some(_) => format!(
                ", each patch's row one span (tolerance {})",
                self.span_tolerance()
            ),
            None => String::new(),
        };
        let normals = match s.normal_angle {
            Some(a) => format!(", divided again where corner normals differ by over {a}°"),
            None => String::new(),
        };
        format!(
            "{}{merged}; roots to {:e} of u/v, flatness {} px{normals}, bands of {} rows, {} sub-scanline(s) per row",
            self.inner.settings_phrase(),
            s.root_tolerance,
            s.flatness,
            s.band,
            s.subscan
        )
    }

    fn summary_rows(&self, counters: &Counters, stats: &RunStats) -> Vec<(&'static str, String)> {
        let mut rows = Vec::new();
        if self.patches > 0 {
            let s = &self.stats;
            let c = &s.clip;
            rows.push((
                "subpatches",
                format!(
                    "{} patches in {} bands: {} subpatches meeting their band ({} front, {} back, {} twisted; {} back culled), mean level {:.2}{}",
                    self.patches,
                    self.bands,
                    s.front + s.back + s.twisted,
                    s.front,
                    s.back,
                    s.twisted,
                    s.back_culled,
                    s.levels as f64 / self.bands.max(1) as f64,
                    if s.capped > 0 {
                        format!(", level capped at {} in {} band(s)", band::MAX_LEVEL, s.capped)
                    } else {
                        String::new()
                    }
                ),
            ));
            rows.push((
                "roots",
                format!(
                    "{} roots of {} edge × row-line curves ({} with no sign change, {} tangencies); average iterations per root {} (tolerance {:e}); {} iterations, {} wasted on pieces without a root, {} splits at ½",
                    c.roots,
                    c.curves,
                    c.rejected,
                    c.touching,
                    c.average().map_or("-".into(), |a| format!("{a:.3}")),
                    self.settings.root_tolerance,
                    c.iterations,
                    c.wasted,
                    c.splits
                ),
            ));
            let hist: Vec<String> = c
                .histogram
                .iter()
                .enumerate()
                .filter(|(_, &n)| n > 0)
                .map(|(i, n)| {
                    if i == HISTOGRAM - 1 {
                        format!("≥{i}: {n}")
                    } else {
                        format!("{i}: {n}")
                    }
                })
                .collect();
            rows.push(("iterations", format!("per root: {}", hist.join(", "))));
            rows.push((
                "pieces",
                format!(
                    "{} straight-sided pieces ({} crossing their strip more than twice), {} triangles; {} silhouette points on row lines ({} twisted pieces with a silhouette leaving through a subpatch edge, not cut)",
                    s.polygons, s.split_polygons, self.triangles, s.silhouette_points, s.silhouettes_unsplit
                ),
            ));
            if let Some(g) = &self.segments {
                rows.push((
                    "visibility",
                    format!(
                        "slab sweep, strip by strip: {} visible fragments of {} pieces ({} wholly hidden); {} slabs, {} cut where edges cross, {} where surfaces cross; {} slivers dropped, {:.1e} px² in all",
                        g.fragments, g.pieces, g.hidden, g.slabs, g.edge_crossings, g.depth_crossings, g.slivers, g.sliver_area
                    ),
                ));
            }
            if let Some(l) = &self.light {
                let b = &l.bands;
                rows.push((
                    "light's scan",
                    format!(
                        "§7: the patches scanned again from each light casting shadows: {} subpatches, {} roots, {} pieces in its view, {} fragments seen; {} clipped against the camera's pieces they lie in front of",
                        b.front + b.back + b.twisted,
                        b.clip.roots,
                        l.pieces,
                        l.fragments,
                        l.clipped
                    ),
                ));
            }
            let shadows = self.inner.polygons().shadow_time.as_nanos() as u64;
            let total = s.subpatch_ns
                + s.roots_ns
                + s.pieces_ns
                + self.visibility_time.as_nanos() as u64
                + shadows;
            let share = |ns: u64| 100.0 * ns as f64 / total.max(1) as f64;
            rows.push((
                "host time",
                format!(
                    "subpatches {:.0}%, roots {:.0}%, pieces {:.0}%, visibility {:.0}%{}",
                    share(s.subpatch_ns),
                    share(s.roots_ns),
                    share(s.pieces_ns),
                    share(self.visibility_time.as_nanos() as u64),
                    if self.light.is_some() {
                        format!(", shadows {:.0}%", share(shadows))
                    } else {
                        String::new()
                    }
                ),
            ));
        }
        rows.extend(self.inner.summary_rows(counters, stats));
        rows
    }

    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        let s = &self.stats;
        if self.patches == 0 {
            return self.inner.stage_times();
        }
        let mut times = vec![
            ("subpatches", Duration::from_nanos(s.subpatch_ns)),
            ("roots", Duration::from_nanos(s.roots_ns)),
            ("pieces", Duration::from_nanos(s.pieces_ns)),
            ("visibility", self.visibility_time),
        ];
        if self.light.is_some() {
            times.push(("shadows", self.inner.polygons().shadow_time));
        }
        times
    }

    fn scene_json(&self) -> serde_json::Value {
        let mut v = self.inner.scene_json();
        if let Some(o) = v.as_object_mut() {
            if let Some(f) = &self.merged {
                // held packed, not in the scene
                o.insert("polygons".into(), f.len().into());
            }
            o.insert(
                "nishita".into(),
                serde_json::to_value(self.counters()).unwrap_or_default(),
            );
        }
        v
    }
}
