//! Screen scenes (`"kind": "screen"`): polygons already in screen space, with one
//! intensity vector per vertex and, optionally, a depth per vertex.

use crate::error::{describe, json_kind, locate_error, read_kind, SceneError, SceneErrorKind};
use crate::predicates::simplicity_fault;
use crate::{MAX_CHANNELS, MAX_COORDINATE, MAX_INTENSITY, MAX_SIDE, MAX_VALUES, SCENE_KINDS};
use serde::{Deserialize, Serialize};
use smallvec::SmallVec;
use std::path::Path;

/// One vertex's intensity: `channels` values, held in place (up to [`MAX_CHANNELS`], every
/// scene's channels), not in a heap block of their own.
pub type VertexIntensity = SmallVec<[f64; cwisim_isa::MAX_CHANNELS]>;

/// A polygon with an intensity vector per vertex.
///
/// Edge `k` runs from vertex `k` to vertex `k + 1` (the last edge closes the polygon).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Polygon {
    /// The vertices `[x, y]`, in either orientation.
    pub vertices: Vec<[f64; 2]>,
    /// `intensity[vertex][channel]`: one vector per vertex.
    pub intensity: Vec<VertexIntensity>,
    /// One depth per vertex, when the scene carries depth: smaller is nearer, and depth
    /// is affine in screen space over the polygon (a plane), so that renderers that
    /// resolve visibility can compare polygons at any point. Renderers that do not
    /// resolve visibility ignore it: their polygons add up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<Vec<f64>>,
}

impl Polygon {
    /// A polygon with one intensity vector per vertex (each a [`VertexIntensity`], or
    /// anything that becomes one: a `Vec<f64>`, a slice).
    pub fn new<I: Into<VertexIntensity>>(vertices: Vec<[f64; 2]>, intensity: Vec<I>) -> Self {
        Polygon {
            vertices,
            intensity: intensity.into_iter().map(Into::into).collect(),
            depth: None,
        }
    }

    /// A polygon with the same intensity vector at every vertex.
    pub fn uniform(vertices: Vec<[f64; 2]>, intensity: &[f64]) -> Self {
        let n = vertices.len();
        Polygon {
            vertices,
            intensity: vec![VertexIntensity::from_slice(intensity); n],
            depth: None,
        }
    }

    /// The same polygon with one depth per vertex.
    pub fn with_depth(mut self, depth: Vec<f64>) -> Self {
        self.depth = Some(depth);
        self
    }

    /// The depth at `p`, from the plane through vertex 0 and the fan triangle
    /// `(0, j, j+1)` of largest area (the best-conditioned one); `None` without depth or
    /// when the polygon has no area.
    pub fn depth_at(&self, p: [f64; 2]) -> Option<f64> {
        let depth = self.depth.as_deref()?;
        let v = &self.vertices;
        let a = v[0];
        let cross = |b: [f64; 2], c: [f64; 2]| {
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        let j = (1..v.len() - 1).max_by(|&i, &k| {
            cross(v[i], v[i + 1])
                .abs()
                .total_cmp(&cross(v[k], v[k + 1]).abs())
        })?;
        let (b, c) = (v[j], v[j + 1]);
        let det = cross(b, c);
        if det == 0.0 {
            return None;
        }
        let s = cross(p, c) / det;
        let t = cross(b, p) / det;
        Some(depth[0] + s * (depth[j] - depth[0]) + t * (depth[j + 1] - depth[0]))
    }
}

/// A screen-space scene: an image size and the polygons drawn into it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScreenScene {
    /// Image width in pixels, `1..=MAX_SIDE`.
    pub width: u32,
    /// Image height in pixels (scanlines), `1..=MAX_SIDE`.
    pub height: u32,
    /// Values per intensity, `1..=MAX_CHANNELS`.
    pub channels: u8,
    /// The polygons, in drawing order.
    pub polygons: Vec<Polygon>,
}

/// A scene of any kind.
///
/// Its serde form is the file format (`kind` as the tag), but serde alone checks nothing
/// beyond the shape: read files with [`parse_scene`] / [`load_scene`], which also validate
/// and locate every fault.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Scene {
    /// `"kind": "screen"`: polygons in screen space.
    Screen(ScreenScene),
}

