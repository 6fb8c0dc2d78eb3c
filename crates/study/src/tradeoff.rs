//! Speed against accuracy: one scene rendered over a grid of settings (renderer,
//! visibility, shading, anti-aliasing, the array's numeric format), each measured — what
//! it costs (instructions, bus cycles, the worst scanline, host time, the renderer's own
//! counters) against how far it is from the exact image (max, RMS, PSNR) — with the
//! Pareto front of error against cycles and register bits marked.
//!
//! The exact image is the same for every setting: the box filter (exact area-weighted
//! mean per pixel) of the Gouraud-shaded visible surfaces, computed by
//! `cwisim_ypipe::exact::scene_box_filtered` — for a world scene on the exact visible
//! fragments, for a screen scene on its polygons — independently of the renderers and of
//! the array.

use crate::error::StudyError;
use cwisim_render::settings::{SbufferMode, Setting as Flag};
use cwisim_render::{
    registry, render, ArrayConfig, PolygonScene, Renderer, Settings, Size, Source, Taps,
};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::Visibility;
use cwisim_xproc::{ImageSink, Machine, Numeric, Timing};
use cwisim_ypipe::exact::scene_box_filtered;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The tessellations tried by default on a scene with Bézier patches (quads per patch
/// side).
pub const DEFAULT_TESSELLATIONS: [u32; 3] = [4, 8, 16];

/// The numeric formats `tradeoff` tries unless told otherwise.
pub const DEFAULT_FORMATS: &[&str] = &[
    "f64",
    "f32",
    "fixed:I=10.22,dI=4.28,ddI=1.35",
    "fixed:I=10.14,dI=4.20,ddI=1.27",
    "fixed:I=10.10,dI=4.14,ddI=1.20",
];

/// One setting of the grid, measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// The renderer feeding the array.
    pub renderer: &'static str,
    /// `flat`, `gouraud` or `phong`.
    pub shading: &'static str,
    /// `none`, `box` (exact) or `box-centre` (the report's coverage × centre value, Phong's
    /// box filter); `-` for a renderer that does not read `--aa` (a supersampling one).
    pub aa: &'static str,
    /// Samples per pixel side of a supersampling renderer (its grid is `l × l`).
    pub samples: Option<u32>,
    /// `exact`, `eval0`, or `-` (screen scenes, and renderers that do not read
    /// `--visibility`: the supersampling ones and `nishita`, which resolve it themselves).
    pub visibility: &'static str,
    /// `on` or `off`: whether the scene's lights cast shadows in this row; `-` for a
    /// screen scene (nothing lit).
    pub shadows: &'static str,
    /// Quads per Bézier patch side (scenes with Bézier meshes, when the grid varies it).
    pub tessellate: Option<u32>,
    /// The root tolerance of a renderer that draws the patches directly (`nishita`);
    /// its rows are measured against the reference at [`REFERENCE_TESSELLATION`].
    pub root_tolerance: Option<f64>,
    /// `nishita`'s normal-difference angle, degrees (`--normal-angle`); `None` where the
    /// test is off or the renderer draws no patches.
    pub normal_angle: Option<f64>,
    /// The array's numeric format.
    pub numeric: String,
    /// Register bits per processor and channel (I, dI, ddI and the accumulator).
    pub register_bits: u32,
    /// Instructions sent, `Refresh` included.
    pub instructions: u64,
    /// Bus-busy cycles over the frame: the array's work.
    pub busy_cycles: u64,
    /// The busiest scanline's bus cycles as a share of the line period.
    pub worst_line_share: f64,
    /// Scanlines not ready by their deadline.
    pub late_lines: u64,
    /// Wall time of preparing and scan-converting (shared by the formats of one stream)
    /// and executing in this format (median of the repeats), milliseconds.
    pub host_ms: f64,
    /// Largest absolute error of any value against the exact image.
    pub max_error: f64,
    /// Root-mean-square error over all values.
    pub rms_error: f64,
    /// Peak signal-to-noise ratio for a peak of 1, dB (infinite for an exact image).
    pub psnr_db: f64,
    /// Register overflows (wraps or saturations) in the array.
    pub overflows: u64,
    /// The renderer's own counters.
    pub counters: cwisim_render::Counters,
    /// Pareto-optimal: no other setting is at least as good in bus cycles, register bits
    /// and RMS error and better in one of them.
    pub pareto: bool,
}

/// One setting of the grid.
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// The renderer.
    pub renderer: &'static registry::Entry,
    /// How it draws.
    pub settings: Settings,
    /// The array's registers.
    pub numeric: Numeric,
}

impl Setting {
    /// The setting in words, as a progress line shows it: renderer, shading, filter or
    /// samples, visibility, tessellation, registers.
    pub fn describe(&self) -> String {
        let s = &self.settings;
        let mut words = vec![self.renderer.name.to_string(), s.shading.name().to_string()];
        if self.renderer.supersampled {
            if s.sbuffer == SbufferMode::Abuffer {
                words.push("abuffer".into());
            }
            words.push(format!("{}×{} samples", s.samples, s.samples));
        } else if reads(self, Flag::Aa) {
            words.push(s.aa.name().to_string());
        }
        if reads(self, Flag::Visibility) {
            words.push(s.visibility.name().to_string());
        }
        if let Some(n) = s.tessellate {
            words.push(format!("tessellate {n}"));
        }
        if self.renderer.patches {
            words.push(format!("root tolerance {:.0e}", s.root_tolerance));
            if let Some(a) = s.normal_angle {
                words.push(format!("normal angle {a}°"));
            }
        }
        if let (Some(on), true) = (s.shadows, reads(self, Flag::Shadows)) {
            words.push(if on { "shadows on" } else { "shadows off" }.into());
        }
        words.push(short_numeric(&self.numeric));
        words.join(" ")
    }
}

/// The `aa` column of `sbuffer`'s scanline A-buffer rows (`--sbuffer abuffer`): its
/// pixels resolved from coverage masks of `samples × samples` bits.
pub const ABUFFER_AA: &str = "abuffer";

/// Samples per pixel side tried for a supersampling renderer: from point sampling to
/// 64 samples per pixel, enough to see the error fall as `l` grows.
pub const SAMPLES_AXIS: [u32; 4] = [1, 2, 4, 8];

/// The axes of the grid besides the renderers and the numeric formats.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Axes {
    /// A world scene: both visibilities, and Phong shading (on exact visibility).
    pub world: bool,
    /// The image size.
    pub size: Option<Size>,
    /// Tessellations of the scene's Bézier meshes (empty: as the scene says).
    pub tessellations: Vec<u32>,
    /// The scene has Bézier patches: a renderer that draws them directly has something
    /// of its own to draw (without, it would draw exactly as `vanrij`).
    pub patches: bool,
    /// Some light of the scene casts shadows as the scene says (`"shadows": true`).
    pub casting: bool,
    /// The shadows axis, for the renderers that draw shadows: each value a
    /// `Settings::shadows` to try (empty: as the scene says, one value).
    pub shadows: Vec<Option<bool>>,
    /// A mesh of the scene is textured: every shading is drawn per pixel (exact
    /// visibility, the per-pixel box filter), by the renderers that draw textures, and
    /// measured against its own best image.
    pub textured: bool,
    /// `sbuffer`'s modes to try at every samples value (empty: its default, `host`);
    /// `abuffer` rows show it in the `aa` column.
    pub sbuffer: Vec<SbufferMode>,
    /// `nishita`'s normal-difference angles to try at every root tolerance (empty: off).
    pub normal_angles: Vec<Option<f64>>,
}

/// The root tolerances of a renderer that draws Bézier patches directly (Nishita et
/// al.'s Table 1).
pub const ROOT_TOLERANCE_AXIS: [f64; 3] = [1e-3, 1e-5, 1e-7];

