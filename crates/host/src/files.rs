//! Writing output files all-or-nothing, and telling whether two paths name one file.
//!
//! Every output of a command goes through [`write_atomic`]:
//!
//! - A **regular file** (or a new path) is written to a hidden sibling of a new, unique
//!   name (`.NAME.XXXXXX.partial`, created exclusively: see [`PartialFile`]) and renamed over the path only when the whole command succeeded: inside
//!   [`transaction`] (which `cwisim`'s dispatch wraps around every command) the renames
//!   wait for the command's end, so the outputs of one command are all written or none is
//!   (`render -o old.png --npy ro/x.npy` keeps `old.png` when the NumPy file cannot be
//!   made).
//! - A **symbolic link** is followed: its target is what gets written (replaced the same
//!   way), and the link stays a link.
//! - A **device, FIFO or socket** (`/dev/null`, `/dev/stdout`, a named pipe) is written in
//!   place, as its bytes are made: it is never replaced by a regular file, and what it was
//!   sent cannot be taken back.
//! - An **interrupted** command (SIGINT, SIGTERM) removes every partial file it had made
//!   ([`install_interrupt_cleanup`]) and exits with [`crate::error::EXIT_INTERRUPTED`].

use crate::error::CliError;
use std::cell::RefCell;
use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Every partial file alive in the process, on any thread: what an interruption removes.
static LIVE_PARTIALS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Every temporary work directory alive in the process (`rtl`'s tools' files): what an
/// interruption removes, with what is in it.
static LIVE_DIRS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A directory for a tool's files: one the user named (`--work-dir`, made new and kept),
/// or a temporary one of a new, unique name (`cwisim-rtl-WHAT-XXXXXX` in the temporary
/// directory), removed when dropped — on an error, a missing tool and an interruption
/// too — unless [`WorkDir::keep`] kept it (a co-simulation that differs, for a look).
pub struct WorkDir {
    path: PathBuf,
    temporary: Option<tempfile::TempDir>,
}

impl WorkDir {
    /// `given` (made new), or a temporary directory for `what`.
    pub fn new(given: Option<&Path>, what: &str) -> Result<WorkDir, CliError> {
        if let Some(d) = given {
            std::fs::create_dir(d).map_err(|e| CliError::write(d, e))?;
            return Ok(WorkDir {
                path: d.to_path_buf(),
                temporary: None,
            });
        }
        let tmp = std::env::temp_dir();
        let dir = tempfile::Builder::new()
            .prefix(&format!("cwisim-rtl-{what}-"))
            .tempdir_in(&tmp)
            .map_err(|e| CliError::write(&tmp, e))?;
        let path = dir.path().to_path_buf();
        if let Ok(mut live) = LIVE_DIRS.lock() {
            live.push(path.clone());
        }
        Ok(WorkDir {
            path,
            temporary: Some(dir),
        })
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Keeps a temporary directory after all (its path is said in a message).
    pub fn keep(mut self) -> PathBuf {
        if let Some(dir) = self.temporary.take() {
            let path = dir.keep();
            if let Ok(mut live) = LIVE_DIRS.lock() {
                live.retain(|p| p != &path);
            }
        }
        self.path.clone()
    }
}

impl Drop for WorkDir {
    fn drop(&mut self) {
        if let Some(dir) = self.temporary.take() {
            drop(dir); // removes it and what it holds
            if let Ok(mut live) = LIVE_DIRS.lock() {
                live.retain(|p| p != &self.path);
            }
        }
    }
}

fn register_partial(path: &Path) {
    if let Ok(mut live) = LIVE_PARTIALS.lock() {
        live.push(path.to_path_buf());
    }
}

fn unregister_partial(path: &Path) {
    if let Ok(mut live) = LIVE_PARTIALS.lock() {
        if let Some(i) = live.iter().rposition(|p| p == path) {
            live.swap_remove(i);
        }
    }
}

/// A hidden file that holds an output's bytes before they are final (the partial of
/// [`write_atomic`], the scanline records of `--stats-json`). Its name is new and unique
/// (`.NAME.XXXXXX.partial`, through the `tempfile` crate), and it is created exclusively
/// (`O_CREAT | O_EXCL`): a file, link or FIFO already there under any name is never
/// followed, written or removed, and two processes writing one output each have their own.
/// Registered so that an interruption removes it; removed when dropped unless
/// [`Self::persist`] renamed it.
pub struct PartialFile {
    path: Option<tempfile::TempPath>,
    registered: PathBuf,
}

impl PartialFile {
    /// Creates a new file in `dir` named `PREFIX` + six random characters + `SUFFIX`,
    /// exclusively, with the mode a new file gets (0666 less the umask), registered for
    /// removal.
    pub fn create_in(
        dir: &Path,
        prefix: &std::ffi::OsStr,
        suffix: &str,
    ) -> io::Result<(PartialFile, File)> {
        let named = tempfile::Builder::new()
            .prefix(prefix)
            .suffix(suffix)
            .rand_bytes(6)
            .make_in(dir, |path| {
                let mut options = OpenOptions::new();
                options.write(true).create_new(true);
                #[cfg(unix)]
                std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o666);
                options.open(path)
            })?;
        let (file, path) = named.into_parts();
        register_partial(&path);
        let registered = path.to_path_buf();
        Ok((
            PartialFile {
                path: Some(path),
                registered,
            },
            file,
        ))
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        &self.registered
    }

