//! What the commands do to the paths they write, and the exit codes (`cwisim --help`'s
//! "Exit status"): a symbolic link is followed and stays a link, a FIFO or device is
//! written in place and stays what it was, the outputs of one command are all written or
//! none, an interrupted command leaves no partial file, and `diff`'s "different" survives
//! a reader that goes away.

mod common;

use common::{cwisim, read, scratch, text, SMALL_TRACE};
use std::io::Read;
use std::os::unix::fs::{symlink, FileTypeExt};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";

/// Every file name in `dir` (hidden partial files included), sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_symlink_is_followed_and_stays_a_link() {
    let dir = scratch("outputs-symlink");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).unwrap();
    std::fs::create_dir(dir.join("real")).unwrap();
    std::fs::write(dir.join("real/old.png"), b"old").unwrap();
    symlink("real/old.png", dir.join("link.png")).unwrap();
    // and a link to a file that does not exist yet
    symlink("real/new.npy", dir.join("dangling.npy")).unwrap();
    let out = cwisim(
        &dir,
        &["run", "t.cwt", "-o", "link.png", "--npy", "dangling.npy"],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    for link in ["link.png", "dangling.npy"] {
        let meta = std::fs::symlink_metadata(dir.join(link)).unwrap();
        assert!(meta.file_type().is_symlink(), "{link} was replaced");
    }
    assert!(read(dir.join("real/old.png")).starts_with(PNG_MAGIC));
    assert!(read(dir.join("real/new.npy")).starts_with(b"\x93NUMPY"));
    assert_eq!(names(&dir.join("real")), ["new.npy", "old.png"]);
}

#[test]
fn a_fifo_is_written_in_place_and_stays_a_fifo() {
    let dir = scratch("outputs-fifo");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).unwrap();
    let fifo = dir.join("pipe.png");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo");
    assert!(made.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            std::fs::File::open(&fifo)
                .expect("open the FIFO")
                .read_to_end(&mut bytes)
                .expect("read the FIFO");
            bytes
        })
    };
    let out = cwisim(&dir, &["run", "t.cwt", "-o", "pipe.png"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let got = reader.join().expect("reader");
    assert!(got.starts_with(PNG_MAGIC), "the FIFO's reader got {got:?}");
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(meta.file_type().is_fifo(), "the FIFO was replaced");
    assert_eq!(names(&dir), ["pipe.png", "t.cwt"]);
}

#[test]
fn a_device_is_written_in_place() {
    let dir = scratch("outputs-device");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).unwrap();
    // the extension check does not apply to a device
    let out = cwisim(
        &dir,
        &[
            "run",
            "t.cwt",
            "--stats-json",
            "/dev/null",
            "--npy",
            "/dev/null",
        ],
    );
    assert!(out.status.success(), "{:?}", text(&out));
    let meta = std::fs::symlink_metadata("/dev/null").unwrap();
    assert!(meta.file_type().is_char_device());
    assert_eq!(names(&dir), ["t.cwt"]);
}

#[test]
fn the_outputs_of_one_command_are_all_written_or_none() {
    let dir = scratch("outputs-all-or-none");
    std::fs::write(dir.join("old.png"), b"old").unwrap();
    std::fs::write(dir.join("file"), b"a file, not a directory").unwrap();
    for bad in ["missing/x.npy", "file/x.npy"] {
        let out = cwisim(&dir, &["render", "fig25", "-o", "old.png", "--npy", bad]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(3), "{bad}: {stderr}");
        assert!(
            stderr.starts_with(&format!("error: {bad}: cannot write")),
            "{stderr}"
        );
        assert_eq!(read(dir.join("old.png")), b"old", "{bad}");
        assert_eq!(names(&dir), ["file", "old.png"], "{bad}");
    }
}

