//! `run`, `emit` and `convert` say what they wrote, as `render` and `tradeoff` do, and
//! nothing with `--quiet`; an output that is standard output itself gets no such line in
//! its stream; `convert` says on standard error what of the input it could not write.

mod common;

use common::{cwisim, repo, scratch, text};

#[test]
fn run_emit_and_convert_say_what_they_wrote_and_nothing_when_quiet() {
    let dir = scratch("wrote");
    let gouraud = repo().join("traces/gouraud.cwt");
    let gouraud = gouraud.to_str().unwrap();
    let cases: [(&[&str], &str, &str); 3] = [
        (
            &["run", gouraud, "-o", "g.png"],
            "g.png",
            "wrote g.png: 6 scanline(s) of 16 × 1 channel(s)",
        ),
        (
            &["emit", "pot", "--size", "32x32", "-o", "p.cwt"],
            "p.cwt",
            "wrote p.cwt: vanrij's stream for 32 × 32 × 1 channel(s)",
        ),
        (
            &["convert", gouraud, "-o", "g.cwb"],
            "g.cwb",
            "wrote g.cwb: ",
        ),
    ];
    for (args, file, want) in cases {
        let out = cwisim(&dir, args);
        let (stdout, stderr) = text(&out);
        assert!(out.status.success(), "{args:?}: {stderr}");
        assert!(stdout.starts_with(want), "{args:?}: {stdout}");
        assert!(dir.join(file).exists());
        std::fs::remove_file(dir.join(file)).unwrap();
        let quiet = cwisim(&dir, &[args, &["--quiet"]].concat());
        let (stdout, stderr) = text(&quiet);
        assert!(quiet.status.success(), "{args:?} --quiet: {stderr}");
        assert_eq!(stdout, "", "{args:?} --quiet");
        assert!(dir.join(file).exists());
    }
    // --quiet --stats: one would do nothing
    let out = cwisim(&dir, &["run", gouraud, "--stats", "--quiet"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_stream_written_to_standard_output_carries_no_wrote_line() {
    let dir = scratch("wrote-stdout");
    let out = cwisim(
        &dir,
        &["emit", "pot", "--size", "16x16", "-o", "/dev/stdout"],
    );
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.starts_with("cwisim-trace version=1"), "{stdout}");
    assert!(!stdout.contains("wrote"), "{stdout}");
    let antialiased = repo().join("traces/antialiased.cwt");
    let out = cwisim(
        &dir,
        &[
            "convert",
            antialiased.to_str().unwrap(),
            "-o",
            "/dev/stdout",
        ],
    );
    let (stdout, _) = text(&out);
    assert!(out.status.success());
    assert!(!stdout.contains("wrote"), "{stdout}");
}

#[test]
fn converting_to_cwb_says_how_many_notes_it_could_not_write() {
    let dir = scratch("wrote-notes");
    let antialiased = repo().join("traces/antialiased.cwt");
    let input = antialiased.to_str().unwrap();
    let out = cwisim(&dir, &["convert", input, "-o", "a.cwb", "--quiet"]);
    let (_, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: 5 note(s) of") && stderr.contains(".cwb has no record for them"),
        "{stderr}"
    );
    // kept by the encodings that carry them: no warning
    for kept in ["a.cwt", "a.jsonl"] {
        let out = cwisim(&dir, &["convert", input, "-o", kept]);
        let (_, stderr) = text(&out);
        assert!(out.status.success(), "{stderr}");
        assert_eq!(stderr, "", "{kept}");
    }
}
