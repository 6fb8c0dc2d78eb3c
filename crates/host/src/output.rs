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

/// One value as an 8-bit PNG sample: `round(clamp(v, 0, 1) × 255)`, halves rounded away
/// from zero. Values below 0 become 0, values above 1 (and +∞) become 255, NaN becomes 0.
///
/// Computed without a call to `round` (a library call on the baseline x86-64 target, once
/// per pixel): `y + 2⁵²` leaves `y`'s nearest integer, ties to even, in the low bits of
/// its mantissa, and the exact remainder `y − that` turns a tie rounded down back up. The
/// same bytes as the formula above for every `f64` (tested against it).
#[inline]
pub fn png_sample(v: f64) -> u8 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    // NaN fails the comparison and becomes 0
    let y = if v >= 0.0 { v.min(1.0) } else { 0.0 } * 255.0;
    let shifted = y + TWO_52;
    let nearest_even = shifted - TWO_52;
    // `y` is in [0, 255]: the integer is the mantissa's low byte
    (shifted.to_bits() as u8) + u8::from(y - nearest_even >= 0.5)
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
    check_png_shape(image.channels, image.width, image.lines)
}

/// [`check_png`] of an image of `channels`, `width` and `lines`.
pub fn check_png_shape(
    channels: usize,
    width: usize,
    lines: usize,
) -> Result<(ExtendedColorType, u32, u32), CliError> {
    let color = png_color(channels)?;
    if lines == 0 || width == 0 {
        return Err(CliError::Usage(NO_SCANLINE.into()));
    }
    const PNG_MAX: u32 = i32::MAX as u32;
    let dim = |v: usize, what: &str| {
        u32::try_from(v)
            .ok()
            .filter(|v| *v <= PNG_MAX)
            .ok_or_else(|| CliError::Usage(format!("a PNG cannot be {v} pixels {what}; use --npy")))
    };
    Ok((color, dim(width, "wide")?, dim(lines, "high")?))
}

/// Writes `image` to `path` as an 8-bit PNG, one pixel row per scanline, each value mapped
/// by [`png_sample`] (clamped to `[0, 1]`, scaled to `0..=255`, rounded). Fails without
/// creating the file when [`check_png`] does.
///
/// Written all-or-nothing ([`write_atomic`]).
pub fn write_png(path: &Path, image: &Image) -> Result<(), CliError> {
    check_png(image)?;
    write_png_samples(path, &PngSamples::of(image))
}

/// Writes samples already mapped by [`png_sample`] as [`write_png`] writes an image.
pub fn write_png_samples(path: &Path, samples: &PngSamples) -> Result<(), CliError> {
    samples.check()?;
    write_atomic(path, |out| {
        encode_png_samples(out, samples).map_err(|e| CliError::write(path, e))
    })
}

/// The PNG bytes of [`write_png`], to any writer.
pub fn encode_png<W: Write>(out: W, image: &Image) -> io::Result<()> {
    encode_png_samples(out, &PngSamples::of(image))
}

/// The PNG bytes of samples already mapped by [`png_sample`].
pub fn encode_png_samples<W: Write>(out: W, samples: &PngSamples) -> io::Result<()> {
    let (color, width, height) = samples
        .check()
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e.one_line()))?;
    PngEncoder::new(out)
        .write_image(&samples.data, width, height, color)
        .map_err(|e| match e {
            image::ImageError::IoError(e) => e,
            other => io::Error::other(other.to_string()),
        })
}

/// An image as 8-bit PNG samples ([`png_sample`] of every value), shape
/// `(lines, width, channels)`, C order: what a PNG holds, an eighth of the `f64` image.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PngSamples {
    /// Pixel columns.
    pub width: usize,
    /// Samples per pixel.
    pub channels: usize,
    /// Pixel rows (scanlines).
    pub lines: usize,
    /// `lines × width × channels` samples.
    pub data: Vec<u8>,
}

impl PngSamples {
    /// Every value of `image` mapped by [`png_sample`].
    pub fn of(image: &Image) -> PngSamples {
        PngSamples {
            width: image.width,
            channels: image.channels,
            lines: image.lines,
            data: image.data.iter().map(|&v| png_sample(v)).collect(),
        }
    }

    /// [`check_png`] of these samples.
    pub fn check(&self) -> Result<(ExtendedColorType, u32, u32), CliError> {
        check_png_shape(self.channels, self.width, self.lines)
    }
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

    /// The mapping as specified, with the library's `round` (the oracle of
    /// [`png_sample`]).
    fn png_sample_by_round(v: f64) -> u8 {
        // `as` saturates, and maps NaN to 0.
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }

    #[test]
    fn png_sample_is_the_rounded_formula_at_every_half_and_whole_step() {
        // the values that land on or next to k + 0.5 and k after scaling, a few ulps apart
        let mut values = vec![f64::MIN_POSITIVE, 1e-300, -1e-300, 0.5 / 255.0];
        for k in 0..=256u32 {
            for centre in [f64::from(k) / 255.0, (f64::from(k) + 0.5) / 255.0] {
                for ulps in -4i64..=4 {
                    values.push(f64::from_bits(centre.to_bits().wrapping_add_signed(ulps)));
                }
            }
        }
        for v in values {
            assert_eq!(png_sample(v), png_sample_by_round(v), "{v:e}");
        }
    }

    proptest::proptest! {
        #[test]
        fn png_sample_is_the_rounded_formula(bits in proptest::prelude::any::<u64>()) {
            let v = f64::from_bits(bits);
            proptest::prop_assert_eq!(png_sample(v), png_sample_by_round(v), "{:e}", v);
        }

        #[test]
        fn png_sample_is_the_rounded_formula_in_range(v in -0.01f64..1.01) {
            proptest::prop_assert_eq!(png_sample(v), png_sample_by_round(v), "{:e}", v);
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