#[test]
fn an_interrupted_run_leaves_no_partial_file() {
    let dir = scratch("outputs-interrupt");
    // a long trace: the stepped model over many scanlines of a wide array
    let mut trace = String::from("cwisim-trace version=1 width=4096 lines=64 channels=1\n");
    for _ in 0..64 * 200 {
        trace.push_str("Eval2 0 4096 0.25 0.0001\nRefresh\n");
    }
    std::fs::write(dir.join("long.cwt"), trace).unwrap();
    std::fs::write(dir.join("s.json"), b"old").unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args([
            "run",
            "long.cwt",
            "--timing",
            "stepped",
            "--stats-json",
            "s.json",
            "--npy",
            "img.npy",
        ])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    // wait for the run to have made its partial file
    let start = Instant::now();
    while !names(&dir).iter().any(|n| n.ends_with(".partial")) {
        assert!(start.elapsed() < Duration::from_secs(60), "no partial file");
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended too soon"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(kill.success());
    let status = child.wait().expect("wait");
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    assert_eq!(status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert_eq!(names(&dir), ["long.cwt", "s.json"]);
    assert_eq!(read(dir.join("s.json")), b"old");
}

#[test]
fn diff_says_different_even_when_its_reader_goes_away() {
    let dir = scratch("outputs-diff-pipe");
    std::fs::write(dir.join("a.cwt"), SMALL_TRACE).unwrap();
    std::fs::write(
        dir.join("b.cwt"),
        SMALL_TRACE.replace("Eval1 0 8 1.0", "Eval1 0 8 0.5"),
    )
    .unwrap();
    // `| head -c 0`: the reader is gone before diff prints
    let mut child = Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args(["diff", "a.cwt", "b.cwt", "--outputs"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("wait");
    assert_eq!(out.status.code(), Some(1), "{:?}", text(&out));
    // and equal stays 0
    let mut child = Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args(["diff", "a.cwt", "a.cwt", "--outputs"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .spawn()
        .expect("spawn");
    drop(child.stdout.take());
    assert_eq!(child.wait().expect("wait").code(), Some(0));
}

#[test]
fn a_full_standard_output_is_a_write_failure() {
    let dir = scratch("outputs-full");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).unwrap();
    for args in [&["--help"][..], &["machine"], &["dump", "t.cwt"]] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full");
        let out = Command::new(env!("CARGO_BIN_EXE_cwisim"))
            .args(args)
            .current_dir(&dir)
            .stdout(full)
            .output()
            .expect("run");
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(3), "{args:?}: {stderr}");
        assert!(
            stderr.starts_with("error: cannot write to standard output"),
            "{args:?}: {stderr}"
        );
    }
}

/// A trace of `lines` scanlines over `width` processors, each line a ramp from `start`: big
/// enough that writing its `.npy` takes a while (the window in which two writers meet).
fn ramp_trace(width: u32, lines: u32, start: f64) -> String {
    let mut t = format!("cwisim-trace version=1 width={width} lines={lines} channels=1\n");
    for k in 0..lines {
        t.push_str(&format!(
            "Eval2 0 {width} {} {}\nRefresh\n",
            start + f64::from(k) * 1e-4,
            1.0 / f64::from(width)
        ));
    }
    t
}

#[test]
fn a_planted_partial_name_is_never_followed_written_or_removed() {
    // what an older cwisim wrote to: `.NAME.partial` beside the output. A link there
    // (symbolic or hard) must not carry the output's bytes into another file, a FIFO there
    // must not block the run, and none of them is removed: they are not cwisim's.
    let dir = scratch("outputs-planted-partial");
    std::fs::write(dir.join("t.cwt"), SMALL_TRACE).unwrap();
    std::fs::write(dir.join("victim.txt"), b"precious").unwrap();
    std::fs::write(dir.join("hard-victim.txt"), b"also precious").unwrap();
    symlink("victim.txt", dir.join(".sym.png.partial")).unwrap();
    std::fs::hard_link(dir.join("hard-victim.txt"), dir.join(".hard.png.partial")).unwrap();
    let made = Command::new("mkfifo")
        .arg(dir.join(".fifo.png.partial"))
        .status()
        .expect("mkfifo");
    assert!(made.success());
    for out_name in ["sym.png", "hard.png", "fifo.png"] {
        // a run that blocked on the FIFO would never end: give it a minute
        let mut child = Command::new(env!("CARGO_BIN_EXE_cwisim"))
            .args(["run", "t.cwt", "-o", out_name])
            .current_dir(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn");
        let start = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status;
            }
            if start.elapsed() > Duration::from_secs(60) {
                let _ = child.kill();
                panic!("`run -o {out_name}` blocked on a planted partial name");
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        assert!(status.success(), "run -o {out_name}");
        let meta = std::fs::symlink_metadata(dir.join(out_name)).unwrap();
        assert!(
            meta.file_type().is_file(),
            "{out_name} is not a regular file"
        );
        assert!(read(dir.join(out_name)).starts_with(PNG_MAGIC));
    }
    assert_eq!(read(dir.join("victim.txt")), b"precious");
    assert_eq!(read(dir.join("hard-victim.txt")), b"also precious");
    // an output gets the mode of any new file (0666 less the umask), not a temporary's 0600
    use std::os::unix::fs::PermissionsExt;
    let mode = |f: &str| std::fs::metadata(dir.join(f)).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode("sym.png"), mode("victim.txt"));
    let planted = std::fs::symlink_metadata(dir.join(".sym.png.partial")).unwrap();
    assert!(planted.file_type().is_symlink());
    let fifo = std::fs::symlink_metadata(dir.join(".fifo.png.partial")).unwrap();
    assert!(fifo.file_type().is_fifo());
    assert!(dir.join(".hard.png.partial").exists());
    assert_eq!(
        names(&dir),
        [
            ".fifo.png.partial",
            ".hard.png.partial",
            ".sym.png.partial",
            "fifo.png",
            "hard-victim.txt",
            "hard.png",
            "sym.png",
            "t.cwt",
            "victim.txt"
        ]
    );
}

#[test]
fn two_writers_of_one_output_leave_one_whole_file_of_one_run() {
    let dir = scratch("outputs-two-writers");
    std::fs::write(dir.join("a.cwt"), ramp_trace(1024, 192, 0.0)).unwrap();
    std::fs::write(dir.join("b.cwt"), ramp_trace(1024, 192, 0.5)).unwrap();
    // each alone, for reference
    for t in ["a", "b"] {
        let out = cwisim(
            &dir,
            &["run", &format!("{t}.cwt"), "--npy", &format!("{t}.npy")],
        );
        assert!(out.status.success(), "{:?}", text(&out));
    }
    let (a, b) = (read(dir.join("a.npy")), read(dir.join("b.npy")));
    assert_ne!(a, b);
    for round in 0..8 {
        let children: Vec<_> = ["a.cwt", "b.cwt"]
            .iter()
            .map(|t| {
                Command::new(env!("CARGO_BIN_EXE_cwisim"))
                    .args(["run", t, "--npy", "out.npy"])
                    .current_dir(&dir)
                    .stdout(Stdio::null())
                    .stderr(Stdio::null())
                    .spawn()
                    .expect("spawn")
            })
            .collect();
        for mut c in children {
            assert!(c.wait().unwrap().success(), "round {round}");
        }
        let got = read(dir.join("out.npy"));
        assert!(
            got == a || got == b,
            "round {round}: out.npy is neither run's whole output ({} bytes)",
            got.len()
        );
    }
    assert_eq!(
        names(&dir),
        ["a.cwt", "a.npy", "b.cwt", "b.npy", "out.npy"],
        "a partial file was left behind"
    );
}
