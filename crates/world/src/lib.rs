//! # cwisim-world — 3D scenes for the Y-processor
//!
//! The host side that the CWI architecture assumes: the Y-processors receive objects
//! whose hidden surfaces are already dealt with. This crate turns a 3D world scene into
//! the screen-space polygons `cwisim-ypipe` scan-converts:
//!
//! 1. [`scene`] — world scene files (`"kind": "world"`): camera, lights, materials with
//!    the report's `k_a`, `k_d`, `k_s`, `n`, meshes; [`mesh`] builds the meshes (inline,
//!    [`obj`] files, surfaces of revolution) with normals per face corner.
//! 2. [`project`] — transform and lighting: [`camera`] projection, back-face culling,
//!    the report's formula ([`lighting`]) per vertex (Gouraud) or per face (flat):
//!    [`face::ScreenTriangle`]s.
//! 3. [`visibility`] — visible surfaces, two ways ([`Visibility`]): exact object-space
//!    fragments (polygon booleans with `i_overlay`), or the triangles in front-to-back
//!    order so that the array's `Eval0` claims hide farther ones. [`sweep`] finds the
//!    visible parts of pieces along a strip slab by slab, with no polygon boolean
//!    (`nishita`'s strips; a frame strip by strip, not yet drawn with).
//! 4. [`to_screen`] — the result as a `cwisim_scene::ScreenScene`.
//!
//! [`parse_any`] / [`load_any`] read any scene file (screen or world); [`embedded`] holds
//! the scenes built into the binary.
//!
//! - [`bezier`] — bicubic Bézier patches (the Utah teapot), evaluated and tessellated.
//! - [`clip`] — Bézier clipping: the roots of a curve in Bernstein form (Nishita et al.).
//! - [`texture`] — textures (PNG images, checkerboards) and their summed-area tables;
//!   [`shade`] looks them up at a pixel.

#![warn(missing_docs)]

pub mod bezier;
mod boolean;
pub mod camera;
pub mod clip;
mod cover;
pub mod embedded;
pub mod events;
pub mod face;
pub mod lighting;
pub mod mesh;
pub mod obj;
pub mod project;
pub mod scene;
pub mod shade;
pub mod shadow;
pub mod sweep;
pub mod texture;
pub mod visibility;

use cwisim_scene::Shading;
use cwisim_scene::{parse_scene, read_kind, Polygon, Scene, SceneError, ScreenScene};
use std::path::Path;

pub use project::ProjectStats;
pub use scene::WorldScene;
pub use visibility::VisibilityStats;

/// The scene kinds `cwisim` reads.
pub const KINDS: &[&str] = &["screen", "world"];

/// A scene of any kind.
#[derive(Clone, Debug, PartialEq)]
// one scene per run: its size on the stack does not matter
#[allow(clippy::large_enum_variant)]
pub enum AnyScene {
    /// Polygons in screen space.
    Screen(ScreenScene),
    /// A 3D world.
    World(WorldScene),
}

