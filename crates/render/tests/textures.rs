//! Textures through the array, held to references that share no code with the texture
//! module, the shader or the span fitter: the area-weighted sum of texels over a pixel's
//! preimage (worked out here from the pinhole camera's formula), and a ray cast from the
//! camera through every pixel centre with the texel under the hit looked up again here.

use cwisim_render::Settings;
use cwisim_scene::{Antialias, Shading};
use cwisim_world::texture::TextureFilter;
use cwisim_world::{AnyScene, WorldScene};
use std::path::{Path, PathBuf};

mod common;
use common::raycast::{hits, ray};
use common::rendered;

const TW: usize = 13;
const TH: usize = 11;

/// Texel `(i, j)` (row `j` from the bottom) of the test image: every one different.
fn texel(i: usize, j: usize) -> f64 {
    ((i * 37 + j * 101 + 11) % 256) as f64 / 255.0
}

/// A directory of its own with the test texture `t.png` (`TW × TH`, grey).
fn texture_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cwisim-textures-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let img = image::GrayImage::from_fn(TW as u32, TH as u32, |x, y| {
        // image row y counts from the top
        image::Luma([(texel(x as usize, TH - 1 - y as usize) * 255.0).round() as u8])
    });
    img.save(dir.join("t.png")).unwrap();
    dir
}

/// A square of half-size `a` in the plane z = 0, turned `tilt` degrees about x, textured
/// with `t.png` (`u` along x, `v` along y), lit by ambient light alone (`k_a` 1): a pixel
/// shows the texture's value itself.
fn square(dir: &Path, size: u32, a: f64, tilt: f64) -> WorldScene {
    let text = format!(
        r#"{{ "kind": "world", "width": {size}, "height": {size}, "channels": 1,
  "camera": {{ "eye": [0, 0, 10], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 30 }},
  "ambient": 1,
  "meshes": [ {{
    "material": {{ "k_a": 1, "k_d": 0, "k_s": 0, "n": 1, "texture": {{ "image": "t.png" }} }},
    "transform": {{ "rotate": [{tilt}, 0, 0] }},
    "vertices": [[-{a}, -{a}, 0], [{a}, -{a}, 0], [{a}, {a}, 0], [-{a}, {a}, 0]],
    "uv": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "faces": [[0, 1, 2, 3]] }} ] }}"#
    );
    let base = dir.to_path_buf();
    match cwisim_world::parse_any(&text, Some(&base)).unwrap() {
        AnyScene::World(w) => w,
        AnyScene::Screen(_) => unreachable!(),
    }
}

/// What the ray cast finds under a hit `h` of mesh 0: its `(u, v)` (from the hit's world
/// barycentrics and the corners' `(u, v)`) and the test texture's texel there, as the
/// 8-bit PNG holds it; `None` within 1e-6 texel of a texel's edge, where rounding decides.
fn texel_under(w: &WorldScene, h: &common::raycast::Hit) -> Option<([f64; 2], f64)> {
    let face = &w.meshes[0].faces[h.face];
    let uv = [0, 1].map(|a| {
        (0..3)
            .map(|k| h.bary[k] * face.uv[h.corners[k]][a])
            .sum::<f64>()
    });
    let (tx, ty) = (uv[0] * TW as f64, uv[1] * TH as f64);
    let near_edge = |t: f64| (t - t.round()).abs() < 1e-6;
    if near_edge(tx) || near_edge(ty) {
        return None;
    }
    let want = texel(
        (tx.floor() as usize).min(TW - 1),
        (ty.floor() as usize).min(TH - 1),
    );
    Some((uv, (want * 255.0).round() / 255.0))
}

fn settings(shading: Shading, aa: Antialias, filter: TextureFilter) -> Settings {
    Settings {
        shading,
        aa,
        texture_filter: filter,
        shade_tolerance: 0.0,
        ..Settings::default()
    }
}

/// The mean of the test texture over `[u0, u1] × [v0, v1]`: each texel cell's area
/// inside it, times its value.
fn area_weighted(u0: f64, u1: f64, v0: f64, v1: f64) -> f64 {
    let (x0, x1) = (u0 * TW as f64, u1 * TW as f64);
    let (y0, y1) = (v0 * TH as f64, v1 * TH as f64);
    let mut sum = 0.0;
    for j in 0..TH {
        for i in 0..TW {
            let ox = (x1.min(i as f64 + 1.0) - x0.max(i as f64)).max(0.0);
            let oy = (y1.min(j as f64 + 1.0) - y0.max(j as f64)).max(0.0);
            sum += ox * oy * texel(i, j);
        }
    }
    sum / ((x1 - x0) * (y1 - y0))
}

