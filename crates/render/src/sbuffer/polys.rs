//! Polygons for the scanline principle, from any scene: each with its CP data (vertices,
//! critical points), its intensities, and a depth plane. Shared by `sbuffer` and `bsp`.
//!
//! * A **screen scene**'s polygons are taken as they are (no triangulation: CP converts
//!   any simple polygon). Their `depth`, when the scene carries it, is the polygon's plane
//!   (`Polygon::depth_at`'s: through vertex 0 and the best-conditioned fan triangle),
//!   smaller nearer; without depth a later polygon lies in front of an earlier one
//!   (painting order), as for `woo-chall`.
//! * A **world scene** is projected and lit (per vertex for Gouraud, per face for flat;
//!   Phong keeps the world corners and normals and lights per pixel) with back faces
//!   culled, and no hidden-surface removal: each triangle is a polygon, its key the plane
//!   of `−1/depth` over the screen (affine in screen space, so exact to interpolate).

use crate::cp::CpPolygon;
use crate::error::RenderError;
use crate::settings::Settings;
use crate::source::{LoadedScene, Source};
use cwisim_isa::TraceHeader;
use cwisim_scene::{Polygon, SceneError, Shading, Vector};
use cwisim_world::face::ScreenTriangle;
use cwisim_world::shade::PhongShader;
use cwisim_world::shadow::{LightSet, LineLights, ShadowTest};
use cwisim_world::texture::RowRelease;
use cwisim_world::{AnyScene, ProjectStats};
use std::time::{Duration, Instant};

/// One polygon, ready to scan-convert by CP.
#[derive(Clone, Debug)]
pub struct Poly {
    /// Vertices and critical points.
    pub cp: CpPolygon,
    /// The intensity at each vertex (Gouraud interpolates along edges, then across).
    pub intensity: Vec<Vector>,
    /// The flat intensity: the vertices' mean (a lit face's value, exactly).
    pub flat: Vector,
    /// The depth key `a·x + b·y + c` (smaller nearer).
    pub plane: [f64; 3],
    /// The screen polygon or world triangle it comes from.
    pub source: u32,
    /// Its material's transmittance (0 opaque; screen polygons are opaque).
    pub transmittance: f64,
}

impl Poly {
    /// The depth key at `(x, y)`: smaller is nearer.
    pub fn key(&self, x: f64, y: f64) -> f64 {
        let [a, b, c] = self.plane;
        a * x + b * y + c
    }
}

/// The plane `k = a·x + b·y + c` through three points `(x, y, k)`; `None` when they are
/// collinear on the screen.
fn plane3(p: [[f64; 2]; 3], k: [f64; 3]) -> Option<[f64; 3]> {
    let (ux, uy, uk) = (p[1][0] - p[0][0], p[1][1] - p[0][1], k[1] - k[0]);
    let (vx, vy, vk) = (p[2][0] - p[0][0], p[2][1] - p[0][1], k[2] - k[0]);
    let det = ux * vy - uy * vx;
    if det == 0.0 {
        return None;
    }
    let a = (uk * vy - uy * vk) / det;
    let b = (ux * vk - uk * vx) / det;
    let c = k[0] - a * p[0][0] - b * p[0][1];
    [a, b, c].iter().all(|v| v.is_finite()).then_some([a, b, c])
}

