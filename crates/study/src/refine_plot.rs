//! `cwisim refine --plot`: above, the RMS error against the full-quality image over the
//! cumulative bus-busy cycles, one series per refinement run (per `--sweep` value) and
//! one for the naive sequence (every phase's renderer in full, the paper's figure 1);
//! below, each frame's bus-busy cycles per scanline against the line period. Both
//! vertical axes and the cycles axis are logarithmic; errors below [`ERROR_FLOOR`] (an
//! image equal to the full-quality one) sit on the floor.

use crate::plot::{
    decade_grid, decades, draw_on, err, log_log_panel, nice_step, panel_area, rgb, Align, Label,
    LogAxis, Rgb, OVERRUN,
};
use crate::refine::{PhaseRow, RefineRun};
use plotters::prelude::*;

/// The smallest error drawn.
pub const ERROR_FLOOR: f64 = 1e-6;

/// Width and height of the chart, pixels.
pub const REFINE_PLOT_SIZE: (u32, u32) = (1100, 820);

/// The series' colours (and `refine --events`'s phases').
pub(crate) const PALETTE: [[u8; 3]; 7] = [
    [31, 119, 180],
    [44, 160, 44],
    [148, 103, 189],
    [255, 127, 14],
    [140, 86, 75],
    [227, 119, 194],
    [23, 190, 207],
];
const NAIVE: [u8; 3] = [127, 127, 127];

