//! Extreme scene values × every renderer: numbers that would overflow are bad input,
//! refused where they are made — never an internal error, never a panic.
//!
//! * **Read** (the CLI's path): a scene file is read and validated, so an intensity or a
//!   lighting term beyond `cwisim_scene::MAX_INTENSITY` is refused at its JSON path
//!   ([`RenderError::Scene`]).
//! * **Built** (a library user's scene, never validated): every renderer checks the
//!   intensities of a screen scene (`prepare::check_intensities`) and the lighting terms of
//!   a world scene (`WorldSpec::check_lighting`) before it draws, refusing them at the
//!   same JSON path.
//! * A scene that passes is drawn by every renderer, every value finite: only
//!   [`RenderError::Usage`] may refuse it (a negative intensity, a shading the renderer
//!   does not draw) — the bound of `docs/LIMITS.md`, "Intensities", held.
//! * Behind the limits, a value that is made anyway and is not finite is refused where it
//!   is made, as [`RenderError::Overflow`] naming the renderer, the row and the pixel or
//!   instruction (`an_overflowing_renderer_is_refused_as_bad_input_at_its_row`, with a
//!   renderer that makes such values on purpose).
//!
//! The issue's cases are named tests; `screen_scenes_of_extreme_intensities` and
//! `world_scenes_of_extreme_lighting` hold the property over random scenes.

use cwisim_isa::{Instruction, Intensity, TraceHeader, TraceWrite};
use cwisim_render::span::fit_span;
use cwisim_render::{
    emit, render, ArrayConfig, Counters, FramePlan, LoadedScene, NonFinite, RenderError, Renderer,
    Settings, Taps, REGISTRY,
};
use cwisim_scene::{Polygon, ScreenScene, Shading, MAX_INTENSITY};
use cwisim_world::scene::PerChannel;
use cwisim_world::{parse_any, AnyScene};
use cwisim_xproc::ImageSink;
use proptest::prelude::*;
use std::io;
use std::ops::Range;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The shadings every renderer is asked for (each draws some, refuses the others).
const SHADINGS: [Shading; 3] = [Shading::Flat, Shading::Gouraud, Shading::Phong];

/// Intensities at the extremes: zero, subnormal, tiny, nominal, at and beyond the limit,
/// near `f32`'s and `f64`'s largest, negative.
const EXTREMES: [f64; 16] = [
    0.0,
    -0.0,
    5e-324,
    1e-300,
    0.5,
    1.0,
    1e12,
    1.000000000001e12,
    1e15,
    3e38,
    1e300,
    1e308,
    f64::MAX,
    -1.0,
    -1e308,
    -f64::MAX,
];

/// Draws `scene` with `renderer` into an image, as `cwisim render` does; a panic is
/// reported as an `Err` of its message.
fn draw(
    renderer: &str,
    scene: &AnyScene,
    settings: &Settings,
    threads: usize,
) -> Result<Result<(), RenderError>, String> {
    let entry = REGISTRY
        .iter()
        .find(|e| e.name == renderer)
        .expect("registered");
    let run = || -> Result<(), RenderError> {
        let loaded = LoadedScene::built("extreme", scene.clone());
        let r = (entry.build)(loaded, settings)?;
        let h = r.header();
        let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 28);
        render(
            &*r,
            &ArrayConfig::default(),
            threads,
            &mut sink,
            Default::default(),
        )?;
        let image = sink.finish()?;
        assert!(
            image.data.iter().all(|v| v.is_finite()),
            "{renderer}: an image value that is not finite"
        );
        Ok(())
    };
    catch_unwind(AssertUnwindSafe(run)).map_err(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "a panic".into())
    })
}

