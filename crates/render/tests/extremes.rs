//! The extremes matrix of issue 22: every registered renderer (`cwisim_render::REGISTRY`,
//! so a renderer registered later is covered without touching this file) × numeric
//! formats × screen scenes at the numeric extremes.
//!
//! For each cell the scene is first validated (`ScreenScene::validate`); a case meant to be
//! refused must be refused with a message naming the offending field. Otherwise the scene
//! is built, emitted and run through the array, and the outcome is one of:
//!
//! * **pass** — every value finite, the `f64` image within the bound of the exact box
//!   filter (`cwisim_ypipe::exact::scene_box_filtered`), and the format's image within the
//!   format's bound of the renderer's own `f64` image (bounds below);
//! * **overflow** (formats other than `f64` only) — the array counted overflow events
//!   (`RunStats::totals.overflows > 0`): the run says the values are out of the format's
//!   range, nothing silent;
//! * **refused** (formats other than `f64` only) — an error with a message.
//!
//! Anything else fails the test: a panic, a non-finite value that no overflow counts, a
//! value beyond its bound, a valid scene refused in `f64`.
//!
//! Bounds, per pixel:
//!
//! * reference, renderers that filter (`supersampled == false`): `|v − box| ≤ 1e-9 ·
//!   max(1, Imax)`, `Imax` the largest intensity magnitude in the scene;
//! * reference, renderers that point-sample (`supersampled == true`): `|v − box| ≤ Σ`
//!   (largest intensity magnitude of each polygon whose bounding box meets the pixel's
//!   closed square) `+ 1e-9 · max(1, Imax)` — a sample is wrong by at most what a polygon
//!   could cover; a pixel no polygon reaches is exact;
//! * `f32` against the renderer's `f64` image: `Σ 2^-20 · (k + 1)² · M` over the Evals
//!   that reach the pixel, `k` its distance from the Eval's `x` and `M = |I| + k·|dI| +
//!   C(k)·|ddI|` (plus the row's largest preload, times `1 + k + C(k)`): the first-order
//!   error of `f32` forward differencing and accumulation (each add rounds by `2^-24` of
//!   its result) with a factor 16 to spare;
//! * fixed point against the renderer's `f64` image: `Σ error_bound(format, order, k + 1)`
//!   over the Evals that reach the pixel (`docs/ACCURACY.md`), with no overflow counted.
//!
//! `cargo test -p cwisim-render --test extremes -- --nocapture` prints the matrix quoted in
//! `docs/ACCURACY.md`.

use cwisim_isa::{Instruction, Opcode};
use cwisim_render::{emit, render, ArrayConfig, Entry, LoadedScene, Settings, REGISTRY};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_world::AnyScene;
use cwisim_xproc::numeric::{error_bound, Numeric};
use cwisim_xproc::ImageSink;
use cwisim_ypipe::exact::scene_box_filtered;
use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The formats of the matrix: the reference, `f32`, and the widest and the default-width
/// fixed formats of `docs/ACCURACY.md`.
const FORMATS: &[&str] = &[
    "f64",
    "f32",
    "fixed:I=12.36,dI=4.44,ddI=1.52,acc=12.36",
    "fixed:I=12.20,dI=4.28,ddI=1.36",
];

