//! Helpers shared by the workspace-level integration tests in `tests/`: locating the
//! checked-in examples, replaying them, rendering a replay as reviewable text, and the
//! bless step that regenerates expected files.
//!
//! Expected files are never edited by hand: run
//! `CWISIM_BLESS=1 cargo test -p cwisim-tests` and review the diff.

use cwisim_isa::{FileReader, TraceHeader, TraceRead};
use cwisim_xproc::{replay, Image, ImageSink, Machine, RunStats, Timing};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The workspace root.
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The `.cwt` examples in `traces/`, sorted by name.
pub fn example_traces() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(workspace_root().join("traces"))
        .expect("traces/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "cwt"))
        .collect();
    v.sort();
    v
}

/// The machine an example runs on: `NAME.machine.json` beside it, or the default.
pub fn machine_for(trace: &Path) -> Machine {
    let m = trace.with_extension("machine.json");
    if m.exists() {
        Machine::from_file(&m).expect("example machine file is valid")
    } else {
        Machine::default()
    }
}

/// Replays a trace file (any encoding) on `machine`.
pub fn replay_file(
    path: &Path,
    machine: &Machine,
    timing: Timing,
) -> (TraceHeader, Image, RunStats) {
    let mut reader = FileReader::open(path).unwrap_or_else(|e| panic!("{e}"));
    let header = *reader.header();
    let mut sink = ImageSink::new(header.width as usize, header.channel_count(), 1 << 30);
    let stats = replay::<f64>(&mut reader, machine, timing, &mut sink, &mut |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    (header, sink.finish().expect("small image"), stats)
}

/// A replay as text: per scanline its timing and its values (channels joined by commas,
/// in the trace format's exact notation), then the totals.
pub fn render_replay(header: &TraceHeader, image: &Image, stats: &RunStats) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "trace: width {} lines {} channels {}; line period {} cycles, traversal {} cycles",
        header.width, header.lines, header.channels, stats.line_period, stats.traversal_cycles
    );
    let row = image.width * image.channels;
    for (l, values) in stats.lines.iter().zip(image.data.chunks(row)) {
        let ops: Vec<String> = cwisim_isa::Opcode::ALL
            .iter()
            .filter(|op| l.opcodes.get(**op) > 0)
            .map(|op| format!("{op}×{}", l.opcodes.get(*op)))
            .collect();
        let _ = writeln!(
            s,
            "line {} (frame {} row {}): {}; updates {} dropped {} suppressed {}; busy {} stall {}; first issue {} ready {} deadline {} slack {}",
            l.line,
            l.frame,
            l.row,
            if ops.is_empty() { "-".to_string() } else { ops.join(" ") },
            l.processor_updates,
            l.dropped_negative,
            l.suppressed,
            l.busy_cycles,
            l.stall_cycles,
            l.first_issue,
            l.ready,
            l.deadline,
            l.slack
        );
        let px: Vec<String> = values
            .chunks(image.channels)
            .map(|p| {
                p.iter()
                    .map(|v| format!("{v:?}"))
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect();
        let _ = writeln!(s, "  {}", px.join(" "));
    }
    let t = &stats.totals;
    let _ = writeln!(
        s,
        "totals: {} instructions, {} lines ({} frames + {} lines), {} late, worst slack {:?} at line {:?}, {} cycles, {} unrefreshed",
        t.instructions, t.lines, t.frames, t.partial_frame_lines, t.late_lines, t.worst_slack, t.worst_line, t.cycles, t.unrefreshed_instructions
    );
    s
}

/// Compares `actual` with the file at `expected`, or rewrites the file when the
/// environment variable `CWISIM_BLESS` is `1`.
pub fn check_or_bless(expected: &Path, actual: &str) {
    if std::env::var("CWISIM_BLESS").as_deref() == Ok("1") {
        std::fs::write(expected, actual).expect("write expected file");
        return;
    }
    let want = std::fs::read_to_string(expected).unwrap_or_else(|_| {
        panic!(
            "{} is missing; run `CWISIM_BLESS=1 cargo test -p cwisim-tests` and review it",
            expected.display()
        )
    });
    if want != actual {
        let diff: Vec<String> = want
            .lines()
            .zip(actual.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .take(5)
            .map(|(i, (a, b))| format!("line {}:\n  expected: {a}\n  actual:   {b}", i + 1))
            .collect();
        panic!(
            "{} differs from the replay ({} vs {} lines):\n{}\nIf the change is intended, bless it: CWISIM_BLESS=1 cargo test -p cwisim-tests",
            expected.display(),
            want.lines().count(),
            actual.lines().count(),
            diff.join("\n")
        );
    }
}
