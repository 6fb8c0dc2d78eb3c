//! No drawing flag is accepted that does nothing: one the renderer does not read, one the
//! other flags leave idle, one the scene has nothing for, and any drawing flag when the
//! input is a trace are refused — exit 2, one line saying what would use it — and the
//! registry's declarations hold both ways: every renderer takes every flag it declares,
//! and that flag changes what it sends.

mod common;

use common::{cwisim, cwisim_ok, patch_scene, read, repo, scratch, text};
use cwisim_render::settings::Setting;
use cwisim_render::REGISTRY;
use std::path::Path;

/// Runs `args` in `dir`, asserting exit 2, nothing on stdout, and `stderr` exactly
/// `error: {message}`.
fn refused(dir: &Path, args: &[&str], message: &str) {
    let out = cwisim(dir, args);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(stderr, format!("error: {message}\n"), "{args:?}");
    assert!(stdout.is_empty(), "{args:?}: {stdout}");
}

#[test]
fn a_flag_the_renderer_does_not_read_is_refused_naming_the_ones_that_do() {
    let dir = scratch("flags-used-renderer");
    refused(
        &dir,
        &["render", "pot", "--samples", "8", "-o", "x.png"],
        "--samples is not used by vanrij (it draws trapezia with the box filter or point sampling; --samples is for woo-chall, sbuffer, bsp)",
    );
    let woo = "it point-samples each pixel on an l×l grid and resolves visibility per sample";
    refused(
        &dir,
        &[
            "render",
            "pot",
            "--renderer",
            "woo-chall",
            "--aa",
            "box-centre",
            "-o",
            "x.png",
        ],
        &format!("--aa is not used by woo-chall ({woo}; --aa is for vanrij, nishita)"),
    );
    refused(
        &dir,
        &[
            "emit",
            "pot",
            "--renderer",
            "woo-chall",
            "--visibility",
            "eval0",
            "-o",
            "x.cwt",
        ],
        &format!("--visibility is not used by woo-chall ({woo}; --visibility is for vanrij)"),
    );
    refused(
        &dir,
        &["render", "pot", "--renderer", "refine", "--shading", "gouraud", "-o", "x.png"],
        "--shading is not used by refine (its phases choose the shading, the filter and the visibility themselves; --shading is for vanrij, woo-chall, sbuffer, bsp, nishita)",
    );
    // every command that draws, the same way
    for command in [
        &["stats", "pot"][..],
        &["fit", "pot", "--max-error", "1/64"],
        &["dump", "pot"],
    ] {
        let mut args = command.to_vec();
        args.extend(["--seed", "3"]);
        refused(
            &dir,
            &args,
            "--seed is not used by vanrij (it draws trapezia with the box filter or point sampling; --seed is for woo-chall)",
        );
    }
    assert!(!dir.join("x.png").exists() && !dir.join("x.cwt").exists());
}

#[test]
fn phong_is_not_drawn_with_the_exact_box_filter() {
    let dir = scratch("flags-used-phong");
    refused(
        &dir,
        &["render", "pot", "--shading", "phong", "--aa", "box", "-o", "x.png"],
        "--aa box (exact) is not drawn with --shading phong: no instruction carries the exact integral of a Phong shade over a pixel; use --aa box-centre (coverage × the shade at the pixel centre, what Phong's box filter is) or --aa none",
    );
    assert!(!dir.join("x.png").exists());
    // the default --aa is shared with Gouraud: the summary says what Phong made of it
    let out = cwisim_ok(
        &dir,
        &[
            "render",
            "pot",
            "--shading",
            "phong",
            "--size",
            "32x32",
            "-o",
            "p.png",
        ],
    );
    let scene = out.lines().next().unwrap_or_default();
    assert!(
        scene.contains("Phong shading") && scene.contains("box filter (coverage × centre value)"),
        "{out}"
    );
    assert_eq!(out.matches("coverage × centre value").count(), 1, "{out}");
    cwisim_ok(
        &dir,
        &[
            "render",
            "pot",
            "--shading",
            "phong",
            "--aa",
            "box-centre",
            "--size",
            "32x32",
            "-o",
            "q.png",
        ],
    );
    assert_eq!(read(dir.join("p.png")), read(dir.join("q.png")));
}

