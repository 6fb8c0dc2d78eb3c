//! World scene files: `"kind": "world"`.
//!
//! A world scene is a camera, lights and meshes in 3D, with the report's reflection
//! coefficients per mesh (van Rij, section 1.2). Every number that is an intensity or a
//! coefficient may be one number (the same in every channel) or an array of `channels`
//! numbers (per channel: RGB for `"channels": 3`).
//!
//! ```json
//! {
//!   "kind": "world",
//!   "width": 320, "height": 240, "channels": 1,
//!   "camera": { "eye": [0, 2.2, 5], "target": [0, 0.8, 0], "up": [0, 1, 0], "fov_y": 35 },
//!   "ambient": 0.3,
//!   "lights": [ { "position": [4, 6, 5], "intensity": 0.9 } ],
//!   "meshes": [
//!     { "name": "pot",
//!       "material": { "k_a": 0.4, "k_d": 0.7, "k_s": 0.4, "n": 16 },
//!       "two_sided": true,
//!       "revolution": { "profile": [[0, 0], [0.6, 0], [1, 0.7], [0.5, 1.4]], "segments": 24 } },
//!     { "name": "floor",
//!       "material": { "k_a": 0.5, "k_d": 0.5, "k_s": 0, "n": 1 },
//!       "vertices": [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]],
//!       "faces": [[0, 1, 2, 3]] },
//!     { "name": "teapot", "material": { "k_a": 0.3, "k_d": 0.6, "k_s": 0.5, "n": 30 },
//!       "obj": "teapot.obj", "transform": { "translate": [1.5, 0, 0], "scale": 0.5 } }
//!   ]
//! }
//! ```
//!
//! The full reference, with every key, is `docs/SCENES.md`. [`parse_world`] reads and
//! checks a scene and builds its meshes ([`crate::mesh`]); every fault is a located
//! [`SceneError`], as for screen scenes.

use crate::mesh::{self, Mesh};
use cwisim_scene::{
    json_error, locate_error, SceneError, SceneErrorKind, MAX_CHANNELS, MAX_INTENSITY, MAX_SIDE,
    MAX_VALUES,
};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The narrowest field of view (degrees): at it the tallest image's focal length is about
/// 4e9 pixels, so that the projection of any scene within the world coordinate limit
/// stays finite; narrower is a telescope no scene here needs.
pub const MIN_FOV_Y: f64 = 1e-3;

/// The largest coordinate magnitude accepted in world space.
pub const MAX_WORLD_COORDINATE: f64 = 1e9;
/// The most triangles a scene may hold after its meshes are built.
pub const MAX_TRIANGLES: usize = 4_000_000;

/// One number for every channel, or one per channel.
///
/// Read by hand rather than as an untagged enum, so that a value of neither form is
/// refused saying what is expected (`expected a number, or a list of numbers (one per
/// channel)`), not that it matched no variant.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum PerChannel {
    /// The same value in every channel.
    All(f64),
    /// One value per channel.
    Each(Vec<f64>),
}

impl PerChannel {
    /// The value in channel `c`.
    pub fn get(&self, c: usize) -> f64 {
        match self {
            PerChannel::All(v) => *v,
            PerChannel::Each(v) => v[c],
        }
    }

