//! The emitted instruction stream of every named fixture, as reviewed snapshots: one
//! trapezium row per DO_FILL case (tests/fixtures/caseNN.json) and the three triangles
//! of the report's figure 25 (also with `Eval0` claims). Each Gouraud box-filtered
//! stream twice: in the exact mode (`caseNN`, the default `--aa box`) and in the
//! report's (`caseNN_centre`, `--aa box-centre`), with the same instructions but for
//! their operands (`tests/exact_box.rs`).

mod common;

use common::{fixture, render, text};
use cwisim_ypipe::exact::scene_coverage;
use cwisim_ypipe::{Antialias, Claim, Options, Shading};

/// The report's box filter: coverage × the intensity at the pixel centre.
fn centre() -> Options {
    Options {
        aa: Antialias::BoxCentre,
        ..Options::default()
    }
}

#[test]
fn each_of_the_twelve_cases_has_its_fixture_and_stream() {
    for k in 1..=12u8 {
        let name = format!("case{k:02}");
        let scene = fixture(&format!("{name}.json"));
        let (_, stats) = render(&scene, &Options::default());
        assert_eq!(
            stats.cases[usize::from(k) - 1],
            1,
            "{name} must be case {k}: {:?}",
            stats.cases
        );
        assert_eq!(stats.cases.iter().sum::<u64>(), 1, "{name}: one row");
        insta::assert_snapshot!(name.clone(), text(&scene, &Options::default()));
        insta::assert_snapshot!(format!("{name}_centre"), text(&scene, &centre()));
    }
}

#[test]
fn figure_25_pairs_edges_by_identifier() {
    let scene = fixture("fig25.json");
    insta::assert_snapshot!("fig25", text(&scene, &Options::default()));
    insta::assert_snapshot!("fig25_centre", text(&scene, &centre()));
    // With the AET grouped by Identifier every trapezium is filled between its own two
    // edges, so with intensity 1 the image is exactly the triangles' coverage. (Sorted on
    // Xmax alone, the report's figure 26 pairs edges of different triangles:
    // `scan.rs::tests::figure_26_pairs_across_triangles_on_xmax_alone`, in its frame.)
    let mut ones = scene.clone();
    for p in &mut ones.polygons {
        for i in &mut p.intensity {
            i.iter_mut().for_each(|v| *v = 1.0);
        }
    }
    let (img, _) = render(&ones, &Options::default());
    let exact = scene_coverage(&ones);
    let worst = img
        .iter()
        .zip(&exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "worst per-pixel coverage error {worst}");
}

#[test]
fn shading_and_antialiasing_modes_of_case_10() {
    let scene = fixture("case10.json");
    for (shading, aa, name) in [
        (Shading::Flat, Antialias::None, "case10_flat_none"),
        (Shading::Flat, Antialias::Box, "case10_flat_box"),
        (Shading::Gouraud, Antialias::None, "case10_gouraud_none"),
    ] {
        insta::assert_snapshot!(
            name,
            text(
                &scene,
                &Options {
                    shading,
                    aa,
                    ..Default::default()
                }
            )
        );
    }
}

/// Figure 25, Gouraud and box filter, each triangle claiming its fully covered pixels
/// with a staircase of `Eval0`s within 1/512 of the Gouraud value. Reviewed: the claims
/// are the middle parts of full rows and the pixels right of the vertical edge x = 2,
/// never a partially covered pixel (checked below against the exact coverage).
#[test]
fn figure_25_with_eval0_claims() {
    let scene = fixture("fig25.json");
    let options = Options {
        claim: Claim::Eval0 {
            tolerance: 1.0 / 512.0,
        },
        ..Options::default()
    };
    let trace = text(&scene, &options);
    insta::assert_snapshot!("fig25_claim", trace);
    insta::assert_snapshot!(
        "fig25_claim_centre",
        text(
            &scene,
            &Options {
                aa: Antialias::BoxCentre,
                ..options
            }
        )
    );
    let (w, h) = (scene.width as usize, scene.height as usize);
    let mut claimed = vec![0u32; w * h];
    let mut row = 0;
    for line in trace.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("Refresh") => row += 1,
            Some("Eval0") => {
                let x: usize = words.next().unwrap().parse().unwrap();
                let dx: usize = words.next().unwrap().parse().unwrap();
                for p in x..x + dx {
                    claimed[row * w + p] += 1;
                }
            }
            _ => {}
        }
    }
    assert_eq!(row, h);
    let cover: Vec<Vec<f64>> = scene
        .polygons
        .iter()
        .map(|p| cwisim_ypipe::exact::coverage(p, scene.width, scene.height))
        .collect();
    let mut n = 0;
    for k in 0..w * h {
        let full = cover.iter().filter(|c| c[k] >= 1.0 - 1e-12).count() as u32;
        // the triangles do not overlap: a pixel is claimed once if one covers it fully
        assert_eq!(claimed[k], full, "pixel ({}, {})", k % w, k / w);
        n += claimed[k];
    }
    assert!(n > 10, "{n} pixels claimed");
}
