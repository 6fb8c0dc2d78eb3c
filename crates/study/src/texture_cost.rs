//! What a texture's frequency costs the array: a checkerboard whose squares are `P`
//! pixels wide, from 64 down to 1, drawn by `vanrij` under each texture filter and span
//! tolerance, measured in instructions, the `Eval1` share, bus cycles, the busiest
//! scanline against the line period, late scanlines on machines of several clock rates,
//! and the error against a brute-force reference (`rays × rays` samples per pixel).
//!
//! The scene is a square facing the camera, turned 10° about the view axis (so that no
//! checker edge runs along a pixel edge), larger than the view: every pixel shows the
//! texture, lit by ambient light alone (`k_a` 1), so a pixel's value is the texture's.
//! Every texture pixel is an intensity the array cannot interpolate across a checker
//! edge: each edge inside a span is a new piece, and at `P = 1` the box filter's mean
//! is nearly flat while point sampling alternates at every pixel.
//!
//! The reference maps each sample back onto the square with the pinhole camera's
//! formula and reads the checker there, written out again here: it shares no code with
//! the texture module, the shader or the span fitter.

use crate::plot::{decades, draw_on, err, log_log_panel, panel_area, rgb, Align, Label, Rgb};
use crate::StudyError;
use cwisim_render::{registry, render, ArrayConfig, LoadedScene, Settings, Taps};
use cwisim_scene::{Antialias, Shading};
use cwisim_world::texture::TextureFilter;
use cwisim_world::{AnyScene, WorldScene};
use cwisim_xproc::{ImageSink, Machine};
use plotters::prelude::*;

/// Checker square widths in pixels, coarse to fine.
pub const PERIODS: [u32; 7] = [64, 32, 16, 8, 4, 2, 1];
/// Span tolerances: exact, the default 1/512, and two coarser.
pub const TOLERANCES: [f64; 4] = [0.0, 1.0 / 512.0, 1.0 / 64.0, 1.0 / 8.0];
/// Array clocks of the machines compared (the default 100 MHz, and two slower).
pub const CLOCKS_HZ: [f64; 3] = [1e8, 5e7, 2.5e7];
/// The checker's two values.
pub const DARK: f64 = 0.2;
/// The checker's light value.
pub const LIGHT: f64 = 0.9;
/// How far the square is turned about the view axis, degrees.
const TURN_DEGREES: f64 = 10.0;
/// The camera's distance from the square and its vertical field of view.
const DISTANCE: f64 = 10.0;
const FOV_Y: f64 = 30.0;

/// What to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct CostPlan {
    /// Image side, pixels.
    pub size: u32,
    /// Checker square widths, pixels.
    pub periods: Vec<u32>,
    /// Texture filters.
    pub filters: Vec<TextureFilter>,
    /// Span tolerances.
    pub tolerances: Vec<f64>,
    /// Reference samples per pixel side.
    pub rays: usize,
    /// Machines' clocks, Hz (the other parameters the defaults).
    pub clocks_hz: Vec<f64>,
}

impl Default for CostPlan {
    fn default() -> Self {
        CostPlan {
            size: 512,
            periods: PERIODS.to_vec(),
            filters: TextureFilter::ALL.to_vec(),
            tolerances: TOLERANCES.to_vec(),
            rays: 64,
            clocks_hz: CLOCKS_HZ.to_vec(),
        }
    }
}

/// One setting measured.
#[derive(Clone, Debug, PartialEq)]
pub struct CostRow {
    /// Checker square width, pixels.
    pub period: u32,
    /// The texture filter.
    pub filter: TextureFilter,
    /// The span tolerance.
    pub tolerance: f64,
    /// Instructions per frame.
    pub instructions: u64,
    /// `Eval1`s per frame.
    pub eval1: u64,
    /// Bus-busy cycles per frame.
    pub busy_cycles: u64,
    /// Bus-busy cycles of the busiest scanline.
    pub worst_line_cycles: u64,
    /// Per machine of [`CostPlan::clocks_hz`]: its line period in cycles and the late
    /// scanlines.
    pub machines: Vec<(f64, u64, u64)>,
    /// RMS error against the reference.
    pub rms_error: f64,
    /// Largest error against the reference.
    pub max_error: f64,
}

