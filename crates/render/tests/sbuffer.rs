//! `sbuffer`, Barkan & Gordon's S-buffer: against a brute-force nearest-depth test, against
//! `vanrij`'s exact visibility, and its overdraw study mode against its host mode.

use cwisim_isa::{Instruction, Opcode};
use cwisim_render::cp::Increment;
use cwisim_render::settings::SbufferMode;
use cwisim_render::{
    emit, registry, render, ArrayConfig, Counters, LoadedScene, Renderer, Settings, Source,
};
use cwisim_scene::{Polygon, ScreenScene, Shading};
use cwisim_world::{AnyScene, Visibility};
use cwisim_xproc::numeric::Numeric;
use cwisim_xproc::ImageSink;
use rand_core::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;

fn one_sample(shading: Shading) -> Settings {
    Settings {
        samples: 1,
        shading,
        ..Settings::default()
    }
}

fn build(name: &str, loaded: LoadedScene, s: &Settings) -> Box<dyn Renderer> {
    (registry::find(name).unwrap().build)(loaded, s).unwrap()
}

/// The image and the counters of a renderer.
fn draw(r: &dyn Renderer, threads: usize) -> (Vec<f64>, Counters) {
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 28);
    let done = render(
        r,
        &ArrayConfig::default(),
        threads,
        &mut sink,
        Default::default(),
    )
    .unwrap();
    (sink.finish().unwrap().data, done.counters)
}

fn embedded(name: &str, s: &Settings, renderer: &str) -> (Vec<f64>, Counters) {
    let loaded = Source::resolve(Some(name.as_ref()))
        .unwrap()
        .load_for(s)
        .unwrap();
    draw(&*build(renderer, loaded, s), 1)
}

/// A random screen scene: `n` star-shaped polygons (concave), each with a planar depth,
/// flat grey values.
fn random_scene(rng: &mut XorShiftRng, n: usize) -> ScreenScene {
    let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let mut polygons = Vec::new();
    while polygons.len() < n {
        let k = 3 + (unit() * 9.0) as usize;
        let mut angles: Vec<f64> = (0..k).map(|_| unit()).collect();
        angles.sort_by(f64::total_cmp);
        let (cx, cy) = (4.0 + unit() * 24.0, 4.0 + unit() * 16.0);
        let v: Vec<[f64; 2]> = angles
            .iter()
            .map(|a| {
                let (t, r) = (a * std::f64::consts::TAU, 1.0 + unit() * 10.0);
                let snap = |c: f64| (c * 4.0).round() / 4.0;
                [snap(cx + r * t.cos()), snap(cy + r * t.sin())]
            })
            .collect();
        if cwisim_scene::predicates::simplicity_fault(&v).is_some() {
            continue;
        }
        let (a, b, c) = (unit() - 0.5, unit() - 0.5, 10.0 + 40.0 * unit());
        let depth = v.iter().map(|p| a * p[0] + b * p[1] + c).collect();
        let value = 0.1 + 0.9 * unit();
        polygons.push(Polygon::uniform(v, &[value]).with_depth(depth));
    }
    ScreenScene {
        width: 32,
        height: 24,
        channels: 1,
        polygons,
    }
}

/// Whether `(x, y)` lies in `v` by the half-open rule every renderer shares: the crossings
/// `≤ x` of the edges with `y_lo ≤ y < y_hi`, at `x_lo + (x_hi − x_lo)/(y_hi − y_lo)·(y − y_lo)`,
/// are odd in number.
fn inside(v: &[[f64; 2]], x: f64, y: f64) -> bool {
    let mut odd = false;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        let (lo, hi) = if a[1] < b[1] { (a, b) } else { (b, a) };
        if lo[1] <= y && y < hi[1] {
            let xc = lo[0] + (hi[0] - lo[0]) / (hi[1] - lo[1]) * (y - lo[1]);
            if xc <= x {
                odd = !odd;
            }
        }
    }
    odd
}

