//! `refine`: Bergman, Fuchs, Grant and Spach, *Image rendering by adaptive refinement*
//! (1986), on a display without a frame buffer. The paper refines one image in place;
//! the CWI array keeps nothing from one frame to the next (each `Refresh` shifts a
//! scanline out), so here **each phase is a complete frame**, re-sent from the host's
//! display list ([`display`]), in which a phase regenerates only the polygons or pixels it
//! refines ([`frame`]):
//!
//! 0. optionally (`--phases`), the paper's first two: **vertices**, the model's corners as
//!    depth-cued points, and **edges**, its triangles' edges as depth-cued one-pixel
//!    lines ([`sketch`]);
//! 1. **flat** — every polygon at one intensity (the mean of its vertex intensities),
//!    point-sampled;
//! 2. **Gouraud** — polygons whose vertex-intensity range exceeds `--gouraud-threshold`
//!    Gouraud-shaded, the rest as in the previous frame, point-sampled;
//! 3. **Phong** — polygons passing the paper's highlight test (a corner's highlight
//!    vector within `--phong-angle` degrees of the direction to the eye,
//!    `cwisim_world::shade::PhongShader::highlight_angle`) lit per pixel, point-sampled;
//! 4. **anti-aliasing** — pixels whose 3 × 3 neighbourhood range in the previous frame's
//!    output exceeds `--aa-threshold` box-filtered (each polygon as the display list
//!    draws it); every other pixel keeps the previous frame's value: the previous
//!    frame's own instructions are re-sent with the flagged pixels masked (`Dis` before
//!    each Eval reaching them), then the box filter's with the others masked.
//!
//! When a light casts shadows, a **shadow** phase follows the flat one: the flat phase
//! draws every polygon as if every light reached it, and the shadow phase redraws the
//! shadow polygons (the exact pieces some light does not reach, `cwisim_world::shadow`)
//! without those lights' terms; the lights reaching each polygon stay with it (the
//! paper's pixel attribute buffer, per polygon here), so the later phases shade the
//! shadows too.
//!
//! A screen scene (intensities only, nothing to light) is drawn as one frame: Gouraud
//! with the box filter, as `vanrij` draws it.

pub mod display;
pub mod frame;
pub mod ids;
pub mod measure;
pub mod sketch;

pub use measure::{aa_flags, flattened, intensity_range};

use crate::error::RenderError;
use crate::prepare::PolygonScene;
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::{Settings, Threshold};
use crate::source::LoadedScene;
use cwisim_isa::TraceHeader;
use cwisim_scene::{Antialias, Shading};
use cwisim_world::shadow::LightSet;
use cwisim_world::{AnyScene, Visibility};
use cwisim_xproc::{Image, RunStats};
use cwisim_ypipe::{emit_rows, header, ScanPlan};
use display::{Mode, Subset};
use frame::{Antialiased, Part, Shaded, BOX};
use sketch::{Sketch, SketchFrame};
use std::io;
use std::ops::Range;
use std::time::Duration;

/// The registry's one line about it.
pub const ABOUT: &str =
    "Bergman et al.'s adaptive refinement: each phase a complete frame (flat, Gouraud above a range threshold, Phong within a highlight angle, box filter on pixels whose 3x3 range exceeds a threshold, the rest re-sent from the previous frame with Dis masks)";

/// A phase: one complete frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Phase {
    /// The model's vertices as depth-cued points.
    Vertices,
    /// The triangles' edges as depth-cued one-pixel lines.
    Edges,
    /// Every polygon at its mean intensity, point-sampled.
    Flat,
    /// The polygons in some light's shadow (the shadow polygons) drawn darker, the
    /// lights reaching each kept for the phases after (the paper's attribute buffer).
    Shadows,
    /// Polygons above the Gouraud threshold Gouraud-shaded, point-sampled.
    Gouraud,
    /// Polygons passing the highlight test lit per pixel, point-sampled.
    Phong,
    /// Flagged pixels box-filtered, the rest re-sent as the previous frame drew them.
    Antialias,
    /// A screen scene: the polygons as given, Gouraud, box filter (one frame).
    Whole,
}

