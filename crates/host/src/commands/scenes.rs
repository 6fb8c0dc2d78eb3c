//! `cwisim scenes`: the embedded scenes, listed, or one printed as its JSON file.

use crate::error::CliError;
use clap::Args;
use cwisim_world::embedded::{embedded, EMBEDDED};
use std::io::Write;

/// The arguments of `cwisim scenes`.
#[derive(Args, Clone, Debug, PartialEq, Eq)]
pub struct ScenesArgs {
    /// Print this embedded scene's JSON file (to copy and edit) instead of the list.
    #[arg(value_name = "NAME")]
    pub name: Option<String>,
}

/// Runs `cwisim scenes`.
pub fn run(args: &ScenesArgs, stdout: &mut dyn Write) -> Result<(), CliError> {
    match &args.name {
        None => {
            let width = EMBEDDED.iter().map(|e| e.name.len()).max().unwrap_or(0);
            for e in EMBEDDED {
                writeln!(stdout, "{:<width$}  {}", e.name, e.about).map_err(CliError::Stdout)?;
            }
        }
        Some(name) => {
            let Some(e) = embedded(name) else {
                let names: Vec<&str> = EMBEDDED.iter().map(|e| e.name).collect();
                return Err(CliError::Usage(format!(
                    "no embedded scene `{name}`; the embedded scenes are {}",
                    names.join(", ")
                )));
            };
            stdout
                .write_all(e.text.as_bytes())
                .map_err(CliError::Stdout)?;
        }
    }
    stdout.flush().map_err(CliError::Stdout)
}
