//! The scan engine shared by `sbuffer` and `bsp`: one line of samples filled polygon by
//! polygon (FILL, by a [`Rule`]), then the row sent to the array.
//!
//! * [`Rule::Nearer`] — the S-buffer: a sample set where the polygon is nearer than the
//!   depth line says (strictly: on a tie the polygon met first keeps it).
//! * [`Rule::Paint`] — painter's: every sample of every span set, the last one stays.
//! * [`Rule::Unset`] — Gordon & Chen's front-to-back display: a run-length list of the
//!   unset samples ([`UnsetList`]); a span sets only what the list still holds, and the
//!   line's walk stops when the list is empty.
//! * [`Rule::Claim`] — front to back through the array's lock bits: every span sent as
//!   `Eval0`, the first claim wins; the host mirrors the locks only to count what the
//!   array suppresses.
//!
//! At one sample per pixel, Gouraud values follow the host's adder chain along each span
//! (`v += dI` from the span's first pixel), and a run starting at pixel `a` is sent with
//! the chain's value at `a`: the array, adding the same `dI`, holds exactly the host's
//! values, whichever run of the span ends up visible.

use super::abuffer::{resolve, Fragment, FragmentLine};
use super::layers::{composite, LayerLine};
use super::polys::{Poly, Polys};
use super::sweep::{edge_value, span_gradient, LineCounts, Sweep};
use crate::cp::{columns_in, Increment};
use crate::error::{scene_io, NonFinite};
use crate::renderer::Counters;
use crate::span::{fit_span, SpanStats};
use crate::subsample::{Grid, Sampler};
use crate::woochall::emit::{emit_row, send, Class, EmitCounts, EmitRule, Subline};
use crate::woochall::lists::NONE;
use cwisim_isa::{Instruction, Intensity, Opcode, TraceWrite};
use cwisim_scene::{Shading, Vector};
use cwisim_world::shadow::LightSet;
use std::collections::HashMap;
use std::io;
use std::ops::Range;

/// How FILL sets samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// Where the polygon is nearer (the S-buffer).
    Nearer,
    /// Always (painter's, back to front).
    Paint,
    /// Where still unset (front to back, Gordon & Chen's list on the host).
    Unset,
    /// Every span as `Eval0` (front to back, the array's locks as the list).
    Claim,
}

/// Gordon & Chen's run-length list of the unset samples of a line: disjoint `[a, b)`
/// intervals in order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct UnsetList {
    runs: Vec<(usize, usize)>,
}

impl UnsetList {
    /// Every sample of `0..n` unset.
    pub fn reset(&mut self, n: usize) {
        self.runs.clear();
        if n > 0 {
            self.runs.push((0, n));
        }
    }

    /// Whether every sample is set.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// The runs, in order.
    pub fn runs(&self) -> &[(usize, usize)] {
        &self.runs
    }

    /// The merge of a span `[first, end)` with the list: the unset runs it covers, taken
    /// off the list, in order (into `taken`, cleared first). Returns the list entries it
    /// visited.
    pub fn take(&mut self, first: usize, end: usize, taken: &mut Vec<(usize, usize)>) -> u64 {
        taken.clear();
        let start = self.runs.partition_point(|r| r.1 <= first);
        let mut k = start;
        let mut keep: Vec<(usize, usize)> = Vec::new();
        while k < self.runs.len() && self.runs[k].0 < end {
            let (a, b) = self.runs[k];
            let (s, e) = (a.max(first), b.min(end));
            if s < e {
                taken.push((s, e));
            }
            if a < s {
                keep.push((a, s));
            }
            if e < b {
                keep.push((e, b));
            }
            k += 1;
        }
        let visited = (k - start) as u64;
        self.runs.splice(start..k, keep);
        visited
    }
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
    /// With transparency (§5.2): each sample's list down to the nearest opaque polygon.
    pub(crate) layers: LayerLine,
    /// The A-buffer (§5.2): each pixel's fragments, over the row's sub-scanlines (reset
    /// per row, not per line).
    pub(crate) frags: FragmentLine,
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
        self.layers.reset(columns);
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
    pub(crate) spans: u64,
    pub(crate) polygons_walked: u64,
    pub(crate) walks_stopped: u64,
    pub(crate) list_visits: u64,
    pub(crate) eval0: u64,
    pub(crate) suppressed_claims: u64,
    pub(crate) eval1: u64,
    pub(crate) eval2: u64,
    pub(crate) eval3: u64,
    pub(crate) fit_candidates: u64,
    pub(crate) instructions: u64,
    /// Spans of a partly lit polygon, tested sample by sample against the lit parts.
    pub(crate) shadow_spans: u64,
    /// The lit parts' edges those spans' lines cross (§5.3's shadow edges in `P.AET`).
    pub(crate) shadow_crossings: u64,
    /// The comparisons sorting them took.
    pub(crate) shadow_comparisons: u64,
    /// The A-buffer's fragments.
    pub(crate) fragments: u64,
}

