//! Scene files: what to draw, as JSON.
//!
//! A scene file is one JSON object whose `kind` says how to read the rest. The one kind so
//! far is `"screen"` ([`ScreenScene`]): polygons already in screen space, with one
//! intensity vector per vertex.
//!
//! ```json
//! {
//!   "kind": "screen",
//!   "width": 64, "height": 48, "channels": 1,
//!   "polygons": [
//!     { "vertices": [[10.5, 3.25], [40.0, 3.25], [30.0, 20.0]],
//!       "intensity": [[1.0], [0.5], [0.25]] }
//!   ]
//! }
//! ```
//!
//! Coordinates: x grows to the right, y downward; pixel column `i` covers `[i, i+1)`,
//! pixel row `j` covers `[j, j+1)`, and row 0 is the first scanline output.
//!
//! [`parse_scene`] / [`load_scene`] read a scene and check it ([`ScreenScene::validate`]);
//! every fault is a [`SceneError`] naming the file, the line and column, the JSON path
//! (`polygons[3].intensity[1]`) where it applies, what was expected and what was found.
//! [`ScreenScene::to_json`] writes a scene back, deterministically and losslessly.
//!
//! Other kinds live in the crates that draw them (the 3D `"world"` scenes: `cwisim-world`);
//! their readers build on [`read_kind`], [`locate_error`] and [`json_error`], so that every
//! kind's errors look alike.
//!
//! ```
//! use cwisim_ypipe::scene::{parse_scene, Scene};
//! let text = r#"{"kind": "screen", "width": 4, "height": 3, "channels": 1,
//!   "polygons": [{"vertices": [[0, 0], [4, 0], [0, 3]], "intensity": [[1], [0], [0]]}]}"#;
//! let Scene::Screen(s) = parse_scene(text).unwrap();
//! assert_eq!((s.width, s.height, s.polygons.len()), (4, 3, 1));
//! assert_eq!(parse_scene(&s.to_json()).unwrap(), Scene::Screen(s));
//!
//! let err = parse_scene(r#"{"kind": "solid"}"#).unwrap_err();
//! assert_eq!(err.to_string(), r#"1:10: kind: unknown scene kind "solid"; expected "screen""#);
//! ```

use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

/// The scene kinds this build reads, as the `kind` key names them.
pub const SCENE_KINDS: &[&str] = &["screen"];
/// The widest image, and the tallest (pixels).
pub const MAX_SIDE: u32 = 65_536;
/// The most channels per intensity.
pub const MAX_CHANNELS: u8 = 4;
/// The most values (`width × height × channels`) an image may hold: 2^28.
pub const MAX_VALUES: u64 = 1 << 28;
/// The largest coordinate magnitude accepted. At 1e15 the spacing of `f64` is 0.125
/// pixel; beyond it a coordinate can no longer resolve a pixel.
pub const MAX_COORDINATE: f64 = 1e15;

/// A polygon with an intensity vector per vertex.
///
/// Edge `k` runs from vertex `k` to vertex `k + 1` (the last edge closes the polygon).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Polygon {
    /// The vertices `[x, y]`, in either orientation.
    pub vertices: Vec<[f64; 2]>,
    /// `intensity[vertex][channel]`: one vector per vertex.
    pub intensity: Vec<Vec<f64>>,
}

impl Polygon {
    /// A polygon with one intensity vector per vertex.
    pub fn new(vertices: Vec<[f64; 2]>, intensity: Vec<Vec<f64>>) -> Self {
        Polygon {
            vertices,
            intensity,
        }
    }