    /// Renames it to `target`; on failure it is removed.
    fn persist(mut self, target: &Path) -> io::Result<()> {
        let path = self.path.take().expect("persisted once");
        let result = path.persist(target).map_err(|e| e.error);
        unregister_partial(&self.registered);
        result
    }
}

impl Drop for PartialFile {
    fn drop(&mut self) {
        if let Some(path) = self.path.take() {
            drop(path); // removes the file
            unregister_partial(&self.registered);
        }
    }
}

/// Stops every HDL tool the command runs (`rtl`'s simulators and Yosys, with what they
/// started), removes every partial file and temporary work directory on SIGINT or SIGTERM
/// (SIGHUP too), then exits with
/// [`crate::error::EXIT_INTERRUPTED`]: an interrupted command leaves nothing behind and
/// replaces nothing. Installed once by `cwisim`'s `main`; a second call does nothing.
pub fn install_interrupt_cleanup() {
    let _ = ctrlc::set_handler(|| {
        // the HDL tools first, so that none writes into what is removed next
        cwisim_rtl::tools::stop_children();
        if let Ok(live) = LIVE_PARTIALS.lock() {
            for p in live.iter() {
                let _ = std::fs::remove_file(p);
            }
        }
        if let Ok(live) = LIVE_DIRS.lock() {
            for d in live.iter() {
                let _ = std::fs::remove_dir_all(d);
            }
        }
        let _ = writeln!(io::stderr(), "error: interrupted; no output was written");
        std::process::exit(i32::from(crate::error::EXIT_INTERRUPTED));
    });
}

/// The regular files written by [`write_atomic`] inside the [`transaction`] of this
/// thread, waiting for its end to be renamed over their paths.
type Pending = Vec<(PartialFile, PathBuf)>;

thread_local! {
    static TRANSACTION: RefCell<Option<Pending>> = const { RefCell::new(None) };
}