    /// Checks the shape (one number, or `channels`), that every value is finite, at least
    /// `min` and at most [`MAX_INTENSITY`] in magnitude (a value beyond it is named by its
    /// own path, `field[c]`, when given per channel).
    pub(crate) fn check(&self, field: &str, channels: usize, min: f64) -> Result<(), SceneError> {
        let values: Vec<f64> = match self {
            PerChannel::All(v) => vec![*v],
            PerChannel::Each(v) => {
                if v.len() != channels {
                    return Err(SceneError::at_field(
                        SceneErrorKind::Shape,
                        field,
                        format!(
                            "expected one number or {channels} (the scene's channels), found {}",
                            v.len()
                        ),
                    ));
                }
                v.clone()
            }
        };
        let each = matches!(self, PerChannel::Each(_));
        for (c, v) in values.into_iter().enumerate() {
            finite(field, v)?;
            if v < min {
                return Err(SceneError::at_field(
                    SceneErrorKind::Limit,
                    field,
                    format!("expected a value ≥ {min}, found {v}"),
                ));
            }
            if v.abs() > MAX_INTENSITY {
                return Err(SceneError::at_field(
                    SceneErrorKind::Limit,
                    if each { format!("{field}[{c}]") } else { field.to_string() },
                    format!(
                        "{v:e} is beyond {MAX_INTENSITY:e}, the limit of every intensity and lighting term (it keeps the lighting and the renderers' arithmetic finite; terms are nominally 0 to 1)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The pinhole camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Where the camera is.
    pub eye: [f64; 3],
    /// The point it looks at (the image centre).
    pub target: [f64; 3],
    /// Which way is up (need not be perpendicular to the view direction).
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// The vertical field of view, degrees, in `(0, 180)`.
    pub fov_y: f64,
    /// The near plane: every vertex must be at least this far in front of the camera.
    #[serde(default = "default_near")]
    pub near: f64,
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

fn default_near() -> f64 {
    1e-3
}

/// A point light source.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Where it is.
    pub position: [f64; 3],
    /// `I_l`.
    pub intensity: PerChannel,
    /// It casts shadows (`"shadows": true`; `render --shadows on|off` overrides every
    /// light): see [`crate::shadow`].
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub shadows: bool,
}

/// The reflection coefficients of the report's formula.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Ambient reflection `k_a`.
    pub k_a: PerChannel,
    /// Diffuse reflection `k_d` (the object's colour).
    pub k_d: PerChannel,
    /// Specular reflection `k_s`.
    pub k_s: PerChannel,
    /// Specular exponent `n` (shininess), ≥ 0.
    pub n: f64,
    /// The fraction of light from behind that passes through, in `[0, 1]` (0, the
    /// default: opaque). Drawn by renderers that composite layers per sample
    /// (`woo-chall`); the others draw the mesh opaque and say so.
    #[serde(default, skip_serializing_if = "is_opaque")]
    pub transmittance: f64,
    /// A texture multiplying `k_d` and `k_a` per channel ([`crate::texture`]); the mesh
    /// needs texture coordinates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<crate::texture::TextureSpec>,
}

fn is_opaque(t: &f64) -> bool {
    *t == 0.0
}

/// A placement: scale, then rotate (degrees about x, then y, then z), then translate.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    /// Scale: one factor, or one per axis.
    #[serde(default)]
    pub scale: Option<Scale>,
    /// Rotation in degrees about the x, y and z axes, applied in that order.
    #[serde(default)]
    pub rotate: Option<[f64; 3]>,
    /// Translation.
    #[serde(default)]
    pub translate: Option<[f64; 3]>,
}

/// A uniform or per-axis scale.
///
/// Read by hand (as [`PerChannel`]), so that a value of neither form says what is
/// expected.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(f64),
    /// One factor per axis.
    Axes([f64; 3]),
}

/// A number or a list of numbers, as one of two variants: `one` of a number, `many` of
/// the list (each element read as `f64`), `expecting` the words for what is expected.
struct NumberOrList<T> {
    expecting: &'static str,
    one: fn(f64) -> T,
    many: fn(Vec<f64>) -> Result<T, usize>,
}

impl<'de, T> serde::de::Visitor<'de> for NumberOrList<T> {
    type Value = T;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(self.expecting)
    }

    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<T, E> {
        Ok((self.one)(v))
    }

    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<T, E> {
        Ok((self.one)(v as f64))
    }

    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<T, E> {
        Ok((self.one)(v as f64))
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<T, A::Error> {
        let mut values = Vec::new();
        while let Some(v) = seq.next_element::<f64>()? {
            values.push(v);
        }
        let n = values.len();
        (self.many)(values).map_err(|_| serde::de::Error::invalid_length(n, &self))
    }
}

impl<'de> Deserialize<'de> for PerChannel {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(NumberOrList {
            expecting: "a number, or a list of numbers (one per channel)",
            one: PerChannel::All,
            many: |v| Ok(PerChannel::Each(v)),
        })
    }
}

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(NumberOrList {
            expecting: "a number, or a list of 3 numbers (one per axis)",
            one: Scale::Uniform,
            many: |v| {
                <[f64; 3]>::try_from(v)
                    .map(Scale::Axes)
                    .map_err(|v| v.len())
            },
        })
    }
}

