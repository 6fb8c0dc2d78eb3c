//! `woo-chall`: Woo & Chall's scanline visibility (*An efficient scanline visibility
//! implementation*) as a Y-processor — triangles point-sampled top to bottom and left
//! to right on an `l × l` grid per pixel, the nearest triangle winning each sample,
//! shading calls saved by `keepObj` and made adaptively and stochastically, and every
//! row sent to the X-processor array: runs of interior pixels through the span fitter,
//! edge pixels as one `Eval1` each.
//!
//! * [`triangle`] — the parameterisation (§4), span ends, the exact inside test.
//! * [`lists`] — `ySortList`, `yActiveList`, `xActiveList` (§3.1–3.3): the winners.
//! * [`shade`] — `keepObj` and the adaptive–stochastic shading calls (§3.4).
//! * [`emit`] — pixels from samples, and instructions from pixels.
//! * [`prepare`] — triangles from any scene.
//!
//! `docs/RENDERERS.md` says how it reads the paper; `docs/ERRATA.md` what it corrects.

pub mod emit;
pub mod lists;
pub mod prepare;
pub mod shade;
pub mod triangle;

use crate::error::{NonFinite, RenderError};
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::Settings;
use crate::source::LoadedScene;
use crate::subsample::Sampler;
use cwisim_isa::{Instruction, TraceHeader, TraceWrite};
use cwisim_scene::Shading;
use cwisim_xproc::{Image, RunStats};
use emit::{emit_row, EmitCounts, EmitRule, Subline};
use lists::{Layers, ListStats, Lists};
use prepare::Triangles;
use shade::{RowShader, ShadeRule, ShadeStats};
use std::io;
use std::ops::Range;
use std::time::Duration;

/// The registry's one line about it.
pub const ABOUT: &str = "Woo & Chall's scanline visibility: triangles point-sampled on an l×l grid (--samples, --grid), nearest wins; keepObj and adaptive-stochastic shading calls; interior runs through the span fitter";

/// Woo & Chall's renderer of a scene.
pub struct WooChall {
    triangles: Triangles,
    sampler: Sampler,
    shading: Shading,
    rule: ShadeRule,
    merge: bool,
    shade_tolerance: f64,
}

impl WooChall {
    /// The renderer of `loaded` under `settings`.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<WooChall, RenderError> {
        let loaded = loaded.drawn_as(settings)?;
        settings.check().map_err(RenderError::Usage)?;
        let triangles = Triangles::new(loaded, settings.shading)?;
        let sampler = Sampler::new(
            settings.samples,
            settings.grid,
            triangles.width,
            triangles.height,
        )
        .map_err(RenderError::Usage)?;
        let p = settings
            .shade_p
            .unwrap_or_else(|| sampler.paper_shade_probability());
        Ok(WooChall {
            triangles,
            sampler,
            shading: settings.shading,
            rule: ShadeRule {
                p,
                contrast: settings.shade_contrast,
                seed: settings.seed,
            },
            merge: settings.merge_subscanlines,
            shade_tolerance: settings.shade_tolerance,
        })
    }

    /// For the registry.
    pub fn build(
        loaded: LoadedScene,
        settings: &Settings,
    ) -> Result<Box<dyn Renderer>, RenderError> {
        Ok(Box::new(WooChall::new(loaded, settings)?))
    }

    /// The sampler it uses.
    pub fn sampler(&self) -> &Sampler {
        &self.sampler
    }

    /// Runs the whole frame, in scan order (the shading state runs from row to row).
    fn run(&self) -> io::Result<WooFrame> {
        let t = &self.triangles;
        let s = &self.sampler;
        let channels = usize::from(t.channels);
        let mut lists = Lists::new(&t.tris, *s);
        let mut shader = RowShader::new(self.rule, *s, channels);
        let mut list_stats = ListStats::default();
        let rule = EmitRule {
            merge: self.merge,
            tolerance: (self.shading == Shading::Phong).then_some(self.shade_tolerance),
            channels,
        };
        let l = s.l as usize;
        let mut rows = Vec::with_capacity(t.height as usize);
        let mut row_counts = Vec::with_capacity(t.height as usize);
        // the row's sub-scanlines; on the corner grid the first is the previous row's last
        let mut sublines: Vec<Subline> = vec![Subline::default(); l];
        let mut carried = false;
        // the winners of the sub-scanline above (hidden-line drawing)
        let mut above: Vec<u32> = Vec::new();
        let mut layers = Layers::default();
        let mut figures = Vec::with_capacity(t.height as usize);
        for row in 0..t.height {
            let (first, _) = s.of_pixel(row);
            let mut row_lists = ListStats::default();
            let shaded_before = shader.stats;
            let start = if carried {
                sublines.swap(0, l - 1);
                1
            } else {
                0
            };
            for (o, sub) in sublines.iter_mut().enumerate().skip(start) {
                let j = first + o;
                lists.subline(j as u32, &mut sub.winners, &mut layers, &mut row_lists);
                if self.shading == Shading::Hidden {
                    shade::hidden_subline(&sub.winners, &above, channels, &mut sub.rgb);
                } else {
                    let y = s.subline_y(j);
                    shader.subline(
                        y,
                        &sub.winners,
                        &layers,
                        &t.tris,
                        &mut sub.rgb,
                        |tri, x, y| t.shade(tri, x, y),
                    );
                }
                above.clone_from(&sub.winners);
            }
            shader.end_row();
            carried = s.grid == crate::subsample::Grid::Corner;
            let refs: Vec<&Subline> = sublines.iter().collect();
            let mut out = Vec::new();
            let counts =
                emit_row(s, &refs, &rule, &mut out).map_err(|e| NonFinite::at_row(e, row))?;
            list_stats.merge(&row_lists);
            let shaded = &shader.stats;
            figures.push(serde_json::json!({
                "row": row,
                "max_active": row_lists.max_active,
                "max_visible_spans": row_lists.max_visible_spans,
                "geometry": row_lists.geometry,
                "shading": shaded.calls - shaded_before.calls,
                "forced_pixels": shaded.forced_pixels - shaded_before.forced_pixels,
                "instructions": counts.instructions,
                "eval1": counts.edge_pixels + counts.runs.eval1,
                "passes": counts.passes,
            }));
            rows.push(out);
            row_counts.push(counts);
        }
        Ok(WooFrame {
            figures: serde_json::Value::from(figures),
            rows,
            row_counts,
            list_stats,
            shade_stats: shader.stats,
            sorted: lists.sorted() as u64,
            triangles: t.tris.len() as u64,
        })
    }
}

