//! From a loaded scene to screen-space polygons: what every polygon renderer starts from.
//! A screen scene is taken as it is; a world scene is projected, lit (per vertex for
//! Gouraud shading, per face for flat) with back faces culled, and its hidden surfaces
//! removed (exact fragments, or whole triangles front to back for `Eval0` claims).

use crate::error::RenderError;
use crate::settings::Settings;
use crate::source::{LoadedScene, Source};
use cwisim_scene::{SceneError, ScreenScene, Shading, Vector};
use cwisim_world::face::ScreenTriangle;
use cwisim_world::shade::PhongShader;
use cwisim_world::shadow::{self, Casters, LightSet, ShadowStats, ShadowTest};
use cwisim_world::texture::{RowRelease, TextureFilter};
use cwisim_world::{AnyScene, ProjectStats, Visibility, VisibilityStats};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Screen-space polygons, ready to scan-convert, and what making them did.
#[derive(Clone, Debug)]
pub struct PolygonScene {
    /// Where the scene came from.
    pub source: Source,
    /// `"screen"` or `"world"`.
    pub kind: &'static str,
    /// The polygons, in the order they are sent.
    pub screen: ScreenScene,
    /// What projection did (world scenes).
    pub project: Option<ProjectStats>,
    /// What exact visibility did (world scenes, exact visibility).
    pub visibility: Option<VisibilityStats>,
    /// The visibility used (world scenes; screen scenes are drawn as they are).
    pub visibility_mode: Option<Visibility>,
    /// Wall time of reading the scene.
    pub load_time: Duration,
    /// Wall time of transform, lighting and culling (world scenes).
    pub transform_time: Duration,
    /// Wall time of hidden-surface removal (world scenes).
    pub visibility_time: Duration,
    /// What the shadow pass did (world scenes with a light casting shadows).
    pub shadows: Option<ShadowStats>,
    /// Wall time of the shadow pass.
    pub shadow_time: Duration,
    /// With Phong shading, or a textured scene under any shading: what per-pixel
    /// shading needs of the world.
    pub phong: Option<PhongSurfaces>,
    /// Meshes whose material lets light through (`transmittance` > 0), drawn opaque
    /// here: polygon renderers keep the nearest surface only.
    pub transparent_meshes: u64,
    /// A screen scene whose polygons carry depths, which the polygon renderers do not
    /// read: their polygons add up.
    pub ignored_depths: bool,
}

/// What per-pixel (Phong) shading needs: the projected triangles with their world
/// corners and normals, the source triangle of every polygon, and the scene's lighting.
#[derive(Clone, Debug)]
pub struct PhongSurfaces {
    /// The projected, lit triangles.
    pub triangles: Vec<ScreenTriangle>,
    /// For each polygon of the screen scene (an exact visible fragment), the triangle it
    /// is a piece of.
    pub sources: Vec<usize>,
    /// The lighting.
    pub shader: PhongShader,
    /// With shadows: which lights reach each polygon.
    pub shadows: Option<PolygonLights>,
    /// How a pixel reads a texture.
    pub filter: TextureFilter,
    /// With textures: each dropped after the last row its triangles reach
    /// ([`Self::rows_done`]).
    pub release: Option<Arc<RowRelease>>,
}

/// Which lights reach each polygon of a scene drawn with shadows.
#[derive(Clone, Debug)]
pub struct PolygonLights {
    /// The lights that cast shadows.
    pub casters: Casters,
    /// Per polygon, the casters that reach it.
    pub lit: Vec<LightSet>,
}

impl PhongSurfaces {
    /// Per-pixel shading without shadows.
    pub fn new(triangles: Vec<ScreenTriangle>, sources: Vec<usize>, shader: PhongShader) -> Self {
        let release = shader
            .textured()
            .then(|| Arc::new(RowRelease::of_triangles(shader.texture_store(), &triangles)));
        PhongSurfaces {
            triangles,
            sources,
            shader,
            shadows: None,
            filter: TextureFilter::Box,
            release,
        }
    }

    /// Rows `rows` are emitted: the textures no later row reads are dropped (decoded
    /// again if a later frame reads them).
    pub fn rows_done(&self, rows: std::ops::Range<u32>) {
        if let Some(r) = &self.release {
            r.rows_done(rows);
        }
    }

    /// The same, reading textures through `filter`.
    pub fn filtered(self, filter: TextureFilter) -> Self {
        PhongSurfaces { filter, ..self }
    }

