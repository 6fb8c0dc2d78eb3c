//! `--cost-image OUT.png` and `--cost-npy OUT.npy`: where `run` and `render` write the
//! cost map (`cwisim_study::cost`) they count.

use crate::error::CliError;
use crate::files::write_atomic;
use clap::Args;
use cwisim_study::cost::{encode_cost_npy, render_cost_image, CostMap};
use std::path::{Path, PathBuf};

/// `--cost-image OUT.png` and `--cost-npy OUT.npy` (`run` and `render`).
#[derive(Args, Clone, Debug, Default, PartialEq)]
pub struct CostArgs {
    /// Write a cost image: per pixel, how many instructions addressed it on its scanline
    /// (a viridis heat map, black for none, with a colour bar; small arrays scaled up).
    #[arg(long, value_name = "OUT.png")]
    pub cost_image: Option<PathBuf>,

    /// Write the cost counts as a NumPy array: uint32, shape (scanlines, width).
    #[arg(long, value_name = "OUT.npy")]
    pub cost_npy: Option<PathBuf>,
}

/// Refuses an output whose extension is not `ext` (case-insensitive).
pub fn check_extension(flag: &str, path: &Path, ext: &str) -> Result<(), CliError> {
    if crate::files::is_special(path) {
        // a device or FIFO (`/dev/null`, `/dev/stdout`) has no extension to check
        return Ok(());
    }
    let got = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if got.eq_ignore_ascii_case(ext) {
        Ok(())
    } else {
        Err(CliError::Usage(format!(
            "{flag} writes a .{ext} file, but `{}` does not end in .{ext}",
            path.display()
        )))
    }
}

impl CostArgs {
    /// Whether any cost output was asked for.
    pub fn wanted(&self) -> bool {
        self.cost_image.is_some() || self.cost_npy.is_some()
    }

    /// The outputs with their flags, for path checks.
    pub fn outputs(&self) -> [(&'static str, Option<&PathBuf>); 2] {
        [
            ("--cost-image", self.cost_image.as_ref()),
            ("--cost-npy", self.cost_npy.as_ref()),
        ]
    }

    /// Refuses, before any work, outputs with the wrong extension.
    pub fn check(&self) -> Result<(), CliError> {
        if let Some(p) = &self.cost_image {
            check_extension("--cost-image", p, "png")?;
        }
        if let Some(p) = &self.cost_npy {
            check_extension("--cost-npy", p, "npy")?;
        }
        Ok(())
    }

    /// Writes the outputs asked for (the image drawn first, so that a map that cannot be
    /// drawn writes neither). `name` titles the image.
    pub fn write(&self, map: &CostMap, name: &str) -> Result<(), CliError> {
        map.check()?;
        let image = match &self.cost_image {
            Some(_) => Some(render_cost_image(map, name)?),
            None => None,
        };
        if let (Some(path), Some(image)) = (&self.cost_image, &image) {
            crate::output::write_rgb_png(path, image)?;
        }
        if let Some(path) = &self.cost_npy {
            write_atomic(path, |w| {
                encode_cost_npy(w, map).map_err(|e| CliError::write(path, e))
            })?;
        }
        Ok(())
    }
}

/// The file name of `path` for titles (never a directory).
pub fn display_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}
