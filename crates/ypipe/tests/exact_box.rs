//! The exact box filter (`--aa box`): every pixel, executed on the array, within 1e-9
//! of the independent exact reference (`exact::scene_box_filtered`), with the same
//! instructions (count, opcodes, ranges) as the report's mode (`--aa box-centre`) on the
//! same input. Intensities are planar over each polygon (a linear function of the vertex
//! positions, per channel): what triangles and the fragments of exact visibility carry.

mod common;

use common::{fixture, instructions, render, render_run};
use cwisim_isa::{Instruction, Opcode};
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_ypipe::exact::scene_box_filtered;
use cwisim_ypipe::{Antialias, Claim, Options, Shading};
use proptest::prelude::*;

fn mode(aa: Antialias) -> Options {
    Options {
        aa,
        ..Options::default()
    }
}

/// `v` with, per channel `c`, the intensity `a + bx·x + by·y` of `planes[c]`, raised so
/// that the smallest vertex value is `floor`.
fn planar(v: Vec<[f64; 2]>, planes: &[[f64; 3]], floor: f64) -> Polygon {
    let at = |p: &[f64; 2], f: &[f64; 3]| f[0] + f[1] * p[0] + f[2] * p[1];
    let lift: Vec<f64> = planes
        .iter()
        .map(|f| floor - v.iter().map(|p| at(p, f)).fold(f64::INFINITY, f64::min))
        .collect();
    let intensity = v
        .iter()
        .map(|p| {
            planes
                .iter()
                .zip(&lift)
                .map(|(f, l)| at(p, f) + l)
                .collect()
        })
        .collect::<Vec<Vec<f64>>>();
    Polygon::new(v, intensity)
}

fn scene(width: u32, height: u32, channels: u8, polygons: Vec<Polygon>) -> ScreenScene {
    ScreenScene {
        width,
        height,
        channels,
        polygons,
    }
}

/// The largest per-value difference between the array's image in `options` and the
/// exact box filter.
fn max_error(s: &ScreenScene, options: &Options) -> f64 {
    let (img, _) = render(s, options);
    img.iter()
        .zip(scene_box_filtered(s))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Every value within 1e-9 of the exact box filter, nothing dropped as negative.
fn check_exact(s: &ScreenScene) -> Result<(), TestCaseError> {
    let (img, run) = render_run(s, &Options::default());
    let exact = scene_box_filtered(s);
    let (w, ch) = (s.width as usize, usize::from(s.channels));
    for (k, (a, b)) in img.iter().zip(&exact).enumerate() {
        prop_assert!(
            (a - b).abs() <= 1e-9,
            "pixel ({}, {}) channel {}: simulated {a}, exact {b}",
            (k / ch) % w,
            k / ch / w,
            k % ch
        );
    }
    prop_assert_eq!(
        run.totals.dropped_negative,
        0,
        "negative contributions dropped"
    );
    Ok(())
}

/// The two modes send the same instructions but for their operands: opcode, `x` and
/// `dx`, one for one.
fn check_same_instructions(s: &ScreenScene) -> Result<(), TestCaseError> {
    let exact = instructions(s, &mode(Antialias::Box));
    let centre = instructions(s, &mode(Antialias::BoxCentre));
    prop_assert_eq!(exact.len(), centre.len(), "instruction count");
    for (k, (a, b)) in exact.iter().zip(&centre).enumerate() {
        prop_assert_eq!(
            (a.op, a.x, a.dx),
            (b.op, b.x, b.dx),
            "instruction {}: {:?} vs {:?}",
            k,
            a,
            b
        );
    }
    Ok(())
}

fn check(s: &ScreenScene) -> Result<(), TestCaseError> {
    check_exact(s)?;
    check_same_instructions(s)
}

/// A star-shaped (so simple), possibly concave polygon around a centre.
fn star(cx: f64, cy: f64, radii: &[f64], phase: f64, reverse: bool) -> Vec<[f64; 2]> {
    let n = radii.len();
    let mut v: Vec<[f64; 2]> = radii
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let a = phase + std::f64::consts::TAU * k as f64 / n as f64;
            [cx + r * a.cos(), cy + r * a.sin()]
        })
        .collect();
    if reverse {
        v.reverse();
    }
    v
}

fn coordinate(limit: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -3.0..limit + 3.0,
        // on pixel edges and centres
        1 => (-2i32..(limit as i32 + 2)).prop_map(f64::from),
        1 => (-2i32..(limit as i32 + 2)).prop_map(|v| f64::from(v) + 0.5),
    ]
}