/// A surface of revolution about the y axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Revolution {
    /// The profile `[radius, height]`, from one end to the other. A point with radius 0
    /// lies on the axis: the faces there are triangles, elsewhere trapezia.
    pub profile: Vec<[f64; 2]>,
    /// Faces around the axis, `3..=1024`.
    pub segments: u32,
}

/// Bicubic Bézier patches (the Utah teapot's form): control points, and per patch the
/// indices of its 4×4 control points, row-major (`u` along a row, `v` down the rows).
/// Polygon renderers draw each patch tessellated `tessellate` × `tessellate`, with
/// normals from the patch's derivatives (`crate::bezier`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BezierSource {
    /// Control points `[x, y, z]`.
    pub vertices: Vec<[f64; 3]>,
    /// Per patch, 16 indices into `vertices`.
    pub patches: Vec<Vec<u64>>,
    /// Quads per patch side, `1..=MAX_TESSELLATION`.
    pub tessellate: u32,
}

/// The finest tessellation of a Bézier patch: 128 × 128 quads (the teapot then has
/// 1,047,552 triangles: 445 MB to draw with `vanrij` on one thread, PERFORMANCE.md).
pub const MAX_TESSELLATION: u32 = 128;
/// The most triangles a Bézier mesh may tessellate into: 2^22.
pub const MAX_BEZIER_TRIANGLES: u64 = 1 << 22;

impl BezierSource {
    /// The triangles its patches tessellate into, two a quad (before degenerate ones are
    /// dropped): what its limit and the memory budget count.
    pub fn triangles(&self) -> u64 {
        self.patches.len() as u64 * 2 * u64::from(self.tessellate) * u64::from(self.tessellate)
    }

    /// Checks counts, indices, coordinates and the tessellation level; every fault names
    /// its JSON path under `field` (`meshes[k].bezier`).
    pub fn validate(&self, field: &str) -> Result<(), SceneError> {
        use SceneErrorKind as K;
        if self.patches.is_empty() {
            return Err(SceneError::at_field(
                K::Shape,
                format!("{field}.patches"),
                "expected at least one patch",
            ));
        }
        for (i, v) in self.vertices.iter().enumerate() {
            check_point(&format!("{field}.vertices[{i}]"), *v)?;
        }
        for (k, p) in self.patches.iter().enumerate() {
            if p.len() != 16 {
                return Err(SceneError::at_field(
                    K::Shape,
                    format!("{field}.patches[{k}]"),
                    format!(
                        "expected 16 control-point indices (4×4, row-major), found {}",
                        p.len()
                    ),
                ));
            }
            for (j, &index) in p.iter().enumerate() {
                if index >= self.vertices.len() as u64 {
                    return Err(SceneError::at_field(
                        K::Shape,
                        format!("{field}.patches[{k}][{j}]"),
                        format!(
                            "vertex index {index} is out of range: there are {} vertices (indices from 0)",
                            self.vertices.len()
                        ),
                    ));
                }
            }
        }
        if !(1..=MAX_TESSELLATION).contains(&self.tessellate) {
            return Err(SceneError::at_field(
                K::Limit,
                format!("{field}.tessellate"),
                format!(
                    "expected quads per patch side in 1..={MAX_TESSELLATION}, found {}",
                    self.tessellate
                ),
            ));
        }
        let triangles = self.triangles();
        if triangles > MAX_BEZIER_TRIANGLES {
            return Err(SceneError::at_field(
                K::Limit,
                format!("{field}.tessellate"),
                format!(
                    "{} patches tessellated {} × {} would make {triangles} triangles; the limit is {MAX_BEZIER_TRIANGLES} (2^22)",
                    self.patches.len(),
                    self.tessellate,
                    self.tessellate
                ),
            ));
        }
        Ok(())
    }
}

