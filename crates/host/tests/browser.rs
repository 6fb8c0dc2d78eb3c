//! `cwisim inspect`'s page in a real browser: headless Chromium (Debian's `chromium`,
//! installed by `tests/browser/install-chromium.sh`, which this test runs itself when no
//! Chromium is found) opens the page
//! from disk, a scripted click on a named pixel (the page's `#click=X,LINE` address
//! dispatches a click on the image at that pixel) shows the same history lines as
//! `cwisim history` and the scanline's disassembly as `cwisim dump`, with no console
//! message and no script error, and the screenshot shows the image.
//!
//! What only a browser shows is driven from a harness page that holds the page in a
//! frame (Chromium with `--allow-file-access-from-files` lets it reach in): a click on
//! the image writes the address, the back button returns to the pixel before, a changed
//! address is followed; the scanline's event view is drawn and its hover names the token
//! at its cycle and processor; the error overlay leaves rounding (1e-14) uncoloured until
//! its floor is lowered, and colours `f32`'s errors; an A/B page flips between its runs.
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
            "--virtual-time-budget=60000",
            "--allow-file-access-from-files",
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
    // its text: the spans that make lines links left out (a literal `<` is `&lt;` here)
    let mut text = String::new();
    let mut in_tag = false;
    for c in dom[start..end].chars() {
        match c {
            '<' => in_tag = true,
            '>' if in_tag => in_tag = false,
            c if !in_tag => text.push(c),
            _ => {}
        }
    }
    text.replace("&lt;", "<")
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
    // with the notes heading the visits (where each instruction came from), as the page
    // shows them: without the heading line only
    let expected: Vec<&str> = history
        .lines()
        .filter(|l| !l.starts_with("# processor"))
        .collect();
    assert!(expected.len() >= 4, "{history}");
    assert!(
        expected.iter().any(|l| l.starts_with("# row 60 trapezium")),
        "the renderer's notes head the visits: {history}"
    );
    assert_eq!(pre(&dom, "history"), expected.join("\n"));
    assert!(pre(&dom, "pixel").starts_with("x 80, scanline 60\n"));

    let dump = cwisim_ok(&dir, &["dump", "pot", size[0], size[1], "--lines", "60"]);
    let expected: Vec<&str> = dump
        .lines()
        .filter(|l| !l.starts_with("cwisim-trace") && !l.starts_with("# cycles"))
        .collect();
    assert!(
        expected.iter().any(|l| l.starts_with("# row 60 trapezium")),
        "the renderer's notes head the instructions: {dump}"
    );
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