impl Phase {
    /// Its name (in `--phases` and the summary).
    pub fn name(self) -> &'static str {
        match self {
            Phase::Vertices => "vertices",
            Phase::Edges => "edges",
            Phase::Flat => "flat",
            Phase::Shadows => "shadows",
            Phase::Gouraud => "gouraud",
            Phase::Phong => "phong",
            Phase::Antialias => "aa",
            Phase::Whole => "whole",
        }
    }

    /// The counter `what` (`instructions`, `regenerated`, `pixels`, `polygons` — for
    /// the vertex and edge phases, the points or lines drawn) of this phase:
    /// `gouraud_polygons`, `aa_instructions`, ….
    pub fn counter(self, what: &str) -> &'static str {
        const NAMES: [[&str; 4]; 8] = [
            [
                "vertices_instructions",
                "vertices_regenerated",
                "vertices_pixels",
                "vertices_drawn",
            ],
            [
                "edges_instructions",
                "edges_regenerated",
                "edges_pixels",
                "edges_drawn",
            ],
            [
                "flat_instructions",
                "flat_regenerated",
                "flat_pixels",
                "flat_polygons",
            ],
            [
                "shadows_instructions",
                "shadows_regenerated",
                "shadows_pixels",
                "shadows_polygons",
            ],
            [
                "gouraud_instructions",
                "gouraud_regenerated",
                "gouraud_pixels",
                "gouraud_polygons",
            ],
            [
                "phong_instructions",
                "phong_regenerated",
                "phong_pixels",
                "phong_polygons",
            ],
            [
                "aa_instructions",
                "aa_regenerated",
                "aa_pixels",
                "aa_polygons",
            ],
            ["instructions", "regenerated", "pixels", "polygons"],
        ];
        let row = match self {
            Phase::Vertices => 0,
            Phase::Edges => 1,
            Phase::Flat => 2,
            Phase::Shadows => 3,
            Phase::Gouraud => 4,
            Phase::Phong => 5,
            Phase::Antialias => 6,
            Phase::Whole => 7,
        };
        let col = match what {
            "instructions" => 0,
            "regenerated" => 1,
            "pixels" => 2,
            _ => 3,
        };
        NAMES[row][col]
    }
}

/// The most frames the vertex phase may be split into (`--vertex-fraction` 1/20).
pub const MAX_VERTEX_PARTS: u32 = 20;

macro_rules! vertex_part_names {
    ($($k:literal)*) => {
        /// The frame names and counter names (instructions, regenerated, pixels, points)
        /// of the vertex phase's first frames when it is split: `vertices-K`.
        const VERTEX_PARTS: [(&str, [&str; 4]); MAX_VERTEX_PARTS as usize - 1] = [$(
            (
                concat!("vertices-", $k),
                [
                    concat!("vertices_", $k, "_instructions"),
                    concat!("vertices_", $k, "_regenerated"),
                    concat!("vertices_", $k, "_pixels"),
                    concat!("vertices_", $k, "_drawn"),
                ],
            ),
        )*];
    };
}
vertex_part_names!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19);

/// `--vertex-fraction F`: how many frames the vertex phase is split into, `1/F`, each
/// adding a fraction `F` of the vertices (`F` must be `1/N`, `N` from 1 to
/// [`MAX_VERTEX_PARTS`]).
pub fn vertex_parts(fraction: f64) -> Result<u32, String> {
    let n = (1.0 / fraction).round();
    let admitted = fraction > 0.0
        && fraction <= 1.0
        && (1.0..=f64::from(MAX_VERTEX_PARTS)).contains(&n)
        && (n * fraction - 1.0).abs() <= 1e-9;
    if !admitted {
        return Err(format!(
            "--vertex-fraction {fraction}: expected 1/N for N from 1 to {MAX_VERTEX_PARTS} (0.1: ten frames, each adding a tenth of the vertices; 1: all at once)"
        ));
    }
    Ok(n as u32)
}

