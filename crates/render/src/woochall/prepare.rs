//! Triangles from any scene. A world scene is projected and lit (per vertex for
//! Gouraud, per face for flat; Phong keeps the world corners and normals and lights per
//! sample) with back faces culled — no hidden-surface removal: the samples resolve it.
//! A screen scene's polygons are triangulated (ear clipping, the `earcut` crate); a
//! polygon's `depth`, when the scene carries it, is its nearness (smaller depth nearer),
//! and without depth a later polygon lies in front of an earlier one (painting order).

use super::triangle::Tri;
use crate::error::RenderError;
use crate::settings::Settings;
use crate::source::{LoadedScene, Source};
use cwisim_isa::TraceHeader;
use cwisim_scene::{SceneError, ScreenScene, Shading, Vector};
use cwisim_world::face::ScreenTriangle;
use cwisim_world::shade::PhongShader;
use cwisim_world::shadow::{LightSet, ShadowTest};
use cwisim_world::texture::TextureStore;
use cwisim_world::{AnyScene, ProjectStats};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What shading calls need to shade with shadows.
pub struct Shadows {
    /// What the lights reach of each projected triangle.
    pub test: ShadowTest,
    /// The projected triangles (`Tri::source` indexes them).
    pub screen: Vec<ScreenTriangle>,
    /// Per projected triangle that the same lights reach everywhere, not all of them: the
    /// triangle relit by those lights (made once, not per call).
    pub relit: Vec<Option<ScreenTriangle>>,
}

/// What [`Triangles::new`] holds a triangle of a world scene, the meshes aside: the
/// screen triangles, the renderer's own and their index (970–1,030 bytes measured on the
/// teapot and the pot; `tests/projection_memory.rs`), checked against the memory budget
/// before projecting.
pub const BYTES_PER_TRIANGLE: u64 = 1_100;

/// The triangles of a scene, and what making them did.
pub struct Triangles {
    /// Where the scene came from.
    pub source: Source,
    /// `"screen"` or `"world"`.
    pub kind: &'static str,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Channels.
    pub channels: u8,
    header: TraceHeader,
    /// The triangles (zero-area ones dropped).
    pub tris: Vec<Tri>,
    /// With Phong shading: the projected triangles (`Tri::source` indexes them) and the
    /// lighting.
    pub phong: Option<(Vec<ScreenTriangle>, PhongShader)>,
    /// With shadows: what the lights reach of each projected triangle.
    pub shadows: Option<Shadows>,
    /// The scene's textures, decoded when first shaded (`None` for a screen scene).
    pub textures: Option<Arc<TextureStore>>,
    /// Wall time of the shadow pass (the lights' views).
    pub shadow_time: Duration,
    /// What projection did (world scenes).
    pub project: Option<ProjectStats>,
    /// Polygons triangulated (screen scenes).
    pub polygons: u64,
    /// Wall time of reading the scene.
    pub load_time: Duration,
    /// Wall time of projection and lighting, or triangulation.
    pub transform_time: Duration,
}

impl Triangles {
    /// The triangles of `loaded`, lit for `settings.shading`, with what the lights that
    /// cast shadows reach of each (`settings.shadows`; their views on `settings.threads`).
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<Triangles, RenderError> {
        let shading = settings.shading;
        let start = Instant::now();
        let kind = loaded.scene.kind();
        let loaded_textured = loaded.scene.is_textured();
        let (mut project, mut phong, mut polygons) = (None, None, 0);
        let (mut shadows, mut shadow_time) = (None, Duration::ZERO);
        let mut textures = None;
        let (width, height, channels, tris) = match loaded.scene {
            AnyScene::Screen(s) => {
                if shading == Shading::Phong {
                    return Err(crate::prepare::phong_needs_world());
                }
                crate::prepare::check_intensities(&s, &loaded.source)?;
                polygons = s.polygons.len() as u64;
                (s.width, s.height, s.channels, screen_triangles(&s))
            }
            AnyScene::World(w) => {
                crate::prepare::check_projection_memory(&w, BYTES_PER_TRIANGLE, "woo-chall")?;
                let (screen, stats) = cwisim_world::project::project(&w, shading)?;
                let tris = screen
                    .iter()
                    .enumerate()
                    .filter_map(|(k, t)| {
                        let mut tri =
                            Tri::new(t.points, t.inv_depth, t.intensity, t.mesh, k as u32)?;
                        tri.transmittance = w.spec.meshes[t.mesh as usize].material.transmittance;
                        Some(tri)
                    })
                    .collect();
                project = Some(stats);
                if let Some((test, time)) = crate::prepare::sampled_shadows(&w, &screen, settings)?
                {
                    let relit = (0..screen.len())
                        .map(|k| match test.uniform(k) {
                            Some(set) if set != LightSet::ALL => Some(ScreenTriangle {
                                intensity: test.corners(k, &screen[k], set),
                                ..screen[k]
                            }),
                            _ => None,
                        })
                        .collect();
                    shadows = Some(Shadows {
                        test,
                        screen: screen.clone(),
                        relit,
                    });
                    shadow_time = time;
                }
                textures = Some(Arc::clone(&w.textures));
                // a textured mesh is shaded per call whatever the shading, as Phong is:
                // its texture read at the sample
                if shading == Shading::Phong || loaded_textured {
                    phong = Some((screen, PhongShader::for_shading(&w, shading)));
                }
                (w.width(), w.height(), w.channels() as u8, tris)
            }
        };
        let header = TraceHeader::new(width, height, channels)
            .map_err(|e| RenderError::Usage(format!("the scene does not fit the array: {e}")))?;
        Ok(Triangles {
            source: loaded.source,
            kind,
            width,
            height,
            channels,
            header,
            tris,
            phong,
            shadows,
            textures,
            shadow_time,
            project,
            polygons,
            load_time: loaded.load_time,
            transform_time: start.elapsed() - shadow_time,
        })
    }

