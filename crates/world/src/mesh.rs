//! Meshes: built from a scene's description (inline, OBJ, or a surface of revolution),
//! placed in the world, checked, and given a normal at every face corner.
//!
//! Faces are convex polygons, counter-clockwise seen from the front. Polygons with more
//! than three corners are drawn as a fan of triangles from their first corner
//! ([`Face::triangles`]); a face whose fan would fold over (non-convex as seen from its
//! first corner) is refused rather than drawn wrong. Planarity is not checked: a
//! non-planar face is drawn as its fan.
//!
//! Normals: given ones (inline `normals`, OBJ `vn`) are used as they are (transformed);
//! otherwise the normal at a corner is the area-weighted mean of the normals of the
//! faces around that vertex that differ from this face's by less than the mesh's
//! `crease_angle`, so smooth surfaces shade smoothly and creases stay sharp.

use crate::bezier::{patches_from, tessellate};
use crate::obj;
use crate::scene::{BezierSource, MeshSpec, Revolution, Scale, Transform};
use cwisim_scene::{SceneError, SceneErrorKind};
use glam::{DMat3, DMat4, DQuat, DVec3, EulerRot};
use smallvec::SmallVec;
use std::path::Path;

/// A face's corners: held in the face up to four (a triangle, a quad), on the heap past.
pub type Corners = SmallVec<[u32; 4]>;

/// One value per corner of a face, held in the face for a triangle: a dense mesh's faces
/// are then one block, not three small ones a face (which the allocator keeps once freed).
pub type PerCorner<T> = SmallVec<[T; 3]>;

/// One face: its corners (indices into [`Mesh::positions`]) and a unit normal per corner.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Vertex indices, counter-clockwise seen from the front.
    pub corners: Corners,
    /// The shading normal at each corner (unit length).
    pub normals: PerCorner<DVec3>,
    /// The texture coordinates `(u, v)` at each corner; empty when the mesh has none.
    pub uv: PerCorner<[f64; 2]>,
}

impl Face {
    /// The fan triangles `(0, k, k+1)` as corner positions within the face.
    pub fn triangles(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        (1..self.corners.len() - 1).map(|k| [0, k, k + 1])
    }
}

/// A mesh in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Its name (the scene's, or `mesh K`).
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Faces.
    pub faces: Vec<Face>,
}

impl Mesh {
    /// Whether its faces carry texture coordinates (all of them do, or none).
    pub fn has_uv(&self) -> bool {
        self.faces.first().is_some_and(|f| !f.uv.is_empty())
    }

    /// Triangles after fanning every face.
    pub fn triangle_count(&self) -> usize {
        self.faces.iter().map(|f| f.corners.len() - 2).sum()
    }

    /// The bytes the mesh holds: its positions, its faces, and what a face keeps outside
    /// itself (past four corners, or three normals or texture coordinates). What the
    /// memory budget counts for a built mesh.
    pub fn held_bytes(&self) -> u64 {
        use std::mem::size_of;
        fn outside<A: smallvec::Array>(v: &SmallVec<A>) -> usize {
            if v.spilled() {
                v.capacity() * size_of::<A::Item>()
            } else {
                0
            }
        }
        let spilled: usize = self
            .faces
            .iter()
            .map(|f| outside(&f.corners) + outside(&f.normals) + outside(&f.uv))
            .sum();
        (self.name.capacity()
            + self.positions.capacity() * size_of::<DVec3>()
            + self.faces.capacity() * size_of::<Face>()
            + spilled) as u64
    }

    /// The geometric (Newell) normal of face `f`, not normalized: its length is twice the
    /// face's area.
    pub fn face_normal(&self, f: usize) -> DVec3 {
        newell(&self.faces[f].corners, &self.positions)
    }
}

/// Why a mesh could not be built.
#[derive(Debug)]
pub enum BuildError {
    /// A fault at a JSON path of the scene (to be located in the scene's text).
    Scene(SceneError),
    /// A fault in another file (already located there).
    File(SceneError),
}