/// Per sample of an `l × l` centre grid, the brute-force nearest polygon's value (0
/// where none), averaged per pixel; `None` for a pixel where two depths tie.
fn brute_force(scene: &ScreenScene, l: u32) -> Vec<Option<f64>> {
    let mut out = Vec::new();
    for py in 0..scene.height {
        for px in 0..scene.width {
            let mut sum = Some(0.0);
            for j in 0..l {
                for i in 0..l {
                    // the sampler's positions: sample column k at (k + ½)/l
                    let x = (f64::from(px * l + i) + 0.5) / f64::from(l);
                    let y = (f64::from(py * l + j) + 0.5) / f64::from(l);
                    let mut hits: Vec<(f64, f64)> = scene
                        .polygons
                        .iter()
                        .filter(|p| inside(&p.vertices, x, y))
                        .map(|p| (p.depth_at([x, y]).unwrap(), p.intensity[0][0]))
                        .collect();
                    hits.sort_by(|a, b| a.0.total_cmp(&b.0));
                    if hits.len() > 1 && hits[1].0 - hits[0].0 < 1e-9 {
                        sum = None;
                    }
                    let v = hits.first().map_or(0.0, |h| h.1);
                    sum = sum.map(|s| s + v / f64::from(l * l));
                }
            }
            out.push(sum);
        }
    }
    out
}

#[test]
fn sbuffer_is_the_nearest_polygon_at_every_sample() {
    let mut rng = XorShiftRng::seed_from_u64(2121);
    for l in [1, 2, 3] {
        let (mut compared, mut ties) = (0, 0);
        for _ in 0..40 {
            let scene = random_scene(&mut rng, 8);
            let loaded = LoadedScene::built("random", AnyScene::Screen(scene.clone()));
            let settings = Settings {
                samples: l,
                ..one_sample(Shading::Flat)
            };
            let (image, _) = draw(&*build("sbuffer", loaded, &settings), 1);
            for (p, want) in brute_force(&scene, l).into_iter().enumerate() {
                let Some(want) = want else {
                    ties += 1;
                    continue;
                };
                // one sample: exact; more: the passes' weighted sums, up to rounding
                let tol = if l == 1 { 0.0 } else { 1e-9 };
                assert!(
                    (image[p] - want).abs() <= tol,
                    "l = {l}, pixel {p}: {} against {want}",
                    image[p]
                );
                compared += 1;
            }
        }
        assert!(
            compared > 25_000 && ties < 100,
            "{compared} compared, {ties} ties"
        );
    }
}

#[test]
fn without_depth_a_later_polygon_is_in_front() {
    let scene = ScreenScene {
        width: 8,
        height: 4,
        channels: 1,
        polygons: vec![
            Polygon::uniform(
                vec![[0.0, 0.0], [6.0, 0.0], [6.0, 4.0], [0.0, 4.0]],
                &[0.25],
            ),
            Polygon::uniform(vec![[2.0, 0.0], [8.0, 0.0], [8.0, 4.0], [2.0, 4.0]], &[0.5]),
        ],
    };
    let loaded = LoadedScene::built("two", AnyScene::Screen(scene));
    let (image, c) = draw(&*build("sbuffer", loaded, &one_sample(Shading::Flat)), 1);
    assert_eq!(&image[..8], &[0.25, 0.25, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]);
    assert_eq!(c.get("pixels_overwritten"), Some(4 * 4));
    assert_eq!(c.get("visible_runs"), Some(2 * 4));
}

/// With and without shadows (every light casting).
#[test]
fn sbuffer_equals_vanrij_exact_visibility_on_flat_world_scenes() {
    for (scene, shadows) in [
        ("still-life", Some(false)),
        ("pot", None),
        ("still-life", Some(true)),
        ("pot", Some(true)),
    ] {
        let s = Settings {
            shadows,
            ..one_sample(Shading::Flat)
        };
        let (sb, c) = embedded(scene, &s, "sbuffer");
        let vr = Settings {
            aa: cwisim_scene::Antialias::None,
            visibility: Visibility::Exact,
            ..s
        };
        let (vanrij, _) = embedded(scene, &vr, "vanrij");
        assert_eq!(sb, vanrij, "{scene}, shadows {shadows:?}");
        assert!(c.get("pixels_overwritten").unwrap() > 0);
        // and the study mode draws the same image, bit for bit
        let od = Settings {
            sbuffer: SbufferMode::Overdraw,
            ..s
        };
        let (overdraw, oc) = embedded(scene, &od, "sbuffer");
        assert_eq!(overdraw, sb, "{scene} overdraw, shadows {shadows:?}");
        assert!(oc.get("undo_runs").unwrap() > 0);
        assert!(oc.get("instructions") > c.get("instructions"));
    }
}

