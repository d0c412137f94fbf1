//! Extended constant-turn (ECT) motion of a ground vehicle: the planar coordinated turn with
//! the heading carried in the state, so that the vehicle's pose (and with it the pose of a
//! vehicle-mounted sensor) can be predicted one step ahead.
//!
//! State `[X, Ẋ, Y, Ẏ, φ, φ̇]` in the world frame: position, velocity, heading φ (about z,
//! from the world x axis) and turn rate ω = φ̇. Over a step of length T, with θ = ωT,
//!
//! ```text
//! a = sin(θ)/ω,  b = (1 − cos θ)/ω        (a → T, b → 0 as ω → 0)
//!
//!       ⎡ 1  a      0  −b     0  0 ⎤
//!       ⎢ 0  cos θ  0  −sin θ 0  0 ⎥
//! F  =  ⎢ 0  b      1   a     0  0 ⎥        x_{k+1} = F(ω_k) x_k + G u,  u ~ N(0, I₃)
//!       ⎢ 0  sin θ  0   cos θ 0  0 ⎥
//!       ⎢ 0  0      0   0     1  T ⎥
//!       ⎣ 0  0      0   0     0  1 ⎦
//!
//!       ⎡ σ_a T²/2  0         0        ⎤
//!       ⎢ σ_a T     0         0        ⎥
//! G  =  ⎢ 0         σ_a T²/2  0        ⎥        Q = G Gᵀ
//!       ⎢ 0         σ_a T     0        ⎥
//!       ⎢ 0         0         σ_ω T²/2 ⎥
//!       ⎣ 0         0         0   σ_ω T ⎦
//! ```
//!
//! This is eq. (36) of the planar-feature paper (seed 001) with the turn rate, not the heading,
//! inside the trigonometric terms (the paper writes `sin(φ_k T)/φ_k`; the quantity meant there is
//! φ̇_k). σ_a = `sigma_accel` (m/s²) is a white acceleration on each axis, σ_ω =
//! `sigma_turn_accel` (rad/s²) a white angular acceleration; both enter position and velocity
//! (heading and turn rate) through the same discretised gains T²/2 and T.
//!
//! For |θ| < 1e-4 the coefficients a and b come from their Taylor series (see
//! [`CoordinatedTurn::coefficients`]), so there is no division by a tiny ω and no jump at the
//! threshold.
//!
//! Not for: the motion of tracked objects other than the ego vehicle (use
//! [`CoordinatedTurn`] or [`crate::models::ConstantVelocity`]), or three-dimensional motion.

use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{check_state_dim, StepContext, TransitionModel};
use crate::models::CoordinatedTurn;
use crate::rng::FilterRng;
use nalgebra::{DMatrix, Isometry3, Vector3};
use rand_distr::{Distribution, StandardNormal};

/// Extended constant-turn transition, state `[X, Ẋ, Y, Ẏ, φ, φ̇]`.
///
/// The step length is `ctx.dt`. Particle sets with fewer than 6 components are an error;
/// components beyond the sixth are not touched.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ExtendedConstantTurn {
    sigma_accel: f64,
    sigma_turn_accel: f64,
}

