//! A script of user events for an interactive session (Bergman et al.'s "we start a new
//! image whenever new user input is received"): the camera or a light moved at given
//! times, in the simulated display's cycles or frames.
//!
//! ```json
//! {
//!   "unit": "frames",
//!   "end": 12,
//!   "events": [
//!     { "at": 2.5, "camera": { "eye": [1, 6, 9] } },
//!     { "at": 4, "light": 0, "position": [2, 8, 3] }
//!   ]
//! }
//! ```
//!
//! `unit` is `cycles` or `frames` (a display frame: its scanlines and its vertical
//! blanking lines, times the line period);
//! `end` is when the session ends; each event's `at` is after the one before and before
//! `end`. A `camera` event sets any of `eye`, `target`, `up`, `fov_y`; a `light` event
//! sets light `light`'s `position` or `intensity` (or both). Changes add up: each event
//! changes the scene as the events before it left it. Every error is located: the file,
//! the line and column, and the JSON path (`events[1].at`).

use crate::scene::{PerChannel, WorldSpec};
use cwisim_scene::{json_error, locate_error, SceneError, SceneErrorKind};
use serde::Deserialize;

/// When the times of a script are counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Unit {
    /// The display's clock cycles.
    Cycles,
    /// Display frames: a frame's scanlines and blanking lines times the line period.
    Frames,
}

/// A camera moved: the fields given replace the camera's.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraChange {
    /// Where the camera is.
    pub eye: Option<[f64; 3]>,
    /// What it looks at.
    pub target: Option<[f64; 3]>,
    /// Which way is up.
    pub up: Option<[f64; 3]>,
    /// The vertical field of view, degrees.
    pub fov_y: Option<f64>,
}

/// What an event changes.
#[derive(Clone, Debug, PartialEq)]
pub enum Change {
    /// The camera.
    Camera(CameraChange),
    /// Light `index`: its position, its intensity, or both.
    Light {
        /// The light, by index into the scene's `lights`.
        index: usize,
        /// Its new position.
        position: Option<[f64; 3]>,
        /// Its new intensity.
        intensity: Option<PerChannel>,
    },
}

impl Change {
    /// A few words on what it changes (for a report).
    pub fn describe(&self) -> String {
        let v = |p: [f64; 3]| format!("[{}, {}, {}]", p[0], p[1], p[2]);
        match self {
            Change::Camera(c) => {
                let mut parts = Vec::new();
                if let Some(e) = c.eye {
                    parts.push(format!("eye {}", v(e)));
                }
                if let Some(t) = c.target {
                    parts.push(format!("target {}", v(t)));
                }
                if let Some(u) = c.up {
                    parts.push(format!("up {}", v(u)));
                }
                if let Some(f) = c.fov_y {
                    parts.push(format!("fov_y {f}"));
                }
                format!("camera {}", parts.join(", "))
            }
            Change::Light {
                index,
                position,
                intensity,
            } => {
                let mut parts = Vec::new();
                if let Some(p) = position {
                    parts.push(format!("position {}", v(*p)));
                }
                if intensity.is_some() {
                    parts.push("intensity".to_string());
                }
                format!("light {index} {}", parts.join(", "))
            }
        }
    }

    /// `spec` as this change leaves it; a light that `spec` does not have is refused,
    /// at `lights` (a change read against another scene).
    pub fn apply(&self, spec: &mut WorldSpec) -> Result<(), SceneError> {
        match self {
            Change::Camera(c) => {
                let cam = &mut spec.camera;
                cam.eye = c.eye.unwrap_or(cam.eye);
                cam.target = c.target.unwrap_or(cam.target);
                cam.up = c.up.unwrap_or(cam.up);
                cam.fov_y = c.fov_y.unwrap_or(cam.fov_y);
            }
            Change::Light {
                index,
                position,
                intensity,
            } => {
                let count = spec.lights.len();
                let Some(light) = spec.lights.get_mut(*index) else {
                    return Err(SceneError::at_field(
                        SceneErrorKind::Schema,
                        "lights",
                        format!("an event moves light {index}, and the scene has {count} light(s)"),
                    ));
                };
                if let Some(p) = position {
                    light.position = *p;
                }
                if let Some(i) = intensity {
                    light.intensity = i.clone();
                }
            }
        }
        Ok(())
    }
}

