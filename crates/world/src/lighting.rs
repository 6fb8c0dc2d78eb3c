//! The report's lighting formula (van Rij, section 1.2, after Phong 1975), per channel:
//!
//! ```text
//! I = I_a · k_a + Σ_lights I_l · ( k_d · (N·L) + k_s · (R·V)^n )
//! ```
//!
//! `N` the unit normal, `L` the unit vector to the light, `R = 2 (N·L) N − L` the light
//! vector mirrored in `N`, `V` the unit vector to the viewer. Decisions (docs/SCENES.md):
//! a light behind the surface (`N·L ≤ 0`) contributes nothing, neither diffuse nor
//! specular, and a highlight facing away (`R·V ≤ 0`) contributes no specular term — the
//! formula as printed would subtract light there. Several lights add up. Intensities
//! are not clamped: a PNG clamps to `[0, 1]` on output, `.npy` keeps the values.

use crate::scene::{LightSpec, Material, PerChannel};
use cwisim_scene::{vector, Vector};
use glam::DVec3;

/// The lights of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// `I_a`.
    pub ambient: PerChannel,
    /// The point lights.
    pub lights: Vec<LightSpec>,
    /// Channels.
    pub channels: usize,
}

impl Lighting {
    /// The intensity at `point` with unit normal `normal`, seen from `eye`.
    pub fn intensity(&self, m: &Material, point: DVec3, normal: DVec3, eye: DVec3) -> Vector {
        let v = (eye - point).normalize_or_zero();
        let mut out = vector(self.channels, |c| self.ambient.get(c) * m.k_a.get(c));
        for light in &self.lights {
            let l = (DVec3::from_array(light.position) - point).normalize_or_zero();
            let n_dot_l = normal.dot(l);
            if n_dot_l <= 0.0 {
                continue;
            }
            let r = 2.0 * n_dot_l * normal - l;
            let r_dot_v = r.dot(v);
            for (c, value) in out.iter_mut().enumerate().take(self.channels) {
                let specular = if r_dot_v > 0.0 && m.k_s.get(c) != 0.0 {
                    m.k_s.get(c) * r_dot_v.powf(m.n)
                } else {
                    0.0
                };
                *value += light.intensity.get(c) * (m.k_d.get(c) * n_dot_l + specular);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lighting() -> Lighting {
        Lighting {
            ambient: PerChannel::All(0.2),
            lights: vec![LightSpec {
                position: [0.0, 10.0, 0.0],
                intensity: PerChannel::Each(vec![1.0, 0.5, 0.0]),
            }],
            channels: 3,
        }
    }

    fn material() -> Material {
        Material {
            k_a: PerChannel::All(0.5),
            k_d: PerChannel::All(0.8),
            k_s: PerChannel::All(0.4),
            n: 10.0,
            transmittance: 0.0,
        }
    }

    #[test]
    fn the_formula_term_by_term() {
        let l = lighting();
        // light straight above, viewer straight above: N·L = 1, R = N, R·V = 1
        let i = l.intensity(
            &material(),
            DVec3::ZERO,
            DVec3::Y,
            DVec3::new(0.0, 5.0, 0.0),
        );
        let expected = [0.1 + 1.0 * (0.8 + 0.4), 0.1 + 0.5 * (0.8 + 0.4), 0.1];
        for c in 0..3 {
            assert!((i[c] - expected[c]).abs() < 1e-15, "{i:?} {expected:?}");
        }
        // viewer at 60° from the normal, light above: R·V = cos 60° = 1/2
        let eye = DVec3::new(60f64.to_radians().sin(), 60f64.to_radians().cos(), 0.0);
        let i = l.intensity(&material(), DVec3::ZERO, DVec3::Y, eye);
        let expected = 0.1 + 1.0 * (0.8 + 0.4 * 0.5f64.powi(10));
        assert!((i[0] - expected).abs() < 1e-12, "{} {expected}", i[0]);
        // a surface facing away from the light gets only the ambient term
        let i = l.intensity(
            &material(),
            DVec3::ZERO,
            -DVec3::Y,
            DVec3::new(0.0, -5.0, 0.0),
        );
        assert_eq!(&i[..3], &[0.1, 0.1, 0.1]);
    }
}