impl ExtendedConstantTurn {
    /// A model with white acceleration noise `sigma_accel` (m/s², per axis) and white angular
    /// acceleration noise `sigma_turn_accel` (rad/s²); both finite and ≥ 0.
    pub fn new(sigma_accel: f64, sigma_turn_accel: f64) -> Result<Self> {
        for (name, v) in [
            ("sigma_accel", sigma_accel),
            ("sigma_turn_accel", sigma_turn_accel),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("extended constant-turn {name}"),
                    format!("{v} (must be finite and non-negative)"),
                ));
            }
        }
        Ok(ExtendedConstantTurn {
            sigma_accel,
            sigma_turn_accel,
        })
    }

    /// A noiseless model (every step is [`ExtendedConstantTurn::step_noiseless`]).
    pub fn noiseless() -> Self {
        ExtendedConstantTurn {
            sigma_accel: 0.0,
            sigma_turn_accel: 0.0,
        }
    }

    /// Standard deviation of the white acceleration, m/s².
    pub fn sigma_accel(&self) -> f64 {
        self.sigma_accel
    }

    /// Standard deviation of the white angular acceleration, rad/s².
    pub fn sigma_turn_accel(&self) -> f64 {
        self.sigma_turn_accel
    }

    /// One noiseless step, x ← F(ω) x, of a single state over `dt` seconds.
    pub fn step_noiseless(state: &[f64; 6], dt: f64) -> [f64; 6] {
        let [x, vx, y, vy, phi, w] = *state;
        let (a, b, c, s) = CoordinatedTurn::coefficients(w, dt);
        [
            x + a * vx - b * vy,
            c * vx - s * vy,
            y + b * vx + a * vy,
            s * vx + c * vy,
            phi + w * dt,
            w,
        ]
    }

    /// One noisy step of a single state: F(ω) x + G u with a fresh u ~ N(0, I₃) from `rng`.
    pub fn sample_step(&self, state: &[f64; 6], dt: f64, rng: &mut FilterRng) -> [f64; 6] {
        let mut next = Self::step_noiseless(state, dt);
        self.add_noise(&mut next, dt, rng);
        next
    }

    fn add_noise(&self, s: &mut [f64; 6], dt: f64, rng: &mut FilterRng) {
        let half = 0.5 * dt * dt;
        if self.sigma_accel > 0.0 {
            let e1: f64 = StandardNormal.sample(rng);
            let e2: f64 = StandardNormal.sample(rng);
            s[0] += self.sigma_accel * half * e1;
            s[1] += self.sigma_accel * dt * e1;
            s[2] += self.sigma_accel * half * e2;
            s[3] += self.sigma_accel * dt * e2;
        }
        if self.sigma_turn_accel > 0.0 {
            let e3: f64 = StandardNormal.sample(rng);
            s[4] += self.sigma_turn_accel * half * e3;
            s[5] += self.sigma_turn_accel * dt * e3;
        }
    }

    /// The noise gain G (6 × 3) for a step of length `dt`; the process noise covariance is
    /// Q = G Gᵀ.
    pub fn noise_gain(&self, dt: f64) -> DMatrix<f64> {
        let mut g = DMatrix::zeros(6, 3);
        g[(0, 0)] = self.sigma_accel * dt * dt / 2.0;
        g[(1, 0)] = self.sigma_accel * dt;
        g[(2, 1)] = self.sigma_accel * dt * dt / 2.0;
        g[(3, 1)] = self.sigma_accel * dt;
        g[(4, 2)] = self.sigma_turn_accel * dt * dt / 2.0;
        g[(5, 2)] = self.sigma_turn_accel * dt;
        g
    }

    /// The planar pose of a vehicle state: rotation φ about z and translation (X, Y, 0).
    ///
    /// This is the 4 × 4 matrix R_k of seed 001 (eq. 28): it maps vehicle-frame points to the
    /// world frame.
    pub fn pose_of(state: &[f64; 6]) -> Isometry3<f64> {
        Isometry3::new(
            Vector3::new(state[0], state[2], 0.0),
            Vector3::new(0.0, 0.0, state[4]),
        )
    }
}