/// Every renderer × shading draws `scene`, every value finite, or refuses it as bad
/// input: at a JSON path ([`RenderError::Scene`]; not for a scene `read`, which passed
/// validation) or for its usage ([`RenderError::Usage`]). A scene within the limits never
/// overflows: [`RenderError::Overflow`] fails the test, as an internal error does.
fn every_renderer(scene: &AnyScene, read: bool) -> Result<(), TestCaseError> {
    for entry in REGISTRY {
        for shading in SHADINGS {
            let settings = Settings {
                shading,
                ..Settings::default()
            };
            let how = if read { "read" } else { "built" };
            let what = format!("{} / {shading:?} / {how}", entry.name);
            match draw(entry.name, scene, &settings, 1) {
                Err(panic) => {
                    return Err(TestCaseError::fail(format!("{what}: panicked: {panic}")))
                }
                Ok(Ok(())) | Ok(Err(RenderError::Usage(_))) => {}
                Ok(Err(RenderError::Scene(e))) if !read && e.field.is_some() => {}
                Ok(Err(e)) => return Err(TestCaseError::fail(format!("{what}: {e:?}"))),
            }
        }
    }
    Ok(())
}

/// A value a scene may hold, at the extremes: finite, ≥ 0, within the limit.
fn extreme() -> impl Strategy<Value = f64> {
    let valid: Vec<f64> = EXTREMES
        .iter()
        .copied()
        .filter(|v| (0.0..=MAX_INTENSITY).contains(v))
        .collect();
    prop_oneof![
        2 => prop::sample::select(valid),
        1 => 0.0..=MAX_INTENSITY,
        1 => 0.0..=1.0f64,
    ]
}

/// `n` values at the extremes: in half the cases only ones a scene may hold ([`extreme`]:
/// such scenes are drawn), in the other half mostly any of [`EXTREMES`] (most such scenes
/// are refused).
fn extremes(n: usize) -> impl Strategy<Value = Vec<f64>> {
    let any = prop_oneof![
        3 => prop::sample::select(EXTREMES.to_vec()),
        1 => extreme(),
    ];
    prop_oneof![
        prop::collection::vec(extreme(), n),
        prop::collection::vec(any, n),
    ]
}

/// A small screen scene: triangles in and around a 16 × 16 image (some of them slivers),
/// one or two channels, intensities at the extremes.
fn screen_scene() -> impl Strategy<Value = ScreenScene> {
    let point = [-4.0..20.0f64, -4.0..20.0f64];
    let triangle = (prop::array::uniform3(point), prop::bool::ANY);
    (
        1u8..=2,
        prop::collection::vec(triangle, 1..=3),
        extremes(18),
    )
        .prop_map(|(channels, triangles, values)| {
            let ch = usize::from(channels);
            let mut next = values.iter().cycle();
            let polygons = triangles
                .into_iter()
                .map(|(mut v, sliver)| {
                    if sliver {
                        // the third vertex 1e-9 px off the first edge's line
                        v[2] = [v[1][0] + 1e-9, v[1][1]];
                    }
                    let intensity = (0..3)
                        .map(|_| (0..ch).map(|_| *next.next().expect("cycles")).collect())
                        .collect::<Vec<Vec<f64>>>();
                    Polygon::new(v.to_vec(), intensity)
                })
                .collect();
            ScreenScene {
                width: 16,
                height: 16,
                channels,
                polygons,
            }
        })
}

/// A world scene of a quad and a one-patch Bézier mesh (what `nishita` draws), 12 × 12,
/// its lighting terms given.
fn world_text(ambient: f64, light: f64, k_a: f64, k_d: f64, k_s: f64, n: f64) -> String {
    let num = |v: f64| serde_json::to_string(&v).expect("finite");
    let mut control = Vec::new();
    for r in 0..4 {
        for c in 0..4 {
            let z = if (r == 1 || r == 2) && (c == 1 || c == 2) {
                0.3
            } else {
                0.0
            };
            control.push(format!(
                "[{}, {}, {z}]",
                c as f64 / 3.0 - 0.5,
                r as f64 / 3.0 - 0.5
            ));
        }
    }
    let material = format!(
        r#"{{ "k_a": {}, "k_d": {}, "k_s": {}, "n": {} }}"#,
        num(k_a),
        num(k_d),
        num(k_s),
        num(n)
    );
    format!(
        r#"{{
  "kind": "world", "width": 12, "height": 12, "channels": 1,
  "camera": {{ "eye": [0.2, 0.1, 3], "target": [0, 0, 0], "fov_y": 40 }},
  "ambient": {},
  "lights": [ {{ "position": [0, 0, 4], "intensity": {} }}, {{ "position": [1, 0.5, 4], "intensity": {} }} ],
  "meshes": [
    {{ "material": {material},
      "bezier": {{ "vertices": [{}], "patches": [[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]], "tessellate": 2 }} }},
    {{ "material": {material},
      "vertices": [[-1, -1, -0.5], [1, -1, -0.5], [1, 1, -0.5], [-1, 1, -0.5]], "faces": [[0, 1, 2, 3]] }}
  ]
}}"#,
        num(ambient),
        num(light),
        num(light),
        control.join(", ")
    )
}

