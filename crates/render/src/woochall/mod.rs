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
pub mod textures;
pub mod triangle;

use crate::error::{scene_io, NonFinite, RenderError};
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::Settings;
use crate::source::LoadedScene;
use crate::subsample::Sampler;
use cwisim_isa::{Instruction, TraceHeader, TraceWrite};
use cwisim_scene::{Shading, Vector};
use cwisim_xproc::{Image, RunStats};
use emit::{emit_row, EmitCounts, EmitRule, Subline};
use lists::{Layers, ListStats, Lists};
use prepare::Triangles;
use shade::{RowShader, ShadeRule};
use std::io;
use std::ops::Range;
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Duration;
use textures::Residency;

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
        let triangles = Triangles::new(loaded, settings)?;
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

    /// How a row's pixels are sent.
    fn emit_rule(&self) -> EmitRule {
        EmitRule {
            merge: self.merge,
            tolerance: (self.shading == Shading::Phong || self.triangles.textured())
                .then_some(self.shade_tolerance),
            channels: usize::from(self.triangles.channels),
        }
    }
}

/// The state of a frame's scan that runs from row to row (the lists, `keepObj` and the
/// stochastic draws, the corner grid's shared sub-scanline), and what the rows made so
/// far counted.
struct Scan<'a> {
    /// The next row to make.
    next_row: u32,
    /// A band stopped part way (an error): the state is that of no row boundary.
    broken: bool,
    /// Times the frame was started again from the top.
    epoch: u64,
    lists: Lists<'a>,
    shader: RowShader,
    list_stats: ListStats,
    /// The row's sub-scanlines; on the corner grid the first is the previous row's last.
    sublines: Vec<Subline>,
    carried: bool,
    /// The winners of the sub-scanline above (hidden-line drawing).
    above: Vec<u32>,
    layers: Layers,
    /// Per pixel row made: the lists', the shading's and the emitter's figures.
    figures: Vec<serde_json::Value>,
    /// Which textures are loaded (§5).
    residency: Residency,
}