    /// The intensity of polygon `polygon` at screen point `p` (on its triangle) of the
    /// pixel whose centre is `centre`, by the lights that reach it, its texture read
    /// through [`Self::filter`] (`cwisim_world::shade::PhongShader::at_pixel_lit`).
    /// A texture decoded here that fails is the scene's error.
    pub fn shade_pixel(
        &self,
        polygon: usize,
        p: [f64; 2],
        centre: [f64; 2],
    ) -> Result<Option<Vector>, SceneError> {
        let triangle = &self.triangles[self.sources[polygon]];
        match &self.shadows {
            None => self
                .shader
                .at_pixel_lit(triangle, p, centre, self.filter, |_| true),
            Some(s) => self
                .shader
                .at_pixel_lit(triangle, p, centre, self.filter, |k| {
                    s.casters.reaches(s.lit[polygon], k)
                }),
        }
    }
}

/// Refuses, before a triangle is projected, a scene whose screen triangles and their
/// visibility would hold more than the memory budget: the triangles with their surfaces
/// (`keep_surfaces`) or without, exact visibility's own figure a triangle
/// ([`cwisim_world::visibility::exact_memory`]), and the built meshes
/// ([`cwisim_world::WorldScene::mesh_bytes`]) while they are held — while the triangles
/// are projected, and all along when the surfaces are kept (else they are dropped once
/// projected).
fn check_visibility_memory(
    w: &cwisim_world::WorldScene,
    settings: &Settings,
    keep_surfaces: bool,
) -> Result<(), RenderError> {
    use cwisim_world::face::ScreenTriangle;
    let triangles = w.triangle_count() as u64;
    let triangle_bytes = if keep_surfaces {
        std::mem::size_of::<ScreenTriangle>()
    } else {
        std::mem::size_of::<ScreenTriangle<()>>()
    } as u64;
    let meshes = w.mesh_bytes();
    let projected = triangles.saturating_mul(triangle_bytes);
    let (what, held) = match settings.visibility {
        Visibility::Exact => (
            "exact visibility of",
            cwisim_world::visibility::exact_memory(triangles, triangle_bytes, settings.threads),
        ),
        Visibility::Eval0 => ("projecting", projected),
    };
    let bytes = if keep_surfaces {
        meshes.saturating_add(held)
    } else {
        meshes.saturating_add(projected).max(held)
    };
    cwisim_scene::budget::Budget::current()
        .check_memory(&format!("{what} the scene's {triangles} triangles"), bytes)
        .map_err(|e| RenderError::Usage(e.to_string()))
}

/// Refuses, before a triangle is projected, a scene whose triangles, as a renderer that
/// projects its own (`woo-chall`, `sbuffer`, `bsp`) holds them, would pass the memory
/// budget: `bytes_per_triangle` (the renderer's figure, measured on the teapot by
/// `tests/projection_memory.rs`) for each, beside the built meshes
/// ([`cwisim_world::WorldScene::mesh_bytes`]), held all along. Shadows are checked by
/// their own pass.
pub(crate) fn check_projection_memory(
    w: &cwisim_world::WorldScene,
    bytes_per_triangle: u64,
    renderer: &str,
) -> Result<(), RenderError> {
    let triangles = w.triangle_count() as u64;
    let meshes = w.mesh_bytes();
    let bytes = meshes.saturating_add(triangles.saturating_mul(bytes_per_triangle));
    cwisim_scene::budget::Budget::current()
        .check_memory(
            &format!("projecting the scene's {triangles} triangles for {renderer}"),
            bytes,
        )
        .map_err(|e| RenderError::Usage(e.to_string()))
}

/// The lights of world scene `w` that cast shadows under `settings`, refusing a
/// `--shadows` that would change nothing: `on` in a scene without lights, `off` in one
/// where no light casts shadows.
pub(crate) fn world_casters(
    w: &cwisim_world::WorldScene,
    settings: &Settings,
) -> Result<Casters, RenderError> {
    let lights = &w.spec.lights;
    match settings.shadows {
        Some(true) if lights.is_empty() => Err(RenderError::Usage(
            "--shadows on: the scene has no lights to cast them (ambient light casts no shadow)".into(),
        )),
        Some(false) if !lights.iter().any(|l| l.shadows) => Err(RenderError::Usage(
            "--shadows off: no light of the scene casts shadows (none says \"shadows\": true), so it would draw exactly as without".into(),
        )),
        _ => Ok(shadow::casters(&w.spec, settings.shadows)?),
    }
}

