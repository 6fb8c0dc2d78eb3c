//! `nishita`'s shadows on the patches (the paper's §7), held to an analytic case: a flat
//! bicubic patch over a flat patch, its shadow checked pixel by pixel against the exact
//! shadow polygon (the caster's corners projected from the light onto the floor's plane,
//! then by the camera), box-filtered by clipping to each pixel here; and the renderer's
//! answers around it (threads, a light too wide for one view, `--shadows`).

mod common;

use cwisim_render::nishita::Nishita;
use cwisim_render::{LoadedScene, Settings};
use cwisim_world::camera::Camera;
use cwisim_world::{AnyScene, WorldScene};
use glam::DVec3;

type Pt = [f64; 2];

/// A flat bicubic patch: the parallelogram `corner + s·a + t·b`, `s, t ∈ [0, 1]`, its
/// control points a regular grid (so its parametrisation is affine), as JSON vertices.
fn flat_patch(corner: DVec3, a: DVec3, b: DVec3) -> String {
    let mut points = Vec::new();
    for i in 0..4 {
        for j in 0..4 {
            let p = corner + a * (j as f64 / 3.0) + b * (i as f64 / 3.0);
            points.push(format!("[{}, {}, {}]", p.x, p.y, p.z));
        }
    }
    points.join(", ")
}

const LIGHT: [f64; 3] = [1.5, 8.0, 1.0];
const CASTER: (DVec3, DVec3, DVec3) = (
    DVec3::new(-0.8, 1.5, -0.5),
    DVec3::new(1.4, 0.0, 0.3),
    DVec3::new(-0.2, 0.0, 1.2),
);

/// A floor patch at y = 0 (shadowed, its intensity is `ambient · k_a` = 0.3 exactly) and
/// a smaller patch 1.5 above it, lit by one light casting shadows.
fn scene(light: [f64; 3]) -> WorldScene {
    let floor = flat_patch(
        DVec3::new(-4.0, 0.0, -4.0),
        DVec3::new(8.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 8.0),
    );
    let caster = flat_patch(CASTER.0, CASTER.1, CASTER.2);
    let indices: Vec<String> = (0..16).map(|i| i.to_string()).collect();
    let patch = indices.join(", ");
    let text = format!(
        r#"{{"kind": "world", "width": 64, "height": 48, "channels": 1,
"camera": {{"eye": [0, 6, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40}},
"ambient": 0.3,
"lights": [{{"position": [{}, {}, {}], "intensity": 0.7, "shadows": true}}],
"meshes": [
  {{"name": "floor", "material": {{"k_a": 1, "k_d": 1, "k_s": 0, "n": 1}}, "two_sided": true,
    "bezier": {{"tessellate": 4, "vertices": [{floor}], "patches": [[{patch}]]}}}},
  {{"name": "caster", "material": {{"k_a": 0.5, "k_d": 0.2, "k_s": 0, "n": 1}}, "two_sided": true,
    "bezier": {{"tessellate": 4, "vertices": [{caster}], "patches": [[{patch}]]}}}}
]}}"#,
        light[0], light[1], light[2]
    );
    common::world(&text, None)
}

/// The part of polygon `poly` inside the convex polygon `clip` (counter-clockwise or
/// not): Sutherland–Hodgman, side by side.
fn clip_convex(poly: &[Pt], clip: &[Pt]) -> Vec<Pt> {
    let orientation = signed_area(clip).signum();
    let mut out = poly.to_vec();
    for e in 0..clip.len() {
        if out.len() < 3 {
            return Vec::new();
        }
        let (a, b) = (clip[e], clip[(e + 1) % clip.len()]);
        let side =
            |p: Pt| orientation * ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]));
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (p, q) = (input[i], input[(i + 1) % input.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0) {
                let t = sp / (sp - sq);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
    }
    out
}

