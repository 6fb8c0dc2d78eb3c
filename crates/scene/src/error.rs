//! Scene errors: what is wrong, and where — the file, the line and column, the JSON path.
//!
//! Every reader of scene files (screen scenes here, world scenes in `cwisim-world`, and
//! any kind to come) builds on [`read_kind`], [`locate_error`] and [`json_error`], so that
//! every kind's errors look alike: `FILE:LINE:COL: FIELD: message`.

use crate::locate::{first_token, line_column, locate};
use std::path::{Path, PathBuf};

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

    pub(crate) fn at_offset(mut self, text: &str, offset: usize) -> Self {
        let (line, column) = line_column(text, offset);
        self.line = Some(line);
        self.column = Some(column);
        self
    }

    pub(crate) fn from_json(kind: SceneErrorKind, e: &serde_json::Error) -> Self {
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

    /// One printable line: control characters the input put into the message or the
    /// path are written as escapes (`cwisim_isa::printable`).
    fn render(&self) -> String {
        cwisim_isa::printable(&self.render_raw()).into_owned()
    }

    fn render_raw(&self) -> String {
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

pub(crate) fn json_kind(e: &serde_json::Error) -> SceneErrorKind {
    match e.classify() {
        serde_json::error::Category::Data => SceneErrorKind::Schema,
        _ => SceneErrorKind::Syntax,
    }
}

pub(crate) fn describe(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}