/// One mesh: where its geometry comes from, its material, and how it is placed.
///
/// Exactly one geometry source: `vertices` + `faces` (inline), `obj` (a Wavefront OBJ
/// file, relative to the scene file), `revolution`, or `bezier`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// A name for messages and statistics.
    #[serde(default)]
    pub name: Option<String>,
    /// The reflection coefficients.
    pub material: Material,
    /// Draw back faces too (lit with the normal turned to the viewer), for open surfaces
    /// whose inside shows.
    #[serde(default)]
    pub two_sided: bool,
    /// Normals at a vertex are averaged over its faces whose normals differ by less than
    /// this angle (degrees); sharper edges stay sharp. 0: faceted.
    #[serde(default = "default_crease")]
    pub crease_angle: f64,
    /// Placement in the world.
    #[serde(default)]
    pub transform: Transform,
    /// Inline vertices `[x, y, z]`.
    #[serde(default)]
    pub vertices: Option<Vec<[f64; 3]>>,
    /// Inline faces: vertex indices, counter-clockwise seen from the front (outside).
    #[serde(default)]
    pub faces: Option<Vec<Vec<u64>>>,
    /// Inline normals, one per vertex (optional: otherwise from the faces).
    #[serde(default)]
    pub normals: Option<Vec<[f64; 3]>>,
    /// Inline texture coordinates `[u, v]`, one per vertex (optional; what a texture
    /// needs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uv: Option<Vec<[f64; 2]>>,
    /// A Wavefront OBJ file.
    #[serde(default)]
    pub obj: Option<String>,
    /// A surface of revolution.
    #[serde(default)]
    pub revolution: Option<Revolution>,
    /// Bicubic Bézier patches.
    #[serde(default)]
    pub bezier: Option<BezierSource>,
}

fn default_crease() -> f64 {
    50.0
}

/// A world scene as its file says.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Always `"world"`.
    pub kind: String,
    /// Image width, pixels.
    pub width: u64,
    /// Image height, pixels.
    pub height: u64,
    /// 1 (grey) to 4; 3 is RGB.
    pub channels: u64,
    /// The camera.
    pub camera: CameraSpec,
    /// Ambient light `I_a`.
    pub ambient: PerChannel,
    /// Point lights.
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// The meshes.
    pub meshes: Vec<MeshSpec>,
}

/// A checked world scene with its meshes built (in world space, transforms applied).
#[derive(Clone, Debug, PartialEq)]
pub struct WorldScene {
    /// The description it was built from.
    pub spec: WorldSpec,
    /// The meshes, in the order of `spec.meshes`.
    pub meshes: Vec<Mesh>,
    /// Per mesh, its material's texture: its size read, its texels decoded when first
    /// needed ([`crate::texture::TextureStore`]; clones of the scene share it).
    pub textures: std::sync::Arc<crate::texture::TextureStore>,
}

impl WorldScene {
    /// Image width.
    pub fn width(&self) -> u32 {
        self.spec.width as u32
    }

    /// Image height.
    pub fn height(&self) -> u32 {
        self.spec.height as u32
    }

    /// Channels.
    pub fn channels(&self) -> usize {
        self.spec.channels as usize
    }

    /// Triangles of its meshes after fanning every face (before culling): what
    /// projection makes at most.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(Mesh::triangle_count).sum()
    }

    /// The bytes its built meshes hold ([`Mesh::held_bytes`]): what the memory budget
    /// counts for them while they are held.
    pub fn mesh_bytes(&self) -> u64 {
        self.meshes.iter().map(Mesh::held_bytes).sum()
    }

    /// The screen scene of `polygons` (what visibility made of this scene), at this
    /// scene's image size and channels.
    pub fn screen(&self, polygons: Vec<cwisim_scene::Polygon>) -> cwisim_scene::ScreenScene {
        cwisim_scene::ScreenScene {
            width: self.width(),
            height: self.height(),
            channels: self.channels() as u8,
            polygons,
        }
    }

    /// The same scene with its Bézier meshes tessellated `n` × `n` per patch (other
    /// meshes as they are); refused outside `1..=MAX_TESSELLATION` or past the triangle
    /// limit, naming the mesh.
    pub fn with_tessellation(mut self, n: u32) -> Result<Self, SceneError> {
        for k in 0..self.spec.meshes.len() {
            let Some(b) = self.spec.meshes[k].bezier.as_mut() else {
                continue;
            };
            b.tessellate = n;
            b.validate(&format!("meshes[{k}].bezier"))?;
            self.meshes[k] = mesh::build(&self.spec.meshes[k], k, None).map_err(|e| match e {
                mesh::BuildError::Scene(e) | mesh::BuildError::File(e) => e,
            })?;
        }
        Ok(self)
    }

    /// The same scene with another image size (the camera keeps its vertical field of
    /// view; the horizontal one follows the aspect ratio).
    pub fn with_size(mut self, width: u32, height: u32) -> Result<Self, SceneError> {
        self.spec.width = u64::from(width);
        self.spec.height = u64::from(height);
        check_image(&self.spec)?;
        Ok(self)
    }
}

