//! Direct, noisy observation of an object's position in two or three dimensions.
//!
//! z = H x + w with w ~ N(0, R), R = diag(σ₁², …, σ_d²), where H picks the position
//! components 0, 2 (, 4) of the interleaved state `[x, ẋ, y, ẏ(, z, ż)]`:
//!
//! ```text
//! log g(z | x) = − Σⱼ [ (zⱼ − x₂ⱼ)² / (2 σⱼ²) + ln σⱼ ] − (d/2) ln 2π
//! ```
//!
//! The gate admits z when every axis satisfies |zⱼ − m₂ⱼ| ≤ k · √(σⱼ² + s₂ⱼ²) with m and s the
//! track's mean and standard deviation and k = `gate_sigmas` (5 by default).
//! Not for: measurements in sensor coordinates (see [`crate::models::RangeBearing`]).

use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{MeasurementModel, StepContext, TrackSummary};

/// Default gate half-width, in combined standard deviations per axis.
pub const DEFAULT_GATE_SIGMAS: f64 = 5.0;

/// Position measurement with independent Gaussian noise per axis.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PositionMeasurement {
    dims: usize,
    sigma: [f64; 3],
    gate_sigmas: f64,
}

impl PositionMeasurement {
    /// `dims` axes (2 or 3), the same noise standard deviation `sigma` > 0 on each.
    pub fn new(dims: usize, sigma: f64) -> Result<Self> {
        if dims != 2 && dims != 3 {
            return Err(Error::invalid(
                "position measurement dimension",
                format!("{dims} axes (must be 2 or 3)"),
            ));
        }
        Self::per_axis(&vec![sigma; dims])
    }

    /// One noise standard deviation per axis (2 or 3 values, each > 0).
    pub fn per_axis(sigmas: &[f64]) -> Result<Self> {
        let dims = sigmas.len();
        if dims != 2 && dims != 3 {
            return Err(Error::invalid(
                "position measurement dimension",
                format!("{dims} axes (must be 2 or 3)"),
            ));
        }
        let mut sigma = [1.0; 3];
        for (j, &s) in sigmas.iter().enumerate() {
            if !(s.is_finite() && s > 0.0) {
                return Err(Error::invalid(
                    format!("position measurement sigma of axis {j}"),
                    format!("{s} (must be finite and positive)"),
                ));
            }
            sigma[j] = s;
        }
        Ok(PositionMeasurement {
            dims,
            sigma,
            gate_sigmas: DEFAULT_GATE_SIGMAS,
        })
    }

    /// The same model with gate half-width `k` > 0 (in standard deviations; +∞ disables
    /// gating).
    pub fn with_gate_sigmas(mut self, k: f64) -> Result<Self> {
        if k.is_nan() || k <= 0.0 {
            return Err(Error::invalid(
                "position measurement gate",
                format!("{k} standard deviations (must be positive)"),
            ));
        }
        self.gate_sigmas = k;
        Ok(self)
    }

    /// Number of measured axes.
    pub fn dims(&self) -> usize {
        self.dims
    }

    /// Noise standard deviation of each axis.
    pub fn sigmas(&self) -> &[f64] {
        &self.sigma[..self.dims]
    }

    /// Gate half-width in standard deviations.
    pub fn gate_sigmas(&self) -> f64 {
        self.gate_sigmas
    }

    /// −(Σ ln σⱼ + (d/2) ln 2π), the log-likelihood at zero residual.
    pub fn log_normaliser(&self) -> f64 {
        let half_ln_2pi = 0.5 * (2.0 * std::f64::consts::PI).ln();
        -self
            .sigmas()
            .iter()
            .map(|s| s.ln() + half_ln_2pi)
            .sum::<f64>()
    }
}

impl MeasurementModel for PositionMeasurement {
    fn measurement_dim(&self) -> usize {
        self.dims
    }

    fn state_dim(&self) -> Option<usize> {
        // reads the positions in components 0, 2 (and 4)
        Some(2 * self.dims - 1)
    }

    fn log_likelihood(
        &self,
        z: &[f64],
        particles: &ParticleSet,
        _ctx: &StepContext,
        out: &mut [f64],
    ) {
        if z.len() != self.dims
            || particles.dim() < 2 * self.dims - 1
            || z.iter().any(|v| !v.is_finite())
        {
            out.fill(f64::NEG_INFINITY);
            return;
        }
        out.fill(self.log_normaliser());
        for (j, (&zj, &sj)) in z.iter().zip(self.sigmas()).enumerate() {
            let inv = 1.0 / sj;
            for (o, &x) in out.iter_mut().zip(particles.component(2 * j)) {
                let r = (zj - x) * inv;
                *o -= 0.5 * r * r;
            }
        }
        for o in out.iter_mut() {
            if o.is_nan() {
                *o = f64::NEG_INFINITY;
            }
        }
    }

