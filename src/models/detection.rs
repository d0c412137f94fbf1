//! Detection probabilities p_D(x): constant, a Gaussian fall-off with distance from a point
//! (the nonlinear benchmark's sensor), and a range/bearing field of view around the platform.
//!
//! All three read the position from components 0 and 2 of the state (the layout of the
//! built-in motion models, see [`crate::models`]); particle sets with fewer than three
//! components get p_D = 0. Not for: occlusion (see
//! [`crate::pipeline::people_tracking::models::occlusion`]) or appearance-based
//! detectability.

use crate::error::{ensure_positive, ensure_probability, Result};
use crate::filter::survival::clamp_probability;
use crate::filter::ParticleSet;
use crate::filter::{DetectionModel, StepContext};

/// p_D(x) = `self.0` everywhere.
///
/// Values outside [0, 1] are clamped when used (NaN counts as 0); [`ConstantDetection::new`]
/// rejects them up front.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConstantDetection(pub f64);

impl ConstantDetection {
    /// A detection probability `p` in [0, 1].
    pub fn new(p: f64) -> Result<Self> {
        ensure_probability("detection probability", p)?;
        Ok(ConstantDetection(p))
    }

    /// The probability actually used: `self.0` clamped to [0, 1], NaN mapped to 0.
    pub fn probability(&self) -> f64 {
        clamp_probability(self.0)
    }
}

impl DetectionModel for ConstantDetection {
    fn detection_probability(&self, _particles: &ParticleSet, _ctx: &StepContext, out: &mut [f64]) {
        out.fill(self.probability());
    }
}

/// p_D(x) = peak · exp(−((x − cx)² + (y − cy)²) / (2 · scale²)), a detection probability that
/// fades with the distance from a fixed world point `center = (cx, cy)`.
///
/// The nonlinear benchmark uses peak 0.98, scale 2000 m, centre at the origin
/// ([`GaussianRangeDetection::benchmark`]).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GaussianRangeDetection {
    peak: f64,
    scale: f64,
    center: [f64; 2],
}

impl GaussianRangeDetection {
    /// Peak probability `peak` ∈ [0, 1] at `center`, length scale `scale` > 0.
    pub fn new(peak: f64, scale: f64, center: [f64; 2]) -> Result<Self> {
        ensure_probability("detection peak", peak)?;
        ensure_positive("detection scale", scale)?;
        crate::error::ensure_finite("detection centre", &center)?;
        Ok(GaussianRangeDetection {
            peak,
            scale,
            center,
        })
    }

    /// The benchmark's p_D(x) = 0.98 · exp(−(x² + y²) / (2 · 2000²)).
    pub fn benchmark() -> Self {
        GaussianRangeDetection {
            peak: 0.98,
            scale: 2000.0,
            center: [0.0, 0.0],
        }
    }

    /// p_D at the planar position (x, y).
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let dx = x - self.center[0];
        let dy = y - self.center[1];
        let p = self.peak * (-(dx * dx + dy * dy) / (2.0 * self.scale * self.scale)).exp();
        clamp_probability(p)
    }

    /// Peak probability.
    pub fn peak(&self) -> f64 {
        self.peak
    }

    /// Length scale.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Centre of the fall-off.
    pub fn center(&self) -> [f64; 2] {
        self.center
    }
}

impl DetectionModel for GaussianRangeDetection {
    fn detection_probability(&self, particles: &ParticleSet, _ctx: &StepContext, out: &mut [f64]) {
        if particles.dim() < 3 {
            out.fill(0.0);
            return;
        }
        let xs = particles.component(0);
        let ys = particles.component(2);
        for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
            *o = self.at(x, y);
        }
    }
}

/// A sensor sector attached to the platform: p_D = `p_inside` for positions within
/// `max_range` of the sensor and within `half_angle` of its boresight, `p_outside` elsewhere.
///
/// The sensor sits at the platform pose (x, y, φ) of [`StepContext::platform_xy_heading`]
/// moved by the mounting offset (a, b) in the platform frame:
/// x_s = x + a cos φ − b sin φ, y_s = y + a sin φ + b cos φ; its boresight is the platform's
/// heading φ. A `half_angle` of π or more gives an all-round sensor.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FieldOfViewDetection {
    p_inside: f64,
    p_outside: f64,
    max_range: f64,
    half_angle: f64,
    offset: (f64, f64),
}

