//! Per-pixel (Phong) shading: the report's lighting formula evaluated at any screen point
//! of a projected triangle, with the point and the normal interpolated
//! perspective-correctly over it.
//!
//! Screen-space barycentric coordinates `b` are not the triangle's own: under perspective
//! the weights of the world corners are `w_k = b_k · (1/z_k) / Σ_j b_j · (1/z_j)` (`1/z`
//! is affine in screen space). The point is `Σ w_k P_k`, the normal `Σ w_k N_k`
//! normalized — Phong's interpolation, in the world, not on the screen.
//!
//! A textured mesh ([`crate::texture`]) is shaded here for every shading, since its
//! intensity changes within a triangle however it is lit. The texture multiplies `k_a` and
//! `k_d`: the intensity is `T · (ambient + diffuse) + specular`, `T` the texture's value
//! per channel. The lighting is Phong's at the point (`--shading phong`), the corners'
//! two parts interpolated affinely on the screen as the array interpolates Gouraud's
//! (`gouraud`), or the face's at its centroid (`flat`). `T` is read at the texture
//! coordinates interpolated perspective-correctly: at the point ([`TextureFilter::Point`]),
//! or averaged over a pixel's footprint ([`TextureFilter::Box`]): the pixel square's four
//! corners mapped onto the triangle's plane, and the texture's mean over the bounding box
//! of their `(u, v)` (a summed-area table; the footprint itself is a quadrilateral).

use crate::face::ScreenTriangle;
use crate::lighting::Lighting;
use crate::scene::{Material, WorldScene};
use crate::texture::{TextureFilter, TextureStore};
use cwisim_scene::{SceneError, Shading, Vector};
use glam::DVec3;
use std::sync::Arc;

/// What a pixel reads of a texture.
#[derive(Clone, Copy)]
enum Lookup {
    /// Nothing (no texture coordinates there): the factor is 1.
    Nothing,
    /// The texel under a point `(u, v)`.
    Point([f64; 2]),
    /// The mean over the rectangle between two corners in `(u, v)`.
    Mean([f64; 2], [f64; 2]),
}

/// The lighting of a world scene, ready to shade its triangles at any screen point.
#[derive(Clone, Debug)]
pub struct PhongShader {
    lighting: Lighting,
    eye: DVec3,
    /// Per mesh.
    materials: Vec<Material>,
    /// The scene's textures, decoded when first read.
    textures: Arc<TextureStore>,
    /// How a textured mesh is lit (every other mesh: Phong's).
    shading: Shading,
    /// Per mesh and face of a textured mesh, the face's centroid (where flat shading
    /// lights it); empty for the others.
    centroids: Vec<Vec<DVec3>>,
}

impl PhongShader {
    /// The shader of `scene`'s lights, camera, materials and textures, for Phong shading.
    pub fn new(scene: &WorldScene) -> PhongShader {
        PhongShader::for_shading(scene, Shading::Phong)
    }

    /// The shader of `scene` lit as `shading` says: Phong's at every point, or, for a
    /// textured scene, Gouraud's or flat's lighting with the texture per point.
    pub fn for_shading(scene: &WorldScene, shading: Shading) -> PhongShader {
        let spec = &scene.spec;
        let centroids = scene
            .meshes
            .iter()
            .enumerate()
            .map(|(k, m)| match scene.textures.is_textured(k as u32) {
                true => (0..m.faces.len())
                    .map(|f| crate::project::face_centroid(m, f))
                    .collect(),
                false => Vec::new(),
            })
            .collect();
        PhongShader {
            lighting: Lighting {
                ambient: spec.ambient.clone(),
                lights: spec.lights.clone(),
                channels: scene.channels(),
            },
            eye: DVec3::from_array(spec.camera.eye),
            materials: spec.meshes.iter().map(|m| m.material.clone()).collect(),
            textures: scene.textures.clone(),
            shading,
            centroids,
        }
    }

    /// The same shader lighting textured meshes as `shading` says.
    pub fn with_shading(self, shading: Shading) -> PhongShader {
        PhongShader { shading, ..self }
    }

    /// The scene's textures (sizes and labels known, texels decoded when first read).
    pub fn textures(&self) -> &TextureStore {
        &self.textures
    }

    /// The scene's texture store, shared.
    pub fn texture_store(&self) -> Arc<TextureStore> {
        Arc::clone(&self.textures)
    }

    /// Whether mesh `mesh` is textured (nothing decoded).
    pub fn is_textured(&self, mesh: u32) -> bool {
        self.textures.is_textured(mesh)
    }