impl Scene {
    /// The `kind` key of this scene.
    pub fn kind(&self) -> &'static str {
        match self {
            Scene::Screen(_) => "screen",
        }
    }

    /// The scene as its file: pretty, deterministic JSON that [`parse_scene`] reads back
    /// to an equal scene.
    pub fn to_json(&self) -> String {
        match self {
            Scene::Screen(s) => s.to_json(),
        }
    }

    /// Checks the scene against every rule of its kind.
    pub fn validate(&self) -> Result<(), SceneError> {
        match self {
            Scene::Screen(s) => s.validate(),
        }
    }
}

/// Reads a scene from JSON text and validates it.
///
/// Syntax and type errors are located by the JSON parser; the faults of [`validate`]
/// (`ScreenScene::validate`) are located at the value their JSON path names.
///
/// [`validate`]: ScreenScene::validate
pub fn parse_scene(text: &str) -> Result<Scene, SceneError> {
    // One typed pass over the text: a sound scene is read and validated in it. Any fault
    // sends the text to the passes below, which find it and locate it (the messages do
    // not depend on which path found the scene sound).
    if let Ok(fast) = serde_json::from_str::<FastScreen>(text) {
        if let Ok(scene) = fast.0.into_scene() {
            if scene.validate().is_ok() {
                return Ok(Scene::Screen(scene));
            }
        }
    }
    parse_located(text)
}

/// [`parse_scene`] without its fast path: a scene read in up to three passes, each
/// fault located.
fn parse_located(text: &str) -> Result<Scene, SceneError> {
    let kind = read_kind(text, SCENE_KINDS)?;
    let locate = |e: SceneError| {
        let located = locate_error(text, e);
        if located.line.is_some() {
            return located;
        }
        // a path that is not in the text as written (a repeated key: the value read is
        // the last, the path found the first): the typed reading locates the repeat
        match serde_json::from_str::<RawScreen>(text) {
            Err(typed) => SceneError::from_json(json_kind(&typed), &typed),
            Ok(_) => located,
        }
    };
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| SceneError::from_json(json_kind(&e), &e))?;
    let root = value.as_object().expect("read_kind checked the object");
    match kind.as_str() {
        "screen" => {
            if let Some(serde_json::Value::Array(polys)) = root.get("polygons") {
                for (k, p) in polys.iter().enumerate() {
                    if !p.is_object() {
                        return Err(locate(SceneError::at_field(
                            SceneErrorKind::Schema,
                            format!("polygons[{k}]"),
                            format!(
                                "expected a polygon object {{\"vertices\": …, \"intensity\": …}}, found {}",
                                describe(p)
                            ),
                        )));
                    }
                    if let Some(serde_json::Value::Array(vs)) = p.get("vertices") {
                        for (v, xy) in vs.iter().enumerate() {
                            match xy {
                                serde_json::Value::Array(a) if a.len() != 2 => {
                                    return Err(locate(SceneError::at_field(
                                        SceneErrorKind::Shape,
                                        format!("polygons[{k}].vertices[{v}]"),
                                        format!(
                                            "expected a point [x, y], found an array of {} values",
                                            a.len()
                                        ),
                                    )))
                                }
                                _ => {}
                            }
                        }
                    }
                }
            }
            // Second pass: the typed form, straight from the text (exact locations).
            let raw: RawScreen =
                serde_json::from_str(text).map_err(|e| SceneError::from_json(json_kind(&e), &e))?;
            let scene = raw.into_scene().map_err(locate)?;
            scene.validate().map_err(locate)?;
            Ok(Scene::Screen(scene))
        }
        other => unreachable!("read_kind accepts only SCENE_KINDS, not {other}"),
    }
}

/// Reads and validates a scene file; every error names the file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = read_scene_text(path)?;
    parse_scene(&text).map_err(|e| e.in_file(path))
}

