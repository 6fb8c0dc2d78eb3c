//! `nishita` held to the tests: Table 1's iteration counts and their trend,
//! conservative band clipping, no cracks between subpatches (interior coverage 1 within
//! 1e-9, from the pieces themselves), the silhouette against a fine tessellation drawn by
//! `vanrij`, and `--threads N` byte-identical.

mod common;

use cwisim_render::nishita::band::{subpatches, BandStats, Facings, Params, View};
use cwisim_render::nishita::classify::Facing;
use cwisim_render::nishita::{pieces, Pieces};
use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Settings, Taps};
use cwisim_scene::Shading;
use cwisim_world::camera::Camera;
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, AnyScene, WorldScene};
use cwisim_xproc::ImageSink;
use std::collections::HashMap;

fn teapot(size: u32) -> WorldScene {
    let scene = parse_any(embedded("teapot").unwrap().text, None)
        .unwrap()
        .with_size(size, size)
        .unwrap();
    match scene {
        AnyScene::World(w) => w,
        AnyScene::Screen(_) => unreachable!("the teapot is a world scene"),
    }
}

fn nishita(tolerance: f64) -> Settings {
    Settings {
        root_tolerance: tolerance,
        ..Settings::default()
    }
}

#[test]
fn average_iterations_follow_table_1() {
    let w = teapot(500);
    let mut averages = Vec::new();
    let mut roots = Vec::new();
    for tol in [1e-3, 1e-5, 1e-7] {
        let p = pieces(&w, &nishita(tol)).unwrap();
        let c = &p.stats.clip;
        averages.push(c.average().unwrap());
        roots.push(c.roots);
        // the histogram holds every root, and iterations add up
        assert_eq!(c.histogram.iter().sum::<u64>(), c.roots);
        assert!(c.iterations >= c.wasted);
    }
    eprintln!("average iterations at 1e-3, 1e-5, 1e-7: {averages:?}; roots {roots:?}");
    assert!((1.0..=2.5).contains(&averages[0]), "1e-3: {}", averages[0]);
    assert!(
        averages[0] < averages[1] && averages[1] < averages[2],
        "{averages:?}"
    );
    assert!(averages[2] - averages[0] <= 1.3, "{averages:?}");
    // the crossings do not depend on the tolerance: the same roots, narrower
    assert!(roots.iter().all(|&r| r == roots[0]), "{roots:?}");
}

#[test]
fn band_clipping_is_conservative() {
    // every (u, v) of a dense grid whose projection lies in a band lies in one of that
    // band's subpatches
    let w = teapot(200);
    let settings = Settings::default();
    let camera = Camera::new(&w.spec.camera, w.width(), w.height());
    let view = View { camera };
    let params = Params {
        tolerance: settings.root_tolerance,
        flatness: settings.flatness,
        subscan: 1,
        normal_cos: None,
    };
    let patches = cwisim_world::mesh::placed_patches(&w.spec.meshes[0])
        .unwrap()
        .unwrap();
    let band = 4;
    let mut checked = 0;
    let mut top = 0;
    while top < w.height() {
        let rows = band.min(w.height() - top);
        let mut stats = BandStats::default();
        let (cells, level, _) = subpatches(
            &view,
            &patches,
            &Facings::default(),
            top,
            rows,
            &params,
            &mut stats,
        );
        let scale = f64::from(1u32 << level);
        for (k, p) in patches.iter().enumerate() {
            for a in 0..=60 {
                for b in 0..=60 {
                    let (u, v) = (a as f64 / 60.0, b as f64 / 60.0);
                    let y = camera.project(p.point(u, v))[1];
                    if !(y >= f64::from(top) && y <= f64::from(top + rows)) {
                        continue;
                    }
                    checked += 1;
                    let inside = cells.iter().any(|c| {
                        c.patch == k as u32
                            && u * scale >= f64::from(c.index.0)
                            && u * scale <= f64::from(c.index.0 + 1)
                            && v * scale >= f64::from(c.index.1)
                            && v * scale <= f64::from(c.index.1 + 1)
                    });
                    assert!(inside, "patch {k} ({u}, {v}) at row {y} not in band {top}");
                }
            }
        }
        top += rows;
    }
    assert!(checked > 50_000, "{checked}");
}

