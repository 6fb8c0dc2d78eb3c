//! Barkan & Gordon's benchmark, the host side: `cargo bench -p cwisim-render --bench cp`.
//!
//! For each family of `cwisim scenes generate cp-bench` (convex, few, many critical
//! points) at `n` = 100 and 1000 vertices per polygon, 200 polygons in 512 × 512 (seed 1):
//! the Y-processor's work for one frame — the renderer built from the scene and every row
//! emitted into memory — of `sbuffer` (critical-points scan conversion into a one-line
//! depth buffer) and of `vanrij --aa none` (the trapezoid path). The array is not run: its
//! work depends on the spans, not on `n` (docs/REPRODUCTION.md).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use cwisim_isa::Instruction;
use cwisim_render::cpbench::{generate, BenchSpec, Family};
use cwisim_render::{registry, LoadedScene, Settings};
use cwisim_scene::Antialias;
use cwisim_world::AnyScene;
use std::hint::black_box;
use std::time::Duration;

fn host_frame(name: &str, scene: &cwisim_scene::ScreenScene, settings: &Settings) -> usize {
    let loaded = LoadedScene::built("cp-bench", AnyScene::Screen(scene.clone()));
    let r = (registry::find(name).expect("registered").build)(loaded, settings).expect("builds");
    let plan = r.frame(0, None).expect("plans");
    let mut out: Vec<Instruction> = Vec::new();
    plan.emit_rows(0..r.header().lines, &mut out)
        .expect("emits");
    out.len()
}

fn cp_bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("cp_bench");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    let sbuffer = Settings {
        samples: 1,
        ..Settings::default()
    };
    let vanrij = Settings {
        aa: Antialias::None,
        ..Settings::default()
    };
    for family in Family::ALL {
        for n in [100u32, 1000] {
            let (scene, _) = generate(&BenchSpec {
                family,
                polygons: 200,
                vertices: n..=n,
                seed: 1,
                width: 512,
                height: 512,
            })
            .expect("a benchmark scene");
            let id = format!("{family}/{n}");
            g.bench_with_input(BenchmarkId::new("sbuffer", &id), &scene, |b, s| {
                b.iter(|| black_box(host_frame("sbuffer", s, &sbuffer)))
            });
            g.bench_with_input(BenchmarkId::new("vanrij", &id), &scene, |b, s| {
                b.iter(|| black_box(host_frame("vanrij", s, &vanrij)))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, cp_bench);
criterion_main!(benches);
