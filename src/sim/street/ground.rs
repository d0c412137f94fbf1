//! The street's ground surface: a height field z = g(x, y) in the world frame that is almost,
//! but not exactly, the plane z = 0, and where a lidar ray meets it.
//!
//! Real road surfaces are not perfect planes: they undulate over tens of metres, have dips and
//! patches over a few metres and roughness below that. This matters to scan registration: on a
//! perfect plane seen from a constant height, every beam draws the same ring at the same range
//! in every scan, so the ground looks identical wherever the vehicle is and pulls point-to-point
//! ICP towards zero motion. On a real road each ring's range changes with the local height
//! under it (a 2 cm rise moves the ring of a beam 8° down by 14 cm). Measured on the default
//! street, the relief alone does not free ICP from that trap (the body's pitch and roll do,
//! see [`super::body`]), but it makes the ground a road rather than a drawing of one.
//!
//! **Model.** g is a sum of octaves of value noise: octave i has a square lattice of cell size
//! c_i whose nodes carry heights drawn uniformly from [−a_i, a_i] (a hash of the seed, the
//! octave and the node, so nothing is stored and any point can be evaluated in any order),
//! blended with the smoothstep weights, so g is continuous with a continuous gradient and
//! |g| ≤ Σ a_i. With no octaves g = 0, the flat ground. The vehicle is simulated level at
//! constant height above z = 0 (its suspension absorbs the few centimetres).
//!
//! **Rays.** [`Ground::intersect`] finds the first crossing of a ray with the surface: every
//! crossing lies where the ray's height is within ±Σ a_i. A ray that descends more steeply than
//! the surface's steepest possible slope crosses it once in that stretch; a shallower one is
//! marched through it in steps of a quarter of the finest cell. The first sign change is refined
//! by the Illinois variant of regula falsi until the ray is within 0.01 mm of the surface.
//!
//! Not for: walls and objects (see [`super::lidar`]) or the street layout (see [`super::world`]).

use crate::error::{ensure_positive, Result};
use crate::rng::mix64;
use serde::{Deserialize, Serialize};

/// One octave of the ground's relief.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReliefOctave {
    /// Lattice cell size, metres (the wavelength of the relief, roughly).
    pub cell: f64,
    /// Largest height of a lattice node above or below z = 0, metres.
    pub amplitude: f64,
}

/// The ground's relief as data: octaves of value noise. Empty = the flat plane z = 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroundConfig {
    /// The octaves, any order.
    pub relief: Vec<ReliefOctave>,
}

impl Default for GroundConfig {
    /// Long undulations (±4 cm over ~25 m) and patches (±1.5 cm over ~6 m): a road that a
    /// plane fits to a few centimetres, as a KITTI street's does. Finer roughness would hide
    /// under the lidar's 2 cm range noise.
    fn default() -> Self {
        GroundConfig {
            relief: vec![
                ReliefOctave {
                    cell: 25.0,
                    amplitude: 0.04,
                },
                ReliefOctave {
                    cell: 6.0,
                    amplitude: 0.015,
                },
            ],
        }
    }
}

impl GroundConfig {
    /// A flat ground, z = 0 everywhere.
    pub fn flat() -> Self {
        GroundConfig { relief: Vec::new() }
    }

