//! `woo-chall` held to what it must equal: van Rij's point sampling at one sample per
//! pixel, the exact box filter as the grid grows (`cwisim_ypipe::exact`, which shares no
//! code with it), barycentric coordinates and edge functions written out here, and its
//! own invariants (shading-call counts, determinism, passes against merged rows, no
//! sample dropped on a shared edge).

mod common;

use cwisim_isa::Instruction;
use cwisim_render::subsample::{Grid, Sampler};
use cwisim_render::woochall::lists::span;
use cwisim_render::woochall::triangle::Tri;
use cwisim_render::{emit, registry, render, ArrayConfig, LoadedScene, Settings, Source, Taps};
use cwisim_scene::{Antialias, Polygon, ScreenScene, Shading};
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, AnyScene};
use cwisim_xproc::ImageSink;
use proptest::prelude::*;

fn image_of(name: &str, loaded: LoadedScene, settings: &Settings, threads: usize) -> Vec<f64> {
    common::drawn_on(name, loaded, settings, threads).0
}

fn embedded_scene(name: &str, size: u32) -> LoadedScene {
    let e = embedded(name).unwrap();
    let scene = parse_any(e.text, None)
        .unwrap()
        .with_size(size, size)
        .unwrap();
    LoadedScene::built(name, scene)
}

fn woo(samples: u32) -> Settings {
    Settings {
        samples,
        ..Settings::default()
    }
}

fn stream(loaded: LoadedScene, settings: &Settings) -> Vec<Instruction> {
    let r = (registry::find("woo-chall").unwrap().build)(loaded, settings).unwrap();
    let mut out: Vec<Instruction> = Vec::new();
    emit(&*r, &mut out).unwrap();
    out
}

/// With and without shadows (every light casting: the same lit parts, tested per sample
/// here and cut into polygons there).
#[test]
fn one_sample_per_pixel_is_van_rijs_point_sampling() {
    // (`bowl`'s and `still-life`'s main light cast shadows of their own)
    for (name, shadows, casting) in [
        ("pot", None, false),
        ("still-life", None, true),
        ("still-life", Some(false), false),
        ("teapot", None, false),
        ("pot", Some(true), true),
        ("still-life", Some(true), true),
        ("teapot", Some(true), true),
        ("bowl", None, true),
        ("bowl", Some(false), false),
    ] {
        for shading in [Shading::Flat, Shading::Gouraud] {
            let vanrij = image_of(
                "vanrij",
                embedded_scene(name, 96),
                &Settings {
                    shading,
                    aa: Antialias::None,
                    shadows,
                    ..Settings::default()
                },
                1,
            );
            let woo = image_of(
                "woo-chall",
                embedded_scene(name, 96),
                &Settings {
                    shading,
                    shadows,
                    ..woo(1)
                },
                1,
            );
            assert_eq!(vanrij.len(), woo.len());
            let worst = vanrij
                .iter()
                .zip(&woo)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            match shading {
                // flat without shadows: the same bits (with shadows, a piece's constant
                // value may reach the array through a polygon's plane: within rounding)
                Shading::Flat if !casting => assert!(
                    vanrij
                        .iter()
                        .zip(&woo)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "{name} flat, shadows {shadows:?}: images differ (worst {worst:e})"
                ),
                _ => assert!(
                    worst <= 1e-12,
                    "{name} Gouraud, shadows {shadows:?}: worst {worst:e}"
                ),
            }
        }
    }
}

/// One triangle of intensity 1 on a 16×16 screen.
fn one_triangle(points: [[f64; 2]; 3]) -> ScreenScene {
    ScreenScene {
        width: 16,
        height: 16,
        channels: 1,
        polygons: vec![Polygon::new(points.to_vec(), vec![vec![1.0]; 3])],
    }
}

fn coverage_error(scene: &ScreenScene, l: u32) -> (f64, f64) {
    let exact = cwisim_ypipe::exact::coverage(&scene.polygons[0], scene.width, scene.height);
    let got = image_of(
        "woo-chall",
        LoadedScene::built("triangle", AnyScene::Screen(scene.clone())),
        &Settings {
            shading: Shading::Flat,
            merge_subscanlines: true,
            ..woo(l)
        },
        1,
    );
    let (mut worst, mut sq) = (0.0f64, 0.0);
    for (a, b) in exact.iter().zip(&got) {
        worst = worst.max((a - b).abs());
        sq += (a - b).powi(2);
    }
    (worst, sq)
}