#[test]
fn the_box_filter_of_a_square_facing_the_camera_is_the_area_weighted_sum_of_its_texels() {
    let dir = texture_dir("box");
    let (size, a) = (64u32, 2.0);
    let w = square(&dir, size, a, 0.0);
    for shading in [Shading::Flat, Shading::Gouraud, Shading::Phong] {
        let aa = if shading == Shading::Phong {
            Antialias::BoxCentre
        } else {
            Antialias::Box
        };
        let image = rendered(&w, &settings(shading, aa, TextureFilter::Box));
        // the square at depth 10: x_screen = W/2 + F·x/10, y_screen = H/2 − F·y/10
        let focal = 0.5 * f64::from(size) / 15f64.to_radians().tan();
        let to_u = |x: f64| ((x - 0.5 * f64::from(size)) * 10.0 / focal + a) / (2.0 * a);
        let to_v = |y: f64| ((0.5 * f64::from(size) - y) * 10.0 / focal + a) / (2.0 * a);
        let mut checked = 0;
        for py in 0..size as usize {
            for px in 0..size as usize {
                let (u0, u1) = (to_u(px as f64), to_u(px as f64 + 1.0));
                let (v0, v1) = (to_v(py as f64 + 1.0), to_v(py as f64));
                // pixels wholly on the square
                if !(u0 > 0.0 && u1 < 1.0 && v0 > 0.0 && v1 < 1.0) {
                    continue;
                }
                let want = area_weighted(u0, u1, v0, v1);
                let got = image[py * size as usize + px];
                assert!(
                    (got - want).abs() < 1e-9,
                    "{shading:?} pixel ({px}, {py}): {got} against {want}"
                );
                checked += 1;
            }
        }
        assert!(checked > 1500, "{checked} pixels checked");
    }
}

#[test]
fn point_sampling_is_perspective_correct_against_a_ray_cast() {
    let dir = texture_dir("point");
    let size = 64u32;
    let w = square(&dir, size, 3.0, -62.0);
    let image = rendered(
        &w,
        &settings(Shading::Gouraud, Antialias::None, TextureFilter::Point),
    );
    let (mut checked, mut affine_would_differ) = (0, 0);
    for py in 0..size as usize {
        for px in 0..size as usize {
            let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
            let (o, d) = ray(&w, size, size, x, y);
            let Some(h) = hits(&w, o, d).into_iter().next() else {
                continue;
            };
            if h.margin < 1e-6 {
                continue;
            }
            assert_eq!(h.mesh, 0);
            let Some((uv, want)) = texel_under(&w, &h) else {
                continue;
            };
            let got = image[py * size as usize + px];
            assert!(
                (got - want).abs() < 1e-12,
                "pixel ({px}, {py}): {got} against the ray cast's {want} (u, v = {uv:?})"
            );
            checked += 1;
            // the screen-affine (u, v) would land elsewhere on many pixels: the test tells
            // perspective-correct from affine interpolation
            if (uv[1] - affine_v(&w, size, y)).abs() * TH as f64 > 0.5 {
                affine_would_differ += 1;
            }
        }
    }
    assert!(checked > 800, "{checked} pixels checked");
    assert!(affine_would_differ > 100, "{affine_would_differ}");
}

/// `v` at screen row `y` if it were interpolated affinely on the screen between the
/// square's near and far edges (what a renderer without perspective correction does).
fn affine_v(w: &WorldScene, size: u32, y: f64) -> f64 {
    let c = &w.spec.camera;
    let focal = 0.5 * f64::from(size) / (0.5 * c.fov_y.to_radians()).tan();
    let row = |p: glam::DVec3| 0.5 * f64::from(size) - focal * p.y / (10.0 - p.z);
    let m = &w.meshes[0];
    // corners 0 (v = 0) and 3 (v = 1)
    let (y0, y1) = (row(m.positions[0]), row(m.positions[3]));
    (y - y0) / (y1 - y0)
}

#[test]
fn a_texture_of_ones_changes_nothing_of_phong_shading() {
    // a checker whose squares are both 1 multiplies by 1: Phong with and without it
    let lit = |texture: &str| {
        let text = cwisim_world::embedded::embedded("teapot")
            .unwrap()
            .text
            .replace(
                r#""material": { "k_a": 0.4, "k_d": 0.7, "k_s": 0.5, "n": 24 }"#,
                &format!(
                    r#""material": {{ "k_a": 0.4, "k_d": 0.7, "k_s": 0.5, "n": 24{texture} }}"#
                ),
            );
        let w = common::world(&text, Some((96, 96)))
            .with_tessellation(3)
            .unwrap();
        rendered(
            &w,
            &settings(Shading::Phong, Antialias::BoxCentre, TextureFilter::Box),
        )
    };
    let plain = lit("");
    let ones = lit(r#", "texture": { "checker": { "squares": [3, 5], "dark": 1, "light": 1 } }"#);
    assert_eq!(plain.len(), ones.len());
    let worst = plain
        .iter()
        .zip(&ones)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst}");
    assert!(plain.iter().any(|&v| v > 0.1));
}

