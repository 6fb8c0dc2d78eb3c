//! `refine`: Bergman, Fuchs, Grant and Spach, *Image rendering by adaptive refinement*
//! (1986), on a display without a frame buffer. The paper refines one image in place;
//! the CWI array keeps nothing from one frame to the next (each `Refresh` shifts a
//! scanline out), so here **each phase is a complete frame**, re-sent from the host's
//! display list, in which a phase regenerates only the polygons or pixels it refines:
//!
//! 1. **flat** — every polygon at one intensity (the mean of its vertex intensities),
//!    point-sampled;
//! 2. **Gouraud** — polygons whose vertex-intensity range exceeds `--gouraud-threshold`
//!    Gouraud-shaded, the rest as in phase 1, point-sampled;
//! 3. **anti-aliasing** — pixels whose 3 × 3 neighbourhood range in the previous frame's
//!    output exceeds `--aa-threshold` box-filtered; every other pixel keeps the previous
//!    frame's value, re-sent as an `Eval0` claim (one per run of equal values) before the
//!    box filter's instructions, which the claimed (locked) processors then ignore.
//!
//! A screen scene (intensities only, nothing to light) is drawn as one frame: Gouraud
//! with the box filter, as `vanrij` draws it. Phong and the paper's earlier phases
//! (vertices, edges) are not built yet (docs/RENDERERS.md, "Adaptive refinement").

use crate::error::RenderError;
use crate::prepare::PolygonScene;
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::{Settings, Threshold};
use crate::source::LoadedScene;
use crate::vanrij;
use cwisim_isa::{Instruction, Intensity, TraceHeader, TraceWrite};
use cwisim_scene::{Antialias, Polygon, ScreenScene, Shading};
use cwisim_world::{AnyScene, Visibility};
use cwisim_xproc::{Image, RunStats};
use cwisim_ypipe::{emit_rows, header, Claim, Options, ScanPlan};
use std::io;
use std::ops::Range;
use std::time::Duration;

/// The registry's one line about it.
pub const ABOUT: &str =
    "Bergman et al.'s adaptive refinement: each phase a complete frame (flat, Gouraud above a threshold, box filter on pixels whose 3x3 range exceeds a threshold, the rest re-sent as Eval0 claims)";

/// A phase: one complete frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Every polygon at its mean intensity, point-sampled.
    Flat,
    /// Polygons above the Gouraud threshold Gouraud-shaded, point-sampled.
    Gouraud,
    /// Flagged pixels box-filtered, the rest claimed with the previous frame's values.
    Antialias,
    /// A screen scene: the polygons as given, Gouraud, box filter (one frame).
    Whole,
}

impl Phase {
    /// Its name in the summary.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Flat => "flat",
            Phase::Gouraud => "gouraud",
            Phase::Antialias => "anti-aliasing",
            Phase::Whole => "whole",
        }
    }

    /// Counter: instructions it emitted.
    fn instructions(self) -> &'static str {
        match self {
            Phase::Flat => "flat_instructions",
            Phase::Gouraud => "gouraud_instructions",
            Phase::Antialias => "aa_instructions",
            Phase::Whole => "instructions",
        }
    }
}

/// The phases of a world scene, in order.
pub const WORLD_PHASES: [Phase; 3] = [Phase::Flat, Phase::Gouraud, Phase::Antialias];

/// The polygon at one intensity: the mean of its vertex intensities, per channel (the
/// flat value every renderer takes, `cwisim_ypipe::flat_mean`).
pub fn flattened(p: &Polygon) -> Polygon {
    let channels = p.intensity.first().map_or(0, Vec::len);
    let mean = cwisim_ypipe::flat_mean(&p.intensity, channels)[..channels].to_vec();
    Polygon {
        vertices: p.vertices.clone(),
        intensity: vec![mean; p.intensity.len()],
        depth: p.depth.clone(),
    }
}