/// The harness: loads `?page=URL` in a frame, waits until it is ready, runs the steps
/// `?steps=a,b` and writes what it saw as JSON into `<pre id="result">` (or `FAILED: …`).
const HARNESS: &str = r#"<!DOCTYPE html>
<html><head><meta charset="utf-8"></head><body>
<pre id="result">running</pre>
<iframe id="f" width="1400" height="1000"></iframe>
<script>
'use strict';
const q = new URLSearchParams(location.search);
const f = document.getElementById('f');
const out = {};
const sleep = ms => new Promise(r => setTimeout(r, ms));
async function until(what, cond) {
  for (let i = 0; i < 2000; i++) { if (cond()) return; await sleep(20); }
  throw new Error('timed out: ' + what);
}
const doc = () => f.contentDocument, win = () => f.contentWindow;
const el = id => doc().getElementById(id);
const text = id => el(id).textContent;
const applied = () => Number(doc().body.dataset.hashApplied || 0);
async function go(hash) {
  if (win().location.hash === '#' + hash) return;
  const n = applied();
  win().location.hash = hash;
  await until('the page follows #' + hash, () => applied() > n);
}
async function back() {
  const n = applied();
  win().history.back();
  await until('the page goes back', () => applied() > n);
}
// a canvas's pixels, read from a copy (reading the page's own would slow it down)
function pixels(id) {
  const c = el(id), copy = document.createElement('canvas');
  copy.width = c.width; copy.height = c.height;
  const ctx = copy.getContext('2d', { willReadFrequently: true });
  ctx.drawImage(c, 0, 0);
  return ctx.getImageData(0, 0, c.width, c.height).data;
}
function differing(a, b) {
  let n = 0;
  for (let i = 0; i < a.length; i += 4) if (a[i] !== b[i] || a[i + 1] !== b[i + 1] || a[i + 2] !== b[i + 2]) n++;
  return n;
}
function at(id, type, x, y, extra) {
  const c = el(id), r = c.getBoundingClientRect();
  c.dispatchEvent(new (win().MouseEvent)(type, Object.assign({ clientX: r.left + x * r.width / c.width,
    clientY: r.top + y * r.height / c.height, bubbles: true }, extra || {})));
}
const steps = {
  async address() {
    out.start_hash = win().location.hash;
    out.start_title = text('history-title');
    at('view', 'click', el('view').width / 2, el('view').height / 2);
    out.clicked_hash = win().location.hash;
    out.clicked_title = text('history-title');
    await back();
    out.back_hash = win().location.hash;
    out.back_title = text('history-title');
    out.back_history = text('history');
    await go('pixel=10,20');
    out.go_title = text('history-title');
    out.go_history = text('history');
    out.go_cmd = text('history-cmd');
    await go('line=30');
    out.line_dump = text('dump').split('\n')[0];
    out.line_hash = win().location.hash;
  },
  async link() {
    // a history entry links to its instruction in the disassembly, and the instructions
    // of the same polygon are marked there
    await go('pixel=80,60');
    const visit = doc().querySelector('#history .visit');
    out.link_visit = visit ? visit.textContent : null;
    if (visit) visit.click();
    const at = doc().querySelector('#dump span.at');
    out.link_at = at ? at.textContent : null;
    out.link_same = doc().querySelectorAll('#dump span.same').length;
  },
  async events() {
    await go('pixel=80,60');
    const px = pixels('events');
    let coloured = 0;
    for (let i = 0; i < px.length; i += 4) {
      const [r, g, b] = [px[i], px[i + 1], px[i + 2]];
      if (Math.max(r, g, b) - Math.min(r, g, b) > 60) coloured++;
    }
    out.events_coloured = coloured;
    out.events_drawn = Number(doc().body.dataset.eventsDrawn || 0);
    const c = el('events');
    search: for (let y = 40; y < c.height - 30; y += 3) {
      for (let x = 80; x < c.width - 12; x += 3) {
        at('events', 'mousemove', x, y);
        if (text('event-info').includes('the token of')) break search;
      }
    }
    out.event_info = text('event-info');
  },
  async threshold() {
    await go('pixel=80,60');
    const plain = pixels('view');
    await go('pixel=80,60&overlay=error');
    out.error_default = differing(plain, pixels('view'));
    out.scale = text('ov-scale-line');
    await go('pixel=80,60&overlay=error&floor=1e-16');
    out.error_low_floor = differing(plain, pixels('view'));
  },
  async frames() {
    out.first_title = text('title');
    await go('frame=3');
    out.frame_title = text('title');
    el('frame-next').click();
    await until('the next frame', () => text('title').includes('frame 4 '));
    out.next_hash = win().location.hash;
    await back();
    out.back_title = text('title');
    await go('pixel=3,9');
    out.pixel_title = text('title');
    out.pixel_history_title = text('history-title');
    out.pixel_history = text('history');
  },
  async ab() {
    await go('pixel=32,24');
    const a = pixels('view');
    out.a_title = text('history-title');
    win().dispatchEvent(new (win().KeyboardEvent)('keydown', { key: 'b' }));
    await until('run B shown', () => text('history-title').includes(' in B '));
    out.b_title = text('history-title');
    out.b_hash = win().location.hash;
    out.ab_differ = differing(a, pixels('view'));
    out.b_history = text('history');
    out.other_history = text('history-other');
    await go('pixel=32,24&overlay=diff');
    out.diff_differ = differing(a, pixels('view'));
  },
};
async function run() {
  f.src = q.get('page');
  await until('the page is ready', () => doc() && doc().body && doc().body.dataset.ready === '1');
  for (const s of q.get('steps').split(',')) await steps[s]();
  out.errors = doc().body.dataset.errors ? text('errors') : '';
}
run().then(() => { document.getElementById('result').textContent = JSON.stringify(out); },
  e => { document.getElementById('result').textContent = 'FAILED: ' + e; })
  .finally(() => { document.body.dataset.done = '1'; });
</script>
</body></html>
"#;

