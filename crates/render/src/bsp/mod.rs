//! `bsp`: BSP trees displayed in scanline order — Barkan & Gordon, *The scanline
//! principle*, section 4.3 — as a Y-processor. A BSP tree is built in world space over
//! the scene's triangles (spanning triangles split: [`tree`]), traversed from the camera
//! into a priority order, and the pieces are scan-converted by CP ([`crate::cp`]) one
//! scanline at a time, the active polygon table walked in that order:
//!
//! * `--order back-to-front`: painter's, into a host colour line (the array cannot
//!   overwrite: it only adds), the line's visible runs then sent; the overdraw is
//!   reported (`pixels_overwritten`).
//! * `--order front-to-back --unset host`: Gordon & Chen's run-length list of unset
//!   pixels, one per scanline: a span sets only what the list still holds, those newly
//!   set runs are sent at once, and the scanline's walk stops when the list is empty
//!   (output-sensitive: the polygons not reached are not even advanced).
//! * `--order front-to-back --unset eval0`: every active span sent as `Eval0`: the array's
//!   lock bits are the list of unset pixels, the first claim wins; `suppressed_claims`
//!   counts what the locks suppress. Exact only with flat shading at one sample per pixel
//!   (an `Eval0` sets one value over its range and claims whole pixels).
//!
//! A screen scene's polygons are triangulated and placed at `(x, y, depth)` (their depth
//! plane, or painting order without depth), seen along `+depth`.
//!
//! The scan itself (FILL's rules, the row's emission, supersampling) is the S-buffer's
//! ([`crate::sbuffer::fill`]).

pub mod tree;

use crate::cp::{CpPolygon, Increment};
use crate::error::RenderError;
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::sbuffer::fill::{cp_rows, Rule, Scan};
use crate::sbuffer::polys::{Poly, Polys};
use crate::settings::{BspOrder, Settings, Unset};
use crate::source::LoadedScene;
use crate::subsample::{Grid, Sampler};
use cwisim_isa::TraceHeader;
use cwisim_scene::Shading;
use cwisim_world::face::ScreenTriangle;
use cwisim_xproc::{Image, RunStats};
use glam::DVec3;
use std::time::{Duration, Instant};
use tree::{Piece, Tree, View};

/// The registry's one line about it.
pub const ABOUT: &str = "Barkan & Gordon's BSP display in scanline order: a world-space BSP tree (splits counted), pieces scan-converted by CP per scanline in tree order (--order back-to-front|front-to-back, --unset host|eval0)";

/// The BSP renderer of a world scene.
pub struct Bsp {
    polys: Polys,
    pieces: Vec<Poly>,
    rank: Vec<u32>,
    splits: u64,
    depth: u64,
    sampler: Sampler,
    shading: Shading,
    increment: Increment,
    order: BspOrder,
    unset: Unset,
    merge: bool,
    shade_tolerance: f64,
    build_time: Duration,
}

/// What the BSP renderer holds a triangle of a world scene, the meshes aside: the
/// polygons, their pieces in the world, the tree and the pieces its planes split off
/// (1,940–2,540 bytes measured on the teapot and the pot; `tests/projection_memory.rs`),
/// checked against the memory budget before projecting. A scene whose planes split far
/// more pieces than these is stopped as its tree grows ([`PIECE_BYTES`]).
pub const BYTES_PER_TRIANGLE: u64 = 2_800;

/// What each piece of the tree holds, with its polygon for the scan, its rank and its
/// place in the nodes' lists (738–905 bytes measured on the teapot and the pot;
/// `tests/projection_memory.rs`): the tree stops, and the scene is refused, once its
/// splits make more pieces than the memory budget leaves room for beside the polygons.
pub const PIECE_BYTES: u64 = 1_000;