/// What a case must give.
#[derive(Clone, Copy, Debug)]
enum Expect {
    /// A valid scene: drawn (in `f64`, always; other formats may count overflow or refuse).
    Draw,
    /// Refused by validation, with a message naming this field (JSON path).
    Refuse(&'static str),
    /// Valid, but refused by every renderer with a message naming this field.
    RefuseToDraw(&'static str),
}

struct Case {
    name: &'static str,
    scene: ScreenScene,
    expect: Expect,
}

fn screen(width: u32, height: u32, polygons: Vec<Polygon>) -> ScreenScene {
    ScreenScene {
        width,
        height,
        channels: 1,
        polygons,
    }
}

fn square(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// A sliver 1e-12 px wide across a 16×16 screen, shaded from 0 to `top` across its
/// width.
fn sliver(top: f64) -> ScreenScene {
    screen(
        16,
        16,
        vec![Polygon::new(
            vec![
                [1.0, 3.0],
                [15.0, 9.0],
                [15.0, 9.0 + 1e-12],
                [1.0, 3.0 + 1e-12],
            ],
            vec![vec![0.0], vec![0.0], vec![top], vec![top]],
        )],
    )
}

fn cases() -> Vec<Case> {
    let draw = |name, scene| Case {
        name,
        scene,
        expect: Expect::Draw,
    };
    let refuse = |name, scene, field| Case {
        name,
        scene,
        expect: Expect::Refuse(field),
    };
    let f32_int = f64::from(1u32 << 24); // 2^24: f32's last exact integer
    let uniform = |v: f64| Polygon::uniform(square(2.25, 3.5, 13.75, 12.125), &[v]);
    let refuse_to_draw = |name, scene, field| Case {
        name,
        scene,
        expect: Expect::RefuseToDraw(field),
    };
    vec![
        draw(
            "polygon of 1e-9 px²",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![[5.3, 5.3], [5.3 + 1e-4, 5.3], [5.3, 5.3 + 2e-5]],
                    &[1.0],
                )],
            ),
        ),
        draw(
            "sliver 1e-12 px wide across 14 px",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![
                        [1.0, 3.0],
                        [15.0, 9.0],
                        [15.0, 9.0 + 1e-12],
                        [1.0, 3.0 + 1e-12],
                    ],
                    &[1.0],
                )],
            ),
        ),
        draw(
            "sliver 1e-12 px wide, intensity 0 → 1 across its width",
            sliver(1.0),
        ),
        draw(
            "polygons 1e6 px outside the screen",
            screen(
                16,
                16,
                vec![
                    Polygon::uniform(square(1e6, 4.0, 1e6 + 10.0, 9.0), &[1.0]),
                    Polygon::uniform(square(-1e6 - 10.0, -1e6 - 7.0, -1e6, -1e6), &[1.0]),
                    Polygon::uniform(square(3.0, 1e6, 9.0, 1e6 + 3.0), &[1.0]),
                ],
            ),
        ),
        draw(
            "vertices at ±2^24 (f32's integers), clipped to 16×16",
            screen(
                16,
                16,
                vec![Polygon::new(
                    vec![[-f32_int, -f32_int], [f32_int, 7.5], [5.25, f32_int]],
                    vec![vec![0.0], vec![1.0], vec![0.5]],
                )],
            ),
        ),
        draw(
            "vertices at 2^24 + 0.5 px, an edge through the screen",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![
                        [-f32_int - 0.5, 8.25],
                        [f32_int + 0.5, 8.75],
                        [0.5, f32_int + 0.5],
                    ],
                    &[1.0],
                )],
            ),
        ),
        draw(
            "vertices at ±1e15 (the coordinate limit)",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![[-1e15, -1e15], [1e15, 6.5], [6.5, 1e15]],
                    &[1.0],
                )],
            ),
        ),
        refuse(
            "a vertex beyond 1e15",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![[0.0, 0.0], [2e15, 6.5], [6.5, 10.0]],
                    &[1.0],
                )],
            ),
            "polygons[0].vertices[1]",
        ),
        draw(
            "ramp 0 → 2000 over 4096 px (the fixed formats' integer range)",
            screen(
                4096,
                2,
                vec![Polygon::new(
                    square(0.0, 0.0, 4096.0, 2.0),
                    vec![vec![0.0], vec![2000.0], vec![2000.0], vec![0.0]],
                )],
            ),
        ),
        draw(
            "all vertices equal",
            screen(16, 16, vec![Polygon::uniform(vec![[4.5, 4.5]; 3], &[1.0])]),
        ),
        draw(
            "collinear vertices (zero area)",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![[1.0, 1.0], [8.3, 8.3], [15.0, 15.0]],
                    &[1.0],
                )],
            ),
        ),
        draw(
            "repeated and collinear vertices on a square",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![
                        [2.0, 2.5],
                        [8.0, 2.5],
                        [8.0, 2.5],
                        [14.0, 2.5],
                        [14.0, 14.0],
                        [8.0, 14.0],
                        [2.0, 14.0],
                    ],
                    &[1.0],
                )],
            ),
        ),
        refuse(
            "two vertices",
            screen(
                16,
                16,
                vec![Polygon::uniform(vec![[1.0, 1.0], [9.0, 9.0]], &[1.0])],
            ),
            "polygons[0].vertices",
        ),
        refuse(
            "a bow tie (self-intersecting)",
            screen(
                16,
                16,
                vec![Polygon::uniform(
                    vec![[1.0, 1.0], [9.0, 9.0], [9.0, 1.0], [1.0, 9.0]],
                    &[1.0],
                )],
            ),
            "polygons[0].vertices",
        ),
        draw(
            "coincident polygons",
            screen(16, 16, vec![uniform(0.5), uniform(0.25)]),
        ),
        draw("intensity 0", screen(16, 16, vec![uniform(0.0)])),
        draw("intensity 1", screen(16, 16, vec![uniform(1.0)])),
        draw("intensity 1e-300", screen(16, 16, vec![uniform(1e-300)])),
        draw(
            "intensity 2047 (the fixed formats' largest integer)",
            screen(16, 16, vec![uniform(2047.0)]),
        ),
        draw(
            "intensity 1e12 (the limit, MAX_INTENSITY)",
            screen(16, 16, vec![uniform(1e12)]),
        ),
        refuse(
            "intensity 1.000000000001e12 (just beyond the limit)",
            screen(16, 16, vec![uniform(1.000000000001e12)]),
            "polygons[0].intensity[0][0]",
        ),
        refuse(
            "intensity 3e38 (near f32's largest)",
            screen(16, 16, vec![uniform(3e38)]),
            "polygons[0].intensity[0][0]",
        ),
        refuse(
            "intensity 1e308",
            screen(16, 16, vec![uniform(1e308)]),
            "polygons[0].intensity[0][0]",
        ),
        refuse_to_draw(
            "intensity -1",
            screen(16, 16, vec![uniform(-1.0)]),
            "polygons[0].intensity[0]",
        ),
        draw(
            "sliver 1e-12 px wide, intensity 0 → 1e12 (the limit) across its width",
            sliver(1e12),
        ),
        draw(
            "triangle of 1e-9 px², intensities 0, 1e12, 5e11",
            screen(
                16,
                16,
                vec![Polygon::new(
                    vec![[5.3, 5.3], [5.3 + 1e-4, 5.3], [5.3, 5.3 + 2e-5]],
                    vec![vec![0.0], vec![1e12], vec![5e11]],
                )],
            ),
        ),
        draw(
            "64 coincident layers",
            screen(
                16,
                16,
                (0..64).map(|k| uniform(f64::from(k) / 64.0)).collect(),
            ),
        ),
        draw(
            "the last pixels of a 65 536-wide row",
            screen(
                65_536,
                1,
                vec![Polygon::new(
                    vec![[65_530.25, 0.0], [65_536.0, 0.125], [65_535.5, 1.0]],
                    vec![vec![0.25], vec![1.0], vec![0.5]],
                )],
            ),
        ),
        draw(
            "four channels at 0, 1, 1e-300 and 2047",
            ScreenScene {
                width: 16,
                height: 16,
                channels: 4,
                polygons: vec![Polygon::uniform(
                    square(2.25, 3.5, 13.75, 12.125),
                    &[0.0, 1.0, 1e-300, 2047.0],
                )],
            },
        ),
        refuse(
            "intensity NaN",
            screen(16, 16, vec![uniform(f64::NAN)]),
            "polygons[0].intensity[0]",
        ),
        refuse(
            "width 65 537",
            screen(65_537, 1, vec![uniform(1.0)]),
            "width",
        ),
    ]
}

