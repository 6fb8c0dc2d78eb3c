//! cwisim's anti-aliased polygon fill against peer rasterizers, on the same polygons at
//! 1024×1024: `cargo bench -p cwisim-world --bench peers`.
//!
//! Groups `peers_pot_1024` (the embedded pot's 2D visible fragments: disjoint),
//! `peers_random_1024` (200 random overlapping triangles and quads, seeded) and
//! `peers_mesh_1024` (the tessellated surface of 2048 triangles, every edge shared:
//! `cwisim_scene::grid::warped_grid(32, 1024)`). Throughput:
//! polygons per second. Each benchmark starts from the screen-space polygons and ends with a
//! full 1024×1024 coverage image (or, for `ypipe_flat`, the counted stream):
//!
//! * `zeno/…`, `ab_glyph_rasterizer/…`, `tiny-skia/…` — the peers: `per_polygon` fills each
//!   polygon alone and adds it into an `f32` image (the summed coverage cwisim computes, for
//!   both sets); `one_path` (pot only) fills all polygons as one path into one buffer of the
//!   peer's native type (`u8` or `f32`). The outlines are clipped and oriented once, before
//!   timing; building each peer's path is timed.
//! * `cwisim/ypipe_flat` — the Y-processor alone: trapezia, AET, DO_FILL's box-filtered
//!   stream with flat shading, into an instruction counter (no array).
//! * `cwisim/array_flat`, `cwisim/array_gouraud` — the Y-processor and the array (fast
//!   engine with its timing model, `f64` registers, `EngineWriter` + `ImageSink`), flat and
//!   Gouraud shading, each instruction fed to the array as it comes.
//! * `cwisim/bands_flat`, `cwisim/bands_gouraud` — the same as `cwisim render` runs it on
//!   one thread: bands of 16 rows executed as emitted, each taken in by the array in order.
//!
//! What exactly is compared, and the accuracy of each (not timed here):
//! `tests/peers/mod.rs` and `cargo run --release -p cwisim-world --example peer_accuracy`.

#[path = "../tests/peers/mod.rs"]
mod peers;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use cwisim_scene::ScreenScene;
use cwisim_ypipe::Shading;
use peers::{cwisim_image, cwisim_image_in_bands, fill, outlines, ypipe_only, Mode, Peer};
use std::hint::black_box;

const SIZE: u32 = 1024;

fn set(c: &mut Criterion, name: &str, scene: &ScreenScene, modes: &[Mode]) {
    let o = outlines(scene);
    let mut group = c.benchmark_group(format!("peers_{name}_{SIZE}"));
    group.sample_size(20);
    group.throughput(Throughput::Elements(scene.polygons.len() as u64));
    for &mode in modes {
        for peer in Peer::ALL {
            group.bench_function(format!("{}/{}", peer.name(), mode.name()), |b| {
                b.iter(|| black_box(fill(peer, mode, black_box(&o), SIZE, SIZE)))
            });
        }
    }
    group.bench_function("cwisim/ypipe_flat", |b| {
        b.iter(|| black_box(ypipe_only(black_box(scene), Shading::Flat)))
    });
    for (id, shading) in [
        ("cwisim/array_flat", Shading::Flat),
        ("cwisim/array_gouraud", Shading::Gouraud),
    ] {
        group.bench_function(id, |b| {
            b.iter(|| black_box(cwisim_image(black_box(scene), shading)))
        });
    }
    for (id, shading) in [
        ("cwisim/bands_flat", Shading::Flat),
        ("cwisim/bands_gouraud", Shading::Gouraud),
    ] {
        group.bench_function(id, |b| {
            b.iter(|| black_box(cwisim_image_in_bands(black_box(scene), shading)))
        });
    }
    group.finish();
}

fn bench(c: &mut Criterion) {
    set(
        c,
        "pot",
        &peers::pot(SIZE),
        &[Mode::PerPolygon, Mode::OnePath],
    );
    set(
        c,
        "random",
        &peers::random(SIZE, 200, 0x5EED_CAFE),
        &[Mode::PerPolygon],
    );
    set(
        c,
        "mesh",
        &cwisim_scene::grid::warped_grid(32, SIZE),
        &[Mode::PerPolygon, Mode::OnePath],
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
