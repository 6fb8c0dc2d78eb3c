//! Per-pixel (Phong) shading: the report's lighting formula evaluated at any screen point
//! of a projected triangle, with the point and the normal interpolated
//! perspective-correctly over it.
//!
//! Screen-space barycentric coordinates `b` are not the triangle's own: under perspective
//! the weights of the world corners are `w_k = b_k · (1/z_k) / Σ_j b_j · (1/z_j)` (`1/z`
//! is affine in screen space). The point is `Σ w_k P_k`, the normal `Σ w_k N_k`
//! normalized — Phong's interpolation, in the world, not on the screen.

use crate::face::ScreenTriangle;
use crate::lighting::Lighting;
use crate::scene::{Material, WorldScene};
use cwisim_scene::Vector;
use glam::DVec3;

/// The lighting of a world scene, ready to shade its triangles at any screen point.
#[derive(Clone, Debug)]
pub struct PhongShader {
    lighting: Lighting,
    eye: DVec3,
    /// Per mesh.
    materials: Vec<Material>,
}

impl PhongShader {
    /// The shader of `scene`'s lights, camera and materials.
    pub fn new(scene: &WorldScene) -> PhongShader {
        let spec = &scene.spec;
        PhongShader {
            lighting: Lighting {
                ambient: spec.ambient.clone(),
                lights: spec.lights.clone(),
                channels: scene.channels(),
            },
            eye: DVec3::from_array(spec.camera.eye),
            materials: spec.meshes.iter().map(|m| m.material.clone()).collect(),
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

    /// The intensity of `t` at screen point `p` (see [`Self::surface_at`]).
    pub fn at(&self, t: &ScreenTriangle, p: [f64; 2]) -> Option<Vector> {
        self.at_lit(t, p, |_| true)
    }

    /// [`Self::at`] by the lights `reaches` says reach the point (light `k` of the scene;
    /// [`crate::shadow`]): a shadowed point loses that light's terms.
    pub fn at_lit(
        &self,
        t: &ScreenTriangle,
        p: [f64; 2],
        reaches: impl Fn(usize) -> bool,
    ) -> Option<Vector> {
        let (point, normal) = self.surface_at(t, p)?;
        Some(self.lighting.intensity_lit(
            &self.materials[t.mesh as usize],
            point,
            normal,
            self.eye,
            reaches,
        ))
    }
}