/// Random triangles with vertices in the 16×16 screen, from a fixed generator.
fn random_triangles(n: usize) -> Vec<[[f64; 2]; 3]> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| std::array::from_fn(|_| [1.0 + 14.0 * next(), 1.0 + 14.0 * next()]))
        .collect()
}

#[test]
fn coverage_converges_to_the_box_filter() {
    let triangles = random_triangles(24);
    let ls = [2u32, 4, 8, 16, 32];
    let mut rms = Vec::new();
    for &l in &ls {
        let mut sq = 0.0;
        let mut pixels = 0usize;
        for t in &triangles {
            let scene = one_triangle(*t);
            let (worst, s) = coverage_error(&scene, l);
            // a pixel is wrong by at most the samples an edge can misplace: l per edge
            // crossing it, each 1/l², and a pixel meets at most 3 edges; in practice an
            // edge pixel is within 0.5/l + a corner's share
            assert!(worst <= 1.5 / f64::from(l), "l = {l}: worst {worst}");
            sq += s;
            pixels += 256;
        }
        rms.push((sq / pixels as f64).sqrt());
    }
    // log-log slope of the RMS error against l
    let xs: Vec<f64> = ls.iter().map(|&l| f64::from(l).ln()).collect();
    let ys: Vec<f64> = rms.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / 5.0, ys.iter().sum::<f64>() / 5.0);
    let slope = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / xs.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
    assert!((-1.8..=-1.2).contains(&slope), "RMS {rms:?}: slope {slope}");
}

#[test]
fn a_half_plane_is_within_half_a_sample_row_per_pixel() {
    // a half-plane: a triangle far larger than the screen, one edge across it
    for (a, b) in [
        ([-1.0, 3.3], [17.0, 11.7]),
        ([4.2, -1.0], [9.9, 17.0]),
        ([-1.0, 8.0], [17.0, 8.0]),
    ] {
        let far = [a[0] + 1000.0 * (b[1] - a[1]), a[1] - 1000.0 * (b[0] - a[0])];
        for l in [2u32, 5, 8, 16] {
            let (worst, _) = coverage_error(&one_triangle([a, b, far]), l);
            assert!(worst <= 0.5 / f64::from(l) + 1e-12, "l = {l}: {worst}");
        }
    }
}

fn barycentric(p: [[f64; 2]; 3], x: f64, y: f64) -> [f64; 3] {
    let d = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    let wb = ((x - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (y - p[0][1])) / d;
    let wc = ((p[1][0] - p[0][0]) * (y - p[0][1]) - (x - p[0][0]) * (p[1][1] - p[0][1])) / d;
    [1.0 - wb - wc, wb, wc]
}

fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        (-50.0f64..50.0),
        // on the sample lattice of l = 4 (centre grid): edges through samples
        (-200i32..200).prop_map(|k| (f64::from(k) + 0.5) / 4.0),
    ]
}