impl AnyScene {
    /// `"screen"` or `"world"`.
    pub fn kind(&self) -> &'static str {
        match self {
            AnyScene::Screen(_) => "screen",
            AnyScene::World(_) => "world",
        }
    }

    /// The image size.
    pub fn size(&self) -> (u32, u32) {
        match self {
            AnyScene::Screen(s) => (s.width, s.height),
            AnyScene::World(w) => (w.width(), w.height()),
        }
    }

    /// Whether a mesh of it has a texture.
    pub fn is_textured(&self) -> bool {
        match self {
            AnyScene::Screen(_) => false,
            AnyScene::World(w) => w.textures.any(),
        }
    }

    /// The same scene with its Bézier meshes tessellated `n` × `n` per patch (a screen
    /// scene, or a world without Bézier meshes, is unchanged).
    pub fn with_tessellation(self, n: u32) -> Result<AnyScene, SceneError> {
        match self {
            AnyScene::World(w) => Ok(AnyScene::World(w.with_tessellation(n)?)),
            screen => Ok(screen),
        }
    }

    /// Whether every Bézier mesh is tessellated `n` × `n` per patch (true when there is
    /// none).
    pub fn is_tessellated_at(&self, n: u32) -> bool {
        match self {
            AnyScene::World(w) => w
                .spec
                .meshes
                .iter()
                .filter_map(|m| m.bezier.as_ref())
                .all(|b| b.tessellate == n),
            AnyScene::Screen(_) => true,
        }
    }

    /// Whether any mesh is made of Bézier patches.
    pub fn has_patches(&self) -> bool {
        match self {
            AnyScene::World(w) => w.spec.meshes.iter().any(|m| m.bezier.is_some()),
            AnyScene::Screen(_) => false,
        }
    }

    /// The same scene drawn at another size: a world scene's camera keeps its vertical
    /// field of view; a screen scene's polygons are scaled (x by `width / old width`, y by
    /// `height / old height`).
    pub fn with_size(self, width: u32, height: u32) -> Result<AnyScene, SceneError> {
        match self {
            AnyScene::World(w) => Ok(AnyScene::World(w.with_size(width, height)?)),
            AnyScene::Screen(mut s) => {
                let (fx, fy) = (
                    f64::from(width) / f64::from(s.width),
                    f64::from(height) / f64::from(s.height),
                );
                for p in &mut s.polygons {
                    for v in &mut p.vertices {
                        *v = [v[0] * fx, v[1] * fy];
                    }
                }
                s.width = width;
                s.height = height;
                s.validate()?;
                Ok(AnyScene::Screen(s))
            }
        }
    }
}

/// Reads a scene of any kind from JSON text. OBJ files named by a world scene are read
/// relative to `base`.
pub fn parse_any(text: &str, base: Option<&Path>) -> Result<AnyScene, SceneError> {
    match read_kind(text, KINDS)?.as_str() {
        "screen" => {
            let Scene::Screen(s) = parse_scene(text)?;
            Ok(AnyScene::Screen(s))
        }
        _ => Ok(AnyScene::World(scene::parse_world(text, base)?)),
    }
}

/// The files a scene's text names besides itself — its meshes' OBJ files
/// (`meshes[K].obj`) and its textures' images (`meshes[K].material.texture.image`) — each
/// with the JSON path that names it, as the loader reads them (relative to `base`). A
/// command checks its outputs against these before any work (an output may not be an
/// input). A text that is not a world scene, or not a readable one, names none: reading
/// it says why.
pub fn referenced_files(text: &str, base: Option<&Path>) -> Vec<(String, std::path::PathBuf)> {
    let Ok(spec) = serde_json::from_str::<scene::WorldSpec>(text) else {
        return Vec::new();
    };
    let at = |name: &str| base.map_or_else(|| Path::new(name).to_path_buf(), |b| b.join(name));
    let mut files = Vec::new();
    for (k, m) in spec.meshes.iter().enumerate() {
        if let Some(obj) = &m.obj {
            files.push((format!("meshes[{k}].obj"), at(obj)));
        }
        if let Some(image) = m.material.texture.as_ref().and_then(|t| t.image.as_ref()) {
            files.push((format!("meshes[{k}].material.texture.image"), at(image)));
        }
    }
    files
}

/// Reads a scene file of any kind; errors name the file.
pub fn load_any(path: &Path) -> Result<AnyScene, SceneError> {
    let text = cwisim_scene::read_scene_text(path)?;
    let scene = parse_any(&text, path.parent()).map_err(|e| match e.path {
        Some(_) => e, // an OBJ file's error names that file
        None => e.in_file(path),
    })?;
    if let AnyScene::World(w) = &scene {
        // a texture decoded when first needed names the scene file too
        w.textures.in_file(path);
    }
    Ok(scene)
}

/// How hidden surfaces are removed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Visibility {
    /// In object space: each triangle minus what hides it, exactly
    /// ([`visibility::exact_fragments`]).
    #[default]
    Exact,
    /// By the array: whole triangles front to back, each claiming its fully covered
    /// pixels with `Eval0` (set the Y-processor's `Claim::Eval0`).
    Eval0,
}

