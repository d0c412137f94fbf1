//! Interacting multiple models (IMM) for one track: a constant-velocity (CV) and a
//! coordinated-turn (CT) model over the common state `[x, ẋ, y, ẏ, ω]`, as in seed 003, Sec. V.
//!
//! * CV: the position/velocity pairs move as in [`super::ekf::cv_matrices`]; ω is carried
//!   unchanged (with a little noise, `sigma_turn_cv`), so mixing with CT is well defined.
//! * CT: the arc of [`crate::models::CoordinatedTurn`] (x ← x + a ẋ − b ẏ, …, with
//!   a = sin(ωT)/ω, b = (1 − cos ωT)/ω), linearised by its Jacobian F (derivatives in ω below),
//!   and noise G Gᵀ with the same G as that model.
//!
//! ```text
//! ∂a/∂ω = (T cos ωT − a)/ω   (→ −ωT³/3)      ∂b/∂ω = (T sin ωT − b)/ω   (→ T²/2 − ω²T⁴/8)
//! ```
//!
//! One cycle (Bar-Shalom, Li & Kirubarajan 2001, Sec. 11.6): mixing probabilities
//! μ_{i|j} = π_ij μ_i / c̄_j with c̄_j = Σ_i π_ij μ_i; mixed initial densities per model; one
//! EKF prediction per model; after the measurement update the mode probabilities become
//! μ_j ∝ Λ_j c̄_j with Λ_j the model's measurement likelihood; the output is the moment-matched
//! mixture. The measurement update itself is left to the caller (PDA-style in
//! [`super::jpda_imm`]).
//!
//! Seed 003 names the two models but gives no numbers; the defaults of [`ImmConfig`] are this
//! module's own.
//!
//! Not for: data association.

use super::ekf::{cv_matrices, symmetrise, Gaussian};
use crate::error::{Error, Result};
use crate::models::CoordinatedTurn;
use nalgebra::{Matrix5, Vector5};

/// Below this |ωT| the derivatives of the turn coefficients come from their series.
const SERIES: f64 = 1e-3;

/// IMM tuning.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ImmConfig {
    /// CV white acceleration noise (m/s²). Default 0.5.
    pub sigma_accel_cv: f64,
    /// Random walk of ω under CV (rad/s²). Default 0.01.
    pub sigma_turn_cv: f64,
    /// CT velocity noise (m/s², the σ_vel of [`CoordinatedTurn`]). Default 1.
    pub sigma_vel_ct: f64,
    /// CT turn-rate noise (rad/s²). Default 0.5.
    pub sigma_turn_ct: f64,
    /// Probability of staying in the same model from one step to the next. Default 0.95.
    pub stay: f64,
    /// Mode probabilities [CV, CT] of a new track. Default [0.8, 0.2].
    pub initial_modes: [f64; 2],
    /// Turn-rate standard deviation of a new track (rad/s). Default 0.5.
    pub turn_std: f64,
}

impl Default for ImmConfig {
    fn default() -> Self {
        ImmConfig {
            sigma_accel_cv: 0.5,
            sigma_turn_cv: 0.01,
            sigma_vel_ct: 1.0,
            sigma_turn_ct: 0.5,
            stay: 0.95,
            initial_modes: [0.8, 0.2],
            turn_std: 0.5,
        }
    }
}

impl ImmConfig {
    /// Checks noise levels and probabilities.
    pub fn validate(&self) -> Result<()> {
        for (what, v) in [
            ("IMM sigma_accel_cv", self.sigma_accel_cv),
            ("IMM sigma_turn_cv", self.sigma_turn_cv),
            ("IMM sigma_vel_ct", self.sigma_vel_ct),
            ("IMM sigma_turn_ct", self.sigma_turn_ct),
        ] {
            crate::error::ensure_non_negative(what, v)?;
        }
        crate::error::ensure_positive("IMM turn_std", self.turn_std)?;
        let [a, b] = self.initial_modes;
        let ok = self.stay > 0.0
            && self.stay < 1.0
            && a >= 0.0
            && b >= 0.0
            && ((a + b) - 1.0).abs() < 1e-9;
        if !ok {
            return Err(Error::invalid(
                "IMM probabilities",
                format!(
                    "stay {}, initial modes {:?} (need 0 < stay < 1, modes summing to 1)",
                    self.stay, self.initial_modes
                ),
            ));
        }
        Ok(())
    }

