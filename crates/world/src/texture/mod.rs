//! Textures: a material's `k_d` and `k_a` multiplied per channel by an image (a PNG file)
//! or a procedural checkerboard, looked up at a surface's texture coordinates `(u, v)`.
//!
//! A texture is a grid of `width × height` texels, each a constant over its cell: texel
//! `(i, j)` covers `u ∈ [i/width, (i+1)/width)`, `v ∈ [j/height, (j+1)/height)`, row
//! `j = 0` at `v = 0`, the **bottom** of the image (OBJ's and OpenGL's convention). The
//! texture repeats outside `[0, 1)²`; `repeat` scales `(u, v)` first (a repeat of 4 lays
//! four copies across the surface's `[0, 1]`).
//!
//! Two lookups ([`TextureFilter`]):
//!
//! * **point** — the texel under one point (the pixel centre's `(u, v)`);
//! * **box** — the texture's mean over a rectangle of `(u, v)` (the bounding box of a
//!   pixel's preimage on the surface, [`crate::shade`]), from a **summed-area table**
//!   (Crow 1984). The table holds the integral of the texels over `[0, x] × [0, y]` at every
//!   texel corner; between corners that integral is bilinear (the texels are constant
//!   over their cells), so the mean over any rectangle, even one spanning many repeats,
//!   is exact up to rounding. What it approximates is the footprint: a pixel's preimage
//!   is a quadrilateral, and the table averages its bounding box.
//!
//! A channel `c` of the scene takes the image's channel `c` (red, green, blue; a fourth
//! channel is not textured), a grey scene the image's luminance; texel values are the
//! stored bytes over 255, linear, as `cwisim` writes its PNGs.

pub mod store;

pub use store::{RowRelease, TextureStore};

use crate::scene::PerChannel;
use cwisim_scene::{SceneError, SceneErrorKind};
use serde::{Deserialize, Serialize};
use std::io::Read;
use std::path::{Path, PathBuf};

/// The most texels a texture may have: 2²² (2048 × 2048).
pub const MAX_TEXELS: u64 = 1 << 22;
/// The largest texture file read (bytes).
pub const MAX_TEXTURE_BYTES: u64 = 64 << 20;
/// The most checkerboard squares per side.
pub const MAX_CHECKER_SQUARES: u32 = 2048;
/// The largest `repeat`.
pub const MAX_REPEAT: f64 = 1e6;

/// A material's texture as the scene file gives it: exactly one of `image` and
/// `checker`, and how often it repeats across `[0, 1]²`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureSpec {
    /// A PNG file, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image: Option<String>,
    /// A checkerboard that needs no file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub checker: Option<Checker>,
    /// Copies across `u` and `v` (default `[1, 1]`).
    #[serde(default = "one_repeat")]
    pub repeat: [f64; 2],
}

fn one_repeat() -> [f64; 2] {
    [1.0, 1.0]
}

/// A checkerboard of `squares[0] × squares[1]` squares over `[0, 1]²`, alternating
/// `dark` (at `(0, 0)`) and `light`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Checker {
    /// Squares along `u` and `v`.
    pub squares: [u32; 2],
    /// The factor of the dark squares (default 0.25).
    #[serde(default = "dark")]
    pub dark: PerChannel,
    /// The factor of the light squares (default 1).
    #[serde(default = "light")]
    pub light: PerChannel,
}

fn dark() -> PerChannel {
    PerChannel::All(0.25)
}

fn light() -> PerChannel {
    PerChannel::All(1.0)
}

/// How a pixel reads a texture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TextureFilter {
    /// The mean over the pixel's footprint, from the summed-area table.
    #[default]
    Box,
    /// The texel under the pixel centre.
    Point,
}

impl TextureFilter {
    /// Every filter, in the order `--help` lists them.
    pub const ALL: [TextureFilter; 2] = [TextureFilter::Box, TextureFilter::Point];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TextureFilter::Box => "box",
            TextureFilter::Point => "point",
        }
    }

    /// The filter of a name.
    pub fn of_name(name: &str) -> Option<TextureFilter> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// A texture ready to look up: its texels (scene channels, interleaved, bottom row