/// The area of triangle `t` inside pixel `(x, y)`.
fn pixel_area(t: &[[f64; 2]; 3], x: f64, y: f64) -> f64 {
    let mut poly: Vec<[f64; 2]> = t.to_vec();
    // clip by x ≥ x0, x ≤ x0 + 1, y ≥ y0, y ≤ y0 + 1
    for (axis, bound, keep_above) in [
        (0, x, true),
        (0, x + 1.0, false),
        (1, y, true),
        (1, y + 1.0, false),
    ] {
        let inside = |p: &[f64; 2]| {
            if keep_above {
                p[axis] >= bound
            } else {
                p[axis] <= bound
            }
        };
        let mut out = Vec::new();
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let s = (bound - a[axis]) / (b[axis] - a[axis]);
                let mut p = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
                p[axis] = bound;
                out.push(p);
            }
        }
        poly = out;
        if poly.is_empty() {
            return 0.0;
        }
    }
    let n = poly.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        .abs()
}

/// The patch boundaries (patch, side: 0 v=0, 1 u=1, 2 v=1, 3 u=0) no other patch shares.
fn open_boundaries(w: &WorldScene) -> Vec<(u32, u32)> {
    let patches = cwisim_world::mesh::placed_patches(&w.spec.meshes[0])
        .unwrap()
        .unwrap();
    let key = |c: [glam::DVec3; 4]| {
        let f: Vec<u64> = c
            .iter()
            .flat_map(|p| p.to_array().map(|x| (x + 0.0).to_bits()))
            .collect();
        let r: Vec<u64> = c
            .iter()
            .rev()
            .flat_map(|p| p.to_array().map(|x| (x + 0.0).to_bits()))
            .collect();
        f.min(r)
    };
    let sides = |p: &cwisim_world::bezier::Patch| {
        let q = p.points;
        let col = |c: usize| [q[0][c], q[1][c], q[2][c], q[3][c]];
        [q[0], col(3), q[3], col(0)]
    };
    let mut count: HashMap<Vec<u64>, u32> = HashMap::new();
    for p in &patches {
        for s in sides(p) {
            *count.entry(key(s)).or_default() += 1;
        }
    }
    let mut open = Vec::new();
    for (k, p) in patches.iter().enumerate() {
        for (side, s) in sides(p).into_iter().enumerate() {
            let degenerate = s.iter().all(|q| *q == s[0]);
            if count[&key(s)] == 1 && !degenerate {
                open.push((k as u32, side as u32));
            }
        }
    }
    open
}

#[test]
fn interior_pixels_are_covered_exactly_once_by_front_pieces() {
    let w = teapot(500);
    let p: Pieces = pieces(&w, &Settings::default()).unwrap();
    let open = open_boundaries(&w);
    assert!(!open.is_empty() && open.len() <= 16, "{open:?}");
    let on_open = |patch: u32, uv: &[(f64, f64); 3]| {
        uv.iter().any(|&(u, v)| {
            open.iter().any(|&(q, side)| {
                q == patch
                    && match side {
                        0 => v == 0.0,
                        1 => u == 1.0,
                        2 => v == 1.0,
                        _ => u == 0.0,
                    }
            })
        })
    };
    let (wd, ht) = (w.width() as i64, w.height() as i64);
    let mut cover = vec![0.0f64; (wd * ht) as usize];
    let mut masked = vec![false; (wd * ht) as usize];
    for ((t, f), (_, patch, uv)) in p.triangles.iter().zip(&p.facing).zip(&p.origin) {
        let xs = t.points.map(|q| q[0]);
        let ys = t.points.map(|q| q[1]);
        let (x0, x1) = (
            xs.iter().cloned().fold(f64::INFINITY, f64::min),
            xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        );
        let (y0, y1) = (
            ys.iter().cloned().fold(f64::INFINITY, f64::min),
            ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        );
        // back pieces lie under front ones (the inside of the pot): not counted; the
        // front sheet's outline runs through twisted subpatches (silhouettes) and along
        // open patch boundaries
        if *f == Facing::Back {
            continue;
        }
        let outline = *f == Facing::Twisted || on_open(*patch, uv);
        for y in (y0.floor() as i64).max(0)..=(y1.floor() as i64).min(ht - 1) {
            for x in (x0.floor() as i64).max(0)..=(x1.floor() as i64).min(wd - 1) {
                let i = (y * wd + x) as usize;
                if outline {
                    // and the pixels around: a piece's edge may graze a neighbour
                    for dy in -1..=1 {
                        for dx in -1..=1 {
                            let (xx, yy) = (x + dx, y + dy);
                            if (0..wd).contains(&xx) && (0..ht).contains(&yy) {
                                masked[(yy * wd + xx) as usize] = true;
                            }
                        }
                    }
                } else {
                    cover[i] += pixel_area(&t.points, x as f64, y as f64);
                }
            }
        }
    }
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for i in 0..cover.len() {
        if masked[i] || cover[i] == 0.0 {
            continue;
        }
        checked += 1;
        let err = (cover[i] - cover[i].round()).abs();
        worst = worst.max(err);
        assert!(
            err <= 1e-9 && cover[i].round() >= 1.0,
            "pixel ({}, {}): front coverage {}",
            i as i64 % wd,
            i as i64 / wd,
            cover[i]
        );
    }
    eprintln!("{checked} interior pixels, worst |coverage − integer| {worst:e}");
    assert!(checked > 40_000, "{checked}");
}