/// Runs the harness on `page` (a file in `dir`, with its address) and `steps`: what it
/// saw, after checking that it finished and nothing went to the console.
fn harness(bin: &Path, dir: &Path, page: &str, steps: &str) -> serde_json::Value {
    let harness = dir.join("harness.html");
    std::fs::write(&harness, HARNESS).unwrap();
    let page_url = format!("file://{}/{page}", dir.canonicalize().unwrap().display());
    let url = format!(
        "file://{}?steps={steps}&page={}",
        harness.canonicalize().unwrap().display(),
        page_url
            .bytes()
            .map(|b| match b {
                b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'/' => {
                    (b as char).to_string()
                }
                _ => format!("%{b:02X}"),
            })
            .collect::<String>()
    );
    let (dom, log) = run_chromium(bin, dir, &url, &["--dump-dom"]);
    assert!(
        dom.contains("data-done=\"1\""),
        "the harness never finished:\n{log}"
    );
    let result = pre(&dom, "result");
    assert!(
        !result.starts_with("FAILED"),
        "{steps} on {page}: {result}\n{log}"
    );
    let console: Vec<&str> = log.lines().filter(|l| l.contains(":CONSOLE")).collect();
    assert!(console.is_empty(), "console messages: {console:#?}");
    let out: serde_json::Value = serde_json::from_str(&result).expect("the harness's JSON");
    assert_eq!(out["errors"], "", "the page reported errors");
    out
}

