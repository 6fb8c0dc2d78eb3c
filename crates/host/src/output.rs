//! The image outputs of `cwisim run`: an exact NumPy array, or an 8-bit PNG picture.
//!
//! Both take an [`Image`]: every scanline the array shifted out, all frames stacked top
//! to bottom, shape `(scanlines, width, channels)`.

use crate::error::CliError;
use crate::files::write_atomic;
use cwisim_xproc::Image;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use npyz::WriterBuilder;
use std::io::{self, Write};
use std::path::Path;

/// What `-o` says about a trace that output no scanline.
pub const NO_SCANLINE: &str = "the trace output no scanline (no Refresh); nothing to write";

/// Writes `image` to `path` as a NumPy `.npy` file: float64 (`<f8`), shape
/// `(scanlines, width, channels)`, C order, every value exactly as the array computed it
/// (nothing clamped; an image of no scanline has shape `(0, width, channels)`).
///
/// Written all-or-nothing ([`write_atomic`]).
pub fn write_npy(path: &Path, image: &Image) -> Result<(), CliError> {
    write_atomic(path, |out| {
        encode_npy(out, image).map_err(|e| CliError::write(path, e))
    })
}

/// The `.npy` bytes of [`write_npy`], to any writer.
pub fn encode_npy<W: Write>(out: W, image: &Image) -> io::Result<()> {
    let shape = [
        image.lines as u64,
        image.width as u64,
        image.channels as u64,
    ];
    let expected = shape.iter().product::<u64>();
    if expected != image.data.len() as u64 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "the image holds {} values, its shape {shape:?} needs {expected}",
                image.data.len()
            ),
        ));
    }
    let mut writer = npyz::WriteOptions::<f64>::new()
        .default_dtype()
        .shape(&shape)
        .writer(out)
        .begin_nd()?;
    writer.extend(image.data.iter().copied())?;
    writer.finish()
}

/// One value as an 8-bit PNG sample: `round(clamp(v, 0, 1) × 255)`. Values below 0 become
/// 0, values above 1 (and +∞) become 255, NaN becomes 0.
pub fn png_sample(v: f64) -> u8 {
    // `as` saturates, and maps NaN to 0.
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The PNG colour type for a channel count: 1 → 8-bit grey, 3 → 8-bit RGB; anything else
/// is an error pointing to `--npy`.
pub fn png_color(channels: usize) -> Result<ExtendedColorType, CliError> {
    match channels {
        1 => Ok(ExtendedColorType::L8),
        3 => Ok(ExtendedColorType::Rgb8),
        n => Err(CliError::Usage(format!(
            "PNG needs 1 or 3 channels, the trace has {n}; use --npy for the exact values"
        ))),
    }
}

/// Checks that `image` can be a PNG: 1 or 3 channels, at least one scanline, dimensions
/// within PNG's limits. Returns the colour type and `(width, height)`.
pub fn check_png(image: &Image) -> Result<(ExtendedColorType, u32, u32), CliError> {
    let color = png_color(image.channels)?;
    if image.lines == 0 || image.width == 0 {
        return Err(CliError::Usage(NO_SCANLINE.into()));
    }
    const PNG_MAX: u32 = i32::MAX as u32;
    let dim = |v: usize, what: &str| {
        u32::try_from(v)
            .ok()
            .filter(|v| *v <= PNG_MAX)
            .ok_or_else(|| CliError::Usage(format!("a PNG cannot be {v} pixels {what}; use --npy")))
    };
    Ok((color, dim(image.width, "wide")?, dim(image.lines, "high")?))
}

/// Writes `image` to `path` as an 8-bit PNG, one pixel row per scanline, each value mapped
/// by [`png_sample`] (clamped to `[0, 1]`, scaled to `0..=255`, rounded). Fails without
/// creating the file when [`check_png`] does.
///
/// Written all-or-nothing ([`write_atomic`]).
pub fn write_png(path: &Path, image: &Image) -> Result<(), CliError> {
    check_png(image)?;
    write_atomic(path, |out| {
        encode_png(out, image).map_err(|e| CliError::write(path, e))
    })
}

/// The PNG bytes of [`write_png`], to any writer.
pub fn encode_png<W: Write>(out: W, image: &Image) -> io::Result<()> {
    let (color, width, height) =
        check_png(image).map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e.one_line()))?;
    let pixels: Vec<u8> = image.data.iter().map(|v| png_sample(*v)).collect();
    PngEncoder::new(out)
        .write_image(&pixels, width, height, color)
        .map_err(|e| match e {
            image::ImageError::IoError(e) => e,
            other => io::Error::other(other.to_string()),
        })
}

