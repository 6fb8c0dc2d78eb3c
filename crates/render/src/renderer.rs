//! The renderer interface: what every Y-processor program gives the pipeline.
//!
//! A [`Renderer`] is built once per scene and settings (see [`crate::registry`]). It says
//! what it draws into ([`Renderer::header`]) and how many frames; for each frame it makes
//! a [`FramePlan`] — whatever it prepares once per frame, shared by every thread — from
//! which any band of pixel rows can be emitted, independently, into any [`TraceWrite`].
//! The bands' streams, concatenated in row order, are the frame's stream: that is what
//! lets the pipeline emit bands on threads and stay byte-identical to one thread.
//!
//! What a renderer counts ([`Counters`]: its own figures, by name) is summed over bands
//! and frames and printed generically: by `cwisim render`'s summary, `--stats-json` and
//! `cwisim tradeoff`.

use crate::error::RenderError;
use cwisim_isa::{TraceHeader, TraceWrite};
use cwisim_xproc::numeric::Numeric;
use cwisim_xproc::{Image, RunStats};
use serde::ser::SerializeMap;
use std::io;
use std::ops::Range;
use std::time::Duration;

/// A Y-processor program: a scene, made ready, that emits the instructions of its frames.
///
/// `Sync`: one renderer is shared by the threads that emit bands of it.
pub trait Renderer: Sync {
    /// The name it is registered under (`--renderer NAME`).
    fn name(&self) -> &'static str;

    /// The array it draws into: width (processors), lines per frame, channels.
    fn header(&self) -> TraceHeader;

    /// How many frames it draws (progressive renderers draw several; each is a complete
    /// frame, since the array keeps nothing from one frame to the next).
    fn frames(&self) -> u32 {
        1
    }

    /// Whether [`Self::frame`] needs the previous frame's output (the image the array
    /// shifted out). The pipeline then keeps one frame's image and runs frames one after
    /// the other.
    fn needs_previous_frame(&self) -> bool {
        false
    }

    /// The plan of frame `index` (`0..frames()`). `previous` is frame `index − 1`'s output
    /// when [`Self::needs_previous_frame`] says so and `index > 0`.
    fn frame<'a>(
        &'a self,
        index: u32,
        previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError>;

    /// What the summary says of the settings it used, as one phrase: "Gouraud shading,
    /// box filter, exact visibility".
    fn settings_phrase(&self) -> String;

    /// Summary rows of its own (label, text), such as the host side's geometry and
    /// visibility figures; `counters` and `stats` are the whole run's.
    fn summary_rows(&self, _counters: &Counters, _stats: &RunStats) -> Vec<(&'static str, String)> {
        Vec::new()
    }

    /// Wall time of the host-side stages it ran before emitting, by name, in order
    /// (e.g. "transform & lighting", "visibility").
    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        Vec::new()
    }

    /// What it drew, for `--stats-json`: deterministic (no times, no paths).
    fn scene_json(&self) -> serde_json::Value {
        serde_json::Value::Null
    }

    /// The most memory its frames hold while they are emitted on `threads` threads, in
    /// bytes, beyond what is built and the image the array shifts out: checked against
    /// the memory budget (`CWISIM_MAX_MEMORY`) before the first scanline. The default, 0,
    /// is for renderers whose frames are made before they are emitted (their fragments
    /// or pieces are part of what is built) and send them a row at a time.
    fn frame_memory(&self, _threads: usize) -> u64 {
        0
    }

    /// Refuses a numeric format its stream is not meant for, saying why (a study mode
    /// that relies on exact cancellation in `f64`, say). `render` asks before anything is
    /// sent; the default accepts every format.
    fn check_numeric(&self, _numeric: &Numeric) -> Result<(), String> {
        Ok(())
    }
}

/// One frame, made ready: any band of its rows can be emitted, on any thread.
pub trait FramePlan: Sync {
    /// What belongs to the whole frame rather than to a band (polygons, trapezia, …).
    /// Asked after the frame's rows are emitted (a renderer may make them as they are).
    fn counters(&self) -> Counters {
        Counters::default()
    }

    /// Emits pixel rows `rows` into `sink`, each ending with its `Refresh`; the counts of
    /// this band only. Emitting `0..lines` in one call, or in consecutive bands, gives the
    /// same stream.
    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters>;

    /// The renderer's own figures per pixel row of this frame, for `--stats-json`
    /// (`"renderer_rows"`): an array with one object per row, or `None` when it keeps
    /// none. Deterministic: no times. Asked after the frame's rows are emitted.
    fn row_figures(&self) -> Option<serde_json::Value> {
        None
    }
}

/// A renderer's own figures, by name, in the order first counted. Adding counters adds
/// them name by name; a name one side lacks counts as 0.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    entries: Vec<(&'static str, u64)>,
}

impl Counters {
    /// Adds `value` to the counter `name` (created at the end if new).
    pub fn add(&mut self, name: &'static str, value: u64) {
        match self.entries.iter_mut().find(|(n, _)| *n == name) {
            Some((_, v)) => *v += value,
            None => self.entries.push((name, value)),
        }
    }

    /// The counters with `name` set to `value` (builder form).
    pub fn with(mut self, name: &'static str, value: u64) -> Self {
        self.add(name, value);
        self
    }

    /// Adds every counter of `other`.
    pub fn merge(&mut self, other: &Counters) {
        for &(name, value) in &other.entries {
            self.add(name, value);
        }
    }

    /// The value of `name`, if counted.
    pub fn get(&self, name: &str) -> Option<u64> {
        self.entries
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, v)| v)
    }

    /// Every counter, in order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, u64)> + '_ {
        self.entries.iter().copied()
    }

    /// Whether nothing is counted.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

/// A JSON object, name → value. (JSON objects are unordered: `serde_json` documents
/// come out with their keys sorted; the summary and `tradeoff`'s CSV keep the renderer's
/// order.)
impl serde::Serialize for Counters {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.entries.len()))?;
        for (name, value) in &self.entries {
            map.serialize_entry(name, value)?;
        }
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counters_add_by_name_and_keep_their_order() {
        let mut a = Counters::default().with("polygons", 2).with("rows", 5);
        let b = Counters::default().with("rows", 1).with("claims", 3);
        a.merge(&b);
        assert_eq!(
            a.iter().collect::<Vec<_>>(),
            [("polygons", 2), ("rows", 6), ("claims", 3)]
        );
        assert_eq!(a.get("rows"), Some(6));
        assert_eq!(a.get("nothing"), None);
        assert_eq!(
            serde_json::to_string(&a).unwrap(),
            r#"{"polygons":2,"rows":6,"claims":3}"#
        );
    }
}