fn geometry(field: String, message: String) -> BuildError {
    BuildError::Scene(SceneError::at_field(
        SceneErrorKind::Geometry,
        field,
        message,
    ))
}

fn newell(corners: &[u32], p: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    let o = p[corners[0] as usize];
    for k in 1..corners.len() - 1 {
        let (a, b) = (p[corners[k] as usize] - o, p[corners[k + 1] as usize] - o);
        n += a.cross(b);
    }
    n
}

/// The raw geometry of a source, before placement: positions, faces (their normals the
/// source's, untransformed, or none; texture coordinates at every face's corners or at
/// none), and how to name a face in messages. The faces become the mesh's in place.
#[derive(Debug)]
pub(crate) struct Raw {
    pub positions: Vec<DVec3>,
    pub faces: Vec<Face>,
    /// Whether every face carries the source's normals (else none does).
    pub normals_given: bool,
    /// An OBJ file's: each face's `f` line (1-based), to locate a face's fault there.
    pub face_lines: Option<Vec<u64>>,
}

/// Builds mesh `k` of a scene.
pub fn build(spec: &MeshSpec, k: usize, base: Option<&Path>) -> Result<Mesh, BuildError> {
    let name = spec.name.clone().unwrap_or_else(|| format!("mesh {k}"));
    type FaceError = Box<dyn Fn(usize, String) -> BuildError>;
    let at_field = |field: Box<dyn Fn(usize) -> String>| -> FaceError {
        Box::new(move |f, message| geometry(field(f), message))
    };
    let (raw, face_error): (Raw, FaceError) = if let Some(b) = &spec.bezier {
        (
            bezier(b, k)?,
            at_field(Box::new(move |f| {
                format!("meshes[{k}].bezier (triangle {f})")
            })),
        )
    } else if let Some(r) = &spec.revolution {
        (
            revolution(r, k)?,
            at_field(Box::new(move |f| {
                format!("meshes[{k}].revolution (face {f})")
            })),
        )
    } else if let Some(file) = &spec.obj {
        let path = match base {
            Some(b) => b.join(file),
            None => Path::new(file).to_path_buf(),
        };
        let raw = obj::read(&path).map_err(BuildError::File)?;
        // a face's fault is the OBJ file's, at its `f` line; where the faces could not
        // be matched to their lines, the scene's, at the mesh's `obj`
        let lines = raw.face_lines.clone();
        let shown = file.clone();
        let located: FaceError =
            Box::new(
                move |f, message| match lines.as_ref().and_then(|l| l.get(f).copied()) {
                    Some(line) => BuildError::File(SceneError {
                        kind: SceneErrorKind::Geometry,
                        ..obj::error(&path, Some(line), format!("face {f}: {message}"))
                    }),
                    None => geometry(format!("meshes[{k}].obj (face {f} of {shown})"), message),
                },
            );
        (raw, located)
    } else {
        (
            inline(spec, k)?,
            at_field(Box::new(move |f| format!("meshes[{k}].faces[{f}]"))),
        )
    };
    if raw.faces.is_empty() {
        return Err(geometry(
            format!("meshes[{k}]"),
            format!("mesh {name:?} has no faces"),
        ));
    }
    let matrix = placement(&spec.transform);
    let normal_matrix = DMat3::from_mat4(matrix).inverse().transpose();
    let positions: Vec<DVec3> = raw
        .positions
        .iter()
        .map(|p| matrix.transform_point3(*p))
        .collect();
    for (i, p) in positions.iter().enumerate() {
        if !p.is_finite() || p.abs().max_element() > crate::scene::MAX_WORLD_COORDINATE {
            return Err(BuildError::Scene(SceneError::at_field(
                SceneErrorKind::Limit,
                format!("meshes[{k}]"),
                format!(
                    "vertex {i} of mesh {name:?} lands at {p} after its transform, beyond ±1e9"
                ),
            )));
        }
    }
    // checks: corners, degenerate and non-convex faces
    let mut areas = Vec::with_capacity(raw.faces.len());
    for (f, face) in raw.faces.iter().enumerate() {
        let corners = &face.corners;
        if corners.len() < 3 {
            return Err(face_error(
                f,
                format!("a face needs at least 3 corners, found {}", corners.len()),
            ));
        }
        let n = newell(corners, &positions);
        let scale = corners
            .iter()
            .map(|&c| (positions[c as usize] - positions[corners[0] as usize]).length_squared())
            .fold(0.0, f64::max);
        if n.length() <= 1e-12 * scale || scale == 0.0 {
            return Err(face_error(
                f,
                "degenerate face: its corners are collinear or coincide (zero area)".into(),
            ));
        }
        if corners.len() > 3 {
            let o = positions[corners[0] as usize];
            for c in 1..corners.len() - 1 {
                let t = (positions[corners[c] as usize] - o)
                    .cross(positions[corners[c + 1] as usize] - o);
                if t.dot(n) < -1e-12 * scale {
                    return Err(face_error(
                        f,
                        format!(
                            "non-convex face ({} corners): the fan of triangles from its first corner would fold over; split it into triangles or convex faces",
                            corners.len()
                        ),
                    ));
                }
            }
        }
        areas.push(n);
    }
    let mut faces = raw.faces;
    if raw.normals_given {
        for face in &mut faces {
            for n in &mut face.normals {
                *n = (normal_matrix * *n).normalize_or_zero();
            }
        }
    } else {
        smooth_normals(&mut faces, &areas, positions.len(), spec.crease_angle);
    }
    for (f, face) in faces.iter().enumerate() {
        if face
            .normals
            .iter()
            .any(|n| *n == DVec3::ZERO || !n.is_finite())
        {
            return Err(face_error(f, "a given normal is zero or not finite".into()));
        }
    }
    Ok(Mesh {
        name,
        positions,
        faces,
    })
}

