//! The worked example of a custom renderer (`examples/rectangles/`), held to the
//! renderer interface: if the `Renderer` or `FramePlan` trait changes, this stops
//! compiling; if the pipeline changes what reaches the array, the snapshot or the
//! independent per-pixel sum fails.
//!
//! How to snapshot-test your own renderer's stream this way: docs/RENDERERS.md.

#[path = "../examples/rectangles/renderer.rs"]
mod renderer;

use cwisim_isa::{Encoding, Instruction};
use cwisim_render::{emit, render, ArrayConfig, Renderer, Taps};
use cwisim_xproc::ImageSink;
use renderer::{Rect, Rectangles};

fn example() -> Rectangles {
    renderer::three_rectangles()
}

/// The emitted stream, as the text trace a person reviews.
#[test]
fn the_stream_is_snapshot_tested() {
    let r = example();
    let mut bytes = Vec::new();
    {
        let mut w = Encoding::Text.writer(&mut bytes, &r.header()).unwrap();
        let counters = emit(&r, &mut *w).unwrap();
        assert_eq!(counters.get("rectangles"), Some(3));
        assert_eq!(counters.get("spans"), Some(5 + 6 + 3));
    }
    insta::assert_snapshot!("rectangles_cwt", String::from_utf8(bytes).unwrap());
}

/// Through the array, on 1, 2 and 3 threads: every pixel is the sum of the rectangles
/// over it, computed here independently, and the statistics do not depend on threads.
#[test]
fn through_the_array_each_pixel_is_the_sum_of_its_rectangles() {
    let r = example();
    let h = r.header();
    let mut reference = vec![0.0; 16 * 10];
    for rect in [(2, 1, 12, 6, 0.5), (6, 3, 15, 9, 0.25), (0, 7, 4, 10, 1.0)] {
        for y in rect.1..rect.3 {
            for x in rect.0..rect.2 {
                reference[y * 16 + x] += rect.4;
            }
        }
    }
    let mut first = None;
    for threads in [1, 2, 3] {
        let mut sink = ImageSink::new(16, 1, 1 << 20);
        let done = render(
            &r,
            &ArrayConfig::default(),
            threads,
            &mut sink,
            Taps::default(),
        )
        .expect("renders");
        let image = sink.finish().unwrap();
        assert_eq!(image.data, reference, "{threads} thread(s)");
        assert_eq!(done.stats.totals.instructions, 14 + u64::from(h.lines));
        let key = (done.counters.clone(), format!("{:?}", done.stats.totals));
        match &first {
            None => first = Some(key),
            Some(f) => assert_eq!(f, &key, "{threads} thread(s)"),
        }
    }
}

/// A renderer's bad input is refused before anything is emitted.
#[test]
fn bad_rectangles_are_refused() {
    let e = Rectangles::new(
        8,
        8,
        vec![Rect {
            x0: 3,
            y0: 0,
            x1: 3,
            y1: 2,
            value: 1.0,
        }],
    )
    .err()
    .expect("refused");
    assert!(e.to_string().contains("rectangle 0 is empty"), "{e}");
    assert!(Rectangles::new(0, 8, vec![]).is_err());
}

/// The stream collected in memory equals the one the text trace holds.
#[test]
fn the_stream_collects_in_memory() {
    let r = example();
    let mut stream: Vec<Instruction> = Vec::new();
    emit(&r, &mut stream).unwrap();
    assert_eq!(stream.len(), 14 + 10);
    assert_eq!(
        stream[1],
        Instruction::eval1(2, 10, cwisim_isa::Intensity::grey(0.5))
    );
}
