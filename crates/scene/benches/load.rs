//! Scene loading: a screen scene's text parsed and validated (`parse_scene`).
//!
//! * `load/grid_32` — the 2048-triangle tessellated surface at 1024×1024
//!   ([`cwisim_scene::grid::warped_grid`]), as [`ScreenScene::to_json`] writes it.
//!
//! The figures are in docs/PERFORMANCE.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use cwisim_scene::grid::warped_grid;
use cwisim_scene::parse_scene;
use std::hint::black_box;
use std::time::Duration;

fn load(c: &mut Criterion) {
    let text = warped_grid(32, 1024).to_json();
    let mut g = c.benchmark_group("load");
    g.sample_size(30).measurement_time(Duration::from_secs(4));
    g.throughput(Throughput::Bytes(text.len() as u64));
    g.bench_function("grid_32", |b| {
        b.iter(|| black_box(parse_scene(black_box(&text)).expect("valid")))
    });
    g.finish();
    eprintln!("load grid_32: {} bytes", text.len());
}

criterion_group!(benches, load);
criterion_main!(benches);
