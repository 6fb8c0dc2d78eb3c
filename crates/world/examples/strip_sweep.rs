//! Exact visibility pair by pair (`visibility::exact_fragments_on`, one thread) against
//! strip by strip (`sweep::strip_by_strip`), on the teapot tessellated `N × N` per patch,
//! the two alternated in one run: the engine issue 54 moves to, measured where it stands.
//!
//! ```text
//! cargo run --release -p cwisim-world --example strip_sweep [N [ROWS [RUNS]]]
//! ```
//!
//! N defaults to 32 (65,280 triangles), ROWS (pixel rows a strip) to 4, RUNS to 5; with
//! `STACKED=L` the scene is the pot as `L` stacked shells instead (`depth_complexity`'s
//! `stacked` family), with `QUADS=L` `L` squares stacked over one footprint (each shifted
//! by up to 5 px, so that none hides another whole). Prints each engine's median wall
//! time on one thread, the ratio, strip by strip's on two threads (and its speed-up; the
//! fragments must be the same), the peak heap each allocated (a counting allocator, the
//! fragments included) and the sweep's own when its bands are handed on and dropped
//! (`strip_by_strip_into`), their fragments, and the largest difference between the
//! visible areas they give a triangle (they must agree: the run stops if not), and a hash
//! of each engine's fragments, bit for bit (two builds that give the same fragments give
//! the same hashes). With `PAIRS_ONLY=1` it runs the pair-by-pair engine alone, `RUNS`
//! times, and prints each run's time and hash (to set two builds side by side). The
//! figures are in `docs/VISIBILITY.md`.

use cwisim_scene::Shading;
use cwisim_world::embedded::embedded;
use cwisim_world::face::ScreenTriangle;
use cwisim_world::visibility::{exact_fragments_on, Fragment};
use cwisim_world::{parse_any, AnyScene};
use std::time::{Duration, Instant};

#[path = "../tests/layers/mod.rs"]
mod layers;

/// Each source's visible area.
fn areas(fragments: &[Fragment], n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n];
    for f in fragments {
        let v = &f.polygon.vertices;
        let o = v[0];
        out[f.source] += 0.5
            * (1..v.len() - 1)
                .map(|i| {
                    (v[i][0] - o[0]) * (v[i + 1][1] - o[1])
                        - (v[i][1] - o[1]) * (v[i + 1][0] - o[0])
                })
                .sum::<f64>()
                .abs();
    }
    out
}

/// `layers` squares of 400 px over one footprint, each shifted by up to 5 px along the
/// diagonal (so that no one hides another whole), on parallel planes at `layers` depths
/// in a scrambled order; each square two triangles (`like`'s, moved).
fn stacked_quads(layers: usize, like: ScreenTriangle) -> Vec<ScreenTriangle> {
    let mut out = Vec::with_capacity(2 * layers);
    for k in 0..layers {
        let shift = ((k * 37) % 101) as f64 * 0.05;
        let inv_depth = 1.0 / (10.0 + ((k * 7919) % layers) as f64 * 0.01);
        let corner = |x: f64, y: f64| [x + shift, y + shift];
        let (a, b, c, d) = (
            corner(50.0, 50.0),
            corner(450.0, 50.0),
            corner(450.0, 450.0),
            corner(50.0, 450.0),
        );
        for points in [[a, b, c], [a, c, d]] {
            out.push(ScreenTriangle {
                points,
                inv_depth: [inv_depth; 3],
                ..like
            });
        }
    }
    out
}