/// `cwisim history`'s lines without its heading (the notes heading its visits kept: the
/// page shows them too), joined.
fn history(dir: &Path, args: &[&str]) -> String {
    let out = cwisim_ok(dir, args);
    out.lines()
        .filter(|l| !l.starts_with("# processor"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn the_address_follows_clicks_and_the_back_button_and_the_event_view_is_drawn() {
    let Some(bin) = chromium() else { return };
    let dir = scratch("browser_address");
    let size = ["--size", "160x120"];
    cwisim_ok(
        &dir,
        &["inspect", "pot", size[0], size[1], "-o", "pot.html"],
    );
    let out = harness(
        &bin,
        &dir,
        "pot.html#pixel=80,60",
        "address,link,events,threshold",
    );
    // a history entry's instruction, marked in its scanline's disassembly (RenderDoc's
    // jump to the draw call), with the others its polygon made
    let visit = out["link_visit"].as_str().expect("a visit to click");
    let index = visit
        .split('#')
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap();
    let marked = out["link_at"].as_str().expect("the instruction marked");
    assert!(
        marked.contains(&format!("# #{index} line 60")),
        "{visit} → {marked}"
    );
    assert!(
        out["link_same"].as_u64().unwrap() >= 1,
        "the polygon's other instructions"
    );

    // a click writes the address; back returns to the pixel before
    assert_eq!(out["start_hash"], "#pixel=80,60");
    assert!(out["start_title"]
        .as_str()
        .unwrap()
        .contains("processor 80 on scanline 60"));
    let clicked = out["clicked_hash"].as_str().unwrap();
    assert!(
        clicked.starts_with("#pixel=") && clicked != "#pixel=80,60",
        "{clicked}"
    );
    let (x, line) = clicked["#pixel=".len()..].split_once(',').unwrap();
    assert_eq!(
        out["clicked_title"],
        format!("processor {x} on scanline {line}")
    );
    assert_eq!(out["back_hash"], "#pixel=80,60");
    assert_eq!(out["back_title"], "processor 80 on scanline 60");
    let args = |x: &'static str, l: &'static str| {
        ["history", "pot", size[0], size[1], "--x", x, "--line", l]
    };
    assert_eq!(out["back_history"], history(&dir, &args("80", "60")));
    // a changed address is followed, and its command is the page's own
    assert_eq!(out["go_title"], "processor 10 on scanline 20");
    assert_eq!(out["go_history"], history(&dir, &args("10", "20")));
    assert_eq!(
        out["go_cmd"],
        "cwisim history pot --size 160x120 --x 10 --line 20"
    );
    assert_eq!(out["line_dump"], "# --- scanline 30");
    assert_eq!(out["line_hash"], "#line=30");

    // the event view: drawn, and its hover names a token of scanline 60 where it is
    assert!(out["events_drawn"].as_u64().unwrap() > 10, "{out}");
    assert!(out["events_coloured"].as_u64().unwrap() > 200, "{out}");
    let info = out["event_info"].as_str().unwrap();
    let dump = cwisim_ok(&dir, &["dump", "pot", size[0], size[1], "--lines", "60"]);
    let token = info.lines().nth(1).unwrap_or("");
    assert!(
        dump.lines().any(|l| l == token),
        "the hover names no instruction of scanline 60: {info}"
    );
    // `cycle C, processor P: …` and `in processor P over cycles A..B`: A = enter + P
    let head = info.lines().next().unwrap();
    let p: u64 = head
        .split("processor ")
        .nth(1)
        .unwrap()
        .split(':')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let enter: u64 = token.rsplit(' ').next().unwrap().parse().unwrap();
    assert!(
        info.contains(&format!(
            "in processor {p} over cycles {}..{}",
            enter + p,
            enter + p + 1
        )),
        "{info}"
    );

    // rounding (the pot's f64 error, ~1e-14) is not coloured until the floor is lowered
    assert_eq!(out["error_default"], 0, "{}", out["scale"]);
    assert!(
        out["scale"]
            .as_str()
            .unwrap()
            .contains("0 pixel(s) at or over it"),
        "{}",
        out["scale"]
    );
    assert!(out["error_low_floor"].as_u64().unwrap() > 1000, "{out}");

    // f32's errors are over the floor
    cwisim_ok(
        &dir,
        &[
            "inspect",
            "pot",
            size[0],
            size[1],
            "--numeric",
            "f32",
            "-o",
            "f32.html",
        ],
    );
    let out = harness(&bin, &dir, "f32.html#pixel=80,60", "threshold");
    assert!(out["error_default"].as_u64().unwrap() > 1000, "{out}");
}

#[test]
fn a_page_of_frames_selects_them_by_address_and_buttons() {
    let Some(bin) = chromium() else { return };
    let dir = scratch("browser_frames");
    let mut text = String::from("cwisim-trace version=1 width=8 lines=2 channels=1\n");
    for f in 0..5 {
        let v = (f + 1) as f64 / 16.0;
        text += &format!(
            "Eval2 {} 4 {v} 0.125\nRefresh\nEval1 0 8 {v}\nRefresh\n",
            f % 4
        );
    }
    std::fs::write(dir.join("five.cwt"), text).unwrap();
    let said = cwisim_ok(
        &dir,
        &["inspect", "five.cwt", "--frames", "1..", "-o", "five.html"],
    );
    assert!(said.contains("8×2 frames 1..5"), "{said}");
    let out = harness(&bin, &dir, "five.html", "frames");
    let title =
        |f: u64| format!("cwisim inspect: five.cwt (trace), frame {f} of 1..5, registers f64");
    assert_eq!(out["first_title"], title(1));
    assert_eq!(out["frame_title"], title(3));
    assert_eq!(out["next_hash"], "#frame=4");
    assert_eq!(out["back_title"], title(3));
    assert_eq!(out["pixel_title"], title(4));
    assert_eq!(out["pixel_history_title"], "processor 3 on scanline 9");
    assert_eq!(
        out["pixel_history"],
        history(&dir, &["history", "five.cwt", "--x", "3", "--line", "9"])
    );
}

#[test]
fn an_ab_page_flips_between_its_runs() {
    let Some(bin) = chromium() else { return };
    let dir = scratch("browser_ab");
    cwisim_ok(
        &dir,
        &[
            "inspect",
            "pot",
            "--size",
            "64x48",
            "--against",
            "pot --size 64x48 --renderer woo-chall --samples 2",
            "-o",
            "ab.html",
        ],
    );
    let out = harness(&bin, &dir, "ab.html", "ab");
    assert_eq!(out["a_title"], "processor 32 on scanline 24 in A pot");
    assert_eq!(out["b_title"], "processor 32 on scanline 24 in B pot");
    assert_eq!(out["b_hash"], "#pixel=32,24&run=b");
    assert!(out["ab_differ"].as_u64().unwrap() > 100, "{out}");
    assert!(out["diff_differ"].as_u64().unwrap() > 100, "{out}");
    let a = history(
        &dir,
        &[
            "history", "pot", "--size", "64x48", "--x", "32", "--line", "24",
        ],
    );
    let b = history(
        &dir,
        &[
            "history",
            "pot",
            "--size",
            "64x48",
            "--renderer",
            "woo-chall",
            "--samples",
            "2",
            "--x",
            "32",
            "--line",
            "24",
        ],
    );
    assert_eq!(out["b_history"], b);
    assert_eq!(out["other_history"], a);
}
