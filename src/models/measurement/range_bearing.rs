//! Range and bearing to an object from a sensor mounted on a (possibly moving) platform.
//!
//! The platform pose (x, y, φ) comes from [`StepContext::platform_xy_heading`] (the world
//! origin with φ = 0 when no platform is set). The sensor is mounted at (a, b) in the platform
//! frame, so in the world it sits at
//!
//! ```text
//! x_s = x + a cos φ − b sin φ
//! y_s = y + a sin φ + b cos φ
//! ```
//!
//! and looks along the platform heading. An object at world position (p_x, p_y) — components
//! 0 and 2 of the state — has offset (d_x, d_y) = (p_x − x_s, p_y − y_s), which in the sensor
//! frame reads l_x = cos φ d_x + sin φ d_y, l_y = −sin φ d_x + cos φ d_y. Then
//!
//! ```text
//! range   ρ = √(d_x² + d_y²)
//! bearing θ = atan2(l_y, l_x)   (BearingConvention::FromXAxis: counter-clockwise from the
//!                                heading, = atan2(d_y, d_x) − φ wrapped to (−π, π])
//! bearing θ = atan2(l_x, l_y)   (BearingConvention::FromYAxis: clockwise from the sensor's
//!                                y axis; with no platform this is the benchmark's atan2(x, y))
//! ```
//!
//! z = (ρ, θ) + w with w ~ N(0, diag(σ_ρ², σ_θ²)), and
//! log g(z | x) = −(ρ_z − ρ)²/(2σ_ρ²) − wrap(θ_z − θ)²/(2σ_θ²) − ln(2π σ_ρ σ_θ), the bearing
//! residual wrapped to (−π, π].
//!
//! Not for: three-dimensional (elevation) measurements or sensors that rotate independently of
//! the platform.

use crate::error::{Error, Result};
use crate::filter::{MeasurementModel, StepContext, TrackSummary};
use crate::filter::{Measurements, ParticleSet};
use crate::geometry::wrap_angle;
use crate::numerics::atan::{atan2, atan2_slices};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Default gate half-width, in standard deviations (see [`RangeBearing::gate`]).
pub const DEFAULT_GATE_SIGMAS: f64 = 5.0;

/// Where the bearing is measured from.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BearingConvention {
    /// Counter-clockwise from the sensor's x axis (its boresight): θ = atan2(l_y, l_x). The
    /// usual robotics convention.
    #[default]
    FromXAxis,
    /// Clockwise from the sensor's y axis: θ = atan2(l_x, l_y). The nonlinear RFS benchmark
    /// uses this with the sensor at the origin, θ = atan2(x, y).
    FromYAxis,
}

/// Range-bearing measurement model, z = [range, bearing].
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RangeBearing {
    sigma_range: f64,
    sigma_bearing: f64,
    offset: (f64, f64),
    convention: BearingConvention,
    gate_sigmas: f64,
}

/// Sensor position and heading in the world frame.
#[derive(Copy, Clone, Debug)]
struct Sensor {
    x: f64,
    y: f64,
    cos: f64,
    sin: f64,
}

