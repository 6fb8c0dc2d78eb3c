//! `cwisim refine`: Bergman et al.'s adaptive refinement measured phase by phase — what
//! each phase's frame cost the array (instructions, regenerated ones, bus-busy cycles,
//! the worst scanline against the line period, late scanlines) against how far it is
//! from the full-quality image (`render --shading phong --aa box`: RMS, PSNR), with the
//! display list's bytes beside a frame buffer's, and the naive sequence the paper's
//! figure 1 compares against: every phase's renderer in full, one after the other.

use crate::cost::CostMap;
use crate::error::StudyError;
use crate::refine_ids::IdImage;
use crate::tradeoff::errors;
use cwisim_isa::{Instruction, Opcode, TraceWrite};
use cwisim_render::refine::{Phase, Refine};
use cwisim_render::settings::Threshold;
use cwisim_render::vanrij::VanRij;
use cwisim_render::{render, ArrayConfig, RenderError, Renderer, Settings, Source, Taps};
use cwisim_scene::Shading;
use cwisim_world::events::Change;
use cwisim_xproc::{Image, ImageSink, Machine, RunStats, Timing};
use std::io;
use std::path::Path;

/// Bytes per instruction head in the display list (`cwisim_isa::packed`'s layout: opcode,
/// value lengths, `x`, `dx`).
pub const HEAD_BYTES: u64 = 12;
/// Bytes per carried value in the display list (`f64`).
pub const VALUE_BYTES: u64 = 8;
/// Bytes per pixel and channel of the frame buffer the display list is compared with
/// (8 bits, what a display shows).
pub const FRAME_BUFFER_BYTES_PER_SAMPLE: u64 = 1;

/// One phase's figures.
#[derive(Clone, Debug, PartialEq)]
pub struct PhaseRow {
    /// The phase's name (`flat`, `gouraud`, `phong`, `aa`).
    pub phase: &'static str,
    /// Pixels it processed: those its regenerated instructions evaluated (shading
    /// phases), or those it box-filtered (anti-aliasing).
    pub pixels: u64,
    /// Instructions of its frame, `Refresh` included.
    pub instructions: u64,
    /// Of those, the ones it regenerated (the rest re-send what the previous frame had).
    pub regenerated: u64,
    /// Bus-busy cycles of its frame.
    pub busy_cycles: u64,
    /// Bus-busy cycles of every frame up to and including this one.
    pub cumulative_cycles: u64,
    /// The busiest scanline's bus-busy cycles.
    pub worst_line_cycles: u64,
    /// Scanlines not ready by their deadline.
    pub late_lines: u64,
    /// RMS error against the full-quality image.
    pub rms: f64,
    /// PSNR against it, dB (peak 1; infinite when equal).
    pub psnr: f64,
    /// The frame's display list: its instructions as the host keeps them.
    pub display_list_bytes: u64,
    /// The cycle, from the run's start, by which the display has shown the frame's last
    /// scanline: when it was ready, or its deadline if later (the display takes each
    /// scanline at its deadline, so a frame is never shown sooner than its scanlines'
    /// periods allow).
    pub shown_cycles: u64,
}

/// What one refinement run measured.
#[derive(Clone, Debug)]
pub struct RefineRun {
    /// The scene's name.
    pub scene: String,
    /// The stream's header (for a trace of it).
    pub header: cwisim_isa::TraceHeader,
    /// Pixel columns.
    pub width: usize,
    /// Scanlines.
    pub lines: usize,
    /// Values per pixel.
    pub channels: usize,
    /// The array's line period, cycles.
    pub line_period: u64,
    /// A frame buffer of the image ([`FRAME_BUFFER_BYTES_PER_SAMPLE`] per value).
    pub frame_buffer_bytes: u64,
    /// One row per phase.
    pub rows: Vec<PhaseRow>,
    /// The naive sequence: every phase in full (each threshold `all`), one row per phase.
    pub naive: Vec<PhaseRow>,
    /// Bus-busy cycles of every scanline, per frame.
    pub busy_per_line: Vec<Vec<u64>>,
    /// Each frame's image.
    pub frames: Vec<Image>,
    /// Each frame's cost map (when asked for).
    pub cost_maps: Vec<CostMap>,
    /// The polygon-ID view of the display list (when asked for).
    pub ids: Option<IdImage>,
    /// The renderer's counters over the run (`gouraud_polygons`, `aa_fragments`, …).
    pub counters: cwisim_render::Counters,
    /// Polygons of the display list (exact visible fragments).
    pub polygons: u64,
    /// Visible triangles passing the highlight test, and all visible triangles.
    pub highlight: (u64, u64),
}