/// The largest magnitude in a polygon's intensities.
fn peak(p: &Polygon) -> f64 {
    p.intensity
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// Per pixel: the sum and the largest of the peaks of the polygons whose bounding box
/// meets the pixel (grown by one pixel).
fn reach(s: &ScreenScene) -> Vec<(f64, f64)> {
    let (w, h) = (s.width as usize, s.height as usize);
    let mut out = vec![(0.0, 0.0f64); w * h];
    for p in &s.polygons {
        let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for [x, y] in &p.vertices {
            (x0, y0, x1, y1) = (x0.min(*x), y0.min(*y), x1.max(*x), y1.max(*y));
        }
        let clamp = |v: f64, n: usize| v.clamp(0.0, n as f64) as usize;
        let (cx0, cx1) = (clamp(x0.floor() - 1.0, w), clamp(x1.ceil() + 1.0, w));
        let (cy0, cy1) = (clamp(y0.floor() - 1.0, h), clamp(y1.ceil() + 1.0, h));
        for y in cy0..cy1 {
            for x in cx0..cx1 {
                let o = &mut out[y * w + x];
                *o = (o.0 + peak(p), o.1.max(peak(p)));
            }
        }
    }
    out
}

fn magnitude(v: &cwisim_isa::Intensity) -> f64 {
    v.as_slice().iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Per value, the bound of the format against the renderer's `f64` image (module docs);
/// `None` for `f64`.
fn format_bound(stream: &[Instruction], numeric: &Numeric, w: usize, h: usize) -> Vec<f64> {
    let mut out = vec![0.0; w * h];
    let mut line = 0usize;
    let mut preload = 0.0f64;
    for i in stream {
        let order = match i.op {
            Opcode::Eval0 => 0,
            Opcode::Eval1 => 1,
            Opcode::Eval2 => 2,
            Opcode::Eval3 => 3,
            Opcode::Refresh => {
                line += 1;
                preload = 0.0;
                continue;
            }
            Opcode::SetI
            | Opcode::SetdI
            | Opcode::SetddI
            | Opcode::SetPI
            | Opcode::SetPdI
            | Opcode::SetPddI => {
                preload = preload.max(magnitude(&i.i()));
                continue;
            }
            _ => continue,
        };
        if line >= h {
            break;
        }
        let [a, d, dd] = i.values().map(|v| magnitude(&v));
        let end = (i.x as usize + i.dx as usize).min(w);
        for p in (i.x as usize)..end {
            let k = (p - i.x as usize) as f64;
            let c = k * (k - 1.0).max(0.0) / 2.0;
            out[line * w + p] += match numeric {
                Numeric::F64 => 0.0,
                Numeric::F32 => {
                    let m = match order {
                        0 | 1 => a + preload,
                        2 => a + k * d + preload * (1.0 + k),
                        _ => a + k * d + c * dd + preload * (1.0 + k + c),
                    };
                    // relative rounding, and underflow below f32's smallest subnormal
                    2f64.powi(-20) * (k + 1.0).powi(2) * m + 2f64.powi(-149) * (2.0 + k + c)
                }
                Numeric::Fixed(f) => error_bound(f, order, k as u64 + 1),
            };
        }
    }
    out
}

/// One cell's outcome.
enum Outcome {
    Pass {
        vs_exact: f64,
        vs_f64: f64,
        worst_ratio: f64,
    },
    Overflow(u64),
    Refused(String),
    Fail(String),
}

struct Drawn {
    image: Vec<f64>,
    overflows: u64,
}

fn settings() -> Settings {
    Settings {
        samples: 1,
        ..Settings::default()
    }
}

/// Builds, emits and runs; an error is the message, a panic is a failure.
fn draw(
    entry: &Entry,
    scene: &ScreenScene,
    numeric: &Numeric,
) -> Result<Result<(Drawn, Vec<Instruction>), String>, String> {
    let run = || -> Result<(Drawn, Vec<Instruction>), String> {
        let loaded = || LoadedScene::built("extreme", AnyScene::Screen(scene.clone()));
        let renderer = (entry.build)(loaded(), &settings()).map_err(|e| e.to_string())?;
        let mut stream: Vec<Instruction> = Vec::new();
        emit(&*renderer, &mut stream).map_err(|e| e.to_string())?;
        let h = renderer.header();
        let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 28);
        let array = ArrayConfig {
            numeric: *numeric,
            ..ArrayConfig::default()
        };
        let done = render(&*renderer, &array, 1, &mut sink, Default::default())
            .map_err(|e| e.to_string())?;
        let image = sink.finish().map_err(|e| e.to_string())?.data;
        Ok((
            Drawn {
                image,
                overflows: done.stats.totals.overflows,
            },
            stream,
        ))
    };
    catch_unwind(AssertUnwindSafe(run)).map_err(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "a panic".into())
    })
}