    /// The Markov switching matrix π_ij (from model i to model j).
    pub fn switching(&self) -> [[f64; 2]; 2] {
        let s = self.stay;
        [[s, 1.0 - s], [1.0 - s, s]]
    }
}

/// The CT state after `dt` and the Jacobian of that map.
pub fn ct_transition(x: &Vector5<f64>, dt: f64) -> (Vector5<f64>, Matrix5<f64>) {
    let (vx, vy, w) = (x[1], x[3], x[4]);
    let (a, b, c, s) = CoordinatedTurn::coefficients(w, dt);
    let theta = w * dt;
    let (da, db) = if theta.abs() < SERIES {
        (
            -w * dt.powi(3) / 3.0,
            dt * dt / 2.0 - w * w * dt.powi(4) / 8.0,
        )
    } else {
        ((dt * c - a) / w, (dt * s - b) / w)
    };
    let mut state = [x[0], vx, x[2], vy, w];
    CoordinatedTurn::step_noiseless(&mut state, dt);
    #[rustfmt::skip]
    let f = Matrix5::new(
        1.0, a,   0.0, -b,  da * vx - db * vy,
        0.0, c,   0.0, -s,  -dt * (s * vx + c * vy),
        0.0, b,   1.0, a,   db * vx + da * vy,
        0.0, s,   0.0, c,   dt * (c * vx - s * vy),
        0.0, 0.0, 0.0, 0.0, 1.0,
    );
    (Vector5::from(state), f)
}

/// One IMM track density: a Gaussian and a probability per model ([CV, CT]).
#[derive(Clone, Debug, PartialEq)]
pub struct ImmDensity {
    /// Model-conditioned densities.
    pub models: [Gaussian<5>; 2],
    /// Mode probabilities (after the last update; the predicted ones after [`Self::predict`]).
    pub modes: [f64; 2],
}

impl ImmDensity {
    /// A new track from a CV density `[x, ẋ, y, ẏ]`: ω = 0 with the configured spread, in
    /// both models.
    pub fn from_cv(g: &Gaussian<4>, config: &ImmConfig) -> Self {
        let mut mean = Vector5::zeros();
        let mut cov = Matrix5::zeros();
        for i in 0..4 {
            mean[i] = g.mean[i];
            for j in 0..4 {
                cov[(i, j)] = g.cov[(i, j)];
            }
        }
        cov[(4, 4)] = config.turn_std * config.turn_std;
        let g5 = Gaussian { mean, cov };
        ImmDensity {
            models: [g5.clone(), g5],
            modes: config.initial_modes,
        }
    }

    /// Interaction and per-model prediction over `dt`; `modes` become the predicted c̄_j.
    pub fn predict(&mut self, dt: f64, config: &ImmConfig) {
        let pi = config.switching();
        let mut cbar = [0.0; 2];
        for (j, c) in cbar.iter_mut().enumerate() {
            *c = (0..2)
                .map(|i| pi[i][j] * self.modes[i])
                .sum::<f64>()
                .max(1e-300);
        }
        let mixed: Vec<Gaussian<5>> = (0..2)
            .map(|j| {
                let w: Vec<f64> = (0..2).map(|i| pi[i][j] * self.modes[i] / cbar[j]).collect();
                moment_match(&self.models, &w)
            })
            .collect();
        let [cv, ct] = [&mixed[0], &mixed[1]];
        // CV
        let (f4, q4) = cv_matrices(dt, config.sigma_accel_cv);
        let mut f = Matrix5::identity();
        let mut q = Matrix5::zeros();
        for i in 0..4 {
            for j in 0..4 {
                f[(i, j)] = f4[(i, j)];
                q[(i, j)] = q4[(i, j)];
            }
        }
        q[(4, 4)] = (config.sigma_turn_cv * dt).powi(2);
        let mut g_cv = Gaussian {
            mean: f * cv.mean,
            cov: f * cv.cov * f.transpose() + q,
        };
        symmetrise(&mut g_cv.cov);
        // CT
        let (mean, f) = ct_transition(&ct.mean, dt);
        let (gp, gv, gw) = (
            config.sigma_vel_ct * dt * dt / 2.0,
            config.sigma_vel_ct * dt,
            config.sigma_turn_ct * dt,
        );
        let mut q = Matrix5::zeros();
        for p in [0, 2] {
            q[(p, p)] = gp * gp;
            q[(p, p + 1)] = gp * gv;
            q[(p + 1, p)] = gp * gv;
            q[(p + 1, p + 1)] = gv * gv;
        }
        q[(4, 4)] = gw * gw;
        let mut g_ct = Gaussian {
            mean,
            cov: f * ct.cov * f.transpose() + q,
        };
        symmetrise(&mut g_ct.cov);
        self.models = [g_cv, g_ct];
        self.modes = cbar;
    }