/// What to run.
#[derive(Clone, Debug)]
pub struct RefineSetup<'a> {
    /// The scene: a file or an embedded name (`None`: the default).
    pub scene: Option<&'a Path>,
    /// Changes made to the scene once loaded, in order (an interactive session's events
    /// so far, [`crate::refine_session`]); empty: the scene as it is.
    pub changes: &'a [Change],
    /// The drawing settings (thresholds, size, span tolerance).
    pub settings: Settings,
    /// The phases, in order.
    pub phases: Vec<Phase>,
    /// Frames the vertex phase is split into (`--vertex-fraction`; 1: one frame).
    pub vertex_parts: u32,
    /// The machine model.
    pub machine: Machine,
    /// Also measure the naive sequence.
    pub naive: bool,
    /// Keep each frame's cost map.
    pub cost_maps: bool,
    /// Gather the polygon-ID view ([`RefineRun::ids`]).
    pub ids: bool,
    /// Threads the run's frames are rendered on (the pipeline's bands; the same output
    /// at any count): [`run_refines`] gives a single run all of its threads, a sweep's
    /// runs one each.
    pub threads: usize,
    /// Set: the run stops after the scanline being drawn, with
    /// [`cwisim_render::RenderError::Cancelled`] (a Python caller's Ctrl-C).
    pub cancel: Option<&'a std::sync::atomic::AtomicBool>,
}

/// A tap on the stream: each frame's cost map and display-list bytes, and the stream
/// passed on to a trace writer.
struct Tap<'a> {
    lines: usize,
    width: usize,
    refreshes: usize,
    maps: Option<Vec<CostMap>>,
    bytes: Vec<u64>,
    trace: Option<&'a mut dyn TraceWrite>,
}

impl TraceWrite for Tap<'_> {
    fn write(&mut self, i: &Instruction) -> io::Result<()> {
        let frame = self.refreshes / self.lines.max(1);
        if self.bytes.len() <= frame {
            self.bytes.resize(frame + 1, 0);
        }
        let values: usize = (0..3).map(|slot| i.value(slot).len()).sum();
        self.bytes[frame] += HEAD_BYTES + VALUE_BYTES * values as u64;
        if let Some(maps) = &mut self.maps {
            if maps.len() <= frame {
                maps.push(CostMap::new(self.width));
            }
            maps[frame].record(i);
        }
        if i.op == Opcode::Refresh {
            self.refreshes += 1;
        }
        match &mut self.trace {
            Some(t) => t.write(i),
            None => Ok(()),
        }
    }

    fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// The full-quality image: `render --renderer vanrij --shading phong --aa box` at the
/// settings' size, tessellation and span tolerance.
pub fn full_quality(
    scene: Option<&Path>,
    changes: &[Change],
    settings: &Settings,
    machine: &Machine,
) -> Result<Vec<f64>, StudyError> {
    let phong = Settings {
        shading: Shading::Phong,
        ..*settings
    };
    let loaded = load(scene, changes, &phong)?;
    let r = VanRij::new(loaded, &phong)?;
    let h = r.header();
    let mut sink = ImageSink::new(
        h.width as usize,
        h.channel_count(),
        ImageSink::DEFAULT_LIMIT_BYTES,
    );
    let array = ArrayConfig {
        machine: machine.clone(),
        ..ArrayConfig::default()
    };
    render(&r, &array, settings.threads, &mut sink, Taps::default())?;
    Ok(sink.finish()?.data)
}

