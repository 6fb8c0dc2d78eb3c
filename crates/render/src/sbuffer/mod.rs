//! `sbuffer`: Barkan & Gordon's S-buffer (*The scanline principle*, section 4.2 and
//! Appendix A) as a Y-processor — a depth buffer one scanline long, filled polygon by
//! polygon by critical-points scan conversion ([`crate::cp`]), scanline after scanline.
//!
//! The X-processor array has no depth register and no compare (its accumulator only
//! adds), so the array is the **colour half** of the one-scanline buffer and the depth
//! half stays on the host: per scanline the active polygons' `POLINE`s fill a host depth
//! line, a sample set where the polygon is nearer, and the scanline's **visible runs**
//! are sent — `Eval1` flat, `Eval2` Gouraud (the host's own adder chain, so the array
//! holds exactly the host's values), the span fitter for Phong.
//!
//! * `--sbuffer overdraw` (study mode) sends every run as FILL sets it and undoes what a
//!   nearer polygon overwrites with a negated draw between two `Acc_mode`s, so the array's
//!   work follows the pixels set (the paper's claim that a rough front-to-back order sets
//!   fewer pixels). The cancellation is exact only in `f64` with the array's adder chain:
//!   other numeric formats are refused.
//! * `--samples L` (with `--grid`): one host depth line per sub-scanline of the shared
//!   sampler ([`crate::subsample`]); pixels from samples as `woo-chall` makes them.
//!
//! [`polys`] makes the polygons from any scene, [`sweep`] is the PT/APT loop shared with
//! `bsp`. `docs/RENDERERS.md` says how it reads the paper; `docs/ERRATA.md` what it
//! corrects.

pub mod polys;
pub mod sweep;

use crate::cp::{columns_in, Increment};
use crate::error::RenderError;
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::{SbufferMode, Settings};
use crate::source::LoadedScene;
use crate::span::{fit_span, SpanStats};
use crate::subsample::{Grid, Sampler};
use crate::woochall::emit::{emit_row, EmitRule, Subline};
use crate::woochall::lists::NONE;
use cwisim_isa::{Instruction, Intensity, Opcode, TraceHeader, TraceWrite};
use cwisim_scene::{Shading, Vector};
use cwisim_xproc::numeric::Numeric;
use cwisim_xproc::{Image, RunStats};
use polys::{Poly, Polys};
use std::io;
use std::ops::Range;
use std::time::Duration;
use sweep::{edge_value, span_gradient, Sweep};

/// The registry's one line about it.
pub const ABOUT: &str = "Barkan & Gordon's S-buffer: critical-points scan conversion polygon by polygon into a host depth line per scanline (or sub-scanline, --samples), visible runs sent (--sbuffer host|overdraw, --cp-increment)";

/// The S-buffer renderer of a scene.
pub struct SBuffer {
    polys: Polys,
    sampler: Sampler,
    shading: Shading,
    increment: Increment,
    mode: SbufferMode,
    merge: bool,
    shade_tolerance: f64,
}

/// One sample column of the depth line: its depth key, owner and value.
#[derive(Clone, Debug, Default)]
pub(crate) struct DepthLine {
    pub(crate) key: Vec<f64>,
    pub(crate) owner: Vec<u32>,
    /// The owner's span (numbered along the line).
    pub(crate) span: Vec<u32>,
    /// The value the host's adder chain gives there (Gouraud), or the flat value.
    pub(crate) val: Vec<Vector>,
    /// The gradient of the owner's span (Gouraud; 0 for flat).
    pub(crate) grad: Vec<Vector>,
}

impl DepthLine {
    fn reset(&mut self, columns: usize) {
        self.key.clear();
        self.key.resize(columns, f64::INFINITY);
        self.owner.clear();
        self.owner.resize(columns, NONE);
        self.span.clear();
        self.span.resize(columns, NONE);
        self.val.clear();
        self.val.resize(columns, Vector::default());
        self.grad.clear();
        self.grad.resize(columns, Vector::default());
    }
}

/// What a frame counted, per row and in all.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct RowCounts {
    pub(crate) pixels_set: u64,
    pub(crate) pixels_overwritten: u64,
    pub(crate) visible_runs: u64,
    pub(crate) undo_runs: u64,
    pub(crate) acc_mode: u64,
    pub(crate) eval0: u64,
    pub(crate) suppressed_claims: u64,
    pub(crate) eval1: u64,
    pub(crate) eval2: u64,
    pub(crate) eval3: u64,
    pub(crate) fit_candidates: u64,
    pub(crate) instructions: u64,
}