/// The teapot lit by a constant (ambient 1, `k_a` 1, no lights): the image is coverage.
fn white_teapot(size: u32) -> LoadedScene {
    let mut w = teapot(size);
    w.spec.lights.clear();
    w.spec.ambient = serde_json::from_value(serde_json::json!(1.0)).unwrap();
    w.spec.meshes[0].material =
        serde_json::from_value(serde_json::json!({"k_a": 1.0, "k_d": 0.0, "k_s": 0.0, "n": 1}))
            .unwrap();
    LoadedScene::built("white-teapot", AnyScene::World(w))
}

fn image_of(name: &str, loaded: LoadedScene, settings: &Settings, threads: usize) -> Vec<f64> {
    common::drawn_on(name, loaded, settings, threads).0
}

#[test]
fn the_silhouette_matches_a_fine_tessellation() {
    let size = 160;
    let n = image_of("nishita", white_teapot(size), &Settings::default(), 1);
    // the tessellation is the source's (`Source::load_for` applies `--tessellate`; a
    // scene built in code is tessellated here)
    let fine = match white_teapot(size).scene {
        AnyScene::World(w) => w.with_tessellation(32).unwrap(),
        AnyScene::Screen(_) => unreachable!(),
    };
    let v = image_of(
        "vanrij",
        LoadedScene::built("white-teapot-32", AnyScene::World(fine)),
        &Settings::default(),
        1,
    );
    let (mut worst, mut total) = (0.0f64, 0.0f64);
    for (a, b) in n.iter().zip(&v) {
        worst = worst.max((a - b).abs());
        total += (a - b).abs();
    }
    let area: f64 = n.iter().sum();
    eprintln!("coverage: worst pixel {worst:.4}, total |Δ| {total:.3} px² of {area:.1} px²");
    // per pixel: the chord error of either side along a pixel of outline (flatness
    // 0.5 px bounds nishita's pieces; the 32 × 32 tessellation's chords are of the same
    // order here); in all, a thin band along the outline
    assert!(worst <= 0.1, "{worst}");
    assert!(total <= 1e-3 * area, "{total} of {area}");
}