/// The scene `scene` loaded for `settings`, with `changes` made to it (a world scene's).
fn load(
    scene: Option<&Path>,
    changes: &[Change],
    settings: &Settings,
) -> Result<cwisim_render::LoadedScene, StudyError> {
    let mut loaded = Source::resolve(scene)?.load_for(settings)?;
    if let cwisim_world::AnyScene::World(w) = &mut loaded.scene {
        if !changes.is_empty() {
            // changes read against another scene are refused here, not drawn wrong
            for c in changes {
                c.apply(&mut w.spec).map_err(RenderError::from)?;
            }
            w.spec.validate().map_err(RenderError::from)?;
        }
    }
    Ok(loaded)
}

/// One pass of the refinement through the array: its frames, statistics, and taps.
struct Pass {
    refine: Refine,
    frames: Vec<Image>,
    stats: RunStats,
    counters: cwisim_render::Counters,
    bytes: Vec<u64>,
    maps: Vec<CostMap>,
}

fn pass(
    setup: &RefineSetup,
    settings: &Settings,
    trace: Option<&mut dyn TraceWrite>,
    mut progress: Option<&mut dyn FnMut(u64)>,
) -> Result<Pass, StudyError> {
    let settings = &Settings {
        threads: setup.threads,
        ..*settings
    };
    let loaded = load(setup.scene, setup.changes, settings)?;
    let refine = Refine::with_vertex_parts(loaded, settings, &setup.phases, setup.vertex_parts)?;
    let h = refine.header();
    let (w, lines, ch) = (h.width as usize, h.lines as usize, h.channel_count());
    // every frame's image is kept (8 bytes a value), with the cost maps' counts (8 bytes
    // a pixel) when asked for: against the memory budget before the first is drawn
    let frames = u64::from(refine.frames());
    let per_frame = (w * lines) as u64 * (8 * ch as u64 + if setup.cost_maps { 8 } else { 0 });
    cwisim_scene::budget::Budget::current()
        .check_memory(
            &format!("refine's {frames} frame(s) of {w}×{lines}×{ch} values"),
            frames.saturating_mul(per_frame),
        )
        .map_err(|e| StudyError::Usage(e.to_string()))?;
    let mut sink = ImageSink::new(w, ch, ImageSink::DEFAULT_LIMIT_BYTES);
    let mut tap = Tap {
        lines,
        width: w,
        refreshes: 0,
        maps: setup.cost_maps.then(Vec::new),
        bytes: Vec::new(),
        trace,
    };
    let mut report = |lines: u64| {
        if let Some(p) = progress.as_mut() {
            p(lines);
        }
    };
    let array = ArrayConfig {
        machine: setup.machine.clone(),
        numeric: cwisim_xproc::Numeric::F64,
        timing: Timing::Fast,
    };
    let stop = || {
        setup
            .cancel
            .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
    };
    let done = render(
        &refine,
        &array,
        setup.threads,
        &mut sink,
        Taps {
            also: Some(&mut tap),
            progress: Some(&mut report),
            cancel: Some(&stop),
        },
    )?;
    let image = sink.finish()?;
    let per = w * lines * ch;
    let frames = image
        .data
        .chunks(per.max(1))
        .map(|d| Image {
            width: w,
            channels: ch,
            lines,
            data: d.to_vec(),
        })
        .collect();
    Ok(Pass {
        refine,
        frames,
        stats: done.stats,
        counters: done.counters,
        bytes: tap.bytes,
        maps: tap.maps.unwrap_or_default(),
    })
}