/// The settings of the grid, in order: renderer, tessellation (scenes with Bézier
/// meshes), visibility (world scenes), shading (Phong on world scenes with exact
/// visibility), anti-aliasing (`box`, `box-centre` with Gouraud shading, `none`; Phong's
/// box filter is `box-centre` alone, [`box_filter`]) and numeric format. A supersampling
/// renderer resolves visibility itself and samples instead of filtering: its axis is
/// [`SAMPLES_AXIS`]. Each setting is what `cwisim render` accepts with the flags its row
/// prints.
pub fn grid(
    renderers: &[&'static registry::Entry],
    axes: &Axes,
    formats: &[Numeric],
) -> Vec<Setting> {
    let mut out = Vec::new();
    let visibilities: &[Visibility] = if axes.world && !axes.textured {
        &[Visibility::Exact, Visibility::Eval0]
    } else {
        &[Visibility::Exact]
    };
    let tessellations: Vec<Option<u32>> = if axes.tessellations.is_empty() {
        vec![None]
    } else {
        axes.tessellations.iter().map(|&n| Some(n)).collect()
    };
    for &renderer in renderers {
        if skipped(renderer, axes).is_some() {
            continue;
        }
        // the renderer's block once per shadows value (its numeric formats kept together:
        // they share a stream)
        let start = out.len();
        grid_of(
            renderer,
            axes,
            formats,
            &tessellations,
            visibilities,
            &mut out,
        );
        if renderer.uses.contains(&Flag::Shadows) && !axes.shadows.is_empty() {
            let block: Vec<Setting> = out.drain(start..).collect();
            for &shadows in &axes.shadows {
                out.extend(block.iter().map(|s| Setting {
                    settings: Settings {
                        shadows,
                        ..s.settings
                    },
                    ..*s
                }));
            }
        }
    }
    out
}

/// Why `renderer` is left out of the grid: a renderer of Bézier patches on a scene
/// without any (it would draw exactly as `vanrij`), or one that does not draw shadows on
/// a scene whose lights cast them.
fn skipped(renderer: &registry::Entry, axes: &Axes) -> Option<String> {
    if renderer.patches && !axes.patches {
        return Some("the scene has no Bézier patches, so it would draw exactly as vanrij".into());
    }
    // (where the scene casts none, it is measured as drawn: without, beside the shadows
    // axis's `off` rows)
    if axes.casting && !renderer.uses.contains(&Flag::Shadows) {
        return Some("it does not draw shadows, and the scene's lights cast them".into());
    }
    if axes.textured && !renderer.textures {
        return Some("it does not draw textures, and the scene has textured meshes".into());
    }
    None
}

/// The settings of one renderer ([`grid`]), appended to `out`.
fn grid_of(
    renderer: &'static registry::Entry,
    axes: &Axes,
    formats: &[Numeric],
    tessellations: &[Option<u32>],
    visibilities: &[Visibility],
    out: &mut Vec<Setting>,
) {
    {
        if renderer.patches {
            // patches drawn directly: no tessellation, exact visibility (it reads no
            // other), smooth shading, the box filter (Phong's: `box-centre`); the root
            // tolerance is its axis
            let angles = match axes.normal_angles.is_empty() {
                true => vec![None],
                false => axes.normal_angles.clone(),
            };
            for tolerance in ROOT_TOLERANCE_AXIS {
                for &normal_angle in &angles {
                    for shading in [Shading::Phong, Shading::Gouraud] {
                        for numeric in formats {
                            out.push(Setting {
                                renderer,
                                settings: Settings {
                                    shading,
                                    aa: box_filter(shading),
                                    size: axes.size,
                                    root_tolerance: tolerance,
                                    normal_angle,
                                    ..Settings::default()
                                },
                                numeric: *numeric,
                            });
                        }
                    }
                }
            }
            return;
        }
        if renderer.supersampled {
            let modes = match renderer.uses.contains(&Flag::Sbuffer) && !axes.sbuffer.is_empty() {
                true => axes.sbuffer.clone(),
                false => vec![SbufferMode::Host],
            };
            for &tessellate in tessellations {
                for shading in [Shading::Phong, Shading::Gouraud, Shading::Flat] {
                    if shading == Shading::Phong && !axes.world {
                        continue;
                    }
                    for &sbuffer in &modes {
                        for samples in SAMPLES_AXIS {
                            for numeric in formats {
                                out.push(Setting {
                                    renderer,
                                    settings: Settings {
                                        shading,
                                        samples,
                                        size: axes.size,
                                        tessellate,
                                        sbuffer,
                                        ..Settings::default()
                                    },
                                    numeric: *numeric,
                                });
                            }
                        }
                    }
                }
            }
            return;
        }
        for &tessellate in tessellations {
            for &visibility in visibilities {
                for shading in [Shading::Phong, Shading::Gouraud, Shading::Flat] {
                    if shading == Shading::Phong && !(axes.world && visibility == Visibility::Exact)
                    {
                        continue;
                    }
                    // the report's box filter differs from the exact one only where
                    // the intensity varies over a polygon: Gouraud; Phong's box filter is
                    // the report's alone (`--aa box` is refused with Phong)
                    // (a textured mesh's every shading is per pixel, as Phong's: its box
                    // filter is the report's alone)
                    let filters: &[Antialias] = match shading {
                        _ if axes.textured => &[Antialias::BoxCentre],
                        Shading::Gouraud => &[Antialias::Box, Antialias::BoxCentre],
                        _ => &[box_filter(shading)],
                    };
                    for &aa in filters.iter().chain(&[Antialias::None]) {
                        for numeric in formats {
                            out.push(Setting {
                                renderer,
                                settings: Settings {
                                    shading,
                                    aa,
                                    visibility,
                                    size: axes.size,
                                    tessellate,
                                    ..Settings::default()
                                },
                                numeric: *numeric,
                            });
                        }
                    }
                }
            }
        }
    }
}

/// The box filter a shading is drawn with in the grid, as `cwisim render --aa` names
/// it: Phong's is the report's, coverage × the shade at the pixel centre (`box-centre`;
/// `--aa box` is refused with Phong), any other shading's the exact one (`box`).
pub fn box_filter(shading: Shading) -> Antialias {
    match shading {
        Shading::Phong => Antialias::BoxCentre,
        _ => Antialias::Box,
    }
}

/// A format as the table shows it: the canonical form without the defaults (an
/// accumulator like I, saturation).
pub fn short_numeric(numeric: &Numeric) -> String {
    let mut s = numeric.to_string();
    if let Numeric::Fixed(f) = numeric {
        if f.acc == f.i {
            s = s.replace(&format!(",acc={}.{}", f.acc.int_bits, f.acc.frac_bits), "");
        }
        s = s.replace(",overflow=saturate", "");
    }
    s
}

/// Errors of `image` against `reference`: max, RMS, PSNR (peak 1).
pub fn errors(image: &[f64], reference: &[f64]) -> (f64, f64, f64) {
    let mut max = 0.0f64;
    let mut sum_sq = 0.0;
    for (a, b) in image.iter().zip(reference) {
        let e = (a - b).abs();
        max = max.max(e);
        sum_sq += e * e;
    }
    let mse = sum_sq / reference.len().max(1) as f64;
    let psnr = if mse == 0.0 {
        f64::INFINITY
    } else {
        -10.0 * mse.log10()
    };
    (max, mse.sqrt(), psnr)
}

/// Register bits per processor and channel: I, dI, ddI and the accumulator.
pub fn register_bits(numeric: &Numeric) -> u32 {
    match numeric {
        Numeric::F64 => 4 * 64,
        Numeric::F32 => 4 * 32,
        Numeric::Fixed(f) => [f.i, f.di, f.ddi, f.acc]
            .iter()
            .map(|q| q.int_bits + q.frac_bits)
            .sum(),
    }
}

/// Marks the Pareto-optimal rows: no other row has fewer or equal bus cycles, register
/// bits and RMS error, and fewer of one. (The numeric format changes bits and error but
/// not cycles; cycles alone would hide the format's trade.)
pub fn mark_pareto(rows: &mut [Row]) {
    let points: Vec<(u64, u32, f64)> = rows
        .iter()
        .map(|r| (r.busy_cycles, r.register_bits, r.rms_error))
        .collect();
    for (row, optimal) in rows.iter_mut().zip(pareto(&points)) {
        row.pareto = optimal;
    }
}

/// Which of the points (bus cycles, register bits, RMS error) are Pareto-optimal: no
/// other point is at most as large in all three and smaller in one ([`mark_pareto`]). A
/// point whose error is not a number is never optimal, and dominates none.
///
/// In O(n log n), so that a merged sweep of a million rows is marked in a moment: a point
/// dominates only points after it in lexicographic order (cycles, bits, error), so the
/// points are taken in that order, and each is dominated exactly when a point before it
/// (not equal to it) has at most its bits and at most its error — a prefix minimum of the
/// error over the bits seen, kept in a Fenwick tree over the distinct bit counts.
pub fn pareto(points: &[(u64, u32, f64)]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].2.is_nan())
        .collect();
    order.sort_by(|&i, &j| {
        let (a, b) = (points[i], points[j]);
        (a.0, a.1).cmp(&(b.0, b.1)).then(a.2.total_cmp(&b.2))
    });
    let mut bits: Vec<u32> = order.iter().map(|&i| points[i].1).collect();
    bits.sort_unstable();
    bits.dedup();
    // tree[k]: the least error over a range of bit ranks ending at k (1-based), `None`
    // before any point is entered there
    let mut tree: Vec<Option<f64>> = vec![None; bits.len() + 1];
    let rank = |b: u32| bits.partition_point(|&x| x < b) + 1;
    let least = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, None) | (None, x) => x,
    };
    let least_up_to = |tree: &[Option<f64>], mut k: usize| {
        let mut m = None;
        while k > 0 {
            m = least(m, tree[k]);
            k &= k - 1;
        }
        m
    };
    let mut optimal = vec![false; points.len()];
    let mut start = 0;
    while start < order.len() {
        // a run of equal points: none dominates another, so all are judged before any
        // is entered
        let p = points[order[start]];
        let mut end = start + 1;
        while end < order.len() && points[order[end]] == p {
            end += 1;
        }
        let dominated = least_up_to(&tree, rank(p.1)).is_some_and(|m| m <= p.2);
        for &i in &order[start..end] {
            optimal[i] = !dominated;
        }
        let mut k = rank(p.1);
        while k < tree.len() {
            tree[k] = least(tree[k], Some(p.2));
            k += k & k.wrapping_neg();
        }
        start = end;
    }
    optimal
}

/// The exact image of the scene SCENE names, at `size`: the box-filtered Gouraud image of
/// its exact visible surfaces, computed by the independent reference.
pub fn exact_image(scene: Option<&Path>, size: Option<Size>) -> Result<Vec<f64>, StudyError> {
    reference_image(
        scene,
        &Settings {
            size,
            ..Settings::default()
        },
    )
}

/// The reference a setting is measured against, for its geometry (size, tessellation):
/// for flat and Gouraud shading the exact box-filtered Gouraud image of the exact visible
/// surfaces (`cwisim_ypipe::exact`, independent of the renderers and the array); for
/// Phong, Phong's own best image — its box filter (`box-centre`), span tolerance 0 (the
/// per-pixel value at every centre a triangle covers whole), `f64` registers — so that a
/// Phong row's error is what its span tolerance, point sampling and register format add.
/// On a textured scene every shading is drawn per pixel, as Phong is, and measured so
/// against its own best image (with the texture's box filter).
pub fn reference_image(scene: Option<&Path>, setting: &Settings) -> Result<Vec<f64>, StudyError> {
    let loaded = Source::resolve(scene)?.load_for(setting)?;
    if setting.shading == Shading::Phong || loaded.scene.is_textured() {
        let best = Settings {
            aa: box_filter(Shading::Phong),
            visibility: Visibility::Exact,
            shade_tolerance: 0.0,
            texture_filter: cwisim_world::texture::TextureFilter::Box,
            ..*setting
        };
        let renderer = cwisim_render::vanrij::VanRij::new(loaded, &best)?;
        let h = renderer.header();
        let mut sink = ImageSink::new(
            h.width as usize,
            h.channel_count(),
            ImageSink::DEFAULT_LIMIT_BYTES,
        );
        render(
            &renderer,
            &ArrayConfig::default(),
            1,
            &mut sink,
            Taps::default(),
        )?;
        return Ok(sink.finish()?.data);
    }
    let gouraud = Settings {
        shading: Shading::Gouraud,
        visibility: Visibility::Exact,
        ..*setting
    };
    let p = PolygonScene::new(loaded, &gouraud)?;
    Ok(scene_box_filtered(&p.screen))
}

/// What measuring one setting gives.
pub struct Measured {
    /// The image, `(lines, width, channels)`.
    pub image: Vec<f64>,
    /// The renderer's counters.
    pub counters: cwisim_render::Counters,
    /// The array's statistics.
    pub stats: cwisim_xproc::RunStats,
    /// Wall time of reading, preparing, rendering and executing.
    pub time: Duration,
}

/// Renders one setting.
pub fn measure(
    scene: Option<&Path>,
    setting: &Setting,
    machine: &Machine,
) -> Result<Measured, StudyError> {
    let start = Instant::now();
    let loaded = Source::resolve(scene)?.load_for(&setting.settings)?;
    let renderer = (setting.renderer.build)(loaded, &setting.settings)?;
    let h = renderer.header();
    let mut sink = ImageSink::new(
        h.width as usize,
        h.channel_count(),
        ImageSink::DEFAULT_LIMIT_BYTES,
    );
    let array = ArrayConfig {
        machine: machine.clone(),
        numeric: setting.numeric,
        timing: Timing::Fast,
    };
    let rendered = render(&*renderer, &array, 1, &mut sink, Taps::default())?;
    let time = start.elapsed();
    let image = sink.finish()?;
    Ok(Measured {
        image: image.data,
        counters: rendered.counters,
        stats: rendered.stats,
        time,
    })
}

/// What [`tradeoff_rows`] reports as it goes, for a progress bar and a table printed row
/// by row.
#[derive(Debug)]
pub enum Step<'a> {
    /// The grid is known: `total` settings; the renderers left out, each with why.
    Start {
        /// Settings to measure.
        total: usize,
        /// `(renderer, why)` of every renderer left out because it would draw the scene
        /// exactly as another.
        skipped: &'a [(&'static str, String)],
    },
    /// The settings of a stream, from `index` on, are being measured (on some thread;
    /// several can be at once, and rows before `index` may still be to come).
    Measuring {
        /// The index of its first setting.
        index: usize,
        /// Settings in all.
        total: usize,
        /// The settings, in words (`vanrij gouraud box exact (5 formats)`).
        setting: String,
    },
    /// Setting `index` was measured: its row (not yet marked Pareto: that needs every
    /// row).
    Measured {
        /// Its index.
        index: usize,
        /// Settings in all.
        total: usize,
        /// The row.
        row: &'a Row,
    },
}