impl RowCounts {
    pub(crate) fn add(&mut self, o: &RowCounts) {
        self.pixels_set += o.pixels_set;
        self.pixels_overwritten += o.pixels_overwritten;
        self.visible_runs += o.visible_runs;
        self.undo_runs += o.undo_runs;
        self.acc_mode += o.acc_mode;
        self.eval0 += o.eval0;
        self.suppressed_claims += o.suppressed_claims;
        self.eval1 += o.eval1;
        self.eval2 += o.eval2;
        self.eval3 += o.eval3;
        self.fit_candidates += o.fit_candidates;
        self.instructions += o.instructions;
    }

    fn spans(&mut self, s: &SpanStats) {
        self.eval1 += s.eval1;
        self.eval2 += s.eval2;
        self.eval3 += s.eval3;
        self.fit_candidates += s.candidates;
        self.instructions += s.pieces();
    }

    pub(crate) fn counters(&self) -> Counters {
        Counters::default()
            .with("pixels_set", self.pixels_set)
            .with("pixels_overwritten", self.pixels_overwritten)
            .with("visible_runs", self.visible_runs)
            .with("undo_runs", self.undo_runs)
            .with("acc_mode", self.acc_mode)
            .with("eval0", self.eval0)
            .with("suppressed_claims", self.suppressed_claims)
            .with("eval1", self.eval1)
            .with("eval2", self.eval2)
            .with("eval3", self.eval3)
            .with("fit_candidates", self.fit_candidates)
            .with("instructions", self.instructions)
    }
}

/// Writes into a row's instruction list, counting.
pub(crate) struct Out<'a> {
    pub(crate) list: &'a mut Vec<Instruction>,
    pub(crate) counts: &'a mut RowCounts,
}

impl Out<'_> {
    pub(crate) fn push(&mut self, i: Instruction) {
        match i.op {
            Opcode::Eval0 => self.counts.eval0 += 1,
            Opcode::Eval1 => self.counts.eval1 += 1,
            Opcode::Eval2 => self.counts.eval2 += 1,
            Opcode::Eval3 => self.counts.eval3 += 1,
            Opcode::AccMode => self.counts.acc_mode += 1,
            _ => {}
        }
        self.counts.instructions += 1;
        self.list.push(i);
    }
}

/// Whether every channel of a value and its gradient is 0 (nothing to add).
fn is_zero(v: &Vector, d: &Vector, channels: usize) -> bool {
    (0..channels).all(|c| v[c] == 0.0 && d[c] == 0.0)
}

/// Sends a run `[x, x + len)` whose first value is `v` and gradient `d`: `Eval1` when the
/// gradient is 0 in every channel (flat), else `Eval2`. Nothing for an all-zero run.
pub(crate) fn draw_run(
    out: &mut Out<'_>,
    x: u32,
    len: u32,
    v: &Vector,
    d: &Vector,
    flat: bool,
    channels: usize,
) {
    if len == 0 || is_zero(v, d, channels) {
        return;
    }
    let i = Intensity::new(&v[..channels]);
    if flat {
        out.push(Instruction::eval1(x, len, i));
    } else {
        out.push(Instruction::eval2(
            x,
            len,
            i,
            Intensity::new(&d[..channels]),
        ));
    }
}

/// The negated draws that cancel what the array accumulated from columns `[a, b)` of the
/// line (one owner's span): per channel, a value the array dropped (negative, `Acc_mode`
/// off) is not undone, so the run is split where the channels' signs change and a
/// dropped channel is sent as 0.
fn undo_run(out: &mut Out<'_>, line: &DepthLine, a: usize, b: usize, flat: bool, ch: usize) {
    let neg = |k: usize| -> [bool; cwisim_isa::MAX_CHANNELS] {
        std::array::from_fn(|c| c < ch && line.val[k][c] < 0.0)
    };
    let mut u = a;
    while u < b {
        let sign = neg(u);
        let mut w = u + 1;
        while w < b && neg(w) == sign {
            w += 1;
        }
        let v = cwisim_scene::vector(ch, |c| if sign[c] { 0.0 } else { -line.val[u][c] });
        let d = cwisim_scene::vector(ch, |c| if sign[c] { 0.0 } else { -line.grad[u][c] });
        let before = out.counts.instructions;
        draw_run(out, u as u32, (w - u) as u32, &v, &d, flat, ch);
        if out.counts.instructions > before {
            out.counts.undo_runs += 1;
        }
        u = w;
    }
}