fn triangle() -> impl Strategy<Value = [[f64; 2]; 3]> {
    prop_oneof![
        [
            [coordinate(), coordinate()],
            [coordinate(), coordinate()],
            [coordinate(), coordinate()]
        ],
        // slivers: the third vertex a hair off the line of the first two
        (
            [coordinate(), coordinate()],
            [coordinate(), coordinate()],
            0.0f64..1.0,
            -1e-6f64..1e-6
        )
            .prop_map(|(a, b, s, h)| {
                let c = [
                    a[0] + s * (b[0] - a[0]) - h * (b[1] - a[1]),
                    a[1] + s * (b[1] - a[1]) + h * (b[0] - a[0]),
                ];
                [a, b, c]
            }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, ..ProptestConfig::default() })]

    /// `s`, `t` and depth are the barycentric weights; the span's samples are those the
    /// edge functions put inside.
    #[test]
    fn the_parameterisation_is_barycentric(p in triangle(), q in [coordinate(), coordinate()]) {
        let Some(t) = Tri::new(p, [1.0, 2.5, -0.5], [[0.0; 4]; 3], 0, 0) else {
            return Ok(());
        };
        let w = barycentric(t.points, q[0], q[1]);
        let (s, u) = t.s_t(q[0], q[1]);
        let scale = 1.0 + w.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        prop_assert!((s - w[1]).abs() <= 1e-9 * scale, "s {} vs {}", s, w[1]);
        prop_assert!((u - w[2]).abs() <= 1e-9 * scale, "t {} vs {}", u, w[2]);
        let near = w[0] * t.near[0] + w[1] * t.near[1] + w[2] * t.near[2];
        prop_assert!((t.near_at(q[0], q[1]) - near).abs() <= 1e-9 * scale * 3.0);

        // span ends: every sample of a sub-scanline is in the span iff all three
        // edge values are positive (or zero on a top-left edge)
        let sampler = Sampler::new(4, Grid::Centre, 64, 64).unwrap();
        let y = q[1].rem_euclid(64.0);
        let y = sampler.subline_y(sampler.index_at_or_after(y).min(255.0) as usize);
        let got = span(&t, y, &sampler);
        let inside: Vec<usize> = (0..sampler.columns())
            .filter(|&k| {
                let x = sampler.column_x(k);
                t.edge_values(x, y).iter().all(|&e| e >= 0.0) && t.covers(x, y)
            })
            .collect();
        match got {
            None => prop_assert!(inside.is_empty(), "missed {:?}", inside),
            Some((lo, hi)) => {
                prop_assert_eq!(inside.first().copied(), Some(lo as usize));
                prop_assert_eq!(inside.last().copied(), Some(hi as usize));
                prop_assert_eq!(inside.len(), (hi - lo + 1) as usize);
            }
        }
    }
}

/// A square tiled by triangles whose vertices and edges pass through sample points, at
/// one depth: every sample is covered once, so every pixel is exactly 1.
#[test]
fn shared_edges_drop_no_sample() {
    let mut polygons = Vec::new();
    let n = 6;
    for i in 0..n {
        for j in 0..n {
            let (x0, y0) = (2.0 * f64::from(i) + 2.0, 2.0 * f64::from(j) + 2.0);
            let (x1, y1) = (x0 + 2.0, y0 + 2.0);
            // alternate diagonals; vertices on the l = 2 centre lattice's lines
            let (a, b, c, d) = ([x0, y0], [x1, y0], [x1, y1], [x0, y1]);
            let quads = if (i + j) % 2 == 0 {
                [[a, b, c], [a, c, d]]
            } else {
                [[a, b, d], [b, c, d]]
            };
            for t in quads {
                polygons
                    .push(Polygon::new(t.to_vec(), vec![vec![1.0]; 3]).with_depth(vec![1.0; 3]));
            }
        }
    }
    let scene = ScreenScene {
        width: 16,
        height: 16,
        channels: 1,
        polygons,
    };
    for (l, grid) in [
        (1, Grid::Centre),
        (2, Grid::Centre),
        (4, Grid::Centre),
        (3, Grid::Corner),
        (5, Grid::Corner),
    ] {
        let img = image_of(
            "woo-chall",
            LoadedScene::built("tiles", AnyScene::Screen(scene.clone())),
            &Settings {
                shading: Shading::Flat,
                grid,
                ..woo(l)
            },
            1,
        );
        for y in 3..13 {
            for x in 3..13 {
                let v = img[y * 16 + x];
                assert!(
                    (v - 1.0).abs() < 1e-12,
                    "l = {l} {grid}: pixel ({x}, {y}) = {v}"
                );
            }
        }
    }
}