/// Runs `command` so that the outputs it writes with [`write_atomic`] (on this thread) are
/// all-or-nothing: each is written to its partial file as the command goes, and only when
/// `command` returns `Ok` are they renamed over their paths, in the order written. On an
/// error nothing is renamed and every partial is removed. Devices and FIFOs are written in
/// place and are not held back. Not reentrant: an inner transaction joins the outer one.
pub fn transaction<T>(command: impl FnOnce() -> Result<T, CliError>) -> Result<T, CliError> {
    let outer = TRANSACTION.with(|t| t.borrow().is_some());
    if outer {
        return command();
    }
    TRANSACTION.with(|t| *t.borrow_mut() = Some(Vec::new()));
    let result = command();
    let pending = TRANSACTION
        .with(|t| t.borrow_mut().take())
        .unwrap_or_default();
    let value = result?;
    // the renames: every partial is complete and synced; a rename fails only when the
    // directory changed under us, and then the rest are still removed on drop
    for (partial, target) in pending {
        partial
            .persist(&target)
            .map_err(|e| CliError::write(&target, e))?;
    }
    Ok(value)
}

/// Renames every output the current [`transaction`] holds over its path now, so that it
/// stays even though the command then fails: `run --keep-partial` keeps the image of the
/// scanlines completed before a bad instruction, and still exits 2. Outside a transaction
/// there is nothing pending.
pub fn commit_pending() -> Result<(), CliError> {
    let pending = TRANSACTION.with(|t| t.borrow_mut().as_mut().map(std::mem::take));
    for (partial, target) in pending.unwrap_or_default() {
        partial
            .persist(&target)
            .map_err(|e| CliError::write(&target, e))?;
    }
    Ok(())
}

/// Where writing `path` really goes: symbolic links followed (to a target that need not
/// exist yet), at most 40 deep.
pub fn resolve_output(path: &Path) -> Result<PathBuf, CliError> {
    let mut current = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&current) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&current).map_err(|e| CliError::write(path, e))?;
                current = match current.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(CliError::write(
        path,
        io::Error::other("too many levels of symbolic links"),
    ))
}

/// What kind of thing an output path names, after [`resolve_output`].
enum OutputKind {
    /// Nothing yet, or a regular file: written all-or-nothing.
    Regular,
    /// A device, FIFO or socket: written in place.
    InPlace,
}

/// `path`'s kind; `stat` follows every link, the kernel's `/proc/self/fd` links included.
fn output_kind(path: &Path) -> Result<OutputKind, CliError> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(CliError::write(
            path,
            io::Error::new(io::ErrorKind::IsADirectory, "is a directory"),
        )),
        Ok(m) if !m.is_file() => Ok(OutputKind::InPlace),
        _ => Ok(OutputKind::Regular),
    }
}

/// True when `path` names an existing device, FIFO or socket (after links): an output
/// written in place, whose name need not carry the format's extension.
pub fn is_special(path: &Path) -> bool {
    matches!(output_kind(path), Ok(OutputKind::InPlace))
}

/// The encoding a trace written to `path` gets: the one its extension names; for a device
/// or FIFO whose name has no extension (`/dev/stdout`, a named pipe), the annotated text
/// (`.cwt`), as LIMITS.md says ("its name need not carry the format's extension").
pub fn trace_output_encoding(path: &Path) -> Result<cwisim_isa::Encoding, CliError> {
    match cwisim_isa::Encoding::from_path(path) {
        Ok(e) => Ok(e),
        Err(_) if path.extension().is_none() && is_special(path) => Ok(cwisim_isa::Encoding::Text),
        Err(e) => Err(e.into()),
    }
}

/// A writer that stops at the output budget (`CWISIM_MAX_OUTPUT`): a write that would
/// take the file past it fails, and [`Self::over`] says so, so that every output of every
/// command is held to the one budget.
struct Budgeted<W: Write> {
    inner: W,
    written: u64,
    limit: u64,
    over: bool,
}

impl<W: Write> Budgeted<W> {
    fn new(inner: W) -> Self {
        Budgeted {
            inner,
            written: 0,
            limit: cwisim_scene::budget::Budget::current().output_bytes,
            over: false,
        }
    }