/// The phases of a world scene, in order.
pub const WORLD_PHASES: [Phase; 4] = [Phase::Flat, Phase::Gouraud, Phase::Phong, Phase::Antialias];

/// `--phases`: a comma-separated list of `vertices`, `edges`, `flat`, `shadows`,
/// `gouraud`, `phong`, `aa`, in that order, each at most once, with `flat` whenever a
/// later phase refines it.
pub fn parse_phases(list: &str) -> Result<Vec<Phase>, String> {
    const KNOWN: &str = "vertices, edges, flat, shadows, gouraud, phong, aa";
    let mut phases = Vec::new();
    for name in list.split(',').map(str::trim) {
        let phase = match name {
            "vertices" => Phase::Vertices,
            "edges" => Phase::Edges,
            "flat" => Phase::Flat,
            "gouraud" => Phase::Gouraud,
            "phong" => Phase::Phong,
            "aa" | "anti-aliasing" => Phase::Antialias,
            "shadows" => Phase::Shadows,
            _ => return Err(format!("--phases: unknown phase `{name}`; known: {KNOWN}")),
        };
        if phases.last().is_some_and(|&p| p >= phase) {
            return Err(format!(
                "--phases: `{name}` out of order or repeated; the phases run {KNOWN}, each at most once"
            ));
        }
        if phase > Phase::Flat && !phases.contains(&Phase::Flat) {
            return Err(format!(
                "--phases: `{name}` refines the flat frame: list `flat` before it"
            ));
        }
        phases.push(phase);
    }
    Ok(phases)
}

/// What one phase's frame draws.
#[derive(Clone, Debug)]
enum Plan {
    /// Kept polygons as the previous frame drew them, then the regenerated ones.
    Shaded {
        kept: Box<Subset>,
        refined: Box<Subset>,
    },
    /// The whole display list, box-filtered on flagged pixels.
    Antialias { list: Box<Subset> },
    /// Points or lines.
    Sketch(Box<Sketch>),
    /// A screen scene as `vanrij` draws it.
    Whole,
}

/// Adaptive refinement on a scene's polygons.
#[derive(Clone, Debug)]
pub struct Refine {
    scene: PolygonScene,
    phases: Vec<Phase>,
    plans: Vec<Plan>,
    /// How each polygon is drawn after the last shading phase.
    modes: Vec<Mode>,
    gouraud_polygons: u64,
    shadow_polygons: u64,
    phong_polygons: u64,
    /// Visible triangles (with a fragment in the display list) passing the highlight
    /// test, and how many are visible.
    highlight: (u64, u64),
    gouraud_threshold: Threshold,
    phong_angle: Threshold,
    aa_threshold: Threshold,
    shade_tolerance: f64,
    /// Frames the vertex phase is split into (1: all the vertices in one frame).
    vertex_parts: u32,
}