    /// The array it draws into.
    pub fn header(&self) -> TraceHeader {
        self.header
    }

    /// Whether a mesh is textured.
    pub fn textured(&self) -> bool {
        self.textures.as_ref().is_some_and(|t| t.any())
    }

    /// One shading call: the colour of `tri` at `(x, y)`; the error of a texture that
    /// fails to decode here, when first needed.
    pub fn shade(&self, tri: &Tri, x: f64, y: f64) -> Result<Vector, SceneError> {
        let channels = usize::from(self.channels);
        let k = tri.source as usize;
        // the lights that reach the sample (every light without shadows)
        let lit = self
            .shadows
            .as_ref()
            .map_or(LightSet::ALL, |s| s.test.lit_at(k, [x, y]));
        match (&self.phong, &self.shadows) {
            (Some((tris, shader)), shadows) => {
                let mut v = match shadows {
                    Some(s) if lit != LightSet::ALL => {
                        shader.at_lit(&tris[k], [x, y], |l| s.test.casters().reaches(lit, l))
                    }
                    _ => shader.at(&tris[k], [x, y]),
                }?
                .unwrap_or_default();
                for c in v.iter_mut() {
                    *c = c.max(0.0);
                }
                Ok(v)
            }
            (None, Some(s)) if lit != LightSet::ALL => {
                // Gouraud or flat without the lights that do not reach: the corners relit
                let made;
                let shaded = match &s.relit[k] {
                    Some(t) => t,
                    None => {
                        let t = &s.screen[k];
                        made = ScreenTriangle {
                            intensity: s.test.corners(k, t, lit),
                            ..*t
                        };
                        &made
                    }
                };
                Ok(shaded.intensity_at([x, y], channels).unwrap_or_default())
            }
            _ => Ok(tri.intensity_at(x, y, channels)),
        }
    }

    /// The summary's geometry row.
    pub fn summary_rows(&self) -> Vec<(&'static str, String)> {
        let mut rows = self.geometry_rows();
        if let Some(Shadows { test, .. }) = &self.shadows {
            rows.push(crate::prepare::sampled_shadows_row(
                test,
                "each shading call tests its sample against the lit parts",
            ));
        }
        rows
    }

    fn geometry_rows(&self) -> Vec<(&'static str, String)> {
        match &self.project {
            Some(g) => vec![(
                "geometry",
                format!(
                    "{}; no hidden-surface removal before sampling",
                    crate::prepare::geometry_phrase(g)
                ),
            )],
            None => vec![(
                "geometry",
                format!(
                    "{} polygon(s) → {} triangles (ear clipping)",
                    self.polygons,
                    self.tris.len()
                ),
            )],
        }
    }

    /// The scene part of `--stats-json`.
    pub fn scene_json(&self) -> serde_json::Value {
        serde_json::json!({
            "name": self.source.name(),
            "kind": self.kind,
            "triangles": self.tris.len(),
            "project": self.project,
            "shadows": self
                .shadows
                .as_ref()
                .map(|Shadows { test, .. }| crate::prepare::sampled_shadows_json(test)),
        })
    }
}

/// A screen scene's polygons as triangles.
fn screen_triangles(s: &ScreenScene) -> Vec<Tri> {
    let channels = s.channel_count();
    let mut earcut = earcut::Earcut::new();
    let mut indices: Vec<u32> = Vec::new();
    let mut tris = Vec::new();
    for (k, p) in s.polygons.iter().enumerate() {
        earcut.earcut(p.vertices.iter().copied(), &[] as &[u32], &mut indices);
        let near = |v: usize| match &p.depth {
            Some(d) => -d[v],
            None => k as f64,
        };
        let intensity = |v: usize| cwisim_scene::vector(channels, |c| p.intensity[v][c]);
        for t in indices.chunks_exact(3) {
            let v = [t[0] as usize, t[1] as usize, t[2] as usize];
            if let Some(tri) = Tri::new(
                v.map(|i| p.vertices[i]),
                v.map(near),
                v.map(intensity),
                k as u32,
                k as u32,
            ) {
                tris.push(tri);
            }
        }
    }
    tris
}