/// The world scene of [`world_text`] with nominal terms, then given `terms` in code
/// (never validated: what a library user may build).
fn built_world(terms: [f64; 6]) -> AnyScene {
    let AnyScene::World(mut w) =
        parse_any(&world_text(0.2, 0.8, 0.4, 0.6, 0.3, 8.0), None).expect("a valid scene")
    else {
        panic!("a world scene")
    };
    let [ambient, light, k_a, k_d, k_s, n] = terms;
    w.spec.ambient = PerChannel::All(ambient);
    for l in &mut w.spec.lights {
        l.intensity = PerChannel::All(light);
    }
    for m in &mut w.spec.meshes {
        m.material.k_a = PerChannel::All(k_a);
        m.material.k_d = PerChannel::All(k_d);
        m.material.k_s = PerChannel::All(k_s);
        m.material.n = n;
    }
    AnyScene::World(w)
}

proptest! {
    #![proptest_config(ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::with_cases(64)
    })]

    /// Screen scenes of extreme intensities: read, refused at the path or drawn by every
    /// renderer; built in code (not validated), refused at the same path by every renderer
    /// (a valid one is the scene read, drawn once).
    #[test]
    fn screen_scenes_of_extreme_intensities(scene in screen_scene()) {
        let beyond = scene
            .polygons
            .iter()
            .flat_map(|p| p.intensity.iter().flatten())
            .any(|v| v.abs() > MAX_INTENSITY);
        match scene.validate() {
            Err(e) => {
                // only a value beyond the limit may be refused (triangles are simple)
                prop_assert!(beyond, "{e}");
                prop_assert!(e.to_string().contains(".intensity["), "{e}");
            }
            Ok(()) => return every_renderer(&AnyScene::Screen(scene), true),
        }
        every_renderer(&AnyScene::Screen(scene), false)?;
    }

    /// World scenes of extreme lighting terms: read, refused at the path or drawn by every
    /// renderer; built in code (not validated), refused at the same path by every renderer
    /// (a valid one is the scene read, drawn once).
    #[test]
    fn world_scenes_of_extreme_lighting(
        terms in extremes(5),
        n in prop::sample::select(vec![0.0, 1.0, 8.0, 1e300, f64::MAX]),
    ) {
        let [ambient, light, k_a, k_d, k_s] = [terms[0], terms[1], terms[2], terms[3], terms[4]];
        let bad = terms.iter().any(|v| *v < 0.0 || *v > MAX_INTENSITY);
        match parse_any(&world_text(ambient, light, k_a, k_d, k_s, n), None) {
            Err(e) => {
                prop_assert!(bad, "{e}");
                let m = e.to_string();
                prop_assert!(m.contains("is beyond 1e12") || m.contains("expected a value ≥ 0"), "{m}");
            }
            Ok(scene) => {
                prop_assert!(!bad);
                return every_renderer(&scene, true);
            }
        }
        every_renderer(&built_world([ambient, light, k_a, k_d, k_s, n]), false)?;
    }
}

