//! A ray caster written for the tests alone: it shares no code with the projection, the
//! visibility, the shadows or the shader it checks (the camera's and Möller–Trumbore's
//! formulas written out again here).

use cwisim_world::WorldScene;
use glam::DVec3;

/// A hit: distance along the ray, the triangle's three corners (mesh, face, corner
/// index in the face), world barycentrics, and how close to an edge it is.
pub struct Hit {
    pub t: f64,
    pub mesh: usize,
    pub face: usize,
    pub corners: [usize; 3],
    pub bary: [f64; 3],
    pub margin: f64,
}

/// Every hit of the ray `o + t·d` with the scene's triangles (fans of faces).
pub fn hits(w: &WorldScene, o: DVec3, d: DVec3) -> Vec<Hit> {
    let mut out = Vec::new();
    for (m, mesh) in w.meshes.iter().enumerate() {
        for (f, face) in mesh.faces.iter().enumerate() {
            for k in 1..face.corners.len() - 1 {
                let c = [0, k, k + 1];
                let p = c.map(|i| mesh.positions[face.corners[i] as usize]);
                // Möller–Trumbore
                let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
                let q = d.cross(e2);
                let det = e1.dot(q);
                if det.abs() < 1e-14 {
                    continue;
                }
                let s = o - p[0];
                let u = s.dot(q) / det;
                let r = s.cross(e1);
                let v = d.dot(r) / det;
                let t = e2.dot(r) / det;
                let bary = [1.0 - u - v, u, v];
                if t > 0.0 && bary.iter().all(|&b| b >= -1e-12) {
                    let margin = bary.iter().cloned().fold(f64::INFINITY, f64::min);
                    out.push(Hit {
                        t,
                        mesh: m,
                        face: f,
                        corners: c,
                        bary,
                        margin,
                    });
                }
            }
        }
    }
    out.sort_by(|a, b| a.t.total_cmp(&b.t));
    out
}

/// The ray through screen point `(x, y)` of a `width × height` image: its origin (the eye)
/// and unit direction.
pub fn ray(w: &WorldScene, width: u32, height: u32, x: f64, y: f64) -> (DVec3, DVec3) {
    let c = &w.spec.camera;
    let eye = DVec3::from_array(c.eye);
    let forward = (DVec3::from_array(c.target) - eye).normalize();
    let right = forward.cross(DVec3::from_array(c.up)).normalize();
    let up = right.cross(forward);
    let focal = 0.5 * f64::from(height) / (0.5 * c.fov_y.to_radians()).tan();
    let (cx, cy) = (0.5 * f64::from(width), 0.5 * f64::from(height));
    let d = forward * focal + right * (x - cx) - up * (y - cy);
    (eye, d.normalize())
}