/// A scene file's text; a file that cannot be read is an [`SceneErrorKind::Io`] error
/// naming it (what every reader of scene files starts with), invalid UTF-8 is located by
/// byte, line and column, and a file larger than the memory budget
/// ([`crate::budget::Budget`]) is refused before it is read. A stream whose size is not
/// known (a FIFO, a device) is read up to the budget and refused past it.
pub fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    use std::io::Read;
    let fail =
        |message: String| SceneError::at_field(SceneErrorKind::Io, "", message).in_file(path);
    // the file's size against the memory budget before it is read whole
    let size = std::fs::metadata(path)
        .map_err(|e| fail(format!("cannot read the scene: {e}")))?
        .len();
    let budget = crate::budget::Budget::current();
    let what = "reading the scene file";
    budget
        .check_memory(what, size)
        .map_err(|e| fail(e.to_string()))?;
    let mut bytes = Vec::with_capacity(size as usize);
    std::fs::File::open(path)
        .and_then(|f| {
            f.take(budget.memory_bytes.saturating_add(1))
                .read_to_end(&mut bytes)
        })
        .map_err(|e| fail(format!("cannot read the scene: {e}")))?;
    budget
        .check_memory(what, bytes.len() as u64)
        .map_err(|e| fail(e.to_string()))?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let text = &e.as_bytes()[..at];
        let line = 1 + text.iter().filter(|&&b| b == b'\n').count();
        let column = 1 + text.iter().rev().take_while(|&&b| b != b'\n').count();
        fail(format!(
            "invalid UTF-8 at byte {at} (line {line}, column {column}): a scene file is UTF-8 JSON"
        ))
    })
}

/// A screen scene as the fast path of [`parse_scene`] reads it: [`RawScreen`] whose
/// `kind` is `"screen"` and whose polygons are JSON objects (serde would also take a
/// struct from an array, which the located reading refuses).
struct FastScreen(RawScreen);

impl<'de> Deserialize<'de> for FastScreen {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Fields {
            kind: String,
            width: u64,
            height: u64,
            channels: u64,
            polygons: Vec<ObjectPolygon>,
        }
        let f = Fields::deserialize(d)?;
        if f.kind != "screen" {
            return Err(serde::de::Error::custom("not a screen scene"));
        }
        Ok(FastScreen(RawScreen {
            kind: f.kind,
            width: f.width,
            height: f.height,
            channels: f.channels,
            polygons: f.polygons.into_iter().map(|p| p.0).collect(),
        }))
    }
}

/// A [`Polygon`] read from a JSON object only.
struct ObjectPolygon(Polygon);

impl<'de> Deserialize<'de> for ObjectPolygon {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = ObjectPolygon;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a polygon object")
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(
                self,
                map: M,
            ) -> Result<Self::Value, M::Error> {
                Polygon::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(ObjectPolygon)
            }
        }
        d.deserialize_map(Visit)
    }
}

/// The screen kind as it is read: sizes as `u64` so that a too-large one gets the
/// limit's message rather than the integer type's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScreen {
    #[allow(dead_code)]
    kind: String,
    width: u64,
    height: u64,
    channels: u64,
    polygons: Vec<Polygon>,
}

impl RawScreen {
    fn into_scene(self) -> Result<ScreenScene, SceneError> {
        let side = |name: &str, v: u64| {
            if (1..=u64::from(MAX_SIDE)).contains(&v) {
                Ok(v as u32)
            } else {
                Err(SceneError::at_field(
                    SceneErrorKind::Limit,
                    name,
                    format!("{name} {v} is outside 1..={MAX_SIDE} pixels"),
                ))
            }
        };
        let width = side("width", self.width)?;
        let height = side("height", self.height)?;
        if !(1..=u64::from(MAX_CHANNELS)).contains(&self.channels) {
            return Err(channels_error(self.channels));
        }
        Ok(ScreenScene {
            width,
            height,
            channels: self.channels as u8,
            polygons: self.polygons,
        })
    }
}

fn channels_error(channels: u64) -> SceneError {
    SceneError::at_field(
        SceneErrorKind::Limit,
        "channels",
        format!("channels {channels} is outside 1..={MAX_CHANNELS} (1 grey, 3 RGB)"),
    )
}