/// The rows of a pass, measured against `reference`.
fn rows(p: &Pass, reference: &[f64]) -> Vec<PhaseRow> {
    let mut cumulative = 0;
    let get = |name: &str| p.counters.get(name).unwrap_or(0);
    p.refine
        .phases()
        .iter()
        .enumerate()
        .map(|(k, _)| {
            let lines = p.stats.lines.iter().filter(|l| l.frame == k as u64);
            let (busy, worst, late, shown) = lines.fold((0, 0, 0, 0), |(b, w, n, s), l| {
                (
                    b + l.busy_cycles,
                    w.max(l.busy_cycles),
                    n + u64::from(l.slack < 0),
                    s.max(l.ready.max(l.deadline)),
                )
            });
            cumulative += busy;
            let (_, rms, psnr) = errors(&p.frames[k].data, reference);
            PhaseRow {
                phase: p.refine.frame_name(k),
                pixels: get(p.refine.frame_counter(k, "pixels")),
                instructions: get(p.refine.frame_counter(k, "instructions")),
                regenerated: get(p.refine.frame_counter(k, "regenerated")),
                busy_cycles: busy,
                cumulative_cycles: cumulative,
                worst_line_cycles: worst,
                late_lines: late,
                rms,
                psnr,
                display_list_bytes: p.bytes.get(k).copied().unwrap_or(0),
                shown_cycles: shown,
            }
        })
        .collect()
}

/// Runs the refinement of `setup` (and, if asked, the naive sequence), writing its
/// stream to `trace` and reporting scanlines done to `progress`.
pub fn run_refine(
    setup: &RefineSetup,
    trace: Option<&mut dyn TraceWrite>,
    progress: Option<&mut dyn FnMut(u64)>,
) -> Result<RefineRun, StudyError> {
    let reference = || {
        full_quality(
            setup.scene,
            setup.changes,
            &Settings {
                threads: setup.threads,
                ..setup.settings
            },
            &setup.machine,
        )
        .map(std::sync::Arc::new)
    };
    run_refine_against(setup, trace, progress, &reference)
}

/// [`run_refine`], its full-quality image from `reference`.
fn run_refine_against(
    setup: &RefineSetup,
    trace: Option<&mut dyn TraceWrite>,
    progress: Option<&mut dyn FnMut(u64)>,
    reference: &dyn Fn() -> Result<std::sync::Arc<Vec<f64>>, StudyError>,
) -> Result<RefineRun, StudyError> {
    let source = Source::resolve(setup.scene)?;
    if let cwisim_world::AnyScene::Screen(_) = source.load_for(&setup.settings)?.scene {
        return Err(StudyError::Usage(format!(
            "{} is a screen scene (intensities only, nothing to light or refine): refine measures world scenes; `render --renderer refine` draws a screen scene as its one frame",
            source.name()
        )));
    }
    let reference = reference()?;
    let reference = reference.as_slice();
    let p = pass(setup, &setup.settings, trace, progress)?;
    let h = p.refine.header();
    let naive = if setup.naive {
        let all = Settings {
            gouraud_threshold: Threshold::All,
            phong_angle: Threshold::All,
            aa_threshold: Threshold::All,
            ..setup.settings
        };
        let full = RefineSetup {
            cost_maps: false,
            ids: false,
            ..setup.clone()
        };
        let mut rows = rows(&pass(&full, &all, None, None)?, reference);
        // from scratch each time: a frame's cost is its own, and they add up
        let mut cumulative = 0;
        for r in &mut rows {
            cumulative += r.busy_cycles;
            r.cumulative_cycles = cumulative;
        }
        rows
    } else {
        Vec::new()
    };
    let busy_per_line = (0..p.frames.len() as u64)
        .map(|k| {
            p.stats
                .lines
                .iter()
                .filter(|l| l.frame == k)
                .map(|l| l.busy_cycles)
                .collect()
        })
        .collect();
    let (width, lines, channels) = (h.width as usize, h.lines as usize, h.channel_count());
    let ids = if setup.ids {
        Some(IdImage::gather(&p.refine.id_view()?, lines)?)
    } else {
        None
    };
    Ok(RefineRun {
        scene: Source::resolve(setup.scene)?.name(),
        header: h,
        width,
        lines,
        channels,
        line_period: p.stats.line_period,
        frame_buffer_bytes: (width * lines * channels) as u64 * FRAME_BUFFER_BYTES_PER_SAMPLE,
        rows: rows(&p, reference),
        naive,
        busy_per_line,
        counters: p.counters.clone(),
        polygons: p.refine.polygons().screen.polygons.len() as u64,
        highlight: p.refine.highlight_pass(),
        frames: p.frames,
        cost_maps: p.maps,
        ids,
    })
}