    fn gate(&self, z: &[f64], track: &TrackSummary, _ctx: &StepContext) -> bool {
        if z.len() != self.dims {
            return false;
        }
        let need = 2 * self.dims - 1;
        if track.mean.len() < need || track.std.len() < need {
            return true;
        }
        z.iter()
            .zip(self.sigmas())
            .enumerate()
            .all(|(j, (&zj, &sj))| {
                let m = track.mean[2 * j];
                let s = track.std[2 * j];
                (zj - m).abs() <= self.gate_sigmas * (sj * sj + s * s).sqrt()
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn ctx() -> StepContext {
        StepContext::new(0, 0.0, 1.0)
    }

    #[test]
    fn log_likelihood_matches_hand_computation() {
        let m = PositionMeasurement::per_axis(&[10.0, 5.0]).unwrap();
        let rows = vec![vec![1.0, 0.0, 2.0, 0.0], vec![11.0, 9.0, -3.0, 9.0]];
        let p = ParticleSet::from_rows(&rows, &[1.0, 1.0]).unwrap();
        let mut out = vec![0.0; 2];
        m.log_likelihood(&[1.0, 2.0], &p, &ctx(), &mut out);
        let at_zero = -(2.0 * PI * 10.0 * 5.0f64).ln();
        assert!((out[0] - at_zero).abs() < 1e-12);
        // residual (−10, 5): −0.5·(1 + 1) = −1
        assert!((out[1] - (at_zero - 1.0)).abs() < 1e-12);
    }

    #[test]
    fn three_dimensional_uses_components_0_2_4() {
        let m = PositionMeasurement::new(3, 2.0).unwrap();
        let rows = vec![vec![1.0, 100.0, 2.0, 100.0, 3.0, 100.0]];
        let p = ParticleSet::from_rows(&rows, &[1.0]).unwrap();
        let mut out = vec![0.0];
        m.log_likelihood(&[1.0, 2.0, 5.0], &p, &ctx(), &mut out);
        let expected = -1.5 * (2.0 * PI).ln() - 3.0 * 2.0f64.ln() - 0.5;
        assert!((out[0] - expected).abs() < 1e-12);
    }

    #[test]
    fn bad_input_gives_minus_infinity_not_nan() {
        let m = PositionMeasurement::new(2, 1.0).unwrap();
        let p = ParticleSet::zeroed(4, 2);
        let mut out = vec![0.0; 2];
        m.log_likelihood(&[1.0], &p, &ctx(), &mut out);
        assert_eq!(out, vec![f64::NEG_INFINITY; 2]);
        m.log_likelihood(&[f64::NAN, 0.0], &p, &ctx(), &mut out);
        assert_eq!(out, vec![f64::NEG_INFINITY; 2]);
        let rows = vec![vec![f64::NAN, 0.0, 0.0, 0.0], vec![0.0; 4]];
        let p = ParticleSet::from_rows(&rows, &[1.0, 1.0]).unwrap();
        m.log_likelihood(&[0.0, 0.0], &p, &ctx(), &mut out);
        assert_eq!(out[0], f64::NEG_INFINITY);
        assert!(out[1].is_finite());
    }

    #[test]
    fn gate_uses_combined_spread_per_axis() {
        let m = PositionMeasurement::new(2, 3.0)
            .unwrap()
            .with_gate_sigmas(2.0)
            .unwrap();
        let track = TrackSummary {
            mean: vec![0.0, 0.0, 0.0, 0.0],
            std: vec![4.0, 1.0, 4.0, 1.0],
            tag: None,
        };
        // combined std 5, gate 10 per axis
        assert!(m.gate(&[10.0, -10.0], &track, &ctx()));
        assert!(!m.gate(&[10.1, 0.0], &track, &ctx()));
        assert!(!m.gate(&[0.0, -10.1], &track, &ctx()));
        assert!(!m.gate(&[0.0], &track, &ctx()));
        assert!(PositionMeasurement::new(2, 0.0).is_err());
        assert!(PositionMeasurement::new(4, 1.0).is_err());
        assert!(PositionMeasurement::new(2, 1.0)
            .unwrap()
            .with_gate_sigmas(-1.0)
            .is_err());
    }
}
