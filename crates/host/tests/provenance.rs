//! Where an instruction came from, through the study tools: the renderer's notes of a
//! `.cwt` trace (`# row 60 trapezium 4 (polygon 2): case 8: …`) shown by `dump` and
//! `history`, of a trace file and of a scene drawn in memory alike, kept by `convert`
//! where the encoding carries them, and never changing what is executed.

mod common;

use common::{cwisim, cwisim_ok, read, scratch, text};
use std::path::Path;

/// The embedded pot, small, as `render` draws it.
const DRAW: [&str; 2] = ["--size", "120x120"];

/// `cwisim emit pot` into `name` (its extension chooses the encoding).
fn emit(dir: &Path, name: &str) {
    let mut args = vec!["emit", "pot", "-o", name];
    args.extend(DRAW);
    cwisim_ok(dir, &args);
}

/// The lines of a `.cwt` trace that make scanline `line`: its instructions and the notes
/// above them (comment lines), in order.
fn scanline_of_trace(trace: &str, line: u64) -> Vec<String> {
    let mut out = Vec::new();
    let mut refreshes = 0;
    for l in trace.lines().skip(1) {
        if refreshes == line {
            out.push(l.to_string());
        }
        if l == "Refresh" {
            refreshes += 1;
        }
    }
    out
}

/// The lines of a dump that make its scanline `line`, without the dump's own
/// annotations (the trailing `# #N line … issue … enter …`, the scanline's marker and the
/// blank line after it).
fn scanline_of_dump(dump: &str, line: u64) -> Vec<String> {
    let marker = format!("# --- scanline {line}");
    let mut lines = dump.lines().skip_while(|l| *l != marker).skip(1);
    assert_eq!(lines.next(), Some(""), "a blank line after the marker");
    lines
        .take_while(|l| !l.starts_with("# --- scanline"))
        .map(|l| match l.split_once(" # #") {
            Some((instr, _)) => instr.trim_end().to_string(),
            None => l.to_string(),
        })
        .collect()
}

