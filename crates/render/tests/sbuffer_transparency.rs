//! `sbuffer --sbuffer transparent`, Barkan & Gordon's §5.2 transparency (per sample a
//! list of the transparent polygons down to the nearest opaque one): against `woo-chall`'s
//! compositing at the same samples (within 1e-9), and at one sample against a ray cast
//! written here that composites the layers it hits front to back.

mod common;

use common::raycast::{hits, ray};
use cwisim_render::settings::SbufferMode;
use cwisim_render::{registry, LoadedScene, Settings, Size, Source};
use cwisim_scene::Shading;
use cwisim_world::{parse_any, AnyScene, WorldScene};
use glam::DVec3;
use rand_core::{Rng, SeedableRng};
use rand_xorshift::XorShiftRng;

fn transparent(samples: u32, shading: Shading) -> Settings {
    Settings {
        samples,
        shading,
        sbuffer: SbufferMode::Transparent,
        ..Settings::default()
    }
}

/// `woo-chall` with a shading call at every sample (P = 1), otherwise as `s`.
fn woo(s: &Settings) -> Settings {
    Settings {
        shade_p: Some(1.0),
        sbuffer: SbufferMode::Host,
        ..*s
    }
}

fn image(name: &str, loaded: LoadedScene, s: &Settings, threads: usize) -> Vec<f64> {
    common::drawn_on(name, loaded, s, threads).0
}

fn embedded(name: &str, s: &Settings) -> LoadedScene {
    Source::resolve(Some(name.as_ref()))
        .unwrap()
        .load_for(s)
        .unwrap()
}

fn built(w: &WorldScene) -> LoadedScene {
    LoadedScene::built("test", AnyScene::World(w.clone()))
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Random triangles facing the camera (each wound to face it), tilted so that they
/// pierce each other and their order changes across the image, lit by ambient light
/// alone (a triangle's colour is its `k_a`); a third of them opaque.
fn random_layers(rng: &mut XorShiftRng, n: usize) -> WorldScene {
    let mut u = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let eye = DVec3::new(0.0, 0.0, 5.0);
    let mut meshes = Vec::new();
    for _ in 0..n {
        let centre = DVec3::new(3.0 * u() - 1.5, 3.0 * u() - 1.5, 2.0 * u() - 1.0);
        let mut p: Vec<DVec3> = (0..3)
            .map(|_| centre + DVec3::new(2.4 * u() - 1.2, 2.4 * u() - 1.2, 1.6 * u() - 0.8))
            .collect();
        if (p[1] - p[0]).cross(p[2] - p[0]).dot(eye - p[0]) < 0.0 {
            p.swap(1, 2);
        }
        let t = [0.0, 0.25, 0.5, 0.8][(u() * 4.0) as usize];
        let k_a = 0.1 + 0.9 * u();
        meshes.push(format!(
            r#"{{ "material": {{ "k_a": {k_a}, "k_d": 0, "k_s": 0, "n": 1, "transmittance": {t} }},
                 "vertices": [{}], "faces": [[0, 1, 2]] }}"#,
            p.iter()
                .map(|v| format!("[{}, {}, {}]", v.x, v.y, v.z))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    let text = format!(
        r#"{{ "kind": "world", "width": 40, "height": 40, "channels": 1,
            "camera": {{ "eye": [0, 0, 5], "target": [0, 0, 0], "fov_y": 40 }},
            "ambient": 1, "lights": [], "meshes": [{}] }}"#,
        meshes.join(", ")
    );
    match parse_any(&text, None).unwrap() {
        AnyScene::World(w) => w,
        AnyScene::Screen(_) => unreachable!(),
    }
}

