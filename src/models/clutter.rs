//! Clutter spread uniformly over the measurement space.
//!
//! κ(z) = λ_c / V: a Poisson number of false measurements with mean λ_c (`rate`), each uniform
//! over a region of volume V. The region itself is not checked — a measurement outside it
//! gets the same intensity — so that no measurement is ever impossible for the filter.
//! Not for: clutter that varies over the measurement space.

use crate::error::{Error, Result};
use crate::filter::{ClutterModel, StepContext};

/// Uniform clutter with mean count `rate` per scan over a region of volume `volume`.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UniformClutter {
    rate: f64,
    volume: f64,
}

impl UniformClutter {
    /// Mean count `rate` ≥ 0 over a region of volume `volume` > 0 (both finite).
    pub fn new(rate: f64, volume: f64) -> Result<Self> {
        if !(rate.is_finite() && rate >= 0.0) {
            return Err(Error::invalid(
                "clutter rate",
                format!("{rate} (must be finite and non-negative)"),
            ));
        }
        if !(volume.is_finite() && volume > 0.0) {
            return Err(Error::invalid(
                "clutter volume",
                format!("{volume} (must be finite and positive)"),
            ));
        }
        Ok(UniformClutter { rate, volume })
    }

    /// Clutter uniform on the rectangle [x₀, x₁] × [y₀, y₁] (position measurements).
    pub fn rectangle(rate: f64, x: [f64; 2], y: [f64; 2]) -> Result<Self> {
        Self::new(rate, (x[1] - x[0]) * (y[1] - y[0]))
    }

    /// Clutter uniform on a bearing interval of width `bearing_span` (radians) times the range
    /// interval [0, `max_range`] (range-bearing measurements): V = bearing_span · max_range.
    pub fn range_bearing(rate: f64, bearing_span: f64, max_range: f64) -> Result<Self> {
        if !(bearing_span > 0.0 && max_range > 0.0) {
            return Err(Error::invalid(
                "range-bearing clutter region",
                format!("bearing span {bearing_span}, range {max_range} (both must be positive)"),
            ));
        }
        Self::new(rate, bearing_span * max_range)
    }

    /// Mean number of clutter measurements per scan.
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// Volume of the clutter region.
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// κ = rate / volume.
    pub fn intensity(&self) -> f64 {
        self.rate / self.volume
    }
}

impl ClutterModel for UniformClutter {
    fn log_intensity(&self, _z: &[f64], _ctx: &StepContext) -> f64 {
        self.rate.ln() - self.volume.ln()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn benchmark_intensities() {
        let ctx = StepContext::new(0, 0.0, 1.0);
        let lin = UniformClutter::rectangle(30.0, [-1000.0, 1000.0], [-1000.0, 1000.0]).unwrap();
        assert!((lin.intensity() - 30.0 / 4e6).abs() < 1e-18);
        assert!((lin.log_intensity(&[0.0, 0.0], &ctx) - (30.0f64 / 4e6).ln()).abs() < 1e-12);
        let nl = UniformClutter::range_bearing(10.0, PI, 2000.0).unwrap();
        assert!((nl.intensity() - 10.0 / (PI * 2000.0)).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_regions() {
        assert!(UniformClutter::rectangle(30.0, [1.0, 1.0], [0.0, 1.0]).is_err());
        assert!(UniformClutter::rectangle(30.0, [1.0, 0.0], [0.0, 1.0]).is_err());
        assert!(UniformClutter::new(-1.0, 1.0).is_err());
        assert!(UniformClutter::range_bearing(1.0, 0.0, 1.0).is_err());
        let none = UniformClutter::new(0.0, 1.0).unwrap();
        assert_eq!(
            none.log_intensity(&[], &StepContext::new(0, 0.0, 1.0)),
            f64::NEG_INFINITY
        );
    }
}
