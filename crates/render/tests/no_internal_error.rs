//! No embedded scene, at any size, with any shading, filter or shadows, makes any renderer
//! fail with an internal error (exit 4): it draws, or refuses a setting it does not take
//! as a usage error. Issue 53's case — `render textures4 --size 160x120 --shadows on`,
//! whose per-pixel targets went −2e-15 where shadows cut a textured surface into slivers
//! (a pixel's coverage, a difference of two edges' fractions, rounded below 0) — is named.

use cwisim_render::{render, ArrayConfig, RenderError, Settings, Size, Source, REGISTRY};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::embedded::EMBEDDED;
use cwisim_xproc::ImageSink;
use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Draws embedded `scene` with `renderer` into an image as `cwisim render` does: `Ok` if
/// it drew or refused the settings as bad usage; the internal error or panic otherwise.
fn draws_or_refuses(scene: &str, renderer: &str, settings: &Settings) -> Result<(), String> {
    let entry = REGISTRY
        .iter()
        .find(|e| e.name == renderer)
        .expect("registered");
    let run = || -> Result<(), RenderError> {
        let loaded = Source::resolve(Some(scene.as_ref()))?.load_for(settings)?;
        let r = (entry.build)(loaded, settings)?;
        let h = r.header();
        let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 28);
        render(
            &*r,
            &ArrayConfig::default(),
            1,
            &mut sink,
            Default::default(),
        )?;
        sink.finish()?;
        Ok(())
    };
    let what = format!("{renderer} on {scene} ({settings:?})");
    match catch_unwind(AssertUnwindSafe(run)) {
        Err(_) => Err(format!("{what}: panicked")),
        Ok(Err(e)) if e.is_internal() => Err(format!("{what}: internal error: {e}")),
        Ok(_) => Ok(()),
    }
}

fn settings(w: u32, h: u32, shading: Shading, aa: Antialias, shadows: Option<bool>) -> Settings {
    Settings {
        size: Some(Size {
            width: w,
            height: h,
        }),
        shading,
        aa,
        shadows,
        ..Settings::default()
    }
}

#[test]
fn textures4_at_160x120_with_shadows_draws() {
    for shading in [Shading::Flat, Shading::Gouraud, Shading::Phong] {
        for aa in [Antialias::Box, Antialias::BoxCentre] {
            let s = settings(160, 120, shading, aa, Some(true));
            draws_or_refuses("textures4", "vanrij", &s).unwrap();
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn no_scene_size_or_setting_is_an_internal_error(
        scene in 0..EMBEDDED.len(),
        renderer in 0..REGISTRY.len(),
        w in 8u32..=160,
        h in 8u32..=120,
        shading in prop::sample::select(vec![Shading::Flat, Shading::Gouraud, Shading::Phong]),
        aa in prop::sample::select(vec![Antialias::Box, Antialias::BoxCentre]),
        shadows in prop::sample::select(vec![None, Some(true), Some(false)]),
    ) {
        let s = settings(w, h, shading, aa, shadows);
        let r = draws_or_refuses(EMBEDDED[scene].name, REGISTRY[renderer].name, &s);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }
}
