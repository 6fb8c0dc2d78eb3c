//! Each departure from the report in docs/ERRATA.md, with a test that tells the
//! report's reading from the project's, against the independent exact reference.

mod common;

use common::render;
use cwisim_isa::{Instruction, Intensity, TraceHeader};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_xproc::{run, Machine, Timing};
use cwisim_ypipe::exact::coverage;
use cwisim_ypipe::{Antialias, Options, Shading};

fn grey(vertices: Vec<[f64; 2]>) -> Polygon {
    let n = vertices.len();
    Polygon {
        vertices,
        intensity: vec![vec![1.0]; n],
        depth: None,
    }
}

/// E1: inside an edge's span, the covered area grows by 1/|1/slope| per pixel — not
/// 1/(2·|1/slope|) as the sequence procedure says.
#[test]
fn e1_sequence_increment_is_one_over_inverse_slope() {
    for inv_slope in [4.0f64, -4.0, 6.5, -12.25] {
        // a band one pixel row high, left edge with that 1/slope, right edge far right
        let (x_top, x_bot) = if inv_slope > 0.0 {
            (2.0, 2.0 + inv_slope)
        } else {
            (2.0 - inv_slope, 2.0)
        };
        let p = grey(vec![[x_top, 0.0], [30.0, 0.0], [30.0, 1.0], [x_bot, 1.0]]);
        let c = coverage(&p, 32, 1);
        let increment = c[4] - c[3];
        let corrected = 1.0 / inv_slope.abs();
        let report = 1.0 / (2.0 * inv_slope.abs());
        assert!(
            (increment - corrected).abs() < 1e-12,
            "1/slope {inv_slope}: {increment} vs {corrected}"
        );
        assert!(
            (increment - report).abs() > 0.4 * corrected,
            "the report's value {report} would match"
        );
    }
}

/// E2: the share-sequence increment is 1/|1/slope_left| − 1/|1/slope_right| whichever
/// way the edges lean (the report's signed S1 − S2 is right only when they lean apart).
#[test]
fn e2_share_sequence_increment_uses_absolute_slopes() {
    for (l, r) in [(6.0f64, 8.0f64), (6.0, -8.0), (-6.0, -8.0)] {
        // left edge 1/slope l, right edge 1/slope r, sharing pixels 5..=7
        let (lt, lb) = if l > 0.0 {
            (3.0, 3.0 + l)
        } else {
            (3.0 - l, 3.0)
        };
        let (rt, rb) = if r > 0.0 {
            (4.0, 4.0 + r)
        } else {
            (4.0 - r, 4.0)
        };
        let p = grey(vec![[lt, 0.0], [rt, 0.0], [rb, 1.0], [lb, 1.0]]);
        let c = coverage(&p, 24, 1);
        let increment = c[6] - c[5];
        let corrected = 1.0 / l.abs() - 1.0 / r.abs();
        assert!(
            (increment - corrected).abs() < 1e-12,
            "l {l} r {r}: {increment} vs {corrected}"
        );
        if l.signum() != r.signum() {
            let signed = 1.0 / l - 1.0 / r;
            assert!(
                (increment - signed).abs() > 0.05,
                "signed slopes would match for l {l} r {r}"
            );
        }
    }
}

/// E3 (a formula that survives): the report's Eval3 parameters reproduce
/// (FPi + di·X)(AC + S·X) on the array, for X = 0 … N−1.
#[test]
fn e3_eval3_parameters_are_right() {
    let (fpi, di, ac, s, n) = (0.3125, -0.0390625, 0.15625, 0.1875, 5u32);
    let i = Intensity::grey;
    let instr = Instruction::eval3(
        0,
        n,
        i(fpi * ac),
        i(di * s + di * ac + s * fpi),
        i(2.0 * di * s),
    );
    let h = TraceHeader::new(8, 1, 1).unwrap();
    let (img, _) = run::<f64>(
        &h,
        &[Instruction::acc_mode(), instr, Instruction::refresh()],
        &Machine::default(),
        Timing::Fast,
    )
    .unwrap();
    for x in 0..n as usize {
        let want = (fpi + di * x as f64) * (ac + s * x as f64);
        assert!(
            (img.data[x] - want).abs() < 1e-15,
            "X = {x}: {} vs {want}",
            img.data[x]
        );
    }
}

/// E4: pixel centres are at half-integers (pixel i covers [i, i+1)), not at whole
/// coordinates (the report's figure 9): a point-sampled span from x = 2.5 to 5.5 covers
/// pixels 2, 3, 4 — with centres on whole coordinates it would be 3, 4, 5.
#[test]
fn e4_pixel_centres_are_at_half_integers() {
    let s = ScreenScene {
        width: 8,
        height: 1,
        channels: 1,
        polygons: vec![grey(vec![[2.5, 0.0], [5.5, 0.0], [5.5, 1.0], [2.5, 1.0]])],
    };
    let (img, _) = render(
        &s,
        &Options {
            shading: Shading::Flat,
            aa: Antialias::None,
            ..Default::default()
        },
    );
    assert_eq!(img, [0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]);
}
