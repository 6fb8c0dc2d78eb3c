//! A generated screen scene for benchmarks: a tessellated surface.

use crate::screen::{Polygon, ScreenScene};

/// An `n × n` grid of warped quads filling a `size × size` image, each quad split into
/// two triangles (`2n²` polygons), every inner edge shared by two triangles: a
/// tessellated surface as a renderer meets it. The grid's inner vertices are moved by
/// up to a quarter of a cell (deterministically, by sines of their indices), so that
/// edges run at every slope and no triangle degenerates; the border stays on the image's
/// edge. One grey intensity per vertex (a smooth ramp in steps of 1/256); coordinates
/// at full precision, as an exporter writes them.
///
/// `n = 32`, `size = 1024`: the 2048-triangle scene of the performance targets, 430 KB
/// as cwisim writes it ([`ScreenScene::to_json`]; the file was about 350 KB).
///
/// # Panics
/// If `n` or `size` is 0.
pub fn warped_grid(n: u32, size: u32) -> ScreenScene {
    assert!(n > 0 && size > 0, "a grid of at least one cell");
    let cell = f64::from(size) / f64::from(n);
    let point = |i: u32, j: u32| -> ([f64; 2], f64) {
        let (fi, fj) = (f64::from(i), f64::from(j));
        let inner = |k: u32| k > 0 && k < n;
        let dx = if inner(i) {
            0.25 * cell * (1.7 * fi + 0.9 * fj).sin()
        } else {
            0.0
        };
        let dy = if inner(j) {
            0.25 * cell * (1.3 * fj - 0.7 * fi).cos()
        } else {
            0.0
        };
        let v = 0.5 + 0.45 * (0.37 * fi).sin() * (0.23 * fj + 0.5).cos();
        let v = (v * 256.0).round() / 256.0;
        ([fi * cell + dx, fj * cell + dy], v)
    };
    let mut polygons = Vec::with_capacity(2 * (n as usize).pow(2));
    for j in 0..n {
        for i in 0..n {
            let corners = [
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            ];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                polygons.push(Polygon::new(
                    tri.iter().map(|&c| corners[c].0).collect(),
                    tri.iter()
                        .map(|&c| crate::VertexIntensity::from_slice(&[corners[c].1]))
                        .collect::<Vec<_>>(),
                ));
            }
        }
    }
    ScreenScene {
        width: size,
        height: size,
        channels: 1,
        polygons,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{parse_scene, Scene};

    #[test]
    fn the_benchmark_grid_is_valid_and_about_350_kb() {
        let s = warped_grid(32, 1024);
        assert_eq!(s.polygons.len(), 2048);
        s.validate().expect("valid");
        let text = s.to_json();
        assert!(
            (300_000..500_000).contains(&text.len()),
            "{} bytes",
            text.len()
        );
        assert_eq!(parse_scene(&text).expect("reads"), Scene::Screen(s));
    }
}
