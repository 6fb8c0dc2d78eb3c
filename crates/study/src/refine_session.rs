//! `cwisim refine --events`: Bergman et al.'s interaction, simulated. "We start a new image
//! whenever new user input is received": a script of user events
//! ([`cwisim_world::events`]) moves the camera or a light at given times, and at each event
//! the refinement restarts from its first phase on the scene the event leaves. Each run
//! (the scene as given, then one per event) is a refinement of its own scene
//! ([`crate::refine::run_refine`]); the session lays them end to end on the display's
//! clock: run `k` starts at its event and is cut short by the next event (or the
//! session's end). For each run it reports when each phase's frame was shown, counted
//! from the event (the latency the user sees), and which phase the run reached before it
//! was interrupted.

use crate::error::StudyError;
use crate::plot::{draw_on, err, rgb, Align, Label, Rgb};
use crate::refine::{run_refines, RefineRun, RefineSetup};
use crate::refine_plot::PALETTE;
use cwisim_world::events::{EventScript, Unit};
use plotters::prelude::*;
use std::io::{self, Write};

/// One run of a session: the refinement restarted at an event.
#[derive(Clone, Debug, PartialEq)]
pub struct SessionRun {
    /// The event that started it (`None`: the session's start, the scene as given).
    pub event: Option<String>,
    /// The cycle it starts at.
    pub start: u64,
    /// The cycle it is cut short at: the next event, or the session's end.
    pub stop: u64,
    /// Each phase's name, and the cycles from `start` by which the display has shown its
    /// frame.
    pub phases: Vec<(&'static str, u64)>,
}

impl SessionRun {
    /// How many of its phases' frames were shown before it was cut short.
    pub fn reached(&self) -> usize {
        self.phases
            .iter()
            .take_while(|(_, c)| self.start.saturating_add(*c) <= self.stop)
            .count()
    }