    /// A polygon with the same intensity vector at every vertex.
    pub fn uniform(vertices: Vec<[f64; 2]>, intensity: &[f64]) -> Self {
        let n = vertices.len();
        Polygon {
            vertices,
            intensity: vec![intensity.to_vec(); n],
        }
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

/// What kind of fault a scene has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SceneErrorKind {
    /// Reading the file failed.
    Io,
    /// Malformed JSON, or a number that overflows `f64`.
    Syntax,
    /// A key that is unknown, missing or repeated, or a value of the wrong type.
    Schema,
    /// An unknown `kind`.
    Kind,
    /// A size, channel count or coordinate outside the limits.
    Limit,
    /// Too few vertices, or intensities that do not match the vertices or channels.
    Shape,
    /// NaN or an infinity (possible only in scenes built in code).
    NonFinite,
    /// A polygon whose edges cross, touch or overlap.
    SelfIntersection,
    /// A world scene whose geometry cannot be drawn: a degenerate face, a non-convex
    /// face, an empty mesh, or a camera inside or behind an object.
    Geometry,
}

/// A scene that cannot be used: where, what kind of fault, and what was expected.
///
/// Displayed as `FILE:LINE:COL: FIELD: message`, leaving out whatever is unknown (a scene
/// built in code has no file, line or column; a syntax error has no field).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}", self.render())]
pub struct SceneError {
    /// The file, when known.
    pub path: Option<PathBuf>,
    /// 1-based line, when the scene came from text.
    pub line: Option<u64>,
    /// 1-based column (in bytes), when the scene came from text.
    pub column: Option<u64>,
    /// The JSON path of the offending value (`polygons[3].intensity[1]`), when known.
    pub field: Option<String>,
    /// The kind of fault.
    pub kind: SceneErrorKind,
    /// One line saying what was expected and what was found.
    pub message: String,
}

impl SceneError {
    /// An error about the value at the JSON path `field` (empty: the whole scene).
    pub fn at_field(
        kind: SceneErrorKind,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        let field = field.into();
        SceneError {
            path: None,
            line: None,
            column: None,
            field: (!field.is_empty()).then_some(field),
            kind,
            message: message.into(),
        }
    }

    /// The same error, naming the file.
    pub fn in_file(mut self, path: &Path) -> Self {
        self.path = Some(path.to_path_buf());
        self
    }

    fn at_offset(mut self, text: &str, offset: usize) -> Self {
        let (line, column) = line_column(text, offset);
        self.line = Some(line);
        self.column = Some(column);
        self
    }

    fn from_json(kind: SceneErrorKind, e: &serde_json::Error) -> Self {
        let full = e.to_string();
        let suffix = format!(" at line {} column {}", e.line(), e.column());
        let mut message = full.strip_suffix(&suffix).unwrap_or(&full).to_string();
        if message == "number out of range" {
            message.push_str(": it overflows f64 (numbers must be finite, at most about 1.8e308)");
        }
        SceneError {
            path: None,
            line: Some(e.line() as u64),
            column: Some(e.column().max(1) as u64),
            field: None,
            kind,
            message,
        }
    }