/// The issue's screen polygon: intensity 1e308, `--shading flat` — exit 1 "internal
/// error … Eval1 1 1 -inf" with vanrij, sbuffer, bsp and nishita (which draws a screen
/// scene as vanrij does). Read from its file it is refused at its JSON path; built in
/// code, every one of them refuses it at the same path before drawing anything.
#[test]
fn the_issue_s_polygon_of_intensity_1e308_flat_is_refused_at_its_path() {
    let text = r#"{"kind": "screen", "width": 16, "height": 16, "channels": 1, "polygons": [
  {"vertices": [[1, 1], [15, 1], [15, 15], [1, 15]], "intensity": [[1e308], [0], [0], [0]]}]}"#;
    let limit = "polygons[0].intensity[0][0]: intensity 1e308 is beyond ±1e12, the limit that keeps the renderers' arithmetic finite (intensities are nominally 0 to 1)";
    let dir = std::env::temp_dir().join(format!("cwisim-overflow-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("F.json");
    std::fs::write(&path, text).unwrap();
    let settings = Settings {
        shading: Shading::Flat,
        ..Settings::default()
    };
    let source = cwisim_render::Source::resolve(Some(&path)).unwrap();
    let e = source.load_for(&settings).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(matches!(e, RenderError::Scene(_)), "{e:?}");
    assert_eq!(e.to_string(), format!("{}:2:69: {limit}", path.display()));

    let AnyScene::Screen(mut scene) = parse_any(&text.replace("1e308", "0.5"), None).unwrap()
    else {
        panic!("a screen scene")
    };
    scene.polygons[0].intensity[0][0] = 1e308;
    let scene = AnyScene::Screen(scene);
    for renderer in ["vanrij", "sbuffer", "bsp", "nishita"] {
        let e = draw(renderer, &scene, &settings, 1)
            .expect("no panic")
            .expect_err("refused");
        assert!(matches!(e, RenderError::Scene(_)), "{renderer}: {e:?}");
        assert_eq!(e.to_string(), limit, "{renderer}");
    }
    // every other renderer too, at every shading
    every_renderer(&scene, false).unwrap();
}

/// The issue's world scenes: an ambient term or a light intensity near `f64::MAX` gave
/// NaN (exit 1) with some renderers and an image with others. Read, they are refused at
/// their JSON path; built in code, every renderer refuses them at the same path.
#[test]
fn the_issue_s_world_lighting_near_f64_max_is_refused_at_its_path() {
    let beyond = "is beyond 1e12, the limit of every intensity and lighting term (it keeps the lighting and the renderers' arithmetic finite; terms are nominally 0 to 1)";
    let e = parse_any(&world_text(f64::MAX, 0.8, 0.4, 0.6, 0.3, 8.0), None).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("4:14: ambient: 1.7976931348623157e308 {beyond}")
    );
    let e = parse_any(&world_text(0.2, 1.7e308, 0.4, 0.6, 0.3, 8.0), None).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("5:53: lights[0].intensity: 1.7e308 {beyond}")
    );
    for (terms, shown) in [
        (
            [f64::MAX, 0.8, 0.4, 0.6, 0.3, 8.0],
            format!("ambient: 1.7976931348623157e308 {beyond}"),
        ),
        (
            [0.2, 1.7e308, 0.4, 0.6, 0.3, 8.0],
            format!("lights[0].intensity: 1.7e308 {beyond}"),
        ),
    ] {
        let scene = built_world(terms);
        for entry in REGISTRY {
            for shading in SHADINGS {
                let settings = Settings {
                    shading,
                    ..Settings::default()
                };
                match draw(entry.name, &scene, &settings, 1).expect("no panic") {
                    Err(RenderError::Scene(e)) => assert_eq!(e.to_string(), shown),
                    // a shading the renderer does not draw, refused first
                    Err(RenderError::Usage(_)) => {}
                    other => panic!("{} {shading:?}: {other:?}", entry.name),
                }
            }
        }
    }
}

/// A renderer that makes values that are not finite on purpose, behind the limits: an
/// `Eval2` whose `dI` is infinite in row `row` (`shade: false`), or a run whose per-pixel
/// shade is infinite there, sent through the span fitter (`shade: true`).
struct Overflowing {
    row: u32,
    shade: bool,
    frames: u32,
}

impl Renderer for Overflowing {
    fn name(&self) -> &'static str {
        "overflowing"
    }

    fn header(&self) -> TraceHeader {
        TraceHeader::new(8, 4, 1).unwrap()
    }

    fn frames(&self) -> u32 {
        self.frames
    }

    fn frame<'a>(
        &'a self,
        index: u32,
        _previous: Option<&'a cwisim_xproc::Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        Ok(Box::new(OverflowingFrame {
            r: self,
            last: index + 1 == self.frames,
        }))
    }

    fn settings_phrase(&self) -> String {
        "values that overflow".into()
    }
}

