//! `refine` (Bergman et al., adaptive refinement) held to what its phases must equal:
//! van Rij's Gouraud box filter when every threshold is `all`, the flat frame when every
//! threshold is `none`, a brute-force 3 × 3 range over the array's own previous output
//! for the anti-aliasing flags, and an error against the full-quality image that does not
//! grow from the first phase to the last.

use cwisim_isa::{Instruction, Opcode};
use cwisim_render::refine::{Phase, Refine};
use cwisim_render::settings::Threshold;
use cwisim_render::{
    emit, registry, render, ArrayConfig, LoadedScene, Renderer, Settings, Source, Taps,
};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::embedded::embedded;
use cwisim_world::parse_any;
use cwisim_xproc::ImageSink;

fn scene(name: &str, size: u32) -> LoadedScene {
    let e = embedded(name).unwrap();
    let scene = parse_any(e.text, None)
        .unwrap()
        .with_size(size, size)
        .unwrap();
    LoadedScene::built(name, scene)
}

fn thresholds(gouraud: Threshold, aa: Threshold) -> Settings {
    Settings {
        gouraud_threshold: gouraud,
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

/// The full-quality image and stream: `render --renderer vanrij --shading gouraud --aa box`.
fn full(name: &str, size: u32) -> (Vec<f64>, Vec<Instruction>) {
    let r = build("vanrij", scene(name, size), &Settings::default());
    let mut stream = Vec::new();
    emit(&*r, &mut stream).unwrap();
    let run = run(&*r, 1);
    (run.frames[0].clone(), stream)
}

fn rms(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64).sqrt()
}

#[test]
fn a_world_scene_is_refined_in_three_complete_frames() {
    let r = Refine::new(scene("pot", 64), &Settings::default()).unwrap();
    assert_eq!(r.phases(), [Phase::Flat, Phase::Gouraud, Phase::Antialias]);
    assert!(r.needs_previous_frame());
    // its stream exists only while it runs through the array
    let e = emit(&r, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("previous frame"), "{e}");
}

#[test]
fn every_threshold_at_all_gives_van_rijs_gouraud_box_filter_bit_for_bit() {
    for name in ["pot", "still-life"] {
        let (image, stream) = full(name, 96);
        let r = build(
            "refine",
            scene(name, 96),
            &thresholds(Threshold::All, Threshold::All),
        );
        let run = run(&*r, 1);
        let last = run.frames.last().unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(last), bits(&image), "{name}: last frame");
        assert_eq!(run.streams.last().unwrap(), &stream, "{name}: last stream");
        // and the Gouraud phase Gouraud-shades every polygon: van Rij point-sampled
        let point = build(
            "vanrij",
            scene(name, 96),
            &Settings {
                aa: Antialias::None,
                ..Settings::default()
            },
        );
        assert_eq!(bits(&run.frames[1]), bits(&self::run(&*point, 1).frames[0]));
        // nothing was claimed: every pixel box-filtered
        assert_eq!(run.counters.get("aa_claims"), Some(0));
        let h = r.header();
        assert_eq!(
            run.counters.get("aa_pixels"),
            Some(u64::from(h.width) * u64::from(h.lines))
        );
    }
}

#[test]
fn every_threshold_at_none_repeats_the_flat_frame_and_regenerates_nothing() {
    let r = build(
        "refine",
        scene("pot", 96),
        &thresholds(Threshold::None, Threshold::None),
    );
    let run = run(&*r, 1);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&run.frames[1]), bits(&run.frames[0]));
    assert_eq!(bits(&run.frames[2]), bits(&run.frames[0]));
    assert_eq!(
        run.streams[1], run.streams[0],
        "the Gouraud frame re-sends phase 1"
    );
    // the AA frame: only claims and Refresh, no filter instruction
    assert!(run.streams[2]
        .iter()
        .all(|i| matches!(i.op, Opcode::Eval0 | Opcode::Refresh)));
    assert_eq!(run.counters.get("aa_pixels"), Some(0));
    assert_eq!(run.counters.get("gouraud_polygons"), Some(0));
    // and the flat frame differs from the full-quality Gouraud one (the test can fail)
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
    for (name, t) in [("pot", 0.05), ("still-life", 0.1), ("pot", 0.0)] {
        let r = build(
            "refine",
            scene(name, 80),
            &thresholds(Threshold::Above(0.02), Threshold::Above(t)),
        );
        let h = r.header();
        let (w, lines, ch) = (h.width as usize, h.lines as usize, h.channel_count());
        let run = run(&*r, 1);
        let flags = brute_flags(&run.frames[1], w, lines, ch, t);
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
        let (image, _) = full(name, 80);
        for (p, &f) in flags.iter().enumerate() {
            let got = &run.frames[2][p * ch..(p + 1) * ch];
            let want = if f {
                &image[p * ch..(p + 1) * ch]
            } else {
                &run.frames[1][p * ch..(p + 1) * ch]
            };
            assert_eq!(
                got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                want.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                "{name}: pixel {p} (flagged: {f})"
            );
        }
    }
}

#[test]
fn the_error_against_full_quality_does_not_grow_from_flat_to_the_last_phase() {
    for name in ["pot", "still-life", "teapot"] {
        let r = build("refine", scene(name, 96), &Settings::default());
        let run = run(&*r, 1);
        let (image, _) = full(name, 96);
        let errors: Vec<f64> = run.frames.iter().map(|f| rms(f, &image)).collect();
        println!("{name}: RMS per phase {errors:?}");
        assert!(
            errors[0] > 0.0,
            "{name}: the flat phase is not full quality"
        );
        assert!(
            errors[2] <= errors[0],
            "{name}: RMS grew from {} to {}",
            errors[0],
            errors[2]
        );
        assert!(
            errors[2] <= errors[1],
            "{name}: anti-aliasing made it worse"
        );
    }
}

#[test]
fn gouraud_polygons_equal_a_recount() {
    let settings = thresholds(Threshold::Above(0.02), Threshold::Above(0.05));
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