    /// Whether any mesh is textured.
    pub fn textured(&self) -> bool {
        self.textures.any()
    }

    /// The texture coordinates of `t` at screen point `p`, perspective-correct; `None`
    /// where the triangle's plane is degenerate or at or behind the eye there.
    pub fn uv_at(&self, t: &ScreenTriangle, p: [f64; 2]) -> Option<[f64; 2]> {
        let (w, sum) = t.perspective_weights(p)?;
        if sum <= 0.0 {
            return None;
        }
        let uv = &t.surface.uv;
        Some([0, 1].map(|a| (w[0] * uv[0][a] + w[1] * uv[1][a] + w[2] * uv[2][a]) / sum))
    }

    /// The texture's factor for `t` at screen point `p` of the pixel whose centre is
    /// `centre`, per channel (all 1 for an untextured mesh), read as `filter` says: the
    /// texel under `centre` on the triangle's plane, or the texture averaged over the
    /// pixel's footprint on that plane (either at `p` where the plane is at or behind the
    /// eye there). The texture is decoded if it is not resident: its error, if that fails.
    pub fn texture_factor(
        &self,
        t: &ScreenTriangle,
        p: [f64; 2],
        centre: [f64; 2],
        filter: TextureFilter,
    ) -> Result<[f64; 4], SceneError> {
        if !self.textures.is_textured(t.mesh) {
            return Ok([1.0; 4]);
        }
        let lookup = self.lookup(t, p, centre, filter);
        let factor = self.textures.with(t.mesh, |texture| match lookup {
            Lookup::Nothing => [1.0; 4],
            Lookup::Point(uv) => texture.point(uv),
            Lookup::Mean(lo, hi) => texture.mean(lo, hi),
        })?;
        Ok(factor.unwrap_or([1.0; 4]))
    }

