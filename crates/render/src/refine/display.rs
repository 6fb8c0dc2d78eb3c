//! The host's display list: how each polygon is drawn at a phase (flat, Gouraud or
//! Phong), and the polygons of one phase split into those kept from the previous frame
//! and those the phase regenerates.

use super::measure::flattened;
use crate::prepare::{PhongSurfaces, PolygonScene};
use cwisim_scene::ScreenScene;

/// How a polygon is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// At one intensity (the mean of its vertex intensities).
    Flat,
    /// Its vertex intensities interpolated (DO_FILL's Gouraud).
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
        let mut phong = empty();
        let mut sources = Vec::new();
        let mut polygons = 0;
        for (k, p) in scene.screen.polygons.iter().enumerate() {
            if !pick(k) {
                continue;
            }
            polygons += 1;
            match modes[k] {
                Mode::Flat => dofill.polygons.push(flattened(p)),
                Mode::Gouraud => dofill.polygons.push(p.clone()),
                Mode::Phong => {
                    phong.polygons.push(p.clone());
                    if let Some(s) = &scene.phong {
                        sources.push(s.sources[k]);
                    }
                }
            }
        }
        let phong = match &scene.phong {
            Some(s) if !phong.polygons.is_empty() => Some((
                phong,
                PhongSurfaces::new(s.triangles.clone(), sources, s.shader.clone()),
            )),
            _ => None,
        };
        Subset {
            dofill,
            phong,
            polygons,
        }
    }
}
