//! Transform and lighting: a world scene's meshes become lit screen triangles, with back
//! faces culled.
//!
//! For every face: each fan triangle is **front-facing** when its geometric normal points
//! to the eye (`n · (eye − p) > 0`); back-facing ones are dropped, unless the mesh is
//! `two_sided`, in which case they are kept and lit with their normals turned to the
//! viewer (the inside of an open pot). Intensities follow the report's formula
//! ([`crate::lighting`]):
//!
//! * Gouraud — at every corner, with the corner's shading normal;
//! * flat — once per face, at its centroid with its geometric normal (the report: "one
//!   intensity is calculated for each polygon"), the same value at all corners.

use crate::camera::Camera;
use crate::face::{ScreenTriangle, Surface};
use crate::lighting::Lighting;
use crate::mesh::Mesh;
use crate::scene::{Material, WorldScene};
use cwisim_scene::{SceneError, SceneErrorKind, MAX_COORDINATE};
use cwisim_scene::{Shading, Vector};
use glam::DVec3;

/// What projection did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct ProjectStats {
    /// Meshes.
    pub meshes: u64,
    /// Faces of all meshes.
    pub faces: u64,
    /// Triangles after fanning the faces.
    pub triangles: u64,
    /// Back-facing triangles dropped.
    pub culled: u64,
    /// Back-facing triangles kept (two-sided meshes).
    pub back_faces_drawn: u64,
    /// Triangles seen exactly edge-on (zero area on the screen), dropped.
    pub edge_on: u64,
}

/// Refuses a mesh with a vertex nearer than the camera's near distance, or behind it:
/// the camera is inside or behind the object (there is no near-plane clipping).
pub fn check_in_front(camera: &Camera, mesh: &Mesh, k: usize) -> Result<(), SceneError> {
    for (i, &p) in mesh.positions.iter().enumerate() {
        let depth = camera.depth(p);
        if depth < camera.near {
            return Err(SceneError::at_field(
                SceneErrorKind::Geometry,
                format!("meshes[{k}]"),
                format!(
                    "vertex {i} of mesh {:?} at {p} is {} the camera (depth {depth:.6}, near {}): the camera is inside or behind the object; move the camera (there is no near-plane clipping)",
                    mesh.name,
                    if depth < 0.0 { "behind" } else { "too close to" },
                    camera.near
                ),
            ));
        }
    }
    Ok(())
}

/// The lit screen triangles of a scene, in mesh and face order. The lighting terms are
/// checked first ([`WorldSpec::check_lighting`](crate::scene::WorldSpec::check_lighting):
/// a scene built in code is refused as a file would be), and every lit intensity where it
/// is made ([`check_lit`](crate::lighting::check_lit)).
pub fn project(
    scene: &WorldScene,
    shading: Shading,
) -> Result<(Vec<ScreenTriangle>, ProjectStats), SceneError> {
    project_keeping(scene, shading, |surface| surface)
}

/// [`project`]'s triangles without their [`Surface`]s (the same points, depths and
/// intensities, bit for bit): what visibility alone reads, for a frame that neither
/// shades per pixel nor casts shadows. 176 bytes a triangle where [`project`]'s take 368.
pub fn project_plain(
    scene: &WorldScene,
    shading: Shading,
) -> Result<(Vec<ScreenTriangle<()>>, ProjectStats), SceneError> {
    project_keeping(scene, shading, |_| ())
}

