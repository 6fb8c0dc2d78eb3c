//! Woo & Chall §5, "Scanline information assisting texture mapping": a texture is
//! loaded when a surface that needs it is first shaded on a scanline (never, if every
//! surface using it is hidden), and freed after the last scanline that can use it — the
//! lowest pixel row any of its triangles reaches, known from their bounding boxes before
//! the frame starts. Their Figure 10 applies four textures with memory for three.
//!
//! Here a texture is a textured mesh's; the shading calls say which mesh they shade
//! ([`Residency::touch`]: the scene's [`TextureStore`] decodes its texels then, if they are
//! not resident), and the end of each pixel row frees what no later row can use
//! ([`Residency::end_row`]: the store drops the texels). The counters count what the store
//! did: decodes and drops of texels.

use super::triangle::Tri;
use cwisim_scene::SceneError;
use cwisim_world::texture::TextureStore;
use std::sync::Arc;

/// What loading and freeing did over a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ResidencyStats {
    /// Textured meshes in the scene.
    pub textures: u64,
    /// Loads: texels decoded (each texture at most once: one freed is not used again).
    pub loads: u64,
    /// Frees: texels dropped.
    pub frees: u64,
    /// Most textures resident during one pixel row.
    pub peak: u64,
    /// The first row where that many were resident.
    pub peak_row: u64,
    /// Most texture memory resident during one row, bytes (texels and tables).
    pub peak_bytes: u64,
}

/// Which textures are resident, row by row.
#[derive(Debug)]
pub struct Residency {
    /// The textures (`None`: a screen scene).
    store: Option<Arc<TextureStore>>,
    /// Per mesh: for a textured one, its texture's size in bytes and the last pixel row
    /// its triangles reach.
    textured: Vec<Option<(u64, u32)>>,
    loaded: Vec<bool>,
    freed: Vec<bool>,
    /// Resident now.
    resident: u64,
    bytes: u64,
    /// Most resident during the current row (what was loaded before it, and in it).
    row_peak: (u64, u64),
    /// What it did so far.
    pub stats: ResidencyStats,
}

impl Residency {
    /// The residency of a frame of `tris` (`Tri::surface` is the mesh) whose textures
    /// `store` holds; rows of an image `height` pixels high.
    pub fn new(tris: &[Tri], store: Option<Arc<TextureStore>>, height: u32) -> Residency {
        let bytes: Vec<Option<u64>> = store.as_ref().map_or_else(Vec::new, |s| {
            (0..s.len() as u32).map(|k| s.bytes(k)).collect()
        });
        let mut textured: Vec<Option<(u64, u32)>> = vec![None; bytes.len()];
        for t in tris {
            let k = t.surface as usize;
            let Some(Some(b)) = bytes.get(k) else {
                continue;
            };
            let bottom = t
                .points
                .iter()
                .map(|p| p[1])
                .fold(f64::NEG_INFINITY, f64::max);
            let row = bottom.floor().clamp(0.0, f64::from(height.max(1) - 1)) as u32;
            let last = textured[k].map_or(row, |(_, r)| r.max(row));
            textured[k] = Some((*b, last));
        }
        let n = bytes.len();
        Residency {
            store,
            stats: ResidencyStats {
                textures: textured.iter().flatten().count() as u64,
                ..ResidencyStats::default()
            },
            textured,
            loaded: vec![false; n],
            freed: vec![false; n],
            resident: 0,
            bytes: 0,
            row_peak: (0, 0),
        }
    }

    /// Whether any mesh is textured.
    pub fn any(&self) -> bool {
        self.stats.textures > 0
    }

    /// A shading call on mesh `mesh`: its texture is loaded if it is not yet (decoded by
    /// the store); the store's error if that fails.
    pub fn touch(&mut self, mesh: u32) -> Result<(), SceneError> {
        let k = mesh as usize;
        let Some(Some((bytes, _))) = self.textured.get(k) else {
            return Ok(());
        };
        if self.loaded[k] {
            return Ok(());
        }
        let decoded = match &self.store {
            Some(store) => store.load(mesh)?,
            None => false,
        };
        // a freed texture is never needed again: its last row is behind
        debug_assert!(
            !self.freed[k],
            "texture of mesh {k} used after its last row"
        );
        self.loaded[k] = true;
        self.resident += 1;
        self.bytes += bytes;
        self.stats.loads += u64::from(decoded);
        self.row_peak = (
            self.row_peak.0.max(self.resident),
            self.row_peak.1.max(self.bytes),
        );
        Ok(())
    }

