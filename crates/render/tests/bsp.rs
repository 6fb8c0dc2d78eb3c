//! `bsp`, BSP trees displayed in scanline order: its three modes against each other, the
//! S-buffer and `vanrij`'s exact visibility, and its order against depth.

use cwisim_render::bsp::Bsp;
use cwisim_render::cp::{scan_rows, Increment};
use cwisim_render::settings::{BspOrder, Unset};
use cwisim_render::{
    registry, render, ArrayConfig, Counters, LoadedScene, Renderer, Settings, Source,
};
use cwisim_scene::{Antialias, Polygon, ScreenScene, Shading};
use cwisim_world::{AnyScene, Visibility};
use cwisim_xproc::ImageSink;

fn flat_one_sample() -> Settings {
    Settings {
        samples: 1,
        shading: Shading::Flat,
        ..Settings::default()
    }
}

fn loaded(name: &str, s: &Settings) -> LoadedScene {
    Source::resolve(Some(name.as_ref()))
        .unwrap()
        .load_for(s)
        .unwrap()
}

/// Image, counters and the array's suppressed contributions.
fn draw(r: &dyn Renderer) -> (Vec<f64>, Counters, u64) {
    let h = r.header();
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 28);
    let done = render(r, &ArrayConfig::default(), 2, &mut sink, Default::default()).unwrap();
    (
        sink.finish().unwrap().data,
        done.counters,
        done.stats.totals.suppressed,
    )
}

fn by_name(renderer: &str, scene: &str, s: &Settings) -> (Vec<f64>, Counters, u64) {
    draw(&*(registry::find(renderer).unwrap().build)(loaded(scene, s), s).unwrap())
}

/// With and without shadows (every light casting).
#[test]
fn every_mode_draws_what_the_s_buffer_and_exact_visibility_draw() {
    for (scene, shadows) in [
        ("still-life", Some(false)),
        ("pot", None),
        ("still-life", Some(true)),
        ("pot", Some(true)),
    ] {
        let s = Settings {
            shadows,
            ..flat_one_sample()
        };
        let (sbuffer, _, _) = by_name("sbuffer", scene, &s);
        let vr = Settings {
            aa: Antialias::None,
            visibility: Visibility::Exact,
            ..s
        };
        let (vanrij, _, _) = by_name("vanrij", scene, &vr);
        assert_eq!(sbuffer, vanrij, "{scene}");
        let mode = |order, unset| Settings {
            bsp_order: order,
            unset,
            ..s
        };
        let (b2f, bc, _) = by_name("bsp", scene, &mode(BspOrder::BackToFront, Unset::Host));
        let (host, hc, _) = by_name("bsp", scene, &mode(BspOrder::FrontToBack, Unset::Host));
        let (eval0, ec, suppressed) =
            by_name("bsp", scene, &mode(BspOrder::FrontToBack, Unset::Eval0));
        assert_eq!(b2f, sbuffer, "{scene}: back to front");
        assert_eq!(host, sbuffer, "{scene}: front to back, host list");
        assert_eq!(eval0, sbuffer, "{scene}: front to back, Eval0");
        // painter's overwrites; front to back never does
        assert!(bc.get("pixels_overwritten").unwrap() > 0);
        assert_eq!(hc.get("pixels_overwritten"), Some(0));
        // the array's locks suppressed what the host mirror says they would, and something
        let claimed = ec.get("suppressed_claims").unwrap();
        assert!(claimed > 0);
        assert_eq!(suppressed, claimed, "{scene}");
        assert!(
            hc.get("instructions").unwrap() <= ec.get("instructions").unwrap(),
            "{scene}: host {:?} eval0 {:?}",
            hc.get("instructions"),
            ec.get("instructions")
        );
        assert!(bc.get("bsp_splits").unwrap() > 0);
        assert_eq!(
            bc.get("polygons").unwrap(),
            bc.get("bsp_triangles").unwrap() + bc.get("bsp_splits").unwrap()
        );
    }
}

