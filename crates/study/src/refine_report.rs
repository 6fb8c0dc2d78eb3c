//! `cwisim refine`'s table, CSV and `--sweep`: the phase rows of [`crate::refine`] as
//! text, and a threshold swept over values.

use crate::refine::{PhaseRow, RefineRun};
use cwisim_render::settings::Threshold;
use cwisim_render::Settings;
use std::fmt::Write as _;
use std::io::{self, Write};

/// A threshold `--sweep` can vary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepName {
    /// `--gouraud-threshold`.
    GouraudThreshold,
    /// `--phong-angle`.
    PhongAngle,
    /// `--aa-threshold`.
    AaThreshold,
}

impl SweepName {
    /// Its flag's name, without dashes.
    pub fn flag(self) -> &'static str {
        match self {
            SweepName::GouraudThreshold => "gouraud-threshold",
            SweepName::PhongAngle => "phong-angle",
            SweepName::AaThreshold => "aa-threshold",
        }
    }

    /// `settings` with this threshold at `value`.
    pub fn apply(self, settings: &Settings, value: Threshold) -> Settings {
        let mut s = *settings;
        match self {
            SweepName::GouraudThreshold => s.gouraud_threshold = value,
            SweepName::PhongAngle => s.phong_angle = value,
            SweepName::AaThreshold => s.aa_threshold = value,
        }
        s
    }
}

/// `--sweep NAME=V1,V2,…`: a threshold and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// Which threshold.
    pub name: SweepName,
    /// Its values, in the order given.
    pub values: Vec<Threshold>,
}

impl std::str::FromStr for Sweep {
    type Err = String;

