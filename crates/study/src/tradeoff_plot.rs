//! The `cwisim tradeoff --plot` chart: RMS error against the array's bus cycles, one
//! point per setting, both axes logarithmic; the staircase of the least error for the
//! cycles, and rings on the settings that are Pareto-optimal in cycles, register bits and
//! error.
//!
//! Colour is the numeric format; a filled marker is a box filter (exact or the
//! report's), a hollow one point sampling; a circle is exact visibility, a square eval0 (or a screen scene). Errors
//! below [`ERROR_FLOOR`] (an exact image) are drawn on the floor.

use crate::plot::{decades, draw_on, err, log_log_panel, panel_area, rgb, wrap, Align, Label, Rgb};
use crate::tradeoff::Row;
use plotters::prelude::*;

/// The smallest error the chart shows; smaller ones sit on this line.
pub const ERROR_FLOOR: f64 = 1e-12;

/// The blank kept at the right edge of the legend, pixels.
const LEGEND_MARGIN: i32 = 10;

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
            let width = (w as i32 - LEGEND_MARGIN - lx - 20) as f32;
            for line in wrap(f, 12.0, width) {
                labels
                    .push(Label::new(line, (lx + 20, ly), 12.0).align(Align::Start, Align::Center));
                ly += 16;
            }
            ly += 4;
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
        // as many as fit above the bottom edge, each wrapped to the legend's width (a
        // line of the same setting indented); the rest said in the last lines
        const ROW: i32 = 15;
        let width = (w as i32 - LEGEND_MARGIN - lx) as f32;
        let bottom = h as i32 - 12;
        let named: Vec<Vec<String>> = front
            .iter()
            .map(|r| {
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
                wrap(&words.join(" "), 11.0, width - 12.0)
            })
            .collect();
        let more = |n: usize| {
            wrap(
                &format!("… and {n} more (the table's Pareto front, the CSV's pareto column)"),
                11.0,
                width,
            )
        };
        let mut shown = 0;
        let mut used = 0;
        for (k, lines) in named.iter().enumerate() {
            let rest = if k + 1 < named.len() {
                more(named.len() - k - 1).len()
            } else {
                0
            };
            if ly + ROW * (used + lines.len() + rest) as i32 > bottom {
                break;
            }
            shown += 1;
            used += lines.len();
        }
        for lines in &named[..shown] {
            for (k, line) in lines.iter().enumerate() {
                let x = if k == 0 { lx } else { lx + 12 };
                labels.push(
                    Label::new(line.as_str(), (x, ly), 11.0).align(Align::Start, Align::Center),
                );
                ly += ROW;
            }
        }
        if shown < named.len() {
            for line in more(named.len() - shown) {
                labels.push(Label::new(line, (lx, ly), 11.0).align(Align::Start, Align::Center));
                ly += ROW;
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn row(k: usize, numeric: &str) -> Row {
        Row {
            renderer: ["woo-chall", "sbuffer", "vanrij"][k % 3],
            shading: "gouraud",
            aa: if k.is_multiple_of(2) { "box" } else { "none" },
            samples: Some(1 + (k % 4) as u32),
            visibility: "exact",
            shadows: "-",
            tessellate: Some(16),
            root_tolerance: None,
            normal_angle: None,
            numeric: numeric.to_string(),
            register_bits: 40 + k as u32,
            instructions: 1000 + k as u64,
            busy_cycles: 100 + 17 * k as u64,
            worst_line_share: 0.5,
            late_lines: 0,
            host_ms: 1.0,
            max_error: 0.1,
            rms_error: 1e-3 / (1 + k) as f64,
            psnr_db: 60.0,
            overflows: 0,
            counters: Default::default(),
            pareto: true,
        }
    }

    /// Whether any pixel of the image's last `columns` columns is darker than the grid.
    fn ink_at_the_right_edge(img: &Rgb, columns: u32) -> Option<(u32, u32)> {
        (img.width - columns..img.width)
            .flat_map(|x| (0..img.height).map(move |y| (x, y)))
            .find(|&(x, y)| img.get(x, y).iter().any(|&c| c < 160))
    }

    #[test]
    fn the_legend_stays_within_the_canvas() {
        // 40 Pareto-optimal settings with long names (the last line used to run off the
        // right edge: "… the CSV's pareto colum"), and a format longer than the legend
        let long = "fixed:I=10.22,dI=4.28,ddI=1.35,acc=12.40,dI_extra=1.1,more=2.2";
        let rows: Vec<Row> = (0..40)
            .map(|k| {
                row(
                    k,
                    if k % 5 == 0 {
                        long
                    } else {
                        "fixed:I=10.14,dI=4.20,ddI=1.27"
                    },
                )
            })
            .collect();
        let img = render_tradeoff_plot(&rows, "a scene").unwrap();
        assert_eq!(
            ink_at_the_right_edge(&img, LEGEND_MARGIN as u32 / 2),
            None,
            "text at the right edge"
        );
    }

    #[test]
    fn wrapped_lines_fit_and_keep_every_word() {
        let text = "… and 12 more (the table's Pareto front, the CSV's pareto column)";
        let lines = wrap(text, 11.0, 200.0);
        assert!(lines.len() >= 2, "{lines:?}");
        assert!(lines
            .iter()
            .all(|l| crate::plot::text_width(l, 11.0) <= 200.0));
        assert_eq!(lines.join(" "), text);
        // a format wider than the width is broken after its commas
        let f = "fixed:I=10.22,dI=4.28,ddI=1.35,acc=12.40";
        let lines = wrap(f, 12.0, 100.0);
        assert!(lines.len() >= 2, "{lines:?}");
        assert_eq!(lines.concat(), f);
    }
}