    /// The end of pixel row `row`: the textures resident during it, counted; then those
    /// whose last row it was, freed. Returns how many were resident during it.
    pub fn end_row(&mut self, row: u32) -> u64 {
        let during = self.row_peak.0.max(self.resident);
        let bytes = self.row_peak.1.max(self.bytes);
        if during > self.stats.peak {
            self.stats.peak = during;
            self.stats.peak_row = u64::from(row);
        }
        self.stats.peak_bytes = self.stats.peak_bytes.max(bytes);
        for (k, t) in self.textured.iter().enumerate() {
            if let Some((b, last)) = t {
                if self.loaded[k] && *last <= row {
                    self.loaded[k] = false;
                    self.freed[k] = true;
                    self.resident -= 1;
                    self.bytes -= b;
                    let dropped = self.store.as_ref().is_some_and(|s| s.release(k as u32));
                    self.stats.frees += u64::from(dropped);
                }
            }
        }
        self.row_peak = (self.resident, self.bytes);
        during
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(mesh: u32, top: f64, bottom: f64) -> Tri {
        Tri::new(
            [[0.0, top], [4.0, top], [2.0, bottom]],
            [1.0; 3],
            [[0.0; 4]; 3],
            mesh,
            0,
        )
        .expect("a triangle")
    }

    #[test]
    fn a_texture_is_loaded_when_first_shaded_and_freed_after_its_last_row() {
        // meshes 0 and 1 textured (rows 0–4 and 3–9), 2 not, 3 textured but never shaded
        let tris = [
            tri(0, 0.0, 4.5),
            tri(1, 3.0, 9.2),
            tri(2, 0.0, 9.0),
            tri(3, 6.0, 8.0),
        ];
        let checker = |n: u32| -> cwisim_world::texture::TextureSpec {
            serde_json::from_value(serde_json::json!({ "checker": { "squares": [n, n] } }))
                .expect("a checker")
        };
        let specs = [Some(4), Some(2), None, Some(8)]
            .map(|n| n.map(|n| (checker(n), "meshes[k].material.texture".to_string())));
        let store = Arc::new(TextureStore::new(specs.to_vec(), 1, None, &|e| e).expect("a store"));
        let bytes = [0, 1, 3].map(|k| store.bytes(k).expect("textured"));
        let mut r = Residency::new(&tris, Some(Arc::clone(&store)), 12);
        assert_eq!(r.stats.textures, 3);
        let mut per_row = Vec::new();
        let mut resident = Vec::new();
        for row in 0..12 {
            if row <= 4 {
                r.touch(0).expect("decoded");
            }
            if (3..=9).contains(&row) {
                r.touch(1).expect("decoded");
            }
            r.touch(2).expect("untextured");
            resident.push([0, 1, 3].map(|k| store.is_resident(k)));
            per_row.push(r.end_row(row));
        }
        assert_eq!(per_row, [1, 1, 1, 2, 2, 1, 1, 1, 1, 1, 0, 0]);
        // the texels themselves: decoded at the first touch, dropped after the last row,
        // and mesh 3's (never shaded) never decoded
        assert_eq!(resident[0], [true, false, false]);
        assert_eq!(resident[3], [true, true, false]);
        assert_eq!(resident[5], [false, true, false]);
        assert_eq!(resident[10], [false, false, false]);
        assert!(!store.is_resident(3) && (store.loads(), store.frees()) == (2, 2));
        assert_eq!(
            r.stats,
            ResidencyStats {
                textures: 3,
                loads: 2,
                frees: 2,
                peak: 2,
                peak_row: 3,
                peak_bytes: bytes[0] + bytes[1],
            }
        );
    }
}
