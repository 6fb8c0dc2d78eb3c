//! Shared by the ypipe integration tests: emitting a scene into the array simulator or
//! into text.

#![allow(dead_code)]

use cwisim_isa::text::TextWriter;
use cwisim_isa::TraceWrite;
use cwisim_scene::{parse_scene, Scene, ScreenScene};
use cwisim_xproc::{EngineWriter, ImageSink, Machine, Timing};
use cwisim_ypipe::{emit, header, EmitStats, Options};
use std::path::PathBuf;

pub fn fixture(name: &str) -> ScreenScene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    let text = std::fs::read_to_string(&path).expect("fixture exists");
    let Scene::Screen(s) = parse_scene(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    s
}

/// The scene through the Y-processor and the array: the image (rows × width × channels).
pub fn render(scene: &ScreenScene, options: &Options) -> (Vec<f64>, EmitStats) {
    let h = header(scene);
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let stats = {
        let mut w = EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink)
            .expect("machine");
        let stats = emit(scene, options, &mut w).expect("every emitted instruction fits the array");
        w.finish().expect("finish");
        stats
    };
    let image = sink.finish().expect("image");
    assert_eq!(
        image.lines, scene.height as usize,
        "one scanline per image row"
    );
    (image.data, stats)
}

/// The scene through the Y-processor and the array: the image and the array's statistics
/// (dropped negative contributions among them).
pub fn render_run(scene: &ScreenScene, options: &Options) -> (Vec<f64>, cwisim_xproc::RunStats) {
    let h = header(scene);
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
    let run = {
        let mut w = EngineWriter::<f64>::new(&h, &Machine::default(), Timing::Fast, &mut sink)
            .expect("machine");
        emit(scene, options, &mut w).expect("every emitted instruction fits the array");
        w.finish().expect("finish");
        w.into_stats().expect("statistics after finish")
    };
    (sink.finish().expect("image").data, run)
}

/// The scene's instructions, `Refresh` included.
pub fn instructions(scene: &ScreenScene, options: &Options) -> Vec<cwisim_isa::Instruction> {
    let mut out = Vec::new();
    emit(scene, options, &mut out).expect("emit into memory");
    out
}

/// The scene as an annotated text trace.
pub fn text(scene: &ScreenScene, options: &Options) -> String {
    let mut buf = Vec::new();
    {
        let mut w = TextWriter::new(&mut buf, &header(scene)).expect("header");
        emit(scene, options, &mut w).expect("emit");
        w.finish().expect("finish");
    }
    String::from_utf8(buf).expect("utf-8")
}
