//! `refine` (Bergman et al., adaptive refinement) held to what its phases must equal:
//! van Rij's Phong box filter when every threshold is `all`, the flat frame when every
//! threshold is `none`, a brute-force 3 × 3 range over the array's own previous output
//! for the anti-aliasing flags, an error against the full-quality image that does not
//! grow from the first phase to the last, and counts equal to a recount written here.

use cwisim_isa::{Instruction, Opcode};
use cwisim_render::refine::{Phase, Refine};
use cwisim_render::settings::Threshold;
use cwisim_render::{
    emit, registry, render, ArrayConfig, LoadedScene, Renderer, Settings, Source, Taps,
};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::embedded::embedded;
use cwisim_world::face::ScreenTriangle;
use cwisim_world::parse_any;
use cwisim_xproc::ImageSink;
use glam::DVec3;

fn scene(name: &str, size: u32) -> LoadedScene {
    let e = embedded(name).unwrap();
    let scene = parse_any(e.text, None)
        .unwrap()
        .with_size(size, size)
        .unwrap();
    LoadedScene::built(name, scene)
}

fn thresholds(gouraud: Threshold, phong: Threshold, aa: Threshold) -> Settings {
    Settings {
        gouraud_threshold: gouraud,
        phong_angle: phong,
        aa_threshold: aa,
        ..Settings::default()
    }
}

/// Every frame's image (f64 values) and instructions, in order.
struct Run {
    frames: Vec<Vec<f64>>,
    streams: Vec<Vec<Instruction>>,
    counters: cwisim_render::Counters,
}

fn run(r: &dyn Renderer, threads: usize) -> Run {
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let mut stream: Vec<Instruction> = Vec::new();
    let done = render(
        r,
        &ArrayConfig::default(),
        threads,
        &mut sink,
        Taps {
            also: Some(&mut stream),
            progress: None,
            cancel: None,
        },
    )
    .unwrap();
    let data = sink.finish().unwrap().data;
    let per = h.width as usize * h.lines as usize * h.channel_count();
    assert_eq!(data.len(), per * r.frames() as usize);
    let frames = data.chunks(per).map(<[f64]>::to_vec).collect();
    let mut streams = vec![Vec::new()];
    let mut refreshes = 0;
    for i in stream {
        let refresh = i.op == Opcode::Refresh;
        streams.last_mut().unwrap().push(i);
        if refresh {
            refreshes += 1;
            if refreshes % h.lines == 0 {
                streams.push(Vec::new());
            }
        }
    }
    streams.pop();
    assert_eq!(streams.len(), r.frames() as usize);
    Run {
        frames,
        streams,
        counters: done.counters,
    }
}

fn build(name: &str, loaded: LoadedScene, settings: &Settings) -> Box<dyn Renderer> {
    (registry::find(name).unwrap().build)(loaded, settings).unwrap()
}

/// The full-quality image and stream: `render --renderer vanrij --shading phong --aa box`.
fn full(name: &str, size: u32) -> (Vec<f64>, Vec<Instruction>) {
    let phong = Settings {
        shading: Shading::Phong,
        ..Settings::default()
    };
    let r = build("vanrij", scene(name, size), &phong);
    let mut stream = Vec::new();
    emit(&*r, &mut stream).unwrap();
    let run = run(&*r, 1);
    (run.frames[0].clone(), stream)
}

/// `vanrij`'s point-sampled image of the embedded scene `name` at `size` in `shading`.
fn point_sampled(name: &str, size: u32, shading: Shading) -> Vec<f64> {
    let point = Settings {
        aa: Antialias::None,
        shading,
        ..Settings::default()
    };
    let r = build("vanrij", scene(name, size), &point);
    run(&*r, 1).frames.remove(0)
}

fn rms(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64).sqrt()
}

#[test]
fn a_world_scene_is_refined_in_four_complete_frames() {
    let r = Refine::new(scene("pot", 64), &Settings::default()).unwrap();
    assert_eq!(
        r.phases(),
        [Phase::Flat, Phase::Gouraud, Phase::Phong, Phase::Antialias]
    );
    assert!(r.needs_previous_frame());
    // its stream exists only while it runs through the array
    let e = emit(&r, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("previous frame"), "{e}");
}

