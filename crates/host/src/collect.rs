//! What `-o` and `--npy` collect as the array shifts its scanlines out: the exact `f64`
//! values only when a NumPy file is asked for, the 8-bit PNG samples only when a PNG is,
//! and nothing when neither is.
//!
//! A PNG needs an eighth of the memory of the `f64` image (1 MB against 8 MB at 1024²
//! grey), and a fresh process pays a page fault for every 4 KB it first writes: collecting
//! the `f64` image only to map it to bytes at the end cost `cwisim render` about 4 ms of
//! its "array in order" stage on the pot at 1024², and the mapping pass another 3 ms
//! (docs/PERFORMANCE.md, "What the user runs").

use crate::output::{png_sample, PngSamples};
use cwisim_xproc::{Image, ImageLimit, ImageSink, LineOut, LineSink};

/// Collects scanlines as [`PngSamples`] (each value mapped by [`png_sample`] as it
/// comes), up to a limit on the bytes held.
pub struct PngSink {
    samples: PngSamples,
    limit_bytes: u64,
    overflow: Option<ImageLimit>,
}

impl PngSink {
    /// A collector for an array of `width` processors and `channels` channels, holding at
    /// most `limit_bytes` samples.
    pub fn new(width: usize, channels: usize, limit_bytes: u64) -> Self {
        PngSink {
            samples: PngSamples {
                width,
                channels,
                ..PngSamples::default()
            },
            limit_bytes,
            overflow: None,
        }
    }

    /// Room for `lines` scanlines reserved up front, within the limit (a hint: the
    /// samples collected are the same either way).
    pub fn with_room_for(mut self, lines: u64) -> Self {
        let row = (self.samples.width * self.samples.channels) as u64;
        let values = lines.min(self.limit_bytes / row.max(1)).saturating_mul(row);
        if let Ok(values) = usize::try_from(values) {
            let _ = self.samples.data.try_reserve_exact(values);
        }
        self
    }

    /// The samples, or the limit they ran into.
    pub fn finish(self) -> Result<PngSamples, ImageLimit> {
        match self.overflow {
            Some(e) => Err(e),
            None => Ok(self.samples),
        }
    }
}

impl LineSink<f64> for PngSink {
    fn line(&mut self, line: LineOut<'_, f64>) {
        if self.overflow.is_some() {
            return;
        }
        let (c, row) = (
            self.samples.channels,
            self.samples.width * self.samples.channels,
        );
        if (self.samples.lines as u64 + 1) * row as u64 > self.limit_bytes {
            self.overflow = Some(ImageLimit {
                limit_bytes: self.limit_bytes,
                line: line.index,
                width: self.samples.width,
                channels: c,
            });
            return;
        }
        let start = self.samples.data.len();
        // outside its span a scanline is +0.0: sample 0
        self.samples.data.resize(start + row, 0);
        let dst = &mut self.samples.data[start + line.span.0 * c..start + line.span.1 * c];
        for (d, &v) in dst.iter_mut().zip(line.values) {
            *d = png_sample(v);
        }
        self.samples.lines += 1;
    }
}

/// The collectors of the image outputs asked for: a [`LineSink`] that hands each
/// scanline to each.
pub struct OutputSink {
    exact: Option<ImageSink>,
    png: Option<PngSink>,
}

impl OutputSink {
    /// The exact image when `exact`, the PNG samples when `png`, each with room for
    /// `lines` scanlines (a hint) and the memory budget as its limit
    /// ([`cwisim_scene::budget::Budget::current`], `CWISIM_MAX_MEMORY`).
    pub fn new(width: usize, channels: usize, exact: bool, png: bool, lines: u64) -> Self {
        let limit = cwisim_scene::budget::Budget::current().memory_bytes;
        OutputSink {
            exact: exact.then(|| ImageSink::new(width, channels, limit).with_room_for(lines)),
            png: png.then(|| PngSink::new(width, channels, limit).with_room_for(lines)),
        }
    }

    /// What was collected, or the limit a collector ran into.
    pub fn finish(self) -> Result<Collected, ImageLimit> {
        Ok(Collected {
            exact: self.exact.map(ImageSink::finish).transpose()?,
            png: self.png.map(PngSink::finish).transpose()?,
        })
    }
}

impl LineSink<f64> for OutputSink {
    fn line(&mut self, line: LineOut<'_, f64>) {
        if let Some(png) = &mut self.png {
            png.line(line);
        }
        if let Some(exact) = &mut self.exact {
            exact.line(line);
        }
    }
}

/// The image outputs' data, as [`OutputSink`] collected it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Collected {
    /// The exact image, when a NumPy file was asked for.
    pub exact: Option<Image>,
    /// The PNG samples, when a PNG was asked for.
    pub png: Option<PngSamples>,
}

impl Collected {
    /// The scanlines collected (by either collector; both see every scanline).
    pub fn lines(&self) -> usize {
        match (&self.exact, &self.png) {
            (Some(image), _) => image.lines,
            (None, Some(samples)) => samples.lines,
            (None, None) => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn feed(sink: &mut dyn LineSink<f64>, lines: &[(usize, Vec<f64>)]) {
        for (k, (x, values)) in lines.iter().enumerate() {
            sink.line(LineOut {
                index: k as u64,
                span: (*x, *x + values.len()),
                values,
            });
        }
    }

    #[test]
    fn png_samples_are_the_exact_image_mapped() {
        let lines = vec![
            (0, vec![0.25, 1.5, -0.5, f64::NAN]),
            (1, vec![0.5]),
            (2, vec![]),
            (3, vec![1.0 / 255.0]),
        ];
        let mut both = OutputSink::new(4, 1, true, true, 4);
        feed(&mut both, &lines);
        let both = both.finish().expect("within the limit");
        let exact = both.exact.expect("asked for");
        assert_eq!(both.png, Some(PngSamples::of(&exact)));
        assert_eq!(
            both.png.as_ref().map(|p| p.data.clone()),
            Some(vec![64, 255, 0, 0, 0, 128, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1])
        );
        // the PNG alone collects the same samples, without the exact image
        let mut png = OutputSink::new(4, 1, false, true, 0);
        feed(&mut png, &lines);
        let png = png.finish().expect("within the limit");
        assert_eq!(
            (png.exact.as_ref(), png.png.as_ref()),
            (None, both.png.as_ref())
        );
        assert_eq!(png.lines(), 4);
    }

    #[test]
    fn nothing_asked_collects_nothing() {
        let mut none = OutputSink::new(4, 1, false, false, 10);
        feed(&mut none, &[(0, vec![0.5])]);
        assert_eq!(none.finish().expect("nothing held"), Collected::default());
    }

    #[test]
    fn the_png_limit_counts_bytes_and_names_the_scanline() {
        // three channels of four pixels: 12 bytes a scanline, 30 bytes hold two
        let mut sink = PngSink::new(4, 3, 30).with_room_for(1 << 40);
        assert_eq!(
            sink.samples.data.capacity(),
            24,
            "no more than the limit allows"
        );
        for k in 0..3 {
            sink.line(LineOut {
                index: 7 + k,
                span: (0, 1),
                values: &[0.5, 0.5, 0.5],
            });
        }
        let e = sink.finish().expect_err("past the limit");
        assert_eq!((e.line, e.limit_bytes, e.width, e.channels), (9, 30, 4, 3));
    }
}
