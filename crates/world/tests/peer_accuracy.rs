//! cwisim's box-filtered fill is more exact than every peer rasterizer, on both polygon
//! sets of `benches/peers.rs` at 1024×1024; and every peer is within a sanity ceiling, so
//! that a broken peer setup (a polygon lost, misplaced, or mis-scaled) does not pass as a
//! mere "less exact" peer. The table itself: `examples/peer_accuracy.rs`.

mod peers;

use peers::{accuracy, error, fill, outlines, random, Error, Exact, Mode, Peer};

const SIZE: u32 = 1024;

/// The most a sane peer errs: the largest absolute error per pixel (tiny-skia's 4
/// sub-scanlines err by up to 1/8 per polygon, and overlapping polygons add their errors),
/// and the RMS over the pixels some polygon covers partly. A polygon lost or off by half a
/// pixel errs by 1/2 or more.
const MAX_CEILING: f64 = 0.25;
const EDGE_RMS_CEILING: f64 = 1.0 / 16.0;

fn sane(e: &Error) -> bool {
    e.max < MAX_CEILING && e.edge_rms < EDGE_RMS_CEILING
}

fn check(set: &str, rows: &[peers::Row], modes: usize) {
    let ours = &rows[0];
    assert_eq!(ours.rasterizer, "cwisim");
    let o = ours.error;
    assert!(o.edge_pixels > 10_000, "{set}: {o:?}");
    assert!(o.max <= 1e-9, "{set}: cwisim errs by {o:?}");
    assert_eq!(rows.len(), 1 + Peer::ALL.len() * modes);
    for row in &rows[1..] {
        let e = row.error;
        let who = format!("{set}: {} ({})", row.rasterizer, row.mode);
        assert!(sane(&e), "{who} is beyond the sanity ceiling: {e:?}");
        assert!(
            o.max <= e.max && o.rms <= e.rms && o.edge_rms <= e.edge_rms,
            "{who} is more exact than cwisim: {e:?} against {o:?}"
        );
    }
}

#[test]
fn cwisim_is_more_exact_than_every_peer_on_the_pot() {
    check("pot", &accuracy(&peers::pot(SIZE), true), 2);
}

#[test]
fn cwisim_is_more_exact_than_every_peer_on_random_polygons() {
    check(
        "random",
        &accuracy(&random(SIZE, 200, 0x5EED_CAFE), false),
        1,
    );
}

/// The ceiling catches a broken setup: every peer fed the pot's outlines half a pixel to
/// the right fails it, in both modes (which the pot's disjoint fragments both allow).
#[test]
fn a_misplaced_fill_is_beyond_the_ceiling() {
    let scene = peers::pot(SIZE);
    let exact = Exact::of(&scene);
    let shifted: Vec<Vec<[f64; 2]>> = outlines(&scene)
        .into_iter()
        .map(|v| v.into_iter().map(|p| [p[0] + 0.5, p[1]]).collect())
        .collect();
    for mode in [Mode::PerPolygon, Mode::OnePath] {
        for peer in Peer::ALL {
            let image = fill(peer, mode, &shifted, SIZE, SIZE);
            let e = error(&exact, |k| image.at(k));
            assert!(
                !sane(&e),
                "{} ({}) shifted: {e:?}",
                peer.name(),
                mode.name()
            );
        }
    }
}

/// The array fed in bands of rows (as `cwisim render` on one thread) draws the image it
/// draws fed instruction by instruction, bit for bit, flat and Gouraud, on all three sets.
#[test]
fn bands_of_rows_draw_the_image_instruction_by_instruction_draws() {
    let sets = [
        ("pot", peers::pot(256)),
        ("random", peers::random(256, 60, 0x5EED_CAFE)),
        ("mesh", cwisim_scene::grid::warped_grid(8, 256)),
    ];
    for (name, scene) in &sets {
        for shading in [cwisim_ypipe::Shading::Flat, cwisim_ypipe::Shading::Gouraud] {
            let bits = |v: Vec<f64>| v.into_iter().map(f64::to_bits).collect::<Vec<_>>();
            let one = bits(peers::cwisim_image(scene, shading));
            assert!(one.iter().any(|&b| b != 0), "{name}: something drawn");
            assert_eq!(
                bits(peers::cwisim_image_in_bands(scene, shading)),
                one,
                "{name} {shading:?}"
            );
        }
    }
}