    /// Checks every octave; errors name the field.
    pub fn validate(&self) -> Result<()> {
        for (i, o) in self.relief.iter().enumerate() {
            ensure_positive(&format!("ground.relief[{i}].cell"), o.cell)?;
            crate::error::ensure_non_negative(
                &format!("ground.relief[{i}].amplitude"),
                o.amplitude,
            )?;
            if o.amplitude > 1.0 {
                return Err(crate::error::Error::invalid(
                    format!("ground.relief[{i}].amplitude"),
                    format!(
                        "{} m (at most 1 m: the ground stays near z = 0)",
                        o.amplitude
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The ground height field of one street (its configuration and seed).
#[derive(Clone, Debug, PartialEq)]
pub struct Ground {
    octaves: Vec<(ReliefOctave, u64)>,
    bound: f64,
    slope: f64,
    step: f64,
}

/// A crossing is refined until the ray is this close to the surface (or its bracket this
/// short), metres.
const HEIGHT_TOLERANCE: f64 = 1e-5;
/// Refinement steps at most.
const MAX_REFINEMENTS: usize = 60;

fn smoothstep(t: f64) -> f64 {
    t * t * (3.0 - 2.0 * t)
}

/// Uniform in [−1, 1] from a key and a lattice node.
fn node_value(key: u64, i: i64, j: i64) -> f64 {
    let h =
        mix64(key ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (j as u64).rotate_left(32));
    (h >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

impl Ground {
    /// The height field of `config` for `seed` (validate the configuration first).
    pub fn new(config: &GroundConfig, seed: u64) -> Ground {
        let octaves: Vec<(ReliefOctave, u64)> = config
            .relief
            .iter()
            .enumerate()
            .filter(|(_, o)| o.amplitude > 0.0)
            .map(|(i, o)| (*o, mix64(seed ^ mix64(0x6E0D_0000 + i as u64))))
            .collect();
        let bound = octaves.iter().map(|(o, _)| o.amplitude).sum();
        // Node values differ by at most 2a and the smoothstep's slope is at most 1.5/cell:
        // |∂g/∂x|, |∂g/∂y| ≤ Σ 3a/c, and any horizontal direction at most √2 times that.
        let slope = std::f64::consts::SQRT_2
            * octaves
                .iter()
                .map(|(o, _)| 3.0 * o.amplitude / o.cell)
                .sum::<f64>();
        let step = octaves
            .iter()
            .map(|(o, _)| 0.25 * o.cell)
            .fold(f64::INFINITY, f64::min);
        Ground {
            octaves,
            bound,
            slope,
            step,
        }
    }

    /// The flat ground z = 0.
    pub fn flat() -> Ground {
        Ground::new(&GroundConfig::flat(), 0)
    }

    /// No point of the surface is farther than this from z = 0, metres.
    pub fn bound(&self) -> f64 {
        self.bound
    }

    /// Ground height at (x, y), metres.
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let mut z = 0.0;
        for (o, key) in &self.octaves {
            let (u, v) = (x / o.cell, y / o.cell);
            let (fi, fj) = (u.floor(), v.floor());
            let (i, j) = (fi as i64, fj as i64);
            let (s, t) = (smoothstep(u - fi), smoothstep(v - fj));
            let a = node_value(*key, i, j);
            let b = node_value(*key, i + 1, j);
            let c = node_value(*key, i, j + 1);
            let d = node_value(*key, i + 1, j + 1);
            let low = a + s * (b - a);
            let high = c + s * (d - c);
            z += o.amplitude * (low + t * (high - low));
        }
        z
    }

    /// The smallest ray parameter t in (0, `t_max`] at which o + t·d meets the ground, from
    /// above; `None` when the ray stays above it up to `t_max` (or starts below it).
    pub fn intersect(&self, o: [f64; 3], d: [f64; 3], t_max: f64) -> Option<f64> {
        if d[2] >= 0.0 {
            return None;
        }
        let f = |t: f64| o[2] + t * d[2] - self.height(o[0] + t * d[0], o[1] + t * d[1]);
        if self.octaves.is_empty() {
            let t = -o[2] / d[2];
            return (t > 0.0 && t <= t_max).then_some(t);
        }
        // Crossings lie where the ray is within ±bound of z = 0.
        let t_lo = ((o[2] - self.bound) / -d[2]).max(0.0);
        let t_hi = ((o[2] + self.bound) / -d[2]).min(t_max);
        if t_lo > t_hi {
            return None;
        }
        let f_start = f(t_lo);
        if f_start < 0.0 {
            return None;
        }
        let horizontal = d[0].hypot(d[1]);
        // A ray descending faster than any slope of the surface crosses it once: the whole
        // stretch is one bracket. Otherwise march to the first sign change.
        let dt = if -d[2] > self.slope * horizontal {
            t_hi - t_lo
        } else if horizontal > 1e-12 {
            self.step / horizontal
        } else {
            t_hi - t_lo
        };
        let (mut a, mut f_a) = (t_lo, f_start);
        loop {
            let b = (a + dt).min(t_hi);
            let f_b = f(b);
            if f_b <= 0.0 {
                // Illinois regula falsi on the bracket [lo, hi], f(lo) > 0 ≥ f(hi).
                let (mut lo, mut hi, mut f_lo, mut f_hi) = (a, b, f_a, f_b);
                let mut side = 0i8;
                let mut t = hi;
                for _ in 0..MAX_REFINEMENTS {
                    t = if f_lo - f_hi > 0.0 {
                        hi - f_hi * (hi - lo) / (f_hi - f_lo)
                    } else {
                        hi
                    };
                    let ft = f(t);
                    if ft.abs() <= HEIGHT_TOLERANCE || hi - lo <= HEIGHT_TOLERANCE {
                        break;
                    }
                    if ft > 0.0 {
                        lo = t;
                        f_lo = ft;
                        if side == 1 {
                            f_hi *= 0.5;
                        }
                        side = 1;
                    } else {
                        hi = t;
                        f_hi = ft;
                        if side == -1 {
                            f_lo *= 0.5;
                        }
                        side = -1;
                    }
                }
                return (t > 0.0).then_some(t);
            }
            if b >= t_hi {
                return None;
            }
            (a, f_a) = (b, f_b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_ground_is_the_plane() {
        let g = Ground::flat();
        assert_eq!(g.height(3.0, -7.0), 0.0);
        let t = g
            .intersect([0.0, 0.0, 2.0], [0.6, 0.0, -0.8], 100.0)
            .unwrap();
        assert!((t - 2.5).abs() < 1e-12);
        assert_eq!(g.intersect([0.0, 0.0, 2.0], [1.0, 0.0, 0.0], 100.0), None);
        assert_eq!(g.intersect([0.0, 0.0, 2.0], [0.6, 0.0, -0.8], 2.0), None);
    }

    #[test]
    fn relief_is_bounded_continuous_and_seeded() {
        let cfg = GroundConfig::default();
        let g = Ground::new(&cfg, 3);
        let bound: f64 = cfg.relief.iter().map(|o| o.amplitude).sum();
        assert!((g.bound() - bound).abs() < 1e-15);
        let (mut lo, mut hi, mut worst_step) = (0.0f64, 0.0f64, 0.0f64);
        let mut prev = g.height(-50.0, 7.3);
        for k in 1..=20_000 {
            let x = -50.0 + k as f64 * 0.005;
            let z = g.height(x, 7.3);
            assert!(z.abs() <= bound, "{z}");
            lo = lo.min(z);
            hi = hi.max(z);
            worst_step = worst_step.max((z - prev).abs());
            prev = z;
        }
        // It does vary, by centimetres, and smoothly (a 5 mm step changes it by far less).
        assert!(hi - lo > 0.02, "{lo} {hi}");
        assert!(worst_step < 1e-3, "{worst_step}");
        assert_eq!(Ground::new(&cfg, 3), g);
        assert_ne!(Ground::new(&cfg, 4).height(1.3, 2.1), g.height(1.3, 2.1));
    }

    #[test]
    fn rays_meet_the_surface_at_its_first_crossing() {
        let g = Ground::new(&GroundConfig::default(), 9);
        for k in 0..200 {
            let a = k as f64 * 0.1;
            let e = -(0.5 + 0.12 * k as f64).to_radians();
            let d = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
            let o = [1.0, -2.0, 1.73];
            let t = g.intersect(o, d, 1000.0).expect("a descending ray hits");
            let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
            let miss = (p[2] - g.height(p[0], p[1])).abs();
            assert!(miss <= 1e-5, "ray {k}: {miss} m off the surface");
            // Above the ground all the way there, to a millimetre (a grazing ray may cut a bump
            // thinner than the march step).
            for i in 1..1000 {
                let s = t * i as f64 / 1000.0;
                let q = [o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]];
                assert!(q[2] > g.height(q[0], q[1]) - 1e-3, "ray {k} at {s}");
            }
        }
    }
}
