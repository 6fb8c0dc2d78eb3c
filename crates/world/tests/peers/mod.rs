//! cwisim's anti-aliased polygon fill and three peer rasterizers on the same polygons, at
//! the same size: shared by `benches/peers.rs` (time), `examples/peer_accuracy.rs` (the
//! error table) and `tests/peer_accuracy.rs` (the error ordering, checked).
//!
//! # The polygon sets
//!
//! * [`pot`] — the visible fragments of the embedded `pot` (exact visibility): simple,
//!   disjoint polygons, so their coverages never add up past 1.
//! * [`random`] — 200 random triangles and quads (a seeded xorshift), 10–200 px across at
//!   1024×1024 (scaled with the image), overlapping each other.
//!
//! # What is compared
//!
//! The quantity is the one the array computes: the **sum over the polygons of each
//! polygon's exact box-filtered coverage** of a pixel (its area ∩ pixel), which exceeds 1
//! where polygons overlap. The reference is [`Exact`]: `cwisim_ypipe::exact::coverage` per
//! polygon, summed. cwisim's value is the array's output for the scene with intensity 1 on
//! every vertex and flat shading ([`coverage_scene`], [`cwisim_image`]; the same in bands
//! of rows, as `cwisim render` runs it, [`cwisim_image_in_bands`]).
//!
//! The peers are driven two ways ([`Mode`]):
//!
//! * [`Mode::PerPolygon`] — each polygon alone, into the peer's own coverage buffer of the
//!   polygon's pixel bounding box, then added into a `width × height` `f32` image. This is
//!   exactly the summed quantity, for any set (overlaps included).
//! * [`Mode::OnePath`] — every polygon as a subpath of **one** path, filled once (non-zero
//!   rule) into one `width × height` buffer of the peer's native type (`u8` for zeno and
//!   tiny-skia, `f32` for ab_glyph_rasterizer): the peers' fastest use. For disjoint
//!   polygons of one orientation (all outlines are made counter-clockwise, see
//!   [`outlines`]) the exact-area peers compute the same sum; tiny-skia composes subpaths'
//!   coverage per supersample, so where two fragments share an edge it also equals the sum.
//!   Only meaningful for the pot (overlapping polygons would be united, not added).
//!
//! Every peer gets `f32` coordinates: for [`Mode::PerPolygon`] relative to the integer
//! corner of the polygon's pixel box (computed in `f64`), for [`Mode::OnePath`] the
//! absolute ones.

#![allow(dead_code)] // each of the three targets uses a part

use cwisim_isa::{Instruction, TraceWrite};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, to_screen, AnyScene, Visibility};
use cwisim_xproc::{Band, EngineWriter, ImageSink, Machine, Timing};
use cwisim_ypipe::clip::clip_to_rect;
use cwisim_ypipe::exact::coverage;
use cwisim_ypipe::{emit, emit_rows, header, Antialias, Claim, Options, ScanPlan, Shading};
use std::io;

// ---------------------------------------------------------------------------------------
// The polygon sets.

/// The visible fragments of the embedded pot at `size × size`, with the scene's Gouraud
/// intensities (exact visibility).
pub fn pot(size: u32) -> ScreenScene {
    let AnyScene::World(w) = parse_any(embedded("pot").expect("the pot is embedded").text, None)
        .expect("the pot reads")
        .with_size(size, size)
        .expect("the size is valid")
    else {
        panic!("the pot is a world scene")
    };
    to_screen(&w, Shading::Gouraud, Visibility::Exact)
        .expect("the pot projects")
        .screen
}