#[test]
fn overdraw_equals_host_with_gouraud_in_f64_at_any_thread_count() {
    let s = one_sample(Shading::Gouraud);
    let (host, _) = embedded("pot", &s, "sbuffer");
    let od = Settings {
        sbuffer: SbufferMode::Overdraw,
        ..s
    };
    let (overdraw, _) = embedded("pot", &od, "sbuffer");
    assert_eq!(host, overdraw);
    let loaded = Source::resolve(Some("pot".as_ref()))
        .unwrap()
        .load_for(&od)
        .unwrap();
    let (threaded, _) = draw(&*build("sbuffer", loaded, &od), 3);
    assert_eq!(threaded, overdraw);
}

/// Ten overlapping squares, each nearer than the last (`reverse`: each farther).
fn stack(reverse: bool) -> ScreenScene {
    let mut polygons: Vec<Polygon> = (0..10)
        .map(|k| {
            let o = k as f64;
            Polygon::uniform(
                vec![[o, o], [o + 12.0, o], [o + 12.0, o + 12.0], [o, o + 12.0]],
                &[0.05 * (k + 1) as f64],
            )
            .with_depth(vec![10.0 - o; 4])
        })
        .collect();
    if reverse {
        polygons.reverse();
    }
    ScreenScene {
        width: 24,
        height: 24,
        channels: 1,
        polygons,
    }
}

#[test]
fn overdraw_sends_fewer_instructions_front_to_back() {
    let od = Settings {
        sbuffer: SbufferMode::Overdraw,
        ..one_sample(Shading::Flat)
    };
    let run = |reverse| {
        let loaded = LoadedScene::built("stack", AnyScene::Screen(stack(reverse)));
        draw(&*build("sbuffer", loaded, &od), 1)
    };
    // stack(false) lists the squares back to front, stack(true) front to back
    let (back_to_front, b) = run(false);
    let (front_to_back, f) = run(true);
    assert_eq!(back_to_front, front_to_back);
    assert_eq!(f.get("pixels_overwritten"), Some(0));
    assert!(b.get("pixels_overwritten").unwrap() > 0);
    assert!(f.get("instructions").unwrap() < b.get("instructions").unwrap());
    assert!(f.get("pixels_set").unwrap() < b.get("pixels_set").unwrap());
}

#[test]
fn overdraw_refuses_what_it_cannot_undo_exactly() {
    let od = Settings {
        sbuffer: SbufferMode::Overdraw,
        ..one_sample(Shading::Flat)
    };
    let loaded = || LoadedScene::built("stack", AnyScene::Screen(stack(false)));
    let r = build("sbuffer", loaded(), &od);
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, 1, 1 << 20);
    let array = ArrayConfig {
        numeric: Numeric::F32,
        ..ArrayConfig::default()
    };
    let e = render(&*r, &array, 1, &mut sink, Default::default())
        .err()
        .unwrap();
    assert!(e.to_string().contains("only in f64"), "{e}");
    assert!(!e.is_internal());
    let e = (registry::find("sbuffer").unwrap().build)(loaded(), &Settings { samples: 2, ..od })
        .err()
        .unwrap();
    assert!(e.to_string().contains("--samples 1"), "{e}");
}

#[test]
fn overdraw_undoes_with_acc_mode_in_pairs() {
    let od = Settings {
        sbuffer: SbufferMode::Overdraw,
        ..one_sample(Shading::Gouraud)
    };
    let loaded = LoadedScene::built("stack", AnyScene::Screen(stack(false)));
    let r = build("sbuffer", loaded, &od);
    let mut stream: Vec<Instruction> = Vec::new();
    emit(&*r, &mut stream).unwrap();
    // Acc_mode toggles come in pairs within a row, and only negative draws lie between
    let mut on = false;
    for i in &stream {
        match i.op {
            Opcode::AccMode => on = !on,
            Opcode::Refresh => assert!(!on),
            Opcode::Eval1 | Opcode::Eval2 => {
                let v = i.value(0)[0];
                assert_eq!(on, v < 0.0, "{i:?}");
            }
            _ => {}
        }
    }
}

