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
//! [`polys`] makes the polygons from any scene, [`sweep`] is the PT/APT loop and
//! [`fill`] the scan engine (FILL's rules, a row's emission), both shared with `bsp`.
//! `docs/RENDERERS.md` says how it reads the paper; `docs/ERRATA.md` what it corrects.

mod abuffer;
pub mod fill;
mod layers;
pub mod polys;
pub mod sweep;

use crate::cp::Increment;
use crate::error::RenderError;
use crate::renderer::{Counters, FramePlan, Renderer};
use crate::settings::{SbufferMode, Settings};
use crate::source::LoadedScene;
use crate::subsample::{Grid, Sampler};
use cwisim_isa::TraceHeader;
use cwisim_scene::Shading;
use cwisim_xproc::numeric::Numeric;
use cwisim_xproc::{Image, RunStats};
use fill::{cp_rows, Rule, Scan};
use polys::Polys;
use std::time::Duration;

/// The registry's one line about it.
pub const ABOUT: &str = "Barkan & Gordon's S-buffer: critical-points scan conversion polygon by polygon into a host depth line per scanline (or sub-scanline, --samples), visible runs sent (--sbuffer host|overdraw|transparent, --cp-increment)";

/// The widest A-buffer mask: 8 × 8 bits, one `u64`.
pub const MAX_MASK_SIDE: u32 = 8;

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

impl SBuffer {
    /// The renderer of `loaded` under `settings`.
    pub fn new(loaded: LoadedScene, settings: &Settings) -> Result<SBuffer, RenderError> {
        let loaded = loaded.drawn_as(settings)?;
        settings.check().map_err(RenderError::Usage)?;
        let polys = Polys::new(loaded, settings, "sbuffer", polys::BYTES_PER_TRIANGLE)?;
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
            if polys.textured() {
                return Err(RenderError::Usage(
                    "--sbuffer overdraw undoes runs exactly, which the fitted pieces of a texture do not allow: use --sbuffer host".into(),
                ));
            }
        }
        if settings.sbuffer == SbufferMode::Abuffer {
            if !(1..=MAX_MASK_SIDE).contains(&sampler.l) {
                return Err(RenderError::Usage(format!(
                    "--sbuffer abuffer keeps a --samples × --samples coverage mask in 64 bits: use --samples 1 to {MAX_MASK_SIDE}, found {}",
                    sampler.l
                )));
            }
            if sampler.grid != Grid::Centre {
                return Err(RenderError::Usage(
                    "--sbuffer abuffer's mask bits are the centres of a pixel's l × l cells: use --grid centre".into(),
                ));
            }
        }
        if settings.sbuffer == SbufferMode::Transparent && !polys.transparent() {
            return Err(RenderError::Usage(format!(
                "--sbuffer transparent composites the polygons of transparent meshes, and {} has none (no material with a transmittance above 0): use --sbuffer host",
                polys.source.name()
            )));
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

    fn scan(&self) -> Scan<'_> {
        Scan {
            scene: &self.polys,
            list: &self.polys.polys,
            rank: None,
            sampler: self.sampler,
            shading: self.shading,
            increment: self.increment,
            rule: Rule::Nearer,
            overdraw: self.mode == SbufferMode::Overdraw,
            transparent: self.mode == SbufferMode::Transparent,
            abuffer: self.mode == SbufferMode::Abuffer,
            merge: self.merge,
            shade_tolerance: self.shade_tolerance,
        }
    }
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
        let frame = self
            .scan()
            .run()
            .map_err(|source| RenderError::of_renderer("sbuffer", source))?;
        Ok(Box::new(frame))
    }

    fn settings_phrase(&self) -> String {
        let s = &self.sampler;
        let fitted = if self.scan().per_pixel() {
            format!(" (span tolerance {})", self.shade_tolerance)
        } else {
            String::new()
        };
        let sampling = if self.mode == SbufferMode::Abuffer {
            format!(
                "{l}×{l} coverage mask per pixel ({} bits), fragments resolved per pixel by the host",
                s.l * s.l,
                l = s.l
            )
        } else if self.scan().one_sample() {
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
                SbufferMode::Transparent =>
                    "per sample a list of the transparent polygons down to the nearest opaque one, composited (§5.2)",
                SbufferMode::Abuffer =>
                    "the scanline A-buffer: per pixel a fragment per polygon (coverage mask, colour), resolved nearest first at the pixel centre (§5.2)",
            }
        )
    }

    fn summary_rows(&self, c: &Counters, _stats: &RunStats) -> Vec<(&'static str, String)> {
        let mut rows = self.polys.summary_rows();
        rows.extend(cp_rows(c));
        if self.mode != SbufferMode::Transparent && self.polys.transparent() {
            rows.push((
                "note",
                "meshes with a transmittance drawn opaque: this mode keeps the nearest surface (--sbuffer transparent composites the layers)".to_string(),
            ));
        }
        rows
    }

    fn stage_times(&self) -> Vec<(&'static str, Duration)> {
        let mut times = vec![("transform & lighting", self.polys.transform_time)];
        if self.polys.shadows.is_some() {
            times.push(("shadows", self.polys.shadow_time));
        }
        times
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
