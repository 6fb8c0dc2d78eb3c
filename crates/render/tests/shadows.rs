//! Shadows held to an independent reference: a ray cast from the camera through every
//! pixel centre, and from the point it hits to every light (`tests/common/raycast.rs`, no
//! code shared with the shadow polygons, the visibility or the projection). Point-sampled
//! (`--aa none`), every pixel whose rays pass clear of every edge must get exactly the
//! lights its shadow rays reach.

use cwisim_render::{registry, LoadedScene, Settings};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::embedded::embedded;
use cwisim_world::lighting::Lighting;
use cwisim_world::{AnyScene, WorldScene};
use glam::DVec3;

mod common;
use common::raycast::{hits, ray, Hit};
use common::{rendered, rendered_by};

fn world(text: &str) -> WorldScene {
    common::world(text, None)
}

/// `still-life` at 192×128 (the ray caster looks at every triangle for every ray).
fn still_life() -> WorldScene {
    common::world(embedded("still-life").unwrap().text, Some((192, 128)))
}

/// Point sampling at the pixel centres, as `renderer` is told it: `--aa none` for
/// `vanrij`, one sample per pixel for the others.
fn settings(renderer: &str, shading: Shading, shadows: bool) -> Settings {
    let point = if renderer == "vanrij" {
        Settings {
            aa: Antialias::None,
            ..Settings::default()
        }
    } else {
        Settings {
            samples: 1,
            ..Settings::default()
        }
    };
    Settings {
        shading,
        shadows: Some(shadows),
        ..point
    }
}

/// The renderers that draw shadows.
const RENDERERS: [&str; 4] = ["vanrij", "woo-chall", "sbuffer", "bsp"];

/// How close to an edge (in barycentric terms) a ray may pass and still be called.
const MARGIN: f64 = 1e-6;

/// Which lights reach `point` on the triangle of `seen`: `None` where a shadow ray passes
/// too close to an occluder's edge to call.
fn reaching(w: &WorldScene, seen: &Hit, point: DVec3) -> Option<Vec<bool>> {
    let mut out = Vec::new();
    for light in &w.spec.lights {
        let to = DVec3::from_array(light.position) - point;
        let length = to.length();
        let mut blocked = false;
        for h in hits(w, point, to / length) {
            let same = h.mesh == seen.mesh && h.face == seen.face && h.corners == seen.corners;
            if same || h.t >= length * (1.0 - 1e-9) {
                continue;
            }
            if h.t <= 1e-9 * length || h.margin < MARGIN {
                // leaving the surface by a neighbour, or grazing an occluder's edge
                return None;
            }
            blocked = true;
        }
        out.push(!blocked);
    }
    Some(out)
}

/// A pixel's reference value (its channels) and the lights reaching its surface.
type Seen = (Vec<f64>, Vec<bool>);

/// The reference at a pixel centre: the nearest surface's value lit by the lights its
/// shadow rays reach (`Ok(None)` where the ray misses; `Err` where too close to call), and
/// those lights.
fn reference(w: &WorldScene, shading: Shading, x: f64, y: f64) -> Result<Option<Seen>, ()> {
    let spec = &w.spec;
    let (o, d) = ray(w, w.width(), w.height(), x, y);
    let all = hits(w, o, d);
    let Some(h) = all.first() else {
        return Ok(None);
    };
    if h.margin < MARGIN || all.get(1).is_some_and(|n| n.t - h.t < 1e-6 * h.t) {
        return Err(());
    }
    let mesh = &w.meshes[h.mesh];
    let face = &mesh.faces[h.face];
    let p = h.corners.map(|i| mesh.positions[face.corners[i] as usize]);
    let point = o + h.t * d;
    let reach = reaching(w, h, point).ok_or(())?;
    let lighting = Lighting {
        ambient: spec.ambient.clone(),
        lights: spec.lights.clone(),
        channels: w.channels(),
    };
    let material = &spec.meshes[h.mesh].material;
    let eye = DVec3::from_array(spec.camera.eye);
    // a back face (two-sided) is lit with its normals turned to the viewer
    let toward = if (p[1] - p[0]).cross(p[2] - p[0]).dot(eye - p[0]) <= 0.0 {
        -1.0
    } else {
        1.0
    };
    let lit = |at: DVec3, n: DVec3| lighting.intensity_lit(material, at, n, eye, |k| reach[k]);
    let value = match shading {
        Shading::Flat => {
            let centroid = face
                .corners
                .iter()
                .map(|&c| mesh.positions[c as usize])
                .sum::<DVec3>()
                / face.corners.len() as f64;
            let n = toward * mesh.face_normal(h.face).normalize();
            lit(centroid, n)
        }
        _ => {
            // Gouraud: the corners' values, affine on the screen (weights ∝ world
            // barycentric × depth)
            let forward = (DVec3::from_array(spec.camera.target) - eye).normalize();
            let corner = h.corners.map(|i| {
                lit(
                    mesh.positions[face.corners[i] as usize],
                    toward * face.normals[i],
                )
            });
            let depth = p.map(|q| (q - eye).dot(forward));
            let s = [0, 1, 2].map(|k| h.bary[k] * depth[k]);
            let sum = s[0] + s[1] + s[2];
            let mut v = corner[0];
            for c in 0..w.channels() {
                v[c] = (s[0] * corner[0][c] + s[1] * corner[1][c] + s[2] * corner[2][c]) / sum;
            }
            v
        }
    };
    Ok(Some((value[..w.channels()].to_vec(), reach)))
}