/// For a renderer that tests each sample: what the lights that cast shadows under
/// `settings` reach of the projected triangles `tris` of `w` (lit for `shading`), and how
/// long making it took; `None` when no light casts shadows.
pub(crate) fn sampled_shadows(
    w: &cwisim_world::WorldScene,
    tris: &[ScreenTriangle],
    settings: &Settings,
) -> Result<Option<(ShadowTest, Duration)>, RenderError> {
    let casters = world_casters(w, settings)?;
    if casters.is_empty() {
        return Ok(None);
    }
    let start = Instant::now();
    let test = ShadowTest::new(w, settings.shading, tris, &casters, settings.threads)?;
    Ok(Some((test, start.elapsed())))
}

/// The summary's `shadows` row of a renderer that tests each sample (`how`: what it
/// tests).
pub(crate) fn sampled_shadows_row(test: &ShadowTest, how: &str) -> (&'static str, String) {
    (
        "shadows",
        format!(
            "{} light(s) casting, exact: {how} ({} triangles in the lights' views, {} seen)",
            test.casters().lights.len(),
            test.light_triangles,
            test.light_fragments
        ),
    )
}

/// The `--stats-json` figures of [`sampled_shadows`].
pub(crate) fn sampled_shadows_json(test: &ShadowTest) -> serde_json::Value {
    serde_json::json!({
        "lights": test.casters().lights.len(),
        "light_triangles": test.light_triangles,
        "light_fragments": test.light_fragments,
    })
}

/// The refusal of Phong shading on a screen scene, the same from every renderer.
pub fn phong_needs_world() -> RenderError {
    RenderError::Usage(
        "Phong shading needs a world scene (normals in 3D); a screen scene has only intensities: use --shading gouraud or flat".into(),
    )
}

/// Checks a screen scene's intensities as every renderer of screen scenes draws them,
/// naming the value's JSON path: each finite and at most `cwisim_scene::MAX_INTENSITY` in
/// magnitude ([`RenderError::Scene`], as `ScreenScene::validate` refuses a file's — a
/// scene built in code is never validated, and its values must not overflow a renderer's
/// arithmetic either), and none negative ([`RenderError::Usage`]: the array adds light and
/// drops negative contributions while `Acc_mode` is off, so a negative polygon would be
/// drawn as 0 — silently wrong). Every renderer of screen scenes calls it.
///
/// `source` names the file in the message, when the scene is one.
pub fn check_intensities(s: &ScreenScene, source: &Source) -> Result<(), RenderError> {
    let file = source.path();
    for (k, p) in s.polygons.iter().enumerate() {
        for (v, i) in p.intensity.iter().enumerate() {
            cwisim_scene::check_intensity(k, v, i).map_err(|e| match file {
                Some(f) => e.in_file(f),
                None => e,
            })?;
            if let Some(bad) = i.iter().find(|c| **c < 0.0) {
                let at = file.map_or_else(String::new, |f| format!("{}: ", f.display()));
                return Err(RenderError::Usage(format!(
                    "{at}polygons[{k}].intensity[{v}]: intensity {bad:?} is negative; renderers draw light, intensities ≥ 0 (the array drops negative contributions)"
                )));
            }
        }
    }
    Ok(())
}

/// What projection did, as the summary's `geometry` row says it.
pub fn geometry_phrase(g: &ProjectStats) -> String {
    format!(
        "{} mesh(es), {} faces → {} triangles: {} back faces culled, {} drawn ({} back faces of two-sided meshes, {} edge-on dropped)",
        g.meshes,
        g.faces,
        g.triangles,
        g.culled,
        g.triangles - g.culled - g.edge_on,
        g.back_faces_drawn,
        g.edge_on
    )
}

