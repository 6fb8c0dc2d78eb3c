//! Every command that reads a trace also reads a scene, drawn through the renderer and
//! options on its command line: its output equals the same command on `cwisim emit`'s
//! trace of that scene, drawn with the same options.

mod common;

use common::{cwisim, cwisim_ok, read, scratch, text};

/// Runs `args` with `input` in place of `{}`, returning stdout.
fn with(dir: &std::path::Path, args: &[&str], input: &str) -> String {
    let args: Vec<&str> = args
        .iter()
        .map(|a| if *a == "{}" { input } else { a })
        .collect();
    cwisim_ok(dir, &args)
}

#[test]
fn study_commands_read_a_scene_as_its_emitted_trace() {
    let dir = scratch("inputs-scene");
    for draw in [
        &["--size", "120x120"][..],
        &[
            "--size",
            "120x120",
            "--renderer",
            "woo-chall",
            "--samples",
            "2",
        ][..],
    ] {
        let mut emit = vec!["emit", "pot", "-o", "pot.cwt"];
        emit.extend_from_slice(draw);
        cwisim_ok(&dir, &emit);
        for command in [
            &["stats", "{}"][..],
            &["history", "{}", "--line", "60", "--x", "50"],
            &["dump", "{}", "--lines", "60"],
        ] {
            // the trace is replayed as it is: the drawing flags are for the scene
            let trace = with(&dir, command, "pot.cwt");
            let mut args = command.to_vec();
            args.extend_from_slice(draw);
            let scene = with(&dir, &args, "pot");
            assert_eq!(scene, trace.replace("pot.cwt", "pot"), "{args:?}");
            assert!(!scene.is_empty());
        }
        // the whole array (the default window), and a window
        for window in [&[][..], &["--x", "40..=60"]] {
            let mut vcd = vec!["vcd", "pot", "--line", "60", "-o", "a.vcd"];
            vcd.extend_from_slice(window);
            let mut trace = vcd.clone();
            trace[1] = "pot.cwt";
            trace[5] = "b.vcd";
            cwisim_ok(&dir, &trace);
            vcd.extend_from_slice(draw);
            cwisim_ok(&dir, &vcd);
            assert_eq!(
                read(dir.join("a.vcd")),
                read(dir.join("b.vcd")),
                "{window:?}"
            );
        }
        let mut run = vec!["run", "pot", "-o", "a.png"];
        run.extend_from_slice(draw);
        cwisim_ok(&dir, &run);
        cwisim_ok(&dir, &["run", "pot.cwt", "-o", "b.png"]);
        assert_eq!(read(dir.join("a.png")), read(dir.join("b.png")));
        let mut diff = vec!["diff", "pot", "pot.cwt"];
        diff.extend_from_slice(draw);
        assert!(cwisim_ok(&dir, &diff).contains("the traces are equal"));
    }
}

#[test]
fn the_old_spelling_of_the_scanline_still_works() {
    let dir = scratch("inputs-alias");
    let new = cwisim_ok(&dir, &["history", "fig25", "--line", "10", "--x", "10"]);
    let old = cwisim_ok(&dir, &["history", "fig25", "--y", "10", "--x", "10"]);
    assert_eq!(new, old);
}

#[test]
fn an_unknown_scene_names_the_embedded_ones() {
    let dir = scratch("inputs-unknown");
    for command in ["stats", "dump", "run"] {
        let out = cwisim(&dir, &[command, "nosuch"]);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{command}: {stderr}");
        assert!(stderr.contains("embedded: pot"), "{command}: {stderr}");
    }
}