    /// The budget's refusal of the output `path`, if a write went past it.
    fn over(&self, path: &Path) -> Option<CliError> {
        self.over.then(|| {
            let budget = cwisim_scene::budget::Budget {
                output_bytes: self.limit,
                ..cwisim_scene::budget::Budget::current()
            };
            let what = format!("the output {}", path.display());
            CliError::Budget(
                budget
                    .check_output(&what, self.limit.saturating_add(1))
                    .expect_err("past the budget"),
            )
        })
    }
}

impl<W: Write> Write for Budgeted<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.written.saturating_add(buf.len() as u64) > self.limit {
            self.over = true;
            return Err(io::Error::other(
                "the output budget (CWISIM_MAX_OUTPUT) is spent",
            ));
        }
        let n = self.inner.write(buf)?;
        self.written += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// Writes `path` through `fill`, all or nothing (see the module's documentation), within
/// the output budget (`CWISIM_MAX_OUTPUT`: a file that would grow past it is refused and
/// not written).
///
/// A regular file's bytes go to a hidden sibling (a [`PartialFile`]), flushed and synced,
/// then renamed over the path: at once outside a [`transaction`], at its successful end
/// inside one. On any error the partial is removed and the old file is untouched. A
/// symbolic link is followed; a device or FIFO is written in place.
pub fn write_atomic<F>(path: &Path, fill: F) -> Result<(), CliError>
where
    F: FnOnce(&mut dyn Write) -> Result<(), CliError>,
{
    if let OutputKind::InPlace = output_kind(path)? {
        let file = OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(|e| CliError::write(path, e))?;
        let mut out = Budgeted::new(BufWriter::new(file));
        let filled = fill(&mut out);
        if let Some(over) = out.over(path) {
            return Err(over);
        }
        filled?;
        return out.flush().map_err(|e| CliError::write(path, e));
    }
    let target = resolve_output(path)?;
    let (dir, prefix) = partial_place(&target, path)?;
    let (partial, file) =
        PartialFile::create_in(&dir, &prefix, ".partial").map_err(|e| CliError::write(path, e))?;
    let mut out = Budgeted::new(BufWriter::new(file));
    let filled = fill(&mut out);
    if let Some(over) = out.over(path) {
        return Err(over);
    }
    filled?;
    let file = out
        .inner
        .into_inner()
        .map_err(|e| CliError::write(path, e.into_error()))?;
    file.sync_all().map_err(|e| CliError::write(path, e))?;
    drop(file);
    let held = TRANSACTION.with(|t| match t.borrow_mut().as_mut() {
        Some(pending) => {
            pending.push((partial, target.clone()));
            None
        }
        None => Some(partial),
    });
    match held {
        Some(partial) => partial
            .persist(&target)
            .map_err(|e| CliError::write(path, e)),
        None => Ok(()),
    }
}

/// Where `write_atomic` makes the partial file it renames to `target`: `target`'s
/// directory, and the name's prefix `.NAME.` (`shown` is the path as the user gave it,
/// for messages).
fn partial_place(target: &Path, shown: &Path) -> Result<(PathBuf, std::ffi::OsString), CliError> {
    let name = target.file_name().ok_or_else(|| {
        CliError::write(
            shown,
            io::Error::new(io::ErrorKind::InvalidInput, "the output path names no file"),
        )
    })?;
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(name);
    prefix.push(".");
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((dir, prefix))
}

/// Checks, before any work, that `path` can be written: its directory exists and takes a
/// new file (a probe file is made and removed at once), or it is a device or FIFO. So a
/// command whose output cannot be written fails at its start, not after the whole render.
pub fn check_writable(path: &Path) -> Result<(), CliError> {
    if let OutputKind::InPlace = output_kind(path)? {
        return Ok(());
    }
    let target = resolve_output(path)?;
    let (dir, prefix) = partial_place(&target, path)?;
    let (partial, file) =
        PartialFile::create_in(&dir, &prefix, ".probe").map_err(|e| CliError::write(path, e))?;
    drop(file);
    drop(partial);
    Ok(())
}

