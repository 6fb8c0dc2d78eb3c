//! Stability at the extremes: the named suite of issue 6, for every numeric format.
//!
//! Each case is an instruction stream with an exact reference (computed analytically, or
//! by `cwisim_ypipe::exact` for scenes). For each format it measures the max absolute
//! error against the f64 array and against the exact reference, and for fixed point
//! checks the measured distance from the f64 array against the analytic bound of
//! `docs/ACCURACY.md` (`cwisim_xproc::numeric::error_bound`, summed per pixel over the
//! Evals that reach it). `cargo test --test extremes -- --nocapture` prints the table
//! quoted in docs/ACCURACY.md.

use cwisim_isa::{Instruction, Intensity, Opcode, TraceHeader, TraceWrite};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_xproc::numeric::{error_bound, Numeric};
use cwisim_xproc::{EngineWriter, ImageSink, Machine, RunStats, Timing};
use cwisim_ypipe::exact::scene_box_filtered;
use cwisim_ypipe::{emit, header, Options};

/// The formats of the suite: the reference, f32, and fixed point wide enough for every
/// case's range (so the bound applies), plus a narrow one.
const FORMATS: &[&str] = &[
    "f64",
    "f32",
    "fixed:I=12.36,dI=4.44,ddI=1.52,acc=12.36",
    "fixed:I=12.20,dI=4.28,ddI=1.36",
    "fixed:I=12.12,dI=4.20,ddI=1.28",
];

struct Case {
    name: &'static str,
    header: TraceHeader,
    instructions: Vec<Instruction>,
    exact: Vec<f64>,
}

fn run(c: &Case, numeric: &Numeric) -> (Vec<f64>, RunStats) {
    let mut sink = ImageSink::new(c.header.width as usize, c.header.channel_count(), 1 << 31);
    let stats = {
        let mut w = EngineWriter::with_numeric(
            &c.header,
            &Machine::default(),
            Timing::Fast,
            numeric,
            &mut sink,
        )
        .expect("a valid format");
        for i in &c.instructions {
            w.write(i).expect("a valid instruction");
        }
        w.finish().expect("finish");
        w.into_stats().expect("stats")
    };
    (sink.finish().expect("image").data, stats)
}