/// The renderers among `entries` left out of the grid, with why ([`skipped`]): one that
/// draws Bézier patches directly, on a scene without patches, draws it as `vanrij` does;
/// one that does not draw shadows cannot draw a scene whose lights cast them.
pub fn skipped_renderers(
    entries: &[&'static registry::Entry],
    axes: &Axes,
) -> Vec<(&'static str, String)> {
    entries
        .iter()
        .filter_map(|e| skipped(e, axes).map(|why| (e.name, why)))
        .collect()
}

/// The shadows axis for the values `wanted` (`true`: on) on a scene whose lights cast
/// shadows as `lights` says: `on` every light casting (`--shadows on`), `off` none
/// (`--shadows off`, or the scene as it is when no light casts). Refused where a value
/// could not be drawn: shadows in a scene without lights.
pub fn shadows_axis(wanted: &[bool], lights: &[bool]) -> Result<Vec<Option<bool>>, StudyError> {
    wanted
        .iter()
        .map(|&on| match on {
            true if lights.is_empty() => Err(StudyError::from(cwisim_render::RenderError::Usage(
                "--shadows on: the scene has no lights to cast them".into(),
            ))),
            true => Ok(Some(true)),
            false if lights.contains(&true) => Ok(Some(false)),
            false => Ok(None),
        })
        .collect()
}

/// What a sweep tries, as `cwisim tradeoff` takes it: each axis's values (empty: the
/// axis's default, as [`Plan::new`] says).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Request {
    /// The image size (`None`: the scene's).
    pub size: Option<Size>,
    /// Tessellations of the scene's Bézier meshes (empty: as the scene says).
    pub tessellations: Vec<u32>,
    /// Shadows on (`true`) and off to try (empty: as the scene says).
    pub shadows: Vec<bool>,
    /// Renderers by name (empty: every registered one-frame renderer).
    pub renderers: Vec<String>,
    /// The array's numeric formats.
    pub formats: Vec<Numeric>,
    /// `sbuffer`'s modes, `host` and `abuffer` (empty: `host`).
    pub sbuffer: Vec<SbufferMode>,
    /// `nishita`'s normal-difference angles, degrees (`None`: the test off; empty: off).
    pub normal_angles: Vec<Option<f64>>,
}

/// Refuses a normal-angle axis that nothing would read (`--renderers` without `nishita`),
/// an angle `cwisim render --normal-angle` would refuse, or a value given twice.
fn check_normal_angles(angles: &[Option<f64>], renderers: &[String]) -> Result<(), StudyError> {
    if !angles.is_empty() && !renderers.is_empty() && !renderers.iter().any(|r| r == "nishita") {
        return Err(StudyError::Usage(
            "--normal-angle sets nishita's subdivision, and --renderers leaves nishita out".into(),
        ));
    }
    for a in angles {
        Settings {
            normal_angle: *a,
            ..Settings::default()
        }
        .check()
        .map_err(StudyError::Usage)?;
    }
    if (1..angles.len()).any(|k| angles[..k].contains(&angles[k])) {
        return Err(StudyError::Usage(
            "--normal-angle: each angle (and off) at most once".into(),
        ));
    }
    Ok(())
}

/// A sweep planned: the grid of settings of one scene, cut into the groups that share a
/// stream ([`streams`]). Each group is measured alone ([`Plan::measure_group`]), so a
/// group is a task: a thread's here ([`tradeoff_rows`]), a Dask task's in Python. The
/// rows of every group, concatenated in group order and marked by [`mark_pareto`], are
/// the sweep's, whoever measured them.
pub struct Plan {
    scene: Option<PathBuf>,
    /// Every setting, in the grid's order.
    pub settings: Vec<Setting>,
    /// The groups: ranges of `settings` that share a stream, in order.
    pub groups: Vec<std::ops::Range<usize>>,
    /// The renderers left out of the grid, with why.
    pub skipped: Vec<(&'static str, String)>,
    axes: Axes,
    references: References,
    /// Values of one image: width × height × channels.
    image_values: u64,
}

impl Plan {
    /// The grid of `scene` (a file or an embedded name; `None`: the default) over the
    /// axes `request` asks for: `renderers` by name (empty: every registered one-frame
    /// renderer), `size`, the `tessellations` of a scene with patches, the `shadows`
    /// values, `sbuffer`'s modes, `nishita`'s normal angles and the numeric `formats`.
    /// Refused: a value of an axis no renderer of the grid would read, a value given twice.
    pub fn new(scene: Option<&Path>, request: &Request) -> Result<Plan, StudyError> {
        let Request {
            size,
            tessellations,
            shadows,
            renderers,
            formats,
            sbuffer,
            normal_angles,
        } = request;
        let size = *size;
        if let Some(m) = sbuffer
            .iter()
            .find(|m| !matches!(m, SbufferMode::Host | SbufferMode::Abuffer))
        {
            return Err(StudyError::Usage(format!(
                "--sbuffer {m}: tradeoff tries host and abuffer (they draw the image the exact one measures; overdraw draws host's, transparent composites what the exact image does not)"
            )));
        }
        if (1..sbuffer.len()).any(|k| sbuffer[..k].contains(&sbuffer[k])) {
            return Err(StudyError::Usage(
                "--sbuffer: each mode at most once".into(),
            ));
        }
        if !sbuffer.is_empty() && !renderers.is_empty() && !renderers.iter().any(|r| r == "sbuffer")
        {
            return Err(StudyError::Usage(
                "--sbuffer sets sbuffer's modes, and --renderers leaves sbuffer out".into(),
            ));
        }
        check_normal_angles(normal_angles, renderers)?;
        // a progressive renderer's frames refine one another: one frame against the exact
        // image says nothing of it (its phases are measured by its own summary)
        let entries: Vec<&'static registry::Entry> = if renderers.is_empty() {
            registry::REGISTRY
                .iter()
                .filter(|e| !e.progressive)
                .collect()
        } else {
            renderers
                .iter()
                .map(|n| {
                    registry::find(n).and_then(|e| match e.progressive {
                        false => Ok(e),
                        true => Err(cwisim_render::RenderError::Usage(format!(
                            "`{n}` draws several frames, each refining the previous one: tradeoff measures one-frame renderers against the exact image; `cwisim render --renderer {n}` prints its phases"
                        ))),
                    })
                })
                .collect::<Result<_, _>>()?
        };
        let probe = Source::resolve(scene)?.load(size)?.scene;
        let lights = match &probe {
            cwisim_world::AnyScene::World(w) => w.spec.lights.iter().map(|l| l.shadows).collect(),
            cwisim_world::AnyScene::Screen(_) => Vec::new(),
        };
        let axes = Axes {
            casting: lights.contains(&true),
            shadows: shadows_axis(shadows, &lights)?,
            world: probe.kind() == "world",
            size,
            tessellations: if probe.has_patches() {
                tessellations.to_vec()
            } else {
                Vec::new()
            },
            patches: probe.has_patches(),
            textured: probe.is_textured(),
            sbuffer: sbuffer.to_vec(),
            normal_angles: normal_angles.clone(),
        };
        if !normal_angles.is_empty() && !axes.patches {
            return Err(StudyError::Usage(
                "--normal-angle is nishita's subdivision of Bézier patches, and the scene has none"
                    .into(),
            ));
        }
        let settings = grid(&entries, &axes, formats);
        let skipped = skipped_renderers(&entries, &axes);
        if settings.is_empty() {
            // every renderer asked for left out: a sweep of nothing is not a sweep
            let why: Vec<String> = skipped
                .iter()
                .map(|(name, why)| format!("{name}: {why}"))
                .collect();
            return Err(StudyError::Usage(format!(
                "no setting to measure: every renderer asked for is left out ({})",
                why.join("; ")
            )));
        }
        let (w, h) = probe.size();
        let channels = match &probe {
            cwisim_world::AnyScene::Screen(s) => s.channel_count(),
            cwisim_world::AnyScene::World(w) => w.channels(),
        };
        Ok(Plan {
            scene: scene.map(Path::to_path_buf),
            groups: streams(&settings),
            skipped,
            settings,
            axes,
            references: References::default(),
            image_values: u64::from(w) * u64::from(h) * channels as u64,
        })
    }

    /// Refuses, before any is made, the images measuring `at_once` groups at a time holds
    /// past the memory budget (`CWISIM_MAX_MEMORY`): each group's image per format, and the
    /// references every group is measured against (made once, kept to the end), 8 bytes a
    /// value.
    pub fn check_memory(&self, at_once: usize) -> Result<(), StudyError> {
        let widest = self.groups.iter().map(|g| g.len()).max().unwrap_or(0);
        let mut keys: Vec<ReferenceKey> = self
            .settings
            .iter()
            .map(|s| reference_key(s, self.axes.world, self.axes.textured))
            .collect();
        keys.sort();
        keys.dedup();
        let images = (at_once.max(1) * widest + keys.len()) as u64;
        let what = format!(
            "tradeoff's images ({images} at once: {} group(s) of up to {widest} format(s) and {} reference(s), {} values each)",
            at_once.max(1),
            keys.len(),
            self.image_values
        );
        cwisim_scene::budget::Budget::current()
            .check_memory(
                &what,
                images.saturating_mul(self.image_values).saturating_mul(8),
            )
            .map_err(|e| StudyError::Usage(e.to_string()))
    }

