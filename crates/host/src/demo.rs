//! The embedded default trace that `cwisim run` replays when no file is given: a
//! Gouraud-shaded disc, anti-aliased along each scanline, built from the instruction set
//! alone (`Eval1` for the partly covered end pixels, `Eval2` for the interior, `Refresh`
//! per scanline). It stands in for the Y-processor until `cwisim render` exists, and
//! exercises the array with spans of every length.

use cwisim_isa::{Instruction, Intensity, TraceHeader};

/// Width of the demo frame.
pub const WIDTH: u32 = 96;
/// Scanlines of the demo frame.
pub const LINES: u32 = 64;

/// The demo's header and instructions (deterministic).
pub fn trace() -> (TraceHeader, Vec<Instruction>) {
    let header = TraceHeader::new(WIDTH, LINES, 1).expect("demo header within limits");
    let (cx, cy, r) = (48.0f64, 32.0f64, 28.0f64);
    // intensity rises linearly from the disc's left edge to its right edge
    let shade = |x: f64| 0.15 + 0.85 * ((x - (cx - r)) / (2.0 * r)).clamp(0.0, 1.0);
    let g = Intensity::grey;
    let mut out = Vec::new();
    for row in 0..LINES {
        let y = f64::from(row) + 0.5 - cy;
        if y.abs() < r {
            let half = (r * r - y * y).sqrt();
            let (xl, xr) = (cx - half, cx + half);
            let (pl, pr) = (xl.floor() as u32, xr.floor() as u32);
            if pl == pr {
                let centre = f64::from(pl) + 0.5;
                out.push(Instruction::eval1(pl, 1, g(shade(centre) * (xr - xl))));
            } else {
                // left end pixel: covered from xl to its right side
                let cl = f64::from(pl) + 0.5;
                out.push(Instruction::eval1(
                    pl,
                    1,
                    g(shade(cl) * (f64::from(pl + 1) - xl)),
                ));
                // interior: full coverage, a linear ramp sampled at pixel centres
                let n = pr - pl - 1;
                if n > 0 {
                    let first = f64::from(pl + 1) + 0.5;
                    let slope = 0.85 / (2.0 * r);
                    out.push(Instruction::eval2(pl + 1, n, g(shade(first)), g(slope)));
                }
                // right end pixel: covered from its left side to xr
                let cr = f64::from(pr) + 0.5;
                out.push(Instruction::eval1(
                    pr,
                    1,
                    g(shade(cr) * (xr - f64::from(pr))),
                ));
            }
        }
        out.push(Instruction::refresh());
    }
    (header, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cwisim_xproc::{run, Machine, Timing};

    #[test]
    fn the_demo_is_valid_and_covers_the_disc_area() {
        let (h, instrs) = trace();
        for i in &instrs {
            i.check(&h).expect("demo instruction fits the header");
        }
        // with intensity 1 everywhere the image would sum to the disc's area; with the
        // shading it sums to the integral of the shade over the disc, which lies between
        // 0.15 and 1.0 times the area.
        let (img, stats) =
            run::<f64>(&h, &instrs, &Machine::default(), Timing::Fast).expect("default machine");
        assert_eq!(stats.totals.lines, u64::from(LINES));
        let total: f64 = img.data.iter().sum();
        let area = std::f64::consts::PI * 28.0 * 28.0;
        assert!(
            total > 0.15 * area && total < area,
            "{total} vs area {area}"
        );
        // symmetric shading about the centre averages to (0.15 + 1.0) / 2
        assert!((total / area - 0.575).abs() < 0.02, "{}", total / area);
        assert_eq!(stats.totals.late_lines, 0);
    }
}