/// A hash of the fragments, bit for bit (each one's source, corners and intensities, in
/// order): equal between two builds when they give the same fragments.
fn bits(fragments: &[Fragment]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for f in fragments {
        f.source.hash(&mut h);
        for v in &f.polygon.vertices {
            v.map(f64::to_bits).hash(&mut h);
        }
        for i in &f.polygon.intensity {
            for c in i {
                c.to_bits().hash(&mut h);
            }
        }
    }
    h.finish()
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn main() {
    let arg = |k: usize, default: u32| -> u32 {
        std::env::args().nth(k).map_or(default, |s| {
            s.parse().expect("N, ROWS and RUNS are whole numbers")
        })
    };
    let (n, rows, runs) = (arg(1, 32), arg(2, 4), arg(3, 5).max(1));
    let w = match std::env::var("STACKED") {
        // the pot as stacked shells (`depth_complexity`'s `stacked` family)
        Ok(l) => cwisim_world::scene::parse_world(
            &layers::layered_pot(l.parse().expect("STACKED=LAYERS"), 0.02),
            None,
        )
        .expect("a valid scene"),
        Err(_) => {
            let scene = parse_any(embedded("teapot").expect("the teapot").text, None)
                .and_then(|s| s.with_tessellation(n))
                .expect("the teapot tessellated");
            let AnyScene::World(w) = scene else {
                unreachable!("the teapot is a world scene")
            };
            w
        }
    };
    let (mut tris, _) = cwisim_world::project::project(&w, Shading::Gouraud).expect("projected");
    if let Ok(l) = std::env::var("QUADS") {
        tris = stacked_quads(l.parse().expect("QUADS=LAYERS"), tris[0]);
    }
    let channels = w.channels();
    if std::env::var("PAIRS_ONLY").is_ok() {
        for _ in 0..runs {
            let t = Instant::now();
            let (f, _) = exact_fragments_on(&tris, channels, 1);
            println!(
                "pair by pair {:.1} ms, fragments' bits {:016x}",
                t.elapsed().as_secs_f64() * 1e3,
                bits(&f)
            );
        }
        return;
    }
    let (mut pairs, mut strips, mut strips2) = (Vec::new(), Vec::new(), Vec::new());
    let (mut by_pairs, mut by_strips) = (Vec::new(), Vec::new());
    let (mut heap_pairs, mut heap_strips) = (0, 0);
    for _ in 0..runs {
        let t = Instant::now();
        (by_pairs, heap_pairs) = layers::peak_heap(|| exact_fragments_on(&tris, channels, 1).0);
        pairs.push(t.elapsed());
        let t = Instant::now();
        (by_strips, heap_strips) =
            layers::peak_heap(|| cwisim_world::sweep::strip_by_strip(&tris, channels, rows).0);
        strips.push(t.elapsed());
        let t = Instant::now();
        let two = cwisim_world::sweep::strip_by_strip_on(&tris, channels, rows, 2).0;
        strips2.push(t.elapsed());
        assert!(two == by_strips, "two threads gave other fragments");
    }
    // handed on band by band and dropped: what the sweep itself holds
    let ((), heap_streamed) = layers::peak_heap(|| {
        cwisim_world::sweep::strip_by_strip_into(&tris, channels, rows, 1, drop)
    });
    let (a, b) = (areas(&by_pairs, tris.len()), areas(&by_strips, tris.len()));
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let (p, s, s2) = (median(pairs), median(strips), median(strips2));
    println!("| triangles | strip rows | pair by pair | strip by strip | ratio | strips, 2 threads | peak heap (pairs / strips / streamed) | fragments (pairs / strips) | largest area difference |");
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    println!(
        "| {} | {rows} | {:.1} ms | {:.1} ms | {:.2}× | {:.1} ms ({:.2}×) | {:.1} / {:.1} / {:.1} MB | {} / {} | {worst:.1e} px² |",
        tris.len(),
        p.as_secs_f64() * 1e3,
        s.as_secs_f64() * 1e3,
        p.as_secs_f64() / s.as_secs_f64(),
        s2.as_secs_f64() * 1e3,
        s.as_secs_f64() / s2.as_secs_f64(),
        heap_pairs as f64 / 1e6,
        heap_strips as f64 / 1e6,
        heap_streamed as f64 / 1e6,
        by_pairs.len(),
        by_strips.len()
    );
    println!(
        "fragments' bits (pairs / strips): {:016x} / {:016x}",
        bits(&by_pairs),
        bits(&by_strips)
    );
    assert!(
        worst <= 1e-7,
        "the engines disagree by {worst} px² on a triangle"
    );
}
