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
