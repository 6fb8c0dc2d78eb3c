//! `vanrij`: van Rij's Y-processor (CWI report CS-R9427) — polygons into trapezia, the
//! active edge table grouped by Identifier, DO_FILL's twelve cases of box-filter coverage
//! (or point sampling), flat or Gouraud, optionally claiming covered pixels with `Eval0`.
//! A thin adapter over `cwisim-ypipe`, where the scan conversion lives.

use crate::error::RenderError;
use crate::phong::PhongFrame;
use crate::prepare::PolygonScene;
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::Settings;
use crate::source::LoadedScene;
use cwisim_isa::{TraceHeader, TraceWrite};
use cwisim_scene::Antialias;
use cwisim_world::Visibility;
use cwisim_xproc::{Image, RunStats};
use cwisim_ypipe::{emit_rows, header, Claim, EmitStats, Options, ScanPlan};
use std::io;
use std::ops::Range;
use std::time::Duration;

/// The registry's one line about it.
pub const ABOUT: &str =
    "van Rij's DO_FILL (CWI CS-R9427): trapezia, exact box-filter coverage in twelve cases, flat or Gouraud, Eval0 claims; Phong lit per pixel through the span fitter";

/// DO_FILL's counter names for cases 1–12.
const CASES: [&str; 12] = [
    "case_1", "case_2", "case_3", "case_4", "case_5", "case_6", "case_7", "case_8", "case_9",
    "case_10", "case_11", "case_12",
];

/// van Rij's Y-processor on a scene's polygons.
#[derive(Clone, Debug)]
pub struct VanRij {
    scene: PolygonScene,
    options: Options,
    /// The span fitter's tolerance (Phong shading).
    shade_tolerance: f64,
}

impl VanRij {
    /// The polygons of `loaded` as `settings` say (a world scene projected, lit and its
    /// hidden surfaces removed first).
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<VanRij, RenderError> {
        let loaded = loaded.drawn_as(settings)?;
        let scene = PolygonScene::new(loaded, settings)?;
        Ok(VanRij::from_polygons(scene, settings))
    }

    /// The renderer of polygons already prepared.
    pub fn from_polygons(scene: PolygonScene, settings: &Settings) -> VanRij {
        let claim = match scene.visibility_mode {
            Some(Visibility::Eval0) => Claim::Eval0 {
                tolerance: settings.eval0_tolerance,
            },
            _ => Claim::Accumulate,
        };
        VanRij {
            scene,
            options: Options {
                shading: settings.shading,
                aa: settings.aa,
                claim,
            },
            shade_tolerance: settings.shade_tolerance,
        }
    }

    /// For the registry.
    pub fn build(
        loaded: LoadedScene,
        settings: &Settings,
    ) -> Result<Box<dyn Renderer>, RenderError> {
        Ok(Box::new(VanRij::new(loaded, settings)?))
    }

    /// The polygons it draws, and what preparing them did.
    pub fn polygons(&self) -> &PolygonScene {
        &self.scene
    }

    /// The Y-processor's options.
    pub fn options(&self) -> &Options {
        &self.options
    }
}

/// DO_FILL's statistics as counters.
pub fn counters(e: &EmitStats) -> Counters {
    let mut c = Counters::default()
        .with("polygons", e.polygons)
        .with("trapezia", e.trapezia)
        .with("rows_filled", e.rows_filled);
    for (name, n) in CASES.iter().zip(e.cases) {
        c.add(name, n);
    }
    c.with("single_pixels", e.single_pixels)
        .with("middle_parts", e.middle_parts)
        .with("sequences", e.sequences)
        .with("share_sequences", e.share_sequences)
        .with("claims", e.claims)
        .with("instructions", e.instructions)
}

struct Frame<'a> {
    plan: ScanPlan<'a>,
    options: &'a Options,
}

impl FramePlan for Frame<'_> {
    fn counters(&self) -> Counters {
        counters(&self.plan.scene_stats())
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        emit_rows(&self.plan, self.options, rows, sink).map(|e| counters(&e))
    }
}

impl Renderer for VanRij {
    fn name(&self) -> &'static str {
        "vanrij"
    }

    fn header(&self) -> TraceHeader {
        header(&self.scene.screen)
    }

    fn frame<'a>(
        &'a self,
        _index: u32,
        _previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        if let Some(surfaces) = &self.scene.phong {
            return Ok(Box::new(PhongFrame::new(
                &self.scene.screen,
                surfaces,
                self.options.aa,
                self.shade_tolerance,
            )));
        }
        Ok(Box::new(Frame {
            plan: ScanPlan::new(&self.scene.screen, &self.options),
            options: &self.options,
        }))
    }

    fn settings_phrase(&self) -> String {
        let visibility = match self.scene.visibility_mode {
            Some(v) => format!(", {v} visibility"),
            None => String::new(),
        };
        let fitted = match self.scene.phong {
            Some(_) => format!(" (span tolerance {})", self.shade_tolerance),
            None => String::new(),
        };
        // Phong's box filter is coverage × the shade at the centre, whichever box
        let aa = match self.scene.phong {
            Some(_) if self.options.aa.is_box() => Antialias::BoxCentre.title(),
            _ => self.options.aa.title(),
        };
        format!(
            "{} shading{fitted}, {aa}{visibility}",
            self.options.shading.title(),
        )
    }

    fn summary_rows(&self, counters: &Counters, stats: &RunStats) -> Vec<(&'static str, String)> {
        let mut rows = self.scene.summary_rows();
        if self.scene.visibility_mode == Some(Visibility::Eval0) {
            rows.push((
                "visibility",
                format!(
                    "eval0: triangles front to back; {} Eval0 claims, {} contributions suppressed by them",
                    counters.get("claims").unwrap_or(0),
                    stats.totals.suppressed
                ),
            ));
        }
        rows
    }

    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        self.scene.stage_times()
    }

    fn scene_json(&self) -> serde_json::Value {
        self.scene.scene_json()
    }
}
