//! `cwisim renderers`: the registered renderers, one line each.

use crate::error::CliError;
use clap::Args;
use cwisim_render::{DEFAULT_RENDERER, REGISTRY};
use std::io::Write;

/// The arguments of `cwisim renderers` (none).
#[derive(Args, Clone, Debug, PartialEq, Eq)]
pub struct RenderersArgs {}

/// Runs `cwisim renderers`.
pub fn run(_args: &RenderersArgs, stdout: &mut dyn Write) -> Result<(), CliError> {
    let width = REGISTRY.iter().map(|e| e.name.len()).max().unwrap_or(0);
    for e in REGISTRY {
        let default = if e.name == DEFAULT_RENDERER {
            " (the default)"
        } else {
            ""
        };
        writeln!(stdout, "{:<width$}  {}{default}", e.name, e.about).map_err(CliError::Stdout)?;
    }
    stdout.flush().map_err(CliError::Stdout)
}