impl Bsp {
    /// The renderer of `loaded` under `settings`.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<Bsp, RenderError> {
        let loaded = loaded.drawn_as(settings)?;
        settings.check().map_err(RenderError::Usage)?;
        let polys = Polys::new(loaded, settings, "bsp", BYTES_PER_TRIANGLE)?;
        let sampler = Sampler::new(settings.samples, settings.grid, polys.width, polys.height)
            .map_err(RenderError::Usage)?;
        let eval0 = settings.bsp_order == BspOrder::FrontToBack && settings.unset == Unset::Eval0;
        if eval0 && settings.shading != Shading::Flat {
            return Err(RenderError::Usage(format!(
                "--unset eval0 claims each span with one Eval0 value (no gradient, no per-pixel shade): exact with --shading flat only, found {}; use --unset host",
                settings.shading
            )));
        }
        if eval0 && polys.textured() {
            return Err(RenderError::Usage(
                "--unset eval0 claims each span with one Eval0 value, and a texture changes within a span: use --unset host".into(),
            ));
        }
        if eval0 && (sampler.l != 1 || sampler.grid != Grid::Centre) {
            return Err(RenderError::Usage(
                "--unset eval0 locks whole pixels, so the first polygon to reach a pixel would own all its samples: exact at one sample per pixel only; use --samples 1 or --unset host".into(),
            ));
        }
        let start = Instant::now();
        let channels = polys.channel_count();
        let (pieces, view) = match (polys.eye, polys.triangles.as_ref()) {
            (Some(eye), Some(tris)) => (
                world_pieces(&polys.polys, tris),
                View::Eye(DVec3::from_array(eye)),
            ),
            _ => (screen_pieces(&polys.polys, channels), View::Along(DVec3::Z)),
        };
        let scale = pieces
            .iter()
            .flat_map(|p| p.world.iter())
            .map(|v| v.abs().max_element())
            .fold(1.0f64, f64::max);
        // the tree's pieces as its splits make them, against what the budget leaves
        // beside the polygons
        let budget = cwisim_scene::budget::Budget::current();
        let polygons = polys.polys.len() as u64;
        let held = polygons.saturating_mul(crate::sbuffer::polys::BYTES_PER_TRIANGLE);
        let max_pieces = budget.memory_bytes.saturating_sub(held) / PIECE_BYTES;
        let tree = Tree::build(
            pieces,
            1e-9 * scale,
            channels,
            usize::try_from(max_pieces).unwrap_or(usize::MAX),
        )
        .map_err(|made| {
            use cwisim_scene::budget::{human, MEMORY_VAR};
            RenderError::Usage(format!(
                "bsp's tree of the scene's {polygons} polygons passes the memory budget of {}: its splits had made {made} pieces ({PIECE_BYTES} bytes each, beside the polygons' {}) when it was stopped (raise it with {MEMORY_VAR}=SIZE, e.g. {MEMORY_VAR}=16G)",
                human(budget.memory_bytes),
                human(held),
            ))
        })?;
        let order = tree.order(view, settings.bsp_order == BspOrder::FrontToBack);
        let mut rank = vec![0u32; tree.pieces.len()];
        for (r, &k) in order.iter().enumerate() {
            rank[k as usize] = r as u32;
        }
        let list = tree
            .pieces
            .iter()
            .map(|piece| {
                let p = &polys.polys[piece.source as usize];
                Poly {
                    cp: CpPolygon::new(&piece.screen),
                    intensity: piece.intensity.clone(),
                    flat: p.flat,
                    plane: p.plane,
                    source: p.source,
                    transmittance: p.transmittance,
                }
            })
            .collect();
        Ok(Bsp {
            build_time: start.elapsed(),
            splits: tree.splits,
            depth: tree.depth,
            pieces: list,
            rank,
            polys,
            sampler,
            shading: settings.shading,
            increment: settings.cp_increment,
            order: settings.bsp_order,
            unset: settings.unset,
            merge: settings.merge_subscanlines,
            shade_tolerance: settings.shade_tolerance,
        })
    }

    /// For the registry.
    pub fn build(
        loaded: LoadedScene,
        settings: &Settings,
    ) -> Result<Box<dyn Renderer>, RenderError> {
        Ok(Box::new(Bsp::new(loaded, settings)?))
    }

    /// The pieces in the tree (the scene's polygons, split), and each one's place in the
    /// display order.
    pub fn pieces(&self) -> (&[Poly], &[u32]) {
        (&self.pieces, &self.rank)
    }

    fn rule(&self) -> Rule {
        match (self.order, self.unset) {
            (BspOrder::BackToFront, _) => Rule::Paint,
            (BspOrder::FrontToBack, Unset::Host) => Rule::Unset,
            (BspOrder::FrontToBack, Unset::Eval0) => Rule::Claim,
        }
    }

    fn scan(&self) -> Scan<'_> {
        Scan {
            scene: &self.polys,
            list: &self.pieces,
            rank: Some(self.rank.clone()),
            sampler: self.sampler,
            shading: self.shading,
            increment: self.increment,
            rule: self.rule(),
            overdraw: false,
            transparent: false,
            abuffer: false,
            merge: self.merge,
            shade_tolerance: self.shade_tolerance,
        }
    }
}