impl Refine {
    /// The refinement of `loaded` under `settings`, in every phase.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<Refine, RenderError> {
        Refine::with_phases(loaded, settings, &WORLD_PHASES)
    }

    /// The refinement of `loaded` under `settings` in `phases` (of a world scene; a screen
    /// scene is one frame). `phases` as [`parse_phases`] admits them.
    pub fn with_phases(
        loaded: LoadedScene,
        settings: &Settings,
        phases: &[Phase],
    ) -> Result<Refine, RenderError> {
        Refine::with_vertex_parts(loaded, settings, phases, 1)
    }

    /// [`Refine::with_phases`], the vertex phase (when `phases` has it) split into
    /// `parts` frames ([`vertex_parts`]): frame `j` of them draws the vertices whose index
    /// in the model's order of distinct corners is `j` or less modulo `parts`, so the first
    /// draws every `parts`-th vertex, spread over the whole model (the paper's Figure 5, a
    /// sparse sketch of all of it), and the last all of them (Figure 6).
    pub fn with_vertex_parts(
        loaded: LoadedScene,
        settings: &Settings,
        phases: &[Phase],
        parts: u32,
    ) -> Result<Refine, RenderError> {
        if !(1..=MAX_VERTEX_PARTS).contains(&parts) {
            return Err(RenderError::Usage(format!(
                "the vertex phase is split into 1 to {MAX_VERTEX_PARTS} frames, not {parts}"
            )));
        }
        if parts > 1 && !phases.contains(&Phase::Vertices) {
            return Err(RenderError::Usage(
                "--vertex-fraction splits the vertex phase: list `vertices` in --phases".into(),
            ));
        }
        let loaded = loaded.drawn_as(settings)?;
        if settings.shading != Shading::Gouraud {
            return Err(RenderError::Usage(format!(
                "--renderer refine chooses each phase's shading itself (flat, then Gouraud above --gouraud-threshold, Phong within --phong-angle); --shading {} does not apply: leave it at gouraud",
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
        let names: Vec<&str> = phases.iter().map(|p| p.name()).collect();
        let checked = parse_phases(&names.join(",")).map_err(RenderError::Usage)?;
        let world = matches!(loaded.scene, AnyScene::World(_));
        // a world scene is prepared for Phong (the same fragments and vertex intensities
        // as Gouraud, and the source triangle of each): every phase draws from it
        let prepared = Settings {
            shading: if world {
                Shading::Phong
            } else {
                Shading::Gouraud
            },
            ..*settings
        };
        let scene = PolygonScene::new(loaded, &prepared)?;
        let n = scene.screen.polygons.len();
        // the shadow phase runs after the flat one exactly when a light casts shadows
        let mut checked = checked;
        let casting = scene.shadows.is_some();
        if world && casting && !checked.contains(&Phase::Shadows) {
            if let Some(at) = checked.iter().position(|&p| p == Phase::Flat) {
                checked.insert(at + 1, Phase::Shadows);
            }
        }
        if world && !casting && checked.contains(&Phase::Shadows) {
            return Err(RenderError::Usage(
                "--phases shadows: no light of the scene casts shadows (give one \"shadows\": true, or render with --shadows on)".into(),
            ));
        }
        // the vertex phase's frames: `parts` of them
        if let Some(at) = checked.iter().position(|&p| p == Phase::Vertices) {
            for _ in 1..parts {
                checked.insert(at, Phase::Vertices);
            }
        }
        let mut refine = Refine {
            vertex_parts: if world { parts } else { 1 },
            phases: if world { checked } else { vec![Phase::Whole] },
            plans: Vec::new(),
            modes: vec![Mode::Flat; n],
            gouraud_polygons: 0,
            shadow_polygons: 0,
            phong_polygons: 0,
            highlight: (0, 0),
            gouraud_threshold: settings.gouraud_threshold,
            phong_angle: settings.phong_angle,
            aa_threshold: settings.aa_threshold,
            shade_tolerance: settings.shade_tolerance,
            scene,
        };
        if let Some(s) = &refine.scene.phong {
            // the triangles that show: those with a visible fragment
            let mut visible = s.sources.clone();
            visible.sort_unstable();
            visible.dedup();
            let passing = visible
                .iter()
                .filter(|&&k| {
                    let t = &s.triangles[k];
                    settings.phong_angle.admits(s.shader.highlight_angle(t))
                })
                .count();
            refine.highlight = (passing as u64, visible.len() as u64);
        }
        refine.plan();
        Ok(refine)
    }

    /// Each phase's plan, and the display list's modes as they end.
    fn plan(&mut self) {
        let scene = &self.scene;
        let n = scene.screen.polygons.len();
        // before a shadow phase, the flat phase draws every polygon as if lit by all
        let first = if self.phases.contains(&Phase::Shadows) {
            Mode::Unshadowed
        } else {
            Mode::Flat
        };
        // the lights that reach each polygon (every light without shadows)
        let shadowed = |k: usize| {
            scene
                .phong
                .as_ref()
                .and_then(|s| s.shadows.as_ref())
                .is_some_and(|l| l.lit[k] != LightSet::ALL)
        };
        let mut modes = vec![first; n];
        let mut plans = Vec::new();
        let mut vertex_frame = 0;
        for &phase in &self.phases {
            let next: Vec<Mode> = (0..n)
                .map(|k| {
                    let p = &scene.screen.polygons[k];
                    match phase {
                        Phase::Shadows if modes[k] == Mode::Unshadowed => Mode::Flat,
                        // a textured polygon's texture shows from the Gouraud phase on
                        Phase::Gouraud
                            if modes[k] == Mode::Flat
                                && (self.gouraud_threshold.passes(intensity_range(p))
                                    || display::is_textured(scene, k)) =>
                        {
                            Mode::Gouraud
                        }
                        Phase::Phong
                            if scene.phong.as_ref().is_some_and(|s| {
                                let t = &s.triangles[s.sources[k]];
                                self.phong_angle.admits(s.shader.highlight_angle(t))
                            }) =>
                        {
                            Mode::Phong
                        }
                        _ => modes[k],
                    }
                })
                .collect();
            // the shadow phase redraws the shadow polygons only: a polygon every light
            // reaches draws the same either way
            let changed: Vec<bool> = (0..n)
                .map(|k| match phase {
                    Phase::Flat => true,
                    Phase::Shadows => shadowed(k),
                    _ => next[k] != modes[k],
                })
                .collect();
            let regenerated = changed.iter().filter(|&&c| c).count() as u64;
            match phase {
                Phase::Shadows => self.shadow_polygons = regenerated,
                Phase::Gouraud => self.gouraud_polygons = regenerated,
                Phase::Phong => self.phong_polygons = regenerated,
                _ => {}
            }
            let (w, h) = (scene.screen.width, scene.screen.height);
            let triangles = scene.phong.as_ref().map_or(&[][..], |s| &s.triangles[..]);
            plans.push(match phase {
                Phase::Whole => Plan::Whole,
                Phase::Vertices => {
                    vertex_frame += 1;
                    Plan::Sketch(Box::new(Sketch::points_part(
                        triangles,
                        w,
                        h,
                        vertex_frame,
                        self.vertex_parts,
                    )))
                }
                Phase::Edges => Plan::Sketch(Box::new(Sketch::edges(triangles, w, h))),
                Phase::Antialias => Plan::Antialias {
                    list: Box::new(Subset::of(scene, &next, |_| true)),
                },
                _ => Plan::Shaded {
                    kept: Box::new(Subset::of(scene, &modes, |k| !changed[k])),
                    refined: Box::new(Subset::of(scene, &next, |k| changed[k])),
                },
            });
            modes = next;
        }
        self.plans = plans;
        self.modes = modes;
    }

    /// The polygon-ID view of the display list (its polygons in order, identifiers from
    /// 1), drawn one scanline at a time.
    pub fn id_view(&self) -> Result<ids::IdView, RenderError> {
        ids::IdView::new(&self.scene.screen)
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

    /// Which of a split vertex phase's frames before its last frame `k` is, from 0 (`None`:
    /// frame `k` is another phase's, or the vertex phase's last or only frame).
    fn vertex_parts_before(&self, k: usize) -> Option<usize> {
        let first = self.phases.iter().position(|&p| p == Phase::Vertices)?;
        let j = k.checked_sub(first)?;
        (j + 1 < self.vertex_parts as usize).then_some(j)
    }

    /// Frame `k`'s name: its phase's, or `vertices-J` for the `J`-th of a split vertex
    /// phase's frames but the last (which is `vertices`).
    pub fn frame_name(&self, k: usize) -> &'static str {
        match self.vertex_parts_before(k) {
            Some(j) => VERTEX_PARTS[j].0,
            None => self.phases.get(k).map_or("frame", |p| p.name()),
        }
    }

    /// Frame `k`'s counter `what` (as [`Phase::counter`]; a split vertex phase's frames
    /// have their own, `vertices_J_instructions`, …).
    pub fn frame_counter(&self, k: usize, what: &str) -> &'static str {
        match self.vertex_parts_before(k) {
            Some(j) => {
                let col = match what {
                    "instructions" => 0,
                    "regenerated" => 1,
                    "pixels" => 2,
                    _ => 3,
                };
                VERTEX_PARTS[j].1[col]
            }
            None => self
                .phases
                .get(k)
                .map_or("instructions", |p| p.counter(what)),
        }
    }

    /// The polygons the Gouraud phase Gouraud-shades.
    pub fn gouraud_polygons(&self) -> u64 {
        self.gouraud_polygons
    }

    /// The polygons (visible fragments) the Phong phase lights per pixel.
    pub fn phong_polygons(&self) -> u64 {
        self.phong_polygons
    }

    /// The visible triangles (those with a fragment in the display list) passing the
    /// highlight test, and how many are visible: the paper's Phong pass rate.
    pub fn highlight_pass(&self) -> (u64, u64) {
        self.highlight
    }

    /// How each polygon is drawn after the last shading phase.
    pub fn modes(&self) -> &[Mode] {
        &self.modes
    }

    /// The polygons of every phase as prepared (the full-quality scene).
    pub fn polygons(&self) -> &PolygonScene {
        &self.scene
    }
}

/// A screen scene's one frame: `vanrij`'s box filter.
struct Whole<'a> {
    plan: ScanPlan<'a>,
}

impl FramePlan for Whole<'_> {
    fn counters(&self) -> Counters {
        crate::vanrij::counters(&self.plan.scene_stats())
    }

    fn emit_rows(
        &self,
        rows: Range<u32>,
        sink: &mut dyn cwisim_isa::TraceWrite,
    ) -> io::Result<Counters> {
        emit_rows(&self.plan, &BOX, rows, sink).map(|e| crate::vanrij::counters(&e))
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
        let k = index as usize;
        let (Some(&phase), Some(plan)) = (self.phases.get(k), self.plans.get(k)) else {
            return Err(RenderError::Usage(format!(
                "refine has {} frame(s); frame {index} asked for",
                self.phases.len()
            )));
        };
        let tolerance = self.shade_tolerance;
        Ok(match plan {
            Plan::Sketch(sketch) => Box::new(SketchFrame {
                sketch,
                channels: self.header().channel_count(),
                names: ["instructions", "regenerated", "pixels", "polygons"]
                    .map(|what| self.frame_counter(k, what)),
            }),
            Plan::Whole => Box::new(Whole {
                plan: ScanPlan::new(&self.scene.screen, &BOX),
            }),
            Plan::Shaded { kept, refined } => Box::new(Shaded {
                phase,
                kept: Part::of(kept, Antialias::None, tolerance),
                refined: Part::of(refined, Antialias::None, tolerance),
                refined_polygons: refined.polygons,
            }),
            Plan::Antialias { list } => {
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
                let flags = aa_flags(previous, lines, self.aa_threshold);
                // the previous frame's own parts, in the order it sent them
                let previous_parts = match k.checked_sub(1).and_then(|j| self.plans.get(j)) {
                    Some(Plan::Shaded { kept, refined }) => {
                        let mut parts = Part::of(kept, Antialias::None, tolerance);
                        parts.extend(Part::of(refined, Antialias::None, tolerance));
                        parts
                    }
                    _ => {
                        return Err(RenderError::Usage(
                            "refine's anti-aliasing phase follows a shading phase (flat, gouraud or phong)".into(),
                        ))
                    }
                };
                Box::new(Antialiased {
                    parts: Part::of(list, Antialias::Box, tolerance),
                    previous_parts,
                    width: w,
                    fragments: measure::aa_fragments(&self.scene.screen, &flags),
                    flags,
                })
            }
        })
    }

    fn settings_phrase(&self) -> String {
        if self.phases == [Phase::Whole] {
            return "a screen scene: one frame, Gouraud shading, box filter (exact)".into();
        }
        let names: Vec<&str> = self.phases.iter().map(|p| p.name()).collect();
        format!(
            "adaptive refinement ({}): Gouraud above range {}, Phong within {}° of the highlight, box filter where the 3x3 range exceeds {} (point sampling before), exact visibility",
            names.join(", "),
            self.gouraud_threshold,
            self.phong_angle,
            self.aa_threshold
        )
    }

    fn summary_rows(&self, counters: &Counters, stats: &RunStats) -> Vec<(&'static str, String)> {
        const LABELS: [&str; 30] = [
            "phase 1", "phase 2", "phase 3", "phase 4", "phase 5", "phase 6", "phase 7", "phase 8",
            "phase 9", "phase 10", "phase 11", "phase 12", "phase 13", "phase 14", "phase 15",
            "phase 16", "phase 17", "phase 18", "phase 19", "phase 20", "phase 21", "phase 22",
            "phase 23", "phase 24", "phase 25", "phase 26", "phase 27", "phase 28", "phase 29",
            "phase 30",
        ];
        let mut rows = self.scene.summary_rows();
        if self.phases == [Phase::Whole] {
            return rows;
        }
        let pixels = u64::from(self.header().lines) * u64::from(self.header().width);
        let polygons = self.scene.screen.polygons.len() as u64;
        let get = |name: &str| counters.get(name).unwrap_or(0);
        for (k, phase) in self.phases.iter().enumerate() {
            let frame = stats.lines.iter().filter(|l| l.frame == k as u64);
            let (busy, worst) = frame.fold((0u64, 0u64), |(b, w), l| {
                (b + l.busy_cycles, w.max(l.busy_cycles))
            });
            let what = match phase {
                Phase::Vertices => format!(
                    "{}: {} depth-cued points, {} pixels",
                    self.frame_name(k),
                    get(self.frame_counter(k, "drawn")),
                    get(self.frame_counter(k, "pixels"))
                ),
                Phase::Edges => format!(
                    "edges: {} depth-cued lines, {} pixels",
                    get("edges_drawn"),
                    get("edges_pixels")
                ),
                Phase::Flat if self.phases.contains(&Phase::Shadows) => format!(
                    "flat: {polygons} polygons at one intensity, every light reaching"
                ),
                Phase::Flat => format!("flat: {polygons} polygons at one intensity"),
                Phase::Shadows => format!(
                    "shadows: {} of {polygons} polygons in some light's shadow redrawn without its terms (the lights reaching each kept for the later phases)",
                    get("shadows_polygons")
                ),
                Phase::Gouraud => format!(
                    "Gouraud: {} of {polygons} polygons Gouraud-shaded",
                    get("gouraud_polygons")
                ),
                Phase::Phong => format!(
                    "Phong: {} of {polygons} polygons lit per pixel ({} of {} visible triangles within the highlight angle)",
                    get("phong_polygons"),
                    self.highlight.0,
                    self.highlight.1
                ),
                Phase::Antialias => format!(
                    "anti-aliasing: {} of {pixels} pixels box-filtered ({:.1}%), {} fragments, {} Dis masks (the previous frame re-sent around them)",
                    get("aa_pixels"),
                    100.0 * get("aa_pixels") as f64 / pixels.max(1) as f64,
                    get("aa_fragments"),
                    get("aa_masks")
                ),
                Phase::Whole => String::new(),
            };
            rows.push((
                LABELS[k.min(LABELS.len() - 1)],
                format!(
                    "{what}; {} instructions ({} regenerated), {busy} busy cycles (worst scanline {worst} of the line period {})",
                    get(self.frame_counter(k, "instructions")),
                    get(self.frame_counter(k, "regenerated")),
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
        j["shadow_polygons"] = serde_json::json!(self.shadow_polygons);
        j["phong_polygons"] = serde_json::json!(self.phong_polygons);
        j
    }
}