/// Draws the chart of `runs` (each with its label: the sweep value, or none).
pub fn render_refine_plot(runs: &[(Option<String>, RefineRun)]) -> Result<Rgb, String> {
    let Some((_, first)) = runs.first() else {
        return Err("no refinement to plot".into());
    };
    let mut series: Vec<(String, [u8; 3], &[PhaseRow])> = runs
        .iter()
        .enumerate()
        .map(|(k, (label, run))| {
            let name = match label {
                Some(l) => format!("refine, {l}"),
                None => "refine".into(),
            };
            (name, PALETTE[k % PALETTE.len()], run.rows.as_slice())
        })
        .collect();
    if !first.naive.is_empty() {
        series.push((
            "naive: every phase in full".into(),
            NAIVE,
            first.naive.as_slice(),
        ));
    }
    let points = || series.iter().flat_map(|(_, _, rows)| rows.iter());
    let y_of = |r: &PhaseRow| r.rms.max(ERROR_FLOOR);
    let (cmin, cmax) = points().fold((f64::INFINITY, 0.0f64), |(a, b), r| {
        let c = r.cumulative_cycles.max(1) as f64;
        (a.min(c), b.max(c))
    });
    let (emin, emax) = points().fold((f64::INFINITY, 0.0f64), |(a, b), r| {
        (a.min(y_of(r)), b.max(y_of(r)))
    });
    let (x0, x1) = decades(cmin, cmax);
    let (y0, y1) = decades(emin, emax);
    let busy_max = first
        .busy_per_line
        .iter()
        .flatten()
        .copied()
        .max()
        .unwrap_or(1)
        .max(first.line_period)
        .max(1) as f64;
    let busy_min = first
        .busy_per_line
        .iter()
        .flatten()
        .copied()
        .filter(|&b| b > 0)
        .min()
        .unwrap_or(1) as f64;
    let (b0, b1) = decades(busy_min, busy_max);

    let (w, h) = REFINE_PLOT_SIZE;
    let (left, right) = (90i32, w as i32 - 290);
    let (top_upper, top_lower) = (80i32, 430i32);
    let (bot_upper, bot_lower) = (500i32, h as i32 - 60);
    let mut img = Rgb::white(w, h);
    draw_on(&mut img, |root, labels| {
        labels.push(Label::new(
            format!(
                "{}: adaptive refinement, {}×{}",
                first.scene, first.width, first.lines
            ),
            (16, 12),
            22.0,
        ));
        labels.push(Label::new(
            "RMS error against render --shading phong --aa box, over the bus-busy cycles of every frame so far (errors below 1e-6, equal images, on the floor)",
            (16, 44),
            14.0,
        ));
        // the upper panel
        let area = panel_area(root, (left, right), (top_upper, top_lower));
        let mut chart = log_log_panel(
            root,
            &area,
            labels,
            ((x0, x1), (y0, y1)),
            ((left, right), (top_upper, top_lower)),
        )?;
        labels.push(
            Label::new(
                "cumulative bus-busy cycles",
                ((left + right) / 2, top_lower + 26),
                14.0,
            )
            .align(Align::Center, Align::Start),
        );
        labels.push(
            Label::new("RMS error", (left - 8, top_upper - 12), 14.0).align(Align::End, Align::End),
        );
        // each phase's name once where two series' points of it (nearly) coincide
        let mut named: Vec<(&str, i32, i32)> = Vec::new();
        for (_, color, rows) in &series {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .map(|r| (r.cumulative_cycles.max(1) as f64, y_of(r)))
                .collect();
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts.clone(),
                    rgb(*color).stroke_width(2),
                )))
                .map_err(err)?;
            for (r, p) in rows.iter().zip(&pts) {
                let (px, py) = chart.backend_coord(p);
                root.draw(&Circle::new((px, py), 4, rgb(*color).filled()))
                    .map_err(err)?;
                let near = |&&(name, x, y): &&(&str, i32, i32)| {
                    name == r.phase && (x - px).abs() < 24 && (y - py).abs() < 12
                };
                if named.iter().any(|n| near(&n)) {
                    continue;
                }
                named.push((r.phase, px, py));
                labels.push(
                    Label::new(r.phase, (px + 6, py - 4), 11.0)
                        .align(Align::Start, Align::End)
                        .color(*color),
                );
            }
        }
        // the legend
        let lx = right + 24;
        let mut ly = top_upper;
        for (name, color, _) in &series {
            root.draw(&PathElement::new(
                vec![(lx, ly), (lx + 16, ly)],
                rgb(*color).stroke_width(3),
            ))
            .map_err(err)?;
            labels.push(Label::new(name, (lx + 24, ly), 12.0).align(Align::Start, Align::Center));
            ly += 20;
        }
        // the lower panel: busy cycles per scanline, per frame of the first run
        let lines = first.lines.max(2) as f64;
        let area = panel_area(root, (left, right), (bot_upper, bot_lower));
        let mut chart = ChartBuilder::on(&area)
            .build_cartesian_2d(0f64..lines, (b0..b1).log_scale())
            .map_err(err)?;
        decade_grid(
            root,
            labels,
            LogAxis::Y,
            (b0, b1),
            |y| chart.backend_coord(&(0.0, y)).1,
            (left, right),
        )?;
        let (_, py) = chart.backend_coord(&(0.0, first.line_period.max(1) as f64));
        root.draw(&PathElement::new(
            vec![(left, py), (right, py)],
            rgb(OVERRUN).stroke_width(2),
        ))
        .map_err(err)?;
        labels.push(
            Label::new(
                format!("line period {}", first.line_period),
                (right - 4, py - 4),
                12.0,
            )
            .align(Align::End, Align::End)
            .color(OVERRUN),
        );
        labels.push(
            Label::new(
                "bus-busy cycles per scanline, each frame",
                (left, bot_upper - 14),
                14.0,
            )
            .align(Align::Start, Align::End),
        );
        // scanline ticks, about every 80 pixels
        let step = nice_step(80.0 * lines / f64::from((right - left).max(1) as u32));
        let mut tick = 0u64;
        while tick as f64 <= lines {
            let (px, _) = chart.backend_coord(&(tick as f64, b0));
            root.draw(&PathElement::new(
                vec![(px, bot_lower), (px, bot_lower + 4)],
                BLACK,
            ))
            .map_err(err)?;
            labels.push(
                Label::new(tick.to_string(), (px, bot_lower + 7), 12.0)
                    .align(Align::Center, Align::Start),
            );
            tick += step;
        }
        labels.push(
            Label::new("scanline", ((left + right) / 2, bot_lower + 26), 14.0)
                .align(Align::Center, Align::Start),
        );
        root.draw(&PathElement::new(
            vec![(left, bot_upper), (left, bot_lower), (right, bot_lower)],
            BLACK,
        ))
        .map_err(err)?;
        let mut ly = bot_upper;
        for (k, busy) in first.busy_per_line.iter().enumerate() {
            let color = PALETTE[(k + 3) % PALETTE.len()];
            let pts: Vec<(f64, f64)> = busy
                .iter()
                .enumerate()
                .map(|(row, &b)| (row as f64 + 0.5, b.max(1) as f64))
                .collect();
            chart
                .draw_series(std::iter::once(PathElement::new(pts, rgb(color))))
                .map_err(err)?;
            root.draw(&PathElement::new(
                vec![(lx, ly), (lx + 16, ly)],
                rgb(color).stroke_width(3),
            ))
            .map_err(err)?;
            let name = first.rows.get(k).map_or("frame", |r| r.phase);
            labels.push(
                Label::new(format!("frame {}: {name}", k + 1), (lx + 24, ly), 12.0)
                    .align(Align::Start, Align::Center),
            );
            ly += 20;
        }
        Ok(())
    })?;
    Ok(img)
}