/// A world scene's triangles as pieces: world corners, screen points, `1/depth`.
fn world_pieces(polys: &[Poly], tris: &[ScreenTriangle]) -> Vec<Piece> {
    polys
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let t = &tris[p.source as usize];
            Piece {
                world: t.surface.world.to_vec(),
                screen: t.points.to_vec(),
                w: t.inv_depth.to_vec(),
                intensity: t.intensity.to_vec(),
                source: i as u32,
            }
        })
        .collect()
}

/// A screen scene's polygons as pieces: triangulated (ear clipping, so that every piece
/// is convex and a split cuts it in two), each point `(x, y, depth key)` seen along
/// `+depth` (a parallel view: `1/depth` taken as 1, so a split is linear on the screen).
fn screen_pieces(polys: &[Poly], channels: usize) -> Vec<Piece> {
    let mut earcut = earcut::Earcut::new();
    let mut indices: Vec<u32> = Vec::new();
    let mut pieces = Vec::new();
    for (i, p) in polys.iter().enumerate() {
        let v: Vec<[f64; 2]> = (0..p.cp.len()).map(|k| p.cp.vertex(k)).collect();
        earcut.earcut(v.iter().copied(), &[] as &[u32], &mut indices);
        for t in indices.chunks_exact(3) {
            let k = [t[0] as usize, t[1] as usize, t[2] as usize];
            pieces.push(Piece {
                world: k
                    .iter()
                    .map(|&j| DVec3::new(v[j][0], v[j][1], p.key(v[j][0], v[j][1])))
                    .collect(),
                screen: k.iter().map(|&j| v[j]).collect(),
                w: vec![1.0; 3],
                intensity: k
                    .iter()
                    .map(|&j| cwisim_scene::vector(channels, |c| p.intensity[j][c]))
                    .collect(),
                source: i as u32,
            });
        }
    }
    pieces
}

impl Renderer for Bsp {
    fn name(&self) -> &'static str {
        "bsp"
    }

    fn header(&self) -> TraceHeader {
        self.polys.header()
    }

    fn frame<'a>(
        &'a self,
        _index: u32,
        _previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        let mut frame = self
            .scan()
            .run()
            .map_err(|source| RenderError::of_renderer("bsp", source))?;
        frame.frame = std::mem::take(&mut frame.frame)
            .with("bsp_triangles", self.polys.polys.len() as u64)
            .with("bsp_splits", self.splits)
            .with("bsp_depth", self.depth);
        Ok(Box::new(frame))
    }

    fn settings_phrase(&self) -> String {
        let s = &self.sampler;
        let sampling = if self.scan().one_sample() {
            "one sample per pixel (its centre)".to_string()
        } else {
            format!("{l}×{l} {} grid", s.grid, l = s.l)
        };
        let how = match self.rule() {
            Rule::Paint => "back to front, painted into a host colour line",
            Rule::Unset => "front to back, unset pixels listed on the host",
            _ => "front to back, Eval0 claims (the array's locks list the unset pixels)",
        };
        format!(
            "{} shading, {sampling}, {how}, CP increment {}",
            self.shading.title(),
            self.increment
        )
    }

    fn summary_rows(&self, c: &Counters, _stats: &RunStats) -> Vec<(&'static str, String)> {
        let get = |n: &str| c.get(n).unwrap_or(0);
        let mut rows = self.polys.summary_rows();
        rows.push((
            "BSP",
            format!(
                "{} triangles → {} pieces ({} splits), depth {}; {} polygon visits, {} walks stopped early ({} unset-list entries visited); {} claimed samples suppressed",
                get("bsp_triangles"),
                get("polygons"),
                get("bsp_splits"),
                get("bsp_depth"),
                get("polygons_walked"),
                get("walks_stopped"),
                get("unset_list_visits"),
                get("suppressed_claims"),
            ),
        ));
        rows.extend(cp_rows(c));
        if self.polys.transparent() {
            rows.push((
                "note",
                "meshes with a transmittance drawn opaque: this renderer keeps the nearest surface (woo-chall and sbuffer --sbuffer transparent composite the layers)".to_string(),
            ));
        }
        rows
    }

    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        let mut times = vec![("transform & lighting", self.polys.transform_time)];
        if self.polys.shadows.is_some() {
            times.push(("shadows", self.polys.shadow_time));
        }
        times.push(("BSP tree", self.build_time));
        times
    }

    fn scene_json(&self) -> serde_json::Value {
        self.polys.scene_json()
    }
}
