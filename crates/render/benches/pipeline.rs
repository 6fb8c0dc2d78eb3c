//! The whole pipeline, measured: `cargo bench -p cwisim-render --bench pipeline`.
//!
//! * `pot_1024` — the embedded pot at 1024×1024, end to end from the parsed scene:
//!   transform and lighting, visibility, the Y-processor, and the array with its timing
//!   model (fast engine, f64) into an image; `exact` and `eval0` visibility, one thread
//!   and two (`render --threads 2`: exact visibility and the pipeline on two threads).
//! * `stages_1024` — the same stages one by one: host preparation (project + visibility;
//!   `exact_2threads`: exact visibility on two threads),
//!   the Y-processor alone (trapezium rows per second), the array alone replaying the
//!   stream (instructions per second; `array_instructions` with no output,
//!   `array_image` into the `f64` image as `cwisim render`'s array stage).
//! * `scaling` — a fixed polygon set (the pot's visible fragments at 256×256) in images
//!   from 256² to 4096²: the cost follows the work in the scene plus one `Refresh` per
//!   scanline, not the image's area.
//! * `decode` — reading the pot's stream back from each trace encoding, instructions
//!   per second.
//!
//! The figures are in docs/PERFORMANCE.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use cwisim_isa::{io::read_all, Encoding, Instruction, TraceHeader, TraceWrite};
use cwisim_render::vanrij::VanRij;
use cwisim_render::{
    render as run_pipeline, ArrayConfig, LoadedScene, PolygonScene, Settings, Taps,
};
use cwisim_scene::ScreenScene;
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, project::project, resolve_on, AnyScene, Visibility, WorldScene};
use cwisim_xproc::{EngineWriter, ImageSink, LineSink, Machine, NullSink, RunStats, Timing};
use cwisim_ypipe::{emit, header, Claim, Options, Shading};
use std::hint::black_box;
use std::time::Duration;

/// `stream` through the fast `f64` array, each instruction checked as a renderer's is,
/// its scanlines into `sink`; the array's statistics.
fn replay(h: &TraceHeader, stream: &[Instruction], sink: &mut dyn LineSink<f64>) -> RunStats {
    let mut a =
        EngineWriter::<f64>::new(h, &Machine::default(), Timing::Fast, sink).expect("machine");
    for i in stream {
        a.write(i).expect("valid");
    }
    a.finish().expect("finish");
    a.into_stats().expect("finished")
}

fn pot(size: u32) -> WorldScene {
    match parse_any(embedded("pot").expect("pot").text, None)
        .expect("pot reads")
        .with_size(size, size)
        .expect("size")
    {
        AnyScene::World(w) => w,
        AnyScene::Screen(_) => unreachable!("the pot is a world scene"),
    }
}

fn options(visibility: Visibility) -> Options {
    Options {
        claim: match visibility {
            Visibility::Exact => Claim::Accumulate,
            Visibility::Eval0 => Claim::Eval0 {
                tolerance: 1.0 / 512.0,
            },
        },
        ..Options::default()
    }
}

/// Host preparation: the screen scene of `w`, exact visibility on `threads` threads.
fn prepare(w: &WorldScene, visibility: Visibility, threads: usize) -> ScreenScene {
    let (tris, _) = project(w, Shading::Gouraud).expect("projects");
    let (polygons, _) = resolve_on(&tris, w.channels(), visibility, threads);
    w.screen(polygons)
}

/// The array and its timing on a screen scene, into an image (or nowhere), through the
/// renderer interface and the pipeline as `cwisim render` runs them.
fn render(screen: ScreenScene, visibility: Visibility, threads: usize, image: bool) -> u64 {
    let h = header(&screen);
    // as `cwisim render` collects it: room for the frame reserved up front
    let mut img =
        ImageSink::new(h.width as usize, h.channel_count(), 1 << 34).with_room_for(h.lines.into());
    let mut null = NullSink;
    let sink: &mut dyn cwisim_xproc::LineSink<f64> = if image { &mut img } else { &mut null };
    let settings = Settings {
        visibility,
        ..Settings::default()
    };
    let loaded = LoadedScene::built("bench", AnyScene::Screen(screen));
    let mut polygons = PolygonScene::new(loaded, &settings).expect("prepares");
    // the screen scene stands for a world scene's visible surfaces: claim as eval0 does
    polygons.visibility_mode = Some(visibility);
    let renderer = VanRij::from_polygons(polygons, &settings);
    let r = run_pipeline(
        &renderer,
        &ArrayConfig::default(),
        threads,
        sink,
        Taps::default(),
    )
    .expect("renders");
    r.stats.totals.cycles
}