    fn render(&self) -> String {
        let mut out = String::new();
        if let Some(p) = &self.path {
            out.push_str(&p.display().to_string());
        }
        if let (Some(l), Some(c)) = (self.line, self.column) {
            if self.path.is_some() {
                out.push(':');
            }
            out.push_str(&format!("{l}:{c}"));
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        if let Some(f) = &self.field {
            out.push_str(f);
            out.push_str(": ");
        }
        out.push_str(&self.message);
        out
    }
}

/// Reads a scene from JSON text and validates it.
///
/// Syntax and type errors are located by the JSON parser; the faults of [`validate`]
/// (`ScreenScene::validate`) are located at the value their JSON path names.
///
/// [`validate`]: ScreenScene::validate
pub fn parse_scene(text: &str) -> Result<Scene, SceneError> {
    let kind = read_kind(text, SCENE_KINDS)?;
    let locate = |e: SceneError| locate_error(text, e);
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

/// Reads the `kind` of a scene file's text and checks it is one of `known`: the first
/// step of every reader of scene files (this crate's screen scenes, and the readers of
/// other kinds that build on it). Errors are located in `text`.
pub fn read_kind(text: &str, known: &[&str]) -> Result<String, SceneError> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| SceneError::from_json(json_kind(&e), &e))?;
    let locate = |e: SceneError| locate_error(text, e);
    let serde_json::Value::Object(root) = &value else {
        return Err(locate(SceneError::at_field(
            SceneErrorKind::Schema,
            "",
            format!(
                "expected a scene object {{\"kind\": …}}, found {}",
                describe(&value)
            ),
        )));
    };
    let kinds = known
        .iter()
        .map(|k| format!("\"{k}\""))
        .collect::<Vec<_>>()
        .join(" or ");
    match root.get("kind") {
        None => Err(locate(SceneError::at_field(
            SceneErrorKind::Schema,
            "",
            format!("missing field `kind`; expected {kinds}"),
        ))),
        Some(serde_json::Value::String(k)) if known.contains(&k.as_str()) => Ok(k.clone()),
        Some(serde_json::Value::String(k)) => Err(locate(SceneError::at_field(
            SceneErrorKind::Kind,
            "kind",
            format!(
                "unknown scene kind {}; expected {kinds}",
                serde_json::Value::from(k.as_str())
            ),
        ))),
        Some(other) => Err(locate(SceneError::at_field(
            SceneErrorKind::Schema,
            "kind",
            format!("expected a string ({kinds}), found {}", describe(other)),
        ))),
    }
}

/// Gives `e` the line and column, in `text`, of the value its JSON path names (of the
/// scene's first token when it names none). A path that is not in `text` leaves `e`
/// unlocated.
pub fn locate_error(text: &str, e: SceneError) -> SceneError {
    let offset = e
        .field
        .as_deref()
        .map_or(Some(first_token(text)), |f| locate(text, f));
    match offset {
        Some(o) => e.at_offset(text, o),
        None => e,
    }
}

/// A `serde_json` error while reading a scene, located (line and column) and typed
/// ([`SceneErrorKind::Syntax`], or [`SceneErrorKind::Schema`] for a wrong type or key).
pub fn json_error(e: &serde_json::Error) -> SceneError {
    SceneError::from_json(json_kind(e), e)
}

/// What a JSON value is, for messages: "a number", "an array", …
pub fn describe_json(v: &serde_json::Value) -> &'static str {
    describe(v)
}

