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

use super::{accelerate, arc, planar_pose, VehicleModel, VehicleState};
use crate::error::{ensure_non_negative, Result};
use crate::rng::FilterRng;
use nalgebra::Isometry3;
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
fn step(state: &[f64], dt: f64, next: &mut [f64]) {
    let (x, y, phi) = arc(state[0], state[1], state[2], state[3], state[4], dt);
    next.copy_from_slice(&[x, y, phi, state[3], state[4]]);
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
        step(state, dt, next);
        accelerate(self.sigma_accel, state[2], dt, rng, next);
        if self.sigma_turn_accel > 0.0 {
            let e: f64 = StandardNormal.sample(rng);
            next[2] += self.sigma_turn_accel * 0.5 * dt * dt * e;
            next[4] += self.sigma_turn_accel * dt * e;
        }
    }

    fn mean_step(&self, state: &[f64], dt: f64, next: &mut [f64]) {
        step(state, dt, next);
    }

    fn pose_of(&self, state: &[f64]) -> Isometry3<f64> {
        planar_pose(state)
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