/// The line a command prints once it has written `paths`, `wrote A, B` (with `detail`
/// after a colon when given), leaving out an output that is standard output itself (its
/// reader has it already, and the line would land in the stream); `None` when nothing is
/// left.
pub fn wrote_line(paths: &[&Path], detail: Option<&str>) -> Option<String> {
    let names: Vec<String> = paths
        .iter()
        .filter(|p| !is_standard_output(p))
        .map(|p| p.display().to_string())
        .collect();
    if names.is_empty() {
        return None;
    }
    Some(match detail {
        Some(d) => format!("wrote {}: {d}", names.join(", ")),
        None => format!("wrote {}", names.join(", ")),
    })
}

/// True when `path` is the file, pipe or terminal this process's standard output goes to.
fn is_standard_output(path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(path), std::fs::metadata("/dev/stdout")) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
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

/// What a command reads and writes, checked once before any work by [`Io::check`]: no
/// output may be an input (a trace, a scene, the files a scene names, a machine file, a
/// part to merge), no two outputs one file, and every output writable. Every command
/// builds one; the checks are this one function's, not each command's.
#[derive(Default)]
pub struct Io<'a> {
    inputs: Vec<(String, PathBuf)>,
    outputs: Vec<(&'a str, &'a Path)>,
}

impl<'a> Io<'a> {
    /// Nothing read or written yet.
    pub fn new() -> Io<'a> {
        Io::default()
    }

    /// An input file, called `noun` in the message (`"trace being read"`), if given.
    pub fn input(mut self, noun: &str, path: Option<&Path>) -> Self {
        if let Some(p) = path {
            self.inputs.push((noun.to_string(), p.to_path_buf()));
        }
        self
    }

    /// A trace or scene argument (a file, or an embedded scene's name): the file, when it
    /// exists, and when it is a scene file every file it names (OBJ meshes, texture
    /// images: [`cwisim_world::referenced_files`]).
    pub fn source(mut self, noun: &str, arg: Option<&Path>) -> Self {
        let Some(path) = arg.filter(|p| p.exists()) else {
            return self;
        };
        self.inputs.push((noun.to_string(), path.to_path_buf()));
        if !path.is_file() || cwisim_isa::Encoding::from_path(path).is_ok() {
            return self; // a trace, or not a regular file: it names no file
        }
        if let Ok(text) = cwisim_scene::read_scene_text(path) {
            for (field, file) in cwisim_world::referenced_files(&text, path.parent()) {
                self.inputs
                    .push((format!("file the {noun} names at {field}"), file));
            }
        }
        self
    }

    /// The `--machine` file, if given.
    pub fn machine(self, machine: &crate::commands::MachineArgs) -> Self {
        self.input("machine file", machine.machine.as_deref())
    }

    /// An output, by the option that names it (`-o`, `--npy`), if given.
    pub fn output(mut self, flag: &'a str, path: Option<&'a Path>) -> Self {
        if let Some(p) = path {
            self.outputs.push((flag, p));
        }
        self
    }

    /// Refuses (a usage error, exit 2) an output that is an input or another output, and
    /// an output that cannot be written at all ([`check_writable`]). A device or FIFO may
    /// be named twice (`/dev/null`).
    pub fn check(&self) -> Result<(), CliError> {
        for (i, (flag, path)) in self.outputs.iter().enumerate() {
            for (noun, input) in &self.inputs {
                if same_file(path, input) {
                    return Err(CliError::Usage(format!(
                        "{flag} {} would overwrite the {noun}",
                        path.display()
                    )));
                }
            }
            for (other, other_path) in &self.outputs[..i] {
                if same_file(path, other_path) && !is_special(path) {
                    return Err(CliError::Usage(format!(
                        "{other} and {flag} both name {}; give each output its own file",
                        path.display()
                    )));
                }
            }
        }
        for (_, path) in &self.outputs {
            check_writable(path)?;
        }
        Ok(())
    }
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