/// Checks the intensity of polygon `k`'s vertex `v`: every value finite and at most
/// [`MAX_INTENSITY`] in magnitude; a fault names its JSON path
/// (`polygons[k].intensity[v]`, or `…[v][c]` for a value beyond the limit). What
/// [`ScreenScene::validate`] asks of every intensity, for code that draws scenes it did not
/// read (`cwisim-render` checks scenes built in code with it).
pub fn check_intensity(k: usize, v: usize, values: &[f64]) -> Result<(), SceneError> {
    if let Some(bad) = values.iter().find(|c| !c.is_finite()) {
        return Err(SceneError::at_field(
            SceneErrorKind::NonFinite,
            format!("polygons[{k}].intensity[{v}]"),
            format!("expected a finite intensity, found {bad}"),
        ));
    }
    if let Some((c, big)) = values
        .iter()
        .enumerate()
        .find(|(_, c)| c.abs() > MAX_INTENSITY)
    {
        return Err(SceneError::at_field(
            SceneErrorKind::Limit,
            format!("polygons[{k}].intensity[{v}][{c}]"),
            format!(
                "intensity {big:e} is beyond ±{MAX_INTENSITY:e}, the limit that keeps the renderers' arithmetic finite (intensities are nominally 0 to 1)"
            ),
        ));
    }
    Ok(())
}

impl ScreenScene {
    /// The channel count as a `usize`.
    pub fn channel_count(&self) -> usize {
        usize::from(self.channels)
    }

    /// The scene as its file: pretty, deterministic JSON (one polygon per object, each
    /// vertex list on one line) that [`parse_scene`] reads back to an equal scene, every
    /// `f64` bit for bit. Non-finite numbers (which [`validate`](Self::validate) refuses)
    /// are written as `null`.
    pub fn to_json(&self) -> String {
        fn num(v: f64) -> String {
            serde_json::to_string(&v).expect("an f64 always serializes")
        }
        fn list<T>(items: &[T], f: impl Fn(&T) -> String) -> String {
            let parts: Vec<String> = items.iter().map(f).collect();
            format!("[{}]", parts.join(", "))
        }
        let mut out = String::new();
        out.push_str("{\n  \"kind\": \"screen\",\n");
        out.push_str(&format!("  \"width\": {},\n", self.width));
        out.push_str(&format!("  \"height\": {},\n", self.height));
        out.push_str(&format!("  \"channels\": {},\n", self.channels));
        if self.polygons.is_empty() {
            out.push_str("  \"polygons\": []\n}\n");
            return out;
        }
        out.push_str("  \"polygons\": [\n");
        for (k, p) in self.polygons.iter().enumerate() {
            let vertices = list(&p.vertices, |v| list(v, |&x| num(x)));
            let intensity = list(&p.intensity, |v| list(v, |&x| num(x)));
            out.push_str("    {\n");
            out.push_str(&format!("      \"vertices\": {vertices},\n"));
            match &p.depth {
                Some(depth) => {
                    out.push_str(&format!("      \"intensity\": {intensity},\n"));
                    out.push_str(&format!("      \"depth\": {}\n", list(depth, |&x| num(x))));
                }
                None => out.push_str(&format!("      \"intensity\": {intensity}\n")),
            }
            out.push_str(if k + 1 == self.polygons.len() {
                "    }\n"
            } else {
                "    },\n"
            });
        }
        out.push_str("  ]\n}\n");
        out
    }