/// The ray cast: at each pixel centre, every triangle the ray hits, nearest first,
/// composited `Σ (1 − t_i) Π_{j<i} t_j · k_a,i` down to the first opaque one.
fn ray_cast(w: &WorldScene) -> Vec<f64> {
    let (width, height) = (w.width(), w.height());
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let (o, d) = ray(w, width, height, f64::from(x) + 0.5, f64::from(y) + 0.5);
            let (mut sum, mut through) = (0.0, 1.0);
            for h in hits(w, o, d) {
                let m = &w.spec.meshes[h.mesh].material;
                sum += through * (1.0 - m.transmittance) * m.k_a.get(0);
                through *= m.transmittance;
                if m.transmittance == 0.0 {
                    break;
                }
            }
            out.push(sum);
        }
    }
    out
}

#[test]
fn at_one_sample_it_equals_a_ray_cast_compositing_the_layers() {
    let mut rng = XorShiftRng::seed_from_u64(56);
    for n in [2, 5, 12, 25] {
        let w = random_layers(&mut rng, n);
        let want = ray_cast(&w);
        for shading in [Shading::Flat, Shading::Gouraud, Shading::Phong] {
            let s = Settings {
                shade_tolerance: 0.0,
                ..transparent(1, shading)
            };
            let got = image("sbuffer", built(&w), &s, 1);
            let e = largest_difference(&got, &want);
            assert!(e < 1e-9, "{n} triangles, {shading:?}: {e}");
        }
        // the default mode keeps the nearest surface: not the composite
        let opaque = Settings {
            sbuffer: SbufferMode::Host,
            ..transparent(1, Shading::Flat)
        };
        assert!(largest_difference(&image("sbuffer", built(&w), &opaque, 1), &want) > 1e-3);
    }
}

#[test]
fn it_equals_woo_chall_compositing_at_the_same_samples() {
    let glass = |s: &Settings| {
        embedded(
            "glass",
            &Settings {
                size: Some(Size {
                    width: 96,
                    height: 72,
                }),
                ..*s
            },
        )
    };
    let mut rng = XorShiftRng::seed_from_u64(5);
    let layers = random_layers(&mut rng, 12);
    for samples in [1, 2, 3] {
        for shading in [Shading::Flat, Shading::Gouraud, Shading::Phong] {
            let s = transparent(samples, shading);
            let sb = image("sbuffer", glass(&s), &s, 1);
            let wc = image("woo-chall", glass(&s), &woo(&s), 1);
            let e = largest_difference(&sb, &wc);
            assert!(e < 1e-9, "glass, {samples}×{samples}, {shading:?}: {e}");
            let sb = image("sbuffer", built(&layers), &s, 1);
            let wc = image("woo-chall", built(&layers), &woo(&s), 1);
            let e = largest_difference(&sb, &wc);
            assert!(e < 1e-9, "layers, {samples}×{samples}, {shading:?}: {e}");
        }
    }
    // merged sub-scanlines and the corner grid too
    for s in [
        Settings {
            merge_subscanlines: true,
            ..transparent(3, Shading::Gouraud)
        },
        Settings {
            grid: cwisim_render::subsample::Grid::Corner,
            ..transparent(3, Shading::Gouraud)
        },
    ] {
        let sb = image("sbuffer", glass(&s), &s, 1);
        let wc = image("woo-chall", glass(&s), &woo(&s), 1);
        assert!(largest_difference(&sb, &wc) < 1e-9, "{s:?}");
    }
}

#[test]
fn the_image_is_the_same_at_any_thread_count() {
    let s = Settings {
        size: Some(Size {
            width: 80,
            height: 60,
        }),
        ..transparent(2, Shading::Gouraud)
    };
    let one = image("sbuffer", embedded("glass", &s), &s, 1);
    for threads in [2, 3] {
        assert_eq!(image("sbuffer", embedded("glass", &s), &s, threads), one);
    }
}

#[test]
fn a_scene_without_transparent_meshes_is_refused() {
    let s = transparent(1, Shading::Flat);
    for name in ["pot", "fig25"] {
        let e = (registry::find("sbuffer").unwrap().build)(embedded(name, &s), &s)
            .err()
            .expect("refused")
            .to_string();
        assert!(
            e.contains("--sbuffer transparent") && e.contains("transmittance"),
            "{e}"
        );
    }
}