/// The checker's repeat across the square for squares `period` pixels wide at `size`.
fn geometry(size: u32, period: u32) -> (f64, f64) {
    let half_view = DISTANCE * (0.5 * FOV_Y).to_radians().tan();
    // large enough to cover the view turned
    let half = 1.5 * half_view;
    let pixel = 2.0 * half_view / f64::from(size);
    // two squares per repeat
    let repeat = 2.0 * half / (2.0 * f64::from(period) * pixel);
    (half, repeat)
}

/// The scene at `size` with checker squares `period` pixels wide.
pub fn scene(size: u32, period: u32) -> Result<WorldScene, StudyError> {
    let (a, repeat) = geometry(size, period);
    let text = format!(
        r#"{{ "kind": "world", "width": {size}, "height": {size}, "channels": 1,
  "camera": {{ "eye": [0, 0, {DISTANCE}], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": {FOV_Y} }},
  "ambient": 1,
  "meshes": [ {{
    "material": {{ "k_a": 1, "k_d": 0, "k_s": 0, "n": 1,
      "texture": {{ "checker": {{ "squares": [2, 2], "dark": {DARK}, "light": {LIGHT} }}, "repeat": [{repeat}, {repeat}] }} }},
    "transform": {{ "rotate": [0, 0, {TURN_DEGREES}] }},
    "vertices": [[-{a}, -{a}, 0], [{a}, -{a}, 0], [{a}, {a}, 0], [-{a}, {a}, 0]],
    "uv": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "faces": [[0, 1, 2, 3]] }} ] }}"#
    );
    match cwisim_world::parse_any(&text, None).map_err(cwisim_render::RenderError::from)? {
        AnyScene::World(w) => Ok(w),
        AnyScene::Screen(_) => Err(StudyError::Usage("not a world scene".into())),
    }
}

/// The reference image: per pixel, the mean of the checker over `rays × rays` samples on
/// a regular grid of sub-pixel centres.
pub fn reference(size: u32, period: u32, rays: usize) -> Vec<f64> {
    let (a, repeat) = geometry(size, period);
    let focal = 0.5 * f64::from(size) / (0.5 * FOV_Y).to_radians().tan();
    let (sin, cos) = TURN_DEGREES.to_radians().sin_cos();
    let centre = 0.5 * f64::from(size);
    let squares = 2.0 * repeat;
    let mut out = Vec::with_capacity((size * size) as usize);
    for py in 0..size {
        for px in 0..size {
            let mut sum = 0.0;
            for j in 0..rays {
                let sy = f64::from(py) + (j as f64 + 0.5) / rays as f64;
                let y = (centre - sy) * DISTANCE / focal;
                for i in 0..rays {
                    let sx = f64::from(px) + (i as f64 + 0.5) / rays as f64;
                    let x = (sx - centre) * DISTANCE / focal;
                    // the square's own axes: the world point turned back
                    let (xs, ys) = (x * cos + y * sin, -x * sin + y * cos);
                    let (u, v) = ((xs + a) / (2.0 * a), (ys + a) / (2.0 * a));
                    let k = (u * squares).floor() as i64 + (v * squares).floor() as i64;
                    sum += if k.rem_euclid(2) == 0 { DARK } else { LIGHT };
                }
            }
            out.push(sum / (rays * rays) as f64);
        }
    }
    out
}

