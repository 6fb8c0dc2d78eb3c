//! `Claim::Eval0`: polygons claim the pixels they fully cover with `Eval0`, so that
//! polygons sent later (farther, when the scene is sorted front to back) no longer
//! accumulate there. Executed on the array and checked against `Claim::Accumulate` and
//! the exact reference.

mod common;

use cwisim_isa::{Instruction, Opcode, TraceWrite};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_xproc::{EngineWriter, ImageSink, Machine, RunStats, Timing};
use cwisim_ypipe::exact::coverage;
use cwisim_ypipe::{emit, header, Antialias, Claim, EmitStats, Options, Shading};
use proptest::prelude::*;

/// The scene through the Y-processor and the array: the image, what the Y-processor
/// emitted and what the array did.
fn run(scene: &ScreenScene, options: &Options) -> (Vec<f64>, EmitStats, RunStats) {
    let h = header(scene);
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let (emitted, stats) = {
        let mut w = EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink)
            .expect("machine");
        let emitted = emit(scene, options, &mut w).expect("every instruction fits the array");
        w.finish().expect("finish");
        (emitted, w.into_stats().expect("stats after finish"))
    };
    let image = sink.finish().expect("image");
    assert_eq!(image.lines, scene.height as usize);
    assert_eq!(
        emitted.claims,
        stats.totals.opcodes.get(Opcode::Eval0),
        "EmitStats::claims counts the Eval0s"
    );
    assert_eq!(emitted.instructions, stats.totals.instructions);
    (image.data, emitted, stats)
}

/// Every `Eval0` of a stream, as (row, first pixel, end).
#[derive(Default)]
struct Eval0Spans {
    row: u32,
    spans: Vec<(u32, u32, u32)>,
}

impl TraceWrite for Eval0Spans {
    fn write(&mut self, i: &Instruction) -> std::io::Result<()> {
        match i.op {
            Opcode::Refresh => self.row += 1,
            Opcode::Eval0 => self.spans.push((self.row, i.x, i.x + i.dx)),
            _ => {}
        }
        Ok(())
    }
    fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn eval0_spans(scene: &ScreenScene, options: &Options) -> Vec<(u32, u32, u32)> {
    let mut w = Eval0Spans::default();
    emit(scene, options, &mut w).expect("emit");
    w.spans
}

fn options(shading: Shading, aa: Antialias, claim: Claim) -> Options {
    Options { shading, aa, claim }
}

fn eval0(tolerance: f64) -> Claim {
    Claim::Eval0 { tolerance }
}

fn flat(vertices: Vec<[f64; 2]>, i: &[f64]) -> Polygon {
    let n = vertices.len();
    Polygon {
        vertices,
        intensity: vec![i.into(); n],
        depth: None,
    }
}

fn scene(width: u32, height: u32, channels: u8, polygons: Vec<Polygon>) -> ScreenScene {
    ScreenScene {
        width,
        height,
        channels,
        polygons,
    }
}

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// A star-shaped (so simple), possibly concave polygon around a centre.
fn star(cx: f64, cy: f64, radii: &[f64], phase: f64) -> Vec<[f64; 2]> {
    let n = radii.len();
    radii
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
            [cx + r * a.cos(), cy + r * a.sin()]
        })
        .collect()
}