/// Per value, the sum of the bounds of the Evals that reached it (no preloads here).
fn bound(c: &Case, numeric: &Numeric) -> Option<Vec<f64>> {
    let Numeric::Fixed(f) = numeric else {
        return None;
    };
    let (w, ch) = (c.header.width as usize, c.header.channel_count());
    let mut out = vec![0.0; c.exact.len()];
    let mut line = 0usize;
    for i in &c.instructions {
        let order = match i.op {
            Opcode::Eval0 => 0,
            Opcode::Eval1 => 1,
            Opcode::Eval2 => 2,
            Opcode::Eval3 => 3,
            Opcode::Refresh => {
                line += 1;
                continue;
            }
            _ => continue,
        };
        for p in i.x as usize..(i.x + i.dx) as usize {
            let b = error_bound(f, order, (p - i.x as usize + 1) as u64);
            for k in 0..ch {
                out[(line * w + p) * ch + k] += b;
            }
        }
    }
    Some(out)
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn grey(v: f64) -> Intensity {
    Intensity::grey(v)
}

fn synthetic() -> Vec<Case> {
    let mut cases = Vec::new();
    // a span over the full width of 4096 processors: a first-order ramp 0 → 1.365
    // (a slope that is no binary fraction, so every format rounds it)
    let h = TraceHeader::new(4096, 1, 1).unwrap();
    let d = 1.0 / 3000.0;
    cases.push(Case {
        name: "full-width ramp (Eval2, 4096 px)",
        header: h,
        instructions: vec![
            Instruction::eval2(0, 4096, grey(0.1), grey(d)),
            Instruction::refresh(),
        ],
        exact: (0..4096).map(|p| 0.1 + p as f64 * d).collect(),
    });
    // a second-order wave over the full width: v_k = 0.1 + k·d0 + k(k−1)/2·dd
    let dd = 1.0 / 7e6;
    let d0 = 1.0 / 9000.0;
    cases.push(Case {
        name: "full-width parabola (Eval3, 4096 px)",
        header: h,
        instructions: vec![
            Instruction::eval3(0, 4096, grey(0.1), grey(d0), grey(dd)),
            Instruction::refresh(),
        ],
        exact: (0..4096)
            .map(|k| {
                let k = k as f64;
                0.1 + k * d0 + k * (k - 1.0) / 2.0 * dd
            })
            .collect(),
    });
    // a large second difference: 0.12 per step over 64 px, down from 50 through zero and
    // up again (v_k = 50 − 3.7k + 0.06·k(k−1)); Acc_mode on, so the negative middle
    // accumulates
    let h64 = TraceHeader::new(64, 1, 1).unwrap();
    cases.push(Case {
        name: "large second differences (Eval3, ddI = 0.12, through zero)",
        header: h64,
        instructions: vec![
            Instruction::acc_mode(),
            Instruction::eval3(0, 64, grey(50.0), grey(-3.7), grey(0.12)),
            Instruction::refresh(),
        ],
        exact: (0..64)
            .map(|k| {
                let k = k as f64;
                50.0 - 3.7 * k + 0.12 * k * (k - 1.0) / 2.0
            })
            .collect(),
    });
    // 16 384 accumulations on one processor, of a value that is not a binary fraction
    let v = 0.1 / 16384.0;
    let h8 = TraceHeader::new(8, 1, 1).unwrap();
    let mut instrs: Vec<Instruction> = (0..16384)
        .map(|_| Instruction::eval1(3, 1, grey(v)))
        .collect();
    instrs.push(Instruction::refresh());
    let mut exact = vec![0.0; 8];
    exact[3] = 16384.0 * v; // exact: a power of two times the operand
    cases.push(Case {
        name: "16 384 accumulations on one processor",
        header: h8,
        instructions: instrs,
        exact,
    });
    cases
}

fn scene_case(name: &'static str, scene: ScreenScene) -> Case {
    let h = header(&scene);
    let mut instructions: Vec<Instruction> = Vec::new();
    emit(&scene, &Options::default(), &mut instructions).expect("emit");
    Case {
        name,
        header: h,
        exact: scene_box_filtered(&scene),
        instructions,
    }
}

fn scenes() -> Vec<Case> {
    let screen = |w, h, polygons| ScreenScene {
        width: w,
        height: h,
        channels: 1,
        polygons,
    };
    vec![
        scene_case(
            "a sliver 1e-6 px thick across 4096 px",
            screen(
                4096,
                4,
                vec![Polygon::uniform(
                    vec![[0.0, 1.0], [4096.0, 2.5], [4096.0, 2.500001]],
                    &[1.0],
                )],
            ),
        ),
        scene_case(
            "a near-horizontal edge (slope 1e-6) across 4096 px",
            screen(
                4096,
                4,
                vec![Polygon::new(
                    vec![[0.0, 1.2], [4096.0, 1.204096], [4096.0, 3.0], [0.0, 3.0]],
                    vec![vec![0.0], vec![1.0], vec![1.0], vec![0.0]],
                )],
            ),
        ),
        scene_case(
            "coordinates up to ±65536, clipped to 256×256",
            screen(
                256,
                256,
                vec![Polygon::new(
                    vec![[-65536.0, -65536.0], [65536.0, 100.5], [100.25, 65536.0]],
                    vec![vec![0.0], vec![1.0], vec![0.5]],
                )],
            ),
        ),
        scene_case(
            "400 polygons smaller than a pixel",
            screen(
                40,
                40,
                (0..400)
                    .map(|k| {
                        let (x, y) = ((k % 20) as f64 * 2.0 + 0.3, (k / 20) as f64 * 2.0 + 0.45);
                        // one intensity: the box filter of a sub-pixel polygon is then its
                        // area, which DO_FILL gets exactly (a gradient would measure the
                        // Y-processor's centre sampling instead: docs/ERRATA.md)
                        Polygon::uniform(
                            vec![[x, y], [x + 0.6, y + 0.1], [x + 0.2, y + 0.7]],
                            &[0.7],
                        )
                    })
                    .collect(),
            ),
        ),
    ]
}

#[test]
fn the_extremes_suite_holds_for_every_format() {
    let mut cases = synthetic();
    cases.extend(scenes());
    println!(
        "| case | format | max error vs f64 | max error vs exact | bound (fixed) | overflows |"
    );
    println!("| --- | --- | --- | --- | --- | --- |");
    for c in &cases {
        let (reference, _) = run(c, &Numeric::F64);
        let f64_error = max_diff(&reference, &c.exact);
        // the f64 array itself is exact to rounding on every case
        assert!(
            f64_error < 1e-9,
            "{}: f64 is {f64_error:e} from exact",
            c.name
        );
        for f in FORMATS {
            let numeric: Numeric = f.parse().unwrap();
            let (image, stats) = run(c, &numeric);
            let vs_f64 = max_diff(&image, &reference);
            let vs_exact = max_diff(&image, &c.exact);
            let bound_text = match bound(c, &numeric) {
                Some(b) => {
                    assert_eq!(stats.totals.overflows, 0, "{} in {f}: overflow", c.name);
                    let mut worst_ratio = 0.0f64;
                    for ((x, y), b) in image.iter().zip(&reference).zip(&b) {
                        let e = (x - y).abs();
                        assert!(
                            e <= b + 1e-9,
                            "{} in {f}: error {e:e} beyond the bound {b:e}",
                            c.name
                        );
                        if *b > 0.0 {
                            worst_ratio = worst_ratio.max(e / b);
                        }
                    }
                    let max_b = b.iter().cloned().fold(0.0, f64::max);
                    format!(
                        "{max_b:.2e} (measured ≤ {:.0} % of it)",
                        100.0 * worst_ratio
                    )
                }
                None => "-".into(),
            };
            println!(
                "| {} | `{f}` | {vs_f64:.2e} | {vs_exact:.2e} | {bound_text} | {} |",
                c.name, stats.totals.overflows
            );
        }
    }
}

#[test]
fn narrow_registers_overflow_countably_by_either_policy() {
    let h = TraceHeader::new(64, 1, 1).unwrap();
    let c = Case {
        name: "ramp past the range",
        header: h,
        instructions: vec![
            Instruction::acc_mode(),
            Instruction::eval2(0, 64, grey(0.0), grey(0.25)),
            Instruction::refresh(),
        ],
        exact: (0..64).map(|k| k as f64 * 0.25).collect(),
    };
    // I = 3.4: the range is [-4, 4 − 1/16]; the ramp passes 4 at k = 16
    let (sat, s) = run(&c, &"fixed:I=3.4,dI=3.4,ddI=3.4,acc=8.4".parse().unwrap());
    let (wrap, w) = run(
        &c,
        &"fixed:I=3.4,dI=3.4,ddI=3.4,acc=8.4,overflow=wrap"
            .parse()
            .unwrap(),
    );
    assert!(s.totals.overflows > 0 && w.totals.overflows > 0);
    assert_eq!(sat[63], 4.0 - 1.0 / 16.0, "saturated");
    assert_eq!(wrap[16], -4.0, "wrapped to the bottom of the range");
    assert_eq!(sat[..16], c.exact[..16], "exact below the range");
}