impl RangeBearing {
    /// Range noise `sigma_range` (m) and bearing noise `sigma_bearing` (rad), both finite and
    /// positive; no mounting offset, [`BearingConvention::FromXAxis`], gate of
    /// [`DEFAULT_GATE_SIGMAS`].
    pub fn new(sigma_range: f64, sigma_bearing: f64) -> Result<Self> {
        for (name, v) in [
            ("sigma_range", sigma_range),
            ("sigma_bearing", sigma_bearing),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("range-bearing {name}"),
                    format!("{v} (must be finite and positive)"),
                ));
            }
        }
        Ok(RangeBearing {
            sigma_range,
            sigma_bearing,
            offset: (0.0, 0.0),
            convention: BearingConvention::FromXAxis,
            gate_sigmas: DEFAULT_GATE_SIGMAS,
        })
    }

    /// The nonlinear benchmark's sensor: σ_ρ = 10 m, σ_θ = 2°, bearing from the y axis,
    /// sensor at the origin.
    pub fn benchmark() -> Self {
        RangeBearing {
            sigma_range: 10.0,
            sigma_bearing: 2.0f64.to_radians(),
            offset: (0.0, 0.0),
            convention: BearingConvention::FromYAxis,
            gate_sigmas: DEFAULT_GATE_SIGMAS,
        }
    }

    /// Noise standard deviations (range in m, bearing in rad).
    pub fn noise(&self) -> (f64, f64) {
        (self.sigma_range, self.sigma_bearing)
    }

    /// The same model with the sensor mounted at (a, b) in the platform frame.
    pub fn with_offset(mut self, a: f64, b: f64) -> Result<Self> {
        crate::error::ensure_finite("range-bearing mounting offset", &[a, b])?;
        self.offset = (a, b);
        Ok(self)
    }

    /// The same model with another bearing convention.
    pub fn with_convention(mut self, convention: BearingConvention) -> Self {
        self.convention = convention;
        self
    }

    /// The same model with gate half-width `k` > 0 (+∞ disables gating).
    pub fn with_gate_sigmas(mut self, k: f64) -> Result<Self> {
        if k.is_nan() || k <= 0.0 {
            return Err(Error::invalid(
                "range-bearing gate",
                format!("{k} standard deviations (must be positive)"),
            ));
        }
        self.gate_sigmas = k;
        Ok(self)
    }

    /// Range noise standard deviation.
    pub fn sigma_range(&self) -> f64 {
        self.sigma_range
    }

    /// Bearing noise standard deviation (radians).
    pub fn sigma_bearing(&self) -> f64 {
        self.sigma_bearing
    }

    /// Mounting offset (a, b) in the platform frame.
    pub fn offset(&self) -> (f64, f64) {
        self.offset
    }

    /// The bearing convention.
    pub fn convention(&self) -> BearingConvention {
        self.convention
    }

    /// Gate half-width in standard deviations.
    pub fn gate_sigmas(&self) -> f64 {
        self.gate_sigmas
    }

    /// −ln(2π σ_ρ σ_θ), the log-likelihood at zero residual.
    pub fn log_normaliser(&self) -> f64 {
        -(TAU * self.sigma_range * self.sigma_bearing).ln()
    }

    /// The sensor's world pose (x_s, y_s, φ) at this step.
    pub fn sensor_pose(&self, ctx: &StepContext) -> (f64, f64, f64) {
        let (_, _, phi) = ctx.platform_xy_heading();
        let s = self.sensor(ctx);
        (s.x, s.y, phi)
    }

    fn sensor(&self, ctx: &StepContext) -> Sensor {
        let (px, py, phi) = ctx.platform_xy_heading();
        let (sin, cos) = phi.sin_cos();
        let (a, b) = self.offset;
        Sensor {
            x: px + a * cos - b * sin,
            y: py + a * sin + b * cos,
            cos,
            sin,
        }
    }

    #[inline(always)]
    fn measure(&self, s: &Sensor, px: f64, py: f64) -> (f64, f64) {
        let dx = px - s.x;
        let dy = py - s.y;
        let lx = s.cos * dx + s.sin * dy;
        let ly = -s.sin * dx + s.cos * dy;
        let bearing = match self.convention {
            BearingConvention::FromXAxis => atan2(ly, lx),
            BearingConvention::FromYAxis => atan2(lx, ly),
        };
        // sqrt, not hypot: no overflow at these scales, and hypot's care costs a third of a
        // likelihood evaluation
        ((dx * dx + dy * dy).sqrt(), bearing)
    }

    /// [`Self::measure`] of every particle, in passes that run on vector lanes: the
    /// sensor-frame offsets and ranges, then the bearings ([`atan2_slices`]); the same numbers.
    fn measure_all(
        &self,
        s: &Sensor,
        particles: &ParticleSet,
        ranges: &mut [f64],
        bearings: &mut [f64],
    ) {
        const CHUNK: usize = 64;
        let (mut lxs, mut lys) = ([0.0; CHUNK], [0.0; CHUNK]);
        let chunks = ranges
            .chunks_mut(CHUNK)
            .zip(bearings.chunks_mut(CHUNK))
            .zip(particles.component(0).chunks(CHUNK))
            .zip(particles.component(2).chunks(CHUNK));
        for (((r, b), xs), ys) in chunks {
            let m = r.len();
            let (lx, ly) = (&mut lxs[..m], &mut lys[..m]);
            for ((((r, lx), ly), &px), &py) in r
                .iter_mut()
                .zip(lx.iter_mut())
                .zip(ly.iter_mut())
                .zip(xs)
                .zip(ys)
            {
                let dx = px - s.x;
                let dy = py - s.y;
                *lx = s.cos * dx + s.sin * dy;
                *ly = -s.sin * dx + s.cos * dy;
                *r = (dx * dx + dy * dy).sqrt();
            }
            match self.convention {
                BearingConvention::FromXAxis => atan2_slices(ly, lx, b),
                BearingConvention::FromYAxis => atan2_slices(lx, ly, b),
            }
        }
    }

    /// The noiseless measurement [range, bearing] of `state` (position in components 0
    /// and 2). States with fewer than three components give [NaN, NaN]. One state at a time,
    /// so the bearing comes from the library's `atan2` (the particle loops use the cheaper
    /// one of equal precision).
    pub fn predict_measurement(&self, state: &[f64], ctx: &StepContext) -> [f64; 2] {
        match (state.first(), state.get(2)) {
            (Some(&x), Some(&y)) => {
                let s = self.sensor(ctx);
                let (dx, dy) = (x - s.x, y - s.y);
                let lx = s.cos * dx + s.sin * dy;
                let ly = -s.sin * dx + s.cos * dy;
                let bearing = match self.convention {
                    BearingConvention::FromXAxis => ly.atan2(lx),
                    BearingConvention::FromYAxis => lx.atan2(ly),
                };
                [(dx * dx + dy * dy).sqrt(), bearing]
            }
            _ => [f64::NAN, f64::NAN],
        }
    }

    /// The residual h(xᵢ) − `z` of every particle (position in components 0 and 2), range
    /// into `range` and bearing, wrapped to (−π, π], into `bearing` (one slot per particle;
    /// NaN for states with fewer than three components).
    pub fn residuals(
        &self,
        z: [f64; 2],
        particles: &ParticleSet,
        ctx: &StepContext,
        range: &mut [f64],
        bearing: &mut [f64],
    ) {
        if particles.dim() < 3 {
            range.fill(f64::NAN);
            bearing.fill(f64::NAN);
            return;
        }
        let s = self.sensor(ctx);
        let (xs, ys) = (particles.component(0), particles.component(2));
        for (((r, b), &x), &y) in range.iter_mut().zip(bearing.iter_mut()).zip(xs).zip(ys) {
            let (hr, hb) = self.measure(&s, x, y);
            *r = hr - z[0];
            *b = wrap_angle(hb - z[1]);
        }
    }

    /// The world point (x, y) at which a noiseless measurement would read `z` = [range,
    /// bearing] — the inverse of [`RangeBearing::predict_measurement`] on positions.
    pub fn to_cartesian(&self, z: [f64; 2], ctx: &StepContext) -> [f64; 2] {
        let s = self.sensor(ctx);
        let [range, bearing] = z;
        let local_angle = match self.convention {
            BearingConvention::FromXAxis => bearing,
            BearingConvention::FromYAxis => FRAC_PI_2 - bearing,
        };
        let (sa, ca) = local_angle.sin_cos();
        let (lx, ly) = (range * ca, range * sa);
        [s.x + s.cos * lx - s.sin * ly, s.y + s.sin * lx + s.cos * ly]
    }
}