#[test]
fn every_threshold_at_all_gives_van_rijs_phong_box_filter_bit_for_bit() {
    let all = thresholds(Threshold::All, Threshold::All, Threshold::All);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for name in ["pot", "still-life"] {
        let (image, stream) = full(name, 96);
        let r = build("refine", scene(name, 96), &all);
        let run = run(&*r, 1);
        let last = run.frames.last().unwrap();
        assert_eq!(bits(last), bits(&image), "{name}: last frame");
        assert_eq!(run.streams.last().unwrap(), &stream, "{name}: last stream");
        // the Gouraud phase Gouraud-shades every polygon: van Rij point-sampled
        let point = |shading| point_sampled(name, 96, shading);
        // (with a light casting shadows, the shadow phase would come second)
        let gouraud = run.frames.len() - 3;
        assert_eq!(bits(&run.frames[gouraud]), bits(&point(Shading::Gouraud)));
        // and the Phong phase lights every polygon per pixel: van Rij's Phong, sampled
        assert_eq!(bits(&run.frames[gouraud + 1]), bits(&point(Shading::Phong)));
        // nothing was masked: every pixel box-filtered
        assert_eq!(run.counters.get("aa_masks"), Some(0));
        let h = r.header();
        assert_eq!(
            run.counters.get("aa_pixels"),
            Some(u64::from(h.width) * u64::from(h.lines))
        );
    }
}

#[test]
fn a_textured_scene_s_phases_are_van_rijs_textured_images_bit_for_bit() {
    // every threshold at `none` but the texture: the Gouraud phase regenerates exactly the
    // textured polygons, lit per pixel with their texture as vanrij draws them
    // the first value that differs, not the whole image
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let same = |a: &[f64], b: &[f64], what: &str| {
        assert_eq!(a.len(), b.len(), "{what}");
        if let Some(k) = (0..a.len()).find(|&k| a[k].to_bits() != b[k].to_bits()) {
            panic!("{what}: value {k} is {} against {}", a[k], b[k]);
        }
    };
    let all = thresholds(Threshold::All, Threshold::All, Threshold::All);
    for name in ["teapot-textured", "textures4"] {
        let (image, _) = full(name, 64);
        let r = build("refine", scene(name, 64), &all);
        let run = run(&*r, 1);
        same(
            run.frames.last().unwrap(),
            &image,
            &format!("{name}: last frame"),
        );
        let point = |shading| point_sampled(name, 64, shading);
        let gouraud = run.frames.len() - 3;
        same(
            &run.frames[gouraud],
            &point(Shading::Gouraud),
            &format!("{name}: Gouraud phase"),
        );
        same(
            &run.frames[gouraud + 1],
            &point(Shading::Phong),
            &format!("{name}: Phong phase"),
        );
        // with the Gouraud threshold at none, the textured polygons alone are regenerated
        let none = thresholds(Threshold::None, Threshold::None, Threshold::None);
        let r = build("refine", scene(name, 64), &none);
        let textured_run = self::run(&*r, 1);
        let regenerated = textured_run.counters.get("gouraud_polygons").unwrap();
        assert!(regenerated > 0, "{name}");
        assert_ne!(
            bits(&textured_run.frames[0]),
            bits(&textured_run.frames[1]),
            "{name}: the texture shows from the Gouraud phase on"
        );
    }
}

/// With every light casting shadows: the shadow phase follows the flat one and darkens
/// exactly the shadow polygons, and every later phase draws what `vanrij` draws with
/// the same shadows, bit for bit.
#[test]
fn the_shadow_phase_darkens_the_flat_frame_and_later_phases_keep_the_shadows() {
    let shadows = Settings {
        shadows: Some(true),
        ..thresholds(Threshold::All, Threshold::All, Threshold::All)
    };
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let r = Refine::new(scene("still-life", 96), &shadows).unwrap();
    assert_eq!(
        r.phases(),
        [
            Phase::Flat,
            Phase::Shadows,
            Phase::Gouraud,
            Phase::Phong,
            Phase::Antialias
        ]
    );
    let run = run(&r, 1);
    let (flat, shadowed) = (&run.frames[0], &run.frames[1]);
    assert!(shadowed.iter().zip(flat).all(|(s, f)| s <= f));
    let darker = shadowed.iter().zip(flat).filter(|(s, f)| s < f).count();
    assert!(darker > 300, "{darker} samples darker");
    assert!(run.counters.get("shadows_polygons").unwrap() > 0);
    let vanrij = |shading, aa| {
        let r = build(
            "vanrij",
            scene("still-life", 96),
            &Settings {
                aa,
                shading,
                shadows: Some(true),
                ..Settings::default()
            },
        );
        self::run(&*r, 1).frames.remove(0)
    };
    assert_eq!(
        bits(&run.frames[2]),
        bits(&vanrij(Shading::Gouraud, Antialias::None))
    );
    assert_eq!(
        bits(&run.frames[3]),
        bits(&vanrij(Shading::Phong, Antialias::None))
    );
    assert_eq!(
        bits(&run.frames[4]),
        bits(&vanrij(Shading::Phong, Antialias::Box))
    );
    // without a light casting, no shadow phase can be asked for
    let e = Refine::with_phases(
        scene("pot", 32),
        &Settings::default(),
        &[Phase::Flat, Phase::Shadows],
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("no light of the scene casts shadows"),
        "{e}"
    );
}

