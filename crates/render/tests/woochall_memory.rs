//! `woo-chall` makes its rows as they are emitted, holding one row's instructions at a
//! time rather than the frame's: the heap a frame needs grows with the image's side (the
//! rows' state, the bands of scanlines), not with its area. (One test in this binary: the
//! counting allocator sees every thread's allocations.) `woochall_frame_memory.rs` checks
//! the bound the memory budget is checked with.

use cwisim_fuzzing::heap::Counting;
use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Settings, Taps};
use cwisim_world::embedded::embedded;
use cwisim_world::parse_any;
use cwisim_xproc::NullSink;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The most heap rendering the pot at `side × side` on one thread (bands of 16 rows)
/// held at once, beyond the renderer built (bytes), and the instructions it emitted.
fn peak_heap(side: u32) -> (usize, u64) {
    let scene = parse_any(embedded("pot").unwrap().text, None)
        .unwrap()
        .with_size(side, side)
        .unwrap();
    let settings = Settings {
        samples: 2,
        ..Settings::default()
    };
    let r =
        (registry::find("woo-chall").unwrap().build)(LoadedScene::built("pot", scene), &settings)
            .unwrap();
    let (done, peak) = cwisim_fuzzing::heap::peak_heap(|| {
        render(
            &*r,
            &ArrayConfig::default(),
            1,
            &mut NullSink,
            Taps::default(),
        )
        .unwrap()
    });
    (peak, done.counters.get("instructions").unwrap())
}

#[test]
fn a_frame_s_heap_grows_with_its_side_not_its_area() {
    let (small, small_instructions) = peak_heap(128);
    let (large, large_instructions) = peak_heap(1024);
    // 64 times the area, and (the pot scaled) more than 16 times the instructions; 8
    // times the side. (Holding the frame's instructions, as it once did: 0.7 MB → 17 MB,
    // 24 times; one row's: 0.33 MB → 2.2 MB, 6.7 times.)
    assert!(
        large_instructions > 16 * small_instructions,
        "{small_instructions} → {large_instructions} instructions"
    );
    assert!(
        large < 12 * small,
        "peak heap {small} B at 128², {large} B at 1024²: it grows with the area"
    );
}
