//! The memory `woo-chall`'s frames hold as they are emitted stays within the bound the
//! memory budget is checked with (`Renderer::frame_memory`), on every embedded scene, on
//! one thread and two. (One test in this binary: the counting allocator sees every
//! thread's allocations.)

use cwisim_fuzzing::heap::Counting;
use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Settings, Taps};
use cwisim_world::embedded::{embedded, EMBEDDED};
use cwisim_world::parse_any;
use cwisim_xproc::NullSink;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn a_frame_holds_no_more_than_its_bound_on_every_embedded_scene() {
    for e in EMBEDDED {
        for threads in [1, 2] {
            let scene = parse_any(embedded(e.name).unwrap().text, None)
                .unwrap()
                .with_size(320, 240)
                .unwrap();
            let settings = Settings {
                samples: 8,
                threads,
                ..Settings::default()
            };
            let r = (registry::find("woo-chall").unwrap().build)(
                LoadedScene::built(e.name, scene),
                &settings,
            )
            .unwrap();
            let bound = r.frame_memory(threads);
            let (_, peak) = cwisim_fuzzing::heap::peak_heap(|| {
                render(
                    &*r,
                    &ArrayConfig::default(),
                    threads,
                    &mut NullSink,
                    Taps::default(),
                )
                .unwrap()
            });
            assert!(
                peak as u64 <= bound,
                "{} on {threads} thread(s): {peak} B held, bound {bound} B",
                e.name
            );
        }
    }
}