/// One frame, shaded: its rows' instructions, ready to send.
struct WooFrame {
    /// Per pixel row: the lists', the shading's and the emitter's figures.
    figures: serde_json::Value,
    rows: Vec<Vec<Instruction>>,
    row_counts: Vec<EmitCounts>,
    list_stats: ListStats,
    shade_stats: ShadeStats,
    sorted: u64,
    triangles: u64,
}

fn emit_counters(c: &EmitCounts) -> Counters {
    Counters::default()
        .with("passes", c.passes)
        .with("edge_pixels", c.edge_pixels)
        .with("run_eval1", c.runs.eval1)
        .with("run_eval2", c.runs.eval2)
        .with("run_eval3", c.runs.eval3)
        .with("fit_candidates", c.runs.candidates)
        .with("instructions", c.instructions)
}

impl FramePlan for WooFrame {
    fn counters(&self) -> Counters {
        let (l, s) = (&self.list_stats, &self.shade_stats);
        Counters::default()
            .with("triangles", self.triangles)
            .with("triangles_sorted", self.sorted)
            .with("max_active", l.max_active)
            .with("max_visible_spans", l.max_visible_spans)
            .with("geometry", l.geometry)
            .with("spans", l.spans)
            .with("depth_tests", l.depth_tests)
            .with("shading", s.calls)
            .with("shading_new_surface", s.new_surface)
            .with("shading_stochastic", s.stochastic)
            .with("shading_forced", s.forced_calls)
            .with("forced_pixels", s.forced_pixels)
            .with("shading_layers", s.layer_calls)
    }

    fn row_figures(&self) -> Option<serde_json::Value> {
        Some(self.figures.clone())
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let mut total = EmitCounts::default();
        for r in rows {
            for i in &self.rows[r as usize] {
                sink.write(i)?;
            }
            total.add(&self.row_counts[r as usize]);
        }
        Ok(emit_counters(&total))
    }
}

impl Renderer for WooChall {
    fn name(&self) -> &'static str {
        "woo-chall"
    }

    fn header(&self) -> TraceHeader {
        self.triangles.header()
    }

    fn frame<'a>(
        &'a self,
        _index: u32,
        _previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        let frame = self
            .run()
            .map_err(|source| RenderError::of_renderer("woo-chall", source))?;
        Ok(Box::new(frame))
    }

    fn settings_phrase(&self) -> String {
        let s = &self.sampler;
        let fitted = match self.shading {
            Shading::Phong => format!(" (span tolerance {})", self.shade_tolerance),
            _ => String::new(),
        };
        let contrast = if self.rule.contrast.is_infinite() {
            "never forced".to_string()
        } else {
            format!("forced above contrast {}", self.rule.contrast)
        };
        format!(
            "{} shading{fitted}, {l}×{l} {} grid, sub-scanlines {}, shading calls with P = {:.4}, {contrast}, seed {}",
            self.shading.title(),
            s.grid,
            if self.merge { "merged by the host" } else { "as passes the array accumulates" },
            self.rule.p,
            self.rule.seed,
            l = s.l,
        )
    }

    fn summary_rows(&self, c: &Counters, _stats: &RunStats) -> Vec<(&'static str, String)> {
        let get = |n: &str| c.get(n).unwrap_or(0);
        let n = get("triangles");
        let m = get("max_active");
        let geometry = get("geometry");
        let shading = get("shading");
        let instructions = get("instructions").max(1);
        let eval1 = get("edge_pixels") + get("run_eval1");
        let mut rows = self.triangles.summary_rows();
        rows.push((
            "lists",
            format!(
                "n = {n} triangles, m = {m} on yActiveList at most (m/n = {:.1}%); at most {} visible spans on a sub-scanline; {} spans, {} depth tests",
                100.0 * m as f64 / n.max(1) as f64,
                get("max_visible_spans"),
                get("spans"),
                get("depth_tests")
            ),
        ));
        rows.push((
            "sampling",
            format!(
                "#Geometry {geometry} samples, #Shading {shading} calls ({:.3} per sample: {} new surface, {} stochastic, {} forced); {} pixels forced",
                shading as f64 / geometry.max(1) as f64,
                get("shading_new_surface"),
                get("shading_stochastic"),
                get("shading_forced"),
                get("forced_pixels")
            ),
        ));
        rows.push((
            "emitted",
            format!(
                "{} passes; {} edge-pixel Eval1 + run pieces {}/{}/{} (Eval1/2/3); Eval1 share {:.1}% of {} instructions",
                get("passes"),
                get("edge_pixels"),
                get("run_eval1"),
                get("run_eval2"),
                get("run_eval3"),
                100.0 * eval1 as f64 / instructions as f64,
                get("instructions")
            ),
        ));
        rows
    }

    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        vec![("transform & lighting", self.triangles.transform_time)]
    }

    fn scene_json(&self) -> serde_json::Value {
        self.triangles.scene_json()
    }
}