/// Point-sampled, the shadows are the ray caster's at every pixel it can call, on
/// `still-life` with both its lights casting, flat and Gouraud, from every renderer that
/// draws them.
#[test]
fn point_sampled_shadows_are_the_ray_caster_s() {
    let w = still_life();
    let (width, height) = (w.width(), w.height());
    let channels = w.channels();
    // the reference once per shading, every renderer against it
    for shading in [Shading::Flat, Shading::Gouraud] {
        let mut seen = Vec::new();
        for py in 0..height {
            for px in 0..width {
                seen.push(reference(
                    &w,
                    shading,
                    f64::from(px) + 0.5,
                    f64::from(py) + 0.5,
                ));
            }
        }
        for renderer in RENDERERS {
            let image = rendered_by(renderer, &w, &settings(renderer, shading, true));
            against(&image, &seen, width, height, channels, shading, renderer);
        }
    }
}

/// Holds `image` to the reference at every pixel it can call.
fn against(
    image: &[f64],
    seen: &[Result<Option<Seen>, ()>],
    width: u32,
    height: u32,
    channels: usize,
    shading: Shading,
    renderer: &str,
) {
    {
        let (mut checked, mut shadowed) = (0, [0usize; 2]);
        for py in 0..height {
            for px in 0..width {
                let Ok(seen) = &seen[(py * width + px) as usize] else {
                    continue;
                };
                let k = (py * width + px) as usize * channels;
                let got = &image[k..k + channels];
                let (expected, reach) =
                    seen.clone().unwrap_or((vec![0.0; channels], vec![true; 2]));
                let tolerance = if shading == Shading::Flat {
                    1e-12
                } else {
                    1e-9
                };
                assert!(
                    got.iter()
                        .zip(&expected)
                        .all(|(g, e)| (g - e).abs() <= tolerance),
                    "{renderer} {shading:?} pixel ({px}, {py}): {got:?}, the ray caster {expected:?} (lights reaching: {reach:?})"
                );
                checked += 1;
                for (l, r) in reach.iter().enumerate() {
                    shadowed[l] += usize::from(!r);
                }
            }
        }
        let pixels = (width * height) as usize;
        assert!(
            checked > pixels * 9 / 10,
            "{shading:?}: {checked} of {pixels} checked"
        );
        // both lights shadow a good part of the picture
        eprintln!("{shading:?}: {checked} pixels checked, shadowed per light {shadowed:?}");
        assert!(
            shadowed.iter().all(|&s| s > 500),
            "{shading:?}: shadowed pixels per light {shadowed:?}"
        );
    }
}

/// The floor's shadow of a triangle, box-filtered, against the analytic integral: the
/// occluder projected from the light onto the floor's plane, then by the camera onto the
/// screen, clipped to each pixel. The occluder lies outside the camera's view, so every
/// pixel sees the floor alone: lit, less the light's terms on the shadow's share of it.
mod analytic {
    use super::*;
    use proptest::prelude::*;

    const SIZE: u32 = 24;

