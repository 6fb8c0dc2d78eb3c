//! The `cwisim tradeoff --plot` chart: RMS error against the array's bus cycles, one
//! point per setting, both axes logarithmic; the staircase of the least error for the
//! cycles, and rings on the settings that are Pareto-optimal in cycles, register bits and
//! error.
//!
//! Colour is the numeric format; a filled marker is a box filter (exact or the
//! report's), a hollow one point sampling; a circle is exact visibility, a square eval0 (or a screen scene). Errors
//! below [`ERROR_FLOOR`] (an exact image) are drawn on the floor.

use crate::plot::{decades, draw_on, err, log_log_panel, panel_area, rgb, Align, Label, Rgb};
use crate::tradeoff::Row;
use plotters::prelude::*;

/// The smallest error the chart shows; smaller ones sit on this line.
pub const ERROR_FLOOR: f64 = 1e-12;

/// Width and height of the chart, pixels.
pub const TRADEOFF_PLOT_SIZE: (u32, u32) = (1100, 700);

const PALETTE: [[u8; 3]; 8] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
];

/// Draws the chart of `rows` for the scene called `name`.
pub fn render_tradeoff_plot(rows: &[Row], name: &str) -> Result<Rgb, String> {
    if rows.is_empty() {
        return Err("no setting to plot".into());
    }
    let mut formats: Vec<&str> = Vec::new();
    for r in rows {
        if !formats.contains(&r.numeric.as_str()) {
            formats.push(&r.numeric);
        }
    }
    let y_of = |r: &Row| r.rms_error.max(ERROR_FLOOR);
    let (cmin, cmax) = rows.iter().fold((u64::MAX, 0u64), |(a, b), r| {
        (a.min(r.busy_cycles.max(1)), b.max(r.busy_cycles.max(1)))
    });
    let (emin, emax) = rows.iter().fold((f64::INFINITY, 0.0f64), |(a, b), r| {
        (a.min(y_of(r)), b.max(y_of(r)))
    });
    let (x0, x1) = decades(cmin as f64, cmax as f64);
    let (y0, y1) = decades(emin, emax);

    let (w, h) = TRADEOFF_PLOT_SIZE;
    let (left, right, upper, lower) = (90i32, w as i32 - 330, 80i32, h as i32 - 60);
    let mut img = Rgb::white(w, h);
    draw_on(&mut img, |root, labels| {
        labels.push(Label::new(
            format!("{name}: error against cycles, {} settings", rows.len()),
            (16, 12),
            22.0,
        ));
        labels.push(Label::new(
            "RMS error against the exact box-filtered image; the staircase: the least error for the cycles; rings: Pareto-optimal in cycles, register bits and error",
            (16, 42),
            14.0,
        ));
        let area = panel_area(root, (left, right), (upper, lower));
        let mut chart = log_log_panel(
            root,
            &area,
            labels,
            ((x0, x1), (y0, y1)),
            ((left, right), (upper, lower)),
        )?;
        labels.push(
            Label::new(
                "bus-busy cycles per frame",
                ((left + right) / 2, lower + 30),
                15.0,
            )
            .align(Align::Center, Align::Start),
        );
        labels.push(
            Label::new("RMS error", (left - 8, upper - 12), 15.0).align(Align::End, Align::End),
        );
        // the staircase: the lowest error reached for at most so many cycles
        let mut by_cycles: Vec<&Row> = rows.iter().collect();
        by_cycles.sort_by(|a, b| {
            a.busy_cycles
                .cmp(&b.busy_cycles)
                .then(a.rms_error.total_cmp(&b.rms_error))
        });
        let mut stair: Vec<&Row> = Vec::new();
        for r in by_cycles {
            if stair.last().is_none_or(|l| r.rms_error < l.rms_error) {
                stair.push(r);
            }
        }
        let front: Vec<&Row> = rows.iter().filter(|r| r.pareto).collect();
        let mut path = Vec::new();
        for (k, r) in stair.iter().enumerate() {
            let p = (r.busy_cycles.max(1) as f64, y_of(r));
            if k > 0 {
                let prev: &(f64, f64) = path.last().expect("a point");
                path.push((p.0, prev.1));
            }
            path.push(p);
        }
        if let Some(&(_, last_y)) = path.last() {
            path.push((x1, last_y));
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                path,
                BLACK.stroke_width(2),
            )))
            .map_err(err)?;
        // the points
        for r in rows {
            let color =
                rgb(PALETTE
                    [formats.iter().position(|f| *f == r.numeric).unwrap_or(0) % PALETTE.len()]);
            let (px, py) = chart.backend_coord(&(r.busy_cycles.max(1) as f64, y_of(r)));
            let style = if r.aa != "none" {
                color.filled()
            } else {
                color.stroke_width(2)
            };
            if r.visibility == "eval0" {
                root.draw(&Rectangle::new([(px - 5, py - 5), (px + 5, py + 5)], style))
                    .map_err(err)?;
            } else {
                root.draw(&Circle::new((px, py), 5, style)).map_err(err)?;
            }
            if r.pareto {
                root.draw(&Circle::new((px, py), 9, BLACK.stroke_width(1)))
                    .map_err(err)?;
            }
        }
        // the legend
        let lx = right + 24;
        let mut ly = upper;
        labels
            .push(Label::new("numeric format", (lx, ly), 15.0).align(Align::Start, Align::Center));
        ly += 24;
        for (k, f) in formats.iter().enumerate() {
            root.draw(&Circle::new(
                (lx + 6, ly),
                5,
                rgb(PALETTE[k % PALETTE.len()]).filled(),
            ))
            .map_err(err)?;
            labels.push(Label::new(*f, (lx + 20, ly), 12.0).align(Align::Start, Align::Center));
            ly += 20;
        }
        ly += 14;
        for (text, shape) in [
            ("box filter (filled)", 0),
            ("point sampling (hollow)", 1),
            ("exact visibility (circle)", 2),
            ("eval0 visibility (square)", 3),
            ("Pareto-optimal (ring)", 4),
        ] {
            let grey = RGBColor(90, 90, 90);
            match shape {
                0 => root.draw(&Circle::new((lx + 6, ly), 5, grey.filled())),
                1 => root.draw(&Circle::new((lx + 6, ly), 5, grey.stroke_width(2))),
                2 => root.draw(&Circle::new((lx + 6, ly), 5, grey.filled())),
                3 => root.draw(&Rectangle::new(
                    [(lx + 1, ly - 5), (lx + 11, ly + 5)],
                    grey.filled(),
                )),
                _ => root.draw(&Circle::new((lx + 6, ly), 9, BLACK.stroke_width(1))),
            }
            .map_err(err)?;
            labels.push(Label::new(text, (lx + 20, ly), 12.0).align(Align::Start, Align::Center));
            ly += 20;
        }
        // the front, named
        ly += 14;
        labels.push(
            Label::new("Pareto-optimal settings", (lx, ly), 15.0)
                .align(Align::Start, Align::Center),
        );
        ly += 22;
        // as many as fit above the bottom edge; the rest said in one line
        const ROW: i32 = 17;
        let room = ((h as i32 - 20 - ly) / ROW).max(1) as usize;
        let shown = if front.len() > room {
            room - 1
        } else {
            front.len()
        };
        for r in &front[..shown] {
            labels.push(
                Label::new(
                    {
                        // the row's own settings, what does not apply ("-") left out
                        let mut words = vec![r.renderer.to_string()];
                        if let Some(n) = r.tessellate {
                            words.push(format!("tessellated {n},"));
                        }
                        words.push(r.shading.to_string());
                        words.extend(
                            [r.aa, r.visibility]
                                .into_iter()
                                .filter(|w| *w != "-")
                                .map(str::to_string),
                        );
                        if let Some(l) = r.samples {
                            words.push(format!("{l}×{l} samples"));
                        }
                        words.push(short(&r.numeric));
                        words.join(" ")
                    },
                    (lx, ly),
                    11.0,
                )
                .align(Align::Start, Align::Center),
            );
            ly += ROW;
        }
        if shown < front.len() {
            labels.push(
                Label::new(
                    format!(
                        "… and {} more (the table's Pareto front, the CSV's pareto column)",
                        front.len() - shown
                    ),
                    (lx, ly),
                    11.0,
                )
                .align(Align::Start, Align::Center),
            );
        }
        Ok(())
    })?;
    Ok(img)
}

/// A format, shortened for the legend.
fn short(numeric: &str) -> String {
    numeric
        .strip_prefix("fixed:")
        .map_or_else(|| numeric.to_string(), |f| format!("fx {f}"))
}