fn signed_area(p: &[Pt]) -> f64 {
    (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

/// Per pixel of a `width × height` image, the area of it the polygons cover.
fn coverage(polygons: &[Vec<Pt>], width: usize, height: usize) -> Vec<f64> {
    let mut out = vec![0.0; width * height];
    for poly in polygons {
        let (x0, x1, y0, y1) = poly.iter().fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |(a, b, c, d), p| (a.min(p[0]), b.max(p[0]), c.min(p[1]), d.max(p[1])),
        );
        for y in (y0.floor().max(0.0) as usize)..(y1.ceil().max(0.0) as usize).min(height) {
            for x in (x0.floor().max(0.0) as usize)..(x1.ceil().max(0.0) as usize).min(width) {
                let (fx, fy) = (x as f64, y as f64);
                let pixel = [
                    [fx, fy],
                    [fx + 1.0, fy],
                    [fx + 1.0, fy + 1.0],
                    [fx, fy + 1.0],
                ];
                let part = clip_convex(poly, &pixel);
                if part.len() >= 3 {
                    out[y * width + x] += signed_area(&part).abs();
                }
            }
        }
    }
    out
}

fn drawn(w: &WorldScene, settings: &Settings) -> Nishita {
    Nishita::new(
        LoadedScene::built("flat", AnyScene::World(w.clone())),
        settings,
    )
    .unwrap()
}

/// The floor's shadow: the polygons drawn at exactly the floor's unlit intensity.
fn shadow_polygons(n: &Nishita) -> Vec<Vec<Pt>> {
    n.polygons()
        .screen
        .polygons
        .iter()
        .filter(|p| p.intensity.iter().all(|i| (i[0] - 0.3).abs() < 1e-12))
        .map(|p| p.vertices.clone())
        .collect()
}

#[test]
fn a_flat_patch_s_shadow_on_a_flat_patch_is_the_exact_shadow_polygon() {
    let w = scene(LIGHT);
    let camera = Camera::new(&w.spec.camera, 64, 48);
    let light = DVec3::from_array(LIGHT);
    let (c, a, b) = CASTER;
    let corners = [c, c + a, c + a + b, c + b];
    // from the light through each corner down to y = 0
    let shadow: Vec<Pt> = corners
        .iter()
        .map(|&q| camera.project(light + (q - light) * (light.y / (light.y - q.y))))
        .collect();
    let caster: Vec<Pt> = corners.iter().map(|&q| camera.project(q)).collect();
    let expected = coverage(&[shadow], 64, 48);
    for settings in [
        Settings::default(),
        Settings {
            flatness: 4.0,
            band: 1,
            ..Settings::default()
        },
        Settings {
            shading: cwisim_scene::Shading::Phong,
            ..Settings::default()
        },
    ] {
        let n = drawn(&w, &settings);
        let got = coverage(&shadow_polygons(&n), 64, 48);
        // the pixels away from the caster's own image (it hides the shadow's edge there)
        let (cx0, cx1, cy0, cy1) = caster.iter().fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |(a, b, c, d), p| (a.min(p[0]), b.max(p[0]), c.min(p[1]), d.max(p[1])),
        );
        let (mut checked, mut partial, mut total) = (0, 0, 0.0);
        for y in 0..48 {
            for x in 0..64 {
                let (fx, fy) = (x as f64, y as f64);
                if fx + 2.0 > cx0 && fx - 1.0 < cx1 && fy + 2.0 > cy0 && fy - 1.0 < cy1 {
                    continue;
                }
                let (g, e) = (got[y * 64 + x], expected[y * 64 + x]);
                assert!(
                    (g - e).abs() <= 1e-9,
                    "{settings:?}: pixel ({x}, {y}): shadow covers {g}, exactly {e}"
                );
                checked += 1;
                partial += usize::from(e > 1e-6 && e < 1.0 - 1e-6);
                total += e;
            }
        }
        assert!(
            checked > 2500 && partial > 20 && total > 60.0,
            "{checked} {partial} {total}"
        );
    }
}

#[test]
fn shadows_on_patches_are_byte_identical_at_any_thread_count() {
    let w = scene(LIGHT);
    let image = |threads: usize| {
        let settings = Settings {
            threads,
            ..Settings::default()
        };
        let loaded = LoadedScene::built("flat", AnyScene::World(w.clone()));
        common::drawn_on("nishita", loaded, &settings, threads).0
    };
    let one = image(1);
    assert_eq!(one, image(2));
    assert_eq!(one, image(3));
    // and the shadow is there: the same scene without it is brighter somewhere
    let settings = Settings {
        shadows: Some(false),
        ..Settings::default()
    };
    let off = common::rendered_by("nishita", &w, &settings);
    let darker = one.iter().zip(&off).filter(|(a, b)| *a + 0.1 < **b).count();
    assert!(darker > 30, "{darker} pixels in shadow");
}

#[test]
fn a_light_too_wide_for_one_view_of_the_patches_is_refused_at_its_position() {
    // just over the floor's middle: the floor's corners are nearly 90° from straight down
    let w = scene([0.0, 0.2, 0.0]);
    let loaded = LoadedScene::built("flat", AnyScene::World(w));
    let e = Nishita::new(loaded, &Settings::default())
        .err()
        .expect("refused");
    let text = e.to_string();
    assert!(text.contains("lights[0].position"), "{text}");
    assert!(text.contains("use --renderer vanrij"), "{text}");
}
