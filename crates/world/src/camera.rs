//! The pinhole camera: world space to screen pixels.
//!
//! The camera looks from `eye` at `target`; `up` fixes the roll. A point's **depth** is
//! its distance in front of the camera along the view direction; it lands at
//!
//! ```text
//! x_screen = W/2 + F · x_view / depth,   y_screen = H/2 − F · y_view / depth,
//! F = (H/2) / tan(fov_y / 2)
//! ```
//!
//! (square pixels, y downward as the Y-processor wants it). There is no near-plane
//! clipping: every vertex must be at least `near` in front of the camera, and a scene
//! where one is not (the camera inside or behind an object) is refused with the mesh and
//! vertex named.

use crate::scene::CameraSpec;
use glam::DVec3;

/// A camera set up for an image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where it is.
    pub eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    focal: f64,
    centre: [f64; 2],
    /// The near distance.
    pub near: f64,
}

impl Camera {
    /// The camera of `spec` for a `width × height` image. The spec must be valid
    /// ([`crate::scene::WorldSpec::validate`]).
    pub fn new(spec: &CameraSpec, width: u32, height: u32) -> Camera {
        let eye = DVec3::from_array(spec.eye);
        let forward = (DVec3::from_array(spec.target) - eye).normalize();
        let right = forward.cross(DVec3::from_array(spec.up)).normalize();
        let up = right.cross(forward);
        let focal = 0.5 * f64::from(height) / (0.5 * spec.fov_y.to_radians()).tan();
        Camera {
            eye,
            forward,
            right,
            up,
            focal,
            centre: [0.5 * f64::from(width), 0.5 * f64::from(height)],
            near: spec.near,
        }
    }

    /// The focal length in pixels: a pixel at depth `d` is `d / focal` world units wide.
    pub fn focal(&self) -> f64 {
        self.focal
    }

    /// The depth of `p`: its distance in front of the camera along the view direction.
    pub fn depth(&self, p: DVec3) -> f64 {
        (p - self.eye).dot(self.forward)
    }

    /// `(depth, depth · y)` of `p`, `y` the screen row it projects to. Both are affine in
    /// `p`, so for a Bézier curve or patch they are Bernstein coefficients: the scan
    /// plane through the eye and the pixel row `y_s` is `depth · y_s − depth · y = 0`,
    /// and `depth_i · y_s − (depth · y)_i` are Nishita et al.'s `Y'_i` (their eq. 3, up to
    /// the positive factor `1/R` and the direction of `y`): positive above the row.
    pub fn depth_and_scaled_row(&self, p: DVec3) -> (f64, f64) {
        let d = p - self.eye;
        let depth = d.dot(self.forward);
        (depth, self.centre[1] * depth - self.focal * d.dot(self.up))
    }

    /// Where `p` lands on the screen (pixels), for a point in front of the camera.
    pub fn project(&self, p: DVec3) -> [f64; 2] {
        let d = p - self.eye;
        let depth = d.dot(self.forward);
        [
            self.centre[0] + self.focal * d.dot(self.right) / depth,
            self.centre[1] - self.focal * d.dot(self.up) / depth,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_lands_in_the_centre_and_the_frustum_edge_on_the_border() {
        let spec = CameraSpec {
            eye: [0.0, 0.0, 5.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y: 90.0,
            near: 0.1,
        };
        let c = Camera::new(&spec, 200, 100);
        assert_eq!(c.project(DVec3::ZERO), [100.0, 50.0]);
        assert_eq!(c.depth(DVec3::ZERO), 5.0);
        // fov 90°: at depth 5 the top of the view is y = 5
        let top = c.project(DVec3::new(0.0, 5.0, 0.0));
        assert!(
            (top[1] - 0.0).abs() < 1e-12 && (top[0] - 100.0).abs() < 1e-12,
            "{top:?}"
        );
        // the scan-plane values: depth·y of a point is its row times its depth
        for p in [DVec3::new(1.0, 2.0, -3.0), DVec3::new(-0.5, 0.25, 1.0)] {
            let (d, dy) = c.depth_and_scaled_row(p);
            assert!((dy / d - c.project(p)[1]).abs() < 1e-12);
            assert_eq!(d, c.depth(p));
        }
        // x to the right, square pixels
        let right = c.project(DVec3::new(5.0, 0.0, 0.0));
        assert!((right[0] - 150.0).abs() < 1e-12, "{right:?}");
    }
}
