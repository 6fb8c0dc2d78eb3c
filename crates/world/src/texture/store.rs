//! A scene's textures, decoded when a shading call first needs one and dropped when a
//! renderer says its last row is behind (Woo & Chall §5, "Scanline information assisting
//! texture mapping").
//!
//! Reading a scene checks every texture's file and size (its header: nothing decoded) and
//! what they would all need against the memory budget; the texels are decoded here, on
//! the first [`TextureStore::with`] or [`TextureStore::load`] of their mesh, so a texture
//! only hidden surfaces use is never decoded. A file that fails to decode then (cut short,
//! corrupt after a valid header) is the same located error it would have been when the
//! scene was read, returned to every caller that asks for it. [`TextureStore::release`]
//! drops a texture's texels (they are freed when the last lookup in flight ends); one
//! needed again is decoded again, and counted again.
//!
//! A pixel's lookup takes no lock: the texels are read through an [`ArcSwapOption`].
//! Decoding takes the texture's own lock, so two threads never decode one texture twice.

use super::{extent, load, Texture, TextureSpec};
use arc_swap::ArcSwapOption;
use cwisim_scene::SceneError;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

/// Per mesh, its texture, decoded on first use ([module docs](self)).
#[derive(Debug, Default)]
pub struct TextureStore {
    slots: Vec<Option<Slot>>,
    /// The scene file, for the errors of decodes ([`Self::in_file`]).
    file: OnceLock<PathBuf>,
}

/// One mesh's texture: where it comes from, its size, and its texels when resident.
struct Slot {
    spec: TextureSpec,
    /// The JSON path of the texture in the scene, for errors.
    field: String,
    /// The line and column of its image's name in the scene text, for errors.
    at: (Option<u64>, Option<u64>),
    base: Option<PathBuf>,
    channels: usize,
    size: (usize, usize),
    label: String,
    texels: ArcSwapOption<Texture>,
    /// Held while decoding; the error of a decode that failed, kept for every later caller.
    decoding: Mutex<Option<SceneError>>,
    loads: AtomicU64,
    frees: AtomicU64,
}

impl std::fmt::Debug for Slot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Slot")
            .field("field", &self.field)
            .field("size", &self.size)
            .field("label", &self.label)
            .field("resident", &self.texels.load().is_some())
            .finish()
    }
}

/// Two stores are equal when they hold the same textures (what is resident aside).
impl PartialEq for TextureStore {
    fn eq(&self, other: &Self) -> bool {
        self.slots.len() == other.slots.len()
            && self
                .slots
                .iter()
                .zip(&other.slots)
                .all(|(a, b)| match (a, b) {
                    (None, None) => true,
                    (Some(a), Some(b)) => {
                        a.spec == b.spec
                            && a.field == b.field
                            && a.base == b.base
                            && a.channels == b.channels
                            && a.size == b.size
                    }
                    _ => false,
                })
    }
}

impl TextureStore {
    /// The store of textures `specs` (per mesh, its texture and the JSON path naming it)
    /// in a scene of `channels` channels whose files are relative to `base`: each file
    /// checked and its size read from its header (or a checker's squares), nothing
    /// decoded. The caller checks the sizes against the memory budget ([`Self::bytes`]).
    /// `locate` gives an error about the scene its line and column in the scene's text
    /// (the errors here, and a decode's later).
    pub fn new(
        specs: Vec<Option<(TextureSpec, String)>>,
        channels: usize,
        base: Option<&Path>,
        locate: &dyn Fn(SceneError) -> SceneError,
    ) -> Result<TextureStore, SceneError> {
        let slots = specs
            .into_iter()
            .map(|s| {
                s.map(|(spec, field)| {
                    let size = extent(&spec, &field, base).map_err(locate)?;
                    let named = locate(SceneError::at_field(
                        cwisim_scene::SceneErrorKind::Shape,
                        format!("{field}.image"),
                        "",
                    ));
                    Ok(Slot {
                        at: (named.line, named.column),
                        label: label_of(&spec),
                        spec,
                        field,
                        base: base.map(Path::to_path_buf),
                        channels,
                        size,
                        texels: ArcSwapOption::empty(),
                        decoding: Mutex::new(None),
                        loads: AtomicU64::new(0),
                        frees: AtomicU64::new(0),
                    })
                })
                .transpose()
            })
            .collect::<Result<_, SceneError>>()?;
        Ok(TextureStore {
            slots,
            file: OnceLock::new(),
        })
    }

