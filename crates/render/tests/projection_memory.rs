//! What `woo-chall`, `sbuffer` and `bsp` hold a triangle when they project a world scene,
//! measured with a counting allocator: at most the figure each checks against the memory
//! budget before projecting (`BYTES_PER_TRIANGLE` of `woochall::prepare`,
//! `sbuffer::polys` and `bsp`), on the teapot at 4 to 16 quads a patch side and on the
//! pot and the glass scene (no light casts shadows there: the shadow pass is checked on
//! its own), and not far above it; and `bsp`'s tree at most `bsp::PIECE_BYTES` a piece
//! beyond those polygons, the figure its splits are checked against as they grow. One
//! test in this binary, so that no other test's allocations are counted with it.

use cwisim_fuzzing::heap::{peak_heap, Counting};
use cwisim_render::{registry, LoadedScene, Settings};
use cwisim_world::embedded::embedded;
use cwisim_world::{parse_any, AnyScene};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn each_renderer_holds_what_it_checks_against_the_budget() {
    let renderers = [
        (
            "woo-chall",
            cwisim_render::woochall::prepare::BYTES_PER_TRIANGLE,
        ),
        ("sbuffer", cwisim_render::sbuffer::polys::BYTES_PER_TRIANGLE),
        ("bsp", cwisim_render::bsp::BYTES_PER_TRIANGLE),
    ];
    let scenes = [
        ("teapot", 4),
        ("teapot", 8),
        ("teapot", 16),
        ("pot", 0),
        ("glass", 0),
    ];
    for (name, figure) in renderers {
        let mut largest = 0.0f64;
        for (scene, n) in scenes {
            let AnyScene::World(mut w) = parse_any(embedded(scene).unwrap().text, None).unwrap()
            else {
                panic!("{scene} is a world scene")
            };
            if n > 0 {
                w = w.with_tessellation(n).unwrap();
            }
            let triangles = w.triangle_count() as u64;
            let build = registry::find(name).unwrap().build;
            let settings = Settings {
                threads: 1,
                ..Settings::default()
            };
            // the meshes are built before: what the renderer adds to them
            let (renderer, peak) =
                peak_heap(|| build(LoadedScene::built(scene, AnyScene::World(w)), &settings));
            assert!(renderer.is_ok(), "{name} on {scene}");
            drop(renderer);
            assert!(
                peak as u64 <= triangles * figure,
                "{name} on {scene} ({triangles} triangles): {peak} B at the peak, {} counted",
                triangles * figure
            );
            if scene == "teapot" {
                largest = largest.max(peak as f64 / triangles as f64);
            }
        }
        assert!(
            largest > 0.8 * figure as f64,
            "{name}: {largest:.0} B a triangle at most, {figure} counted"
        );
    }
    // bsp's pieces, as its splits make them: what `bsp` holds past `sbuffer`'s polygons,
    // a piece of its tree, at most `bsp::PIECE_BYTES`
    let figure = cwisim_render::bsp::PIECE_BYTES;
    let mut largest = 0.0f64;
    for (scene, n) in scenes {
        let load = || {
            let AnyScene::World(w) = parse_any(embedded(scene).unwrap().text, None).unwrap() else {
                panic!("{scene} is a world scene")
            };
            AnyScene::World(if n > 0 {
                w.with_tessellation(n).unwrap()
            } else {
                w
            })
        };
        let settings = Settings {
            threads: 1,
            ..Settings::default()
        };
        let (scene_polys, polygons) = {
            let built = load();
            let build = registry::find("sbuffer").unwrap().build;
            peak_heap(|| build(LoadedScene::built(scene, built), &settings).map(drop))
        };
        assert!(scene_polys.is_ok());
        let built = load();
        let (bsp, tree) =
            peak_heap(|| cwisim_render::bsp::Bsp::new(LoadedScene::built(scene, built), &settings));
        let pieces = bsp.expect("bsp draws it").pieces().0.len();
        let per_piece = tree.saturating_sub(polygons) as f64 / pieces as f64;
        assert!(
            per_piece <= figure as f64,
            "bsp on {scene}: {per_piece:.0} B a piece ({pieces} pieces), {figure} counted"
        );
        largest = largest.max(per_piece);
    }
    assert!(
        largest > 0.8 * figure as f64,
        "bsp: {largest:.0} B a piece at most, {figure} counted"
    );
}
