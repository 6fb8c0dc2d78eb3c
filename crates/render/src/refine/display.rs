//! The host's display list: how each polygon is drawn at a phase (flat, Gouraud or
//! Phong), and the polygons of one phase split into those kept from the previous frame
//! and those the phase regenerates.

use super::measure::flattened;
use crate::prepare::{PhongSurfaces, PolygonLights, PolygonScene};
use cwisim_scene::{Polygon, ScreenScene, Shading, VertexIntensity};
use cwisim_world::shadow::LightSet;

/// Polygon `k` (`p`) of `scene` as every light would shade it: its triangle's own
/// intensities at its vertices (the polygon itself where it has no triangle, or no light
/// casts shadows).
fn unshadowed(scene: &PolygonScene, k: usize, p: &Polygon) -> Polygon {
    let Some(s) = &scene.phong else {
        return p.clone();
    };
    let t = &s.triangles[s.sources[k]];
    let channels = scene.screen.channel_count();
    let intensity = p
        .vertices
        .iter()
        .map(|&v| {
            t.intensity_at(v, channels).map_or_else(
                || VertexIntensity::from_elem(0.0, channels),
                |i| VertexIntensity::from_slice(&i[..channels]),
            )
        })
        .collect::<Vec<_>>();
    Polygon::new(p.vertices.clone(), intensity)
}

/// Whether polygon `k` of `scene` is part of a textured mesh.
pub fn is_textured(scene: &PolygonScene, k: usize) -> bool {
    scene
        .phong
        .as_ref()
        .is_some_and(|s| s.shader.is_textured(s.triangles[s.sources[k]].mesh))
}

/// Polygons lit per pixel, gathered with their source triangles and lights.
struct PerPixel {
    screen: ScreenScene,
    sources: Vec<usize>,
    lit: Vec<LightSet>,
}

impl PerPixel {
    fn new(screen: ScreenScene) -> PerPixel {
        PerPixel {
            screen,
            sources: Vec::new(),
            lit: Vec::new(),
        }
    }

    fn push(&mut self, scene: &PolygonScene, k: usize, p: &Polygon) {
        self.screen.polygons.push(p.clone());
        if let Some(s) = &scene.phong {
            self.sources.push(s.sources[k]);
            if let Some(l) = &s.shadows {
                self.lit.push(l.lit[k]);
            }
        }
    }

    /// The polygons and what lighting them as `shading` says needs; `None` when there
    /// are none.
    fn surfaces(
        self,
        scene: &PolygonScene,
        shading: Shading,
    ) -> Option<(ScreenScene, PhongSurfaces)> {
        let s = scene.phong.as_ref()?;
        if self.screen.polygons.is_empty() {
            return None;
        }
        let mut surfaces = PhongSurfaces::new(
            s.triangles.clone(),
            self.sources,
            s.shader.clone().with_shading(shading),
        )
        .filtered(s.filter);
        // the attribute the shadow phase set: the lights that reach each polygon
        surfaces.shadows = s.shadows.as_ref().map(|l| PolygonLights {
            casters: l.casters.clone(),
            lit: self.lit,
        });
        Some((self.screen, surfaces))
    }
}

/// How a polygon is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// At one intensity, every light reaching it (the mean of its triangle's unshadowed
    /// intensities at its vertices): the flat phase before the shadow phase.
    Unshadowed,
    /// At one intensity (the mean of its vertex intensities).
    Flat,
    /// Its vertex intensities interpolated (DO_FILL's Gouraud); a textured polygon lit
    /// per pixel with Gouraud's lighting and its texture.
    Gouraud,
    /// Lit per pixel (`crate::phong`).
    Phong,
}

/// Some polygons of the display list, ready to scan: those DO_FILL draws (flat ones at
/// their mean, Gouraud ones as they are) and those lit per pixel, each in scene order.
#[derive(Clone, Debug)]
pub struct Subset {
    /// Flat and Gouraud polygons.
    pub dofill: ScreenScene,
    /// Phong polygons and what lighting them needs (`None` when there are none).
    pub phong: Option<(ScreenScene, PhongSurfaces)>,
    /// Gouraud polygons of a textured scene, lit per pixel (`None` when there are none).
    pub textured: Option<(ScreenScene, PhongSurfaces)>,
    /// How many polygons it holds.
    pub polygons: u64,
}

impl Subset {
    /// The polygons `k` of `scene` with `pick(k)`, each drawn as `modes[k]` says.
    pub fn of(scene: &PolygonScene, modes: &[Mode], pick: impl Fn(usize) -> bool) -> Subset {
        let s = &scene.screen;
        let empty = || ScreenScene {
            width: s.width,
            height: s.height,
            channels: s.channels,
            polygons: Vec::new(),
        };
        let mut dofill = empty();
        let mut phong = PerPixel::new(empty());
        let mut textured = PerPixel::new(empty());
        let textured_scene = scene.phong.as_ref().is_some_and(|s| s.shader.textured());
        let mut polygons = 0;
        for (k, p) in scene.screen.polygons.iter().enumerate() {
            if !pick(k) {
                continue;
            }
            polygons += 1;
            match modes[k] {
                Mode::Unshadowed => dofill.polygons.push(flattened(&unshadowed(scene, k, p))),
                Mode::Flat => dofill.polygons.push(flattened(p)),
                // in a textured scene every Gouraud polygon is lit per pixel, as vanrij
                // draws the scene
                Mode::Gouraud if textured_scene => textured.push(scene, k, p),
                Mode::Gouraud => dofill.polygons.push(p.clone()),
                Mode::Phong => phong.push(scene, k, p),
            }
        }
        Subset {
            dofill,
            phong: phong.surfaces(scene, Shading::Phong),
            textured: textured.surfaces(scene, Shading::Gouraud),
            polygons,
        }
    }
}