impl RowCounts {
    pub(crate) fn add(&mut self, o: &RowCounts) {
        self.pixels_set += o.pixels_set;
        self.pixels_overwritten += o.pixels_overwritten;
        self.visible_runs += o.visible_runs;
        self.undo_runs += o.undo_runs;
        self.acc_mode += o.acc_mode;
        self.spans += o.spans;
        self.polygons_walked += o.polygons_walked;
        self.walks_stopped += o.walks_stopped;
        self.list_visits += o.list_visits;
        self.eval0 += o.eval0;
        self.suppressed_claims += o.suppressed_claims;
        self.eval1 += o.eval1;
        self.eval2 += o.eval2;
        self.eval3 += o.eval3;
        self.fit_candidates += o.fit_candidates;
        self.instructions += o.instructions;
        self.shadow_spans += o.shadow_spans;
        self.shadow_crossings += o.shadow_crossings;
        self.shadow_comparisons += o.shadow_comparisons;
        self.fragments += o.fragments;
    }

    fn spans_fitted(&mut self, s: &SpanStats) {
        self.eval1 += s.eval1;
        self.eval2 += s.eval2;
        self.eval3 += s.eval3;
        self.fit_candidates += s.candidates;
        self.instructions += s.pieces();
    }

    /// Its counters; the shadow ones only where some span was tested against lit parts.
    pub(crate) fn counters(&self) -> Counters {
        let c = Counters::default()
            .with("polygons_walked", self.polygons_walked)
            .with("walks_stopped", self.walks_stopped)
            .with("unset_list_visits", self.list_visits)
            .with("spans", self.spans)
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
            .with("instructions", self.instructions);
        let c = if self.fragments > 0 {
            c.with("fragments", self.fragments)
        } else {
            c
        };
        if self.shadow_spans == 0 {
            return c;
        }
        c.with("shadow_spans", self.shadow_spans)
            .with("shadow_crossings", self.shadow_crossings)
            .with("shadow_sort_comparisons", self.shadow_comparisons)
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

/// What a scan is and how it sends its rows.
pub(crate) struct Scan<'a> {
    /// The scene's polygons (Phong's lighting, the image's size).
    pub(crate) scene: &'a Polys,
    /// The polygons scanned (the scene's, or a BSP tree's pieces).
    pub(crate) list: &'a [Poly],
    /// Their priority on the APT (`None`: by index).
    pub(crate) rank: Option<Vec<u32>>,
    pub(crate) sampler: Sampler,
    pub(crate) shading: Shading,
    pub(crate) increment: Increment,
    pub(crate) rule: Rule,
    /// `Rule::Nearer` at one sample: send each run as it is set, undoing overwrites.
    pub(crate) overdraw: bool,
    /// `Rule::Nearer` with §5.2's lists: each sample's transparent polygons down to the
    /// nearest opaque one, composited.
    pub(crate) transparent: bool,
    /// The scanline A-buffer (§5.2): every sample of a span goes to its pixel's fragment
    /// of the polygon, resolved per pixel once the row's sub-scanlines are done.
    pub(crate) abuffer: bool,
    pub(crate) merge: bool,
    pub(crate) shade_tolerance: f64,
}

impl Scan<'_> {
    /// Whether samples are lit one by one (Phong, or a textured scene under any shading)
    /// rather than read off the spans' Gouraud chains.
    pub(crate) fn per_pixel(&self) -> bool {
        self.shading == Shading::Phong || self.scene.textured()
    }

    /// Whether each row is one line of samples at the pixel centres.
    pub(crate) fn one_sample(&self) -> bool {
        self.sampler.l == 1 && self.sampler.grid == Grid::Centre
    }