fn finite(field: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::at_field(
            SceneErrorKind::NonFinite,
            field,
            format!("expected a finite number, found {v}"),
        ))
    }
}

pub(crate) fn check_point(field: &str, p: [f64; 3]) -> Result<(), SceneError> {
    for v in p {
        finite(field, v)?;
        if v.abs() > MAX_WORLD_COORDINATE {
            return Err(SceneError::at_field(
                SceneErrorKind::Limit,
                field,
                format!("coordinate {v:e} is beyond ±{MAX_WORLD_COORDINATE:e}"),
            ));
        }
    }
    Ok(())
}

fn check_image(s: &WorldSpec) -> Result<(), SceneError> {
    for (name, v) in [("width", s.width), ("height", s.height)] {
        if !(1..=u64::from(MAX_SIDE)).contains(&v) {
            return Err(SceneError::at_field(
                SceneErrorKind::Limit,
                name,
                format!("{name} {v} is outside 1..={MAX_SIDE} pixels"),
            ));
        }
    }
    if !(1..=u64::from(MAX_CHANNELS)).contains(&s.channels) {
        return Err(SceneError::at_field(
            SceneErrorKind::Limit,
            "channels",
            format!(
                "channels {} is outside 1..={MAX_CHANNELS} (1 grey, 3 RGB)",
                s.channels
            ),
        ));
    }
    let values = s.width * s.height * s.channels;
    if values > MAX_VALUES {
        return Err(SceneError::at_field(
            SceneErrorKind::Limit,
            "",
            format!(
                "the image would hold {} × {} × {} = {values} values; the limit is {MAX_VALUES} (2^28)",
                s.width, s.height, s.channels
            ),
        ));
    }
    Ok(())
}

impl Material {
    /// Checks the lighting coefficients of mesh `k`'s material: `k_a`, `k_d`, `k_s`
    /// finite, ≥ 0 and at most [`MAX_INTENSITY`]; `n` finite and ≥ 0 (any size: `(R·V)^n`
    /// is at most 1).
    fn check(&self, k: usize, channels: usize) -> Result<(), SceneError> {
        let f = |key: &str| format!("meshes[{k}].material.{key}");
        self.k_a.check(&f("k_a"), channels, 0.0)?;
        self.k_d.check(&f("k_d"), channels, 0.0)?;
        self.k_s.check(&f("k_s"), channels, 0.0)?;
        finite(&f("n"), self.n)?;
        if self.n < 0.0 {
            return Err(SceneError::at_field(
                SceneErrorKind::Limit,
                f("n"),
                format!("expected a specular exponent ≥ 0, found {}", self.n),
            ));
        }
        Ok(())
    }
}

impl WorldSpec {
    /// Checks the lighting terms alone, as [`WorldSpec::validate`] does: the ambient
    /// term and every light's intensity (finite, ≥ 0, at most [`MAX_INTENSITY`]), and
    /// every material's coefficients. What lighting needs to stay finite, for code that
    /// lights a scene it did not read (a scene built in code is never validated):
    /// [`crate::project::project`] and `cwisim-render`'s `nishita` start with it.
    pub fn check_lighting(&self) -> Result<(), SceneError> {
        let channels = self.channels as usize;
        self.ambient.check("ambient", channels, 0.0)?;
        for (k, l) in self.lights.iter().enumerate() {
            l.intensity
                .check(&format!("lights[{k}].intensity"), channels, 0.0)?;
        }
        for (k, m) in self.meshes.iter().enumerate() {
            m.material.check(k, channels)?;
        }
        Ok(())
    }