#[test]
fn shading_calls_follow_the_rule() {
    let scene = || embedded_scene("still-life", 64);
    let counters = |settings: &Settings| {
        let r = (registry::find("woo-chall").unwrap().build)(scene(), settings).unwrap();
        let h = r.header();
        let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
        render(&*r, &ArrayConfig::default(), 1, &mut sink, Taps::default())
            .unwrap()
            .counters
    };
    for grid in [Grid::Centre, Grid::Corner] {
        // P = 0, never forced: one call per change of surface in a pixel's samples
        let c = counters(&Settings {
            shade_p: Some(0.0),
            shade_contrast: f64::INFINITY,
            grid,
            ..woo(3)
        });
        assert_eq!(c.get("shading"), c.get("shading_new_surface"));
        assert_eq!(c.get("shading_stochastic"), Some(0));
        assert_eq!(c.get("forced_pixels"), Some(0));
        let c1 = counters(&Settings {
            shade_p: Some(1.0),
            shade_contrast: f64::INFINITY,
            grid,
            ..woo(3)
        });
        assert_eq!(c1.get("shading"), c1.get("geometry"));
        assert_eq!(c1.get("geometry"), c.get("geometry"));
        assert!(c.get("shading") < c1.get("shading"));
    }
}

/// The shading calls of P = 0 counted independently: per pixel and row, the samples in
/// scan order (sub-scanlines top to bottom, columns left to right, each shared sample
/// once, in the pixel that reaches it first), a call whenever the surface changes.
#[test]
fn keep_obj_calls_are_surface_changes() {
    let loaded = embedded_scene("still-life", 48);
    let settings = Settings {
        shade_p: Some(0.0),
        shade_contrast: f64::INFINITY,
        shading: Shading::Flat,
        ..woo(3)
    };
    let r = (registry::find("woo-chall").unwrap().build)(loaded.clone(), &settings).unwrap();
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let calls = render(&*r, &ArrayConfig::default(), 1, &mut sink, Taps::default())
        .unwrap()
        .counters
        .get("shading")
        .unwrap();
    // the same winners through the lists, counted here
    let tris = cwisim_render::woochall::prepare::Triangles::new(
        loaded,
        &Settings {
            shading: Shading::Flat,
            ..Settings::default()
        },
    )
    .unwrap();
    let sampler = Sampler::new(3, Grid::Centre, tris.width, tris.height).unwrap();
    let mut lists = cwisim_render::woochall::lists::Lists::new(&tris.tris, sampler);
    let mut stats = Default::default();
    let mut winners = Vec::new();
    let mut layers = Default::default();
    let mut expected = 0u64;
    for row in 0..tris.height {
        let mut last: Vec<Option<u32>> = vec![None; tris.width as usize];
        for j in 0..3 {
            lists.subline(row * 3 + j, &mut winners, &mut layers, &mut stats);
            for (k, &w) in winners.iter().enumerate() {
                if w == u32::MAX {
                    continue;
                }
                let surface = tris.tris[w as usize].surface;
                let x = k / 3;
                if last[x] != Some(surface) {
                    expected += 1;
                    last[x] = Some(surface);
                }
            }
        }
    }
    assert_eq!(calls, expected);
}

#[test]
fn the_same_seed_gives_the_same_stream_at_any_thread_count() {
    let settings = Settings { seed: 7, ..woo(3) };
    let one = stream(embedded_scene("pot", 64), &settings);
    assert_eq!(one, stream(embedded_scene("pot", 64), &settings));
    let bits = |threads| {
        image_of("woo-chall", embedded_scene("pot", 64), &settings, threads)
            .iter()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(1), bits(3));
    let other = stream(
        embedded_scene("pot", 64),
        &Settings {
            seed: 8,
            ..settings
        },
    );
    assert_ne!(one, other, "the seed drives the stochastic calls");
}

#[test]
fn passes_and_merged_rows_agree() {
    for grid in [Grid::Centre, Grid::Corner] {
        for shading in [Shading::Flat, Shading::Gouraud, Shading::Phong] {
            let settings = Settings {
                grid,
                shading,
                shade_tolerance: 0.0,
                ..woo(4)
            };
            let passes = image_of("woo-chall", embedded_scene("pot", 48), &settings, 1);
            let merged = image_of(
                "woo-chall",
                embedded_scene("pot", 48),
                &Settings {
                    merge_subscanlines: true,
                    ..settings
                },
                1,
            );
            let worst = passes
                .iter()
                .zip(&merged)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst <= 1e-12, "{grid} {shading}: {worst:e}");
        }
    }
}