/// Writes a drawn plot (an RGB bitmap from `cwisim-study`) as a PNG, all or nothing.
pub fn write_rgb_png(path: &Path, rgb: &cwisim_study::plot::Rgb) -> Result<(), CliError> {
    crate::files::write_atomic(path, |w| {
        rgb.encode_png(w).map_err(|e| CliError::write(path, e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(lines: usize, width: usize, channels: usize, data: Vec<f64>) -> Image {
        Image {
            width,
            channels,
            lines,
            data,
        }
    }

    #[test]
    fn png_samples_clamp_and_round() {
        assert_eq!(png_sample(0.0), 0);
        assert_eq!(png_sample(-0.0), 0);
        assert_eq!(png_sample(-3.0), 0);
        assert_eq!(png_sample(1.0), 255);
        assert_eq!(png_sample(7.5), 255);
        assert_eq!(png_sample(f64::INFINITY), 255);
        assert_eq!(png_sample(f64::NEG_INFINITY), 0);
        assert_eq!(png_sample(f64::NAN), 0);
        assert_eq!(png_sample(0.5), 128); // 127.5 rounds half away from zero
        assert_eq!(png_sample(0.25), 64); // 63.75
        assert_eq!(png_sample(1.0 / 255.0), 1);
        assert_eq!(png_sample(0.4 / 255.0), 0);
    }

    #[test]
    fn grey_png_decodes_to_the_mapped_values() {
        let img = image(2, 3, 1, vec![0.0, 0.5, 1.0, -1.0, 2.0, 0.25]);
        let mut bytes = Vec::new();
        encode_png(&mut bytes, &img).expect("encode");
        let decoded =
            image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).expect("decode");
        assert_eq!(decoded.color(), image::ColorType::L8);
        assert_eq!((decoded.width(), decoded.height()), (3, 2));
        assert_eq!(decoded.into_luma8().into_raw(), [0, 128, 255, 0, 255, 64]);
    }

    #[test]
    fn rgb_png_keeps_channel_order() {
        let img = image(1, 2, 3, vec![1.0, 0.0, 0.0, 0.0, 0.5, 1.0]);
        let mut bytes = Vec::new();
        encode_png(&mut bytes, &img).expect("encode");
        let decoded =
            image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).expect("decode");
        assert_eq!(decoded.color(), image::ColorType::Rgb8);
        assert_eq!(decoded.into_rgb8().into_raw(), [255, 0, 0, 0, 128, 255]);
    }

    #[test]
    fn png_refuses_two_and_four_channels_and_empty_images() {
        for c in [2, 4] {
            let e = check_png(&image(1, 1, c, vec![0.0; c])).expect_err("channels");
            assert!(e.to_string().contains("PNG needs 1 or 3 channels"), "{e}");
            assert!(e.to_string().contains("--npy"), "{e}");
        }
        let e = check_png(&image(0, 4, 1, vec![])).expect_err("empty");
        assert_eq!(e.to_string(), NO_SCANLINE);
        assert!(encode_png(Vec::new(), &image(0, 4, 1, vec![])).is_err());
    }

    #[test]
    fn npy_round_trips_shape_and_exact_values() {
        let data = vec![0.1, -2.5, f64::MAX, 1e-300, -0.0, 7.0];
        let img = image(2, 1, 3, data.clone());
        let mut bytes = Vec::new();
        encode_npy(&mut bytes, &img).expect("encode");
        let npy = npyz::NpyFile::new(&bytes[..]).expect("header");
        assert_eq!(npy.shape(), &[2, 1, 3]);
        assert_eq!(npy.order(), npyz::Order::C);
        let back = npy.into_vec::<f64>().expect("data");
        assert_eq!(
            back.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            data.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
    }

    #[test]
    fn npy_of_no_scanline_has_zero_rows() {
        let mut bytes = Vec::new();
        encode_npy(&mut bytes, &image(0, 5, 3, vec![])).expect("encode");
        let npy = npyz::NpyFile::new(&bytes[..]).expect("header");
        assert_eq!(npy.shape(), &[0, 5, 3]);
        assert!(npy.into_vec::<f64>().expect("data").is_empty());
    }

    #[test]
    fn npy_refuses_an_inconsistent_image() {
        assert!(encode_npy(Vec::new(), &image(2, 2, 1, vec![0.0; 3])).is_err());
    }
}