    /// Names the scene file `path` in the errors of later decodes (once: a store's scene
    /// comes from one file).
    pub fn in_file(&self, path: &Path) {
        let _ = self.file.set(path.to_path_buf());
    }

    fn slot(&self, mesh: u32) -> Option<&Slot> {
        self.slots.get(mesh as usize)?.as_ref()
    }

    /// Meshes (textured or not).
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether the store has no meshes.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Whether any mesh is textured.
    pub fn any(&self) -> bool {
        self.slots.iter().any(Option::is_some)
    }

    /// Whether mesh `mesh` is textured (nothing decoded).
    pub fn is_textured(&self, mesh: u32) -> bool {
        self.slot(mesh).is_some()
    }

    /// Mesh `mesh`'s texture size, `width × height` texels (nothing decoded).
    pub fn size(&self, mesh: u32) -> Option<(usize, usize)> {
        self.slot(mesh).map(|s| s.size)
    }

    /// What mesh `mesh`'s texture comes from: `checker`, or the image file's name.
    pub fn label(&self, mesh: u32) -> Option<&str> {
        self.slot(mesh).map(|s| s.label.as_str())
    }

    /// The memory mesh `mesh`'s texture takes when resident, bytes (texels and table).
    pub fn bytes(&self, mesh: u32) -> Option<u64> {
        self.slot(mesh)
            .map(|s| super::bytes_for(s.size.0, s.size.1, s.channels))
    }

    /// Whether mesh `mesh`'s texels are resident now.
    pub fn is_resident(&self, mesh: u32) -> bool {
        self.slot(mesh).is_some_and(|s| s.texels.load().is_some())
    }

    /// `f` of mesh `mesh`'s texture, decoded first if it is not resident; `Ok(None)` for
    /// an untextured mesh; the decoder's located error if it fails.
    pub fn with<R>(
        &self,
        mesh: u32,
        f: impl FnOnce(&Texture) -> R,
    ) -> Result<Option<R>, SceneError> {
        let Some(slot) = self.slot(mesh) else {
            return Ok(None);
        };
        if let Some(t) = slot.texels.load().as_deref() {
            return Ok(Some(f(t)));
        }
        let (texture, _) = slot.decode(self.file.get())?;
        Ok(Some(f(&texture)))
    }

    /// Makes mesh `mesh`'s texture resident: `Ok(true)` if this call decoded it, `Ok(false)`
    /// if it was resident already or the mesh is untextured.
    pub fn load(&self, mesh: u32) -> Result<bool, SceneError> {
        let Some(slot) = self.slot(mesh) else {
            return Ok(false);
        };
        if slot.texels.load().is_some() {
            return Ok(false);
        }
        slot.decode(self.file.get()).map(|(_, decoded)| decoded)
    }

    /// Drops mesh `mesh`'s texels; whether they were resident. They are freed when the
    /// last lookup holding them ends.
    pub fn release(&self, mesh: u32) -> bool {
        let Some(slot) = self.slot(mesh) else {
            return false;
        };
        let was = slot.texels.swap(None).is_some();
        if was {
            slot.frees.fetch_add(1, Ordering::Relaxed);
        }
        was
    }

    /// Decodes so far, over every texture.
    pub fn loads(&self) -> u64 {
        self.slots
            .iter()
            .flatten()
            .map(|s| s.loads.load(Ordering::Relaxed))
            .sum()
    }

    /// Releases of resident texels so far, over every texture.
    pub fn frees(&self) -> u64 {
        self.slots
            .iter()
            .flatten()
            .map(|s| s.frees.load(Ordering::Relaxed))
            .sum()
    }
}

/// A frame's textures dropped after the last pixel row their triangles reach, for a
/// renderer whose rows are emitted in bands (in any order, on any thread): each band says
/// when it is done ([`RowRelease::rows_done`]), and once every row up to a texture's last
/// is done, the store drops its texels. A frame's last row done starts the count again for
/// the next frame (a texture used again is decoded again).
#[derive(Debug)]
pub struct RowRelease {
    store: Arc<TextureStore>,
    /// `(last row, mesh)` of every textured mesh drawn, by last row.
    last: Vec<(u32, u32)>,
    state: Mutex<Rows>,
}

/// Which rows are done, and how far without a gap.
#[derive(Debug)]
struct Rows {
    done: Vec<bool>,
    /// Every row before it is done.
    prefix: usize,
    /// `last[..released]` are dropped.
    released: usize,
}