#[test]
fn the_box_filter_comes_closer_than_point_sampling_to_the_true_mean_over_a_pixel() {
    // a checkerboard floor receding to the horizon, 16 × 16 rays per pixel (the docs'
    // table takes 64 × 64: crates/render/examples/texture_filter.rs)
    use common::footprint::{errors, floor, reference};
    let size = 40;
    let w = floor(size);
    let truth = reference(&w, size, 16);
    let measure = |filter| {
        let aa = Antialias::Box;
        errors(&rendered(&w, &settings(Shading::Flat, aa, filter)), &truth)
    };
    let (box_rms, box_max, n) = measure(TextureFilter::Box);
    let (point_rms, point_max, _) = measure(TextureFilter::Point);
    assert!(n > 400, "{n} pixels");
    assert!(
        box_rms < 0.5 * point_rms,
        "box {box_rms} against point {point_rms}"
    );
    assert!(
        box_max < point_max,
        "box {box_max} against point {point_max}"
    );
}

#[test]
fn point_filtered_pixels_split_by_a_shared_edge_read_the_texel_under_their_centre() {
    // the square's two triangles share its diagonal; a pixel the diagonal crosses is in
    // parts, each of its own triangle, and must still show the one texel under its centre
    // (issue 53: each part read its own, up to 0.31 off), as a ray cast finds it
    let dir = texture_dir("point-seam");
    let size = 64u32;
    let w = square(&dir, size, 3.0, -40.0);
    for shading in [Shading::Flat, Shading::Gouraud] {
        let image = rendered(&w, &settings(shading, Antialias::Box, TextureFilter::Point));
        let (mut checked, mut split) = (0, 0);
        for py in 0..size as usize {
            for px in 0..size as usize {
                // wholly on the square: its four corners' rays hit it, clear of its rim
                let corners: Vec<_> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
                    .iter()
                    .map(|&(dx, dy)| {
                        let (o, d) = ray(&w, size, size, px as f64 + dx, py as f64 + dy);
                        hits(&w, o, d).into_iter().next()
                    })
                    .collect();
                if corners.iter().any(|h| h.is_none()) {
                    continue;
                }
                let (o, d) = ray(&w, size, size, px as f64 + 0.5, py as f64 + 0.5);
                let Some(h) = hits(&w, o, d).into_iter().next() else {
                    continue;
                };
                if h.margin.abs() < 1e-9 {
                    continue;
                }
                let Some((_, want)) = texel_under(&w, &h) else {
                    continue;
                };
                let got = image[py * size as usize + px];
                assert!(
                    (got - want).abs() < 1e-9,
                    "{shading:?} pixel ({px}, {py}): {got} against the ray cast's {want}"
                );
                checked += 1;
                let triangles = corners
                    .iter()
                    .flatten()
                    .map(|h| h.corners)
                    .collect::<Vec<_>>();
                if triangles.iter().any(|c| *c != triangles[0]) {
                    split += 1;
                }
            }
        }
        assert!(checked > 1000, "{checked} pixels checked");
        assert!(split > 30, "{split} pixels split by the diagonal checked");
    }
}

/// An embedded scene at `size`.
fn embedded(name: &str, size: (u32, u32)) -> WorldScene {
    common::world(
        cwisim_world::embedded::embedded(name).unwrap().text,
        Some(size),
    )
}

#[test]
fn woo_chall_at_one_sample_draws_what_vanrij_draws_point_sampled() {
    for (name, size) in [("textures4", (80, 60)), ("teapot-textured", (64, 64))] {
        let w = embedded(name, size);
        for shading in [Shading::Gouraud, Shading::Phong] {
            let point = Settings {
                samples: 1,
                ..settings(shading, Antialias::None, TextureFilter::Point)
            };
            let vanrij = rendered(&w, &point);
            let woo = common::rendered_by("woo-chall", &w, &point);
            let worst = vanrij
                .iter()
                .zip(&woo)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-9, "{name} {shading:?}: {worst}");
        }
    }
}

#[test]
fn woo_chall_loads_four_textures_into_memory_for_three() {
    use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Taps};
    let w = embedded("textures4", (200, 150));
    let loaded = LoadedScene::built("textures4", AnyScene::World(w));
    let r = (registry::find("woo-chall").unwrap().build)(loaded, &Settings::default()).unwrap();
    let mut sink = cwisim_xproc::ImageSink::new(200, 3, 1 << 30);
    let done = render(&*r, &ArrayConfig::default(), 1, &mut sink, Taps::default()).unwrap();
    let c = |n: &str| done.counters.get(n);
    assert_eq!(c("textures"), Some(4));
    assert_eq!(c("texture_loads"), Some(4));
    assert_eq!(c("texture_frees"), Some(4));
    assert_eq!(c("textures_peak"), Some(3));
    // per row: none above the pictures, three where the vase meets them, none at the end
    let rows = done.row_figures[0].as_array().unwrap();
    let resident: Vec<u64> = rows
        .iter()
        .map(|r| r["textures_resident"].as_u64().unwrap())
        .collect();
    assert_eq!(resident.len(), 150);
    assert_eq!(resident[0], 0);
    assert_eq!(*resident.iter().max().unwrap(), 3);
    assert_eq!(*resident.last().unwrap(), 0);
    // loaded once each: the count rises only where a texture is first shaded
    let rises: u64 = resident.windows(2).map(|p| p[1].saturating_sub(p[0])).sum();
    assert!(rises <= 4, "{resident:?}");
}