    fn scene(light: [f64; 3], occluder: [[f64; 3]; 3]) -> String {
        format!(
            r#"{{
  "kind": "world", "width": {SIZE}, "height": {SIZE}, "channels": 1,
  "camera": {{ "eye": [0, 10, 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov_y": 12 }},
  "ambient": 0.2,
  "lights": [ {{ "position": {light:?}, "intensity": 0.9, "shadows": true }} ],
  "meshes": [
    {{ "name": "floor", "material": {{ "k_a": 0.5, "k_d": 0.7, "k_s": 0, "n": 1 }},
       "vertices": [[-5, 0, -5], [-5, 0, 5], [5, 0, 5], [5, 0, -5]], "faces": [[0, 1, 2, 3]] }},
    {{ "name": "occluder", "material": {{ "k_a": 0.5, "k_d": 0.7, "k_s": 0, "n": 1 }},
       "vertices": {occluder:?}, "faces": [[0, 1, 2]] }}
  ]
}}"#
        )
    }

    /// Where world point `p` lands on the screen (the camera written out again).
    fn screen(p: DVec3) -> [f64; 2] {
        let (eye, forward, up) = (DVec3::new(0.0, 10.0, 0.0), -DVec3::Y, -DVec3::Z);
        let right = forward.cross(up).normalize();
        let focal = 0.5 * f64::from(SIZE) / 6f64.to_radians().tan();
        let d = p - eye;
        let depth = d.dot(forward);
        let half = 0.5 * f64::from(SIZE);
        [
            half + focal * d.dot(right) / depth,
            half - focal * d.dot(up) / depth,
        ]
    }

    /// The area of polygon `poly` inside the unit pixel at `(x, y)`.
    fn area_in_pixel(poly: &[[f64; 2]], x: f64, y: f64) -> f64 {
        let mut p = poly.to_vec();
        // keep where f ≥ 0, for the four sides of the pixel
        let sides: [&dyn Fn([f64; 2]) -> f64; 4] =
            [&|q| q[0] - x, &|q| x + 1.0 - q[0], &|q| q[1] - y, &|q| {
                y + 1.0 - q[1]
            }];
        for f in sides {
            let mut out = Vec::new();
            for k in 0..p.len() {
                let (a, b) = (p[k], p[(k + 1) % p.len()]);
                let (fa, fb) = (f(a), f(b));
                if fa >= 0.0 {
                    out.push(a);
                }
                if (fa < 0.0) != (fb < 0.0) {
                    let t = fa / (fa - fb);
                    out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
                }
            }
            p = out;
            if p.is_empty() {
                return 0.0;
            }
        }
        let mut doubled = 0.0;
        for k in 0..p.len() {
            let (a, b) = (p[k], p[(k + 1) % p.len()]);
            doubled += a[0] * b[1] - b[0] * a[1];
        }
        0.5 * doubled.abs()
    }

    /// Renders the floor and returns the image, the analytic image, and the shadow's area
    /// on the screen.
    fn both(light: [f64; 3], occluder: [[f64; 3]; 3]) -> (Vec<f64>, Vec<f64>, f64) {
        let w = world(&scene(light, occluder));
        let image = rendered(
            &w,
            &Settings {
                shading: Shading::Flat,
                ..Settings::default()
            },
        );
        let l = DVec3::from_array(light);
        // the floor's flat value (at its centroid, the origin, normal up) and its value
        // without the light
        let to = l.normalize();
        let lit = 0.2 * 0.5 + 0.9 * 0.7 * to.y;
        let dark = 0.2 * 0.5;
        let shadow: Vec<[f64; 2]> = occluder
            .iter()
            .map(|&p| {
                let p = DVec3::from_array(p);
                screen(l + (p - l) * (l.y / (l.y - p.y)))
            })
            .collect();
        let mut expected = Vec::new();
        let mut total = 0.0;
        for py in 0..SIZE {
            for px in 0..SIZE {
                let a = area_in_pixel(&shadow, f64::from(px), f64::from(py));
                total += a;
                expected.push(lit - (lit - dark) * a);
            }
        }
        (image, expected, total)
    }

    fn assert_close(image: &[f64], expected: &[f64]) {
        for (k, (g, e)) in image.iter().zip(expected).enumerate() {
            assert!(
                (g - e).abs() <= 1e-9,
                "pixel ({}, {}): {g} against the integral {e}",
                k as u32 % SIZE,
                k as u32 / SIZE
            );
        }
    }

    #[test]
    fn a_triangle_s_shadow_on_the_floor_is_the_integral() {
        let (image, expected, area) = both(
            [6.0, 4.0, 0.5],
            [[2.5, 1.5, -0.4], [3.0, 1.2, 0.6], [2.2, 1.0, 0.3]],
        );
        assert!(area > 20.0, "the shadow covers {area} px² of the view");
        assert_close(&image, &expected);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn any_triangle_s_shadow_from_any_light_is_the_integral(
            lx in 5.0f64..8.0, ly in 3.0f64..6.0, lz in -1.5f64..1.5,
            corners in proptest::array::uniform3((2.0f64..3.5, 0.3f64..2.0, -1.5f64..1.5)),
        ) {
            let occluder = corners.map(|(x, y, z)| [x, y, z]);
            // a sliver of an occluder makes a sliver of a shadow: still exact, but say so
            let (image, expected, _) = both([lx, ly, lz], occluder);
            assert_close(&image, &expected);
        }
    }
}

/// Every renderer draws the shadows a scene's lights cast (`nishita` on its patches too);
/// `--shadows` that would change nothing is refused.
#[test]
fn shadows_that_would_be_dropped_or_a_flag_that_changes_nothing_are_refused() {
    // still-life as embedded (its main light casting shadows), and with none casting
    let casting = embedded("still-life").unwrap().text;
    let text = &casting.replacen(r#", "shadows": true }"#, " }", 1);
    assert_ne!(casting, text);
    let build = |name: &str, text: &str, settings: &Settings| {
        let loaded = LoadedScene::built("test", AnyScene::World(world(text)));
        (registry::find(name).unwrap().build)(loaded, settings).map(|_| ())
    };
    let teapot = embedded("teapot").unwrap().text;
    let casting_teapot = teapot.replacen(
        r#""intensity": 0.85 }"#,
        r#""intensity": 0.85, "shadows": true }"#,
        1,
    );
    assert_ne!(casting_teapot, teapot);
    // nishita draws shadows on its patches (§7): a casting light, or --shadows on
    assert!(build("nishita", &casting_teapot, &Settings::default()).is_ok());
    assert!(build("nishita", teapot, &Settings::default()).is_ok());
    let on = Settings {
        shadows: Some(true),
        ..Settings::default()
    };
    assert!(build("nishita", teapot, &on).is_ok());
    // on a scene without patches it draws the polygons as vanrij does, shadows and all
    for name in RENDERERS.into_iter().chain(["refine", "nishita"]) {
        assert!(build(name, casting, &Settings::default()).is_ok(), "{name}");
    }
    let off = Settings {
        shadows: Some(false),
        ..Settings::default()
    };
    assert!(build("vanrij", casting, &off).is_ok());
    for name in RENDERERS {
        let e = build(name, text, &off).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("--shadows off: no light of the scene casts shadows"),
            "{name}: {e}"
        );
    }
    let dark = r#"{"kind": "world", "width": 8, "height": 8, "channels": 1,
"camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "fov_y": 40}, "ambient": 0.5, "lights": [],
"meshes": [{"material": {"k_a": 1, "k_d": 0, "k_s": 0, "n": 1},
  "vertices": [[-1, -1, 0], [1, -1, 0], [0, 1, 0]], "faces": [[0, 1, 2]]}]}"#;
    let on = Settings {
        shadows: Some(true),
        ..Settings::default()
    };
    for name in RENDERERS {
        let e = build(name, dark, &on).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("--shadows on: the scene has no lights"),
            "{name}: {e}"
        );
    }
}

/// `nishita` on a scene without Bézier patches draws its polygons as `vanrij` does, with
/// the same shadow polygons: the same image, value for value, box filter and Phong.
#[test]
fn nishita_without_patches_draws_vanrij_s_shadows() {
    let w = still_life();
    for shading in [Shading::Gouraud, Shading::Phong] {
        let s = Settings {
            shading,
            ..Settings::default()
        };
        let vanrij = rendered(&w, &s);
        let unshadowed = rendered(
            &w,
            &Settings {
                shadows: Some(false),
                ..s
            },
        );
        assert_ne!(vanrij, unshadowed, "{shading}: the shadows show");
        assert_eq!(rendered_by("nishita", &w, &s), vanrij, "{shading}");
    }
}