    /// Where the rows of groups `groups` (a [`Shard`]'s, or all of them) measured on
    /// `machine` stand in this sweep: its identity and their first setting's index
    /// ([`Provenance`]), which [`csv`] writes with every row and [`merge_csv`] checks.
    pub fn provenance(&self, machine: &Machine, groups: std::ops::Range<usize>) -> Provenance {
        // FNV-1a over the scene's name, every setting (renderer, drawing settings but the
        // threads, numeric format) and the machine: two parts agree on it only when they
        // measure one grid on one machine
        let name =
            Source::resolve(self.scene.as_deref()).map_or_else(|_| "scene".into(), |s| s.name());
        let mut text = format!("{name}\n{machine:?}\n");
        for s in &self.settings {
            let settings = Settings {
                threads: 0,
                ..s.settings
            };
            text.push_str(&format!("{}|{settings:?}|{}\n", s.renderer.name, s.numeric));
        }
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        for b in text.bytes() {
            hash = (hash ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
        let safe: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "._-".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        Provenance {
            sweep: format!("{safe}:{hash:016x}"),
            first: self
                .groups
                .get(groups.start)
                .map_or(self.settings.len(), |g| g.start),
            settings: self.settings.len(),
        }
    }

    /// The rows of group `g` (in the grid's order; none marked Pareto-optimal yet): its
    /// stream drawn once and executed in each of its formats, `repeat` times for the host
    /// times, each against its reference (made once per plan).
    pub fn measure_group(
        &self,
        g: usize,
        machine: &Machine,
        repeat: u32,
    ) -> Result<Vec<Row>, StudyError> {
        self.measure_group_until(g, machine, repeat, None)
    }

    /// [`Plan::measure_group`], stopped with [`StudyError::Cancelled`] at the next
    /// drawing or replay once `cancel` is set (a Python caller's Ctrl-C).
    pub fn measure_group_until(
        &self,
        g: usize,
        machine: &Machine,
        repeat: u32,
        cancel: Option<&std::sync::atomic::AtomicBool>,
    ) -> Result<Vec<Row>, StudyError> {
        check_repeat(repeat)?;
        self.check_memory(1)?;
        let scene = self.scene.as_deref();
        let group = &self.settings[self.groups[g].clone()];
        let measured = measure_stream_until(scene, group, machine, repeat, cancel)?;
        group
            .iter()
            .zip(measured)
            .map(|(setting, (measured, times))| {
                let reference =
                    self.references
                        .get(scene, setting, self.axes.world, self.axes.textured)?;
                Ok(row_of(setting, &measured, &times, &reference, &self.axes))
            })
            .collect()
    }
}

/// Refuses a sweep that would time each setting no times at all.
fn check_repeat(repeat: u32) -> Result<(), StudyError> {
    match repeat {
        0 => Err(StudyError::Usage(
            "repeat must be at least 1: each setting is timed that many times and the median reported".into(),
        )),
        _ => Ok(()),
    }
}

/// Measures every setting of the grid ([`Plan`]) of `scene` over the axes `request`
/// asks for, on `threads` threads (0: one per core). The settings
/// that share a stream (the same drawing in several numeric formats, [`streams`]) are
/// measured together: the stream is drawn once and executed in each format
/// ([`measure_stream`]); each reference image is made once. Streams are measured in
/// parallel, their rows reported to `progress` in the grid's order as soon as they and
/// every row before them are measured: the rows (but their host times) are the same at any
/// thread count.
pub fn tradeoff_rows(
    scene: Option<&Path>,
    request: &Request,
    machine: &Machine,
    repeat: u32,
    threads: usize,
    progress: &mut dyn FnMut(Step<'_>),
) -> Result<Vec<Row>, StudyError> {
    let plan = Plan::new(scene, request)?;
    let mut rows = measure_groups(
        &plan,
        0..plan.groups.len(),
        machine,
        repeat,
        threads,
        progress,
    )?;
    mark_pareto(&mut rows);
    Ok(rows)
}

/// The rows of `plan`'s groups `groups` (a [`Shard`]'s, or all of them), measured on
/// `threads` threads and reported to `progress` in the grid's order; none marked
/// Pareto-optimal (that needs every row: [`mark_pareto`], or [`merge_csv`] of the shards).
pub fn measure_groups(
    plan: &Plan,
    groups: std::ops::Range<usize>,
    machine: &Machine,
    repeat: u32,
    threads: usize,
    progress: &mut dyn FnMut(Step<'_>),
) -> Result<Vec<Row>, StudyError> {
    check_repeat(repeat)?;
    let workers = if threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        threads
    };
    plan.check_memory(workers.min(groups.len()))?;
    let settings = &plan.settings;
    let first = groups.start;
    let ranges = &plan.groups[groups];
    let total: usize = ranges.iter().map(|r| r.len()).sum();
    let base = ranges.first().map_or(0, |r| r.start);
    progress(Step::Start {
        total,
        skipped: &plan.skipped,
    });
    let mut rows = Vec::with_capacity(total);
    crate::parallel::ordered(
        ranges.len(),
        threads,
        |g| plan.measure_group(first + g, machine, repeat),
        |event| match event {
            crate::parallel::Event::Started(g) => progress(Step::Measuring {
                index: ranges[g].start - base,
                total,
                setting: describe_stream(&settings[ranges[g].clone()]),
            }),
            crate::parallel::Event::Done(g, group) => {
                for (index, row) in ranges[g].clone().zip(group) {
                    rows.push(row);
                    progress(Step::Measured {
                        index: index - base,
                        total,
                        row: rows.last().expect("just pushed"),
                    });
                }
            }
        },
    )?;
    Ok(rows)
}

/// One of `count` parts of a sweep (`--shard index/count`), for batch systems: each part
/// a job (a Slurm array task, say) measuring its consecutive share of the plan's groups,
/// the parts' CSVs then merged in order ([`merge_csv`]) into the whole sweep's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// Which part, from 0.
    pub index: usize,
    /// How many.
    pub count: usize,
}

impl Shard {
    /// Its groups among `groups`: consecutive, the parts' sizes within one of each other.
    pub fn groups(self, groups: usize) -> std::ops::Range<usize> {
        groups * self.index / self.count..groups * (self.index + 1) / self.count
    }
}

impl std::str::FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("expected I/N with 0 ≤ I < N (the part and how many), found `{s}`");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

/// The settings of `settings` that draw one stream — the same renderer and drawing
/// settings, in consecutive places, differing only in the array's numeric format (which
/// the stream does not depend on) — as ranges of indices, in order.
pub fn streams(settings: &[Setting]) -> Vec<std::ops::Range<usize>> {
    let mut out: Vec<std::ops::Range<usize>> = Vec::new();
    for (k, s) in settings.iter().enumerate() {
        match out.last_mut() {
            Some(last)
                if std::ptr::eq(settings[last.start].renderer, s.renderer)
                    && settings[last.start].settings == s.settings =>
            {
                last.end = k + 1
            }
            _ => out.push(k..k + 1),
        }
    }
    out
}

/// Settings that share one stream in words, as a progress line shows them: the first
/// one's, with the count of formats.
fn describe_stream(group: &[Setting]) -> String {
    match group {
        [one] => one.describe(),
        [first, ..] => {
            let mut words = first.describe();
            let numeric = short_numeric(&first.numeric);
            words.truncate(words.len() - numeric.len());
            format!("{words}({} formats)", group.len())
        }
        [] => String::new(),
    }
}

/// The references made so far, by (Phong, tessellation): each made once, by the first
/// setting that needs it, while the others that need it wait.
#[derive(Default)]
struct References {
    made: std::sync::Mutex<BTreeMap<ReferenceKey, Reference>>,
}

/// What tells references apart: the exact Gouraud image or a shading's own best (Phong's,
/// or any shading's on a textured scene), the tessellation, the shadows.
type ReferenceKey = (Option<String>, Option<u32>, Option<bool>);

/// The reference `setting` is measured against, as a key ([`References::get`]).
fn reference_key(setting: &Setting, world: bool, textured: bool) -> ReferenceKey {
    let shading = setting.settings.shading;
    (
        (shading == Shading::Phong || textured).then(|| shading.to_string()),
        reference_tessellation(setting, world),
        setting.settings.shadows,
    )
}

type Reference = std::sync::Arc<std::sync::Mutex<Option<std::sync::Arc<Vec<f64>>>>>;

impl References {
    /// The reference `setting` is measured against: its own geometry's, or for patches
    /// drawn directly (on a world scene) [`REFERENCE_TESSELLATION`]'s — close to the
    /// true surface at a cost a sweep can pay.
    fn get(
        &self,
        scene: Option<&Path>,
        setting: &Setting,
        world: bool,
        textured: bool,
    ) -> Result<std::sync::Arc<Vec<f64>>, StudyError> {
        let tessellation = reference_tessellation(setting, world);
        let key = reference_key(setting, world, textured);
        let slot = {
            let mut made = self.made.lock().expect("no reference panicked");
            std::sync::Arc::clone(made.entry(key).or_default())
        };
        let mut slot = slot.lock().expect("no reference panicked");
        if let Some(image) = &*slot {
            return Ok(std::sync::Arc::clone(image));
        }
        let image = std::sync::Arc::new(reference_image(
            scene,
            &Settings {
                tessellate: tessellation,
                ..setting.settings
            },
        )?);
        *slot = Some(std::sync::Arc::clone(&image));
        Ok(image)
    }
}

/// The tessellation of the exact reference that settings drawing Bézier patches
/// directly (`nishita`) are measured against: 64 × 64 quads a patch (261,632 triangles
/// for the teapot). The scene's own limit, [`cwisim_world::scene::MAX_TESSELLATION`],
/// is finer, at four times the triangles, the time and the memory of every reference.
pub const REFERENCE_TESSELLATION: u32 = 64;

/// The tessellation of the reference a setting is measured against (see
/// [`References::get`]).
fn reference_tessellation(setting: &Setting, world: bool) -> Option<u32> {
    if setting.renderer.patches && world {
        Some(REFERENCE_TESSELLATION)
    } else {
        setting.settings.tessellate
    }
}

/// The settings of one stream ([`streams`]) measured: the stream drawn once (read,
/// prepared, scan-converted) and executed in each setting's numeric format; all of it
/// `repeat` times for the host times. Each setting's measurement (its image, counters
/// and statistics from the first time) with its host times: the drawing's, which its
/// formats share, plus its own execution's.
pub fn measure_stream(
    scene: Option<&Path>,
    group: &[Setting],
    machine: &Machine,
    repeat: u32,
) -> Result<Vec<(Measured, Vec<Duration>)>, StudyError> {
    measure_stream_until(scene, group, machine, repeat, None)
}

/// [`measure_stream`], stopped at the next drawing or replay once `cancel` is set.
fn measure_stream_until(
    scene: Option<&Path>,
    group: &[Setting],
    machine: &Machine,
    repeat: u32,
    cancel: Option<&std::sync::atomic::AtomicBool>,
) -> Result<Vec<(Measured, Vec<Duration>)>, StudyError> {
    let Some(first) = group.first() else {
        return Ok(Vec::new());
    };
    let stop = || {
        if cancel.is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed)) {
            Err(StudyError::Cancelled)
        } else {
            Ok(())
        }
    };
    let mut out: Vec<(Measured, Vec<Duration>)> = Vec::with_capacity(group.len());
    for time in 0..repeat {
        stop()?;
        let start = Instant::now();
        let loaded = Source::resolve(scene)?.load_for(&first.settings)?;
        let renderer = (first.renderer.build)(loaded, &first.settings)?;
        let header = renderer.header();
        let mut instructions: Vec<cwisim_isa::Instruction> = Vec::new();
        let counters = cwisim_render::emit(&*renderer, &mut instructions)?;
        let stream = cwisim_isa::CheckedStream::from_vec(&header, instructions)
            .map_err(|unfit| StudyError::Array(unfit.refusal()))?;
        let drawing = start.elapsed();
        for (k, setting) in group.iter().enumerate() {
            stop()?;
            renderer
                .check_numeric(&setting.numeric)
                .map_err(cwisim_render::RenderError::Usage)?;
            let start = Instant::now();
            let mut sink = ImageSink::new(
                header.width as usize,
                header.channel_count(),
                ImageSink::DEFAULT_LIMIT_BYTES,
            );
            let stats = {
                let mut w = cwisim_xproc::EngineWriter::with_numeric(
                    &header,
                    machine,
                    Timing::Fast,
                    &setting.numeric,
                    &mut sink,
                )?;
                w.write_checked(&stream).map_err(StudyError::Array)?;
                cwisim_isa::TraceWrite::finish(&mut w).map_err(StudyError::Array)?;
                w.into_stats().expect("finished")
            };
            let image = sink.finish()?.data;
            let elapsed = drawing + start.elapsed();
            if time == 0 {
                out.push((
                    Measured {
                        image,
                        counters: counters.clone(),
                        stats,
                        time: elapsed,
                    },
                    vec![elapsed],
                ));
            } else {
                out[k].1.push(elapsed);
            }
        }
    }
    Ok(out)
}

/// Whether the renderer of `setting` reads `flag`'s setting (the registry's
/// [`registry::Entry::uses`]): a row shows only those, so that its flags are what
/// `cwisim render` accepts for it.
fn reads(setting: &Setting, flag: Flag) -> bool {
    setting.renderer.uses.contains(&flag)
}

/// The row of `setting`, measured (its host times, `repeat` of them) against
/// `reference`; not yet marked Pareto.
fn row_of(
    setting: &Setting,
    measured: &Measured,
    times: &[Duration],
    reference: &[f64],
    axes: &Axes,
) -> Row {
    let world = axes.world;
    let mut times = times.to_vec();
    times.sort();
    let stats = &measured.stats;
    let (root_tolerance, normal_angle) = patch_columns(setting, world);
    let (max_error, rms_error, psnr_db) = errors(&measured.image, reference);
    let worst = stats.lines.iter().map(|l| l.busy_cycles).max().unwrap_or(0);
    let s = &setting.settings;
    // shadows as drawn: the setting's, or the scene's own (a renderer that does not draw
    // them is measured only where the scene casts none)
    let shadows = match s.shadows {
        Some(on) if reads(setting, Flag::Shadows) => on,
        _ => axes.casting,
    };
    Row {
        renderer: setting.renderer.name,
        shading: s.shading.name(),
        shadows: match (world, shadows) {
            (false, _) => "-",
            (true, true) => "on",
            (true, false) => "off",
        },
        aa: if reads(setting, Flag::Aa) {
            s.aa.name()
        } else if s.sbuffer == SbufferMode::Abuffer {
            ABUFFER_AA
        } else {
            "-"
        },
        samples: setting.renderer.supersampled.then_some(s.samples),
        visibility: if world && reads(setting, Flag::Visibility) {
            s.visibility.name()
        } else {
            "-"
        },
        tessellate: s.tessellate,
        root_tolerance,
        normal_angle,
        numeric: short_numeric(&setting.numeric),
        register_bits: register_bits(&setting.numeric),
        instructions: stats.totals.instructions,
        busy_cycles: stats.lines.iter().map(|l| l.busy_cycles).sum(),
        worst_line_share: if stats.line_period > 0 {
            worst as f64 / stats.line_period as f64
        } else {
            0.0
        },
        late_lines: stats.totals.late_lines,
        host_ms: times
            .get(times.len() / 2)
            .map_or(0.0, |t| t.as_secs_f64() * 1e3),
        max_error,
        rms_error,
        psnr_db,
        overflows: stats.totals.overflows,
        counters: measured.counters.clone(),
        pareto: false,
    }
}