/// first) and their summed-area table.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    channels: usize,
    repeat: [f64; 2],
    texels: Vec<f64>,
    /// `(width + 1) × (height + 1)` corners × channels: the sum of the texels below and to
    /// the left of each corner.
    table: Vec<f64>,
    /// What it came from, for summaries: `checker` or the file's name.
    label: String,
}

impl Texture {
    /// A texture of `width × height` texels given bottom row first, `channels` values
    /// each. The caller keeps the size within [`MAX_TEXELS`].
    pub fn from_texels(
        width: usize,
        height: usize,
        channels: usize,
        repeat: [f64; 2],
        texels: Vec<f64>,
        label: String,
    ) -> Texture {
        assert_eq!(texels.len(), width * height * channels, "texel count");
        assert!(width > 0 && height > 0, "an empty texture");
        let stride = (width + 1) * channels;
        let mut table = vec![0.0; (height + 1) * stride];
        for j in 0..height {
            let mut row = [0.0f64; 4];
            for i in 0..width {
                for c in 0..channels {
                    row[c] += texels[(j * width + i) * channels + c];
                    table[(j + 1) * stride + (i + 1) * channels + c] =
                        table[j * stride + (i + 1) * channels + c] + row[c];
                }
            }
        }
        Texture {
            width,
            height,
            channels,
            repeat,
            texels,
            table,
            label,
        }
    }

    /// `width × height`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// What it came from: `checker`, or the image file's name.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The texels' memory, bytes (texels and table).
    pub fn bytes(&self) -> u64 {
        bytes_for(self.width, self.height, self.channels)
    }

    /// `(u, v)` in texels, repeat applied.
    fn to_texels(&self, uv: [f64; 2]) -> [f64; 2] {
        [
            uv[0] * self.repeat[0] * self.width as f64,
            uv[1] * self.repeat[1] * self.height as f64,
        ]
    }

    /// The texel under `(u, v)` (wrapped), per channel; unused channels 1.
    pub fn point(&self, uv: [f64; 2]) -> [f64; 4] {
        let [x, y] = self.to_texels(uv);
        let (i, j) = (x.floor() as i64, y.floor() as i64);
        let mut out = [1.0; 4];
        for (c, value) in out.iter_mut().enumerate().take(self.channels) {
            *value = self.texel(i, j, c);
        }
        out
    }

    /// The mean of the texture over the rectangle with corners `lo` and `hi` in `(u, v)`
    /// (wrapped), per channel; unused channels 1. A rectangle thinner than 1e-9 texel in
    /// a direction is widened to that, so a line or a point reads what lies under it.
    pub fn mean(&self, lo: [f64; 2], hi: [f64; 2]) -> [f64; 4] {
        let [mut x0, mut y0] = self.to_texels(lo);
        let [mut x1, mut y1] = self.to_texels(hi);
        if x1 < x0 {
            std::mem::swap(&mut x0, &mut x1);
        }
        if y1 < y0 {
            std::mem::swap(&mut y0, &mut y1);
        }
        const THIN: f64 = 1e-9;
        if x1 - x0 < THIN {
            x1 = x0 + THIN;
        }
        if y1 - y0 < THIN {
            y1 = y0 + THIN;
        }
        let mut out = [1.0; 4];
        let columns = span(x0, x1);
        let rows = span(y0, y1);
        for (c, value) in out.iter_mut().enumerate().take(self.channels) {
            *value = match (columns, rows) {
                // a box within two columns (or two rows) is summed strip by strip, so that
                // no difference of the table's large sums is divided by its small width
                (Some((first, last)), _) => {
                    (first..=last)
                        .map(|i| overlap(i, x0, x1) * self.column_mean(i, y0, y1, rows, c))
                        .sum::<f64>()
                        / (x1 - x0)
                }
                (None, Some((first, last))) => {
                    (first..=last)
                        .map(|j| overlap(j, y0, y1) * self.row_mean(j, x0, x1, c))
                        .sum::<f64>()
                        / (y1 - y0)
                }
                (None, None) => {
                    let sum = self.integral(x1, y1, c)
                        - self.integral(x0, y1, c)
                        - self.integral(x1, y0, c)
                        + self.integral(x0, y0, c);
                    sum / ((x1 - x0) * (y1 - y0))
                }
            };
        }
        out
    }