/// Per channel a plane with gradients up to 0.5 per pixel.
fn planes(channels: usize) -> impl Strategy<Value = Vec<[f64; 3]>> {
    proptest::collection::vec(
        (0.0f64..1.0, -0.5f64..0.5, -0.5f64..0.5).prop_map(|(a, b, c)| [a, b, c]),
        channels,
    )
}

fn non_degenerate(v: &[[f64; 2]]) -> bool {
    let det = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
    det.abs() > 1e-6
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Triangles anywhere (partly or wholly off the image too), grey or RGB.
    #[test]
    fn triangles_are_exact_with_the_same_instructions(
        v in proptest::collection::vec((coordinate(24.0), coordinate(16.0)), 3),
        f in prop_oneof![planes(1), planes(3)],
        floor in 0.0f64..0.5,
    ) {
        let v: Vec<[f64; 2]> = v.into_iter().map(|(x, y)| [x, y]).collect();
        prop_assume!(non_degenerate(&v));
        let ch = f.len() as u8;
        check(&scene(24, 16, ch, vec![planar(v, &f, floor)]))?;
    }

    /// Concave polygons of either orientation: several trapezia per row.
    #[test]
    fn concave_polygons_are_exact_with_the_same_instructions(
        cx in 2.0f64..22.0, cy in 2.0f64..14.0,
        radii in proptest::collection::vec(0.3f64..11.0, 3..12),
        phase in 0.0f64..6.3, reverse in any::<bool>(),
        f in planes(3), floor in 0.0f64..0.5,
    ) {
        let v = star(cx, cy, &radii, phase, reverse);
        check(&scene(24, 16, 3, vec![planar(v, &f, floor)]))?;
    }

    /// Slivers (flat and steep), sub-pixel triangles and steep gradients.
    #[test]
    fn slivers_and_sub_pixel_triangles_are_exact(
        x in 0.0f64..30.0, y in 0.0f64..20.0,
        len in 0.05f64..28.0, angle in 0.0f64..6.3, width in 0.01f64..0.6,
        f in planes(1), steep in 1.0f64..8.0,
    ) {
        let (dx, dy) = (len * angle.cos(), len * angle.sin());
        let (nx, ny) = (-angle.sin() * width, angle.cos() * width);
        let v = vec![[x, y], [x + dx, y + dy], [x + 0.5 * dx + nx, y + 0.5 * dy + ny]];
        let f: Vec<[f64; 3]> = f.iter().map(|p| [p[0], p[1] * steep, p[2] * steep]).collect();
        check(&scene(32, 20, 1, vec![planar(v, &f, 0.0)]))?;
    }
}

/// The twelve DO_FILL cases of the fixtures, their geometry with planar RGB
/// intensities (the fixtures' own intensities are not planar: see
/// `non_planar_intensities_are_not_exact`), and figure 25 as it is (its triangles are).
#[test]
fn the_twelve_cases_and_figure_25_are_exact_with_the_same_instructions() {
    let f = [[0.1, 0.06, 0.4], [0.9, -0.05, 0.0], [0.2, 0.0, -0.3]];
    for k in 1..=12u8 {
        let base = fixture(&format!("case{k:02}.json"));
        let polygons = base
            .polygons
            .iter()
            .map(|p| planar(p.vertices.clone(), &f, 0.05))
            .collect();
        let s = scene(base.width, base.height, 3, polygons);
        let (_, stats) = render(&s, &Options::default());
        assert_eq!(
            stats.cases[usize::from(k) - 1],
            1,
            "case {k}: {:?}",
            stats.cases
        );
        check(&s).unwrap_or_else(|e| panic!("case {k}: {e}"));
        let centre = max_error(&s, &mode(Antialias::BoxCentre));
        assert!(
            centre > 1e-4,
            "case {k}: the report's mode is off by {centre}"
        );
    }
    let fig25 = fixture("fig25.json");
    check(&fig25).unwrap();
    assert!(max_error(&fig25, &mode(Antialias::BoxCentre)) > 0.05);
}