#[test]
fn threads_are_byte_identical() {
    for shading in [Shading::Gouraud, Shading::Phong] {
        let settings = Settings {
            shading,
            ..Settings::default()
        };
        let one = image_of("nishita", white_teapot(96), &settings, 1);
        // three threads for the pipeline's bands and for exact visibility
        let on_three = Settings {
            threads: 3,
            ..settings
        };
        let three = image_of("nishita", white_teapot(96), &on_three, 3);
        assert_eq!(
            one.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            three.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }
}

#[test]
fn bad_settings_and_flat_shading_are_refused() {
    let build =
        |s: Settings| (registry::find("nishita").unwrap().build)(white_teapot(64), &s).map(|_| ());
    let e = build(Settings {
        shading: Shading::Flat,
        ..Settings::default()
    })
    .unwrap_err();
    assert!(e.to_string().contains("--shading gouraud or phong"), "{e}");
    let e = build(Settings {
        root_tolerance: 0.0,
        ..Settings::default()
    })
    .unwrap_err();
    assert!(e.to_string().contains("--root-tolerance"), "{e}");
}

fn run(name: &str, loaded: LoadedScene, settings: &Settings) -> (Vec<f64>, u64, u64) {
    let r = (registry::find(name).unwrap().build)(loaded, settings).unwrap();
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let out = render(&*r, &ArrayConfig::default(), 1, &mut sink, Taps::default()).unwrap();
    let instructions = out.counters.get("instructions").unwrap_or(0);
    (
        sink.finish().unwrap().data,
        instructions,
        out.stats.totals.late_lines,
    )
}

#[test]
fn a_patchs_row_is_one_span_within_its_tolerance_and_no_scanline_is_late() {
    let size = 160;
    let lit = || LoadedScene::built("teapot", AnyScene::World(teapot(size)));
    let settings = Settings::default();
    let (fitted, instructions, late) = run("nishita", lit(), &settings);
    // tolerance 0: every pixel's exact box-filtered value, one Eval1 each
    let exact = Settings {
        shade_tolerance: 0.0,
        ..settings
    };
    let (values, pixels, _) = run("nishita", lit(), &exact);
    // the same teapot tessellated 8 × 8 and drawn by vanrij, as a tessellated teapot is
    let coarse = teapot(size).with_tessellation(8).unwrap();
    let (_, vanrij, vanrij_late) = run(
        "vanrij",
        LoadedScene::built("teapot-8", AnyScene::World(coarse)),
        &settings,
    );
    eprintln!(
        "instructions: nishita {instructions} (tolerance 0: {pixels}), vanrij at 8 × 8 {vanrij}; late {late}, vanrij {vanrij_late}"
    );
    assert!(instructions < vanrij, "{instructions} ≥ {vanrij}");
    assert_eq!((late, vanrij_late), (0, 0));
    // a pixel is reached by the spans of a few patches, each within the tolerance
    let bound = 4.0 * settings.shade_tolerance / 8.0;
    let worst = fitted
        .iter()
        .zip(&values)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst <= bound, "{worst} > {bound}");
}

/// `nishita` does not read `--visibility` (its registry entry does not list it): a
/// library user's `Visibility::Eval0` draws exactly what `Exact` draws — the same stream,
/// the same image — with either shading, rather than a whole-frame pass of Eval0 claims
/// over pieces at most a row high.
#[test]
fn visibility_is_not_read() {
    use cwisim_world::Visibility;
    assert!(!registry::find("nishita")
        .unwrap()
        .uses
        .contains(&cwisim_render::settings::Setting::Visibility));
    let lit = || LoadedScene::built("teapot", AnyScene::World(teapot(32)));
    for shading in [Shading::Gouraud, Shading::Phong] {
        let drawn = |visibility| {
            let settings = Settings {
                shading,
                visibility,
                ..Settings::default()
            };
            let r = (registry::find("nishita").unwrap().build)(lit(), &settings).unwrap();
            let mut stream: Vec<cwisim_isa::Instruction> = Vec::new();
            cwisim_render::emit(&*r, &mut stream).unwrap();
            (stream, image_of("nishita", lit(), &settings, 1))
        };
        let (exact_stream, exact_image) = drawn(Visibility::Exact);
        let (eval0_stream, eval0_image) = drawn(Visibility::Eval0);
        assert!(!exact_stream.is_empty());
        assert!(
            eval0_stream == exact_stream,
            "{shading:?}: {} instructions with eval0, {} with exact",
            eval0_stream.len(),
            exact_stream.len()
        );
        assert_eq!(
            eval0_image.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            exact_image.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            "{shading:?}"
        );
    }
}

