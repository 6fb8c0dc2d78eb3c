//! Phong shading through the array, held to an independent reference: a ray cast from
//! the camera through every pixel centre into the world meshes, the nearest hit's normal
//! interpolated with the hit's own (world-space) barycentric coordinates, and the
//! report's formula written out again here — no code shared with the projection, the
//! visibility, the shader or the span fitter.

use cwisim_isa::{Instruction, Opcode};
use cwisim_render::{emit, registry, LoadedScene, Settings, Source};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, AnyScene, Visibility, WorldScene};
use glam::DVec3;

mod common;
use common::raycast::{hits, ray};
use common::rendered;

fn world(text: &str, size: u32) -> WorldScene {
    common::world(text, Some((size, size)))
}

fn phong(aa: Antialias, tolerance: f64) -> Settings {
    Settings {
        shading: Shading::Phong,
        aa,
        shade_tolerance: tolerance,
        ..Settings::default()
    }
}

/// The report's formula: `I = I_a·k_a + Σ I_l·(k_d·(N·L) + k_s·(R·V)^n)`, terms that face
/// away left out.
fn lit(w: &WorldScene, mesh: usize, p: DVec3, n: DVec3) -> f64 {
    let spec = &w.spec;
    let mat = &spec.meshes[mesh].material;
    let eye = DVec3::from_array(spec.camera.eye);
    let v = (eye - p).normalize();
    let mut i = spec.ambient.get(0) * mat.k_a.get(0);
    for light in &spec.lights {
        let l = (DVec3::from_array(light.position) - p).normalize();
        let nl = n.dot(l);
        if nl <= 0.0 {
            continue;
        }
        let r = 2.0 * nl * n - l;
        let rv = r.dot(v);
        let spec_term = if rv > 0.0 && mat.k_s.get(0) != 0.0 {
            mat.k_s.get(0) * rv.powf(mat.n)
        } else {
            0.0
        };
        i += light.intensity.get(0) * (mat.k_d.get(0) * nl + spec_term);
    }
    i
}

/// The reference at a screen point: `Some(value)` where the nearest hit is clear of
/// every edge and of the next hit; `None` where a ray misses; `Err` where it is too close
/// to call.
type Seen = (f64, usize, usize, [usize; 3]);

fn reference(w: &WorldScene, size: u32, x: f64, y: f64) -> Result<Option<Seen>, ()> {
    let (o, d) = ray(w, size, size, x, y);
    let hits = hits(w, o, d);
    let Some(h) = hits.first() else {
        return Ok(None);
    };
    if h.margin < 1e-6 || hits.get(1).is_some_and(|n| n.t - h.t < 1e-6 * h.t) {
        return Err(());
    }
    let mesh = &w.meshes[h.mesh];
    let face = &mesh.faces[h.face];
    let p = h.corners.map(|i| mesh.positions[face.corners[i] as usize]);
    let point = h.bary[0] * p[0] + h.bary[1] * p[1] + h.bary[2] * p[2];
    let mut n = (h.bary[0] * face.normals[h.corners[0]]
        + h.bary[1] * face.normals[h.corners[1]]
        + h.bary[2] * face.normals[h.corners[2]])
        .normalize();
    // a back face (two-sided) is lit with its normal turned to the viewer
    let geometric = (p[1] - p[0]).cross(p[2] - p[0]);
    if geometric.dot(o - p[0]) <= 0.0 {
        n = -n;
    }
    Ok(Some((lit(w, h.mesh, point, n), h.mesh, h.face, h.corners)))
}