/// The polygon's vertex-intensity range: the largest, over channels, of max − min over
/// its vertices (the Gouraud test's measure).
pub fn intensity_range(p: &Polygon) -> f64 {
    let channels = p.intensity.first().map_or(0, Vec::len);
    (0..channels)
        .map(|c| {
            let (lo, hi) = p
                .intensity
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v[c]), hi.max(v[c]))
                });
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// The anti-aliasing test: for each pixel of `image` (`lines × width`), whether the range
/// (max − min, largest over channels) of its 3 × 3 neighbourhood, clipped to the image,
/// passes `threshold`.
pub fn aa_flags(image: &Image, lines: usize, threshold: Threshold) -> Vec<bool> {
    let (w, ch) = (image.width, image.channels);
    let mut flags = vec![false; w * lines];
    for y in 0..lines {
        for x in 0..w {
            let mut range = 0.0f64;
            for c in 0..ch {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for ny in y.saturating_sub(1)..(y + 2).min(lines) {
                    for nx in x.saturating_sub(1)..(x + 2).min(w) {
                        let v = image.data[(ny * w + nx) * ch + c];
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
                range = range.max(hi - lo);
            }
            flags[y * w + x] = threshold.passes(range);
        }
    }
    flags
}

/// A pixel's values as bits: runs are of bit-identical values, so that a claim re-sends
/// exactly what the array output (`-0.0` is not `+0.0`).
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Adaptive refinement on a scene's polygons.
#[derive(Clone, Debug)]
pub struct Refine {
    scene: PolygonScene,
    /// Phase 1's polygons.
    flat: ScreenScene,
    /// Phase 2's polygons.
    gouraud: ScreenScene,
    /// How many polygons phase 2 Gouraud-shades.
    gouraud_polygons: u64,
    phases: Vec<Phase>,
    gouraud_threshold: Threshold,
    aa_threshold: Threshold,
}

impl Refine {
    /// The refinement of `loaded` under `settings`.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<Refine, RenderError> {
        let loaded = loaded.drawn_as(settings)?;
        if settings.shading != Shading::Gouraud {
            return Err(RenderError::Usage(format!(
                "--renderer refine chooses each phase's shading itself (flat, then Gouraud above --gouraud-threshold); --shading {} does not apply: leave it at gouraud",
                settings.shading
            )));
        }
        if settings.visibility != Visibility::Exact {
            return Err(RenderError::Usage(
                "--renderer refine draws exact visible fragments (its phases re-send them per polygon): use --visibility exact".into(),
            ));
        }
        if settings.aa != Antialias::Box {
            return Err(RenderError::Usage(
                "--renderer refine point-samples its first phases and box-filters in its last: --aa does not apply, leave it at box".into(),
            ));
        }
        let world = matches!(loaded.scene, AnyScene::World(_));
        let scene = PolygonScene::new(loaded, settings)?;
        let mut flat = scene.screen.clone();
        let mut gouraud = scene.screen.clone();
        let mut gouraud_polygons = 0;
        for (k, p) in scene.screen.polygons.iter().enumerate() {
            flat.polygons[k] = flattened(p);
            if settings.gouraud_threshold.passes(intensity_range(p)) {
                gouraud_polygons += 1;
            } else {
                gouraud.polygons[k] = flat.polygons[k].clone();
            }
        }
        let phases = if world {
            WORLD_PHASES.to_vec()
        } else {
            vec![Phase::Whole]
        };
        Ok(Refine {
            scene,
            flat,
            gouraud,
            gouraud_polygons,
            phases,
            gouraud_threshold: settings.gouraud_threshold,
            aa_threshold: settings.aa_threshold,
        })
    }

    /// For the registry.
    pub fn build(
        loaded: LoadedScene,
        settings: &Settings,
    ) -> Result<Box<dyn Renderer>, RenderError> {
        Ok(Box::new(Refine::new(loaded, settings)?))
    }

    /// Its frames, in order.
    pub fn phases(&self) -> &[Phase] {
        &self.phases
    }

    /// The polygons phase 2 Gouraud-shades.
    pub fn gouraud_polygons(&self) -> u64 {
        self.gouraud_polygons
    }

    /// The polygons of every phase as prepared (the full-quality scene).
    pub fn polygons(&self) -> &PolygonScene {
        &self.scene
    }
}

const POINT: Options = Options {
    shading: Shading::Gouraud,
    aa: Antialias::None,
    claim: Claim::Accumulate,
};

const BOX: Options = Options {
    shading: Shading::Gouraud,
    aa: Antialias::Box,
    claim: Claim::Accumulate,
};

/// A point-sampled or whole frame: a scene through DO_FILL.
struct Drawn<'a> {
    plan: ScanPlan<'a>,
    options: &'static Options,
    phase: Phase,
    regenerated: u64,
}