/// Runs several refinements — a sweep's runs, `setups` — on `threads` threads (0: one
/// per core), handing each run to `each` in order as soon as it and every run before it
/// are done; the runs in order. `progress` is told the scanlines done over every run so
/// far (from any thread). The runs are the same at any thread count. A trace is written
/// only of a single run (on the calling thread): with `trace` and several setups, a
/// usage error. A single run is rendered on `threads` threads itself (its bands; the
/// same output at any count), each run of several on one.
pub fn run_refines(
    setups: &[RefineSetup<'_>],
    threads: usize,
    trace: Option<&mut dyn TraceWrite>,
    progress: &(dyn Fn(u64) + Sync),
    mut each: impl FnMut(usize, &RefineRun),
) -> Result<Vec<RefineRun>, StudyError> {
    if let Some(trace) = trace {
        let [setup] = setups else {
            return Err(StudyError::Usage(
                "a trace is the stream of one run; a sweep makes several".into(),
            ));
        };
        let setup = RefineSetup {
            threads,
            ..setup.clone()
        };
        let run = run_refine(&setup, Some(trace), Some(&mut |lines| progress(lines)))?;
        each(0, &run);
        return Ok(vec![run]);
    }
    if let [setup] = setups {
        let setup = RefineSetup {
            threads,
            ..setup.clone()
        };
        let run = run_refine(&setup, None, Some(&mut |lines| progress(lines)))?;
        each(0, &run);
        return Ok(vec![run]);
    }
    // scanlines done by each run so far
    let done: Vec<std::sync::atomic::AtomicU64> = setups
        .iter()
        .map(|_| std::sync::atomic::AtomicU64::new(0))
        .collect();
    // the full-quality image depends on the drawing and the scene's changes (a
    // session's events), not on the thresholds a sweep varies: one per drawing, made by
    // the first run that needs it while the others wait
    let drawing = |setup: &RefineSetup<'_>| {
        (
            Settings {
                gouraud_threshold: Threshold::All,
                phong_angle: Threshold::All,
                aa_threshold: Threshold::All,
                threads: 1,
                ..setup.settings
            },
            setup.changes.to_vec(),
        )
    };
    type Slot = std::sync::Mutex<Option<std::sync::Arc<Vec<f64>>>>;
    let mut references: Vec<((Settings, Vec<Change>), Slot)> = Vec::new();
    for setup in setups {
        let key = drawing(setup);
        if !references.iter().any(|(k, _)| *k == key) {
            references.push((key, std::sync::Mutex::new(None)));
        }
    }
    let reference_of = |setup: &RefineSetup<'_>| {
        let key = drawing(setup);
        let (_, slot) = references
            .iter()
            .find(|(k, _)| *k == key)
            .expect("every drawing has a slot");
        let mut slot = slot.lock().expect("no reference panicked");
        if let Some(image) = &*slot {
            return Ok(std::sync::Arc::clone(image));
        }
        let image = std::sync::Arc::new(full_quality(
            setup.scene,
            setup.changes,
            &setup.settings,
            &setup.machine,
        )?);
        *slot = Some(std::sync::Arc::clone(&image));
        Ok(image)
    };
    let mut runs = Vec::with_capacity(setups.len());
    crate::parallel::ordered(
        setups.len(),
        threads,
        |k| {
            let mut report = |lines: u64| {
                done[k].store(lines, std::sync::atomic::Ordering::Relaxed);
                progress(
                    done.iter()
                        .map(|d| d.load(std::sync::atomic::Ordering::Relaxed))
                        .sum(),
                );
            };
            run_refine_against(&setups[k], None, Some(&mut report), &|| {
                reference_of(&setups[k])
            })
        },
        |event| {
            if let crate::parallel::Event::Done(k, run) = event {
                each(k, &run);
                runs.push(run);
            }
        },
    )?;
    Ok(runs)
}