/// Reads and validates a scene file; every error names the file.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        SceneError::at_field(
            SceneErrorKind::Io,
            "",
            format!("cannot read the scene: {e}"),
        )
        .in_file(path)
    })?;
    parse_scene(&text).map_err(|e| e.in_file(path))
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
            out.push_str(&format!("      \"intensity\": {intensity}\n"));
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
    ///   intensity vector per vertex, each of `channels` finite values.
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
                if let Some(bad) = i.iter().find(|c| !c.is_finite()) {
                    return Err(SceneError::at_field(
                        K::NonFinite,
                        field(),
                        format!("expected a finite intensity, found {bad}"),
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

// ---------------------------------------------------------------------------------------
// Simplicity: exact orientation and segment tests.

/// `a + b` as `(sum, error)`, exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a × b` as `(product, error)`, exactly (barring underflow).
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// The exact sign of `(b - a) × (c - a)`: positive when `a, b, c` turn one way, negative
/// the other, zero when collinear. Sums the six products of the expanded determinant as a
/// nonoverlapping expansion (Shewchuk's grow-expansion), whose largest component has the
/// sign of the exact sum.
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    // Shewchuk's filter: the rounded determinant when its error bound proves the sign
    let left = (a[0] - c[0]) * (b[1] - c[1]);
    let right = (a[1] - c[1]) * (b[0] - c[0]);
    let det = left - right;
    let sum = if left > 0.0 && right > 0.0 {
        left + right
    } else if left < 0.0 && right < 0.0 {
        -left - right
    } else {
        0.0
    };
    const BOUND: f64 = (3.0 + 16.0 * f64::EPSILON / 2.0) * f64::EPSILON / 2.0;
    if (sum == 0.0 && det != 0.0) || (sum.is_finite() && det.abs() > BOUND * sum) {
        return if det > 0.0 { 1 } else { -1 };
    }
    let terms = [
        (b[0], c[1]),
        (-b[0], a[1]),
        (-a[0], c[1]),
        (-b[1], c[0]),
        (a[0], b[1]),
        (a[1], c[0]),
    ];
    let mut expansion: Vec<f64> = Vec::with_capacity(12);
    let mut grow = |x: f64| {
        let mut q = x;
        let mut next = Vec::with_capacity(expansion.len() + 1);
        for &e in &expansion {
            let (s, err) = two_sum(q, e);
            if err != 0.0 {
                next.push(err);
            }
            q = s;
        }
        if q != 0.0 {
            next.push(q);
        }
        expansion = next;
    };
    for (x, y) in terms {
        let (p, e) = two_product(x, y);
        grow(e);
        grow(p);
    }
    let top = expansion.last().copied().unwrap_or(0.0);
    if top > 0.0 {
        1
    } else if top < 0.0 {
        -1
    } else {
        0
    }
}

/// Whether `p`, collinear with segment `a b`, lies on it (closed).
fn within(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    (0..2).all(|k| a[k].min(b[k]) <= p[k] && p[k] <= a[k].max(b[k]))
}

/// How closed segments `p` and `q` meet: `None`, `Some(true)` for a proper crossing,
/// `Some(false)` for touching (an endpoint on the other segment, or collinear overlap).
fn segments_meet(p: ([f64; 2], [f64; 2]), q: ([f64; 2], [f64; 2])) -> Option<bool> {
    for k in 0..2 {
        let (plo, phi) = (p.0[k].min(p.1[k]), p.0[k].max(p.1[k]));
        let (qlo, qhi) = (q.0[k].min(q.1[k]), q.0[k].max(q.1[k]));
        if phi < qlo || qhi < plo {
            return None;
        }
    }
    let o1 = orient(p.0, p.1, q.0);
    let o2 = orient(p.0, p.1, q.1);
    let o3 = orient(q.0, q.1, p.0);
    let o4 = orient(q.0, q.1, p.1);
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return Some(true);
    }
    let touches = (o1 == 0 && within(p.0, p.1, q.0))
        || (o2 == 0 && within(p.0, p.1, q.1))
        || (o3 == 0 && within(q.0, q.1, p.0))
        || (o4 == 0 && within(q.0, q.1, p.1));
    touches.then_some(false)
}

/// Why the closed polygon `v` is not simple, naming its edges; `None` when it is simple
/// (or all its vertices lie on one line).
fn simplicity_fault(v: &[[f64; 2]]) -> Option<String> {
    let n = v.len();
    // The distinct-vertex cycle: drop repeats of the previous vertex (cyclically). Each
    // kept vertex remembers the original edge that leaves its last repeat.
    let start = (0..n).find(|&k| v[k] != v[(k + n - 1) % n])?; // None: all one point
    let mut kept: Vec<usize> = Vec::new();
    for s in 0..n {
        let k = (start + s) % n;
        if v[k] != v[(k + n - 1) % n] {
            kept.push(k);
        }
    }
    let m = kept.len();
    let pts: Vec<[f64; 2]> = kept.iter().map(|&k| v[k]).collect();
    // original index of the edge from kept vertex i to kept vertex i+1
    let edge_id: Vec<usize> = (0..m).map(|i| (kept[(i + 1) % m] + n - 1) % n).collect();
    // all on one line: zero area, allowed
    let (a, b) = (pts[0], pts[1]);
    if pts.iter().all(|&p| orient(a, b, p) == 0) {
        return None;
    }
    let edge = |i: usize| (pts[i], pts[(i + 1) % m]);
    let name = |i: usize, j: usize| {
        let (x, y) = (edge_id[i].min(edge_id[j]), edge_id[i].max(edge_id[j]));
        (x, y)
    };
    // adjacent edges a→b, b→c overlap when c lies back along b→a
    for i in 0..m {
        let (a, b, c) = (pts[i], pts[(i + 1) % m], pts[(i + 2) % m]);
        if orient(a, b, c) == 0 {
            let k = if a[0] != b[0] { 0 } else { 1 };
            if (a[k] < b[k]) == (c[k] < b[k]) {
                let (x, y) = name(i, (i + 1) % m);
                return Some(format!(
                    "adjacent edges {x} and {y} overlap at vertex {}",
                    kept[(i + 1) % m]
                ));
            }
        }
    }
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue; // adjacent through the closing vertex
            }
            if let Some(cross) = segments_meet(edge(i), edge(j)) {
                let (x, y) = name(i, j);
                let how = if cross { "cross" } else { "touch" };
                return Some(format!("edges {x} and {y} {how}"));
            }
        }
    }
    None
}

