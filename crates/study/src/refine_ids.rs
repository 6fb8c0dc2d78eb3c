//! The polygon-ID view of a refinement (`cwisim refine --ids`): which polygon of the
//! display list owns each pixel, gathered scanline by scanline from
//! [`cwisim_render::refine::ids::IdView`] into an image for a file — false colour as a
//! PNG, the identifiers themselves as `.npy`.

use crate::plot::Rgb;
use cwisim_render::refine::ids::{IdView, NONE, SHARED};
use cwisim_render::RenderError;
use npyz::WriterBuilder;
use std::io::{self, Write};

/// The owners of every pixel: `0` none, `k` the display list's polygon `k − 1`,
/// `u32::MAX` more than one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IdImage {
    /// Pixel columns.
    pub width: usize,
    /// Scanlines.
    pub lines: usize,
    /// `lines × width` owners, row-major.
    pub owners: Vec<u32>,
}

impl IdImage {
    /// Every scanline of `view`.
    pub fn gather(view: &IdView, lines: usize) -> Result<IdImage, RenderError> {
        let width = view.width();
        let mut owners = Vec::with_capacity(width * lines);
        view.scan(&mut |_, row| owners.extend_from_slice(row))?;
        Ok(IdImage {
            width,
            lines: owners.len() / width.max(1),
            owners,
        })
    }

    /// Pixels some polygon owns.
    pub fn owned(&self) -> u64 {
        self.owners.iter().filter(|&&o| o != NONE).count() as u64
    }

    /// Pixels more than one polygon reaches (none when the fragments are disjoint).
    pub fn shared(&self) -> u64 {
        self.owners.iter().filter(|&&o| o == SHARED).count() as u64
    }
}

/// A colour per identifier: black for none, white for shared, otherwise a colour from a
/// hash of the identifier (neighbouring polygons differ), never near black or white.
pub fn id_color(id: u32) -> [u8; 3] {
    match id {
        NONE => [0, 0, 0],
        SHARED => [255, 255, 255],
        _ => {
            // splitmix-style mixing of the identifier
            let mut h = u64::from(id).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            h ^= h >> 31;
            h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h ^= h >> 29;
            let c = |s: u32| 40 + ((h >> s) & 0xFF) as u8 % 176;
            [c(0), c(8), c(16)]
        }
    }
}

/// The view in false colour.
pub fn id_rgb(image: &IdImage) -> Rgb {
    Rgb {
        width: image.width as u32,
        height: image.lines as u32,
        data: image.owners.iter().flat_map(|&o| id_color(o)).collect(),
    }
}

/// The `.npy` bytes of the view: `uint32` (`<u4`), shape `(scanlines, width)`.
pub fn encode_id_npy<W: Write>(out: W, image: &IdImage) -> io::Result<()> {
    let shape = [image.lines as u64, image.width as u64];
    let mut writer = npyz::WriteOptions::<u32>::new()
        .default_dtype()
        .shape(&shape)
        .writer(out)
        .begin_nd()?;
    writer.extend(image.owners.iter().copied())?;
    writer.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_tell_none_shared_and_polygons_apart() {
        assert_eq!(id_color(NONE), [0, 0, 0]);
        assert_eq!(id_color(SHARED), [255, 255, 255]);
        let colours: std::collections::HashSet<[u8; 3]> = (1..200).map(id_color).collect();
        assert!(colours.len() > 190, "{} distinct", colours.len());
        for id in 1..200 {
            let c = id_color(id);
            assert!(c.iter().all(|&v| (40..216).contains(&v)), "{id}: {c:?}");
        }
    }

    #[test]
    fn the_npy_holds_the_owners() {
        let image = IdImage {
            width: 3,
            lines: 2,
            owners: vec![0, 1, 2, 2, SHARED, 0],
        };
        let mut bytes = Vec::new();
        encode_id_npy(&mut bytes, &image).unwrap();
        let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(npy.shape(), &[2, 3]);
        let back: Vec<u32> = npy.into_vec().unwrap();
        assert_eq!(back, image.owners);
    }
}
