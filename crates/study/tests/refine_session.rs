//! An interactive session restarts the refinement at each event: the frames after a
//! restart are a fresh refinement's of the scene the event leaves (here written out as a
//! scene file of its own, the camera and light moved in its text), bit for bit, and the
//! session cuts each run short where the next event comes.

use cwisim_render::refine::WORLD_PHASES;
use cwisim_render::Settings;
use cwisim_study::refine::{run_refine, RefineSetup};
use cwisim_study::refine_session::run_session;
use cwisim_world::embedded::embedded;
use cwisim_world::events::EventScript;
use cwisim_xproc::Machine;
use std::path::Path;

fn setup<'a>(scene: &'a Path, settings: Settings) -> RefineSetup<'a> {
    RefineSetup {
        scene: Some(scene),
        changes: &[],
        settings,
        phases: WORLD_PHASES.to_vec(),
        vertex_parts: 1,
        machine: Machine::default(),
        naive: false,
        cost_maps: false,
        ids: false,
        threads: 1,
        cancel: None,
    }
}

#[test]
fn a_restart_gives_the_frames_of_a_fresh_run_of_the_new_scene() {
    let dir = std::env::temp_dir().join(format!("cwisim-session-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pot = embedded("pot").unwrap().text;
    let given = dir.join("pot.json");
    std::fs::write(&given, pot).unwrap();
    // the scene after both events, written by hand
    let camera = r#""eye": [0, 3.2, 5.0]"#;
    let light = r#""position": [4, 6, 5]"#;
    assert!(pot.contains(camera) && pot.contains(light));
    let moved = pot
        .replacen(camera, r#""eye": [1.5, 3.0, 4.6]"#, 1)
        .replacen(light, r#""position": [-3, 7, 4]"#, 1);
    let fresh = dir.join("moved.json");
    std::fs::write(&fresh, &moved).unwrap();

    let spec = cwisim_world::scene::parse_world(pot, None).unwrap().spec;
    let script = EventScript::parse(
        r#"{"unit": "frames", "end": 9, "events": [
  {"at": 1.5, "camera": {"eye": [1.5, 3.0, 4.6]}},
  {"at": 2, "light": 0, "position": [-3, 7, 4]}
]}"#,
        &spec,
    )
    .unwrap();
    let settings = Settings {
        size: Some("64x64".parse().unwrap()),
        ..Settings::default()
    };
    let (session, runs) = run_session(&setup(&given, settings), &script, 1, &|_| {}).unwrap();
    let alone = run_refine(&setup(&fresh, settings), None, None).unwrap();
    assert_eq!(runs.len(), 3);
    let last = &runs[2];
    assert_eq!(last.frames.len(), alone.frames.len());
    for (a, b) in last.frames.iter().zip(&alone.frames) {
        assert_eq!(a.data, b.data, "a frame after the restart");
    }
    assert_eq!(last.rows, alone.rows);
    // and the run before differs: the events changed the scene
    assert_ne!(runs[0].frames[0].data, last.frames[0].data);
    // the session: run 1 lasts half a frame, too short for its first frame
    let f = session.frame_cycles;
    assert_eq!(
        f,
        (64 + u64::from(Machine::default().vblank_lines)) * runs[0].line_period
    );
    assert_eq!(session.runs[1].start, 3 * f / 2);
    assert_eq!(session.runs[1].stop, 2 * f);
    assert_eq!(session.runs[1].reached(), 0);
    assert_eq!(session.runs[1].first_frame(), None);
    assert_eq!(session.runs[2].stop, 9 * f);
    assert_eq!(session.runs[2].reached(), session.runs[2].phases.len());
    assert_eq!(
        session.runs[2].phases[0].1, alone.rows[0].shown_cycles,
        "the latency to the first frame is the fresh run's"
    );
    std::fs::remove_dir_all(&dir).ok();
}