#[test]
fn bad_settings_are_refused_with_their_flag() {
    let build = |settings: Settings| {
        let loaded = Source::resolve(Some("pot".as_ref()))
            .unwrap()
            .load(None)
            .unwrap();
        (registry::find("woo-chall").unwrap().build)(loaded, &settings)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    assert!(build(woo(0)).contains("--samples"));
    assert!(build(woo(65)).contains("--samples"));
    assert!(build(Settings {
        grid: Grid::Corner,
        ..woo(1)
    })
    .contains("corner"));
    assert!(build(Settings {
        shade_p: Some(1.5),
        ..woo(2)
    })
    .contains("--shade-p"));
    assert!(build(Settings {
        shade_contrast: f64::NAN,
        ..woo(2)
    })
    .contains("--shade-contrast"));
}

/// Three squares facing the camera, lit by ambient light alone (intensity = `k_a`):
/// two half-transparent ones in front of an opaque one.
fn layered_scene(front_t: f64, middle_t: f64) -> LoadedScene {
    let quad = |z: f64, k_a: f64, t: f64| {
        format!(
            r#"{{ "material": {{ "k_a": {k_a}, "k_d": 0, "k_s": 0, "n": 1, "transmittance": {t} }},
                "vertices": [[-1, -1, {z}], [1, -1, {z}], [1, 1, {z}], [-1, 1, {z}]],
                "faces": [[0, 1, 2, 3]] }}"#
        )
    };
    let text = format!(
        r#"{{ "kind": "world", "width": 32, "height": 32, "channels": 1,
            "camera": {{ "eye": [0, 0, 5], "target": [0, 0, 0], "fov_y": 40 }},
            "ambient": 1, "lights": [],
            "meshes": [{}, {}, {}] }}"#,
        quad(0.5, 0.8, front_t),
        quad(0.0, 0.4, middle_t),
        quad(-0.5, 0.2, 0.0)
    );
    LoadedScene::built("layers", parse_any(&text, None).unwrap())
}

#[test]
fn transparent_layers_composite_nearest_first() {
    for (samples, merge) in [(1, false), (3, false), (3, true)] {
        let settings = Settings {
            shading: Shading::Flat,
            merge_subscanlines: merge,
            ..woo(samples)
        };
        let img = image_of("woo-chall", layered_scene(0.5, 0.5), &settings, 1);
        // by hand: (1 − ½)·0.8 + ½(1 − ½)·0.4 + ½·½·0.2
        let want = 0.5 * 0.8 + 0.25 * 0.4 + 0.25 * 0.2;
        let centre = img[16 * 32 + 16];
        assert!(
            (centre - want).abs() < 1e-12,
            "l = {samples}: {centre} vs {want}"
        );
        // past the squares behind (the front one is nearer, so larger on the screen:
        // pixel 6's centre is on it alone), the front over the background, opaque at
        // z = ∞ and black, lets ½ through
        if samples == 1 {
            let alone = img[16 * 32 + 6];
            assert!((alone - 0.5 * 0.8).abs() < 1e-12, "{alone}");
        }
        // opaque: the front square alone
        let opaque = image_of("woo-chall", layered_scene(0.0, 0.5), &settings, 1);
        assert!((opaque[16 * 32 + 16] - 0.8).abs() < 1e-12);
    }
    // every layer behind a transparent front is a shading call
    let r = (registry::find("woo-chall").unwrap().build)(layered_scene(0.5, 0.5), &woo(1)).unwrap();
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let c = render(&*r, &ArrayConfig::default(), 1, &mut sink, Taps::default())
        .unwrap()
        .counters;
    // at l = 1 every sample's front is shaded once, and each layer behind it once more
    let (geometry, layers) = (c.get("geometry").unwrap(), c.get("shading_layers").unwrap());
    assert!(layers > 0);
    assert_eq!(c.get("shading"), Some(geometry + layers));
}