impl FramePlan for Drawn<'_> {
    fn counters(&self) -> Counters {
        let c = Counters::default();
        match self.phase {
            Phase::Whole => vanrij::counters(&self.plan.scene_stats()),
            Phase::Gouraud => c.with("gouraud_polygons", self.regenerated),
            _ => c,
        }
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let e = emit_rows(&self.plan, self.options, rows, sink)?;
        Ok(match self.phase {
            Phase::Whole => vanrij::counters(&e),
            p => Counters::default().with(p.instructions(), e.instructions),
        })
    }
}

/// The anti-aliasing frame: per row, the previous frame's unflagged pixels claimed with
/// `Eval0`, then (in rows with a flagged pixel) the box filter's instructions.
struct Antialiased<'a> {
    plan: ScanPlan<'a>,
    previous: &'a Image,
    flags: Vec<bool>,
    width: usize,
}

impl FramePlan for Antialiased<'_> {
    fn counters(&self) -> Counters {
        Counters::default().with(
            "aa_pixels",
            self.flags.iter().filter(|&&f| f).count() as u64,
        )
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let (w, ch) = (self.width, self.previous.channels);
        let mut claims = 0u64;
        let mut instructions = 0u64;
        for row in rows {
            let r = row as usize;
            let flags = &self.flags[r * w..(r + 1) * w];
            let value = |x: usize| &self.previous.data[(r * w + x) * ch..(r * w + x + 1) * ch];
            let mut x = 0;
            while x < w {
                if flags[x] {
                    x += 1;
                    continue;
                }
                // a run of equal values (bit for bit: a NaN, which equals nothing, is a
                // run of one)
                let start = x;
                x += 1;
                while x < w && !flags[x] && same_bits(value(x), value(start)) {
                    x += 1;
                }
                sink.write(&Instruction::eval0(
                    start as u32,
                    (x - start) as u32,
                    Intensity::new(value(start)),
                ))?;
                claims += 1;
            }
            if flags.iter().any(|&f| f) {
                instructions += emit_rows(&self.plan, &BOX, row..row + 1, sink)?.instructions;
            } else {
                sink.write(&Instruction::refresh())?;
                instructions += 1;
            }
        }
        Ok(Counters::default()
            .with("aa_claims", claims)
            .with("aa_instructions", instructions + claims))
    }
}

