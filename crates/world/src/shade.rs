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
        let b = t.barycentric(p)?;
        let w = [0, 1, 2].map(|k| b[k] * t.inv_depth[k]);
        let sum = w[0] + w[1] + w[2];
        if sum == 0.0 || !sum.is_finite() {
            return None;
        }
        let s = &t.surface;
        let point = (w[0] * s.world[0] + w[1] * s.world[1] + w[2] * s.world[2]) / sum;
        let normal =
            (w[0] * s.normals[0] + w[1] * s.normals[1] + w[2] * s.normals[2]).try_normalize()?;
        Some((point, normal))
    }

    /// The intensity of `t` at screen point `p` (see [`Self::surface_at`]).
    pub fn at(&self, t: &ScreenTriangle, p: [f64; 2]) -> Option<Vector> {
        let (point, normal) = self.surface_at(t, p)?;
        Some(
            self.lighting
                .intensity(&self.materials[t.mesh as usize], point, normal, self.eye),
        )
    }
}