impl TransitionModel for ExtendedConstantTurn {
    fn state_dim(&self) -> usize {
        6
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        check_state_dim(&self.name(), 6, particles)?;
        if particles.is_empty() {
            return Ok(());
        }
        let dt = ctx.dt;
        let mut comps = particles.components_mut();
        let [px, pvx, py, pvy, pphi, pw, ..] = comps.as_mut_slice() else {
            return Ok(());
        };
        let n = px.len();
        for i in 0..n {
            let mut s = Self::step_noiseless(&[px[i], pvx[i], py[i], pvy[i], pphi[i], pw[i]], dt);
            self.add_noise(&mut s, dt, rng);
            px[i] = s[0];
            pvx[i] = s[1];
            py[i] = s[2];
            pvy[i] = s[3];
            pphi[i] = s[4];
            pw[i] = s[5];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use std::f64::consts::PI;

    fn close(a: &[f64], b: &[f64], tol: f64) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= tol, "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(ExtendedConstantTurn::new(-1.0, 0.1).is_err());
        assert!(ExtendedConstantTurn::new(1.0, f64::NAN).is_err());
        assert!(ExtendedConstantTurn::new(0.0, 0.0).is_ok());
    }

    #[test]
    fn zero_turn_rate_is_constant_velocity() {
        let s = ExtendedConstantTurn::step_noiseless(&[10.0, 3.0, -5.0, 4.0, 0.7, 0.0], 2.0);
        assert_eq!(s, [16.0, 3.0, 3.0, 4.0, 0.7, 0.0]);
    }

    #[test]
    fn quarter_turn_by_hand() {
        // Speed 1 along x, ω = π/2 over T = 1: the velocity turns to +y, the position follows
        // a quarter circle of radius 2/π, the heading grows by π/2.
        let s = ExtendedConstantTurn::step_noiseless(&[0.0, 1.0, 0.0, 0.0, 0.0, PI / 2.0], 1.0);
        close(
            &s,
            &[2.0 / PI, 0.0, 2.0 / PI, 1.0, PI / 2.0, PI / 2.0],
            1e-12,
        );
    }

    #[test]
    fn continuous_across_series_threshold() {
        let x0 = [5.0, 8.0, -2.0, 3.0, 0.3, 0.0];
        let dt = 0.1;
        // |ωT| straddles 1e-4: ω = 1e-3 ± tiny.
        for &w in &[0.999_999e-3, 1.000_001e-3, -0.999_999e-3, -1.000_001e-3] {
            let mut st = x0;
            st[5] = w;
            let s = ExtendedConstantTurn::step_noiseless(&st, dt);
            // exact arc with a longer series: a = T(1 − θ²/6 + θ⁴/120), b = T(θ/2 − θ³/24)
            let th: f64 = w * dt;
            let a = dt * (1.0 - th * th / 6.0 + th.powi(4) / 120.0);
            let b = dt * (th / 2.0 - th.powi(3) / 24.0);
            let (c, sn) = (th.cos(), th.sin());
            let r = [
                st[0] + a * st[1] - b * st[3],
                c * st[1] - sn * st[3],
                st[2] + b * st[1] + a * st[3],
                sn * st[1] + c * st[3],
                st[4] + w * dt,
                w,
            ];
            close(&s, &r, 1e-14);
        }
        // and the ω → 0 limit is exactly constant velocity
        let s = ExtendedConstantTurn::step_noiseless(&x0, dt);
        close(&s, &[5.8, 8.0, -1.7, 3.0, 0.3, 0.0], 1e-14);
    }

    #[test]
    fn predict_agrees_with_step_noiseless() {
        let m = ExtendedConstantTurn::noiseless();
        let st = [100.0, -10.0, 50.0, 7.0, 1.0, 0.03];
        let mut p = ParticleSet::from_rows(&[st.to_vec()], &[1.0]).unwrap();
        m.predict(&mut p, &StepContext::new(1, 0.1, 0.1), &mut seeded(1))
            .unwrap();
        assert_eq!(
            p.state(0),
            ExtendedConstantTurn::step_noiseless(&st, 0.1).to_vec()
        );
    }

    #[test]
    fn pose_of_is_planar() {
        let pose = ExtendedConstantTurn::pose_of(&[3.0, 0.0, 4.0, 0.0, PI / 2.0, 0.0]);
        let p = pose * nalgebra::Point3::new(1.0, 0.0, 2.0);
        close(&[p.x, p.y, p.z], &[3.0, 5.0, 2.0], 1e-12);
    }

    #[test]
    fn process_noise_covariance_matches_g_gt() {
        let m = ExtendedConstantTurn::new(2.0, 0.3).unwrap();
        let n = 20_000;
        let mut p = ParticleSet::zeroed(6, n);
        let dt = 0.5;
        m.predict(&mut p, &StepContext::new(1, dt, dt), &mut seeded(11))
            .unwrap();
        let g = m.noise_gain(dt);
        let q = &g * g.transpose();
        let cov = p.covariance();
        for (a, b) in [
            (0, 0),
            (0, 1),
            (1, 1),
            (2, 2),
            (2, 3),
            (3, 3),
            (4, 4),
            (4, 5),
            (5, 5),
        ] {
            let rel = (cov[(a, b)] - q[(a, b)]).abs() / q[(a, b)];
            assert!(rel < 0.05, "Q[{a},{b}]: {} vs {}", cov[(a, b)], q[(a, b)]);
        }
        for (a, b) in [(0, 2), (1, 5), (3, 4)] {
            let corr = cov[(a, b)] / (q[(a, a)] * q[(b, b)]).sqrt();
            assert!(corr.abs() < 0.05, "cross {a},{b}: {corr}");
        }
    }
}