/// [`project`], keeping of each triangle's [`Surface`] what `keep` makes of it.
fn project_keeping<S>(
    scene: &WorldScene,
    shading: Shading,
    keep: impl Fn(Surface) -> S,
) -> Result<(Vec<ScreenTriangle<S>>, ProjectStats), SceneError> {
    let spec = &scene.spec;
    // a scene built in code was never validated: its lighting terms are checked here
    spec.check_lighting()?;
    let channels = scene.channels();
    let camera = Camera::new(&spec.camera, scene.width(), scene.height());
    let lighting = Lighting {
        ambient: spec.ambient.clone(),
        lights: spec.lights.clone(),
        channels,
    };
    let mut stats = ProjectStats {
        meshes: scene.meshes.len() as u64,
        ..ProjectStats::default()
    };
    // room for every triangle at once: growing by doubling would hold the old and the
    // new buffer together, half again the final size, at the largest step
    let mut out = Vec::with_capacity(scene.triangle_count());
    for (k, (mesh, mspec)) in scene.meshes.iter().zip(&spec.meshes).enumerate() {
        check_in_front(&camera, mesh, k)?;
        // every vertex on a representable screen position
        let mut screen = Vec::with_capacity(mesh.positions.len());
        for (i, &p) in mesh.positions.iter().enumerate() {
            let s = camera.project(p);
            if !(s[0].abs() <= MAX_COORDINATE && s[1].abs() <= MAX_COORDINATE) {
                return Err(SceneError::at_field(
                    SceneErrorKind::Limit,
                    format!("meshes[{k}]"),
                    format!(
                        "vertex {i} of mesh {:?} projects to {s:?}, beyond ±{MAX_COORDINATE:e} pixels: it is nearly in the camera's plane",
                        mesh.name
                    ),
                ));
            }
            screen.push(s);
        }
        let material = &mspec.material;
        for (f, face) in mesh.faces.iter().enumerate() {
            stats.faces += 1;
            let flat = (shading == Shading::Flat)
                .then(|| (face_centroid(mesh, f), mesh.face_normal(f).normalize()));
            for tri in face.triangles() {
                stats.triangles += 1;
                let idx = tri.map(|c| face.corners[c] as usize);
                let p = idx.map(|i| mesh.positions[i]);
                let normal = (p[1] - p[0]).cross(p[2] - p[0]);
                let facing = normal.dot(camera.eye - p[0]);
                let back = facing <= 0.0;
                if back && !mspec.two_sided {
                    stats.culled += 1;
                    continue;
                }
                let points = idx.map(|i| screen[i]);
                let doubled = (points[1][0] - points[0][0]) * (points[2][1] - points[0][1])
                    - (points[2][0] - points[0][0]) * (points[1][1] - points[0][1]);
                if doubled == 0.0 || facing == 0.0 {
                    stats.edge_on += 1;
                    continue;
                }
                if back {
                    stats.back_faces_drawn += 1;
                }
                let toward = if back { -1.0 } else { 1.0 };
                let normals = match flat {
                    Some((_, n)) => [toward * n; 3],
                    None => tri.map(|c| toward * face.normals[c]),
                };
                let uv = if face.uv.is_empty() {
                    [[0.0; 2]; 3]
                } else {
                    tri.map(|c| face.uv[c])
                };
                let surface = Surface {
                    world: p,
                    normals,
                    uv,
                };
                let centroid = flat.map(|(centroid, _)| centroid);
                let intensity =
                    lit_corners(&lighting, material, centroid, &surface, camera.eye, |_| {
                        true
                    });
                for i in &intensity {
                    crate::lighting::check_lit(i, channels, || {
                        (format!("meshes[{k}]"), format!("face {f}"))
                    })?;
                }
                out.push(ScreenTriangle {
                    points,
                    inv_depth: p.map(|q| 1.0 / camera.depth(q)),
                    intensity,
                    mesh: k as u32,
                    face: f as u32,
                    surface: keep(surface),
                });
            }
        }
    }
    // what culling and edge-on triangles left unused goes back
    out.shrink_to_fit();
    Ok((out, stats))
}

/// The centroid of face `f` of `mesh`: where flat shading lights it.
pub fn face_centroid(mesh: &Mesh, f: usize) -> DVec3 {
    let face = &mesh.faces[f];
    face.corners
        .iter()
        .map(|&c| mesh.positions[c as usize])
        .sum::<DVec3>()
        / face.corners.len() as f64
}

/// A triangle's corner intensities as [`project`] lights them, by the lights `reaches`
/// says reach it ([`Lighting::intensity_lit`]): at each corner with its shading normal
/// (Gouraud), or once at the face's `centroid` with its normal (flat: `Some`, the
/// normals being the face's). With every light reaching, [`project`]'s own, bit for bit.
pub fn lit_corners(
    lighting: &Lighting,
    material: &Material,
    centroid: Option<DVec3>,
    surface: &Surface,
    eye: DVec3,
    reaches: impl Fn(usize) -> bool,
) -> [Vector; 3] {
    match centroid {
        Some(centroid) => {
            let i = lighting.intensity_lit(material, centroid, surface.normals[0], eye, reaches);
            [i; 3]
        }
        None => std::array::from_fn(|c| {
            lighting.intensity_lit(
                material,
                surface.world[c],
                surface.normals[c],
                eye,
                &reaches,
            )
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `project_plain` is `project` without the surfaces: the same triangles, in the same
    /// order, bit for bit, on every embedded world scene in both shadings.
    #[test]
    fn plain_triangles_are_the_full_ones_without_their_surfaces() {
        let mut compared = 0;
        for e in crate::embedded::EMBEDDED {
            let Ok(crate::AnyScene::World(w)) = crate::parse_any(e.text, None) else {
                continue;
            };
            for shading in [Shading::Flat, Shading::Gouraud] {
                let (full, full_stats) = project(&w, shading).unwrap();
                let (plain, plain_stats) = project_plain(&w, shading).unwrap();
                assert_eq!(full_stats, plain_stats, "{}", e.name);
                let dropped: Vec<ScreenTriangle<()>> = full
                    .iter()
                    .map(|t| ScreenTriangle {
                        points: t.points,
                        inv_depth: t.inv_depth,
                        intensity: t.intensity,
                        mesh: t.mesh,
                        face: t.face,
                        surface: (),
                    })
                    .collect();
                // compared by their bits: a NaN would not equal itself
                let bits = |ts: &[ScreenTriangle<()>]| format!("{ts:?}");
                assert_eq!(bits(&plain), bits(&dropped), "{}", e.name);
                assert_eq!(
                    plain.len(),
                    plain.capacity(),
                    "{}: no room left unused",
                    e.name
                );
                compared += plain.len();
            }
        }
        assert!(compared > 10_000, "{compared} triangles compared");
    }
}