impl SBuffer {
    /// The renderer of `loaded` under `settings`.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<SBuffer, RenderError> {
        settings.check().map_err(RenderError::Usage)?;
        let polys = Polys::new(loaded, settings.shading)?;
        let sampler = Sampler::new(settings.samples, settings.grid, polys.width, polys.height)
            .map_err(RenderError::Usage)?;
        if settings.sbuffer == SbufferMode::Overdraw {
            if sampler.l != 1 || sampler.grid != Grid::Centre {
                return Err(RenderError::Usage(
                    "--sbuffer overdraw sends pixels as FILL sets them, one sample per pixel: use --samples 1 (supersampled pixels are sums of samples, which a negated draw cannot undo one by one)".into(),
                ));
            }
            if settings.shading == Shading::Phong {
                return Err(RenderError::Usage(
                    "--sbuffer overdraw undoes runs exactly, which fitted Phong pieces do not allow: use --shading flat or gouraud, or --sbuffer host".into(),
                ));
            }
        }
        Ok(SBuffer {
            polys,
            sampler,
            shading: settings.shading,
            increment: settings.cp_increment,
            mode: settings.sbuffer,
            merge: settings.merge_subscanlines,
            shade_tolerance: settings.shade_tolerance,
        })
    }

    /// For the registry.
    pub fn build(
        loaded: LoadedScene,
        settings: &Settings,
    ) -> Result<Box<dyn Renderer>, RenderError> {
        Ok(Box::new(SBuffer::new(loaded, settings)?))
    }

    /// The polygons it draws.
    pub fn polys(&self) -> &Polys {
        &self.polys
    }

    /// Whether each row is one line of samples at the pixel centres.
    fn one_sample(&self) -> bool {
        self.sampler.l == 1 && self.sampler.grid == Grid::Centre
    }

    /// FILLs one line `y` of samples: every active polygon's spans into `line`, a
    /// sample set where the polygon is nearer. In overdraw mode, each run set is sent
    /// (after undoing what it overwrote) into `out`.
    fn fill_line(
        &self,
        sweep: &mut Sweep<'_>,
        j: usize,
        y: f64,
        line: &mut DepthLine,
        mut out: Option<&mut Out<'_>>,
        counts: &mut RowCounts,
    ) -> sweep::LineCounts {
        let s = &self.sampler;
        let ch = self.polys.channel_count();
        let columns = s.columns();
        line.reset(columns);
        let flat = self.shading == Shading::Flat;
        let mut span_id = 0u32;
        let mut set = Vec::new();
        sweep.line(j, y, |k, p: &Poly, aet| {
            for pair in aet.chunks_exact(2) {
                let (a, b) = (&pair[0], &pair[1]);
                let (first, end) = columns_in(
                    a.xc,
                    b.xc,
                    columns,
                    |c| s.column_x(c),
                    |x| s.index_at_or_after(x),
                );
                span_id += 1;
                if first >= end {
                    continue;
                }
                let (mut v, d) = if flat || self.shading == Shading::Phong {
                    (p.flat, Vector::default())
                } else {
                    let il = edge_value(p, a, y, ch);
                    let ir = edge_value(p, b, y, ch);
                    let d = span_gradient(&il, &ir, a.xc, b.xc, ch);
                    let dx = s.column_x(first) - a.xc;
                    // the chain steps one sample column: 1 pixel at one sample, else
                    // 1/l (centre grid) or 1/(l − 1) (corner grid)
                    let per = f64::from(s.step_count());
                    let step = cwisim_scene::vector(ch, |c| d[c] / per);
                    (cwisim_scene::vector(ch, |c| il[c] + dx * d[c]), step)
                };
                set.clear();
                for c in first..end {
                    let key = p.key(s.column_x(c), y);
                    set.push(key < line.key[c]);
                    if key < line.key[c] {
                        line.key[c] = key;
                    }
                }
                // runs of samples set, in order
                let mut c = first;
                while c < end {
                    if !set[c - first] {
                        for x in v.iter_mut().zip(&d) {
                            *x.0 += x.1;
                        }
                        c += 1;
                        continue;
                    }
                    let start = c;
                    let v0 = v;
                    while c < end && set[c - first] {
                        c += 1;
                    }
                    if let Some(out) = out.as_deref_mut() {
                        // undo each earlier owner's part of the run, then draw it
                        let mut undo = Vec::new();
                        let mut u = start;
                        while u < c {
                            let (o, sp) = (line.owner[u], line.span[u]);
                            let mut w = u + 1;
                            while w < c && line.owner[w] == o && line.span[w] == sp {
                                w += 1;
                            }
                            if o != NONE {
                                let mut o = Out {
                                    list: &mut undo,
                                    counts: out.counts,
                                };
                                undo_run(&mut o, line, u, w, flat, ch);
                            }
                            u = w;
                        }
                        if !undo.is_empty() {
                            out.push(Instruction::acc_mode());
                            out.list.append(&mut undo);
                            out.push(Instruction::acc_mode());
                        }
                        draw_run(out, start as u32, (c - start) as u32, &v0, &d, flat, ch);
                    }
                    let mut w = v0;
                    for x in start..c {
                        counts.pixels_set += 1;
                        if line.owner[x] != NONE {
                            counts.pixels_overwritten += 1;
                        }
                        line.owner[x] = k;
                        line.span[x] = span_id;
                        line.val[x] = w;
                        line.grad[x] = d;
                        for q in w.iter_mut().zip(&d) {
                            *q.0 += q.1;
                        }
                    }
                    v = w;
                }
            }
            true
        })
    }

    /// The visible runs of a one-sample line, sent.
    fn send_visible(&self, line: &DepthLine, row: u32, out: &mut Out<'_>) -> io::Result<()> {
        let ch = self.polys.channel_count();
        let flat = self.shading == Shading::Flat;
        let mut x = 0;
        let n = line.owner.len();
        let mut targets = Vec::new();
        while x < n {
            let (o, sp) = (line.owner[x], line.span[x]);
            let mut e = x + 1;
            while e < n && line.owner[e] == o && line.span[e] == sp {
                e += 1;
            }
            if o != NONE {
                out.counts.visible_runs += 1;
                if self.shading == Shading::Phong {
                    let p = &self.polys.polys[o as usize];
                    targets.clear();
                    let y = f64::from(row) + 0.5;
                    for c in x..e {
                        let v = self.polys.phong(p, c as f64 + 0.5, y).unwrap_or_default();
                        targets.extend_from_slice(&v[..ch]);
                    }
                    let mut pieces = Vec::new();
                    let s = fit_span(x as u32, &targets, ch, self.shade_tolerance, &mut pieces)?;
                    out.list.extend(pieces);
                    out.counts.spans(&s);
                } else {
                    draw_run(
                        out,
                        x as u32,
                        (e - x) as u32,
                        &line.val[x],
                        &line.grad[x],
                        flat,
                        ch,
                    );
                }
            }
            x = e;
        }
        Ok(())
    }

    /// A sub-scanline's samples as `woo-chall`'s emitter takes them: winners and colours.
    fn subline_of(&self, line: &DepthLine, y: f64, sub: &mut Subline) {
        sub.winners.clone_from(&line.owner);
        sub.rgb.clear();
        for (c, &o) in line.owner.iter().enumerate() {
            sub.rgb.push(match o {
                NONE => Vector::default(),
                _ if self.shading == Shading::Phong => self
                    .polys
                    .phong(&self.polys.polys[o as usize], self.sampler.column_x(c), y)
                    .unwrap_or_default(),
                _ => line.val[c],
            });
        }
    }

    /// Runs the whole frame in scan order.
    fn run(&self) -> io::Result<SFrame> {
        let s = &self.sampler;
        let height = self.polys.height;
        let mut sweep = Sweep::new(
            &self.polys.polys,
            s.sublines(),
            |j| s.subline_y(j),
            |y| first_at_or_after(s, y),
            None,
            self.increment,
        );
        let ch = self.polys.channel_count();
        let mut line = DepthLine::default();
        let mut rows = Vec::with_capacity(height as usize);
        let mut row_counts = Vec::with_capacity(height as usize);
        let mut figures = Vec::with_capacity(height as usize);
        let l = s.l as usize;
        let mut sublines: Vec<Subline> = vec![Subline::default(); l];
        let mut next_line = 0usize;
        for row in 0..height {
            let mut list = Vec::new();
            let mut counts = RowCounts::default();
            let cp_before = sweep.stats;
            let (mut active, mut aet) = (0u64, 0u64);
            if self.one_sample() {
                let y = f64::from(row) + 0.5;
                let overdraw = self.mode == SbufferMode::Overdraw;
                let mut od_counts = RowCounts::default();
                let lc = {
                    let mut out = Out {
                        list: &mut list,
                        counts: &mut od_counts,
                    };
                    self.fill_line(
                        &mut sweep,
                        row as usize,
                        y,
                        &mut line,
                        overdraw.then_some(&mut out),
                        &mut counts,
                    )
                };
                (active, aet) = (lc.active, lc.aet);
                counts.add(&od_counts);
                let mut visible = RowCounts::default();
                let mut out = Out {
                    list: &mut list,
                    counts: &mut visible,
                };
                if overdraw {
                    // the runs are already sent; count the visible ones
                    let mut probe = Vec::new();
                    let mut c = RowCounts::default();
                    self.send_visible(
                        &line,
                        row,
                        &mut Out {
                            list: &mut probe,
                            counts: &mut c,
                        },
                    )?;
                    counts.visible_runs += c.visible_runs;
                } else {
                    self.send_visible(&line, row, &mut out)?;
                    counts.add(&visible);
                }
                list.push(Instruction::refresh());
                counts.instructions += 1;
            } else {
                let (first, _) = s.of_pixel(row);
                let carried = s.grid == Grid::Corner && row > 0;
                if carried {
                    sublines.swap(0, l - 1);
                }
                for (o, sub) in sublines.iter_mut().enumerate().skip(usize::from(carried)) {
                    let j = first + o;
                    debug_assert_eq!(j, next_line);
                    next_line = j + 1;
                    let y = s.subline_y(j);
                    let lc = self.fill_line(&mut sweep, j, y, &mut line, None, &mut counts);
                    active = active.max(lc.active);
                    aet = aet.max(lc.aet);
                    self.subline_of(&line, y, sub);
                    // visible runs of the sub-scanline
                    let mut x = 0;
                    while x < line.owner.len() {
                        let (o, sp) = (line.owner[x], line.span[x]);
                        let mut e = x + 1;
                        while e < line.owner.len() && line.owner[e] == o && line.span[e] == sp {
                            e += 1;
                        }
                        counts.visible_runs += u64::from(o != NONE);
                        x = e;
                    }
                }
                let refs: Vec<&Subline> = sublines.iter().collect();
                let rule = EmitRule {
                    merge: self.merge,
                    tolerance: (self.shading == Shading::Phong).then_some(self.shade_tolerance),
                    channels: ch,
                };
                let c = emit_row(s, &refs, &rule, &mut list)?;
                counts.eval1 += c.edge_pixels + c.runs.eval1;
                counts.eval2 += c.runs.eval2;
                counts.eval3 += c.runs.eval3;
                counts.fit_candidates += c.runs.candidates;
                counts.instructions += c.instructions;
            }
            let cp = sweep.stats;
            figures.push(serde_json::json!({
                "row": row,
                "active_polygons": active,
                "aet_elements": aet,
                "moveup_steps": cp.moveup_steps - cp_before.moveup_steps,
                "aet_inserts": cp.inserts - cp_before.inserts,
                "aet_deletes": cp.deletes - cp_before.deletes,
                "pixels_set": counts.pixels_set,
                "pixels_overwritten": counts.pixels_overwritten,
                "visible_runs": counts.visible_runs,
                "instructions": counts.instructions,
            }));
            rows.push(list);
            row_counts.push(counts);
        }
        let critical = self
            .polys
            .polys
            .iter()
            .map(|p| p.cp.critical_points().len() as u64)
            .sum();
        Ok(SFrame {
            rows,
            row_counts,
            figures: serde_json::Value::from(figures),
            frame: Counters::default()
                .with("polygons", self.polys.polys.len() as u64)
                .with(
                    "vertices",
                    self.polys.polys.iter().map(|p| p.cp.len() as u64).sum(),
                )
                .with("critical_points", critical)
                .with("max_active_polygons", sweep.max_active)
                .with("max_aet", sweep.max_aet)
                .with("moveup_steps", sweep.stats.moveup_steps)
                .with("aet_inserts", sweep.stats.inserts)
                .with("aet_deletes", sweep.stats.deletes)
                .with("cp_recomputes", sweep.stats.recomputes)
                .with("cp_increments", sweep.stats.increments),
        })
    }
}