impl Visibility {
    /// Every value, in order.
    pub const ALL: [Visibility; 2] = [Visibility::Exact, Visibility::Eval0];

    /// The name the command line, the summaries and `tradeoff` use.
    pub fn name(self) -> &'static str {
        match self {
            Visibility::Exact => "exact",
            Visibility::Eval0 => "eval0",
        }
    }
}

impl std::fmt::Display for Visibility {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Visibility {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Visibility::ALL
            .into_iter()
            .find(|v| v.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown visibility `{s}`; expected exact or eval0"))
    }
}

/// A world scene made ready for the Y-processor.
#[derive(Clone, Debug, PartialEq)]
pub struct Prepared {
    /// The screen-space polygons, in the order to send them.
    pub screen: ScreenScene,
    /// What projection did.
    pub project: ProjectStats,
    /// What visibility did (exact only).
    pub visibility: Option<VisibilityStats>,
}

/// The polygons to send for lit screen triangles, in order: exact visible fragments,
/// or the whole triangles front to back ([`Visibility`]).
pub fn resolve<S: Sync>(
    tris: &[face::ScreenTriangle<S>],
    channels: usize,
    visibility: Visibility,
) -> (Vec<Polygon>, Option<VisibilityStats>) {
    resolve_on(tris, channels, visibility, 1)
}

/// [`resolve`] with exact visibility on `threads` threads
/// ([`visibility::exact_fragments_on`]; 0: one per core): the same polygons and
/// statistics, bit for bit, at any thread count. Front-to-back order is a sort, on one
/// thread.
pub fn resolve_on<S: Sync>(
    tris: &[face::ScreenTriangle<S>],
    channels: usize,
    visibility: Visibility,
    threads: usize,
) -> (Vec<Polygon>, Option<VisibilityStats>) {
    match visibility {
        Visibility::Exact => {
            let (fragments, stats) = visibility::exact_fragments_on(tris, channels, threads);
            (
                fragments.into_iter().map(|f| f.polygon).collect(),
                Some(stats),
            )
        }
        Visibility::Eval0 => (
            visibility::front_to_back_fragments(tris, channels)
                .into_iter()
                .map(|f| f.polygon)
                .collect(),
            None,
        ),
    }
}

/// Projects, lights and resolves the visibility of a world scene
/// ([`project::project_plain`], then [`resolve`]).
pub fn to_screen(
    scene: &WorldScene,
    shading: Shading,
    visibility: Visibility,
) -> Result<Prepared, SceneError> {
    let (tris, project) = project::project_plain(scene, shading)?;
    let (polygons, visibility) = resolve(&tris, scene.channels(), visibility);
    Ok(Prepared {
        screen: scene.screen(polygons),
        project,
        visibility,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn referenced_files_lists_objs_and_texture_images_relative_to_base() {
        let text = r#"{ "kind": "world", "width": 8, "height": 8, "channels": 1,
            "camera": { "eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 30 },
            "ambient": 0.2, "lights": [],
            "meshes": [
              { "material": { "k_a": 1, "k_d": 0, "k_s": 0, "n": 1,
                              "texture": { "image": "t.png" } }, "obj": "a.obj" },
              { "material": { "k_a": 1, "k_d": 0, "k_s": 0, "n": 1,
                              "texture": { "checker": { "squares": [2, 2] } } },
                "obj": "b.obj" }
            ] }"#;
        let files = referenced_files(text, Some(Path::new("dir")));
        let expect = [
            ("meshes[0].obj", "dir/a.obj"),
            ("meshes[0].material.texture.image", "dir/t.png"),
            ("meshes[1].obj", "dir/b.obj"),
        ];
        assert_eq!(files.len(), expect.len(), "{files:?}");
        for ((field, path), (f, p)) in files.iter().zip(expect) {
            assert_eq!((field.as_str(), path.as_path()), (f, Path::new(p)));
        }
        // not a world scene, or not one at all: none
        assert!(referenced_files("{\"kind\": \"screen\"}", None).is_empty());
        assert!(referenced_files("not json", None).is_empty());
    }
}