struct OverflowingFrame<'a> {
    r: &'a Overflowing,
    last: bool,
}

impl FramePlan for OverflowingFrame<'_> {
    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        for row in rows {
            let bad = self.last && row == self.r.row;
            match (bad, self.r.shade) {
                (true, true) => {
                    fit_span(2, &[0.5, 0.25, f64::INFINITY, 0.5], 1, 1e-3, sink)?;
                }
                (true, false) => sink.write(&Instruction::eval2(
                    1,
                    6,
                    Intensity::new(&[0.5]),
                    Intensity::new(&[f64::INFINITY]),
                ))?,
                _ => sink.write(&Instruction::eval1(0, 8, Intensity::new(&[0.25])))?,
            }
            sink.write(&Instruction::refresh())?;
        }
        Ok(Counters::default())
    }
}

/// Behind the limits: a value made anyway that is not finite is refused as bad input,
/// naming the renderer, the frame (of several), the row and the pixel or instruction —
/// on one thread or several, into the array or into a trace, with or without a tap — and
/// no tap or trace gets it.
#[test]
fn an_overflowing_renderer_is_refused_as_bad_input_at_its_row() {
    let tail = ": a value computed from the scene overflows f64 (its intensities or lighting terms are too large for this renderer's arithmetic; docs/LIMITS.md, \"Intensities\")";
    for (r, shown) in [
        (
            Overflowing { row: 2, shade: false, frames: 1 },
            "overflowing: row 2: emitted instruction: `Eval2 1 6 0.5 inf`: the first forward difference dI is inf",
        ),
        (
            Overflowing { row: 3, shade: true, frames: 1 },
            "overflowing: row 3: per-pixel shading: pixel 4, channel 0: the shade is inf",
        ),
        (
            Overflowing { row: 1, shade: false, frames: 2 },
            "overflowing: frame 1, row 1: emitted instruction: `Eval2 1 6 0.5 inf`: the first forward difference dI is inf",
        ),
    ] {
        for threads in [1, 2] {
            for tapped in [false, true] {
                let mut seen: Vec<Instruction> = Vec::new();
                let mut sink = ImageSink::new(8, 1, 1 << 20);
                let taps = Taps {
                    also: tapped.then_some(&mut seen as &mut dyn TraceWrite),
                    progress: None,
                    cancel: None,
                };
                let e = render(&r, &ArrayConfig::default(), threads, &mut sink, taps)
                    .expect_err("refused");
                assert!(matches!(e, RenderError::Overflow { .. }), "{e:?}");
                assert!(!e.is_internal());
                assert_eq!(e.to_string(), format!("{shown}{tail}"), "{threads} thread(s)");
                assert!(seen.iter().all(|i| i.values().iter().all(|v| v.as_slice().iter().all(|f| f.is_finite()))));
            }
        }
        if r.frames == 1 {
            let mut trace: Vec<Instruction> = Vec::new();
            let e = emit(&r, &mut trace).expect_err("refused");
            assert_eq!(e.to_string(), format!("{shown}{tail}"));
            assert!(trace.iter().all(|i| i.values().iter().all(|v| v.as_slice().iter().all(|f| f.is_finite()))));
            // the rows before it were written
            assert_eq!(
                trace.iter().filter(|i| *i == &Instruction::refresh()).count() as u32,
                r.row
            );
        }
    }
    // a renderer that makes a frame's values before emitting them (woo-chall, sbuffer,
    // bsp) gives the row where it knows it
    let made = NonFinite::at_row(
        NonFinite {
            row: None,
            stage: "per-pixel shading",
            detail: "pixel 4, channel 0: the shade is NaN".into(),
        }
        .into_io(),
        7,
    );
    let e = RenderError::of_renderer("woo-chall", made);
    assert_eq!(
        e.to_string(),
        format!("woo-chall: row 7: per-pixel shading: pixel 4, channel 0: the shade is NaN{tail}")
    );
    // anything else is the renderer's fault, as before
    let e = RenderError::of_renderer("woo-chall", io::Error::other("a bug"));
    assert!(e.is_internal(), "{e:?}");
}