/// The Bézier patches of a mesh spec placed in the world by its transform (a Bézier
/// patch is affine invariant: the placed control points are the placed patch's), or
/// `None` when the mesh is not made of patches. The spec must be valid.
pub fn placed_patches(spec: &MeshSpec) -> Option<Result<Vec<crate::bezier::Patch>, String>> {
    let b = spec.bezier.as_ref()?;
    let indices: Vec<[usize; 16]> = b
        .patches
        .iter()
        .map(|p| std::array::from_fn(|j| p[j] as usize))
        .collect();
    let matrix = placement(&spec.transform);
    let placed: Vec<[f64; 3]> = b
        .vertices
        .iter()
        .map(|v| matrix.transform_point3(DVec3::from_array(*v)).to_array())
        .collect();
    Some(patches_from(&placed, &indices))
}

/// Scale, then rotate (x, then y, then z), then translate.
fn placement(t: &Transform) -> DMat4 {
    let scale = match t.scale {
        None => DVec3::ONE,
        Some(Scale::Uniform(s)) => DVec3::splat(s),
        Some(Scale::Axes(s)) => DVec3::from_array(s),
    };
    let r = t.rotate.unwrap_or([0.0; 3]).map(f64::to_radians);
    // extrinsic x, then y, then z: R = Rz · Ry · Rx
    let rotation = DQuat::from_euler(EulerRot::ZYX, r[2], r[1], r[0]);
    let translation = DVec3::from_array(t.translate.unwrap_or([0.0; 3]));
    DMat4::from_scale_rotation_translation(scale, rotation, translation)
}