/// The gate of one track in measurement space (see [`RangeBearing`]'s `gate`): the
/// predicted measurement of the track's mean and the admitted half-widths, computed once per
/// track.
#[derive(Clone, Copy, Debug)]
struct GateWindow {
    /// Admit everything (a summary without positions, or NaN in it).
    all: bool,
    rho: f64,
    theta: f64,
    range_half_width: f64,
    /// Half-width in bearing; infinite when the cloud reaches the sensor.
    bearing_half_width: f64,
}

impl GateWindow {
    fn admits(&self, z: &[f64]) -> bool {
        let [zr, zb] = match z {
            [r, b] if r.is_finite() && b.is_finite() => [*r, *b],
            _ => return false,
        };
        self.all
            || ((zr - self.rho).abs() <= self.range_half_width
                && wrap_angle(zb - self.theta).abs() <= self.bearing_half_width)
    }
}

impl RangeBearing {
    /// The gate window of `track`: `z` is admitted when it falls around the predicted
    /// measurement of the track's mean position, in measurement space: |z_ρ − ρ̂| ≤ k·(σ_ρ + s) and
    /// |z_θ − θ̂| ≤ k·σ_θ + asin(min(1, k·s / ρ̂)), where k is the gate width and
    /// s = √(s_x² + s_y²) the track's position spread. A particle cloud of radius k·s at range ρ̂
    /// subtends at most that bearing interval, so the window is conservative; a track whose
    /// cloud reaches the sensor admits every bearing.
    fn gate_window(&self, track: &TrackSummary, ctx: &StepContext) -> GateWindow {
        let mut w = GateWindow {
            all: true,
            rho: 0.0,
            theta: 0.0,
            range_half_width: f64::INFINITY,
            bearing_half_width: f64::INFINITY,
        };
        if track.mean.len() < 3 || track.std.len() < 3 {
            return w;
        }
        let s = self.sensor(ctx);
        let (rho, theta) = self.measure(&s, track.mean[0], track.mean[2]);
        let spread = track.std[0].hypot(track.std[2]);
        // NaN in the summary: admit rather than silently drop.
        if !(rho.is_finite() && spread.is_finite()) {
            return w;
        }
        let k = self.gate_sigmas;
        let reach = if rho > 0.0 {
            (k * spread / rho).min(1.0)
        } else {
            1.0
        };
        w.all = false;
        w.rho = rho;
        w.theta = theta;
        w.range_half_width = k * (self.sigma_range + spread);
        if reach < 1.0 {
            w.bearing_half_width = k * self.sigma_bearing + reach.asin();
        }
        w
    }
}