    /// FILLs one line `y` of samples into `line`. With `out` (one sample per pixel),
    /// runs are sent as they are set: the overdraw study, newly set runs of the unset
    /// list, and `Eval0` claims.
    #[allow(clippy::too_many_arguments)]
    fn fill_line(
        &self,
        sweep: &mut Sweep<'_>,
        j: usize,
        y: f64,
        line: &mut DepthLine,
        unset: &mut UnsetList,
        mut out: Option<&mut Out<'_>>,
        counts: &mut RowCounts,
    ) -> LineCounts {
        let s = &self.sampler;
        let ch = self.scene.channel_count();
        let columns = s.columns();
        // the A-buffer keeps no depth line: its fragments are the buffer
        line.reset(if self.abuffer { 0 } else { columns });
        unset.reset(columns);
        let flat = self.shading == Shading::Flat;
        let mut span_id = 0u32;
        let mut set = Vec::new();
        let mut slots: Vec<usize> = Vec::new();
        let mut taken = Vec::new();
        let rule = self.rule;
        let shadows = self.scene.shadows.is_some();
        // with shadows: the lights reaching each sample of the span, and the polygons
        // relit for the light sets met on this line
        let mut lights: Vec<LightSet> = Vec::new();
        let mut relit: HashMap<(u32, LightSet), Poly> = HashMap::new();
        sweep.line(j, y, |k, p: &Poly, aet| {
            counts.polygons_walked += 1;
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
                counts.spans += 1;
                lights.clear();
                if shadows {
                    // a test per sample only where a light reaches part of the triangle
                    match self.scene.uniform_lit(p) {
                        Some(LightSet::ALL) => {}
                        Some(set) => lights.resize(end - first, set),
                        None => {
                            if let Some(line) = self.scene.line_lights(p, y) {
                                counts.shadow_spans += 1;
                                counts.shadow_crossings += line.crossings();
                                counts.shadow_comparisons += line.comparisons();
                                lights.extend((first..end).map(|c| line.at(s.column_x(c))));
                            }
                        }
                    }
                }
                let light_of = |c: usize| lights.get(c - first).copied().unwrap_or(LightSet::ALL);
                let mut relit_of = |lit: LightSet| -> Poly {
                    relit
                        .entry((k, lit))
                        .or_insert_with(|| self.scene.relit(p, lit))
                        .clone()
                };
                if rule == Rule::Claim {
                    // the array keeps the list: claim the whole span (a run per light set
                    // with shadows), count what its locks will suppress
                    let mut c = first;
                    while c < end {
                        let (start, here) = (c, light_of(c));
                        while c < end && light_of(c) == here {
                            c += 1;
                        }
                        if start != first {
                            span_id += 1;
                        }
                        let flat = if here == LightSet::ALL {
                            p.flat
                        } else {
                            relit_of(here).flat
                        };
                        for x in start..c {
                            if line.owner[x] == NONE {
                                line.owner[x] = k;
                                line.span[x] = span_id;
                                line.val[x] = flat;
                                counts.pixels_set += 1;
                            } else {
                                counts.suppressed_claims += 1;
                            }
                        }
                        if let Some(out) = out.as_deref_mut() {
                            out.push(Instruction::eval0(
                                start as u32,
                                (c - start) as u32,
                                Intensity::new(&flat[..ch]),
                            ));
                        }
                    }
                    continue;
                }
                // the span's values from `q`'s: its Gouraud chain's value at sample `at`
                // and its step
                let values = |q: &Poly, at: usize| -> (Vector, Vector) {
                    if flat || self.per_pixel() {
                        (q.flat, Vector::default())
                    } else {
                        let il = edge_value(q, a, y, ch);
                        let ir = edge_value(q, b, y, ch);
                        let d = span_gradient(&il, &ir, a.xc, b.xc, ch);
                        let dx = s.column_x(at) - a.xc;
                        // the chain steps one sample column: 1 pixel at one sample, else
                        // 1/l (centre grid) or 1/(l − 1) (corner grid)
                        let per = f64::from(s.step_count());
                        let step = cwisim_scene::vector(ch, |c| d[c] / per);
                        (cwisim_scene::vector(ch, |c| il[c] + dx * d[c]), step)
                    }
                };
                let (mut v, span_step) = values(p, first);
                set.clear();
                slots.clear();
                match rule {
                    Rule::Nearer if self.abuffer => set.resize(end - first, true),
                    Rule::Nearer if self.transparent => {
                        for c in first..end {
                            let key = p.key(s.column_x(c), y);
                            let at = line.layers.insert(c, key, k, p.transmittance);
                            set.push(at.is_some());
                            slots.push(at.unwrap_or(0));
                        }
                    }
                    Rule::Nearer => {
                        for c in first..end {
                            let key = p.key(s.column_x(c), y);
                            set.push(key < line.key[c]);
                            if key < line.key[c] {
                                line.key[c] = key;
                            }
                        }
                    }
                    Rule::Paint => set.resize(end - first, true),
                    Rule::Unset => {
                        set.resize(end - first, false);
                        counts.list_visits += unset.take(first, end, &mut taken);
                        for &(u, w) in &taken {
                            set[u - first..w - first].iter_mut().for_each(|x| *x = true);
                        }
                    }
                    Rule::Claim => unreachable!("handled above"),
                }
                // runs of samples set, in order
                let mut c = first;
                while c < end {
                    if !set[c - first] {
                        for x in v.iter_mut().zip(&span_step) {
                            *x.0 += x.1;
                        }
                        c += 1;
                        continue;
                    }
                    let (start, here) = (c, light_of(c));
                    while c < end && set[c - first] && light_of(c) == here {
                        c += 1;
                    }
                    if shadows && start != first {
                        // a run of its own, so that it is sent with its own values
                        span_id += 1;
                    }
                    // the span's chain where every light reaches; the relit polygon's
                    // own chain from the run's start where some does not
                    let (v0, d) = if here == LightSet::ALL {
                        (v, span_step)
                    } else {
                        values(&relit_of(here), start)
                    };
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
                        if self.abuffer {
                            line.frags.add(x, k, &w, s.column_x(x), y);
                            for q in w.iter_mut().zip(&d) {
                                *q.0 += q.1;
                            }
                            continue;
                        }
                        if self.transparent {
                            line.layers.set_val(x, slots[x - first], w);
                            for q in w.iter_mut().zip(&d) {
                                *q.0 += q.1;
                            }
                            continue;
                        }
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
                    if here == LightSet::ALL {
                        v = w;
                    } else {
                        // the span's own chain steps over the relit run
                        for _ in start..c {
                            for q in v.iter_mut().zip(&span_step) {
                                *q.0 += q.1;
                            }
                        }
                    }
                }
            }
            // Gordon & Chen: the walk stops once every sample is set
            let more = !(rule == Rule::Unset && unset.is_empty());
            if !more {
                counts.walks_stopped += 1;
            }
            more
        })
    }

    /// The visible runs of a one-sample line, sent.
    fn send_visible(&self, line: &DepthLine, row: u32, out: &mut Out<'_>) -> io::Result<()> {
        let ch = self.scene.channel_count();
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
                if self.per_pixel() {
                    let p = &self.list[o as usize];
                    targets.clear();
                    let y = f64::from(row) + 0.5;
                    for c in x..e {
                        let v = self
                            .scene
                            .phong(p, c as f64 + 0.5, y)
                            .map_err(scene_io)?
                            .unwrap_or_default();
                        targets.extend_from_slice(&v[..ch]);
                    }
                    let mut pieces = Vec::new();
                    let s = fit_span(x as u32, &targets, ch, self.shade_tolerance, &mut pieces)?;
                    out.list.extend(pieces);
                    out.counts.spans_fitted(&s);
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

    /// The visible runs of a line, counted only.
    fn count_visible(line: &DepthLine) -> u64 {
        let mut runs = 0;
        let mut x = 0;
        while x < line.owner.len() {
            let (o, sp) = (line.owner[x], line.span[x]);
            let mut e = x + 1;
            while e < line.owner.len() && line.owner[e] == o && line.span[e] == sp {
                e += 1;
            }
            runs += u64::from(o != NONE);
            x = e;
        }
        runs
    }

    /// A sub-scanline's samples as `woo-chall`'s emitter takes them: winners and colours.
    /// With transparency each sample's winner is its list's front and its colour the
    /// list's composite (and the line's owners are set to the fronts, for the counts).
    fn subline_of(&self, line: &mut DepthLine, y: f64, sub: &mut Subline) -> io::Result<()> {
        if self.transparent {
            return self.composite_of(line, y, sub);
        }
        sub.winners.clone_from(&line.owner);
        sub.rgb.clear();
        for (c, &o) in line.owner.iter().enumerate() {
            sub.rgb.push(match o {
                NONE => Vector::default(),
                _ if self.per_pixel() => self
                    .scene
                    .phong(&self.list[o as usize], self.sampler.column_x(c), y)
                    .map_err(scene_io)?
                    .unwrap_or_default(),
                _ => line.val[c],
            });
        }
        Ok(())
    }

    /// [`Self::subline_of`] with transparency: the lists composited.
    fn composite_of(&self, line: &mut DepthLine, y: f64, sub: &mut Subline) -> io::Result<()> {
        sub.winners.clear();
        sub.rgb.clear();
        for c in 0..line.owner.len() {
            let list = line.layers.list(c);
            let front = list.first().map_or(NONE, |l| l.owner);
            line.owner[c] = front;
            line.span[c] = 0;
            sub.winners.push(front);
            let x = self.sampler.column_x(c);
            sub.rgb.push(composite(list, |l| -> io::Result<Vector> {
                if self.per_pixel() {
                    Ok(self
                        .scene
                        .phong(&self.list[l.owner as usize], x, y)
                        .map_err(scene_io)?
                        .unwrap_or_default())
                } else {
                    Ok(l.val)
                }
            })?);
        }
        Ok(())
    }

    /// The bytes of the one-scanline buffer, from the sizes of what it holds: the
    /// A-buffer's fragments on the row holding most, with a list per pixel; the S-buffer's
    /// depth line (depth, owner, span, value and gradient per sample column) and, with
    /// several samples per pixel or transparency, the row's sub-scanlines kept for the
    /// emitter (a winner and a colour per sample column); with transparency its lists
    /// are not counted (their length varies: `max_layers`).
    fn buffer_bytes(&self, max_fragments: usize) -> u64 {
        use std::mem::size_of;
        let width = self.scene.width as usize;
        let bytes = if self.abuffer {
            max_fragments * size_of::<Fragment>() + width * size_of::<Vec<Fragment>>()
        } else {
            let columns = self.sampler.columns();
            let depth =
                columns * (size_of::<f64>() + 2 * size_of::<u32>() + 2 * size_of::<Vector>());
            let kept = if self.one_sample() && !self.transparent {
                0
            } else {
                self.sampler.l as usize * columns * (size_of::<u32>() + size_of::<Vector>())
            };
            depth + kept
        };
        bytes as u64
    }

    /// The A-buffer's row: each pixel's fragments resolved (their depth at the pixel
    /// centre orders them; a fragment's colour is its samples' mean, or with per-pixel
    /// lighting the shade at their centroid) and sent as `woo-chall`'s emitter sends a
    /// merged row: runs of pixels one polygon covers whole and in front through the span
    /// fitter, the others one `Eval1` each.
    fn resolve_row(
        &self,
        frags: &FragmentLine,
        row: u32,
        list: &mut Vec<Instruction>,
    ) -> io::Result<EmitCounts> {
        let ch = self.scene.channel_count();
        let width = self.scene.width as usize;
        let yc = f64::from(row) + 0.5;
        let mut targets = vec![0.0; width * ch];
        let mut class = vec![Class::Empty; width];
        for x in 0..width {
            let xc = x as f64 + 0.5;
            let r = resolve(
                frags.pixel(x),
                frags.side,
                ch,
                |f| self.list[f.owner as usize].key(xc, yc),
                |f| -> io::Result<Vector> {
                    let n = f64::from(f.mask.count_ones());
                    if self.per_pixel() {
                        Ok(self
                            .scene
                            .phong(&self.list[f.owner as usize], f.at[0] / n, f.at[1] / n)
                            .map_err(scene_io)?
                            .unwrap_or_default())
                    } else {
                        Ok(cwisim_scene::vector(ch, |c| f.sum[c] / n))
                    }
                },
            )?;
            targets[x * ch..(x + 1) * ch].copy_from_slice(&r.value[..ch]);
            class[x] = match r.interior {
                _ if r.empty => Class::Empty,
                Some(k) => Class::Interior(k),
                None => Class::Mixed,
            };
        }
        let rule = EmitRule {
            merge: true,
            tolerance: self.per_pixel().then_some(self.shade_tolerance),
            channels: ch,
        };
        let mut counts = EmitCounts::default();
        send(&targets, &class, &rule, 1, list, &mut counts)?;
        Ok(counts)
    }

    /// Runs the whole frame in scan order.
    pub(crate) fn run(&self) -> io::Result<SFrame> {
        let s = &self.sampler;
        let height = self.scene.height;
        let mut sweep = Sweep::new(
            self.list,
            s.sublines(),
            |j| s.subline_y(j),
            |y| first_at_or_after(s, y),
            self.rank.clone(),
            self.increment,
        );
        let ch = self.scene.channel_count();
        let mut line = DepthLine::default();
        let mut unset = UnsetList::default();
        let mut rows = Vec::with_capacity(height as usize);
        let mut row_counts = Vec::with_capacity(height as usize);
        let mut figures = Vec::with_capacity(height as usize);
        let l = s.l as usize;
        let mut sublines: Vec<Subline> = vec![Subline::default(); l];
        // which rules send runs while they fill (a Phong run's values are per pixel,
        // lit and fitted when the line is done: the unset list's runs wait for it too)
        let sends_while_filling = match self.rule {
            Rule::Nearer => self.overdraw,
            Rule::Unset => !self.per_pixel(),
            Rule::Claim => true,
            Rule::Paint => false,
        };
        let release = self.scene.texture_release();
        let mut max_fragments = 0usize;
        for row in 0..height {
            let mut list = Vec::new();
            let mut counts = RowCounts::default();
            let cp_before = sweep.stats;
            let (mut active, mut aet) = (0u64, 0u64);
            if self.abuffer {
                let (first, _) = s.of_pixel(row);
                line.frags.reset(self.scene.width as usize, l);
                for o in 0..l {
                    line.frags.sub = o;
                    let j = first + o;
                    let lc = self.fill_line(
                        &mut sweep,
                        j,
                        s.subline_y(j),
                        &mut line,
                        &mut unset,
                        None,
                        &mut counts,
                    );
                    active = active.max(lc.active);
                    aet = aet.max(lc.aet);
                }
                counts.fragments += line.frags.count as u64;
                max_fragments = max_fragments.max(line.frags.count);
                let c = self
                    .resolve_row(&line.frags, row, &mut list)
                    .map_err(|e| NonFinite::at_row(e, row))?;
                counts.eval1 += c.edge_pixels + c.runs.eval1;
                counts.eval2 += c.runs.eval2;
                counts.eval3 += c.runs.eval3;
                counts.fit_candidates += c.runs.candidates;
                counts.instructions += c.instructions;
                list.push(Instruction::refresh());
                counts.instructions += 1;
            } else if self.one_sample() && !self.transparent {
                let y = f64::from(row) + 0.5;
                let mut sent = RowCounts::default();
                let lc = {
                    let mut out = Out {
                        list: &mut list,
                        counts: &mut sent,
                    };
                    self.fill_line(
                        &mut sweep,
                        row as usize,
                        y,
                        &mut line,
                        &mut unset,
                        sends_while_filling.then_some(&mut out),
                        &mut counts,
                    )
                };
                (active, aet) = (lc.active, lc.aet);
                counts.add(&sent);
                if sends_while_filling {
                    counts.visible_runs += Scan::count_visible(&line);
                } else {
                    let mut visible = RowCounts::default();
                    self.send_visible(
                        &line,
                        row,
                        &mut Out {
                            list: &mut list,
                            counts: &mut visible,
                        },
                    )
                    .map_err(|e| NonFinite::at_row(e, row))?;
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
                    let y = s.subline_y(j);
                    let lc =
                        self.fill_line(&mut sweep, j, y, &mut line, &mut unset, None, &mut counts);
                    active = active.max(lc.active);
                    aet = aet.max(lc.aet);
                    self.subline_of(&mut line, y, sub)?;
                    counts.visible_runs += Scan::count_visible(&line);
                }
                let refs: Vec<&Subline> = sublines.iter().collect();
                let rule = EmitRule {
                    merge: self.merge,
                    tolerance: self.per_pixel().then_some(self.shade_tolerance),
                    channels: ch,
                };
                let c =
                    emit_row(s, &refs, &rule, &mut list).map_err(|e| NonFinite::at_row(e, row))?;
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
                "polygons_walked": counts.polygons_walked,
                "pixels_set": counts.pixels_set,
                "pixels_overwritten": counts.pixels_overwritten,
                "visible_runs": counts.visible_runs,
                "suppressed_claims": counts.suppressed_claims,
                "instructions": counts.instructions,
            }));
            rows.push(list);
            row_counts.push(counts);
            if let Some(r) = &release {
                r.rows_done(row..row + 1);
            }
        }
        let critical = self
            .list
            .iter()
            .map(|p| p.cp.critical_points().len() as u64)
            .sum();
        let frame = Counters::default()
            .with("polygons", self.list.len() as u64)
            .with(
                "vertices",
                self.list.iter().map(|p| p.cp.len() as u64).sum(),
            )
            .with("critical_points", critical)
            .with("max_active_polygons", sweep.max_active)
            .with("max_aet", sweep.max_aet)
            .with("moveup_steps", sweep.stats.moveup_steps)
            .with("aet_inserts", sweep.stats.inserts)
            .with("aet_insert_scans", sweep.stats.insert_scans)
            .with("aet_deletes", sweep.stats.deletes)
            .with("cp_recomputes", sweep.stats.recomputes)
            .with("cp_increments", sweep.stats.increments)
            .with("buffer_bytes", self.buffer_bytes(max_fragments));
        let frame = if self.transparent {
            frame.with("max_layers", line.layers.max_len as u64)
        } else {
            frame
        };
        Ok(SFrame {
            rows,
            row_counts,
            figures: serde_json::Value::from(figures),
            frame,
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

impl crate::renderer::FramePlan for SFrame {
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
                "{} polygons, {} vertices, {} critical points; APT at most {}, AETs at most {} elements on a line; {} MOVEUP steps, {} inserts (past {} elements), {} deletes; intersections {} recomputed, {} incremented",
                get("polygons"),
                get("vertices"),
                get("critical_points"),
                get("max_active_polygons"),
                get("max_aet"),
                get("moveup_steps"),
                get("aet_inserts"),
                get("aet_insert_scans"),
                get("aet_deletes"),
                get("cp_recomputes"),
                get("cp_increments"),
            ),
        ),
        (
            "pixels",
            format!(
                "{} spans, {} samples set, {} of them overwritten; {} visible runs",
                get("spans"),
                get("pixels_set"),
                get("pixels_overwritten"),
                get("visible_runs"),
            ),
        ),
        (
            "emitted",
            format!(
                "{} instructions: Eval0 {}, Eval1 {}, Eval2 {}, Eval3 {}; {} undo runs, {} Acc_mode",
                get("instructions"),
                get("eval0"),
                get("eval1"),
                get("eval2"),
                get("eval3"),
                get("undo_runs"),
                get("acc_mode"),
            ),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unset_list_takes_what_a_span_covers() {
        let mut l = UnsetList::default();
        l.reset(10);
        let mut taken = Vec::new();
        assert_eq!(l.take(2, 4, &mut taken), 1);
        assert_eq!(taken, [(2, 4)]);
        assert_eq!(l.runs(), [(0, 2), (4, 10)]);
        // a span across the hole takes both sides of it
        l.take(1, 6, &mut taken);
        assert_eq!(taken, [(1, 2), (4, 6)]);
        assert_eq!(l.runs(), [(0, 1), (6, 10)]);
        l.take(0, 10, &mut taken);
        assert!(l.is_empty());
        assert_eq!(l.take(3, 5, &mut taken), 0);
        assert!(taken.is_empty());
    }

    #[test]
    fn an_undo_skips_what_the_array_dropped() {
        // a two-channel run: channel 1 drifts below 0 at its last two pixels (the array
        // dropped those values), channel 0 stays positive
        let mut line = DepthLine::default();
        line.reset(4);
        let vals = [[0.5, 0.3], [0.4, 0.1], [0.3, -1e-17], [0.2, -0.1]];
        for (k, v) in vals.iter().enumerate() {
            line.owner[k] = 0;
            line.val[k] = cwisim_scene::vector(2, |c| v[c]);
            line.grad[k] = cwisim_scene::vector(2, |c| [-0.1, -0.2][c]);
        }
        let (mut list, mut counts) = (Vec::new(), RowCounts::default());
        let mut out = Out {
            list: &mut list,
            counts: &mut counts,
        };
        undo_run(&mut out, &line, 0, 4, false, 2);
        assert_eq!(counts.undo_runs, 2);
        assert_eq!(
            list,
            [
                Instruction::eval2(
                    0,
                    2,
                    Intensity::new(&[-0.5, -0.3]),
                    Intensity::new(&[0.1, 0.2])
                ),
                // channel 1 undone no further: 0 plus 0
                Instruction::eval2(
                    2,
                    2,
                    Intensity::new(&[-0.3, 0.0]),
                    Intensity::new(&[0.1, 0.0])
                ),
            ]
        );
    }
}
