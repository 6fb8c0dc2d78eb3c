//! What a pixel's texture should be: the mean of the texture over the pixel, from
//! `sub × sub` rays per pixel into a receding checkerboard floor, the checker's value
//! worked out again here (no code shared with the texture module or the shader).

use super::raycast::{hits, ray};
use cwisim_world::{AnyScene, WorldScene};

/// The floor's checkerboard: squares per side, and its two values.
pub const SQUARES: u32 = 24;
pub const DARK: f64 = 0.2;
pub const LIGHT: f64 = 0.9;

/// A `size × size` view over a checkerboard floor receding toward the horizon, lit by
/// ambient light alone (`k_a` 1): a pixel shows the texture's value itself.
pub fn floor(size: u32) -> WorldScene {
    let text = format!(
        r#"{{ "kind": "world", "width": {size}, "height": {size}, "channels": 1,
  "camera": {{ "eye": [0, 1.2, 6], "target": [0, 0, -4], "up": [0, 1, 0], "fov_y": 50 }},
  "ambient": 1,
  "meshes": [ {{
    "material": {{ "k_a": 1, "k_d": 0, "k_s": 0, "n": 1,
      "texture": {{ "checker": {{ "squares": [{SQUARES}, {SQUARES}], "dark": {DARK}, "light": {LIGHT} }} }} }},
    "vertices": [[-8, 0, 4], [8, 0, 4], [8, 0, -40], [-8, 0, -40]],
    "uv": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "faces": [[0, 1, 2, 3]] }} ] }}"#
    );
    match cwisim_world::parse_any(&text, None).unwrap() {
        AnyScene::World(w) => w,
        AnyScene::Screen(_) => unreachable!(),
    }
}

/// The checker's value at `(u, v)`: dark where the square indices' sum is even.
fn checker(uv: [f64; 2]) -> f64 {
    let n = f64::from(SQUARES);
    let (i, j) = ((uv[0] * n).floor() as i64, (uv[1] * n).floor() as i64);
    if (i + j).rem_euclid(2) == 0 {
        DARK
    } else {
        LIGHT
    }
}

/// Per pixel, the mean of the texture over it from `sub × sub` rays (on a regular grid
/// of sub-pixel centres); `None` where a ray misses the floor (a pixel it does not cover
/// whole).
pub fn reference(w: &WorldScene, size: u32, sub: usize) -> Vec<Option<f64>> {
    let mesh = &w.meshes[0];
    let mut out = Vec::with_capacity((size * size) as usize);
    for py in 0..size {
        for px in 0..size {
            let mut sum = 0.0;
            let mut whole = true;
            'samples: for j in 0..sub {
                for i in 0..sub {
                    let x = f64::from(px) + (i as f64 + 0.5) / sub as f64;
                    let y = f64::from(py) + (j as f64 + 0.5) / sub as f64;
                    let (o, d) = ray(w, size, size, x, y);
                    let Some(h) = hits(w, o, d).into_iter().next() else {
                        whole = false;
                        break 'samples;
                    };
                    let face = &mesh.faces[h.face];
                    let uv = [0, 1].map(|a| {
                        (0..3)
                            .map(|k| h.bary[k] * face.uv[h.corners[k]][a])
                            .sum::<f64>()
                    });
                    sum += checker(uv);
                }
            }
            out.push(whole.then(|| sum / (sub * sub) as f64));
        }
    }
    out
}

/// The error of `image` against `reference` over the pixels it covers whole: root mean
/// square, largest, and how many pixels.
pub fn errors(image: &[f64], reference: &[Option<f64>]) -> (f64, f64, usize) {
    let (mut squares, mut worst, mut n) = (0.0, 0.0f64, 0usize);
    for (v, r) in image.iter().zip(reference) {
        if let Some(r) = r {
            let e = (v - r).abs();
            squares += e * e;
            worst = worst.max(e);
            n += 1;
        }
    }
    ((squares / n as f64).sqrt(), worst, n)
}
