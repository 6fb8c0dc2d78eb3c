//! Where scanlines go when a `Refresh` shifts them out.

use crate::sample::Sample;

/// One scanline as the array shifts it out.
///
/// Only `span` may hold non-zero values; every pixel outside it is exactly `+0.0`. This
/// lets an engine skip processors that no instruction reached.
#[derive(Clone, Copy, Debug)]
pub struct LineOut<'a, T> {
    /// Scanline number over the whole trace (frame × lines per frame + row).
    pub index: u64,
    /// Pixel columns `[span.0, span.1)` that `values` covers.
    pub span: (usize, usize),
    /// `(span.1 - span.0) × channels` values, pixel-major.
    pub values: &'a [T],
}

/// Receives scanlines in order.
pub trait LineSink<T: Sample> {
    /// One finished scanline.
    fn line(&mut self, line: LineOut<'_, T>);
}

/// Discards scanlines (for statistics-only runs).
pub struct NullSink;

impl<T: Sample> LineSink<T> for NullSink {
    fn line(&mut self, _line: LineOut<'_, T>) {}
}

/// Every scanline of a run as `f64`, shape `(lines, width, channels)`, C order.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Pixel columns.
    pub width: usize,
    /// Values per pixel.
    pub channels: usize,
    /// Scanlines output so far.
    pub lines: usize,
    /// `lines × width × channels` values.
    pub data: Vec<f64>,
}

/// The output would exceed the collector's limit (of bytes held: 8 a value for an exact
/// image, 1 for 8-bit samples).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the output image would exceed {limit_bytes} bytes at scanline {line} ({width} × {channels} values per scanline); write statistics only, or raise the limit")]
pub struct ImageLimit {
    /// The limit.
    pub limit_bytes: u64,
    /// The scanline that crossed it.
    pub line: u64,
    /// Width.
    pub width: usize,
    /// Channels.
    pub channels: usize,
}

/// Collects scanlines into an [`Image`], up to a size limit.
pub struct ImageSink {
    image: Image,
    limit_bytes: u64,
    overflow: Option<ImageLimit>,
}

impl ImageSink {
    /// Default limit on the collected image: 4 GiB of f64 values.
    pub const DEFAULT_LIMIT_BYTES: u64 = 4 << 30;

    /// A collector for an array of `width` processors and `channels` channels.
    pub fn new(width: usize, channels: usize, limit_bytes: u64) -> Self {
        ImageSink {
            image: Image {
                width,
                channels,
                lines: 0,
                data: Vec::new(),
            },
            limit_bytes,
            overflow: None,
        }
    }

    /// Room for `lines` scanlines reserved up front — as many as the limit allows, and
    /// none if the allocator refuses — so that the image is not copied as it grows. The
    /// image collected is the same either way.
    pub fn with_room_for(mut self, lines: u64) -> Self {
        let row = (self.image.width * self.image.channels) as u64;
        let within_limit = self.limit_bytes / 8 / row.max(1);
        let values = lines.min(within_limit).saturating_mul(row);
        if let Ok(values) = usize::try_from(values) {
            // a hint: on refusal the image grows as it comes
            let _ = self.image.data.try_reserve_exact(values);
        }
        self
    }

    /// The image, or the limit it ran into.
    pub fn finish(self) -> Result<Image, ImageLimit> {
        match self.overflow {
            Some(e) => Err(e),
            None => Ok(self.image),
        }
    }
}

impl<T: Sample> LineSink<T> for ImageSink {
    fn line(&mut self, line: LineOut<'_, T>) {
        if self.overflow.is_some() {
            return;
        }
        let row = self.image.width * self.image.channels;
        let bytes = (self.image.lines as u64 + 1) * row as u64 * 8;
        if bytes > self.limit_bytes {
            self.overflow = Some(ImageLimit {
                limit_bytes: self.limit_bytes,
                line: line.index,
                width: self.image.width,
                channels: self.image.channels,
            });
            return;
        }
        // zeros left and right of the span, the span's values between: each value
        // written once (not zeroed, then written)
        let data = &mut self.image.data;
        let start = data.len();
        let c = self.image.channels;
        let (from, to) = (line.span.0 * c, line.span.1 * c);
        data.resize(start + from, 0.0);
        data.extend(line.values.iter().take(to - from).map(|s| s.to_f64()));
        data.resize(start + row, 0.0);
        self.image.lines += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(index: u64, values: &[f64]) -> LineOut<'_, f64> {
        LineOut {
            index,
            span: (1, 1 + values.len()),
            values,
        }
    }

    #[test]
    fn room_reserved_up_front_within_the_limit_collects_the_same_image() {
        let collect = |sink: ImageSink| {
            let mut sink = sink;
            for k in 0..3 {
                LineSink::<f64>::line(&mut sink, line(k, &[0.5, k as f64]));
            }
            sink
        };
        // four values per scanline, 32 bytes: a limit of 100 bytes holds 3 scanlines
        let plain = collect(ImageSink::new(4, 1, 100));
        let roomy = ImageSink::new(4, 1, 100).with_room_for(1 << 40);
        assert_eq!(
            roomy.image.data.capacity(),
            12,
            "no more than the limit allows"
        );
        let roomy = collect(roomy);
        assert_eq!(roomy.image.data.capacity(), 12, "not grown");
        assert_eq!(plain.finish().unwrap(), roomy.finish().unwrap());
        // a scanline past the limit is refused the same way with room reserved
        let mut over = ImageSink::new(4, 1, 100).with_room_for(2);
        for k in 0..4 {
            LineSink::<f64>::line(&mut over, line(k, &[1.0]));
        }
        assert_eq!(over.finish().unwrap_err().line, 3);
        // an empty row reserves nothing
        assert_eq!(
            ImageSink::new(0, 1, 100)
                .with_room_for(5)
                .image
                .data
                .capacity(),
            0
        );
    }
}