fn worst(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A random polygon (star-shaped, 3 to 9 vertices, up to 12 px across, partly outside
/// the 32 × 24 image at times) with random vertex intensities in 1 or 3 channels.
fn polygon() -> impl Strategy<Value = (Polygon, u8)> {
    (
        (2.0f64..30.0, 2.0f64..22.0),
        proptest::collection::vec(1.0f64..12.0, 3..10),
        0.0f64..6.3,
        prop_oneof![Just(1u8), Just(3u8)],
        proptest::collection::vec(0.0f64..1.0, 27),
    )
        .prop_map(|((cx, cy), radii, phase, channels, values)| {
            let vertices = star(cx, cy, &radii, phase);
            let c = usize::from(channels);
            let intensity = (0..vertices.len())
                .map(|v| values[v * 3..v * 3 + c].into())
                .collect();
            (
                Polygon {
                    vertices,
                    intensity,
                    depth: None,
                },
                channels,
            )
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Alone, a polygon claiming its fully covered pixels draws the image it draws when
    /// it accumulates there: exactly when flat, within the tolerance when Gouraud. And
    /// every Eval0 lies over pixels the polygon fully covers.
    #[test]
    fn a_polygon_alone_draws_the_same_image_when_it_claims((p, channels) in polygon()) {
        let s = scene(32, 24, channels, vec![p.clone()]);
        let cover = coverage(&p, 32, 24);
        let mut claimed = 0;
        for aa in [Antialias::Box, Antialias::None] {
            let (want, acc, _) = run(&s, &options(Shading::Flat, aa, Claim::Accumulate));
            prop_assert_eq!(acc.claims, 0);
            let (got, emitted, _) = run(&s, &options(Shading::Flat, aa, eval0(0.0)));
            let e = worst(&got, &want);
            prop_assert!(e <= 1e-12, "flat {:?}: worst difference {:e}", aa, e);
            prop_assert_eq!(emitted.instructions, acc.instructions, "one Eval0 per claimed stretch");
            claimed += emitted.claims;

            let (want, acc, _) = run(&s, &options(Shading::Gouraud, aa, Claim::Accumulate));
            for tolerance in [0.0, 1.0 / 512.0, 1e9] {
                let o = options(Shading::Gouraud, aa, eval0(tolerance));
                let (got, emitted, _) = run(&s, &o);
                let e = worst(&got, &want);
                prop_assert!(
                    e <= tolerance + 1e-12,
                    "Gouraud {:?}, tolerance {}: worst difference {:e}", aa, tolerance, e
                );
                prop_assert!(emitted.instructions >= acc.instructions);
                if tolerance == 1e9 {
                    prop_assert_eq!(emitted.instructions, acc.instructions);
                }
                if aa == Antialias::Box {
                    for (row, x0, x1) in eval0_spans(&s, &o) {
                        for x in x0..x1 {
                            let c = cover[(row * 32 + x) as usize];
                            prop_assert!(c >= 1.0 - 1e-9, "Eval0 at ({}, {}), coverage {}", x, row, c);
                        }
                    }
                }
            }
        }
        // a polygon with a pixel centre inside claims something when point-sampled
        prop_assert!(claimed > 0 || cover.iter().all(|c| *c < 1.0));
    }
}

/// The front square first, then the back one overlapping it; flat, box filter.
#[test]
fn a_front_square_sent_first_hides_the_back_one_where_it_fully_covers() {
    check_two_squares(rect(4.3, 3.6, 12.7, 10.2), rect(8.2, 6.4, 17.5, 13.9));
    // the front square's left edge on a pixel border: its fully covered first pixel is a
    // separately calculated one (DO_FILL's Single), claimed too, over the back square
    check_two_squares(rect(4.0, 3.6, 12.7, 10.2), rect(2.5, 6.4, 17.5, 13.9));
}

fn check_two_squares(front: Vec<[f64; 2]>, back: Vec<[f64; 2]>) {
    let (front_i, back_i) = (0.8, 0.3);
    let (front, back) = (flat(front, &[front_i]), flat(back, &[back_i]));
    let (w, h) = (24u32, 18u32);
    let s = scene(w, h, 1, vec![front.clone(), back.clone()]);
    let (fc, bc) = (coverage(&front, w, h), coverage(&back, w, h));
    let o = options(Shading::Flat, Antialias::Box, eval0(0.0));
    let (img, emitted, stats) = run(&s, &o);
    let (naive, _, naive_stats) = run(
        &s,
        &options(Shading::Flat, Antialias::Box, Claim::Accumulate),
    );
    assert_eq!(naive_stats.totals.suppressed, 0);
    assert!(emitted.claims > 0);

    let full = |c: f64| c >= 1.0 - 1e-12;
    let (mut hidden, mut front_full, mut back_only_full, mut overwritten) = (0, 0, 0, 0);
    for k in 0..(w * h) as usize {
        let (x, y) = (k % w as usize, k / w as usize);
        let (f, b) = (fc[k], bc[k]);
        if full(f) {
            // the front intensity, exactly: the back square is suppressed here
            assert_eq!(img[k], front_i, "({x}, {y}) fully covered by the front");
            front_full += 1;
            if b > 0.0 {
                hidden += 1;
                assert!(
                    (naive[k] - front_i - back_i * b).abs() < 1e-12,
                    "accumulating adds both"
                );
            }
        } else if full(b) && f == 0.0 {
            assert_eq!(
                img[k], back_i,
                "({x}, {y}) fully covered by the back square only"
            );
            back_only_full += 1;
        } else if full(b) {
            // Eval0 sets: the back square's claim replaces what the front square's edge
            // accumulated there first (edge pixels stay approximate)
            assert_eq!(img[k], back_i, "({x}, {y}) under the front square's edge");
            overwritten += 1;
        } else if f == 0.0 && b == 0.0 {
            assert_eq!(img[k], 0.0, "({x}, {y}) outside both");
        } else if b == 0.0 {
            assert!(
                (img[k] - front_i * f).abs() < 1e-12,
                "({x}, {y}) front edge"
            );
        } else if f == 0.0 {
            assert!((img[k] - back_i * b).abs() < 1e-12, "({x}, {y}) back edge");
        }
    }
    assert!(hidden > 0 && front_full > hidden && back_only_full > 0 && overwritten > 0);
    // every back-square instruction over a front-claimed pixel was suppressed there
    assert_eq!(stats.totals.suppressed, hidden);
}

/// Point sampling with claims is exact visibility: each pixel shows the first polygon
/// (in sending order) whose sample it is, as that polygon alone would draw it.
#[test]
fn point_sampling_with_claims_shows_the_front_polygon() {
    let front = flat(
        vec![[3.2, 2.7], [19.6, 5.1], [12.3, 15.8], [6.1, 11.4]],
        &[0.9, 0.2, 0.4],
    );
    let back = Polygon {
        vertices: vec![[9.4, 0.6], [27.7, 8.3], [14.9, 19.2], [1.3, 16.6]],
        intensity: vec![
            vec![0.1, 0.5, 0.7].into(),
            vec![0.6, 0.3, 0.2].into(),
            vec![0.4, 0.9, 0.1].into(),
            vec![0.2, 0.1, 0.8].into(),
        ],
        depth: None,
    };
    let overlap = check_point_sampled_visibility(&front, &back, 3);
    assert!(overlap > 20, "the polygons overlap ({overlap} samples)");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn point_sampling_with_claims_is_exact_visibility(
        (front, _) in polygon(),
        (back, _) in polygon(),
    ) {
        // same channel count for both
        let one = |p: &Polygon| Polygon {
            vertices: p.vertices.clone(),
            intensity: p.intensity.iter().map(|i| vec![i[0]].into()).collect(),
            depth: None,
        };
        check_point_sampled_visibility(&one(&front), &one(&back), 1);
    }
}

/// Front first: where the front polygon's sample is, its own image (flat or Gouraud,
/// claimed alone); elsewhere the back polygon's; nothing else adds.
fn check_point_sampled_visibility(front: &Polygon, back: &Polygon, channels: u8) -> u64 {
    let (w, h) = (32u32, 24u32);
    let c = usize::from(channels);
    let mask = |p: &Polygon| {
        let ones = flat(p.vertices.clone(), &vec![1.0; c]);
        let o = options(Shading::Flat, Antialias::None, Claim::Accumulate);
        let (img, _, _) = run(&scene(w, h, channels, vec![ones]), &o);
        assert!(
            img.iter().all(|v| *v == 0.0 || *v == 1.0),
            "a sample is in or out"
        );
        img
    };
    let (front_mask, back_mask) = (mask(front), mask(back));
    let mut overlaps = 0;
    for shading in [Shading::Flat, Shading::Gouraud] {
        for tolerance in [0.0, 1.0 / 512.0] {
            let o = options(shading, Antialias::None, eval0(tolerance));
            let alone = |p: &Polygon| run(&scene(w, h, channels, vec![p.clone()]), &o).0;
            let (front_alone, back_alone) = (alone(front), alone(back));
            let both = scene(w, h, channels, vec![front.clone(), back.clone()]);
            let (img, _, stats) = run(&both, &o);
            let mut overlap = 0;
            for k in 0..img.len() {
                let want = if front_mask[k] == 1.0 {
                    overlap += u64::from(back_mask[k] == 1.0);
                    front_alone[k]
                } else {
                    back_alone[k]
                };
                assert_eq!(
                    img[k],
                    want,
                    "{shading:?}, tolerance {tolerance}: pixel ({}, {}) channel {}",
                    k / c % w as usize,
                    k / c / w as usize,
                    k % c
                );
            }
            // each channel of the mask counted the overlap once
            assert_eq!(stats.totals.suppressed, overlap / c as u64);
            overlaps = overlap / c as u64;
        }
    }
    overlaps
}