#[test]
fn nishita_refuses_a_scene_without_patches() {
    let dir = scratch("flags-used-nishita");
    for command in ["render", "stats", "inspect"] {
        refused(
            &dir,
            &[command, "pot", "--renderer", "nishita", "-o", "x.html"][..if command == "stats" {
                4
            } else {
                6
            }],
            "--renderer nishita draws Bézier patches, and pot has none: it would draw exactly as vanrij; use --renderer vanrij",
        );
    }
    assert!(!dir.join("x.html").exists());
    let out = cwisim_ok(
        &dir,
        &[
            "render",
            "teapot",
            "--renderer",
            "nishita",
            "--size",
            "32x32",
            "-o",
            "t.png",
        ],
    );
    assert!(out.contains("roots to 1e-3"), "{out}");
}

#[test]
fn a_flag_the_other_flags_or_the_scene_leave_idle_is_refused() {
    let dir = scratch("flags-used-idle");
    for (args, message) in [
        (
            &["--shade-tolerance", "0"][..],
            "--shade-tolerance is the span fitter's, used with --shading phong, on textured meshes, and by nishita under the box filter; pot has no texture",
        ),

        (
            &["--eval0-tolerance", "0"],
            "--eval0-tolerance is used with --visibility eval0 and --shading gouraud only (a flat claim is one value)",
        ),
        (
            &["--visibility", "eval0", "--shading", "flat", "--eval0-tolerance", "0"],
            "--eval0-tolerance is used with --visibility eval0 and --shading gouraud only (a flat claim is one value)",
        ),
        (
            &["--renderer", "bsp", "--order", "back-to-front", "--unset", "host"],
            "--unset is used with --order front-to-back only (back to front paints into a host colour line)",
        ),
        (
            &["--renderer", "sbuffer", "--samples", "1", "--merge-subscanlines"],
            "--merge-subscanlines is used with --samples 2 or more (one sub-scanline per row has nothing to merge)",
        ),
        (
            &["--renderer", "woo-chall", "--shading", "hidden", "--shade-p", "0.5"],
            "--shade-p is for shading calls, and --shading hidden makes none",
        ),
        (
            &["--tessellate", "4"],
            "--tessellate applies to Bézier meshes; pot has none",
        ),
    ] {
        let mut all = vec!["render", "pot", "-o", "x.png"];
        all.extend_from_slice(args);
        refused(&dir, &all, message);
    }
    for flag in [
        &["--visibility", "eval0"][..],
        &["--renderer", "refine", "--aa-threshold", "all"],
    ] {
        let mut all = vec!["render", "fig25", "-o", "x.png"];
        all.extend_from_slice(flag);
        let name = flag[flag.len() - 2];
        refused(
            &dir,
            &all,
            &format!(
                "{name} applies to world scenes; fig25 is a screen scene, its polygons drawn as they are"
            ),
        );
    }
    // nishita fits a patch's row as one span under the box filter, whatever the
    // shading: --shade-tolerance is refused only under point sampling
    let nishita = [
        "render",
        "teapot",
        "-o",
        "x.png",
        "--renderer",
        "nishita",
        "--size",
        "24x24",
    ];
    refused(
        &dir,
        &[&nishita[..], &["--aa", "none", "--shade-tolerance", "0"]].concat(),
        "--shade-tolerance is the span fitter's, used with --shading phong, on textured meshes, and by nishita under the box filter; teapot has no texture",
    );
    assert!(!dir.join("x.png").exists());
    let coarse = cwisim_ok(
        &dir,
        &[&nishita[..], &["--shade-tolerance", "0.05"]].concat(),
    );
    let exact = cwisim_ok(&dir, &[&nishita[..], &["--shade-tolerance", "0"]].concat());
    let count = |out: &str| -> u64 {
        let line = out
            .lines()
            .find(|l| l.starts_with("instructions"))
            .expect(out);
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    assert!(count(&coarse) < count(&exact), "{coarse}\n{exact}");
}

#[test]
fn a_trace_input_refuses_every_drawing_flag() {
    let dir = scratch("flags-used-trace");
    std::fs::create_dir(dir.join("traces")).unwrap();
    std::fs::copy(
        repo().join("traces/gouraud.cwt"),
        dir.join("traces/gouraud.cwt"),
    )
    .unwrap();
    let t = "traces/gouraud.cwt";
    let says = "--renderer applies when the input is a scene; traces/gouraud.cwt is a trace, replayed as it is";
    for command in [
        &["run", t][..],
        &["stats", t],
        &["dump", t],
        &["history", t, "--line", "0", "--x", "1"],
        &["vcd", t, "--line", "0", "-o", "x.vcd"],
        &["inspect", t, "-o", "x.html"],
        &["diff", t, t],
    ] {
        let mut args = command.to_vec();
        args.extend(["--renderer", "woo-chall"]);
        refused(&dir, &args, says);
        // naming the default is still a flag that does nothing here
        let mut args = command.to_vec();
        args.extend(["--renderer", "vanrij", "--size", "4x4"]);
        refused(
            &dir,
            &args,
            "--renderer and --size apply when the input is a scene; traces/gouraud.cwt is a trace, replayed as it is",
        );
    }
    refused(
        &dir,
        &["run", "--shading", "flat"],
        "--shading applies when the input is a scene; without one, the embedded demo trace is replayed as it is",
    );
    assert!(!dir.join("x.vcd").exists() && !dir.join("x.html").exists());
    // without drawing flags the trace is replayed; a scene on one side of diff takes them
    cwisim_ok(&dir, &["run", t]);
    let out = cwisim(
        &dir,
        &["diff", "pot", t, "--shading", "flat", "--size", "8x8"],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out).1);
}

