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
        intensity: vec![vec![1.0].into(); n],
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

/// E2 (a clarification): in a run of pixels cut by both edges, coverage changes by
/// 1/|1/slope_left| − 1/|1/slope_right| (E1's factor fixed). Only edges that lean the
/// same way share pixels (on a simple polygon, edges leaning apart overlap in x in at most
/// a point), and for them the report's signed `S1 − S2` of its 1/slope fields (y up:
/// `(bottom_x − top_x)/(bottom_y − top_y)`) is right when both fields are positive and
/// of the wrong sign when both are negative — which its "case B … divide −1" corrects.
/// So cwisim's absolute form equals the report with case B read as "both fields
/// negative", and differs from the procedure as defined without it. Simple polygons only.
#[test]
fn e2_share_sequence_increment_is_the_report_s_with_case_b() {
    // (polygon, its left and right edges' report fields, the pixels both edges cut)
    type Case = (Vec<[f64; 2]>, f64, f64, std::ops::Range<usize>);
    let cases: [Case; 3] = [
        // edges running down to the right (y down): both fields negative
        (
            vec![[3.0, 0.0], [4.0, 0.0], [12.0, 1.0], [9.0, 1.0]],
            -6.0,
            -8.0,
            5..8,
        ),
        // the control: both running down to the left, both fields positive
        (
            vec![[9.0, 0.0], [12.0, 0.0], [4.0, 1.0], [3.0, 1.0]],
            6.0,
            8.0,
            5..8,
        ),
        // a triangle with a shared apex row
        (vec![[0.0, 0.0], [1.0, 0.0], [5.0, 1.0]], -5.0, -4.0, 2..4),
    ];
    for (vertices, left, right, run) in cases {
        let p = grey(vertices.clone());
        let c = coverage(&p, 16, 1);
        let absolute = 1.0 / left.abs() - 1.0 / right.abs();
        let signed = 1.0 / left - 1.0 / right;
        let case_b = if left < 0.0 && right < 0.0 {
            -signed
        } else {
            signed
        };
        for k in run.start..run.end - 1 {
            let increment = c[k + 1] - c[k];
            assert!(
                (increment - absolute).abs() < 1e-12,
                "{vertices:?} pixel {k}: {increment} vs {absolute}"
            );
            assert!((case_b - absolute).abs() < 1e-15);
            // the procedure as defined, without case B, is wrong exactly when both
            // fields are negative
            assert_eq!(
                (increment - signed).abs() > 0.05,
                left < 0.0 && right < 0.0,
                "{vertices:?}: signed {signed} against {increment}"
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
