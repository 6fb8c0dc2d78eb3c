//! The emitted instruction stream of every named fixture, as reviewed snapshots: one
//! trapezium row per DO_FILL case (tests/fixtures/caseNN.json) and the three triangles
//! of the report's figure 25.

mod common;

use common::{fixture, render, text};
use cwisim_ypipe::exact::scene_coverage;
use cwisim_ypipe::{Antialias, Options, Shading};

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
        insta::assert_snapshot!(name, text(&scene, &Options::default()));
    }
}

#[test]
fn figure_25_pairs_edges_by_identifier() {
    let scene = fixture("fig25.json");
    insta::assert_snapshot!("fig25", text(&scene, &Options::default()));
    // With the AET grouped by Identifier every trapezium is filled between its own two
    // edges, so with intensity 1 the image is exactly the triangles' coverage. (Sorted on
    // Xmax alone, row 6 would pair edges of different triangles, as the report shows.)
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
        insta::assert_snapshot!(name, text(&scene, &Options { shading, aa }));
    }
}
