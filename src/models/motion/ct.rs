//! Planar coordinated-turn motion with an unknown, slowly varying turn rate — the dynamics of
//! the nonlinear SMC benchmark.
//!
//! State `[x, ẋ, y, ẏ, ω]`. Over a step of length T the velocity vector turns by θ = ωT and the
//! position follows the arc:
//!
//! ```text
//! a = sin(θ)/ω,  b = (1 − cos θ)/ω        (a → T, b → ωT²/2 as ω → 0)
//! x ← x + a ẋ − b ẏ
//! ẋ ← cos θ ẋ − sin θ ẏ
//! y ← y + b ẋ + a ẏ
//! ẏ ← sin θ ẋ + cos θ ẏ
//! ω ← ω
//! ```
//!
//! followed by additive noise G v with v ~ N(0, I₃) and the 5 × 3 matrix
//!
//! ```text
//! G = [[σ_vel T²/2, 0,          0        ],
//!      [σ_vel T,    0,          0        ],
//!      [0,          σ_vel T²/2, 0        ],
//!      [0,          σ_vel T,    0        ],
//!      [0,          0,          σ_turn T ]]
//! ```
//!
//! For |θ| < 1e-4 the coefficients come from their Taylor series
//! (a = T(1 − θ²/6), b = Tθ/2 · (1 − θ²/12)), so there is no jump at any threshold and no
//! division by a tiny ω; above it b is computed as 2 sin²(θ/2)/ω, which avoids cancellation.
//!
//! Not for: three-dimensional motion or turn-rate models with a speed component.

use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{check_state_dim, StepContext, TransitionModel};
use crate::rng::FilterRng;
use nalgebra::DMatrix;
use rand_distr::{Distribution, StandardNormal};

/// Below this |ωT| the turn coefficients are evaluated by their Taylor series.
const SERIES_THRESHOLD: f64 = 1e-4;

/// Coordinated-turn transition, state `[x, ẋ, y, ẏ, ω]`.
///
/// `sigma_vel` (m/s²) drives the velocity and position of each axis like a white-noise
/// acceleration; `sigma_turn` (rad/s²) drives the turn rate. The step length is `ctx.dt`.
/// Particle sets with fewer than 5 components are an error.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CoordinatedTurn {
    sigma_vel: f64,
    sigma_turn: f64,
}

impl CoordinatedTurn {
    /// A model with acceleration noise `sigma_vel` and turn-rate noise `sigma_turn`
    /// (both finite and ≥ 0).
    pub fn new(sigma_vel: f64, sigma_turn: f64) -> Result<Self> {
        for (name, v) in [("sigma_vel", sigma_vel), ("sigma_turn", sigma_turn)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("coordinated-turn {name}"),
                    format!("{v} (must be finite and non-negative)"),
                ));
            }
        }
        Ok(CoordinatedTurn {
            sigma_vel,
            sigma_turn,
        })
    }

    /// Standard deviation of the acceleration noise.
    pub fn sigma_vel(&self) -> f64 {
        self.sigma_vel
    }

    /// Standard deviation of the turn-rate noise.
    pub fn sigma_turn(&self) -> f64 {
        self.sigma_turn
    }

    /// The arc coefficients `(a, b, cos θ, sin θ)` for turn rate `omega` over a step `dt`,
    /// with θ = ω·dt, a = sin(θ)/ω and b = (1 − cos θ)/ω (Taylor series for |θ| < 1e-4).
    pub fn coefficients(omega: f64, dt: f64) -> (f64, f64, f64, f64) {
        let theta = omega * dt;
        let (s, c) = theta.sin_cos();
        if theta.abs() < SERIES_THRESHOLD {
            let t2 = theta * theta;
            let a = dt * (1.0 - t2 / 6.0);
            let b = dt * theta * 0.5 * (1.0 - t2 / 12.0);
            (a, b, c, s)
        } else {
            let h = (0.5 * theta).sin();
            (s / omega, 2.0 * h * h / omega, c, s)
        }
    }

    /// One noiseless step of a single state `[x, ẋ, y, ẏ, ω]`.
    pub fn step_noiseless(state: &mut [f64; 5], dt: f64) {
        let [x, vx, y, vy, w] = *state;
        let (a, b, c, s) = Self::coefficients(w, dt);
        *state = [
            x + a * vx - b * vy,
            c * vx - s * vy,
            y + b * vx + a * vy,
            s * vx + c * vy,
            w,
        ];
    }

    /// The noise gain G (5 × 3) for a step of length `dt`.
    pub fn noise_gain(&self, dt: f64) -> DMatrix<f64> {
        let mut g = DMatrix::zeros(5, 3);
        g[(0, 0)] = self.sigma_vel * dt * dt / 2.0;
        g[(1, 0)] = self.sigma_vel * dt;
        g[(2, 1)] = self.sigma_vel * dt * dt / 2.0;
        g[(3, 1)] = self.sigma_vel * dt;
        g[(4, 2)] = self.sigma_turn * dt;
        g
    }
}