#[test]
fn the_order_never_contradicts_depth_where_pieces_overlap() {
    for scene in ["still-life", "pot"] {
        let s = flat_one_sample();
        let bsp = Bsp::new(loaded(scene, &s), &s).unwrap();
        let h = bsp.header();
        let (pieces, rank) = bsp.pieces();
        // per pixel: (rank, depth key) of every piece covering its centre
        let mut cover: Vec<Vec<(u32, f64)>> = vec![Vec::new(); (h.width * h.lines) as usize];
        for (k, p) in pieces.iter().enumerate() {
            let (rows, _) = scan_rows(&p.cp, h.width, h.lines, Increment::Direct);
            for (r, spans) in rows.iter().enumerate() {
                for &(a, b) in spans {
                    for x in a..b {
                        let key = p.key(f64::from(x) + 0.5, r as f64 + 0.5);
                        cover[r * h.width as usize + x as usize].push((rank[k], key));
                    }
                }
            }
        }
        let mut overlaps = 0;
        for (i, c) in cover.iter_mut().enumerate() {
            c.sort_by_key(|e| e.0);
            for w in c.windows(2) {
                overlaps += 1;
                // front to back: an earlier piece is no farther (keys: −1/depth)
                let tol = 1e-9 * w[0].1.abs().max(w[1].1.abs());
                assert!(
                    w[0].1 <= w[1].1 + tol,
                    "{scene}, pixel {i}: rank {} key {} before rank {} key {}",
                    w[0].0,
                    w[0].1,
                    w[1].0,
                    w[1].1
                );
            }
        }
        assert!(overlaps > 1000, "{scene}: {overlaps}");
    }
}

#[test]
fn screen_scenes_are_triangulated_and_ordered_by_depth() {
    // two squares crossing in depth: each is nearer over half of the other
    let scene = ScreenScene {
        width: 16,
        height: 8,
        channels: 1,
        polygons: vec![
            Polygon::uniform(
                vec![[0.0, 0.0], [12.0, 0.0], [12.0, 8.0], [0.0, 8.0]],
                &[0.25],
            )
            .with_depth(vec![0.0, 12.0, 12.0, 0.0]),
            Polygon::uniform(
                vec![[4.0, 0.0], [16.0, 0.0], [16.0, 8.0], [4.0, 8.0]],
                &[0.5],
            )
            .with_depth(vec![10.0, 2.0, 2.0, 10.0]),
        ],
    };
    let s = flat_one_sample();
    let built = || LoadedScene::built("crossing", AnyScene::Screen(scene.clone()));
    let (sb, _, _) = draw(&*(registry::find("sbuffer").unwrap().build)(built(), &s).unwrap());
    for (order, unset) in [
        (BspOrder::BackToFront, Unset::Host),
        (BspOrder::FrontToBack, Unset::Host),
        (BspOrder::FrontToBack, Unset::Eval0),
    ] {
        let m = Settings {
            bsp_order: order,
            unset,
            ..s
        };
        let (b, c, _) = draw(&*Bsp::build(built(), &m).unwrap());
        assert_eq!(b, sb, "{order} {unset}");
        assert!(c.get("bsp_splits").unwrap() > 0);
    }
    // the crossing sits at x = 7.6: left of it the first square, right the second
    assert_eq!(
        &sb[..16],
        &[0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]
    );
}

#[test]
fn eval0_is_refused_where_it_is_not_exact() {
    let m = Settings {
        unset: Unset::Eval0,
        ..flat_one_sample()
    };
    let e = Bsp::new(
        loaded("pot", &m),
        &Settings {
            shading: Shading::Gouraud,
            ..m
        },
    )
    .err()
    .unwrap();
    assert!(e.to_string().contains("--shading flat"), "{e}");
    let e = Bsp::new(loaded("pot", &m), &Settings { samples: 3, ..m })
        .err()
        .unwrap();
    assert!(e.to_string().contains("one sample per pixel"), "{e}");
}

#[test]
fn gouraud_and_supersampling_match_the_s_buffer() {
    for samples in [1, 2] {
        let s = Settings {
            samples,
            ..Settings::default()
        };
        let (sb, _, _) = by_name("sbuffer", "pot", &s);
        let (b, _, _) = by_name("bsp", "pot", &s);
        let worst = sb
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        // split pieces interpolate the same Gouraud function: rounding only
        assert!(worst < 1e-9, "samples {samples}: {worst}");
    }
}

/// Phong at one sample is lit per pixel in every order: front to back too (whose unset
/// list hands its runs out while it fills, before the line is lit) — within the span
/// fitter's tolerance of the S-buffer's, as both are of the per-pixel shade. (It once
/// sent each run at its polygon's flat value: 0.04 off.)
#[test]
fn phong_is_lit_per_pixel_in_every_order() {
    for scene in ["pot", "bowl"] {
        let s = Settings {
            samples: 1,
            shading: Shading::Phong,
            ..Settings::default()
        };
        let (sbuffer, _, _) = by_name("sbuffer", scene, &s);
        for order in [BspOrder::FrontToBack, BspOrder::BackToFront] {
            let (bsp, _, _) = by_name(
                "bsp",
                scene,
                &Settings {
                    bsp_order: order,
                    ..s
                },
            );
            let worst = bsp
                .iter()
                .zip(&sbuffer)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                worst <= 2.0 * s.shade_tolerance + 1e-12,
                "{scene} {order:?}: {worst}"
            );
        }
    }
}