#[test]
fn every_threshold_at_none_repeats_the_flat_frame_and_regenerates_nothing() {
    let none = thresholds(Threshold::None, Threshold::None, Threshold::None);
    let r = build("refine", scene("pot", 96), &none);
    let run = run(&*r, 1);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for k in 1..4 {
        assert_eq!(bits(&run.frames[k]), bits(&run.frames[0]), "frame {k}");
    }
    assert_eq!(
        run.streams[1], run.streams[0],
        "the Gouraud frame re-sends phase 1"
    );
    assert_eq!(
        run.streams[2], run.streams[0],
        "the Phong frame re-sends phase 1"
    );
    // the AA frame: nothing flagged, so the previous frame re-sent as it was, unmasked
    assert_eq!(
        run.streams[3], run.streams[0],
        "the anti-aliasing frame re-sends phase 1"
    );
    for counter in [
        "gouraud_polygons",
        "gouraud_regenerated",
        "phong_polygons",
        "phong_regenerated",
        "aa_pixels",
        "aa_regenerated",
        "aa_fragments",
    ] {
        assert_eq!(run.counters.get(counter), Some(0), "{counter}");
    }
    // and the flat frame differs from the full-quality one (the test can fail)
    let (image, _) = full("pot", 96);
    assert!(rms(&run.frames[0], &image) > 0.0);
}

/// The 3 × 3 range written out: max − min over the neighbours that exist, largest over
/// channels.
fn brute_flags(img: &[f64], w: usize, h: usize, ch: usize, t: f64) -> Vec<bool> {
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let mut worst = 0.0f64;
            for c in 0..ch {
                let mut vals = Vec::new();
                for dy in -1..=1i64 {
                    for dx in -1..=1i64 {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx >= 0 && ny >= 0 && nx < w as i64 && ny < h as i64 {
                            vals.push(img[(ny as usize * w + nx as usize) * ch + c]);
                        }
                    }
                }
                let hi = vals.iter().cloned().fold(f64::MIN, f64::max);
                let lo = vals.iter().cloned().fold(f64::MAX, f64::min);
                worst = worst.max(hi - lo);
            }
            out.push(worst > t);
        }
    }
    out
}

#[test]
fn aa_flags_are_the_3x3_range_of_the_previous_output_and_the_rest_is_kept() {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for (name, t) in [("pot", 0.05), ("still-life", 0.1), ("pot", 0.0)] {
        let some = |aa| thresholds(Threshold::Above(0.02), Threshold::Above(30.0), aa);
        let r = build("refine", scene(name, 80), &some(Threshold::Above(t)));
        let h = r.header();
        let (w, lines, ch) = (h.width as usize, h.lines as usize, h.channel_count());
        let run = run(&*r, 1);
        // the frame before the anti-aliasing one (the last)
        let flags = brute_flags(&run.frames[run.frames.len() - 2], w, lines, ch, t);
        let flagged = flags.iter().filter(|&&f| f).count();
        assert!(
            flagged > 0 && flagged < w * lines,
            "{name}: {flagged} flagged"
        );
        assert_eq!(
            run.counters.get("aa_pixels"),
            Some(flagged as u64),
            "{name}"
        );
        // a flagged pixel holds the display list's box filter (every pixel filtered)
        let filtered = build("refine", scene(name, 80), &some(Threshold::All));
        let filtered = self::run(&*filtered, 1).frames.pop().unwrap();
        let (last, before) = (run.frames.len() - 1, run.frames.len() - 2);
        for (p, &f) in flags.iter().enumerate() {
            let got = &run.frames[last][p * ch..(p + 1) * ch];
            let want = if f {
                &filtered[p * ch..(p + 1) * ch]
            } else {
                &run.frames[before][p * ch..(p + 1) * ch]
            };
            assert_eq!(bits(got), bits(want), "{name}: pixel {p} (flagged: {f})");
        }
        // the fragments: flagged pixels and the polygons covering them, recounted by
        // clipping each polygon to each flagged pixel
        let refine = Refine::new(scene(name, 80), &some(Threshold::Above(t))).unwrap();
        let polygons = &refine.polygons().screen.polygons;
        let mut fragments = 0u64;
        for (p, _) in flags.iter().enumerate().filter(|(_, &f)| f) {
            let (x, y) = ((p % w) as f64, (p / w) as f64);
            fragments += polygons
                .iter()
                .filter(|poly| covered(&poly.vertices, x, y) > 1e-9)
                .count() as u64;
        }
        assert!(fragments >= flagged as u64 / 2, "{name}: {fragments}");
        assert_eq!(run.counters.get("aa_fragments"), Some(fragments), "{name}");
    }
}