impl MeasurementModel for RangeBearing {
    fn measurement_dim(&self) -> usize {
        2
    }

    fn state_dim(&self) -> Option<usize> {
        // reads the position in components 0 and 2
        Some(3)
    }

    fn log_likelihood(
        &self,
        z: &[f64],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [f64],
    ) {
        let (zr, zb) = match z {
            [r, b] if r.is_finite() && b.is_finite() => (*r, *b),
            _ => {
                out.fill(f64::NEG_INFINITY);
                return;
            }
        };
        if particles.dim() < 3 {
            out.fill(f64::NEG_INFINITY);
            return;
        }
        let s = self.sensor(ctx);
        let norm = self.log_normaliser();
        let inv_r = 1.0 / self.sigma_range;
        let inv_b = 1.0 / self.sigma_bearing;
        let xs = particles.component(0);
        let ys = particles.component(2);
        for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
            let (r, b) = self.measure(&s, x, y);
            let er = (zr - r) * inv_r;
            let eb = wrap_angle(zb - b) * inv_b;
            let l = norm - 0.5 * (er * er + eb * eb);
            *o = if l.is_nan() { f64::NEG_INFINITY } else { l };
        }
    }

    /// Admits `z` inside the track's gate window (`gate_window`), which is conservative for
    /// the whole particle cloud.
    fn gate(&self, z: &[f64], track: &TrackSummary, ctx: &StepContext) -> bool {
        self.gate_window(track, ctx).admits(z)
    }

    fn gate_all(
        &self,
        zs: &Measurements,
        track: &TrackSummary,
        ctx: &StepContext,
        out: &mut Vec<usize>,
    ) {
        let window = self.gate_window(track, ctx);
        out.clear();
        out.extend((0..zs.len()).filter(|&j| window.admits(zs.get(j))));
    }

    fn log_likelihood_batch(
        &self,
        zs: &[&[f64]],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [Vec<f64>],
    ) {
        if particles.dim() < 3 {
            out.iter_mut().for_each(|o| o.fill(f64::NEG_INFINITY));
            return;
        }
        // The predicted measurement of every particle, once for all measurements.
        let s = self.sensor(ctx);
        let n = particles.len();
        let (mut ranges, mut bearings) = (vec![0.0; n], vec![0.0; n]);
        self.measure_all(&s, particles, &mut ranges, &mut bearings);
        let norm = self.log_normaliser();
        let inv_r = 1.0 / self.sigma_range;
        let inv_b = 1.0 / self.sigma_bearing;
        for (z, o) in zs.iter().zip(out.iter_mut()) {
            let (zr, zb) = match z {
                [r, b] if r.is_finite() && b.is_finite() => (*r, *b),
                _ => {
                    o.fill(f64::NEG_INFINITY);
                    continue;
                }
            };
            if zb.abs() <= PI {
                // Both bearings lie in [−π, π], so their difference needs at most one turn
                // added or removed: the same numbers as `wrap_angle`, without its branch
                // into the general case, in a loop that runs on vector lanes.
                for ((o, &r), &b) in o.iter_mut().zip(&ranges).zip(&bearings) {
                    let er = (zr - r) * inv_r;
                    let a = zb - b;
                    let w = if a > PI {
                        a - TAU
                    } else if a <= -PI {
                        a + TAU
                    } else {
                        a
                    };
                    let eb = w * inv_b;
                    let l = norm - 0.5 * (er * er + eb * eb);
                    *o = if l.is_nan() { f64::NEG_INFINITY } else { l };
                }
            } else {
                for ((o, &r), &b) in o.iter_mut().zip(&ranges).zip(&bearings) {
                    let er = (zr - r) * inv_r;
                    let eb = wrap_angle(zb - b) * inv_b;
                    let l = norm - 0.5 * (er * er + eb * eb);
                    *o = if l.is_nan() { f64::NEG_INFINITY } else { l };
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Vector3};

    fn ctx() -> StepContext {
        StepContext::new(0, 0.0, 1.0)
    }

    fn with_pose(x: f64, y: f64, phi: f64) -> StepContext {
        let mut c = ctx();
        c.platform = Some(Isometry3::new(
            Vector3::new(x, y, 0.0),
            Vector3::new(0.0, 0.0, phi),
        ));
        c
    }

    fn one(x: f64, y: f64) -> ParticleSet {
        ParticleSet::from_rows(&[vec![x, 0.0, y, 0.0]], &[1.0]).unwrap()
    }

    #[test]
    fn wrap_angle_lands_in_half_open_interval() {
        assert!((wrap_angle(358f64.to_radians()) - (-2f64).to_radians()).abs() < 1e-12);
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-7.0) - (-7.0 + TAU)).abs() < 1e-12);
        assert_eq!(wrap_angle(0.5), 0.5);
    }

    #[test]
    fn zero_residual_log_likelihood_is_the_normaliser() {
        let m = RangeBearing::new(10.0, 0.02).unwrap();
        let p = one(30.0, 40.0);
        let z = m.predict_measurement(&p.state(0), &ctx());
        assert!((z[0] - 50.0).abs() < 1e-12);
        assert!((z[1] - (40.0f64).atan2(30.0)).abs() < 1e-12);
        let mut out = vec![0.0];
        m.log_likelihood(&z, &p, &ctx(), &mut out);
        assert!((out[0] + (TAU * 10.0 * 0.02).ln()).abs() < 1e-12);
    }

    #[test]
    fn bearing_residual_wraps_across_pi() {
        let sb = 1f64.to_radians();
        let m = RangeBearing::new(1.0, sb).unwrap();
        // object at bearing −179° (range 100): behind-left, just below the negative x axis
        let h = (-179f64).to_radians();
        let p = one(100.0 * h.cos(), 100.0 * h.sin());
        let mut out = vec![0.0];
        m.log_likelihood(&[100.0, 179f64.to_radians()], &p, &ctx(), &mut out);
        // residual is 2°, i.e. two standard deviations: −0.5·4 = −2
        let expected = m.log_normaliser() - 2.0;
        assert!((out[0] - expected).abs() < 1e-9, "{} vs {expected}", out[0]);
    }

    #[test]
    fn mounting_offset_with_heading_quarter_turn() {
        // platform at (1, 2) facing +y; sensor mounted 3 ahead, 1 to the left:
        // x_s = 1 + 3·cos(π/2) − 1·sin(π/2) = 0, y_s = 2 + 3·sin(π/2) + 1·cos(π/2) = 5
        let m = RangeBearing::new(1.0, 0.01)
            .unwrap()
            .with_offset(3.0, 1.0)
            .unwrap();
        let c = with_pose(1.0, 2.0, FRAC_PI_2);
        let (sx, sy, phi) = m.sensor_pose(&c);
        assert!(sx.abs() < 1e-12 && (sy - 5.0).abs() < 1e-12 && (phi - FRAC_PI_2).abs() < 1e-12);
        // straight ahead of the sensor (along +y) → bearing 0
        let z = m.predict_measurement(&[0.0, 0.0, 15.0, 0.0], &c);
        assert!((z[0] - 10.0).abs() < 1e-12 && z[1].abs() < 1e-12);
        // world −x is to the sensor's left → bearing +π/2
        let z = m.predict_measurement(&[-10.0, 0.0, 5.0, 0.0], &c);
        assert!((z[0] - 10.0).abs() < 1e-12 && (z[1] - FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn from_y_axis_is_the_benchmark_convention() {
        let m = RangeBearing::benchmark();
        let z = m.predict_measurement(&[1.0, 0.0, 0.0, 0.0, 0.0], &ctx());
        assert!((z[1] - FRAC_PI_2).abs() < 1e-12);
        let z = m.predict_measurement(&[-300.0, 0.0, 400.0, 0.0, 0.0], &ctx());
        assert!((z[0] - 500.0).abs() < 1e-12);
        assert!((z[1] - (-300.0f64).atan2(400.0)).abs() < 1e-12);
    }

    #[test]
    fn to_cartesian_inverts_prediction() {
        for conv in [BearingConvention::FromXAxis, BearingConvention::FromYAxis] {
            let m = RangeBearing::new(1.0, 0.01)
                .unwrap()
                .with_offset(0.5, -0.25)
                .unwrap()
                .with_convention(conv);
            let c = with_pose(-3.0, 7.0, 2.5);
            for &(x, y) in &[(10.0, 3.0), (-40.0, -2.0), (0.0, 100.0), (-3.0, -50.0)] {
                let z = m.predict_measurement(&[x, 0.0, y, 0.0], &c);
                let [cx, cy] = m.to_cartesian(z, &c);
                assert!((cx - x).abs() < 1e-9 && (cy - y).abs() < 1e-9, "{conv:?}");
            }
        }
    }

    proptest::proptest! {
        /// Gating all measurements of a track at once admits exactly those the gate of one
        /// measurement admits: tracks near and far, tight and spread, with NaN or short
        /// summaries, from a moved and turned platform.
        #[test]
        fn gate_all_admits_what_gate_admits(
            mean in (-15.0f64..15.0, -15.0f64..15.0),
            spread in (0.0f64..3.0, 0.0f64..3.0),
            zs in proptest::collection::vec((0.0f64..20.0, -3.5f64..3.5), 0..12),
            pose in (-2.0f64..2.0, -2.0f64..2.0, -3.0f64..3.0),
            broken in 0u8..4,
        ) {
            let m = RangeBearing::new(0.2, 0.035).unwrap().with_offset(0.3, 0.1).unwrap();
            let mut c = StepContext::new(1, 0.1, 0.1);
            c.platform = Some(Isometry3::new(
                Vector3::new(pose.0, pose.1, 0.0),
                Vector3::new(0.0, 0.0, pose.2),
            ));
            let mut track = TrackSummary {
                mean: vec![mean.0, 0.0, mean.1, 0.0],
                std: vec![spread.0, 0.1, spread.1, 0.1],
                tag: None,
            };
            match broken {
                1 => track.mean[0] = f64::NAN,
                2 => track.std.truncate(2),
                _ => {}
            }
            let rows: Vec<[f64; 2]> = zs.iter().map(|&(r, b)| [r, b]).collect();
            let z = Measurements::from_rows(2, &rows).unwrap();
            let mut all = vec![99];
            m.gate_all(&z, &track, &c, &mut all);
            let one: Vec<usize> = (0..z.len()).filter(|&j| m.gate(z.get(j), &track, &c)).collect();
            // The rule as documented, from the library's atan2.
            let rule = |z: &[f64]| {
                if track.mean.len() < 3 || track.std.len() < 3 {
                    return true;
                }
                let h = m.predict_measurement(&track.mean, &c);
                let s = track.std[0].hypot(track.std[2]);
                if !(h[0].is_finite() && s.is_finite()) {
                    return true;
                }
                let k = m.gate_sigmas();
                let reach = if h[0] > 0.0 { (k * s / h[0]).min(1.0) } else { 1.0 };
                (z[0] - h[0]).abs() <= k * (0.2 + s)
                    && (reach >= 1.0 || wrap_angle(z[1] - h[1]).abs() <= k * 0.035 + reach.asin())
            };
            let by_rule: Vec<usize> = (0..z.len()).filter(|&j| rule(z.get(j))).collect();
            proptest::prop_assert_eq!(&all, &one);
            proptest::prop_assert_eq!(&all, &by_rule);
        }
    }

    #[test]
    fn gate_is_conservative_and_rejects_far_measurements() {
        let m = RangeBearing::benchmark();
        let track = TrackSummary {
            mean: vec![0.0, 0.0, 1000.0, 0.0, 0.0],
            std: vec![20.0, 5.0, 20.0, 5.0, 0.01],
            tag: None,
        };
        // 3σ in range and 3σ in bearing away from the mean: inside a 5σ gate
        let z = [1030.0, 6f64.to_radians()];
        assert!(m.gate(&z, &track, &ctx()));
        // the opposite side of the sensor
        assert!(!m.gate(&[1000.0, PI], &track, &ctx()));
        assert!(!m.gate(&[1.0], &track, &ctx()));
        assert!(RangeBearing::new(0.0, 1.0).is_err());
        assert!(RangeBearing::new(1.0, 1.0)
            .unwrap()
            .with_gate_sigmas(0.0)
            .is_err());
    }

    #[test]
    fn gate_window_is_tight_in_range_and_wide_in_bearing() {
        let m = RangeBearing::benchmark();
        // mean at range 1000 straight along +y (bearing 0), spread s = √(20² + 20²) = 28.3 m:
        // range half-width 5·(10 + 28.3) = 191 m; bearing half-width 5·2° + asin(141/1000) = 18.1°
        let track = TrackSummary {
            mean: vec![0.0, 0.0, 1000.0, 0.0, 0.0],
            std: vec![20.0, 5.0, 20.0, 5.0, 0.01],
            tag: None,
        };
        assert!(m.gate(&[1180.0, 0.0], &track, &ctx()));
        assert!(!m.gate(&[1200.0, 0.0], &track, &ctx()));
        assert!(m.gate(&[1000.0, 18f64.to_radians()], &track, &ctx()));
        assert!(!m.gate(&[1000.0, 18.5f64.to_radians()], &track, &ctx()));
        // a cloud that reaches the sensor admits every bearing
        let near = TrackSummary {
            mean: vec![0.0, 0.0, 10.0, 0.0, 0.0],
            std: vec![5.0, 1.0, 5.0, 1.0, 0.0],
            tag: None,
        };
        assert!(m.gate(&[10.0, PI], &near, &ctx()));
    }

    #[test]
    fn batch_likelihood_equals_one_at_a_time() {
        let m = RangeBearing::new(2.0, 0.05)
            .unwrap()
            .with_offset(0.3, -0.1)
            .unwrap();
        let mut rng = crate::rng::seeded(5);
        let p = ParticleSet::sampled(&[3.0, 0.0, 4.0, 0.0], &[1.0, 1.0, 1.0, 1.0], 50, &mut rng);
        let zs: [&[f64]; 3] = [&[5.0, 0.9], &[4.0, -3.1], &[f64::NAN, 0.0]];
        let mut batch = vec![vec![0.0; 50]; 3];
        m.log_likelihood_batch(&zs, &p, &ctx(), &mut batch);
        for (z, row) in zs.iter().zip(&batch) {
            let mut one = vec![0.0; 50];
            m.log_likelihood(z, &p, &ctx(), &mut one);
            assert_eq!(&one, row);
        }
    }

    proptest::proptest! {
        /// The batch's one-turn wrap gives bit for bit the single-measurement likelihood, for
        /// bearings anywhere around the sensor and beyond ±π.
        #[test]
        fn batch_equals_one_at_a_time_for_any_bearing(
            zs in proptest::collection::vec((0.0f64..20.0, -7.0f64..7.0), 1..5),
            seed in 0u64..1000,
            heading in -3.2f64..3.2,
            from_y in proptest::bool::ANY,
        ) {
            // 150 particles: two whole passes of 64 and a partial one
            let convention = if from_y {
                BearingConvention::FromYAxis
            } else {
                BearingConvention::FromXAxis
            };
            let m = RangeBearing::new(0.2, 0.03)
                .unwrap()
                .with_offset(0.1, 0.2)
                .unwrap()
                .with_convention(convention);
            let mut rng = crate::rng::seeded(seed);
            let p = ParticleSet::sampled(&[-1.0, 0.0, 0.5, 0.0], &[4.0, 1.0, 4.0, 1.0], 150, &mut rng);
            let c = with_pose(0.3, -0.2, heading);
            let rows: Vec<[f64; 2]> = zs.iter().map(|z| [z.0, z.1]).collect();
            let refs: Vec<&[f64]> = rows.iter().map(|r| &r[..]).collect();
            let mut batch = vec![vec![0.0; 150]; refs.len()];
            m.log_likelihood_batch(&refs, &p, &c, &mut batch);
            for (z, row) in refs.iter().zip(&batch) {
                let mut one = vec![0.0; 150];
                m.log_likelihood(z, &p, &c, &mut one);
                proptest::prop_assert_eq!(&one, row);
            }
        }
    }

    #[test]
    fn bad_input_gives_minus_infinity() {
        let m = RangeBearing::new(1.0, 0.1).unwrap();
        let p = one(1.0, 1.0);
        let mut out = vec![0.0];
        m.log_likelihood(&[1.0, f64::NAN], &p, &ctx(), &mut out);
        assert_eq!(out[0], f64::NEG_INFINITY);
        m.log_likelihood(&[1.0, 0.0, 0.0], &p, &ctx(), &mut out);
        assert_eq!(out[0], f64::NEG_INFINITY);
        assert!(m.predict_measurement(&[1.0], &ctx())[0].is_nan());
    }
}