/// Normals per corner from the faces around each vertex within the crease angle, into
/// each face.
fn smooth_normals(faces: &mut [Face], newell: &[DVec3], vertices: usize, crease_degrees: f64) {
    // the faces around each vertex in face order, vertex by vertex in one vector
    // (`start[v]..start[v + 1]`), each face once (`last`: the last face counted at a vertex)
    let mut last = vec![u32::MAX; vertices];
    let mut start = vec![0u32; vertices + 1];
    for (f, face) in faces.iter().enumerate() {
        for &c in &face.corners {
            if std::mem::replace(&mut last[c as usize], f as u32) != f as u32 {
                start[c as usize + 1] += 1;
            }
        }
    }
    for v in 0..vertices {
        start[v + 1] += start[v];
    }
    last.fill(u32::MAX);
    let mut filled = start.clone();
    let mut around = vec![0u32; start[vertices] as usize];
    for (f, face) in faces.iter().enumerate() {
        for &c in &face.corners {
            if std::mem::replace(&mut last[c as usize], f as u32) != f as u32 {
                around[filled[c as usize] as usize] = f as u32;
                filled[c as usize] += 1;
            }
        }
    }
    let cos_crease = crease_degrees.to_radians().cos();
    let unit: Vec<DVec3> = newell.iter().map(|n| n.normalize()).collect();
    for (f, face) in faces.iter_mut().enumerate() {
        face.normals = face
            .corners
            .iter()
            .map(|&c| {
                let mut sum = DVec3::ZERO;
                let c = c as usize;
                for &g in &around[start[c] as usize..start[c + 1] as usize] {
                    let g = g as usize;
                    if g == f || unit[g].dot(unit[f]) > cos_crease {
                        sum += newell[g];
                    }
                }
                sum.normalize_or(unit[f])
            })
            .collect();
    }
}

fn inline(spec: &MeshSpec, k: usize) -> Result<Raw, BuildError> {
    let vertices = spec.vertices.as_deref().unwrap_or_default();
    let faces = spec.faces.as_deref().unwrap_or_default();
    if vertices.is_empty() {
        return Err(BuildError::Scene(SceneError::at_field(
            SceneErrorKind::Shape,
            format!("meshes[{k}].vertices"),
            "an inline mesh needs at least 3 vertices, found none",
        )));
    }
    for (i, v) in vertices.iter().enumerate() {
        crate::scene::check_point(&format!("meshes[{k}].vertices[{i}]"), *v)
            .map_err(BuildError::Scene)?;
    }
    let mut out_faces = Vec::with_capacity(faces.len());
    for (f, face) in faces.iter().enumerate() {
        let mut corners = Corners::with_capacity(face.len());
        for (c, &i) in face.iter().enumerate() {
            if i >= vertices.len() as u64 {
                return Err(BuildError::Scene(SceneError::at_field(
                    SceneErrorKind::Shape,
                    format!("meshes[{k}].faces[{f}][{c}]"),
                    format!(
                        "vertex index {i} is out of range: the mesh has {} vertices (indices from 0)",
                        vertices.len()
                    ),
                )));
            }
            corners.push(i as u32);
        }
        out_faces.push(corners);
    }
    let normals = match &spec.normals {
        None => None,
        Some(ns) => {
            if ns.len() != vertices.len() {
                return Err(BuildError::Scene(SceneError::at_field(
                    SceneErrorKind::Shape,
                    format!("meshes[{k}].normals"),
                    format!(
                        "expected one normal per vertex ({}), found {}",
                        vertices.len(),
                        ns.len()
                    ),
                )));
            }
            for (i, n) in ns.iter().enumerate() {
                crate::scene::check_point(&format!("meshes[{k}].normals[{i}]"), *n)
                    .map_err(BuildError::Scene)?;
            }
            Some(ns)
        }
    };
    let uv = match &spec.uv {
        None => None,
        Some(uv) => {
            if uv.len() != vertices.len() {
                return Err(BuildError::Scene(SceneError::at_field(
                    SceneErrorKind::Shape,
                    format!("meshes[{k}].uv"),
                    format!(
                        "expected one [u, v] per vertex ({}), found {}",
                        vertices.len(),
                        uv.len()
                    ),
                )));
            }
            for (i, t) in uv.iter().enumerate() {
                if !t
                    .iter()
                    .all(|x| x.is_finite() && x.abs() <= crate::scene::MAX_WORLD_COORDINATE)
                {
                    return Err(BuildError::Scene(SceneError::at_field(
                        SceneErrorKind::Limit,
                        format!("meshes[{k}].uv[{i}]"),
                        format!("expected finite texture coordinates within ±1e9, found {t:?}"),
                    )));
                }
            }
            Some(uv)
        }
    };
    let faces = out_faces
        .into_iter()
        .map(|corners: Corners| Face {
            normals: normals.map_or_else(PerCorner::new, |ns| {
                corners
                    .iter()
                    .map(|&c| DVec3::from_array(ns[c as usize]))
                    .collect()
            }),
            uv: uv.map_or_else(PerCorner::new, |uv| {
                corners.iter().map(|&c| uv[c as usize]).collect()
            }),
            corners,
        })
        .collect();
    Ok(Raw {
        positions: vertices.iter().map(|v| DVec3::from_array(*v)).collect(),
        faces,
        normals_given: normals.is_some(),
        face_lines: None,
    })
}