/// The area of polygon `v` inside pixel `[x, x + 1] × [y, y + 1]`: Sutherland–Hodgman
/// against the pixel's four sides, then the shoelace formula.
fn covered(v: &[[f64; 2]], x: f64, y: f64) -> f64 {
    let (lo, hi) = v
        .iter()
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        });
    if hi[0] <= x || lo[0] >= x + 1.0 || hi[1] <= y || lo[1] >= y + 1.0 {
        return 0.0;
    }
    let mut poly: Vec<[f64; 2]> = v.to_vec();
    // (axis, bound, keep the side below the bound)
    for (axis, bound, below) in [
        (0, x, false),
        (0, x + 1.0, true),
        (1, y, false),
        (1, y + 1.0, true),
    ] {
        let inside = |p: &[f64; 2]| {
            if below {
                p[axis] <= bound
            } else {
                p[axis] >= bound
            }
        };
        let mut out = Vec::new();
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let s = (bound - a[axis]) / (b[axis] - a[axis]);
                out.push([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]);
            }
        }
        poly = out;
        if poly.is_empty() {
            return 0.0;
        }
    }
    let n = poly.len();
    (0..n)
        .map(|k| poly[k][0] * poly[(k + 1) % n][1] - poly[(k + 1) % n][0] * poly[k][1])
        .sum::<f64>()
        .abs()
        / 2.0
}

#[test]
fn the_error_against_full_quality_does_not_grow_from_flat_to_the_last_phase() {
    for e in cwisim_world::embedded::EMBEDDED {
        let r = build("refine", scene(e.name, 64), &Settings::default());
        let run = run(&*r, 1);
        let (image, _) = full_or_gouraud(e.name, 64);
        let errors: Vec<f64> = run.frames.iter().map(|f| rms(f, &image)).collect();
        println!("{}: RMS per phase {errors:?}", e.name);
        let last = *errors.last().unwrap();
        if run.frames.len() == 1 {
            // a screen scene: one frame, van Rij's own
            assert_eq!(last, 0.0, "{}", e.name);
            continue;
        }
        assert!(
            errors[0] > 0.0,
            "{}: the flat phase is not full quality",
            e.name
        );
        assert!(
            last <= errors[0],
            "{}: RMS grew from {} to {last}",
            e.name,
            errors[0]
        );
    }
}

/// The full-quality image of a world scene (Phong), or van Rij's Gouraud box filter of a
/// screen scene (nothing to light).
fn full_or_gouraud(name: &str, size: u32) -> (Vec<f64>, Vec<Instruction>) {
    let loaded = scene(name, size);
    if matches!(loaded.scene, cwisim_world::AnyScene::World(_)) {
        return full(name, size);
    }
    let r = build("vanrij", loaded, &Settings::default());
    (run(&*r, 1).frames.remove(0), Vec::new())
}

#[test]
fn gouraud_polygons_equal_a_recount() {
    let settings = thresholds(
        Threshold::Above(0.02),
        Threshold::Above(30.0),
        Threshold::Above(0.05),
    );
    let r = Refine::new(scene("still-life", 64), &settings).unwrap();
    let recount = r
        .polygons()
        .screen
        .polygons
        .iter()
        .filter(|p| {
            let ch = p.intensity[0].len();
            (0..ch).any(|c| {
                let v: Vec<f64> = p.intensity.iter().map(|i| i[c]).collect();
                let hi = v.iter().cloned().fold(f64::MIN, f64::max);
                let lo = v.iter().cloned().fold(f64::MAX, f64::min);
                hi - lo > 0.02
            })
        })
        .count() as u64;
    assert!(recount > 0);
    assert_eq!(r.gouraud_polygons(), recount);
    let run = run(&r, 1);
    assert_eq!(run.counters.get("gouraud_polygons"), Some(recount));
}

/// The highlight test written out from the scene file: at each corner, for each light
/// in front of it, the angle between the light's mirror direction and the eye, by
/// `atan2(|R × V|, R · V)`; a material without a specular term has no highlight.
fn highlight_within(w: &cwisim_world::WorldScene, t: &ScreenTriangle, degrees: f64) -> bool {
    let spec = &w.spec;
    let m = &spec.meshes[t.mesh as usize].material;
    if (0..w.channels()).all(|c| m.k_s.get(c) == 0.0) {
        return false;
    }
    let eye = DVec3::from_array(spec.camera.eye);
    (0..3).any(|k| {
        let p = t.surface.world[k];
        let n = t.surface.normals[k] / t.surface.normals[k].length();
        let v = (eye - p) / (eye - p).length();
        spec.lights.iter().any(|light| {
            let l = DVec3::from_array(light.position) - p;
            let l = l / l.length();
            let d = n.dot(l);
            let r = n * (2.0 * d) - l;
            d > 0.0 && r.cross(v).length().atan2(r.dot(v)).to_degrees() <= degrees
        })
    })
}