    /// The value of texel `(i, j)` (wrapped), channel `c`.
    fn texel(&self, i: i64, j: i64, c: usize) -> f64 {
        let i = i.rem_euclid(self.width as i64) as usize;
        let j = j.rem_euclid(self.height as i64) as usize;
        self.texels[(j * self.width + i) * self.channels + c]
    }

    /// The mean of channel `c` of texel column `i` over `[y0, y1]`: texel by texel when
    /// the range spans at most two rows (`rows`), else from the table.
    fn column_mean(&self, i: i64, y0: f64, y1: f64, rows: Option<(i64, i64)>, c: usize) -> f64 {
        match rows {
            Some((first, last)) => {
                (first..=last)
                    .map(|j| overlap(j, y0, y1) * self.texel(i, j, c))
                    .sum::<f64>()
                    / (y1 - y0)
            }
            None => {
                let x = i as f64;
                let column = |y: f64| self.integral(x + 1.0, y, c) - self.integral(x, y, c);
                (column(y1) - column(y0)) / (y1 - y0)
            }
        }
    }

    /// The mean of channel `c` of texel row `j` over `[x0, x1]`, from the table.
    fn row_mean(&self, j: i64, x0: f64, x1: f64, c: usize) -> f64 {
        let y = j as f64;
        let row = |x: f64| self.integral(x, y + 1.0, c) - self.integral(x, y, c);
        (row(x1) - row(x0)) / (x1 - x0)
    }

    /// The integral of channel `c` over `[0, x] × [0, y]` (texel units, signed, the
    /// texture repeated).
    fn integral(&self, x: f64, y: f64, c: usize) -> f64 {
        let (w, h) = (self.width as f64, self.height as f64);
        let (qx, qy) = ((x / w).floor(), (y / h).floor());
        let (rx, ry) = (x - qx * w, y - qy * h);
        // rounding can leave a remainder a hair outside [0, w]
        let (rx, ry) = (rx.clamp(0.0, w), ry.clamp(0.0, h));
        qx * qy * self.tile(w, h, c)
            + qx * self.tile(w, ry, c)
            + qy * self.tile(rx, h, c)
            + self.tile(rx, ry, c)
    }

    /// The integral of channel `c` over `[0, x] × [0, y]` within one tile
    /// (`0 ≤ x ≤ width`, `0 ≤ y ≤ height`): the table interpolated bilinearly, exact for
    /// texels constant over their cells.
    fn tile(&self, x: f64, y: f64, c: usize) -> f64 {
        let i = (x.floor() as usize).min(self.width - 1);
        let j = (y.floor() as usize).min(self.height - 1);
        let (fx, fy) = (x - i as f64, y - j as f64);
        let stride = (self.width + 1) * self.channels;
        let at = |i: usize, j: usize| self.table[j * stride + i * self.channels + c];
        let (a, b) = (at(i, j), at(i + 1, j));
        let (d, e) = (at(i, j + 1), at(i + 1, j + 1));
        a + fx * (b - a) + fy * (d - a) + fx * fy * (e - d - b + a)
    }
}

/// The texel indices `[x0, x1)` meets, when they are at most two.
fn span(x0: f64, x1: f64) -> Option<(i64, i64)> {
    let first = x0.floor();
    let last = (x1.ceil() - 1.0).max(first);
    (last - first <= 1.0).then_some((first as i64, last as i64))
}

/// The length of `[x0, x1]` within texel `i`'s `[i, i + 1]`.
fn overlap(i: i64, x0: f64, x1: f64) -> f64 {
    let i = i as f64;
    (x1.min(i + 1.0) - x0.max(i)).max(0.0)
}