    /// What [`Self::texture_factor`] reads of the texture.
    fn lookup(
        &self,
        t: &ScreenTriangle,
        p: [f64; 2],
        centre: [f64; 2],
        filter: TextureFilter,
    ) -> Lookup {
        let at_p = || self.uv_at(t, p).map_or(Lookup::Nothing, Lookup::Point);
        match filter {
            // the texel under the pixel centre, on the triangle's plane extended to it
            // (the centre may lie outside the triangle, in a neighbour's part of the
            // pixel): every part of a pixel of one planar, uniformly mapped surface reads
            // the same texel, so no seam shows along the triangles' shared edges
            TextureFilter::Point => self.uv_at(t, centre).map_or_else(at_p, Lookup::Point),
            TextureFilter::Box => {
                let mut lo = [f64::INFINITY; 2];
                let mut hi = [f64::NEG_INFINITY; 2];
                for (dx, dy) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
                    let Some(uv) = self.uv_at(t, [centre[0] + dx, centre[1] + dy]) else {
                        return at_p();
                    };
                    for a in 0..2 {
                        lo[a] = lo[a].min(uv[a]);
                        hi[a] = hi[a].max(uv[a]);
                    }
                }
                if !(lo.iter().chain(&hi).all(|x| x.is_finite())) {
                    return at_p();
                }
                Lookup::Mean(lo, hi)
            }
        }
    }

    /// The world point and the unit normal of `t` at screen point `p`; `None` for a
    /// degenerate triangle or where the interpolated normal vanishes.
    pub fn surface_at(&self, t: &ScreenTriangle, p: [f64; 2]) -> Option<(DVec3, DVec3)> {
        let (w, sum) = t.perspective_weights(p)?;
        let s = &t.surface;
        let point = (w[0] * s.world[0] + w[1] * s.world[1] + w[2] * s.world[2]) / sum;
        let normal =
            (w[0] * s.normals[0] + w[1] * s.normals[1] + w[2] * s.normals[2]).try_normalize()?;
        Some((point, normal))
    }

    /// Bergman et al.'s highlight measure of `t` (their Phong test, docs/ERRATA.md
    /// "RB5"): the smallest angle, in degrees, between a corner's highlight vector `R`
    /// (the vector to a light mirrored in the corner's unit normal, `2 (N·L) N − L`) and
    /// the direction of maximum highlight, the unit vector `V` to the eye — over the three
    /// corners and every light that lights the corner (`N·L > 0`, the lighting formula's
    /// own rule). `None` when no light lights a corner, or the material has no specular
    /// term in any channel: such a triangle has no highlight to refine.
    pub fn highlight_angle(&self, t: &ScreenTriangle) -> Option<f64> {
        let m = self.materials.get(t.mesh as usize)?;
        if (0..self.lighting.channels).all(|c| m.k_s.get(c) == 0.0) {
            return None;
        }
        let mut best: Option<f64> = None;
        for k in 0..3 {
            let point = t.surface.world[k];
            let Some(n) = t.surface.normals[k].try_normalize() else {
                continue;
            };
            let Some(v) = (self.eye - point).try_normalize() else {
                continue;
            };
            for light in &self.lighting.lights {
                let Some(l) = (DVec3::from_array(light.position) - point).try_normalize() else {
                    continue;
                };
                let n_dot_l = n.dot(l);
                if n_dot_l <= 0.0 {
                    continue;
                }
                let r = 2.0 * n_dot_l * n - l;
                let angle = r.dot(v).clamp(-1.0, 1.0).acos().to_degrees();
                best = Some(best.map_or(angle, |b| b.min(angle)));
            }
        }
        best
    }

    /// The intensity of `t` at screen point `p` (see [`Self::surface_at`]); the error of
    /// its texture, if it is decoded here and that fails.
    pub fn at(&self, t: &ScreenTriangle, p: [f64; 2]) -> Result<Option<Vector>, SceneError> {
        self.at_lit(t, p, |_| true)
    }

    /// [`Self::at`] by the lights `reaches` says reach the point (light `k` of the scene;
    /// [`crate::shadow`]): a shadowed point loses that light's terms. A textured mesh
    /// reads its texture at `p` ([`TextureFilter::Point`]).
    pub fn at_lit(
        &self,
        t: &ScreenTriangle,
        p: [f64; 2],
        reaches: impl Fn(usize) -> bool,
    ) -> Result<Option<Vector>, SceneError> {
        self.at_pixel_lit(t, p, p, TextureFilter::Point, reaches)
    }

    /// The intensity of `t` at screen point `p` of the pixel whose centre is `centre`, by
    /// the lights `reaches` says reach it, its texture read as `filter` says
    /// ([`Self::texture_factor`]). An untextured mesh is Phong's [`Self::at_lit`] at `p`.
    pub fn at_pixel_lit(
        &self,
        t: &ScreenTriangle,
        p: [f64; 2],
        centre: [f64; 2],
        filter: TextureFilter,
        reaches: impl Fn(usize) -> bool,
    ) -> Result<Option<Vector>, SceneError> {
        let material = &self.materials[t.mesh as usize];
        if !self.textures.is_textured(t.mesh) {
            return Ok(self.surface_at(t, p).map(|(point, normal)| {
                self.lighting
                    .intensity_lit(material, point, normal, self.eye, reaches)
            }));
        }
        let factor = self.texture_factor(t, p, centre, filter)?;
        Ok(self.textured_at(t, p, factor, reaches))
    }

    /// A textured mesh's intensity at `p` with the texture's `factor` there.
    fn textured_at(
        &self,
        t: &ScreenTriangle,
        p: [f64; 2],
        factor: [f64; 4],
        reaches: impl Fn(usize) -> bool,
    ) -> Option<Vector> {
        let material = &self.materials[t.mesh as usize];
        let (diffuse, specular) = match self.shading {
            Shading::Flat => {
                let centroid = self.centroids[t.mesh as usize][t.face as usize];
                self.lighting.intensity_split(
                    material,
                    centroid,
                    t.surface.normals[0],
                    self.eye,
                    reaches,
                )
            }
            Shading::Gouraud => {
                let b = t.barycentric(p)?;
                let corners: [(Vector, Vector); 3] = std::array::from_fn(|k| {
                    self.lighting.intensity_split(
                        material,
                        t.surface.world[k],
                        t.surface.normals[k],
                        self.eye,
                        &reaches,
                    )
                });
                let mix = |f: fn(&(Vector, Vector)) -> &Vector| {
                    let [a, b1, c] = [f(&corners[0]), f(&corners[1]), f(&corners[2])];
                    cwisim_scene::vector(self.lighting.channels, |k| {
                        a[k] + b[1] * (b1[k] - a[k]) + b[2] * (c[k] - a[k])
                    })
                };
                (mix(|c| &c.0), mix(|c| &c.1))
            }
            _ => {
                let (point, normal) = self.surface_at(t, p)?;
                self.lighting
                    .intensity_split(material, point, normal, self.eye, reaches)
            }
        };
        Some(cwisim_scene::vector(self.lighting.channels, |c| {
            factor[c] * diffuse[c] + specular[c]
        }))
    }
}
