//! The span fitter through the real array: whatever the targets and the tolerance, every
//! pixel the array outputs is within the tolerance of its target in `f64`, and within
//! the tolerance plus the documented error bound in fixed point.

use cwisim_isa::{Instruction, Opcode, TraceHeader};
use cwisim_render::span::{fit_pieces, SpanStats};
use cwisim_xproc::numeric::{error_bound, Numeric};
use cwisim_xproc::{run, run_numeric, Machine, Timing};
use proptest::prelude::*;

/// Targets of every kind: smooth curves, steps, noise, zeros, and sums of them.
fn targets() -> impl Strategy<Value = (Vec<f64>, usize)> {
    (1usize..=3, 1usize..160).prop_flat_map(|(channels, n)| {
        let smooth = (
            0.0f64..1.0,
            -0.02f64..0.02,
            -1e-4f64..1e-4,
            0.0f64..0.3,
            0.0f64..0.2,
        );
        (
            proptest::collection::vec(smooth, channels),
            proptest::collection::vec(0.0f64..1.0, n * channels),
            0.0f64..0.3,
            0usize..n,
            Just(n),
            Just(channels),
        )
            .prop_map(|(curves, noise, noisiness, step_at, n, channels)| {
                let mut t = Vec::with_capacity(n * channels);
                for k in 0..n {
                    for (c, &(a, b, q, wobble, step)) in curves.iter().enumerate() {
                        let x = k as f64;
                        let mut v = a + b * x + q * x * x + wobble * (x / 7.0).sin();
                        if k >= step_at {
                            v += step;
                        }
                        v += noisiness * noise[k * channels + c];
                        t.push(v.max(0.0));
                    }
                }
                (t, channels)
            })
    })
}

fn tolerance() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(1e-9),
        Just(1.0 / 512.0),
        Just(0.01),
        0.0f64..0.1
    ]
}

/// The pieces at `x0` followed by a `Refresh`, through the array in `numeric`.
fn through_array(
    x0: u32,
    n: usize,
    channels: usize,
    pieces: &[Instruction],
    numeric: Option<&Numeric>,
) -> Vec<f64> {
    let h = TraceHeader::new(x0 + n as u32, 1, channels as u8).unwrap();
    let mut stream = pieces.to_vec();
    stream.push(Instruction::refresh());
    let (image, stats) = match numeric {
        None => run::<f64>(&h, &stream, &Machine::default(), Timing::Fast).unwrap(),
        Some(f) => run_numeric(&h, &stream, &Machine::default(), Timing::Fast, f).unwrap(),
    };
    assert_eq!(stats.totals.overflows, 0, "no overflow in this format");
    image.data[x0 as usize * channels..].to_vec()
}

/// For every pixel, the order of the piece that reached it and its distance from the
/// piece's start, plus one.
fn reach(x0: u32, n: usize, pieces: &[Instruction]) -> Vec<(u32, u64)> {
    let mut out = vec![(0, 0); n];
    for p in pieces {
        let order = match p.op {
            Opcode::Eval1 => 1,
            Opcode::Eval2 => 2,
            Opcode::Eval3 => 3,
            op => panic!("the fitter sent {op:?}"),
        };
        for k in 0..p.dx {
            let pixel = (p.x + k - x0) as usize;
            assert_eq!(out[pixel], (0, 0), "pixel {pixel} reached twice");
            out[pixel] = (order, u64::from(k) + 1);
        }
    }
    assert!(out.iter().all(|r| r.0 > 0), "every pixel reached");
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn the_array_shows_every_target_within_the_tolerance(
        (targets, channels) in targets(),
        tol in tolerance(),
        x0 in 0u32..5,
    ) {
        let n = targets.len() / channels;
        let (pieces, stats) = fit_pieces(x0, &targets, channels, tol).unwrap();
        prop_assert_eq!(stats.pieces(), pieces.len() as u64);
        prop_assert_eq!(stats.pixels, n as u64);
        let reached = reach(x0, n, &pieces);
        let out = through_array(x0, n, channels, &pieces, None);
        for (k, (o, t)) in out.iter().zip(&targets).enumerate() {
            prop_assert!((o - t).abs() <= tol, "pixel {} channel {}: {} vs {} (tol {})", k / channels, k % channels, o, t, tol);
        }
        if tol == 0.0 {
            prop_assert_eq!(stats.eval1, n as u64);
        }
        // fixed point: within the tolerance plus the bound of the piece that reached it
        let format: Numeric = "fixed:I=4.24,dI=4.30,ddI=4.36,acc=4.24".parse().unwrap();
        let Numeric::Fixed(f) = format else { unreachable!() };
        let fixed = through_array(x0, n, channels, &pieces, Some(&format));
        for (k, (o, t)) in fixed.iter().zip(&targets).enumerate() {
            let (order, m) = reached[k / channels];
            let bound = error_bound(&f, order, m);
            prop_assert!((o - t).abs() <= tol + bound, "pixel {} (order {order}, n {m}): {} vs {} (tol {tol} + {bound})", k / channels, o, t);
        }
    }
}

/// A smooth, Phong-like highlight over 400 pixels: a few pieces, not 400.
#[test]
fn a_smooth_highlight_takes_a_few_long_pieces() {
    let targets: Vec<f64> = (0..400)
        .map(|k| {
            let x = (k as f64 - 230.0) / 60.0;
            0.2 + 0.5 * (1.0 / (1.0 + x * x)) + 0.3 * (-(x * x)).exp().powi(8)
        })
        .collect();
    let mut totals = SpanStats::default();
    for (tol, most) in [(1.0 / 512.0, 24), (1.0 / 64.0, 10)] {
        let (pieces, stats) = fit_pieces(0, &targets, 1, tol).unwrap();
        assert!(pieces.len() <= most, "tol {tol}: {} pieces", pieces.len());
        assert!(stats.eval3 > 0, "a curve takes parabolas");
        let out = through_array(0, 400, 1, &pieces, None);
        assert!(out.iter().zip(&targets).all(|(o, t)| (o - t).abs() <= tol));
        totals.add(&stats);
    }
    assert_eq!(totals.pixels, 800);
}
