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
//! Manoeuvres ([`ConstantVelocity::with_manoeuvres`]): with probability p a particle's
//! acceleration in a step is drawn k times wider (one draw of the mode per particle and step,
//! shared by its axes) — a contaminated Gaussian, the memoryless form of a two-mode jump model
//! (cruise and manoeuvre). The cloud then keeps a fringe of particles that can follow a turn or
//! a braking the core would lag behind; its covariance is (1 − p + p k²) Q.
//!
//! Not for: sustained turns at a known rate (see [`crate::models::CoordinatedTurn`]) or
//! ego-motion compensation.

use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{check_state_dim, StepContext, TransitionModel};
use crate::rng::FilterRng;
use nalgebra::DMatrix;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};

/// Constant-velocity transition with white-noise acceleration of standard deviation
/// `sigma_accel` on every axis.
///
/// `dims` is the number of spatial axes (2 or 3); the state has `2 · dims` components laid out
/// `[x, ẋ, y, ẏ(, z, ż)]`. The step length is `ctx.dt`. Particle sets with fewer components
/// than [`TransitionModel::state_dim`] are an error; extra components are not touched.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConstantVelocity {
    dims: usize,
    sigma_accel: f64,
    /// (probability, scale) of a manoeuvre step, when set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    manoeuvre: Option<(f64, f64)>,
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
        Ok(ConstantVelocity {
            dims,
            sigma_accel,
            manoeuvre: None,
        })
    }

    /// The same model whose acceleration is, with probability `probability` per particle and
    /// step, drawn `scale` times wider (see the module notes). `probability` 0 keeps the plain
    /// model (and its random stream); `probability` must lie in [0, 1], `scale` be finite and
    /// at least 1.
    pub fn with_manoeuvres(mut self, probability: f64, scale: f64) -> Result<Self> {
        if !(0.0..=1.0).contains(&probability) {
            return Err(Error::invalid(
                "constant-velocity manoeuvre probability",
                format!("{probability} (must lie in [0, 1])"),
            ));
        }
        if !(scale.is_finite() && scale >= 1.0) {
            return Err(Error::invalid(
                "constant-velocity manoeuvre scale",
                format!("{scale} (must be finite and at least 1)"),
            ));
        }
        self.manoeuvre = (probability > 0.0).then_some((probability, scale));
        Ok(self)
    }

    /// (probability, scale) of a manoeuvre step, when the model has them.
    pub fn manoeuvres(&self) -> Option<(f64, f64)> {
        self.manoeuvre
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

    /// The process-noise covariance Q for a step of length `dt` (with manoeuvres, that of the
    /// mixture: (1 − p + p k²) times the plain one).
    pub fn process_covariance(&self, dt: f64) -> DMatrix<f64> {
        let n = 2 * self.dims;
        let widen = self.manoeuvre.map_or(1.0, |(p, k)| 1.0 - p + p * k * k);
        let s2 = self.sigma_accel * self.sigma_accel * widen;
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

impl ConstantVelocity {
    /// One step of every axis: particle i's acceleration is `width(i)`·e, e ~ N(0, 1) drawn
    /// axis after axis, particle after particle.
    #[inline(always)]
    fn accelerate(
        &self,
        particles: &mut ParticleSet,
        dt: f64,
        width: impl Fn(usize) -> f64,
        rng: &mut FilterRng,
    ) {
        let half_dt2 = 0.5 * dt * dt;
        let mut comps = particles.components_mut();
        for axis in 0..self.dims {
            let (head, tail) = comps.split_at_mut(2 * axis + 1);
            let pos = &mut *head[2 * axis];
            let vel = &mut *tail[0];
            for (i, (p, v)) in pos.iter_mut().zip(vel.iter_mut()).enumerate() {
                let e: f64 = StandardNormal.sample(rng);
                let a = width(i) * e;
                *p += dt * *v + half_dt2 * a;
                *v += dt * a;
            }
        }
    }
}

impl TransitionModel for ConstantVelocity {
    fn state_dim(&self) -> usize {
        2 * self.dims
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        check_state_dim(&self.name(), self.state_dim(), particles)?;
        if particles.is_empty() {
            return Ok(());
        }
        let (dt, sigma) = (ctx.dt, self.sigma_accel);
        if sigma == 0.0 {
            let mut comps = particles.components_mut();
            for axis in 0..self.dims {
                let (head, tail) = comps.split_at_mut(2 * axis + 1);
                for (p, v) in head[2 * axis].iter_mut().zip(tail[0].iter()) {
                    *p += dt * *v;
                }
            }
            return Ok(());
        }
        match self.manoeuvre {
            None => self.accelerate(particles, dt, |_| sigma, rng),
            Some((probability, scale)) => {
                // One mode a particle, drawn before its axes' accelerations.
                let widths: Vec<f64> = (0..particles.len())
                    .map(|_| {
                        if rng.random::<f64>() < probability {
                            sigma * scale
                        } else {
                            sigma
                        }
                    })
                    .collect();
                self.accelerate(particles, dt, |i| widths[i], rng)
            }
        }
        Ok(())
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
        cv.predict(&mut p, &ctx, &mut seeded(1)).unwrap();
        // x + 2·ẋ, y + 2·ẏ; velocities unchanged
        assert_eq!(p.state(0), vec![5.0, 2.0, -2.0, 0.5]);
        assert_eq!(p.state(1), vec![-2.0, -1.0, 8.0, 4.0]);
    }

    #[test]
    fn noiseless_step_matches_transition_matrix_in_3d() {
        let cv = ConstantVelocity::spatial(0.0).unwrap();
        let x = vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let mut p = ParticleSet::from_rows(std::slice::from_ref(&x), &[1.0]).unwrap();
        cv.predict(&mut p, &StepContext::new(1, 0.5, 0.5), &mut seeded(1))
            .unwrap();
        let expected = cv.transition_matrix(0.5) * nalgebra::DVector::from_vec(x);
        for (a, b) in p.state(0).iter().zip(expected.iter()) {
            assert!((a - b).abs() < 1e-12);
        }
        // hand-computed: [1 + 1, 2, 3 + 2, 4, 5 + 3, 6]
        assert_eq!(p.state(0), vec![2.0, 2.0, 5.0, 4.0, 8.0, 6.0]);
    }

    #[test]
    fn too_short_particles_are_an_error_and_left_alone() {
        let cv = ConstantVelocity::spatial(1.0).unwrap();
        let mut p = ParticleSet::zeroed(4, 3);
        let before = p.clone();
        let e = cv
            .predict(&mut p, &StepContext::new(1, 1.0, 1.0), &mut seeded(1))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("4 components") && e.contains("states of 6"),
            "{e}"
        );
        assert_eq!(p, before);
    }

    #[test]
    fn process_noise_covariance_matches_q() {
        let sigma = 5.0;
        let dt = 2.0;
        let cv = ConstantVelocity::planar(sigma).unwrap();
        let n = 20_000;
        let mut p = ParticleSet::zeroed(4, n);
        for v in p.component_mut(1) {
            *v = 3.0;
        }
        cv.predict(&mut p, &StepContext::new(1, dt, dt), &mut seeded(42))
            .unwrap();
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

    #[test]
    fn manoeuvres_are_checked_and_probability_zero_is_the_plain_model() {
        let cv = ConstantVelocity::spatial(2.0).unwrap();
        assert!(cv.with_manoeuvres(-0.1, 3.0).is_err());
        assert!(cv.with_manoeuvres(1.5, 3.0).is_err());
        assert!(cv.with_manoeuvres(0.1, 0.5).is_err());
        assert!(cv.with_manoeuvres(0.1, f64::INFINITY).is_err());
        assert_eq!(
            cv.with_manoeuvres(0.2, 3.0).unwrap().manoeuvres(),
            Some((0.2, 3.0))
        );
        let off = cv.with_manoeuvres(0.0, 3.0).unwrap();
        assert_eq!(off, cv);
        let step = |m: &ConstantVelocity| {
            let mut p = ParticleSet::zeroed(6, 50);
            m.predict(&mut p, &StepContext::new(1, 0.1, 0.1), &mut seeded(5))
                .unwrap();
            p
        };
        assert_eq!(step(&off), step(&cv));
    }

    /// With manoeuvres the velocity change of one step is the contaminated Gaussian
    /// (1 − p)·N(0, (σT)²) + p·N(0, (kσT)²): its variance is (1 − p + p k²)(σT)², the
    /// process covariance says so, and |Δv| > 3σT is as frequent as the mixture makes it
    /// (0.9 · 0.27 % + 0.1 · 31.7 % ≈ 3.4 % for p = 0.1, k = 3), far above a Gaussian's 0.27 %.
    #[test]
    fn manoeuvres_widen_the_acceleration_as_the_mixture_does() {
        let (sigma, dt, p, k) = (8.0, 0.1, 0.1, 3.0);
        let cv = ConstantVelocity::spatial(sigma)
            .unwrap()
            .with_manoeuvres(p, k)
            .unwrap();
        let n = 200_000;
        let mut set = ParticleSet::zeroed(6, n);
        cv.predict(&mut set, &StepContext::new(1, dt, dt), &mut seeded(9))
            .unwrap();
        let s = sigma * dt;
        let widen = 1.0 - p + p * k * k;
        for axis in 0..3 {
            let v = set.component(2 * axis + 1);
            let var = v.iter().map(|x| x * x).sum::<f64>() / n as f64;
            assert!(
                (var / (widen * s * s) - 1.0).abs() < 0.03,
                "axis {axis}: {var}"
            );
            let tail = v.iter().filter(|x| x.abs() > 3.0 * s).count() as f64 / n as f64;
            assert!((0.030..0.039).contains(&tail), "axis {axis}: tail {tail}");
        }
        // One mode a particle: its axes are widened together, so their squares correlate.
        let (vx, vy) = (set.component(1), set.component(3));
        let mean_sq = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / n as f64;
        let joint = vx.iter().zip(vy).map(|(a, b)| a * a * b * b).sum::<f64>() / n as f64;
        assert!(joint > 1.2 * mean_sq(vx) * mean_sq(vy), "{joint}");
        let q = cv.process_covariance(dt);
        assert!((q[(1, 1)] - widen * s * s).abs() < 1e-12);
    }
}