/// The case-12 fixture, whose report-mode stream starts with negative values (the
/// intensity at pixel centres outside the thin polygon, extrapolated): none in the exact
/// mode, and nothing dropped by the array; the image is the exact one.
#[test]
fn the_case_12_fixture_has_no_negative_values_in_the_exact_mode() {
    let s = fixture("case12.json");
    assert!(s.polygons[0].intensity.iter().flatten().all(|&i| i >= 0.0));
    let values = |aa| -> Vec<f64> {
        let mut out = Vec::new();
        for i in instructions(&s, &mode(aa)) {
            // every value the wave accumulates
            if !matches!(i.op, Opcode::Eval1 | Opcode::Eval2 | Opcode::Eval3) {
                continue;
            }
            let (mut v, mut d, mut dd) = (i.i().as_slice()[0], 0.0, 0.0);
            match i.op {
                Opcode::Eval2 => d = i.di().as_slice()[0],
                Opcode::Eval3 => {
                    d = i.di().as_slice()[0];
                    dd = i.ddi().as_slice()[0];
                }
                _ => {}
            }
            for _ in 0..i.dx {
                out.push(v);
                v += d;
                d += dd;
            }
        }
        out
    };
    let centre = values(Antialias::BoxCentre);
    assert!(
        centre.iter().any(|&v| v < 0.0),
        "the report's mode: {centre:?}"
    );
    let exact = values(Antialias::Box);
    assert!(exact.iter().all(|&v| v >= 0.0), "the exact mode: {exact:?}");
    let (_, run) = render_run(&s, &mode(Antialias::BoxCentre));
    assert!(run.totals.dropped_negative > 0);
    check_exact(&s).unwrap();
}

/// Where the intensity changes down the rows but not along them, the report's
/// sequences are `Eval2`s (its centre values are linear in the pixel index) and the
/// exact ones `Eval3`s: the one place the opcode mix differs, at the same count and
/// ranges.
#[test]
fn an_intensity_flat_along_the_rows_needs_eval3_for_its_sequences() {
    let s = scene(
        20,
        8,
        1,
        vec![planar(
            vec![[1.0, 0.5], [18.5, 2.25], [3.25, 7.5]],
            &[[0.0, 0.0, 0.1]],
            0.2,
        )],
    );
    check_exact(&s).unwrap();
    let exact = instructions(&s, &mode(Antialias::Box));
    let centre = instructions(&s, &mode(Antialias::BoxCentre));
    assert_eq!(exact.len(), centre.len());
    let mut swapped = 0;
    for (a, b) in exact.iter().zip(&centre) {
        assert_eq!((a.x, a.dx), (b.x, b.dx));
        if a.op != b.op {
            assert_eq!(
                (a.op, b.op),
                (Opcode::Eval3, Opcode::Eval2),
                "{a:?} vs {b:?}"
            );
            swapped += 1;
        }
    }
    assert!(swapped > 0, "a shallow edge's sequences");
}

/// With flat shading, or constant intensities, the two modes are one: the same stream.
#[test]
fn flat_shading_is_the_same_stream_in_both_modes() {
    for name in ["case05.json", "case10.json", "fig25.json"] {
        let s = fixture(name);
        let flat = |aa| Options {
            shading: Shading::Flat,
            aa,
            ..Options::default()
        };
        assert_eq!(
            instructions(&s, &flat(Antialias::Box)),
            instructions(&s, &flat(Antialias::BoxCentre)),
            "{name}"
        );
    }
    let grey = scene(
        16,
        8,
        1,
        vec![planar(
            vec![[1.5, 0.5], [14.0, 3.0], [4.0, 7.5]],
            &[[0.5, 0.0, 0.0]],
            0.5,
        )],
    );
    assert_eq!(
        instructions(&grey, &mode(Antialias::Box)),
        instructions(&grey, &mode(Antialias::BoxCentre))
    );
}

/// With `Eval0` claims the exact mode claims the same pixels; the rest stay exact.
#[test]
fn claims_keep_the_instruction_shapes() {
    let s = fixture("fig25.json");
    let claim = |aa| Options {
        aa,
        claim: Claim::Eval0 { tolerance: 0.0 },
        ..Options::default()
    };
    let a: Vec<Instruction> = instructions(&s, &claim(Antialias::Box));
    let b: Vec<Instruction> = instructions(&s, &claim(Antialias::BoxCentre));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.op, x.x, x.dx), (y.op, y.x, y.dx));
        if x.op == Opcode::Eval0 {
            assert_eq!(x, y, "a claim holds the centre value in both modes");
        }
    }
}

/// The limit of the mode: a quadrilateral whose vertex intensities lie on no plane has a
/// scanline Gouraud function that is rational, not affine, within a row; the exact mode
/// integrates the row's affine approximation exactly, and is off the true box filter
/// by far less than the report's mode, but not to 1e-9.
#[test]
fn non_planar_intensities_are_not_exact() {
    let s = fixture("case05.json");
    let exact = max_error(&s, &mode(Antialias::Box));
    let centre = max_error(&s, &mode(Antialias::BoxCentre));
    assert!(exact > 1e-9, "{exact}");
    assert!(exact < centre, "exact mode {exact}, report's {centre}");
}
