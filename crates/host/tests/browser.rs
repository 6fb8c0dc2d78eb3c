//! `cwisim inspect`'s page in a real browser: headless Chromium (Debian's `chromium`,
//! installed by `tests/browser/install-chromium.sh`, which this test runs itself when no
//! Chromium is found) opens the page
//! from disk, a scripted click on a named pixel (the page's `#click=X,LINE` address
//! dispatches a click on the image at that pixel) shows the same history lines as
//! `cwisim history` and the scanline's disassembly as `cwisim dump`, with no console
//! message and no script error, and the screenshot shows the image.
//!
//! When the script cannot install Chromium (no root, no sudo, no package) the test fails,
//! naming the script; it is skipped only when `CWISIM_SKIP_BROWSER_TEST=1` says so.

mod common;

use common::{cwisim_ok, scratch};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `chromium` on the PATH, if any.
fn chromium_on_path() -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join("chromium"))
            .find(|p| p.is_file())
    })
}

/// Chromium: `CWISIM_CHROMIUM`, else `chromium` on the PATH, else the one that the
/// project's own script installs (`tests/browser/install-chromium.sh`, Debian's package
/// through apt-get), so that the README's test command needs nothing installed by hand;
/// `None` when the environment asks to skip.
fn chromium() -> Option<PathBuf> {
    if std::env::var("CWISIM_SKIP_BROWSER_TEST").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED: the browser test of `cwisim inspect` (CWISIM_SKIP_BROWSER_TEST=1)");
        return None;
    }
    if let Some(p) = std::env::var_os("CWISIM_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    if let Some(p) = chromium_on_path() {
        return Some(p);
    }
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/browser/install-chromium.sh");
    eprintln!(
        "the browser test needs Chromium: running {}",
        script.display()
    );
    let status = Command::new("bash").arg(&script).status();
    let installed = status.as_ref().is_ok_and(|s| s.success());
    match chromium_on_path() {
        Some(p) if installed => Some(p),
        _ => panic!(
            "the browser test needs Chromium and {} could not install it ({status:?}): install \
Debian's chromium package, set CWISIM_CHROMIUM to a Chromium binary, or set \
CWISIM_SKIP_BROWSER_TEST=1 to skip this test",
            script.display()
        ),
    }
}

/// Runs headless Chromium on `url` with `extra` arguments; its standard output and error.
fn run_chromium(bin: &Path, dir: &Path, url: &str, extra: &[&str]) -> (String, String) {
    let profile = dir.join(format!("profile-{}", extra.len()));
    let out = Command::new(bin)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=20000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .current_dir(dir)
        .output()
        .expect("run chromium");
    assert!(out.status.success(), "chromium failed: {:?}", out);
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The text of the `<pre id="ID">` element of a dumped DOM, entities decoded.
fn pre(dom: &str, id: &str) -> String {
    let open = format!("<pre id=\"{id}\"");
    let start = dom
        .find(&open)
        .unwrap_or_else(|| panic!("no #{id} in the DOM"));
    let start = start + dom[start..].find('>').unwrap() + 1;
    let end = start + dom[start..].find("</pre>").unwrap();
    dom[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

#[test]
fn the_page_shows_a_clicked_pixels_history_in_chromium() {
    let Some(bin) = chromium() else { return };
    let dir = scratch("browser");
    let size = ["--size", "160x120"];
    let said = cwisim_ok(
        &dir,
        &["inspect", "pot", size[0], size[1], "-o", "pot.html"],
    );
    assert!(said.contains("160×120"), "{said}");
    let page = dir.join("pot.html").canonicalize().unwrap();
    let url = format!("file://{}#click=80,60", page.display());

    // with every overlay drawn too
    let with_overlays = format!("{url}&overlay=cost,error,late");
    let (dom, log) = run_chromium(&bin, &dir, &with_overlays, &["--dump-dom"]);
    assert!(
        dom.contains("data-ready=\"1\""),
        "the page never got ready:\n{log}"
    );
    assert!(
        !dom.contains("data-errors"),
        "script errors: {}",
        pre(&dom, "errors")
    );
    let console: Vec<&str> = log.lines().filter(|l| l.contains(":CONSOLE")).collect();
    assert!(console.is_empty(), "console messages: {console:#?}");
    // (the page does report what goes wrong: an address it cannot follow)
    let bad = format!("file://{}#overlay=bogus", page.display());
    let (bad_dom, _) = run_chromium(&bin, &dir, &bad, &["--dump-dom"]);
    assert!(bad_dom.contains("data-errors=\"1\""), "no error shown");
    assert!(pre(&bad_dom, "errors").contains("no overlay bogus"));

    let history = cwisim_ok(
        &dir,
        &[
            "history", "pot", size[0], size[1], "--x", "80", "--line", "60",
        ],
    );
    // without the notes heading the visits (where each instruction came from), which the
    // page does not show yet
    let expected: Vec<&str> = history
        .lines()
        .filter(|l| !l.starts_with('#') || l.ends_with("(--all lists them)"))
        .collect();
    assert!(expected.len() >= 4, "{history}");
    assert_eq!(pre(&dom, "history"), expected.join("\n"));
    assert!(pre(&dom, "pixel").starts_with("x 80, scanline 60\n"));

    let dump = cwisim_ok(&dir, &["dump", "pot", size[0], size[1], "--lines", "60"]);
    let expected: Vec<&str> = dump
        .lines()
        .filter(|l| !l.starts_with("cwisim-trace") && !l.starts_with("# cycles"))
        // nor the notes, nor the blank line that sets the scanline's marker apart from them
        .filter(|l| !l.is_empty() && (!l.starts_with('#') || l.starts_with("# --- scanline")))
        .collect();
    assert_eq!(pre(&dom, "dump"), expected.join("\n"));

    // the screenshot shows the image
    let (_, log) = run_chromium(
        &bin,
        &dir,
        &url,
        &["--screenshot=shot.png", "--window-size=1400,1000"],
    );
    let shot = image::open(dir.join("shot.png"))
        .unwrap_or_else(|e| panic!("no screenshot ({e}):\n{log}"))
        .to_rgb8();
    let mut greys = std::collections::BTreeMap::<u8, usize>::new();
    for p in shot.pixels() {
        if p[0] == p[1] && p[1] == p[2] {
            *greys.entry(p[0]).or_default() += 1;
        }
    }
    // the scene's black background and the pot's shades, each grey level a block of
    // zoomed pixels (7 × 7 inside the pixel grid at 8×): a blank page has neither
    let black = greys.get(&0).copied().unwrap_or(0);
    let levels = greys
        .iter()
        .filter(|&(&g, &n)| g != 0 && g != 255 && n >= 40)
        .count();
    assert!(black > 5000, "no image drawn: {black} black pixels");
    assert!(levels >= 20, "no image drawn: {levels} grey levels");
}