/// Measures every setting of `plan`, in the order periods × filters × tolerances;
/// `progress(done, total)` after each.
pub fn measure(
    plan: &CostPlan,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<CostRow>, StudyError> {
    if plan.size == 0 || plan.rays == 0 || plan.clocks_hz.is_empty() {
        return Err(StudyError::Usage(
            "a texture cost study needs an image, reference samples and a machine".into(),
        ));
    }
    let total = plan.periods.len() * plan.filters.len() * plan.tolerances.len();
    let mut rows = Vec::with_capacity(total);
    for &period in &plan.periods {
        let w = scene(plan.size, period)?;
        let truth = reference(plan.size, period, plan.rays);
        for &filter in &plan.filters {
            for &tolerance in &plan.tolerances {
                let settings = Settings {
                    shading: Shading::Flat,
                    aa: Antialias::Box,
                    texture_filter: filter,
                    shade_tolerance: tolerance,
                    ..Settings::default()
                };
                let mut machines = Vec::new();
                let mut first = None;
                for &clock_hz in &plan.clocks_hz {
                    let config = ArrayConfig {
                        machine: Machine {
                            clock_hz,
                            ..Machine::default()
                        },
                        ..ArrayConfig::default()
                    };
                    let loaded = LoadedScene::built("texture-cost", AnyScene::World(w.clone()));
                    let r = (registry::find("vanrij")?.build)(loaded, &settings)?;
                    let h = r.header();
                    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), 1 << 30);
                    let done = render(&*r, &config, 1, &mut sink, Taps::default())?;
                    machines.push((
                        clock_hz,
                        done.stats.line_period,
                        done.stats.totals.late_lines,
                    ));
                    if first.is_none() {
                        let image = sink.finish()?.data;
                        first = Some((done.stats, image));
                    }
                }
                let (stats, image) = first.expect("a machine");
                let (mut squares, mut max_error) = (0.0, 0.0f64);
                for (v, t) in image.iter().zip(&truth) {
                    let e = (v - t).abs();
                    squares += e * e;
                    max_error = max_error.max(e);
                }
                let busy: Vec<u64> = stats.lines.iter().map(|l| l.busy_cycles).collect();
                rows.push(CostRow {
                    period,
                    filter,
                    tolerance,
                    instructions: stats.totals.instructions,
                    eval1: stats.totals.opcodes.get(cwisim_isa::Opcode::Eval1),
                    busy_cycles: busy.iter().sum(),
                    worst_line_cycles: busy.iter().copied().max().unwrap_or(0),
                    machines,
                    rms_error: (squares / image.len().max(1) as f64).sqrt(),
                    max_error,
                });
                progress(rows.len(), total);
            }
        }
    }
    Ok(rows)
}

/// The rows as CSV, one header line: `period,filter,tolerance,instructions,eval1_share,
/// busy_cycles,worst_line_cycles`, then per machine `line_period_at_<MHz>MHz` and
/// `late_at_<MHz>MHz`, then `rms_error,max_error`.
pub fn csv(rows: &[CostRow]) -> String {
    let mut out = String::from(
        "period,filter,tolerance,instructions,eval1_share,busy_cycles,worst_line_cycles",
    );
    if let Some(r) = rows.first() {
        for (clock, _, _) in &r.machines {
            out.push_str(&format!(
                ",line_period_at_{mhz}MHz,late_at_{mhz}MHz",
                mhz = clock / 1e6
            ));
        }
    }
    out.push_str(",rms_error,max_error\n");
    for r in rows {
        out.push_str(&format!(
            "{},{},{},{},{:.4},{},{}",
            r.period,
            r.filter.name(),
            r.tolerance,
            r.instructions,
            r.eval1 as f64 / r.instructions.max(1) as f64,
            r.busy_cycles,
            r.worst_line_cycles
        ));
        for (_, period, late) in &r.machines {
            out.push_str(&format!(",{period},{late}"));
        }
        out.push_str(&format!(",{:.3e},{:.3e}\n", r.rms_error, r.max_error));
    }
    out
}

/// Width and height of the chart, pixels.
pub const TEXTURE_COST_PLOT_SIZE: (u32, u32) = (1200, 560);

const COLOURS: [[u8; 3]; 4] = [[31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40]];

