//! A scene built in code is drawn as the same scene read from its source under the same
//! settings: `--size` and `--tessellate` apply whichever way the scene arrived (they used
//! to apply only to scenes read through `Source::load_for`).

use cwisim_isa::Instruction;
use cwisim_render::pipeline::emit;
use cwisim_render::registry::REGISTRY;
use cwisim_render::{LoadedScene, Settings, Size, Source};
use cwisim_world::AnyScene;

/// The embedded teapot as read from its text, at its own size and tessellation (500×500,
/// 8 × 8 quads per patch).
fn teapot() -> AnyScene {
    let text = cwisim_world::embedded::embedded("teapot")
        .expect("the embedded teapot")
        .text;
    cwisim_world::parse_any(text, None).expect("parses")
}

#[test]
fn size_and_tessellation_apply_to_a_scene_built_in_code() {
    let settings = Settings {
        size: Some(Size {
            width: 64,
            height: 48,
        }),
        tessellate: Some(2),
        samples: 1,
        ..Settings::default()
    };
    assert!(
        !teapot().is_tessellated_at(2),
        "the test needs another level"
    );
    for entry in REGISTRY {
        let from_source = Source::Embedded("teapot")
            .load_for(&settings)
            .and_then(|l| (entry.build)(l, &settings));
        let built = (entry.build)(LoadedScene::built("teapot", teapot()), &settings);
        let (from_source, built) = match (from_source, built) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(a), Err(b)) => {
                // refused either way, for the same reason
                assert_eq!(a.to_string(), b.to_string(), "{}", entry.name);
                continue;
            }
            (a, b) => panic!(
                "{}: from the source {:?}, built {:?}",
                entry.name,
                a.err().map(|e| e.to_string()),
                b.err().map(|e| e.to_string())
            ),
        };
        let header = built.header();
        assert_eq!((header.width, header.lines), (64, 48), "{}", entry.name);
        assert_eq!(header, from_source.header(), "{}", entry.name);
        assert_eq!(
            built.scene_json(),
            from_source.scene_json(),
            "{}: what it drew",
            entry.name
        );
        let (mut a, mut b): (Vec<Instruction>, Vec<Instruction>) = (Vec::new(), Vec::new());
        match (emit(&*built, &mut a), emit(&*from_source, &mut b)) {
            (Ok(_), Ok(_)) => assert_eq!(a, b, "{}: the streams", entry.name),
            (Err(x), Err(y)) => assert_eq!(x.to_string(), y.to_string(), "{}", entry.name),
            (x, y) => panic!("{}: {x:?} against {y:?}", entry.name),
        }
    }
}

/// A screen scene whose polygons carry depths (two squares, the nearer drawn first).
fn squares_with_depths() -> AnyScene {
    let text = r#"{"kind": "screen", "width": 8, "height": 8, "channels": 1, "polygons": [
        {"vertices": [[0,0],[6,0],[6,6],[0,6]], "intensity": [[1],[1],[1],[1]], "depth": [1,1,1,1]},
        {"vertices": [[2,2],[8,2],[8,8],[2,8]], "intensity": [[0.5],[0.5],[0.5],[0.5]], "depth": [2,2,2,2]}
    ]}"#;
    cwisim_world::parse_any(text, None).unwrap()
}

#[test]
fn a_renderer_that_does_not_read_a_screen_scene_s_depths_says_so() {
    // the README's cp-bench scene carries depths: drawn by vanrij its polygons add up
    // (white, every scanline late), which the summary now says; those that read them don't
    let mut built = Vec::new();
    for entry in REGISTRY {
        let Ok(r) = (entry.build)(
            LoadedScene::built("squares", squares_with_depths()),
            &Settings::default(),
        ) else {
            continue;
        };
        let rows = r.summary_rows(&Default::default(), &Default::default());
        let noted = rows
            .iter()
            .any(|(label, text)| *label == "note" && text.contains("carry depths"));
        let reads_depths = ["woo-chall", "sbuffer", "bsp"].contains(&entry.name);
        assert_eq!(noted, !reads_depths, "{}: {rows:?}", entry.name);
        built.push(entry.name);
    }
    for name in ["vanrij", "refine", "woo-chall", "sbuffer", "bsp"] {
        assert!(
            built.contains(&name),
            "{name} draws screen scenes: {built:?}"
        );
    }
}