/// A small deterministic generator (xorshift64*), so every run draws the same polygons.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `count` random triangles and quads in a `size × size` image, one grey channel with a
/// random intensity per vertex; each polygon is `(10 + 190 u) · size / 1024` pixels across
/// its circumscribing circle, wholly inside the image, and overlaps whatever it falls on.
///
/// Each is star-shaped about its centre: vertex `k` of `n` at the angle
/// `2π (k + 0.8 u) / n` (plus a random phase), at a radius of ½ to 1 times the circle's,
/// so it is simple (for quads every angular gap is below π) and not degenerate.
pub fn random(size: u32, count: usize, seed: u64) -> ScreenScene {
    let mut rng = Rng(seed | 1);
    let side = f64::from(size);
    let scale = side / 1024.0;
    let polygons = (0..count)
        .map(|_| {
            let r = 0.5 * scale * (10.0 + 190.0 * rng.unit());
            let (cx, cy) = (
                r + (side - 2.0 * r) * rng.unit(),
                r + (side - 2.0 * r) * rng.unit(),
            );
            let n = if rng.next() & 1 == 0 { 3 } else { 4 };
            let phase = std::f64::consts::TAU * rng.unit();
            let vertices: Vec<[f64; 2]> = (0..n)
                .map(|k| {
                    let a =
                        phase + std::f64::consts::TAU * (k as f64 + 0.8 * rng.unit()) / n as f64;
                    let rk = r * (0.5 + 0.5 * rng.unit());
                    [cx + rk * a.cos(), cy + rk * a.sin()]
                })
                .collect();
            let intensity = (0..n).map(|_| vec![rng.unit()]).collect();
            Polygon::new(vertices, intensity)
        })
        .collect();
    let scene = ScreenScene {
        width: size,
        height: size,
        channels: 1,
        polygons,
    };
    scene.validate().expect("random polygons are simple");
    scene
}

/// The scene with intensity 1 on every vertex (one channel): what the array outputs for
/// it with flat shading is each pixel's summed coverage.
pub fn coverage_scene(scene: &ScreenScene) -> ScreenScene {
    ScreenScene {
        width: scene.width,
        height: scene.height,
        channels: 1,
        polygons: scene
            .polygons
            .iter()
            .map(|p| Polygon::uniform(p.vertices.clone(), &[1.0]))
            .collect(),
    }
}

/// The polygons as the peers get them: clipped to the image (exactly; a no-op for both
/// sets, which lie inside), fewer than 3 vertices dropped, and made counter-clockwise on
/// screen (positive shoelace sum in x-right, y-down coordinates) so that one-path fills of
/// disjoint polygons add up instead of cancelling.
pub fn outlines(scene: &ScreenScene) -> Vec<Vec<[f64; 2]>> {
    let (w, h) = (f64::from(scene.width), f64::from(scene.height));
    scene
        .polygons
        .iter()
        .filter_map(|p| {
            let mut v = clip_to_rect(p, 0.0, 0.0, w, h).vertices;
            if v.len() < 3 {
                return None;
            }
            let o = v[0];
            let twice_area: f64 = (0..v.len())
                .map(|k| {
                    let (a, b) = (v[k], v[(k + 1) % v.len()]);
                    (a[0] - o[0]) * (b[1] - o[1]) - (b[0] - o[0]) * (a[1] - o[1])
                })
                .sum();
            if twice_area < 0.0 {
                v.reverse();
            }
            Some(v)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// The peers.

/// A peer rasterizer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Peer {
    /// `zeno`: FreeType-style cells (24.8 fixed point) accumulating exact area and cover;
    /// `u8` masks.
    Zeno,
    /// `ab_glyph_rasterizer`: exact signed area per pixel in an `f32` accumulation buffer
    /// (font-rs).
    AbGlyph,
    /// `tiny-skia`: anti-aliased fill by 4× supersampling in each direction (16 levels
    /// per pixel, run-length accumulated); `u8` masks.
    TinySkia,
}

impl Peer {
    /// Every peer.
    pub const ALL: [Peer; 3] = [Peer::Zeno, Peer::AbGlyph, Peer::TinySkia];

    /// The crate's name.
    pub fn name(self) -> &'static str {
        match self {
            Peer::Zeno => "zeno",
            Peer::AbGlyph => "ab_glyph_rasterizer",
            Peer::TinySkia => "tiny-skia",
        }
    }
}

/// How a peer is driven (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Each polygon alone into its pixel box, added into an `f32` image.
    PerPolygon,
    /// All polygons as one path, one fill into one native buffer.
    OnePath,
}