impl FieldOfViewDetection {
    /// A sector of radius `max_range` > 0 and half opening `half_angle` > 0 (radians), with
    /// probabilities `p_inside` and `p_outside` in [0, 1]; no mounting offset.
    pub fn new(p_inside: f64, p_outside: f64, max_range: f64, half_angle: f64) -> Result<Self> {
        ensure_probability("detection probability inside the field of view", p_inside)?;
        ensure_probability("detection probability outside the field of view", p_outside)?;
        ensure_positive("field-of-view range", max_range)?;
        ensure_positive("field-of-view half angle", half_angle)?;
        Ok(FieldOfViewDetection {
            p_inside,
            p_outside,
            max_range,
            half_angle,
            offset: (0.0, 0.0),
        })
    }

    /// The same sector with the sensor mounted at (a, b) in the platform frame.
    pub fn with_offset(mut self, a: f64, b: f64) -> Result<Self> {
        crate::error::ensure_finite("field-of-view mounting offset", &[a, b])?;
        self.offset = (a, b);
        Ok(self)
    }

    /// Whether the planar world point (x, y) lies in the sector at this step.
    pub fn contains(&self, x: f64, y: f64, ctx: &StepContext) -> bool {
        let (sx, sy, c, s) = self.sensor(ctx);
        self.contains_from(x, y, sx, sy, c, s)
    }

    /// Probability inside the sector.
    pub fn p_inside(&self) -> f64 {
        self.p_inside
    }

    /// Probability outside the sector.
    pub fn p_outside(&self) -> f64 {
        self.p_outside
    }

    /// Sensor position and (cos φ, sin φ) of its heading.
    pub(crate) fn sensor(&self, ctx: &StepContext) -> (f64, f64, f64, f64) {
        let (px, py, phi) = ctx.platform_xy_heading();
        let (s, c) = phi.sin_cos();
        let (a, b) = self.offset;
        (px + a * c - b * s, py + a * s + b * c, c, s)
    }

    /// Whether every point within the polar bounds `b` (taken from this sensor, see
    /// [`super::CloudBox::polar_from`]) is inside the sector with room to spare, so that
    /// [`FieldOfViewDetection::contains_from`] holds for each of them.
    #[cfg_attr(not(feature = "laser2d"), allow(dead_code))]
    pub(crate) fn surely_contains(&self, b: &super::PolarBounds) -> bool {
        let inside_range = b.d_max < self.max_range * (1.0 - 1e-9);
        let inside_angle = self.half_angle >= std::f64::consts::PI
            || (b.bearing_max < self.half_angle - 1e-9 && b.bearing_min > -self.half_angle + 1e-9);
        inside_range && inside_angle
    }

    /// |bearing| ≤ half angle is tested as cos(bearing) ≥ cos(half angle), i.e.
    /// l_x ≥ d · cos(half angle) (cos falls on [0, π]), which avoids an atan2 per particle.
    #[inline]
    pub(crate) fn contains_from(&self, x: f64, y: f64, sx: f64, sy: f64, c: f64, s: f64) -> bool {
        let dx = x - sx;
        let dy = y - sy;
        let lx = c * dx + s * dy;
        let ly = -s * dx + c * dy;
        let d2 = lx * lx + ly * ly;
        if d2 > self.max_range * self.max_range {
            return false;
        }
        self.half_angle >= std::f64::consts::PI || lx >= d2.sqrt() * self.half_angle.cos()
    }
}

impl FieldOfViewDetection {
    /// [`Self::contains_from`] on sensor-frame coordinates: `lx` and `d2` = l_x² + l_y², with
    /// `cos_half` = cos(half angle). The same answer, without branches, for loops over many
    /// points.
    #[inline(always)]
    #[cfg_attr(not(feature = "laser2d"), allow(dead_code))]
    pub(crate) fn contains_local(&self, lx: f64, d2: f64, cos_half: f64) -> bool {
        // as `contains_from`: a NaN distance is not out of range
        let in_range = (d2 <= self.max_range * self.max_range) | d2.is_nan();
        let in_angle = (self.half_angle >= std::f64::consts::PI) | (lx >= d2.sqrt() * cos_half);
        in_range & in_angle
    }