#[test]
fn phong_polygons_equal_a_recount() {
    for (name, degrees) in [("pot", 30.0), ("still-life", 20.0), ("teapot", 45.0)] {
        let settings = thresholds(
            Threshold::Above(0.02),
            Threshold::Above(degrees),
            Threshold::Above(0.05),
        );
        let loaded = scene(name, 64);
        let cwisim_world::AnyScene::World(w) = &loaded.scene else {
            panic!("{name} is a world scene");
        };
        let w = w.clone();
        let r = Refine::new(loaded, &settings).unwrap();
        let s = r.polygons().phong.as_ref().unwrap();
        let fragments = s
            .sources
            .iter()
            .filter(|&&k| highlight_within(&w, &s.triangles[k], degrees))
            .count() as u64;
        let visible: std::collections::BTreeSet<usize> = s.sources.iter().copied().collect();
        let triangles = visible
            .iter()
            .filter(|&&k| highlight_within(&w, &s.triangles[k], degrees))
            .count() as u64;
        println!(
            "{name}: {fragments} fragments, {triangles} of {} visible triangles",
            visible.len()
        );
        assert!(fragments > 0 && triangles < visible.len() as u64, "{name}");
        assert_eq!(r.phong_polygons(), fragments, "{name}");
        assert_eq!(
            r.highlight_pass(),
            (triangles, visible.len() as u64),
            "{name}"
        );
        let run = run(&r, 1);
        assert_eq!(
            run.counters.get("phong_polygons"),
            Some(fragments),
            "{name}"
        );
    }
}

#[test]
fn output_is_the_same_on_any_number_of_threads() {
    let r = build("refine", scene("pot", 72), &Settings::default());
    let one = run(&*r, 1);
    let three = run(&*r, 3);
    assert_eq!(one.frames, three.frames);
    assert_eq!(one.streams, three.streams);
    assert_eq!(one.counters, three.counters);
}

#[test]
fn a_screen_scene_is_one_frame_of_van_rijs_box_filter() {
    let source = Source::resolve(Some("fig25".as_ref())).unwrap();
    let r = build("refine", source.load(None).unwrap(), &Settings::default());
    assert_eq!(r.frames(), 1);
    assert!(!r.needs_previous_frame());
    let v = build("vanrij", source.load(None).unwrap(), &Settings::default());
    let (mut a, mut b) = (Vec::new(), Vec::new());
    emit(&*r, &mut a).unwrap();
    emit(&*v, &mut b).unwrap();
    assert_eq!(a, b);
}

#[test]
fn settings_it_chooses_itself_are_refused_with_a_reason() {
    for (settings, flag) in [
        (
            Settings {
                shading: Shading::Phong,
                ..Settings::default()
            },
            "--shading",
        ),
        (
            Settings {
                aa: Antialias::None,
                ..Settings::default()
            },
            "--aa",
        ),
        (
            Settings {
                visibility: cwisim_world::Visibility::Eval0,
                ..Settings::default()
            },
            "--visibility",
        ),
    ] {
        let e = Refine::new(scene("pot", 32), &settings)
            .unwrap_err()
            .to_string();
        assert!(e.contains(flag), "{e}");
    }
}