/// Checks a texture spec at JSON path `field` (`meshes[k].material.texture`).
pub fn validate(spec: &TextureSpec, field: &str, channels: usize) -> Result<(), SceneError> {
    use SceneErrorKind as K;
    match (&spec.image, &spec.checker) {
        (Some(_), Some(_)) | (None, None) => {
            return Err(SceneError::at_field(
                K::Schema,
                field,
                "expected exactly one of \"image\" (a PNG file) and \"checker\"",
            ))
        }
        (Some(image), None) if image.is_empty() => {
            return Err(SceneError::at_field(
                K::Schema,
                format!("{field}.image"),
                "expected the name of a PNG file, found an empty string",
            ))
        }
        _ => {}
    }
    for (k, r) in spec.repeat.iter().enumerate() {
        if !(r.is_finite() && *r > 0.0 && *r <= MAX_REPEAT) {
            return Err(SceneError::at_field(
                K::Limit,
                format!("{field}.repeat[{k}]"),
                format!("expected a repeat > 0 and at most {MAX_REPEAT:e}, found {r}"),
            ));
        }
    }
    if let Some(c) = &spec.checker {
        for (k, &s) in c.squares.iter().enumerate() {
            if !(1..=MAX_CHECKER_SQUARES).contains(&s) {
                return Err(SceneError::at_field(
                    K::Limit,
                    format!("{field}.checker.squares[{k}]"),
                    format!("expected 1..={MAX_CHECKER_SQUARES} squares, found {s}"),
                ));
            }
        }
        c.dark
            .check(&format!("{field}.checker.dark"), channels, 0.0)?;
        c.light
            .check(&format!("{field}.checker.light"), channels, 0.0)?;
    }
    Ok(())
}

/// A texture's image file: its name as the scene gives it, its path, and the JSON path of
/// the name, for errors.
struct ImageFile<'a> {
    name: &'a str,
    path: PathBuf,
    field: String,
}

impl ImageFile<'_> {
    fn of<'a>(name: &'a str, field: &str, base: Option<&Path>) -> ImageFile<'a> {
        ImageFile {
            name,
            path: base.map_or_else(|| PathBuf::from(name), |b| b.join(name)),
            field: format!("{field}.image"),
        }
    }

    fn fail(&self, kind: SceneErrorKind, what: String) -> SceneError {
        SceneError::at_field(
            kind,
            self.field.clone(),
            format!("texture {:?}: {what}", self.name),
        )
    }

    fn io(&self, e: std::io::Error) -> SceneError {
        self.fail(SceneErrorKind::Io, format!("cannot read it: {e}"))
    }

    fn not_png(&self, e: image::ImageError) -> SceneError {
        self.fail(
            SceneErrorKind::Shape,
            format!("not a readable PNG image ({e})"),
        )
    }

    /// Its size from its header, the file checked first: a regular file within
    /// [`MAX_TEXTURE_BYTES`], a PNG, not empty, within [`MAX_TEXELS`]. Nothing decoded.
    fn extent(&self) -> Result<(u32, u32), SceneError> {
        let meta = std::fs::metadata(&self.path).map_err(|e| self.io(e))?;
        if !meta.is_file() {
            return Err(self.fail(
                SceneErrorKind::Io,
                "not a regular file (a PNG file is expected)".into(),
            ));
        }
        if meta.len() > MAX_TEXTURE_BYTES {
            return Err(self.fail(
                SceneErrorKind::Limit,
                format!(
                    "the file has {} bytes; the limit is {MAX_TEXTURE_BYTES}",
                    meta.len()
                ),
            ));
        }
        let mut file = std::fs::File::open(&self.path).map_err(|e| self.io(e))?;
        // the size the header claims, against the limit before the decoder sees it (a
        // width of 2^31, beyond PNG's own range, is over the limit, not a decoder's
        // error); the decoder not asked at all when the header is read here, since it
        // would inflate the chunks before the image data (an iCCP profile) to find it
        let mut head = [0u8; 24];
        let mut got = 0;
        while got < head.len() {
            match std::io::Read::read(&mut file, &mut head[got..]).map_err(|e| self.io(e))? {
                0 => break,
                n => got += n,
            }
        }
        if let Some((width, height)) = png_header_size(&head[..got]) {
            if width == 0 || height == 0 {
                return Err(self.fail(
                    SceneErrorKind::Shape,
                    format!("the image is empty ({width}×{height})"),
                ));
            }
            self.within_limit(width, height)?;
            return Ok((width, height));
        }
        std::io::Seek::rewind(&mut file).map_err(|e| self.io(e))?;
        let reader =
            image::ImageReader::with_format(std::io::BufReader::new(file), image::ImageFormat::Png);
        let (width, height) = reader.into_dimensions().map_err(|e| self.not_png(e))?;
        if width == 0 || height == 0 {
            return Err(self.fail(
                SceneErrorKind::Shape,
                format!("the image is empty ({width}×{height})"),
            ));
        }
        self.within_limit(width, height)?;
        Ok((width, height))
    }

    /// Refuses a size over [`MAX_TEXELS`].
    fn within_limit(&self, width: u32, height: u32) -> Result<(), SceneError> {
        let texels = u64::from(width) * u64::from(height);
        if texels > MAX_TEXELS {
            return Err(self.fail(
                SceneErrorKind::Limit,
                format!(
                    "{width}×{height} = {texels} texels; the limit is {MAX_TEXELS} (2048×2048)"
                ),
            ));
        }
        Ok(())
    }
}