/// A row's `root_tolerance` and `normal_angle`: a renderer's that draws the patches of a
/// world scene directly, `None` for any other.
fn patch_columns(setting: &Setting, world: bool) -> (Option<f64>, Option<f64>) {
    match setting.renderer.patches && world {
        true => (
            Some(setting.settings.root_tolerance),
            setting.settings.normal_angle,
        ),
        false => (None, None),
    }
}

/// The table, as `tradeoff` prints it.
pub fn write_table(out: &mut dyn Write, rows: &[Row]) -> std::io::Result<()> {
    let layout = TableLayout::of_rows(rows);
    write_table_header(out, layout)?;
    for r in rows {
        write_table_row(out, r, layout)?;
    }
    Ok(())
}

/// The width of the renderer column for these names (at least the header's).
pub fn name_width<'a>(names: impl Iterator<Item = &'a str>) -> usize {
    names.map(str::len).chain([8]).max().unwrap_or(8)
}

/// The `tess` column's cell: the tessellation, or the root tolerance of a renderer that
/// draws patches directly, with its normal angle when the test is on (`1e-5 20°`).
fn tess_cell(
    tessellate: Option<u32>,
    root_tolerance: Option<f64>,
    normal_angle: Option<f64>,
) -> String {
    match (tessellate, root_tolerance, normal_angle) {
        (_, Some(t), Some(a)) => format!("{t:.0e} {a}°"),
        (_, Some(t), None) => format!("{t:.0e}"),
        (Some(n), None, _) => n.to_string(),
        (None, None, _) => "-".to_string(),
    }
}

/// The widths of the table's columns that vary: the renderer's (its names) and `tess`'s
/// (wider when a row shows `nishita`'s normal angle beside its root tolerance).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableLayout {
    /// The renderer column's width ([`name_width`]).
    pub renderer: usize,
    /// The `tess` column's width (at least the header's 4).
    pub tess: usize,
}

impl TableLayout {
    /// The layout of these rows, the renderer column as wide as every registered
    /// renderer's name (so that sweeps' tables line up).
    pub fn of_rows(rows: &[Row]) -> TableLayout {
        TableLayout {
            renderer: name_width(registry::REGISTRY.iter().map(|e| e.name)),
            tess: rows
                .iter()
                .map(|r| {
                    tess_cell(r.tessellate, r.root_tolerance, r.normal_angle)
                        .chars()
                        .count()
                })
                .chain([4])
                .max()
                .unwrap_or(4),
        }
    }

    /// The layout of a plan's rows before they are measured, the renderer column as wide
    /// as every registered renderer's name (so that sweeps' tables line up).
    pub fn of_plan(plan: &Plan) -> TableLayout {
        TableLayout {
            renderer: name_width(registry::REGISTRY.iter().map(|e| e.name)),
            tess: plan
                .settings
                .iter()
                .map(|s| {
                    let (root_tolerance, normal_angle) = patch_columns(s, plan.axes.world);
                    tess_cell(s.settings.tessellate, root_tolerance, normal_angle)
                        .chars()
                        .count()
                })
                .chain([4])
                .max()
                .unwrap_or(4),
        }
    }
}

/// The table's header line, laid out as `layout` says.
pub fn write_table_header(out: &mut dyn Write, layout: TableLayout) -> std::io::Result<()> {
    let (rw, tw) = (layout.renderer, layout.tess);
    writeln!(
        out,
        "{:<rw$} {:>tw$} {:<8} {:<10} {:>2} {:<5} {:<4} {:<34} {:>4} {:>8} {:>9} {:>6} {:>4} {:>8} {:>9} {:>9} {:>6} {:>5}  pareto",
        "renderer", "tess", "shading", "aa", "l", "vis", "shad", "numeric", "bits", "instr", "busy cyc", "worst", "late", "host ms", "max err", "RMS err", "PSNR", "ovfl"
    )
}

/// One row of the table, laid out as `layout` says; `*` in the last column when the row
/// is on the Pareto front ([`mark_pareto`]: known only once every row is measured).
pub fn write_table_row(out: &mut dyn Write, r: &Row, layout: TableLayout) -> std::io::Result<()> {
    let (rw, tw) = (layout.renderer, layout.tess);
    writeln!(
            out,
            "{:<rw$} {:>tw$} {:<8} {:<10} {:>2} {:<5} {:<4} {:<34} {:>4} {:>8} {:>9} {:>5.1}% {:>4} {:>8.2} {:>9.2e} {:>9.2e} {:>6} {:>5}  {}",
            r.renderer,
            tess_cell(r.tessellate, r.root_tolerance, r.normal_angle),
            r.shading,
            r.aa,
            r.samples.map_or_else(|| "-".to_string(), |n| n.to_string()),
            r.visibility,
            r.shadows,
            r.numeric,
            r.register_bits,
            r.instructions,
            r.busy_cycles,
            100.0 * r.worst_line_share,
            r.late_lines,
            r.host_ms,
            r.max_error,
            r.rms_error,
            if r.psnr_db.is_finite() {
                format!("{:.1}", r.psnr_db)
            } else {
                "inf".into()
            },
            r.overflows,
            if r.pareto { "*" } else { "" }
        )
}

/// The fixed columns of [`csv`], in order; the renderers' counters follow, one column
/// `counter_NAME` each.
pub const CSV_COLUMNS: [&str; 21] = [
    "renderer",
    "tessellate",
    "root_tolerance",
    "normal_angle",
    "shading",
    "aa",
    "samples",
    "visibility",
    "shadows",
    "numeric",
    "register_bits",
    "instructions",
    "busy_cycles",
    "worst_line_share",
    "late_lines",
    "host_ms",
    "max_error",
    "rms_error",
    "psnr_db",
    "overflows",
    "pareto",
];

/// The CSV's columns that say where each row stands in its sweep: the sweep's identity
/// (`SCENE:HASH` of its grid and machine), the row's setting's index in the grid (from 0)
/// and the grid's size. [`merge_csv`] checks with them that parts tile one grid once.
pub const PROVENANCE_COLUMNS: [&str; 3] = ["sweep", "setting", "settings"];

/// Where a run of rows stands in its sweep ([`Plan::provenance`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Provenance {
    /// The sweep's identity: `SCENE:HASH`.
    pub sweep: String,
    /// The grid index of the first row.
    pub first: usize,
    /// The grid's size.
    pub settings: usize,
}

/// The table as CSV (one header line, one line per setting). After the fixed columns
/// ([`CSV_COLUMNS`]) come the provenance's ([`PROVENANCE_COLUMNS`]: row `k` is setting
/// `prov.first + k`) and then the renderers' own counters, one column `counter_NAME` per
/// name (the union over the rows, in the order first met), empty where a row's renderer
/// does not count it.
pub fn csv(rows: &[Row], prov: &Provenance) -> String {
    let mut names: Vec<&'static str> = Vec::new();
    for r in rows {
        for (name, _) in r.counters.iter() {
            if !names.contains(&name) {
                names.push(name);
            }
        }
    }
    let mut s = CSV_COLUMNS.join(",");
    for c in PROVENANCE_COLUMNS {
        s.push(',');
        s.push_str(c);
    }
    for name in &names {
        s.push_str(",counter_");
        s.push_str(name);
    }
    s.push('\n');
    for (k, r) in rows.iter().enumerate() {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},\"{}\",{},{},{},{},{},{},{:e},{:e},{},{},{}",
            r.renderer,
            r.tessellate.map_or_else(String::new, |n| n.to_string()),
            r.root_tolerance
                .map_or_else(String::new, |t| format!("{t:e}")),
            r.normal_angle.map_or_else(String::new, |a| a.to_string()),
            r.shading,
            r.aa,
            r.samples.map_or_else(String::new, |n| n.to_string()),
            r.visibility,
            r.shadows,
            r.numeric,
            r.register_bits,
            r.instructions,
            r.busy_cycles,
            r.worst_line_share,
            r.late_lines,
            r.host_ms,
            r.max_error,
            r.rms_error,
            r.psnr_db,
            r.overflows,
            r.pareto
        ));
        s.push_str(&format!(
            ",{},{},{}",
            prov.sweep,
            prov.first + k,
            prov.settings
        ));
        for name in &names {
            s.push(',');
            if let Some(v) = r.counters.get(name) {
                s.push_str(&v.to_string());
            }
        }
        s.push('\n');
    }
    s
}

/// One CSV record's fields ([`csv`]'s: a field in double quotes may hold commas).
fn csv_fields(line: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut field)),
            (c, _) => field.push(c),
        }
    }
    if quoted {
        return Err("a quoted field is not closed".into());
    }
    out.push(field);
    Ok(out)
}

/// A row of [`csv`] read back, without its counters (for the table and the plot).
fn row_of_fields(f: &[String]) -> Result<Row, String> {
    let col = |k: usize| -> &str { &f[k] };
    let what = |k: usize, expected: &str| {
        format!(
            "column `{}`: expected {expected}, found `{}`",
            CSV_COLUMNS[k],
            col(k)
        )
    };
    let int = |k: usize| col(k).parse::<u64>().map_err(|_| what(k, "a whole number"));
    let real = |k: usize| col(k).parse::<f64>().map_err(|_| what(k, "a number"));
    let optional = |k: usize| -> Result<Option<u64>, String> {
        if col(k).is_empty() {
            Ok(None)
        } else {
            int(k).map(Some)
        }
    };
    let small = |v: u64, k: usize| u32::try_from(v).map_err(|_| what(k, "a smaller number"));
    let dash_or = |k: usize, known: &[&'static str]| -> Result<&'static str, String> {
        known
            .iter()
            .chain(&["-"])
            .find(|n| n.eq_ignore_ascii_case(col(k)))
            .copied()
            .ok_or_else(|| what(k, &known.join(" or ")))
    };
    let shadings: Vec<&'static str> = Shading::ALL.iter().map(|s| s.name()).collect();
    let filters: Vec<&'static str> = Antialias::ALL.iter().map(|a| a.name()).collect();
    let visibilities: Vec<&'static str> = Visibility::ALL.iter().map(|v| v.name()).collect();
    Ok(Row {
        renderer: registry::find(col(0))
            .map_err(|e| format!("column `renderer`: {e}"))?
            .name,
        tessellate: optional(1)?.map(|v| small(v, 1)).transpose()?,
        root_tolerance: if col(2).is_empty() {
            None
        } else {
            Some(real(2)?)
        },
        normal_angle: if col(3).is_empty() {
            None
        } else {
            Some(real(3)?)
        },
        shading: dash_or(4, &shadings)?,
        aa: dash_or(5, &[filters.as_slice(), &[ABUFFER_AA]].concat())?,
        samples: optional(6)?.map(|v| small(v, 6)).transpose()?,
        visibility: dash_or(7, &visibilities)?,
        shadows: dash_or(8, &["on", "off"])?,
        numeric: col(9).to_string(),
        register_bits: small(int(10)?, 10)?,
        instructions: int(11)?,
        busy_cycles: int(12)?,
        worst_line_share: real(13)?,
        late_lines: int(14)?,
        host_ms: real(15)?,
        max_error: real(16)?,
        rms_error: real(17)?,
        psnr_db: real(18)?,
        overflows: int(19)?,
        counters: cwisim_render::Counters::default(),
        pareto: match col(20) {
            "true" => true,
            "false" => false,
            _ => return Err(what(20, "true or false")),
        },
    })
}

/// A row of a part placed in the grid: the row, its part and line, and the line itself.
struct Placed<'a> {
    row: Row,
    part: usize,
    line: usize,
    text: &'a str,
}