struct Count(u64);

impl TraceWrite for Count {
    fn write(&mut self, _: &Instruction) -> std::io::Result<()> {
        self.0 += 1;
        Ok(())
    }
    fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn pot_1024(c: &mut Criterion) {
    let w = pot(1024);
    let mut g = c.benchmark_group("pot_1024");
    g.sample_size(20).measurement_time(Duration::from_secs(8));
    for (name, vis) in [("exact", Visibility::Exact), ("eval0", Visibility::Eval0)] {
        for threads in [1usize, 2] {
            g.bench_function(BenchmarkId::new(name, format!("{threads}thread")), |b| {
                b.iter(|| {
                    let screen = prepare(black_box(&w), vis, threads);
                    black_box(render(screen, vis, threads, true))
                })
            });
        }
    }
    g.finish();
}

fn stages_1024(c: &mut Criterion) {
    let w = pot(1024);
    let mut g = c.benchmark_group("stages_1024");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    for (name, vis) in [("exact", Visibility::Exact), ("eval0", Visibility::Eval0)] {
        g.bench_function(BenchmarkId::new("host_prepare", name), |b| {
            b.iter(|| black_box(prepare(black_box(&w), vis, 1)))
        });
        if vis == Visibility::Exact {
            // exact visibility on two threads (`render --threads 2`)
            g.bench_function(BenchmarkId::new("host_prepare", "exact_2threads"), |b| {
                b.iter(|| black_box(prepare(black_box(&w), vis, 2)))
            });
        }
        let screen = prepare(&w, vis, 1);
        let opts = options(vis);
        let stats = emit(&screen, &opts, &mut Count(0)).expect("emit");
        g.throughput(Throughput::Elements(stats.rows_filled));
        g.bench_function(BenchmarkId::new("ypipe_rows", name), |b| {
            b.iter(|| black_box(emit(&screen, &opts, &mut Count(0)).expect("emit")))
        });
        let mut stream: Vec<Instruction> = Vec::new();
        emit(&screen, &opts, &mut stream).expect("emit");
        let h = header(&screen);
        g.throughput(Throughput::Elements(stream.len() as u64));
        g.bench_function(BenchmarkId::new("array_instructions", name), |b| {
            b.iter(|| black_box(replay(&h, &stream, &mut NullSink)))
        });
        // the same into the `f64` image, as `cwisim render`'s array stage does
        g.bench_function(BenchmarkId::new("array_image", name), |b| {
            b.iter(|| {
                let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 34);
                black_box(replay(&h, &stream, &mut sink));
                black_box(sink.finish().expect("within the limit"))
            })
        });
        eprintln!(
            "pot 1024² {name}: {} polygons, {} trapezia, {} trapezium rows, {} instructions ({:.1} per polygon)",
            screen.polygons.len(),
            stats.trapezia,
            stats.rows_filled,
            stats.instructions,
            stats.instructions as f64 / screen.polygons.len() as f64
        );
    }
    g.finish();
}

fn scaling(c: &mut Criterion) {
    // the pot's visible fragments at 256×256, the same polygons in every image
    let fixed = prepare(&pot(256), Visibility::Exact, 1);
    let mut g = c.benchmark_group("scaling");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    for side in [256u32, 512, 1024, 2048, 4096] {
        let screen = ScreenScene {
            width: side,
            height: side,
            ..fixed.clone()
        };
        g.bench_with_input(BenchmarkId::from_parameter(side), &screen, |b, s| {
            b.iter(|| black_box(render(s.clone(), Visibility::Exact, 1, false)))
        });
    }
    g.finish();
}

fn decode(c: &mut Criterion) {
    let screen = prepare(&pot(1024), Visibility::Exact, 1);
    let h = header(&screen);
    let mut g = c.benchmark_group("decode");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    for (name, enc) in [
        ("cwt", Encoding::Text),
        ("jsonl", Encoding::JsonLines),
        ("cwb", Encoding::Binary),
    ] {
        let mut bytes = Vec::new();
        let n = {
            let mut w = enc.writer(&mut bytes, &h).expect("writer");
            let stats = emit(&screen, &Options::default(), &mut *w).expect("emit");
            w.finish().expect("finish");
            stats.instructions
        };
        g.throughput(Throughput::Elements(n));
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut r = enc.reader(&bytes[..]).expect("reader");
                black_box(read_all(&mut *r).expect("decodes").len())
            })
        });
        eprintln!("decode {name}: {} bytes for {n} instructions", bytes.len());
    }
    g.finish();
}

criterion_group!(benches, pot_1024, stages_1024, scaling, decode);
criterion_main!(benches);