/// What drawing in `f64` gave: the reference of the other formats.
type Base = Result<Result<(Drawn, Vec<Instruction>), String>, String>;

fn cell(entry: &Entry, case: &Case, numeric: &Numeric, reference: &[f64], base: &Base) -> Outcome {
    let s = &case.scene;
    let (base, stream) = match base {
        Err(panic) => return Outcome::Fail(format!("panicked in f64: {panic}")),
        Ok(Err(e)) => return Outcome::Fail(format!("a valid scene refused in f64: {e}")),
        Ok(Ok(r)) => r,
    };
    let imax = s.polygons.iter().map(peak).fold(1.0f64, f64::max);
    let tol = 1e-9 * imax;
    // the f64 image against the exact reference
    let reach = reach(s);
    let ch = usize::from(s.channels);
    for (p, (v, e)) in base.image.iter().zip(reference).enumerate() {
        if !v.is_finite() {
            return Outcome::Fail(format!("f64 value {v} at {p}"));
        }
        let (sum, top) = reach[p / ch];
        let allowed = if entry.supersampled {
            // one surface per sample: no larger than the largest polygon reaching it
            if v.abs() > top + tol {
                return Outcome::Fail(format!(
                    "f64 value {v:e} at {p} is beyond every polygon reaching it ({top:e})"
                ));
            }
            sum + tol
        } else {
            tol
        };
        let err = (v - e).abs();
        if err > allowed {
            return Outcome::Fail(format!(
                "f64 value {v:e} at {p} is {err:e} from the exact {e:e}, beyond {allowed:e}"
            ));
        }
    }
    let drawn = match numeric {
        Numeric::F64 => base.image.clone(),
        _ => match draw(entry, s, numeric) {
            Err(panic) => return Outcome::Fail(format!("panicked: {panic}")),
            Ok(Err(e)) if e.trim().is_empty() => return Outcome::Fail("an empty refusal".into()),
            Ok(Err(e)) => return Outcome::Refused(e),
            Ok(Ok((d, _))) if d.overflows > 0 => return Outcome::Overflow(d.overflows),
            Ok(Ok((d, _))) => d.image,
        },
    };
    let bound = format_bound(stream, numeric, s.width as usize, s.height as usize);
    let (mut vs_f64, mut worst_ratio) = (0.0f64, 0.0f64);
    for (p, (v, b)) in drawn.iter().zip(&base.image).enumerate() {
        if !v.is_finite() {
            return Outcome::Fail(format!("value {v} at {p} with no overflow counted"));
        }
        let r = &bound[p / ch];
        let err = (v - b).abs();
        // f64 against itself: bit for bit; otherwise the bound, up to the rounding of
        // the difference itself
        if err > *r + 4.0 * f64::EPSILON * b.abs() {
            return Outcome::Fail(format!(
                "value {v:e} at {p} is {err:e} from f64's {b:e}, beyond the bound {r:e}"
            ));
        }
        vs_f64 = vs_f64.max(err);
        if *r > 0.0 {
            worst_ratio = worst_ratio.max(err / r);
        }
    }
    let vs_exact = drawn
        .iter()
        .zip(reference)
        .map(|(v, e)| (v - e).abs())
        .fold(0.0, f64::max);
    Outcome::Pass {
        vs_exact,
        vs_f64,
        worst_ratio,
    }
}