impl RowRelease {
    /// The release of `store`'s textures for a frame of triangles `spans`: each its mesh
    /// and the largest `y` it reaches (pixel row `⌊y⌋`).
    pub fn new(
        store: Arc<TextureStore>,
        spans: impl IntoIterator<Item = (u32, f64)>,
    ) -> RowRelease {
        let mut last: Vec<Option<u32>> = vec![None; store.len()];
        for (mesh, y) in spans {
            if !store.is_textured(mesh) || !y.is_finite() {
                continue;
            }
            // a triangle may reach far below the image (nothing clips it there): no frame
            // has more rows than a trace, so neither does the count of rows done
            let bottom = cwisim_isa::MAX_LINES - 1;
            let row = y.floor().clamp(0.0, f64::from(bottom)) as u32;
            let slot = &mut last[mesh as usize];
            *slot = Some(slot.map_or(row, |r| r.max(row)));
        }
        let mut last: Vec<(u32, u32)> = last
            .into_iter()
            .enumerate()
            .filter_map(|(k, r)| r.map(|r| (r, k as u32)))
            .collect();
        last.sort_unstable();
        let rows = last.last().map_or(0, |l| l.0 as usize + 1);
        RowRelease {
            store,
            last,
            state: Mutex::new(Rows {
                done: vec![false; rows],
                prefix: 0,
                released: 0,
            }),
        }
    }

    /// The release of `store`'s textures for a frame of the projected triangles `tris`.
    pub fn of_triangles(
        store: Arc<TextureStore>,
        tris: &[crate::face::ScreenTriangle],
    ) -> RowRelease {
        RowRelease::new(
            store,
            tris.iter().map(|t| {
                let bottom = t
                    .points
                    .iter()
                    .map(|p| p[1])
                    .fold(f64::NEG_INFINITY, f64::max);
                (t.mesh, bottom)
            }),
        )
    }

    /// Rows `rows` are emitted: the textures whose last row is now behind every row done
    /// are dropped.
    pub fn rows_done(&self, rows: std::ops::Range<u32>) {
        let Ok(mut state) = self.state.lock() else {
            return;
        };
        let n = state.done.len();
        let (a, b) = ((rows.start as usize).min(n), (rows.end as usize).min(n));
        state.done[a..b].iter_mut().for_each(|d| *d = true);
        while state.prefix < n && state.done[state.prefix] {
            state.prefix += 1;
        }
        while let Some(&(row, mesh)) = self.last.get(state.released) {
            if (row as usize) >= state.prefix {
                break;
            }
            self.store.release(mesh);
            state.released += 1;
        }
        if state.prefix == n {
            // the frame's rows all done: the next frame counts again
            state.done.iter_mut().for_each(|d| *d = false);
            state.prefix = 0;
            state.released = 0;
        }
    }
}

impl Slot {
    /// The texels, decoded if no other thread did meanwhile; whether this call decoded.
    /// An error is located in the scene (`file`, the line and column of the image's name).
    fn decode(&self, file: Option<&PathBuf>) -> Result<(Arc<Texture>, bool), SceneError> {
        let mut failed = self
            .decoding
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(e) = &*failed {
            return Err(e.clone());
        }
        if let Some(t) = self.texels.load_full() {
            return Ok((t, false));
        }
        match load(&self.spec, &self.field, self.channels, self.base.as_deref()) {
            Ok(t) => {
                let t = Arc::new(t);
                self.texels.store(Some(Arc::clone(&t)));
                self.loads.fetch_add(1, Ordering::Relaxed);
                Ok((t, true))
            }
            Err(mut e) => {
                (e.line, e.column) = self.at;
                if e.path.is_none() {
                    e.path = file.cloned();
                }
                *failed = Some(e.clone());
                Err(e)
            }
        }
    }
}