/// One event: at a time, a change.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// When, in the script's unit.
    pub at: f64,
    /// What it changes.
    pub change: Change,
}

/// A script of events.
#[derive(Clone, Debug, PartialEq)]
pub struct EventScript {
    /// The unit of `end` and each event's `at`.
    pub unit: Unit,
    /// When the session ends.
    pub end: f64,
    /// The events, in time order.
    pub events: Vec<Event>,
}

/// An event as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEvent {
    at: f64,
    camera: Option<CameraChange>,
    light: Option<usize>,
    position: Option<[f64; 3]>,
    intensity: Option<PerChannel>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScript {
    unit: Unit,
    end: f64,
    events: Vec<RawEvent>,
}

/// The most events a script may hold (each restarts a refinement: a run of the scene).
pub const MAX_EVENTS: usize = 10_000;

impl EventScript {
    /// The script in `text`, checked against `spec` (the scene the session starts from:
    /// a light event's light exists, and every scene an event leaves is valid). Errors
    /// are located in `text` (line, column and JSON path).
    pub fn parse(text: &str, spec: &WorldSpec) -> Result<EventScript, SceneError> {
        let raw: RawScript = serde_json::from_str(text).map_err(|e| json_error(&e))?;
        let locate = |field: String, kind: SceneErrorKind, message: String| {
            locate_error(text, SceneError::at_field(kind, field, message))
        };
        if !(raw.end.is_finite() && raw.end > 0.0) {
            return Err(locate(
                "end".into(),
                SceneErrorKind::Limit,
                format!(
                    "the session's end must be a positive number of {} (found {})",
                    unit_name(raw.unit),
                    raw.end
                ),
            ));
        }
        if raw.events.len() > MAX_EVENTS {
            return Err(locate(
                "events".into(),
                SceneErrorKind::Limit,
                format!(
                    "{} events; at most {MAX_EVENTS} (each restarts the refinement)",
                    raw.events.len()
                ),
            ));
        }
        let mut events = Vec::with_capacity(raw.events.len());
        let mut scene = spec.clone();
        let mut before = 0.0;
        for (k, e) in raw.events.into_iter().enumerate() {
            let at = |what: &str| format!("events[{k}]{what}");
            if !(e.at.is_finite() && e.at > before) {
                return Err(locate(
                    at(".at"),
                    SceneErrorKind::Limit,
                    format!(
                        "an event's time must be after {} ({}; the session starts at 0 with the scene as given): found {}",
                        if k == 0 { "0".to_string() } else { format!("events[{}]'s, {before}", k - 1) },
                        unit_name(raw.unit),
                        e.at
                    ),
                ));
            }
            if e.at >= raw.end {
                return Err(locate(
                    at(".at"),
                    SceneErrorKind::Limit,
                    format!(
                        "the event at {} {} is past the session's end ({})",
                        e.at,
                        unit_name(raw.unit),
                        raw.end
                    ),
                ));
            }
            before = e.at;
            let change = match (e.camera, e.light) {
                (Some(c), None) => {
                    if e.position.is_some() || e.intensity.is_some() {
                        return Err(locate(
                            at(""),
                            SceneErrorKind::Schema,
                            "a camera event sets the camera only: `position` and `intensity` belong to a light event (`\"light\": K`)".into(),
                        ));
                    }
                    if c == CameraChange::default() {
                        return Err(locate(
                            at(".camera"),
                            SceneErrorKind::Schema,
                            "a camera event changes nothing: give `eye`, `target`, `up` or `fov_y`".into(),
                        ));
                    }
                    Change::Camera(c)
                }
                (None, Some(index)) => {
                    if index >= spec.lights.len() {
                        return Err(locate(
                            at(".light"),
                            SceneErrorKind::Schema,
                            format!(
                                "light {index}: the scene has {} light(s)",
                                spec.lights.len()
                            ),
                        ));
                    }
                    if e.position.is_none() && e.intensity.is_none() {
                        return Err(locate(
                            at(""),
                            SceneErrorKind::Schema,
                            "a light event changes nothing: give `position` or `intensity`"
                                .into(),
                        ));
                    }
                    Change::Light {
                        index,
                        position: e.position,
                        intensity: e.intensity,
                    }
                }
                _ => {
                    return Err(locate(
                        at(""),
                        SceneErrorKind::Schema,
                        "an unknown event: give either `camera` (an object) or `light` (a light's index) with `position` or `intensity`".into(),
                    ))
                }
            };
            change
                .apply(&mut scene)
                .and_then(|()| scene.validate())
                .map_err(|inner| {
                    locate(
                        at(""),
                        inner.kind,
                        format!("the scene this event leaves: {}", inner),
                    )
                })?;
            events.push(Event { at: e.at, change });
        }
        Ok(EventScript {
            unit: raw.unit,
            end: raw.end,
            events,
        })
    }