/// The chart: left, the busiest scanline's bus cycles against the checker's square width,
/// with each machine's line period; right, the RMS error. A line per filter and
/// tolerance: colour the tolerance; thick with filled dots the box filter, thin with rings point sampling.
pub fn render_plot(rows: &[CostRow]) -> Result<Rgb, String> {
    if rows.is_empty() {
        return Err("no setting to plot".into());
    }
    let mut tolerances: Vec<f64> = Vec::new();
    for r in rows {
        if !tolerances.contains(&r.tolerance) {
            tolerances.push(r.tolerance);
        }
    }
    let periods = rows.iter().map(|r| f64::from(r.period));
    let (pmin, pmax) = periods.fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p), b.max(p)));
    let x = decades(pmin, pmax);
    let cycles = rows
        .iter()
        .flat_map(|r| {
            std::iter::once(r.worst_line_cycles.max(1) as f64)
                .chain(r.machines.iter().map(|m| m.1 as f64))
        })
        .fold((f64::INFINITY, 0.0f64), |(a, b), c| (a.min(c), b.max(c)));
    let y_cycles = decades(cycles.0, cycles.1);
    const FLOOR: f64 = 1e-6;
    let errors = rows
        .iter()
        .map(|r| r.rms_error.max(FLOOR))
        .fold((f64::INFINITY, 0.0f64), |(a, b), e| (a.min(e), b.max(e)));
    let y_error = decades(errors.0, errors.1);
    let (w, h) = TEXTURE_COST_PLOT_SIZE;
    let mut img = Rgb::white(w, h);
    draw_on(&mut img, |root, labels| {
        labels.push(Label::new(
            "A checkerboard's cost on the array (vanrij, box-filtered coverage): the busiest scanline, and the error",
            (16, 12),
            20.0,
        ));
        labels.push(Label::new(
            "x: checker square width in pixels; colour: span tolerance; thick, filled dots: the texture's box filter; thin, rings: point sampling; grey: each machine's line period",
            (16, 40),
            13.0,
        ));
        let (upper, lower) = (90, h as i32 - 70);
        for (panel, (left, right)) in [(0, (90, 540)), (1, (680, 1130))] {
            let area = panel_area(root, (left, right), (upper, lower));
            let y = if panel == 0 { y_cycles } else { y_error };
            let mut chart =
                log_log_panel(root, &area, labels, (x, y), ((left, right), (upper, lower)))?;
            labels.push(
                Label::new(
                    "checker square width, pixels",
                    ((left + right) / 2, lower + 30),
                    14.0,
                )
                .align(Align::Center, Align::Start),
            );
            labels.push(
                Label::new(
                    if panel == 0 {
                        "bus cycles of the busiest scanline"
                    } else {
                        "RMS error against 64×64 rays per pixel"
                    },
                    (left - 8, upper - 12),
                    14.0,
                )
                .align(Align::Start, Align::End),
            );
            if panel == 0 {
                if let Some(r) = rows.first() {
                    for (clock, period, _) in &r.machines {
                        let p = *period as f64;
                        chart
                            .draw_series(std::iter::once(PathElement::new(
                                vec![(x.0, p), (x.1, p)],
                                RGBColor(150, 150, 150).stroke_width(2),
                            )))
                            .map_err(err)?;
                        let (_, py) = chart.backend_coord(&(x.1, p));
                        labels.push(
                            Label::new(format!("{} MHz", clock / 1e6), (right + 6, py), 12.0)
                                .align(Align::Start, Align::Center),
                        );
                    }
                }
            }
            for (k, &tolerance) in tolerances.iter().enumerate() {
                for filter in TextureFilter::ALL {
                    let mut points: Vec<(f64, f64)> = rows
                        .iter()
                        .filter(|r| r.tolerance == tolerance && r.filter == filter)
                        .map(|r| {
                            let v = if panel == 0 {
                                r.worst_line_cycles.max(1) as f64
                            } else {
                                r.rms_error.max(FLOOR)
                            };
                            (f64::from(r.period), v)
                        })
                        .collect();
                    points.sort_by(|a, b| a.0.total_cmp(&b.0));
                    let colour = rgb(COLOURS[k % COLOURS.len()]);
                    let (width, filled) = match filter {
                        TextureFilter::Box => (2, true),
                        TextureFilter::Point => (1, false),
                    };
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            points.clone(),
                            colour.stroke_width(width),
                        )))
                        .map_err(err)?;
                    let marker = if filled {
                        colour.filled()
                    } else {
                        colour.stroke_width(2)
                    };
                    chart
                        .draw_series(points.iter().map(|&p| Circle::new(p, 4, marker)))
                        .map_err(err)?;
                }
            }
        }
        // the legend of the tolerances
        let mut lx = 90;
        for (k, t) in tolerances.iter().enumerate() {
            let ly = h as i32 - 22;
            root.draw(&Rectangle::new(
                [(lx, ly - 5), (lx + 18, ly + 5)],
                rgb(COLOURS[k % COLOURS.len()]).filled(),
            ))
            .map_err(err)?;
            let text = if *t == 0.0 {
                "tolerance 0 (exact)".to_string()
            } else {
                format!("tolerance {t}")
            };
            let width = crate::plot::text_width(&text, 13.0) as i32;
            labels.push(Label::new(text, (lx + 24, ly), 13.0).align(Align::Start, Align::Center));
            lx += 24 + width + 30;
        }
        Ok(())
    })?;
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_of_a_coarse_checker_is_its_two_values_away_from_edges() {
        let r = reference(32, 16, 4);
        assert!(r
            .iter()
            .all(|&v| (DARK - 1e-12..=LIGHT + 1e-12).contains(&v)));
        let near = |c: f64| r.iter().any(|&v| (v - c).abs() < 1e-12);
        assert!(near(DARK) && near(LIGHT));
    }

    #[test]
    fn finer_checkers_cost_more_and_the_box_filter_errs_less_on_the_finest() {
        let plan = CostPlan {
            size: 48,
            periods: vec![64, 16, 1],
            filters: TextureFilter::ALL.to_vec(),
            tolerances: vec![1.0 / 512.0],
            rays: 8,
            clocks_hz: vec![1e8],
        };
        let rows = measure(&plan, |_, _| {}).unwrap();
        assert_eq!(rows.len(), 6);
        let get = |period, filter| {
            rows.iter()
                .find(|r| r.period == period && r.filter == filter)
                .unwrap()
        };
        for filter in TextureFilter::ALL {
            let (coarse, mid, fine) = (get(64, filter), get(16, filter), get(1, filter));
            assert!(coarse.instructions < mid.instructions, "{filter:?}");
            assert!(mid.instructions < fine.instructions, "{filter:?}");
            assert!(coarse.busy_cycles < fine.busy_cycles, "{filter:?}");
            // one square covers the view: only the span tolerance errs
            assert!(coarse.max_error < 4.0 / 512.0, "{}", coarse.max_error);
        }
        // squares a pixel wide: the box filter's mean is near the reference's, point
        // sampling aliases
        let (fine_box, fine_point) = (get(1, TextureFilter::Box), get(1, TextureFilter::Point));
        assert!(
            fine_box.rms_error < 0.3 * fine_point.rms_error,
            "{} against {}",
            fine_box.rms_error,
            fine_point.rms_error
        );
        let csv = csv(&rows);
        assert_eq!(csv.lines().count(), 7);
        assert!(csv.starts_with("period,filter,tolerance,instructions,eval1_share,busy_cycles,worst_line_cycles,line_period_at_100MHz,late_at_100MHz,rms_error,max_error\n"), "{csv}");
        let plot = render_plot(&rows).unwrap();
        let mut png = Vec::new();
        plot.encode_png(&mut png).unwrap();
        assert!(png.len() > 1000);
    }
}