#[test]
fn every_renderer_in_every_format_draws_the_extremes_or_refuses_them() {
    let cases = cases();
    let mut failures = Vec::new();
    // renderer × format → [pass, overflow, refused, refused by validation]
    let mut summary: BTreeMap<(usize, usize), [u32; 4]> = BTreeMap::new();
    println!("| renderer | case | format | outcome | max error vs exact | max error vs f64 | of the bound |");
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    for case in &cases {
        let validated = case.scene.validate();
        match (case.expect, &validated) {
            (Expect::Refuse(field), Err(e)) => {
                let message = e.to_string();
                assert!(
                    message.contains(field),
                    "{}: the refusal `{message}` does not name `{field}`",
                    case.name
                );
                for (r, entry) in REGISTRY.iter().enumerate() {
                    for f in 0..FORMATS.len() {
                        summary.entry((r, f)).or_default()[3] += 1;
                    }
                    println!(
                        "| {} | {} | all | refused by validation: {message} | | | |",
                        entry.name, case.name
                    );
                }
                continue;
            }
            (Expect::RefuseToDraw(field), Ok(())) => {
                for (r, entry) in REGISTRY.iter().enumerate() {
                    match draw(entry, &case.scene, &Numeric::F64) {
                        Ok(Err(message)) if message.contains(field) => {
                            for f in 0..FORMATS.len() {
                                summary.entry((r, f)).or_default()[2] += 1;
                            }
                            println!(
                                "| {} | {} | all | refused: {message} | | | |",
                                entry.name, case.name
                            );
                        }
                        other => failures.push(format!(
                            "{} / {}: expected a refusal naming `{field}`, got {}",
                            entry.name,
                            case.name,
                            match other {
                                Ok(Ok(_)) => "an image".to_string(),
                                Ok(Err(m)) => format!("`{m}`"),
                                Err(panic) => format!("a panic: {panic}"),
                            }
                        )),
                    }
                }
                continue;
            }
            (Expect::Refuse(field), Ok(())) => {
                failures.push(format!(
                    "{}: expected a refusal naming `{field}`, validated",
                    case.name
                ));
                continue;
            }
            (Expect::Draw | Expect::RefuseToDraw(_), Err(e)) => {
                failures.push(format!("{}: a valid scene refused: {e}", case.name));
                continue;
            }
            (Expect::Draw, Ok(())) => {}
        }
        let reference = scene_box_filtered(&case.scene);
        for (r, entry) in REGISTRY.iter().enumerate() {
            let base = draw(entry, &case.scene, &Numeric::F64);
            for (f, format) in FORMATS.iter().enumerate() {
                let numeric: Numeric = format.parse().expect("a format");
                let outcome = cell(entry, case, &numeric, &reference, &base);
                let counts = summary.entry((r, f)).or_default();
                let row = |outcome: &str, rest: &str| {
                    println!(
                        "| {} | {} | `{format}` | {outcome} | {rest} |",
                        entry.name, case.name
                    )
                };
                match outcome {
                    Outcome::Pass {
                        vs_exact,
                        vs_f64,
                        worst_ratio,
                    } => {
                        counts[0] += 1;
                        row(
                            "pass",
                            &format!(
                                "{vs_exact:.2e} | {vs_f64:.2e} | {:.0} %",
                                100.0 * worst_ratio
                            ),
                        );
                    }
                    Outcome::Overflow(n) => {
                        counts[1] += 1;
                        row(&format!("overflow counted ({n})"), " | |");
                    }
                    Outcome::Refused(e) => {
                        counts[2] += 1;
                        row(&format!("refused: {e}"), " | |");
                    }
                    Outcome::Fail(why) => {
                        row(&format!("**FAIL**: {why}"), " | |");
                        failures.push(format!("{} / {} / {format}: {why}", entry.name, case.name));
                    }
                }
            }
        }
    }
    println!();
    println!("| renderer | format | pass | overflow counted | refused | refused by validation |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for ((r, f), [pass, overflow, refused, invalid]) in &summary {
        println!(
            "| {} | `{}` | {pass} | {overflow} | {refused} | {invalid} |",
            REGISTRY[*r].name, FORMATS[*f]
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
