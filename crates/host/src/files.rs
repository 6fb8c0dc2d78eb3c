//! Writing output files all-or-nothing, and telling whether two paths name one file.

use crate::error::CliError;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes `path` through `fill`, all or nothing.
///
/// The bytes go to a hidden sibling file (`.NAME.partial`) that is renamed over `path` only
/// once `fill` succeeded and everything was flushed; on any error it is removed, so an
/// interrupted or failed command never leaves a half-written output (nor clobbers an
/// existing one).
pub fn write_atomic<F>(path: &Path, fill: F) -> Result<(), CliError>
where
    F: FnOnce(&mut dyn Write) -> Result<(), CliError>,
{
    let tmp = partial_path(path)?;
    let file = File::create(&tmp).map_err(|e| CliError::write(path, e))?;
    let mut out = BufWriter::new(file);
    let result = fill(&mut out).and_then(|()| {
        let file = out
            .into_inner()
            .map_err(|e| CliError::write(path, e.into_error()))?;
        file.sync_all().map_err(|e| CliError::write(path, e))?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(|e| CliError::write(path, e))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The temporary sibling `write_atomic` fills before renaming it to `path`.
fn partial_path(path: &Path) -> Result<PathBuf, CliError> {
    let name = path.file_name().ok_or_else(|| {
        CliError::write(
            path,
            io::Error::new(io::ErrorKind::InvalidInput, "the output path names no file"),
        )
    })?;
    let mut tmp = std::ffi::OsString::from(".");
    tmp.push(name);
    tmp.push(".partial");
    Ok(path.with_file_name(tmp))
}

/// True when `a` and `b` name the same file, also when the file does not exist yet
/// (`./t.cwt` and `t.cwt` are the same; symbolic links are followed where they
/// exist).
pub fn same_file(a: &Path, b: &Path) -> bool {
    resolve(a) == resolve(b)
}

fn resolve(p: &Path) -> PathBuf {
    if let Ok(c) = p.canonicalize() {
        return c;
    }
    let parent = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (parent.canonicalize(), p.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => p.to_path_buf(),
    }
}

/// Refuses outputs that would overwrite the input or one another. `input` is what is read
/// and what to call it in the message (`"trace being read"`, `"scene"`); `outputs` pairs
/// each option (`-o`, `--npy`, …) with the path it was given, if any.
pub fn check_outputs(
    input: Option<(&str, &Path)>,
    outputs: &[(&str, Option<&Path>)],
) -> Result<(), CliError> {
    let given: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|(f, p)| p.map(|p| (*f, p)))
        .collect();
    for (i, (flag, path)) in given.iter().enumerate() {
        if let Some((noun, input)) = input {
            if same_file(path, input) {
                return Err(CliError::Usage(format!(
                    "{flag} {} would overwrite the {noun}",
                    path.display()
                )));
            }
        }
        for (other, other_path) in &given[..i] {
            if same_file(path, other_path) {
                return Err(CliError::Usage(format!(
                    "{other} and {flag} both name {}; give each output its own file",
                    path.display()
                )));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("cwisim-host-files-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        dir
    }

    #[test]
    fn a_failed_write_leaves_nothing_and_keeps_the_old_file() {
        let dir = scratch("atomic");
        let path = dir.join("out.bin");
        write_atomic(&path, |w| {
            w.write_all(b"first").map_err(|e| CliError::write("x", e))
        })
        .expect("write");
        assert_eq!(std::fs::read(&path).expect("read"), b"first");
        let e = write_atomic(&path, |w| {
            w.write_all(b"half").map_err(|e| CliError::write("x", e))?;
            Err(CliError::Usage("stop".into()))
        });
        assert!(e.is_err());
        assert_eq!(std::fs::read(&path).expect("read"), b"first");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .expect("dir")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["out.bin"]);
        std::fs::remove_dir_all(&dir).expect("cleanup");
    }

    #[test]
    fn same_file_sees_through_spelling() {
        let dir = scratch("same");
        let a = dir.join("t.cwt");
        std::fs::write(&a, "x").expect("write");
        std::fs::create_dir_all(dir.join("sub")).expect("sub dir");
        assert!(same_file(&a, &dir.join("sub").join("..").join("t.cwt")));
        assert!(same_file(&a, &dir.join(".").join("t.cwt")));
        assert!(same_file(
            &dir.join("new.png"),
            &dir.join(".").join("new.png")
        ));
        assert!(!same_file(&a, &dir.join("t.cwb")));
        std::fs::remove_dir_all(&dir).expect("cleanup");
    }
}