impl<'a> Scan<'a> {
    /// The state at the top of the frame.
    fn new(w: &'a WooChall) -> Scan<'a> {
        let t = &w.triangles;
        let s = w.sampler;
        let channels = usize::from(t.channels);
        Scan {
            next_row: 0,
            broken: false,
            epoch: 0,
            lists: Lists::new(&t.tris, s),
            shader: RowShader::new(w.rule, s, channels),
            list_stats: ListStats::default(),
            sublines: vec![Subline::default(); s.l as usize],
            carried: false,
            above: Vec::new(),
            layers: Layers::default(),
            figures: Vec::new(),
            residency: Residency::new(&t.tris, t.textures.clone(), s.height),
        }
    }

    /// Makes row `next_row` into `out` (cleared first), in scan order: its sub-scanlines
    /// sampled and shaded, its instructions ending with `Refresh`.
    fn row(
        &mut self,
        w: &WooChall,
        rule: &EmitRule,
        out: &mut Vec<Instruction>,
    ) -> io::Result<EmitCounts> {
        let (t, s) = (&w.triangles, &w.sampler);
        let channels = usize::from(t.channels);
        let l = s.l as usize;
        let row = self.next_row;
        let (first, _) = s.of_pixel(row);
        let mut row_lists = ListStats::default();
        let shaded_before = self.shader.stats;
        let start = if self.carried {
            self.sublines.swap(0, l - 1);
            1
        } else {
            0
        };
        for (o, sub) in self.sublines.iter_mut().enumerate().skip(start) {
            let j = first + o;
            self.lists
                .subline(j as u32, &mut sub.winners, &mut self.layers, &mut row_lists);
            if w.shading == Shading::Hidden {
                shade::hidden_subline(&sub.winners, &self.above, channels, &mut sub.rgb);
            } else {
                let y = s.subline_y(j);
                let residency = &mut self.residency;
                // a texture that fails to decode when first shaded: the first such error
                let mut failed = None;
                self.shader.subline(
                    y,
                    &sub.winners,
                    &self.layers,
                    &t.tris,
                    &mut sub.rgb,
                    |tri, x, y| {
                        let shaded = residency
                            .touch(tri.surface)
                            .and_then(|()| t.shade(tri, x, y));
                        shaded.unwrap_or_else(|e| {
                            failed.get_or_insert(e);
                            Vector::default()
                        })
                    },
                );
                if let Some(e) = failed {
                    return Err(scene_io(e));
                }
            }
            self.above.clone_from(&sub.winners);
        }
        self.shader.end_row();
        self.carried = s.grid == crate::subsample::Grid::Corner;
        let refs: Vec<&Subline> = self.sublines.iter().collect();
        out.clear();
        let counts = emit_row(s, &refs, rule, out).map_err(|e| NonFinite::at_row(e, row))?;
        self.list_stats.merge(&row_lists);
        let shaded = &self.shader.stats;
        let resident = self.residency.end_row(row);
        let mut figures = serde_json::json!({
            "row": row,
            "max_active": row_lists.max_active,
            "max_visible_spans": row_lists.max_visible_spans,
            "geometry": row_lists.geometry,
            "shading": shaded.calls - shaded_before.calls,
            "forced_pixels": shaded.forced_pixels - shaded_before.forced_pixels,
            "instructions": counts.instructions,
            "eval1": counts.edge_pixels + counts.runs.eval1,
            "passes": counts.passes,
        });
        if self.residency.any() {
            figures["textures_resident"] = resident.into();
        }
        self.figures.push(figures);
        self.next_row += 1;
        Ok(counts)
    }
}

/// Instructions a band's thread makes before it sends them (at least one row's): enough
/// that the next band's rows are made while these are executed on another thread, few
/// enough (a few MB) that memory does not grow with the frame.
const CHUNK_INSTRUCTIONS: usize = 1 << 16;

/// What a frame's rows hold per sample column (`width × l`), an upper bound: the most
/// measured over the embedded scenes is 2.2 KB (`still-life` at 1600×1200, `--samples 8`,
/// two threads: the sub-scanlines' winners and colours, the layers behind transparent
/// surfaces, the shading's and the emitter's rows); `crates/render/tests/woochall_memory.rs`
/// checks it on every embedded scene. Transparent surfaces stacked deeper than those
/// scenes' can hold more.
pub const FRAME_BYTES_PER_SAMPLE_COLUMN: u64 = 3 * 1024;

/// What a frame holds per thread: its chunk of instructions ([`CHUNK_INSTRUCTIONS`], 48
/// bytes each) and the pipeline's buffers, an upper bound.
pub const FRAME_BYTES_PER_THREAD: u64 = 4 << 20;

/// One frame, made as it is emitted: the shading state runs from row to row, so bands of
/// rows are made in order (a band asked for ahead of its turn waits for the bands before
/// it), the instructions sent in chunks of about [`CHUNK_INSTRUCTIONS`]. Only the
/// scan's state and a chunk per thread are held, however large the frame. A band asked for again
/// (one that failed, to be emitted again where its error is told) is made again from the
/// top of the frame: the stream is the same.
struct WooFrame<'a> {
    renderer: &'a WooChall,
    rule: EmitRule,
    scan: Mutex<Scan<'a>>,
    /// Signalled when a band ends (or stops).
    turn: Condvar,
    sorted_triangles: u64,
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

/// `n` bytes in B, KiB or MiB.
fn bytes(n: u64) -> String {
    match n {
        0..1024 => format!("{n} B"),
        1024..1_048_576 => format!("{:.1} KiB", n as f64 / 1024.0),
        _ => format!("{:.1} MiB", n as f64 / 1_048_576.0),
    }
}

/// A band's thread panicked holding the scan.
fn poisoned<T>(_: T) -> io::Error {
    io::Error::other("woo-chall: the thread making an earlier band panicked")
}

impl WooFrame<'_> {
    /// `e`, with the scan marked stopped part way (its state is no row boundary) and the
    /// bands waiting for their turn told.
    fn stop(&self, mut scan: MutexGuard<'_, Scan<'_>>, e: io::Error) -> io::Error {
        scan.broken = true;
        drop(scan);
        self.turn.notify_all();
        e
    }
}

/// Sends `instructions` to `sink`.
fn send(instructions: &[Instruction], sink: &mut dyn TraceWrite) -> io::Result<()> {
    instructions.iter().try_for_each(|i| sink.write(i))
}

