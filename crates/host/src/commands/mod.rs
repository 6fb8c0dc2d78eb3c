//! The subcommands of `cwisim`, one module each, and the machine options they share.

pub mod convert;
pub mod diff;
pub mod dump;
pub mod fit;
pub mod history;
pub mod inspect;
pub mod machine;
pub mod refine;
pub mod renderers;
pub mod rtl;
pub mod run;
pub mod scene;
pub mod scenes;
pub mod stats;
pub mod tradeoff;
pub mod vcd;

use crate::collect::{Collected, OutputSink};
use crate::error::CliError;
use crate::output;
use clap::Args;
use cwisim_xproc::Machine;
use std::path::PathBuf;

/// `-o OUT.png` and `--npy OUT.npy`: where the image goes (`run` and `render`).
#[derive(Args, Clone, Debug, Default, PartialEq)]
pub struct ImageArgs {
    /// Write the image as an 8-bit PNG (1 channel: grey, 3: RGB). Values are clamped to
    /// [0, 1] and mapped to round(v × 255); NaN becomes 0.
    #[arg(short = 'o', long = "output", value_name = "OUT.png")]
    pub output: Option<PathBuf>,

    /// Write the image as a NumPy array: float64, shape (scanlines, width, channels),
    /// C order, exact values, nothing clamped.
    #[arg(long, value_name = "OUT.npy")]
    pub npy: Option<PathBuf>,
}

impl ImageArgs {
    /// Whether any image output was asked for.
    pub fn wanted(&self) -> bool {
        self.output.is_some() || self.npy.is_some()
    }

    /// Refuses, before any work, images the memory budget cannot hold: `lines` scanlines
    /// (a frame, known from the header) of `width × channels` values, 8 bytes each for
    /// `--npy`, 1 for `-o`'s PNG.
    pub fn check_memory(&self, width: u32, channels: usize, lines: u64) -> Result<(), CliError> {
        self.check_memory_with(width, channels, lines, None)
    }

    /// [`Self::check_memory`], with `also` (what, bytes) held at the same time: a
    /// renderer's frames as they are emitted ([`cwisim_render::Renderer::frame_memory`]).
    pub fn check_memory_with(
        &self,
        width: u32,
        channels: usize,
        lines: u64,
        also: Option<(String, u64)>,
    ) -> Result<(), CliError> {
        let values = lines
            .saturating_mul(u64::from(width))
            .saturating_mul(channels as u64);
        let per_value = 8 * u64::from(self.npy.is_some()) + u64::from(self.output.is_some());
        if per_value == 0 {
            return Ok(());
        }
        let mut what = format!(
            "the image of {lines} scanline(s) of {width} × {channels} value(s) ({})",
            match (self.npy.is_some(), self.output.is_some()) {
                (true, true) => "--npy and -o",
                (true, false) => "--npy",
                _ => "-o",
            }
        );
        let mut bytes = values.saturating_mul(per_value);
        if let Some((also, more)) = also.filter(|(_, more)| *more > 0) {
            what = format!("{what} with {also}");
            bytes = bytes.saturating_add(more);
        }
        cwisim_scene::budget::Budget::current()
            .check_memory(&what, bytes)
            .map_err(CliError::from)
    }

    /// Refuses, before any work, an output whose extension is not the format written
    /// (`-o` writes PNG, `--npy` NumPy: `-o x.jpg` is an error, not PNG bytes in a .jpg)
    /// and a PNG of a channel count PNG cannot hold.
    pub fn check(&self, channels: usize) -> Result<(), CliError> {
        if let Some(png) = &self.output {
            let ext = png.extension().and_then(|e| e.to_str()).unwrap_or("");
            if ext.eq_ignore_ascii_case("npy") {
                return Err(CliError::Usage(format!(
                    "-o writes PNG, but `{}` names a NumPy file; use --npy {}",
                    png.display(),
                    png.display()
                )));
            }
            crate::cost_args::check_extension("-o", png, "png")?;
            output::png_color(channels)?;
        }
        if let Some(npy) = &self.npy {
            crate::cost_args::check_extension("--npy", npy, "npy")?;
        }
        Ok(())
    }

    /// The collector of what the outputs asked for need, for scanlines of `width`
    /// pixels of `channels` values, with room for `lines` of them (a hint): the exact
    /// image for `--npy`, the PNG's samples for `-o`, nothing for neither.
    pub fn sink(&self, width: usize, channels: usize, lines: u64) -> OutputSink {
        OutputSink::new(
            width,
            channels,
            self.npy.is_some(),
            self.output.is_some(),
            lines,
        )
    }

    /// Writes the outputs asked for from what [`Self::sink`] collected, the PNG first:
    /// it is checked before its file is made, so that either both or neither is written
    /// when the PNG cannot be.
    pub fn write(&self, collected: &Collected) -> Result<(), CliError> {
        if let (Some(path), Some(samples)) = (&self.output, &collected.png) {
            output::write_png_samples(path, samples)?;
        }
        if let (Some(path), Some(image)) = (&self.npy, &collected.exact) {
            output::write_npy(path, image)?;
        }
        Ok(())
    }
}

/// `--machine FILE` and `--set KEY=VALUE`: which machine model to simulate.
#[derive(Args, Clone, Debug, Default, PartialEq)]
pub struct MachineArgs {
    /// Machine model file (JSON; keys not given keep their defaults). Print the defaults
    /// with `cwisim machine`.
    #[arg(long, value_name = "M.json")]
    pub machine: Option<PathBuf>,

    /// Override one machine parameter, after --machine; repeatable. VALUE is JSON.
    ///
    /// Keys: clock_hz, frame_rate_hz, vblank_lines, line_period_cycles (null derives it),
    /// hop_cycles, value_cycles, opcode_cycles.NAME (e.g. opcode_cycles.Eval3). Example:
    /// --set clock_hz=2e8 --set opcode_cycles.Eval3=2
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl MachineArgs {
    /// The machine: the defaults, or the `--machine` file, then every `--set` in order.
    pub fn load(&self) -> Result<Machine, CliError> {
        let base = match &self.machine {
            Some(path) => Machine::from_file(path)?,
            None => Machine::default(),
        };
        if self.set.is_empty() {
            Ok(base)
        } else {
            Ok(base.with_overrides(&self.set)?)
        }
    }
}
