//! Barkan & Gordon's Tables 3–5 as cwisim measures them: for each family of
//! `cwisim scenes generate cp-bench` (convex, few, many critical points) and each vertex
//! count `n` = 100, 200, …, 1000, a scene of 1000 polygons (seed 1, 512 × 512) drawn by
//! `sbuffer` (one sample per pixel) and by `vanrij --aa none` (the trapezoid path, the
//! baseline; on a screen scene it adds the polygons up rather than resolving depth). It
//! prints, per row, the critical points, CP's work (MOVEUP steps, AET inserts and
//! deletes), the plain edge table's work (edges inserted, each once), `vanrij`'s
//! trapezia, both renderers' array instructions and busy bus cycles, and the host time of
//! the Y-processor as ratios.
//!
//! ```sh
//! cargo run --release -p cwisim-render --example cp_tables [-- POLYGONS [STEP [REPEAT [FAMILY N,…]]]]
//! ```
//!
//! Counts are deterministic. Host times are the median of REPEAT runs (default 1), with
//! the spread (min–max) when REPEAT > 1, on whatever machine runs it; FAMILY and a list
//! of `n` restrict the table to those rows (`convex 100,1000`).

use cwisim_render::cpbench::{generate, BenchSpec, Family};
use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Rendered, Settings};
use cwisim_scene::{Antialias, ScreenScene};
use cwisim_world::AnyScene;
use cwisim_xproc::NullSink;

fn run(name: &str, scene: &ScreenScene, settings: &Settings) -> Rendered {
    let loaded = LoadedScene::built("cp-bench", AnyScene::Screen(scene.clone()));
    let renderer = (registry::find(name).expect("registered").build)(loaded, settings)
        .expect("the benchmark draws");
    render(
        &*renderer,
        &ArrayConfig::default(),
        1,
        &mut NullSink,
        Default::default(),
    )
    .expect("the benchmark draws")
}

/// Host times in ms: the median, and the spread (min–max) of several.
fn times(ms: &mut [f64]) -> String {
    ms.sort_by(f64::total_cmp);
    let median = ms[ms.len() / 2];
    match ms {
        [_] => format!("{median:.1}"),
        _ => format!("{median:.1} ({:.1}–{:.1})", ms[0], ms[ms.len() - 1]),
    }
}

/// Edges a plain edge table holds: every edge that is not horizontal.
fn plain_edges(scene: &ScreenScene) -> u64 {
    scene
        .polygons
        .iter()
        .map(|p| {
            let v = &p.vertices;
            (0..v.len())
                .filter(|&i| v[i][1] != v[(i + 1) % v.len()][1])
                .count() as u64
        })
        .sum()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let polygons: u32 = args.next().map_or(1000, |a| a.parse().expect("POLYGONS"));
    let step: u32 = args.next().map_or(100, |a| a.parse().expect("STEP"));
    let repeat: usize = args.next().map_or(1, |a| a.parse().expect("REPEAT"));
    let only: Option<Family> = args.next().map(|a| a.parse().expect("FAMILY"));
    let ns: Option<Vec<u32>> = args
        .next()
        .map(|a| a.split(',').map(|n| n.parse().expect("N,…")).collect());
    let sbuffer = Settings {
        samples: 1,
        ..Settings::default()
    };
    let vanrij = Settings {
        aa: Antialias::None,
        ..Settings::default()
    };
    println!(
        "| family | n | c per polygon | MOVEUP steps | AET inserts | INSERT scans | AET deletes | plain ET edges | vanrij trapezia | sbuffer instructions | sbuffer busy cycles | vanrij instructions | vanrij busy cycles | sbuffer host ms | vanrij host ms |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for family in Family::ALL {
        if only.is_some_and(|f| f != family) {
            continue;
        }
        let mut n = step;
        while n <= 10 * step {
            if ns.as_ref().is_some_and(|ns| !ns.contains(&n)) {
                n += step;
                continue;
            }
            let (scene, counts) = generate(&BenchSpec {
                family,
                polygons,
                vertices: n..=n,
                seed: 1,
                width: 512,
                height: 512,
            })
            .expect("a benchmark scene");
            let s = run("sbuffer", &scene, &sbuffer);
            let v = run("vanrij", &scene, &vanrij);
            let mut s_ms = vec![s.renderer_time.as_secs_f64() * 1e3];
            let mut v_ms = vec![v.renderer_time.as_secs_f64() * 1e3];
            for _ in 1..repeat {
                s_ms.push(run("sbuffer", &scene, &sbuffer).renderer_time.as_secs_f64() * 1e3);
                v_ms.push(run("vanrij", &scene, &vanrij).renderer_time.as_secs_f64() * 1e3);
            }
            let get = |r: &Rendered, k: &str| r.counters.get(k).unwrap_or(0);
            let busy = |r: &Rendered| r.stats.lines.iter().map(|l| l.busy_cycles).sum::<u64>();
            println!(
                "| {family} | {n} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                counts.critical_points as f64 / f64::from(polygons),
                get(&s, "moveup_steps"),
                get(&s, "aet_inserts"),
                get(&s, "aet_insert_scans"),
                get(&s, "aet_deletes"),
                plain_edges(&scene),
                get(&v, "trapezia"),
                s.stats.totals.instructions,
                busy(&s),
                v.stats.totals.instructions,
                busy(&v),
                times(&mut s_ms),
                times(&mut v_ms),
            );
            n += step;
        }
    }
}