impl FramePlan for WooFrame<'_> {
    /// Asked after the frame's rows are emitted: the lists' and the shading's figures of
    /// the whole frame.
    fn counters(&self) -> Counters {
        let Ok(scan) = self.scan.lock() else {
            return Counters::default();
        };
        let (l, s) = (&scan.list_stats, &scan.shader.stats);
        let counters = Counters::default()
            .with("triangles", self.renderer.triangles.tris.len() as u64)
            .with("triangles_sorted", self.sorted_triangles)
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
            .with("shading_layers", s.layer_calls);
        let r = &scan.residency.stats;
        if r.textures == 0 {
            return counters;
        }
        counters
            .with("textures", r.textures)
            .with("texture_loads", r.loads)
            .with("texture_frees", r.frees)
            .with("textures_peak", r.peak)
            .with("textures_peak_row", r.peak_row)
            .with("texture_peak_bytes", r.peak_bytes)
    }

    fn row_figures(&self) -> Option<serde_json::Value> {
        let scan = self.scan.lock().ok()?;
        Some(serde_json::Value::from(scan.figures.clone()))
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let mut scan = self.scan.lock().map_err(poisoned)?;
        loop {
            if scan.next_row > rows.start || (scan.broken && scan.next_row >= rows.start) {
                // asked again (it failed): from the top of the frame
                let epoch = scan.epoch + 1;
                *scan = Scan::new(self.renderer);
                scan.epoch = epoch;
                break;
            }
            if scan.broken {
                return Err(io::Error::other(
                    "woo-chall: an earlier band stopped part way; this one is made again after it",
                ));
            }
            if scan.next_row == rows.start {
                break;
            }
            scan = self.turn.wait(scan).map_err(poisoned)?;
        }
        let epoch = scan.epoch;
        let (mut out, mut chunk) = (Vec::new(), Vec::new());
        while scan.next_row < rows.start {
            if let Err(e) = scan.row(self.renderer, &self.rule, &mut out) {
                return Err(self.stop(scan, e));
            }
        }
        let mut total = EmitCounts::default();
        for r in rows.clone() {
            match scan.row(self.renderer, &self.rule, &mut out) {
                Ok(counts) => total.add(&counts),
                Err(e) => return Err(self.stop(scan, e)),
            }
            chunk.append(&mut out);
            if chunk.len() >= CHUNK_INSTRUCTIONS && r + 1 < rows.end {
                // sent with the scan free: the turn stays this band's (no band starts
                // within it), unless a band before it is made again meanwhile
                drop(scan);
                let sent = send(&chunk, sink);
                chunk.clear();
                scan = self.scan.lock().map_err(poisoned)?;
                if scan.epoch != epoch {
                    return Err(io::Error::other(
                        "woo-chall: the frame was started again while this band was sent; it is made again after",
                    ));
                }
                if let Err(e) = sent {
                    return Err(self.stop(scan, e));
                }
            }
        }
        // the next band's rows can be made while these are sent
        drop(scan);
        self.turn.notify_all();
        send(&chunk, sink)?;
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
        let scan = Scan::new(self);
        let sorted_triangles = scan.lists.sorted() as u64;
        Ok(Box::new(WooFrame {
            renderer: self,
            rule: self.emit_rule(),
            scan: Mutex::new(scan),
            turn: Condvar::new(),
            sorted_triangles,
        }))
    }

    /// The rows' state (`l` sub-scanlines of samples, their layers, the shading's and the
    /// emitter's), a bound of [`FRAME_BYTES_PER_SAMPLE_COLUMN`] per sample column, and a
    /// chunk of instructions with the pipeline's buffers per thread,
    /// [`FRAME_BYTES_PER_THREAD`].
    fn frame_memory(&self, threads: usize) -> u64 {
        let columns = u64::from(self.sampler.width) * u64::from(self.sampler.l);
        columns
            .saturating_mul(FRAME_BYTES_PER_SAMPLE_COLUMN)
            .saturating_add((threads as u64).saturating_mul(FRAME_BYTES_PER_THREAD))
    }

    fn settings_phrase(&self) -> String {
        let s = &self.sampler;
        let fitted = if self.emit_rule().tolerance.is_some() {
            format!(" (span tolerance {})", self.shade_tolerance)
        } else {
            String::new()
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
        if get("textures") > 0 {
            rows.push((
                "textures",
                format!(
                    "{} textured mesh(es), each read at its shading calls' samples; loaded when first shaded ({} loaded, {} never: hidden), freed after their last row ({} freed); at most {} resident at once (first at row {}), {} of texels and tables",
                    get("textures"),
                    get("texture_loads"),
                    get("textures") - get("texture_loads"),
                    get("texture_frees"),
                    get("textures_peak"),
                    get("textures_peak_row"),
                    bytes(get("texture_peak_bytes"))
                ),
            ));
        }
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
        let mut times = vec![("transform & lighting", self.triangles.transform_time)];
        if self.triangles.shadows.is_some() {
            times.push(("shadows", self.triangles.shadow_time));
        }
        times
    }

    fn scene_json(&self) -> serde_json::Value {
        self.triangles.scene_json()
    }
}
