//! A plan whose trapezia are made band by band (`ScanPlan::by_bands`) holds, while its
//! bands are emitted, the bands' trapezia and a few bytes a polygon (its first
//! Identifier and rows), not the frame's trapezia: a frame four times as tall needs no
//! more than those few bytes for each of its extra polygons, where the plan that makes
//! the frame's trapezia at once (`ScanPlan::new` below `BANDED_FROM_POLYGONS`) grows by
//! a trapezium's 184 bytes and its edges' 48 for each. One test in this binary, so that no
//! other test's allocations are counted with it.

use cwisim_fuzzing::heap::{peak_heap, Counting};
use cwisim_isa::{Instruction, TraceWrite};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_ypipe::{emit_rows, Options, ScanPlan, Shading};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// A sink that counts what it is given and keeps nothing.
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

/// A mesh of small triangles over `width × height` pixels (cells of 1.7 px, each cut in
/// two), Gouraud-shaded: the visible fragments of a dense mesh.
fn mesh(width: u32, height: u32) -> ScreenScene {
    let cell = 1.7;
    let (nx, ny) = (
        (f64::from(width) / cell) as usize,
        (f64::from(height) / cell) as usize,
    );
    let mut polygons = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let at = |di: usize, dj: usize| [(i + di) as f64 * cell, (j + dj) as f64 * cell];
            let (a, b, c, d) = (at(0, 0), at(1, 0), at(1, 1), at(0, 1));
            for v in [[a, b, c], [a, c, d]] {
                let shade = |p: [f64; 2]| vec![0.25 + 1e-3 * p[0] + 5e-4 * p[1]];
                polygons.push(Polygon::new(
                    v.to_vec(),
                    v.iter().map(|&p| shade(p)).collect(),
                ));
            }
        }
    }
    ScreenScene {
        width,
        height,
        channels: 1,
        polygons,
    }
}

/// The plan made and its frame emitted in bands of 16 rows: the instructions, and the
/// peak heap beyond the scene.
fn emitted(scene: &ScreenScene, by_bands: bool) -> (u64, usize) {
    let options = Options {
        shading: Shading::Gouraud,
        ..Options::default()
    };
    let mut sink = Count(0);
    let ((), peak) = peak_heap(|| {
        let plan = if by_bands {
            ScanPlan::by_bands(scene, &options)
        } else {
            ScanPlan::new(scene, &options)
        };
        let mut row = 0;
        while row < scene.height {
            let end = (row + 16).min(scene.height);
            emit_rows(&plan, &options, row..end, &mut sink).expect("a sink that keeps nothing");
            row = end;
        }
    });
    (sink.0, peak)
}

#[test]
fn a_plan_made_band_by_band_holds_the_bands_not_the_frame() {
    let short = mesh(96, 64);
    let tall = mesh(96, 256);
    let more = tall.polygons.len() - short.polygons.len();
    assert!(tall.polygons.len() < cwisim_ypipe::BANDED_FROM_POLYGONS);
    let (short_out, short_peak) = emitted(&short, true);
    let (tall_out, tall_peak) = emitted(&tall, true);
    assert!(tall_out > 3 * short_out, "{short_out} {tall_out}");
    // the tall frame's extra polygons' rows and first Identifiers (16 and 4 bytes, in
    // vectors grown by doubling), and some room
    let index = 2 * 20 * more;
    let slack = 64 << 10;
    assert!(
        tall_peak <= short_peak + index + slack,
        "by bands: {short_peak} B for {} polygons, {tall_peak} B for {}",
        short.polygons.len(),
        tall.polygons.len()
    );
    // the frame's trapezia at once grow with the frame: this test would see it
    let (whole_short_out, whole_short) = emitted(&short, false);
    let (whole_tall_out, whole_tall) = emitted(&tall, false);
    assert_eq!((whole_short_out, whole_tall_out), (short_out, tall_out));
    eprintln!(
        "peak heap, {} then {} polygons: by bands {short_peak} then {tall_peak} B, \
         the frame's trapezia at once {whole_short} then {whole_tall} B",
        short.polygons.len(),
        tall.polygons.len()
    );
    assert!(
        whole_tall > whole_short + index + slack,
        "the frame's trapezia: {whole_short} B, then {whole_tall} B"
    );
    assert!(
        whole_tall > whole_short + 200 * more,
        "{whole_short} B, then {whole_tall} B for {more} more polygons"
    );
}
