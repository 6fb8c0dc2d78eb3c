//! One name per concept across the commands: every subcommand's flags are walked, and a
//! flag that names a known concept by another spelling fails the test. Old spellings
//! live on only as hidden aliases.

mod common;

use clap::CommandFactory;
use common::{cwisim, scratch, text};
use cwisim_host::cli::Cli;

/// Spellings that must not be a flag's name, and the name the concept has.
const SYNONYMS: &[(&str, &str)] = &[
    ("y", "line"),
    ("scanline", "line"),
    ("row", "line"),
    ("scanlines", "lines"),
    ("rows", "lines"),
    ("column", "x"),
    ("processor", "x"),
    ("pixel", "x"),
    ("frame-range", "frames"),
    ("out", "output"),
    ("output-file", "output"),
    ("outfile", "output"),
    ("tol", "tolerance"),
    ("shade-tol", "shade-contrast"),
    ("threads-count", "threads"),
];

#[test]
fn every_flag_names_its_concept_one_way() {
    let cli = Cli::command();
    let mut seen = 0;
    let mut bad = Vec::new();
    for sub in cli.get_subcommands() {
        for arg in sub.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            seen += 1;
            if let Some((_, want)) = SYNONYMS.iter().find(|(s, _)| *s == long) {
                bad.push(format!("{} --{long}: call it --{want}", sub.get_name()));
            }
            // `-o` is always the output file, and always `--output`
            if arg.get_short() == Some('o') && long != "output" {
                bad.push(format!(
                    "{} -o is --{long}: call it --output",
                    sub.get_name()
                ));
            }
        }
    }
    assert!(seen > 50, "the walk found only {seen} flags");
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn a_flag_means_the_same_in_every_command() {
    // a flag shared by several commands takes the same kind of value everywhere
    let cli = Cli::command();
    let mut kinds: std::collections::BTreeMap<String, (String, String)> = Default::default();
    let mut bad = Vec::new();
    for sub in cli.get_subcommands() {
        for arg in sub.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            // what it takes: nothing (a switch) or a value, named alike (a list of values,
            // as a grid axis takes, is the same concept; an output's extension is its
            // format, not its concept)
            let takes = if arg.get_action().takes_values() {
                "a value"
            } else {
                "nothing"
            };
            let name = arg
                .get_value_names()
                .and_then(|v| v.first())
                .map(|s| s.split(['.', ',']).next().unwrap_or("").to_string())
                .unwrap_or_default();
            let kind = format!("{takes} {name}");
            match kinds.get(long) {
                Some((k, first)) if *k != kind => bad.push(format!(
                    "--{long}: `{kind}` in {} but `{k}` in {first}",
                    sub.get_name()
                )),
                Some(_) => {}
                None => {
                    kinds.insert(long.to_string(), (kind, sub.get_name().to_string()));
                }
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn an_output_extension_the_command_cannot_write_is_refused() {
    let dir = scratch("vocabulary-ext");
    for args in [
        &["run", "-o", "x.jpg"][..],
        &["render", "fig25", "-o", "x.jpg"],
        &["render", "fig25", "--npy", "x.png"],
        &["render", "fig25", "--cost-image", "x.bmp"],
        &["tradeoff", "fig25", "--plot", "x.svg"],
        &["refine", "--plot", "x.svg"],
        &["refine", "--csv", "x.txt"],
    ] {
        let out = cwisim(&dir, args);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains("writes a ."), "{args:?}: {stderr}");
    }
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "nothing written"
    );
}