impl Renderer for Refine {
    fn name(&self) -> &'static str {
        "refine"
    }

    fn header(&self) -> TraceHeader {
        header(&self.scene.screen)
    }

    fn frames(&self) -> u32 {
        self.phases.len() as u32
    }

    fn needs_previous_frame(&self) -> bool {
        self.phases.contains(&Phase::Antialias)
    }

    fn frame<'a>(
        &'a self,
        index: u32,
        previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        let phase = *self.phases.get(index as usize).ok_or_else(|| {
            RenderError::Usage(format!(
                "refine has {} frame(s); frame {index} asked for",
                self.phases.len()
            ))
        })?;
        let drawn = |scene: &'a ScreenScene, options: &'static Options, regenerated| {
            Box::new(Drawn {
                plan: ScanPlan::new(scene, options),
                options,
                phase,
                regenerated,
            })
        };
        Ok(match phase {
            Phase::Whole => drawn(&self.scene.screen, &BOX, 0),
            Phase::Flat => drawn(&self.flat, &POINT, 0),
            Phase::Gouraud => drawn(&self.gouraud, &POINT, self.gouraud_polygons),
            Phase::Antialias => {
                let h = self.header();
                let previous = previous.ok_or_else(|| {
                    RenderError::Usage(
                        "refine's anti-aliasing phase draws from the previous frame's output: run it through the array (`cwisim render`)".into(),
                    )
                })?;
                let (w, lines) = (h.width as usize, h.lines as usize);
                if previous.width != w
                    || previous.channels != h.channel_count()
                    || previous.data.len() != w * lines * previous.channels
                {
                    return Err(RenderError::Usage(format!(
                        "refine's previous frame is {}×{} with {} channel(s); expected {w}×{lines} with {}",
                        previous.width,
                        previous.data.len() / (previous.width * previous.channels).max(1),
                        previous.channels,
                        h.channel_count()
                    )));
                }
                Box::new(Antialiased {
                    plan: ScanPlan::new(&self.scene.screen, &BOX),
                    previous,
                    flags: aa_flags(previous, lines, self.aa_threshold),
                    width: w,
                })
            }
        })
    }

    fn settings_phrase(&self) -> String {
        if self.phases == [Phase::Whole] {
            return "a screen scene: one frame, Gouraud shading, box filter (exact)".into();
        }
        format!(
            "adaptive refinement: flat, Gouraud above range {}, box filter where the 3x3 range exceeds {} (point sampling before), exact visibility",
            self.gouraud_threshold, self.aa_threshold
        )
    }

    fn summary_rows(&self, counters: &Counters, stats: &RunStats) -> Vec<(&'static str, String)> {
        let mut rows = self.scene.summary_rows();
        if self.phases == [Phase::Whole] {
            return rows;
        }
        let pixels = u64::from(self.header().lines) * u64::from(self.header().width);
        let polygons = self.scene.screen.polygons.len() as u64;
        for (k, phase) in self.phases.iter().enumerate() {
            let frame = stats.lines.iter().filter(|l| l.frame == k as u64);
            let (busy, worst) = frame.fold((0u64, 0u64), |(b, w), l| {
                (b + l.busy_cycles, w.max(l.busy_cycles))
            });
            let what = match phase {
                Phase::Flat => format!("flat: {polygons} polygons at one intensity, {pixels} pixels"),
                Phase::Gouraud => format!(
                    "Gouraud: {} of {polygons} polygons Gouraud-shaded",
                    counters.get("gouraud_polygons").unwrap_or(0)
                ),
                Phase::Antialias => format!(
                    "anti-aliasing: {} of {pixels} pixels box-filtered ({:.1}%), {} Eval0 claims re-send the rest",
                    counters.get("aa_pixels").unwrap_or(0),
                    100.0 * counters.get("aa_pixels").unwrap_or(0) as f64 / pixels.max(1) as f64,
                    counters.get("aa_claims").unwrap_or(0)
                ),
                Phase::Whole => String::new(),
            };
            let label: &'static str = match phase {
                Phase::Flat => "phase 1",
                Phase::Gouraud => "phase 2",
                Phase::Antialias => "phase 3",
                Phase::Whole => "phase",
            };
            rows.push((
                label,
                format!(
                    "{what}; {} instructions, {busy} busy cycles (worst scanline {worst} of the line period {})",
                    counters.get(phase.instructions()).unwrap_or(0),
                    stats.line_period
                ),
            ));
        }
        rows
    }

    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        self.scene.stage_times()
    }

    fn scene_json(&self) -> serde_json::Value {
        let mut j = self.scene.scene_json();
        j["phases"] = serde_json::json!(self.phases.iter().map(|p| p.name()).collect::<Vec<_>>());
        j["gouraud_polygons"] = serde_json::json!(self.gouraud_polygons);
        j
    }
}
