//! The strip sweep's memory follows the bands in flight, not the frame: handed on band by
//! band (`sweep::strip_by_strip_into`), a frame four times as tall needs no more than its
//! triangles' index (64 bytes a triangle) besides what the shorter one needed, where
//! collecting the frame's fragments (`strip_by_strip`) grows with them. One test in this
//! binary, so that no other test's allocations are counted with it.

use cwisim_world::face::ScreenTriangle;
use cwisim_world::sweep::{strip_by_strip, strip_by_strip_into};

// for its counting allocator and `peak_heap` (its scenes are not used here)
#[path = "layers/mod.rs"]
#[allow(dead_code)]
mod layers;

/// Two layers of a mesh over `width × height` pixels: a grid of `cell`-pixel squares cut
/// into triangles, each layer on a tilted plane, the back one shifted by a third of a cell
/// (so that its triangles are cut by the front one's edges).
fn two_layers(width: f64, height: f64, cell: f64) -> Vec<ScreenTriangle> {
    let mut out = Vec::new();
    for (layer, shift, z0) in [(0u32, 0.0, 0.5), (1, cell / 3.0, 0.25)] {
        let inv_depth = |p: [f64; 2]| z0 + 1e-4 * p[0] - 5e-5 * p[1];
        let (nx, ny) = ((width / cell) as usize, (height / cell) as usize);
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let at = |di: usize, dj: usize| {
                    [
                        (i + di) as f64 * cell + shift,
                        (j + dj) as f64 * cell + shift,
                    ]
                };
                let (a, b, c, d) = (at(0, 0), at(1, 0), at(1, 1), at(0, 1));
                for points in [[a, b, c], [a, c, d]] {
                    let mut t = ScreenTriangle {
                        points,
                        inv_depth: points.map(inv_depth),
                        intensity: Default::default(),
                        mesh: layer,
                        face: out.len() as u32,
                        surface: Default::default(),
                    };
                    t.intensity[0][0] = 0.5;
                    out.push(t);
                }
            }
        }
    }
    out
}

#[test]
fn handed_on_band_by_band_the_sweep_holds_the_bands_not_the_frame() {
    let short = two_layers(96.0, 64.0, 1.7);
    let tall = two_layers(96.0, 256.0, 1.7);
    let streamed = |tris: &[ScreenTriangle], threads: usize| {
        let mut fragments = 0;
        let ((), peak) = layers::peak_heap(|| {
            strip_by_strip_into(tris, 1, 1, threads, |band| {
                fragments += band.fragments.len()
            })
        });
        (fragments, peak)
    };
    let collected = |tris: &[ScreenTriangle]| {
        let (fragments, peak) = layers::peak_heap(|| strip_by_strip(tris, 1, 1).0);
        (fragments.len(), peak)
    };
    // what the tall frame may need beyond the short one: its extra triangles' index
    let index = 64 * (tall.len() - short.len());
    let slack = 64 << 10;
    let (short_fragments, short_peak) = streamed(&short, 1);
    let (tall_fragments, tall_peak) = streamed(&tall, 1);
    assert!(
        tall_fragments > 3 * short_fragments,
        "{short_fragments} {tall_fragments}"
    );
    assert!(
        tall_peak <= short_peak + index + slack,
        "streamed: {short_peak} B for {} triangles, {tall_peak} B for {}",
        short.len(),
        tall.len()
    );
    // on two threads, at most four bands in flight
    let (two_fragments, two_peak) = streamed(&tall, 2);
    assert_eq!(two_fragments, tall_fragments);
    assert!(
        two_peak <= tall_peak + 4 * short_peak + slack,
        "two threads: {two_peak} B against {tall_peak} B on one"
    );
    // the measure tells them apart: holding the frame's fragments grows with them
    let (n, short_held) = collected(&short);
    assert_eq!(n, short_fragments);
    let (n, tall_held) = collected(&tall);
    assert_eq!(n, tall_fragments);
    assert!(
        tall_held > short_held + index + slack,
        "collected: {short_held} B, then {tall_held} B"
    );
    eprintln!(
        "triangles {} / {}; fragments {short_fragments} / {tall_fragments}; \
         streamed {short_peak} / {tall_peak} B (two threads {two_peak} B); \
         collected {short_held} / {tall_held} B",
        short.len(),
        tall.len()
    );
}
