//! Screen triangles: what projection and lighting hand to visibility.

use cwisim_scene::Vector;

/// A triangle in screen space after projection and lighting.
///
/// Screen coordinates are pixels, x to the right, y downward (the Y-processor's
/// convention). `inv_depth` is `1 / depth` at each vertex, depth being the distance in
/// front of the camera along its view direction: for a planar triangle under perspective
/// projection, `1 / depth` is an **affine** function of the screen position, so comparing
/// two triangles' `1 / depth` at a screen point is an exact depth test, and the set of
/// points where one is nearer than the other is a half-plane.
///
/// `intensity` is the per-vertex intensity vector (its first `channels` entries used).
/// Across the triangle the intensity is the affine interpolation of the three vertex
/// values in screen space (Gouraud as the X-processors do it): [`ScreenTriangle::intensity_at`].
///
/// `S` is what it keeps of its corners in the world: a [`Surface`] (the default) where
/// per-pixel shading, textures or shadows will read it, `()` where only visibility and
/// the corners' intensities will (192 bytes a triangle fewer: [`crate::project::project_plain`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenTriangle<S = Surface> {
    /// The vertices `[x, y]` in pixels.
    pub points: [[f64; 2]; 3],
    /// `1 / depth` at each vertex (> 0: in front of the camera).
    pub inv_depth: [f64; 3],
    /// The intensity vector at each vertex.
    pub intensity: [Vector; 3],
    /// Which mesh of the scene it comes from.
    pub mesh: u32,
    /// Which face of that mesh.
    pub face: u32,
    /// Where its corners are in the world, and their shading normals: what per-pixel
    /// (Phong) shading interpolates (`()` where nothing will).
    pub surface: S,
}

/// A screen triangle's corners in the world: positions, and unit shading normals turned
/// toward the viewer (the face's normal for flat shading; a back face of a two-sided mesh
/// has them reversed, as its lighting has).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Surface {
    /// World positions of the three corners.
    pub world: [glam::DVec3; 3],
    /// Unit shading normals at the three corners.
    pub normals: [glam::DVec3; 3],
    /// Texture coordinates `(u, v)` at the three corners (zero for a mesh without them).
    pub uv: [[f64; 2]; 3],
}

impl<S> ScreenTriangle<S> {
    /// The same triangle keeping of its surface what `keep` makes of it.
    pub fn map_surface<T>(self, keep: impl FnOnce(S) -> T) -> ScreenTriangle<T> {
        ScreenTriangle {
            points: self.points,
            inv_depth: self.inv_depth,
            intensity: self.intensity,
            mesh: self.mesh,
            face: self.face,
            surface: keep(self.surface),
        }
    }

    /// Twice the signed area (positive: counter-clockwise with y downward, i.e. clockwise
    /// as seen on the screen).
    pub fn doubled_area(&self) -> f64 {
        let [a, b, c] = self.points;
        (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
    }

    /// The barycentric coordinates of screen point `p` (they sum to 1; all ≥ 0 inside).
    /// `None` for a degenerate (zero-area) triangle.
    pub fn barycentric(&self, p: [f64; 2]) -> Option<[f64; 3]> {
        let d = self.doubled_area();
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        let [a, b, c] = self.points;
        let w_b = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / d;
        let w_c = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / d;
        Some([1.0 - w_b - w_c, w_b, w_c])
    }

    /// The perspective-correct weights of the world corners at screen point `p`, not yet
    /// divided by their sum (returned beside them): `b_k · (1/z_k)`, `b` the screen
    /// barycentrics. The world point there is `Σ w_k P_k / sum`. `None` for a degenerate
    /// triangle or a sum that is zero or not finite.
    pub fn perspective_weights(&self, p: [f64; 2]) -> Option<([f64; 3], f64)> {
        let b = self.barycentric(p)?;
        let w = [0, 1, 2].map(|k| b[k] * self.inv_depth[k]);
        let sum = w[0] + w[1] + w[2];
        (sum != 0.0 && sum.is_finite()).then_some((w, sum))
    }

    /// `1 / depth` at screen point `p` (affine; extrapolated outside the triangle).
    pub fn inv_depth_at(&self, p: [f64; 2]) -> Option<f64> {
        let w = self.barycentric(p)?;
        Some(w[0] * self.inv_depth[0] + w[1] * self.inv_depth[1] + w[2] * self.inv_depth[2])
    }

    /// The intensity at screen point `p` (affine; extrapolated outside the triangle).
    /// Evaluated as `I₀ + w₁(I₁ − I₀) + w₂(I₂ − I₀)`, so a flat triangle's intensity is
    /// its vertices' exactly, wherever it is taken.
    pub fn intensity_at(&self, p: [f64; 2], channels: usize) -> Option<Vector> {
        let w = self.barycentric(p)?;
        let [a, b, c] = &self.intensity;
        Some(cwisim_scene::vector(channels, |k| {
            a[k] + w[1] * (b[k] - a[k]) + w[2] * (c[k] - a[k])
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> ScreenTriangle {
        let mut i = [[0.0; 4]; 3];
        i[0][0] = 1.0;
        i[1][0] = 3.0;
        i[2][0] = 5.0;
        ScreenTriangle {
            points: [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]],
            inv_depth: [1.0, 0.5, 0.25],
            intensity: i,
            mesh: 0,
            face: 0,
            surface: Surface::default(),
        }
    }

    #[test]
    fn affine_functions_reproduce_vertices_and_interpolate() {
        let t = tri();
        for k in 0..3 {
            assert_eq!(t.inv_depth_at(t.points[k]), Some(t.inv_depth[k]));
            assert_eq!(
                t.intensity_at(t.points[k], 1).unwrap()[0],
                t.intensity[k][0]
            );
        }
        // midpoint of the hypotenuse
        assert_eq!(t.inv_depth_at([2.0, 2.0]), Some(0.375));
        assert_eq!(t.intensity_at([2.0, 2.0], 1).unwrap()[0], 4.0);
        assert!(t.doubled_area() > 0.0);
    }
}