    /// The latency to its first complete frame, when it was shown before the run was cut
    /// short.
    pub fn first_frame(&self) -> Option<u64> {
        (self.reached() > 0).then(|| self.phases[0].1)
    }
}

/// A session: its runs end to end.
#[derive(Clone, Debug, PartialEq)]
pub struct Session {
    /// The scene's name.
    pub scene: String,
    /// One display frame, cycles: its scanlines and its vertical blanking lines, times
    /// the line period.
    pub frame_cycles: u64,
    /// The session's end, cycles.
    pub end: u64,
    /// The runs, in time order.
    pub runs: Vec<SessionRun>,
}

/// A time of the script in cycles (`frames` of `frame_cycles` each, or cycles).
fn cycles(t: f64, unit: Unit, frame_cycles: u64) -> u64 {
    let c = match unit {
        Unit::Cycles => t,
        Unit::Frames => t * frame_cycles as f64,
    };
    c.round().clamp(0.0, u64::MAX as f64) as u64
}

/// Runs the session of `script` on `setup`'s scene (each run with `setup`'s settings,
/// phases and machine; the changes of the events so far made to its scene), the runs
/// measured on `threads` threads, `progress` told the scanlines done.
pub fn run_session(
    setup: &RefineSetup<'_>,
    script: &EventScript,
    threads: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(Session, Vec<RefineRun>), StudyError> {
    let changes: Vec<_> = script.events.iter().map(|e| e.change.clone()).collect();
    let setups: Vec<RefineSetup> = (0..=changes.len())
        .map(|k| RefineSetup {
            changes: &changes[..k],
            naive: false,
            cost_maps: false,
            ids: false,
            ..setup.clone()
        })
        .collect();
    // the first run, then the others' frames (every run keeps its own) against the
    // memory budget before they are drawn
    let mut done = run_refines(&setups[..1], threads, None, progress, |_, _| {})?;
    let held: u64 = done[0].frames.iter().map(|f| f.data.len() as u64 * 8).sum();
    cwisim_scene::budget::Budget::current()
        .check_memory(
            &format!(
                "a session of {} refinements, each keeping its frames",
                setups.len()
            ),
            held.saturating_mul(setups.len() as u64),
        )
        .map_err(|e| StudyError::Usage(e.to_string()))?;
    let base = (done[0].frames.len() * done[0].lines) as u64;
    let rest = |lines: u64| progress(base + lines);
    done.extend(run_refines(&setups[1..], threads, None, &rest, |_, _| {})?);
    let first = &done[0];
    let frame_cycles =
        (first.lines as u64 + u64::from(setup.machine.vblank_lines)) * first.line_period;
    let end = cycles(script.end, script.unit, frame_cycles);
    let starts: Vec<u64> = std::iter::once(0)
        .chain(
            script
                .events
                .iter()
                .map(|e| cycles(e.at, script.unit, frame_cycles)),
        )
        .collect();
    let runs = done
        .iter()
        .enumerate()
        .map(|(k, run)| SessionRun {
            event: k
                .checked_sub(1)
                .map(|e| format!("events[{e}]: {}", script.events[e].change.describe())),
            start: starts[k],
            stop: starts.get(k + 1).copied().unwrap_or(end),
            phases: run.rows.iter().map(|r| (r.phase, r.shown_cycles)).collect(),
        })
        .collect();
    Ok((
        Session {
            scene: first.scene.clone(),
            frame_cycles,
            end,
            runs,
        },
        done,
    ))
}

/// Cycles as display frames, two decimals.
fn frames(c: u64, frame_cycles: u64) -> String {
    format!("{:.2}", c as f64 / frame_cycles.max(1) as f64)
}

/// The session's table: per run, its start, what started it, the latency to each
/// phase's frame (cycles, and display frames), and the phase it reached before the next
/// event.
pub fn write_session(out: &mut dyn Write, s: &Session) -> io::Result<()> {
    writeln!(
        out,
        "session of {}: {} run(s) over {} cycles ({} display frames of {} cycles); latency from each event to each phase's frame shown",
        s.scene,
        s.runs.len(),
        s.end,
        frames(s.end, s.frame_cycles),
        s.frame_cycles
    )?;
    for (k, r) in s.runs.iter().enumerate() {
        writeln!(out)?;
        writeln!(
            out,
            "run {k} at cycle {} (frame {}): {}",
            r.start,
            frames(r.start, s.frame_cycles),
            r.event.as_deref().unwrap_or("the scene as given")
        )?;
        writeln!(
            out,
            "  {:<10} {:>14} {:>8}  shown",
            "phase", "latency", "frames"
        )?;
        for (i, (name, c)) in r.phases.iter().enumerate() {
            let shown = if i < r.reached() {
                "yes"
            } else {
                "no: interrupted"
            };
            writeln!(
                out,
                "  {name:<10} {c:>14} {:>8}  {shown}",
                frames(*c, s.frame_cycles)
            )?;
        }
        let reached = r.reached();
        writeln!(
            out,
            "  reached: {} ({} of {} phases) before {} at cycle {}",
            if reached == 0 {
                "no frame"
            } else {
                r.phases[reached - 1].0
            },
            reached,
            r.phases.len(),
            if k + 1 < s.runs.len() {
                "the next event"
            } else {
                "the session's end"
            },
            r.stop
        )?;
    }
    Ok(())
}

/// The session's timeline as a chart: one bar per run from its event to the next, each
/// phase's frame a segment ending where the display has shown it (hatched grey: cut short
/// by the next event), the events as vertical lines.
pub fn render_session_plot(s: &Session) -> Result<Rgb, String> {
    let rows = s.runs.len().max(1) as i32;
    let (w, h) = (1100u32, (150 + 46 * rows + 90) as u32);
    let (left, right) = (90i32, w as i32 - 40);
    let (top, bottom) = (110i32, h as i32 - 70);
    let end = s.end.max(1) as f64;
    let x = |c: u64| left + ((right - left) as f64 * (c as f64 / end).min(1.0)).round() as i32;
    let mut img = Rgb::white(w, h);
    // the phases' names, in their first run's order
    let mut names: Vec<&str> = Vec::new();
    for r in &s.runs {
        for (n, _) in &r.phases {
            if !names.contains(n) {
                names.push(n);
            }
        }
    }
    let color = |n: &str| PALETTE[names.iter().position(|m| *m == n).unwrap_or(0) % PALETTE.len()];
    draw_on(&mut img, |root, labels| {
        labels.push(Label::new(
            format!(
                "{}: an interactive session, {} run(s), each restarted at an event",
                s.scene,
                s.runs.len()
            ),
            (16, 12),
            22.0,
        ));
        labels.push(Label::new(
            "each phase's frame ends where the display has shown it; grey: cut short by the next event",
            (16, 44),
            14.0,
        ));
        // the legend
        let mut lx = 16;
        for n in &names {
            root.draw(&Rectangle::new(
                [(lx, 72), (lx + 14, 86)],
                rgb(color(n)).filled(),
            ))
            .map_err(err)?;
            labels.push(Label::new(n.to_string(), (lx + 20, 71), 14.0));
            lx += 30 + (n.len() as i32) * 9;
        }
        let row_h = (bottom - top) / rows;
        for (k, r) in s.runs.iter().enumerate() {
            let y0 = top + k as i32 * row_h + 6;
            let y1 = y0 + row_h - 12;
            labels.push(
                Label::new(format!("run {k}"), (left - 8, (y0 + y1) / 2), 14.0)
                    .align(Align::End, Align::Center),
            );
            let mut from = r.start;
            for (n, c) in &r.phases {
                let to = r.start.saturating_add(*c);
                let shown = to <= r.stop;
                let fill = if shown { color(n) } else { [200, 200, 200] };
                let (a, b) = (x(from.min(r.stop)), x(to.min(r.stop)));
                if b > a {
                    root.draw(&Rectangle::new([(a, y0), (b, y1)], rgb(fill).filled()))
                        .map_err(err)?;
                    root.draw(&Rectangle::new([(a, y0), (b, y1)], rgb([255, 255, 255])))
                        .map_err(err)?;
                }
                if !shown {
                    break;
                }
                from = to;
            }
        }
        // the events, and the axis in display frames
        for r in s.runs.iter().skip(1) {
            let ex = x(r.start);
            root.draw(&PathElement::new(
                vec![(ex, top - 4), (ex, bottom)],
                rgb([214, 39, 40]).stroke_width(2),
            ))
            .map_err(err)?;
        }
        root.draw(&PathElement::new(
            vec![(left, bottom), (right, bottom)],
            rgb([0, 0, 0]),
        ))
        .map_err(err)?;
        let total = s.end as f64 / s.frame_cycles.max(1) as f64;
        let step = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0]
            .into_iter()
            .find(|&st| total / st <= 12.0)
            .unwrap_or(1000.0);
        let mut t = 0.0;
        while t <= total + 1e-9 {
            let c = (t * s.frame_cycles as f64) as u64;
            let tx = x(c);
            root.draw(&PathElement::new(
                vec![(tx, bottom), (tx, bottom + 5)],
                rgb([0, 0, 0]),
            ))
            .map_err(err)?;
            labels.push(
                Label::new(format!("{t}"), (tx, bottom + 8), 13.0)
                    .align(Align::Center, Align::Start),
            );
            t += step;
        }
        labels.push(
            Label::new(
                format!(
                    "display frames of {} cycles (red: an event, the refinement restarted)",
                    s.frame_cycles
                ),
                ((left + right) / 2, bottom + 30),
                14.0,
            )
            .align(Align::Center, Align::Start),
        );
        Ok(())
    })?;
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(start: u64, stop: u64, shown: &[u64]) -> SessionRun {
        SessionRun {
            event: None,
            start,
            stop,
            phases: ["flat", "gouraud", "phong", "aa"]
                .into_iter()
                .zip(shown.iter().copied())
                .collect(),
        }
    }

    #[test]
    fn a_run_reaches_the_phases_shown_before_it_is_cut_short() {
        let r = run(100, 400, &[100, 200, 300, 400]);
        assert_eq!(r.reached(), 3);
        assert_eq!(r.first_frame(), Some(100));
        assert_eq!(run(100, 150, &[100, 200]).reached(), 0);
        assert_eq!(run(100, 150, &[100, 200]).first_frame(), None);
        assert_eq!(run(0, 200, &[100, 200]).reached(), 2);
    }

    #[test]
    fn script_times_become_cycles() {
        assert_eq!(cycles(2.5, Unit::Frames, 1000), 2500);
        assert_eq!(cycles(1234.4, Unit::Cycles, 1000), 1234);
    }
}