    /// The scene of run `k` of the session (0: as given; `k`: after the first `k`
    /// events), `spec` the scene the script was read against.
    pub fn scene(&self, spec: &WorldSpec, k: usize) -> Result<WorldSpec, SceneError> {
        let mut out = spec.clone();
        for e in &self.events[..k] {
            e.change.apply(&mut out)?;
        }
        Ok(out)
    }
}

fn unit_name(u: Unit) -> &'static str {
    match u {
        Unit::Cycles => "cycles",
        Unit::Frames => "frames",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> WorldSpec {
        crate::scene::parse_world(crate::embedded::embedded("pot").unwrap().text, None)
            .unwrap()
            .spec
    }

    fn err(text: &str) -> String {
        EventScript::parse(text, &spec()).unwrap_err().to_string()
    }

    #[test]
    fn a_script_reads_its_events_in_order_and_they_add_up() {
        let text = r#"{"unit": "frames", "end": 10, "events": [
  {"at": 1.5, "camera": {"eye": [0, 3, 9]}},
  {"at": 4, "light": 0, "position": [5, 5, 5]}
]}"#;
        let s = EventScript::parse(text, &spec()).unwrap();
        assert_eq!(s.unit, Unit::Frames);
        assert_eq!(s.events.len(), 2);
        let two = s.scene(&spec(), 2).unwrap();
        assert_eq!(two.camera.eye, [0.0, 3.0, 9.0]);
        assert_eq!(two.lights[0].position, [5.0, 5.0, 5.0]);
        assert_eq!(s.scene(&spec(), 0).unwrap(), spec());
        assert_eq!(s.scene(&spec(), 1).unwrap().lights, spec().lights);
        // read against another scene, a light it lacks is refused, not a panic
        let mut dark = spec();
        dark.lights.clear();
        let e = s.scene(&dark, 2).unwrap_err().to_string();
        assert!(e.contains("lights: an event moves light 0"), "{e}");
    }

    #[test]
    fn bad_scripts_are_located_errors() {
        let e = err(r#"{"unit": "frames", "end": 10, "events": [
  {"at": 3, "camera": {"eye": [0, 3, 9]}},
  {"at": 2, "camera": {"eye": [0, 3, 8]}}
]}"#);
        assert!(e.starts_with("3:10: events[1].at: "), "{e}");
        assert!(e.contains("after events[0]'s, 3"), "{e}");
        let e = err(
            r#"{"unit": "cycles", "end": 1000, "events": [{"at": 1000, "camera": {"fov_y": 30}}]}"#,
        );
        assert!(
            e.contains("events[0].at") && e.contains("past the session's end"),
            "{e}"
        );
        let e = err(r#"{"unit": "frames", "end": 5, "events": [{"at": 1, "zoom": 2}]}"#);
        assert!(e.contains("unknown field `zoom`"), "{e}");
        let e = err(r#"{"unit": "frames", "end": 5, "events": [{"at": 1}]}"#);
        assert!(e.contains("events[0]: an unknown event"), "{e}");
        let e = err(
            r#"{"unit": "frames", "end": 5, "events": [{"at": 1, "light": 7, "position": [1, 2, 3]}]}"#,
        );
        assert!(e.contains("events[0].light: light 7"), "{e}");
        let e = err(r#"{"unit": "minutes", "end": 5, "events": []}"#);
        assert!(e.contains("unknown variant `minutes`"), "{e}");
        let e = err(r#"{"unit": "frames", "end": -1, "events": []}"#);
        assert!(e.contains("end: the session's end"), "{e}");
        // a camera the scene cannot take: inside the pot's geometry, looking at itself
        let e = err(
            r#"{"unit": "frames", "end": 5, "events": [{"at": 1, "camera": {"eye": [0, 0, 0], "target": [0, 0, 0]}}]}"#,
        );
        assert!(e.contains("events[0]: the scene this event leaves"), "{e}");
    }
}