impl PolygonScene {
    /// Makes `loaded` ready as `settings` say.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<PolygonScene, RenderError> {
        settings.check().map_err(RenderError::Usage)?;
        let loaded = loaded.drawn_as(settings)?;
        let kind = loaded.scene.kind();
        let mut prepared = PolygonScene {
            source: loaded.source,
            kind,
            screen: ScreenScene {
                width: 1,
                height: 1,
                channels: 1,
                polygons: Vec::new(),
            },
            project: None,
            visibility: None,
            visibility_mode: None,
            load_time: loaded.load_time,
            transform_time: Duration::ZERO,
            visibility_time: Duration::ZERO,
            shadows: None,
            shadow_time: Duration::ZERO,
            phong: None,
            transparent_meshes: 0,
            ignored_depths: false,
        };
        if settings.shading == Shading::Hidden {
            return Err(RenderError::Usage(
                "--shading hidden (edges of the visible triangles, no shading calls) is drawn by renderers that resolve visibility per sample: use --renderer woo-chall".into(),
            ));
        }
        let textured = loaded.scene.is_textured();
        let phong = settings.shading == Shading::Phong;
        // a texture changes the intensity within a triangle under any shading: it is
        // drawn per pixel, as Phong is
        let per_pixel = phong || textured;
        match loaded.scene {
            AnyScene::Screen(_) if phong => return Err(phong_needs_world()),
            AnyScene::Screen(s) => {
                check_intensities(&s, &prepared.source)?;
                prepared.ignored_depths = s.polygons.iter().any(|p| p.depth.is_some());
                prepared.screen = s
            }
            AnyScene::World(_) if phong && settings.visibility != Visibility::Exact => {
                return Err(RenderError::Usage(
                    "Phong shading is drawn on exact visible surfaces only: use --visibility exact (eval0 claims hold one value per pixel run, not a per-pixel shade)".into(),
                ))
            }
            AnyScene::World(_) if textured && settings.visibility != Visibility::Exact => {
                return Err(RenderError::Usage(
                    "textures are drawn on exact visible surfaces only: use --visibility exact (eval0 claims hold one value per pixel run, not a texture)".into(),
                ))
            }
            AnyScene::World(mut w) => {
                prepared.transparent_meshes = w
                    .spec
                    .meshes
                    .iter()
                    .filter(|m| m.material.transmittance > 0.0)
                    .count() as u64;
                let casters = world_casters(&w, settings)?;
                let keep_surfaces = per_pixel || !casters.is_empty();
                check_visibility_memory(&w, settings, keep_surfaces)?;
                let start = Instant::now();
                let (polygons, vis, project) = if keep_surfaces {
                    let (tris, project) = cwisim_world::project::project(&w, settings.shading)?;
                    prepared.transform_time = start.elapsed();
                    let start = Instant::now();
                    // the fragments with their source triangles: per-pixel shading and
                    // shadows need them
                    let (fragments, stats) = match settings.visibility {
                        Visibility::Exact => {
                            let (f, stats) = cwisim_world::visibility::exact_fragments_on(
                                &tris,
                                w.channels(),
                                settings.threads,
                            );
                            (f, Some(stats))
                        }
                        Visibility::Eval0 => (
                            cwisim_world::visibility::front_to_back_fragments(&tris, w.channels()),
                            None,
                        ),
                    };
                    prepared.visibility_time = start.elapsed();
                    let start = Instant::now();
                    let shadowed = cwisim_world::shadow::shadowed(
                        &w,
                        settings.shading,
                        &tris,
                        fragments,
                        &casters,
                        settings.threads,
                    )?;
                    if !casters.is_empty() {
                        prepared.shadows = Some(shadowed.stats);
                        prepared.shadow_time = start.elapsed();
                    }
                    let sources = shadowed.fragments.iter().map(|f| f.source).collect();
                    if per_pixel {
                        let mut surfaces = PhongSurfaces::new(
                            tris,
                            sources,
                            PhongShader::for_shading(&w, settings.shading),
                        )
                        .filtered(settings.texture_filter);
                        if !casters.is_empty() {
                            surfaces.shadows = Some(PolygonLights {
                                casters,
                                lit: shadowed.lit,
                            });
                        }
                        prepared.phong = Some(surfaces);
                    }
                    (
                        shadowed.fragments.into_iter().map(|f| f.polygon).collect(),
                        stats,
                        project,
                    )
                } else {
                    // nothing reads the triangles' corners in the world after lighting:
                    // they are not kept
                    let (tris, project) =
                        cwisim_world::project::project_plain(&w, settings.shading)?;
                    // nor the meshes: what follows reads the scene's size alone
                    drop(std::mem::take(&mut w.meshes));
                    prepared.transform_time = start.elapsed();
                    let start = Instant::now();
                    let (polygons, vis) = cwisim_world::resolve_on(
                        &tris,
                        w.channels(),
                        settings.visibility,
                        settings.threads,
                    );
                    prepared.visibility_time = start.elapsed();
                    (polygons, vis, project)
                };
                prepared.screen = w.screen(polygons);
                prepared.project = Some(project);
                prepared.visibility = vis;
                prepared.visibility_mode = Some(settings.visibility);
            }
        }
        Ok(prepared)
    }

    /// The host-side figures every polygon renderer's summary shows: the geometry, and
    /// exact visibility's fragments.
    pub fn summary_rows(&self) -> Vec<(&'static str, String)> {
        let mut rows = Vec::new();
        if let Some(g) = &self.project {
            rows.push(("geometry", geometry_phrase(g)));
        }
        if let (Some(Visibility::Exact), Some(v)) = (&self.visibility_mode, &self.visibility) {
            rows.push((
                "visibility",
                format!(
                    "exact: {} visible fragments of {} triangles ({} wholly hidden; {} occluding pairs; {} hole cuts; {} slivers dropped, {:.1e} px² in all)",
                    v.fragments, v.triangles, v.hidden, v.occluding_pairs, v.hole_cuts, v.dropped_slivers, v.dropped_area
                ),
            ));
        }
        if let Some(s) = &self.shadows {
            rows.push((
                "shadows",
                format!(
                    "{} light(s) casting, exact: {} shadow polygons among {} pieces of {} fragments ({} triangles in the lights' views, {} seen; {} booleans; {} hole cuts; {} slivers dropped, {:.1e} px² in all)",
                    s.lights, s.shadow_polygons, s.pieces, s.fragments_in, s.light_triangles, s.light_fragments, s.booleans, s.hole_cuts, s.dropped_slivers, s.dropped_area
                ),
            ));
        }
        if let Some(t) = self.textures_phrase() {
            rows.push(("textures", t));
        }
        if self.transparent_meshes > 0 {
            rows.push((
                "note",
                format!(
                    "{} mesh(es) with a transmittance drawn opaque: this renderer keeps the nearest surface (woo-chall and sbuffer --sbuffer transparent composite the layers)",
                    self.transparent_meshes
                ),
            ));
        }
        if self.ignored_depths {
            rows.push((
                "note",
                "the scene's polygons carry depths, which this renderer does not read: they add up, each drawn whole (woo-chall, sbuffer and bsp draw the nearest)".to_string(),
            ));
        }
        rows
    }

    /// The textures of a textured scene, and how pixels read them.
    fn textures_phrase(&self) -> Option<String> {
        let s = self.phong.as_ref().filter(|s| s.shader.textured())?;
        let labels = self.texture_labels();
        let how = match s.filter {
            TextureFilter::Box => {
                "box filter: each pixel the texture's mean over its footprint (summed-area table)"
            }
            TextureFilter::Point => "point sampling: each pixel the texel under its centre",
        };
        Some(format!(
            "{} texture(s) ({}), {how}; every shade through the span fitter",
            labels.len(),
            labels.join(", ")
        ))
    }

    /// Per textured mesh, `mesh K: LABEL W×H`.
    fn texture_labels(&self) -> Vec<String> {
        let Some(s) = &self.phong else {
            return Vec::new();
        };
        let store = s.shader.textures();
        (0..store.len() as u32)
            .filter_map(|k| {
                let (w, h) = store.size(k)?;
                Some(format!("mesh {k}: {} {w}×{h}", store.label(k)?))
            })
            .collect()
    }

    /// The host-side stage times: transform & lighting, visibility, shadows (when cast).
    pub fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        let mut times = vec![
            ("transform & lighting", self.transform_time),
            ("visibility", self.visibility_time),
        ];
        if self.shadows.is_some() {
            times.push(("shadows", self.shadow_time));
        }
        times
    }

    /// The scene part of `--stats-json`: deterministic (no times, no paths).
    pub fn scene_json(&self) -> serde_json::Value {
        let mut json = serde_json::json!({
            "name": self.source.name(),
            "kind": self.kind,
            "polygons": self.screen.polygons.len(),
            "visibility": self.visibility_mode.map(Visibility::name),
            "project": self.project,
            "exact_visibility": self.visibility,
            "shadows": self.shadows,
        });
        let textures = self.texture_labels();
        if !textures.is_empty() {
            json["textures"] = textures.into();
        }
        json
    }
}