/// The PNG `bytes` with only its critical chunks (a chunk type whose first letter is upper
/// case: IHDR, PLTE, IDAT, IEND), which are all the decoder needs for the texels: an
/// ancillary chunk (a colour profile, text, …) is never inflated, whatever it would
/// inflate to. Bytes that are not a well-formed sequence of chunks are given back whole,
/// for the decoder to refuse.
fn critical_chunks(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    const SIGNATURE: &[u8; 8] = b"\x89PNG\r\n\x1a\n";
    if bytes.len() < 8 || &bytes[..8] != SIGNATURE {
        return bytes.into();
    }
    let mut out = SIGNATURE.to_vec();
    let mut at = 8;
    while at < bytes.len() {
        let Some(head) = bytes.get(at..at + 8) else {
            return bytes.into();
        };
        let len = u32::from_be_bytes([head[0], head[1], head[2], head[3]]) as usize;
        // length, type, data, CRC
        let Some(end) = at.checked_add(12).and_then(|e| e.checked_add(len)) else {
            return bytes.into();
        };
        let Some(chunk) = bytes.get(at..end) else {
            return bytes.into();
        };
        if head[4].is_ascii_uppercase() {
            out.extend_from_slice(chunk);
        }
        at = end;
    }
    out.into()
}

/// The width and height a PNG's first 24 bytes claim (the signature, then the IHDR chunk's
/// length, type, width and height, big-endian), if they are a PNG's.
fn png_header_size(head: &[u8]) -> Option<(u32, u32)> {
    const SIGNATURE: &[u8; 8] = b"\x89PNG\r\n\x1a\n";
    if head.len() < 24 || &head[..8] != SIGNATURE || &head[12..16] != b"IHDR" {
        return None;
    }
    let word = |at: usize| u32::from_be_bytes([head[at], head[at + 1], head[at + 2], head[at + 3]]);
    Some((word(16), word(20)))
}

/// The size in texels, `(width, height)`, of the texture a (validated) spec makes: a
/// checker's squares, or the PNG file's size read from its header (the file checked as
/// [`load`] checks it; nothing decoded). What a scene's textures will need is known from
/// it before any is built ([`bytes_for`]).
pub fn extent(
    spec: &TextureSpec,
    field: &str,
    base: Option<&Path>,
) -> Result<(usize, usize), SceneError> {
    match (&spec.checker, &spec.image) {
        (Some(c), _) => Ok((c.squares[0] as usize, c.squares[1] as usize)),
        (None, image) => {
            let (w, h) =
                ImageFile::of(image.as_deref().unwrap_or_default(), field, base).extent()?;
            Ok((w as usize, h as usize))
        }
    }
}

/// The memory a texture of `width × height` texels takes in `channels` channels: its
/// texels and its summed-area table, `f64` each.
pub fn bytes_for(width: usize, height: usize, channels: usize) -> u64 {
    let values = (width * height + (width + 1) * (height + 1)) * channels;
    (values * std::mem::size_of::<f64>()) as u64
}