/// The frame's fragments, joined band by band, are held packed without spare room (each
/// band's store made to its size as it is joined, on one thread or several), and are the
/// same at any thread count, Gouraud and Phong.
#[test]
fn resolved_fragments_are_held_without_spare_room() {
    use cwisim_render::nishita::resolve::resolve;
    use cwisim_render::nishita::PatchScene;
    let w = teapot(64);
    for keep in [false, true] {
        let mut polygons = Vec::new();
        for threads in [1, 3] {
            let settings = Settings {
                threads,
                ..Settings::default()
            };
            let scene = PatchScene::new(&w, &settings).unwrap();
            let r = resolve(&scene, &settings, keep).unwrap();
            let n = r.fragments.len();
            assert!(n > 100, "{n} fragments");
            assert_eq!(r.fragments.groups.len(), n);
            assert_eq!(r.fragments.rows.len(), n);
            let room = [
                ("fragments", r.fragments.spare_bytes()),
                ("sources", r.sources.capacity() - r.sources.len()),
                ("triangles", r.triangles.capacity() - r.triangles.len()),
            ];
            assert!(
                room.iter().all(|(_, n)| *n == 0),
                "threads {threads}, keep {keep}: spare room {room:?}"
            );
            assert_eq!(r.sources.len(), if keep { n } else { 0 });
            polygons.push((r.fragments, r.sources));
        }
        assert!(
            polygons[0] == polygons[1],
            "keep {keep}: threads 1 and 3 differ"
        );
    }
}

#[test]
fn the_normal_difference_test_off_or_never_passed_draws_today_s_image_and_on_divides_more() {
    let size = 48;
    let draw = |normal_angle: Option<f64>| {
        let settings = Settings {
            shading: Shading::Phong,
            normal_angle,
            ..Settings::default()
        };
        let loaded = LoadedScene::built("teapot", AnyScene::World(teapot(size)));
        let r = (registry::find("nishita").unwrap().build)(loaded, &settings).unwrap();
        let h = r.header();
        let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
        let out = render(&*r, &ArrayConfig::default(), 1, &mut sink, Taps::default()).unwrap();
        let subpatches: u64 = ["subpatches_front", "subpatches_back", "subpatches_twisted"]
            .iter()
            .map(|c| out.counters.get(c).unwrap())
            .sum();
        (sink.finish().unwrap().data, subpatches, ())
    };
    let (off, off_subpatches, _) = draw(None);
    // an angle no two normals can pass: the image of the test left off, bit for bit
    let (never, never_subpatches, _) = draw(Some(180.0));
    assert!(off
        .iter()
        .zip(&never)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    assert_eq!(off_subpatches, never_subpatches);
    let (_, on_subpatches, _) = draw(Some(60.0));
    assert!(
        on_subpatches > off_subpatches,
        "{on_subpatches} subpatches at 60°, {off_subpatches} off"
    );
}

/// A cell of control points `points` (a whole patch).
fn cell(points: [[glam::DVec3; 4]; 4]) -> cwisim_render::nishita::band::Cell {
    cwisim_render::nishita::band::Cell {
        patch: 0,
        level: 0,
        index: (0, 0),
        points,
    }
}

#[test]
fn a_cell_s_corner_normals_are_apart_as_far_as_the_surface_turns() {
    use glam::DVec3;
    // a quarter cylinder: the arc (1, 0) → (0, 1) along each row, rows along z; its
    // corner normals turn through 90°
    let k = 0.552_284_75;
    let arc = [[1.0, 0.0], [1.0, k], [k, 1.0], [0.0, 1.0]];
    let quarter = std::array::from_fn(|r| {
        std::array::from_fn(|c| DVec3::new(arc[c][0], arc[c][1], r as f64 / 3.0))
    });
    let q = cell(quarter);
    assert!(q.normals_apart(80f64.to_radians().cos()));
    assert!(!q.normals_apart(100f64.to_radians().cos()));
    // flat: no two normals apart, even at 1°
    let flat = cell(std::array::from_fn(|r| {
        std::array::from_fn(|c| DVec3::new(c as f64, r as f64, 0.0))
    }));
    assert!(!flat.normals_apart(1f64.to_radians().cos()));
    // a corner where both edges collapse has no normal; the others still count
    let mut cone = quarter;
    cone[0] = [DVec3::ZERO; 4];
    let c = cell(cone);
    assert!(c.normals_apart(80f64.to_radians().cos()));
    assert!(!c.normals_apart(-1.0));
}
