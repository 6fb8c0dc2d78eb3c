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
//!
//! Every term is at most `cwisim_scene::MAX_INTENSITY` (`M`, checked when a scene is read)
//! and `N·L`, `(R·V)^n` are in `[0, 1]`, so `I ≤ M² (1 + 2 · lights)`: finite for any scene
//! a file can hold (`docs/LIMITS.md`, "Intensities").

use crate::scene::{LightSpec, Material, PerChannel};
use cwisim_scene::{vector, SceneError, SceneErrorKind, Vector, MAX_INTENSITY};
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
        self.intensity_lit(m, point, normal, eye, |_| true)
    }

    /// [`Self::intensity`] with only the lights `reaches(k)` says reach the point (light
    /// `k` of [`Self::lights`]): a shadowed point keeps the ambient term and every other
    /// light's, and loses that light's diffuse and specular terms. With every light
    /// reaching it is [`Self::intensity`], bit for bit.
    pub fn intensity_lit(
        &self,
        m: &Material,
        point: DVec3,
        normal: DVec3,
        eye: DVec3,
        reaches: impl Fn(usize) -> bool,
    ) -> Vector {
        let mut out = vector(self.channels, |c| self.ambient.get(c) * m.k_a.get(c));
        for (light, n_dot_l, r_dot_v) in self.facing(point, normal, eye, reaches) {
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

    /// The lights `reaches` says reach `point` that face it (`N·L > 0`), each with `N·L`
    /// and `R·V` (at most 1: rounding can give 1 + 2^-52, which a large exponent `n`
    /// would raise to infinity, so `(R·V)^n` is in [0, 1] for every `n ≥ 0`).
    fn facing(
        &self,
        point: DVec3,
        normal: DVec3,
        eye: DVec3,
        reaches: impl Fn(usize) -> bool,
    ) -> impl Iterator<Item = (&LightSpec, f64, f64)> {
        let v = (eye - point).normalize_or_zero();
        self.lights
            .iter()
            .enumerate()
            .filter(move |(k, _)| reaches(*k))
            .filter_map(move |(_, light)| {
                let l = (DVec3::from_array(light.position) - point).normalize_or_zero();
                let n_dot_l = normal.dot(l);
                if n_dot_l <= 0.0 {
                    return None;
                }
                let r = 2.0 * n_dot_l * normal - l;
                Some((light, n_dot_l, r.dot(v).min(1.0)))
            })
    }

    /// [`Self::intensity_lit`] in two parts, `(ambient + diffuse, specular)`: what a
    /// texture scales (it multiplies `k_a` and `k_d`) and what it leaves. Their sum is the
    /// intensity up to rounding.
    pub fn intensity_split(
        &self,
        m: &Material,
        point: DVec3,
        normal: DVec3,
        eye: DVec3,
        reaches: impl Fn(usize) -> bool,
    ) -> (Vector, Vector) {
        let mut diffuse = vector(self.channels, |c| self.ambient.get(c) * m.k_a.get(c));
        let mut specular = Vector::default();
        for (light, n_dot_l, r_dot_v) in self.facing(point, normal, eye, reaches) {
            for c in 0..self.channels {
                let i = light.intensity.get(c);
                diffuse[c] += i * m.k_d.get(c) * n_dot_l;
                if r_dot_v > 0.0 && m.k_s.get(c) != 0.0 {
                    specular[c] += i * m.k_s.get(c) * r_dot_v.powf(m.n);
                }
            }
        }
        (diffuse, specular)
    }
}

/// Refuses a lit intensity that is not finite: what lighting makes is checked where it is
/// made (the scene's limits keep it finite; this is the defence behind them), so that no
/// renderer gets a value the array would refuse. `place` names, only when needed, the
/// JSON path of the mesh (or patch) and the part lit (`("meshes[2]", "face 7")`).
pub fn check_lit(
    i: &Vector,
    channels: usize,
    place: impl FnOnce() -> (String, String),
) -> Result<(), SceneError> {
    match i[..channels].iter().find(|v| !v.is_finite()) {
        None => Ok(()),
        Some(bad) => {
            let (field, part) = place();
            Err(SceneError::at_field(
                SceneErrorKind::NonFinite,
                field,
                format!(
                    "lighting: {part} is lit to {bad}: ambient × k_a + Σ lights × (k_d + k_s) overflows f64 (each term is limited to ±{MAX_INTENSITY:e})"
                ),
            ))
        }
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
                shadows: false,
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
            texture: None,
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

    #[test]
    fn a_huge_exponent_gives_a_highlight_of_at_most_one_and_overflow_is_refused() {
        let mut m = material();
        m.n = f64::MAX;
        // a light and an eye placed so that R·V rounds to 1 + 2^-52 (found by search):
        // the highlight is clamped to (R·V)^n = 1, not raised to infinity
        let l = Lighting {
            lights: vec![LightSpec {
                position: [0.9095578363365777, 8.098510160219618, -2.4368424793545906],
                intensity: PerChannel::All(1.0),
                shadows: false,
            }],
            ..lighting()
        };
        let eye = DVec3::new(-0.5346591013375908, 4.7604912974814875, 1.432432285296553);
        let n_dot_l = DVec3::Y.dot(DVec3::from_array(l.lights[0].position).normalize());
        let i = l.intensity(&m, DVec3::ZERO, DVec3::Y, eye);
        assert_eq!(i[0], 0.1 + (0.8 * n_dot_l + 0.4), "{i:?}");
        let place = || ("meshes[2]".to_string(), "face 7".to_string());
        assert_eq!(check_lit(&[0.5, 1.0, 0.0, f64::NAN], 3, place), Ok(()));
        let e = check_lit(&[0.5, f64::INFINITY, 0.0, 0.0], 3, place).unwrap_err();
        assert_eq!(
            e.to_string(),
            "meshes[2]: lighting: face 7 is lit to inf: ambient × k_a + Σ lights × (k_d + k_s) overflows f64 (each term is limited to ±1e12)"
        );
    }
}
