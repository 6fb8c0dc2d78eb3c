//! The docs a new user reads first stay in step with the binary: every embedded scene is
//! in the README's list and in SCENES.md's table, and the top-level `--help`'s examples
//! run as written in an empty directory, one after the other (each uses what the one
//! before wrote; `doc_examples.rs` runs every help's examples after making the files
//! their generic names stand for).

mod common;

use common::{cwisim, repo, scratch, text};
use cwisim_world::embedded::EMBEDDED;

#[test]
fn every_embedded_scene_is_in_the_readme_and_scenes_md() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let scenes = std::fs::read_to_string(repo().join("docs/SCENES.md")).unwrap();
    // the README's list: the comment that names them, over one or more lines
    let start = readme
        .find("# the embedded scenes (")
        .expect("the README lists the embedded scenes");
    let list = &readme[start..start + readme[start..].find(')').unwrap()];
    for e in EMBEDDED {
        let listed = list
            .split(|c: char| c == ',' || c == '(' || c.is_whitespace() || c == '#')
            .any(|w| w == e.name);
        assert!(
            listed,
            "README.md's list of embedded scenes lacks {}",
            e.name
        );
        assert!(
            scenes.contains(&format!("\n| `{}` ", e.name))
                || scenes.contains(&format!("\n| `{}` (", e.name)),
            "docs/SCENES.md's table lacks {}",
            e.name
        );
    }
}

#[test]
fn the_top_level_help_s_examples_run_as_written_in_an_empty_directory() {
    let dir = scratch("help-examples");
    let help = cwisim(&dir, &["--help"]);
    let (help, _) = text(&help);
    let examples: Vec<Vec<String>> = help
        .lines()
        .skip_while(|l| !l.starts_with("Examples"))
        .skip(1)
        .take_while(|l| l.starts_with("  cwisim "))
        .map(|l| {
            let command = l.split('#').next().unwrap();
            command
                .split_whitespace()
                .skip(1)
                .map(String::from)
                .collect()
        })
        .collect();
    assert!(examples.len() >= 3, "{help}");
    for args in &examples {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = cwisim(&dir, &args);
        let (_, stderr) = text(&out);
        assert!(out.status.success(), "cwisim {}: {stderr}", args.join(" "));
    }
    for made in ["pot.png", "pot.cwb", "pot-replayed.png"] {
        assert!(dir.join(made).exists(), "{made}");
    }
}