impl Mode {
    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::PerPolygon => "per_polygon",
            Mode::OnePath => "one_path",
        }
    }
}

/// A peer's coverage image, row-major `width × height`, in its native type.
pub enum Coverage {
    /// 0–255 for 0–1 (zeno and tiny-skia, one path).
    U8(Vec<u8>),
    /// Coverage itself (ab_glyph_rasterizer, and every per-polygon sum).
    F32(Vec<f32>),
}

impl Coverage {
    /// Pixel `k`'s coverage.
    pub fn at(&self, k: usize) -> f64 {
        match self {
            Coverage::U8(v) => f64::from(v[k]) / 255.0,
            Coverage::F32(v) => f64::from(v[k]),
        }
    }

    /// Pixels.
    pub fn len(&self) -> usize {
        match self {
            Coverage::U8(v) => v.len(),
            Coverage::F32(v) => v.len(),
        }
    }
}

/// The pixels a polygon can touch, within a `width × height` image: columns `x0..x0 + w`,
/// rows `y0..y0 + h`.
#[derive(Clone, Copy)]
struct PixelBox {
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
}

impl PixelBox {
    fn of(v: &[[f64; 2]], width: u32, height: u32) -> PixelBox {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in v {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let span = |a: usize, n: u32| {
            let first = lo[a].floor().clamp(0.0, f64::from(n)) as usize;
            let end = (hi[a].floor() + 1.0).clamp(0.0, f64::from(n)) as usize;
            (first, end.saturating_sub(first))
        };
        let ((x0, w), (y0, h)) = (span(0, width), span(1, height));
        PixelBox { x0, y0, w, h }
    }

    /// `v` relative to the box's corner, in `f32`.
    fn local(&self, p: [f64; 2]) -> (f32, f32) {
        (
            (p[0] - self.x0 as f64) as f32,
            (p[1] - self.y0 as f64) as f32,
        )
    }

    /// Adds the box-sized row-major `values` into the `width`-wide `image`.
    fn add(&self, image: &mut [f32], width: usize, values: impl Fn(usize) -> f32) {
        for y in 0..self.h {
            let row = &mut image[(self.y0 + y) * width + self.x0..][..self.w];
            for (x, o) in row.iter_mut().enumerate() {
                *o += values(y * self.w + x);
            }
        }
    }
}

/// Fills `outlines` into a `width × height` coverage image with `peer`, driven by `mode`.
pub fn fill(
    peer: Peer,
    mode: Mode,
    outlines: &[Vec<[f64; 2]>],
    width: u32,
    height: u32,
) -> Coverage {
    match (peer, mode) {
        (Peer::Zeno, Mode::PerPolygon) => Coverage::F32(zeno_per_polygon(outlines, width, height)),
        (Peer::Zeno, Mode::OnePath) => Coverage::U8(zeno_one_path(outlines, width, height)),
        (Peer::AbGlyph, Mode::PerPolygon) => {
            Coverage::F32(ab_glyph_per_polygon(outlines, width, height))
        }
        (Peer::AbGlyph, Mode::OnePath) => Coverage::F32(ab_glyph_one_path(outlines, width, height)),
        (Peer::TinySkia, Mode::PerPolygon) => {
            Coverage::F32(tiny_skia_per_polygon(outlines, width, height))
        }
        (Peer::TinySkia, Mode::OnePath) => {
            Coverage::U8(tiny_skia_one_path(outlines, width, height))
        }
    }
}

/// Appends `v` as a closed subpath of zeno commands, each point through `at`.
fn zeno_subpath(
    cmds: &mut Vec<zeno::Command>,
    v: &[[f64; 2]],
    at: impl Fn([f64; 2]) -> (f32, f32),
) {
    for (k, &p) in v.iter().enumerate() {
        let (x, y) = at(p);
        let p = zeno::Point::new(x, y);
        cmds.push(if k == 0 {
            zeno::Command::MoveTo(p)
        } else {
            zeno::Command::LineTo(p)
        });
    }
    cmds.push(zeno::Command::Close);
}

fn zeno_per_polygon(outlines: &[Vec<[f64; 2]>], width: u32, height: u32) -> Vec<f32> {
    let mut image = vec![0.0f32; width as usize * height as usize];
    let mut scratch = zeno::Scratch::new();
    let (mut cmds, mut mask) = (Vec::new(), Vec::new());
    for v in outlines {
        let b = PixelBox::of(v, width, height);
        if b.w == 0 || b.h == 0 {
            continue;
        }
        cmds.clear();
        zeno_subpath(&mut cmds, v, |p| b.local(p));
        mask.clear();
        mask.resize(b.w * b.h, 0u8);
        zeno::Mask::with_scratch(&cmds, &mut scratch)
            .size(b.w as u32, b.h as u32)
            .render_into(&mut mask, None);
        b.add(&mut image, width as usize, |k| f32::from(mask[k]) / 255.0);
    }
    image
}

fn zeno_one_path(outlines: &[Vec<[f64; 2]>], width: u32, height: u32) -> Vec<u8> {
    let mut cmds = Vec::new();
    for v in outlines {
        zeno_subpath(&mut cmds, v, |p| (p[0] as f32, p[1] as f32));
    }
    let mut mask = vec![0u8; width as usize * height as usize];
    let mut scratch = zeno::Scratch::new();
    zeno::Mask::with_scratch(&cmds, &mut scratch)
        .size(width, height)
        .render_into(&mut mask, None);
    mask
}

/// Draws the closed outline `v` into `r`, each point through `at`.
fn ab_glyph_outline(
    r: &mut ab_glyph_rasterizer::Rasterizer,
    v: &[[f64; 2]],
    at: impl Fn([f64; 2]) -> (f32, f32),
) {
    let point = |p| {
        let (x, y) = at(p);
        ab_glyph_rasterizer::point(x, y)
    };
    for k in 0..v.len() {
        r.draw_line(point(v[k]), point(v[(k + 1) % v.len()]));
    }
}

fn ab_glyph_per_polygon(outlines: &[Vec<[f64; 2]>], width: u32, height: u32) -> Vec<f32> {
    let mut image = vec![0.0f32; width as usize * height as usize];
    let mut r = ab_glyph_rasterizer::Rasterizer::new(0, 0);
    let w = width as usize;
    for v in outlines {
        let b = PixelBox::of(v, width, height);
        if b.w == 0 || b.h == 0 {
            continue;
        }
        r.reset(b.w, b.h);
        ab_glyph_outline(&mut r, v, |p| b.local(p));
        r.for_each_pixel(|k, a| image[(b.y0 + k / b.w) * w + b.x0 + k % b.w] += a);
    }
    image
}

fn ab_glyph_one_path(outlines: &[Vec<[f64; 2]>], width: u32, height: u32) -> Vec<f32> {
    let mut r = ab_glyph_rasterizer::Rasterizer::new(width as usize, height as usize);
    for v in outlines {
        ab_glyph_outline(&mut r, v, |p| (p[0] as f32, p[1] as f32));
    }
    let mut image = vec![0.0f32; width as usize * height as usize];
    r.for_each_pixel(|k, a| image[k] = a);
    image
}

/// Appends `v` as a closed subpath, each point through `at`.
fn tiny_skia_subpath(
    pb: &mut tiny_skia::PathBuilder,
    v: &[[f64; 2]],
    at: impl Fn([f64; 2]) -> (f32, f32),
) {
    for (k, &p) in v.iter().enumerate() {
        let (x, y) = at(p);
        if k == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    pb.close();
}

fn tiny_skia_per_polygon(outlines: &[Vec<[f64; 2]>], width: u32, height: u32) -> Vec<f32> {
    let mut image = vec![0.0f32; width as usize * height as usize];
    let mut buf = Vec::new();
    for v in outlines {
        let b = PixelBox::of(v, width, height);
        let Some(size) = tiny_skia::IntSize::from_wh(b.w as u32, b.h as u32) else {
            continue;
        };
        let mut pb = tiny_skia::PathBuilder::new();
        tiny_skia_subpath(&mut pb, v, |p| b.local(p));
        let Some(path) = pb.finish() else {
            continue; // no area
        };
        buf.clear();
        buf.resize(b.w * b.h, 0u8);
        let mut mask = tiny_skia::Mask::from_vec(buf, size).expect("the size matches");
        mask.fill_path(
            &path,
            tiny_skia::FillRule::Winding,
            true,
            tiny_skia::Transform::identity(),
        );
        let data = mask.data();
        b.add(&mut image, width as usize, |k| f32::from(data[k]) / 255.0);
        buf = mask.take();
    }
    image
}

fn tiny_skia_one_path(outlines: &[Vec<[f64; 2]>], width: u32, height: u32) -> Vec<u8> {
    let mut mask = tiny_skia::Mask::new(width, height).expect("a valid size");
    let mut pb = tiny_skia::PathBuilder::new();
    for v in outlines {
        tiny_skia_subpath(&mut pb, v, |p| (p[0] as f32, p[1] as f32));
    }
    if let Some(path) = pb.finish() {
        mask.fill_path(
            &path,
            tiny_skia::FillRule::Winding,
            true,
            tiny_skia::Transform::identity(),
        );
    }
    mask.take()
}

// ---------------------------------------------------------------------------------------
// cwisim.

/// The Y-processor's options: box filter, every pixel accumulates.
pub fn options(shading: Shading) -> Options {
    Options {
        shading,
        aa: Antialias::Box,
        claim: Claim::Accumulate,
    }
}

/// A sink that only counts instructions.
#[derive(Default)]
pub struct Counter(pub u64);

impl TraceWrite for Counter {
    fn write(&mut self, _instr: &Instruction) -> io::Result<()> {
        self.0 += 1;
        Ok(())
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// The Y-processor alone: the box-filtered stream of `scene` into a [`Counter`]; the
/// instructions it emitted.
pub fn ypipe_only(scene: &ScreenScene, shading: Shading) -> u64 {
    let mut count = Counter::default();
    emit(scene, &options(shading), &mut count).expect("a counter never fails");
    count.finish().expect("a counter never fails");
    count.0
}

/// The Y-processor and the array (fast engine, its timing model, `f64` registers) into an
/// image: `width × height × channels` values, row-major.
pub fn cwisim_image(scene: &ScreenScene, shading: Shading) -> Vec<f64> {
    array_image(scene, |array| {
        emit(scene, &options(shading), array).expect("the stream fits the header");
    })
}

/// Rows per band in [`cwisim_image_in_bands`]: as `cwisim render` on one thread.
const BAND_ROWS: u32 = 16;

/// [`cwisim_image`] as `cwisim render` runs it on one thread: the rows emitted in bands of
/// 16 into processors of the array's own (`BandArray`, each band started after the one
/// before), each band's scanlines then taken in by the array, in order (`absorb`).
pub fn cwisim_image_in_bands(scene: &ScreenScene, shading: Shading) -> Vec<f64> {
    let options = options(shading);
    let plan = ScanPlan::new(scene, &options);
    array_image(scene, |array| {
        let mut processors = array.band_array().expect("the fast engine takes bands");
        let (mut previous, mut spare) = (Band::new(), Band::new());
        for first in (0..scene.height).step_by(BAND_ROWS as usize) {
            let rows = first..(first + BAND_ROWS).min(scene.height);
            processors.start_after(spare, &previous);
            emit_rows(&plan, &options, rows, &mut processors).expect("the stream fits");
            let band = processors.take().expect("whole scanlines");
            assert!(
                array.absorb(&band).expect("the array takes bands"),
                "a band started after the one before is taken"
            );
            spare = std::mem::replace(&mut previous, band);
        }
    })
}

/// The image the array (the default machine, fast engine, `f64`) draws for `scene` when
/// `feed` drives it.
fn array_image(scene: &ScreenScene, feed: impl FnOnce(&mut EngineWriter<'_, f64>)) -> Vec<f64> {
    let h = header(scene);
    let mut sink = ImageSink::new(
        h.width as usize,
        h.channel_count(),
        ImageSink::DEFAULT_LIMIT_BYTES,
    );
    {
        let mut array = EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink)
            .expect("the default machine");
        feed(&mut array);
        array.finish().expect("the array finishes");
    }
    let image = sink.finish().expect("the image fits").data;
    assert_eq!(
        image.len(),
        scene.width as usize * scene.height as usize * usize::from(scene.channels),
        "one frame"
    );
    image
}

// ---------------------------------------------------------------------------------------
// The exact reference and errors.

/// The exact summed coverage of a scene's polygons, and which pixels are edge pixels.
pub struct Exact {
    /// Row-major `width × height`: `Σ_polygons area(polygon ∩ pixel)`.
    pub sum: Vec<f64>,
    /// Whether some polygon covers the pixel partly (neither 0 nor 1, by more than 1e-12).
    pub edge: Vec<bool>,
}

impl Exact {
    /// `cwisim_ypipe::exact::coverage` of every polygon, summed (over each polygon's
    /// bounding box only: the rest of its image is zero).
    pub fn of(scene: &ScreenScene) -> Exact {
        let (w, h) = (scene.width, scene.height);
        let n = w as usize * h as usize;
        let (mut sum, mut edge) = (vec![0.0; n], vec![false; n]);
        for p in &scene.polygons {
            let c = coverage(p, w, h);
            let b = PixelBox::of(&p.vertices, w, h);
            for y in b.y0..b.y0 + b.h {
                for k in y * w as usize + b.x0..y * w as usize + b.x0 + b.w {
                    sum[k] += c[k];
                    edge[k] |= c[k] > 1e-12 && c[k] < 1.0 - 1e-12;
                }
            }
        }
        Exact { sum, edge }
    }
}

/// How far an image is from the exact coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Error {
    /// The largest absolute difference over all pixels.
    pub max: f64,
    /// The root mean square difference over all pixels.
    pub rms: f64,
    /// The root mean square difference over the edge pixels ([`Exact::edge`]).
    pub edge_rms: f64,
    /// Edge pixels.
    pub edge_pixels: usize,
}

/// The error of `image` (pixel `k`'s value by `at(k)`) against `exact`.
pub fn error(exact: &Exact, at: impl Fn(usize) -> f64) -> Error {
    let (mut max, mut all, mut edge, mut edges) = (0.0f64, 0.0, 0.0, 0usize);
    for (k, (&e, &is_edge)) in exact.sum.iter().zip(&exact.edge).enumerate() {
        let d = at(k) - e;
        max = max.max(d.abs());
        all += d * d;
        if is_edge {
            edge += d * d;
            edges += 1;
        }
    }
    Error {
        max,
        rms: (all / exact.sum.len() as f64).sqrt(),
        edge_rms: (edge / edges.max(1) as f64).sqrt(),
        edge_pixels: edges,
    }
}

/// One row of the accuracy table.
pub struct Row {
    /// `cwisim` or a peer's name.
    pub rasterizer: &'static str,
    /// `array` for cwisim, the [`Mode`] for a peer.
    pub mode: &'static str,
    /// Its error.
    pub error: Error,
}

/// The accuracy of cwisim and every peer (per polygon; one path too when `one_path`) on
/// `scene`, against [`Exact`]. cwisim's row comes first.
pub fn accuracy(scene: &ScreenScene, one_path: bool) -> Vec<Row> {
    let exact = Exact::of(scene);
    let ours = cwisim_image(&coverage_scene(scene), Shading::Flat);
    let mut rows = vec![Row {
        rasterizer: "cwisim",
        mode: "array",
        error: error(&exact, |k| ours[k]),
    }];
    let o = outlines(scene);
    let modes: &[Mode] = if one_path {
        &[Mode::PerPolygon, Mode::OnePath]
    } else {
        &[Mode::PerPolygon]
    };
    for &mode in modes {
        for peer in Peer::ALL {
            let image = fill(peer, mode, &o, scene.width, scene.height);
            assert_eq!(image.len(), exact.sum.len());
            rows.push(Row {
                rasterizer: peer.name(),
                mode: mode.name(),
                error: error(&exact, |k| image.at(k)),
            });
        }
    }
    rows
}
