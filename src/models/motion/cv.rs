//! Constant-velocity motion (discretised white-noise acceleration) in two or three dimensions.
//!
//! Each axis is an independent position/velocity pair driven by an acceleration that is white
//! noise, held constant over one step. Over a step of length T:
//!
//! ```text
//! per axis:  A = [[1, T],      Q_axis = σ² [[T⁴/4, T³/2],
//!                 [0, 1]]                   [T³/2, T² ]]
//! F = blockdiag(A, A[, A]),  Q = blockdiag(Q_axis, Q_axis[, Q_axis])
//! ```
//!
//! with the state laid out `[x, ẋ, y, ẏ]` (2 axes) or `[x, ẋ, y, ẏ, z, ż]` (3 axes). The noise
//! is sampled exactly: Q_axis = σ² b bᵀ with b = [T²/2, T]ᵀ has rank one, so one draw
//! a ~ N(0, σ²) per axis and particle moves the position by T²/2 · a and the velocity by T · a.
//!
//! Not for: manoeuvring objects (see [`crate::models::CoordinatedTurn`]) or ego-motion
//! compensation.

use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{StepContext, TransitionModel};
use crate::rng::FilterRng;
use nalgebra::DMatrix;
use rand_distr::{Distribution, StandardNormal};

/// Constant-velocity transition with white-noise acceleration of standard deviation
/// `sigma_accel` on every axis.
///
/// `dims` is the number of spatial axes (2 or 3); the state has `2 · dims` components laid out
/// `[x, ẋ, y, ẏ(, z, ż)]`. The step length is `ctx.dt`. Particle sets with fewer components
/// than [`TransitionModel::state_dim`] are left unchanged; extra components are not touched.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConstantVelocity {
    dims: usize,
    sigma_accel: f64,
}

impl ConstantVelocity {
    /// A model with `dims` axes (2 or 3) and acceleration noise `sigma_accel` (m/s², ≥ 0).
    pub fn new(dims: usize, sigma_accel: f64) -> Result<Self> {
        if dims != 2 && dims != 3 {
            return Err(Error::invalid(
                "constant-velocity dimension",
                format!("{dims} axes (must be 2 or 3)"),
            ));
        }
        if !(sigma_accel.is_finite() && sigma_accel >= 0.0) {
            return Err(Error::invalid(
                "constant-velocity sigma_accel",
                format!("{sigma_accel} (must be finite and non-negative)"),
            ));
        }
        Ok(ConstantVelocity { dims, sigma_accel })
    }

    /// A planar model, state `[x, ẋ, y, ẏ]`.
    pub fn planar(sigma_accel: f64) -> Result<Self> {
        Self::new(2, sigma_accel)
    }

    /// A spatial model, state `[x, ẋ, y, ẏ, z, ż]`.
    pub fn spatial(sigma_accel: f64) -> Result<Self> {
        Self::new(3, sigma_accel)
    }

    /// Number of spatial axes (2 or 3).
    pub fn dims(&self) -> usize {
        self.dims
    }

    /// Standard deviation of the acceleration noise.
    pub fn sigma_accel(&self) -> f64 {
        self.sigma_accel
    }

    /// The transition matrix F for a step of length `dt`.
    pub fn transition_matrix(&self, dt: f64) -> DMatrix<f64> {
        let n = 2 * self.dims;
        let mut f = DMatrix::identity(n, n);
        for axis in 0..self.dims {
            f[(2 * axis, 2 * axis + 1)] = dt;
        }
        f
    }

    /// The process-noise covariance Q for a step of length `dt`.
    pub fn process_covariance(&self, dt: f64) -> DMatrix<f64> {
        let n = 2 * self.dims;
        let s2 = self.sigma_accel * self.sigma_accel;
        let mut q = DMatrix::zeros(n, n);
        for axis in 0..self.dims {
            let (p, v) = (2 * axis, 2 * axis + 1);
            q[(p, p)] = s2 * dt.powi(4) / 4.0;
            q[(p, v)] = s2 * dt.powi(3) / 2.0;
            q[(v, p)] = s2 * dt.powi(3) / 2.0;
            q[(v, v)] = s2 * dt * dt;
        }
        q
    }
}

impl TransitionModel for ConstantVelocity {
    fn state_dim(&self) -> usize {
        2 * self.dims
    }