#[test]
fn vertices_and_edges_are_depth_cued_points_and_lines_then_the_flat_frame() {
    let phases = [Phase::Vertices, Phase::Edges, Phase::Flat];
    let r = Refine::with_phases(scene("pot", 64), &Settings::default(), &phases).unwrap();
    assert!(!r.needs_previous_frame());
    let run = run(&r, 1);
    let h = r.header();
    let (w, lines) = (h.width as usize, h.lines as usize);
    let tris = &r.polygons().phong.as_ref().unwrap().triangles;
    // the distinct corners and edges, and the pixels of the corners inside the image
    let key = |p: [f64; 2]| (p[0].to_bits(), p[1].to_bits());
    let mut corners = std::collections::BTreeSet::new();
    let mut edges = std::collections::BTreeSet::new();
    let mut corner_pixels = std::collections::BTreeSet::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t.points[k], t.points[(k + 1) % 3]);
            corners.insert(key(a));
            edges.insert(std::cmp::min((key(a), key(b)), (key(b), key(a))));
            let (x, y) = (a[0].floor(), a[1].floor());
            if x >= 0.0 && y >= 0.0 && (x as usize) < w && (y as usize) < lines {
                corner_pixels.insert((x as usize, y as usize));
            }
        }
    }
    assert_eq!(
        run.counters.get("vertices_drawn"),
        Some(corners.len() as u64)
    );
    assert_eq!(run.counters.get("edges_drawn"), Some(edges.len() as u64));
    let lit = |frame: &[f64]| -> std::collections::BTreeSet<(usize, usize)> {
        (0..w * lines)
            .filter(|&p| frame[p] != 0.0)
            .map(|p| (p % w, p / w))
            .collect()
    };
    // the vertex frame lights exactly the corners' pixels, depth-cued in [1/4, 1]
    let points = lit(&run.frames[0]);
    assert_eq!(points, corner_pixels);
    assert_eq!(
        run.counters.get("vertices_pixels"),
        Some(points.len() as u64)
    );
    let values: Vec<f64> = run.frames[0]
        .iter()
        .copied()
        .filter(|&v| v != 0.0)
        .collect();
    assert!(values.iter().all(|&v| (0.25..=1.0).contains(&v)));
    assert_eq!(
        values.iter().cloned().fold(0.0, f64::max),
        1.0,
        "the nearest corner"
    );
    // the edge frame: every corner lit, and every lit pixel on an edge (its centre within
    // half a pixel's diagonal of the segment)
    let lines_lit = lit(&run.frames[1]);
    assert!(corner_pixels.is_subset(&lines_lit));
    assert!(
        lines_lit.len() > 3 * points.len(),
        "{} pixels",
        lines_lit.len()
    );
    let near_an_edge = |(x, y): (usize, usize)| {
        let c = [x as f64 + 0.5, y as f64 + 0.5];
        tris.iter().any(|t| {
            (0..3).any(|k| {
                let (a, b) = (t.points[k], t.points[(k + 1) % 3]);
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let len2 = dx * dx + dy * dy;
                let u = if len2 > 0.0 {
                    (((c[0] - a[0]) * dx + (c[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (px, py) = (a[0] + u * dx - c[0], a[1] + u * dy - c[1]);
                (px * px + py * py).sqrt() <= 0.5f64.sqrt() + 1e-9
            })
        })
    };
    assert!(lines_lit.iter().all(|&p| near_an_edge(p)));
    // the flat frame after them is the flat frame of the default sequence
    let default = build("refine", scene("pot", 64), &Settings::default());
    let first = self::run(&*default, 1).frames.remove(0);
    assert_eq!(run.frames[2], first);
}

#[test]
fn phase_lists_are_checked() {
    use cwisim_render::refine::parse_phases;
    assert_eq!(
        parse_phases("vertices, edges,flat,aa").unwrap(),
        [Phase::Vertices, Phase::Edges, Phase::Flat, Phase::Antialias]
    );
    for (bad, says) in [
        ("gouraud,flat", "list `flat` before it"),
        ("flat,phong,gouraud", "out of order"),
        ("flat,flat", "out of order"),
        ("vertices,gouraud", "list `flat` before it"),
        ("shadows,flat", "list `flat` before it"),
        ("flat,gouraud,shadows", "out of order"),
        ("flat,ray-tracing", "unknown phase `ray-tracing`"),
        ("", "unknown phase ``"),
    ] {
        let e = parse_phases(bad).unwrap_err();
        assert!(e.contains(says), "{bad}: {e}");
    }
}

/// Each scanline of the polygon-ID view, collected.
fn owners(r: &Refine) -> Vec<Vec<u32>> {
    let view = r.id_view().unwrap();
    let mut rows = Vec::new();
    view.scan(&mut |y, owners| {
        assert_eq!(y, rows.len());
        rows.push(owners.to_vec());
    })
    .unwrap();
    rows
}

/// Whether `(x, y)` is inside the polygon `v` (crossing number), and its distance to the
/// nearest edge.
fn inside_and_margin(v: &[[f64; 2]], x: f64, y: f64) -> (bool, f64) {
    let mut inside = false;
    let mut margin = f64::INFINITY;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        if (a[1] > y) != (b[1] > y) && x < a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            inside = !inside;
        }
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((x - a[0]) * dx + (y - a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (px, py) = (a[0] + t * dx - x, a[1] + t * dy - y);
        margin = margin.min((px * px + py * py).sqrt());
    }
    (inside, margin)
}

#[test]
fn the_id_view_names_the_polygon_at_each_pixel_centre() {
    for name in ["pot", "still-life", "teapot"] {
        let r = Refine::new(scene(name, 96), &Settings::default()).unwrap();
        let rows = owners(&r);
        let screen = &r.polygons().screen;
        let (w, h) = (screen.width as usize, screen.height as usize);
        assert_eq!(rows.len(), h);
        // brute force, polygon by polygon over its bounding box: which polygons hold
        // each pixel centre, away from every edge
        let mut holders = vec![Vec::new(); w * h];
        let mut near_edge = vec![false; w * h];
        for (k, p) in screen.polygons.iter().enumerate() {
            let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
            for v in &p.vertices {
                (x0, x1, y0, y1) = (x0.min(v[0]), x1.max(v[0]), y0.min(v[1]), y1.max(v[1]));
            }
            let xs = (x0.floor().max(0.0) as usize)..((x1.ceil() as usize).min(w));
            let ys = (y0.floor().max(0.0) as usize)..((y1.ceil() as usize).min(h));
            for y in ys {
                for x in xs.clone() {
                    let (inside, margin) =
                        inside_and_margin(&p.vertices, x as f64 + 0.5, y as f64 + 0.5);
                    if margin < 1e-6 {
                        near_edge[y * w + x] = true;
                    } else if inside {
                        holders[y * w + x].push(k as u32 + 1);
                    }
                }
            }
        }
        let mut checked = 0;
        for y in 0..h {
            for x in 0..w {
                let o = rows[y][x];
                assert_ne!(o, cwisim_render::refine::ids::SHARED, "{name} ({x}, {y})");
                if near_edge[y * w + x] {
                    continue;
                }
                let want = match holders[y * w + x][..] {
                    [] => cwisim_render::refine::ids::NONE,
                    [k] => k,
                    ref many => panic!("{name} ({x}, {y}): fragments overlap: {many:?}"),
                };
                assert_eq!(o, want, "{name} pixel ({x}, {y})");
                checked += 1;
            }
        }
        assert!(
            checked > w * h * 9 / 10,
            "{name}: {checked} of {} checked",
            w * h
        );
    }
}

#[test]
fn the_flat_frame_is_the_owners_flat_value_and_phase_pixels_are_owned_pixels() {
    // without shadows: with them the flat frame is the pieces' unshadowed value
    let settings = Settings {
        shadows: Some(false),
        ..thresholds(Threshold::Above(0.02), Threshold::None, Threshold::None)
    };
    let r = Refine::new(scene("still-life", 80), &settings).unwrap();
    let rows = owners(&r);
    let run = run(&r, 1);
    let screen = &r.polygons().screen;
    let ch = usize::from(screen.channels);
    let w = screen.width as usize;
    let (mut owned, mut gouraud) = (0u64, 0u64);
    for (y, row) in rows.iter().enumerate() {
        for (x, &o) in row.iter().enumerate() {
            let pixel = &run.frames[0][(y * w + x) * ch..][..ch];
            if o == cwisim_render::refine::ids::NONE {
                assert!(pixel.iter().all(|&v| v == 0.0), "({x}, {y}) {pixel:?}");
                continue;
            }
            owned += 1;
            let p = &screen.polygons[o as usize - 1];
            let mean = cwisim_ypipe::flat_mean(&p.intensity, ch);
            assert_eq!(pixel, &mean[..ch], "({x}, {y}) owned by {o}");
            if r.modes()[o as usize - 1] == cwisim_render::refine::display::Mode::Gouraud {
                gouraud += 1;
            }
        }
    }
    assert!(gouraud > 0 && gouraud < owned);
    assert_eq!(run.counters.get("flat_pixels"), Some(owned));
    assert_eq!(run.counters.get("gouraud_pixels"), Some(gouraud));
}

#[test]
fn anti_aliasing_a_few_pixels_costs_less_than_the_full_box_filter() {
    // the previous frame re-sent with Dis masks, Evals that write nothing dropped: with a
    // few per cent of the pixels flagged the frame is smaller than van Rij's whole box
    // filter (re-sending the kept pixels as Eval0 claims made it 3.8 times larger at
    // 400×400)
    let settings = thresholds(
        Threshold::Above(0.02),
        Threshold::Above(30.0),
        Threshold::Above(0.1),
    );
    let r = build("refine", scene("pot", 200), &settings);
    let run = run(&*r, 1);
    let h = r.header();
    let flagged = run.counters.get("aa_pixels").unwrap();
    assert!(
        flagged * 10 < u64::from(h.width) * u64::from(h.lines),
        "{flagged}"
    );
    let aa = run.streams[3].len();
    let (_, box_filter) = full("pot", 200);
    assert!(
        aa < box_filter.len(),
        "{aa} instructions against {}",
        box_filter.len()
    );
    let masks = run.counters.get("aa_masks").unwrap() as usize;
    assert_eq!(
        run.streams[3]
            .iter()
            .filter(|i| i.op == Opcode::Dis)
            .count(),
        masks
    );
    assert!(masks > 0);
}

#[test]
fn kept_pixels_are_the_previous_frames_in_a_narrow_fixed_format_too() {
    // the kept pixels get the very instructions that made them, masks around them
    // included, so a fixed format whose I register is narrower than acc keeps them bit
    // for bit as well
    let settings = thresholds(
        Threshold::Above(0.02),
        Threshold::Above(30.0),
        Threshold::Above(0.05),
    );
    let r = build("refine", scene("pot", 96), &settings);
    let h = r.header();
    let (w, lines, ch) = (h.width as usize, h.lines as usize, h.channel_count());
    let array = ArrayConfig {
        numeric: "fixed:I=12.20,dI=4.28,ddI=1.36,acc=12.36".parse().unwrap(),
        ..ArrayConfig::default()
    };
    let mut sink = ImageSink::new(w, ch, 1 << 30);
    render(&*r, &array, 1, &mut sink, Taps::default()).unwrap();
    let data = sink.finish().unwrap().data;
    let per = w * lines * ch;
    let (phong, aa) = (&data[2 * per..3 * per], &data[3 * per..4 * per]);
    let flags = brute_flags(phong, w, lines, ch, 0.05);
    let kept = flags.iter().filter(|&&f| !f).count();
    assert!(kept > 0 && kept < w * lines);
    for (p, _) in flags.iter().enumerate().filter(|(_, &f)| !f) {
        let (a, b) = (&phong[p * ch..(p + 1) * ch], &aa[p * ch..(p + 1) * ch]);
        assert_eq!(
            a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            b.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "pixel {p}"
        );
    }
}

/// `--vertex-fraction 1/N`: the vertex phase in N frames, each adding every N-th vertex;
/// the last is the unsplit phase's frame bit for bit, each frame lights what the one
/// before lit, and the first draws a tenth of the points, spread over the model.
#[test]
fn the_vertex_phase_a_fraction_at_a_time_ends_at_the_whole_one() {
    let settings = Settings::default();
    let phases = [Phase::Vertices, Phase::Flat];
    let whole = Refine::with_phases(scene("teapot", 160), &settings, &phases).unwrap();
    let split = Refine::with_vertex_parts(scene("teapot", 160), &settings, &phases, 10).unwrap();
    assert_eq!(whole.frames(), 2);
    assert_eq!(split.frames(), 11);
    let (a, b) = (run(&whole, 1), run(&split, 2));
    // the last vertex frame and the flat frame are the unsplit run's
    assert_eq!(b.frames[9], a.frames[0]);
    assert_eq!(b.frames[10], a.frames[1]);
    assert_eq!(b.streams[9], a.streams[0]);
    // each frame lights every pixel the one before lit (the nearest point wins a pixel,
    // so a lit pixel may brighten, never go dark)
    for k in 1..10 {
        for (p, q) in b.frames[k - 1].iter().zip(&b.frames[k]) {
            assert!(*q >= *p, "frame {k}");
        }
    }
    let drawn = |k: usize| b.counters.get(split.frame_counter(k, "drawn")).unwrap();
    let all = a.counters.get("vertices_drawn").unwrap();
    assert_eq!(drawn(9), all);
    assert_eq!(drawn(0), all.div_ceil(10));
    for k in 1..10 {
        assert!(drawn(k) > drawn(k - 1));
    }
    assert_eq!(split.frame_name(0), "vertices-1");
    assert_eq!(split.frame_name(9), "vertices");
    assert_eq!(split.frame_name(10), "flat");
    // the first tenth is spread: points in every quarter of the model's width
    let lit: Vec<usize> = (0..160 * 160).filter(|&i| b.frames[0][i] > 0.0).collect();
    let (x0, x1) = lit.iter().fold((usize::MAX, 0), |(a, c), &i| {
        (a.min(i % 160), c.max(i % 160))
    });
    for q in 0..4 {
        let (from, to) = (x0 + q * (x1 - x0) / 4, x0 + (q + 1) * (x1 - x0) / 4);
        assert!(
            lit.iter().any(|&i| (from..=to).contains(&(i % 160))),
            "quarter {q}"
        );
    }
    // refusals
    assert!(cwisim_render::refine::vertex_parts(0.3).is_err());
    assert!(cwisim_render::refine::vertex_parts(0.01).is_err());
    assert_eq!(cwisim_render::refine::vertex_parts(0.1), Ok(10));
    assert_eq!(cwisim_render::refine::vertex_parts(1.0), Ok(1));
    assert!(Refine::with_vertex_parts(scene("teapot", 64), &settings, &[Phase::Flat], 4).is_err());
}