/// The first sub-scanline at or below `y` (`sublines()` when none): the arithmetic
/// candidate, checked against the sampler's own positions.
pub(crate) fn first_at_or_after(s: &Sampler, y: f64) -> usize {
    let n = s.sublines();
    columns_in(
        y,
        f64::INFINITY,
        n,
        |j| s.subline_y(j),
        |v| s.index_at_or_after(v),
    )
    .0
}

/// One frame: its rows' instructions, ready to send.
pub(crate) struct SFrame {
    pub(crate) rows: Vec<Vec<Instruction>>,
    pub(crate) row_counts: Vec<RowCounts>,
    pub(crate) figures: serde_json::Value,
    pub(crate) frame: Counters,
}

impl FramePlan for SFrame {
    fn counters(&self) -> Counters {
        self.frame.clone()
    }

    fn row_figures(&self) -> Option<serde_json::Value> {
        Some(self.figures.clone())
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let mut total = RowCounts::default();
        for r in rows {
            for i in &self.rows[r as usize] {
                sink.write(i)?;
            }
            total.add(&self.row_counts[r as usize]);
        }
        Ok(total.counters())
    }
}

/// The summary rows every scanline-principle renderer shares: CP's work and the pixels.
pub(crate) fn cp_rows(c: &Counters) -> Vec<(&'static str, String)> {
    let get = |n: &str| c.get(n).unwrap_or(0);
    vec![
        (
            "CP",
            format!(
                "{} polygons, {} vertices, {} critical points; APT at most {}, AETs at most {} elements on a line; {} MOVEUP steps, {} inserts, {} deletes; intersections {} recomputed, {} incremented",
                get("polygons"),
                get("vertices"),
                get("critical_points"),
                get("max_active_polygons"),
                get("max_aet"),
                get("moveup_steps"),
                get("aet_inserts"),
                get("aet_deletes"),
                get("cp_recomputes"),
                get("cp_increments"),
            ),
        ),
        (
            "pixels",
            format!(
                "{} samples set, {} of them overwritten; {} visible runs",
                get("pixels_set"),
                get("pixels_overwritten"),
                get("visible_runs"),
            ),
        ),
        (
            "emitted",
            format!(
                "{} instructions: Eval1 {}, Eval2 {}, Eval3 {}, Eval0 {}; {} undo runs, {} Acc_mode",
                get("instructions"),
                get("eval1"),
                get("eval2"),
                get("eval3"),
                get("eval0"),
                get("undo_runs"),
                get("acc_mode"),
            ),
        ),
    ]
}

