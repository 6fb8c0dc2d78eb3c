//! The pot drawn as several layers of one surface: the depth-complexity scenes of
//! `tests/depth_complexity.rs` and `examples/depth_complexity.rs`, and the peak heap they
//! measure (each binary that includes this module allocates through
//! `cwisim_fuzzing::heap::Counting`).

pub use cwisim_fuzzing::heap::peak_heap;
use cwisim_fuzzing::heap::Counting;

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The pot's profile (`crates/world/scenes/pot.json`).
const PROFILE: [[f64; 2]; 16] = [
    [0.0, 0.0],
    [0.5, 0.0],
    [0.58, 0.03],
    [0.7, 0.12],
    [0.82, 0.26],
    [0.92, 0.42],
    [0.98, 0.6],
    [0.98, 0.78],
    [0.92, 0.96],
    [0.8, 1.12],
    [0.64, 1.27],
    [0.52, 1.4],
    [0.48, 1.52],
    [0.5, 1.64],
    [0.6, 1.76],
    [0.72, 1.84],
];

/// The pot scene with `layers` copies of its surface, copy `k`'s radii scaled by
/// `1 + k·step`.
pub fn layered_pot(layers: usize, step: f64) -> String {
    let meshes: Vec<serde_json::Value> = (0..layers)
        .map(|k| {
            let s = 1.0 + k as f64 * step;
            let profile: Vec<[f64; 2]> = PROFILE.iter().map(|p| [p[0] * s, p[1]]).collect();
            serde_json::json!({
                "name": format!("layer {k}"),
                "material": { "k_a": 0.4, "k_d": 0.75, "k_s": 0.45, "n": 16 },
                "two_sided": true,
                "revolution": { "profile": profile, "segments": 32 }
            })
        })
        .collect();
    serde_json::json!({
        "kind": "world",
        "width": 400,
        "height": 400,
        "channels": 1,
        "camera": { "eye": [0, 3.2, 5.0], "target": [0, 0.85, 0], "up": [0, 1, 0], "fov_y": 32 },
        "ambient": 0.25,
        "lights": [ { "position": [4, 6, 5], "intensity": 0.85 } ],
        "meshes": meshes
    })
    .to_string()
}