/// The most segments around the axis.
pub const MAX_SEGMENTS: u32 = 1024;

/// A surface of revolution about the y axis: a ring of `segments` vertices per profile
/// point off the axis, one vertex per point on it; trapezia between two rings, triangles
/// between a ring and the axis. The front is on the right of the profile traversed in
/// order, in the (radius → right, height → up) plane: a profile that starts on the axis
/// at the bottom and climbs outward faces outward.
/// Bézier patches, each tessellated `tessellate` × `tessellate` into triangles with the
/// patch's own normals (the limit at degenerate poles); shared patch edges give
/// bit-identical points, so the mesh has no cracks (`crate::bezier::tessellate`).
/// The most a Bézier mesh's build holds at once, a triangle (its faces, the grid of the
/// patch being tessellated, the positions): checked against the memory budget before a
/// patch is tessellated, and held to a counting allocator by `tests/mesh_memory.rs`.
pub const BEZIER_BUILD_BYTES_PER_TRIANGLE: u64 = 224;

fn bezier(b: &BezierSource, k: usize) -> Result<Raw, BuildError> {
    let indices: Vec<[usize; 16]> = b
        .patches
        .iter()
        .map(|p| std::array::from_fn(|j| p[j] as usize))
        .collect();
    let patches = patches_from(&b.vertices, &indices)
        .map_err(|e| geometry(format!("meshes[{k}].bezier"), e))?;
    let triangles = b.triangles();
    let n = b.tessellate;
    cwisim_scene::budget::Budget::current()
        .check_memory(
            &format!(
                "tessellating the {} patches {n} × {n} ({triangles} triangles)",
                patches.len()
            ),
            triangles.saturating_mul(BEZIER_BUILD_BYTES_PER_TRIANGLE),
        )
        .map_err(|e| {
            BuildError::Scene(SceneError::at_field(
                SceneErrorKind::Limit,
                format!("meshes[{k}].bezier.tessellate"),
                e.to_string(),
            ))
        })?;
    let mut raw = Raw {
        positions: Vec::new(),
        // within MAX_BEZIER_TRIANGLES (validated): it fits a usize
        faces: Vec::with_capacity(triangles as usize),
        normals_given: true,
        face_lines: None,
    };
    for patch in &patches {
        let grid = tessellate(patch, b.tessellate as usize);
        let base = raw.positions.len() as u32;
        raw.positions.extend(&grid.points);
        // vertex (i, k) of the grid lies at the patch's (u, v) = (i/n, k/n)
        let n = grid.n;
        let at = |index: u32| {
            let index = index as usize;
            [
                (index % (n + 1)) as f64 / n as f64,
                (index / (n + 1)) as f64 / n as f64,
            ]
        };
        for t in &grid.triangles {
            raw.faces.push(Face {
                corners: t.iter().map(|&i| base + i).collect(),
                normals: t.iter().map(|&i| grid.normals[i as usize]).collect(),
                uv: t.iter().map(|&i| at(i)).collect(),
            });
        }
    }
    Ok(raw)
}