    /// cos(half angle), for [`Self::contains_local`].
    #[cfg_attr(not(feature = "laser2d"), allow(dead_code))]
    pub(crate) fn cos_half_angle(&self) -> f64 {
        self.half_angle.cos()
    }
}

impl DetectionModel for FieldOfViewDetection {
    fn detection_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        if particles.dim() < 3 {
            out.fill(0.0);
            return;
        }
        let (sx, sy, c, s) = self.sensor(ctx);
        let xs = particles.component(0);
        let ys = particles.component(2);
        for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
            *o = if self.contains_from(x, y, sx, sy, c, s) {
                self.p_inside
            } else {
                self.p_outside
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Vector3};
    use std::f64::consts::PI;

    fn set(points: &[(f64, f64)]) -> ParticleSet {
        let rows: Vec<Vec<f64>> = points.iter().map(|&(x, y)| vec![x, 0.0, y, 0.0]).collect();
        ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap()
    }

    #[test]
    fn constant_detection_fills_and_validates() {
        let mut out = vec![0.0; 2];
        ConstantDetection(0.98).detection_probability(
            &set(&[(0.0, 0.0), (1.0, 1.0)]),
            &StepContext::new(0, 0.0, 1.0),
            &mut out,
        );
        assert_eq!(out, vec![0.98, 0.98]);
        assert!(ConstantDetection::new(1.01).is_err());
    }

    #[test]
    fn gaussian_detection_matches_benchmark_formula() {
        let d = GaussianRangeDetection::benchmark();
        let mut out = vec![0.0; 3];
        d.detection_probability(
            &set(&[(0.0, 0.0), (2000.0, 0.0), (1200.0, -1600.0)]),
            &StepContext::new(0, 0.0, 1.0),
            &mut out,
        );
        // r = 0 → 0.98; r = 2000 → 0.98·e^(−1/2); (1200, −1600) has r = 2000 too
        assert!((out[0] - 0.98).abs() < 1e-15);
        assert!((out[1] - 0.98 * (-0.5f64).exp()).abs() < 1e-15);
        assert!((out[2] - out[1]).abs() < 1e-15);
        assert!(GaussianRangeDetection::new(0.9, 0.0, [0.0, 0.0]).is_err());
        let shifted = GaussianRangeDetection::new(0.5, 10.0, [3.0, 4.0]).unwrap();
        assert!((shifted.at(3.0, 4.0) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn field_of_view_follows_the_platform() {
        let fov = FieldOfViewDetection::new(0.9, 0.05, 50.0, PI / 4.0).unwrap();
        let ctx0 = StepContext::new(0, 0.0, 1.0);
        assert!(fov.contains(10.0, 0.0, &ctx0));
        assert!(!fov.contains(0.0, 10.0, &ctx0)); // 90° off boresight
        assert!(!fov.contains(60.0, 0.0, &ctx0)); // too far
                                                  // platform at (100, 0) facing +y: the point (100, 20) is straight ahead
        let mut ctx = ctx0;
        ctx.platform = Some(Isometry3::new(
            Vector3::new(100.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, PI / 2.0),
        ));
        assert!(fov.contains(100.0, 20.0, &ctx));
        assert!(!fov.contains(120.0, 0.0, &ctx));
        let mut out = vec![0.0; 2];
        fov.detection_probability(&set(&[(100.0, 20.0), (120.0, 0.0)]), &ctx, &mut out);
        assert_eq!(out, vec![0.9, 0.05]);
        // mounted 10 m ahead of the platform: sensor at (100, 10), the point (100, 5) is behind
        let ahead = fov.with_offset(10.0, 0.0).unwrap();
        assert!(!ahead.contains(100.0, 5.0, &ctx));
        assert!(ahead.contains(100.0, 15.0, &ctx));
    }

    #[test]
    fn short_states_are_never_detected() {
        let p = ParticleSet::zeroed(2, 3);
        let mut out = vec![1.0; 3];
        GaussianRangeDetection::benchmark().detection_probability(
            &p,
            &StepContext::new(0, 0.0, 1.0),
            &mut out,
        );
        assert_eq!(out, vec![0.0; 3]);
    }
}