/// Builds the texture of a (validated) spec for a scene of `channels` channels: a
/// checkerboard, or the PNG file `image` relative to `base`. A file that is missing,
/// unreadable, not a PNG, empty or over the limits is an error at `field.image` naming
/// the file, found from its header before its texels are allocated.
pub fn load(
    spec: &TextureSpec,
    field: &str,
    channels: usize,
    base: Option<&Path>,
) -> Result<Texture, SceneError> {
    if let Some(c) = &spec.checker {
        let [su, sv] = c.squares.map(|s| s as usize);
        let mut texels = Vec::with_capacity(su * sv * channels);
        for j in 0..sv {
            for i in 0..su {
                let value = if (i + j) % 2 == 0 { &c.dark } else { &c.light };
                texels.extend((0..channels).map(|ch| value.get(ch)));
            }
        }
        return Ok(Texture::from_texels(
            su,
            sv,
            channels,
            spec.repeat,
            texels,
            "checker".into(),
        ));
    }
    let name = spec.image.as_deref().unwrap_or_default();
    let file = ImageFile::of(name, field, base);
    let (width, height) = file.extent()?;
    let mut bytes = Vec::new();
    std::fs::File::open(&file.path)
        .map_err(|e| file.io(e))?
        .take(MAX_TEXTURE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| file.io(e))?;
    // ancillary chunks (a colour profile, text) left out before the decoder sees them: an
    // iCCP profile is inflated whatever its size (a 0.5 MB file took 530 MB), and no
    // texel depends on one
    let bytes = critical_chunks(&bytes);
    let mut reader =
        image::ImageReader::with_format(std::io::Cursor::new(&*bytes), image::ImageFormat::Png);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    limits.max_alloc = Some(u64::from(width) * u64::from(height) * 16 + (1 << 20));
    reader.limits(limits);
    let decoded = reader.decode().map_err(|e| file.not_png(e))?;
    let (w, h) = (width as usize, height as usize);
    let mut out = Vec::with_capacity(w * h * channels);
    let rgb = decoded.to_rgb8();
    // bottom row first
    for j in (0..h).rev() {
        for i in 0..w {
            let p = rgb
                .get_pixel(i as u32, j as u32)
                .0
                .map(|b| f64::from(b) / 255.0);
            if channels == 1 {
                out.push(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
            } else {
                out.extend((0..channels).map(|c| if c < 3 { p[c] } else { 1.0 }));
            }
        }
    }
    let label = Path::new(name)
        .file_name()
        .map_or_else(|| name.to_string(), |n| n.to_string_lossy().into_owned());
    Ok(Texture::from_texels(
        w,
        h,
        channels,
        spec.repeat,
        out,
        label,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(w: usize, h: usize) -> Texture {
        // texel (i, j) = 1 + i + 10 j: every texel different
        let texels = (0..h)
            .flat_map(|j| (0..w).map(move |i| 1.0 + i as f64 + 10.0 * j as f64))
            .collect();
        Texture::from_texels(w, h, 1, [1.0, 1.0], texels, "grid".into())
    }

    /// The mean of the texture over a rectangle in texel units, brute force: the area of
    /// each texel cell (over several repeats) inside it.
    fn brute(t: &Texture, x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
        let (w, h) = (t.width as i64, t.height as i64);
        let mut sum = 0.0;
        for j in y0.floor() as i64..=y1.floor() as i64 {
            for i in x0.floor() as i64..=x1.floor() as i64 {
                let ox = (x1.min(i as f64 + 1.0) - x0.max(i as f64)).max(0.0);
                let oy = (y1.min(j as f64 + 1.0) - y0.max(j as f64)).max(0.0);
                let (ti, tj) = (i.rem_euclid(w) as usize, j.rem_euclid(h) as usize);
                sum += ox * oy * t.texels[tj * t.width + ti];
            }
        }
        sum / ((x1 - x0) * (y1 - y0))
    }

    #[test]
    fn the_table_is_exact_over_any_rectangle_even_across_repeats() {
        let t = grid(5, 3);
        let cases = [
            (0.0, 0.0, 5.0, 3.0),
            (0.25, 0.5, 1.75, 2.5),
            (-3.3, -1.2, 7.9, 4.4),
            (12.1, 7.7, 12.6, 7.9),
            (-0.4, 2.9, 0.4, 3.1),
            // narrow in one direction, long in the other, and tiny
            (2.3, -4.1, 2.3001, 9.7),
            (7.5, 0.2, 19.9, 0.20001),
            (3.999_999, 1.5, 4.000_001, 1.500_001),
        ];
        for (x0, y0, x1, y1) in cases {
            let got = t.mean([x0 / 5.0, y0 / 3.0], [x1 / 5.0, y1 / 3.0])[0];
            let want = brute(&t, x0, y0, x1, y1);
            assert!(
                (got - want).abs() < 1e-9 * want.abs().max(1.0),
                "{x0} {y0} {x1} {y1}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn a_point_reads_its_texel_and_a_thin_box_reads_what_lies_under_it() {
        let t = grid(5, 3);
        assert_eq!(t.point([0.1, 0.1])[0], 1.0);
        assert_eq!(t.point([0.99, 0.99])[0], 1.0 + 4.0 + 20.0);
        assert_eq!(t.point([-0.1, 1.1])[0], 1.0 + 4.0);
        let m = t.mean([0.5, 0.5], [0.5, 0.5])[0];
        assert!((m - t.point([0.5, 0.5])[0]).abs() < 1e-6);
        // unused channels are 1
        assert_eq!(t.point([0.5, 0.5])[3], 1.0);
    }

    #[test]
    fn a_header_claiming_2_to_the_31_texels_wide_is_the_limit_s_refusal() {
        // a valid PNG of 1×1, its IHDR width rewritten to 2^31 (beyond PNG's own range,
        // which the decoder would refuse with a message of its own)
        let mut png = Vec::new();
        image::GrayImage::from_raw(1, 1, vec![7])
            .unwrap()
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        png[16..20].copy_from_slice(&(1u32 << 31).to_be_bytes());
        let dir = std::env::temp_dir().join(format!("cwisim-tex-huge-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("huge.png"), &png).unwrap();
        let spec = TextureSpec {
            image: Some("huge.png".into()),
            checker: None,
            repeat: [1.0, 1.0],
        };
        let e = extent(&spec, "meshes[0].material.texture", Some(&dir)).unwrap_err();
        assert_eq!(e.kind, SceneErrorKind::Limit, "{e}");
        assert!(
            e.message
                .contains("2147483648×1 = 2147483648 texels; the limit is"),
            "{e}"
        );
        assert_eq!(png_header_size(&png[..23]), None);
        assert_eq!(png_header_size(b"GIF89a..................."), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_checker_alternates_from_dark_at_the_origin() {
        let spec = TextureSpec {
            image: None,
            checker: Some(Checker {
                squares: [4, 2],
                dark: PerChannel::All(0.1),
                light: PerChannel::All(0.9),
            }),
            repeat: [1.0, 1.0],
        };
        validate(&spec, "t", 1).unwrap();
        let t = load(&spec, "t", 1, None).unwrap();
        assert_eq!(t.point([0.1, 0.1])[0], 0.1);
        assert_eq!(t.point([0.3, 0.1])[0], 0.9);
        assert_eq!(t.point([0.3, 0.6])[0], 0.1);
        // the mean of the whole board is the mean of its two colours
        assert!((t.mean([0.0, 0.0], [1.0, 1.0])[0] - 0.5).abs() < 1e-12);
        assert_eq!((t.label(), t.size()), ("checker", (4, 2)));
    }

    #[test]
    fn bad_specs_name_their_field() {
        let mut spec = TextureSpec {
            image: Some("a.png".into()),
            checker: Some(Checker {
                squares: [0, 2],
                dark: dark(),
                light: light(),
            }),
            repeat: [1.0, 1.0],
        };
        let e = validate(&spec, "meshes[0].material.texture", 1).unwrap_err();
        assert!(e.to_string().contains("exactly one of"), "{e}");
        spec.image = None;
        let e = validate(&spec, "meshes[0].material.texture", 1).unwrap_err();
        assert_eq!(
            e.field.as_deref(),
            Some("meshes[0].material.texture.checker.squares[0]")
        );
        spec.checker.as_mut().unwrap().squares = [2, 2];
        spec.repeat = [0.0, 1.0];
        let e = validate(&spec, "m", 1).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("m.repeat[0]"));
    }
}