#[test]
fn help_says_the_drawing_flags_are_for_scenes() {
    let dir = scratch("flags-used-help");
    for command in ["run", "stats", "dump", "history", "vcd", "inspect", "diff"] {
        let out = cwisim_ok(&dir, &[command, "--help"]);
        assert!(
            out.contains("\nDrawing a scene (only when the input is a scene; refused with a trace):\n      --renderer <NAME>"),
            "{command}: {out}"
        );
    }
    let out = cwisim_ok(&dir, &["render", "--help"]);
    for heading in [
        "Supersampling (woo-chall, sbuffer, bsp):\n      --samples",
        "Stochastic shading calls (woo-chall):\n      --shade-p",
        "Bézier patches (nishita):\n      --root-tolerance",
        "Adaptive refinement (refine):\n      --gouraud-threshold",
    ] {
        assert!(out.contains(heading), "{heading}: {out}");
    }
    assert!(!out.contains("refused with a trace"), "{out}");
}

/// A value other than the default for `s`, with what it needs of the other flags when
/// the renderer reads them (`shading`: whether it reads `--shading`).
fn example(s: Setting, shading: bool) -> Vec<&'static str> {
    let phong = |rest: &[&'static str]| {
        let mut v = if shading {
            vec!["--shading", "phong"]
        } else {
            Vec::new()
        };
        v.extend_from_slice(rest);
        v
    };
    match s {
        Setting::Shading => vec!["--shading", "phong"],
        Setting::Aa => vec!["--aa", "none"],
        Setting::Visibility => vec!["--visibility", "eval0"],
        Setting::Eval0Tolerance => vec!["--visibility", "eval0", "--eval0-tolerance", "0"],
        Setting::Size => vec!["--size", "24x20"],
        Setting::ShadeTolerance => phong(&["--shade-tolerance", "0"]),
        Setting::Tessellate => vec!["--tessellate", "2"],
        Setting::Samples => vec!["--samples", "2"],
        Setting::Grid => vec!["--grid", "corner"],
        Setting::MergeSubscanlines => vec!["--merge-subscanlines"],
        Setting::ShadeP => vec!["--shade-p", "1"],
        Setting::ShadeContrast => vec!["--shade-contrast", "0"],
        Setting::Seed => vec!["--seed", "7"],
        Setting::CpIncrement => vec!["--cp-increment", "paper"],
        Setting::Sbuffer => vec!["--sbuffer", "overdraw", "--samples", "1"],
        Setting::Order => vec!["--order", "back-to-front"],
        Setting::Unset => vec!["--unset", "eval0", "--shading", "flat", "--samples", "1"],
        Setting::RootTolerance => vec!["--root-tolerance", "0.2"],
        Setting::Flatness => vec!["--flatness", "4"],
        Setting::NormalAngle => vec!["--normal-angle", "45"],
        Setting::Band => vec!["--band", "1"],
        Setting::Subscan => vec!["--subscan", "3"],
        Setting::GouraudThreshold => vec!["--gouraud-threshold", "all"],
        Setting::AaThreshold => vec!["--aa-threshold", "all"],
        Setting::PhongAngle => vec!["--phong-angle", "all"],
        Setting::Shadows => vec!["--shadows", "on"],
        Setting::TextureFilter => vec!["--texture-filter", "point"],
    }
}