#[test]
fn supersampling_and_the_papers_increment_draw_too() {
    let s = Settings {
        samples: 3,
        ..Settings::default()
    };
    let (image, c) = embedded("fig25", &s, "sbuffer");
    assert!(image.iter().any(|&v| v > 0.0));
    assert!(c.get("visible_runs").unwrap() > 0);
    let p = Settings {
        cp_increment: Increment::Paper,
        ..one_sample(Shading::Gouraud)
    };
    let (_, c) = embedded("pot", &p, "sbuffer");
    assert!(c.get("cp_increments").unwrap() > 0);
}

#[test]
fn supersampled_it_equals_woo_chall_shading_every_sample() {
    // woo-chall's samples, winners and weights with a shading call at every sample
    // (P = 1): the same image, bit for bit, on flat world scenes
    for (scene, samples) in [("pot", 3), ("still-life", 2)] {
        let s = Settings {
            samples,
            ..one_sample(Shading::Flat)
        };
        let (sb, _) = embedded(scene, &s, "sbuffer");
        let (woo, _) = embedded(
            scene,
            &Settings {
                shade_p: Some(1.0),
                ..s
            },
            "woo-chall",
        );
        assert_eq!(sb, woo, "{scene} at {samples}×{samples}");
    }
}

#[test]
fn the_overdraw_stream_is_snapshot_tested() {
    // three squares listed back to front, each nearer than the last: the second and the
    // third undo part of what came before (Acc_mode, negated Eval1, Acc_mode) and draw
    let polygons = (0..3)
        .map(|k| {
            let o = f64::from(k);
            Polygon::uniform(
                vec![[o, o], [o + 4.0, o], [o + 4.0, o + 4.0], [o, o + 4.0]],
                &[0.25 * f64::from(k + 1)],
            )
            .with_depth(vec![3.0 - o; 4])
        })
        .collect();
    let scene = ScreenScene {
        width: 8,
        height: 7,
        channels: 1,
        polygons,
    };
    let od = Settings {
        sbuffer: SbufferMode::Overdraw,
        ..one_sample(Shading::Flat)
    };
    let r = build(
        "sbuffer",
        LoadedScene::built("three", AnyScene::Screen(scene)),
        &od,
    );
    let mut bytes = Vec::new();
    {
        let mut w = cwisim_isa::Encoding::Text
            .writer(&mut bytes, &r.header())
            .unwrap();
        let c = emit(&*r, &mut *w).unwrap();
        assert_eq!(c.get("pixels_overwritten"), Some(2 * 3 * 3));
    }
    insta::assert_snapshot!(
        "overdraw_three_squares_cwt",
        String::from_utf8(bytes).unwrap()
    );
}

/// A random RGB screen scene with Gouraud intensities, many of them 0 (spans falling to
/// 0 in some channels and not in others), and random depths. (A value the array drops,
/// a chain a rounding below 0, is rare here: `fill::tests::an_undo_skips_what_the_array_dropped`
/// holds the undo to it directly.)
fn random_rgb_scene(rng: &mut XorShiftRng) -> ScreenScene {
    let mut s = random_scene(rng, 10);
    s.channels = 3;
    for p in &mut s.polygons {
        let n = p.vertices.len();
        p.intensity = (0..n)
            .map(|_| {
                (0..3)
                    .map(|_| {
                        let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
                        if u < 0.4 {
                            0.0
                        } else {
                            u
                        }
                    })
                    .collect()
            })
            .collect();
    }
    s
}

#[test]
fn overdraw_equals_host_on_random_rgb_gouraud_scenes() {
    let mut rng = XorShiftRng::seed_from_u64(77);
    let host = one_sample(Shading::Gouraud);
    let od = Settings {
        sbuffer: SbufferMode::Overdraw,
        ..host
    };
    let mut undone = 0;
    for _ in 0..40 {
        let scene = random_rgb_scene(&mut rng);
        let built = || LoadedScene::built("rgb", AnyScene::Screen(scene.clone()));
        let (a, _) = draw(&*build("sbuffer", built(), &host), 1);
        let (b, c) = draw(&*build("sbuffer", built(), &od), 1);
        assert_eq!(a, b);
        undone += c.get("undo_runs").unwrap();
    }
    assert!(undone > 100, "{undone}");
}