#[test]
fn a_transmittance_outside_zero_to_one_is_refused_where_it_is() {
    let text = r#"{ "kind": "world", "width": 8, "height": 8, "channels": 1,
        "camera": { "eye": [0, 0, 5], "target": [0, 0, 0], "fov_y": 40 },
        "ambient": 1, "lights": [],
        "meshes": [{ "material": { "k_a": 1, "k_d": 0, "k_s": 0, "n": 1, "transmittance": 1.5 },
                     "vertices": [[-1, -1, 0], [1, -1, 0], [1, 1, 0]], "faces": [[0, 1, 2]] }] }"#;
    let e = parse_any(text, None).unwrap_err().to_string();
    assert!(
        e.contains("meshes[0].material.transmittance") && e.contains("[0, 1]"),
        "{e}"
    );
}

#[test]
fn the_row_figures_add_up_to_the_frame() {
    let r =
        (registry::find("woo-chall").unwrap().build)(embedded_scene("pot", 48), &woo(3)).unwrap();
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let done = render(&*r, &ArrayConfig::default(), 2, &mut sink, Taps::default()).unwrap();
    let rows = done.row_figures[0].as_array().unwrap();
    assert_eq!(rows.len(), 48);
    let sum = |k: &str| rows.iter().map(|r| r[k].as_u64().unwrap()).sum::<u64>();
    let max = |k: &str| rows.iter().map(|r| r[k].as_u64().unwrap()).max().unwrap();
    for k in [
        "geometry",
        "shading",
        "instructions",
        "forced_pixels",
        "passes",
    ] {
        assert_eq!(Some(sum(k)), done.counters.get(k), "{k}");
    }
    assert_eq!(Some(max("max_active")), done.counters.get("max_active"));
    assert_eq!(sum("instructions"), done.stats.totals.instructions);
}

/// A trace sink that refuses its `n`-th instruction.
struct RefuseAt {
    n: usize,
    seen: usize,
}

impl cwisim_isa::TraceWrite for RefuseAt {
    fn write(&mut self, _: &Instruction) -> std::io::Result<()> {
        self.seen += 1;
        if self.seen > self.n {
            return Err(std::io::Error::other("refused"));
        }
        Ok(())
    }

    fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn bands_asked_out_of_turn_or_again_give_the_frame_s_stream() {
    // the rows are made as they are emitted, the state running from row to row: a band
    // asked ahead of its turn waits for the bands before it, one asked again (it failed)
    // is made again from the top of the frame
    let r =
        (registry::find("woo-chall").unwrap().build)(embedded_scene("pot", 64), &woo(3)).unwrap();
    let emitted = |plan: &dyn cwisim_render::FramePlan, rows| {
        let mut out: Vec<Instruction> = Vec::new();
        plan.emit_rows(rows, &mut out).unwrap();
        out
    };
    let plan = r.frame(0, None).unwrap();
    let whole = emitted(&*plan, 0..64);
    let (counters, figures) = (plan.counters(), plan.row_figures());
    assert_eq!(figures.as_ref().unwrap().as_array().unwrap().len(), 64);
    // four bands on four threads, started last first
    let plan = r.frame(0, None).unwrap();
    let bands = std::thread::scope(|s| {
        let threads: Vec<_> = (0..4u32)
            .rev()
            .map(|k| {
                let plan = &*plan;
                s.spawn(move || (k, emitted(plan, k * 16..k * 16 + 16)))
            })
            .collect();
        let mut bands: Vec<_> = threads.into_iter().map(|t| t.join().unwrap()).collect();
        bands.sort_by_key(|&(k, _)| k);
        bands.into_iter().flat_map(|(_, b)| b).collect::<Vec<_>>()
    });
    assert!(
        bands == whole,
        "bands on threads differ from the frame's stream"
    );
    assert_eq!(
        (plan.counters(), plan.row_figures()),
        (counters.clone(), figures.clone())
    );
    // a band whose sink refuses it part way, asked again
    let plan = r.frame(0, None).unwrap();
    let mut again = emitted(&*plan, 0..16);
    let mut refusing = RefuseAt { n: 10, seen: 0 };
    assert!(plan.emit_rows(16..32, &mut refusing).is_err());
    again.extend(emitted(&*plan, 16..32));
    again.extend(emitted(&*plan, 32..64));
    assert!(
        again == whole,
        "a band made again differs from the frame's stream"
    );
    assert_eq!((plan.counters(), plan.row_figures()), (counters, figures));
}