pub(crate) fn revolution(r: &Revolution, k: usize) -> Result<Raw, BuildError> {
    let field = |s: &str| format!("meshes[{k}].revolution.{s}");
    if !(3..=MAX_SEGMENTS).contains(&r.segments) {
        return Err(BuildError::Scene(SceneError::at_field(
            SceneErrorKind::Limit,
            field("segments"),
            format!("expected 3..={MAX_SEGMENTS} segments, found {}", r.segments),
        )));
    }
    if r.profile.len() < 2 {
        return Err(BuildError::Scene(SceneError::at_field(
            SceneErrorKind::Shape,
            field("profile"),
            format!(
                "a profile needs at least 2 points, found {}",
                r.profile.len()
            ),
        )));
    }
    for (i, p) in r.profile.iter().enumerate() {
        let f = field(&format!("profile[{i}]"));
        crate::scene::check_point(&f, [p[0], p[1], 0.0]).map_err(BuildError::Scene)?;
        if p[0] < 0.0 {
            return Err(BuildError::Scene(SceneError::at_field(
                SceneErrorKind::Shape,
                f,
                format!("a radius must be ≥ 0, found {}", p[0]),
            )));
        }
        if i > 0 && r.profile[i - 1] == *p {
            return Err(geometry(
                f,
                format!("profile points {} and {i} coincide", i - 1),
            ));
        }
        if i > 0 && p[0] == 0.0 && r.profile[i - 1][0] == 0.0 {
            return Err(geometry(
                f,
                format!(
                    "profile points {} and {i} both lie on the axis: that segment has no surface",
                    i - 1
                ),
            ));
        }
    }
    let s = r.segments as usize;
    let mut positions = Vec::new();
    // first vertex index of each profile point's ring (a ring of 1 on the axis)
    let mut rings = Vec::with_capacity(r.profile.len());
    for p in &r.profile {
        rings.push(positions.len() as u32);
        if p[0] == 0.0 {
            positions.push(DVec3::new(0.0, p[1], 0.0));
        } else {
            for j in 0..s {
                let a = std::f64::consts::TAU * j as f64 / s as f64;
                positions.push(DVec3::new(p[0] * a.cos(), p[1], -p[0] * a.sin()));
            }
        }
    }
    let at = |i: usize, j: usize| -> u32 {
        if r.profile[i][0] == 0.0 {
            rings[i]
        } else {
            rings[i] + (j % s) as u32
        }
    };
    // texture coordinates: u the angle over a full turn, v the length along the profile
    // over its whole length
    let mut along = vec![0.0f64];
    for w in r.profile.windows(2) {
        let last = *along.last().expect("starts with 0");
        along.push(last + (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]));
    }
    let total = *along.last().expect("at least 2 points");
    let uv_at = |i: usize, j: usize| [j as f64 / s as f64, along[i] / total];
    let mut faces = Vec::new();
    for i in 0..r.profile.len() - 1 {
        let (p, q) = (r.profile[i], r.profile[i + 1]);
        for j in 0..s {
            let mut corners: Vec<(u32, [f64; 2])> =
                [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)]
                    .map(|(a, b)| (at(a, b), uv_at(a, b)))
                    .to_vec();
            corners.dedup_by_key(|c| c.0);
            if corners.first().map(|c| c.0) == corners.last().map(|c| c.0) {
                corners.pop();
            }
            let mut face: Corners = corners.iter().map(|c| c.0).collect();
            let mut uv: PerCorner<[f64; 2]> = corners.iter().map(|c| c.1).collect();
            // orient: the outward normal of the profile segment, turned to this segment
            let a = std::f64::consts::TAU * (j as f64 + 0.5) / s as f64;
            let (dr, dh) = (q[0] - p[0], q[1] - p[1]);
            let expected = DVec3::new(dh * a.cos(), -dr, -dh * a.sin());
            if newell(&face, &positions).dot(expected) < 0.0 {
                face.reverse();
                uv.reverse();
            }
            faces.push(Face {
                corners: face,
                normals: PerCorner::new(),
                uv,
            });
        }
    }
    Ok(Raw {
        positions,
        faces,
        normals_given: false,
        face_lines: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, PerChannel};

    fn spec() -> MeshSpec {
        MeshSpec {
            name: None,
            material: Material {
                k_a: PerChannel::All(0.1),
                k_d: PerChannel::All(0.5),
                k_s: PerChannel::All(0.0),
                n: 1.0,
                transmittance: 0.0,
                texture: None,
            },
            two_sided: false,
            crease_angle: 50.0,
            transform: Transform::default(),
            vertices: None,
            faces: None,
            normals: None,
            obj: None,
            revolution: None,
            bezier: None,
            uv: None,
        }
    }

    #[test]
    fn a_revolved_cylinder_faces_outward_and_is_smooth_around_sharp_at_the_base() {
        let mut m = spec();
        m.revolution = Some(Revolution {
            profile: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]],
            segments: 16,
        });
        let mesh = build(&m, 0, None).unwrap();
        assert_eq!(mesh.faces.len(), 32);
        // base triangles face down, side trapezia face outward
        for (f, face) in mesh.faces.iter().enumerate() {
            let n = mesh.face_normal(f).normalize();
            let centre: DVec3 = face
                .corners
                .iter()
                .map(|&c| mesh.positions[c as usize])
                .sum::<DVec3>()
                / face.corners.len() as f64;
            if f < 16 {
                assert_eq!(face.corners.len(), 3);
                assert!(n.y < -0.999, "{n}");
                // the 90° base edge is a crease: normals there stay the base's
                assert!(face.normals.iter().all(|m| m.y < -0.999));
            } else {
                assert_eq!(face.corners.len(), 4);
                let radial = DVec3::new(centre.x, 0.0, centre.z).normalize();
                assert!(n.dot(radial) > 0.98, "{n} {radial}");
                // smooth around: each corner normal is the radial direction of its vertex
                for (c, m) in face.corners.iter().zip(&face.normals) {
                    let p = mesh.positions[*c as usize];
                    let radial = DVec3::new(p.x, 0.0, p.z).normalize();
                    assert!((m.dot(radial) - 1.0).abs() < 1e-12, "{m} {radial}");
                }
            }
        }
    }

    #[test]
    fn degenerate_and_non_convex_faces_are_refused_with_their_path() {
        let mut m = spec();
        m.vertices = Some(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
        m.faces = Some(vec![vec![0, 1, 2]]);
        let Err(BuildError::Scene(e)) = build(&m, 3, None) else {
            panic!()
        };
        assert_eq!(e.field.as_deref(), Some("meshes[3].faces[0]"));
        assert!(e.message.contains("degenerate"), "{e}");
        m.vertices = Some(vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 0.5, 0.0],
            [0.0, 2.0, 0.0],
        ]);
        m.faces = Some(vec![vec![0, 1, 2, 3, 4]]);
        let Err(BuildError::Scene(e)) = build(&m, 0, None) else {
            panic!()
        };
        assert!(e.message.contains("non-convex"), "{e}");
        m.faces = Some(vec![vec![0, 1, 7]]);
        let Err(BuildError::Scene(e)) = build(&m, 0, None) else {
            panic!()
        };
        assert_eq!(e.field.as_deref(), Some("meshes[0].faces[0][2]"));
    }

    #[test]
    fn transforms_scale_then_rotate_then_translate() {
        let t = Transform {
            scale: Some(Scale::Uniform(2.0)),
            rotate: Some([0.0, 90.0, 0.0]),
            translate: Some([1.0, 0.0, 0.0]),
        };
        let p = placement(&t).transform_point3(DVec3::X);
        // scaled to (2,0,0), turned 90° about y to (0,0,-2), moved to (1,0,-2)
        assert!((p - DVec3::new(1.0, 0.0, -2.0)).length() < 1e-12, "{p}");
    }
}