    /// Mode probabilities after an update with per-model likelihoods `likelihood`
    /// (μ_j ∝ Λ_j c̄_j); unchanged when every product underflows.
    pub fn update_modes(&mut self, likelihood: [f64; 2]) {
        let w = [likelihood[0] * self.modes[0], likelihood[1] * self.modes[1]];
        let total = w[0] + w[1];
        if total.is_finite() && total > 0.0 {
            self.modes = [w[0] / total, w[1] / total];
        }
    }

    /// The moment-matched mixture of the two models.
    pub fn combined(&self) -> Gaussian<5> {
        moment_match(&self.models, &self.modes)
    }
}

/// Mean and covariance of the mixture Σ wᵢ N(mᵢ, Pᵢ) (weights summing to one).
pub fn moment_match(parts: &[Gaussian<5>], weights: &[f64]) -> Gaussian<5> {
    let mean: Vector5<f64> = parts.iter().zip(weights).map(|(g, &w)| g.mean * w).sum();
    let mut cov = Matrix5::zeros();
    for (g, &w) in parts.iter().zip(weights) {
        let d = g.mean - mean;
        cov += (g.cov + d * d.transpose()) * w;
    }
    symmetrise(&mut cov);
    Gaussian { mean, cov }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn ct_jacobian_matches_finite_differences(
            vx in -2.0f64..2.0, vy in -2.0f64..2.0, w in -1.0f64..1.0, dt in 0.05f64..1.0,
        ) {
            let x = Vector5::new(1.0, vx, -2.0, vy, w);
            let (_, f) = ct_transition(&x, dt);
            let eps = 1e-6;
            for col in 0..5 {
                let (mut up, mut down) = (x, x);
                up[col] += eps;
                down[col] -= eps;
                let d = (ct_transition(&up, dt).0 - ct_transition(&down, dt).0) / (2.0 * eps);
                for row in 0..5 {
                    prop_assert!((d[row] - f[(row, col)]).abs() < 1e-5,
                        "F[{},{}] = {} vs {}", row, col, f[(row, col)], d[row]);
                }
            }
        }
    }

    #[test]
    fn quarter_turn_in_one_second() {
        // ω = π/2 rad/s, speed 1 along +x: after 1 s the velocity points along +y and the
        // position is on the circle of radius 2/π: (2/π, 2/π)
        let x = Vector5::new(0.0, 1.0, 0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let (y, _) = ct_transition(&x, 1.0);
        let r = 2.0 / std::f64::consts::PI;
        assert!((y[0] - r).abs() < 1e-12 && (y[2] - r).abs() < 1e-12);
        assert!(y[1].abs() < 1e-12 && (y[3] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn mode_probabilities_follow_the_likelihoods() {
        let cfg = ImmConfig::default();
        let g = Gaussian {
            mean: nalgebra::Vector4::new(0.0, 1.0, 0.0, 0.0),
            cov: nalgebra::Matrix4::identity(),
        };
        let mut d = ImmDensity::from_cv(&g, &cfg);
        d.predict(0.1, &cfg);
        // c̄ = [0.95·0.8 + 0.05·0.2, 0.05·0.8 + 0.95·0.2] = [0.77, 0.23]
        assert!((d.modes[0] - 0.77).abs() < 1e-12 && (d.modes[1] - 0.23).abs() < 1e-12);
        d.update_modes([1.0, 3.0]);
        // ∝ [0.77, 0.69]
        assert!((d.modes[0] - 0.77 / 1.46).abs() < 1e-12);
        let m = d.combined();
        assert!((m.mean[0] - 0.1).abs() < 1e-9, "{}", m.mean);
    }
}