    fn from_str(s: &str) -> Result<Sweep, String> {
        const NAMES: [SweepName; 3] = [
            SweepName::GouraudThreshold,
            SweepName::PhongAngle,
            SweepName::AaThreshold,
        ];
        let known = "gouraud-threshold, phong-angle, aa-threshold";
        let (name, values) = s
            .split_once('=')
            .ok_or_else(|| format!("expected NAME=V1,V2,… (NAME one of {known}); found `{s}`"))?;
        let name = name.trim().trim_start_matches("--");
        let name = NAMES
            .into_iter()
            .find(|n| n.flag() == name)
            .ok_or_else(|| format!("unknown threshold `{name}` to sweep; known: {known}"))?;
        let values = values
            .split(',')
            .map(|v| {
                v.parse::<Threshold>()
                    .map_err(|e| format!("{}: {e}", name.flag()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Sweep { name, values })
    }
}

/// A number of bytes, short: `1.2 MB`, `35.0 kB`, `812 B`.
fn bytes(n: u64) -> String {
    match n {
        n if n >= 1_000_000 => format!("{:.1} MB", n as f64 / 1e6),
        n if n >= 1_000 => format!("{:.1} kB", n as f64 / 1e3),
        n => format!("{n} B"),
    }
}

fn psnr(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2}")
    } else {
        "inf".into()
    }
}

/// The table's column headers.
pub const COLUMNS: [&str; 11] = [
    "phase",
    "pixels",
    "instructions",
    "regenerated",
    "busy",
    "cumulative",
    "worst line",
    "late",
    "RMS",
    "PSNR dB",
    "display list",
];

fn cells(r: &PhaseRow, line_period: u64, frame_buffer: u64) -> [String; 11] {
    [
        r.phase.to_string(),
        r.pixels.to_string(),
        r.instructions.to_string(),
        r.regenerated.to_string(),
        r.busy_cycles.to_string(),
        r.cumulative_cycles.to_string(),
        format!(
            "{} ({:.1}%)",
            r.worst_line_cycles,
            100.0 * r.worst_line_cycles as f64 / line_period.max(1) as f64
        ),
        r.late_lines.to_string(),
        format!("{:.5}", r.rms),
        psnr(r.psnr),
        format!(
            "{} ({:.2}× FB)",
            bytes(r.display_list_bytes),
            r.display_list_bytes as f64 / frame_buffer.max(1) as f64
        ),
    ]
}

fn table(out: &mut String, rows: &[PhaseRow], run: &RefineRun) {
    let body: Vec<[String; 11]> = rows
        .iter()
        .map(|r| cells(r, run.line_period, run.frame_buffer_bytes))
        .collect();
    let widths: Vec<usize> = (0..COLUMNS.len())
        .map(|c| {
            body.iter()
                .map(|r| r[c].chars().count())
                .chain([COLUMNS[c].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |out: &mut String, cells: &[&str]| {
        let mut s = String::new();
        for (c, text) in cells.iter().enumerate() {
            let pad = widths[c] - text.chars().count();
            if c == 0 {
                s.push_str(text);
                s.push_str(&" ".repeat(pad));
            } else {
                s.push_str("  ");
                s.push_str(&" ".repeat(pad));
                s.push_str(text);
            }
        }
        let _ = writeln!(out, "{}", s.trim_end());
    };
    line(out, &COLUMNS);
    for r in &body {
        let refs: Vec<&str> = r.iter().map(String::as_str).collect();
        line(out, &refs);
    }
}

/// Writes the phase table of `run` (and the naive sequence's, when measured), with a
/// heading saying what was measured.
pub fn write_table(out: &mut dyn Write, run: &RefineRun, label: Option<&str>) -> io::Result<()> {
    let mut s = String::new();
    let pixels = (run.width * run.lines) as u64;
    let aa = run.counters.get("aa_pixels");
    let _ = writeln!(
        s,
        "{}{}: {}×{}, {} polygons (visible fragments); line period {} cycles; frame buffer {} ({} byte per value); error against render --shading phong --aa box",
        run.scene,
        label.map_or_else(String::new, |l| format!(" ({l})")),
        run.width,
        run.lines,
        run.polygons,
        run.line_period,
        bytes(run.frame_buffer_bytes),
        crate::refine::FRAME_BUFFER_BYTES_PER_SAMPLE
    );
    let _ = writeln!(
        s,
        "Gouraud {} polygons; Phong {} polygons ({} of {} visible triangles within the highlight angle); anti-aliased {} of {pixels} pixels ({:.1}%), {} fragments",
        run.counters.get("gouraud_polygons").unwrap_or(0),
        run.counters.get("phong_polygons").unwrap_or(0),
        run.highlight.0,
        run.highlight.1,
        aa.unwrap_or(0),
        100.0 * aa.unwrap_or(0) as f64 / pixels.max(1) as f64,
        run.counters.get("aa_fragments").unwrap_or(0),
    );
    if let Some(points) = run.counters.get("vertices_drawn") {
        let _ = writeln!(s, "vertices: {points} distinct corners drawn as points");
    }
    if let Some(lines) = run.counters.get("edges_drawn") {
        let _ = writeln!(s, "edges: {lines} distinct edges drawn as lines");
    }
    s.push('\n');
    table(&mut s, &run.rows, run);
    if !run.naive.is_empty() {
        let _ = writeln!(
            s,
            "\nnaive: every phase's renderer in full, one after the other"
        );
        table(&mut s, &run.naive, run);
    }
    out.write_all(s.as_bytes())
}

/// The CSV of runs (each with its sweep value, if any): one line per phase, the refined
/// sequence (`sequence` = `refine`) and the naive one (`naive`).
pub fn csv(runs: &[(Option<String>, RefineRun)]) -> String {
    let mut s = String::from(
        "scene,sweep,sequence,phase,pixels,instructions,regenerated,busy_cycles,cumulative_cycles,worst_line_cycles,line_period,late_lines,rms,psnr,display_list_bytes,frame_buffer_bytes\n",
    );
    for (label, run) in runs {
        for (sequence, rows) in [("refine", &run.rows), ("naive", &run.naive)] {
            for r in rows {
                let _ = writeln!(
                    s,
                    "{},{},{sequence},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    run.scene,
                    label.as_deref().unwrap_or(""),
                    r.phase,
                    r.pixels,
                    r.instructions,
                    r.regenerated,
                    r.busy_cycles,
                    r.cumulative_cycles,
                    r.worst_line_cycles,
                    run.line_period,
                    r.late_lines,
                    r.rms,
                    psnr(r.psnr),
                    r.display_list_bytes,
                    run.frame_buffer_bytes
                );
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_parse_and_refuse() {
        let s: Sweep = "phong-angle=10,all,45".parse().unwrap();
        assert_eq!(s.name, SweepName::PhongAngle);
        assert_eq!(
            s.values,
            [
                Threshold::Above(10.0),
                Threshold::All,
                Threshold::Above(45.0)
            ]
        );
        assert_eq!(
            "--aa-threshold=none".parse::<Sweep>().unwrap().name,
            SweepName::AaThreshold
        );
        for (bad, says) in [
            ("phong-angle", "expected NAME=V1"),
            ("size=1,2", "unknown threshold `size`"),
            ("aa-threshold=0.1,x", "aa-threshold: expected `all`"),
        ] {
            let e = bad.parse::<Sweep>().unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
        let applied = SweepName::GouraudThreshold.apply(&Settings::default(), Threshold::None);
        assert_eq!(applied.gouraud_threshold, Threshold::None);
    }
}