    /// Checks every rule that does not need the meshes built: sizes, channels, camera,
    /// lights, materials, transforms, and that each mesh names exactly one source.
    pub fn validate(&self) -> Result<(), SceneError> {
        use SceneErrorKind as K;
        check_image(self)?;
        let channels = self.channels as usize;
        let c = &self.camera;
        check_point("camera.eye", c.eye)?;
        check_point("camera.target", c.target)?;
        check_point("camera.up", c.up)?;
        finite("camera.fov_y", c.fov_y)?;
        if !(c.fov_y >= MIN_FOV_Y && c.fov_y < 180.0) {
            return Err(SceneError::at_field(
                K::Limit,
                "camera.fov_y",
                format!(
                    "expected a field of view from {MIN_FOV_Y} to under 180 degrees, found {:?}",
                    c.fov_y
                ),
            ));
        }
        finite("camera.near", c.near)?;
        if c.near <= 0.0 {
            return Err(SceneError::at_field(
                K::Limit,
                "camera.near",
                format!("expected a near distance > 0, found {}", c.near),
            ));
        }
        let view = sub(c.target, c.eye);
        if norm(view) == 0.0 {
            return Err(SceneError::at_field(
                K::Geometry,
                "camera.target",
                "the camera looks at its own position: target must differ from eye",
            ));
        }
        if norm(cross(view, c.up)) <= 1e-9 * norm(view) * norm(c.up) {
            return Err(SceneError::at_field(
                K::Geometry,
                "camera.up",
                "up is zero or parallel to the view direction (target − eye)",
            ));
        }
        self.ambient.check("ambient", channels, 0.0)?;
        for (k, l) in self.lights.iter().enumerate() {
            check_point(&format!("lights[{k}].position"), l.position)?;
            l.intensity
                .check(&format!("lights[{k}].intensity"), channels, 0.0)?;
        }
        if self.meshes.is_empty() {
            return Err(SceneError::at_field(
                K::Shape,
                "meshes",
                "a world scene needs at least one mesh",
            ));
        }
        for (k, m) in self.meshes.iter().enumerate() {
            let f = |key: &str| format!("meshes[{k}].{key}");
            let mat = &m.material;
            mat.check(k, channels)?;
            finite(&f("material.transmittance"), mat.transmittance)?;
            if !(0.0..=1.0).contains(&mat.transmittance) {
                return Err(SceneError::at_field(
                    K::Limit,
                    f("material.transmittance"),
                    format!(
                        "expected a transmittance in [0, 1] (0 opaque, 1 invisible), found {}",
                        mat.transmittance
                    ),
                ));
            }
            if let Some(t) = &mat.texture {
                crate::texture::validate(t, &f("material.texture"), channels)?;
            }
            finite(&f("crease_angle"), m.crease_angle)?;
            if !(0.0..=180.0).contains(&m.crease_angle) {
                return Err(SceneError::at_field(
                    K::Limit,
                    f("crease_angle"),
                    format!(
                        "expected an angle in 0..=180 degrees, found {}",
                        m.crease_angle
                    ),
                ));
            }
            let t = &m.transform;
            match &t.scale {
                Some(Scale::Uniform(s)) => nonzero_scale(&f("transform.scale"), &[*s])?,
                Some(Scale::Axes(s)) => nonzero_scale(&f("transform.scale"), s)?,
                None => {}
            }
            if let Some(r) = t.rotate {
                check_point(&f("transform.rotate"), r)?;
            }
            if let Some(p) = t.translate {
                check_point(&f("transform.translate"), p)?;
            }
            let sources = [
                m.vertices.is_some() || m.faces.is_some() || m.normals.is_some() || m.uv.is_some(),
                m.obj.is_some(),
                m.revolution.is_some(),
                m.bezier.is_some(),
            ];
            match sources.iter().filter(|s| **s).count() {
                1 => {}
                0 => {
                    return Err(SceneError::at_field(
                        K::Schema,
                        format!("meshes[{k}]"),
                        "expected one geometry source: \"vertices\" + \"faces\", \"obj\", \"revolution\" or \"bezier\"",
                    ))
                }
                _ => {
                    return Err(SceneError::at_field(
                        K::Schema,
                        format!("meshes[{k}]"),
                        "expected only one geometry source: \"vertices\" + \"faces\", \"obj\", \"revolution\" or \"bezier\"",
                    ))
                }
            }
            if let Some(b) = &m.bezier {
                b.validate(&f("bezier"))?;
            }
            if sources[0] && (m.vertices.is_none() || m.faces.is_none()) {
                return Err(SceneError::at_field(
                    K::Schema,
                    format!("meshes[{k}]"),
                    "an inline mesh needs both \"vertices\" and \"faces\"",
                ));
            }
        }
        Ok(())
    }
}

