//! The trace header: what every encoding states before the first instruction.

use serde::{Deserialize, Serialize};

/// The trace format version this build reads and writes.
pub const FORMAT_VERSION: u16 = 1;
/// The widest X-processor array a trace may describe.
pub const MAX_WIDTH: u32 = 65_536;
/// The most scanlines per frame a trace may describe.
pub const MAX_LINES: u32 = 65_536;
/// The most channels per intensity (1 grey, 3 RGB; up to 4).
pub const MAX_CHANNELS: usize = 4;

/// The header of a trace: format version, array width, scanlines per frame, channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TraceHeader {
    /// Format version ([`FORMAT_VERSION`]).
    pub version: u16,
    /// Number of X-processors (pixel columns), `1..=MAX_WIDTH`.
    pub width: u32,
    /// Scanlines per frame, `1..=MAX_LINES`.
    pub lines: u32,
    /// Values per intensity, `1..=MAX_CHANNELS`.
    pub channels: u8,
}

impl TraceHeader {
    /// A header of the current version, checked against the limits.
    pub fn new(width: u32, lines: u32, channels: u8) -> Result<Self, HeaderFault> {
        let h = TraceHeader {
            version: FORMAT_VERSION,
            width,
            lines,
            channels,
        };
        h.check()?;
        Ok(h)
    }

    /// Checks every field against the limits; the fault names the field and says why.
    pub fn check(&self) -> Result<(), HeaderFault> {
        let fault = |field, message| Err(HeaderFault { field, message });
        if self.version != FORMAT_VERSION {
            return fault(
                "version",
                format!(
                    "unsupported trace format version {}; this build reads version {FORMAT_VERSION}",
                    self.version
                ),
            );
        }
        if self.width == 0 || self.width > MAX_WIDTH {
            return fault(
                "width",
                format!("width {} is outside 1..={MAX_WIDTH} processors", self.width),
            );
        }
        if self.lines == 0 || self.lines > MAX_LINES {
            return fault(
                "lines",
                format!(
                    "lines {} is outside 1..={MAX_LINES} scanlines per frame",
                    self.lines
                ),
            );
        }
        if self.channels == 0 || usize::from(self.channels) > MAX_CHANNELS {
            return fault(
                "channels",
                format!("channels {} is outside 1..={MAX_CHANNELS}", self.channels),
            );
        }
        Ok(())
    }

    /// The channel count as a `usize`.
    pub fn channel_count(&self) -> usize {
        usize::from(self.channels)
    }
}

/// A header field outside its limits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HeaderFault {
    /// `version`, `width`, `lines` or `channels`.
    pub field: &'static str,
    /// What is wrong with it.
    pub message: String,
}

impl std::fmt::Display for HeaderFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for HeaderFault {}