    /// Checks every rule of a screen scene; the first fault found, with its JSON path.
    ///
    /// * `width`, `height` in `1..=MAX_SIDE`; `channels` in `1..=MAX_CHANNELS`;
    ///   `width × height × channels ≤ MAX_VALUES`.
    /// * Every polygon: at least 3 vertices, finite, `|x|, |y| ≤ MAX_COORDINATE`; one
    ///   intensity vector per vertex, each of `channels` finite values of magnitude at
    ///   most `MAX_INTENSITY`.
    /// * `depth`, when given: one finite value per vertex, on every polygon or on none.
    /// * Every polygon is simple: no two non-adjacent edges cross or touch, and no two
    ///   adjacent edges overlap (a vertex that doubles back). Zero-length edges (repeated
    ///   consecutive vertices) are allowed and do not count as touching their
    ///   neighbours; a polygon whose vertices all lie on one line (zero area, covers
    ///   nothing) is allowed as it is. The tests are exact (adaptive-precision
    ///   orientation), unless products of coordinates underflow (|coordinates| below
    ///   about 1e-150).
    pub fn validate(&self) -> Result<(), SceneError> {
        use SceneErrorKind as K;
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if v == 0 || v > MAX_SIDE {
                return Err(SceneError::at_field(
                    K::Limit,
                    name,
                    format!("{name} {v} is outside 1..={MAX_SIDE} pixels"),
                ));
            }
        }
        if self.channels == 0 || self.channels > MAX_CHANNELS {
            return Err(channels_error(u64::from(self.channels)));
        }
        let values = u64::from(self.width) * u64::from(self.height) * u64::from(self.channels);
        if values > MAX_VALUES {
            return Err(SceneError::at_field(
                K::Limit,
                "",
                format!(
                    "the image would hold {} × {} × {} = {values} values; the limit is {MAX_VALUES} (2^28)",
                    self.width, self.height, self.channels
                ),
            ));
        }
        let channels = self.channel_count();
        for (k, p) in self.polygons.iter().enumerate() {
            let n = p.vertices.len();
            if n < 3 {
                return Err(SceneError::at_field(
                    K::Shape,
                    format!("polygons[{k}].vertices"),
                    format!("polygon {k} has {n} vertices; a polygon needs at least 3"),
                ));
            }
            for (v, xy) in p.vertices.iter().enumerate() {
                let field = || format!("polygons[{k}].vertices[{v}]");
                if let Some(bad) = xy.iter().find(|c| !c.is_finite()) {
                    return Err(SceneError::at_field(
                        K::NonFinite,
                        field(),
                        format!("expected a finite coordinate, found {bad}"),
                    ));
                }
                if let Some(big) = xy.iter().find(|c| c.abs() > MAX_COORDINATE) {
                    return Err(SceneError::at_field(
                        K::Limit,
                        field(),
                        format!(
                            "coordinate {big:e} is beyond ±{MAX_COORDINATE:e}, where f64 can no longer resolve a pixel"
                        ),
                    ));
                }
            }
            if p.intensity.len() != n {
                return Err(SceneError::at_field(
                    K::Shape,
                    format!("polygons[{k}].intensity"),
                    format!(
                        "expected one intensity vector per vertex ({n}), found {}",
                        p.intensity.len()
                    ),
                ));
            }
            for (v, i) in p.intensity.iter().enumerate() {
                let field = || format!("polygons[{k}].intensity[{v}]");
                if i.len() != channels {
                    return Err(SceneError::at_field(
                        K::Shape,
                        field(),
                        format!(
                            "expected {channels} value{} (the scene's channels), found {}",
                            if channels == 1 { "" } else { "s" },
                            i.len()
                        ),
                    ));
                }
                check_intensity(k, v, i)?;
            }
            if p.depth.is_some() != self.polygons[0].depth.is_some() {
                return Err(SceneError::at_field(
                    K::Shape,
                    format!("polygons[{k}]"),
                    format!(
                        "polygon {k} {} depth but polygon 0 {}: a scene's polygons all carry depth or none do",
                        if p.depth.is_some() { "has" } else { "has no" },
                        if p.depth.is_some() { "has none" } else { "has" },
                    ),
                ));
            }
            if let Some(depth) = &p.depth {
                if depth.len() != n {
                    return Err(SceneError::at_field(
                        K::Shape,
                        format!("polygons[{k}].depth"),
                        format!("expected one depth per vertex ({n}), found {}", depth.len()),
                    ));
                }
                if let Some((v, bad)) = depth.iter().enumerate().find(|(_, d)| !d.is_finite()) {
                    return Err(SceneError::at_field(
                        K::NonFinite,
                        format!("polygons[{k}].depth[{v}]"),
                        format!("expected a finite depth, found {bad}"),
                    ));
                }
            }
            if let Some(fault) = simplicity_fault(&p.vertices) {
                return Err(SceneError::at_field(
                    K::SelfIntersection,
                    format!("polygons[{k}].vertices"),
                    format!("polygon {k} is not simple: {fault} (edge k runs from vertex k to vertex k+1)"),
                ));
            }
        }
        Ok(())
    }
}