/// The measured figures of a row that must be finite numbers (`psnr_db` may be infinite
/// where the RMS error is 0: an exact image).
const FIGURES: [&str; 5] = [
    "worst_line_share",
    "host_ms",
    "max_error",
    "rms_error",
    "psnr_db",
];

/// Refuses a figure of `row` that is not a finite number ≥ 0 (PSNR: any number, or +∞ for
/// an exact image), naming its column.
fn check_figures(row: &Row) -> Result<(), String> {
    let values = [
        row.worst_line_share,
        row.host_ms,
        row.max_error,
        row.rms_error,
        row.psnr_db,
    ];
    for (name, v) in FIGURES.iter().zip(values) {
        let fine = match *name {
            "psnr_db" => v.is_finite() || (v == f64::INFINITY && row.rms_error == 0.0),
            _ => v.is_finite() && v >= 0.0,
        };
        if !fine {
            return Err(format!(
                "column `{name}`: {v} is not a measured figure (a finite number{})",
                if *name == "psnr_db" {
                    "; +inf only for an exact image"
                } else {
                    " ≥ 0"
                }
            ));
        }
    }
    if let Some(t) = row.root_tolerance.filter(|t| !t.is_finite()) {
        return Err(format!(
            "column `root_tolerance`: {t} is not a finite number"
        ));
    }
    Ok(())
}

/// The header a part's CSV must start with: [`CSV_COLUMNS`], then [`PROVENANCE_COLUMNS`];
/// the first column that differs, or is missing, said.
fn check_header(name: &str, header: &[String]) -> Result<(), StudyError> {
    let expected: Vec<&str> = CSV_COLUMNS
        .iter()
        .chain(&PROVENANCE_COLUMNS)
        .copied()
        .collect();
    for (k, want) in expected.iter().enumerate() {
        match header.get(k) {
            Some(found) if found == want => {}
            Some(found) => {
                return Err(StudyError::Usage(format!(
                    "{name}:1: not a tradeoff CSV of this cwisim: column {} is `{found}`, expected `{want}`",
                    k + 1
                )))
            }
            None => {
                return Err(StudyError::Usage(format!(
                    "{name}:1: not a tradeoff CSV of this cwisim: it has {} column(s), and `{want}` (column {}) is missing",
                    header.len(),
                    k + 1
                )))
            }
        }
    }
    Ok(())
}