impl Renderer for SBuffer {
    fn name(&self) -> &'static str {
        "sbuffer"
    }

    fn header(&self) -> TraceHeader {
        self.polys.header()
    }

    fn frame<'a>(
        &'a self,
        _index: u32,
        _previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        let frame = self.run().map_err(|source| RenderError::Renderer {
            renderer: "sbuffer",
            source,
        })?;
        Ok(Box::new(frame))
    }

    fn settings_phrase(&self) -> String {
        let s = &self.sampler;
        let fitted = match self.shading {
            Shading::Phong => format!(" (span tolerance {})", self.shade_tolerance),
            _ => String::new(),
        };
        let sampling = if self.one_sample() {
            "one sample per pixel (its centre)".to_string()
        } else {
            format!(
                "{l}×{l} {} grid, one depth line per sub-scanline, sub-scanlines {}",
                s.grid,
                if self.merge {
                    "merged by the host"
                } else {
                    "as passes the array accumulates"
                },
                l = s.l
            )
        };
        format!(
            "{} shading{fitted}, {sampling}, CP increment {}, {}",
            self.shading.title(),
            self.increment,
            match self.mode {
                SbufferMode::Host => "visible runs sent (depth on the host)",
                SbufferMode::Overdraw =>
                    "every run sent as set, overwrites undone (overdraw study)",
            }
        )
    }

    fn summary_rows(&self, c: &Counters, _stats: &RunStats) -> Vec<(&'static str, String)> {
        let mut rows = self.polys.summary_rows();
        rows.extend(cp_rows(c));
        rows
    }

    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        vec![("transform & lighting", self.polys.transform_time)]
    }

    fn scene_json(&self) -> serde_json::Value {
        self.polys.scene_json()
    }

    fn check_numeric(&self, numeric: &Numeric) -> Result<(), String> {
        if self.mode == SbufferMode::Overdraw && *numeric != Numeric::F64 {
            return Err(format!(
                "--sbuffer overdraw undoes overwritten runs by negated draws, which cancel exactly only in f64 with the array's adder chain; found --numeric {numeric}: use --numeric f64 or --sbuffer host"
            ));
        }
        Ok(())
    }
}