// ---------------------------------------------------------------------------------------
// Locating a JSON path in the text.

fn json_kind(e: &serde_json::Error) -> SceneErrorKind {
    match e.classify() {
        serde_json::error::Category::Data => SceneErrorKind::Schema,
        _ => SceneErrorKind::Syntax,
    }
}

fn describe(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}

/// 1-based line and byte column of a byte offset.
fn line_column(text: &str, offset: usize) -> (u64, u64) {
    let before = &text.as_bytes()[..offset.min(text.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    (line as u64, (before.len() - start + 1) as u64)
}

fn first_token(text: &str) -> usize {
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

#[derive(Debug, PartialEq)]
enum Segment {
    Key(String),
    Index(usize),
}

/// Splits `polygons[3].intensity[1]` into its keys and indices.
fn segments(path: &str) -> Option<Vec<Segment>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if !key.is_empty() {
            out.push(Segment::Key(key.to_string()));
        }
        while let Some(r) = rest.strip_prefix('[') {
            let close = r.find(']')?;
            out.push(Segment::Index(r[..close].parse().ok()?));
            rest = &r[close + 1..];
        }
        if !rest.is_empty() {
            return None;
        }
    }
    Some(out)
}

/// The byte offset where the value at JSON path `path` starts in `text` (valid JSON).
fn locate(text: &str, path: &str) -> Option<usize> {
    let b = text.as_bytes();
    let mut i = first_token(text);
    let ws = |i: &mut usize| {
        while *i < b.len() && b[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    for seg in segments(path)? {
        match seg {
            Segment::Key(key) => {
                if b.get(i) != Some(&b'{') {
                    return None;
                }
                i += 1;
                loop {
                    ws(&mut i);
                    if b.get(i) != Some(&b'"') {
                        return None;
                    }
                    let end = skip_string(b, i)?;
                    let name: String = serde_json::from_str(&text[i..end]).ok()?;
                    i = end;
                    ws(&mut i);
                    if b.get(i) != Some(&b':') {
                        return None;
                    }
                    i += 1;
                    ws(&mut i);
                    if name == key {
                        break;
                    }
                    i = skip_value(b, i)?;
                    ws(&mut i);
                    if b.get(i) != Some(&b',') {
                        return None;
                    }
                    i += 1;
                }
            }
            Segment::Index(n) => {
                if b.get(i) != Some(&b'[') {
                    return None;
                }
                i += 1;
                for _ in 0..n {
                    ws(&mut i);
                    i = skip_value(b, i)?;
                    ws(&mut i);
                    if b.get(i) != Some(&b',') {
                        return None;
                    }
                    i += 1;
                }
                ws(&mut i);
                if matches!(b.get(i), None | Some(b']')) {
                    return None;
                }
            }
        }
    }
    Some(i)
}

/// The offset just past the string starting at `i` (a `"`).
fn skip_string(b: &[u8], mut i: usize) -> Option<usize> {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            b'"' => return Some(i + 1),
            _ => i += 1,
        }
    }
    None
}

/// The offset just past the value starting at `i`.
fn skip_value(b: &[u8], mut i: usize) -> Option<usize> {
    match b.get(i)? {
        b'"' => skip_string(b, i),
        b'{' | b'[' => {
            let mut depth = 0usize;
            while i < b.len() {
                match b[i] {
                    b'"' => {
                        i = skip_string(b, i)?;
                        continue;
                    }
                    b'{' | b'[' => depth += 1,
                    b'}' | b']' => {
                        depth -= 1;
                        if depth == 0 {
                            return Some(i + 1);
                        }
                    }
                    _ => {}
                }
                i += 1;
            }
            None
        }
        _ => {
            while i < b.len() && !matches!(b[i], b',' | b']' | b'}') && !b[i].is_ascii_whitespace()
            {
                i += 1;
            }
            Some(i)
        }
    }
}

impl fmt::Display for Segment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Segment::Key(k) => write!(f, ".{k}"),
            Segment::Index(n) => write!(f, "[{n}]"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_split_and_locate() {
        assert_eq!(
            segments("polygons[3].intensity[1]").unwrap(),
            vec![
                Segment::Key("polygons".into()),
                Segment::Index(3),
                Segment::Key("intensity".into()),
                Segment::Index(1)
            ]
        );
        let s: String = segments("a[2].b")
            .unwrap()
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(s, ".a[2].b");
        let text = "{\"a\": [1, {\"x\": \"]}\"}, [2,\n  3]], \"b\": {\"c\": null}}";
        assert_eq!(&text[locate(text, "a[2][1]").unwrap()..][..1], "3");
        assert_eq!(&text[locate(text, "b.c").unwrap()..][..4], "null");
        assert_eq!(&text[locate(text, "a[1].x").unwrap()..][..4], "\"]}\"");
        assert_eq!(locate(text, "a[3]"), None);
        assert_eq!(locate(text, "z"), None);
        assert_eq!(line_column(text, locate(text, "a[2][1]").unwrap()), (2, 3));
    }

    #[test]
    fn orientation_is_exact() {
        assert_eq!(orient([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), 1);
        assert_eq!(orient([0.0, 0.0], [0.0, 1.0], [1.0, 0.0]), -1);
        // points on a line whose naive determinant rounds to nonzero
        let a = [0.1, 0.1];
        let b = [0.3, 0.3];
        let c = [1e15 / 3.0, 1e15 / 3.0];
        assert_eq!(orient(a, b, c), 0);
        // a perturbation far below the naive rounding error is still seen
        let c2 = [c[0], f64::from_bits(c[1].to_bits() + 1)];
        assert_eq!(orient(a, b, c2), 1);
        assert_eq!(orient(a, b, [0.5, 0.5 + 1e-17]), 0); // 0.5 + 1e-17 == 0.5
    }

    #[test]
    fn simplicity() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(simplicity_fault(&sq), None);
        let bow = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        assert_eq!(simplicity_fault(&bow).unwrap(), "edges 0 and 2 cross");
        let dup = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 0.0],
        ];
        assert_eq!(simplicity_fault(&dup), None);
        let line = [[0.0, 0.0], [2.0, 0.0], [1.0, 0.0]];
        assert_eq!(simplicity_fault(&line), None);
        let spike = [[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]];
        assert_eq!(
            simplicity_fault(&spike).unwrap(),
            "adjacent edges 0 and 1 overlap at vertex 1"
        );
        // a vertex touching a non-adjacent edge
        let touch = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [2.0, 0.0], [0.0, 4.0]];
        assert_eq!(simplicity_fault(&touch).unwrap(), "edges 0 and 2 touch");
    }
}