    fn predict(&self, particles: &mut ParticleSet, ctx: &StepContext, rng: &mut FilterRng) {
        if particles.dim() < self.state_dim() || particles.is_empty() {
            return;
        }
        let dt = ctx.dt;
        let half_dt2 = 0.5 * dt * dt;
        let sigma = self.sigma_accel;
        let mut comps = particles.components_mut();
        for axis in 0..self.dims {
            let (head, tail) = comps.split_at_mut(2 * axis + 1);
            let pos = &mut *head[2 * axis];
            let vel = &mut *tail[0];
            if sigma > 0.0 {
                for (p, v) in pos.iter_mut().zip(vel.iter_mut()) {
                    let e: f64 = StandardNormal.sample(rng);
                    let a = sigma * e;
                    *p += dt * *v + half_dt2 * a;
                    *v += dt * a;
                }
            } else {
                for (p, v) in pos.iter_mut().zip(vel.iter()) {
                    *p += dt * *v;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    #[test]
    fn rejects_bad_parameters() {
        assert!(ConstantVelocity::new(1, 1.0).is_err());
        assert!(ConstantVelocity::new(4, 1.0).is_err());
        assert!(ConstantVelocity::new(2, -1.0).is_err());
        assert!(ConstantVelocity::new(2, f64::NAN).is_err());
        assert!(ConstantVelocity::new(3, 0.0).is_ok());
    }

    #[test]
    fn noiseless_step_moves_by_velocity_times_dt() {
        let cv = ConstantVelocity::planar(0.0).unwrap();
        let rows = vec![vec![1.0, 2.0, -3.0, 0.5], vec![0.0, -1.0, 0.0, 4.0]];
        let mut p = ParticleSet::from_rows(&rows, &[1.0, 1.0]).unwrap();
        let ctx = StepContext::new(1, 2.0, 2.0);
        cv.predict(&mut p, &ctx, &mut seeded(1));
        // x + 2·ẋ, y + 2·ẏ; velocities unchanged
        assert_eq!(p.state(0), vec![5.0, 2.0, -2.0, 0.5]);
        assert_eq!(p.state(1), vec![-2.0, -1.0, 8.0, 4.0]);
    }

    #[test]
    fn noiseless_step_matches_transition_matrix_in_3d() {
        let cv = ConstantVelocity::spatial(0.0).unwrap();
        let x = vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let mut p = ParticleSet::from_rows(std::slice::from_ref(&x), &[1.0]).unwrap();
        cv.predict(&mut p, &StepContext::new(1, 0.5, 0.5), &mut seeded(1));
        let expected = cv.transition_matrix(0.5) * nalgebra::DVector::from_vec(x);
        for (a, b) in p.state(0).iter().zip(expected.iter()) {
            assert!((a - b).abs() < 1e-12);
        }
        // hand-computed: [1 + 1, 2, 3 + 2, 4, 5 + 3, 6]
        assert_eq!(p.state(0), vec![2.0, 2.0, 5.0, 4.0, 8.0, 6.0]);
    }

    #[test]
    fn too_short_particles_are_left_alone() {
        let cv = ConstantVelocity::spatial(1.0).unwrap();
        let mut p = ParticleSet::zeros(4, 3);
        let before = p.clone();
        cv.predict(&mut p, &StepContext::new(1, 1.0, 1.0), &mut seeded(1));
        assert_eq!(p, before);
    }

    #[test]
    fn process_noise_covariance_matches_q() {
        let sigma = 5.0;
        let dt = 2.0;
        let cv = ConstantVelocity::planar(sigma).unwrap();
        let n = 20_000;
        let mut p = ParticleSet::zeros(4, n);
        for v in p.component_mut(1) {
            *v = 3.0;
        }
        cv.predict(&mut p, &StepContext::new(1, dt, dt), &mut seeded(42));
        // remove the deterministic part (x += dt·3)
        for v in p.component_mut(0) {
            *v -= 3.0 * dt;
        }
        for v in p.component_mut(1) {
            *v -= 3.0;
        }
        let q = cv.process_covariance(dt);
        let rows: Vec<Vec<f64>> = (0..n).map(|i| p.state(i)).collect();
        let cov = |a: usize, b: usize| -> f64 {
            rows.iter().map(|r| r[a] * r[b]).sum::<f64>() / n as f64
        };
        for axis in 0..2 {
            let (i, j) = (2 * axis, 2 * axis + 1);
            for (a, b) in [(i, i), (i, j), (j, j)] {
                let rel = (cov(a, b) - q[(a, b)]).abs() / q[(a, b)];
                assert!(rel < 0.05, "Q[{a},{b}]: {} vs {}", cov(a, b), q[(a, b)]);
            }
        }
        // axes independent
        let cross = cov(0, 2) / (q[(0, 0)] * q[(2, 2)]).sqrt();
        assert!(cross.abs() < 0.05, "cross-axis correlation {cross}");
        // hand-computed Q for σ = 5, T = 2: 25·[[4, 4], [4, 4]]
        assert_eq!(q[(0, 0)], 100.0);
        assert_eq!(q[(0, 1)], 100.0);
        assert_eq!(q[(1, 1)], 100.0);
    }
}
