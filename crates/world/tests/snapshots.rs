//! Snapshots of the instruction streams the embedded scenes emit (annotated text traces):
//! figure 25, and the pot at 64×64 with exact visibility, each with the exact box filter
//! (the default) and the report's (`_centre`: coverage × centre value; the same
//! instructions but for their operands). Review a changed snapshot with
//! `cargo insta review` before accepting it.

use cwisim_isa::text::TextWriter;
use cwisim_isa::TraceWrite;
use cwisim_scene::ScreenScene;
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, to_screen, AnyScene, Visibility};
use cwisim_ypipe::{emit, header, Antialias, Options, Shading};

/// The report's box filter.
fn centre() -> Options {
    Options {
        aa: Antialias::BoxCentre,
        ..Options::default()
    }
}

fn text(scene: &ScreenScene, options: &Options) -> String {
    let mut buf = Vec::new();
    {
        let mut w = TextWriter::new(&mut buf, &header(scene)).expect("header");
        emit(scene, options, &mut w).expect("emit");
        w.finish().expect("finish");
    }
    String::from_utf8(buf).expect("utf-8")
}

fn scene(name: &str) -> AnyScene {
    parse_any(embedded(name).expect("embedded").text, None).expect("reads")
}

#[test]
fn fig25_stream() {
    let AnyScene::Screen(s) = scene("fig25") else {
        panic!("fig25 is a screen scene")
    };
    insta::assert_snapshot!(text(&s, &Options::default()));
    insta::assert_snapshot!("fig25_stream_centre", text(&s, &centre()));
}

#[test]
fn pot_64x64_stream() {
    let AnyScene::World(w) = scene("pot").with_size(64, 64).expect("size") else {
        panic!("pot is a world scene")
    };
    let prepared = to_screen(&w, Shading::Gouraud, Visibility::Exact).expect("prepared");
    let trace = text(&prepared.screen, &Options::default());
    // the same scene gives the same stream, byte for byte
    let again = to_screen(&w, Shading::Gouraud, Visibility::Exact).expect("prepared");
    assert_eq!(trace, text(&again.screen, &Options::default()));
    insta::assert_snapshot!(trace);
    insta::assert_snapshot!("pot_64x64_stream_centre", text(&prepared.screen, &centre()));
}