impl TransitionModel for CoordinatedTurn {
    fn state_dim(&self) -> usize {
        5
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        check_state_dim(&self.name(), 5, particles)?;
        if particles.is_empty() {
            return Ok(());
        }
        let dt = ctx.dt;
        let gp = self.sigma_vel * dt * dt / 2.0;
        let gv = self.sigma_vel * dt;
        let gw = self.sigma_turn * dt;
        let noisy_vel = self.sigma_vel > 0.0;
        let noisy_turn = self.sigma_turn > 0.0;
        let mut comps = particles.components_mut();
        let [px, pvx, py, pvy, pw, ..] = comps.as_mut_slice() else {
            return Ok(());
        };
        let n = px.len();
        let (px, pvx, py, pvy, pw) = (
            &mut px[..n],
            &mut pvx[..n],
            &mut py[..n],
            &mut pvy[..n],
            &mut pw[..n],
        );
        for i in 0..n {
            let (x, vx, y, vy, w) = (px[i], pvx[i], py[i], pvy[i], pw[i]);
            let (a, b, c, s) = Self::coefficients(w, dt);
            let mut nx = x + a * vx - b * vy;
            let mut nvx = c * vx - s * vy;
            let mut ny = y + b * vx + a * vy;
            let mut nvy = s * vx + c * vy;
            let mut nw = w;
            if noisy_vel {
                let e1: f64 = StandardNormal.sample(rng);
                let e2: f64 = StandardNormal.sample(rng);
                nx += gp * e1;
                nvx += gv * e1;
                ny += gp * e2;
                nvy += gv * e2;
            }
            if noisy_turn {
                let e3: f64 = StandardNormal.sample(rng);
                nw += gw * e3;
            }
            px[i] = nx;
            pvx[i] = nvx;
            py[i] = ny;
            pvy[i] = nvy;
            pw[i] = nw;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use std::f64::consts::PI;

    fn one(state: [f64; 5]) -> ParticleSet {
        ParticleSet::from_rows(&[state.to_vec()], &[1.0]).unwrap()
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(CoordinatedTurn::new(-1.0, 0.1).is_err());
        assert!(CoordinatedTurn::new(1.0, f64::INFINITY).is_err());
        assert!(CoordinatedTurn::new(0.0, 0.0).is_ok());
    }

    #[test]
    fn quarter_turn_rotates_velocity_by_ninety_degrees() {
        let ct = CoordinatedTurn::new(0.0, 0.0).unwrap();
        let mut p = one([0.0, 1.0, 0.0, 0.0, PI / 2.0]);
        ct.predict(&mut p, &StepContext::new(1, 1.0, 1.0), &mut seeded(1))
            .unwrap();
        let s = p.state(0);
        // velocity (1, 0) turned left by 90° → (0, 1); a = sin(π/2)/(π/2) = 2/π,
        // b = (1 − 0)/(π/2) = 2/π, so the position is (2/π, 2/π).
        let expected = [2.0 / PI, 0.0, 2.0 / PI, 1.0, PI / 2.0];
        for (a, b) in s.iter().zip(expected) {
            assert!((a - b).abs() < 1e-12, "{s:?}");
        }
    }

    #[test]
    fn zero_turn_rate_is_constant_velocity() {
        let ct = CoordinatedTurn::new(0.0, 0.0).unwrap();
        let mut p = one([10.0, 3.0, -5.0, 4.0, 0.0]);
        ct.predict(&mut p, &StepContext::new(1, 2.0, 2.0), &mut seeded(1))
            .unwrap();
        assert_eq!(p.state(0), vec![16.0, 3.0, 3.0, 4.0, 0.0]);
    }

    #[test]
    fn coefficients_are_continuous_across_the_series_threshold() {
        let dt = 1.0;
        for &w in &[
            0.999_999e-4,
            1.000_001e-4,
            -0.999_999e-4,
            -1.000_001e-4,
            1e-12,
        ] {
            let (a, b, _, _) = CoordinatedTurn::coefficients(w, dt);
            let theta: f64 = w * dt;
            // reference with extended series (more terms than the implementation uses)
            let t2 = theta * theta;
            let a_ref = dt * (1.0 - t2 / 6.0 + t2 * t2 / 120.0);
            let b_ref = dt * (theta / 2.0 - theta * t2 / 24.0 + theta * t2 * t2 / 720.0);
            assert!((a - a_ref).abs() < 1e-15, "a at {w}");
            assert!((b - b_ref).abs() < 1e-18, "b at {w}");
        }
        let (a, b, c, s) = CoordinatedTurn::coefficients(0.0, 3.0);
        assert_eq!((a, b, c, s), (3.0, 0.0, 1.0, 0.0));
    }

    #[test]
    fn step_noiseless_agrees_with_predict() {
        let ct = CoordinatedTurn::new(0.0, 0.0).unwrap();
        let mut st = [100.0, -10.0, 50.0, 7.0, 0.03];
        let mut p = one(st);
        ct.predict(&mut p, &StepContext::new(1, 1.0, 1.0), &mut seeded(1))
            .unwrap();
        CoordinatedTurn::step_noiseless(&mut st, 1.0);
        assert_eq!(p.state(0), st.to_vec());
    }

    #[test]
    fn process_noise_covariance_matches_g_gt() {
        let ct = CoordinatedTurn::new(5.0, PI / 180.0).unwrap();
        let n = 20_000;
        let mut p = ParticleSet::zeroed(5, n);
        ct.predict(&mut p, &StepContext::new(1, 1.0, 1.0), &mut seeded(7))
            .unwrap();
        let g = ct.noise_gain(1.0);
        let q = &g * g.transpose();
        let cov = p.covariance();
        for (a, b) in [(0, 0), (0, 1), (1, 1), (2, 2), (2, 3), (3, 3), (4, 4)] {
            let rel = (cov[(a, b)] - q[(a, b)]).abs() / q[(a, b)];
            assert!(rel < 0.05, "Q[{a},{b}]: {} vs {}", cov[(a, b)], q[(a, b)]);
        }
        let cross = cov[(0, 2)] / (q[(0, 0)] * q[(2, 2)]).sqrt();
        assert!(cross.abs() < 0.05);
    }
}