/// The CSVs of a sweep's parts (`--shard`, each `(its name, its text)`, in any order)
/// merged into the whole sweep's — the CSV a sweep in one go writes, but for the host
/// times: the rows in the grid's order, the counters' columns united (in the grid's order
/// of first use), and the Pareto column marked again over every row. Also the rows,
/// without their counters, for the table and the plot.
///
/// Strict, so that a partial sweep is never presented as whole: every part must be of one
/// sweep (the provenance columns' `sweep`: one scene, grid and machine), the parts must
/// hold every setting of its grid exactly once (a part given twice, parts that overlap and
/// a part left out are each refused, saying which part and line repeats a setting or which
/// settings no part holds), and every measured figure must be a finite number (a `NaN`
/// error is refused at its row and column, never marked Pareto-optimal). A file that is
/// not such a CSV is refused, located (`name:line`, the column).
pub fn merge_csv(parts: &[(String, String)]) -> Result<(String, Vec<Row>), StudyError> {
    let usage = StudyError::Usage;
    let fixed = CSV_COLUMNS.len() + PROVENANCE_COLUMNS.len();
    let mut own: Vec<Vec<String>> = Vec::with_capacity(parts.len());
    // the sweep: its identity, its size, and the part and line that said so first
    let mut sweep: Option<(String, usize, usize, usize)> = None;
    // the rows by their setting's index: as many as the parts hold, whatever size the
    // sweep claims
    let mut placed: BTreeMap<usize, Placed<'_>> = BTreeMap::new();
    for (p, (name, text)) in parts.iter().enumerate() {
        let mut lines = text.lines().enumerate();
        let header = match lines.next() {
            Some((_, h)) => csv_fields(h).map_err(|e| usage(format!("{name}:1: {e}")))?,
            None => return Err(usage(format!("{name}: empty, not a tradeoff CSV"))),
        };
        check_header(name, &header)?;
        own.push(
            header[fixed..]
                .iter()
                .map(|c| c.strip_prefix("counter_").unwrap_or(c).to_string())
                .collect(),
        );
        for (k, line) in lines {
            let at = |e: String| usage(format!("{name}:{}: {e}", k + 1));
            let fields = csv_fields(line).map_err(at)?;
            if fields.len() != header.len() {
                return Err(at(format!(
                    "{} fields, the header has {}",
                    fields.len(),
                    header.len()
                )));
            }
            let row = row_of_fields(&fields).map_err(at)?;
            check_figures(&row).map_err(at)?;
            let prov = &fields[CSV_COLUMNS.len()..fixed];
            let number = |v: &str, c: &str| {
                v.parse::<usize>().map_err(|_| {
                    at(format!(
                        "column `{c}`: expected a whole number, found `{v}`"
                    ))
                })
            };
            let (id, index, size) = (
                prov[0].as_str(),
                number(&prov[1], "setting")?,
                number(&prov[2], "settings")?,
            );
            match &sweep {
                None => sweep = Some((id.to_string(), size, p, k + 1)),
                Some((first, first_size, fp, fl)) if first != id || *first_size != size => {
                    return Err(at(format!(
                        "a row of another sweep ({id}, {size} settings) than {}:{fl}'s ({first}, {first_size} settings): the parts of one sweep share its scene, grid and machine",
                        parts[*fp].0
                    )));
                }
                Some(_) => {}
            }
            if index >= size {
                return Err(at(format!("setting {index} is past the sweep's {size}")));
            }
            if let Some(before) = placed.get(&index) {
                return Err(at(format!(
                    "setting {index} again, already at {}:{} (a part given twice, or parts that overlap)",
                    parts[before.part].0, before.line
                )));
            }
            placed.insert(
                index,
                Placed {
                    row,
                    part: p,
                    line: k + 1,
                    text: line,
                },
            );
        }
    }
    let Some((id, size, _, _)) = sweep else {
        return Err(usage("the parts hold no row: nothing to merge".into()));
    };
    if placed.len() < size {
        // the first few gaps, found from the indices held (never a walk over `size`)
        let mut shown = Vec::new();
        let mut next = 0usize;
        for &i in placed.keys().chain(std::iter::once(&size)) {
            shown.extend(
                (next..i)
                    .take(8 - shown.len().min(8))
                    .map(|m| m.to_string()),
            );
            next = i + 1;
            if shown.len() >= 8 {
                break;
            }
        }
        let missing = size - placed.len();
        return Err(usage(format!(
            "setting(s) {}{} of the sweep's {size} are in no part ({missing} missing): a part left out?",
            shown.join(", "),
            if missing > shown.len() { ", …" } else { "" },
        )));
    }
    let placed: Vec<Placed<'_>> = placed.into_values().collect();
    // the counters' columns: each row's own, in the grid's order of first use
    // (each line split again where it is needed, not held split: a field is a heap block)
    let mut counters: Vec<&str> = Vec::new();
    for pl in &placed {
        let fields = csv_fields(pl.text).expect("parsed once already");
        for (c, v) in own[pl.part].iter().zip(&fields[fixed..]) {
            if !v.is_empty() && !counters.contains(&c.as_str()) {
                counters.push(c);
            }
        }
    }
    let (lines, mut rows): (Vec<(usize, &str)>, Vec<Row>) = placed
        .into_iter()
        .map(|pl| ((pl.part, pl.text), pl.row))
        .unzip();
    mark_pareto(&mut rows);
    let mut out = CSV_COLUMNS.join(",");
    for c in PROVENANCE_COLUMNS {
        out.push(',');
        out.push_str(c);
    }
    for c in &counters {
        out.push_str(",counter_");
        out.push_str(c);
    }
    out.push('\n');
    for (index, (&(part, text), row)) in lines.iter().zip(&rows).enumerate() {
        let fields = csv_fields(text).expect("parsed once already");
        for (k, v) in fields[..CSV_COLUMNS.len()].iter().enumerate() {
            if k > 0 {
                out.push(',');
            }
            match CSV_COLUMNS[k] {
                "pareto" => out.push_str(if row.pareto { "true" } else { "false" }),
                "numeric" => {
                    out.push('"');
                    out.push_str(v);
                    out.push('"');
                }
                _ => out.push_str(v),
            }
        }
        out.push_str(&format!(",{id},{index},{size}"));
        let theirs = &fields[fixed..];
        for c in &counters {
            out.push(',');
            if let Some((_, v)) = own[part].iter().zip(theirs).find(|(n, _)| n == c) {
                out.push_str(v);
            }
        }
        out.push('\n');
    }
    Ok((out, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `text` with the host times blanked (they are the machine's, not the sweep's).
    fn without_host_times(text: &str) -> String {
        let at = CSV_COLUMNS.iter().position(|c| *c == "host_ms").unwrap();
        text.lines()
            .map(|l| {
                let mut f = csv_fields(l).unwrap();
                f[at].clear();
                f.iter()
                    .map(|v| {
                        if v.contains(',') {
                            format!("\"{v}\"")
                        } else {
                            v.clone()
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    #[test]
    fn shards_merged_are_the_whole_sweep() {
        let formats: Vec<Numeric> = ["f64", "fixed:I=10.14,dI=4.20,ddI=1.27"]
            .iter()
            .map(|f| f.parse().unwrap())
            .collect();
        let renderers = ["vanrij".to_string(), "woo-chall".to_string()];
        let size = Some(Size {
            width: 40,
            height: 30,
        });
        let request = Request {
            size,
            renderers: renderers.to_vec(),
            formats: formats.clone(),
            ..Request::default()
        };
        let plan = Plan::new(Some(Path::new("still-life")), &request).unwrap();
        let machine = Machine::default();
        let whole = tradeoff_rows(
            Some(Path::new("still-life")),
            &request,
            &machine,
            1,
            1,
            &mut |_| {},
        )
        .unwrap();
        for count in [2, 5] {
            let mut parts = Vec::new();
            let mut covered = 0;
            for index in 0..count {
                let shard = Shard { index, count };
                let groups = shard.groups(plan.groups.len());
                assert_eq!(groups.start, covered);
                covered = groups.end;
                let rows =
                    measure_groups(&plan, groups.clone(), &machine, 1, 2, &mut |_| {}).unwrap();
                assert!(rows.iter().all(|r| !r.pareto));
                let prov = plan.provenance(&machine, groups.clone());
                parts.push((format!("part-{index}.csv"), csv(&rows, &prov)));
            }
            assert_eq!(covered, plan.groups.len());
            let (merged, rows) = merge_csv(&parts).unwrap();
            assert_eq!(rows.len(), whole.len());
            assert_eq!(
                without_host_times(&merged),
                without_host_times(&csv(
                    &whole,
                    &plan.provenance(&machine, 0..plan.groups.len())
                )),
                "{count} shards"
            );
        }
        assert_eq!("1/3".parse::<Shard>(), Ok(Shard { index: 1, count: 3 }));
        for bad in ["3/3", "1", "a/2", "1/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let e = merge_csv(&[("x.csv".into(), "a,b\n1,2\n".into())]).unwrap_err();
        assert!(
            e.to_string().starts_with("x.csv:1: not a tradeoff CSV"),
            "{e}"
        );
        // in any order
        let mut parts = Vec::new();
        for index in (0..3).rev() {
            let shard = Shard { index, count: 3 };
            let groups = shard.groups(plan.groups.len());
            let rows = measure_groups(&plan, groups.clone(), &machine, 1, 1, &mut |_| {}).unwrap();
            let prov = plan.provenance(&machine, groups);
            parts.push((format!("part-{index}.csv"), csv(&rows, &prov)));
        }
        let (merged, _) = merge_csv(&parts).unwrap();
        let whole_csv = csv(&whole, &plan.provenance(&machine, 0..plan.groups.len()));
        assert_eq!(without_host_times(&merged), without_host_times(&whole_csv));
        // strict: a part twice, a part left out, a part of another sweep, a NaN figure
        let err = |parts: &[(String, String)]| merge_csv(parts).unwrap_err().to_string();
        let twice = [
            parts[0].clone(),
            parts[1].clone(),
            parts[2].clone(),
            parts[0].clone(),
        ];
        let e = err(&twice);
        assert!(
            e.starts_with("part-2.csv:2: setting ") && e.contains("again, already at part-2.csv:2"),
            "{e}"
        );
        let e = err(&parts[..2]);
        assert!(
            e.contains("are in no part") && e.contains("missing): a part left out?"),
            "{e}"
        );
        let other = Plan::new(Some(Path::new("fig25")), &request).unwrap();
        let fig = measure_groups(&other, 0..1, &machine, 1, 1, &mut |_| {}).unwrap();
        let foreign = (
            "fig.csv".to_string(),
            csv(&fig, &other.provenance(&machine, 0..1)),
        );
        let e = err(&[parts[0].clone(), parts[1].clone(), foreign]);
        assert!(
            e.starts_with("fig.csv:2: a row of another sweep (fig25:"),
            "{e}"
        );
        let faster = Machine {
            clock_hz: machine.clock_hz * 2.0,
            ..machine.clone()
        };
        assert_ne!(
            plan.provenance(&faster, 0..1).sweep,
            plan.provenance(&machine, 0..1).sweep,
            "the machine is part of a sweep's identity"
        );
        let at = CSV_COLUMNS.iter().position(|c| *c == "rms_error").unwrap();
        let mut lines: Vec<String> = parts[0].1.lines().map(str::to_string).collect();
        let mut f = csv_fields(&lines[1]).unwrap();
        f[at] = "NaN".into();
        lines[1] = f
            .iter()
            .map(|v| {
                if v.contains(',') {
                    format!("\"{v}\"")
                } else {
                    v.clone()
                }
            })
            .collect::<Vec<_>>()
            .join(",");
        let nan = (parts[0].0.clone(), lines.join("\n"));
        let e = err(&[nan, parts[1].clone(), parts[2].clone()]);
        assert!(
            e.starts_with("part-2.csv:2: column `rms_error`: NaN is not a measured figure"),
            "{e}"
        );
        // an older CSV, without the provenance: the first column missing is named
        let old: String = parts[0]
            .1
            .lines()
            .next()
            .unwrap()
            .split(',')
            .take(CSV_COLUMNS.len())
            .collect::<Vec<_>>()
            .join(",");
        let e = err(&[("old.csv".into(), old)]);
        assert!(
            e.starts_with("old.csv:1: not a tradeoff CSV of this cwisim: it has 21 column(s), and `sweep` (column 22) is missing"),
            "{e}"
        );
        let mut broken = csv(&whole, &plan.provenance(&machine, 0..plan.groups.len()));
        broken = broken.replacen("vanrij", "vanrij-typo", 1);
        let e = merge_csv(&[("y.csv".into(), broken)]).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("y.csv:2: column `renderer`: unknown renderer"),
            "{e}"
        );
    }

    #[test]
    fn a_csv_row_reads_back_as_written_and_the_table_makes_room_for_the_normal_angle() {
        let mut rows = vec![row(10, 1e-3), row(20, 2e-3)];
        rows[0].renderer = "nishita";
        rows[0].root_tolerance = Some(1e-5);
        rows[0].normal_angle = Some(22.5);
        rows[1].renderer = "vanrij";
        rows[1].tessellate = Some(8);
        let prov = Provenance {
            sweep: "x:0".into(),
            first: 0,
            settings: 2,
        };
        let text = csv(&rows, &prov);
        let header: Vec<String> = csv_fields(text.lines().next().unwrap()).unwrap();
        assert_eq!(header[3], "normal_angle");
        for (line, want) in text.lines().skip(1).zip(&rows) {
            let back = row_of_fields(&csv_fields(line).unwrap()).unwrap();
            assert_eq!(&back, want, "{line}");
        }
        let mut table = Vec::new();
        write_table(&mut table, &rows).unwrap();
        let table = String::from_utf8(table).unwrap();
        let lines: Vec<&str> = table.lines().collect();
        let words = |l: &str| l.split_whitespace().take(3).collect::<Vec<_>>().join(" ");
        assert_eq!(words(lines[1]), "nishita 1e-5 22.5°", "{table}");
        assert_eq!(words(lines[2]), "vanrij 8 gouraud", "{table}");
        // the columns after `tess` line up
        let at = |l: &str| l.find("gouraud").map(|b| l[..b].chars().count());
        assert_eq!(at(lines[1]), at(lines[2]));
        assert_eq!(
            lines[0]
                .find("shading")
                .map(|b| lines[0][..b].chars().count()),
            at(lines[1])
        );
    }

    fn row(busy: u64, rms: f64) -> Row {
        Row {
            renderer: "r",
            shading: "gouraud",
            aa: "box",
            samples: None,
            visibility: "exact",
            shadows: "off",
            tessellate: None,
            root_tolerance: None,
            normal_angle: None,
            numeric: "f64".into(),
            register_bits: 256,
            instructions: 0,
            busy_cycles: busy,
            worst_line_share: 0.0,
            late_lines: 0,
            host_ms: 0.0,
            max_error: 0.0,
            rms_error: rms,
            psnr_db: 0.0,
            overflows: 0,
            counters: Default::default(),
            pareto: false,
        }
    }

    #[test]
    fn the_grid_has_phong_on_exact_world_surfaces_and_every_tessellation() {
        let vanrij = registry::find("vanrij").unwrap();
        let f64_only = [Numeric::F64];
        let world = Axes {
            world: true,
            size: None,
            tessellations: vec![4, 8],
            patches: true,
            ..Axes::default()
        };
        let g = grid(&[vanrij], &world, &f64_only);
        // 2 tessellations × (exact: phong, gouraud, flat; eval0: gouraud, flat) × 2 aa,
        // and the report's box filter with Gouraud (exact and eval0); Phong's box filter
        // is the report's (`box-centre`), its only one
        assert_eq!(g.len(), 2 * (5 * 2 + 2));
        let centre = g.iter().filter(|s| s.settings.aa == Antialias::BoxCentre);
        assert_eq!(
            centre
                .clone()
                .filter(|s| s.settings.shading == Shading::Gouraud)
                .count(),
            2 * 2
        );
        assert_eq!(
            centre
                .filter(|s| s.settings.shading == Shading::Phong)
                .count(),
            2
        );
        for s in &g {
            let st = &s.settings;
            assert!(st.shading != Shading::Phong || st.visibility == Visibility::Exact);
            assert!(st.shading != Shading::Phong || st.aa != Antialias::Box);
            assert!(matches!(st.tessellate, Some(4) | Some(8)));
        }
        let screen = Axes::default();
        let g = grid(&[vanrij], &screen, &f64_only);
        assert_eq!(
            g.len(),
            2 * 2 + 1,
            "no Phong, no eval0, no tessellation on a screen scene; box-centre with Gouraud"
        );
        assert!(g
            .iter()
            .all(|s| s.settings.shading != Shading::Phong && s.settings.tessellate.is_none()));
    }

    /// A row of the grid is what `cwisim render` draws with the flags it prints: every
    /// setting shown (shading, aa, visibility, samples, tessellation, root tolerance) is
    /// one its renderer reads and the command line accepts for it (`check_given`,
    /// `check_scene`), and parsed back it is the setting measured. (Phong's box filter
    /// is printed `box-centre`: `--aa box` is refused with Phong; `nishita` reads no
    /// `--visibility`.)
    #[test]
    fn every_row_is_reproducible_with_the_flags_it_prints() {
        let entries: Vec<&'static registry::Entry> = registry::REGISTRY
            .iter()
            .filter(|e| !e.progressive)
            .collect();
        let teapot = Source::resolve(Some("teapot".as_ref()))
            .unwrap()
            .load(None)
            .unwrap()
            .scene;
        let pot = Source::resolve(None).unwrap().load(None).unwrap().scene;
        let fig25 = Source::resolve(Some("fig25".as_ref()))
            .unwrap()
            .load(None)
            .unwrap()
            .scene;
        let size = Some(Size {
            width: 32,
            height: 24,
        });
        let cases = [
            (
                "teapot",
                &teapot,
                Axes {
                    world: true,
                    size,
                    tessellations: vec![4, 8],
                    patches: true,
                    ..Axes::default()
                },
            ),
            (
                "pot",
                &pot,
                Axes {
                    world: true,
                    size,
                    ..Axes::default()
                },
            ),
            (
                "pot",
                &pot,
                Axes {
                    world: true,
                    size,
                    shadows: shadows_axis(&[true, false], &[false]).unwrap(),
                    ..Axes::default()
                },
            ),
            (
                "fig25",
                &fig25,
                Axes {
                    size,
                    ..Axes::default()
                },
            ),
            (
                "pot",
                &pot,
                Axes {
                    world: true,
                    size,
                    sbuffer: vec![SbufferMode::Host, SbufferMode::Abuffer],
                    ..Axes::default()
                },
            ),
            (
                "teapot",
                &teapot,
                Axes {
                    world: true,
                    size,
                    patches: true,
                    normal_angles: vec![None, Some(20.0)],
                    ..Axes::default()
                },
            ),
        ];
        let mut abuffer = 0;
        let mut angled = 0;
        let measured = Measured {
            image: Vec::new(),
            counters: Default::default(),
            stats: Default::default(),
            time: Duration::ZERO,
        };
        let mut phong = 0;
        for (name, scene, axes) in cases {
            let g = grid(&entries, &axes, &[Numeric::F64]);
            assert!(!g.is_empty(), "{name}");
            for setting in &g {
                let row = row_of(setting, &measured, &[], &[], &axes);
                let entry = setting.renderer;
                let what = format!("{name}: {}", setting.describe());
                // the flags the row prints, parsed back over the defaults
                let mut given = vec![Flag::Shading, Flag::Size];
                let mut parsed = Settings {
                    shading: row.shading.parse().unwrap(),
                    size: axes.size,
                    ..Settings::default()
                };
                if row.aa == ABUFFER_AA {
                    // the A-buffer's rows: `--sbuffer abuffer`
                    abuffer += 1;
                    given.push(Flag::Sbuffer);
                    parsed.sbuffer = SbufferMode::Abuffer;
                } else if row.aa != "-" {
                    given.push(Flag::Aa);
                    parsed.aa = row.aa.parse().unwrap();
                }
                if row.visibility != "-" {
                    given.push(Flag::Visibility);
                    parsed.visibility = row.visibility.parse().unwrap();
                }
                if let Some(l) = row.samples {
                    given.push(Flag::Samples);
                    parsed.samples = l;
                }
                if let Some(n) = row.tessellate {
                    given.push(Flag::Tessellate);
                    parsed.tessellate = Some(n);
                }
                if let Some(t) = row.root_tolerance {
                    given.push(Flag::RootTolerance);
                    parsed.root_tolerance = t;
                }
                if let Some(a) = row.normal_angle {
                    angled += 1;
                    given.push(Flag::NormalAngle);
                    parsed.normal_angle = Some(a);
                }
                // shadows printed otherwise than the scene draws them: the flag
                if row.shadows != "-" && (row.shadows == "on") != axes.casting {
                    given.push(Flag::Shadows);
                    parsed.shadows = Some(row.shadows == "on");
                }
                assert_eq!(entry.check_given(&given, &parsed), Ok(()), "{what}");
                assert_eq!(
                    entry.check_scene(&given, scene, name, &parsed),
                    Ok(()),
                    "{what}"
                );
                assert_eq!(parsed, setting.settings, "{what}");
                if row.shading == "phong" {
                    phong += 1;
                    assert_ne!(row.aa, "box", "{what}");
                }
            }
        }
        assert!(phong > 0);
        // sbuffer's A-buffer: three shadings × the samples axis
        assert_eq!(abuffer, 3 * SAMPLES_AXIS.len());
        // nishita's normal angle: two shadings × the root tolerances
        assert_eq!(angled, 2 * ROOT_TOLERANCE_AXIS.len());
    }

    /// Phong's box filter is coverage × the centre's shade whether asked as `box` or
    /// `box-centre`: the grid's `box-centre` rows draw what its `box` rows drew.
    #[test]
    fn phong_draws_box_and_box_centre_alike() {
        let size = Some(Size {
            width: 48,
            height: 40,
        });
        let machine = Machine::default();
        for name in ["vanrij", "nishita"] {
            let scene = (name == "nishita").then_some(Path::new("teapot"));
            let measured = |aa| {
                let setting = Setting {
                    renderer: registry::find(name).unwrap(),
                    settings: Settings {
                        shading: Shading::Phong,
                        aa,
                        size,
                        ..Settings::default()
                    },
                    numeric: Numeric::F64,
                };
                let m = measure(scene, &setting, &machine).unwrap();
                (
                    m.image.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    m.counters,
                    m.stats,
                )
            };
            assert!(
                measured(Antialias::Box) == measured(Antialias::BoxCentre),
                "{name}"
            );
        }
    }

    #[test]
    fn the_settings_of_one_stream_differ_only_in_the_format() {
        let entries = [
            registry::find("vanrij").unwrap(),
            registry::find("woo-chall").unwrap(),
        ];
        let formats = [
            Numeric::F64,
            Numeric::F32,
            "fixed:I=4.8,dI=2.8,ddI=1.8".parse().unwrap(),
        ];
        let axes = Axes {
            world: true,
            ..Axes::default()
        };
        let g = grid(&entries, &axes, &formats);
        let streams = streams(&g);
        assert_eq!(streams.len() * formats.len(), g.len());
        let mut next = 0;
        for r in &streams {
            assert_eq!(r.start, next);
            next = r.end;
            let first = &g[r.start];
            for (s, numeric) in g[r.clone()].iter().zip(&formats) {
                assert_eq!(s.settings, first.settings);
                assert_eq!(s.renderer.name, first.renderer.name);
                assert_eq!(&s.numeric, numeric);
            }
        }
        assert_eq!(next, g.len());
        assert_eq!(
            describe_stream(&g[streams[0].clone()]),
            "vanrij phong box-centre exact (3 formats)"
        );
    }

    /// A stream drawn once and executed in each format measures what rendering each
    /// setting through the pipeline does: image, statistics, counters.
    #[test]
    fn a_shared_stream_measures_as_each_setting_rendered_alone() {
        let size = Some(Size {
            width: 64,
            height: 48,
        });
        for (name, shading) in [("vanrij", Shading::Phong), ("sbuffer", Shading::Gouraud)] {
            let group: Vec<Setting> = [
                Numeric::F64,
                Numeric::F32,
                "fixed:I=10.10,dI=4.14,ddI=1.20".parse().unwrap(),
            ]
            .into_iter()
            .map(|numeric| Setting {
                renderer: registry::find(name).unwrap(),
                settings: Settings {
                    shading,
                    size,
                    samples: 2,
                    ..Settings::default()
                },
                numeric,
            })
            .collect();
            let machine = Machine::default();
            let shared = measure_stream(None, &group, &machine, 2).unwrap();
            assert_eq!(shared.len(), group.len());
            for (setting, (m, times)) in group.iter().zip(&shared) {
                let alone = measure(None, setting, &machine).unwrap();
                assert_eq!(times.len(), 2);
                assert_eq!(m.image, alone.image, "{}", setting.describe());
                assert_eq!(m.counters, alone.counters, "{}", setting.describe());
                let figures = |m: &Measured| {
                    let s = &m.stats;
                    (
                        s.totals.instructions,
                        s.totals.late_lines,
                        s.totals.overflows,
                        s.line_period,
                        s.lines.iter().map(|l| l.busy_cycles).collect::<Vec<_>>(),
                    )
                };
                assert_eq!(figures(m), figures(&alone), "{}", setting.describe());
            }
        }
    }

    #[test]
    fn the_pareto_front_keeps_only_undominated_points() {
        let mut rows = vec![
            row(100, 0.5),
            row(200, 0.1),
            row(150, 0.6), // dominated by (100, 0.5)
            row(300, 0.1), // dominated by (200, 0.1)
            row(400, 0.0),
        ];
        mark_pareto(&mut rows);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto).collect();
        assert_eq!(front, [true, true, false, false, true]);
        // fewer register bits at the same cycles and error dominates; more bits with a
        // smaller error does not
        let mut rows = vec![row(100, 0.5), row(100, 0.5), row(100, 0.4)];
        rows[1].register_bits = 80;
        rows[2].register_bits = 128;
        mark_pareto(&mut rows);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto).collect();
        assert_eq!(front, [false, true, true]);
    }

    /// The brute-force front: every pair compared.
    fn pareto_by_pairs(points: &[(u64, u32, f64)]) -> Vec<bool> {
        points
            .iter()
            .map(|&(c, b, e)| {
                !e.is_nan()
                    && !points.iter().any(|&(c2, b2, e2)| {
                        c2 <= c && b2 <= b && e2 <= e && (c2 < c || b2 < b || e2 < e)
                    })
            })
            .collect()
    }

    proptest::proptest! {
        #[test]
        fn the_fast_front_is_the_front_of_every_pair(
            points in proptest::collection::vec(
                (0u64..6, 0u32..4, proptest::sample::select(vec![0.0, 0.1, 0.2, 0.5, f64::INFINITY, f64::NAN])),
                0..60,
            )
        ) {
            proptest::prop_assert_eq!(pareto(&points), pareto_by_pairs(&points));
        }
    }

    #[test]
    fn a_nan_error_is_never_on_the_front() {
        let mut rows = vec![row(100, f64::NAN), row(200, 0.1)];
        mark_pareto(&mut rows);
        assert_eq!(
            rows.iter().map(|r| r.pareto).collect::<Vec<_>>(),
            [false, true]
        );
    }

    #[test]
    fn short_formats_parse_back() {
        for f in [
            "f64",
            "f32",
            "fixed:I=10.22,dI=4.28,ddI=1.35,acc=10.22,overflow=saturate",
            "fixed:I=3.4,dI=2.8,ddI=1.9,acc=6.4,overflow=wrap",
        ] {
            let n: Numeric = f.parse().unwrap();
            let back: Numeric = short_numeric(&n).parse().unwrap();
            assert_eq!(back, n, "{f}");
        }
        assert_eq!(
            short_numeric(&"fixed:I=10.22,dI=4.28,ddI=1.35".parse().unwrap()),
            "fixed:I=10.22,dI=4.28,ddI=1.35"
        );
    }

    #[test]
    fn errors_and_psnr() {
        let (max, rms, psnr) = errors(&[0.0, 0.5, 1.0, 1.0], &[0.0, 0.5, 1.0, 0.9]);
        assert!((max - 0.1).abs() < 1e-12);
        assert!((rms - 0.05).abs() < 1e-12);
        assert!((psnr - 26.0206).abs() < 1e-3, "{psnr}");
        assert_eq!(errors(&[1.0], &[1.0]).2, f64::INFINITY);
    }

    /// The pot, a world scene with exact visibility: its fragments' intensities are
    /// affine, so the exact box filter (`--aa box`) matches the independent exact
    /// reference within 1e-9 at every pixel, at the same instructions and cycles as the
    /// report's `box-centre`, which is off by its approximation.
    #[test]
    fn the_pot_is_exact_with_the_exact_box_filter() {
        let vanrij = registry::find("vanrij").unwrap();
        let setting = |aa| Setting {
            renderer: vanrij,
            settings: Settings {
                aa,
                size: Some(Size {
                    width: 96,
                    height: 96,
                }),
                ..Settings::default()
            },
            numeric: Numeric::F64,
        };
        let (exact, centre) = (setting(Antialias::Box), setting(Antialias::BoxCentre));
        let reference = reference_image(None, &exact.settings).unwrap();
        let machine = Machine::default();
        let (a, b) = (
            measure(None, &exact, &machine).unwrap(),
            measure(None, &centre, &machine).unwrap(),
        );
        let (max_exact, _, _) = errors(&a.image, &reference);
        let (max_centre, _, _) = errors(&b.image, &reference);
        assert!(max_exact < 1e-9, "{max_exact}");
        assert!(max_centre > 1e-3, "{max_centre}");
        assert_eq!(a.stats.totals.opcodes, b.stats.totals.opcodes);
        let busy = |m: &Measured| -> u64 { m.stats.lines.iter().map(|l| l.busy_cycles).sum() };
        assert_eq!(busy(&a), busy(&b));
    }

    #[test]
    fn a_textured_scene_is_measured_per_pixel_against_each_shading_s_own_best_image() {
        let rows = tradeoff_rows(
            Some(Path::new("textures4")),
            &Request {
                size: Some(Size {
                    width: 40,
                    height: 30,
                }),
                renderers: vec!["vanrij".to_string(), "woo-chall".to_string()],
                formats: vec![Numeric::F64],
                ..Request::default()
            },
            &Machine::default(),
            1,
            1,
            &mut |_| {},
        )
        .unwrap();
        // exact visibility only (eval0 claims hold one value per run), the per-pixel box
        // filter (box-centre) or point sampling, every shading
        assert!(rows
            .iter()
            .all(|r| r.visibility != "eval0" && r.aa != "box"));
        for shading in ["flat", "gouraud", "phong"] {
            let best = rows
                .iter()
                .find(|r| r.renderer == "vanrij" && r.shading == shading && r.aa == "box-centre")
                .unwrap_or_else(|| panic!("{shading}"));
            // the default span tolerance against tolerance 0: small, not nothing
            assert!(
                best.max_error < 8.0 / 512.0,
                "{shading}: {}",
                best.max_error
            );
        }
        assert!(rows.iter().any(|r| r.renderer == "woo-chall"));
        assert!(rows.iter().all(|r| r.rms_error.is_finite()));
    }
}