/// What a texture of `spec` comes from, for summaries: `checker`, or the file's name.
fn label_of(spec: &TextureSpec) -> String {
    match (&spec.checker, &spec.image) {
        (Some(_), _) => "checker".into(),
        (None, image) => {
            let name = image.as_deref().unwrap_or_default();
            Path::new(name)
                .file_name()
                .map_or_else(|| name.to_string(), |n| n.to_string_lossy().into_owned())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker(squares: u32) -> TextureSpec {
        serde_json::from_value(serde_json::json!({
            "checker": { "squares": [squares, squares] }
        }))
        .expect("a checker")
    }

    #[test]
    fn a_texture_is_decoded_on_first_use_once_and_again_after_a_release() {
        let store = TextureStore::new(
            vec![
                Some((checker(4), "meshes[0].material.texture".into())),
                None,
            ],
            3,
            None,
            &|e| e,
        )
        .expect("a store");
        assert!(store.is_textured(0) && !store.is_textured(1) && !store.is_textured(7));
        assert_eq!(store.size(0), Some((4, 4)));
        assert_eq!(store.label(0), Some("checker"));
        assert!(
            !store.is_resident(0),
            "nothing decoded when the store is made"
        );
        assert_eq!(store.loads(), 0);
        assert_eq!(store.with(1, |_| ()).expect("untextured"), None);
        let size = store.with(0, |t| t.size()).expect("decoded");
        assert_eq!(size, Some((4, 4)));
        assert!(store.is_resident(0));
        assert!(!store.load(0).expect("resident"), "already resident");
        assert_eq!((store.loads(), store.frees()), (1, 0));
        assert!(store.release(0));
        assert!(!store.release(0), "released once");
        assert!(!store.is_resident(0));
        assert!(store.load(0).expect("decoded again"));
        assert_eq!((store.loads(), store.frees()), (2, 1));
    }

    #[test]
    fn a_png_that_fails_to_decode_at_first_use_is_a_located_error_for_every_caller() {
        let dir = std::env::temp_dir().join(format!("cwisim-store-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a directory");
        // a valid header (IHDR: 4×4, 8-bit RGB) and nothing after it
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        let ihdr = [0, 0, 0, 4, 0, 0, 0, 4, 8, 2, 0, 0, 0];
        png.extend_from_slice(&(ihdr.len() as u32).to_be_bytes());
        let mut chunk = b"IHDR".to_vec();
        chunk.extend_from_slice(&ihdr);
        png.extend_from_slice(&chunk);
        png.extend_from_slice(&crc(&chunk).to_be_bytes());
        std::fs::write(dir.join("cut.png"), &png).expect("written");
        let spec: TextureSpec =
            serde_json::from_value(serde_json::json!({ "image": "cut.png" })).expect("a spec");
        let store = TextureStore::new(
            vec![Some((spec, "meshes[0].material.texture".into()))],
            3,
            Some(&dir),
            &|e| SceneError {
                line: Some(7),
                column: Some(29),
                ..e
            },
        )
        .expect("the header is read, nothing decoded");
        store.in_file(Path::new("scene.json"));
        assert_eq!(store.size(0), Some((4, 4)));
        let first = store.with(0, |_| ()).expect_err("cut short");
        let text = first.to_string();
        assert!(
            text.starts_with("scene.json:7:29: meshes[0].material.texture.image: texture \"cut.png\": not a readable PNG image"),
            "{text}"
        );
        assert_eq!(store.load(0).expect_err("still cut short"), first);
        assert_eq!(store.loads(), 0);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_texture_is_dropped_once_every_row_up_to_its_last_is_done_in_any_order() {
        let specs = vec![
            Some((checker(2), "a".into())),
            Some((checker(2), "b".into())),
            None,
        ];
        let store = Arc::new(TextureStore::new(specs, 1, None, &|e| e).expect("a store"));
        // mesh 0 reaches row 3, mesh 1 row 7, mesh 2 is not textured
        let release = RowRelease::new(Arc::clone(&store), [(0, 1.5), (0, 3.2), (1, 7.9), (2, 9.0)]);
        store.load(0).expect("decoded");
        store.load(1).expect("decoded");
        // bands out of order: rows 4–7 first, then 0–3
        release.rows_done(4..8);
        assert!(
            store.is_resident(0) && store.is_resident(1),
            "rows 0-3 not done"
        );
        release.rows_done(0..4);
        assert!(!store.is_resident(0) && !store.is_resident(1));
        assert_eq!(store.frees(), 2);
        // the next frame counts again
        store.load(0).expect("decoded again");
        release.rows_done(0..2);
        assert!(store.is_resident(0), "row 3 not done yet");
        release.rows_done(2..4);
        assert!(!store.is_resident(0));
    }

    #[test]
    fn a_triangle_far_below_the_image_counts_no_more_rows_than_a_frame_has() {
        let store = Arc::new(
            TextureStore::new(vec![Some((checker(2), "a".into()))], 1, None, &|e| e)
                .expect("a store"),
        );
        let release = RowRelease::new(Arc::clone(&store), [(0, 1e15)]);
        let rows = release.state.lock().expect("unpoisoned").done.len();
        assert_eq!(rows, cwisim_isa::MAX_LINES as usize);
    }

    fn crc(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
}