/// The flag of `s` and its value in [`example`] (none for a switch).
fn alone(s: Setting) -> Vec<&'static str> {
    let e = example(s, false);
    let at = e.iter().position(|a| *a == s.flag()).expect("the flag");
    let end = match e.get(at + 1) {
        Some(v) if !v.starts_with("--") => at + 2,
        _ => at + 1,
    };
    e[at..end].to_vec()
}

#[test]
fn every_renderer_takes_and_uses_every_flag_it_declares_and_refuses_the_others() {
    let dir = scratch("flags-used-declared");
    std::fs::write(dir.join("patches.json"), patch_scene()).unwrap();
    // the same patches with a checkerboard, for the flags of textured scenes
    let textured = patch_scene().replace(
        r#""n": 20}"#,
        r#""n": 20, "texture": {"checker": {"squares": [3, 3]}}}"#,
    );
    assert_ne!(textured, patch_scene());
    std::fs::write(dir.join("textured.json"), textured).unwrap();
    let scene_of = |s: Setting| match s {
        Setting::TextureFilter => "textured.json",
        _ => "patches.json",
    };
    for entry in REGISTRY {
        // what a flag may change: the image, the instructions per pixel, and the host's
        // work the summary counts (not its first line, which repeats the settings, nor
        // the wall times)
        let render = |scene: &str, extra: &[&str]| {
            let mut args = vec![
                "render",
                scene,
                "--renderer",
                entry.name,
                "--npy",
                "a.npy",
                "--cost-npy",
                "c.npy",
            ];
            args.extend_from_slice(extra);
            let summary: String = cwisim_ok(&dir, &args)
                .lines()
                .filter(|l| {
                    !["scene", "time", "host time", "wrote"]
                        .iter()
                        .any(|p| l.starts_with(p))
                })
                .collect();
            [
                read(dir.join("a.npy")),
                read(dir.join("c.npy")),
                summary.into_bytes(),
            ]
            .concat()
        };
        let mut defaults = std::collections::HashMap::new();
        for &s in entry.uses {
            let scene = scene_of(s);
            let default = defaults
                .entry(scene)
                .or_insert_with(|| render(scene, &[]))
                .clone();
            let extra = example(s, entry.uses.contains(&Setting::Shading));
            // the flag against what it needs of the others without it
            let flag = alone(s);
            let at = extra.iter().position(|a| *a == s.flag()).expect("the flag");
            let needs = [&extra[..at], &extra[at + flag.len()..]].concat();
            let reference = if needs.is_empty() {
                default.clone()
            } else {
                render(scene, &needs)
            };
            assert_ne!(
                render(scene, &extra),
                reference,
                "{} {} changes nothing: {extra:?}",
                entry.name,
                s.flag()
            );
        }
        for s in Setting::ALL {
            if entry.uses.contains(&s) {
                continue;
            }
            let mut args = vec!["render", "patches.json", "--renderer", entry.name];
            args.extend(alone(s));
            args.extend(["-o", "x.png"]);
            let out = cwisim(&dir, &args);
            let (_, stderr) = text(&out);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
            let want = format!("error: {} is not used by {} (", s.flag(), entry.name);
            assert!(stderr.starts_with(&want), "{args:?}: {stderr}");
        }
    }
    assert!(!dir.join("x.png").exists());
}