/// At tolerance 0, point-sampled Phong is the per-pixel Phong value at every pixel
/// centre, and the box filter's fully covered pixels are too.
#[test]
fn tolerance_zero_is_phong_at_every_pixel_centre() {
    // the teapot tessellated coarsely: larger triangles, more pixels inside one
    for (name, size) in [("pot", 80u32), ("teapot", 64)] {
        let text = embedded(name)
            .unwrap()
            .text
            .replace(r#""tessellate": 8"#, r#""tessellate": 3"#);
        let w = world(&text, size);
        let sampled = rendered(&w, &phong(Antialias::None, 0.0));
        let boxed = rendered(&w, &phong(Antialias::Box, 0.0));
        let (mut checked, mut interior) = (0, 0);
        for py in 0..size {
            for px in 0..size {
                let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                let k = (py * size + px) as usize;
                let Ok(centre) = reference(&w, size, x, y) else {
                    continue;
                };
                let expected = centre.map_or(0.0, |c| c.0);
                assert!(
                    (sampled[k] - expected).abs() <= 1e-12,
                    "{name} pixel ({px}, {py}) point-sampled: {} vs {expected}",
                    sampled[k]
                );
                checked += 1;
                // a pixel whose corners all hit the centre's triangle, clear of its
                // edges, is covered by it alone
                let Some((_, mesh, face, tri)) = centre else {
                    continue;
                };
                let whole =
                    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                        .iter()
                        .all(|(dx, dy)| {
                            matches!(
                                reference(&w, size, f64::from(px) + dx, f64::from(py) + dy),
                                Ok(Some((_, m, f, t))) if (m, f, t) == (mesh, face, tri)
                            )
                        });
                if whole {
                    interior += 1;
                    assert!(
                        (boxed[k] - expected).abs() <= 1e-12,
                        "{name} pixel ({px}, {py}) box: {} vs {expected}",
                        boxed[k]
                    );
                }
            }
        }
        assert!(
            checked > (size * size / 2) as usize,
            "{name}: {checked} pixels checked"
        );
        assert!(interior > 40, "{name}: {interior} interior pixels");
    }
}

/// Through the span fitter at a tolerance, every pixel stays within it of tolerance 0,
/// once for every piece that reaches it (fragments meet in edge pixels).
#[test]
fn the_span_tolerance_bounds_the_image() {
    let w = world(embedded("teapot").unwrap().text, 64);
    let exact = rendered(&w, &phong(Antialias::Box, 0.0));
    for tol in [1.0 / 512.0, 1.0 / 32.0] {
        let settings = phong(Antialias::Box, tol);
        let fitted = rendered(&w, &settings);
        // pieces per pixel, from the stream
        let loaded = LoadedScene::built("test", AnyScene::World(w.clone()));
        let r = (registry::find("vanrij").unwrap().build)(loaded, &settings).unwrap();
        let mut stream: Vec<Instruction> = Vec::new();
        emit(&*r, &mut stream).unwrap();
        let mut reached = vec![0u32; exact.len()];
        let mut row = 0usize;
        for i in &stream {
            match i.op {
                Opcode::Refresh => row += 1,
                _ => (i.x..i.x + i.dx).for_each(|x| reached[row * 64 + x as usize] += 1),
            }
        }
        let mut worst_ratio: f64 = 0.0;
        for (k, (a, b)) in exact.iter().zip(&fitted).enumerate() {
            let bound = tol * f64::from(reached[k]) + 1e-12;
            assert!(
                (a - b).abs() <= bound,
                "tolerance {tol}, pixel {k}: {a} vs {b}, {} pieces",
                reached[k]
            );
            if reached[k] == 1 {
                worst_ratio = worst_ratio.max((a - b).abs() / tol);
            }
        }
        assert!(
            worst_ratio > 0.1,
            "the fitter uses its tolerance ({worst_ratio})"
        );
    }
}

/// A plane lit alike everywhere (ambient light only): Phong equals Gouraud.
#[test]
fn a_uniformly_lit_plane_is_the_same_in_phong_and_gouraud() {
    let text = r#"{
  "kind": "world", "width": 40, "height": 30, "channels": 1,
  "camera": { "eye": [0.3, 2, 5], "target": [0, 0, 0], "fov_y": 40 },
  "ambient": 0.8, "lights": [],
  "meshes": [ { "material": { "k_a": 0.7, "k_d": 0.6, "k_s": 0.4, "n": 8 },
    "vertices": [[-1.3, 0, -1], [1.1, 0, -1.2], [1.2, 0.2, 1], [-1, 0.1, 1.1]],
    "faces": [[3, 2, 1, 0]] } ]
}"#;
    let AnyScene::World(w) = parse_any(text, None).unwrap() else {
        panic!()
    };
    for aa in [Antialias::Box, Antialias::None] {
        let gouraud = rendered(
            &w,
            &Settings {
                aa,
                ..Settings::default()
            },
        );
        let phong = rendered(&w, &phong(aa, 0.0));
        assert!(gouraud.iter().any(|&v| v > 0.5), "the plane is drawn");
        for (k, (g, p)) in gouraud.iter().zip(&phong).enumerate() {
            assert!((g - p).abs() <= 1e-12, "{aa:?} pixel {k}: {g} vs {p}");
        }
    }
}

#[test]
fn phong_needs_a_world_scene_and_exact_visibility() {
    let build = |source: &str, settings: &Settings| {
        let loaded = Source::resolve(Some(source.as_ref()))
            .unwrap()
            .load(None)
            .unwrap();
        (registry::find("vanrij").unwrap().build)(loaded, settings).map(|_| ())
    };
    let e = build("fig25", &phong(Antialias::Box, 0.0)).unwrap_err();
    assert!(e.to_string().contains("needs a world scene"), "{e}");
    let eval0 = Settings {
        visibility: Visibility::Eval0,
        ..phong(Antialias::Box, 0.0)
    };
    let e = build("pot", &eval0).unwrap_err();
    assert!(e.to_string().contains("exact visible surfaces only"), "{e}");
    let e = build("pot", &phong(Antialias::Box, -1.0)).unwrap_err();
    assert!(e.to_string().contains("--shade-tolerance"), "{e}");
}