/// A screen polygon's depth plane: through vertex 0 and the fan triangle `(0, j, j+1)`
/// of largest area, as `Polygon::depth_at` takes it.
fn polygon_plane(p: &Polygon, depth: &[f64]) -> Option<[f64; 3]> {
    let v = &p.vertices;
    let a = v[0];
    let cross =
        |b: [f64; 2], c: [f64; 2]| (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    let j = (1..v.len().saturating_sub(1)).max_by(|&i, &k| {
        cross(v[i], v[i + 1])
            .abs()
            .total_cmp(&cross(v[k], v[k + 1]).abs())
    })?;
    plane3([a, v[j], v[j + 1]], [depth[0], depth[j], depth[j + 1]])
}

/// What [`Polys::new`] holds a triangle of a world scene, the meshes aside: the screen
/// triangles and their polygons (713–743 bytes measured with `sbuffer`'s index on the
/// teapot and the pot; `tests/projection_memory.rs`), checked against the memory budget
/// before projecting.
pub const BYTES_PER_TRIANGLE: u64 = 800;

/// The polygons of a scene, and what making them did.
pub struct Polys {
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
    /// The polygons, in the scene's order.
    pub polys: Vec<Poly>,
    /// World scenes: the projected triangles (`Poly::source` indexes them).
    pub triangles: Option<Vec<ScreenTriangle>>,
    /// With Phong shading, or textures: the lighting.
    pub shader: Option<PhongShader>,
    /// A mesh is textured (so every sample is lit one by one).
    textured: bool,
    /// World scenes: the camera's eye, in the world.
    pub eye: Option<[f64; 3]>,
    /// What projection did (world scenes).
    pub project: Option<ProjectStats>,
    /// Polygons with no area on the screen, dropped (`c = 0` or no plane).
    pub degenerate: u64,
    /// With shadows: what the lights that cast them reach of each projected triangle.
    pub shadows: Option<ShadowTest>,
    /// Wall time of the shadow pass (the lights' views).
    pub shadow_time: Duration,
    /// Wall time of reading the scene.
    pub load_time: Duration,
    /// Wall time of projection and lighting, or of preparing the polygons.
    pub transform_time: Duration,
}

impl Polys {
    /// The polygons of `loaded`, lit for `settings.shading`, with what the lights that
    /// cast shadows reach of each (`settings.shadows`; their views on `settings.threads`).
    /// A world scene is first checked against the memory budget: `renderer` holds
    /// `bytes_per_triangle` a triangle ([`BYTES_PER_TRIANGLE`] for these polygons alone).
    pub fn new(
        loaded: LoadedScene,
        settings: &Settings,
        renderer: &str,
        bytes_per_triangle: u64,
    ) -> Result<Polys, RenderError> {
        let shading = settings.shading;
        let (mut shadows, mut shadow_time) = (None, Duration::ZERO);
        let start = Instant::now();
        let kind = loaded.scene.kind();
        let (mut project, mut shader, mut triangles, mut eye) = (None, None, None, None);
        let mut polys = Vec::new();
        let mut degenerate = 0;
        let (width, height, channels) = match loaded.scene {
            AnyScene::Screen(s) => {
                match shading {
                    Shading::Phong => return Err(crate::prepare::phong_needs_world()),
                    Shading::Hidden => return Err(hidden()),
                    _ => {}
                }
                crate::prepare::check_intensities(&s, &loaded.source)?;
                let ch = s.channel_count();
                for (k, p) in s.polygons.iter().enumerate() {
                    let cp = CpPolygon::new(&p.vertices);
                    let plane = match &p.depth {
                        Some(d) => polygon_plane(p, d),
                        None => Some([0.0, 0.0, -(k as f64)]),
                    };
                    let (Some(plane), Some(_)) = (plane, cp.start_y()) else {
                        degenerate += 1;
                        continue;
                    };
                    let intensity: Vec<Vector> = p
                        .intensity
                        .iter()
                        .map(|v| cwisim_scene::vector(ch, |c| v[c]))
                        .collect();
                    polys.push(Poly {
                        cp,
                        flat: cwisim_ypipe::flat_mean(&intensity, ch),
                        intensity,
                        plane,
                        source: k as u32,
                        transmittance: 0.0,
                    });
                }
                (s.width, s.height, s.channels)
            }
            AnyScene::World(w) => {
                if shading == Shading::Hidden {
                    return Err(hidden());
                }
                crate::prepare::check_projection_memory(&w, bytes_per_triangle, renderer)?;
                let (tris, stats) = cwisim_world::project::project(&w, shading)?;
                let ch = w.channels();
                for (k, t) in tris.iter().enumerate() {
                    let cp = CpPolygon::new(&t.points);
                    let plane = plane3(t.points, t.inv_depth.map(|d| -d));
                    let (Some(plane), Some(_)) = (plane, cp.start_y()) else {
                        degenerate += 1;
                        continue;
                    };
                    let intensity = t.intensity.to_vec();
                    polys.push(Poly {
                        cp,
                        flat: cwisim_ypipe::flat_mean(&intensity, ch),
                        intensity,
                        plane,
                        source: k as u32,
                        transmittance: w.spec.meshes[t.mesh as usize].material.transmittance,
                    });
                }
                project = Some(stats);
                // a textured mesh is lit per sample whatever the shading, as Phong is
                if shading == Shading::Phong || w.textures.any() {
                    shader = Some(PhongShader::for_shading(&w, shading));
                }
                if let Some((test, time)) = crate::prepare::sampled_shadows(&w, &tris, settings)? {
                    shadows = Some(test);
                    shadow_time = time;
                }
                triangles = Some(tris);
                eye = Some(w.spec.camera.eye);
                (w.width(), w.height(), w.channels() as u8)
            }
        };
        let header = TraceHeader::new(width, height, channels)
            .map_err(|e| RenderError::Usage(format!("the scene does not fit the array: {e}")))?;
        Ok(Polys {
            source: loaded.source,
            kind,
            width,
            height,
            channels,
            header,
            polys,
            triangles,
            textured: shader.as_ref().is_some_and(PhongShader::textured),
            shader,
            eye,
            project,
            degenerate,
            shadows,
            shadow_time,
            load_time: loaded.load_time,
            transform_time: start.elapsed() - shadow_time,
        })
    }

    /// With textures: their release after the last row their triangles reach.
    pub fn texture_release(&self) -> Option<RowRelease> {
        let (shader, tris) = (self.shader.as_ref()?, self.triangles.as_ref()?);
        self.textured
            .then(|| RowRelease::of_triangles(shader.texture_store(), tris))
    }

    /// The array it draws into.
    pub fn header(&self) -> TraceHeader {
        self.header
    }

    /// Channels, as a count.
    pub fn channel_count(&self) -> usize {
        usize::from(self.channels)
    }

    /// Whether a mesh is textured.
    pub fn textured(&self) -> bool {
        self.textured
    }

    /// Whether some polygon lets light through (a material's transmittance above 0).
    pub fn transparent(&self) -> bool {
        self.polys.iter().any(|p| p.transmittance > 0.0)
    }

    /// With Phong shading (or textures): the lit colour of polygon `p` at `(x, y)` (negative terms
    /// dropped), at the point of its triangle nearest `(x, y)`; the error of a texture
    /// that fails to decode here, when first needed.
    pub fn phong(&self, p: &Poly, x: f64, y: f64) -> Result<Option<Vector>, SceneError> {
        let (Some(shader), Some(tris)) = (self.shader.as_ref(), self.triangles.as_ref()) else {
            return Ok(None);
        };
        let k = p.source as usize;
        let t = &tris[k];
        let at = crate::phong::nearest_in(t, [x, y]);
        let mut v = match &self.shadows {
            Some(test) => {
                let lit = test.lit_at(k, [x, y]);
                shader.at_lit(t, at, |l| test.casters().reaches(lit, l))
            }
            None => shader.at(t, at),
        }?
        .unwrap_or_default();
        for c in v.iter_mut() {
            *c = c.max(0.0);
        }
        Ok(Some(v))
    }

    /// The lights that reach polygon `p` along line `y` (of a world scene with shadows),
    /// ready to be asked at each sample of a span.
    pub fn line_lights(&self, p: &Poly, y: f64) -> Option<LineLights> {
        self.shadows
            .as_ref()
            .map(|test| test.line(p.source as usize, y))
    }

    /// The lights that reach all of polygon `p`, when that is the same everywhere on it
    /// (every light without shadows); `None` when it must be asked sample by sample
    /// ([`Self::line_lights`]).
    pub fn uniform_lit(&self, p: &Poly) -> Option<LightSet> {
        match &self.shadows {
            Some(test) => test.uniform(p.source as usize),
            None => Some(LightSet::ALL),
        }
    }

    /// Polygon `p` shaded by the lights of `lit` only: its vertices' intensities from its
    /// triangle's corners relit ([`ShadowTest::corners`]), its flat value their mean.
    pub fn relit(&self, p: &Poly, lit: LightSet) -> Poly {
        let (Some(test), Some(tris)) = (&self.shadows, &self.triangles) else {
            return p.clone();
        };
        let ch = self.channel_count();
        let k = p.source as usize;
        let t = &tris[k];
        let shaded = ScreenTriangle {
            intensity: test.corners(k, t, lit),
            ..*t
        };
        let intensity: Vec<Vector> = (0..p.cp.len())
            .map(|i| shaded.intensity_at(p.cp.vertex(i), ch).unwrap_or_default())
            .collect();
        Poly {
            flat: cwisim_ypipe::flat_mean(&intensity, ch),
            intensity,
            ..p.clone()
        }
    }

    /// The summary's geometry row, and with shadows their row.
    pub fn summary_rows(&self) -> Vec<(&'static str, String)> {
        let mut rows = self.geometry_rows();
        if let Some(test) = &self.shadows {
            rows.push(crate::prepare::sampled_shadows_row(
                test,
                "each sample a polygon sets is tested against its triangle's lit parts, and a run split where the lights change",
            ));
        }
        rows
    }

    fn geometry_rows(&self) -> Vec<(&'static str, String)> {
        let polygons = self.polys.len() as u64 + self.degenerate;
        match &self.project {
            Some(g) => vec![(
                "geometry",
                format!(
                    "{}; no hidden-surface removal before scan conversion",
                    crate::prepare::geometry_phrase(g)
                ),
            )],
            None => vec![(
                "geometry",
                format!(
                    "{polygons} polygon(s), {} with no area dropped; {} vertices",
                    self.degenerate,
                    self.polys.iter().map(|p| p.cp.len()).sum::<usize>()
                ),
            )],
        }
    }

    /// The scene part of `--stats-json`.
    pub fn scene_json(&self) -> serde_json::Value {
        serde_json::json!({
            "name": self.source.name(),
            "kind": self.kind,
            "polygons": self.polys.len(),
            "degenerate": self.degenerate,
            "project": self.project,
            "shadows": self.shadows.as_ref().map(crate::prepare::sampled_shadows_json),
        })
    }
}

fn hidden() -> RenderError {
    RenderError::Usage(
        "--shading hidden (edges of the visible triangles) is drawn by woo-chall only: use --shading flat, gouraud or phong".into(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_pass_through_their_points() {
        let p = [[0.0, 0.0], [4.0, 1.0], [1.0, 3.0]];
        let k = [1.0, 2.0, -0.5];
        let [a, b, c] = plane3(p, k).unwrap();
        for (q, v) in p.iter().zip(k) {
            assert!((a * q[0] + b * q[1] + c - v).abs() < 1e-12);
        }
        assert!(plane3([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], k).is_none());
    }
}
