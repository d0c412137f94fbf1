//! The coordinated turn in polar form (constant turn rate and velocity, CTRV) as a vehicle
//! model: state [X, Y, φ, v, ω] — position, heading, speed along the heading, turn rate.
//!
//! Over a step of length T the vehicle drives an arc: φ' = φ + ωT and
//! X' = X + v (sin φ' − sin φ)/ω, Y' = Y + v (cos φ − cos φ')/ω, written with the same
//! well-conditioned coefficients as the Cartesian coordinated turn
//! ([`crate::models::CoordinatedTurn::coefficients`]: a = sin(ωT)/ω → T, b = (1 − cos ωT)/ω →
//! 0), so there is no division by a small ω. Noise: a white longitudinal acceleration σ_a
//! (speed + σ_a T e₁, position + σ_a T²/2 e₁ along the heading) and a white angular
//! acceleration σ_ω (heading + σ_ω T²/2 e₂, turn rate + σ_ω T e₂).
//!
//! Unlike the extended constant turn (Gostar et al. 2019), the vehicle always points along its
//! velocity: no side slip. Not for: tracked objects (see [`crate::models::CoordinatedTurn`]).

use super::{VehicleModel, VehicleState};
use crate::error::{ensure_non_negative, Result};
use crate::models::CoordinatedTurn;
use crate::rng::FilterRng;
use nalgebra::{Isometry3, Vector3};
use rand_distr::{Distribution, StandardNormal};

/// Constant turn rate and velocity, state [X, Y, φ, v, ω].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CoordinatedTurnVehicle {
    sigma_accel: f64,
    sigma_turn_accel: f64,
}

impl CoordinatedTurnVehicle {
    /// A model with longitudinal acceleration noise `sigma_accel` (m/s²) and angular
    /// acceleration noise `sigma_turn_accel` (rad/s²), both finite and ≥ 0.
    pub fn new(sigma_accel: f64, sigma_turn_accel: f64) -> Result<Self> {
        ensure_non_negative("coordinated-turn vehicle sigma_accel", sigma_accel)?;
        ensure_non_negative(
            "coordinated-turn vehicle sigma_turn_accel",
            sigma_turn_accel,
        )?;
        Ok(CoordinatedTurnVehicle {
            sigma_accel,
            sigma_turn_accel,
        })
    }
}

/// The arc of a step: position, heading and turn rate after `dt` at constant v and ω.
fn arc(state: &[f64], dt: f64, next: &mut [f64]) {
    let (x, y, phi, v, w) = (state[0], state[1], state[2], state[3], state[4]);
    let (a, b, _, _) = CoordinatedTurn::coefficients(w, dt);
    let (s, c) = phi.sin_cos();
    // velocity (v cos φ, v sin φ) turned through the arc
    let (vx, vy) = (v * c, v * s);
    next[0] = x + a * vx - b * vy;
    next[1] = y + b * vx + a * vy;
    next[2] = phi + w * dt;
    next[3] = v;
    next[4] = w;
}

impl VehicleModel for CoordinatedTurnVehicle {
    fn state_dim(&self) -> usize {
        5
    }

    fn state_of(&self, m: &VehicleState) -> Vec<f64> {
        let (s, c) = m.heading.sin_cos();
        vec![m.x, m.y, m.heading, m.vx * c + m.vy * s, m.yaw_rate]
    }

    fn sample_step(&self, state: &[f64], dt: f64, rng: &mut FilterRng, next: &mut [f64]) {
        arc(state, dt, next);
        let half = 0.5 * dt * dt;
        if self.sigma_accel > 0.0 {
            let e: f64 = StandardNormal.sample(rng);
            let (s, c) = state[2].sin_cos();
            next[0] += self.sigma_accel * half * e * c;
            next[1] += self.sigma_accel * half * e * s;
            next[3] += self.sigma_accel * dt * e;
        }
        if self.sigma_turn_accel > 0.0 {
            let e: f64 = StandardNormal.sample(rng);
            next[2] += self.sigma_turn_accel * half * e;
            next[4] += self.sigma_turn_accel * dt * e;
        }
    }

    fn mean_step(&self, state: &[f64], dt: f64, next: &mut [f64]) {
        arc(state, dt, next);
    }

    fn pose_of(&self, state: &[f64]) -> Isometry3<f64> {
        Isometry3::new(
            Vector3::new(state[0], state[1], 0.0),
            Vector3::new(0.0, 0.0, state[2]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn quarter_circle_by_hand() {
        // 1 m/s at heading 0, ω = π/2 over 1 s: a quarter circle of radius 2/π to the left.
        let m = CoordinatedTurnVehicle::new(0.0, 0.0).unwrap();
        let mut next = [0.0; 5];
        m.mean_step(&[0.0, 0.0, 0.0, 1.0, PI / 2.0], 1.0, &mut next);
        let want = [2.0 / PI, 2.0 / PI, PI / 2.0, 1.0, PI / 2.0];
        for (a, b) in next.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{next:?}");
        }
        // straight ahead without a turn
        m.mean_step(&[1.0, 2.0, PI / 2.0, 3.0, 0.0], 2.0, &mut next);
        assert!((next[0] - 1.0).abs() < 1e-12 && (next[1] - 8.0).abs() < 1e-12);
    }

    #[test]
    fn bad_noise_is_refused() {
        assert!(CoordinatedTurnVehicle::new(-1.0, 0.1).is_err());
        assert!(CoordinatedTurnVehicle::new(0.5, f64::NAN).is_err());
    }
}