fn nonzero_scale(field: &str, s: &[f64]) -> Result<(), SceneError> {
    for &v in s {
        finite(field, v)?;
        if v == 0.0 || v.abs() > MAX_WORLD_COORDINATE || v.abs() < 1.0 / MAX_WORLD_COORDINATE {
            return Err(SceneError::at_field(
                SceneErrorKind::Limit,
                field,
                format!("expected a scale factor with 1e-9 ≤ |s| ≤ 1e9, found {v}"),
            ));
        }
    }
    Ok(())
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Reads a world scene from JSON text, checks it and builds its meshes. OBJ files are
/// read relative to `base` (the scene file's directory; the working directory if
/// `None`). Errors are located in `text` (or, for OBJ faults, in the OBJ file).
pub fn parse_world(text: &str, base: Option<&Path>) -> Result<WorldScene, SceneError> {
    let spec: WorldSpec = serde_json::from_str(text).map_err(|e| json_error(&e))?;
    let locate = |e: SceneError| locate_error(text, e);
    spec.validate().map_err(locate)?;
    let mut meshes = Vec::with_capacity(spec.meshes.len());
    let mut triangles = 0usize;
    for (k, m) in spec.meshes.iter().enumerate() {
        let built = mesh::build(m, k, base).map_err(|e| match e {
            mesh::BuildError::Scene(e) => locate(e),
            mesh::BuildError::File(e) => e,
        })?;
        triangles += built.triangle_count();
        if triangles > MAX_TRIANGLES {
            return Err(locate(SceneError::at_field(
                SceneErrorKind::Limit,
                format!("meshes[{k}]"),
                format!("the scene has more than {MAX_TRIANGLES} triangles"),
            )));
        }
        // the image size does not change depths: any size will do
        let camera = crate::camera::Camera::new(&spec.camera, 1, 1);
        crate::project::check_in_front(&camera, &built, k).map_err(locate)?;
        meshes.push(built);
    }
    let textures = load_textures(&spec, &meshes, base, &locate).map_err(locate)?;
    Ok(WorldScene {
        spec,
        meshes,
        textures,
    })
}

/// The textures of a scene's meshes (validated spec, built meshes): each textured mesh
/// checked to have texture coordinates and each texture's size read (a checker's, an
/// image's header) first; then what they all need checked against the memory budget
/// (`cwisim_scene::budget`), refused at the texture that passes it. Nothing is decoded:
/// the store decodes a texture when a shading call first needs it.
pub(crate) fn load_textures(
    spec: &WorldSpec,
    meshes: &[Mesh],
    base: Option<&Path>,
    locate: &dyn Fn(SceneError) -> SceneError,
) -> Result<std::sync::Arc<crate::texture::TextureStore>, SceneError> {
    use crate::texture;
    let channels = spec.channels as usize;
    let field = |k: usize| format!("meshes[{k}].material.texture");
    let mut needed = 0u64;
    for (k, (m, built)) in spec.meshes.iter().zip(meshes).enumerate() {
        let Some(t) = &m.material.texture else {
            continue;
        };
        if !built.has_uv() {
            return Err(SceneError::at_field(
                SceneErrorKind::Shape,
                field(k),
                format!(
                    "mesh {:?} has no texture coordinates: give inline \"uv\" (one per vertex), an OBJ file with `vt` at every corner, a \"revolution\" or \"bezier\" patches",
                    built.name
                ),
            ));
        }
        let (w, h) = texture::extent(t, &field(k), base)?;
        needed += texture::bytes_for(w, h, channels);
        cwisim_scene::budget::Budget::current()
            .check_memory(
                &format!("the scene's textures (up to meshes[{k}], {w}×{h} texels)"),
                needed,
            )
            .map_err(|e| SceneError::at_field(SceneErrorKind::Limit, field(k), e.to_string()))?;
    }
    let specs = spec
        .meshes
        .iter()
        .enumerate()
        .map(|(k, m)| m.material.texture.clone().map(|t| (t, field(k))))
        .collect();
    texture::TextureStore::new(specs, channels, base, locate).map(std::sync::Arc::new)
}