/// Every line without its notes (the comment lines).
fn without_notes(text: &str) -> String {
    text.lines()
        .filter(|l| !l.starts_with("# row"))
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn dump_shows_the_notes_of_a_rendered_trace_and_of_a_scene() {
    let dir = scratch("provenance-dump");
    emit(&dir, "pot.cwt");
    let trace = String::from_utf8(read(dir.join("pot.cwt"))).unwrap();
    let want = scanline_of_trace(&trace, 60);
    assert!(
        want.iter()
            .any(|l| l.starts_with("# row 60 trapezium ") && l.contains("(polygon ")),
        "{want:?}"
    );
    // the dump of the trace: each note above the instructions it covers, as in the trace
    let dump = cwisim_ok(&dir, &["dump", "pot.cwt", "--lines", "60"]);
    assert_eq!(scanline_of_dump(&dump, 60), want, "{dump}");
    // the scene drawn in memory: the same notes (the same dump, named otherwise)
    let mut args = vec!["dump", "pot", "--lines", "60"];
    args.extend(DRAW);
    assert_eq!(
        cwisim_ok(&dir, &args),
        dump.replace("pot.cwt", "pot"),
        "dump pot"
    );
}

#[test]
fn the_dump_of_a_trace_reads_back_with_its_notes() {
    let dir = scratch("provenance-dump-back");
    emit(&dir, "pot.cwt");
    let dump = cwisim_ok(&dir, &["dump", "pot.cwt"]);
    std::fs::write(dir.join("dump.cwt"), &dump).unwrap();
    // the dump's annotations are remarks, its notes are the trace's: the same JSON Lines
    cwisim_ok(&dir, &["convert", "pot.cwt", "a.jsonl"]);
    cwisim_ok(&dir, &["convert", "dump.cwt", "b.jsonl"]);
    let a = read(dir.join("a.jsonl"));
    assert_eq!(a, read(dir.join("b.jsonl")));
    assert!(String::from_utf8_lossy(&a).contains(",\"note\":\"row 60 trapezium "));
    // and dumped again, the same dump
    assert_eq!(
        cwisim_ok(&dir, &["dump", "dump.cwt"]),
        dump.replace("pot.cwt", "dump.cwt")
    );
}

#[test]
fn history_shows_the_note_of_each_visit() {
    let dir = scratch("provenance-history");
    emit(&dir, "pot.cwt");
    let trace = String::from_utf8(read(dir.join("pot.cwt"))).unwrap();
    let args = ["history", "pot.cwt", "--line", "60", "--x", "24"];
    let history = cwisim_ok(&dir, &args);
    // each visit's instruction, #N, is under the note the trace puts above it
    let instructions: Vec<(Option<String>, &str)> = {
        let (mut above, mut in_force) = (Vec::new(), None::<String>);
        let mut out = Vec::new();
        for l in trace.lines().skip(1) {
            if let Some(text) = l.strip_prefix("# ") {
                above.push(text);
                continue;
            }
            let refresh = l == "Refresh";
            let covered = if !above.is_empty() {
                let note = above.join("\n");
                above.clear();
                in_force = (!refresh).then(|| note.clone());
                Some(note)
            } else if refresh {
                in_force = None;
                None
            } else {
                in_force.clone()
            };
            out.push((covered, l));
        }
        out
    };
    let mut shown_note = None;
    let mut visits = 0;
    for l in history.lines().skip(1) {
        if let Some(text) = l.strip_prefix("# row ") {
            shown_note = Some(format!("row {text}"));
            continue;
        }
        let Some(rest) = l.strip_prefix("cycle ") else {
            continue;
        };
        let index: usize = rest
            .split('#')
            .nth(1)
            .unwrap()
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let (note, instr) = &instructions[index];
        assert!(rest.contains(instr), "{l} is {instr}");
        if let Some(note) = note {
            assert_eq!(shown_note.as_ref(), Some(note), "{l}\n{history}");
            visits += 1;
        }
    }
    assert!(visits >= 4, "{history}");
    assert!(history.contains("\n# row 60 trapezium "), "{history}");
    // the scene drawn in memory shows the same
    let mut scene = vec!["history", "pot", "--line", "60", "--x", "24"];
    scene.extend(DRAW);
    assert_eq!(cwisim_ok(&dir, &scene), history.replace("pot.cwt", "pot"));
}

#[test]
fn convert_keeps_the_notes_where_the_encoding_carries_them() {
    let dir = scratch("provenance-convert");
    emit(&dir, "pot.cwt");
    let trace = read(dir.join("pot.cwt"));
    // .cwt → .jsonl → .cwt: the same bytes, notes and all
    cwisim_ok(&dir, &["convert", "pot.cwt", "pot.jsonl"]);
    cwisim_ok(&dir, &["convert", "pot.jsonl", "back.cwt"]);
    assert_eq!(read(dir.join("back.cwt")), trace);
    // .jsonl as emitted carries them too
    emit(&dir, "emitted.jsonl");
    assert_eq!(read(dir.join("emitted.jsonl")), read(dir.join("pot.jsonl")));
    // .cwb has no place for them, and convert says so: back in text, the trace without
    // its notes
    let out = cwisim(&dir, &["convert", "pot.cwt", "pot.cwb"]);
    let (_, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.starts_with("warning: ") && stderr.contains(" note(s) of pot.cwt not written"),
        "{stderr}"
    );
    cwisim_ok(&dir, &["convert", "pot.cwb", "plain.cwt"]);
    let plain = String::from_utf8(read(dir.join("plain.cwt"))).unwrap();
    assert_eq!(plain, without_notes(&String::from_utf8(trace).unwrap()));
    assert!(!plain.contains('#'));
}

#[test]
fn a_note_never_changes_what_is_executed() {
    let dir = scratch("provenance-same");
    emit(&dir, "pot.cwt");
    let trace = String::from_utf8(read(dir.join("pot.cwt"))).unwrap();
    assert!(trace.contains("\n# row "));
    std::fs::write(dir.join("plain.cwt"), without_notes(&trace)).unwrap();
    for (name, prefix) in [("pot.cwt", "a"), ("plain.cwt", "b"), ("pot", "c")] {
        let npy = format!("{prefix}.npy");
        let json = format!("{prefix}.json");
        let mut args = vec!["run", name, "--npy", &npy, "--stats-json", &json];
        if name == "pot" {
            args.extend(DRAW);
        }
        cwisim_ok(&dir, &args);
    }
    for ext in ["npy", "json"] {
        let a = read(dir.join(format!("a.{ext}")));
        assert_eq!(a, read(dir.join(format!("b.{ext}"))), "{ext}");
        assert_eq!(a, read(dir.join(format!("c.{ext}"))), "{ext}");
    }
    // the study tools: the same, notes aside
    for args in [
        &["dump", "{}", "--lines", "58..62"][..],
        &["history", "{}", "--line", "60", "--x", "24", "--all"],
        &["stats", "{}"],
    ] {
        let with = |input: &str| {
            let a: Vec<&str> = args
                .iter()
                .map(|a| if *a == "{}" { input } else { a })
                .collect();
            cwisim_ok(&dir, &a).replace(input, "TRACE")
        };
        let noted = with("pot.cwt");
        assert_eq!(without_notes(&noted), with("plain.cwt"), "{args:?}");
    }
}
